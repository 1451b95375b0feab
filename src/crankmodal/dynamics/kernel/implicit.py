"""The Radau IIA (order 5) step of ``solve_ivp`` compiled: stiff flexible bodies and oil films.

:class:`CompiledRadau` is SciPy's :class:`scipy.integrate.Radau` (Hairer & Wanner's RADAU5 as
SciPy writes it: its constants read from SciPy, its Newton iteration, error estimate, step-size
control and Jacobian-reuse rule) whose step runs inside Numba: the three stages' right-hand
sides are :func:`.compiled.evaluate` (the one implementation of the model), a Jacobian that
Newton's iteration asks for is :func:`.jacobian.jacobian`, and the linear systems use the
structure of the state ``y = [q, qd, W]``. With ``J = [[0, I, 0], [Jq, Jv, 0], [Pq, Pv, 0]]``
(:mod:`.jacobian`) the system ``(mu I - J) x = b`` of a stage reduces to ``n`` unknowns::

    (mu^2 I - mu Jv - Jq) a = b_v + (mu I - Jv) b_q,   v = mu a - b_q,
    w = (b_W + Pq a + Pv v) / mu

so each factorisation is of an ``n`` square matrix (``n`` coordinates) instead of a
``2 n + 6`` square one: eight times fewer operations, and no threaded LAPACK call (SciPy's costs
10x its work on a busy 2-core machine at these sizes).

Everything around the step stays ``solve_ivp``'s: the output times, the contact events located
on the dense output (SciPy's :class:`~scipy.integrate._ivp.radau.RadauDenseOutput` of the same
``Z``), and the right-hand side at each accepted step, which ``solve_ivp``'s function gives (the
progress bar and the run budget's early stop see that one evaluation per step). The evaluations
inside a step are added to ``Multibody.nfev``; the run budget (``max_rhs_evals``) counts them.

Trajectories equal SciPy's Radau with the compiled Jacobian up to round-off of the reduced
linear algebra (the tests compare them sample by sample).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.integrate import Radau
from scipy.integrate._ivp import radau as _radau

from .compiled import N_AUX, drive_values, evaluate, flush_if_changed
from .jacobian import _lu, _lu_solve, jacobian

#: SciPy's Radau IIA constants C, E, T, TI, TI_REAL, TI_COMPLEX (its dense output's P stays
#: SciPy's: RadauDenseOutput); then MU_REAL, MU_COMPLEX
_K = (np.asarray(_radau.C, float), np.asarray(_radau.E, float),
      np.ascontiguousarray(_radau.T, float), np.ascontiguousarray(_radau.TI, float),
      np.asarray(_radau.TI_REAL, float), np.asarray(_radau.TI_COMPLEX, complex))
_MU_R, _MU_C = float(_radau.MU_REAL), complex(_radau.MU_COMPLEX)
#: SciPy's step control: Newton iterations, smallest and largest step factor
_CTL = np.array([_radau.NEWTON_MAXITER, _radau.MIN_FACTOR, _radau.MAX_FACTOR], float)

# what :func:`step` returns
ACCEPTED, TOO_SMALL, BUDGET, NONFINITE, SINGULAR = range(5)
# slots of the float state ``fs`` and the integer state ``ns``
_T, _H, _HOLD, _EOLD, _TBOUND, _MAXSTEP, _RTOL, _NTOL, _TOLD, _TNEW, _TFAIL = range(11)
_NFEV, _MAXNFEV, _CURJ, _LUOK, _HAVESOL, _NJEV, _NLU, _RECOMP = range(8)
_SQRT_EPS = float(np.sqrt(np.finfo(float).eps))


@njit(cache=True)
def _fun(t, y, dy, M, ns):
    """One counted right-hand side into ``dy``: 0, or BUDGET / NONFINITE / SINGULAR."""
    tabs, work, drv, dv, vimp, gas_py, phi, Cq, diag, powers, lam = M
    ns[_NFEV] += 1
    if ns[_NFEV] > ns[_MAXNFEV]:
        return BUDGET
    n = (y.size - N_AUX) // 2
    drive_values(t, drv, dv)
    for i in range(n):
        dy[i] = y[n + i]
    status = evaluate(t, y[:n], y[n:2 * n], dv, vimp, gas_py, tabs, work, phi, Cq, diag,
                      powers, dy[n:2 * n], lam)
    for i in range(N_AUX):
        dy[2 * n + i] = powers[i]
    if status == 0:
        return 0
    return NONFINITE if status == 1 else SINGULAR


@njit(cache=True)
def _factor(J, mu, S, piv):
    """``S = mu^2 I - mu Jv - Jq`` (``n`` square, see the module docstring) factorised."""
    n = S.shape[0]
    for i in range(n):
        for j in range(n):
            S[i, j] = -mu * J[n + i, n + j] - J[n + i, j]
        S[i, i] += mu * mu
    return _lu(S, piv)


@njit(cache=True)
def _solve(J, mu, S, piv, b, x):
    """``(mu I - J) x = b`` with the factors of :func:`_factor` (module docstring)."""
    n = S.shape[0]
    N = b.size
    a = x[:n]
    for i in range(n):
        acc = b[n + i] + mu * b[i]
        for j in range(n):
            acc -= J[n + i, n + j] * b[j]
        a[i] = acc
    _lu_solve(S, piv, a)
    for i in range(n):
        x[n + i] = mu * a[i] - b[i]
    for k in range(2 * n, N):
        acc = b[k]
        for j in range(n):
            acc += J[k, j] * x[j] + J[k, n + j] * x[n + j]
        x[k] = acc / mu


@njit(cache=True)
def _norm(x, scale):
    """SciPy's ``norm(x / scale)``: the RMS of ``x`` (1-D, or rows each scaled by ``scale``)."""
    xr = x.reshape(-1)
    acc = 0.0
    for i in range(xr.size):
        v = xr[i] / scale[i % scale.size]
        acc += v * v
    return np.sqrt(acc / xr.size)


@njit(cache=True)
def _jacobian(t, y, J, M, JA, ns):
    """:func:`.jacobian.jacobian` at ``(t, y)`` into ``J``: 0 or SINGULAR / NONFINITE."""
    tabs, drv, dv, vimp = M[0], M[2], M[3], M[4]
    floor, gas, m, size, nc = JA
    I, io, F, fo = tabs
    n = (y.size - N_AUX) // 2
    steps = np.empty(2 * n)
    for i in range(2 * n):
        steps[i] = _SQRT_EPS * max(abs(y[i]), floor[i])
    drive_values(t, drv, dv)
    status = jacobian(t, y, n, m, size, nc, steps, dv, vimp, gas, I, io, F, fo, J)
    ns[_NJEV] += 1
    if status == 1:
        return SINGULAR
    return NONFINITE if status == 2 else 0


@njit(cache=True)
def _newton(t, y, h, Z0, scale, tol, J, S, pr, Sc, pc, K, ctl, M, ns, Z, out):
    """SciPy's ``solve_collocation_system``: ``out = (converged, iterations, rate)``; returns
    0 or BUDGET / SINGULAR (a non-finite stage ends the iteration unconverged, as SciPy)."""
    C, _E, T, TI, TI_R, TI_C = K
    N = y.size
    mu_r = _MU_R / h
    mu_c = _MU_C / h
    W = TI @ Z0
    Z[:, :] = Z0
    Fs = np.empty((3, N))
    yi = np.empty(N)
    f_r = np.empty(N)
    f_c = np.empty(N, np.complex128)
    dW_r = np.empty(N)
    dW_c = np.empty(N, np.complex128)
    dW = np.empty((3, N))
    dW_norm_old = np.nan
    rate = np.nan
    converged = False
    k = 0
    newton_max = int(ctl[0])
    while k < newton_max:
        finite = True
        for i in range(3):
            for j in range(N):
                yi[j] = y[j] + Z[i, j]
            st = _fun(t + C[i] * h, yi, Fs[i], M, ns)
            if st == NONFINITE:
                finite = False
                break
            if st != 0:
                return st
        if not finite:
            break
        for j in range(N):
            f_r[j] = Fs[0, j] * TI_R[0] + Fs[1, j] * TI_R[1] + Fs[2, j] * TI_R[2] \
                - mu_r * W[0, j]
            f_c[j] = Fs[0, j] * TI_C[0] + Fs[1, j] * TI_C[1] + Fs[2, j] * TI_C[2] \
                - mu_c * (W[1, j] + 1j * W[2, j])
        _solve(J, mu_r, S, pr, f_r, dW_r)
        _solve(J, mu_c, Sc, pc, f_c, dW_c)
        for j in range(N):
            dW[0, j] = dW_r[j]
            dW[1, j] = dW_c[j].real
            dW[2, j] = dW_c[j].imag
        dW_norm = _norm(dW, scale)
        if not np.isnan(dW_norm_old):
            rate = dW_norm / dW_norm_old
        if not np.isnan(rate) and (rate >= 1.0
                                   or rate ** (newton_max - k) / (1.0 - rate) * dW_norm > tol):
            break
        W += dW
        Z[:, :] = T @ W
        if dW_norm == 0.0 or (not np.isnan(rate) and rate / (1.0 - rate) * dW_norm < tol):
            converged = True
            break
        dW_norm_old = dW_norm
        k += 1
    out[0] = 1.0 if converged else 0.0
    out[1] = min(k + 1, newton_max)
    out[2] = rate
    return 0


@njit(cache=True)
def _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old):
    """SciPy's ``predict_factor`` (Gustafsson's step control); NaN stands for None."""
    if np.isnan(error_norm_old) or np.isnan(h_abs_old) or error_norm == 0.0:
        multiplier = 1.0
    else:
        multiplier = h_abs / h_abs_old * (error_norm_old / error_norm) ** 0.25
    if error_norm == 0.0:
        return np.inf
    return min(1.0, multiplier) * error_norm ** -0.25


@njit(cache=True)
def step(fs, ns, y, f, J, atol, y_old, Qd, Z, y_new, S, pr, Sc, pc, K, ctl, M, JA):
    """One accepted step of SciPy's ``Radau._step_impl`` from ``(fs[_T], y)`` with ``f`` its
    right-hand side, into ``y_new``, ``Z`` and ``fs[_TNEW]``; the previous step's dense output
    (``fs[_TOLD]``, ``y_old``, ``Qd``) predicts the stages. Returns ACCEPTED, or TOO_SMALL,
    BUDGET, NONFINITE, SINGULAR (``fs[_TFAIL]``: where)."""
    C, E = K[0], K[1]
    N = y.size
    t = fs[_T]
    max_step, rtol, t_bound = fs[_MAXSTEP], fs[_RTOL], fs[_TBOUND]
    newton_max, min_factor = ctl[0], ctl[1]
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    h_abs, h_abs_old, err_old = fs[_H], fs[_HOLD], fs[_EOLD]
    if h_abs > max_step:
        h_abs, h_abs_old, err_old = max_step, np.nan, np.nan
    elif h_abs < min_step:
        h_abs, h_abs_old, err_old = min_step, np.nan, np.nan
    Z0 = np.zeros((3, N))
    scale = np.empty(N)
    newton = np.empty(3)
    error = np.empty(N)
    rhs = np.empty(N)
    ye = np.empty(N)
    fe = np.empty(N)
    rejected = False
    fs[_TFAIL] = t
    n_iter, rate, safety, error_norm = 0.0, np.nan, 0.9, 0.0
    while True:
        if h_abs < min_step:
            return TOO_SMALL
        h = h_abs
        t_new = t + h
        if t_new - t_bound > 0.0:
            t_new = t_bound
        h = t_new - t
        h_abs = abs(h)
        if ns[_HAVESOL]:
            h_old = t - fs[_TOLD]
            for i in range(3):
                x = (t + h * C[i] - fs[_TOLD]) / h_old
                for j in range(N):
                    Z0[i, j] = y_old[j] + Qd[j, 0] * x + Qd[j, 1] * x * x \
                        + Qd[j, 2] * x * x * x - y[j]
        for j in range(N):
            scale[j] = atol[j] + abs(y[j]) * rtol
        converged = False
        while not converged:
            if not ns[_LUOK]:
                if not (_factor(J, _MU_R / h, S, pr) and _factor(J, _MU_C / h, Sc, pc)):
                    return SINGULAR
                ns[_LUOK] = 1
                ns[_NLU] += 2
            st = _newton(t, y, h, Z0, scale, fs[_NTOL], J, S, pr, Sc, pc, K, ctl, M, ns, Z,
                         newton)
            if st != 0:
                return st
            converged = newton[0] > 0.0
            if not converged:
                if ns[_CURJ]:
                    break
                st = _jacobian(t, y, J, M, JA, ns)
                if st != 0:
                    return st
                ns[_CURJ] = 1
                ns[_LUOK] = 0
        if not converged:
            h_abs *= 0.5
            ns[_LUOK] = 0
            continue
        n_iter, rate = newton[1], newton[2]
        for j in range(N):
            y_new[j] = y[j] + Z[2, j]
            rhs[j] = f[j] + (Z[0, j] * E[0] + Z[1, j] * E[1] + Z[2, j] * E[2]) / h
        _solve(J, _MU_R / h, S, pr, rhs, error)
        for j in range(N):
            scale[j] = atol[j] + max(abs(y[j]), abs(y_new[j])) * rtol
        error_norm = _norm(error, scale)
        safety = 0.9 * (2.0 * newton_max + 1.0) / (2.0 * newton_max + n_iter)
        if rejected and error_norm > 1.0:
            for j in range(N):
                ye[j] = y[j] + error[j]
            st = _fun(t, ye, fe, M, ns)
            if st != 0:
                return st
            for j in range(N):
                rhs[j] = fe[j] + (Z[0, j] * E[0] + Z[1, j] * E[1] + Z[2, j] * E[2]) / h
            _solve(J, _MU_R / h, S, pr, rhs, error)
            error_norm = _norm(error, scale)
        if error_norm > 1.0:
            factor = _predict_factor(h_abs, h_abs_old, error_norm, err_old)
            h_abs *= max(min_factor, safety * factor)
            ns[_LUOK] = 0
            rejected = True
        else:
            break
    recompute_jac = n_iter > 2 and rate > 1e-3
    factor = min(ctl[2], safety * _predict_factor(h_abs, h_abs_old, error_norm, err_old))
    if not recompute_jac and factor < 1.2:
        factor = 1.0
    else:
        ns[_LUOK] = 0
    ns[_RECOMP] = 1 if recompute_jac else 0
    fs[_HOLD] = fs[_H]
    fs[_EOLD] = error_norm
    fs[_H] = h_abs * factor
    fs[_TNEW] = t_new
    return ACCEPTED

class CompiledRadau(Radau):
    """SciPy's Radau whose step runs compiled (module docstring); a ``solve_ivp`` method.

    Takes SciPy's Radau options and, through ``solve_ivp``'s options, ``sysm`` (a
    :class:`~.system.Multibody` on the compiled kernel with
    :attr:`~.compiled.CompiledSystem.loop_ready`) and ``v_impact`` (the integrator's impact
    velocities, m/s). The Jacobian is :class:`.jacobian.CompiledJacobian` (``jac`` is ignored).

    Attributes
    ----------
    nfev_inner : int
        Right-hand sides evaluated inside the compiled steps (also added to ``sysm.nfev``).
    """

    def __init__(self, fun, t0, y0, t_bound, max_step=np.inf, rtol=1e-3, atol=1e-6,
                 jac=None, sysm=None, v_impact=None, **options):
        from .jacobian import CompiledJacobian

        kernel = sysm.kernel()
        n_y = np.asarray(y0).size
        atol_v = np.broadcast_to(np.asarray(atol, float), (n_y,)).copy()
        cj = CompiledJacobian(kernel, v_impact, atol_v, rtol)
        super().__init__(fun, t0, y0, t_bound, max_step=max_step, rtol=rtol, atol=atol, jac=cj,
                         **options)
        self.sysm, self.kernel = sysm, kernel
        n, m, nc = kernel.n, kernel.m, len(kernel.clearances)
        kernel.vimp[:] = v_impact
        self._v_impact = v_impact
        self._M = (kernel.tabs, kernel._work, kernel.drv, np.zeros((len(kernel.drives), 3)),
                   kernel.vimp, kernel.gas_py, np.empty(m), np.empty((m, n)),
                   np.zeros((nc, kernel._diag.shape[1])), np.zeros(N_AUX), np.empty(m))
        self._JA = (np.ascontiguousarray(cj.floor), np.zeros((2 * n + 1, kernel.gas_py.size)),
                    m, kernel._size, nc)
        self._fs = np.zeros(11)
        self._ns = np.zeros(8, np.int64)
        self._S, self._pr = np.zeros((n, n)), np.zeros(n, np.int64)
        self._Sc, self._pc = np.zeros((n, n), complex), np.zeros(n, np.int64)
        self._y_new = np.zeros(n_y)
        self._Zw = np.zeros((3, n_y))
        self._Qd = np.zeros((n_y, 3))
        self._atol_v = np.ascontiguousarray(self.atol * np.ones(n_y), float)
        self.nfev_inner = 0

    def _step_impl(self):
        from ..model.system import BudgetExceeded, NonFinite

        fs, ns, sysm = self._fs, self._ns, self.sysm
        self.kernel.vimp[:] = self._v_impact  # the integrator sets it between segments
        fs[_T], fs[_H] = self.t, self.h_abs
        fs[_HOLD] = np.nan if self.h_abs_old is None else self.h_abs_old
        fs[_EOLD] = np.nan if self.error_norm_old is None else self.error_norm_old
        fs[_TBOUND], fs[_MAXSTEP], fs[_RTOL] = self.t_bound, self.max_step, self.rtol
        fs[_NTOL] = self.newton_tol
        ns[_NFEV] = 0
        budget = sysm.max_nfev
        ns[_MAXNFEV] = np.iinfo(np.int64).max if budget is None else budget - sysm.nfev
        ns[_CURJ] = int(self.current_jac)
        ns[_LUOK] = int(self.LU_real is not None)
        ns[_HAVESOL] = int(self.sol is not None)
        if self.sol is not None:
            fs[_TOLD] = self.sol.t_old
            self._Qd[:] = self.sol.Q
            y_old = self.sol.y_old
        else:
            y_old = self.y
        J = np.ascontiguousarray(self.J, float)
        code = step(fs, ns, np.ascontiguousarray(self.y, float),
                    np.ascontiguousarray(self.f, float), J, self._atol_v,
                    np.ascontiguousarray(y_old, float), self._Qd, self._Zw, self._y_new,
                    self._S, self._pr, self._Sc, self._pc, _K, _CTL, self._M, self._JA)
        inner = int(ns[_NFEV])
        self.nfev_inner += inner
        self.nfev += inner
        self.njev += int(ns[_NJEV])
        self.nlu += int(ns[_NLU])
        ns[_NJEV] = ns[_NLU] = 0
        sysm.nfev += min(inner, ns[_MAXNFEV])
        if code == BUDGET:
            raise BudgetExceeded(float(fs[_TFAIL]))
        if code == NONFINITE:
            raise NonFinite(float(fs[_TFAIL]))
        if code == SINGULAR:
            raise np.linalg.LinAlgError("Singular matrix")
        if code == TOO_SMALL:
            return False, self.TOO_SMALL_STEP
        self.J = J
        # LU_real stands for "the compiled factors are current" (they live in _S, _Sc)
        self.LU_real = self.LU_complex = (True if ns[_LUOK] else None)
        t, t_new = self.t, float(fs[_TNEW])
        y_new = self._y_new.copy()
        f_new = self.fun(t_new, y_new)  # solve_ivp's function: progress, budget, early stop
        if ns[_RECOMP]:
            self.J = self.jac(t_new, y_new, f_new)
            self.current_jac = True
        else:
            self.current_jac = False
        self.h_abs_old, self.error_norm_old = float(fs[_HOLD]), float(fs[_EOLD])
        self.h_abs = float(fs[_H])
        self.y_old = self.y
        self.t, self.y, self.f = t_new, y_new, f_new
        self.Z = self._Zw.copy()
        self.t_old = t
        self.sol = self._compute_dense_output()
        return True, None


def applicable(sysm, method: str) -> bool:
    """True when ``method`` is Radau and ``sysm``'s whole right-hand side is compiled
    (:attr:`.CompiledSystem.loop_ready`): :class:`CompiledRadau` can then run it."""
    if method != "Radau":
        return False
    k = sysm.kernel()
    return k is not None and k.loop_ready


def solver_options(sysm, method: str, v_impact, atol, rtol) -> dict:
    """``solve_ivp`` options for an implicit ``method``: :class:`CompiledRadau` (as
    ``"method"``, with ``sysm`` and ``v_impact``) when :func:`applicable`, else the compiled
    Jacobian (:func:`.jacobian.jacobian_for`: ``{"jac": ...}``, or ``{}``).

    Parameters
    ----------
    sysm : Multibody
    method : str
        The ``solve_ivp`` method of the run.
    v_impact : ndarray
        The integrator's impact velocities, m/s (read at every step).
    atol : ndarray
        Absolute tolerances per state.
    rtol : float
        Relative tolerance.
    """
    from .jacobian import jacobian_for

    if applicable(sysm, method):
        return {"method": CompiledRadau, "sysm": sysm, "v_impact": v_impact}
    return jacobian_for(sysm, method, v_impact, atol, rtol)


def _flush_if_dependencies_changed() -> bool:
    """This module's cached step calls :mod:`.compiled`, :mod:`.jacobian` and what they call
    (numba issue #1833)."""
    from ..laws import lubrication, reynolds
    from ..model import clearance, joints
    from . import compiled
    from . import jacobian as jac_module

    return flush_if_changed(globals(), __name__,
                            (compiled, jac_module, clearance, lubrication, reynolds, joints))


_flush_if_dependencies_changed()
