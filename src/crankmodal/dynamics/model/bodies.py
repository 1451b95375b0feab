"""Bodies: coordinates, mass, and interface frames whose motion depends on the coordinates.

A joint never looks inside a body; it asks for an interface frame's pose ``(x, y, phi)``, its
Jacobian with respect to the body coordinates and the velocity-product term ``Jdot qdot``. A
rigid planar body has coordinates ``(x, y, theta)`` of its centre of mass; a later flexible
(Craig-Bampton) body adds modal coordinates and implements the same four methods.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Body(Protocol):
    """What every body gives the dynamics core (SI units; ``q`` and ``qd`` are the body's own
    coordinates and velocities, the first three ``(x, y, θ)`` of its reference frame).

    Joints, clearance joints, drives and loads see only interface frames (``frame_pose``,
    ``frame_jacobian``, ``frame_bias``); :class:`~.system.Multibody` assembles the rest. A body
    with elastic coordinates (:class:`~.flexible.FlexibleBody`) adds ``internal_forces`` (elastic
    and damping forces, moved to the left side), ``strain_energy`` and ``damping_power``.
    """

    name: str
    ndof: int
    frames: dict
    z: float

    def mass_matrix(self, q: np.ndarray) -> np.ndarray: ...

    def velocity_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray: ...

    def gravity_force(self, q: np.ndarray, g: np.ndarray) -> np.ndarray: ...

    def potential_energy(self, q: np.ndarray, g: np.ndarray) -> float: ...

    def kinetic_energy(self, q: np.ndarray, qd: np.ndarray) -> float: ...

    def local(self, frame: str) -> tuple[np.ndarray, float]: ...

    def frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray: ...

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray: ...

    def frame_bias(self, q: np.ndarray, qd: np.ndarray, frame: str) -> np.ndarray: ...


@dataclass
class RigidBody:
    """A rigid body moving in the plane.

    Parameters
    ----------
    name : str
        Name, used in outputs.
    mass : float
        kg.
    inertia : float
        Moment of inertia about the centre of mass, kg m^2.
    frames : dict of str -> (x, y) or (x, y, phi)
        Interface frames in body coordinates (origin at the centre of mass), m and rad.
    z : float
        Axial position of the body's plane (row offset), m; used only for 3D moments.

    Raises
    ------
    ParameterError
        ``mass`` or ``inertia`` not finite and >= 0, a frame not 2 or 3 finite numbers, ``z``
        not finite.
    """

    name: str
    mass: float
    inertia: float
    frames: dict = field(default_factory=dict)
    z: float = 0.0

    ndof = 3

    def __post_init__(self):
        from ... import arguments as arg

        self.mass = arg.number("mass", self.mass, ge=0.0)
        self.inertia = arg.number("inertia", self.inertia, ge=0.0)
        self.z = arg.number("z", self.z)
        frames = arg.table("frames", self.frames, set(self.frames))
        for key, value in frames.items():
            value = arg.numbers(f"frames.{key}", value)
            if len(value) not in (2, 3):
                from ...errors import ParameterError

                raise ParameterError(f"frames.{key}", f"must be (x, y) or (x, y, phi), got "
                                     f"{len(value)} numbers")

    def local(self, frame: str) -> tuple[np.ndarray, float]:
        f = self.frames[frame]
        return np.asarray(f[:2], float), float(f[2]) if len(f) > 2 else 0.0

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Mass matrix, shape (3, 3)."""
        return np.diag([self.mass, self.mass, self.inertia])

    def velocity_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Quadratic velocity forces (zero for centre-of-mass coordinates)."""
        return np.zeros(3)

    def gravity_force(self, q: np.ndarray, g: np.ndarray) -> np.ndarray:
        """Generalised weight for gravity vector ``g`` (m/s^2)."""
        return np.array([self.mass * g[0], self.mass * g[1], 0.0])

    def potential_energy(self, q: np.ndarray, g: np.ndarray) -> float:
        """Gravitational potential energy, J (zero at the origin)."""
        return -self.mass * float(g[0] * q[0] + g[1] * q[1])

    def kinetic_energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """J."""
        return 0.5 * (self.mass * (qd[0] ** 2 + qd[1] ** 2) + self.inertia * qd[2] ** 2)

    def frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Pose ``(x, y, phi)`` of an interface frame in the global plane."""
        s, phi = self.local(frame)
        c, sn = np.cos(q[2]), np.sin(q[2])
        return np.array([q[0] + c * s[0] - sn * s[1], q[1] + sn * s[0] + c * s[1], q[2] + phi])

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """d(pose)/dq, shape (3, 3)."""
        s, _ = self.local(frame)
        c, sn = np.cos(q[2]), np.sin(q[2])
        return np.array([[1.0, 0.0, -sn * s[0] - c * s[1]],
                         [0.0, 1.0, c * s[0] - sn * s[1]],
                         [0.0, 0.0, 1.0]])

    def frame_bias(self, q: np.ndarray, qd: np.ndarray, frame: str) -> np.ndarray:
        """``Jdot qdot`` of an interface frame (the centripetal part of its acceleration)."""
        s, _ = self.local(frame)
        c, sn = np.cos(q[2]), np.sin(q[2])
        w2 = qd[2] ** 2
        return np.array([-w2 * (c * s[0] - sn * s[1]), -w2 * (sn * s[0] + c * s[1]), 0.0])


@dataclass
class Ground:
    """The fixed frame: no coordinates, frames at fixed global poses.

    Parameters
    ----------
    name : str
        Its name in the mechanism.
    frames : dict
        Frame name -> fixed global pose ``(x, y)`` in m, or ``(x, y, angle)`` with the angle in
        rad (where joints attach to the ground).
    z : float
        Axial position (m) of the body's plane, as for the other bodies.
    """

    name: str = "ground"
    frames: dict = field(default_factory=dict)
    z: float = 0.0

    ndof = 0

    def frame_pose(self, q, frame: str) -> np.ndarray:
        f = self.frames[frame]
        return np.array([f[0], f[1], f[2] if len(f) > 2 else 0.0], float)

    def frame_jacobian(self, q, frame: str) -> np.ndarray:
        return np.zeros((3, 0))

    def frame_bias(self, q, qd, frame: str) -> np.ndarray:
        return np.zeros(3)
