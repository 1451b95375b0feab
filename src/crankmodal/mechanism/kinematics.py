"""Slider-crank kinematics: exact and second-order series (seed 000, eqs. 1-3), and harmonics.

All functions take the crank angle from top dead centre ``psi`` (rad, any array shape), the crank
radius ``r`` (m), the crank-to-rod ratio ``lam = r / l`` and the constant crank speed ``omega``
(rad/s), and are vectorised over ``psi``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class PistonMotion:
    """Piston and connecting-rod motion of one cylinder.

    Attributes
    ----------
    x, v, a : ndarray
        Piston displacement from top dead centre towards the crank (m), its velocity (m/s) and
        acceleration (m/s^2).
    beta, beta_dot, beta_ddot : ndarray
        Rod angle from the cylinder axis (rad), its angular velocity (rad/s) and angular
        acceleration (rad/s^2); ``sin beta = lam sin psi``.
    """

    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    beta: np.ndarray
    beta_dot: np.ndarray
    beta_ddot: np.ndarray

    def to_dict(self) -> dict:
        return {k: np.asarray(getattr(self, k)) for k in self.__dataclass_fields__}


def check_ratio(lam: float) -> None:
    """Reject a crank-to-rod ratio for which the mechanism cannot turn a full revolution."""
    if not 0.0 <= lam < 1.0:
        raise ValueError(f"crank-to-rod ratio lambda = r/l must be in [0, 1), got {lam}")


def exact_motion(psi, r: float, lam: float, omega: float) -> PistonMotion:
    """Exact piston and rod motion (seed 000, eqs. 1 and 3).

    Parameters
    ----------
    psi : array_like
        Crank angle from top dead centre (rad).
    r : float
        Crank radius (m).
    lam : float
        Crank-to-rod length ratio ``r / l``, in [0, 1).
    omega : float
        Crank angular speed (rad/s), constant.

    Returns
    -------
    PistonMotion
    """
    check_ratio(lam)
    psi = np.asarray(psi, dtype=float)
    s, c = np.sin(psi), np.cos(psi)
    root = np.sqrt(1.0 - (lam * s) ** 2)
    x = r * ((1.0 - c) + (1.0 - root) / lam) if lam > 0 else r * (1.0 - c)
    v = omega * r * (s + lam * s * c / root)
    a = omega**2 * r * (c + lam * (c * c - s * s) / root + lam**3 * (s * c) ** 2 / root**3)
    beta = np.arcsin(lam * s)
    beta_dot = lam * omega * c / root
    beta_ddot = -lam * (1.0 - lam**2) * omega**2 * s / root**3
    return PistonMotion(x, v, a, beta, beta_dot, beta_ddot)


def series_motion(psi, r: float, lam: float, omega: float) -> PistonMotion:
    """Second-order series of the piston motion (seed 000, eq. 2); rod terms to first order in lam.

    The neglected terms are O(lam^3) relative to ``r`` (``r omega``, ``r omega^2``).
    """
    check_ratio(lam)
    psi = np.asarray(psi, dtype=float)
    s, c = np.sin(psi), np.cos(psi)
    x = r * ((1.0 - c) + lam * (1.0 - np.cos(2 * psi)) / 4.0)
    v = omega * r * (s + lam * np.sin(2 * psi) / 2.0)
    a = omega**2 * r * (c + lam * np.cos(2 * psi))
    beta = lam * s
    beta_dot = lam * omega * c
    beta_ddot = -lam * omega**2 * s
    return PistonMotion(x, v, a, beta, beta_dot, beta_ddot)


def kinematic_ratio(psi, r: float, lam: float):
    """``dx/dpsi`` (m/rad), the lever arm that turns a piston force into crank torque."""
    check_ratio(lam)
    psi = np.asarray(psi, dtype=float)
    s, c = np.sin(psi), np.cos(psi)
    return r * (s + lam * s * c / np.sqrt(1.0 - (lam * s) ** 2))


def acceleration_harmonics(lam: float, max_order: int, n_samples: int = 1024) -> np.ndarray:
    """Fourier coefficients ``A_k`` of the exact piston acceleration.

    ``a(psi) = r omega^2 * sum_k A_k cos(k psi)``, k = 1 .. max_order (the series has no sine
    terms and no constant, and only order 1 among the odd orders: ``A_1 = 1`` exactly). The
    second-order series of seed 000 eq. 2 keeps ``A_1 = 1, A_2 = lam``; the exact values are
    ``A_2 = lam + lam^3/4 + ...``, ``A_4 = -lam^3/4 - ...``.

    Parameters
    ----------
    lam : float
        Crank-to-rod ratio.
    max_order : int
        Highest order wanted (>= 1).
    n_samples : int
        Samples per revolution for the FFT; the coefficients decay like lam^(k-1), so 1024 is
        exact to machine precision for lam < 0.5.

    Returns
    -------
    ndarray, shape (max_order,)
        ``A_1 .. A_max_order``.
    """
    if max_order < 1 or n_samples < 2 * max_order + 2:
        raise ValueError("need max_order >= 1 and n_samples > 2 max_order + 1")
    psi = 2 * np.pi * np.arange(n_samples) / n_samples
    a = exact_motion(psi, 1.0, lam, 1.0).a
    spec = np.fft.rfft(a) * 2.0 / n_samples
    return spec.real[1 : max_order + 1].copy()


def motion_from_harmonics(psi, r: float, omega: float, coefficients) -> np.ndarray:
    """Piston acceleration (m/s^2) rebuilt from harmonics ``A_k`` (see acceleration_harmonics)."""
    psi = np.asarray(psi, dtype=float)
    k = np.arange(1, len(coefficients) + 1)
    return omega**2 * r * np.tensordot(np.cos(np.multiply.outer(psi, k)), coefficients, axes=1)
