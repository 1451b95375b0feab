"""The machine: crank, rod, cylinders and working process, as plain frozen dataclasses.

Built from the validated ``[mechanism]`` scene table by :func:`machine_from_params`. Angles are
stored in radians, everything else in SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Rod:
    """Connecting rod (all cylinders use the same rod geometry).

    Attributes
    ----------
    length : float
        Centre distance big end - small end (m).
    mass : float
        Rod mass (kg).
    cg_from_big_end : float
        Distance of the centre of mass from the big-end (crankpin) centre (m).
    inertia : float
        Moment of inertia about the centre of mass, about an axis parallel to the crank (kg m^2).
    """

    length: float
    mass: float
    cg_from_big_end: float
    inertia: float

    @property
    def reciprocating_mass(self) -> float:
        """Exact two-mass split: share at the small end, ``m L1 / l`` (kg).

        The two point masses keep the rod's mass and centre of mass, so their inertia force is
        the rod's exactly; only the inertia couple needs :attr:`inertia_defect` (seed 000's rule
        of thumb ``(0.3..0.4) m_d`` is this with ``L1 = (0.3..0.4) l``).
        """
        return self.mass * self.cg_from_big_end / self.length

    @property
    def rotating_mass(self) -> float:
        """Exact two-mass split: share at the big end, ``m (l - L1) / l`` (kg)."""
        return self.mass - self.reciprocating_mass

    @property
    def inertia_defect(self) -> float:
        """``J - m L1 (l - L1)`` (kg m^2): what the two point masses get wrong (usually < 0)."""
        l1 = self.cg_from_big_end
        return self.inertia - self.mass * l1 * (self.length - l1)


@dataclass(frozen=True)
class Cylinder:
    """One cylinder line of a machine: where its axis lies, its piston and its gas process.

    The multibody dynamics takes the same cylinder as :class:`crankmodal.dynamics.Cylinder`
    (built from this one by :meth:`crankmodal.dynamics.Cylinder.from_machine`: the axis in the
    dynamics' angle convention, with the rod it drives and its gas force as a function). Not a
    geometric surface (:class:`crankmodal.part.CylindricalSurface`).

    Attributes
    ----------
    bank_angle : float
        Cylinder axis from +y towards +x (rad).
    axial_offset : float
        z position of the cylinder plane from the centre of symmetry (m).
    throw_angle : float
        Angle of this cylinder's crankpin ahead of the reference crank (rad); 0 on a shared pin.
    piston_mass : float
        Piston group (piston, pin, rings, crosshead) (kg).
    bore : float
        Cylinder bore (m).
    suction_pressure, discharge_pressure : float or None
        Nominal stage pressures of a compressor cylinder (Pa, absolute).
    relative_clearance : float or None
        Clearance volume over swept volume of a compressor cylinder.
    cycle_phase : float
        Four-stroke only: crank angle of this cylinder's firing TDC in the cycle (rad).
    """

    bank_angle: float
    axial_offset: float
    throw_angle: float
    piston_mass: float
    bore: float
    suction_pressure: float | None = None
    discharge_pressure: float | None = None
    relative_clearance: float | None = None
    cycle_phase: float = 0.0

    @property
    def area(self) -> float:
        """Piston area (m^2)."""
        return math.pi * self.bore**2 / 4.0


@dataclass(frozen=True)
class CompressorGas:
    """Single-acting compressor cycle of seed 000 Sec. 2.2.3.

    ``valve_timing = "pressure"`` opens the valves where the cylinder pressure reaches the line
    pressures; ``"seed"`` uses fixed gas-cycle angles (compression ends at ``seed_angles[0]``,
    expansion ends at ``seed_angles[1]``, measured from bottom dead centre).
    """

    compression_exponent: float
    expansion_exponent: float
    pressure_coefficient: float
    valve_timing: str = "pressure"
    seed_angles: tuple[float, float] = (math.radians(97.0), math.radians(295.0))
    kind: str = field(default="compressor", init=False)


@dataclass(frozen=True)
class FourStrokeGas:
    """Four-stroke engine pressure of seed 003 Sec. 2 (pressures absolute, Pa; angles rad)."""

    intake_pressure: float
    max_pressure: float
    exhaust_pressure: float
    compression_ratio: float
    compression_exponent: float
    expansion_exponent: float
    constant_pressure_duration: float
    rise_end: float = math.radians(15.0)
    exhaust_opening: float = math.radians(170.0)
    kind: str = field(default="four_stroke", init=False)


@dataclass(frozen=True)
class Friction:
    """Piston friction of seed 000 Sec. 2.2.4.

    ``indicated_power``: ``"seed"`` uses the seed's compressor formula, ``"cycle"`` the p-V area.
    """

    mechanical_efficiency: float
    reciprocating_share: float = 0.6
    indicated_power: str = "seed"


@dataclass(frozen=True)
class Machine:
    """A crank mechanism with any number of cylinders.

    Attributes
    ----------
    name : str
    crank_radius : float
        (m)
    rod : Rod
    speed_rpm : float
        Constant crank speed (rev/min).
    cylinders : tuple of Cylinder
    gas : CompressorGas, FourStrokeGas or None
    friction : Friction or None
    atmospheric_pressure : float
        Pressure on the crankcase side of the pistons (Pa).
    crank_unbalance : float
        Mass times radius of the crankshaft's own unbalance, in the crankpin direction (kg m).
    """

    name: str
    crank_radius: float
    rod: Rod
    speed_rpm: float
    cylinders: tuple[Cylinder, ...]
    gas: CompressorGas | FourStrokeGas | None = None
    friction: Friction | None = None
    atmospheric_pressure: float = 1.0e5
    crank_unbalance: float = 0.0

    @property
    def ratio(self) -> float:
        """Crank-to-rod ratio ``lambda = r / l``."""
        return self.crank_radius / self.rod.length

    @property
    def omega(self) -> float:
        """Crank speed (rad/s)."""
        return self.speed_rpm * math.pi / 30.0

    @property
    def stroke(self) -> float:
        """Piston stroke (m)."""
        return 2.0 * self.crank_radius

    @property
    def cycle_revolutions(self) -> int:
        """Crank revolutions per working cycle (2 for a four-stroke engine)."""
        return 2 if isinstance(self.gas, FourStrokeGas) else 1


def machine_from_params(p: dict, name: str = "machine") -> Machine:
    """Build a :class:`Machine` from validated ``[mechanism]`` parameters (see ``stage.py``)."""
    r = p["crank_radius"]
    length = p["rod_length"] if p["rod_length"] is not None else r / p["rod_ratio"]
    rod = Rod(length=length, mass=p["rod_mass"], cg_from_big_end=p["rod_cg_from_big_end"],
              inertia=p["rod_inertia"])
    cyls = tuple(
        Cylinder(
            bank_angle=math.radians(c["bank_angle_deg"]),
            axial_offset=c["axial_offset"],
            throw_angle=math.radians(c["throw_angle_deg"]),
            piston_mass=c["piston_mass"],
            bore=c["bore"],
            suction_pressure=c["suction_pressure"],
            discharge_pressure=c["discharge_pressure"],
            relative_clearance=c["relative_clearance"],
            cycle_phase=math.radians(c["cycle_phase_deg"]),
        )
        for c in p["cylinders"]
    )
    g = p["gas"]
    gas = None
    if g["model"] == "compressor":
        gas = CompressorGas(
            compression_exponent=g["compression_exponent"],
            expansion_exponent=g["expansion_exponent"],
            pressure_coefficient=g["pressure_coefficient"],
            valve_timing=g["valve_timing"],
            seed_angles=tuple(math.radians(a) for a in g["seed_angles_deg"]),
        )
    elif g["model"] == "four_stroke":
        gas = FourStrokeGas(
            intake_pressure=g["intake_pressure"],
            max_pressure=g["max_pressure"],
            exhaust_pressure=g["exhaust_pressure"],
            compression_ratio=g["compression_ratio"],
            compression_exponent=g["compression_exponent"],
            expansion_exponent=g["expansion_exponent"],
            constant_pressure_duration=math.radians(g["constant_pressure_duration_deg"]),
            rise_end=math.radians(g["rise_end_deg"]),
            exhaust_opening=math.radians(g["exhaust_opening_deg"]),
        )
    f = p["friction"]
    friction = None
    if f["mechanical_efficiency"] is not None:
        friction = Friction(
            mechanical_efficiency=f["mechanical_efficiency"],
            reciprocating_share=f["reciprocating_share"],
            indicated_power=f["indicated_power"],
        )
    return Machine(
        name=name,
        crank_radius=r,
        rod=rod,
        speed_rpm=p["speed_rpm"],
        cylinders=cyls,
        gas=gas,
        friction=friction,
        atmospheric_pressure=p["atmospheric_pressure"],
        crank_unbalance=p["crank_unbalance"],
    )
