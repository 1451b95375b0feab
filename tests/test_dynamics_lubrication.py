"""Short-bearing (Ocvirk) film forces against direct integration of the Reynolds pressure."""

import numpy as np
import pytest

from crankmodal.dynamics.laws.lubrication import attitude_angle, short_bearing_force
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import AUX_NAMES, Multibody
from crankmodal.dynamics.run.integrate import SolverSettings, integrate

MU, R, L, C = 0.0175, 0.02, 0.042, 2.1e-5   # seed 001 Table 2


def _reynolds_force(eps, eps_dot, gamma_dot, omega, n=800_001):
    """Short-bearing pressure integrated where it is positive (pi film), midpoint rule."""
    th = (np.arange(n) + 0.5) * 2 * np.pi / n
    h = C * (1.0 - eps * np.cos(th))
    G = 6 * MU * C * (eps * (omega - 2 * gamma_dot) * np.sin(th) - 2 * eps_dot * np.cos(th))
    G = np.minimum(G, 0.0)                       # p >= 0 where G <= 0; the rest cavitates
    # p = G (z^2 - L^2/4) / (2 h^3);  int (z^2 - L^2/4) dz = -L^3/6;  F = -int p u R dtheta dz
    w = R * L**3 / 12 * G / h**3 * 2 * np.pi / n
    return np.sum(w * np.cos(th)), np.sum(w * np.sin(th))


@pytest.mark.parametrize("eps,eps_dot,gamma_dot,omega", [
    (0.5, 0.0, 0.0, 100.0),      # steadily loaded journal
    (0.3, 5.0, 0.0, 0.0),        # pure squeeze
    (0.7, -2.0, 20.0, 30.0),     # whirl, squeeze and rotation together
])
def test_short_bearing_force_equals_integrated_reynolds_pressure(eps, eps_dot, gamma_dot, omega):
    fr, ft = short_bearing_force(eps, eps_dot, gamma_dot, omega, MU, R, L, C)
    fr_ref, ft_ref = _reynolds_force(eps, eps_dot, gamma_dot, omega)
    scale = np.hypot(fr_ref, ft_ref)
    assert fr == pytest.approx(fr_ref, abs=1e-6 * scale)
    assert ft == pytest.approx(ft_ref, abs=1e-6 * scale)


def test_static_short_bearing_load_direction_is_the_ocvirk_attitude_angle(oracle):
    # Oracle: tan(phi) = pi sqrt(1 - eps^2) / (4 eps) (Ocvirk). For comparison, seed 001 Table 3
    # (L/D = 1, finite bearing) prints 75.11, 63.59, 55.55, 50.08, 45.32, 40.54, 36.02 deg for
    # eps = 0.1 .. 0.7; the short-bearing values are 82.7, 75.4, 68.2, 60.9, 53.7, 46.3, 38.7:
    # the same falling trend, 3..13 deg higher (no finite-bearing solver yet).
    eps = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7])
    fr, ft = short_bearing_force(eps, 0.0, 0.0, 100.0, MU, R, L, C)
    expected = np.degrees(np.arctan(np.pi * np.sqrt(1 - eps**2) / (4 * eps)))
    oracle(stage="dynamics", quantity="short bearing attitude angle at eps = 0.5, deg", reference="Ocvirk closed form tan(phi) = pi sqrt(1 - eps^2) / (4 eps)", tolerance="1e-9 deg", measured=np.degrees(np.arctan2(ft, -fr))[4], expected=expected[4])
    np.testing.assert_allclose(np.degrees(np.arctan2(ft, -fr)), expected, atol=1e-9)
    np.testing.assert_allclose(attitude_angle(eps), expected, atol=1e-12)


def test_lubricated_joint_film_carries_a_load_and_books_its_dissipation():
    # A spinning journal under a constant load floats on the film (no dry contact) and the
    # energy balance (film power booked as dissipation) closes.
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", 1.0, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=C, journal_radius=R,
                           law="hertz", law_params={"stiffness": 1e11, "exponent": 1.5},
                           viscosity=MU, bearing_length=L)
    sysm = Multibody([journal], [], [joint], gravity=(0.0, -2000.0))
    assert sysm.kernel() is not None  # the short film runs in the compiled kernel
    q0, qd0 = np.zeros(3), np.array([0.0, 0.0, 200.0])
    out = integrate(sysm, q0, qd0, 0.01, None, SolverSettings(method="LSODA", rtol=1e-7,
                                                             atol=1e-14))
    y = out.y[:, -1]
    assert out.onsets[0] == []                       # no dry contact
    ecc = np.hypot(y[0], y[1]) / C
    assert 0.0 < ecc < 0.95
    ke0 = sysm.energy(q0, qd0)
    ke, pe = sysm.energy(y[:3], y[3:6])
    d_contact = y[6 + AUX_NAMES.index("dissipated_contact")]
    assert (ke + pe) - sum(ke0) == pytest.approx(-d_contact, abs=1e-9 * ke0[0])


@pytest.mark.parametrize("eps,eps_dot,gamma,gamma_dot,omega", [
    (0.6, 3.0, 0.7, 40.0, 300.0),
    (0.3, -8.0, -2.5, -120.0, 150.0),
])
def test_joint_film_force_is_the_short_bearing_force_of_its_polar_kinematics(eps, eps_dot, gamma,
                                                                            gamma_dot, omega):
    # Oracle: a journal centre at e = eps c (cos gamma, sin gamma) moving with
    # v = c eps_dot n + eps c gamma_dot t is the film of short_bearing_force(eps, eps_dot,
    # gamma_dot, omega) in the frame (n, t). The joint turns its kinematics into the film's
    # arguments (lubrication.film_arguments, without gamma_dot) on both paths: ClearanceJoint's
    # film_force and the compiled kernel's contact force (no dry contact inside the clearance).
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", 1.0, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=C, journal_radius=R,
                           law="hertz", law_params={"stiffness": 1e11, "exponent": 1.5},
                           viscosity=MU, bearing_length=L)
    sysm = Multibody([journal], [], [joint])
    n = np.array([np.cos(gamma), np.sin(gamma)])
    t = np.array([-n[1], n[0]])
    q = np.array([*(eps * C * n), 0.4])
    qd = np.array([*(C * eps_dot * n + eps * C * gamma_dot * t), omega])
    fr, ft = short_bearing_force(eps, eps_dot, gamma_dot, omega, MU, R, L, C)
    expected = fr * n + ft * t
    python = joint.film_force(joint.kinematics(sysm, q, qd))
    assert sysm.kernel() is not None
    kernel = sysm.solve(0.0, q, qd)["contacts"][0]["force"]
    scale = np.hypot(fr, ft)
    np.testing.assert_allclose(python, expected, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(kernel, expected, rtol=0, atol=1e-12 * scale)
