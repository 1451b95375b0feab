"""Take a crank train from ``crankmodal.mechanism``: geometry, masses and gas forces.

``crankmodal.mechanism`` measures angles from +y towards +x (the crank turns clockwise seen
with x to the right and y up); the dynamics plane uses the same x, y axes with angles from +x
counter-clockwise. A mechanism bank angle ``phi`` becomes the axis angle ``90 deg - phi`` and the
crank turns with ``direction = -1``; forces keep their x, y components.
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError
from .loads import tabulated_gas_force
from .mechanisms import Cylinder


def cylinders_from_mechanism(mech_params: dict, ring_friction: float = 0.0,
                             cylinder_throws=None, firing_order=None):
    """Cylinders (with gas-force functions), crank data and the arrangement from validated
    ``[mechanism]`` params.

    The arrangement is :func:`~crankmodal.mechanism.arrangement.arrangement_of_machine`'s, the
    one the forced torsion builds from the same machine: each cylinder on its throw at the
    throw's phase. With a firing order the machine's cycle phases are set from it
    (:meth:`~crankmodal.mechanism.arrangement.Arrangement.apply`) and each gas force is
    tabulated against the crank angle from the cylinder's firing top dead centre, which is
    where :func:`~.mechanisms.crank_train` reads it (:mod:`.layout`).

    Parameters
    ----------
    mech_params : dict
        Validated ``[mechanism]`` parameters.
    ring_friction : float
        Coulomb ring friction force per piston, N.
    cylinder_throws, firing_order : sequence of int, optional
        0-based, as :func:`~crankmodal.mechanism.arrangement.arrangement_of_machine` takes
        them (default, as there: one throw per cylinder; no firing order).

    Returns
    -------
    dict
        ``crank_radius`` (m), ``cylinders`` (list of :class:`Cylinder`), ``direction`` (-1),
        ``speed_rpm``, ``crank_unbalance`` (kg m), ``arrangement`` (Arrangement).

    Raises
    ------
    ParameterError
        Naming ``cylinder_throws`` or ``firing_order`` (not a permutation of the cylinders,
        a throw that does not exist, cylinders on one throw at different angles).
    """
    from ...mechanism.analysis import analyse
    from ...mechanism.arrangement import arrangement_of_machine
    from ...mechanism.machine import machine_from_params

    m = machine_from_params(mech_params)
    arrangement = arrangement_of_machine(m, cylinder_throws, firing_order)
    if arrangement.firing_order is not None:
        arrangement.firing_angles()  # the order against the angles, checked here
        m = arrangement.apply(m)
    phases = (arrangement.cycle_phases() if arrangement.firing_order is not None
              else np.zeros(len(m.cylinders)))
    res = analyse(m, n_per_rev=720)
    cycle = 360.0 * m.cycle_revolutions
    out = []
    for i, c in enumerate(m.cylinders):
        # the mechanism's psi (from top dead centre), less the cycle phase crank_train adds
        ang = np.mod(np.degrees(res.psi[:, i] - phases[i]), cycle)
        order = np.argsort(ang)
        ang, force = ang[order], np.asarray(res.gas_force)[order, i]
        gas = tabulated_gas_force(ang, force, cycle) if m.gas is not None else None
        try:
            out.append(Cylinder.from_machine(m, c, gas_force=gas, ring_friction=ring_friction))
        except ParameterError as exc:  # which cylinder of the machine
            raise ParameterError(f"cylinders[{i}].{exc.argument}", exc.text) from None
    return {"crank_radius": m.crank_radius, "cylinders": out, "direction": -1,
            "speed_rpm": m.speed_rpm, "crank_unbalance": m.crank_unbalance,
            "arrangement": arrangement}
