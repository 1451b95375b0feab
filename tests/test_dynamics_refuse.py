"""Refuse what cannot finish (issue 27, item 4): a run's cost estimated before it starts.

Oracles: the evaluations scipy's RK45 really takes on the same model (counted, short runs) for
the estimate, within the factor 3 the refusal allows (:data:`budget.REFUSE_FACTOR`); the
stability step ``2 / omega`` of a linear oscillator, ``2 m / c`` of a dashpot (closed form) for
its arithmetic; a constant-rate run (exact count ``t_end / h``) for the guard's projection.
"""

import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import SCENES, run_cli

from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.run import budget
from crankmodal.dynamics.run.integrate import SolverSettings
from crankmodal.errors import ParameterError


def _scene_mech(scene, *overrides, end_time=None):
    """Mechanism, solver settings, end time and output step of a rigid-body scene."""
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.runner import check
    from crankmodal.scene import load_scene

    params = check(load_scene(SCENES / scene, list(overrides)))
    p = params["dynamics"]
    mech = build_mechanism(p, params.get("mechanism"))
    settings = solver_settings(p, 60.0 * mech.revolution_hz)
    dt = p["output_step"] or 1.0 / (360.0 * mech.revolution_hz)
    return mech, settings, end_time or p["end_time"], dt


# ---------------------------------------------------------------- the two cases
def test_four_star_damping_1e9_is_refused_before_the_run_naming_contact_damping(tmp_path):
    # issue 27: ran 161 s to exit 3; the estimate (IMPACT's dashpot at the static penetration
    # of the inertia load) needs ~8e7 evaluations, 40 times the budget of 2e6
    r = run_cli("run", SCENES / "four_star_dynamics.toml", "--out", tmp_path, "--no-figures",
                "--quiet", "--set", "dynamics.contact.damping=1e9")
    assert r.returncode == 2, r.stderr
    errors = [line for line in r.stderr.splitlines() if "error" in line]
    assert len(errors) == 1 and "Traceback" not in r.stderr
    line = errors[0]
    assert line.startswith("crankmodal: error: dynamics.contact.damping: contact.damping = 1e+09")
    assert "solver.max_rhs_evals = 2000000" in line and "contact.damping must be <=" in line
    assert not (tmp_path / "results.json").exists()


def test_python_api_simulate_refuses_damping_1e9_before_integrating(monkeypatch):
    from crankmodal.dynamics.run import simulate as analysis

    mech, settings, t_end, dt = _scene_mech("four_star_dynamics.toml",
                                            "dynamics.contact.damping=1e9")

    def no_integration(*a, **k):
        raise AssertionError("integrated a run that was to be refused")

    monkeypatch.setattr(analysis, "integrate", no_integration)
    with pytest.raises(ParameterError) as exc:
        analysis.simulate(mech, t_end, dt, settings)
    assert exc.value.argument == "law.damping"  # the core's name; a scene's: contact.damping
    assert "law.damping = 1e+09" in exc.value.text and "2000000" in exc.value.text
    # the estimate: IMPACT's dashpot at the static penetration of the inertia load m w^2 r
    (ts,) = [s for s in budget._contact_scales(mech) if s.key == "law.damping"]
    law, m = ts.scale.law, ts.scale.mass
    load = m * (2 * np.pi * mech.revolution_hz) ** 2 * 0.035  # r = 35 mm
    d = (load / law.stiffness) ** (1 / 1.5)
    x = d / law.penetration
    c = law.damping * x * x * (3 - 2 * x)  # STEP(d, 0, 0, d_max, c_max), a cubic
    assert ts.step == pytest.approx(2 * m / c, rel=1e-9)


@pytest.mark.slow
def test_four_star_stiffness_1e12_is_not_foreseen_by_its_time_scales_but_stopped_early(tmp_path):
    """The contact period of K = 1e12 limits RK45 to 4e-5 s steps: ~1e5 evaluations, within
    the budget; the run jams after ~0.07 s (dry whip under ~0.5 MN, friction at stiction:
    steps of 5e-9 s). The guard stops it once its rate shows it cannot finish, naming the
    stiffness. A smaller budget and end time keep the test short: the same jam."""
    mech, settings, _, _ = _scene_mech("four_star_dynamics.toml",
                                       "dynamics.contact.stiffness=1e12")
    est, texts = budget.check(mech, 0.5, settings)
    assert est.evaluations < 0.2 * settings.max_rhs_evals and texts == []
    r = run_cli("run", SCENES / "four_star_dynamics.toml", "--out", tmp_path, "--no-figures",
                "--quiet", "--set", "dynamics.contact.stiffness=1e12",
                "--set", "dynamics.end_time=0.15", "--set", "dynamics.solver.max_rhs_evals=200000")
    assert r.returncode == 3, r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert "per simulated second" in line and "lower contact.stiffness" in line
    assert "solver.max_rhs_evals = 200000" in line and "changed regime" in line
    assert not (tmp_path / "results.json").exists()


@pytest.mark.slow
def test_four_star_stiffness_1e12_as_the_tester_ran_it_stops_before_its_budget(tmp_path):
    r = run_cli("run", SCENES / "four_star_dynamics.toml", "--out", tmp_path, "--no-figures",
                "--quiet", "--set", "dynamics.contact.stiffness=1e12")
    assert r.returncode == 3, r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert "per simulated second" in line and "lower contact.stiffness" in line
    assert not (tmp_path / "results.json").exists()


# ---------------------------------------------------------------- the estimate
def _journal(mass=2.0, stiffness=1e8, damping=10.0):
    bearing = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", mass, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", bearing, "bore", clearance=1e-4,
                           journal_radius=0.01, law="kelvin_voigt",
                           law_params={"stiffness": stiffness, "damping": damping})
    sysm = Multibody([journal], [], [joint])
    return SimpleNamespace(system=sysm, q0=np.zeros(3), qd0=np.zeros(3), revolution_hz=0.0,
                           crank=journal)


@pytest.mark.parametrize("damping, step", [(10.0, 2 * np.sqrt(2.0 / 1e8)), (1e7, 4e-7)])
def test_estimate_is_the_stability_step_of_the_oscillator_or_the_dashpot(damping, step):
    # K = 1e8 N/m, m = 2 kg: h = 2 / omega = 2 sqrt(m / K); c = 1e7 N s/m: h = 2 m / c
    mech = _journal(damping=damping)
    s = SolverSettings(method="RK45", max_step=1e-3)
    est = budget.estimate(mech, 0.01, s)
    assert est.evaluations == pytest.approx(6 * 0.01 / 1e-3 + 6 * 0.01 / step, rel=1e-9)
    assert est.stiff.key == ("law.damping" if damping > 1e3 else "law.stiffness")
    assert est.wall_time == pytest.approx(est.evaluations * est.cost_per_eval, rel=1e-12)
    assert budget.estimate(mech, 0.01, SolverSettings(method="Radau")).evaluations is None


def test_over_three_times_the_budget_is_refused_and_over_a_fifth_is_warned():
    mech = _journal(damping=1e7)  # 6 * 0.01 / 4e-7 = 1.5e5 evaluations (+ 60 smooth)
    with pytest.raises(ParameterError) as exc:
        budget.check(mech, 0.01, SolverSettings(method="RK45", max_step=1e-3,
                                                max_rhs_evals=40_000))
    assert exc.value.argument == "law.damping" and "must be <=" in exc.value.text
    # 'must be <= c' gives a step that fits the budget: 2 m / c >= 6 t / (budget - smooth)
    c_max = float(exc.value.text.split("must be <= ")[1].split(" ")[0])
    assert 2 * 2.0 / c_max == pytest.approx(6 * 0.01 / (40_000 - 60), rel=1e-2)
    mech = _journal(damping=1e7)
    _, texts = budget.check(mech, 0.01, SolverSettings(method="RK45", max_step=1e-3,
                                                       max_rhs_evals=200_000))
    assert len(texts) == 1 and "estimated wall time" in texts[0]
    assert budget.check(mech, 0.01, SolverSettings(method="RK45", max_step=1e-3,
                                                   max_rhs_evals=200_000))[1] == []  # once


def _measured_against_estimate(scene, t_end, *overrides):
    from crankmodal.dynamics.run.simulate import simulate

    mech, settings, _, dt = _scene_mech(scene, *overrides)
    est = budget.estimate(mech, t_end, settings)
    hist = simulate(mech, t_end, dt, settings, energy_tolerance=None)
    return hist.nfev / est.evaluations


def test_estimate_within_3x_of_the_evaluations_rk45_takes_on_the_slider_crank():
    # measured 11042 evaluations against 8157 estimated (ratio 1.35) over 0.02 s
    ratio = _measured_against_estimate("slider_crank_dynamics.toml", 0.02)
    assert 1 / 3 < ratio < 3


@pytest.mark.slow
@pytest.mark.parametrize("scene, t_end, overrides", [
    ("four_star_dynamics.toml", 0.2, ()),                                    # measured 1.42
    # K = 1e11: 1.89 on the trajectory measured first, but the rattle is chaotic: three starts
    # 1e-12 apart take 37-73 k evaluations on solve_ivp and 55-70 k on the compiled loop
    # (ratio 1.9-3.8), and the unperturbed start on the loop 199 k (10.4, the early stop ends
    # it at the default budget). The estimate does not bound a stiff rattle's regimes: open.
    pytest.param("four_star_dynamics.toml", 0.2, ("dynamics.contact.stiffness=1e11",),
                 marks=pytest.mark.xfail(reason="the estimate underestimates the stiff rattle's "
                                                "evaluations 1.9-10x by regime", strict=False)),
    ("four_star_dynamics.toml", 0.2, ("dynamics.contact.damping=1e6",)),     # 0.73
    ("slider_crank_dynamics.toml", 0.02, ("dynamics.contact.damping=1e6",)),  # 0.45
])
def test_estimate_within_3x_of_the_evaluations_rk45_takes(scene, t_end, overrides):
    ratio = _measured_against_estimate(scene, t_end, *overrides)
    assert 1 / 3 < ratio < 3


@pytest.mark.parametrize("scene", ["four_star_dynamics.toml", "slider_crank_dynamics.toml",
                                   "loom_four_bar_dynamics.toml"])
def test_default_scenes_are_neither_refused_nor_warned(scene):
    mech, settings, t_end, _ = _scene_mech(scene)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        est, texts = budget.check(mech, t_end, settings)
    assert texts == []
    if est.evaluations is not None:
        assert est.evaluations < budget.WARN_FRACTION * settings.max_rhs_evals


# ---------------------------------------------------------------- the guard
def test_an_early_stop_says_when_the_steps_fell_far_below_the_contact_time_scales():
    from crankmodal.dynamics.laws.objects import KelvinVoigt
    from crankmodal.dynamics.run.timescales import TimeScale

    # K = 1e8 N/m on 2 kg: the contact period allows steps of 2 sqrt(m / K) = 2.8e-4 s
    ts = TimeScale("c", 2.0, 100.0, 1e8, 2 * np.pi * np.sqrt(2e-8), None, None,
                   KelvinVoigt(1e8, 0.0))
    note = budget.regime_note(2 * np.sqrt(2e-8) / 100, (ts,))
    assert "100 times shorter" in note and "changed regime" in note
    assert budget.regime_note(1e-4, (ts,)) == "" and budget.regime_note(1e-9, ()) == ""



def _drive(fun, t_end, h):
    t = 0.0
    while t < t_end:
        t = min(t + h, t_end)
        fun(t, None)


def test_guard_projects_a_constant_rate_to_its_exact_count_and_stops_it():
    # steps of 1e-5 s over 1 s need 1e5 evaluations; budget 20000: judged from 0.1 s (10 % of
    # the run, 10001 evaluations, past 2 % of the budget and 1000), and stopped there
    fun = budget.projection_guard(lambda t, y: None, 1.0, 20_000)
    with pytest.raises(budget.Overrun) as exc:
        _drive(fun, 1.0, 1e-5)
    assert exc.value.projected == pytest.approx(1e5, rel=1e-4)  # float sums of h: 1e-4 is
    assert exc.value.t == pytest.approx(0.1, abs=2e-4)           # far above their rounding


def test_guard_leaves_a_small_budget_to_the_budget_itself():
    # 1000 evaluations at most: the guard never judges, the budget stops the run
    fun = budget.projection_guard(lambda t, y: None, 1.0, 1000)
    _drive(fun, 0.1, 1e-4)


def test_guard_lets_a_burst_shorter_than_its_window_pass():
    # 0.1 ms steps over 1 s (1e4 evaluations) with 500 more in 1 ms at 0.5 s, budget 4e4:
    # the window holding the burst runs at 6e4 per s, 2.94e4 for the 0.49 s left, within
    # 1.5 x the 3.45e4 left; on a budget of 2e4 (1.5 x 1.45e4 = 2.2e4 < 2.94e4) it stops
    for limit, stops in ((40_000, False), (20_000, True)):
        fun = budget.projection_guard(lambda t, y: None, 1.0, limit)
        try:
            _drive(fun, 0.5, 1e-4)
            for k in range(500):
                fun(0.5 + (k + 1) * 2e-6, None)
            for k in range(5000):
                fun(0.501 + k * 1e-4, None)
        except budget.Overrun:
            assert stops
        else:
            assert not stops


def test_a_kept_mode_bounds_the_estimate_at_two_over_omega_and_names_its_table():
    # a 20 kHz mode of 'rod_1': RK45 steps of 2 / (2 pi 20e3) = 1.59e-5 s over 0.1 s
    body = SimpleNamespace(name="rod_1", n_elastic=2, frequencies_hz=np.array([5e3, 2e4, 0.0]))
    mech = SimpleNamespace(system=SimpleNamespace(bodies=[body], clearances=[],
                                                  kernel=lambda: None))
    s = SolverSettings(method="RK45", max_step=1e-3, max_rhs_evals=10_000)
    est = budget.estimate(mech, 0.1, s)
    assert est.evaluations == pytest.approx(6 * 0.1 / 1e-3 + 6 * 0.1 * 2 * np.pi * 2e4 / 2,
                                            rel=1e-12)
    with pytest.raises(ParameterError) as exc:  # 3.8e4 estimated, over 3 x 1e4
        budget.check(mech, 0.1, s)
    assert exc.value.argument == "flexible.rods" and "flexible.rods.n_modes" in exc.value.text
