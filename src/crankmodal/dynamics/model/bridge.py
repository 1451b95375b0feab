"""Take a crank train from ``crankmodal.mechanism``: geometry, masses and gas forces.

``crankmodal.mechanism`` measures angles from +y towards +x (the crank turns clockwise seen
with x to the right and y up); the dynamics plane uses the same x, y axes with angles from +x
counter-clockwise. A mechanism bank angle ``phi`` becomes the axis angle ``90 deg - phi`` and the
crank turns with ``direction = -1``; forces keep their x, y components.
"""

from __future__ import annotations

import numpy as np

from ...errors import SceneError
from .loads import tabulated_gas_force
from .mechanisms import Cylinder


def cylinders_from_mechanism(mech_params: dict, ring_friction: float = 0.0):
    """Cylinders (with gas-force functions) and crank data from validated ``[mechanism]`` params.

    Returns
    -------
    dict
        ``crank_radius`` (m), ``cylinders`` (list of :class:`Cylinder`), ``direction`` (-1),
        ``speed_rpm``, ``crank_unbalance`` (kg m).
    """
    from ...mechanism.analysis import analyse
    from ...mechanism.machine import machine_from_params

    m = machine_from_params(mech_params)
    # checked here, before the analysis, and under the scene's name (Cylinder.from_machine
    # refuses the same cylinder with a ParameterError naming its argument)
    if any(abs(c.throw_angle) > 0.0 for c in m.cylinders):
        raise SceneError("dynamics.from_mechanism: cylinders on separate crank throws are not "
                         "supported yet (throw_angle_deg must be 0)")
    res = analyse(m, n_per_rev=720)
    cycle = 360.0 * m.cycle_revolutions
    out = []
    for i, c in enumerate(m.cylinders):
        ang = np.mod(np.degrees(res.psi[:, i]), cycle)
        order = np.argsort(ang)
        ang, force = ang[order], np.asarray(res.gas_force)[order, i]
        gas = tabulated_gas_force(ang, force, cycle) if m.gas is not None else None
        out.append(Cylinder.from_machine(m, c, gas_force=gas, ring_friction=ring_friction))
    return {"crank_radius": m.crank_radius, "cylinders": out, "direction": -1,
            "speed_rpm": m.speed_rpm, "crank_unbalance": m.crank_unbalance}
