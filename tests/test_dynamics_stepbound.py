"""dynamics.stepbound: after a run, whether the stiffest kept mode set an explicit method's step.

Oracle: an explicit method on an undamped-ish mode is stable only while ω h stays inside its
stability interval on the imaginary axis (RK45 ≈ 3.3), and a step bound by the mode scales with
its period: halving every frequency halves the evaluations."""

import numpy as np
import pytest

from crankmodal.dynamics.flexible.body import FlexibleBody
from crankmodal.dynamics.flexible.stepbound import step_bound
from crankmodal.dynamics.model.bodies import Ground
from crankmodal.dynamics.model.joints import Revolute
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.run.integrate import SolverSettings, integrate


def _pendulum(scale):
    """A flexible link (3 modes to 20 kHz x scale) pinned to the ground, swinging in gravity."""
    rng = np.random.default_rng(5)
    k = 3
    f = np.array([2e3, 8e3, 20e3]) * scale
    itf = {"pin": (np.array([-0.1, 0.0, 0.0]), rng.normal(size=(6, k)) * 0.05),
           "tip": (np.array([0.1, 0.0, 0.0]), rng.normal(size=(6, k)) * 0.05)}
    link = FlexibleBody("link", 1.0, 3.3e-3, (0.0, 0.0), f, np.eye(k), np.zeros(k),
                        np.zeros((k, k)), itf, damping_ratio=0.001)
    ground = Ground(frames={"O": (0.0, 0.0)})
    sysm = Multibody([link], [Revolute("O", ground, "O", link, "pin")], gravity=(0.0, -9.81))
    q0 = np.zeros(link.ndof)
    q0[0] = 0.1
    return sysm, link, q0


def _run(scale, method):
    sysm, link, q0 = _pendulum(scale)
    q, qd = sysm.assemble(0.0, q0, np.zeros(link.ndof))
    integ = integrate(sysm, q, qd, 2e-3, None, SolverSettings(method=method, rtol=1e-6,
                                                               atol=1e-9))
    return step_bound([link], method, 2e-3, integ.nfev), integ.nfev


def test_an_explicit_step_is_bound_by_the_stiffest_mode_and_scales_with_its_period():
    b, nfev = _run(1.0, "RK45")
    assert b["body"] == "link" and b["frequency_hz"] == 20e3 and b["bound"]
    assert 0.5 <= b["omega_h"] <= 3.4  # inside RK45's stability interval, and near its edge
    assert "link" in b["advice"] and "n_modes" in b["advice"]
    b_half, nfev_half = _run(0.5, "RK45")
    assert b_half["omega_h"] == pytest.approx(b["omega_h"], rel=0.2)  # the same omega h
    assert 1.6 < nfev / nfev_half < 2.4  # half the frequencies, half the evaluations


def test_an_implicit_method_or_a_rigid_body_is_not_reported_bound():
    b, _ = _run(1.0, "Radau")
    assert b["method"] == "Radau" and not b["bound"] and "advice" not in b
    assert step_bound([], "RK45", 1.0, 100) is None
