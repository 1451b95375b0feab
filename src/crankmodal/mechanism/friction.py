"""Piston friction from indicated power and mechanical efficiency (seed 000, Sec. 2.2.4).

The seed writes its formulas in technical units (kgf/cm^2, m^3/min, kW, kgf; the constants
1.634 = 98066.5/60/1000 and 102 kgf m/s per kW). Here they are restated in SI, which removes
those constants: nothing else changes.
"""

from __future__ import annotations

import math

import numpy as np


def volumetric_coefficient(
    relative_clearance: float,
    pressure_ratio: float,
    expansion_exponent: float,
    compressibility_ratio: float = 1.0,
) -> float:
    """Clearance volumetric coefficient ``lambda_v = 1 - c (eps_s/eps_d * eps^(1/m) - 1)``.

    Parameters
    ----------
    relative_clearance : float
        ``c`` = clearance volume / swept volume.
    pressure_ratio : float
        ``eps`` = discharge / suction pressure.
    expansion_exponent : float
        Polytropic exponent ``m`` of the re-expansion.
    compressibility_ratio : float
        ``eps_s / eps_d`` (1 for an ideal gas; the seed takes ``eps_s = eps_d``).
    """
    return 1.0 - relative_clearance * (
        compressibility_ratio * pressure_ratio ** (1.0 / expansion_exponent) - 1.0
    )


def indicated_power_seed(
    suction_pressure: float,
    discharge_pressure: float,
    swept_volume: float,
    speed_rpm: float,
    relative_clearance: float,
    expansion_exponent: float,
    adiabatic_exponent: float,
) -> float:
    """Indicated power of one compressor cylinder (W), seed 000's formula in SI units.

    ``N = ps Vdot lambda_v k/(k-1) [(pd/ps)^((k-1)/k) - 1] (eps_s + eps_d)/(2 eps_s)`` with
    ``Vdot = swept_volume * n / 60`` and ``eps_s = eps_d``. For ``m = k`` and no pressure losses
    it equals the p-V area of the ideal cycle times the cycle frequency exactly.
    """
    k = adiabatic_exponent
    ratio = discharge_pressure / suction_pressure
    lam_v = volumetric_coefficient(relative_clearance, ratio, expansion_exponent)
    flow = swept_volume * speed_rpm / 60.0
    return suction_pressure * flow * lam_v * k / (k - 1.0) * (ratio ** ((k - 1.0) / k) - 1.0)


def mean_piston_speed(r: float, omega: float) -> float:
    """Mean piston speed ``2 * stroke * n`` (m/s) = ``2 r omega / pi``."""
    return 2.0 * r * omega / math.pi


def friction_force_amplitude(
    indicated_power: float,
    mechanical_efficiency: float,
    r: float,
    omega: float,
    reciprocating_share: float = 0.6,
) -> float:
    """Constant magnitude of the piston friction force (N).

    The friction power ``N_i (1/eta_m - 1)``, of which ``reciprocating_share`` (seed: 0.6) is
    lost at the piston, divided by the mean piston speed.
    """
    lost = abs(indicated_power) * (1.0 / mechanical_efficiency - 1.0)
    return reciprocating_share * lost / mean_piston_speed(r, omega)


def friction_force(amplitude: float, velocity):
    """Friction force on the piston along x (N): ``-amplitude * sign(v)``, opposing the motion."""
    return -amplitude * np.sign(np.asarray(velocity))
