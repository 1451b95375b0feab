"""Modal assurance criterion (MAC) between two sets of mode shapes.

``MAC_ij = |φ_iᵀ ψ_j|² / ((φ_iᵀ φ_i)(ψ_jᵀ ψ_j))`` (Allemang & Brown): 1 for collinear shapes,
0 for orthogonal ones, independent of each shape's scale and sign. Shapes of different meshes
are compared at common points: :func:`sample_at` takes the nearest node of one mesh for each
point of the other (test modes at measurement points, another fidelity's nodes).
"""

from __future__ import annotations

import numpy as np


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


def load_reference(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reference modes from a file: another crankmodal run's ``modes.vtu``, or an ``.npz``.

    The ``.npz`` holds ``points`` (p, 3) in m, ``shapes`` (3 p, k) node-interleaved or
    (p, 3, k), and optionally ``frequencies_hz`` (k,) — e.g. test modes at measurement points.
    In a ``.vtu`` every point array named ``mode_NN_<f>Hz`` (as crankmodal writes them) is one
    mode.

    Returns
    -------
    points : ndarray, shape (p, 3)
    shapes : ndarray, shape (3 p, k)
    frequencies_hz : ndarray, shape (k,) (NaN where unknown)
    """
    import re
    from pathlib import Path

    from ..errors import InputFileError

    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"report.reference: file not found: {path}")
    if path.suffix.lower() == ".npz":
        with np.load(path) as d:
            if "points" not in d or "shapes" not in d:
                raise InputFileError(f"report.reference: {path.name} needs arrays 'points' and "
                                     f"'shapes'")
            pts = np.asarray(d["points"], float)
            sh = np.asarray(d["shapes"], float)
            f = np.asarray(d["frequencies_hz"], float) if "frequencies_hz" in d else None
        sh = sh.reshape(3 * len(pts), -1)
        return pts, sh, f if f is not None else np.full(sh.shape[1], np.nan)
    import meshio

    try:
        m = meshio.read(path)
    except Exception as exc:  # noqa: BLE001 - meshio raises many types on bad input
        raise InputFileError(f"report.reference: cannot read {path.name} ({exc})") from None
    pat = re.compile(r"mode_(\d+)_([0-9.eE+-]+)Hz")
    found = sorted((int(g.group(1)), float(g.group(2)), k) for k in m.point_data
                   if (g := pat.fullmatch(k)))
    if not found:
        raise InputFileError(f"report.reference: {path.name} has no point arrays named "
                             f"mode_NN_<f>Hz")
    sh = np.column_stack([np.asarray(m.point_data[k], float).reshape(-1) for _, _, k in found])
    return np.asarray(m.points, float), sh, np.array([f for _, f, _ in found])
