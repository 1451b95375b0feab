"""The arrangement of a multi-throw machine: which cylinder works on which throw, and when it fires.

A crank train is a row of throws (crankpins) along the shaft; each throw carries one or more
cylinders (inline: one; V: two rods on one pin at their bank angles; opposed: throws 180 deg
apart). The :class:`Arrangement` says, per cylinder, its throw and its bank angle, per throw its
phase angle, and for a four-stroke engine the firing order. It is plain data: the ``[torsion]``
forced response reads it to put each cylinder's tangential effort on its throw, and a later
multi-throw dynamics stage can read the same object.

Angles follow the package convention (see :mod:`crankmodal.mechanism`): a cylinder's crank angle
from its own top dead centre is ``psi = theta + gamma - phi`` (``theta`` the reference crank
angle, ``gamma`` its throw's phase ahead of the reference, ``phi`` its bank angle). Its top dead
centres are at ``theta = phi - gamma (mod 2 pi)``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Arrangement:
    """Cylinders on throws, throw phases and firing order.

    Attributes
    ----------
    throw_angles : tuple of float
        Phase of each throw ahead of the reference crank (rad), one per throw.
    cylinder_throws : tuple of int
        0-based throw of each cylinder.
    bank_angles : tuple of float
        Cylinder axis of each cylinder from +y towards +x (rad).
    cycle_revolutions : int
        Crank revolutions per working cycle: 1 (compressor, two-stroke) or 2 (four-stroke).
    firing_order : tuple of int or None
        0-based cylinders in firing order (four-stroke only); ``None``: the cylinders' own cycle
        phases stand.

    Raises
    ------
    ParameterError
        Naming ``cylinder_throws`` (wrong length, a throw that does not exist),
        ``bank_angles`` (wrong length), ``cycle_revolutions`` or ``firing_order`` (not a
        permutation of the cylinders; given for a one-revolution cycle).
    """

    throw_angles: tuple
    cylinder_throws: tuple
    bank_angles: tuple
    cycle_revolutions: int = 1
    firing_order: tuple | None = None

    def __post_init__(self):
        n_thr, n_cyl = len(self.throw_angles), len(self.cylinder_throws)
        if n_thr < 1:
            raise ParameterError("throw_angles", "needs at least one throw")
        if len(self.bank_angles) != n_cyl:
            raise ParameterError("bank_angles", f"needs one angle per cylinder ({n_cyl}), "
                                 f"got {len(self.bank_angles)}")
        for i, t in enumerate(self.cylinder_throws):
            if not (isinstance(t, (int, np.integer)) and 0 <= t < n_thr):
                raise ParameterError(f"cylinder_throws[{i}]",
                                     f"must be a throw 1..{n_thr}, got {_one_based(t)}")
        if self.cycle_revolutions not in (1, 2):
            raise ParameterError("cycle_revolutions", f"must be 1 or 2, got {self.cycle_revolutions!r}")
        if self.firing_order is not None:
            order = list(self.firing_order)
            if sorted(order) != list(range(n_cyl)):
                raise ParameterError(
                    "firing_order", f"must be a permutation of the cylinders 1..{n_cyl}, "
                    f"got {[_one_based(c) for c in order]}")
            if self.cycle_revolutions != 2:
                raise ParameterError("firing_order", "applies to a four-stroke (720 deg) cycle; "
                                     "in a one-revolution cycle the throws fix the firing")

    @property
    def n_cylinders(self) -> int:
        return len(self.cylinder_throws)

    @property
    def n_throws(self) -> int:
        return len(self.throw_angles)

    def cylinder_throw_angles(self) -> np.ndarray:
        """Throw phase of each cylinder's crankpin (rad)."""
        return np.asarray(self.throw_angles, float)[list(self.cylinder_throws)]

    def top_dead_centres(self) -> np.ndarray:
        """Reference crank angle of each cylinder's first top dead centre, in [0, 2 pi) (rad)."""
        return np.mod(np.asarray(self.bank_angles, float) - self.cylinder_throw_angles(), TWO_PI)

    def firing_angles(self) -> np.ndarray:
        """Reference crank angle at which each cylinder fires, in [0, 2 pi x cycle) (rad).

        With a firing order, the first cylinder fires at its first top dead centre and each
        following one at its first top dead centre after the one before (so the intervals follow
        from the throw and bank angles: 180 deg for an inline four 1-3-4-2, 120 deg for an inline
        six 1-5-3-6-2-4). Without one, every cylinder fires at its first top dead centre.
        """
        tdc = self.top_dead_centres()
        if self.firing_order is None:
            return tdc
        fire = np.empty(self.n_cylinders)
        last = None
        for c in self.firing_order:
            a = tdc[c]
            if last is not None:
                a = a + TWO_PI * math.ceil((last - a) / TWO_PI + 1e-9)
                while a <= last + 1e-9:
                    a += TWO_PI
            fire[c] = a
            last = a
        first = fire[self.firing_order[0]]
        span = TWO_PI * self.cycle_revolutions
        if last - first >= span - 1e-9:
            raise ParameterError(
                "firing_order", "does not fit in one working cycle with these throw and bank "
                f"angles (the last cylinder would fire {math.degrees(last - first):.0f} deg after "
                "the first)")
        return np.mod(fire, span)

    def cycle_phases(self) -> np.ndarray:
        """Each cylinder's ``psi`` at its firing (rad), the ``cycle_phase`` of its Cylinder."""
        span = TWO_PI * self.cycle_revolutions
        psi = self.firing_angles() + self.cylinder_throw_angles() - np.asarray(self.bank_angles)
        return np.mod(np.round(psi / TWO_PI) * TWO_PI, span)

    def apply(self, machine):
        """The machine with each cylinder's throw angle (and, with a firing order, its cycle
        phase) set from this arrangement. ``machine`` is a :class:`~.machine.Machine` with one
        cylinder per arrangement cylinder."""
        if len(machine.cylinders) != self.n_cylinders:
            raise ParameterError("cylinder_throws", f"needs one throw per cylinder "
                                 f"({len(machine.cylinders)}), got {self.n_cylinders}")
        gamma = self.cylinder_throw_angles()
        phases = self.cycle_phases() if self.firing_order is not None else None
        cyls = []
        for i, c in enumerate(machine.cylinders):
            change = {"throw_angle": float(gamma[i])}
            if phases is not None:
                change["cycle_phase"] = float(phases[i])
            cyls.append(dataclasses.replace(c, **change))
        return dataclasses.replace(machine, cylinders=tuple(cyls))

    def to_dict(self) -> dict:
        return {
            "throw_angles_deg": np.degrees(self.throw_angles),
            "cylinder_throws": [t + 1 for t in self.cylinder_throws],
            "bank_angles_deg": np.degrees(self.bank_angles),
            "cycle_revolutions": self.cycle_revolutions,
            "firing_order": None if self.firing_order is None
            else [c + 1 for c in self.firing_order],
            "firing_angles_deg": np.degrees(self.firing_angles()),
        }


def _one_based(v):
    return v + 1 if isinstance(v, (int, np.integer)) else v


def arrangement_of_machine(machine, cylinder_throws=None, firing_order=None,
                           cycle_revolutions: int | None = None) -> Arrangement:
    """The arrangement a :class:`~.machine.Machine` describes.

    Parameters
    ----------
    machine : Machine
        Its cylinders give the bank angles and (per throw) the throw angles.
    cylinder_throws : sequence of int, optional
        0-based throw of each cylinder; default: one throw per cylinder.
    firing_order : sequence of int, optional
        0-based cylinders in firing order (four-stroke).
    cycle_revolutions : int, optional
        Revolutions per working cycle; default the machine's (2 with a four-stroke gas model).
        A measured pressure table of 720 deg makes it 2 whatever the gas model.

    Raises
    ------
    ParameterError
        ``cylinder_throws`` of the wrong length, or cylinders on one throw with different
        throw angles (named ``cylinder_throws[i]``).
    """
    cyl = machine.cylinders
    n = len(cyl)
    throws = list(range(n)) if cylinder_throws is None else [int(t) for t in cylinder_throws]
    if len(throws) != n:
        raise ParameterError("cylinder_throws", f"needs one throw per cylinder ({n}), got {len(throws)}")
    n_thr = max(throws) + 1 if throws else 0
    for i, t in enumerate(throws):
        if t < 0:
            raise ParameterError(f"cylinder_throws[{i}]", f"must be a throw >= 1, got {t + 1}")
    if sorted(set(throws)) != list(range(n_thr)):
        missing = sorted(set(range(n_thr)) - set(throws))
        raise ParameterError("cylinder_throws", f"throws {[m + 1 for m in missing]} carry no cylinder")
    angles = [None] * n_thr
    for i, t in enumerate(throws):
        g = cyl[i].throw_angle
        if angles[t] is None:
            angles[t] = g
        elif abs(math.remainder(g - angles[t], TWO_PI)) > 1e-9:
            raise ParameterError(
                f"cylinder_throws[{i}]", f"cylinder {i + 1} has throw angle {math.degrees(g):g} deg, "
                f"but throw {t + 1} is at {math.degrees(angles[t]):g} deg (cylinders on one throw share "
                "its crankpin)")
    return Arrangement(
        throw_angles=tuple(angles),
        cylinder_throws=tuple(throws),
        bank_angles=tuple(c.bank_angle for c in cyl),
        cycle_revolutions=cycle_revolutions or machine.cycle_revolutions,
        firing_order=None if firing_order is None else tuple(int(c) for c in firing_order),
    )
