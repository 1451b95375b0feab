"""Consistent nodal loads on boundary regions: pressure, total force, remote force (RBE3), and
a pin's force on a bore (bearing load).

Region facets are corner triangles; on a ``tetra10`` mesh their mid-edge nodes are looked up in
the volume connectivity and the 6-node facets are integrated isoparametrically (a pressure on a
curved bore pushes along the true normal). Facets are oriented outward from the owning element.
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..topology import facet_midnodes

_TET_FACES = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
_TET_OPPOSITE = np.array([3, 2, 1, 0])
# degree-4 rule on the reference triangle (Strang-Fix / Dunavant, 6 points), weights sum to 1/2
_A, _B = 0.445948490915965, 0.091576213509771
_QX = np.array([[_A, _A], [1 - 2 * _A, _A], [_A, 1 - 2 * _A],
                [_B, _B], [1 - 2 * _B, _B], [_B, 1 - 2 * _B]])
_QW = 0.5 * np.array([0.223381589678011] * 3 + [0.109951743655322] * 3)


def _keys(a, n):
    a = np.sort(a, axis=-1).astype(np.int64)
    return (a[..., 0] * n + a[..., 1]) * n + a[..., 2]


def oriented_facets(cells: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """Find the element owning each facet.

    Returns
    -------
    f : ndarray (n_facets, 6)
        Corner columns filled, the three mid-node columns -1 (filled by the caller).
    opposite : ndarray (n_facets,)
        The owning element's vertex not on the facet (gives the outward side).
    element : ndarray (n_facets,)
    """
    n = int(max(cells.max(), facets.max())) + 1
    fk = _keys(cells[:, :4][:, _TET_FACES], n).ravel()
    order = np.argsort(fk)
    fk_sorted = fk[order]
    q = _keys(facets, n)
    pos = np.searchsorted(fk_sorted, q)
    pos = np.minimum(pos, len(fk_sorted) - 1)
    if np.any(fk_sorted[pos] != q):
        raise SceneError("region: a facet is not a face of any element")
    idx = order[pos]
    tet, face = idx // 4, idx % 4
    opp = cells[tet, _TET_OPPOSITE[face]]
    out = np.full((len(facets), 6), -1, np.int64)
    out[:, :3] = facets
    return out, opp, tet


def facet_quadrature(points: np.ndarray, cells: np.ndarray, facets: np.ndarray):
    """Nodes, shape-function values and area-vector weights on region facets.

    Returns
    -------
    nodes : ndarray (n_facets, k)
        k = 6 on tetra10 meshes, 3 on tetra meshes.
    N : ndarray (n_q, k)
        Shape functions at the quadrature points.
    nda : ndarray (n_facets, n_q, 3)
        Outward normal times area element times quadrature weight, m².
    """
    f, opp, _ = oriented_facets(cells, facets)
    p = points
    nrm = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    inward = np.einsum("ij,ij->i", nrm, p[opp] - p[f[:, 0]]) > 0
    f[inward, 1], f[inward, 2] = f[inward, 2].copy(), f[inward, 1].copy()
    xi, eta = _QX[:, 0], _QX[:, 1]
    L = np.stack([1 - xi - eta, xi, eta])  # (3, q)
    dL = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])  # dL_i/d(xi, eta)
    if cells.shape[1] == 10:
        f[:, 3:] = facet_midnodes(f[:, :3], cells)
        pairs = ((0, 1), (1, 2), (2, 0))
        N = np.vstack([L * (2 * L - 1)] + [4 * L[a] * L[b] for a, b in pairs]).T  # (q, 6)
        dN = np.zeros((len(xi), 6, 2))
        for i in range(3):
            dN[:, i, :] = (4 * L[i] - 1)[:, None] * dL[i]
        for k, (a, b) in enumerate(pairs):
            dN[:, 3 + k, :] = 4 * (L[b][:, None] * dL[a] + L[a][:, None] * dL[b])
        nodes = f
    else:
        N = L.T
        dN = np.broadcast_to(dL, (len(xi), 3, 2))
        nodes = f[:, :3]
    X = points[nodes]  # (nf, k, 3)
    dxdxi = np.einsum("qk,fkc->fqc", dN[:, :, 0], X)
    dxdeta = np.einsum("qk,fkc->fqc", dN[:, :, 1], X)
    nda = np.cross(dxdxi, dxdeta) * _QW[None, :, None]
    return nodes, N, nda


def _scatter(n_points, nodes, vals):
    """Sum (n_facets, k, 3) nodal contributions into a (3 n_points,) vector."""
    f = np.zeros((n_points, 3))
    for c in range(3):
        f[:, c] = np.bincount(nodes.ravel(), weights=vals[..., c].ravel(), minlength=n_points)
    return f.ravel()


def pressure_load(points, cells, facets, pressure: float) -> np.ndarray:
    """Nodal forces (N) of a uniform pressure (Pa, positive pushing into the surface)."""
    nodes, N, nda = facet_quadrature(points, cells, facets)
    vals = -pressure * np.einsum("qk,fqc->fkc", N, nda)
    return _scatter(len(points), nodes, vals)


def nodal_areas(points, cells, facets):
    """∫ N_a dA over the region, m², per facet node: the distribution weights."""
    nodes, N, nda = facet_quadrature(points, cells, facets)
    da = np.linalg.norm(nda, axis=2)  # (f, q)
    return nodes, np.einsum("qk,fq->fk", N, da)


def traction_force(points, cells, facets, force) -> np.ndarray:
    """Nodal forces of a total force (N, 3-vector) spread as a uniform traction."""
    nodes, w = nodal_areas(points, cells, facets)
    t = np.asarray(force, float) / w.sum()
    return _scatter(len(points), nodes, w[..., None] * t)


def remote_force(points, cells, facets, force, point=None, moment=None) -> np.ndarray:
    """A force (N) and moment (N m) at ``point`` carried to a region by a distributing coupling.

    The RBE3-type coupling spreads them with area weights w_a: f_a = w_a (F/W + (J⁻¹ M_c) × r_a),
    r_a from the weighted centroid c, J = Σ w_a (|r_a|² I − r_a r_aᵀ), M_c the moment about c.
    The nodal forces sum to F and their moment about c is M_c, and the region is not stiffened.
    """
    nodes, w = nodal_areas(points, cells, facets)
    u, inv = np.unique(nodes.ravel(), return_inverse=True)
    wn = np.bincount(inv, weights=w.ravel())
    x = points[u]
    W = wn.sum()
    c = (wn[:, None] * x).sum(0) / W
    F = np.asarray(force, float)
    Mc = np.zeros(3) if moment is None else np.asarray(moment, float).copy()
    if point is not None:
        Mc += np.cross(np.asarray(point, float) - c, F)
    r = x - c
    J = (wn * (r * r).sum(1)).sum() * np.eye(3) - np.einsum("a,ai,aj->ij", wn, r, r)
    theta = np.linalg.lstsq(J, Mc, rcond=None)[0]
    fa = wn[:, None] * (F / W + np.cross(theta, r))
    out = np.zeros((len(points), 3))
    out[u] = fa
    return out.ravel()


def bearing_load(points, cells, facets, force, axis) -> np.ndarray:
    """A radial force (N) through a cylindrical bearing surface, as a pressure ``p0 cos θ``.

    θ is the angle between the force and the direction the surface is pressed in (minus its
    outward normal): a pin pressing a bore (a rod's eye) loads the wall on the force's side, a
    shell pressing a journal (a crankpin) loads the journal on the side facing away from it.
    Where cos θ ≤ 0 there is no pressure — the usual "bearing load" of a strength check
    (no clearance, no friction). ``p0`` is set so that the nodal forces add up to the force
    exactly (analytically ``p0 = 2 |F| / (π R L)``).

    Parameters
    ----------
    force : (3,) array
        N, perpendicular to the axis (a pressure on a cylinder carries no axial force).
    axis : (3,) array
        The cylinder's axis direction (the force must be perpendicular to it).
    """
    F = np.asarray(force, float)
    d = np.asarray(axis, float) / np.linalg.norm(axis)
    fn = np.linalg.norm(F)
    if fn == 0.0:
        return np.zeros(3 * len(points))
    if abs(F @ d) > 1e-6 * fn:
        raise SceneError(f"bearing_force: {F.tolist()} N has {F @ d:.4g} N along the bore axis; "
                         f"a bearing load is radial (give the axial part as a force)")
    fhat = F / fn
    nodes, N, nda = facet_quadrature(points, cells, facets)  # outward normal x area weight
    da = np.linalg.norm(nda, axis=2)
    c = np.maximum(-np.einsum("fqc,c->fq", nda, fhat) / da, 0.0)  # cos θ on the loaded half
    t = -c[..., None] * nda  # traction per unit p0 (pushing into the surface), times the weight
    p0 = fn / float(np.einsum("fqc,c->", t, fhat))
    vals = p0 * np.einsum("qk,fqc->fkc", N, t)
    return _scatter(len(points), nodes, vals)
