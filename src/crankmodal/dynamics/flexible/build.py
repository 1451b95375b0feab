"""Planar flexible bodies for crank trains and four-bars, made from reduced (flexbody) files.

The part → reduced body pipeline is :mod:`crankmodal.reduction.parts`; :func:`reduced_part`
here is that pipeline with messages naming the ``[dynamics.flexible]`` table's keys. Bodies:

- crank (:func:`crank_body`): any number of throws (:func:`crank_throws`: the crankpin bands
  grouped by their pin axis and the main journals between them, in axial order from the free
  end). Frames ``main_<j>`` one per main journal in axial order (j from 1), ``pin_<i>`` the
  crankpin band carrying cylinder ``i`` (on its throw, the band nearest its rod row), ``drive``
  (the flywheel end face if the part has one, else the first journal); body axes turned so that
  the frame angle is the crank angle of throw 1 (its pin along +x), with the two rigid tilts (a
  shaft held at two or more journals).
- rod (:func:`rod_body`): ``big`` and ``small`` (the bores), body x axis from the big to the
  small end.
- four-bar link (:func:`link_body`): its two joints (crank ``A``/``B``, coupler ``B``/``C``,
  rocker ``D``/``C``), body x axis from the first to the second; from a file, or a prismatic
  bar between two pins (:func:`~crankmodal.reduction.parts.reduced_bar`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ...errors import ParameterError
from ...reduction import parts
from ...reduction.parts import (cached_flexbody, check_bar, crank_interface_specs,  # noqa: F401
                                flexbody_cache_dir, reduced_bar)

#: relative tolerance on the crank radius and rod length a reduced body must match
GEOMETRY_TOLERANCE = 0.01
#: tolerance on a throw's phase against the one the caller expects, degrees
PHASE_TOLERANCE_DEG = 1.0


def flexible_table(part: str) -> str:
    """The ``[dynamics.flexible]`` table that reduces a machine's ``part`` (messages)."""
    return f"dynamics.flexible.{'crank' if part == 'crankshaft' else 'rods'}"


def check_part(machine: str, part: str, spec: dict):
    """:func:`crankmodal.reduction.parts.check_part` with errors naming the
    ``[dynamics.flexible]`` table's keys (``dynamics.flexible.crank.mesh_size``)."""
    return parts.check_part(machine, part, spec, key=flexible_table(part))


def reduced_part(machine: str, part: str, spec: dict, n_rods: int = 1) -> Path:
    """:func:`crankmodal.reduction.parts.reduced_part` with errors naming the
    ``[dynamics.flexible]`` table's keys: the flexbody file of a machine's crankshaft or rod,
    reduced once and cached."""
    return parts.reduced_part(machine, part, spec, n_rods=n_rods, key=flexible_table(part))


def _in_plane_angle(v) -> float:
    return float(np.arctan2(v[1], v[0]))


def read(source):
    """``(reduced body, path)`` of a flexbody file path, or of a body read already (so that
    several planar bodies are made from one reading)."""
    from ...reduction.io import load_flexbody

    if isinstance(source, (str, Path)):
        return load_flexbody(source), Path(source)
    return source, Path(source.info.get("file", source.name))


def _centres(fb) -> dict:
    return {n: np.asarray(c, float) for n, c in zip(fb.interface_names, fb.interface_centres)}


def body_spec(spec, link: bool = False) -> dict:
    """A builder's ``spec`` checked by the ``[dynamics.flexible.<body>]`` keys' rules, with
    their defaults filled in (``damping_ratio`` 0.02, every stored in-plane mode).

    Parameters
    ----------
    spec : dict or None
        Any of the table's keys (:data:`~.scene_keys.FLEX_BODY`; a four-bar link's,
        :data:`~.scene_keys.LINK_BODY`, with ``link``); None is ``{}``.

    Raises
    ------
    ParameterError
        Naming ``spec.<key>``: an unknown key, a value out of its range, or both ``n_modes`` and
        ``cutoff_hz``.
    """
    from ... import arguments as arg
    from ..scene.keys import FLEX_BODY, LINK_BODY

    schema = LINK_BODY if link else FLEX_BODY
    out = arg.table("spec", spec, schema)
    for key, rule in schema.items():
        if key in out and key in ("n_modes", "cutoff_hz", "damping_ratio", "interfaces"):
            out[key] = arg.check(f"spec.{key}", out[key], rule, optional=True)
        out.setdefault(key, rule.default)
    if out["damping_ratio"] is None:
        out["damping_ratio"] = schema["damping_ratio"].default
    if out["n_modes"] is not None and out["cutoff_hz"] is not None:
        raise ParameterError("spec.cutoff_hz", "give either n_modes or cutoff_hz, not both")
    return out


def _source(source):
    """``source`` of a builder: a flexbody file path or a reduced body read already."""
    if not isinstance(source, (str, os.PathLike)) and not hasattr(source, "interface_names"):
        raise ParameterError("source", "must be a crankmodal-flexbody .npz path or a reduced "
                             f"body (load_flexbody, reduce_body), got {source!r:.60}")
    return source


def _rows(row_z) -> list[float]:
    from ... import arguments as arg

    return arg.numbers("row_z", [0.0] if row_z is None else row_z)


def _throw_groups(centres: dict, mains: list, bands: list) -> list[dict]:
    """Crankpin bands grouped into throws: bands between the same two main journals whose pin
    axes coincide (within 1e-3 of the crank radius) are one throw; throws in axial order."""
    axis0 = np.mean([centres[n][:2] for n in mains], axis=0)
    z_mains = np.sort([centres[n][2] for n in mains])
    groups: list[dict] = []
    for n in sorted(bands, key=lambda b: centres[b][2]):
        arm = centres[n][:2] - axis0
        bay = int(np.searchsorted(z_mains, centres[n][2]))
        tol = 1e-3 * float(np.hypot(*arm)) + 1e-9
        for g in groups:
            if g["bay"] == bay and float(np.hypot(*(g["arm"] - arm))) <= tol:
                g["bands"].append(n)
                break
        else:
            groups.append({"bay": bay, "arm": arm, "bands": [n]})
    for g in groups:
        g["z"] = float(np.mean([centres[b][2] for b in g["bands"]]))
    return sorted(groups, key=lambda g: g["z"])


def crank_throws(source) -> list[dict]:
    """The throws of a reduced crankshaft, from its interfaces.

    Parameters
    ----------
    source : str, Path or reduced body
        A ``crankmodal-flexbody`` file of a crankshaft (interfaces ``main_journal_*``,
        ``crankpin_*`` bands), or that body read already.

    Returns
    -------
    list of dict
        Per throw, in axial order from the free end (throw 1 first): ``throw`` (1-based),
        ``phase_deg`` (its pin's angle from throw 1's, about +z, in [0, 360)),
        ``angle_deg`` (from the part's +x axis), ``radius_m`` (shaft axis to pin axis),
        ``z_m`` (axial position of the middle of its crankpin bands, part coordinates, m),
        ``bands`` (its crankpin interfaces in axial order) and ``bands_z_m``.

    Raises
    ------
    ParameterError
        Naming ``source``: not a flexbody, or no ``main_journal_*``/``crankpin_*`` interfaces.
    """
    fb, path = read(_source(source))
    return _throws(_centres(fb), path)[1]


def _throws(centres: dict, path) -> tuple[list, list]:
    mains = sorted((n for n in centres if n.startswith("main_journal")),
                   key=lambda n: centres[n][2])
    bands = [n for n in centres if n.startswith("crankpin")]
    if not mains or not bands:
        raise ParameterError("source", f"{path}: needs main_journal_* and crankpin_* "
                             f"interfaces; has {', '.join(sorted(centres)) or 'none'}")
    groups = _throw_groups(centres, mains, bands)
    a1 = _in_plane_angle(groups[0]["arm"])
    out = []
    for k, g in enumerate(groups, start=1):
        a = _in_plane_angle(g["arm"])
        out.append({"throw": k, "phase_deg": float(np.rad2deg(a - a1) % 360.0),
                    "angle_deg": float(np.rad2deg(a) % 360.0),
                    "radius_m": float(np.hypot(*g["arm"])), "z_m": g["z"],
                    "bands": list(g["bands"]),
                    "bands_z_m": [float(centres[b][2]) for b in g["bands"]]})
    return mains, out


def _cylinder_throws(throws, n_rows, n_throws: int) -> list[int]:
    """Throw of each cylinder: given, or one cylinder per throw, or all on a single throw."""
    from ... import arguments as arg

    if throws is None:
        if n_throws == 1:
            return [1] * (n_rows or 1)
        if n_rows in (None, n_throws):
            return list(range(1, n_throws + 1))
        raise ParameterError("throws", f"the crank has {n_throws} throws and row_z gives "
                             f"{n_rows} cylinders: say which throw carries each cylinder "
                             "(throws = [1-based throw per cylinder])")
    if isinstance(throws, (str, bytes)) or not hasattr(throws, "__len__") or not len(throws):
        raise ParameterError("throws", f"must be a list of throw numbers (1 to {n_throws}), one "
                             f"per cylinder, got {throws!r:.60}")
    out = []
    for i, t in enumerate(throws):
        t = arg.integer(f"throws[{i}]", t)
        if not 1 <= t <= n_throws:
            raise ParameterError(f"throws[{i}]", f"cylinder {i + 1} is on throw {t}; the crank "
                                 f"has {n_throws} throw{'s' if n_throws > 1 else ''} "
                                 f"(1 to {n_throws})")
        out.append(t)
    return out


def _check_layout(info: list, mains: list, path, crank_radius, phases_deg, n_journals) -> None:
    """The file's throws and journals against what the caller expects."""
    from ... import arguments as arg

    for t in info:
        r = t["radius_m"]
        if crank_radius is not None and abs(r / crank_radius - 1) > GEOMETRY_TOLERANCE:
            raise ParameterError("source", f"{path}: its throw {t['throw']} pin is {r:.5g} m "
                                 f"from the main journals' axis, the mechanism's crank radius "
                                 f"is {crank_radius:.5g} m (tolerance {GEOMETRY_TOLERANCE:.0%})")
    if n_journals is not None:
        n = arg.integer("n_journals", n_journals, ge=1)
        if n != len(mains):
            raise ParameterError("n_journals", f"{path}: the crank has {len(mains)} main "
                                 f"journals, expected {n}")
    if phases_deg is not None:
        ph = arg.numbers("phases_deg", phases_deg)
        have = [t["phase_deg"] for t in info]
        if len(ph) != len(info):
            raise ParameterError("phases_deg", f"{path}: the crank has {len(info)} throws at "
                                 f"{_degrees(have)} deg, expected {len(ph)}")
        for k, p in enumerate(ph):
            want = (p - ph[0]) % 360.0
            off = abs((have[k] - want + 180.0) % 360.0 - 180.0)
            if off > PHASE_TOLERANCE_DEG:
                raise ParameterError(f"phases_deg[{k}]", f"{path}: throw {k + 1} is at "
                                     f"{have[k]:.4g} deg from throw 1, expected {want:.4g} "
                                     f"(throws at {_degrees(have)} deg; tolerance "
                                     f"{PHASE_TOLERANCE_DEG:g} deg)")


def _degrees(values) -> str:
    return ", ".join(f"{v:.4g}" for v in values)


def crank_body(source, spec: dict | None = None, row_z=None, crank_radius: float | None = None,
               name: str = "crank", throws=None, phases_deg=None, n_journals: int | None = None):
    """A planar flexible crank from a flexbody file, frames named for a crank train.

    A crank with K throws at their phases and axial positions (:func:`crank_throws`) on N main
    journals: every cylinder's rod sits on a crankpin band of its throw, nearest its row.

    Parameters
    ----------
    source : str, Path or reduced body
        ``crankmodal-flexbody`` file of a crankshaft (interfaces ``main_journal_*``,
        ``crankpin_*`` bands, optionally ``flywheel_end_face``), or that body read already.
    spec : dict, optional
        ``n_modes`` / ``cutoff_hz`` (default: every stored in-plane mode) and
        ``damping_ratio`` (default 0.02), as the ``[dynamics.flexible.crank]`` keys
        (:func:`body_spec`).
    row_z : sequence of float, optional
        Per cylinder, the axial position of its rod row relative to the middle of its throw's
        crankpin, m (default: 0 for each cylinder).
    crank_radius : float or None
        The mechanism's crank radius, m, checked against every throw of the file (±1 %).
    name : str
        The body's name.
    throws : sequence of int, optional
        Per cylinder, the 1-based throw carrying it (axial order from the free end). Default:
        all cylinders on the one throw of a single-throw crank, or one cylinder per throw in
        order when ``row_z`` is not given or has one entry per throw.
    phases_deg : sequence of float, optional
        The throws' phases the caller expects (degrees; only differences count), checked
        against the file's (±1°).
    n_journals : int, optional
        The number of main journals the caller expects, checked against the file.

    Returns
    -------
    body : FlexibleBody
        Frames ``main_1``..``main_N`` (journals in axial order), ``pin_1``..``pin_n`` (one per
        cylinder), ``drive`` and ``main`` (= ``main_1``); ``info["roles"]`` maps each role to
        its interface, ``info["throws"]`` is :func:`crank_throws`' list and
        ``info["cylinder_throws"]`` the throw of each cylinder.
    roles : dict
        ``mains`` (frame names), ``pins`` (one per cylinder), ``drive``: the default of
        :func:`~crankmodal.dynamics.model.mechanisms.crank_train`'s ``crank_roles``.

    Raises
    ------
    ParameterError
        Naming ``spec.<key>``, ``row_z``, ``crank_radius``, ``throws`` (``throws[i]``: a
        cylinder on a throw the crank does not have), ``phases_deg``, ``n_journals`` or
        ``source`` (interfaces missing, a throw's radius off).
    """
    from ... import arguments as arg
    from .body import planar_body

    spec = body_spec(spec)
    rows = None if row_z is None else _rows(row_z)
    crank_radius = arg.number("crank_radius", crank_radius, gt=0.0, optional=True)
    fb, path = read(_source(source))
    centres = _centres(fb)
    mains, info = _throws(centres, path)
    _check_layout(info, mains, path, crank_radius, phases_deg, n_journals)
    cyl = _cylinder_throws(throws, None if rows is None else len(rows), len(info))
    rows = [0.0] * len(cyl) if rows is None else rows
    if len(rows) != len(cyl):
        raise ParameterError("row_z", f"gives {len(rows)} rows for {len(cyl)} cylinders "
                             "(throws); give one per cylinder")
    pins = []
    for t, z in zip(cyl, rows):
        th = info[t - 1]
        dz = [abs(zb - th["z_m"] - z) for zb in th["bands_z_m"]]
        pins.append(th["bands"][int(np.argmin(dz))])
    drive = "flywheel_end_face" if "flywheel_end_face" in centres else mains[0]
    arm1 = np.deg2rad(info[0]["angle_deg"])
    # every stored mode is offered, with its axial kinetic energy: a crank's modes that move
    # mostly axially (flywheel rocking, webs in the throw plane) still move its journals and
    # pins in the plane, and on three or more journals their flexibility decides the split
    with arg.prefixed("spec"):  # planar_body names n_modes: here it is spec's
        body = planar_body(fb, name, n_modes=spec.get("n_modes"),
                           cutoff_hz=spec.get("cutoff_hz"), damping_ratio=spec["damping_ratio"],
                           tilt=len(mains) > 1, orientation=float(arm1), path=path,
                           min_in_plane=0.0, axial_inertia=True)
    roles = {"mains": [], "pins": [], "drive": "drive"}
    for j, n in enumerate(mains, start=1):
        body.alias(f"main_{j}", n)
        roles["mains"].append(f"main_{j}")
    for i, n in enumerate(pins, start=1):
        body.alias(f"pin_{i}", n)
        roles["pins"].append(f"pin_{i}")
    body.alias("drive", drive)
    body.alias("main", mains[0])
    body.info["roles"] = {"mains": mains, "pins": pins, "drive": drive}
    body.info["throws"] = info
    body.info["cylinder_throws"] = cyl
    body.info["mains_z_m"] = [float(centres[n][2]) for n in mains]
    return body, roles


def rod_body(source, spec: dict | None = None, rod_length: float | None = None,
             name: str = "rod_1", z: float = 0.0):
    """A planar flexible rod from a flexbody file (or that body read already, ``source``) with
    ``big_end_bore`` and ``small_end_bore`` interfaces: frames ``big`` and ``small``, body x axis
    from the big to the small end; its length checked against the mechanism's ``rod_length``
    (m, ±1 %). ``spec`` as for :func:`crank_body` (:func:`body_spec`: ``n_modes`` /
    ``cutoff_hz``, ``damping_ratio`` default 0.02); ``z`` the rod's row, m. A bad argument
    raises ParameterError naming it (``spec.damping_ratio``, ``rod_length``, ``source``).

    Parameters
    ----------
    source : str, Path or reduced body
        A ``crankmodal-flexbody`` .npz of a rod, or the body :func:`load_flexbody` read.
    spec : dict, optional
        ``n_modes`` or ``cutoff_hz`` (Hz), ``damping_ratio``.
    rod_length : float, optional
        The mechanism's rod length (m), checked against the bores' distance.
    name : str
        The body's name (``rod_1`` ...).
    z : float
        The rod's row along the crankpin, m.

    Returns
    -------
    FlexibleBody
    """
    from ... import arguments as arg
    from .body import planar_body

    spec = body_spec(spec)
    rod_length = arg.number("rod_length", rod_length, gt=0.0, optional=True)
    z = arg.number("z", z)
    fb, path = read(_source(source))
    c = _centres(fb)
    for bore in ("big_end_bore", "small_end_bore"):
        if bore not in c:
            raise ParameterError("source", f"{path}: no interface {bore!r}; "
                                 f"interfaces: {', '.join(c) or 'none'}")
    d = c["small_end_bore"][:2] - c["big_end_bore"][:2]
    length = float(np.hypot(*d))
    if rod_length is not None and abs(length / rod_length - 1) > GEOMETRY_TOLERANCE:
        raise ParameterError("source", f"{path}: its bores are {length:.5g} m apart, the "
                             f"mechanism's rod length is {rod_length:.5g} m "
                             f"(tolerance {GEOMETRY_TOLERANCE:.0%})")
    with arg.prefixed("spec"):
        body = planar_body(fb, name, n_modes=spec.get("n_modes"),
                           cutoff_hz=spec.get("cutoff_hz"), damping_ratio=spec["damping_ratio"],
                           z=z, orientation=_in_plane_angle(d), path=path)
    body.alias("big", "big_end_bore")
    body.alias("small", "small_end_bore")
    return body


def link_body(source, spec: dict | None = None, length: float | None = None,
              role: str = "coupler", name: str | None = None):
    """A planar flexible four-bar link from a flexbody file (or that body read already).

    Parameters
    ----------
    source : str, Path or reduced body
    spec : dict, optional
        ``n_modes`` / ``cutoff_hz`` / ``damping_ratio`` (defaults as for :func:`crank_body`,
        :func:`body_spec`) and ``interfaces``: the file's two
        interfaces carrying the link's joints, in the order of
        :data:`~.mechanisms.FOUR_BAR_JOINTS` (crank A, B; coupler B, C; rocker D, C); None: the
        file's two interfaces in stored order (it must have exactly two).
    length : float or None
        The mechanism's link length, m, checked against the interfaces' distance (±1 %).
    role : {"crank", "coupler", "rocker"}
    name : str, optional
        Body name (default: ``role``).

    Returns
    -------
    FlexibleBody
        Frames named for its joints (aliases of the interfaces), body x axis from the first
        joint to the second; ``info["roles"]`` maps joint to interface.
    """
    from ... import arguments as arg
    from ..model.mechanisms import FOUR_BAR_JOINTS
    from .body import planar_body

    spec = body_spec(spec, link=True)
    length = arg.number("length", length, gt=0.0, optional=True)
    arg.one_of("role", role, tuple(FOUR_BAR_JOINTS))
    fb, path = read(_source(source))
    c = _centres(fb)
    names = spec.get("interfaces")
    if names is None:
        if len(c) != 2:
            raise ParameterError("interfaces", f"{path}: has {len(c)} interfaces "
                                 f"({', '.join(c) or 'none'}); name the two carrying the "
                                 f"{role}'s joints {' and '.join(FOUR_BAR_JOINTS[role])}")
        names = list(c)
    for n in names:
        if n not in c:
            raise ParameterError("interfaces", f"{path}: no interface {n!r}; interfaces: "
                                 f"{', '.join(c) or 'none'}")
    d = c[names[1]][:2] - c[names[0]][:2]
    dist = float(np.hypot(*d))
    if length is not None and not abs(dist / length - 1) <= GEOMETRY_TOLERANCE:
        raise ParameterError("source", f"{path}: its interfaces {names[0]!r} and "
                             f"{names[1]!r} are {dist:.5g} m apart, the mechanism's {role} "
                             f"length is {length:.5g} m (tolerance {GEOMETRY_TOLERANCE:.0%})")
    with arg.prefixed("spec"):
        body = planar_body(fb, name or role, n_modes=spec.get("n_modes"),
                           cutoff_hz=spec.get("cutoff_hz"), damping_ratio=spec["damping_ratio"],
                           orientation=_in_plane_angle(d), path=path)
    joints = FOUR_BAR_JOINTS[role]
    for j, n in zip(joints, names):
        body.alias(j, n)
    body.info["roles"] = dict(zip(joints, names))
    return body


def rigid_twin(body):
    """The rigid body with a flexible body's mass, inertia and frames (its modes frozen).

    A crank with tilts (held at two or more journals) stays a :class:`~.flexible.FlexibleBody`
    with its tilts and no elastic mode (:meth:`~.flexible.FlexibleBody.frozen`), so that each
    journal's force is still defined; any other body becomes a :class:`~.bodies.RigidBody`
    (the fast path). Rotary inertias attached to its interfaces
    (:meth:`~.flexible.FlexibleBody.attach_inertia`) are kept: frozen, they add to ``J₀``.

    Parameters
    ----------
    body : FlexibleBody

    Returns
    -------
    RigidBody or FlexibleBody
        The twin, with the same name, mass (kg), polar inertia (kg m²) and frames.
    """
    from ..model.bodies import RigidBody

    if body.n_tilt:
        return body.frozen()
    frames = {n: (float(s0[0]), float(s0[1])) for n, (s0, _, _) in body.frames.items()}
    return RigidBody(body.name, body.mass, body.j0 + body.attached_inertia, frames, z=body.z)


__all__ = ["cached_flexbody", "check_bar", "check_part", "crank_body", "crank_interface_specs",
           "crank_throws", "flexbody_cache_dir", "flexible_table", "link_body", "read",
           "reduced_bar", "reduced_part", "rigid_twin", "rod_body"]
