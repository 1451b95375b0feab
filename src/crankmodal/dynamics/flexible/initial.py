"""Initial states of systems with flexible bodies: the elastic coordinates at quasi-static rest.

A flexible body started undeformed at full speed is struck by its own inertia and the applied
loads at once: it rings through every kept mode, and the ringing decays only at the modal
damping (2 %: e^-5 after 40 periods of the slowest mode). :func:`quasi_static_start` instead
finds the state at which the bodies' elastic accelerations vanish at ``t = 0`` with the joints
closed and the elastic velocities zero, so a run starts where a slowly started machine would be.

The static problem is solved as one (the positions and the elastic coordinates together): a
Gauss-Newton iteration on ::

    F(q) = [ Φ(q, t) ;  q̈_ξ(q, q̇(q)) / ω² ] = 0

where ``Φ`` are the joint equations, ``q̈_ξ`` the elastic accelerations of the system's KKT
solve (the multipliers are the joint reactions of the static problem, the drive's speed gives
the centrifugal and inertia terms) and ``q̇(q)`` the builder's velocities made consistent with
the joints at ``q`` (elastic velocities zero). A crank bent over three or more journals has
to close its journals *through* its elastic coordinates: holding the modes while assembling
the joints (this function's former way) cannot close them. Each step is the least-squares,
least-change solution of the linearised equations (Jacobian: ``Φ_q`` exactly, the elastic
rows by forward differences), so coordinates the equations leave free (a free crank angle, a
coupling's twist) stay where the builder put them.
"""

from __future__ import annotations

import numpy as np

from ...errors import NumericalError

#: joint equations closed below this, m or rad (what Multibody.assemble asks of a start)
PHI_TOL = 1e-12
#: singular values of the velocity projection below this share of the largest are free
#: directions: with the modes held, a torque-driven crank's rotation is free, and NumPy's
#: default cut-off (machine precision) let a 1e-15 singular value turn a 1e-12 velocity
#: residual into a 156 rad/s "correction" of the crank's speed
RCOND = 1e-10
#: weight of a rigid coordinate's change (m, rad) against a modal one's (m kg^½) in each
#: least-change step: the elastic residual also depends on the crank and coupling angles (gas
#: forces, coupling torque), and unweighted steps turned a torque-driven crank by 0.7 rad
RIGID_WEIGHT = 1e-4


def _elastic_columns(sysm) -> np.ndarray:
    cols = []
    for b in sysm.bodies:
        k = getattr(b, "n_elastic", 0)
        if k:
            s = sysm.slices[id(b)].start + 3
            cols.extend(range(s, s + k))
    return np.array(cols, int)


def _steps(q: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Forward-difference steps per coordinate: 1e-8 of the rigid coordinates' size (m, rad;
    at least 1e-8), 1e-6 of the largest elastic coordinate (at least 1e-12 m kg^½: the
    elastic rows are close to linear in ξ, so a large step costs nothing and keeps the
    rounding of the KKT solve out of the Jacobian)."""
    h = 1e-8 * np.maximum(1.0, np.abs(q))
    h[cols] = 1e-6 * max(1e-6, float(np.max(np.abs(q[cols]))))
    return h


def quasi_static_start(sysm, q, qd, t=0.0, tol=1e-9, max_iter=10):
    """State at quasi-static rest at time ``t`` (see the module docstring).

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
        A state (e.g. the builder's, bodies undeformed); the velocities of the coordinates the
        joints leave free are kept.
    t : float
        Time of the state, s.
    tol : float
        Stop when the elastic accelerations, each divided by its mode's ω², are below this
        (modal coordinate, m kg^½), > 0, and the joints are closed (1e-12 m or rad).
    max_iter : int
        Newton iterations at most, >= 1.

    Returns
    -------
    q, qd, info : the state (elastic velocities zero, joints closed, velocities consistent)
        and ``{"iterations", "residual"}`` (the largest elastic residual, m kg^½); ``q`` and
        ``qd`` as given (copies) without elastic modes.

    Raises
    ------
    ParameterError
        Naming ``q``, ``qd`` (not ``sysm.n`` finite numbers), ``t``, ``tol`` or ``max_iter``.
    NumericalError
        When the joints cannot be closed (the state's joints are not near a closed state).
    """
    from ... import arguments as arg

    q = np.asarray(arg.numbers("q", np.asarray(q, float).ravel(), length=sysm.n), float)
    qd = np.asarray(arg.numbers("qd", np.asarray(qd, float).ravel(), length=sysm.n), float)
    t = arg.number("t", t)
    tol = arg.number("tol", tol, gt=0.0)
    max_iter = arg.integer("max_iter", max_iter, ge=1)
    cols = _elastic_columns(sysm)
    if cols.size == 0:
        return np.array(q), np.array(qd), {"iterations": 0, "residual": 0.0}
    qd = np.array(qd, float)
    qd[cols] = 0.0
    w2 = np.concatenate([b.K[:b.n_elastic] for b in sysm.bodies if getattr(b, "n_elastic", 0)])

    def residual(qq):
        # velocities made consistent at qq without moving it (tol = inf: no position step)
        _, qqd = sysm.assemble(t, qq, qd, tol=np.inf, hold=cols, rcond=RCOND)
        out = sysm.solve(t, qq, qqd)
        return np.concatenate([out["phi"], out["qdd"][cols] / w2]), out["Cq"]

    m = sysm.m
    q = np.array(q, float)
    W = np.full(sysm.n, RIGID_WEIGHT)
    W[cols] = 1.0
    F, Cq = residual(q)
    it = 0
    for it in range(1, max_iter + 1):
        # at least one Newton step: scaled by ω², the undeformed state of a stiff link (a
        # 17 kHz coupler carrying kN) is already "within tol" while its joints carry almost
        # nothing (the elastic accelerations, not the springs, balance the loads at t = 0)
        if it > 1 and np.max(np.abs(F[m:])) < tol and np.max(np.abs(F[:m]), initial=0.0) < \
                PHI_TOL:
            it -= 1
            break
        h = _steps(q, cols)
        J = np.empty((m + cols.size, sysm.n))
        J[:m] = Cq
        for j in range(sysm.n):
            qq = q.copy()
            qq[j] += h[j]
            J[m:, j] = (residual(qq)[0][m:] - F[m:]) / h[j]
        # least change weighted towards the modes: the joints move the rigid coordinates as
        # much as they need, the free ones (a torque-driven train's angles) stay put
        q = q - W * np.linalg.lstsq(J * W, F, rcond=None)[0]
        F, Cq = residual(q)
    if np.max(np.abs(F[:m]), initial=0.0) > 1e3 * PHI_TOL:
        raise NumericalError(
            f"dynamics: the quasi-static start did not close the joints at t = {t} s (residual "
            f"{np.max(np.abs(F[:m])):.1e} after {it} Newton steps); start the flexible bodies "
            f"undeformed or check the assembly")
    # the joints' last 1e-12 with the modes held, and the velocities
    q, qd = sysm.assemble(t, q, qd, hold=cols, rcond=RCOND)
    r = float(np.max(np.abs(residual(q)[0][m:])))
    if r >= tol:
        import warnings

        warnings.warn(f"dynamics: the quasi-static start stopped after {it} Newton steps with "
                      f"elastic accelerations of {r:.1e} m kg^0.5 (x 1/omega^2), above tol = "
                      f"{tol:.1e}: the run starts with some ringing", RuntimeWarning,
                      stacklevel=2)
    return q, qd, {"iterations": it, "residual": r}


__all__ = ["quasi_static_start"]
