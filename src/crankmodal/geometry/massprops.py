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


def _tet_rule(n: int = 5):
    """Collapsed Gauss rule on the unit tetrahedron: points (m, 3) and weights (m,), exact to degree 2n-3."""
    x, w = np.polynomial.legendre.leggauss(n)
    x, w = 0.5 * (x + 1), 0.5 * w
    a, b, c = (g.ravel() for g in np.meshgrid(x, x, x, indexing="ij"))
    wa, wb, wc = (g.ravel() for g in np.meshgrid(w, w, w, indexing="ij"))
    pts = np.column_stack([a * (1 - b) * (1 - c), b * (1 - c), c])
    return pts, wa * wb * wc * (1 - b) * (1 - c) ** 2


def _shape(pts: np.ndarray, n_nodes: int):
    """Shape functions (q, n) and their reference gradients (q, n, 3) of tetra/tetra10."""
    xi, eta, zeta = pts.T
    lam = np.column_stack([1 - xi - eta - zeta, xi, eta, zeta])
    dlam = np.array([[-1, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    if n_nodes == 4:
        return lam, np.broadcast_to(dlam, (len(pts), 4, 3))
    N = [lam[:, i] * (2 * lam[:, i] - 1) for i in range(4)]
    dN = [(4 * lam[:, i] - 1)[:, None] * dlam[i] for i in range(4)]
    for i, j in TET10_EDGES:
        N.append(4 * lam[:, i] * lam[:, j])
        dN.append(4 * (lam[:, j][:, None] * dlam[i] + lam[:, i][:, None] * dlam[j]))
    return np.column_stack(N), np.stack(dN, axis=1)


def mesh_mass_properties(points: np.ndarray, cells: np.ndarray, chunk: int = 20000) -> MassProperties:
    """Mass properties per density integrated over a tetra/tetra10 mesh (meshio node order).

    The isoparametric map of every element is integrated with a collapsed Gauss rule exact
    for the integrands: 27 points for tetra (degree 2), 125 for the quadratic geometry of
    tetra10 (degree 7).

    Raises
    ------
    ValueError
        If an element has a non-positive Jacobian at a quadrature point.
    """
    pts, w = _tet_rule(5 if cells.shape[1] == 10 else 3)
    N, dN = _shape(pts, cells.shape[1])
    m0, m1, m2 = 0.0, np.zeros(3), np.zeros((3, 3))
    for s in range(0, len(cells), chunk):
        X = points[cells[s:s + chunk]]                      # (e, n, 3)
        J = np.einsum("qnk,enj->eqjk", dN, X, optimize=True)                # (e, q, 3, 3): dx_j/dxi_k
        det = np.linalg.det(J)
        if np.any(det <= 0):
            raise ValueError("mesh has elements with non-positive Jacobian")
        dv = det * w                                         # (e, q)
        x = np.einsum("qn,enj->eqj", N, X, optimize=True)                   # (e, q, 3)
        m0 += dv.sum()
        m1 += np.einsum("eq,eqj->j", dv, x)
        m2 += np.einsum("eq,eqi,eqj->ij", dv, x, x)
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
