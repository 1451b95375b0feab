"""A solver that fails before its first output time: the failure is reported at the restart
point, one NumericalError (not an IndexError from the empty output)."""

import numpy as np
import pytest

from crankmodal.dynamics import Cylinder, SolverSettings, crank_train
from crankmodal.dynamics.run.integrate import integrate
from crankmodal.errors import NumericalError


def test_a_failure_before_the_first_output_time_names_the_restart_time(monkeypatch):
    import scipy.integrate

    cyl = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                   rod_com=0.042, piston_mass=0.75)
    m = crank_train(0.035, [cyl], 3000.0, crank_mass=2.0, crank_inertia=0.01)

    class Failed:  # what solve_ivp returns when its step size underflows at once
        status, message = -1, "Required step size is less than spacing between numbers."
        t, y = np.zeros(0), np.zeros((0, 0))
        t_events = y_events = None

    monkeypatch.setattr(scipy.integrate, "solve_ivp", lambda *a, **k: Failed())
    with pytest.raises(NumericalError, match=r"integrator failed at t = 0 s \(Required step"):
        integrate(m.system, m.q0, m.qd0, 0.01, np.linspace(0.005, 0.01, 3),
                  SolverSettings(method="LSODA"), compiled_loop=False)
