"""Flexible crank and rods for a crank train: reduce the machine's parts (cached) and make bodies.

The chain of :mod:`crankmodal.geometry` → :mod:`crankmodal.fem` → :mod:`crankmodal.reduction`
run for one part of a machine file, its Craig–Bampton body stored under
``$CRANKMODAL_CACHE/flexbodies/<key>.npz`` (key: the part's cache key, the material, the
interfaces, the reduction settings and the reduction package's source), then read as a planar
:class:`~.flexible.FlexibleBody` with the frame names a crank train uses:

- crank: ``main_<j>`` one per main journal (j from 1), ``pin_<i>`` the crankpin band carrying rod
  ``i`` (the band whose axial position is nearest the rod's row), ``drive`` (the flywheel end face
  if the part has one, else the first journal); body axes turned so that the frame angle is the
  crank angle (pin along +x), with the two rigid tilts (a shaft held at two journals).
- rod: ``big`` and ``small`` (the bores), body x axis from the big to the small end.
- four-bar link (:func:`link_body`): its two joints (crank ``A``/``B``, coupler ``B``/``C``,
  rocker ``D``/``C``), body x axis from the first to the second; from a file, or a prismatic
  bar between two pins reduced here (:func:`reduced_bar`).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np

from ...errors import ParameterError, SceneError, scene_keys

#: relative tolerance on the crank radius and rod length a reduced body must match
GEOMETRY_TOLERANCE = 0.01


def flexbody_cache_dir() -> Path:
    """``$CRANKMODAL_CACHE/flexbodies`` (default ``~/.cache/crankmodal/flexbodies``)."""
    from ...caches import cache_folder

    return cache_folder("flexbodies")


def cached_flexbody(path: Path, where: str) -> bool:
    """Whether ``path`` holds a sound cached flexbody. A damaged one (truncated, bit-flipped,
    emptied: :func:`~crankmodal.reduction.io.load_flexbody` refuses it) is removed with a
    one-line warning naming it and what is wrong, so that the caller rebuilds it, as
    :mod:`crankmodal.geometry.cache` does for parts."""
    from ...caches import discard_damaged
    from ...errors import InputFileError
    from ...reduction.io import load_flexbody

    if not path.is_file():
        return False
    try:
        load_flexbody(path)
        return True
    except InputFileError as exc:
        why = getattr(exc, "member", "")
        why = f"{why}: {exc.text}" if why else getattr(exc, "text", str(exc))
        discard_damaged(path, f"{where}: the cached flexbody", why)
        return False


def _reduction_source_digest() -> str:
    h = hashlib.sha256()
    for folder in ("reduction", "fem"):
        for path in sorted((Path(__file__).parents[2] / folder).glob("*.py")):
            h.update(path.read_bytes())
    return h.hexdigest()


def crank_interface_specs(regions, rods_per_pin: int) -> list[dict]:
    """Distributing interfaces of a crankshaft part: each main journal, each crankpin region cut
    into ``rods_per_pin`` bands, and the flywheel end face if present."""
    mains = sorted(n for n in regions if n.startswith("main_journal"))
    pins = sorted(n for n in regions if n.startswith("crankpin"))
    if len(mains) < 1 or not pins:
        raise SceneError("dynamics.flexible.crank: the part has no main_journal_* or crankpin_* "
                         f"regions (regions: {', '.join(sorted(regions))})")
    specs = [{"region": n, "kind": "distributing", "segments": 1} for n in mains]
    specs += [{"region": n, "kind": "distributing", "segments": rods_per_pin} for n in pins]
    if "flywheel_end_face" in regions:
        specs.append({"region": "flywheel_end_face", "kind": "distributing", "segments": 1})
    return specs


def check_part(machine: str, part: str, spec: dict) -> tuple[dict, dict]:
    """The validated ``[geometry]`` and ``[material]`` parameters of the part
    :func:`reduced_part` makes, checked before anything is built (the part's lengths, the
    element count of ``mesh_size``, the material); a ``crankmodal check`` refuses what a run
    would. Errors name the ``[dynamics.flexible]`` table's keys
    (``dynamics.flexible.crank.mesh_size``).

    Raises
    ------
    SceneError
    """
    from types import SimpleNamespace

    from ...fem.material_stage import validate as validate_material
    from ...geometry.stage import validate as validate_geometry

    where = f"dynamics.flexible.{'crank' if part == 'crankshaft' else 'rods'}"
    raw = {"machine": machine, "part": part, "fidelity": spec["fidelity"],
           "mesh_size": spec["mesh_size"], "element_order": spec["element_order"]}
    try:
        gp = validate_geometry(raw, SimpleNamespace(sections={"reduction": {}}))
        mp = validate_material({"name": spec["material"]}, None)
    except SceneError as exc:
        text = str(exc)
        for key in ("mesh_size", "element_order", "fidelity"):  # this table's own keys
            text = text.replace(f"geometry.{key}", f"{where}.{key}")
        raise SceneError(text if text.startswith(where) else f"{where}: {text}") from None
    return gp, mp


def reduced_part(machine: str, part: str, spec: dict, n_rods: int = 1) -> Path:
    """The ``crankmodal-flexbody`` file of a machine's part, reduced once and cached.

    Parameters
    ----------
    machine : str
        Machine file name (``geometry/<machine>.toml``).
    part : {"crankshaft", "rod"}
    spec : dict
        Validated ``[dynamics.flexible.<body>]`` keys: ``fidelity``, ``mesh_size`` (m),
        ``element_order``, ``material``, ``fixed_interface_modes``.
    n_rods : int
        Rods on the crank (crankshaft only): each crankpin region is cut into
        ``ceil(n_rods / crankpin regions)`` bands, one interface each.
    """
    from ...fem.assembly import assemble
    from ...fem.material_stage import make_material
    from ...geometry.cache import part_key
    from ...geometry.stage import make_part
    from ...reduction.interfaces import make_interfaces
    from ...reduction.io import save_flexbody
    from ...reduction.reduce import reduce_body
    from ...reduction.stage import interface_specs

    where = f"dynamics.flexible.{'crank' if part == 'crankshaft' else 'rods'}"
    gp, mp = check_part(machine, part, spec)
    desc = {"part": part, "params": gp["part_params"].to_dict(), "fidelity": gp["fidelity"],
            "mesh": {"size": spec["mesh_size"], "order": spec["element_order"]}}
    key_text = json.dumps({"part": part_key(desc), "material": spec["material"],
                           "modes": spec["fixed_interface_modes"], "n_rods": n_rods,
                           "source": _reduction_source_digest(), "format": 1}, sort_keys=True)
    key = hashlib.sha256(key_text.encode()).hexdigest()[:32]
    path = flexbody_cache_dir() / f"{machine}_{part}_{key}.npz"
    if cached_flexbody(path, where):
        return path
    import time

    from ...progress import PhaseTimings

    steps = PhaseTimings(f"{where}: reducing the {part}", 4)
    t0 = time.perf_counter()
    prt, _ = make_part(gp)
    steps["part_s"] = time.perf_counter() - t0
    mat = make_material(mp)
    t0 = time.perf_counter()
    model = assemble(prt, mat)
    steps["assembly_s"] = time.perf_counter() - t0
    if part == "crankshaft":
        n_pins = sum(1 for n in prt.regions if n.startswith("crankpin"))
        specs = crank_interface_specs(prt.regions, -(-n_rods // max(n_pins, 1)))
    else:
        specs = [{"region": n, "kind": "distributing", "segments": 1}
                 for n in ("big_end_bore", "small_end_bore")]
    with scene_keys(where, {"n_modes": "fixed_interface_modes"}):
        itf = make_interfaces(prt, interface_specs(prt, {"interfaces": specs,
                                                         "coupling": "distributing"}))
        t0 = time.perf_counter()
        body, _ = reduce_body(model, itf, n_modes=spec["fixed_interface_modes"], mesh=prt.mesh,
                              name=prt.name, info={"part": prt.name, "material": mat.name,
                                                   "machine": machine})
    steps["reduction_s"] = time.perf_counter() - t0
    path.parent.mkdir(parents=True, exist_ok=True)
    save_flexbody(path, body)  # atomic
    steps["write_s"] = 0.0
    steps.close()
    return path


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


def crank_body(source, spec: dict | None = None, row_z=None, crank_radius: float | None = None,
               name: str = "crank"):
    """A planar flexible crank from a flexbody file, frames named for a crank train.

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
        Axial position of each rod's row relative to the crankpin's middle, m (default
        ``[0.0]``: one rod in the middle).
    crank_radius : float or None
        The mechanism's crank radius, m, checked against the file (±1 %).

    Returns
    -------
    body : FlexibleBody
    roles : dict
        ``mains`` (frame names), ``pins`` (one per rod), ``drive``; the default of
        :func:`~.mechanisms.crank_train`'s ``crank_roles``.

    Raises
    ------
    ParameterError
        Naming ``spec.<key>``, ``row_z``, ``crank_radius`` or ``source`` (interfaces missing,
        or the crank radius off).
    """
    from ... import arguments as arg
    from .body import planar_body

    spec = body_spec(spec)
    row_z = _rows(row_z)
    crank_radius = arg.number("crank_radius", crank_radius, gt=0.0, optional=True)
    fb, path = read(_source(source))
    centres = _centres(fb)
    mains = sorted(n for n in centres if n.startswith("main_journal"))
    bands = sorted(n for n in centres if n.startswith("crankpin"))
    if not mains or not bands:
        raise ParameterError("source", f"{path}: needs main_journal_* and crankpin_* "
                             f"interfaces; has {', '.join(sorted(centres)) or 'none'}")
    axis0 = np.mean([centres[n] for n in mains], axis=0)
    pin_mid = np.mean([centres[n] for n in bands], axis=0)
    arm = pin_mid[:2] - axis0[:2]
    r_file = float(np.hypot(*arm))
    if crank_radius is not None and abs(r_file / crank_radius - 1) > GEOMETRY_TOLERANCE:
        raise ParameterError("source", f"{path}: its crankpin is {r_file:.5g} m from the main "
                             f"journals' axis, the mechanism's crank radius is "
                             f"{crank_radius:.5g} m (tolerance {GEOMETRY_TOLERANCE:.0%})")
    pins = []
    for z in row_z:
        dz = [abs(centres[n][2] - pin_mid[2] - z) for n in bands]
        pins.append(bands[int(np.argmin(dz))])
    drive = "flywheel_end_face" if "flywheel_end_face" in centres else mains[0]
    body = planar_body(fb, name, n_modes=spec.get("n_modes"), cutoff_hz=spec.get("cutoff_hz"),
                       damping_ratio=spec["damping_ratio"], tilt=len(mains) > 1,
                       orientation=_in_plane_angle(arm), path=path)
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
    body = planar_body(fb, name, n_modes=spec.get("n_modes"), cutoff_hz=spec.get("cutoff_hz"),
                       damping_ratio=spec["damping_ratio"], z=z, orientation=_in_plane_angle(d),
                       path=path)
    body.alias("big", "big_end_bore")
    body.alias("small", "small_end_bore")
    return body


def _bar_arguments(length, section, spec) -> None:
    """The Python API's arguments of :func:`reduced_bar` (a scene's are validated already):
    a ParameterError naming ``length``, ``section`` or ``spec.<key>``."""
    from ...geometry.mesh import is_length

    if not is_length(length):
        raise ParameterError("length", f"must be a number > 0 m, got {length!r}")
    if (not isinstance(section, (tuple, list)) or len(section) != 2
            or not all(is_length(v) for v in section)):
        raise ParameterError("section", f"must be [width, thickness], two numbers > 0 m, got "
                             f"{section!r}")
    if not isinstance(spec, dict):
        raise ParameterError("spec", f"must be a dict, got {type(spec).__name__}")
    checks = {"mesh_size": (is_length, "a number > 0 m"),
              "element_order": (lambda v: v in (1, 2) and not isinstance(v, bool), "1 or 2"),
              "material": (lambda v: isinstance(v, str), "a material name"),
              "fixed_interface_modes": (lambda v: isinstance(v, int) and not isinstance(v, bool)
                                        and 0 <= v <= 400, "an integer in [0, 400]")}
    for k, (ok, rule) in checks.items():
        if k not in spec or not ok(spec[k]):
            raise ParameterError(f"spec.{k}", f"must be {rule}, got {spec.get(k, 'nothing')!r}")


def check_bar(length: float, section, spec: dict, key: str) -> tuple:
    """Refuse the bar of :func:`reduced_bar` before anything is built; return its divisions.

    Its sides (``length``, ``section``) must be sizes crankmodal builds
    (:data:`~crankmodal.geometry.checks.MIN_LENGTH` to ``MAX_LENGTH``), and its tetrahedra at
    ``spec["mesh_size"]`` no more than the limit of parts meshed by gmsh
    (:data:`~crankmodal.geometry.mesh.MAX_ELEMENTS`, or fewer when the memory available could not
    hold the reduction's factorisation: :func:`~crankmodal.geometry.mesh.fe_element_limit`).

    Raises
    ------
    SceneError
        A side out of range, naming ``<key>.bar`` (or ``dynamics.four_bar.lengths``).
    ResourceError
        Too many tetrahedra, naming ``<key>.mesh_size`` and the smallest size allowed.
    """
    from ...errors import ResourceError
    from ...fem.memory import available_bytes
    from ...fem.testparts import check_bar_size
    from ...geometry.checks import MAX_LENGTH, MIN_LENGTH
    from ...geometry.mesh import MAX_ELEMENTS, MeshSizeError, fe_element_limit

    _bar_arguments(length, section, spec)
    sizes = f"the sizes crankmodal builds, [{MIN_LENGTH:g}, {MAX_LENGTH:g}] m"
    if not MIN_LENGTH <= length <= MAX_LENGTH:
        raise SceneError(f"dynamics.four_bar.lengths: the {key.rsplit('.', 1)[-1]} bar reduced "
                         f"here is {length:.6g} m long, outside {sizes}")
    for v in section:
        if not MIN_LENGTH <= v <= MAX_LENGTH:
            raise SceneError(f"{key}.bar: every side must be in {sizes}, got {v:.6g}")
    limit, reason = MAX_ELEMENTS, "crankmodal's limit on the mesh size"
    avail = available_bytes()
    fe = fe_element_limit(spec["element_order"], avail)
    if fe is not None and fe < limit:
        limit = fe
        reason = (f"the P{spec['element_order']} elements whose FE factorisation, "
                  f"0.42 GB x (DOF / 85k)^1.5, fits in the {avail / 1e9:.3g} GB available")
    try:
        return check_bar_size((length, *map(float, section)), spec["mesh_size"], limit, reason)
    except MeshSizeError as exc:
        raise ResourceError(exc.worded(f"{key}.mesh_size")) from None


def reduced_bar(length: float, section, spec: dict, key: str) -> Path:
    """The ``crankmodal-flexbody`` file of a prismatic steel (or ``spec["material"]``) bar
    between two pins, reduced once and cached.

    A link for a mechanism with no part of its own (the seed-001 loom's four-bar): a
    structured tetrahedral bar (:func:`crankmodal.fem.testparts.bar`, no gmsh) along x of
    ``length`` (m, the distance between the joints), in-plane width ``section[0]`` and
    thickness ``section[1]`` (m), about ``spec["mesh_size"]`` (m) per element edge, reduced
    (Craig–Bampton, ``spec["fixed_interface_modes"]``) on its two end faces ``end_x0`` and
    ``end_x1`` with distributing (RBE3) couplings: each joint is the mean motion of an end face,
    at the face centre. ``key`` names the scene table in messages.
    """
    from ...fem.assembly import assemble
    from ...fem.material_stage import make_material
    from ...fem.material_stage import validate as validate_material
    from ...fem.testparts import bar
    from ...reduction.interfaces import make_interfaces
    from ...reduction.io import save_flexbody
    from ...reduction.reduce import reduce_body

    div = check_bar(length, section, spec, key)
    width, thickness = (float(v) for v in section)
    try:
        mp = validate_material({"name": spec["material"]}, None)
    except SceneError as exc:
        raise SceneError(f"{key}.material: {exc}") from None
    key_text = json.dumps({"bar": [length, width, thickness], "divisions": div,
                           "order": spec["element_order"], "material": spec["material"],
                           "modes": spec["fixed_interface_modes"],
                           "source": _reduction_source_digest(), "format": 1}, sort_keys=True)
    digest = hashlib.sha256(key_text.encode()).hexdigest()[:32]
    path = flexbody_cache_dir() / f"bar_{digest}.npz"
    if cached_flexbody(path, key):
        return path
    part = bar(length, width, thickness, div, order=spec["element_order"])
    mat = make_material(mp)
    model = assemble(part, mat)
    with scene_keys(key, {"n_modes": "fixed_interface_modes"}):
        itf = make_interfaces(part, [{"region": n, "kind": "distributing"}
                                     for n in ("end_x0", "end_x1")])
        body, _ = reduce_body(model, itf, n_modes=spec["fixed_interface_modes"],
                              mesh=part.mesh, name="bar",
                              info={"part": "bar", "material": mat.name, "length_m": length,
                                    "section_m": [width, thickness]})
    path.parent.mkdir(parents=True, exist_ok=True)
    save_flexbody(path, body)  # atomic
    return path


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
           "flexbody_cache_dir", "link_body", "read",
           "reduced_bar", "reduced_part", "rigid_twin", "rod_body"]
