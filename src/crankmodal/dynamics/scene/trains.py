"""The ``[dynamics.crank_train]`` keys of multi-throw trains: arrangement, journals, motor.

Turns the validated keys into the typed arguments of :func:`~..model.mechanisms.crank_train`
(an :class:`~crankmodal.mechanism.arrangement.Arrangement`, ``journals_z``, a
:class:`~..model.drive.MotorDrive`) once, relabelling the core's
:class:`~crankmodal.errors.ParameterError` with the scene key. The arrangement is the one the
forced torsion builds from the same ``[mechanism]`` machine
(:func:`~crankmodal.mechanism.arrangement.arrangement_of_machine`, through
:func:`~..model.bridge.cylinders_from_mechanism`).
"""

from __future__ import annotations

from ...errors import ParameterError, SceneError, scene_keys
from ...schema import Field

KEY = "dynamics.crank_train"

#: the keys this module reads (merged into :data:`.keys.CRANK_TRAIN`)
TRAIN_KEYS = {
    "arrangement": Field("str", None, "machine: each [mechanism] cylinder on its throw at the "
                         "throw's phase, gas cycles by the firing order (the arrangement "
                         "[torsion.forced] reads); the default with from_mechanism",
                         choices=("machine",)),
    "cylinder_throws": Field("ints", None, "throw (1-based) of each [mechanism] cylinder "
                             "(default: one throw each, as [torsion.forced])", ge=1),
    "firing_order": Field("ints", None, "four-stroke: cylinders (1-based) in firing order",
                          ge=1),
    "journals_z": Field("floats", None, "rigid crank: axial positions of its two main journals, "
                        "m (cylinders' axial_offset in the same axis): the main-bearing force "
                        "split per journal (main_1, main_2)"),
    "motor_inertia": Field("float", None, "motor rotor inertia, kg m^2: the drive acts on a "
                           "motor coupled to the crank (with coupling_stiffness)", gt=0.0),
    "coupling_stiffness": Field("float", None, "torsional stiffness of the motor coupling, "
                                "N m/rad", gt=0.0),
    "coupling_damping": Field("float", 0.0, "viscous damping across the coupling, N m s/rad",
                              ge=0.0),
}


def check_train_keys(p) -> None:
    """Cross-checks of :data:`TRAIN_KEYS` (SceneError naming the key)."""
    ct = p["crank_train"]
    for key in ("arrangement", "cylinder_throws", "firing_order"):
        if ct.get(key) is not None and not p["from_mechanism"]:
            raise SceneError(f"{KEY}.{key}: the arrangement is the [mechanism] machine's; needs "
                             "dynamics.from_mechanism = true")
    if (ct.get("motor_inertia") is None) != (ct.get("coupling_stiffness") is None):
        given = "motor_inertia" if ct.get("motor_inertia") is not None else "coupling_stiffness"
        other = "coupling_stiffness" if given == "motor_inertia" else "motor_inertia"
        raise SceneError(f"{KEY}.{other}: is required with {given} (a motor drives through a "
                         "coupling: motor_inertia kg m^2 > 0 and coupling_stiffness N m/rad > 0)")
    if ct.get("coupling_damping") and ct.get("motor_inertia") is None:
        raise SceneError(f"{KEY}.coupling_damping: needs motor_inertia and coupling_stiffness")
    jz = ct.get("journals_z")
    if jz is not None and (p.get("flexible") or {}).get("crank") is not None:
        raise SceneError(f"{KEY}.journals_z: is for a rigid crank; a flexible crank's main "
                         "journals are its own (main_1..N)")
    if jz is not None and len(jz) > 2:
        raise SceneError(f"{KEY}.journals_z: a rigid crank on {len(jz)} main journals is "
                         "statically indeterminate (only the crank's flexibility shares the "
                         "load); give two journals, or a flexible crank "
                         "([dynamics.flexible.crank])")


def train_arguments(p, flexible_crank: bool = False) -> dict:
    """``journals_z`` and ``motor`` of :func:`~..model.mechanisms.crank_train` from the keys."""
    from ..model.drive import MotorDrive

    ct = p["crank_train"]
    out = {}
    if ct.get("journals_z") is not None and not flexible_crank:
        out["journals_z"] = list(ct["journals_z"])
    if ct.get("motor_inertia") is not None:
        with scene_keys(KEY):
            out["motor"] = MotorDrive(ct["motor_inertia"], ct["coupling_stiffness"],
                                      ct["coupling_damping"])
    return out


#: the [mechanism] keys of a crank-train cylinder's fields ("{i}": the cylinder's index)
MECHANISM_KEYS = {"rod_length": "mechanism.rod_length", "rod_mass": "mechanism.rod_mass",
                  "rod_inertia": "mechanism.rod_inertia",
                  "rod_com": "mechanism.rod_cg_from_big_end",
                  "piston_mass": "mechanism.cylinders[{i}].piston_mass"}


def _mechanism_key(argument: str | None) -> str | None:
    """The ``[mechanism]`` key of a cylinder's argument ``cylinders[i].<field>``, or None."""
    import re

    m = re.fullmatch(r"cylinders\[(\d+)\]\.(\w+)", argument or "")
    if m is None or m.group(2) not in MECHANISM_KEYS:
        return None
    return MECHANISM_KEYS[m.group(2)].format(i=m.group(1))


def machine_cylinders(p, mechanism_params) -> dict:
    """:func:`~..model.bridge.cylinders_from_mechanism` with the keys' throws and firing order
    (1-based in the scene), errors named by their keys."""
    from ..model.bridge import cylinders_from_mechanism

    ct = p["crank_train"]
    throws = ct.get("cylinder_throws")
    order = ct.get("firing_order")
    try:
        with scene_keys(KEY):
            try:
                return cylinders_from_mechanism(
                    mechanism_params, p["ring_friction_n"],
                    None if throws is None else [t - 1 for t in throws],
                    None if order is None else [c - 1 for c in order])
            except ParameterError as exc:  # a cylinder's value comes from [mechanism]
                key = _mechanism_key(exc.argument)
                if key is None:
                    raise
                raise SceneError(f"{key}: {exc.text}") from None
    except SceneError as exc:
        if "does not fit in one working cycle" not in str(exc):
            raise
        # a permutation that does not fit: the cylinders' angles are the other half (as
        # [torsion.forced] says it)
        raise SceneError(f"{exc} -- check the firing order against "
                         "mechanism.cylinders[i].throw_angle_deg and bank_angle_deg") from None


def check_arrangement(p, scene) -> None:
    """At check time, before any stage runs: the ``[mechanism]`` machine's arrangement with the
    keys' throws and firing order (SceneError naming the key), so nothing is written for a
    scene the run would refuse."""
    ct = p["crank_train"]
    if not p["from_mechanism"] or (ct.get("cylinder_throws") is None
                                   and ct.get("firing_order") is None):
        return
    from ...mechanism.stage import validate as validate_mechanism

    machine_cylinders(p, validate_mechanism(scene.sections["mechanism"], scene))
