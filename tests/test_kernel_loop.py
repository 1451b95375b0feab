"""The compiled integrator loop (kernel/integrator.py) against independent oracles.

The loop is SciPy's RK45 (Dormand-Prince 5(4), its step control and dense output) with the
contact events located inside Numba. Its oracles: ``solve_ivp`` itself on a smooth run (the same
algorithm: round-off only), closed forms of a free journal crossing its clearance (onset time
and impact velocity), the phase-plane integral of a Hunt-Crossley-type impact (the rebound of a
memory law, whose impact velocity the loop must set at each onset), the ensemble spread of the
``solve_ivp`` path on an impacting run (chaotic: one trajectory is not a result), and the run
budget's messages.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from crankmodal.dynamics import Cylinder, SolverSettings, crank_train
from crankmodal.dynamics.kernel import integrator
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.joints import SpeedProfile
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.run.budget import GUARD_FACTOR, Overrun, ProjectionGuard
from crankmodal.dynamics.run.integrate import integrate
from crankmodal.errors import NumericalError

RPM = 3000.0
CLEARANCE = 1e-4


def _slider_crank(clearance=None, law="impact", params=None, ramp_time=0.0):
    cyl = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                   rod_com=0.042, piston_mass=0.75)
    kw = {}
    if clearance:
        kw = {"clearances": {"big_end_1": {"clearance": clearance, "journal_radius": 0.02}},
              "contact_kw": {"law": law, "law_params": params}}
    return crank_train(0.035, [cyl], RPM, crank_mass=2.0, crank_inertia=0.01,
                       ramp_time=ramp_time, **kw)


IMPACT = {"stiffness": 1e10, "exponent": 1.5, "damping": 300.0, "penetration": 1e-4}


def _free_journal(law, params, mass=2.0):
    """A journal (no gravity, no friction) at the centre of a fixed bore of clearance 0.1 mm."""
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", mass, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=CLEARANCE,
                           journal_radius=0.01, law=law, law_params=params)
    return Multibody([journal], [], [joint])


def test_loop_runs_rk45_on_compiled_systems_only():
    m = _slider_crank(CLEARANCE, "impact", IMPACT)
    assert integrator.applicable(m.system, "RK45")
    assert not integrator.applicable(m.system, "LSODA")
    gas = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                   rod_com=0.042, piston_mass=0.75, gas_force=lambda a: 2000.0 + 0.0 * a)
    py_gas = crank_train(0.035, [gas], RPM, crank_mass=2.0, crank_inertia=0.01)
    assert not integrator.applicable(py_gas.system, "RK45")  # a Python gas force: solve_ivp


def test_speed_profile_is_the_adams_step_ramp():
    # closed form of omega(t) = w0 + dw STEP(t/T): s = t/T, speed w0 + dw s^2 (3 - 2 s),
    # angle its integral theta0 + w0 t + dw T (s^3 - s^4 / 2), acceleration 6 dw s (1 - s) / T
    w0, w, T, th0 = 10.0, 155.0, 0.1, 0.3
    prof = SpeedProfile(w, th0, T, w0)
    for t in (0.0, 0.025, 0.05, 0.0999, 0.1, 0.25):
        s = min(t / T, 1.0)
        speed = w0 + (w - w0) * s * s * (3 - 2 * s)
        angle = (th0 + w0 * t + (w - w0) * T * (s**3 - s**4 / 2) if t < T
                 else th0 + w0 * t + (w - w0) * (T / 2 + t - T))
        acc = 6 * (w - w0) * s * (1 - s) / T if 0 < t < T else 0.0
        assert prof.speed(t) == pytest.approx(speed, rel=1e-14)
        assert prof.angle(t) == pytest.approx(angle, rel=1e-14)
        assert prof.acceleration(t) == pytest.approx(acc, rel=1e-12, abs=1e-9)


def test_smooth_slider_crank_equals_solve_ivp_rk45_to_round_off():
    # Oracle: solve_ivp's RK45 on the same right-hand side and tolerances. The loop runs the
    # same algorithm; its sums (stages, error norm) are ordered differently, which moves the
    # step sizes by ~1e-9 relative through the error estimate's cancellation (step times
    # seen 3.5e-13 s apart), and the dense outputs at fixed times then agree to ~1e-15 of each
    # coordinate's peak (seen). 1e-9 of the peak leaves six orders for another CPU's compiler;
    # a wrong tableau entry, error norm or dense output moves them by 1e-6 or more.
    m = _slider_crank(ramp_time=0.01)
    s = SolverSettings(method="RK45", rtol=1e-8, atol=1e-11)
    t_out = np.linspace(0.0, 0.03, 301)
    loop = integrate(m.system, m.q0, m.qd0, 0.03, t_out, s)
    ref = integrate(m.system, m.q0, m.qd0, 0.03, t_out, s, compiled_loop=False)
    n = m.system.n
    assert loop.y.shape == ref.y.shape
    np.testing.assert_array_equal(loop.t, ref.t)
    for rows in (slice(0, n), slice(n, 2 * n)):  # positions, velocities
        peak = np.abs(ref.y[rows]).max(axis=1)
        floor = 1e-9 * peak.max()  # coordinates that stay at round-off (the crank's centre)
        err = np.abs(loop.y[rows] - ref.y[rows]).max(axis=1)
        assert np.all(err <= 1e-9 * peak + floor), (err, peak)
    assert abs(loop.nfev - ref.nfev) <= 0.01 * ref.nfev
    # own steps: as many, at the same times to round-off
    a = integrate(m.system, m.q0, m.qd0, 0.01, None, s)
    b = integrate(m.system, m.q0, m.qd0, 0.01, None, s, compiled_loop=False)
    assert a.n_steps == pytest.approx(b.n_steps, rel=0.01)
    if a.t.size == b.t.size:
        np.testing.assert_allclose(a.t, b.t, rtol=0, atol=1e-9 * 0.01)


def _hysteresis_restitution(a):
    """Exact rebound ratio of F = K d^n (1 + chi d'), a = chi v0: root of
    a (1 + e) = -ln((1 - a e) / (1 + a)) (the phase-plane energy integral, any K and n)."""
    return brentq(lambda e: a * (1.0 + e) + np.log((1.0 - a * e) / (1.0 + a)), 1e-12,
                  min(1.0, 1.0 / a - 1e-12) if a > 1 else 1.0)


def test_free_journal_onset_at_the_closed_form_time_and_speed():
    # Oracle: a journal flying from the bore's centre at v0 touches the wall at t = c / v0 with
    # penetration rate v0; the loop locates it on the step's dense output by Brent's method to
    # 4 ulp. The step that crosses the wall carries the contact force in its last stages, so
    # the velocity interpolant is off by that step's local error (seen 1.9e-8 of v0); the
    # position, under a force that starts as d^1.5, far less (the time: 2e-16)
    v0 = 0.8
    sysm = _free_journal("impact", IMPACT)
    out = integrate(sysm, np.zeros(3), np.array([v0, 0.0, 0.0]), 1e-3, None,
                    SolverSettings(method="RK45", rtol=1e-9, atol=1e-13))
    t_on, rate = out.onsets[0][0]
    assert t_on == pytest.approx(CLEARANCE / v0, rel=1e-12)
    assert rate == pytest.approx(v0, rel=1e-6)
    assert out.separations[0] and out.separations[0][0] > t_on
    t_peak, y_peak = out.peaks[0][0]
    assert t_on < t_peak < out.separations[0][0]
    assert abs(y_peak[3]) < 1e-9 * v0  # the deepest penetration: the journal at rest


@pytest.mark.parametrize("e", [0.5, 0.9])
def test_memory_law_restarts_with_the_impact_velocity(e):
    # Oracle: Lankarani-Nikravesh (1990), F = K d^n (1 + chi d'), chi = 3 (1 - e^2) / (4 v0),
    # v0 the impact velocity the loop sets at the onset (a restart); the rebound ratio is the
    # phase-plane integral's root, read as the speed of the second onset (free flight between)
    v0 = 1.0
    sysm = _free_journal("lankarani_nikravesh", {"stiffness": 1e10, "exponent": 1.5,
                                                 "restitution": e})
    out = integrate(sysm, np.zeros(3), np.array([v0, 0.0, 0.0]), 3e-3, None,
                    SolverSettings(method="RK45", rtol=1e-9, atol=1e-13))
    assert integrator.applicable(sysm, "RK45")
    onsets = out.onsets[0]
    assert len(onsets) >= 2
    assert onsets[0][0] == pytest.approx(CLEARANCE / v0, rel=1e-12)
    expected = _hysteresis_restitution(3.0 * (1.0 - e * e) / (4.0 * v0) * v0)
    assert onsets[1][1] / v0 == pytest.approx(expected, rel=2e-5)


def _ensemble(loop, members=4, t_end=0.06):
    """Per member: impacts per revolution and the mean impact velocity (m/s) at the big end,
    from starts perturbed at round-off (relative k 1e-12, as run/ensemble.py)."""
    out = []
    for k in range(members):
        m = _slider_crank(CLEARANCE, "impact", IMPACT)
        q0 = m.q0 * (1.0 + k * 1e-12)
        r = integrate(m.system, q0, m.qd0, t_end, np.linspace(0, t_end, 61),
                      SolverSettings(method="RK45"), compiled_loop=loop)
        v = np.array([o[1] for o in r.onsets[0]])
        out.append((len(v) / (t_end * RPM / 60.0), v.mean()))
    return np.array(out)


def test_clearance_run_within_the_ensemble_spread_of_solve_ivp():
    # Oracle: the solve_ivp path's ensemble (an impacting run is chaotic: the trajectories of
    # starts 1e-12 apart differ after a few impacts; their spread is the answer's resolution)
    loop, ref = _ensemble(True), _ensemble(False)
    for col in range(2):
        spread = max(ref[:, col].std(ddof=1), loop[:, col].std(ddof=1), 0.02 * ref[:, col].mean())
        assert abs(loop[:, col].mean() - ref[:, col].mean()) <= 3.0 * spread, (loop, ref)


def test_budget_refusal_gives_the_same_message_on_both_paths():
    m = _slider_crank(CLEARANCE, "impact", IMPACT)
    s = SolverSettings(method="RK45", max_rhs_evals=500)
    texts = []
    for loop in (True, False):
        with pytest.raises(NumericalError) as exc:
            integrate(m.system, m.q0, m.qd0, 0.05, None, s, compiled_loop=loop)
        texts.append(str(exc.value))
        assert "after 500 right-hand-side evaluations" in texts[-1]
        assert m.system.nfev == 501  # the evaluation that broke the budget was not spent
    # the same words; the time differs only by where the two paths' round-off put the steps
    assert texts[0].split(" s after")[1] == texts[1].split(" s after")[1]


def test_projection_guard_stops_the_loop_with_its_message():
    # a budget the run's evaluation rate cannot meet: 0.6 s of the slider-crank needs ~60 k
    # evaluations; with 20 k the guard stops it once 10 % of the run is done
    m = _slider_crank(CLEARANCE, "impact", IMPACT)
    s = SolverSettings(method="RK45", max_rhs_evals=20_000)
    with pytest.raises(NumericalError, match="at its present .* per simulated second"):
        integrate(m.system, m.q0, m.qd0, 0.6, np.linspace(0, 0.6, 7), s)
    assert m.system.nfev < 20_000


def test_projection_guard_rule_by_hand():
    # the one rule both paths ask: 1000 evaluations over the window [0.09, 0.1] s is a rate of
    # 1e5 / s; the 0.9 s left need 90 000, over GUARD_FACTOR x the 2 000 left of the budget
    g = ProjectionGuard(1.0, 5000)
    g.check(0.09, 2000)  # too early to judge (before 10 % of the run): starts a window
    g.check(0.095, 2500)  # within the window (1 % of the run): not judged
    with pytest.raises(Overrun) as exc:
        g.check(0.1, 3000)
    assert exc.value.rate == pytest.approx(1e5)
    assert exc.value.projected == pytest.approx(3000 + 1e5 * 0.9)
    assert 1e5 * 0.9 > GUARD_FACTOR * 2000
    ok = ProjectionGuard(1.0, 5000)
    ok.check(0.09, 2000)
    ok.check(0.1, 2010)  # 1e3 / s: 900 more fit in the 2 990 left


def _synthetic_flexible(name, k, frames, rng, mass, j0):
    """A FlexibleBody with random but admissible invariants (no FE): G symmetric positive
    definite, S antisymmetric, random interface maps (as tests/test_dynamics_speed.py)."""
    from crankmodal.dynamics.flexible.body import FlexibleBody

    X = rng.normal(size=(k, k)) * 0.1
    G = np.eye(k) * 0.8 + X @ X.T * 0.1
    S = rng.normal(size=(k, k)) * 0.05
    itf = {nm: (np.array([x, y, 0.0]), rng.normal(size=(6, k)) * 0.05)
           for nm, (x, y) in frames.items()}
    return FlexibleBody(name, mass, j0, (0.0, 0.0), np.sort(rng.uniform(300.0, 3000.0, k)), G,
                        rng.normal(size=k) * 0.01, S - S.T, itf, damping_ratio=0.03,
                        c=rng.normal(size=k) * 1e-3)


def _flexible_train(clearance=True, seed=3):
    rng = np.random.default_rng(seed)
    cyls = [Cylinder(axis_angle=a, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                     rod_com=0.042, piston_mass=0.75, ring_friction=30.0) for a in (0.0, 1.2)]
    crank = _synthetic_flexible("crank", 5, {"main_a": (0.0, 0.0), "pin": (0.035, 0.0)}, rng,
                                2.0, 0.01)
    rods = [_synthetic_flexible(f"rod_{i}", 3, {"big": (-0.042, 0.0), "small": (0.098, 0.0)},
                                rng, 0.9, 3.1e-3) for i in (1, 2)]
    kw = {}
    if clearance:
        kw = {"clearances": {"big_end_1": {"clearance": CLEARANCE, "journal_radius": 0.02}},
              "contact_kw": {"law": "impact", "law_params": IMPACT}}
    return crank_train(0.035, cyls, RPM, crank_body=crank,
                       crank_roles={"mains": ["main_a"], "pins": ["pin", "pin"],
                                    "drive": "main_a"}, rod_bodies=rods, ramp_time=0.005, **kw)


def test_block_solve_of_flexible_bodies_equals_the_whole_kkt_solve_state_by_state():
    # Oracle: LAPACK's LU of the whole KKT system (compiled.evaluate, the Python-called
    # kernel's solve); the loop eliminates the block-diagonal mass matrix first. Two exact
    # solutions of one linear system: equal to round-off, 1e-12 of each block's largest entry
    # (seen 1.8e-14 on the flexible four-star); a wrong block, sign or row breaks it by O(1)
    mech = _flexible_train()
    sysm = mech.system
    assert integrator.blocks(sysm, sysm.kernel())[0].shape[0] == 3  # crank + two rods
    n = sysm.n
    rng = np.random.default_rng(5)
    y0 = np.concatenate([mech.q0, mech.qd0, np.zeros(6)])
    for _ in range(12):
        y = y0.copy()
        y[:n] += rng.normal(size=n) * 3e-5  # in and out of contact at the big end
        y[n:2 * n] += rng.normal(size=n) * 0.05
        t = rng.uniform(0.0, 0.01)
        a, b = integrator.rhs(sysm, t, y), integrator.rhs(sysm, t, y, use_blocks=False)
        np.testing.assert_allclose(b[:2 * n], sysm.kernel().rhs(t, y)[:2 * n], rtol=0,
                                   atol=1e-12 * np.abs(b[:2 * n]).max())
        for blk in (slice(n, 2 * n), slice(2 * n, None)):
            np.testing.assert_allclose(a[blk], b[blk], rtol=0, atol=1e-12 * np.abs(b[blk]).max())


def test_flexible_train_loop_equals_solve_ivp_to_round_off():
    # Oracle: solve_ivp's RK45 (with the whole KKT solve) on a smooth flexible run, as the
    # rigid slider-crank above: the dense outputs at fixed times within 1e-9 of each peak
    mech = _flexible_train(clearance=False)
    s = SolverSettings(method="RK45", rtol=1e-8, atol=1e-11)
    t_out = np.linspace(0.0, 0.01, 101)
    loop = integrate(mech.system, mech.q0, mech.qd0, 0.01, t_out, s)
    ref = integrate(mech.system, mech.q0, mech.qd0, 0.01, t_out, s, compiled_loop=False)
    n = mech.system.n
    for rows in (slice(0, n), slice(n, 2 * n)):
        peak = np.abs(ref.y[rows]).max(axis=1)
        err = np.abs(loop.y[rows] - ref.y[rows]).max(axis=1)
        assert np.all(err <= 1e-9 * peak + 1e-9 * peak.max()), (err, peak)


def test_output_times_outside_the_run_give_the_start_only():
    # no output time inside (0, t_end]: the start alone, as solve_ivp's path (the loop once
    # took the steps as output then and filled its buffer for ever)
    m = _slider_crank()
    s = SolverSettings(method="RK45")
    for loop in (True, False):
        r = integrate(m.system, m.q0, m.qd0, 0.002, np.array([0.0, 0.01]), s, compiled_loop=loop)
        np.testing.assert_array_equal(r.t, [0.0])
        assert r.y.shape == (2 * m.system.n + 6, 1)


def test_an_absurd_contact_stiffness_stops_both_paths_with_the_budget_message():
    # a journal started inside the wall of a 1e300 N/m^1.5 contact: the initial step is 0 and
    # the step control works on inf/nan (NumPy's arithmetic, as SciPy: once a
    # ZeroDivisionError out of the compiled loop); both paths stop at the budget
    texts = []
    for loop in (True, False):
        sysm = _free_journal("hertz", {"stiffness": 1e300, "exponent": 1.5})
        with pytest.raises(NumericalError) as exc:
            integrate(sysm, np.array([2e-4, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), 1e-3, None,
                      SolverSettings(method="RK45", max_rhs_evals=3000), compiled_loop=loop)
        texts.append(str(exc.value))
    assert all("after 3000 right-hand-side evaluations" in t for t in texts), texts


def test_output_times_out_of_order_are_refused_naming_t_out():
    from crankmodal.errors import ParameterError

    m = _slider_crank()
    for loop in (True, False):  # solve_ivp raised a bare ValueError; the loop sampled wrongly
        with pytest.raises(ParameterError, match="t_out"):
            integrate(m.system, m.q0, m.qd0, 0.002, np.array([0.0, 0.002, 0.001]),
                      SolverSettings(method="RK45"), compiled_loop=loop)


@pytest.mark.slow
def test_four_star_scene_per_revolution_statistics_within_the_ensemble_spread(monkeypatch):
    # the seed-000 four-star (scenes/four_star_dynamics.toml, 0.1 mm at big end 1, 1480 rpm),
    # 0.4 s, three starts 1e-12 apart on each path: the per-revolution main-bearing peak and
    # the impacts per revolution after the 0.1 s ramp + 1 revolution agree within three
    # times the larger ensemble spread (chaotic: the paths' trajectories part after a few
    # impacts, as two starts 1e-12 apart do)
    from functools import partial
    from pathlib import Path

    from crankmodal.dynamics.results.stats import statistics
    from crankmodal.dynamics.run import simulate as sim_mod
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.runner import check
    from crankmodal.scene import load_scene

    scene = Path(__file__).resolve().parent.parent / "scenes" / "four_star_dynamics.toml"
    params = check(load_scene(scene, ["dynamics.end_time=0.4"]))
    p = params["dynamics"]
    rows = {}
    for loop in (True, False):
        monkeypatch.setattr(sim_mod, "integrate", partial(integrate, compiled_loop=loop))
        for k in range(3):
            mech = build_mechanism(p, params["mechanism"])
            mech.q0 = mech.q0 * (1.0 + k * 1e-12)
            rev = mech.revolution_hz
            h = sim_mod.simulate(mech, 0.4, 1.0 / (360 * rev), solver_settings(p, 60 * rev))
            st = statistics(h, rev, p["ramp_time"] + 1.0 / rev)
            impacts = st["clearance_joints"]["big_end_1"]["impact_velocity"]["count_per_rev"]
            rows.setdefault(loop, []).append(
                (st["main_bearing_force"]["per_rev_peak"]["mean"], impacts["mean"]))
    a, b = np.array(rows[True]), np.array(rows[False])
    for col in range(2):
        spread = max(a[:, col].std(ddof=1), b[:, col].std(ddof=1), 0.02 * b[:, col].mean())
        assert abs(a[:, col].mean() - b[:, col].mean()) <= 3.0 * spread, (a, b)
