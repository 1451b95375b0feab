"""The compiled Radau IIA step (crankmodal.dynamics.kernel.implicit) against SciPy's Radau.

Oracle: ``scipy.integrate.Radau`` itself (the peer code the compiled step ports), given the same
compiled Jacobian, on smooth runs (flexible bodies on ideal joints; a journal floating on its
oil film): the same number of evaluations and the same trajectory at the output times. The two
differ only in the linear algebra of Newton's iteration (SciPy: LAPACK on the 2 n + 6 square
system; compiled: its n square reduction), i.e. by round-off of the solves, which the error
control damps: 1e-9 of the peaks holds with three orders to spare at rtol 1e-6 (seen: 1e-15 to
3e-12). The step times themselves differ by up to 4e-7 of t on the film, whose error estimate is
ill-conditioned (round-off of the estimate moves the step factor), so the runs are compared at
output times. A wrong reduction (the sign of ``mu Jv``, the work rows' ``1 / mu``) changes
Newton's iterates and the error estimate, hence the trajectory by far more."""

import numpy as np
import pytest
from test_dynamics_speed import FRICTION, PARAMS, _synthetic_flexible

from crankmodal.dynamics import Cylinder, crank_train
from crankmodal.dynamics.kernel import implicit
from crankmodal.dynamics.run.integrate import SolverSettings, integrate
from crankmodal.errors import NumericalError


def _train(flexible=True, film=False):
    """Two-cylinder train without Python gas functions (the whole right-hand side compiled):
    flexible crank (5 modes + 2 tilts) and rods (5 modes) on ideal joints, or rigid bodies with
    the big end floating on seed 001's short-bearing film."""
    rng = np.random.default_rng(3)
    cyls = [Cylinder(axis_angle=a, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                     rod_com=0.042, piston_mass=0.75, ring_friction=30.0) for a in (0.0, 1.2)]
    kw = {"law": "impact", "law_params": PARAMS, "friction": "coulomb",
          "friction_params": FRICTION}
    if not flexible:
        cl = {"big_end_1": {"clearance": 2.1e-5, "journal_radius": 0.02, "viscosity": 0.0175,
                            "bearing_length": 0.03}} if film else None
        return crank_train(0.035, cyls, 3000.0, crank_mass=2.0, crank_inertia=0.01,
                           clearances=cl, contact_kw=kw, gravity=(0.0, -9.81))
    crank = _synthetic_flexible("crank", 7, {"main_a": (0.0, 0.0), "pin": (0.035, 0.0)}, rng,
                                mass=2.0, j0=0.01, tilt=2)
    rods = [_synthetic_flexible(f"rod_{i}", 5, {"big": (-0.042, 0.0), "small": (0.098, 0.0)},
                                rng, mass=0.9, j0=3.1e-3) for i in (1, 2)]
    return crank_train(0.035, cyls, 3000.0, crank_body=crank,
                       crank_roles={"mains": ["main_a"], "pins": ["pin", "pin"],
                                    "drive": "main_a"},
                       rod_bodies=rods, contact_kw=kw, gravity=(0.0, -9.81))


def _run(mech, t_end, compiled, monkeypatch, **settings):
    """Radau through integrate(), with the compiled step or with SciPy's (same Jacobian)."""
    if not compiled:
        monkeypatch.setattr(implicit, "applicable", lambda *a: False)
    try:
        kw = {"method": "Radau", "rtol": 1e-6, "atol": 1e-9, **settings}
        return integrate(mech.system, mech.q0, mech.qd0, t_end, np.linspace(0.0, t_end, 41),
                         SolverSettings(**kw))
    finally:
        monkeypatch.undo()


@pytest.mark.parametrize("case", ["flexible", "film"])
def test_compiled_radau_takes_scipys_steps_and_trajectory(case, monkeypatch):
    mech = _train(flexible=case == "flexible", film=case == "film")
    assert implicit.applicable(mech.system, "Radau")
    t_end = 0.004 if case == "flexible" else 0.01
    ours = _run(mech, t_end, True, monkeypatch)
    scipy = _run(mech, t_end, False, monkeypatch)
    assert ours.nfev == scipy.nfev > 200
    n = mech.system.n
    for blk in (slice(0, n), slice(n, 2 * n), slice(2 * n, None)):
        peak = np.max(np.abs(scipy.y[blk]))
        assert np.max(np.abs(ours.y[blk] - scipy.y[blk])) <= 1e-9 * peak
    if case == "film":  # the journal floated: no dry contact
        assert not ours.onsets[0]


def test_compiled_radau_only_where_the_whole_right_hand_side_is_compiled():
    from test_dynamics_speed import _flexible_train

    mech = _train()
    assert implicit.applicable(mech.system, "Radau")
    assert not implicit.applicable(mech.system, "LSODA")
    assert not implicit.applicable(_flexible_train(clearance=False).system, "Radau")  # gas fn
    opts = implicit.solver_options(mech.system, "BDF", np.zeros(0), np.ones(2 * mech.system.n
                                                                             + 6), 1e-6)
    assert set(opts) == {"jac"}


def test_compiled_radau_stops_at_the_evaluation_budget():
    """The evaluations inside the compiled steps count against solver.max_rhs_evals."""
    mech = _train()
    with pytest.raises(NumericalError, match="after 300 right-hand-side evaluations"):
        integrate(mech.system, mech.q0, mech.qd0, 0.01, None,
                  SolverSettings(method="Radau", rtol=1e-6, atol=1e-9, max_rhs_evals=300))
