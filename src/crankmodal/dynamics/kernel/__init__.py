"""The compiled evaluator (Numba) of a built system, and the compiled integrator loop."""
