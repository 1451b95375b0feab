"""Name mode shapes: bending (about which axis), torsion, axial, or local.

The part is cut into slices along its long axis; in each slice the nodal displacements are fitted
by a rigid motion of the cross-section (translation t, rotation θ). Summed over slices, the
squared axial translation measures extension, the transverse translations bending, the rotation
about the axis (times the section's radius of gyration) torsion, and what the fit leaves over is
local deformation of the sections (plates, webs, counterweights).
"""

from __future__ import annotations

import numpy as np

AXIS_NAMES = ("x", "y", "z")


def long_axis(points: np.ndarray) -> np.ndarray:
    """Unit direction of largest extent of a point cloud (principal axis of its covariance)."""
    x = points - points.mean(axis=0)
    _, v = np.linalg.eigh(x.T @ x)
    a = v[:, -1]
    k = np.argmax(np.abs(a))
    return a * np.sign(a[k])


def axis_name(v: np.ndarray, tol_deg: float = 20.0) -> str:
    """``x``, ``y`` or ``z`` when ``v`` is within ``tol_deg`` of a global axis, else the vector."""
    v = np.asarray(v, float) / np.linalg.norm(v)
    k = int(np.argmax(np.abs(v)))
    if abs(v[k]) >= np.cos(np.radians(tol_deg)):
        return AXIS_NAMES[k]
    return "[" + ", ".join(f"{c:.2f}" for c in v) + "]"


def _frame(a):
    """Orthonormal (a, e1, e2) with e1 as close to a global axis as possible."""
    k = int(np.argmin(np.abs(a)))
    e1 = np.eye(3)[k] - a * a[k]
    e1 /= np.linalg.norm(e1)
    return a, e1, np.cross(a, e1)


def classify(points: np.ndarray, shapes: np.ndarray, axis=None, n_slices: int = 24,
             local_fraction: float = 0.5) -> list[dict]:
    """Classify mode shapes.

    Parameters
    ----------
    points : ndarray, shape (n_points, 3)
        Points of the nodes carried by the shapes (unused points may be included; they move 0).
    shapes : ndarray, shape (3 n_points, n_modes)
    axis : array_like, optional
        The part's long axis (default: principal axis of the point cloud).
    n_slices : int
    local_fraction : float
        Modes whose sections deform more than this fraction of the total are ``local``.

    Returns
    -------
    list of dict
        Per mode: ``label`` (``bending about y``, ``torsion about x``, ``axial along x``,
        ``local``), and the energy fractions ``axial``, ``bending_1``, ``bending_2``,
        ``torsion``, ``local``.
    """
    a = long_axis(points) if axis is None else np.asarray(axis, float) / np.linalg.norm(axis)
    a, e1, e2 = _frame(a)
    c = points.mean(axis=0)
    s = (points - c) @ a
    edges = np.linspace(s.min(), s.max(), n_slices + 1)
    sl = np.clip(np.searchsorted(edges, s, side="right") - 1, 0, n_slices - 1)
    U = shapes.reshape(len(points), 3, -1)
    out_fracs = np.zeros((shapes.shape[1], 5))
    for k in range(n_slices):
        idx = np.flatnonzero(sl == k)
        if len(idx) < 4:
            continue
        r = points[idx] - points[idx].mean(axis=0)
        # rigid motion u = t + θ × r  =>  A [t; θ] with A_i = [I, -skew(r_i)]
        A = np.zeros((len(idx), 3, 6))
        A[:, :, :3] = np.eye(3)
        A[:, 0, 4], A[:, 0, 5] = r[:, 2], -r[:, 1]
        A[:, 1, 3], A[:, 1, 5] = -r[:, 2], r[:, 0]
        A[:, 2, 3], A[:, 2, 4] = r[:, 1], -r[:, 0]
        A2 = A.reshape(-1, 6)
        B = U[idx].reshape(-1, U.shape[2])
        sol, *_ = np.linalg.lstsq(A2, B, rcond=None)
        t, th = sol[:3], sol[3:]
        fit = A2 @ sol
        rperp = r - np.outer(r @ a, a)
        gyr2 = (rperp ** 2).sum(axis=1).mean()
        n = len(idx)
        out_fracs[:, 0] += n * (a @ t) ** 2
        out_fracs[:, 1] += n * (e1 @ t) ** 2
        out_fracs[:, 2] += n * (e2 @ t) ** 2
        out_fracs[:, 3] += n * gyr2 * (a @ th) ** 2
        out_fracs[:, 4] += ((B - fit) ** 2).sum(axis=0)
    total = out_fracs.sum(axis=1, keepdims=True)
    out_fracs /= np.where(total > 0, total, 1.0)
    result = []
    for fr in out_fracs:
        kind = int(np.argmax(fr[:4]))
        if fr[4] > local_fraction:
            label = "local"
        elif kind == 0:
            label = f"axial along {axis_name(a)}"
        elif kind == 3:
            label = f"torsion about {axis_name(a)}"
        else:
            d = e1 if kind == 1 else e2
            label = f"bending about {axis_name(np.cross(a, d))}"
        result.append({"label": label, "axial": fr[0], "bending_1": fr[1], "bending_2": fr[2],
                       "torsion": fr[3], "local": fr[4]})
    return result
