"""Contact time scales before a run, the advice of a run that stops at its budget, progress.

Oracles: the effective mass of a journal in a fixed bore is the journal's mass and of two free
bodies their reduced mass; the contact period of a linear spring is ``2 pi sqrt(m / K)``. The
scene runs check that the key named is the one that limits the step (issue 18, item 5).
"""

import contextlib
import io
import warnings

import numpy as np
import pytest
from conftest import SCENES

from crankmodal import cli, progress
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.run import timescales
from crankmodal.dynamics.run.integrate import SolverSettings, _stiffness_advice, integrate


def _run(*argv):
    """``crankmodal ARGV`` in this process: (status, stderr (where the CLI prints its model
    warnings), the warnings that escaped it)."""
    err = io.StringIO()
    with warnings.catch_warnings(record=True) as caught, contextlib.redirect_stderr(err), \
            contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("always")
        status = cli.main([str(a) for a in argv])
    return status, err.getvalue(), [str(w.message) for w in caught]


def _journal(mass=2.0, law="kelvin_voigt", params=None, bearing_mass=None):
    if bearing_mass is None:
        bearing, frame, bodies = Ground(frames={"bore": (0.0, 0.0)}), "bore", []
    else:
        bearing = RigidBody("bearing", bearing_mass, 1e-3, {"bore": (0.0, 0.0)})
        frame, bodies = "bore", [bearing]
    journal = RigidBody("journal", mass, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", bearing, frame, clearance=1e-4,
                           journal_radius=0.01, law=law,
                           law_params=params or {"stiffness": 1e8, "damping": 10.0})
    return Multibody([journal] + bodies, [], [joint]), joint


def test_effective_mass_is_the_journal_in_a_fixed_bore_and_the_reduced_mass_of_two_bodies():
    sysm, cj = _journal(2.0)
    n = sysm.n
    assert timescales.effective_mass(sysm, cj, np.zeros(n), np.zeros(n)) == pytest.approx(2.0)
    sysm, cj = _journal(2.0, bearing_mass=3.0)
    n = sysm.n
    assert timescales.effective_mass(sysm, cj, np.zeros(n), np.zeros(n)) == pytest.approx(1.2)


def test_linear_contact_period_and_damping_time_and_the_key_they_name():
    # K = 1e8 N/m, m = 2 kg: T = 2 pi sqrt(m / K), step T / pi; c = 10 N s/m: m / c = 0.2 s,
    # the stiffness limits; c = 1e7 N s/m: m / c = 2e-7 s, step 4e-7 s, the damping limits
    from types import SimpleNamespace

    # the core names the law's parameter; a scene names contact.stiffness / contact.damping
    for c, key, step in ((10.0, "law.stiffness", 2 * np.sqrt(2.0 / 1e8)),
                         (1e7, "law.damping", 4e-7)):
        sysm, cj = _journal(2.0, params={"stiffness": 1e8, "damping": c})
        mech = SimpleNamespace(system=sysm, q0=np.zeros(3), qd0=np.zeros(3), revolution_hz=0.0,
                               crank=cj.journal)
        (ts,) = timescales.joint_time_scales(mech)
        assert ts.mass == pytest.approx(2.0) and ts.k_lin == 1e8
        assert ts.period == pytest.approx(2 * np.pi * np.sqrt(2.0 / 1e8))
        assert ts.damping_time == pytest.approx(2.0 / c)
        assert ts.key == key and ts.step == pytest.approx(step)
        assert timescales.estimated_evals(ts, 0.01, "RK45") == pytest.approx(6 * 0.01 / step)
        assert timescales.estimated_evals(ts, 0.01, "Radau") is None
    assert ts.law is cj.normal and ts.stiffness == 1e8 and ts.damping_set == c


def test_the_time_scales_ask_the_joint_law_object():
    """Hertz: K_lin = 1.5 K^(2/3) F^(1/3), no dashpot; the estimate follows the joint's law
    object (a law's own answers are tested in test_dynamics_laws)."""
    from types import SimpleNamespace

    sysm, cj = _journal(2.0, law="hertz", params={"stiffness": 1e10, "exponent": 1.5})
    mech = SimpleNamespace(system=sysm, q0=np.zeros(3), qd0=np.zeros(3), revolution_hz=0.0,
                           crank=cj.journal)
    (ts,) = timescales.joint_time_scales(mech)
    assert ts.load == 1.0  # no gas force, no speed: the floor of 1 N
    assert ts.k_lin == pytest.approx(1.5 * 1e10**(2 / 3) * 1.0**(1 / 3), rel=1e-12)
    assert ts.damping is None and ts.damping_set is None and ts.key == "law.stiffness"
    assert cj.normal.tangent_stiffness(1000.0) == pytest.approx(1.5 * 1e10**(2 / 3) * 10.0)


@pytest.mark.parametrize("method", ["RK45", "DOP853", "LSODA", "Radau", "BDF"])
def test_advice_never_names_the_method_in_use(method):
    # issue 18 #6: a run with LSODA was advised "use LSODA or Radau"
    sysm, _ = _journal(2.0)
    text = _stiffness_advice(sysm, SolverSettings(method=method))
    assert f"'{method}'" not in text and "settings.method = '" in text


def test_over_budget_advice_names_the_damping_when_it_limits_the_step():
    # a kelvin-voigt dashpot of 1e6 N s/m on 2 kg: m/c = 2e-6 s against T/pi = 2.8e-4 s
    sysm, _ = _journal(2.0, params={"stiffness": 1e8, "damping": 1e6})
    from crankmodal.dynamics.laws.objects import KelvinVoigt
    from crankmodal.dynamics.run.timescales import TimeScale
    ts = TimeScale("c", 2.0, 100.0, 1e8, 2 * np.pi * np.sqrt(2e-8), 1e6, 2e-6,
                   KelvinVoigt(1e8, 1e6))
    s = SolverSettings(method="RK45", max_rhs_evals=200, time_scales=(ts,))
    from crankmodal.errors import NumericalError
    with pytest.raises(NumericalError) as exc:
        integrate(sysm, np.zeros(3), np.array([0.5, 0.0, 0.0]), 0.01, None, s)
    assert "lower law.damping" in str(exc.value) and "law.damping = 1e+06" in str(exc.value)
    assert "'RK45'" not in str(exc.value)


def test_slider_crank_damping_1e9_is_refused_before_the_run_naming_contact_damping(tmp_path):
    # issue 18 #5: ran for minutes; with a budget it stopped at exit 3 naming the stiffness
    status, err, _ = _run("run", SCENES / "slider_crank_dynamics.toml", "--out", tmp_path,
                          "--no-figures", "--set", "dynamics.contact.damping=1e9",
                          "--set", "dynamics.end_time=0.005",
                          "--set", "dynamics.solver.max_rhs_evals=20000")
    assert status == 2, err
    line = err.strip().splitlines()[-1]
    assert "dynamics.contact.damping: contact.damping = 1e+09 N s/m" in line
    assert "must be <=" in line and "Traceback" not in err
    assert not (tmp_path / "results.json").exists()


def test_four_star_stiffness_1e12_is_refused_for_a_small_budget_naming_contact_stiffness(tmp_path):
    status, err, _ = _run("run", SCENES / "four_star_dynamics.toml", "--out", tmp_path,
                          "--no-figures", "--set", "dynamics.contact.stiffness=1e12",
                          "--set", "dynamics.end_time=0.02", "--set", "dynamics.ramp_time=0.01",
                          "--set", "dynamics.solver.max_rhs_evals=500")
    assert status == 2, err
    line = err.strip().splitlines()[-1]
    assert "dynamics.contact.stiffness: contact.stiffness = 1e+12" in line
    assert not (tmp_path / "results.json").exists()


def test_four_star_damping_1e7_on_a_small_budget_is_refused_naming_contact_damping(tmp_path):
    # IMPACT's damping ramps with the penetration: the estimate takes it at the static
    # penetration of the inertia load (5.1e5 N s/m: steps of 3.7e-6 s, 3.3e4 evaluations over
    # 0.02 s), 6.5 times the budget of 5000: refused before the run naming contact.damping
    # (issue 27 #4; it used to warn, run and stop at its budget)
    status, err, _ = _run("run", SCENES / "four_star_dynamics.toml", "--out", tmp_path,
                          "--no-figures", "--set", "dynamics.contact.damping=1e7",
                          "--set", "dynamics.end_time=0.02",
                          "--set", "dynamics.ramp_time=0.01",
                          "--set", "dynamics.solver.max_rhs_evals=5000")
    assert status == 2, err
    line = err.strip().splitlines()[-1]
    assert "dynamics.contact.damping: contact.damping = 1e+07" in line
    assert "contact.damping must be <=" in line and "contact.stiffness must" not in line
    assert not (tmp_path / "results.json").exists()


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_progress_shows_simulated_time_and_leaves_the_integration_unchanged(monkeypatch):
    sysm, _ = _journal(2.0, params={"stiffness": 1e8, "damping": 10.0})
    y0 = (np.zeros(3), np.array([0.5, 0.0, 0.0]))
    quiet = integrate(sysm, *y0, 0.02, None, SolverSettings())
    monkeypatch.delenv("CRANKMODAL_QUIET", raising=False)
    tty = _Tty()
    monkeypatch.setattr("sys.stderr", tty)
    progress.set_quiet(False)
    shown = integrate(sysm, *y0, 0.02, None, SolverSettings())
    assert "s simulated" in tty.getvalue() and "0.02" in tty.getvalue()
    assert shown.nfev == quiet.nfev
    np.testing.assert_array_equal(shown.y, quiet.y)
