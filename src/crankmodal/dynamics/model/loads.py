"""Applied loads: gas force on a piston, piston (ring) friction, a torque on the crank, a
torsional coupling (spring and damper) between two bodies' frames.

Each load adds its generalised force to ``Q`` and returns the power it delivers to the system (W).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


def tabulated_gas_force(angles_deg, forces_n, cycle_deg: float = 360.0) -> Callable:
    """A periodic gas-force function of the cylinder's crank angle from a table.

    Parameters
    ----------
    angles_deg : sequence of float
        Crank angles from the cylinder's top dead centre, degrees, increasing, within one cycle.
    forces_n : sequence of float
        Gas force on the piston crown, N, positive pushing the piston towards the crank.
    cycle_deg : float
        360 (two-stroke, compressor) or 720 (four-stroke engine).

    Returns
    -------
    callable
        ``f(angle_rad) -> N``, linear interpolation, periodic.
    """
    a = np.asarray(angles_deg, float)
    f = np.asarray(forces_n, float)
    period = np.deg2rad(cycle_deg)
    xa = np.deg2rad(a)
    # close the table periodically once (np.interp's period= sorts on every call)
    xe = np.concatenate([[xa[-1] - period], xa, [xa[0] + period]])
    fe = np.concatenate([[f[-1]], f, [f[0]]])

    def gas_force(angle: float) -> float:
        return float(np.interp(angle % period, xe, fe))

    gas_force.table = (xe, fe, period)  # the same table, for the compiled right-hand side
    return gas_force


@dataclass
class PistonLoads:
    """Gas force (function of the cylinder's crank angle) and ring friction on one piston.

    Parameters
    ----------
    piston, frame : body, str
        The piston and its pin frame.
    axis : ndarray, shape (2,)
        Unit cylinder axis, pointing from the crank towards the cylinder head.
    tdc_angle : float
        Crank angle at which this cylinder is at top dead centre, rad.
    crank, crank_frame : body, str
        Where the crank angle is read.
    gas_force : callable or None
        ``f(angle_from_tdc_rad) -> N`` pushing the piston towards the crank.
    friction_force : float
        Magnitude of the ring friction, N, smoothed over ``friction_velocity`` (m/s).
    sense : {1, -1}
        Sense of rotation of the crank; the angle from TDC is ``sense * (theta - tdc_angle)``.
    """

    piston: object
    frame: str
    axis: np.ndarray
    tdc_angle: float
    crank: object
    crank_frame: str
    gas_force: Callable | None = None
    friction_force: float = 0.0
    friction_velocity: float = 0.01
    sense: int = 1

    def forces(self, sysm, t, q, qd, Q) -> float:
        _, J, _ = sysm.frame(self.piston, self.frame, q, qd)
        v = float(self.axis @ (sysm.frame_velocity(self.piston, J, qd)[:2]))
        f = 0.0
        if self.gas_force is not None:
            theta = sysm.frame_pose_only(self.crank, self.crank_frame, q)[2]
            f -= self.gas_force(self.sense * (theta - self.tdc_angle))
        if self.friction_force > 0.0:
            f -= self.friction_force * np.tanh(v / self.friction_velocity)
        if f != 0.0:
            sysm.add_frame_force(Q, self.piston, J, np.array([f * self.axis[0], f * self.axis[1], 0.0]))
        return f * v


@dataclass
class CrankTorque:
    """A constant torque (N m) on the crank (free-speed drive); power returned in W."""

    crank: object
    frame: str
    torque: float

    def forces(self, sysm, t, q, qd, Q) -> float:
        _, J, _ = sysm.frame(self.crank, self.frame, q, qd)
        sysm.add_frame_force(Q, self.crank, J, np.array([0.0, 0.0, self.torque]))
        return self.torque * float(sysm.frame_velocity(self.crank, J, qd)[2])


@dataclass
class TorsionalCoupling:
    """A torsional spring and viscous damper between two frames (a flexible coupling).

    The torque ``T = k (phi_b - phi_a - offset) + c (omega_b - omega_a)`` (N m) acts on frame
    ``frame_a`` of body ``a`` and ``-T`` on frame ``frame_b`` of body ``b``: the coupling pulls
    the two frames' angles together. Its elastic energy ``k tw^2 / 2`` is not part of the
    bodies' energies: the load's power (returned, W) carries it, so the run's energy balance
    closes with it in ``work_loads``.

    Parameters
    ----------
    a, b : body
        The two bodies (e.g. a motor rotor and the crank); either may be a ground.
    frame_a, frame_b : str
        Their frames.
    stiffness : float
        N m/rad, > 0.
    damping : float
        N m s/rad, >= 0.
    offset : float
        Angle of ``b`` relative to ``a`` at which the spring is relaxed, rad.

    Raises
    ------
    ParameterError
        ``stiffness`` <= 0 (named ``coupling_stiffness``), ``damping`` < 0 (named
        ``coupling_damping``) or not finite.
    """

    a: object
    frame_a: str
    b: object
    frame_b: str
    stiffness: float
    damping: float = 0.0
    offset: float = 0.0

    def __post_init__(self):
        from ... import arguments as arg

        self.stiffness = arg.number("coupling_stiffness", self.stiffness, gt=0.0)
        self.damping = arg.number("coupling_damping", self.damping, ge=0.0)
        self.offset = arg.number("offset", self.offset)

    def coupling_torque(self, sysm, q, qd) -> tuple[float, object, object, float, float]:
        """The coupling torque on ``a`` (N m), the frames' Jacobians and angular velocities."""
        pa, Ja, _ = sysm.frame(self.a, self.frame_a, q, qd)
        pb, Jb, _ = sysm.frame(self.b, self.frame_b, q, qd)
        wa = float(sysm.frame_velocity(self.a, Ja, qd)[2])
        wb = float(sysm.frame_velocity(self.b, Jb, qd)[2])
        tq = self.stiffness * (pb[2] - pa[2] - self.offset) + self.damping * (wb - wa)
        return tq, Ja, Jb, wa, wb

    def forces(self, sysm, t, q, qd, Q) -> float:
        tq, Ja, Jb, wa, wb = self.coupling_torque(sysm, q, qd)
        sysm.add_frame_force(Q, self.a, Ja, np.array([0.0, 0.0, tq]))
        sysm.add_frame_force(Q, self.b, Jb, np.array([0.0, 0.0, -tq]))
        return tq * (wa - wb)
