"""Four-star (four rods on one crankpin) and the seed-001 four-bar loom linkage."""

import numpy as np
import pytest

from crankmodal.dynamics import (
    Cylinder,
    SolverSettings,
    crank_train,
    four_bar,
    simulate,
)
from crankmodal.dynamics.results.signals import order_amplitudes, whirl_components

RPM = 1480.0
W = RPM * np.pi / 30


def _four_star(clearances=None, contact=None, z=(0.02, 0.02, -0.02, -0.02)):
    cyls = [Cylinder(axis_angle=np.deg2rad(a), rod_length=0.28, rod_mass=0.9, rod_inertia=0.0123,
                     rod_com=0.084, piston_mass=1.2, z=zi)
            for a, zi in zip((90.0, 270.0, 0.0, 180.0), z)]
    return crank_train(0.035, cyls, RPM, crank_mass=3.0, crank_inertia=0.02, clearances=clearances,
                       contact_kw=contact, kind="four_star")


@pytest.fixture(scope="module")
def star_ideal():
    m = _four_star()
    T = 60.0 / RPM
    return m, simulate(m, T, T / 720, SolverSettings(rtol=1e-10, atol=1e-13), ideal=True)


def test_four_star_identical_rods_cancel_every_even_order_of_the_main_bearing_force(star_ideal):
    m, h = star_ideal
    amps = order_amplitudes(h.t, h.main_bearing_force, m.revolution_hz, range(1, 9))
    first = np.abs(amps[0]).max()
    assert first > 100.0
    # orders 2, 4, 6, 8: opposite cylinders see equal even harmonics along opposite axes
    assert np.abs(amps[1::2]).max() < 1e-7 * first
    # the third order survives (it is the seed's "third-order" excitation)
    assert np.abs(amps[2]).max() > 1e-3 * first


def test_four_star_first_order_force_rotates_with_constant_magnitude(star_ideal):
    m, h = star_ideal
    fwd, bwd = whirl_components(h.t, h.main_bearing_force[:, 0], h.main_bearing_force[:, 1],
                                m.revolution_hz, 1)
    assert bwd < 1e-7 * fwd


def test_four_star_row_offsets_make_a_moment_about_the_crank_centre(star_ideal):
    _, h = star_ideal
    # joint_forces[big_end_i] is the force of the crank on rod i; the crank takes its reaction
    # at (0, 0, z_i): M = sum_i (0, 0, z_i) x (-f_i), in-plane components (cross product taken
    # with numpy, not the hand-expanded formula of history.record)
    M = sum(np.cross([0.0, 0.0, z], -np.column_stack([h.joint_forces[f"big_end_{i}"],
                                                      np.zeros(h.t.size)]))[:, :2]
            for i, z in enumerate((0.02, 0.02, -0.02, -0.02), start=1))
    np.testing.assert_allclose(h.main_bearing_moment, M, atol=1e-9)
    assert np.abs(h.main_bearing_moment).max() > 1.0


# ----------------------------------------------------------------------------------- four-bar
LOOM = {"crank_length": 0.035, "coupler_length": 0.075, "rocker_length": 0.145,
        "rocker_pivot": (0.008, 0.1598), "masses": (35.8, 2.27, 10.42),
        "inertias": (0.0155, 0.0114, 0.0528), "extra_rocker_inertia": 0.3728, "speed_rpm": 450.0}


def _loom_positions(th):
    """Closed-form four-bar position analysis (circle intersection), branch +1."""
    D = np.array(LOOM["rocker_pivot"])
    l1, l2, l3 = LOOM["crank_length"], LOOM["coupler_length"], LOOM["rocker_length"]
    B = l1 * np.array([np.cos(th), np.sin(th)])
    d = D - B
    dist = np.hypot(*d)
    x = (dist**2 + l2**2 - l3**2) / (2 * dist)
    y = np.sqrt(l2**2 - x**2)
    e = d / dist
    C = B + x * e + y * np.array([-e[1], e[0]])
    return B, C, np.arctan2(*(C - B)[::-1]), np.arctan2(*(C - D)[::-1])


def _loom_kinetic_energy(th, w, h=1e-5):
    """KE at crank speed w from finite-difference velocities of the closed-form positions."""
    D = np.array(LOOM["rocker_pivot"])
    _, m2, m3 = LOOM["masses"]  # the crank's centre of mass is on its pivot A: no m1 v^2 term
    I1, I2, I3 = LOOM["inertias"]
    I3 += LOOM["extra_rocker_inertia"]

    def coords(t):
        B, C, p2, p3 = _loom_positions(t)
        return np.array([*(0.5 * (B + C)), p2, *(0.5 * (C + D)), p3])

    v = (coords(th + h) - coords(th - h)) / (2 * h) * w
    return 0.5 * (I1 * w**2 + m2 * v[:2] @ v[:2] + I2 * v[2] ** 2 + m3 * v[3:5] @ v[3:5]
                  + I3 * v[5] ** 2)


def test_loom_four_bar_drive_torque_equals_the_rate_of_kinetic_energy():
    m = four_bar(**LOOM)
    w = LOOM["speed_rpm"] * np.pi / 30
    T = 60.0 / LOOM["speed_rpm"]
    h = simulate(m, T, T / 180, SolverSettings(rtol=1e-10, atol=1e-13), ideal=True)
    dth = 1e-4
    dke = np.array([(_loom_kinetic_energy(t + dth, w) - _loom_kinetic_energy(t - dth, w))
                    / (2 * dth) for t in h.crank_angle])
    torque = dke  # T w = dKE/dt = w dKE/dtheta
    np.testing.assert_allclose(h.drive_torque, torque, atol=2e-5 * np.abs(torque).max())


def test_loom_coupler_pin_clearance_orbit_stays_near_the_clearance_circle():
    # Seed 001 Table 2 bearing: R = 20 mm, c = 0.021 mm; dry contact, steel stiffness from E.
    from crankmodal.dynamics.laws.contact import cylinder_stiffness

    K = float(cylinder_stiffness(0.02, 0.020021, 2.1e11, 0.3, 2.1e11, 0.3))
    contact = {"law": "lankarani_nikravesh",
               "law_params": {"stiffness": K, "exponent": 1.5, "restitution": 0.7}}
    m = four_bar(**LOOM, clearances={"C": {"clearance": 2.1e-5, "journal_radius": 0.02}},
                 contact_kw=contact)
    T = 0.5 * 60.0 / LOOM["speed_rpm"]
    h = simulate(m, T, T / 180)
    d = h.contact["C"]
    ecc = np.hypot(d["ex"], d["ey"])
    depth = (d["fn"].max() / K) ** (1 / 1.5)
    assert ecc.max() <= 2.1e-5 + 1.5 * depth
    assert h.energy_error() < 1e-4


def test_compiled_constraint_terms_equal_the_joint_by_joint_assembly(star_ideal):
    # The kernel's constraint values and Jacobian must reproduce the reference path's per-joint
    # blocks at an arbitrary (inconsistent) state.
    m, _ = star_ideal
    for sysm in (m.ideal, m.system, four_bar(**LOOM).ideal):
        rng = np.random.default_rng(1)
        q = rng.normal(size=sysm.n)
        qd = rng.normal(size=sysm.n)
        out = sysm.kernel().solve(0.013, q, qd)
        phi, Cq, _, _ = sysm.constraint_terms(0.013, q, qd)
        for a, b in ((out["phi"], phi), (out["Cq"], Cq)):
            # two summation orders: round-off only, 1e-12 of the terms' size on any CPU
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * max(np.max(np.abs(b)), 1.0))
