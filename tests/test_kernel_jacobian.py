"""The compiled Jacobian of the right-hand side (crankmodal.dynamics.kernel.jacobian) for the
implicit integrators.

Oracles: a central-difference Jacobian of the generic Python path (``compiled=False``: the joints'
and bodies' own methods, not the kernel) at random states, and whole runs with SciPy's own
finite-difference Jacobian (the same Radau/LSODA, only the Jacobian differs)."""

import numpy as np
import pytest
from test_dynamics_speed import _flexible_train, _slider_crank, _states

from crankmodal.dynamics.kernel.jacobian import STEP_FLOOR, CompiledJacobian, jacobian_for
from crankmodal.dynamics.model.system import N_AUX
from crankmodal.dynamics.run.integrate import SolverSettings, integrate

SETTINGS = SolverSettings(method="Radau", rtol=1e-6, atol=1e-9)


def _atol(n, s=SETTINGS):
    return np.concatenate([np.full(n, s.atol), np.full(n, s.atol * s.velocity_scale),
                           np.full(N_AUX, 1e-3)])


def _python_jacobian(sysm, t, y, vimp, steps):
    """Central differences of the Python path's right-hand side, steps ``100 x`` the compiled
    Jacobian's forward ones (truncation ~h^2 f''' of the columns' scale times 1e-12, round-off
    ~eps |f| / h)."""
    n = sysm.n
    sysm.compiled = False
    try:
        J = np.zeros((y.size, y.size))
        for c in range(2 * n):
            h = 100.0 * steps[c]
            yp, ym = y.copy(), y.copy()
            yp[c] += h
            ym[c] -= h
            J[:, c] = (sysm.rhs(t, yp, vimp) - sysm.rhs(t, ym, vimp)) / (2.0 * h)
    finally:
        sysm.compiled = True
    return J


def _compare(mech, seed, count, rel):
    """Compiled Jacobian against the Python path's central differences at ``count`` random
    states: each column within ``rel`` of its largest entry. Returns the largest error seen."""
    sysm = mech.system
    n = sysm.n
    worst = 0.0
    for t, q, qd, y, v_impact in _states(mech, seed, count):
        vimp = np.array([v_impact] * len(sysm.clearances))
        jac = CompiledJacobian(sysm.kernel(), vimp, _atol(n), SETTINGS.rtol)
        J = jac(t, y)
        steps = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(y[:2 * n]), jac.floor)
        ref = _python_jacobian(sysm, t, y, vimp, steps)
        scale = np.max(np.abs(ref), axis=0) + 1e-300
        err = np.max(np.abs(J - ref), axis=0) / scale
        worst = max(worst, float(np.max(err[:2 * n])))
        # the exact blocks: d(qd)/d(qd) = I, nothing depends on the work integrals
        np.testing.assert_array_equal(J[:n, n:2 * n], np.eye(n))
        np.testing.assert_array_equal(J[:n, :n], 0.0)
        np.testing.assert_array_equal(J[:, 2 * n:], 0.0)
    assert worst <= rel, worst
    return worst


# A forward difference with step h = sqrt(eps) max(|y|, STEP_FLOOR atol / rtol) (1.5e-9 m,
# 1.5e-9 rad, 1.5e-6 m/s here) is off by h |f''| / 2: about h / L of the column's scale, L the
# length over which the derivative itself changes. For the flexible bodies (L ~ 0.1 m or
# rad) that is ~1e-7, and round-off of the terms (eps |f| / h) ~1e-5 of the crank angle's
# column (seen: 2.8e-5); SMOOTH = 1e-4. A contact or an oil film changes its stiffness over a
# fraction of the clearance (the film as (1 - eps^2)^-5/2 over c (1 - eps) ~ 1e-5 m): h / L ~
# 1e-4 (seen: 1.6e-4, the same against central steps 1, 10 and 100 times h, so it is the
# forward difference's own error); CONTACT = 1e-3. Radau's and LSODA's Newton iterations need
# the Jacobian to a few per cent only. A wrong term shows as 1e-2 or more (checked: the
# perturbed system's residual taken with the unperturbed matrix, and a drive's speed sign).
SMOOTH, CONTACT = 1e-4, 1e-3


def test_flexible_train_jacobian_equals_central_differences_of_the_python_path():
    """Flexible crank (5 modes + 2 tilts) and two flexible rods (5 modes) on ideal joints, the
    pistons' gas force a Python function of the crank angle (per-column gas forces)."""
    mech = _flexible_train(clearance=False)
    assert mech.system.kernel() is not None and mech.system.kernel()._py_gas
    _compare(mech, 5, 6, SMOOTH)


@pytest.mark.parametrize("bore", ["round", "film"])
def test_clearance_jacobian_equals_central_differences_of_the_python_path(bore):
    """Rigid slider-crank pair with a big-end clearance: dry (in and out of contact at the
    random states) and floating on seed 001's short-bearing film (the reduced and the whole KKT
    system of the kernel)."""
    _compare(_slider_crank("hunt_crossley", "coulomb", bore=bore), 7, 6, CONTACT)


def test_the_step_floor_is_the_one_documented():
    assert STEP_FLOOR == 100.0


def test_jacobian_only_for_implicit_methods_on_the_kernel():
    mech = _flexible_train(clearance=False)
    sysm = mech.system
    atol = _atol(sysm.n)
    v = np.zeros(0)
    assert set(jacobian_for(sysm, "Radau", v, atol, 1e-6)) == {"jac"}
    assert jacobian_for(sysm, "RK45", v, atol, 1e-6) == {}
    sysm.compiled = False
    try:
        assert jacobian_for(sysm, "Radau", v, atol, 1e-6) == {}
    finally:
        sysm.compiled = True


@pytest.mark.slow
def test_radau_with_the_compiled_jacobian_follows_the_same_trajectory(monkeypatch):
    """The flexible train on ideal joints (smooth, no impacts), Radau at rtol 1e-6 with the
    compiled Jacobian and with SciPy's own finite differences, against the same run at rtol
    1e-10 (the converged trajectory). The Jacobian only steers Newton's iterations, so both runs
    carry Radau's error at rtol 1e-6: measured 2-3e-7 of the positions' peak and 3-4e-6 of the
    velocities' (the flexible modes' velocities, 1e-6 of a mode's amplitude times its 2 pi f)
    against the reference, 5e-8 and 8e-7 between the two. Each must stay within 10 rtol of the
    reference (positions) or 20 rtol (velocities) and of each other."""
    from crankmodal.dynamics.kernel import jacobian as jm

    mech = _flexible_train(clearance=False)
    sysm, n = mech.system, mech.system.n
    t_out = np.linspace(0.0, 0.005, 51)

    def run(rtol, compiled):
        if not compiled:
            monkeypatch.setattr(jm, "jacobian_for", lambda *a, **k: {})
        try:
            return integrate(sysm, mech.q0, mech.qd0, 0.005, t_out,
                             SolverSettings(method="Radau", rtol=rtol, atol=rtol * 1e-3)).y
        finally:
            monkeypatch.undo()

    ref = run(1e-10, True)
    with_jac, without = run(1e-6, True), run(1e-6, False)
    for blk, bound in ((slice(0, n), 1e-5), (slice(n, 2 * n), 2e-5)):
        peak = np.max(np.abs(ref[blk]))
        for a, b in ((with_jac, ref), (without, ref), (with_jac, without)):
            assert np.max(np.abs(a[blk] - b[blk])) <= bound * peak


def test_lsoda_on_a_film_with_the_compiled_jacobian_follows_the_same_trajectory(monkeypatch):
    """Seed 001's short-bearing film carrying the big end of a rigid two-cylinder train (no
    dry contact: smooth), LSODA at rtol 1e-6 with the compiled Jacobian and with SciPy's own
    finite differences, against LSODA at rtol 1e-10 (the converged trajectory). LSODA's Jacobian
    steers its Newton iterations and its switch to BDF, not the solution: both runs carry
    LSODA's error at rtol 1e-6: measured 1.5e-7 (positions) and 5.1e-7 (velocities) of the
    peaks against the reference, 8e-10 and 2e-9 between the two; 5e-6 (5 rtol) for all."""
    from test_kernel_implicit import _train

    from crankmodal.dynamics.kernel import jacobian as jm

    mech = _train(flexible=False, film=True)
    sysm, n = mech.system, mech.system.n
    t_out = np.linspace(0.0, 0.01, 41)

    def run(rtol, compiled):
        if not compiled:
            monkeypatch.setattr(jm, "jacobian_for", lambda *a, **k: {})
        try:
            out = integrate(sysm, mech.q0, mech.qd0, 0.01, t_out,
                            SolverSettings(method="LSODA", rtol=rtol, atol=rtol * 1e-4))
        finally:
            monkeypatch.undo()
        assert not out.onsets[0]  # floating on the film
        return out

    ref = run(1e-10, True).y
    with_jac, without = run(1e-6, True), run(1e-6, False)
    assert with_jac.nfev < without.nfev
    for blk in (slice(0, n), slice(n, 2 * n)):
        peak = np.max(np.abs(ref[blk]))
        errs = [np.max(np.abs(a[blk] - b[blk])) / peak
                for a, b in ((with_jac.y, ref), (without.y, ref), (with_jac.y, without.y))]
        assert max(errs) <= 5e-6


@pytest.mark.slow
def test_loom_film_statistics_within_the_ensemble_spread_of_the_former_jacobian(monkeypatch):
    """Seed 001's loom, 1 s (7.5 revolutions at 450 rpm), its lubricated coupler pin with dry
    Lankarani-Nikravesh impacts (LSODA, restarted at every contact event): an impacting run,
    so its numbers are statistics. The run with the compiled Jacobian and two round-off
    perturbed ones (an ensemble of three, as [dynamics] ensemble = 3 runs it) against the run
    with SciPy's own finite-difference Jacobian (the former path): each headline per-revolution
    statistic of the former within three times the ensemble's spread (its standard deviation,
    or the revolutions' standard error where larger) of the ensemble's mean."""
    from pathlib import Path

    from crankmodal.dynamics.kernel import jacobian as jm
    from crankmodal.dynamics.results.stats import statistics
    from crankmodal.dynamics.run.ensemble import headline, run_ensemble
    from crankmodal.dynamics.run.simulate import simulate
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.runner import check
    from crankmodal.scene import load_scene

    scene = Path(__file__).resolve().parent.parent / "scenes" / "loom_four_bar_dynamics.toml"
    p = check(load_scene(scene, ["dynamics.end_time=1.0"]))["dynamics"]
    settings = solver_settings(p, 450.0)
    assert settings.method == "LSODA"
    mech = build_mechanism(p)
    rev_hz = mech.revolution_hz
    dt, t_start = 1.0 / (360.0 * rev_hz), 1.0 / rev_hz  # the first revolution: start-up

    def stats(m):
        return statistics(simulate(m, 1.0, dt, settings), rev_hz, t_start)

    base = stats(mech)
    ens = run_ensemble(mech, base, 3, 1.0, dt, settings, rev_hz, t_start, {})
    monkeypatch.setattr(jm, "jacobian_for", lambda *a, **k: {})
    former = headline(stats(build_mechanism(p)))
    monkeypatch.undo()
    assert ens["spread"]
    for key, s in ens["spread"].items():
        sem = np.sqrt(np.mean([r[key] ** 2 for r in ens["per_trajectory_sem"] if key in r]))
        assert abs(former[key] - s["mean"]) <= 3.0 * max(s["std"], sem), key


def test_difference_step_floor_stays_at_the_film_scale_at_tight_tolerances():
    # the floor atol/rtol grew with a tight rtol: at rtol 1e-9 a 1.5 um step on a 50 um film;
    # capped at the default rtol's scale it stays 1.5 nm (positions, atol 1e-9 m)
    from crankmodal.dynamics.kernel import jacobian as jm

    class K:  # what CompiledJacobian reads of the kernel at construction
        n, gas_py = 2, np.zeros(0)

    atol = np.array([1e-9, 1e-9, 1e-6, 1e-6])
    tight = jm.CompiledJacobian(K, np.zeros(0), atol, 1e-9).floor
    default = jm.CompiledJacobian(K, np.zeros(0), atol, 1e-6).floor
    np.testing.assert_array_equal(tight, default)
    assert jm._SQRT_EPS * tight[0] < 2e-9
