"""Cylinder pressure over the working cycle: compressor (seed 000 Sec. 2.2.3), four-stroke
engine (seed 003 Sec. 2). Pressures are absolute (Pa); the gas force on the piston, towards the
crank, is ``(p - p_crankcase) * area``.
"""

from __future__ import annotations

import math

import numpy as np

from .kinematics import exact_motion, series_motion


def compressor_pressure(
    psi,
    x,
    stroke: float,
    suction_pressure: float,
    discharge_pressure: float,
    relative_clearance: float,
    compression_exponent: float,
    expansion_exponent: float,
    pressure_coefficient: float = 1.0,
    valve_timing: str = "pressure",
    seed_angles: tuple[float, float] = (math.radians(97.0), math.radians(295.0)),
):
    """Cylinder pressure of a single-acting compressor (seed 000, Sec. 2.2.3).

    The cycle starts at bottom dead centre: polytropic compression (exponent ``k``) from the
    actual suction pressure ``ps' = lambda_p ps``, delivery at ``pd' = pd / lambda_p``,
    polytropic re-expansion (exponent ``m``) of the clearance gas, suction at ``ps'``.

    Parameters
    ----------
    psi : array_like
        Crank angle from top dead centre (rad).
    x : array_like
        Piston displacement from top dead centre (m) at ``psi``.
    stroke : float
        (m)
    suction_pressure, discharge_pressure : float
        Nominal line pressures (Pa, absolute).
    relative_clearance : float
        Clearance volume / swept volume.
    compression_exponent, expansion_exponent : float
        Polytropic exponents ``k`` and ``m``.
    pressure_coefficient : float
        ``lambda_p`` in (0, 1]: valve and port losses (seed: ``lambda_p = ps'/ps = pd/pd'``).
    valve_timing : {"pressure", "seed"}
        ``"pressure"``: a valve opens when the cylinder pressure reaches its line pressure.
        ``"seed"``: compression ends at ``seed_angles[0]`` and expansion at ``seed_angles[1]``
        after bottom dead centre (seed: 97 and 295 deg), whatever the pressure then is.

    Returns
    -------
    ndarray
        Absolute cylinder pressure (Pa).
    """
    psi = np.asarray(psi, dtype=float)
    x = np.asarray(x, dtype=float)
    ps = pressure_coefficient * suction_pressure
    pd = discharge_pressure / pressure_coefficient
    s_c = relative_clearance * stroke  # clearance as a length of cylinder
    g = np.mod(psi - np.pi, 2 * np.pi)  # gas-cycle angle, 0 at bottom dead centre
    vol = s_c + x
    p_comp = ps * ((stroke + s_c) / vol) ** compression_exponent
    p_exp = pd * (s_c / vol) ** expansion_exponent
    compressing = g < np.pi
    if valve_timing == "pressure":
        return np.where(compressing, np.minimum(p_comp, pd), np.maximum(p_exp, ps))
    if valve_timing == "seed":
        g1, g3 = seed_angles
        return np.select([g < g1, compressing, g < g3], [p_comp, pd, p_exp], ps)
    raise ValueError(f"valve_timing must be 'pressure' or 'seed', got {valve_timing!r}")


def four_stroke_pressure(
    alpha,
    r: float,
    lam: float,
    intake_pressure: float,
    max_pressure: float,
    exhaust_pressure: float,
    compression_ratio: float,
    compression_exponent: float,
    expansion_exponent: float,
    constant_pressure_duration: float,
    rise_end: float = math.radians(15.0),
    exhaust_opening: float = math.radians(170.0),
    displacement: str = "series",
):
    """Four-stroke engine cylinder pressure (seed 003, Sec. 2).

    ``alpha`` is the crank angle from firing top dead centre; the cycle is 4 pi long:
    combustion rise from ``pc = pa eps^n1`` to ``pz`` linear in piston displacement up to
    ``rise_end`` (seed 15 deg), constant ``pz`` for ``constant_pressure_duration``, polytropic
    expansion (n2) to ``exhaust_opening`` (seed 170 deg), exhaust at ``pb`` to 360 deg, intake
    at ``pa`` to 540 deg, polytropic compression (n1) to 720 deg. The clearance is
    ``Sc = Sp / (eps - 1)``.

    Parameters
    ----------
    alpha : array_like
        Crank angle from firing TDC (rad), any range (taken modulo 4 pi).
    r, lam : float
        Crank radius (m) and crank-to-rod ratio.
    intake_pressure, max_pressure, exhaust_pressure : float
        ``pa``, ``pz``, ``pb`` (Pa, absolute).
    compression_ratio : float
        ``eps`` > 1.
    compression_exponent, expansion_exponent : float
        ``n1``, ``n2``.
    constant_pressure_duration : float
        ``theta`` of seed 003 (rad).
    displacement : {"series", "exact"}
        Piston displacement used in the pressure law. The seed uses the series (seed 000 eq. 2);
        the analysis uses the exact one, so that the polytropes are polytropes of the actual
        cylinder volume and the p-V area has a closed form (the two differ by O(lam^3)).

    Returns
    -------
    ndarray
        Absolute cylinder pressure (Pa).
    """
    motion = series_motion if displacement == "series" else exact_motion
    a = np.mod(np.asarray(alpha, dtype=float), 4 * np.pi)
    s_p = 2.0 * r
    s_c = s_p / (compression_ratio - 1.0)
    x = motion(a, r, lam, 1.0).x
    x_rise = motion(rise_end, r, lam, 1.0).x
    a_z = rise_end + constant_pressure_duration
    x_z = motion(a_z, r, lam, 1.0).x
    p_c = intake_pressure * compression_ratio**compression_exponent
    # a rise too short for the piston to move in floating point (rise_end < ~1e-8 rad) is a
    # jump to pz at TDC, not 0/0
    rise = p_c + (max_pressure - p_c) * (x / x_rise if x_rise > 0 else np.ones_like(x))
    expansion = max_pressure * ((s_c + x_z) / (s_c + x)) ** expansion_exponent
    compression = intake_pressure * ((s_c + s_p) / (s_c + x)) ** compression_exponent
    return np.select(
        [a <= rise_end, a <= a_z, a <= exhaust_opening, a <= 2 * np.pi, a <= 3 * np.pi],
        [rise, max_pressure, expansion, exhaust_pressure, intake_pressure],
        compression,
    )


def gas_force(pressure, area: float, crankcase_pressure: float):
    """Gas force on the piston towards the crank (N): ``(p - p_crankcase) * area``."""
    return (np.asarray(pressure) - crankcase_pressure) * area


def cylinder_volume(x, area: float, clearance_length: float):
    """Cylinder volume (m^3) at piston displacement ``x`` from top dead centre."""
    return area * (clearance_length + np.asarray(x))


def cycle_work(pressure, volume) -> float:
    """Closed-cycle integral of ``p dV`` (J) on a periodic sampling (trapezoid, wrapped).

    Positive when the gas does work on the piston (engine), negative for a compressor.
    """
    p = np.asarray(pressure)
    v = np.asarray(volume)
    dv = np.roll(v, -1) - v
    return float(np.sum(0.5 * (p + np.roll(p, -1)) * dv))


def tabulated_pressure(alpha, angles, pressures, period: float):
    """Cylinder pressure (Pa) interpolated in a measured or digitised table, periodic.

    Parameters
    ----------
    alpha : array_like
        Crank angle (rad) in the table's reference (firing TDC for a four-stroke engine, top dead
        centre otherwise), any range (taken modulo ``period``).
    angles : array_like
        Table crank angles (rad), strictly increasing, spanning exactly one ``period``: the last
        point is the first one a cycle later (a closed cycle).
    pressures : array_like
        Absolute pressures at ``angles`` (Pa); the first and last are equal.
    period : float
        Length of the working cycle (rad): 2 pi or 4 pi.

    Returns
    -------
    ndarray
        Linear interpolation of the table at ``alpha``.
    """
    angles = np.asarray(angles, dtype=float)
    a = angles[0] + np.mod(np.asarray(alpha, dtype=float) - angles[0], period)
    return np.interp(a, angles, np.asarray(pressures, dtype=float))
