"""Modal assurance criterion (MAC) between two sets of mode shapes.

``MAC_ij = |φ_iᵀ ψ_j|² / ((φ_iᵀ φ_i)(ψ_jᵀ ψ_j))`` (Allemang & Brown): 1 for collinear shapes,
0 for orthogonal ones, independent of each shape's scale and sign. Shapes of different meshes
are compared at common points: :func:`sample_at` takes the nearest node of one mesh for each
point of the other (test modes at measurement points, another fidelity's nodes).
"""

from __future__ import annotations

import numpy as np

from .reference import load_reference  # noqa: F401 - re-exported (its old home)


def mac_matrix(phi: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """MAC of every pair of columns.

    Parameters
    ----------
    phi : ndarray, shape (n_dofs, m)
        First set of shapes (any scaling).
    psi : ndarray, shape (n_dofs, k)
        Second set, the same DOFs in the same order.

    Returns
    -------
    ndarray, shape (m, k)
        Values in [0, 1].
    """
    phi = np.asarray(phi, float)
    psi = np.asarray(psi, float)
    if phi.ndim != 2 or psi.ndim != 2 or phi.shape[0] != psi.shape[0]:
        raise ValueError(f"mac_matrix: shapes must be (n_dofs, m) and (n_dofs, k) with the same "
                         f"n_dofs, got {phi.shape} and {psi.shape}")
    num = np.abs(phi.T @ psi) ** 2
    den = np.outer(np.einsum("ij,ij->j", phi, phi), np.einsum("ij,ij->j", psi, psi))
    if np.any(den <= 0):
        raise ValueError("mac_matrix: a mode shape is identically zero")
    return np.clip(num / den, 0.0, 1.0)


def pair_modes(mac: np.ndarray, threshold: float = 0.0) -> list[tuple[int, int, float]]:
    """Pair each row mode with its best-matching column mode (greedy on the largest MAC).

    Returns
    -------
    list of (i, j, mac)
        One per row that found a partner with MAC above ``threshold``, sorted by ``i``.
    """
    m = np.array(mac, float)
    pairs = []
    while m.size and np.nanmax(m) > threshold:
        i, j = np.unravel_index(np.nanargmax(m), m.shape)
        pairs.append((int(i), int(j), float(mac[i, j])))
        m[i, :] = -1.0
        m[:, j] = -1.0
        if len(pairs) == min(mac.shape):
            break
    return sorted(pairs)


def sample_at(points: np.ndarray, shapes: np.ndarray, at: np.ndarray,
              max_distance: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Shapes of a mesh at other points, by the nearest node.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Nodes carrying ``shapes``, m.
    shapes : ndarray, shape (3 n, k)
        Node-interleaved shapes (``dof = 3 * node + component``).
    at : ndarray, shape (p, 3)
        Where to sample, m.
    max_distance : float, optional
        Points farther than this from every node are dropped, m.

    Returns
    -------
    sampled : ndarray, shape (3 q, k)
        Interleaved shapes at the ``q`` kept points.
    kept : ndarray of int, shape (q,)
        Indices into ``at`` of the kept points.
    """
    from scipy.spatial import cKDTree

    dist, idx = cKDTree(np.asarray(points, float)).query(np.asarray(at, float))
    kept = np.arange(len(at)) if max_distance is None else np.flatnonzero(dist <= max_distance)
    U = np.asarray(shapes).reshape(len(points), 3, -1)
    return U[idx[kept]].reshape(3 * len(kept), -1), kept
