"""The ``[geometry]`` scene section: build or import a part and hand it on as a ``Part``.

Keys (fixed by the scene contract: ``file``; ``machine`` + ``part`` + ``fidelity``;
``mesh_size``; ``element_order``) and this stage's own ones are declared in :data:`SCHEMA`.
"""

from __future__ import annotations

import time

from ..errors import GeometryError, SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table

SECTION = "geometry"
REQUIRES = ()

SCHEMA = {
    "file": Field("str", None, "STEP/IGES/BREP (meshed with gmsh) or meshio volume mesh; relative to the scene"),
    "machine": Field("str", None, "machine parameter file in geometry/ (with part and fidelity)"),
    "part": Field("str", "crankshaft", "which part of the machine to build", choices=("crankshaft", "rod")),
    "fidelity": Field("str", "full", "full | dechamfered | simplified",
                      choices=("full", "dechamfered", "simplified")),
    "params": Field("table", None, "part parameters overriding the machine's table (m, deg)"),
    "mesh_size": Field("float", 0.01, "target element size, m", gt=0),
    "element_order": Field("int", 2, "1 or 2 (P1 / curved P2 tetrahedra)", choices=None,
                           check=lambda v: None if v in (1, 2) else "must be 1 or 2"),
    "refine": Field("float", 0.4, "element size at fillets and holes as a fraction of mesh_size", gt=0, le=1),
    "optimize": Field("bool", True, "optimise the tetrahedra after meshing"),
    "regions": Field("tables", [], "named regions of an imported part: {name, axis=[x,y,z,dx,dy,dz], radius} "
                                   "or {name, box=[xmin,xmax,ymin,ymax,zmin,zmax]} (m)"),
    "write_mesh": Field("str", None, "also write the mesh to out_dir under this file name (.vtu, .msh, ...)"),
    "cache": Field("bool", True, "reuse a part cached on disk with the same inputs"),
}


#: Sections that factorise the part's stiffness matrix.
FE_SECTIONS = ("modal", "static", "reduction")


def mesh_settings(p: dict):
    """The :class:`~crankmodal.geometry.mesh.MeshSettings` of validated parameters ``p``: the
    element limit is :data:`~crankmodal.geometry.mesh.MAX_ELEMENTS`, or fewer when an FE stage
    follows and the memory available could not hold its factorisation."""
    from .mesh import fe_mesh_settings

    return fe_mesh_settings(p["mesh_size"], p["element_order"], p["refine"], p["optimize"],
                            bool(p.get("fe_follows")))


def validate(raw: dict, scene) -> dict:
    """Check the section; resolve the file or the machine's part table; check part parameters."""
    from .checks import check_conrod, check_crankshaft
    from .importers import region_specs
    from .params import params_from_dict

    p = validate_table(SECTION, raw, SCHEMA)
    # the FE stages that will factorise this mesh bound its size by the memory (make_part)
    p["fe_follows"] = any(s in scene.sections for s in FE_SECTIONS)
    if (p["file"] is None) == (p["machine"] is None and p["params"] is None):
        raise SceneError("geometry: give either file = \"...\" or machine = \"...\" (with part, fidelity)")
    if p["file"] is not None:
        path = scene.resolve(p["file"])
        if not path.is_file():
            from ..errors import InputFileError

            raise InputFileError(f"geometry.file: file not found: {path}")
        p["file"] = str(path)
        try:
            p["region_specs"] = region_specs(p["regions"])
        except GeometryError as exc:
            raise SceneError(str(exc)) from None
        return p
    table = {}
    if p["machine"] is not None:
        from ..resources import load_machine

        tables = load_machine(p["machine"], key="geometry.machine")
        if p["part"] not in tables:
            raise SceneError(f"geometry.part: machine {p['machine']!r} has no [{p['part']}] table; "
                             f"it has: {', '.join(sorted(tables))}")
        table = dict(tables[p["part"]])
    table.update(p["params"] or {})
    try:
        params = params_from_dict(p["part"], table, where="geometry.params")
        (check_crankshaft if p["part"] == "crankshaft" else check_conrod)(params)
    except GeometryError as exc:  # name the key as the scene spells it
        text = str(exc)
        for prefix in ("crankshaft.", "rod."):
            if text.startswith(prefix):
                text = "geometry.params." + text[len(prefix):]
        origin = f" (machine {p['machine']!r}, [{p['part']}])" if p["machine"] else ""
        raise SceneError(text + origin) from None
    p["part_params"] = params
    from .mesh import MeshSizeError, check_size_floor

    # run estimates again, closer, on the CAD solid; a size or refine out of range is named
    with scene_keys(SECTION, {"size": "mesh_size", "order": "element_order"}):
        try:
            check_size_floor(params, mesh_settings(p))
        except MeshSizeError as exc:
            raise SceneError(exc.worded("geometry.mesh_size", "geometry.params.")) from None
    return p


def _build_or_import(p: dict, settings):
    """The part of validated parameters ``p``: a CAD file meshed, a mesh file read, or built."""
    if p["file"] is not None:
        from .importers import CAD_SUFFIXES, import_cad, import_mesh

        if p["file"].lower().endswith(CAD_SUFFIXES):
            return import_cad(p["file"], p["region_specs"], settings)
        return import_mesh(p["file"], p["region_specs"])
    from .build import build_part

    name = f"{p['machine']}/{p['part']}" if p["machine"] else p["part"]
    return build_part(p["part_params"], p["fidelity"], settings, name=name)


def make_part(p: dict):
    """Build or import the part of validated parameters ``p``, through the on-disk cache.

    Raises
    ------
    ResourceError
        A ``mesh_size`` making more tetrahedra than the limit, named ``geometry.mesh_size``.
    """
    from .cache import file_digest, load_part, part_key, store_part
    from .mesh import MeshSizeError

    settings = mesh_settings(p)
    if p["file"] is not None:
        desc = {"file": file_digest(p["file"]), "suffix": p["file"].rsplit(".", 1)[-1].lower(),
                "regions": p["regions"], "mesh": settings.to_dict()}
    else:
        desc = {"part": p["part"], "params": p["part_params"].to_dict(), "fidelity": p["fidelity"],
                "mesh": settings.to_dict()}
    key = part_key(desc)
    part = load_part(key) if p["cache"] else None
    cached = part is not None
    if part is None:
        with scene_keys(SECTION, {"size": "mesh_size", "order": "element_order"}):
            try:
                part = _build_or_import(p, settings)
            except MeshSizeError as exc:  # the element-count refusal, in the scene's words
                from ..errors import ResourceError

                raise ResourceError(exc.worded("geometry.mesh_size", "geometry.params.")) from None
        if p["cache"]:
            try:
                store_part(key, part)
            except OSError as exc:  # the cache only saves time: a read-only or full one is no error
                from ..errors import warn

                warn(f"geometry.cache: cannot store the part in {exc.filename or 'the cache'} "
                     f"({exc.strerror or exc}); running on without caching it "
                     "(CRANKMODAL_CACHE names the cache folder)")
    return part, cached


def run(p: dict, ctx) -> dict:
    """Make the part, store it in ``ctx.products["geometry"]``, write the mesh if asked."""
    t0 = time.perf_counter()
    part, cached = make_part(p)
    ctx.products[SECTION] = part
    out = part.summary()
    out["cached"] = cached
    out["mesh_time_s"] = time.perf_counter() - t0
    if p["write_mesh"]:
        import meshio

        from ..errors import OutputError
        from ..results import atomic_path

        target = ctx.out_dir / p["write_mesh"]
        tmp_name = str(target)
        try:
            with atomic_path(target) as tmp:  # the suffix kept: meshio picks the format by it
                tmp_name = str(tmp)
                meshio.write(tmp, part.mesh)
        except OutputError:
            raise
        except Exception as exc:  # noqa: BLE001 - meshio: unknown extension or writer failure
            why = str(exc).replace(tmp_name, str(target))  # the user's name, not the temporary's
            raise SceneError(f"geometry.write_mesh: cannot write {p['write_mesh']!r} ({why})") from None
        out["mesh_file"] = str(target)
    q = part.quality
    qual = f", min {q['measure']} {q['min']:.3f}" if q.get("measure") else ""
    vol = f", V = {part.cad_mass.volume * 1e6:.1f} cm3" if part.cad_mass else ""
    out["summary"] = (f"{part.name} ({part.fidelity}): {part.n_elements} P{part.element_order} tetrahedra, "
                      f"{part.n_nodes} nodes, {len(part.regions)} regions{qual}{vol}"
                      + (" [cached]" if cached else ""))
    return out
