"""Running a mechanism: the integrator driver, checked runs, run budgets, contact time scales and ensembles."""
