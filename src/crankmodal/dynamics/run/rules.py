"""The admissible values of a run's arguments: integrator settings and run length.

The core checks :class:`~.integrate.SolverSettings` and :func:`~.simulate.simulate`'s arguments
with these rules (:mod:`crankmodal.arguments`); the ``[dynamics]`` scene keys take theirs from
here (:mod:`..scene.keys`), so the scene and the Python API refuse the same values and the
core imports nothing of the scene.
"""

from __future__ import annotations

from ...schema import Field

#: integration methods: ``auto`` (chosen per mechanism, :func:`~.integrate.auto_method`) and
#: the ``scipy.integrate.solve_ivp`` methods
METHODS = ("auto", "LSODA", "Radau", "BDF", "RK45", "DOP853")

#: most output samples of one run (``end_time / output_step``): 1e7 samples of the history
#: arrays already take gigabytes
MAX_OUTPUT_SAMPLES = 10_000_000

#: initial elastic state of flexible bodies
STARTS = ("quasi_static", "undeformed")

#: :class:`~.integrate.SolverSettings` fields (defaults are the scene's)
SOLVER = {
    "method": Field("str", "auto", "solve_ivp method; auto: RK45 (fastest measured, also for "
                    "stiff contact), LSODA when friction sticks (slow sliding) or with an oil "
                    "film; with flexible bodies Radau on ideal joints or with an oil film",
                    choices=METHODS),
    "rtol": Field("float", 1e-6, "relative tolerance", gt=0.0, lt=1.0),
    "atol": Field("float", None, "absolute position tolerance, m (default min(1e-9, c/1e4))",
                  gt=0.0),
    "max_rhs_evals": Field("int", 2_000_000, "budget of right-hand-side evaluations", gt=0),
    "baumgarte": Field("float", None, "constraint stabilisation rate, 1/s (default 2 omega)",
                       gt=0.0),
}

#: :func:`~.simulate.simulate`'s run length and energy check
RUN = {
    "end_time": Field("float", 0.2, "simulated time, s", gt=0.0, le=100.0),
    "output_step": Field("float", None, "output sampling step, s (default: 1 deg of crank)",
                         gt=0.0),
    "energy_tolerance": Field("float", 1e-3, "admissible energy-balance residual (relative)",
                              gt=0.0),
    "start": Field("str", "quasi_static", "initial elastic state: quasi_static (the bodies "
                   "deformed at rest under the loads at t = 0) or undeformed", choices=STARTS),
}
