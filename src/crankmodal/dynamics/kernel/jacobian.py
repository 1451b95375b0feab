"""The Jacobian of the compiled right-hand side, for the implicit integrators (Radau, BDF, LSODA).

The state is ``y = [q, qd, W]`` (:mod:`~crankmodal.dynamics.model.system`: positions,
velocities and six work integrals), so ``dy/dt = [qd, qdd(q, qd), P(q, qd)]`` and::

    d(dy/dt)/dy = [[ 0,        I,         0 ],
                   [ dqdd/dq,  dqdd/dqd,  0 ],
                   [ dP/dq,    dP/dqd,    0 ]]

The first block row and the work-integral columns are exact; the ``2 n`` columns of
``dqdd/d(q, qd)`` and ``dP/d(q, qd)`` are forward differences of the kernel's own
:func:`~.compiled.assemble` and :func:`~.compiled.finish` (no second copy of any law). The linear
system ``A(q) x = b(q, qd)`` that :func:`~.compiled.assemble` builds is factorised **once**, at
the unperturbed state: each column takes the residual of its perturbed system at the
unperturbed solution, ``dx = A^-1 (b' - A' x)`` (first order in the step, as the difference
itself), solved with the one factorisation, and :func:`~.compiled.finish` turns ``x + dx`` into
the column's accelerations and powers. A Jacobian is one Numba call (0.7-0.9 ms for the 96
states of the 20 + 14 mode slider-crank) where SciPy's own finite differences make ``2 n + 6``
calls of the right-hand side from Python, each with its own factorisation (measured in
``benchmarks/kernel_stiff.py``). The factorisation is written out in Numba (:func:`_lu`):
SciPy's threaded LAPACK took 2.3 ms for the 90 right-hand sides of a 56-square system on the
busy 2-core machine, 0.2 ms on one thread.

The difference step of coordinate ``i`` is ``sqrt(eps) max(|y_i|, STEP_FLOOR atol_i / rtol)``,
scaled by the integrator's own scale of that coordinate (``atol / rtol`` is where its error
control switches from absolute to relative), so a coordinate at zero (a modal coordinate, a
velocity) is still perturbed by a resolvable amount; ``rtol`` is taken at least ``1e-6`` there
(below it the floor grew past the film's scale: at rtol 1e-9 a centred journal's position was
perturbed by 1.5 um, 3 % of its clearance, and Radau, its Newton iterations failing on that
Jacobian, took 185 k evaluations where SciPy's own differences took 3.5 k). Measured on the flexible slider-crank
(crank 20 + rod 14 modes) against central differences: largest error 2e-4 of its column's
largest entry with a floor of ``atol / rtol`` (round-off of the crank angle's column),
4e-6 with :data:`STEP_FLOOR` = 100, 4e-4 with 1e4 (truncation).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .compiled import DIAG, N_AUX, assemble, finish, flush_if_changed

#: columns of the kernel's clearance diagnostics
N_DIAG = len(DIAG)
#: methods of ``solve_ivp`` that use a Jacobian
IMPLICIT = ("Radau", "BDF", "LSODA")
_SQRT_EPS = float(np.sqrt(np.finfo(float).eps))
#: the difference step's floor in units of ``atol / rtol`` (module docstring)
STEP_FLOOR = 100.0


@njit(cache=True)
def _lu(A, piv):
    """LU factorisation with partial pivoting of ``A`` in place, real or complex (LAPACK's
    getrf written out: see the module docstring). Returns False if ``A`` is singular."""
    size = A.shape[0]
    for k in range(size):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, size):
            if abs(A[i, k]) > big:
                big, p = abs(A[i, k]), i
        piv[k] = p
        if big == 0.0:
            return False
        if p != k:
            for j in range(size):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        inv = 1.0 / A[k, k]
        for i in range(k + 1, size):
            f = A[i, k] * inv
            A[i, k] = f
            if f != 0.0:
                for j in range(k + 1, size):
                    A[i, j] -= f * A[k, j]
    return True


@njit(cache=True)
def _lu_solve(LU, piv, b):
    """Solve ``A x = b`` in place with the factors of :func:`_lu`."""
    size = b.size
    for k in range(size):
        p = piv[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
    for i in range(size):
        acc = b[i]
        for j in range(i):
            acc -= LU[i, j] * b[j]
        b[i] = acc
    for i in range(size - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, size):
            acc -= LU[i, j] * b[j]
        b[i] = acc / LU[i, i]


@njit(cache=True)
def jacobian(t, y, n, m, size, nc, steps, dv, vimp, gas, I, io, F, fo, J):
    """The Jacobian ``J`` of the right-hand side ``[qd, qdd, P]`` at ``(t, y)``, ``(2 n +
    N_AUX)`` square (see the module docstring), from :func:`~.compiled.assemble` and
    :func:`~.compiled.finish`.

    ``n``, ``m``, ``size``, ``nc``: coordinates, constraint rows, size of the kernel's linear
    system, clearance joints; ``steps``: the difference step of each of the ``2 n``
    coordinates; ``dv``, ``vimp``: as :func:`~.compiled.assemble` takes them; ``gas[c]``: the gas forces of pistons without a
    table at column ``c``'s state (row ``2 n``: the unperturbed state). Returns 0, or 1 for a
    singular linear system, 2 for a non-finite value.
    """
    phi = np.empty(m)
    diag = np.zeros((nc, N_DIAG))
    A = np.zeros((size, size))
    LU = np.zeros((size, size))
    rhs = np.empty(size)
    Q, Cq, cqd, powers = np.empty(n), np.empty((m, n)), np.empty(m), np.zeros(N_AUX)
    Qc, Cqc, cqdc, pc = np.empty(n), np.empty((m, n)), np.empty(m), np.zeros(N_AUX)
    piv = np.empty(size, np.int64)
    q = y[:n].copy()
    qd = y[n:2 * n].copy()
    assemble(t, q, qd, dv, vimp, gas[2 * n], I, io, F, fo, phi, Cq, diag, powers, Q, cqd, LU,
             rhs)
    if size and not _lu(LU, piv):
        return 1
    x = rhs.copy()
    _lu_solve(LU, piv, x)
    qdd0, qdd, lam = np.empty(n), np.empty(n), np.empty(m)
    ok = finish(x.copy(), Q, Cq, cqd, I, io, F, fo, qdd0, lam, powers)
    J[:, :] = 0.0
    for i in range(n):
        J[i, n + i] = 1.0
    r = np.empty(size)
    for c in range(2 * n):
        h = steps[c]
        if c < n:
            keep = q[c]
            q[c] = keep + h
        else:
            keep = qd[c - n]
            qd[c - n] = keep + h
        assemble(t, q, qd, dv, vimp, gas[c], I, io, F, fo, phi, Cqc, diag, pc, Qc, cqdc, A, rhs)
        # the perturbed system's residual at the unperturbed solution, solved with the
        # unperturbed factors: x + dx is the perturbed solution to first order in h
        for i in range(size):
            acc = rhs[i]
            for j in range(size):
                acc -= A[i, j] * x[j]
            r[i] = acc
        _lu_solve(LU, piv, r)
        for i in range(size):
            r[i] += x[i]
        ok = finish(r, Qc, Cqc, cqdc, I, io, F, fo, qdd, lam, pc) and ok
        for i in range(n):
            J[n + i, c] = (qdd[i] - qdd0[i]) / h
        for k in range(N_AUX):
            J[2 * n + k, c] = (pc[k] - powers[k]) / h
        if c < n:
            q[c] = keep
        else:
            qd[c - n] = keep
    if not ok:
        return 2
    for i in range(J.shape[0]):
        for j in range(J.shape[1]):
            if not np.isfinite(J[i, j]):
                return 2
    return 0


class CompiledJacobian:
    """``jac(t, y)`` for ``solve_ivp`` from a :class:`~.compiled.CompiledSystem`.

    Parameters
    ----------
    kernel : CompiledSystem
        The compiled form of the system (``sysm.kernel()``).
    v_impact : ndarray
        Per clearance joint the impact velocity of its contact in progress, m/s: the
        integrator's array, read at every call (it changes at contact onsets).
    atol : ndarray
        The integrator's absolute tolerances, one per state (m, rad, m/s, rad/s, J).
    rtol : float
        The integrator's relative tolerance (> 0).

    Attributes
    ----------
    njev : int
        Jacobians evaluated.
    """

    def __init__(self, kernel, v_impact, atol, rtol):
        self.kernel = kernel
        self.v_impact = v_impact
        self.n = kernel.n
        self.floor = STEP_FLOOR * np.asarray(atol, float)[:2 * self.n] / max(float(rtol), 1e-6)
        self._gas = np.zeros((2 * self.n + 1, kernel.gas_py.size))
        self.njev = 0

    def _inputs(self, t, y, steps):
        """The drives' (angle, speed, acceleration) at ``t``, the impact velocities and, per
        column and at the unperturbed state (last row), the gas forces of pistons without a
        table (Python functions of the crank angle)."""
        k, n = self.kernel, self.n
        dv = np.empty((len(k.drives), 3))
        for i, (_, _, prof) in enumerate(k.drives):
            dv[i, 0], dv[i, 1], dv[i, 2] = prof.angle(t), prof.speed(t), prof.acceleration(t)
        vimp = np.ascontiguousarray(self.v_impact, float)
        for c in range(2 * n + 1) if k._py_gas else ():
            q = np.array(y[:n], float)
            if c < n:
                q[c] += steps[c]
            for i, ld in k._py_gas:
                th = k.sysm.frame_pose_only(ld.crank, ld.crank_frame, q)[2]
                self._gas[c, i] = ld.gas_force(ld.sense * (th - ld.tdc_angle))
        return dv, vimp

    def __call__(self, t, y):
        """The ``(2 n + 6)``-square Jacobian of :meth:`Multibody.rhs` at ``(t, y)``.

        Raises
        ------
        numpy.linalg.LinAlgError
            A singular constraint Jacobian (as the right-hand side raises it).
        NonFinite
            A non-finite entry.
        """
        from ..model.system import NonFinite

        k, n = self.kernel, self.n
        y = np.ascontiguousarray(y, float)
        steps = _SQRT_EPS * np.maximum(np.abs(y[:2 * n]), self.floor)
        dv, vimp = self._inputs(t, y, steps)
        J = np.empty((y.size, y.size))
        status = jacobian(t, y, n, k.m, k._size, len(k.clearances), steps, dv, vimp, self._gas,
                          k.I, k.io, k.F, k.fo, J)
        self.njev += 1
        if status == 1:
            raise np.linalg.LinAlgError("Singular matrix")
        if status == 2:
            raise NonFinite(t)
        return J


def jacobian_for(sysm, method: str, v_impact, atol, rtol) -> dict:
    """``{"jac": CompiledJacobian}`` for ``solve_ivp`` when ``method`` uses a Jacobian and
    ``sysm`` runs on the compiled kernel, else ``{}`` (SciPy's own finite differences).

    Parameters
    ----------
    sysm : Multibody
    method : str
        The ``solve_ivp`` method.
    v_impact : ndarray
        The integrator's impact velocities, m/s (read at every call).
    atol : ndarray
        Absolute tolerances per state.
    rtol : float
        Relative tolerance.
    """
    if method not in IMPLICIT:
        return {}
    kernel = sysm.kernel()
    if kernel is None:
        return {}
    return {"jac": CompiledJacobian(kernel, v_impact, atol, rtol)}


def _flush_if_dependencies_changed() -> bool:
    """This module's cached Jacobian calls :func:`~.compiled.assemble` and
    :func:`~.compiled.finish` and what they call (numba issue #1833)."""
    from ..laws import lubrication, reynolds
    from ..model import clearance, joints
    from . import compiled

    return flush_if_changed(globals(), __name__,
                            (compiled, clearance, lubrication, reynolds, joints))


_flush_if_dependencies_changed()
