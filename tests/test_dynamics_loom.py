"""Seed 001 loom four-bar: the frame, assembly mode and data under which the seed's angles come out.

Oracles: mirror symmetry of the equations of motion, the two-force coupler in closed form, and
the crank angles seed 001 names for its coupler-pin force (smallest force 20 N at 92 deg, fast
direction changes at 92 and 322 deg).
"""

from pathlib import Path

import numpy as np
import pytest

from crankmodal.dynamics import SolverSettings, four_bar, simulate
from crankmodal.dynamics.results.signals import force_direction
from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
from crankmodal.runner import check
from crankmodal.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
RPM = 450.0
W = RPM * np.pi / 30
T = 60.0 / RPM
LINKS = {"crank_length": 0.035, "coupler_length": 0.075, "rocker_length": 0.145,
         "speed_rpm": RPM, "masses": (35.8, 2.27, 10.42), "inertias": (0.0155, 0.00114, 0.0528),
         "extra_rocker_inertia": 0.3728}
TIGHT = SolverSettings(rtol=1e-10, atol=1e-13)


def test_mirrored_loom_gives_the_mirror_image_of_the_c_force():
    # Reflection x -> -x maps the mechanism with D = (8, 159.8) mm, branch 1, turning clockwise
    # from theta = 180 deg onto D = (-8, 159.8) mm, branch -1, counter-clockwise from 0: the pin
    # forces must be mirror images at every instant (F_x -> -F_x).
    a = four_bar(**LINKS, rocker_pivot=(0.008, 0.1598), branch=1, direction=-1, theta0=np.pi)
    b = four_bar(**LINKS, rocker_pivot=(-0.008, 0.1598), branch=-1)
    ha = simulate(a, 0.5 * T, T / 180, TIGHT, ideal=True)
    hb = simulate(b, 0.5 * T, T / 180, TIGHT, ideal=True)
    np.testing.assert_allclose(np.pi - ha.crank_angle, hb.crank_angle, atol=1e-9)
    for j in "ABCD":
        fa, fb = ha.joint_forces[j], hb.joint_forces[j]
        scale = np.abs(fb).max()
        np.testing.assert_allclose(-fa[:, 0], fb[:, 0], atol=1e-6 * scale)
        np.testing.assert_allclose(fa[:, 1], fb[:, 1], atol=1e-6 * scale)


def _rocker_angle(th, D, branch, l1=0.035, l2=0.075, l3=0.145):
    """Closed-form position of the four-bar: rocker angle and the points B, C (branch as built)."""
    B = l1 * np.array([np.cos(th), np.sin(th)])
    BD = np.asarray(D) - B
    d = np.hypot(*BD)
    x = (d * d + l2 * l2 - l3 * l3) / (2 * d)
    e = BD / d
    C = B + x * e + branch * np.sqrt(l2 * l2 - x * x) * np.array([-e[1], e[0]])
    return np.arctan2(C[1] - D[1], C[0] - D[0]), B, C


def test_nearly_massless_coupler_carries_the_rocker_torque_as_a_two_force_member():
    # With a (nearly) massless coupler the force at C lies along BC (with the seed's 2.27 kg it is
    # up to 0.28 |F| across BC); its moment about D drives rocker and sley, r_DC x F = I_D alpha_3
    # with I_D = I_3 + I_sley + m_3 (l_3/2)^2 and alpha_3 from the closed-form position.
    D, br = (-0.008, 0.1598), -1
    I_D = 0.0528 + 0.3728 + 10.42 * 0.0725**2
    m = four_bar(**dict(LINKS, masses=(35.8, 1e-6, 10.42), inertias=(0.0155, 1e-12, 0.0528)),
                 rocker_pivot=D, branch=br)
    h = simulate(m, T, T / 36, TIGHT, ideal=True)
    dth = 1e-4
    for th, F in zip(h.crank_angle, h.joint_forces["C"]):
        p3 = [_rocker_angle(th + k * dth, D, br)[0] for k in (-1, 0, 1)]
        alpha3 = np.angle(np.exp(1j * (p3[2] - p3[1])) / np.exp(1j * (p3[1] - p3[0]))) / dth**2 * W**2
        _, B, C = _rocker_angle(th, D, br)
        u = (C - B) / np.linalg.norm(C - B)
        f = -F                                  # joint_forces: rocker on coupler; here on the rocker
        r = C - np.asarray(D)
        assert abs(u[0] * f[1] - u[1] * f[0]) < 1e-5 * np.abs(f).max() + 1e-6
        assert r[0] * f[1] - r[1] * f[0] == pytest.approx(I_D * alpha3, rel=2e-4, abs=1e-3)


@pytest.fixture(scope="module")
def loom_scene_ideal():
    params = check(load_scene(ROOT / "scenes" / "loom_four_bar_dynamics.toml",
                              [f"dynamics.end_time={T!r}"]))
    p = params["dynamics"]
    m = build_mechanism(p)
    return simulate(m, T, T / 720, solver_settings(p, RPM), ideal=True)


def test_loom_machine_file_puts_the_c_force_events_at_the_seed_crank_angles(loom_scene_ideal):
    # Seed 001 Sec. 2.3/3: smallest coupler-pin force 20 N at 92 deg; the force direction changes
    # fast at 92 and 322 deg. Crank angle of the machine file = the seed's.
    h = loom_scene_ideal
    deg = np.degrees(h.crank_angle) % 360.0
    F = h.joint_forces["C"]
    mag = np.hypot(F[:, 0], F[:, 1])
    _, rate = force_direction(h.t, F)
    assert deg[np.argmin(mag)] == pytest.approx(92.0, abs=3.0)
    assert 5.0 < mag.min() < 40.0                                      # seed: 20 N
    late = deg > 200.0
    assert deg[late][np.argmax(np.abs(rate[late]))] == pytest.approx(322.0, abs=8.0)
    assert deg[np.argmax(np.abs(rate))] == pytest.approx(92.0, abs=3.0)
