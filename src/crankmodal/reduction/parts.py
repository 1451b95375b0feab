"""Parts reduced to flexible bodies, once, cached: geometry → FE → Craig–Bampton.

What crosses each arrow is a typed object: a machine's part parameters
(:class:`~crankmodal.geometry.params.CrankshaftParams` / ``ConrodParams``) and
:class:`~crankmodal.geometry.mesh.MeshSettings` → a :class:`~crankmodal.part.Part`
(:func:`~crankmodal.geometry.build.build_part`, through the part cache) → an
:class:`~crankmodal.fem.assembly.FEModel` (:func:`~crankmodal.fem.assembly.assemble` with a
:class:`~crankmodal.fem.materials.Material`) → interfaces
(:func:`~crankmodal.reduction.interfaces.make_interfaces`) → the reduced body
(:func:`~crankmodal.reduction.reduce.reduce_body`) → a ``crankmodal-flexbody`` file
(:func:`~crankmodal.reduction.io.save_flexbody`, atomic). No scene stage is involved.

Two kinds of part:

- :func:`reduced_part`: the ``crankshaft`` or ``rod`` of a machine file (``geometry/<machine>.toml``),
  reduced on its bearing surfaces with distributing (RBE3) couplings: a crank on every
  ``main_journal_*``, every ``crankpin_*`` region cut into bands (one per rod) and the
  ``flywheel_end_face``; a rod on its two bores.
- :func:`reduced_bar`: a prismatic bar between two pins (:func:`crankmodal.fem.bar.bar`), for a
  four-bar link with no part of its own.

The files live under ``$CRANKMODAL_CACHE/flexbodies`` (:func:`flexbody_cache_dir`), named by a
digest of everything that makes them (the part's cache key or the bar's sides and grid, the
material, the fixed-interface modes, the rods per crank, and the source of the reduction and FE
packages, :func:`reduction_source_digest`). A damaged file is removed with one warning and
rebuilt (:func:`cached_flexbody`).

Errors: :class:`~crankmodal.errors.ParameterError` naming the argument (``spec.mesh_size``, or
``<key>.mesh_size`` with the ``key`` label a caller gives, as a scene table's name),
:class:`~crankmodal.errors.ResourceError` for a mesh size over the element limit,
:class:`~crankmodal.errors.GeometryError` for impossible part parameters.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from ..errors import ParameterError

#: version of the cache key's recipe (bump to retire every cached flexbody)
KEY_FORMAT = 1
#: largest number of fixed-interface modes a spec may ask for
MAX_FIXED_INTERFACE_MODES = 400


def flexbody_cache_dir() -> Path:
    """``$CRANKMODAL_CACHE/flexbodies`` (default ``~/.cache/crankmodal/flexbodies``)."""
    from ..caches import cache_folder

    return cache_folder("flexbodies")


def cached_flexbody(path: Path, where: str) -> bool:
    """Whether ``path`` holds a sound cached flexbody. A damaged one (truncated, bit-flipped,
    emptied: :func:`~crankmodal.reduction.io.load_flexbody` refuses it) is removed with a
    one-line warning naming ``where``, the file and what is wrong, so that the caller rebuilds
    it, as :mod:`crankmodal.geometry.cache` does for parts."""
    from ..caches import discard_damaged
    from ..errors import InputFileError
    from .io import load_flexbody

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


def reduction_source_digest() -> str:
    """SHA-256 of the source of :mod:`crankmodal.reduction` and :mod:`crankmodal.fem` (the
    code that turns a part into a reduced body, the bar builder :mod:`crankmodal.fem.bar`
    included): an edited reducer never serves a stale cached body."""
    h = hashlib.sha256()
    for folder in ("reduction", "fem"):
        for path in sorted((Path(__file__).parents[1] / folder).glob("*.py")):
            h.update(path.read_bytes())
    return h.hexdigest()


def crank_interface_specs(regions, rods_per_pin: int) -> list[dict]:
    """Distributing interfaces of a crankshaft part: each main journal, each crankpin region cut
    into ``rods_per_pin`` bands, and the flywheel end face if present.

    Parameters
    ----------
    regions : iterable of str
        The part's region names.
    rods_per_pin : int
        Bands per crankpin region (one interface each).

    Returns
    -------
    list of dict
        ``{"region", "kind": "distributing", "segments"}`` per region.

    Raises
    ------
    ParameterError
        Naming ``regions`` when there is no ``main_journal_*`` or ``crankpin_*`` region.
    """
    mains = sorted(n for n in regions if n.startswith("main_journal"))
    pins = sorted(n for n in regions if n.startswith("crankpin"))
    if not mains or not pins:
        raise ParameterError("regions", "the part has no main_journal_* or crankpin_* regions "
                             f"(regions: {', '.join(sorted(regions)) or 'none'})")
    specs = [{"region": n, "kind": "distributing", "segments": 1} for n in mains]
    specs += [{"region": n, "kind": "distributing", "segments": rods_per_pin} for n in pins]
    if "flywheel_end_face" in regions:
        specs.append({"region": "flywheel_end_face", "kind": "distributing", "segments": 1})
    return specs


@dataclass(frozen=True)
class PartInputs:
    """Everything that makes a machine part's reduced body, checked (SI units).

    Attributes
    ----------
    machine, part : str
        Machine file name and part (``crankshaft`` or ``rod``).
    params : CrankshaftParams or ConrodParams
    fidelity : str
    settings : MeshSettings
        Size (m), order, and the element limit of a mesh an FE factorisation follows.
    material : Material
    fixed_interface_modes : int
    """

    machine: str
    part: str
    params: object
    fidelity: str
    settings: object
    material: object
    fixed_interface_modes: int


def _relabelled(exc: ParameterError, key: str, names: dict) -> ParameterError:
    """``exc`` naming ``<key>.<spec key>`` for a core argument in ``names``."""
    head = exc.argument.split(".", 1)[0]
    return ParameterError(f"{key}.{names.get(head, head)}", exc.text)


def _spec_value(spec, name: str, key: str, ok, rule: str):
    if not isinstance(spec, dict):
        raise ParameterError(key, f"must be a dict, got {type(spec).__name__}")
    if name not in spec or not ok(spec[name]):
        raise ParameterError(f"{key}.{name}", f"must be {rule}, got {spec.get(name, 'nothing')!r}")
    return spec[name]


def _is_modes(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= MAX_FIXED_INTERFACE_MODES


def _material(spec, key: str):
    from ..fem.materials import material

    name = _spec_value(spec, "material", key, lambda v: isinstance(v, str), "a material name")
    try:
        return material(name)
    except ParameterError as exc:
        raise ParameterError(f"{key}.material", exc.text) from None


def check_part(machine: str, part: str, spec: dict, key: str = "spec") -> PartInputs:
    """The checked inputs of the part :func:`reduced_part` makes, before anything is built:
    the machine's part table, the mesh size against the part (its element count), the material.

    Parameters
    ----------
    machine : str
        Machine file name (``geometry/<machine>.toml``).
    part : {"crankshaft", "rod"}
    spec : dict
        ``fidelity``, ``mesh_size`` (m), ``element_order`` (1 or 2), ``material`` (a library
        name), ``fixed_interface_modes`` (0 to 400); other keys are ignored.
    key : str
        How messages name ``spec`` (a scene passes its table, ``dynamics.flexible.crank``).

    Returns
    -------
    PartInputs

    Raises
    ------
    ParameterError
        Naming ``machine``, ``part`` or ``<key>.<spec key>``.
    ResourceError
        ``mesh_size`` makes more tetrahedra than the limit (named ``<key>.mesh_size``, with the
        smallest size allowed).
    GeometryError
        The machine's part parameters are impossible (named ``<part>.<parameter>``).
    """
    from ..errors import ResourceError
    from ..geometry.checks import check_conrod, check_crankshaft, check_fidelity
    from ..geometry.mesh import MeshSizeError, check_settings, check_size_floor, fe_mesh_settings
    from ..geometry.params import params_from_dict
    from ..resources import load_machine

    if part not in ("crankshaft", "rod"):
        raise ParameterError("part", f"must be 'crankshaft' or 'rod', got {part!r}")
    if not isinstance(machine, str):
        raise ParameterError("machine", f"must be a machine name, got {machine!r:.60}")
    fidelity = _spec_value(spec, "fidelity", key, lambda v: isinstance(v, str), "a fidelity")
    size = _spec_value(spec, "mesh_size", key, lambda v: v is not None and not isinstance(v, (bool, str)), "a number > 0 m")
    order = _spec_value(spec, "element_order", key,
                        lambda v: v in (1, 2) and not isinstance(v, bool), "1 or 2")
    modes = _spec_value(spec, "fixed_interface_modes", key, _is_modes,
                        f"an integer in [0, {MAX_FIXED_INTERFACE_MODES}]")
    names = {"size": "mesh_size", "order": "element_order", "fidelity": "fidelity"}
    settings = fe_mesh_settings(size, order)
    try:
        check_fidelity(fidelity)
        check_settings(settings)
    except ParameterError as exc:
        raise _relabelled(exc, key, names) from None
    mat = _material(spec, key)
    tables = load_machine(machine, key="machine")
    if part not in tables:
        raise ParameterError("machine", f"machine {machine!r} has no [{part}] table; it has: "
                             f"{', '.join(sorted(tables))}")
    params = params_from_dict(part, dict(tables[part]), where=f"{machine}.toml [{part}]")
    (check_crankshaft if part == "crankshaft" else check_conrod)(params)
    try:
        check_size_floor(params, settings)
    except MeshSizeError as exc:
        raise ResourceError(exc.worded(f"{key}.mesh_size", f"{machine}.toml [{part}] ")) from None
    return PartInputs(machine, part, params, fidelity, settings, mat, modes)


def machine_part(inputs: PartInputs):
    """The meshed part of checked inputs, through the on-disk part cache (shared with the
    ``[geometry]`` stage: the same key for the same parameters, fidelity and mesh).

    Returns
    -------
    part : Part
    cached : bool
    """
    from ..errors import warn
    from ..geometry.build import build_part
    from ..geometry.cache import load_part, part_key, store_part

    desc = {"part": inputs.part, "params": inputs.params.to_dict(), "fidelity": inputs.fidelity,
            "mesh": inputs.settings.to_dict()}
    key = part_key(desc)
    part = load_part(key)
    if part is not None:
        return part, True
    part = build_part(inputs.params, inputs.fidelity, inputs.settings,
                      name=f"{inputs.machine}/{inputs.part}")
    try:
        store_part(key, part)
    except OSError as exc:  # the cache only saves time
        warn(f"part cache: cannot store the part in {exc.filename or 'the cache'} "
             f"({exc.strerror or exc}); running on without caching it "
             "(CRANKMODAL_CACHE names the cache folder)")
    return part, False


def part_interfaces(part, specs: list[dict]):
    """Interfaces of ``specs`` (:func:`crank_interface_specs`) on a part, each region cut into
    its ``segments`` bands (:func:`~crankmodal.reduction.interfaces.split_region`)."""
    import numpy as np

    from .interfaces import make_interfaces, split_region

    cells = np.asarray(part.mesh.cells[0].data)
    points = np.asarray(part.mesh.points, float)[:, :3]
    out = []
    for s in specs:
        region = part.regions[s["region"]]
        if s.get("segments", 1) > 1:
            out += [{"region": r.name, "kind": s["kind"], "region_object": r}
                    for r in split_region(region, points, s["segments"], cells)]
        else:
            out.append({"region": s["region"], "kind": s["kind"]})
    return make_interfaces(part, out)


def flexbody_path(inputs: PartInputs, n_rods: int) -> Path:
    """The cache file of a machine part's reduced body (see the module docstring)."""
    from ..geometry.cache import part_key

    desc = {"part": inputs.part, "params": inputs.params.to_dict(), "fidelity": inputs.fidelity,
            "mesh": {"size": inputs.settings.size, "order": inputs.settings.order}}
    key_text = json.dumps({"part": part_key(desc), "material": inputs.material.name,
                           "modes": inputs.fixed_interface_modes, "n_rods": n_rods,
                           "source": reduction_source_digest(), "format": KEY_FORMAT},
                          sort_keys=True)
    digest = hashlib.sha256(key_text.encode()).hexdigest()[:32]
    return flexbody_cache_dir() / f"{inputs.machine}_{inputs.part}_{digest}.npz"


def _reduce(model, itf, modes: int, mesh, name: str, info: dict, key: str):
    from .reduce import reduce_body

    try:
        return reduce_body(model, itf, fixed_interface_modes=modes, mesh=mesh, name=name,
                           info=info)[0]
    except ParameterError as exc:
        raise _relabelled(exc, key, {}) from None


def reduced_part(machine: str, part: str, spec: dict, n_rods: int = 1,
                 key: str = "spec") -> Path:
    """The ``crankmodal-flexbody`` file of a machine's part, reduced once and cached.

    Parameters
    ----------
    machine : str
        Machine file name (``geometry/<machine>.toml``).
    part : {"crankshaft", "rod"}
    spec : dict
        ``fidelity``, ``mesh_size`` (m), ``element_order``, ``material``,
        ``fixed_interface_modes`` (:func:`check_part`).
    n_rods : int
        Rods on the crank (crankshaft only): each crankpin region is cut into
        ``ceil(n_rods / crankpin regions)`` bands, one interface each.
    key : str
        How messages name ``spec``.

    Returns
    -------
    Path
        The cached file (:func:`crankmodal.reduction.io.load_flexbody` reads it).

    Raises
    ------
    ParameterError, ResourceError, GeometryError
        As :func:`check_part`; ``n_rods`` not an integer >= 1.
    """
    import time

    from ..errors import ResourceError
    from ..fem.assembly import assemble
    from ..geometry.mesh import MeshSizeError
    from ..progress import PhaseTimings
    from .io import save_flexbody

    if isinstance(n_rods, bool) or not isinstance(n_rods, int) or n_rods < 1:
        raise ParameterError("n_rods", f"must be an integer >= 1, got {n_rods!r}")
    inputs = check_part(machine, part, spec, key)
    path = flexbody_path(inputs, n_rods)
    if cached_flexbody(path, key):
        return path
    steps = PhaseTimings(f"{key}: reducing the {part}", 4)
    t0 = time.perf_counter()
    try:
        prt, _ = machine_part(inputs)
    except MeshSizeError as exc:
        raise ResourceError(exc.worded(f"{key}.mesh_size", f"{machine}.toml [{part}] ")) from None
    steps["part_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    model = assemble(prt, inputs.material)
    steps["assembly_s"] = time.perf_counter() - t0
    if part == "crankshaft":
        n_pins = sum(1 for n in prt.regions if n.startswith("crankpin"))
        specs = crank_interface_specs(prt.regions, -(-n_rods // max(n_pins, 1)))
    else:
        specs = [{"region": n, "kind": "distributing", "segments": 1}
                 for n in ("big_end_bore", "small_end_bore")]
    itf = part_interfaces(prt, specs)
    t0 = time.perf_counter()
    body = _reduce(model, itf, inputs.fixed_interface_modes, prt.mesh, prt.name,
                   {"part": prt.name, "material": inputs.material.name, "machine": machine}, key)
    steps["reduction_s"] = time.perf_counter() - t0
    path.parent.mkdir(parents=True, exist_ok=True)
    save_flexbody(path, body)  # atomic
    steps["write_s"] = 0.0
    steps.close()
    return path


def _bar_arguments(length, section, spec) -> None:
    """The Python API's arguments of :func:`reduced_bar`: a ParameterError naming ``length``,
    ``section`` or ``spec.<key>``."""
    from ..geometry.mesh import is_length

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
              "fixed_interface_modes": (_is_modes, "an integer in [0, 400]")}
    for k, (ok, rule) in checks.items():
        if k not in spec or not ok(spec[k]):
            raise ParameterError(f"spec.{k}", f"must be {rule}, got {spec.get(k, 'nothing')!r}")


def check_bar(length: float, section, spec: dict, key: str = "spec") -> tuple:
    """Refuse the bar of :func:`reduced_bar` before anything is built; return its divisions.

    Its sides (``length``, ``section``) must be sizes crankmodal builds
    (:data:`~crankmodal.geometry.checks.MIN_LENGTH` to ``MAX_LENGTH``), and its tetrahedra at
    ``spec["mesh_size"]`` no more than the limit of parts meshed by gmsh
    (:data:`~crankmodal.geometry.mesh.MAX_ELEMENTS`, or fewer when the memory available could not
    hold the reduction's factorisation: :func:`~crankmodal.geometry.mesh.fe_element_limit`).

    Raises
    ------
    ParameterError
        A wrong type (naming ``length``, ``section``, ``spec.<key>``); a side out of range
        (naming ``length`` or ``<key>.bar``).
    ResourceError
        Too many tetrahedra, naming ``<key>.mesh_size`` and the smallest size allowed.
    """
    from ..errors import ResourceError
    from ..fem.bar import check_bar_size
    from ..fem.memory import available_bytes
    from ..geometry.checks import MAX_LENGTH, MIN_LENGTH
    from ..geometry.mesh import MAX_ELEMENTS, MeshSizeError, fe_element_limit

    _bar_arguments(length, section, spec)
    sizes = f"the sizes crankmodal builds, [{MIN_LENGTH:g}, {MAX_LENGTH:g}] m"
    if not MIN_LENGTH <= length <= MAX_LENGTH:
        raise ParameterError("length", f"the {key.rsplit('.', 1)[-1]} bar reduced here is "
                             f"{length:.6g} m long, outside {sizes}")
    for v in section:
        if not MIN_LENGTH <= v <= MAX_LENGTH:
            raise ParameterError(f"{key}.bar", f"every side must be in {sizes}, got {v:.6g}")
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


def reduced_bar(length: float, section, spec: dict, key: str = "spec") -> Path:
    """The ``crankmodal-flexbody`` file of a prismatic bar between two pins, reduced once and
    cached.

    A link for a mechanism with no part of its own (the seed-001 loom's four-bar): a
    structured tetrahedral bar (:func:`crankmodal.fem.bar.bar`, no gmsh) along x of
    ``length`` (m, the distance between the joints), in-plane width ``section[0]`` and
    thickness ``section[1]`` (m), about ``spec["mesh_size"]`` (m) per element edge, of
    ``spec["material"]``, reduced (Craig–Bampton, ``spec["fixed_interface_modes"]``) on its two
    end faces ``end_x0`` and ``end_x1`` with distributing (RBE3) couplings: each joint is the
    mean motion of an end face, at the face centre.

    Parameters
    ----------
    length : float
        m.
    section : (float, float)
        Width and thickness, m.
    spec : dict
        ``mesh_size`` (m), ``element_order``, ``material``, ``fixed_interface_modes``.
    key : str
        How messages name ``spec``.

    Returns
    -------
    Path

    Raises
    ------
    ParameterError, ResourceError
        As :func:`check_bar`; an unknown material (``<key>.material``).
    """
    from ..fem.assembly import assemble
    from ..fem.bar import bar
    from .interfaces import make_interfaces
    from .io import save_flexbody

    div = check_bar(length, section, spec, key)
    width, thickness = (float(v) for v in section)
    mat = _material(spec, key)
    key_text = json.dumps({"bar": [length, width, thickness], "divisions": div,
                           "order": spec["element_order"], "material": spec["material"],
                           "modes": spec["fixed_interface_modes"],
                           "source": reduction_source_digest(), "format": KEY_FORMAT},
                          sort_keys=True)
    digest = hashlib.sha256(key_text.encode()).hexdigest()[:32]
    path = flexbody_cache_dir() / f"bar_{digest}.npz"
    if cached_flexbody(path, key):
        return path
    part = bar(length, width, thickness, div, order=spec["element_order"])
    model = assemble(part, mat)
    itf = make_interfaces(part, [{"region": n, "kind": "distributing"}
                                 for n in ("end_x0", "end_x1")])
    body = _reduce(model, itf, spec["fixed_interface_modes"], part.mesh, "bar",
                   {"part": "bar", "material": mat.name, "length_m": length,
                    "section_m": [width, thickness]}, key)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_flexbody(path, body)  # atomic
    return path


__all__ = ["KEY_FORMAT", "PartInputs", "cached_flexbody", "check_bar", "check_part",
           "crank_interface_specs", "flexbody_cache_dir", "flexbody_path", "machine_part",
           "part_interfaces", "reduced_bar", "reduced_part", "reduction_source_digest"]
