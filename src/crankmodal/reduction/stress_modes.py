"""Stress modes: nodal stresses of every reduced mode at once.

The recovery is that of :func:`crankmodal.fem.static.nodal_stress` (stress at every node of every
element from the element's own displacement field, averaged over the elements sharing a node),
written as one operator applied to the whole mode matrix: per element chunk, the displacement
gradients of all modes are one batched matrix product ``∂N/∂x (e, 3·q, a) @ U (e, a, 3·modes)``,
Hooke's law is applied to the whole block, and the nodal averaging is a sparse matrix applied to
all modes' stress components. A dynamics run superposes them, ``σ(t) = Σ_k σ_k ξ_k(t)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: Voigt order of the six stress components.
VOIGT = ("xx", "yy", "zz", "yz", "xz", "xy")
_VI = np.array([0, 1, 2, 1, 0, 0])
_VJ = np.array([0, 1, 2, 2, 2, 1])


@dataclass
class StressRecovery:
    """The pieces of the recovery operator of a mesh.

    Attributes
    ----------
    grads : ndarray, shape (n_elements, q, 3, a)
        ∂N_a/∂x_i at element node q, 1/m.
    nodes : ndarray of int, shape (n_elements, a)
        Mesh point of every local basis function.
    average : scipy.sparse.csc_matrix, shape (n_points, n_elements · q)
        Nodal averaging of values sitting at element nodes.
    lame : (float, float)
        λ, μ, Pa.
    """

    grads: np.ndarray
    nodes: np.ndarray
    average: sp.csc_matrix
    lame: tuple


def stress_recovery(model, mesh) -> StressRecovery:
    """Build the recovery operator of an FE model (scikit-fem basis at the element nodes)."""
    from skfem import CellBasis

    from ..fem.assembly import local_to_cells, skfem_mesh

    m, element = skfem_mesh(mesh)
    X = np.asarray(element.doflocs, float).T
    basis = CellBasis(m, element, quadrature=(X, np.ones(X.shape[1])))
    nodes = local_to_cells(basis, model.cells, model.points)  # (a, e)
    G = np.stack([basis.basis[a][0].grad for a in range(len(nodes))])  # (a, i, e, q)
    grads = np.ascontiguousarray(G.transpose(2, 3, 1, 0))  # (e, q, i, a)
    owner = nodes.T  # value at quadrature point q sits on local node q
    n = len(model.points)
    count = np.bincount(owner.ravel(), minlength=n).astype(float)
    avg = sp.csc_matrix((1.0 / count[owner.ravel()], (owner.ravel(), np.arange(owner.size))),
                        shape=(n, owner.size))  # one entry per column: cheap column slices
    return StressRecovery(grads=grads, nodes=nodes.T.copy(), average=avg,
                          lame=model.material.lame)


def stress_modes(rec: StressRecovery, shapes: np.ndarray, chunk: int = 4000,
                 dtype=np.float64) -> np.ndarray:
    """Nodal stresses of many displacement fields.

    Parameters
    ----------
    rec : StressRecovery
    shapes : ndarray, shape (3 n_points, n_modes)
        Node-interleaved displacement fields, m (per unit modal coordinate).
    chunk : int
        Elements per batch (bounds memory).
    dtype : numpy dtype
        Of the result (``float32`` halves the file size).

    Returns
    -------
    ndarray, shape (n_points, 6, n_modes)
        Pa, Voigt order ``xx, yy, zz, yz, xz, xy``.
    """
    lam, mu = rec.lame
    n_points = rec.average.shape[0]
    k = shapes.shape[1]
    U = np.ascontiguousarray(shapes).reshape(n_points, 3 * k)
    ne, nq, _, na = rec.grads.shape
    out = np.zeros((n_points, 6 * k), dtype=dtype)  # accumulated in the storage type
    for s in range(0, ne, chunk):
        e = slice(s, min(s + chunk, ne))
        Ue = U[rec.nodes[e]]  # (e, a, 3k)
        H = np.matmul(rec.grads[e].reshape(-1, nq * 3, na), Ue)  # (e, q·i, j·k): ∂u_j/∂x_i
        H = H.reshape(-1, nq, 3, 3, k)  # (e, q, i, j, k)
        tr = lam * (H[:, :, 0, 0] + H[:, :, 1, 1] + H[:, :, 2, 2])
        sig = np.empty((H.shape[0], nq, 6, k))
        for c, (i, j) in enumerate(zip(_VI, _VJ)):  # basic slices: no fancy-index copies
            if i == j:
                np.multiply(H[:, :, i, i], 2.0 * mu, out=sig[:, :, c])
                sig[:, :, c] += tr
            else:
                np.add(H[:, :, i, j], H[:, :, j, i], out=sig[:, :, c])
                sig[:, :, c] *= mu
        cols = slice(s * nq, (s + sig.shape[0]) * nq)
        out += rec.average[:, cols] @ sig.reshape(-1, 6 * k)
    return out.reshape(n_points, 6, k)


def von_mises(voigt: np.ndarray, axis: int = 1) -> np.ndarray:
    """Von Mises stress of Voigt stresses (component axis ``axis``), Pa."""
    s = np.moveaxis(voigt, axis, 0)
    xx, yy, zz, yz, xz, xy = s
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                   + 3.0 * (yz ** 2 + xz ** 2 + xy ** 2))
