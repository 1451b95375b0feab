"""Inertia forces and moments against Newton's law on finite-difference accelerations and
against the closed forms of seed 000 Sec. 2.2.1 (which are re-derived in the comments)."""

import math

import numpy as np
import pytest

from crankmodal.mechanism.analysis import analyse
from crankmodal.mechanism.inertia import direction
from crankmodal.mechanism.kinematics import exact_motion
from crankmodal.mechanism.machine import Cylinder, Machine, Rod

R, LAM, RPM = 0.035, 25 / 280, 1480.0  # seed 000
OMEGA = RPM * math.pi / 30


def machine(bank_deg, offsets=None, piston_mass=1.76, rod=None, throws=None, unbalance=0.0):
    rod = rod or Rod(length=R / LAM, mass=0.0, cg_from_big_end=0.0, inertia=0.0)
    offsets = offsets if offsets is not None else [0.0] * len(bank_deg)
    throws = throws or [0.0] * len(bank_deg)
    cyls = tuple(
        Cylinder(math.radians(p), b, math.radians(t), piston_mass, 0.1)
        for p, b, t in zip(bank_deg, offsets, throws)
    )
    return Machine("test", R, rod, RPM, cyls, crank_unbalance=unbalance)


def positions(theta, m, i, s):
    """Piston pin, crankpin and rod centre of mass of cylinder i at crank angles theta (m)."""
    c = m.cylinders[i]
    psi = theta + c.throw_angle - c.bank_angle
    x = exact_motion(psi, R, m.ratio, 1.0).x
    pin = (R + m.rod.length - x)[:, None] * direction(c.bank_angle)
    crankpin = R * direction(theta + c.throw_angle)
    cg = crankpin + (m.rod.cg_from_big_end / m.rod.length) * (pin - crankpin)
    return {"pin": pin, "crankpin": crankpin, "cg": cg}[s]


def fd_acceleration(m, i, which, theta, h=1e-4):
    """Second central difference in time of a point's position (m/s^2)."""
    dt = h / OMEGA
    p = [positions(theta + k * h, m, i, which) for k in (-1, 0, 1)]
    return (p[0] - 2 * p[1] + p[2]) / dt**2


def test_single_cylinder_inertia_force_equals_mass_times_acceleration():
    # Oracle: Newton, with the piston acceleration from finite differences of its position.
    mp = 2.3
    m = machine([30.0], piston_mass=mp)
    res = analyse(m, n_per_rev=360)
    acc = fd_acceleration(m, 0, "pin", res.theta)
    assert np.abs(res.shaking_force - (-mp * acc)).max() < 1e-5 * mp * R * OMEGA**2


def test_rod_two_mass_split_gives_the_exact_rod_inertia_force():
    # Oracle: -m_rod a_G with a_G from finite differences of the rod's centre of mass. The
    # exact two-mass split (m L1/l at the pin, m (l-L1)/l at the crankpin) must reproduce it.
    rod = Rod(length=0.2, mass=1.6, cg_from_big_end=0.07, inertia=0.01)
    mp = 1.2
    m = machine([0.0, 135.0], piston_mass=mp, rod=rod, throws=[0.0, 40.0])
    res = analyse(m, n_per_rev=360)
    th = res.theta
    newton = sum(-mp * fd_acceleration(m, i, "pin", th) - rod.mass * fd_acceleration(m, i, "cg", th)
                 for i in range(2))
    assert np.abs(res.shaking_force - newton).max() < 1e-5 * (mp + rod.mass) * R * OMEGA**2


def test_seed_rule_of_thumb_split_brackets_the_exact_split():
    # seed 000 Sec. 2.2.2: 0.3..0.4 of the rod reciprocates. With L1 = 0.35 l the exact split
    # is 0.35 m_d at the small end.
    rod = Rod(length=0.392, mass=1.6, cg_from_big_end=0.35 * 0.392, inertia=0.043)
    assert rod.reciprocating_mass == pytest.approx(0.35 * 1.6, rel=1e-12)
    assert rod.rotating_mass == pytest.approx(0.65 * 1.6, rel=1e-12)


def test_four_identical_cylinders_cancel_second_order_force():
    # Four identical slider-cranks at 0/90/180/270 deg on one crankpin (seed 000): the Table 1
    # second-order forces lambda m r w^2 cos 2(theta - phi_i) e_i sum to zero at every angle.
    m = machine([0.0, 180.0, 270.0, 90.0])
    res = analyse(m, n_per_rev=720)
    ref = 1.76 * R * OMEGA**2
    assert np.abs(res.order_force[1]).max() < 1e-12 * ref
    assert res.scalars["second_order_force_cancelled"]
    # Also every higher even order (exact Fourier harmonics up to 8): cos 2k(theta - phi_i) is
    # the same for all four, and the four axes sum to zero.
    res8 = analyse(m, n_per_rev=720, max_order=8, harmonics="fourier")
    assert np.abs(res8.order_force[1:]).max() < 1e-12 * ref


def test_four_star_first_order_resultant_is_constant_two_m_r_omega_squared_along_the_crank(oracle):
    # Oracle: seed 000's closed form |F_s1| = 2 m_s r w^2. Summing Table 1 by hand gives
    # F_s1 = 2 m_s r w^2 (sin theta, cos theta), i.e. along the crank. NOTE: the seed prints
    # F_s1x = 2 m_s r w^2 cos(theta), F_s1y = ... sin(theta): x and y swapped with respect to its
    # own Table 1 (x-components carry sin(phi_i)); the magnitude agrees.
    ms = 1.76
    m = machine([0.0, 180.0, 270.0, 90.0])
    res = analyse(m, n_per_rev=720)
    f1 = res.order_force[0]
    expected = 2 * ms * R * OMEGA**2 * direction(res.theta)
    assert np.abs(f1 - expected).max() < 1e-12 * ms * R * OMEGA**2
    oracle(stage="mechanism", quantity="four-star first-order shaking force, N", reference="seed 000 closed form 2 m_s r w^2", tolerance="1e-12", measured=res.scalars["first_order_force_max_n"], expected=2 * ms * R * OMEGA**2)
    assert res.scalars["first_order_force_max_n"] == pytest.approx(2 * ms * R * OMEGA**2, rel=1e-12)
    assert res.scalars["first_order_magnitude_constant"]
    # and a single cylinder is not balanced: the magnitude swings between 0 and m r w^2
    single = analyse(machine([0.0]), n_per_rev=720).scalars
    assert not single["first_order_magnitude_constant"]
    assert single["first_order_force_max_n"] == pytest.approx(ms * R * OMEGA**2, rel=1e-12)


def test_seed_second_order_moment_closed_form_of_the_four_star():
    # Seed 000: M_s1 = 0 and M_s2 = "10 b lambda m_s r w^2 cos 2 theta". Derivation: with
    # F_s2i = lambda m r w^2 cos 2(theta - phi_i) e_i at axial offsets b_i, phases (0, 180, 270,
    # 90) deg, |M_s2| = lambda m r w^2 |cos 2 theta| sqrt((b1 - b2)^2 + (b3 - b4)^2) and
    # |M_s1| = m r w^2 |(b1 + b2) cos theta, (b3 + b4) sin theta|. M_s1 = 0 needs b2 = -b1,
    # b4 = -b3; four rows at pitch a in the order 1-3-4-2 give b = (-3a/2, 3a/2, -a/2, a/2) and
    # |M_s2| = sqrt(10) a lambda m r w^2 |cos 2 theta|. The seed's "10 b" is read as sqrt(10) b
    # (the radical lost in print), with b the row pitch a. No other symmetric row order gives 10.
    a, ms = 0.03, 1.76
    m = machine([0.0, 180.0, 270.0, 90.0], offsets=[-1.5 * a, 1.5 * a, -0.5 * a, 0.5 * a])
    res = analyse(m, n_per_rev=720)
    ref = ms * R * OMEGA**2
    assert np.abs(res.order_moment[0]).max() < 1e-12 * ref * a
    m2 = np.hypot(res.order_moment[1][:, 0], res.order_moment[1][:, 1])
    closed = math.sqrt(10) * a * LAM * ref * np.abs(np.cos(2 * res.theta))
    assert np.abs(m2 - closed).max() < 1e-12 * ref * a


@pytest.mark.parametrize("b", [(0.01, -0.02, 0.05, 0.0), (-0.04, 0.01, 0.02, 0.03)])
def test_second_order_moment_follows_the_row_offsets(b):
    # Same derivation for arbitrary offsets (the seed's Table 1 moments M = F b).
    m = machine([0.0, 180.0, 270.0, 90.0], offsets=list(b))
    res = analyse(m, n_per_rev=360)
    ref = 1.76 * R * OMEGA**2
    m2 = np.hypot(*res.order_moment[1].T)
    closed = LAM * ref * np.abs(np.cos(2 * res.theta)) * math.hypot(b[0] - b[1], b[2] - b[3])
    assert np.abs(m2 - closed).max() < 1e-12 * ref
    m1 = np.hypot(*res.order_moment[0].T)
    closed1 = ref * np.hypot((b[0] + b[1]) * np.cos(res.theta), (b[2] + b[3]) * np.sin(res.theta))
    assert np.abs(m1 - closed1).max() < 1e-12 * ref


def test_counterweight_balances_half_the_first_order_of_a_single_cylinder():
    # Classical oracle: the first-order force m r w^2 cos(theta) e of one cylinder is two
    # counter-rotating vectors of m r w^2 / 2; a crank counterweight cancels the one turning with
    # the crank plus the rotating masses: m_cw r_cw = m_rot r + m_s r / 2, opposite the pin.
    rod = Rod(length=R / LAM, mass=1.6, cg_from_big_end=0.35 * R / LAM, inertia=0.04)
    m = machine([0.0], piston_mass=1.2, rod=rod, unbalance=0.01)
    s = analyse(m, n_per_rev=720).scalars
    ms, mrot = 1.2 + 0.35 * 1.6, 0.65 * 1.6
    assert s["counterweight_mass_radius_kg_m"] == pytest.approx(mrot * R + 0.01 + ms * R / 2, rel=1e-12)
    assert s["counterweight_angle_deg"] == pytest.approx(180.0, abs=1e-9)
    assert s["first_order_residual_with_counterweight_n"] == pytest.approx(ms * R * OMEGA**2 / 2, rel=1e-12)


def test_counterweight_fully_balances_the_four_star():
    # With the first order turning with the crank and all even orders cancelled, one crank
    # counterweight of 2 m_s r + 4 m_rot r removes the whole shaking force of the four-star.
    rod = Rod(length=R / LAM, mass=1.6, cg_from_big_end=0.35 * R / LAM, inertia=0.04)
    m = machine([0.0, 180.0, 270.0, 90.0], piston_mass=1.2, rod=rod)
    res = analyse(m, n_per_rev=720)
    ms, mrot = 1.2 + 0.35 * 1.6, 0.65 * 1.6
    assert res.scalars["counterweight_mass_radius_kg_m"] == pytest.approx(2 * ms * R + 4 * mrot * R, rel=1e-12)
    residual = np.abs(res.shaking_force + res.counterweight_force).max()
    assert residual < 1e-10 * ms * R * OMEGA**2


def test_in_plane_cylinders_have_no_shaking_moment():
    m = machine([0.0, 180.0, 270.0, 90.0])
    assert np.abs(analyse(m, n_per_rev=360).shaking_moment).max() == 0.0
