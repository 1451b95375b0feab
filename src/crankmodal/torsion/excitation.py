"""Tangential effort of each cylinder on its throw, and its orders, from the machine's mechanism.

The torque of a cylinder on the crankshaft over one working cycle comes from
:func:`crankmodal.mechanism.analysis.analyse` (exact kinematics, gas cycle, reciprocating and
rotating masses, rod inertia couple, piston friction): nothing here recomputes it. At constant
speed ``omega`` the cylinder torque splits into a part that does not depend on speed (gas
pressure; Coulomb piston friction, whose amplitude the mechanism fixes from the indicated power
per revolution) and the inertia part, proportional to ``omega^2``::

    T(theta; omega) = T_gas(theta) + omega^2 T_inertia,1(theta)

so two mechanism cycles (with gas at the machine's speed, and without gas at 1 rad/s) give the
excitation at every speed. A measured or digitised cylinder-pressure table replaces the gas model
(:func:`crankmodal.mechanism.gas.tabulated_pressure`; no piston friction then).

Orders: the working cycle lasts ``cycle_revolutions`` turns (2 for four-stroke), so harmonic ``k``
of the cycle is order ``q = k / cycle_revolutions`` of the shaft speed (half orders for
four-stroke). Convention: ``T(theta) = T_mean + sum_q Re(c_q exp(i q theta))``, theta the
reference crank angle (``theta = omega t``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class PressureTable:
    """A measured or digitised cylinder pressure over one closed cycle.

    Attributes
    ----------
    angles : ndarray
        Crank angle from firing TDC (four-stroke) or from top dead centre (rad), strictly
        increasing, the last one cycle after the first.
    pressures : ndarray
        Absolute pressure (Pa), last equal to first.
    cycle_revolutions : int
        1 (360 deg cycle) or 2 (720 deg).

    Raises
    ------
    ParameterError
        ``angle_deg`` not strictly increasing or not spanning one cycle, ``pressure_pa`` of the
        wrong length, negative, or not closed (last != first).
    """

    angles: np.ndarray
    pressures: np.ndarray
    cycle_revolutions: int

    def __post_init__(self):
        a = np.asarray(self.angles, float)
        p = np.asarray(self.pressures, float)
        object.__setattr__(self, "angles", a)
        object.__setattr__(self, "pressures", p)
        if self.cycle_revolutions not in (1, 2):
            raise ParameterError("cycle_deg", "must be 360 or 720")
        if a.ndim != 1 or len(a) < 3:
            raise ParameterError("angle_deg", f"needs at least 3 points, got {a.size}")
        if p.shape != a.shape:
            raise ParameterError("pressure_pa", f"needs one pressure per angle ({len(a)}), got {p.size}")
        if not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0.0):
            i = int(np.argmax(~(np.diff(a) > 0.0))) if np.all(np.isfinite(a)) else 0
            raise ParameterError("angle_deg", f"must be strictly increasing; entry {i + 1} "
                                 f"({math.degrees(a[i + 1]):g} deg) does not exceed entry {i} "
                                 f"({math.degrees(a[i]):g} deg)")
        span = 2.0 * math.pi * self.cycle_revolutions
        if abs(a[-1] - a[0] - span) > 1e-9 * span:
            raise ParameterError(
                "angle_deg", f"must close the cycle: last - first = {math.degrees(span):g} deg, got "
                f"{math.degrees(a[-1] - a[0]):g} deg (repeat the first point one cycle later)")
        if not np.all(np.isfinite(p)) or np.any(p < 0.0):
            raise ParameterError("pressure_pa", "must be absolute pressures >= 0 and finite")
        if abs(p[-1] - p[0]) > 1e-9 * max(abs(p[0]), 1.0):
            raise ParameterError("pressure_pa", f"must close the cycle: last ({p[-1]:g} Pa) must "
                                 f"equal first ({p[0]:g} Pa)")

    def pressure(self, alpha):
        """Absolute pressure (Pa) at crank angles ``alpha`` (rad) of the table's reference."""
        from ..mechanism.gas import tabulated_pressure

        return tabulated_pressure(alpha, self.angles, self.pressures,
                                  2.0 * math.pi * self.cycle_revolutions)


@dataclass(frozen=True)
class CrankEnd:
    """The crank-end chamber of a double-acting (compressor) cylinder.

    The piston rod passes through it, so its working area is the piston area less the rod's;
    its gas cycle is the head end's half a revolution later, on its own displacement
    ``stroke - x``. Its force on the piston points away from the crank.

    Attributes
    ----------
    cylinder : int
        0-based cylinder.
    rod_diameter : float
        Piston-rod diameter, m (< bore).
    relative_clearance : float or None
        Crank-end clearance / its swept volume; default the cylinder's (head-end) value.
    """

    cylinder: int
    rod_diameter: float
    relative_clearance: float | None = None

    def __post_init__(self):
        if not (math.isfinite(self.rod_diameter) and self.rod_diameter > 0):
            raise ParameterError("rod_diameter", f"must be > 0 (m), got {self.rod_diameter!r}")
        if self.relative_clearance is not None and not 0 < self.relative_clearance < 1:
            raise ParameterError("relative_clearance", f"must be in (0, 1), got {self.relative_clearance!r}")


def crank_end_torque(machine, crank_end: CrankEnd, psi, pressure_table=None):
    """Crank torque of a crank-end chamber (N m) at cylinder angles ``psi`` (rad, from its head
    end's top dead centre), from the machine's compressor cycle or a 360 deg pressure table.

    Raises
    ------
    ParameterError
        ``rod_diameter`` not below the bore, ``cylinder`` out of range, or a machine whose gas is
        not a compressor cycle (and no 360 deg table).
    """
    from ..mechanism import forces as fo
    from ..mechanism import gas as ga
    from ..mechanism.kinematics import exact_motion, kinematic_ratio
    from ..mechanism.machine import CompressorGas

    if not 0 <= crank_end.cylinder < len(machine.cylinders):
        raise ParameterError("cylinder", f"must be 1..{len(machine.cylinders)}, got {crank_end.cylinder + 1}")
    c = machine.cylinders[crank_end.cylinder]
    if not crank_end.rod_diameter < c.bore:
        raise ParameterError("rod_diameter", f"must be < the bore ({c.bore:g} m), got {crank_end.rod_diameter:g}")
    area = c.area - math.pi * crank_end.rod_diameter**2 / 4.0
    r, lam = machine.crank_radius, machine.ratio
    stroke = 2.0 * r
    if pressure_table is not None:
        if pressure_table.cycle_revolutions != 1:
            raise ParameterError("cylinder", "a double-acting cylinder needs a 360 deg cycle")
        p = pressure_table.pressure(psi - math.pi)
    elif isinstance(machine.gas, CompressorGas):
        g = machine.gas
        eps = c.relative_clearance if crank_end.relative_clearance is None else crank_end.relative_clearance
        x_ce = stroke - exact_motion(psi, r, lam, 1.0).x  # crank-end displacement from its own TDC
        p = ga.compressor_pressure(psi - math.pi, x_ce, stroke, c.suction_pressure, c.discharge_pressure,
                                   eps, g.compression_exponent, g.expansion_exponent,
                                   g.pressure_coefficient, g.valve_timing, g.seed_angles)
    else:
        raise ParameterError("cylinder", "double acting needs the compressor gas model or a 360 deg "
                             "pressure table")
    return fo.crank_torque(-ga.gas_force(p, area, machine.atmospheric_pressure), kinematic_ratio(psi, r, lam))


@dataclass
class CylinderEfforts:
    """Crank torque of each cylinder over one working cycle, split by speed dependence.

    Attributes
    ----------
    theta : ndarray, shape (n,)
        Reference crank angle over one working cycle (rad), uniform, periodic.
    cycle_revolutions : int
    crank_radius : float
        (m)
    gas_torque : ndarray, shape (n, n_cyl)
        Speed-independent torque on the crank (gas, piston friction) (N m).
    inertia_torque_unit : ndarray, shape (n, n_cyl)
        Inertia torque at 1 rad/s (N m s^2); at ``omega`` it is ``omega^2`` times this.
    cylinder_throws : ndarray of int
        0-based throw of each cylinder.
    """

    theta: np.ndarray
    cycle_revolutions: int
    crank_radius: float
    gas_torque: np.ndarray
    inertia_torque_unit: np.ndarray
    cylinder_throws: np.ndarray

    @property
    def n_cylinders(self) -> int:
        return self.gas_torque.shape[1]

    def torque(self, omega: float) -> np.ndarray:
        """Cylinder torques at speed ``omega`` (rad/s), shape (n, n_cyl), N m."""
        return self.gas_torque + omega**2 * self.inertia_torque_unit

    def tangential_effort(self, omega: float) -> np.ndarray:
        """Tangential force on each crankpin ``T / r`` (N), shape (n, n_cyl)."""
        return self.torque(omega) / self.crank_radius

    def harmonic_indices(self, max_order: float) -> np.ndarray:
        """Cycle harmonics ``k = 1 .. max_order x cycle_revolutions``."""
        kmax = math.floor(max_order * self.cycle_revolutions + 1e-9)
        if kmax < 1:
            raise ParameterError("max_order", f"must be >= {1 / self.cycle_revolutions:g}, got {max_order}")
        if 2 * kmax >= len(self.theta):
            raise ParameterError("max_order", f"needs more samples per cycle than {len(self.theta)}")
        return np.arange(1, kmax + 1)

    def orders(self, max_order: float) -> np.ndarray:
        """Orders ``q = k / cycle_revolutions`` up to ``max_order``."""
        return self.harmonic_indices(max_order) / self.cycle_revolutions

    def cylinder_harmonics(self, max_order: float) -> tuple[np.ndarray, np.ndarray]:
        """Complex order coefficients of the gas part and of the unit inertia part.

        Returns
        -------
        gas, inertia_unit : ndarray, shape (n_orders, n_cyl), complex
            ``c_q`` with ``T = mean + sum Re(c_q exp(i q theta))``; N m and N m s^2.
        """
        k = self.harmonic_indices(max_order)
        n = len(self.theta)
        g = np.fft.rfft(self.gas_torque, axis=0)[k] * (2.0 / n)
        h = np.fft.rfft(self.inertia_torque_unit, axis=0)[k] * (2.0 / n)
        return g, h

    def mean_torque(self, omega: float = 0.0) -> np.ndarray:
        """Mean torque of each cylinder over the cycle (N m); the inertia part's mean is zero."""
        return self.torque(omega).mean(axis=0)


def cylinder_efforts(machine, arrangement=None, pressure_table: PressureTable | None = None,
                     n_per_rev: int = 720, crank_ends=()) -> CylinderEfforts:
    """Each cylinder's crank torque over one working cycle, from the mechanism.

    Parameters
    ----------
    machine : crankmodal.mechanism.machine.Machine
        Its speed is where the gas part is evaluated (the gas part does not depend on speed).
    arrangement : crankmodal.mechanism.arrangement.Arrangement, optional
        Throw angles and firing order applied to the machine's cylinders first.
    pressure_table : PressureTable, optional
        Replaces the machine's gas model for every cylinder (four-stroke: relative to each
        cylinder's firing TDC).
    n_per_rev : int
        Crank-angle samples per revolution.
    crank_ends : sequence of CrankEnd
        Double-acting cylinders: their crank-end chambers' torque is added to the gas part.

    Returns
    -------
    CylinderEfforts
    """
    from .. import arguments as arg
    from ..mechanism import forces as fo
    from ..mechanism import gas as ga
    from ..mechanism.analysis import analyse
    from ..mechanism.kinematics import kinematic_ratio
    from ..mechanism.machine import Machine

    arg.instance("machine", machine, Machine, "a crankmodal.mechanism.machine.Machine")
    n_per_rev = arg.integer("n_per_rev", n_per_rev, ge=36, le=100_000)
    if pressure_table is not None:
        arg.instance("pressure_table", pressure_table, PressureTable, "a PressureTable")
    crank_ends = tuple(arg.instance(f"crank_ends[{i}]", e, CrankEnd, "a CrankEnd") for i, e in enumerate(crank_ends))
    if arrangement is not None:
        machine = arrangement.apply(machine)
        throws = np.asarray(arrangement.cylinder_throws, int)
        cr = arrangement.cycle_revolutions
    else:
        throws = np.arange(len(machine.cylinders))
        cr = machine.cycle_revolutions
    if pressure_table is not None:
        cr = pressure_table.cycle_revolutions
    n = n_per_rev * cr
    theta = 2.0 * math.pi * cr * np.arange(n) / n

    unit = dataclasses.replace(machine, gas=None, friction=None, speed_rpm=30.0 / math.pi)
    inertia = np.tile(analyse(unit, n_per_rev).cylinder_torque, (cr, 1))  # 1 rad/s, one turn

    cyl = machine.cylinders
    if pressure_table is not None:
        gamma = np.array([c.throw_angle for c in cyl])
        phi = np.array([c.bank_angle for c in cyl])
        psi = theta[:, None] + gamma - phi
        phase = np.array([c.cycle_phase for c in cyl]) if cr == 2 else 0.0
        p = pressure_table.pressure(psi - phase)
        area = np.array([c.area for c in cyl])
        force = ga.gas_force(p, area, machine.atmospheric_pressure)
        gas = fo.crank_torque(force, kinematic_ratio(psi, machine.crank_radius, machine.ratio))
    elif machine.gas is None:
        gas = np.zeros_like(inertia)
    else:
        if machine.cycle_revolutions != cr:
            raise ParameterError("cycle_revolutions", f"the machine's gas model has a "
                                 f"{360 * machine.cycle_revolutions} deg cycle, not {360 * cr} deg")
        full = analyse(machine, n_per_rev).cylinder_torque
        gas = full - machine.omega**2 * inertia
    for i, ce in enumerate(crank_ends):
        if ce.cylinder in [e.cylinder for e in crank_ends[:i]]:
            raise ParameterError("cylinder", f"cylinder {ce.cylinder + 1} is listed twice")
        c = cyl[ce.cylinder] if 0 <= ce.cylinder < len(cyl) else None
        psi_c = theta + (c.throw_angle - c.bank_angle if c is not None else 0.0)
        gas[:, ce.cylinder] += crank_end_torque(machine, ce, psi_c, pressure_table)
    return CylinderEfforts(theta=theta, cycle_revolutions=cr, crank_radius=machine.crank_radius,
                           gas_torque=gas, inertia_torque_unit=inertia, cylinder_throws=throws)


def throw_to_rotor_matrix(cylinder_throws, throw_rotors, n_rotors: int) -> np.ndarray:
    """Incidence matrix ``P`` (n_rotors, n_cyl): rotor torque = ``P @`` cylinder torque.

    Parameters
    ----------
    cylinder_throws : sequence of int
        0-based throw of each cylinder.
    throw_rotors : sequence of int
        0-based rotor of each throw.
    n_rotors : int

    Raises
    ------
    ParameterError
        ``throw_rotors`` of the wrong length or naming a rotor that does not exist.
    """
    cylinder_throws = np.asarray(cylinder_throws, int)
    n_thr = int(cylinder_throws.max()) + 1
    if len(throw_rotors) != n_thr:
        raise ParameterError("throw_rotors", f"needs one rotor per throw ({n_thr}), got {len(throw_rotors)}")
    for i, r in enumerate(throw_rotors):
        if not 0 <= int(r) < n_rotors:
            raise ParameterError(f"throw_rotors[{i}]", f"must be a rotor 1..{n_rotors}, got {int(r) + 1}")
    P = np.zeros((n_rotors, len(cylinder_throws)))
    for c, t in enumerate(cylinder_throws):
        P[int(throw_rotors[t]), c] = 1.0
    return P


@dataclass
class RotorExcitation:
    """Harmonic torques on the rotors at any speed: ``F_q(omega) = G_q + omega^2 H_q``.

    Attributes
    ----------
    orders : ndarray, shape (n_orders,)
    gas : ndarray, shape (n_orders, n_rotors), complex
        Speed-independent coefficients (N m), explicit harmonics included.
    inertia_unit : ndarray, shape (n_orders, n_rotors), complex
        Inertia coefficients at 1 rad/s (N m s^2).
    cycle_revolutions : int
    """

    orders: np.ndarray
    gas: np.ndarray
    inertia_unit: np.ndarray
    cycle_revolutions: int

    def at(self, omega) -> np.ndarray:
        """Coefficients at speeds ``omega`` (rad/s, shape (n_speeds,)): (n_speeds, n_orders, n_rotors)."""
        w2 = np.asarray(omega, float)[:, None, None] ** 2
        return self.gas[None] + w2 * self.inertia_unit[None]


def rotor_excitation(n_rotors: int, max_order: float, cycle_revolutions: int,
                     efforts: CylinderEfforts | None = None, throw_rotors=None,
                     harmonics=()) -> RotorExcitation:
    """Collect the machine's cylinder orders on their rotors, plus explicit harmonic torques.

    Parameters
    ----------
    n_rotors : int
    max_order : float
        Highest order kept.
    cycle_revolutions : int
        1 or 2; orders are multiples of ``1 / cycle_revolutions``.
    efforts : CylinderEfforts, optional
    throw_rotors : sequence of int, optional
        0-based rotor of each throw (required with ``efforts``).
    harmonics : sequence of dict
        ``{"rotor": 0-based, "order", "amplitude" (N m), "phase_deg"}``: ``T = A cos(q theta + phase)``.

    Raises
    ------
    ParameterError
        ``harmonics[i].order`` not a multiple of ``1 / cycle_revolutions`` or above ``max_order``,
        ``harmonics[i].rotor`` out of range, ``throw_rotors`` wrong.
    """
    from .. import arguments as arg
    from ..schema import Field

    n_rotors = arg.integer("n_rotors", n_rotors, ge=1)
    cycle_revolutions = arg.one_of("cycle_revolutions", cycle_revolutions, (1, 2))
    max_order = arg.number("max_order", max_order, gt=0.0, le=100.0)
    schema = {"rotor": Field("int", doc="0-based rotor", ge=0), "order": Field("float", doc="order", gt=0.0),
              "amplitude": Field("float", doc="N m", ge=0.0), "phase_deg": Field("float", 0.0, "deg")}
    harmonics = [arg.table_by(f"harmonics[{i}]", h, schema) for i, h in enumerate(harmonics)]
    kmax = math.floor(max_order * cycle_revolutions + 1e-9)
    if kmax < 1:
        raise ParameterError("max_order", f"must be >= {1 / cycle_revolutions:g}, got {max_order}")
    orders = np.arange(1, kmax + 1) / cycle_revolutions
    gas = np.zeros((kmax, n_rotors), complex)
    inertia = np.zeros((kmax, n_rotors), complex)
    if efforts is not None:
        arg.instance("efforts", efforts, CylinderEfforts, "a CylinderEfforts (cylinder_efforts(...))")
        if throw_rotors is None:
            raise ParameterError("throw_rotors", "is required with efforts (0-based rotor of each throw)")
        if efforts.cycle_revolutions != cycle_revolutions:
            raise ParameterError("cycle_revolutions", "differs from the machine's working cycle")
        P = throw_to_rotor_matrix(efforts.cylinder_throws, throw_rotors, n_rotors)
        g, h = efforts.cylinder_harmonics(max_order)
        gas += g @ P.T
        inertia += h @ P.T
    for i, h in enumerate(harmonics):
        k = h["order"] * cycle_revolutions
        if abs(k - round(k)) > 1e-9 or not 1 <= round(k) <= kmax:
            raise ParameterError(f"harmonics[{i}].order", f"must be a multiple of {1 / cycle_revolutions:g} "
                                 f"in [{1 / cycle_revolutions:g}, {max_order:g}], got {h['order']:g}")
        if not 0 <= h["rotor"] < n_rotors:
            raise ParameterError(f"harmonics[{i}].rotor", f"must be 1..{n_rotors}, got {h['rotor'] + 1}")
        gas[round(k) - 1, h["rotor"]] += h["amplitude"] * np.exp(1j * math.radians(h.get("phase_deg", 0.0)))
    return RotorExcitation(orders=orders, gas=gas, inertia_unit=inertia,
                           cycle_revolutions=cycle_revolutions)
