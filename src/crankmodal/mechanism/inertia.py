"""Inertia forces and moments of a multi-cylinder crank mechanism (seed 000, Sec. 2.2.1-2.2.2).

Forces are d'Alembert forces on the frame, as 2-vectors ``(F_x, F_y)`` in the last axis;
moments are about the centre of symmetry, as the vector ``(M_x, M_y)`` of ``b e_z x F``.
See the package docstring for the angle conventions.
"""

from __future__ import annotations

import numpy as np


def direction(angle):
    """Unit vector at ``angle`` from +y towards +x: ``(sin, cos)``, shape ``angle.shape + (2,)``."""
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.sin(angle), np.cos(angle)], axis=-1)


def normal(angle):
    """Unit vector 90 deg behind :func:`direction`: ``(cos, -sin)``."""
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), -np.sin(angle)], axis=-1)


def reciprocating_force(mass, acceleration, bank_angle):
    """Inertia force of a reciprocating mass on the frame (N), vector ``m a e``.

    ``acceleration`` is the piston acceleration along x (towards the crank), so ``-m * accel``
    along the cylinder axis ``e`` (pointing to the head) is ``+m a e``.
    """
    return (np.asarray(mass) * np.asarray(acceleration))[..., None] * direction(bank_angle)


def rotating_force(mass_radius, omega: float, crank_angle):
    """Centrifugal force of a rotating unbalance ``m r`` (kg m) on the frame (N), vector."""
    return (mass_radius * omega**2) * direction(crank_angle)


def moment(force, axial_offset):
    """Moment ``b e_z x F`` about the centre of symmetry (N m): ``(-b F_y, b F_x)``."""
    f = np.asarray(force)
    return axial_offset * np.stack([-f[..., 1], f[..., 0]], axis=-1)


def order_forces(psi, bank_angles, masses, r: float, omega: float, coefficients):
    """Reciprocating inertia force of each order and each cylinder (seed 000, Table 1).

    Parameters
    ----------
    psi : ndarray, shape (n_theta, n_cyl)
        Crank angle of each cylinder from its top dead centre (rad).
    bank_angles, masses : ndarray, shape (n_cyl,)
        Cylinder axes (rad) and reciprocating masses (kg).
    r, omega : float
        Crank radius (m), crank speed (rad/s).
    coefficients : sequence of float
        ``A_k`` of the acceleration series, k = 1.. (``[1, lam]`` for seed 000's Table 1).

    Returns
    -------
    ndarray, shape (n_orders, n_theta, n_cyl, 2)
        ``m_s r omega^2 A_k cos(k psi) e`` per order and cylinder.
    """
    psi = np.asarray(psi, dtype=float)
    k = np.arange(1, len(coefficients) + 1)[:, None, None]
    amp = np.asarray(coefficients)[:, None, None] * np.asarray(masses) * r * omega**2
    scal = amp * np.cos(k * psi[None])
    return scal[..., None] * direction(np.asarray(bank_angles))[None, None]


def rotating_components(theta, force):
    """Split a once-per-revolution force into parts turning with and against the crank.

    Parameters
    ----------
    theta : ndarray, shape (n,)
        Crank angles sampling whole revolutions uniformly (rad).
    force : ndarray, shape (n, 2)

    Returns
    -------
    forward, backward : complex
        Amplitudes (N) in the complex form ``F_y + i F_x`` such that the first-order part of
        the force is ``forward e^{i theta} + backward e^{-i theta}``: the forward part turns
        with the crank, the backward part against it.
    """
    z = force[:, 1] + 1j * force[:, 0]
    return np.mean(z * np.exp(-1j * theta)), np.mean(z * np.exp(1j * theta))


def counterweight(theta, force, omega: float):
    """Counterweight cancelling the forward-turning first-order force.

    Returns
    -------
    mass_radius : float
        Counterweight mass times its radius (kg m).
    angle : float
        Its direction relative to the reference crank (rad, same sense as theta); pi means
        opposite the crankpin.
    residual : float
        Amplitude of what is left of the first-order force: the backward-turning part (N).
    """
    fwd, bwd = rotating_components(theta, force)
    return abs(fwd) / omega**2, float(np.angle(-fwd)) % (2 * np.pi), abs(bwd)


def magnitude_range(vectors):
    """``(max, min)`` over time of the length of a vector history (..., 2)."""
    m = np.hypot(vectors[..., 0], vectors[..., 1])
    return float(m.max()), float(m.min())
