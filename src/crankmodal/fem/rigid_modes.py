"""The rigid-body motions a set of supports leaves a mesh, known in closed form: their number
(6 per connected piece, less what the supports forbid), a basis of them, and the eigenpairs of
(K, M) on them (Rayleigh–Ritz)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .assembly import FEModel, rigid_body_modes


def allowed_rigid_modes(model: FEModel, T: sp.spmatrix) -> np.ndarray:
    """Rigid-body motions the supports leave, in the coordinates q of ``u = T q``.

    6 per connected piece of the mesh, less the combinations the supports forbid.

    Returns
    -------
    ndarray, shape (n_free, r)
        Columns span the allowed rigid motions (not normalised); ``r`` is their number.
    """
    from scipy.sparse.csgraph import connected_components

    n = len(model.points)
    cells = model.cells
    rows = np.repeat(cells[:, 0], cells.shape[1] - 1)
    cols = cells[:, 1:].ravel()
    g = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    used_labels = np.unique(labels[model.used])
    scale = np.ptp(model.points[model.used], axis=0).max()
    blocks = []
    for lab in used_labels:
        sel = (labels == lab) & model.used
        c = model.points[sel].mean(axis=0)
        R = rigid_body_modes(model.points, c)
        R[:, 3:] /= scale
        mask = np.repeat(sel, 3)
        R[~mask] = 0.0
        blocks.append(R)
    R = np.hstack(blocks)
    T = sp.csr_matrix(T)
    Q = R - T @ (T.T @ R)  # part of each rigid field the supports forbid
    _, sv, Vt = np.linalg.svd(Q, full_matrices=False)  # Q is tall: Vt is square
    rank = int((sv > 1e-8 * np.sqrt(n)).sum())
    return T.T @ (R @ Vt[rank:].T)


def expected_rigid_modes(model: FEModel, T: sp.spmatrix) -> int:
    """Rigid-body modes the supports leave: 6 per connected piece minus what T removes."""
    return allowed_rigid_modes(model, T).shape[1]


def rigid_pairs(K, M, Rq: np.ndarray):
    """The known rigid-body motions as eigenpairs: ``(R, lam_r, Xr)`` with ``R`` the columns of
    ``Rq`` M-orthonormalised, ``lam_r`` (≈ 0, rad²/s²) and ``Xr`` the Rayleigh–Ritz pairs of
    (K, M) on them."""
    L = np.linalg.cholesky(Rq.T @ (M @ Rq))
    R = np.linalg.solve(L, Rq.T).T
    lam_r, W = np.linalg.eigh(R.T @ (K @ R))
    return R, lam_r, R @ W
