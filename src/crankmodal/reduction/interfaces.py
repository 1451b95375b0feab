"""Bearing interfaces: one 6-DOF interface node per region, tied rigidly or by a distributing coupling.

An interface node sits at the exact centre of a bore (the Region's
:class:`~crankmodal.part.CylindricalSurface`, not a mesh average). Its six coordinates
``q = (t, θ)`` (m, rad) are tied to the region's surface nodes in one of two ways:

``rigid`` (RBE2-like)
    Every surface node follows the rigid motion of the node, ``u_i = t + θ × (x_i − c)``. The
    surface DOFs are eliminated by the sparse map :func:`rigid_map`; the bore cannot ovalise.
``distributing`` (RBE3-like)
    The node moves with the area-weighted mean motion of the surface: ``q`` is the L²(Γ)
    projection of the surface displacement on rigid motions about ``c``,
    ``q = argmin ∫_Γ |u − (t + θ × (x − c))|² dA``. That is six sparse constraint rows
    ``q = G u`` (:func:`distributing_rows`) with ``G R = I`` for rigid fields ``R``: the
    translation is the area mean of ``u`` when ``c`` is the surface centroid, and the surface
    stays free to ovalise. The integrals use the (curved, isoparametric) surface triangles of
    the mesh, so ``G u`` is exact for the FE displacement field.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import ParameterError
from ..fem.loads import facet_quadrature
from ..topology import facet_midnodes

KINDS = ("rigid", "distributing")


@dataclass
class Interface:
    """One interface node and the surface it is tied to.

    Attributes
    ----------
    name : str
        Region name.
    kind : str
        ``rigid`` or ``distributing``.
    centre : ndarray, shape (3,)
        Interface node position, m.
    axis : ndarray, shape (3,) or None
        Bore axis (unit) when the region is cylindrical.
    radius : float or None
        m.
    centre_source : str
        ``cylinder`` (exact, from the geometry), ``fit`` (least-squares cylinder) or
        ``centroid`` (area centroid of a non-cylindrical region, e.g. an end face).
    nodes : ndarray of int
        Mesh points of the surface (corner and mid-side nodes).
    facets : ndarray of int, shape (n_facets, 3)
        Corner triangles of the surface.
    """

    name: str
    kind: str
    centre: np.ndarray
    axis: np.ndarray | None
    radius: float | None
    centre_source: str
    nodes: np.ndarray
    facets: np.ndarray

    def to_dict(self) -> dict:
        return {"name": self.name, "kind": self.kind, "centre_m": np.asarray(self.centre).tolist(),
                "axis": None if self.axis is None else np.asarray(self.axis).tolist(),
                "radius_m": self.radius, "centre_source": self.centre_source,
                "n_nodes": len(self.nodes)}


def surface_mass(points: np.ndarray, facets: np.ndarray, cells: np.ndarray):
    """Scalar surface mass matrix ``∫_Γ N_a N_b dA`` of a region (isoparametric triangles).

    Parameters
    ----------
    points : ndarray, shape (n_points, 3)
    facets : ndarray, shape (n_facets, 3)
        Corner triangles.
    cells : ndarray, shape (n_elements, 4 or 10)
        Volume connectivity (for the mid-side nodes of P2 triangles).

    Returns
    -------
    nodes : ndarray of int
        Sorted surface nodes.
    Ms : scipy.sparse.csr_matrix, shape (len(nodes), len(nodes))
        m².
    """
    tri, N, nda = facet_quadrature(points, cells, facets)
    dA = np.linalg.norm(nda, axis=2)  # (f, q): area element times quadrature weight
    me = np.einsum("qa,qb,fq->fab", N, N, dA)
    nodes, local = np.unique(tri, return_inverse=True)
    local = local.reshape(tri.shape)
    nloc = tri.shape[1]
    rows = np.repeat(local, nloc, axis=1).ravel()
    cols = np.tile(local, (1, nloc)).ravel()
    Ms = sp.csr_matrix((me.ravel(), (rows, cols)), shape=(len(nodes), len(nodes)))
    return nodes, Ms


def _is_planar(points: np.ndarray, facets: np.ndarray) -> bool:
    """True when every facet normal is parallel to one direction (to 1e-6)."""
    p = points[facets]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    sv = np.linalg.svd(n, compute_uv=False)
    return bool(sv[1] < 1e-6 * sv[0])


def interface_centre(points: np.ndarray, region, cells: np.ndarray):
    """Centre, axis, radius and source of an interface on ``region``.

    The region's exact CylindricalSurface when it has one; else a least-squares cylinder fit;
    else (a planar end face, say) the area centroid of the surface.
    """
    from ..fem.supports import fit_cylinder

    cyl = region.cylinder
    if cyl is not None:
        a = np.asarray(cyl.axis, float)
        return np.asarray(cyl.centre, float), a / np.linalg.norm(a), float(cyl.radius), "cylinder"
    if not _is_planar(points, np.asarray(region.facets)):
        try:
            cyl = fit_cylinder(points, np.asarray(region.facets))
            return (np.asarray(cyl.centre, float), np.asarray(cyl.axis, float),
                    float(cyl.radius), "fit")
        except (ValueError, np.linalg.LinAlgError):
            pass
    nodes, Ms = surface_mass(points, np.asarray(region.facets), cells)
    w = np.asarray(Ms.sum(axis=1)).ravel()
    return (w @ points[nodes]) / w.sum(), None, None, "centroid"


def make_interfaces(part, specs, cells: np.ndarray | None = None) -> list[Interface]:
    """Interfaces from ``specs``: a list of ``{"region": name, "kind": "rigid"|"distributing"}``.

    Nodes on a boundary line shared by two regions (adjacent bands of a crankpin) belong to the
    first interface listed; a distributing surface still integrates over all its facets.

    Parameters
    ----------
    part : Part
        The meshed part whose named regions the interfaces tie.
    specs : list of dict
        One ``{"region": name, "kind": "rigid" | "distributing"}`` per interface (``kind``
        defaults to ``rigid``: RBE2-like; ``distributing``: RBE3-like, no stiffness added).
    cells : ndarray, optional
        The volume cells (default: the part mesh's first cell block).

    Returns
    -------
    list of Interface
        One 6-DOF interface node each, at the exact bore-axis centre of its region.

    Raises
    ------
    ParameterError
        Naming ``interfaces[i].kind`` (unknown kind) or ``interfaces[i].region`` (unknown
        region, no facets, or wholly inside an earlier interface); ``i`` indexes ``specs``. The
        ``[reduction]`` stage re-raises it under the scene key ``reduction.interfaces[i]...``.
    """
    from ..arguments import instance
    from ..part import Part

    instance("part", part, Part, "a Part (build_part, import_mesh)")
    points = np.asarray(part.mesh.points, float)[:, :3]
    if cells is None:
        cells = np.asarray(part.mesh.cells[0].data)
    out: list[Interface] = []
    seen: dict[int, str] = {}
    for i, spec in enumerate(specs):
        name, kind = spec["region"], spec.get("kind", "rigid")
        key = f"interfaces[{i}]"
        if kind not in KINDS:
            raise ParameterError(f"{key}.kind", f"must be one of {', '.join(KINDS)}; got {kind!r}")
        region = spec.get("region_object") or part.regions.get(name)
        if region is None:
            known = ", ".join(sorted(part.regions)) or "none"
            raise ParameterError(f"{key}.region", f"no region {name!r} in part {part.name!r}; "
                                                  f"regions: {known}")
        if len(region.facets) == 0:
            raise ParameterError(f"{key}.region", f"region {name!r} has no facets")
        nodes = np.asarray(region.nodes, np.int64)
        shared = np.fromiter((n in seen for n in nodes.tolist()), bool, len(nodes))
        if shared.all():
            raise ParameterError(f"{key}.region", f"{name!r} lies inside interface "
                                                  f"{seen[int(nodes[0])]!r}; interfaces must not "
                                                  f"overlap")
        nodes = nodes[~shared]  # a node on a common boundary line belongs to the first interface
        seen.update(dict.fromkeys(nodes.tolist(), name))
        c, a, r, src = interface_centre(points, region, cells)
        out.append(Interface(name=name, kind=kind, centre=c, axis=a, radius=r, centre_source=src,
                             nodes=nodes, facets=np.asarray(region.facets, np.int64)))
    return out


def split_region(region, points: np.ndarray, segments: int, cells: np.ndarray):
    """Cut a cylindrical region into ``segments`` equal axial bands (e.g. two rods on one pin).

    Returns a list of :class:`~crankmodal.part.Region` named ``<name>_seg<k>`` (k from 1), each
    with its own exact CylindricalSurface (centre shifted along the axis, length / segments).
    Nodes on a cut line belong to the lower band only, so rigid bands do not overlap.
    """
    from ..fem.supports import fit_cylinder
    from ..part import CylindricalSurface, Region

    cyl = region.cylinder or fit_cylinder(points, np.asarray(region.facets))
    a = np.asarray(cyl.axis, float) / np.linalg.norm(cyl.axis)
    c0 = np.asarray(cyl.centre, float)
    s = (points[region.facets].mean(axis=1) - c0) @ a
    edges = np.linspace(-0.5 * cyl.length, 0.5 * cyl.length, segments + 1)
    band = np.clip(np.searchsorted(edges, s) - 1, 0, segments - 1)
    out = []
    taken = np.zeros(0, np.int64)
    for k in range(segments):
        f = np.asarray(region.facets)[band == k]
        mid = 0.5 * (edges[k] + edges[k + 1])
        nodes = np.unique(f) if cells.shape[1] == 4 else np.unique(
            np.concatenate([f.ravel(), facet_midnodes(f, cells).ravel()]))
        nodes = np.setdiff1d(nodes, taken)  # a node on a cut belongs to the first band
        taken = np.union1d(taken, nodes)
        out.append(Region(name=f"{region.name}_seg{k + 1}", facets=f, nodes=nodes,
                          cylinder=CylindricalSurface(c0 + mid * a, a, cyl.radius,
                                                      cyl.length / segments)))
    return out


def interface_rigid_fields(interfaces: list[Interface]) -> np.ndarray:
    """Interface coordinates of the six rigid-body motions about the origin, shape (6 m, 6).

    Columns as :func:`crankmodal.fem.assembly.rigid_body_modes`: translations x, y, z, then
    rotations about the x, y, z axes through the origin.
    """
    from ..fem.assembly import rigid_body_modes

    blocks = []
    for itf in interfaces:
        b = np.zeros((6, 6))
        b[:3] = rigid_body_modes(itf.centre[None, :])
        b[3:, 3:] = np.eye(3)
        blocks.append(b)
    return np.vstack(blocks)


def rigid_map(points: np.ndarray, interfaces: list[Interface]):
    """Surface DOFs of the rigid interfaces and their map from the interface coordinates.

    Returns
    -------
    dofs : ndarray of int
        Eliminated DOFs ``3 * point + component``, sorted.
    R : scipy.sparse.csr_matrix, shape (len(dofs), 6 m)
        ``u[dofs] = R q`` with ``q`` the 6 m interface coordinates (all interfaces; columns of
        distributing ones are empty).
    """
    from ..fem.assembly import rigid_body_modes

    rows, cols, vals = [], [], []
    m = len(interfaces)
    for r, itf in enumerate(interfaces):
        if itf.kind != "rigid":
            continue
        Rl = rigid_body_modes(points[itf.nodes], itf.centre)  # (3 n_s, 6)
        d = (3 * itf.nodes[:, None] + np.arange(3)).ravel()
        rows.append(np.repeat(d, 6))
        cols.append(np.tile(6 * r + np.arange(6), len(d)))
        vals.append(Rl.ravel())
    if not rows:
        return np.zeros(0, np.int64), sp.csr_matrix((0, 6 * m))
    rows, cols, vals = map(np.concatenate, (rows, cols, vals))
    keep = vals != 0.0
    dofs, local = np.unique(rows, return_inverse=True)
    R = sp.csr_matrix((vals[keep], (local[keep], cols[keep])), shape=(len(dofs), 6 * m))
    return dofs, R


def distributing_rows(points: np.ndarray, cells: np.ndarray, interfaces: list[Interface]):
    """Constraint rows ``q_r = G_r u`` of the distributing interfaces.

    Returns
    -------
    rows : ndarray of int
        Interface coordinates (indices into the 6 m) that are distributing.
    G : scipy.sparse.csr_matrix, shape (len(rows), 3 n_points)
        ``G = (Rᵀ M_Γ R)⁻¹ Rᵀ M_Γ`` per interface: L²(Γ) projection on rigid motions about its
        centre, with ``M_Γ`` the surface mass matrix; ``G R = I`` for rigid fields.
    """
    from ..fem.assembly import rigid_body_modes

    n = len(points)
    out_rows, blocks = [], []
    for r, itf in enumerate(interfaces):
        if itf.kind != "distributing":
            continue
        nodes, Ms = surface_mass(points, itf.facets, cells)
        Rl = rigid_body_modes(points[nodes], itf.centre)  # (3 s, 6)
        Rn = Rl.reshape(len(nodes), 3, 6)
        B = np.stack([Ms @ Rn[:, :, k] for k in range(6)])  # (6, s, 3) = (Rᵀ M_Γ) per node
        A = np.einsum("kaj,ajl->kl", B, Rn)
        G = np.linalg.solve(A, B.reshape(6, -1))  # (6, 3 s)
        d = (3 * nodes[:, None] + np.arange(3)).ravel()
        blocks.append(sp.csr_matrix((G.ravel(), (np.repeat(np.arange(6), len(d)),
                                                 np.tile(d, 6))), shape=(6, 3 * n)))
        out_rows.append(6 * r + np.arange(6))
    if not blocks:
        return np.zeros(0, np.int64), sp.csr_matrix((0, 3 * n))
    return np.concatenate(out_rows), sp.vstack(blocks, format="csr")


def tie_transformation(n_dofs: int, interfaces: list[Interface], points: np.ndarray):
    """``u = T [u_rest; q]``: the full model with its rigid interfaces tied (surface DOFs gone).

    Returns ``(T, rest)`` with ``rest`` the kept mesh DOFs (every DOF not on a rigid surface)
    and ``T`` of shape (n_dofs, len(rest) + 6 m). Used to check the reduction against a full
    solve of the same tied model.
    """
    dofs, R = rigid_map(points, interfaces)
    rest = np.setdiff1d(np.arange(n_dofs), dofs)
    m6 = R.shape[1]
    top = sp.csr_matrix((np.ones(len(rest)), (rest, np.arange(len(rest)))),
                        shape=(n_dofs, len(rest) + m6))
    Rc = R.tocoo()
    low = sp.csr_matrix((Rc.data, (dofs[Rc.row], len(rest) + Rc.col)),
                        shape=(n_dofs, len(rest) + m6))
    return (top + low).tocsr(), rest
