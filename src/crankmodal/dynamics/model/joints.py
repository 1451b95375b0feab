"""Ideal joints and the crank drive as algebraic constraints on interface frames.

Every constraint ``Phi(q, t) = 0`` supplies its value, its Jacobian blocks per body, the
velocity right-hand side ``nu = -Phi_t`` and the acceleration right-hand side
``gamma = -(Jdot qdot) - Phi_tt`` so that ``Phi_q qddot = gamma``. The Lagrange multipliers
``lam`` make ``-Phi_q^T lam`` the constraint forces on the bodies.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass
class Revolute:
    """Pin between frame ``frame_a`` of body ``a`` and ``frame_b`` of body ``b`` (2 equations).

    The multiplier ``lam`` (N) is the force that body ``a`` exerts on body ``b``.

    Parameters
    ----------
    name : str
        The joint's name (its forces are reported under it).
    a, b : body
        A :class:`RigidBody`, :class:`FlexibleBody` or :class:`Ground`.
    frame_a, frame_b : str
        Names of the frames (interfaces) of ``a`` and ``b`` that the pin joins.
    """

    name: str
    a: object
    frame_a: str
    b: object
    frame_b: str
    n_eq = 2

    def blocks(self, sysm, t, q, qd):
        pa, Ja, ba = sysm.frame(self.a, self.frame_a, q, qd)
        pb, Jb, bb = sysm.frame(self.b, self.frame_b, q, qd)
        phi = pa[:2] - pb[:2]
        gamma = -(ba[:2] - bb[:2])
        return phi, [(self.a, Ja[:2]), (self.b, -Jb[:2])], np.zeros(2), gamma


@dataclass
class Prismatic:
    """Slider of body ``a`` (frame ``frame_a``) along a fixed line of the ground (2 equations).

    The line passes through ``origin`` (m) with unit direction ``axis``; the slider keeps the
    orientation ``angle`` (rad). Multipliers: the force (N) across the line the slider exerts on
    the guide, and the moment (N m) it exerts on the guide.

    Parameters
    ----------
    name : str
        The joint's name.
    a : body
        The sliding body (a piston).
    frame_a : str
        Its frame on the line.
    origin : array_like, shape (2,)
        A point of the line, m.
    axis : array_like, shape (2,)
        The line's unit direction.
    angle : float
        The orientation the slider keeps, rad.
    """

    name: str
    a: object
    frame_a: str
    origin: np.ndarray
    axis: np.ndarray
    angle: float = 0.0
    n_eq = 2

    def blocks(self, sysm, t, q, qd):
        pa, Ja, ba = sysm.frame(self.a, self.frame_a, q, qd)
        n = np.array([-self.axis[1], self.axis[0]])
        phi = np.array([n @ (pa[:2] - self.origin), pa[2] - self.angle])
        J = np.vstack([n @ Ja[:2], Ja[2]])
        gamma = -np.array([n @ ba[:2], ba[2]])
        return phi, [(self.a, J)], np.zeros(2), gamma


@dataclass
class SpeedProfile:
    """Prescribed crank angle: constant speed, optionally reached by an ADAMS STEP ramp.

    ``omega(t) = omega * STEP(t, 0, omega_start/omega, ramp_time, 1)``; angle from ``theta0``.
    Units rad, rad/s, s.
    """

    omega: float
    theta0: float = 0.0
    ramp_time: float = 0.0
    omega_start: float = 0.0

    def angle(self, t: float) -> float:
        """Crank angle at ``t`` s, rad."""
        return speed_profile(float(t), *self.table())[0]

    def speed(self, t: float) -> float:
        """Crank speed at ``t`` s, rad/s."""
        return speed_profile(float(t), *self.table())[1]

    def acceleration(self, t: float) -> float:
        """Crank angular acceleration at ``t`` s, rad/s^2."""
        return speed_profile(float(t), *self.table())[2]

    def table(self) -> tuple:
        """``(omega, theta0, ramp_time, omega_start)`` as floats: the row of
        :func:`speed_profile`'s arguments the compiled kernel keeps."""
        return (float(self.omega), float(self.theta0), float(self.ramp_time),
                float(self.omega_start))


@njit(cache=True)
def speed_profile(t, omega, theta0, ramp_time, omega_start):
    """Angle (rad), speed (rad/s) and acceleration (rad/s^2) of a :class:`SpeedProfile` at
    ``t`` s: constant ``omega``, or ``omega_start`` -> ``omega`` by an ADAMS STEP (cubic
    smoothstep of ``t / ramp_time``) over ``ramp_time`` s. The one implementation: the Python
    path's :class:`SpeedProfile` and the compiled kernel both call it."""
    if ramp_time <= 0.0:
        return theta0 + omega * t, omega, 0.0
    w0, dw, T = omega_start, omega - omega_start, ramp_time
    s = min(max(t / T, 0.0), 1.0)
    if t >= T:
        angle = theta0 + w0 * t + dw * (T / 2 + (t - T))
    else:
        angle = theta0 + w0 * t + dw * T * (s**3 - 0.5 * s**4)
    speed = w0 + dw * s * s * (3.0 - 2.0 * s)
    acc = 0.0 if (t >= T or t <= 0.0) else dw * 6.0 * s * (1.0 - s) / T
    return angle, speed, acc


@dataclass
class AngleDrive:
    """Rheonomic constraint ``phi_a(q) - theta(t) = 0`` on frame ``frame_a`` of the crank.

    Its multiplier is minus the drive torque (N m) applied to the crank.
    """

    name: str
    a: object
    frame_a: str
    profile: SpeedProfile
    n_eq = 1

    def blocks(self, sysm, t, q, qd):
        pa, Ja, ba = sysm.frame(self.a, self.frame_a, q, qd)
        phi = np.array([pa[2] - self.profile.angle(t)])
        nu = np.array([self.profile.speed(t)])
        gamma = np.array([-ba[2] + self.profile.acceleration(t)])
        return phi, [(self.a, Ja[2:3])], nu, gamma


def frames_of(c):
    """The (body, frame) pairs a pin, slider or drive constrains."""
    if isinstance(c, Revolute):
        return [(c.a, c.frame_a), (c.b, c.frame_b)]
    return [(c.a, c.frame_a)]
