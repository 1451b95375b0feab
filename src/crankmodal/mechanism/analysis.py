"""One steady-speed working cycle of a machine: every curve and the headline numbers.

:func:`analyse` composes the pure functions of this subpackage; it is what the stage runs and
what a script calls::

    from crankmodal.mechanism.analysis import analyse
    res = analyse(machine)            # machine: crankmodal.mechanism.machine.Machine
    res.shaking_force                 # (n, 2) N
    res.to_dict()                     # JSON-able key numbers
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import forces as fo
from . import friction as fr
from . import gas as ga
from . import inertia as inr
from .kinematics import (
    acceleration_harmonics,
    exact_motion,
    kinematic_ratio,
    series_motion,
)
from .machine import CompressorGas, FourStrokeGas, Machine

#: a resultant counts as "cancelled"/"constant" below this fraction of one cylinder's amplitude
BALANCE_TOLERANCE = 1e-9


@dataclass
class MechanismResults:
    """Curves over one working cycle (arrays, SI units) and derived key numbers.

    Per-cylinder curves have shape ``(n, n_cyl)``; vectors end in an axis of length 2
    ``(x, y)``; order-resolved arrays start with an axis of orders 1..max_order.
    """

    machine: Machine
    theta: np.ndarray
    psi: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    a_series: np.ndarray
    beta: np.ndarray
    beta_dot: np.ndarray
    beta_ddot: np.ndarray
    pressure: np.ndarray
    volume: np.ndarray
    gas_force: np.ndarray
    inertia_force: np.ndarray
    friction_force: np.ndarray
    piston_force: np.ndarray
    side_thrust: np.ndarray
    rod_force: np.ndarray
    cylinder_torque: np.ndarray
    crank_torque: np.ndarray
    order_coefficients: np.ndarray
    order_force: np.ndarray
    order_moment: np.ndarray
    rotating_force: np.ndarray
    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    counterweight_force: np.ndarray
    friction_amplitude: np.ndarray
    indicated_power_seed: np.ndarray | None = None
    scalars: dict = field(default_factory=dict)

    def curves(self) -> dict:
        """The arrays, by name, for ``numpy.savez``."""
        skip = {"machine", "scalars", "indicated_power_seed"}
        return {k: np.asarray(getattr(self, k)) for k in self.__dataclass_fields__ if k not in skip}

    def to_dict(self) -> dict:
        """Key numbers (JSON-able)."""
        return dict(self.scalars)


def _pressures(m: Machine, psi, x):
    """Absolute cylinder pressure and volume per cylinder (Pa, m^3)."""
    p = np.full(psi.shape, m.atmospheric_pressure)
    vol = np.empty(psi.shape)
    for i, c in enumerate(m.cylinders):
        g = m.gas
        if isinstance(g, CompressorGas):
            s_c = c.relative_clearance * m.stroke
            p[:, i] = ga.compressor_pressure(
                psi[:, i], x[:, i], m.stroke, c.suction_pressure, c.discharge_pressure,
                c.relative_clearance, g.compression_exponent, g.expansion_exponent,
                g.pressure_coefficient, g.valve_timing, g.seed_angles,
            )
        elif isinstance(g, FourStrokeGas):
            s_c = m.stroke / (g.compression_ratio - 1.0)
            p[:, i] = ga.four_stroke_pressure(
                psi[:, i] - c.cycle_phase, m.crank_radius, m.ratio, g.intake_pressure,
                g.max_pressure, g.exhaust_pressure, g.compression_ratio,
                g.compression_exponent, g.expansion_exponent, g.constant_pressure_duration,
                g.rise_end, g.exhaust_opening, displacement="exact",
            )
        else:
            s_c = 0.0
        vol[:, i] = ga.cylinder_volume(x[:, i], c.area, s_c)
    return p, vol


def analyse(m: Machine, n_per_rev: int = 720, max_order: int = 2, harmonics: str = "series"):
    """Kinematics, inertia, gas, friction and torque of ``m`` over one working cycle.

    Parameters
    ----------
    m : Machine
    n_per_rev : int
        Crank-angle samples per revolution (uniform, periodic: the last point is not repeated).
    max_order : int
        Highest order of the order-resolved reciprocating forces and moments.
    harmonics : {"series", "fourier"}
        ``"series"``: seed 000 Table 1 (``A_1 = 1, A_2 = lambda``, max_order <= 2);
        ``"fourier"``: exact Fourier coefficients of the piston acceleration.

    Returns
    -------
    MechanismResults
    """
    r, lam, w = m.crank_radius, m.ratio, m.omega
    n = n_per_rev * m.cycle_revolutions
    theta = 2 * np.pi * m.cycle_revolutions * np.arange(n) / n
    cyl = m.cylinders
    phi = np.array([c.bank_angle for c in cyl])
    gamma = np.array([c.throw_angle for c in cyl])
    b = np.array([c.axial_offset for c in cyl])
    m_s = np.array([c.piston_mass for c in cyl]) + m.rod.reciprocating_mass
    area = np.array([c.area for c in cyl])

    psi = theta[:, None] + gamma - phi
    mo = exact_motion(psi, r, lam, w)
    a_series = series_motion(psi, r, lam, w).a
    dx = kinematic_ratio(psi, r, lam)

    # --- inertia: forces on the frame -------------------------------------------------------
    recip = inr.reciprocating_force(m_s, mo.a, phi)  # (n, n_cyl, 2)
    crank_dir = theta[:, None] + gamma
    rot_cyl = inr.rotating_force(m.rod.rotating_mass * r, w, crank_dir)  # (n, n_cyl, 2)
    rot_crank = inr.rotating_force(m.crank_unbalance, w, theta)
    rotating = rot_cyl.sum(axis=1) + rot_crank
    shaking = recip.sum(axis=1) + rotating
    shaking_moment = inr.moment(recip + rot_cyl, b[:, None]).sum(axis=1)

    if harmonics == "series":
        coeff = np.array([1.0, lam])[:max_order]
    else:
        coeff = acceleration_harmonics(lam, max_order)
    per_order = inr.order_forces(psi, phi, m_s, r, w, coeff)  # (k, n, n_cyl, 2)
    order_force = per_order.sum(axis=2)
    order_moment = inr.moment(per_order, b[:, None]).sum(axis=2)

    first = order_force[0] + rotating
    cw_mr, cw_angle, cw_residual = inr.counterweight(theta, first, w)
    cw_force = inr.rotating_force(cw_mr, w, theta + cw_angle)

    # --- gas, friction, piston force, torque --------------------------------------------------
    p, vol = _pressures(m, psi, mo.x)
    f_gas = ga.gas_force(p, area, m.atmospheric_pressure)
    gas_work = np.array([ga.cycle_work(p[:, i], vol[:, i]) for i in range(len(cyl))])
    cycles_per_s = m.speed_rpm / 60.0 / m.cycle_revolutions
    ind_seed = None
    if isinstance(m.gas, CompressorGas):
        g = m.gas
        ind_seed = np.array([
            fr.indicated_power_seed(
                c.suction_pressure, c.discharge_pressure, c.area * m.stroke, m.speed_rpm,
                c.relative_clearance, g.expansion_exponent, g.compression_exponent,
            )
            for c in cyl
        ])
    if m.friction is None:
        f_amp = np.zeros(len(cyl))
    else:
        ip = ind_seed if m.friction.indicated_power == "seed" else np.abs(gas_work) * cycles_per_s
        f_amp = np.array([
            fr.friction_force_amplitude(
                ip[i], m.friction.mechanical_efficiency, r, w, m.friction.reciprocating_share
            )
            for i in range(len(cyl))
        ])
    f_fric = fr.friction_force(f_amp, mo.v)
    f_in = -m_s * mo.a
    f_p = fo.piston_force(f_gas, f_in, f_fric)
    thrust = fo.side_thrust(f_p, mo.beta)
    t_cyl = fo.crank_torque(f_p, dx) + fo.rod_couple_torque(
        m.rod.inertia_defect, mo.beta_dot, mo.beta_ddot, w
    )
    torque = t_cyl.sum(axis=1)

    res = MechanismResults(
        machine=m, theta=theta, psi=psi, x=mo.x, v=mo.v, a=mo.a, a_series=a_series,
        beta=mo.beta, beta_dot=mo.beta_dot, beta_ddot=mo.beta_ddot, pressure=p, volume=vol,
        gas_force=f_gas, inertia_force=f_in, friction_force=f_fric, piston_force=f_p,
        side_thrust=thrust, rod_force=fo.rod_force(f_p, mo.beta), cylinder_torque=t_cyl,
        crank_torque=torque, order_coefficients=coeff, order_force=order_force,
        order_moment=order_moment, rotating_force=rotating, shaking_force=shaking,
        shaking_moment=shaking_moment, counterweight_force=cw_force, friction_amplitude=f_amp,
        indicated_power_seed=ind_seed,
    )
    res.scalars = _key_numbers(res, m_s, gas_work, cycles_per_s, (cw_mr, cw_angle, cw_residual))
    return res


def _key_numbers(res: MechanismResults, m_s, gas_work, cycles_per_s, cw):
    m = res.machine
    r, w = m.crank_radius, m.omega
    ref = float(np.mean(m_s)) * r * w**2  # one cylinder's first-order amplitude
    orders = []
    for k in range(res.order_force.shape[0]):
        fmax, fmin = inr.magnitude_range(res.order_force[k])
        mmax, mmin = inr.magnitude_range(res.order_moment[k])
        orders.append({"order": k + 1, "coefficient": float(res.order_coefficients[k]),
                       "force_max_n": fmax, "force_min_n": fmin,
                       "moment_max_nm": mmax, "moment_min_nm": mmin})
    f1max, f1min = orders[0]["force_max_n"], orders[0]["force_min_n"]
    second = orders[1]["force_max_n"] if len(orders) > 1 else None
    sh_max, sh_min = inr.magnitude_range(res.shaking_force)
    bal = res.shaking_force + res.counterweight_force
    bal_max, _ = inr.magnitude_range(bal)
    mom_max, _ = inr.magnitude_range(res.shaking_moment)
    work = float(gas_work.sum())
    fric_work = float(np.sum(res.friction_amplitude) * 4.0 * r * m.cycle_revolutions)
    out = {
        "crank_radius_m": r,
        "rod_length_m": m.rod.length,
        "crank_rod_ratio": m.ratio,
        "speed_rpm": m.speed_rpm,
        "omega_rad_s": w,
        "n_cylinders": len(m.cylinders),
        "cycle_revolutions": m.cycle_revolutions,
        "reciprocating_mass_kg": m_s,
        "rod_reciprocating_mass_kg": m.rod.reciprocating_mass,
        "rod_rotating_mass_kg": m.rod.rotating_mass,
        "rod_inertia_defect_kg_m2": m.rod.inertia_defect,
        "peak_acceleration_m_s2": res.a.max(axis=0),
        "min_acceleration_m_s2": res.a.min(axis=0),
        "peak_acceleration_series_m_s2": res.a_series.max(axis=0),
        "peak_rod_angular_acceleration_rad_s2": np.abs(res.beta_ddot).max(axis=0),
        "orders": orders,
        "first_order_force_max_n": f1max,
        "first_order_force_min_n": f1min,
        "second_order_force_max_n": second,
        "second_order_moment_max_nm": orders[1]["moment_max_nm"] if len(orders) > 1 else None,
        "first_order_magnitude_constant": bool(f1max - f1min <= BALANCE_TOLERANCE * ref),
        "second_order_force_cancelled": bool(second is not None
                                             and second <= BALANCE_TOLERANCE * ref),
        "rotating_force_n": inr.magnitude_range(res.rotating_force)[0],
        "shaking_force_max_n": sh_max,
        "shaking_force_min_n": sh_min,
        "shaking_moment_max_nm": mom_max,
        "counterweight_mass_radius_kg_m": cw[0],
        "counterweight_angle_deg": float(np.degrees(cw[1])),
        "first_order_residual_with_counterweight_n": cw[2],
        "shaking_force_with_counterweight_max_n": bal_max,
        "peak_gas_force_n": res.gas_force.max(axis=0),
        "peak_piston_force_n": np.abs(res.piston_force).max(axis=0),
        "peak_side_thrust_n": np.abs(res.side_thrust).max(axis=0),
        "peak_rod_force_n": np.abs(res.rod_force).max(axis=0),
        "friction_force_n": res.friction_amplitude,
        "friction_work_per_cycle_j": fric_work,
        "gas_work_per_cycle_j": work,
        "gas_work_per_cylinder_j": gas_work,
        "indicated_power_w": abs(work) * cycles_per_s,
        "mean_crank_torque_nm": float(res.crank_torque.mean()),
        "max_crank_torque_nm": float(res.crank_torque.max()),
        "min_crank_torque_nm": float(res.crank_torque.min()),
    }
    if res.indicated_power_seed is not None:
        out["indicated_power_seed_formula_w"] = res.indicated_power_seed
    return out
