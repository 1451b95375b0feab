"""Mass properties per unit density: from the CAD solid (gmsh OCC) and integrated over a mesh."""

from __future__ import annotations

import numpy as np

from ..part import MassProperties
from ..topology import TET10_EDGES


def cad_mass_properties(gmsh, volumes: list) -> MassProperties:
    """Volume, centroid and centroidal inertia per density of OCC volumes taken together.

    gmsh returns each volume's inertia about its own centre of mass; the parts are combined
    with the parallel-axis theorem.
    """
    occ = gmsh.model.occ
    vols = np.array([occ.getMass(3, v) for v in volumes])
    cogs = np.array([occ.getCenterOfMass(3, v) for v in volumes])
    total = vols.sum()
    c = (vols[:, None] * cogs).sum(axis=0) / total
    inertia = np.zeros((3, 3))
    for v, m, g in zip(volumes, vols, cogs):
        d = g - c
        inertia += np.asarray(occ.getMatrixOfInertia(3, v)).reshape(3, 3) + m * (d @ d * np.eye(3) - np.outer(d, d))
    return MassProperties(volume=float(total), centroid=c, inertia_per_density=inertia)


#: Polynomial degree a tetra10 cell's moments need: det J (3) times x x^T (4) on the P2 map.
TET10_DEGREE = 7


def _reference(n_nodes: int):
    """A tetrahedral rule exact for the cell's moments, and the shape functions on it.

    scikit-fem's rule of order ``n`` integrates polynomials up to degree ``n - 1`` exactly:
    order 3 for a straight tetra (x x^T, degree 2), order 8 (31 points) for tetra10 (degree 7;
    its 24-point "order 7" rule missed by 1e-6 on a strongly curved cell).
    Shape functions in meshio's (VTK) node order: corners, then the mid-edge nodes of
    :data:`crankmodal.topology.TET10_EDGES`.

    Returns
    -------
    N : ndarray, shape (q, n_nodes)
    dN : ndarray, shape (q, n_nodes, 3)
        Gradients in the reference coordinates.
    w : ndarray, shape (q,)
        Weights (summing to 1/6, the reference volume).
    """
    from skfem.quadrature import get_quadrature
    from skfem.refdom import RefTet

    X, w = get_quadrature(RefTet, (TET10_DEGREE if n_nodes == 10 else 2) + 1)
    lam = np.vstack([1.0 - X.sum(axis=0), X]).T                       # (q, 4) barycentric
    dlam = np.array([[-1.0, -1.0, -1.0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    if n_nodes == 4:
        return lam, np.broadcast_to(dlam, (len(w), 4, 3)), w
    i, j = TET10_EDGES.T
    N = np.hstack([lam * (2 * lam - 1), 4 * lam[:, i] * lam[:, j]])
    dN = np.concatenate([(4 * lam - 1)[:, :, None] * dlam,
                         4 * (lam[:, j, None] * dlam[i] + lam[:, i, None] * dlam[j])], axis=1)
    return N, dN, w


def cell_moments(points: np.ndarray, cells: np.ndarray, chunk: int = 20000,
                 oriented: bool = True):
    """Volume, first and second moments of every tetra/tetra10 cell (meshio node order).

    The isoparametric map of each cell is integrated exactly: a curved (P2) cell's moments are
    those of its quadratic geometry, not of its straight-edged corners.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    cells : ndarray of int, shape (c, 4 or 10)
    chunk : int
        Cells integrated at a time (about 2 kB each).
    oriented : bool
        ``True``: cells must be positively oriented (meshio's convention; a negative Jacobian
        means a wrong node order). ``False``: each cell may have either orientation (that of its
        corners); only a Jacobian that changes sign inside a cell is an error.

    Returns
    -------
    m0 : ndarray, shape (c,)
        ``int dV``, m^3.
    m1 : ndarray, shape (c, 3)
        ``int x dV``, m^4.
    m2 : ndarray, shape (c, 3, 3)
        ``int x x^T dV``, m^5.

    Raises
    ------
    ValueError
        If a cell has neither 4 nor 10 nodes, or a non-positive Jacobian at a quadrature point
        (inverted, or folded by its mid-edge nodes).
    """
    points, cells = np.asarray(points, float), np.asarray(cells)
    if cells.ndim != 2 or cells.shape[1] not in (4, 10):
        raise ValueError(f"cells: need shape (n, 4) or (n, 10), got {cells.shape}")
    N, dN, w = _reference(cells.shape[1])
    m0, m1, m2 = np.empty(len(cells)), np.empty((len(cells), 3)), np.empty((len(cells), 3, 3))
    for s in range(0, len(cells), chunk):
        X = points[cells[s:s + chunk]]                                      # (e, n, 3)
        J = np.einsum("qnk,enj->eqjk", dN, X, optimize=True)                # dx_j / dxi_k
        det = np.linalg.det(J)
        if not oriented:
            c = X[:, :4]
            det *= np.sign(np.einsum("ej,ej->e", np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]),
                                     c[:, 3] - c[:, 0]))[:, None]
        bad = np.any(det <= 0, axis=1)
        if np.any(bad):
            raise ValueError(f"{int(bad.sum())} elements have a non-positive Jacobian "
                             "(inverted, or folded by their mid-edge nodes)")
        dv = det * w                                                        # (e, q)
        x = np.einsum("qn,enj->eqj", N, X, optimize=True)                   # (e, q, 3)
        m0[s:s + chunk] = dv.sum(axis=1)
        m1[s:s + chunk] = np.einsum("eq,eqj->ej", dv, x)
        m2[s:s + chunk] = np.einsum("eq,eqi,eqj->eij", dv, x, x)
    return m0, m1, m2


def mesh_mass_properties(points: np.ndarray, cells: np.ndarray, chunk: int = 20000) -> MassProperties:
    """Mass properties per density integrated over a tetra/tetra10 mesh (meshio node order).

    Sums :func:`cell_moments` (exact for each cell's isoparametric map).

    Raises
    ------
    ValueError
        If an element has a non-positive Jacobian at a quadrature point.
    """
    m0, m1, m2 = (m.sum(axis=0) for m in cell_moments(points, cells, chunk))
    c = m1 / m0
    second = m2 - m0 * np.outer(c, c)                        # centroidal second moments
    inertia = np.trace(second) * np.eye(3) - second
    return MassProperties(volume=float(m0), centroid=c, inertia_per_density=inertia)


def compare(cad: MassProperties, mesh: MassProperties) -> dict:
    """Relative differences mesh vs CAD: volume, centroid (over the inertia radius) and inertia."""
    radius = np.sqrt(np.trace(cad.inertia_per_density) / (2 * cad.volume))
    return {
        "volume": float(mesh.volume / cad.volume - 1),
        "centroid": float(np.linalg.norm(mesh.centroid - cad.centroid) / radius),
        "inertia": float(np.linalg.norm(mesh.inertia_per_density - cad.inertia_per_density)
                         / np.linalg.norm(cad.inertia_per_density)),
    }
