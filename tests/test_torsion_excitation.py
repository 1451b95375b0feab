"""Tangential effort per cylinder and its orders, against closed forms.

- a single compressor cylinder: mean gas torque x omega = indicated power of the ideal polytropic
  cycle (closed form);
- inertia torque of an exact slider-crank (no gas): its orders 1-4 against the series in
  lambda = r / l, derived by hand from T = -(m/2) d(v^2)/dpsi (see the test);
- an inline four-stroke four 1-3-4-2: the phase-vector sums of its orders (2 and 4 add four
  times, 0.5, 1, 1.5 and 3 cancel) — with and without gas, since the four cylinders are equal;
- firing angles of an inline four and six from their throws and firing orders;
- a measured pressure table (here sampled from the model) gives the model's torque orders.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from crankmodal.errors import ParameterError
from crankmodal.mechanism.arrangement import Arrangement, arrangement_of_machine
from crankmodal.mechanism.machine import CompressorGas, Cylinder, FourStrokeGas, Machine, Rod
from crankmodal.torsion.excitation import PressureTable, cylinder_efforts, rotor_excitation


def _rod(length, mass=0.0):
    # two point masses exactly (inertia defect zero), so the torque is the point-mass one
    l1 = length / 3
    return Rod(length=length, mass=mass, cg_from_big_end=l1, inertia=mass * l1 * (length - l1))


def test_single_compressor_cylinder_mean_effort_times_omega_is_indicated_power_1e6(oracle):
    r, lam, n_exp = 0.06, 0.25, 1.3
    ps, pd, eps = 1.0e5, 4.0e5, 0.06
    cyl = Cylinder(bank_angle=0.0, axial_offset=0.0, throw_angle=0.0, piston_mass=5.0, bore=0.12,
                   suction_pressure=ps, discharge_pressure=pd, relative_clearance=eps)
    m = Machine("c", r, _rod(r / lam, 2.0), 1000.0, (cyl,),
                gas=CompressorGas(n_exp, n_exp, 1.0, "pressure"))
    eff = cylinder_efforts(m, n_per_rev=20000)
    power = abs(eff.mean_torque(m.omega)[0]) * m.omega
    # ideal cycle with equal exponents: W = n/(n-1) ps (V1 - V4) ((pd/ps)^((n-1)/n) - 1)
    vs = cyl.area * 2 * r
    v1, v4 = vs * (1 + eps), vs * eps * (pd / ps) ** (1 / n_exp)
    work = n_exp / (n_exp - 1) * ps * (v1 - v4) * ((pd / ps) ** ((n_exp - 1) / n_exp) - 1)
    oracle(stage="torsion", quantity="mean tangential effort x omega, one compressor cylinder",
           reference="closed-form indicated power of the ideal polytropic cycle", tolerance="1e-6 rel",
           measured=power, expected=work * m.speed_rpm / 60.0)
    assert power == pytest.approx(work * m.speed_rpm / 60.0, rel=1e-6)


def _ideal_cycle_work(ps, pd, n, swept, eps):
    """Closed-form p-V work of the ideal polytropic compressor cycle (equal exponents), J."""
    v1, v4 = swept * (1 + eps), swept * eps * (pd / ps) ** (1 / n)
    return n / (n - 1) * ps * (v1 - v4) * ((pd / ps) ** ((n - 1) / n) - 1)


def test_double_acting_cylinder_mean_power_is_both_ends_ideal_cycles_1e6(oracle):
    from crankmodal.torsion.excitation import CrankEnd

    r, lam, n_exp = 0.06, 0.25, 1.3
    ps, pd, eps, eps_ce, d_rod = 1.0e5, 4.0e5, 0.06, 0.09, 0.04
    cyl = Cylinder(0.0, 0.0, 0.0, piston_mass=5.0, bore=0.12, suction_pressure=ps,
                   discharge_pressure=pd, relative_clearance=eps)
    m = Machine("c", r, _rod(r / lam, 2.0), 1000.0, (cyl,), gas=CompressorGas(n_exp, n_exp, 1.0, "pressure"))
    eff = cylinder_efforts(m, n_per_rev=20000, crank_ends=(CrankEnd(0, d_rod, eps_ce),))
    power = abs(eff.mean_torque(m.omega)[0]) * m.omega
    stroke = 2 * r
    work = (_ideal_cycle_work(ps, pd, n_exp, cyl.area * stroke, eps)
            + _ideal_cycle_work(ps, pd, n_exp, (cyl.area - math.pi * d_rod**2 / 4) * stroke, eps_ce))
    oracle(stage="torsion", quantity="mean effort x omega, double-acting compressor cylinder",
           reference="closed-form ideal cycles of head and crank end", tolerance="1e-6 rel",
           measured=power, expected=work * m.speed_rpm / 60.0)
    assert power == pytest.approx(work * m.speed_rpm / 60.0, rel=1e-6)
    # the crank end works half a turn after the head end: order 1 of the gas torque nearly cancels
    single = cylinder_efforts(m, n_per_rev=720)
    g1, _ = single.cylinder_harmonics(2)
    g2, _ = cylinder_efforts(m, n_per_rev=720, crank_ends=(CrankEnd(0, d_rod, eps_ce),)).cylinder_harmonics(2)
    assert abs(g2[0, 0]) < 0.5 * abs(g1[0, 0])
    with pytest.raises(ParameterError, match="rod_diameter"):
        cylinder_efforts(m, crank_ends=(CrankEnd(0, 0.12),))


@pytest.mark.parametrize("lam", [0.1, 0.2])
def test_inertia_torque_orders_match_series_in_lambda(lam, oracle):
    # T = -m a dx/dpsi = -(m/2) d(v^2)/dpsi with v/(r omega) = sin t + lam sin t cos t (1 - lam^2
    # sin^2 t)^(-1/2); expanding v^2 to lam^3 and differentiating, in units m r^2 omega^2:
    # T = (lam/4 + lam^3/16) sin t - 1/2 sin 2t - (3 lam/4 + 9 lam^3/32) sin 3t - lam^2/4 sin 4t
    # + O(lam^4) (orders 2, 4) and O(lam^5) (orders 1, 3).
    r, mass = 0.05, 3.0
    cyl = Cylinder(0.0, 0.0, 0.0, piston_mass=mass, bore=0.1)
    m = Machine("i", r, _rod(r / lam), 1500.0, (cyl,))
    eff = cylinder_efforts(m, n_per_rev=720)
    _, h = eff.cylinder_harmonics(4)
    sine = -h[:, 0].imag / (mass * r**2)  # T = Re(c e^{iqt}) -> sine coefficient -Im(c)
    cosine = h[:, 0].real / (mass * r**2)
    series = np.array([lam / 4 + lam**3 / 16, -0.5, -(3 * lam / 4 + 9 * lam**3 / 32), -lam**2 / 4])
    bound = np.array([lam**5, lam**4, 2 * lam**5, lam**4])  # the first neglected terms, O(1) coefficients
    for k in range(4):
        oracle(stage="torsion", quantity=f"inertia torque order {k + 1} / (m r^2 omega^2), lambda {lam:g}",
               reference="series in lambda (hand-derived closed form)", tolerance=f"{bound[k]:.1e} abs",
               measured=float(sine[k]), expected=float(series[k]))
    assert np.all(np.abs(sine - series) <= bound), (sine - series, bound)
    np.testing.assert_allclose(cosine, 0.0, atol=1e-12)  # odd in psi: no cosine terms


def _inline4(gas=True):
    r, lam = 0.04775, 0.04775 / 0.144
    gas_model = FourStrokeGas(0.1e6, 14e6, 0.11e6, 19.5, 1.36, 1.27, math.radians(10.0)) if gas else None
    cyls = tuple(Cylinder(0.0, 0.09 * i, 0.0, piston_mass=0.6, bore=0.0795) for i in range(4))
    m = Machine("i4", r, _rod(r / lam, 0.6), 2000.0, cyls, gas=gas_model)
    arr = Arrangement(throw_angles=tuple(math.radians(a) for a in (0, 180, 180, 0)),
                      cylinder_throws=(0, 1, 2, 3), bank_angles=(0.0,) * 4, cycle_revolutions=2,
                      firing_order=(0, 2, 3, 1))
    return m, arr


@pytest.mark.parametrize("gas", [True, False])
def test_inline_four_orders_2_and_4_add_and_the_others_cancel(gas):
    m, arr = _inline4(gas)
    eff = cylinder_efforts(m, arr)
    ex = rotor_excitation(4, 4.0, 2, eff, throw_rotors=[0, 1, 2, 3])
    F = ex.at([m.omega])[0]  # (orders, rotors)
    single = np.abs(F[:, 0])
    total = np.abs(F.sum(axis=1))
    for j, q in enumerate(ex.orders):
        if single[j] < 1e-9 * single.max():
            continue
        if q in (2.0, 4.0):
            assert total[j] == pytest.approx(4 * single[j], rel=1e-9), q
        else:
            assert total[j] <= 1e-9 * single.max(), (q, total[j])


def test_firing_angles_of_inline_four_and_six():
    four = Arrangement(tuple(math.radians(a) for a in (0, 180, 180, 0)), (0, 1, 2, 3), (0.0,) * 4, 2,
                       (0, 2, 3, 1))
    np.testing.assert_allclose(np.degrees(four.firing_angles()), [0, 540, 180, 360], atol=1e-9)
    six = Arrangement(tuple(math.radians(a) for a in (0, 240, 120, 120, 240, 0)), tuple(range(6)),
                      (0.0,) * 6, 2, (0, 4, 2, 5, 1, 3))
    fire = np.degrees(six.firing_angles())
    np.testing.assert_allclose(np.sort(fire), np.arange(0, 720, 120), atol=1e-9)
    np.testing.assert_allclose(fire[[0, 4, 2, 5, 1, 3]], np.arange(0, 720, 120), atol=1e-9)


def test_pressure_table_of_the_model_gives_the_model_orders():
    m, arr = _inline4(True)
    eff_model = cylinder_efforts(m, arr, n_per_rev=720)
    # the model's own cylinder-1 pressure sampled at 0.25 deg as if digitised
    from crankmodal.mechanism.gas import four_stroke_pressure

    a = np.radians(np.arange(0, 720.25, 0.25))
    g = m.gas
    p = four_stroke_pressure(a, m.crank_radius, m.ratio, g.intake_pressure, g.max_pressure,
                             g.exhaust_pressure, g.compression_ratio, g.compression_exponent,
                             g.expansion_exponent, g.constant_pressure_duration, g.rise_end,
                             g.exhaust_opening, displacement="exact")
    p[-1] = p[0]
    table = PressureTable(a, p, 2)
    eff_table = cylinder_efforts(m, arr, table, n_per_rev=720)
    g1, _ = eff_model.cylinder_harmonics(6)
    g2, _ = eff_table.cylinder_harmonics(6)
    # linear interpolation of a 0.25 deg table against the closed-form cycle sampled at 0.5 deg:
    # the orders agree to a small fraction of the largest (the combustion jump is smeared by 0.25 deg)
    assert np.abs(g2 - g1).max() <= 2e-3 * np.abs(g1).max()


def test_bad_arrangement_and_pressure_table_are_refused_naming_the_key():
    with pytest.raises(ParameterError, match="firing_order"):
        Arrangement((0.0, math.pi), (0, 1), (0.0, 0.0), 2, (0, 0))
    m, _ = _inline4(True)
    with pytest.raises(ParameterError, match="cylinder_throws"):
        arrangement_of_machine(m, [0, 1, 2])
    with pytest.raises(ParameterError, match="angle_deg"):
        PressureTable(np.radians([0, 100, 90, 720]), [1e5, 2e5, 3e5, 1e5], 2)
    with pytest.raises(ParameterError, match="angle_deg"):
        PressureTable(np.radians([0, 100, 700]), [1e5, 2e5, 1e5], 2)
    with pytest.raises(ParameterError, match="pressure_pa"):
        PressureTable(np.radians([0, 100, 720]), [1e5, 2e5, 1.5e5], 2)
    with pytest.raises(ParameterError, match="throw_rotors"):
        rotor_excitation(4, 4.0, 2, cylinder_efforts(m), throw_rotors=[0, 1])


def test_v_twin_on_one_pin_sums_both_cylinders_on_its_throw():
    r = 0.04
    cyls = (Cylinder(math.radians(-45.0), 0.0, 0.0, piston_mass=0.8, bore=0.09),
            Cylinder(math.radians(45.0), 0.0, 0.0, piston_mass=0.8, bore=0.09))
    m = Machine("v", r, _rod(0.15, 0.5), 3000.0, cyls)
    arr = arrangement_of_machine(m, cylinder_throws=[0, 0])
    assert arr.n_throws == 1
    eff = cylinder_efforts(m, arr)
    ex = rotor_excitation(2, 4.0, 1, eff, throw_rotors=[0])
    _, h = eff.cylinder_harmonics(4)
    # cylinder 2 is cylinder 1 delayed by its 90 deg bank: c_q,2 = c_q,1 exp(-i q 90 deg)
    q = np.arange(1, 5)
    np.testing.assert_allclose(h[:, 1], h[:, 0] * np.exp(-1j * q * math.pi / 2), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(ex.inertia_unit[:, 0], h.sum(axis=1), rtol=1e-12)
    assert not np.any(ex.inertia_unit[:, 1])
    # two cylinders on one throw must share its angle
    bad = Machine("v", r, _rod(0.15, 0.5), 3000.0, (cyls[0], Cylinder(0.0, 0.0, 1.0, 0.8, 0.09)))
    with pytest.raises(ParameterError, match=r"cylinder_throws\[1\]"):
        arrangement_of_machine(bad, cylinder_throws=[0, 0])
