"""Simple structured parts for verification and benchmarks: prismatic bars and thick tubes.

They are built without gmsh (a structured tetrahedral grid from scikit-fem, mapped), so tests can
make them in milliseconds. P2 mid-side nodes are placed in the parameter space before mapping, so
a tube's P2 elements follow its circles (curved, isoparametric). The bar lives in
:mod:`crankmodal.fem.bar` (production uses it for four-bar links); it is re-exported here.
"""

from __future__ import annotations

import numpy as np

from ..part import CylindricalSurface, MassProperties, Part, Region
from ..topology import boundary_facets, facet_nodes
from .bar import (TETS_PER_CELL, _grid, bar, bar_divisions, bar_elements,  # noqa: F401
                  check_bar_size, elevate_to_p2, region)


def tube(inner_radius=0.05, outer_radius=0.1, length=0.1, divisions=(4, 16, 2),
         angle=2 * np.pi, order=2) -> Part:
    """A thick tube along z (a full ring, or a sector of ``angle`` rad starting at +x).

    Regions: ``bore`` (r = inner, with its CylindricalSurface), ``outer`` (with its
    CylindricalSurface), ``end_z0``, ``end_z1``, and for a sector ``cut_0`` (y = 0) and ``cut_1`` (the other cut).
    """
    full = np.isclose(angle, 2 * np.pi)
    p, t = _grid(divisions)
    if order == 2:
        p, t = elevate_to_p2(p, t)
    a, b = inner_radius, outer_radius
    r = a + (b - a) * p[:, 0]
    th = angle * p[:, 1]
    z = length * p[:, 2]
    x = np.column_stack([r * np.cos(th), r * np.sin(th), z])
    if full:  # merge the seam θ = 0 ≡ 2π
        key = np.round(p * 2 * np.array(divisions)).astype(np.int64)  # half-steps: P2 too
        key[:, 1] %= 2 * divisions[1]
        _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
        x, t = x[first], inv.ravel()[t]
    import meshio

    mesh = meshio.Mesh(x, [("tetra10" if order == 2 else "tetra", t)])
    pts, cells = mesh.points, t
    fac = boundary_facets(cells)
    tol = 1e-6 * b
    rad = lambda c: np.hypot(c[:, 0], c[:, 1])
    cyl = lambda R: CylindricalSurface(np.array([0, 0, length / 2]), np.array([0.0, 0, 1]), R,
                                       length)
    # facet centroids of a curved surface lie slightly inside it: select by node radii instead
    rmin = np.hypot(*pts[fac][:, :, :2].transpose(2, 0, 1)).min(axis=1)
    rmax = np.hypot(*pts[fac][:, :, :2].transpose(2, 0, 1)).max(axis=1)
    sel_bore = np.abs(rmax - a) < tol
    sel_outer = np.abs(rmin - b) < tol
    regions = {
        "bore": Region("bore", fac[sel_bore], facet_nodes(fac[sel_bore], cells), cyl(a)),
        "outer": Region("outer", fac[sel_outer], facet_nodes(fac[sel_outer], cells), cyl(b)),
        "end_z0": region("end_z0", pts, cells, fac, lambda c: c[:, 2] < tol),
        "end_z1": region("end_z1", pts, cells, fac, lambda c: c[:, 2] > length - tol),
    }
    if not full:
        n1 = np.array([-np.sin(angle), np.cos(angle), 0.0])
        regions["cut_0"] = region("cut_0", pts, cells, fac, lambda c: np.abs(c[:, 1]) < tol)
        regions["cut_1"] = region("cut_1", pts, cells, fac,
                                  lambda c: (np.abs(c @ n1) < tol) & (rad(c) > 0.5 * a))
    vol = 0.5 * angle * (b * b - a * a) * length
    cad = None
    if full:
        izz = 0.5 * vol * (a * a + b * b)
        ixx = vol * (3 * (a * a + b * b) + length ** 2) / 12
        cad = MassProperties(volume=vol, centroid=np.array([0, 0, length / 2]),
                             inertia_per_density=np.diag([ixx, ixx, izz]))
    return Part(name="tube", mesh=mesh, regions=regions, fidelity="full",
                params={"inner_radius": a, "outer_radius": b, "length": length,
                        "angle": angle}, cad_mass=cad)
