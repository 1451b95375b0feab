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

    What scenes do before a run with flexible bodies (``dynamics.flexible.start =
    "quasi_static"``, the default) and :func:`~.analysis.simulate` does by default
    (:meth:`~.mechanisms.Mechanism.start_quasi_static` calls it on the mechanism's ideal-joint
    twin). Example, a mechanism ``mech`` with a flexible crank::

        q, qd, info = quasi_static_start(mech.ideal, mech.q0, mech.qd0)
        # info["residual"] < 1e-9: the elastic accelerations vanish at t = 0

    Parameters
    ----------
    sysm : Multibody
    q, qd : arrays
        A consistent state (e.g. the builder's, bodies undeformed).
    t : float
        Time of the state, s.
    tol : float
        Stop when the elastic accelerations, each divided by its mode's ω², are below this
        (modal coordinate, m kg^½), > 0.
    max_iter : int
        Newton iterations at most, >= 1.

    Returns
    -------
    q, qd, info : the state (elastic velocities zero, rigid coordinates re-assembled on the
        joints) and ``{"iterations", "residual"}``; ``q`` and ``qd`` as given (copies) without
        elastic modes.

    Raises
    ------
    ParameterError
        Naming ``q``, ``qd`` (not ``sysm.n`` finite numbers), ``t``, ``tol`` or ``max_iter``.
    """
    from ... import arguments as arg

    q = np.asarray(arg.numbers("q", np.asarray(q, float).ravel(), length=sysm.n), float)
    qd = np.asarray(arg.numbers("qd", np.asarray(qd, float).ravel(), length=sysm.n), float)
    t = arg.number("t", t)
    tol = arg.number("tol", tol, gt=0.0)
    max_iter = arg.integer("max_iter", max_iter, ge=1)
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
