"""Stress over one steady cycle from stress modes, in bounded memory.

``σ(t) = σ_0 + Σ_k σ_k ξ_k(t)`` at the points asked for: ``σ_k`` the stress modes (Pa per unit
modal coordinate, :func:`crankmodal.reduction.stress_modes.stress_modes`), ``ξ_k(t)`` the modal
coordinates over the cycle and ``σ_0`` an optional constant stress (a preload, a shrink fit). A
quasi-static load case is one more column: its unit-load stress field with its load history as
the coordinate.

The points are taken in chunks whose stress history (``chunk × 6 × n_times`` doubles) stays
within ``memory_bytes`` (default 64 MB): a 100 000-node crank over 720 steps would otherwise hold
3.5 GB at once. Per point only what the criterion needs is kept: each component's largest and
smallest value, the largest von Mises stress (the yield check) with its time index, and the
largest von Mises stress of ``σ(t) − σ_m`` (the proportionality check of the criterion: under
proportional loading it equals the von Mises stress of the component-wise amplitude).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..reduction.stress_modes import von_mises

#: default memory budget of one chunk's stress history, bytes
MEMORY_BYTES = 64 * 2 ** 20


@dataclass
class CycleExtremes:
    """Per-point extremes of the stress over a cycle.

    Attributes
    ----------
    stress_max, stress_min : ndarray, shape (n, 6)
        Largest and smallest value of each Voigt component (xx, yy, zz, yz, xz, xy), Pa.
    max_von_mises : ndarray, shape (n,)
        Largest von Mises stress over the cycle, Pa.
    max_time_index : ndarray of int, shape (n,)
        The time step at which it occurs.
    max_deviation_von_mises : ndarray, shape (n,)
        Largest von Mises stress of ``σ(t) − σ_m`` over the cycle (``σ_m`` the component-wise
        mean), Pa.
    """

    stress_max: np.ndarray
    stress_min: np.ndarray
    max_von_mises: np.ndarray
    max_time_index: np.ndarray
    max_deviation_von_mises: np.ndarray


def _real_array(name: str, value, ndim: int) -> np.ndarray:
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as exc:  # ragged lists and the like
        raise ParameterError(name, f"must be an array of real numbers ({exc})") from None
    if a.dtype.kind not in "fiu" or a.ndim != ndim:
        raise ParameterError(name, f"must be a {ndim}-D array of real numbers, got "
                                   f"{a.dtype} of shape {a.shape}")
    return a


def check_inputs(stress_modes, modal_coordinates, static_stress=None, nodes=None):
    """The arrays of :func:`cycle_extremes`, checked; a ParameterError names the argument.

    Returns
    -------
    S, xi, s0, nodes
        ``S`` (p, 6, k) as given (no copy), ``xi`` (k, t) float64, ``s0`` (p, 6) or None,
        ``nodes`` (n,) int64.
    """
    S = _real_array("stress_modes", stress_modes, 3)
    if S.shape[1] != 6 or S.shape[0] == 0:
        raise ParameterError("stress_modes", f"must have shape (n_points, 6, n_modes), got {S.shape}")
    xi = _real_array("modal_coordinates", modal_coordinates, 2).astype(float, copy=False)
    if xi.shape[0] != S.shape[2]:
        raise ParameterError("modal_coordinates", f"must have shape (n_modes, n_times) with "
                                                  f"n_modes = {S.shape[2]} (stress_modes), got "
                                                  f"{xi.shape}")
    if xi.shape[1] < 2:
        raise ParameterError("modal_coordinates", f"must hold at least 2 time steps of the "
                                                  f"cycle, got {xi.shape[1]}")
    if not np.all(np.isfinite(xi)):
        i = np.unravel_index(int(np.argmax(~np.isfinite(xi))), xi.shape)
        raise ParameterError("modal_coordinates", f"holds a non-finite value at {list(map(int, i))}")
    s0 = None
    if static_stress is not None:
        s0 = _real_array("static_stress", static_stress, 2).astype(float, copy=False)
        if s0.shape != (S.shape[0], 6):
            raise ParameterError("static_stress", f"must have shape ({S.shape[0]}, 6) like "
                                                  f"stress_modes' points, got {s0.shape}")
        if not np.all(np.isfinite(s0)):
            raise ParameterError("static_stress", "holds a non-finite value")
    if nodes is None:
        idx = np.arange(S.shape[0], dtype=np.int64)
    else:
        idx = _real_array("nodes", nodes, 1)
        if idx.dtype.kind not in "iu":
            raise ParameterError("nodes", f"must be integer point indices, got {idx.dtype}")
        if idx.size == 0:
            raise ParameterError("nodes", "must name at least one point")
        if idx.min() < 0 or idx.max() >= S.shape[0]:
            raise ParameterError("nodes", f"must index 0 to {S.shape[0] - 1} (stress_modes' "
                                          f"points), got {int(idx.min())} to {int(idx.max())}")
        idx = idx.astype(np.int64)
    return S, xi, s0, idx


def chunk_points(n_times: int, memory_bytes: float = MEMORY_BYTES) -> int:
    """Points per chunk so that one chunk's history (points × 6 × n_times doubles, and its von
    Mises stresses) stays within ``memory_bytes``; at least 1."""
    return max(1, int(memory_bytes // (8 * 8 * max(1, n_times))))


def cycle_extremes(stress_modes, modal_coordinates, static_stress=None, nodes=None,
                   memory_bytes: float = MEMORY_BYTES) -> CycleExtremes:
    """Per-point extremes of ``σ(t) = σ_0 + Σ_k σ_k ξ_k(t)`` over a cycle, in chunks.

    Parameters
    ----------
    stress_modes : ndarray, shape (n_points, 6, n_modes)
        Pa per unit modal coordinate, Voigt order xx, yy, zz, yz, xz, xy (float32 accepted).
    modal_coordinates : ndarray, shape (n_modes, n_times)
        ξ over one steady cycle (the rows' unit: whatever the stress modes are per).
    static_stress : ndarray, shape (n_points, 6), optional
        Constant stress added at every time, Pa.
    nodes : ndarray of int, optional
        The points to evaluate (default all), e.g. the surface nodes.
    memory_bytes : float
        Bound on one chunk's stress history, bytes.

    Returns
    -------
    CycleExtremes
        For ``nodes``, in their order.

    Raises
    ------
    ParameterError
        Naming ``stress_modes``, ``modal_coordinates``, ``static_stress`` or ``nodes`` (shape,
        type, a non-finite value, an index out of range).
    """
    S, xi, s0, idx = check_inputs(stress_modes, modal_coordinates, static_stress, nodes)
    k, nt = xi.shape
    n = len(idx)
    smax = np.empty((n, 6))
    smin = np.empty((n, 6))
    vmax = np.empty(n)
    vdev = np.empty(n)
    when = np.empty(n, np.int64)
    step = chunk_points(nt, memory_bytes)
    for a in range(0, n, step):
        b = min(a + step, n)
        block = np.asarray(S[idx[a:b]], float)  # (c, 6, k)
        if not np.all(np.isfinite(block)):
            bad = idx[a:b][~np.all(np.isfinite(block), axis=(1, 2))][0]
            raise ParameterError("stress_modes", f"holds a non-finite value at point {int(bad)}")
        sig = (block.reshape(-1, k) @ xi).reshape(b - a, 6, nt)  # (c, 6, t)
        if s0 is not None:
            sig += s0[idx[a:b], :, None]
        smax[a:b] = sig.max(axis=2)
        smin[a:b] = sig.min(axis=2)
        vm = von_mises(sig, axis=1)  # (c, t)
        when[a:b] = np.argmax(vm, axis=1)
        vmax[a:b] = vm[np.arange(b - a), when[a:b]]
        del vm
        sig -= (0.5 * (smax[a:b] + smin[a:b]))[:, :, None]  # σ(t) − σ_m, in place
        vdev[a:b] = von_mises(sig, axis=1).max(axis=1)
    return CycleExtremes(stress_max=smax, stress_min=smin, max_von_mises=vmax,
                         max_time_index=when, max_deviation_von_mises=vdev)
