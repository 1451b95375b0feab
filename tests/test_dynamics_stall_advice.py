"""The advice of a run that stops on its evaluation budget with ideal joints only: with a flexible
body it names the stiffest kept mode (the one that bounds an explicit step, see
test_dynamics_stepbound.py) and what to change; without one it says so as before."""

import numpy as np
import pytest
from test_dynamics_stepbound import _pendulum

from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.joints import Revolute
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.run.integrate import SolverSettings, integrate
from crankmodal.errors import NumericalError


def _stall(sysm, q0, method, budget):
    """The error text of a 2 ms run stopped after ``budget`` right-hand-side evaluations."""
    q, qd = sysm.assemble(0.0, q0, np.zeros(q0.size))
    with pytest.raises(NumericalError) as exc:
        integrate(sysm, q, qd, 2e-3, None, SolverSettings(method=method, rtol=1e-6, atol=1e-9,
                                                          max_rhs_evals=budget))
    return str(exc.value)


@pytest.mark.parametrize("method", ["RK45", "LSODA"])
def test_a_flexible_body_on_ideal_joints_names_its_stiffest_mode(method):
    sysm, link, q0 = _pendulum(1.0)  # modes 2, 8, 20 kHz: RK45 needs ~1100 evaluations
    assert max(link.frequencies_hz[:link.n_elastic]) == 20e3
    text = _stall(sysm, q0, method, 200)
    assert "after 200 right-hand-side evaluations" in text
    assert "tighten nothing" not in text
    assert "stiffest kept mode (2e+04 Hz of 'link') is the stiff part" in text
    assert "use settings.method = 'Radau'" in text and "n_modes / cutoff_hz" in text


def test_radau_is_told_to_raise_the_budget_or_drop_modes():
    sysm, _, q0 = _pendulum(1.0)
    text = _stall(sysm, q0, "Radau", 20)  # the finite-difference Jacobian alone takes more
    assert "(2e+04 Hz of 'link')" in text and "'Radau'" not in text
    assert "raise settings.max_rhs_evals or keep fewer modes of 'link'" in text


def test_a_rigid_pendulum_keeps_the_ideal_joints_advice():
    link = RigidBody("link", 1.0, 3.3e-3, {"pin": (-0.1, 0.0)})
    sysm = Multibody([link], [Revolute("O", Ground(frames={"O": (0.0, 0.0)}), "O", link, "pin")],
                     gravity=(0.0, -9.81))
    text = _stall(sysm, np.array([0.1, 0.0, 0.0]), "RK45", 4)  # it needs 8
    assert text.endswith("tighten nothing: ideal joints only; check the speed and masses")
