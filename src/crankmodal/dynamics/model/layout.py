"""Where each cylinder of a multi-throw crank train sits: its throw, its pin, its top dead centre.

The machine's :class:`~crankmodal.mechanism.arrangement.Arrangement` (the description the
forced torsion reads too) gives per throw its phase ``gamma`` ahead of the reference crank, per
cylinder its throw and bank angle ``phi``, and for a four-stroke engine the firing order. The
dynamics plane measures angles from +x counter-clockwise; the crank turns with ``direction``
(``d = -1`` clockwise, the machines' sense). Then, in the crank's body axes (x along the
reference throw), throw ``t``'s pin lies at the angle ``d gamma_t`` ("ahead in the sense of
rotation"); cylinder ``i``'s axis is at ``pi/2 - phi_i`` (as :meth:`.Cylinder.from_machine`),
and it is at top dead centre when its pin points along its axis::

    theta_tdc,i = (pi/2 - phi_i) - d gamma_t(i)

Its crank angle from top dead centre is ``psi_i = d (theta - theta_tdc,i)``, which is the
mechanism's ``psi = theta_m + gamma - phi`` with ``theta_m = pi/2 - theta`` for ``d = -1``.
With a firing order the gas cycle of cylinder ``i`` starts at its firing top dead centre, its
cycle phase ``c_i`` (a whole number of turns, :meth:`.Arrangement.cycle_phases`) later: the
gas force is read at ``psi_i - c_i = d (theta - (theta_tdc,i + d c_i))``, so the piston load's
``tdc_angle`` is the firing top dead centre ``theta_tdc,i + d c_i``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError

#: tolerance on a cylinder axis against its arrangement bank angle, and on a crank body's pin
#: angles against the throw phases, rad
ANGLE_TOLERANCE = 1e-3


@dataclass(frozen=True)
class ThrowLayout:
    """Per cylinder: its throw, the pin angle in the crank's body axes and its top dead centres.

    Attributes
    ----------
    throws : tuple of int
        0-based throw of each cylinder.
    pin_angles : tuple of float
        Angle of each throw's pin in the crank's body axes (x along the reference throw), rad.
    tdc_angles : tuple of float
        Reference crank angle of each cylinder's top dead centre, rad.
    firing_tdc_angles : tuple of float
        Reference crank angle of each cylinder's firing top dead centre (the start of its gas
        cycle), rad: ``tdc_angles`` plus ``direction`` times its cycle phase.
    cycle_revolutions : int
        Crank revolutions per working cycle (1 or 2).
    """

    throws: tuple
    pin_angles: tuple
    tdc_angles: tuple
    firing_tdc_angles: tuple
    cycle_revolutions: int = 1

    @property
    def n_throws(self) -> int:
        return len(self.pin_angles)


def single_pin_layout(axis_angles) -> ThrowLayout:
    """Every cylinder on one crankpin at the reference (today's crank trains)."""
    axes = tuple(float(a) for a in axis_angles)
    return ThrowLayout(throws=(0,) * len(axes), pin_angles=(0.0,), tdc_angles=axes,
                       firing_tdc_angles=axes)


def throw_layout(arrangement, axis_angles, direction: int) -> ThrowLayout:
    """The layout an arrangement gives cylinders with these axes (dynamics convention).

    Parameters
    ----------
    arrangement : Arrangement
        Throws, phases, cylinders' throws and bank angles, firing order.
    axis_angles : sequence of float
        Each cylinder's axis from +x counter-clockwise, rad (must be ``pi/2 - phi_i``).
    direction : {1, -1}
        Sense of rotation of the crank.

    Raises
    ------
    ParameterError
        ``arrangement`` not an Arrangement, or with another number of cylinders
        (``arrangement.cylinder_throws``); a cylinder whose axis is not its bank angle
        (``cylinders[i].axis_angle``); a firing order that does not fit the cycle
        (``arrangement.firing_order``).
    """
    from ...mechanism.arrangement import Arrangement

    if not isinstance(arrangement, Arrangement):
        raise ParameterError("arrangement", f"must be a crankmodal.mechanism.arrangement."
                             f"Arrangement (arrangement_of_machine), got {arrangement!r:.60}")
    axes = [float(a) for a in axis_angles]
    if arrangement.n_cylinders != len(axes):
        raise ParameterError("arrangement.cylinder_throws", f"places "
                             f"{arrangement.n_cylinders} cylinders; the train has {len(axes)}")
    for i, (a, phi) in enumerate(zip(axes, arrangement.bank_angles)):
        off = np.angle(np.exp(1j * (a - (np.pi / 2 - phi))))
        if abs(off) > ANGLE_TOLERANCE:
            raise ParameterError(f"cylinders[{i}].axis_angle", f"{np.degrees(a):.6g} deg is not "
                                 f"the arrangement's bank angle {np.degrees(phi):.6g} deg "
                                 f"(axis = 90 deg - bank angle: "
                                 f"{np.degrees(np.pi / 2 - phi):.6g} deg)")
    try:
        phases = (arrangement.cycle_phases() if arrangement.firing_order is not None
                  else np.zeros(len(axes)))
    except ParameterError as exc:
        raise ParameterError(f"arrangement.{exc.argument}", exc.text) from None
    gamma = arrangement.cylinder_throw_angles()
    tdc = [a - direction * g for a, g in zip(axes, gamma)]
    fire = [x + direction * c for x, c in zip(tdc, phases)]
    return ThrowLayout(throws=tuple(int(t) for t in arrangement.cylinder_throws),
                       pin_angles=tuple(direction * float(g) for g in arrangement.throw_angles),
                       tdc_angles=tuple(tdc), firing_tdc_angles=tuple(fire),
                       cycle_revolutions=arrangement.cycle_revolutions)


def body_reference_angle(body, main_frame: str, pin_frames, layout: ThrowLayout) -> float:
    """Angle of a crank body's reference throw in its own axes, rad (0 for a rigid crank made
    by :func:`~.mechanisms.crank_train`), from its undeformed pin frames.

    Each cylinder's pin frame must lie at its throw's angle from the reference, within
    :data:`ANGLE_TOLERANCE`, else ParameterError naming ``crank_roles.pins[i]``.
    """
    axis = body.local(main_frame)[0]
    offsets = []
    for i, frame in enumerate(pin_frames):
        arm = body.local(frame)[0] - axis
        if np.hypot(*arm) <= 0.0:
            raise ParameterError(f"crank_roles.pins[{i}]", f"frame {frame!r} lies on the main "
                                 "journals' axis: it is not a crankpin")
        offsets.append(np.arctan2(arm[1], arm[0]) - layout.pin_angles[layout.throws[i]])
    ref = float(offsets[0])
    for i, o in enumerate(offsets):
        dev = np.angle(np.exp(1j * (o - ref)))
        if abs(dev) > ANGLE_TOLERANCE:
            raise ParameterError(f"crank_roles.pins[{i}]", f"frame {pin_frames[i]!r} is "
                                 f"{np.degrees(dev):+.4g} deg off its throw "
                                 f"{layout.throws[i] + 1}'s phase (the arrangement's throw "
                                 "angles and the crank body's pins do not match)")
    return float(np.angle(np.exp(1j * ref)))
