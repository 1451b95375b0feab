"""Rotor inertias about the shaft axis integrated over a tetrahedral mesh of the real part.

The lumped chain's inertias come from handbook formulas (seed 004 eqs. 2-5); once the geometry
stage has meshed the crankshaft, the same rotors can be measured exactly: cut the part into axial
slabs (one per rotor, cut planes normal to the shaft axis) and integrate ``rho |r_perp|^2`` over
the elements whose centroids fall in each slab. For a straight-edged tetrahedron with corners
``x_a`` the second moments are exact::

    int x x^T dV = V / 20 (sum_a x_a x_a^T + (sum_a x_a)(sum_a x_a)^T)

Second-order (tetra10) cells are integrated on their four corner nodes, i.e. with straight edges.
Elements straddling a cut go wholly to the slab holding their centroid, so the split converges
with the mesh size while the total is exact.
"""

from __future__ import annotations

import numpy as np


def slab_axial_inertias(
    points, cells, density: float, cuts, axis_point=(0.0, 0.0, 0.0), axis_direction=(1.0, 0.0, 0.0)
) -> np.ndarray:
    """Inertia about the shaft axis of each axial slab of a tetrahedral mesh, kg m^2.

    Parameters
    ----------
    points : array_like, shape (n_nodes, 3)
        Node coordinates, m.
    cells : array_like of int, shape (n_cells, 4 or 10)
        Tetrahedra (meshio node order; only the four corners are used).
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
    """
    e = np.asarray(axis_direction, float)
    e = e / np.linalg.norm(e)
    x = np.asarray(points, float)[np.asarray(cells)[:, :4]] - np.asarray(axis_point, float)  # (c, 4, 3)
    vol = np.abs(np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0])) / 6.0
    s = x.sum(axis=1)
    second = vol[:, None, None] / 20.0 * (np.einsum("cai,caj->cij", x, x) + np.einsum("ci,cj->cij", s, s))
    # int |r_perp|^2 dV = trace(S) - e.S.e with S the second-moment tensor about the axis point
    r2 = np.einsum("cii->c", second) - np.einsum("i,cij,j->c", e, second, e)
    slab = np.searchsorted(np.asarray(cuts, float), (s / 4.0) @ e)
    return density * np.bincount(slab, weights=r2, minlength=len(cuts) + 1)
