"""Seed 003's worn (elliptical) con-rod bearing: bore geometry and penetration rate, on the
Python path (ClearanceJoint) and in the compiled kernel (Multibody.gap, penetration_rate)."""

import numpy as np
import pytest

from crankmodal.dynamics.model.bodies import RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import Multibody

R_J = 0.024                       # m, journal radius D/2
D_MIN, D_MAX = 1.0e-4, 3.0e-4     # m, seed 003's diametral clearances Delta_min, Delta_max


def _worn_pair(gamma):
    rod = RigidBody("rod", 1.0, 1e-3, {"big": (0.0, 0.0)})
    pin = RigidBody("pin", 1.0, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("big_end", pin, "centre", rod, "big", clearance=D_MIN / 2,
                           clearance_major=D_MAX / 2, wear_angle=gamma, journal_radius=R_J,
                           law="hertz", law_params={"stiffness": 1e10, "exponent": 1.5})
    return Multibody([rod, pin], [], [joint]), joint


def _seed_penetration(x12, y12, rod_angle, gamma):
    """Seed 003 Sec. 3: delta = (r12 + D/2) - p2, p2 = b2 / sqrt(1 - eps2^2 cos^2 phi2)."""
    a2, b2 = (2 * R_J + D_MAX) / 2, (2 * R_J + D_MIN) / 2
    eps2 = np.sqrt(1.0 - b2**2 / a2**2)
    phi2 = np.arctan2(y12, x12) - gamma - rod_angle
    p2 = b2 / np.sqrt(1.0 - np.cos(phi2) ** 2 * eps2**2)
    return np.hypot(x12, y12) + R_J - p2


@pytest.mark.parametrize("gamma", [0.0, 0.4, -1.2])
def test_worn_bore_penetration_is_seed_003s_ellipse_in_the_rod_frame(gamma):
    sysm, joint = _worn_pair(gamma)
    assert sysm.kernel() is not None  # Multibody.gap: the compiled kernel
    rng = np.random.default_rng(3)
    for _ in range(20):
        rod_angle = rng.uniform(-np.pi, np.pi)
        e = rng.uniform(-2.5e-4, 2.5e-4, 2)                    # journal centre - bore centre
        q = np.array([0.1, -0.2, rod_angle, 0.1 + e[0], -0.2 + e[1], rng.uniform(0, 6)])
        # the seed's (x12, y12) point from the journal to the bore: the ellipse is symmetric
        expected = _seed_penetration(-e[0], -e[1], rod_angle, gamma)
        assert joint.gap(sysm, q) == pytest.approx(expected, abs=1e-12)
        assert sysm.gap(0, q) == pytest.approx(expected, abs=1e-12)


def test_worn_bore_penetration_rate_is_the_time_derivative_of_the_penetration():
    # journal and a spinning rod moving on smooth paths: the joint's delta_dot against a central
    # difference of its gap (the rod's rotation turns the ellipse under the journal)
    sysm, joint = _worn_pair(0.3)
    assert sysm.kernel() is not None

    def state(t):
        q = np.array([0.01 * np.sin(40 * t), 0.0, 2.0 + 60.0 * t,
                      0.01 * np.sin(40 * t) + 1.2e-4 * np.cos(300 * t), 1.0e-4 * np.sin(170 * t),
                      5.0 * t])
        qd = np.array([0.4 * np.cos(40 * t), 0.0, 60.0,
                       0.4 * np.cos(40 * t) - 0.036 * np.sin(300 * t), 0.017 * np.cos(170 * t),
                       5.0])
        return q, qd

    for t in np.linspace(0.0, 0.05, 11):
        q, qd = state(t)
        k = joint.kinematics(sysm, q, qd)
        h = 1e-7
        fd = (joint.gap(sysm, state(t + h)[0]) - joint.gap(sysm, state(t - h)[0])) / (2 * h)
        assert k["delta"] == pytest.approx(joint.gap(sysm, q), abs=1e-15)
        assert k["delta_dot"] == pytest.approx(fd, rel=1e-6, abs=1e-9)
        assert sysm.penetration_rate(0, q, qd) == pytest.approx(fd, rel=1e-6, abs=1e-9)
