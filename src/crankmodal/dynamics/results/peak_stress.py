"""The largest von Mises stress (or deflection) of a flexible body over a run, without
superposing every point.

A run's stress is ``σ_p(t) = Σ_k S_pk ξ_k(t)`` at each stress point ``p`` (``S_pk`` the stress
modes, Pa per unit modal coordinate; ``ξ_k`` the modal coordinates). Superposing all points at
all output samples costs ``6 · k · n_points · n_times`` multiply-adds and as many von Mises
evaluations: for seed 004's crank (37 724 points, 20 modes) 5.4 s of CPU per 1000 samples,
more than integrating the run.

The von Mises stress is a seminorm of the stress (the square root of a positive semidefinite
quadratic form), so ``vm(σ_p(t)) <= Σ_k |ξ_k(t)| vm(S_pk) <= U_p = Σ_k A_k vm(S_pk)`` with
``A_k = max_t |ξ_k(t)|``. The points are visited in decreasing ``U_p``, each chunk superposed
exactly over all times (one matrix product); once the next point's bound is below the largest
value found, no later point can exceed it and the search stops. The result is the brute-force
maximum (the same value up to the round-off of the products' summation order); only the work
depends on how tight the bounds are. The same holds for any seminorm of a field linear in the
modal coordinates (:func:`peak_seminorm`): the elastic deflection's length at the mesh nodes
(:func:`.validity.elastic_deflection`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: points superposed exactly at once (each chunk holds ``6 · chunk · n_times`` doubles)
CHUNK = 256
#: the bound is widened by this relative margin against its own round-off
BOUND_MARGIN = 1e-9


class Peak(NamedTuple):
    """The largest von Mises stress: value (Pa), point index, time index, and how many points
    were superposed to find it."""

    value: float
    point: int
    time_index: int
    points_superposed: int


def peak_seminorm(fields, modal, norm, chunk: int = CHUNK) -> Peak:
    """Largest ``norm(F_p ξ(t))`` over points ``p`` and times ``t`` (module docstring).

    Parameters
    ----------
    fields : ndarray, shape (n_points, n_components, k)
        Per point the field per unit modal coordinate (stress modes, mode shapes).
    modal : ndarray, shape (n_times, k)
        The modal coordinates at the output times.
    norm : callable
        ``norm(values)`` of ``values`` shaped ``(points, n_components, times)`` -> ``(points,
        times)``; must be a seminorm of the components (``norm(a x) = |a| norm(x)``, the
        triangle inequality): von Mises stress, Euclidean length.
    chunk : int
        Points superposed at once.

    Returns
    -------
    Peak
        The largest value, its point index and its time index (0, 0, 0 when every coordinate
        is zero), and the number of points superposed.
    """
    F = np.asarray(fields, float)
    xi = np.asarray(modal, float)
    amp = np.abs(xi).max(axis=0) if xi.shape[0] else np.zeros(F.shape[2])  # A_k
    bound = norm(F) @ amp  # U_p: (p, k) the norm of each mode column, times A_k
    bound *= 1.0 + BOUND_MARGIN
    order = np.argsort(-bound, kind="stable")
    best, where, when, done = 0.0, 0, 0, 0
    xt = np.ascontiguousarray(xi.T)  # (k, t)
    for a in range(0, order.size, chunk):
        idx = order[a:a + chunk]
        if bound[idx[0]] <= best:
            break
        values = norm((F[idx].reshape(-1, F.shape[2]) @ xt).reshape(idx.size, F.shape[1], -1))
        done += idx.size
        i, j = np.unravel_index(int(np.argmax(values)), values.shape)
        if values[i, j] > best:
            best, where, when = float(values[i, j]), int(idx[i]), int(j)
    return Peak(best, where, when, done)


def peak_von_mises(stress_modes, modal, chunk: int = CHUNK) -> Peak:
    """Largest von Mises stress over points and times, where and when.

    Parameters
    ----------
    stress_modes : ndarray, shape (n_points, 6, k)
        Pa per unit modal coordinate (Voigt xx, yy, zz, yz, xz, xy).
    modal : ndarray, shape (n_times, k)
        The modal coordinates at the output times (their unit is the one the stress modes are
        per).
    chunk : int
        Points superposed at once.

    Returns
    -------
    Peak
        The largest von Mises stress (Pa), its point index and its time index (0, 0, 0 when
        every coordinate is zero), and the number of points superposed.
    """
    from ...reduction.stress_modes import von_mises

    return peak_seminorm(stress_modes, modal, lambda v: von_mises(v, axis=1), chunk)


__all__ = ["Peak", "peak_seminorm", "peak_von_mises"]
