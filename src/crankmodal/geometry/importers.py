"""Parts from files: STEP/IGES through gmsh, or any meshio-readable volume mesh.

Regions of a STEP part are given geometrically (a cylinder: point, axis and radius; or a box);
the faces of the CAD lying on them become named physical groups. A mesh file brings its own
names: gmsh physical groups, cell sets (Abaqus ``*ELSET``, ...) and point sets (``*NSET``);
geometric definitions may be added on top (boundary facets whose nodes all lie on the cylinder
or in the box).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import GeometryError, InputFileError
from ..part import CylindricalSurface, Part, Region
from ..topology import boundary_facets, facet_nodes
from .mesh import MeshSettings
from .regions import RegionSpec

CAD_SUFFIXES = (".step", ".stp", ".iges", ".igs", ".brep")

#: meshio volume cell types accepted.
_VOLUME = {"tetra": 4, "tetra10": 10}


def region_specs(defs: list) -> list:
    """RegionSpecs from scene tables ``{name, axis = [x,y,z,dx,dy,dz], radius}`` or ``{name, box = [...]}``."""
    specs = []
    for i, d in enumerate(defs or []):
        key = f"geometry.regions[{i}]"
        name = d.get("name")
        if not isinstance(name, str) or not name:
            raise GeometryError(f"{key}.name: must be a non-empty string")
        if "box" in d:
            b = np.asarray(d["box"], float)
            if b.shape != (6,) or np.any(b[1::2] < b[0::2]):
                raise GeometryError(f"{key}.box: must be [xmin, xmax, ymin, ymax, zmin, zmax] (m) with min <= max")
            specs.append(RegionSpec(name, "box", np.zeros(2), 0.0, tuple(b)))
        elif "axis" in d and "radius" in d:
            a = np.asarray(d["axis"], float)
            if a.shape != (6,) or not np.linalg.norm(a[3:]) > 0:
                raise GeometryError(f"{key}.axis: must be [x, y, z, dx, dy, dz] (m) with a non-zero direction")
            if not float(d["radius"]) > 0:
                raise GeometryError(f"{key}.radius: must be > 0 m, got {d['radius']!r}")
            specs.append(RegionSpec(name, "cylinder_axis", a, float(d["radius"]), ()))
        else:
            raise GeometryError(f"{key}: give either box = [6 numbers] or axis = [6 numbers] and radius")
    return specs


def import_cad(path, specs: list, settings: MeshSettings) -> Part:
    """Mesh a STEP/IGES/BREP file (lengths converted to metres) and name its regions.

    Parameters
    ----------
    path : str or Path
        The CAD file (its units converted to m by OpenCASCADE).
    specs : list of RegionSpec
        Named regions to make: ``crankmodal.geometry.regions.RegionSpec`` of kind ``cylinder_axis``
        (the boundary facets on a cylinder: ``axis_xy`` a point and direction, ``radius``, m) or
        ``box`` (``z_range`` the six bounds, m); the scene's ``geometry.regions`` tables become
        these.
    settings : MeshSettings
        Element size (m), order and refinement.

    Returns
    -------
    Part
        The meshed part with its regions, CAD mass properties and mesh-quality report.
    """
    from ..arguments import path as path_argument
    from .build import mesh_tagged
    from .massprops import cad_mass_properties, compare, mesh_mass_properties
    from .session import gmsh_session, quiet_stdout

    path = Path(path_argument("path", path))
    if not path.is_file():
        raise InputFileError(f"geometry.file: file not found: {path}")
    with gmsh_session(f"import {path.name}", {"file": str(path)}) as gmsh:
        gmsh.option.setString("Geometry.OCCTargetUnit", "M")
        with quiet_stdout():
            gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        volumes = [t for _, t in gmsh.model.getEntities(3)]
        if not volumes:
            raise GeometryError(f"geometry.file: {path.name} holds no solid")
        box = np.asarray(gmsh.model.getBoundingBox(-1, -1), float)
        check_extent(path.name, float(np.max(box[3:] - box[:3])))
        cad = cad_mass_properties(gmsh, volumes)
        mesh, regions, stats = mesh_tagged(gmsh, volumes, specs, settings)
    try:
        stats["mass_check"] = compare(cad, mesh_mass_properties(mesh.points, mesh.cells[0].data))
    except ValueError as exc:  # as build_part: a folded element is a geometry failure
        raise GeometryError(f"import {path.name}: {exc}") from None
    return Part(name=path.stem, mesh=mesh, regions=regions, fidelity="imported",
                params={"file": str(path), "mesh": settings.to_dict()}, cad_mass=cad, quality=stats)


def _region(name: str, cells, facets, cylinder=None) -> Region:
    return Region(name=name, facets=facets, nodes=facet_nodes(facets, cells), cylinder=cylinder)


def _geometric_regions(points, cells, specs: list) -> dict:
    facets = boundary_facets(cells)
    scale = float(np.ptp(points, axis=0).max())
    out = {}
    for s in specs:
        p = points[facets]                                   # (f, 3, 3)
        if s.kind == "box":
            b = np.asarray(s.z_range)
            tol = 1e-9 * scale
            inside = np.all((p >= b[0::2] - tol) & (p <= b[1::2] + tol), axis=(1, 2))
            cyl = None
        else:
            p0, d = s.axis_xy[:3], s.axis_xy[3:] / np.linalg.norm(s.axis_xy[3:])
            rel = p - p0
            along = rel @ d
            rad = np.linalg.norm(rel - along[..., None] * d, axis=-1)
            inside = np.all(np.abs(rad - s.radius) < 1e-4 * s.radius + 1e-9 * scale, axis=1)
            cyl = None
            if np.any(inside):
                t0, t1 = along[inside].min(), along[inside].max()
                cyl = CylindricalSurface(centre=p0 + 0.5 * (t0 + t1) * d, axis=d, radius=s.radius, length=float(t1 - t0))
        if not np.any(inside):
            raise GeometryError(f"region {s.name!r}: no boundary facet of the mesh lies on its definition")
        out[s.name] = _region(s.name, cells, facets[inside], cyl)
    return out


def check_cells_and_points(name: str, cells: np.ndarray, points) -> None:
    """Refuse volume cells that name missing points, and non-finite points the cells use.

    A NaN or infinite coordinate otherwise reaches the FE assembly and the eigensolver (a
    ``LinAlgError`` traceback, or a misleading "inverted elements").

    Raises
    ------
    InputFileError
        Naming the file, the first offending cell or point (0-based, as in the file) and value.
    """
    points = np.asarray(points)
    if points.ndim != 2 or points.shape[1] != 3:
        raise InputFileError(f"geometry.file: {name} is not a 3D mesh (points of shape "
                             f"{points.shape})")
    bad = np.flatnonzero(np.any((cells < 0) | (cells >= len(points)), axis=1))
    if len(bad):
        c = cells[bad[0]]
        raise InputFileError(f"geometry.file: {name}: volume cell {bad[0]} refers to point "
                             f"{int(c[(c < 0) | (c >= len(points))][0])}, but the file has "
                             f"{len(points)} points (0 to {len(points) - 1})")
    if not np.issubdtype(points.dtype, np.number):
        raise InputFileError(f"geometry.file: {name}: point coordinates are not numbers "
                             f"({points.dtype})")
    used = np.unique(cells)
    finite = np.all(np.isfinite(points[used].astype(float)), axis=1)
    if not np.all(finite):
        i = int(used[np.argmin(finite)])
        raise InputFileError(f"geometry.file: {name}: point {i} has a non-finite coordinate "
                             f"{np.array2string(points[i].astype(float), separator=', ')} "
                             f"({int((~finite).sum())} such points); every coordinate must be a "
                             f"finite number (m)")
    check_extent(name, np.ptp(points[used].astype(float), axis=0).max())


def check_extent(name: str, extent: float) -> None:
    """Refuse a part whose largest extent is outside the sizes crankmodal builds
    (:data:`~crankmodal.geometry.checks.MIN_LENGTH` to ``MAX_LENGTH``): coordinates are metres,
    and a mesh scaled far outside them fails as overflow or as "inverted elements".

    Raises
    ------
    InputFileError
        Naming the file and its extent.
    """
    from .checks import MAX_LENGTH, MIN_LENGTH

    if not MIN_LENGTH <= extent <= MAX_LENGTH:
        hint = (" (a mesh in millimetres: scale it by 0.001)" if 1e-1 < extent / 1e3 <= MAX_LENGTH
                else "")
        raise InputFileError(f"geometry.file: {name} spans {extent:.6g} m; coordinates are read "
                             f"in metres and crankmodal builds parts of {MIN_LENGTH:g} to "
                             f"{MAX_LENGTH:g} m{hint}")


def import_mesh(path, specs: list = ()) -> Part:
    """A part from a meshio-readable volume mesh (metres assumed) with its named groups.

    Names come from gmsh physical groups of triangles, cell sets of triangles, and point sets
    (boundary facets whose corners all belong to the set). Volume cell sets are ignored.

    Parameters
    ----------
    path : str or Path
        Any meshio volume mesh with tetra or tetra10 cells (.msh, .vtu, .inp, ...), in m. The
        file is untrusted: non-finite points, cells naming missing points, no tetrahedra and
        inverted elements are refused.
    specs : list of RegionSpec
        Further regions to make: ``crankmodal.geometry.regions.RegionSpec`` of kind ``cylinder_axis``
        (the boundary facets on a cylinder: ``axis_xy`` a point and direction, ``radius``, m) or
        ``box`` (``z_range`` the six bounds, m); the scene's ``geometry.regions`` tables become
        these.

    Returns
    -------
    Part
    """
    import meshio

    from ..arguments import path as path_argument

    path = Path(path_argument("path", path))
    if not path.is_file():
        raise InputFileError(f"geometry.file: file not found: {path}")
    try:
        m = meshio.read(path)
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - meshio raises many types, even SystemExit
        raise InputFileError(f"geometry.file: cannot read {path.name} as a mesh ({exc})") from None
    vol = [(i, b) for i, b in enumerate(m.cells) if b.type in _VOLUME]
    kinds = {b.type for _, b in vol}
    if not vol or len(kinds) != 1:
        raise InputFileError(f"geometry.file: {path.name} must hold tetra or tetra10 cells of one kind, "
                             f"found {sorted({b.type for b in m.cells})}")
    kind = kinds.pop()
    cells = np.concatenate([b.data for _, b in vol]).astype(np.int64)
    check_cells_and_points(path.name, cells, m.points)
    used = np.unique(cells)
    remap = -np.ones(len(m.points), dtype=np.int64)
    remap[used] = np.arange(len(used))
    points = np.asarray(m.points, float)[used]
    cells = remap[cells]

    named = {}
    tri = [(i, b) for i, b in enumerate(m.cells) if b.type in ("triangle", "triangle6")]
    names_by_tag = {int(v[0]): k for k, v in (m.field_data or {}).items() if len(v) > 1 and int(v[1]) == 2}
    phys = m.cell_data.get("gmsh:physical")
    if phys is not None and names_by_tag:
        for i, b in tri:
            for tag, name in names_by_tag.items():
                sel = np.asarray(phys[i]) == tag
                if np.any(sel):
                    named.setdefault(name, []).append(remap[b.data[sel, :3]])
    for name, blocks in (m.cell_sets or {}).items():
        if name.startswith("gmsh:") or name in named:  # meshio mirrors gmsh physical names here
            continue
        for i, b in tri:
            idx = np.asarray(blocks[i]) if i < len(blocks) and blocks[i] is not None else np.zeros(0, int)
            if len(idx):
                named.setdefault(name, []).append(remap[b.data[idx, :3]])
    regions = {}
    for n, f in named.items():
        f = np.concatenate(f)
        if np.all(f >= 0):
            _, first = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
            regions[n] = _region(n, cells, f[np.sort(first)])
    if m.point_sets:
        facets = boundary_facets(cells)
        for name, idx in m.point_sets.items():
            member = np.zeros(len(points), bool)
            ids = remap[np.asarray(idx, dtype=np.int64)]
            member[ids[ids >= 0]] = True
            sel = np.all(member[facets], axis=1)
            if np.any(sel) and name not in regions:
                regions[name] = _region(name, cells, facets[sel])
    regions.update(_geometric_regions(points, cells, list(specs)))
    mesh = meshio.Mesh(points, [(kind, cells)])
    from .massprops import mesh_mass_properties

    try:
        mp = mesh_mass_properties(points, cells)
    except ValueError:
        raise GeometryError(f"geometry.file: {path.name} has inverted elements (non-positive Jacobian); "
                            "check its node order") from None
    stats = {"measure": None, "n_elements": len(cells), "n_nodes": len(points),
             "mesh_mass": mp.to_dict()}
    return Part(name=path.stem, mesh=mesh, regions=regions, fidelity="imported",
                params={"file": str(path)}, cad_mass=None, quality=stats)
