"""Rotor inertias about the shaft axis integrated over a tetrahedral mesh of the real part.

The lumped chain's inertias come from handbook formulas (seed 004 eqs. 2-5); once the geometry
stage has meshed the crankshaft, the same rotors can be measured exactly: cut the part into axial
slabs (one per rotor, cut planes normal to the shaft axis) and integrate ``rho |r_perp|^2`` over
the elements whose centroids fall in each slab.

Each cell is integrated exactly for its isoparametric map
(:func:`crankmodal.geometry.massprops.cell_moments`): a ``tetra10`` cell with its quadratic
geometry, whose mid-edge nodes gmsh puts on the CAD surface of journals, pins and webs. The error
left is the geometric one of the P2 surface (a gmsh cylinder: -3.5e-6 at R/h = 5, order 3.9-4.0),
not the h^2 of a corner-only, straight-edged integration (-9.6e-3 there); a ``tetra10`` cell whose
mid-edge nodes sit at the edge midpoints gives the straight-edged value to rounding.

Elements straddling a cut go wholly to the slab holding their centroid (the mean of the four
corners), so the split converges with the mesh size while the total is exact for the mesh.
"""

from __future__ import annotations

import numpy as np

from ..errors import NumericalError


def slab_axial_inertias(
    points, cells, density: float, cuts, axis_point=(0.0, 0.0, 0.0), axis_direction=(1.0, 0.0, 0.0)
) -> np.ndarray:
    """Inertia about the shaft axis of each axial slab of a tetrahedral mesh, kg m^2.

    Parameters
    ----------
    points : array_like, shape (n_nodes, 3)
        Node coordinates, m.
    cells : array_like of int, shape (n_cells, 4 or 10)
        Tetrahedra in meshio (VTK) node order: ``tetra`` cells are integrated exactly as
        straight-edged, ``tetra10`` cells with their quadratic (curved) geometry.
    density : float
        kg/m^3.
    cuts : array_like
        Increasing axial coordinates (m, measured from ``axis_point`` along the axis) of the cut
        planes between rotors; ``len(cuts) + 1`` slabs result.
    axis_point, axis_direction : array_like, shape (3,)
        The shaft axis.

    Returns
    -------
    ndarray, shape (len(cuts) + 1,)
        Inertia of each slab in order along the axis.

    Raises
    ------
    ValueError
        If ``cells`` has neither 4 nor 10 columns.
    NumericalError
        If a ``tetra10`` cell folds over.
    """
    e = np.asarray(axis_direction, float)
    e = e / np.linalg.norm(e)
    from ..geometry.massprops import cell_moments

    a = np.asarray(axis_point, float)
    try:  # moments about the axis point: S = int (x - a)(x - a)^T dV
        _, _, S = cell_moments(np.asarray(points, float) - a, cells, oriented=False)
    except ValueError as exc:
        raise NumericalError(f"torsion: {exc}; remesh with a smaller geometry.mesh_size or "
                             "geometry.element_order = 1") from None
    # int |r_perp|^2 dV = trace(S) - e.S.e
    r2 = np.einsum("cii->c", S) - np.einsum("i,cij,j->c", e, S, e)
    corners = np.asarray(points, float)[np.asarray(cells)[:, :4]].mean(axis=1) - a
    slab = np.searchsorted(np.asarray(cuts, float), corners @ e)
    return density * np.bincount(slab, weights=r2, minlength=len(cuts) + 1)
