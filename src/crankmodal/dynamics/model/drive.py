"""How a crank train is driven: a prescribed speed at the crank, or a motor through a coupling.

Today's drive prescribes the crank's angle at its drive frame (the flywheel or coupling face),
or applies a constant torque there with the speed free. A :class:`MotorDrive` puts a motor rotor
(a rigid body pinned on the crank axis) between the drive and the crank: the speed (or the
torque) acts on the motor, and a :class:`~.loads.TorsionalCoupling` (stiffness and damping)
carries it to the crank's drive frame. The train then has the torsional modes of motor,
coupling and crank, which a prescribed crank speed suppresses: motor ``J1`` on a rigid crank
``J2`` rings at ``sqrt(k (J1 + J2) / (J1 J2)) / (2 pi)`` Hz (:func:`two_inertia_frequency`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class MotorDrive:
    """A motor rotor coupled to the crank's drive frame by a torsional coupling (SI units).

    Parameters
    ----------
    inertia : float
        Polar moment of inertia of the motor rotor (with the coupling half on its side),
        kg m², > 0.
    coupling_stiffness : float
        Torsional stiffness of the coupling, N m/rad, > 0.
    coupling_damping : float
        Viscous damping across the coupling, N m s/rad, >= 0.

    Raises
    ------
    ParameterError
        Naming ``motor_inertia``, ``coupling_stiffness`` or ``coupling_damping``.

    Examples
    --------
    >>> MotorDrive(0.1, 1.5e4, 6.0).coupling_stiffness
    15000.0
    """

    inertia: float
    coupling_stiffness: float
    coupling_damping: float = 0.0

    def __post_init__(self):
        from ... import arguments as arg

        object.__setattr__(self, "inertia", arg.number("motor_inertia", self.inertia, gt=0.0))
        object.__setattr__(self, "coupling_stiffness",
                           arg.number("coupling_stiffness", self.coupling_stiffness, gt=0.0))
        object.__setattr__(self, "coupling_damping",
                           arg.number("coupling_damping", self.coupling_damping, ge=0.0))


def two_inertia_frequency(j1: float, j2: float, stiffness: float) -> float:
    """Natural frequency of two free rotors joined by a torsional spring, Hz.

    ``f = sqrt(k (J1 + J2) / (J1 J2)) / (2 pi)`` (J in kg m², k in N m/rad).
    """
    return float(np.sqrt(stiffness * (j1 + j2) / (j1 * j2)) / (2.0 * np.pi))
