"""Piston force, side thrust, rod force and crank torque (seed 000, Sec. 2.2.4).

All forces along the cylinder are positive towards the crank (the x of the kinematics).
"""

from __future__ import annotations

import numpy as np


def piston_force(gas, inertia, friction):
    """Combined ("multiple") piston force ``F_p = F_ls + F_g + F_f`` (N)."""
    return np.asarray(gas) + np.asarray(inertia) + np.asarray(friction)


def side_thrust(force, beta):
    """Piston side thrust on the cylinder wall ``F_p tan beta`` (N), seed 000 eq. for F_h."""
    return np.asarray(force) * np.tan(beta)


def rod_force(force, beta):
    """Axial rod force ``F_p / cos beta`` (N), compressive positive."""
    return np.asarray(force) / np.cos(beta)


def crank_torque(force, dx_dpsi):
    """Torque of a piston force on the crankshaft (N m), positive in the sense of rotation.

    By virtual work, ``T = F_p dx/dpsi = F_p r sin(psi + beta) / cos(beta)``.
    """
    return np.asarray(force) * np.asarray(dx_dpsi)


def rod_couple_torque(inertia_defect: float, beta_dot, beta_ddot, omega: float):
    """Crank torque from the rod's inertia couple beyond the two point masses (N m).

    The exact rod kinetic energy exceeds that of the two point masses by
    ``(J - m L1 (l - L1)) beta_dot^2 / 2``; at constant crank speed the rods take
    ``d/dt`` of it from the crank: ``T = -(J - m L1 L2) beta_ddot beta_dot / omega``.
    """
    return -inertia_defect * np.asarray(beta_ddot) * np.asarray(beta_dot) / omega
