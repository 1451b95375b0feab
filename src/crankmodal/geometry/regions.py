"""Named regions: find the faces of a built solid, tag them as physical groups, read them back.

A :class:`RegionSpec` says where a region lies (a cylinder about an axis parallel to z, or a
plane z = const); :func:`tag_regions` finds the matching faces on the synchronised gmsh model
and makes one physical surface group per region; :func:`regions_from_mesh` turns the meshed
groups into :class:`crankmodal.part.Region` objects with the exact :class:`~crankmodal.part.CylindricalSurface`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..part import CylindricalSurface, Region

#: Relative tolerance of geometric face matching.
TOL = 1e-6


@dataclass
class RegionSpec:
    """Where a named region lies.

    Attributes
    ----------
    name : str
        Region name.
    kind : str
        ``cylinder`` (faces on a cylinder of ``radius`` about the axis through ``axis_xy``
        along z, within ``z_range``), ``plane_z`` (planar faces at z = ``z_range[0]``; when
        ``radius`` is finite only faces reaching that radius) or ``cylinder_axis`` /
        ``box`` for imported parts (see :mod:`crankmodal.geometry.importers`).
    axis_xy : ndarray
        x, y of the axis, m (for ``cylinder_axis``: a point and direction, shape (6,)).
    radius : float
        m.
    z_range : tuple
        Axial extent, m (for ``box``: the six bounds).
    """

    name: str
    kind: str
    axis_xy: np.ndarray
    radius: float
    z_range: tuple


def _scale(gmsh) -> float:
    b = gmsh.model.getBoundingBox(-1, -1)
    return float(max(b[3] - b[0], b[4] - b[1], b[5] - b[2]))


def find_circles(gmsh, centre, radius: float) -> list:
    """Tags of the full circles (curves) of ``radius`` centred at ``centre`` in a plane z = const."""
    tol = TOL * _scale(gmsh)
    found = []
    for _, c in gmsh.model.getEntities(1):
        if gmsh.model.getType(1, c) != "Circle":
            continue
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, c)
        if (abs(z1 - z0) < 2 * tol + 2e-7 and abs(0.5 * (z0 + z1) - centre[2]) < tol + 2e-7
                and abs(0.5 * (x0 + x1) - centre[0]) < tol + 2e-7 and abs(0.5 * (y0 + y1) - centre[1]) < tol + 2e-7
                and abs(0.5 * (x1 - x0) - radius) < tol + 2e-7 and abs(0.5 * (y1 - y0) - radius) < tol + 2e-7):
            found.append(c)
    return found


def _sample(gmsh, s: int, n: int = 5) -> np.ndarray:
    lo, hi = gmsh.model.getParametrizationBounds(2, s)
    u = np.linspace(lo[0], hi[0], n)
    v = np.linspace(lo[1], hi[1], n)
    uv = np.array([(a, b) for a in u for b in v]).ravel()
    return np.asarray(gmsh.model.getValue(2, s, uv)).reshape(-1, 3)


def _matches(gmsh, s: int, spec: RegionSpec, tol: float) -> bool:
    kind = gmsh.model.getType(2, s)
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, s)
    slack = tol + 2e-7
    if spec.kind == "cylinder":
        if kind != "Cylinder" or z0 < spec.z_range[0] - slack or z1 > spec.z_range[1] + slack:
            return False
        pts = _sample(gmsh, s)
        rad = np.hypot(pts[:, 0] - spec.axis_xy[0], pts[:, 1] - spec.axis_xy[1])
        return bool(np.all(np.abs(rad - spec.radius) < slack))
    if spec.kind == "plane_z":
        if kind != "Plane" or abs(z0 - spec.z_range[0]) > slack or abs(z1 - spec.z_range[0]) > slack:
            return False
        if np.isfinite(spec.radius):
            reach = 0.5 * max(x1 - x0, y1 - y0)
            return abs(reach - spec.radius) < slack
        return True
    if spec.kind == "cylinder_axis":
        if kind not in ("Cylinder", "BSplineSurface", "SurfaceOfRevolution"):
            return False
        pts = _sample(gmsh, s)
        p0, d = spec.axis_xy[:3], spec.axis_xy[3:] / np.linalg.norm(spec.axis_xy[3:])
        rel = pts - p0
        rad = np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)
        return bool(np.all(np.abs(rad - spec.radius) < max(slack, 1e-5 * spec.radius)))
    if spec.kind == "box":
        b = spec.z_range
        return (x0 >= b[0] - slack and x1 <= b[1] + slack and y0 >= b[2] - slack and y1 <= b[3] + slack
                and z0 >= b[4] - slack and z1 <= b[5] + slack)
    raise ValueError(spec.kind)


def tag_regions(gmsh, specs: list, required: bool = True) -> dict:
    """Make one physical surface group per spec; return ``name -> (group tag, face tags)``.

    Raises
    ------
    GeometryError
        When a required region matches no face.
    """
    tol = TOL * _scale(gmsh)
    faces = [s for _, s in gmsh.model.getEntities(2)]
    out = {}
    for spec in specs:
        hit = [s for s in faces if _matches(gmsh, s, spec, tol)]
        if not hit:
            if required:
                raise GeometryError(f"region {spec.name!r}: no surface of the part matches its definition")
            continue
        tag = gmsh.model.addPhysicalGroup(2, hit, name=spec.name)
        out[spec.name] = (tag, hit)
    return out


def exact_cylinder(gmsh, spec: RegionSpec, faces: list) -> CylindricalSurface | None:
    """The exact cylinder a region lies on, with the axial extent of its faces."""
    if spec.kind == "cylinder":
        boxes = np.array([gmsh.model.getBoundingBox(2, s) for s in faces])
        z0 = max(boxes[:, 2].min(), spec.z_range[0])  # bounding boxes carry a 1e-7 slack
        z1 = min(boxes[:, 5].max(), spec.z_range[1])
        return CylindricalSurface(centre=np.array([spec.axis_xy[0], spec.axis_xy[1], 0.5 * (z0 + z1)]),
                        axis=np.array([0.0, 0.0, 1.0]), radius=float(spec.radius), length=float(z1 - z0))
    if spec.kind == "cylinder_axis":
        p0, d = spec.axis_xy[:3], spec.axis_xy[3:] / np.linalg.norm(spec.axis_xy[3:])
        t = []
        for s in faces:
            pts = _sample(gmsh, s, 9)
            t += list((pts - p0) @ d)
        t0, t1 = min(t), max(t)
        return CylindricalSurface(centre=p0 + 0.5 * (t0 + t1) * d, axis=d, radius=float(spec.radius), length=float(t1 - t0))
    return None


def regions_from_mesh(gmsh, tagged: dict, specs: list, node_index: dict) -> dict:
    """Read the meshed physical groups back as :class:`~crankmodal.part.Region` objects.

    Parameters
    ----------
    tagged : dict
        Output of :func:`tag_regions`.
    specs : list of RegionSpec
        The specs, for exact cylinders.
    node_index : callable
        Maps an array of gmsh node tags to row indices of the mesh points.
    """
    by_name = {s.name: s for s in specs}
    regions = {}
    for name, (_, faces) in tagged.items():
        facets, nodes = [], []
        for s in faces:
            types, _, ntags = gmsh.model.mesh.getElements(2, s)
            for et, nt in zip(types, ntags):
                npe = gmsh.model.mesh.getElementProperties(et)[3]
                conn = node_index(np.asarray(nt, dtype=np.int64)).reshape(-1, npe)
                facets.append(conn[:, :3])
                nodes.append(conn.ravel())
        regions[name] = Region(
            name=name,
            facets=np.concatenate(facets) if facets else np.zeros((0, 3), int),
            nodes=np.unique(np.concatenate(nodes)) if nodes else np.zeros(0, int),
            cylinder=exact_cylinder(gmsh, by_name[name], faces) if name in by_name else None,
        )
    return regions
