"""Initial states of systems with flexible bodies: the elastic coordinates at quasi-static rest.

A flexible body started undeformed at full speed is struck by its own inertia and the applied
loads at once: it rings through every kept mode, and the ringing decays only at the modal
damping (2 %: e^-5 after 40 periods of the slowest mode). :func:`quasi_static_start` instead
finds the elastic coordinates ``ξ`` at which the bodies' elastic accelerations vanish at
``t = 0`` (the rigid coordinates re-assembled on the joints for each ``ξ``, the elastic
velocities zero) by Newton's method with a finite-difference Jacobian, so a run starts where a
slowly started machine would be.
"""

from __future__ import annotations

import numpy as np


def _elastic_columns(sysm) -> np.ndarray:
    cols = []
    for b in sysm.bodies:
        k = getattr(b, "n_elastic", 0)
        if k:
            s = sysm.slices[id(b)].start + 3
            cols.extend(range(s, s + k))
    return np.array(cols, int)


def quasi_static_start(sysm, q, qd, t=0.0, tol=1e-9, max_iter=10):
    """Elastic coordinates at quasi-static rest at time ``t`` (see the module docstring).

    Parameters
    ----------
    sysm : Multibody
    q, qd : arrays
        A consistent state (e.g. the builder's, bodies undeformed).
    tol : float
        Stop when the elastic accelerations, scaled by the slowest mode's ω², are below this
        (m kg^½ of modal coordinate).

    Returns
    -------
    q, qd, info : the state and ``{"iterations", "residual"}``.
    """
    cols = _elastic_columns(sysm)
    if cols.size == 0:
        return q, qd, {"iterations": 0, "residual": 0.0}
    qd = np.array(qd, float)
    qd[cols] = 0.0
    w2 = np.concatenate([b.K[:b.n_elastic] for b in sysm.bodies if getattr(b, "n_elastic", 0)])

    def residual(xi):
        qq = np.array(q, float)
        qq[cols] = xi
        qq, qqd = sysm.assemble(t, qq, qd, hold=cols)
        return sysm.solve(t, qq, qqd)["qdd"][cols] / w2, qq, qqd  # the static error in ξ

    xi = np.array(q[cols], float)
    r, qq, qqd = residual(xi)
    it = 0
    for it in range(1, max_iter + 1):
        # at least one Newton step: scaled by ω², the undeformed state of a stiff link (a
        # 17 kHz coupler carrying kN) is already "within tol" while its joints carry almost
        # nothing (the elastic accelerations, not the springs, balance the loads at t = 0)
        if it > 1 and np.max(np.abs(r)) < tol:
            it -= 1
            break
        h = 1e-7 * max(1e-6, float(np.max(np.abs(xi))))
        J = np.empty((cols.size, cols.size))
        for j in range(cols.size):
            e = np.zeros(cols.size)
            e[j] = h
            J[:, j] = (residual(xi + e)[0] - r) / h
        xi = xi - np.linalg.solve(J, r)
        r, qq, qqd = residual(xi)
    return qq, qqd, {"iterations": it, "residual": float(np.max(np.abs(r)))}


__all__ = ["quasi_static_start"]
