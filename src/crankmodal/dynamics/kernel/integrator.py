"""The compiled integrator loop: SciPy's RK45 with contact events, run inside Numba.

:func:`run` integrates a :class:`~.system.Multibody` whose whole right-hand side is compiled
(:attr:`.CompiledSystem.loop_ready`) with the explicit Dormand-Prince 5(4) pair exactly as
``scipy.integrate.solve_ivp(method="RK45")`` does: SciPy's own tableau (``RK45.A/B/C/E/P``,
read from SciPy, not copied), its error norm ``rms(err / (atol + rtol max(|y|, |y_new|)))``,
safety factor 0.9, step factors 0.2..10, ``max_step``, its initial-step selection (Hairer,
Norsett & Wanner II.4), first-same-as-last stages and its quartic dense output. Contact events
are located inside the loop as ``solve_ivp`` locates them: per clearance joint the penetration
crossing zero upwards (onset) and downwards (separation) and its rate crossing zero downwards
(the deepest penetration), a sign change at a step's end solved on the step's dense output by
Brent's method to 4 ulp (the algorithm of SciPy's ``brentq``). Laws with memory (the impact
velocity of a Hunt-Crossley contact) make onsets and separations terminal: the loop returns
and :func:`run` restarts it with the impact velocity set, as the ``solve_ivp`` path of
:func:`~.run.integrate.integrate` does (the same graze rule included).

Each right-hand side is :func:`.compiled.evaluate`, the function the Python-called kernel uses:
one implementation of the model. The loop returns to Python every 1/200 of the run, every
20 000 evaluations, at every terminal event and when its record buffers fill: the progress bar
advances, Ctrl-C is honoured, and the run budget's early stop
(:class:`~.run.budget.ProjectionGuard`) judges the evaluation rate.

Trajectories equal ``solve_ivp``'s up to round-off (the order of a few sums differs); an
impacting run, chaotic, then departs from it within the ensemble spread.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.integrate import RK45
from scipy.integrate._ivp.rk import MAX_FACTOR, MIN_FACTOR, SAFETY

from .compiled import (
    DIAG,
    N_AUX,
    _dgesv,
    assemble,
    clearance_kinematics,
    drive_values,
    evaluate,
    finish,
    flush_if_changed,
)

#: the Dormand-Prince 5(4) pair of SciPy's RK45: C, A, B, E (7 stages with FSAL), P (dense)
_TABLEAU = (np.asarray(RK45.C, float), np.ascontiguousarray(RK45.A, float),
            np.asarray(RK45.B, float), np.asarray(RK45.E, float),
            np.ascontiguousarray(RK45.P, float))
#: SciPy's step-size control: safety, smallest and largest factor, exponent -1/(order + 1)
_CONTROL = np.array([SAFETY, MIN_FACTOR, MAX_FACTOR, -1.0 / (RK45.error_estimator_order + 1)])

# what :func:`advance` returns
DONE, WINDOW, TERMINAL, FULL, BUDGET, NONFINITE, SINGULAR, TOO_SMALL = range(8)
_OK = -1
# slots of the float state ``fs`` and the integer state ``ns``
_T, _H, _TOLD, _TEND, _MAXSTEP, _RTOL, _TWIN, _TFAIL = range(8)
_NFEV, _MAXNFEV, _NWIN, _IOUT, _NREC, _NOWN, _OWN = range(7)
# event kinds (three events per clearance joint: 3 j + kind)
ON, OFF, PEAK = 0, 1, 2
#: evaluations between returns to Python (~0.1-0.5 s)
EVALS_PER_RETURN = 20_000
#: returns to Python per run (progress bar, Ctrl-C, the budget's early stop)
WINDOWS = 200
_REC_CAP, _OWN_CAP = 2048, 4096
_NDIAG = len(DIAG)


class StepFailed(Exception):
    """The step size fell below the spacing of floating-point numbers at ``t`` s."""

    def __init__(self, t):
        super().__init__(t)
        self.t = t


class EventAgain(Exception):
    """A contact event fired again at the point the integration restarted from (``t``, s)."""

    def __init__(self, t):
        super().__init__(t)
        self.t = t


class Singular(np.linalg.LinAlgError):
    """The linear system of the accelerations is singular (near ``t`` s)."""

    def __init__(self, t):
        super().__init__("Singular matrix")
        self.t = t


# ------------------------------------------------------------------------------ compiled part
@njit(cache=True, error_model="numpy")
def _rms(x):
    return np.sqrt(np.sum(x * x) / x.size)


@njit(cache=True, error_model="numpy")
def _cholesky_solve(sz, L, b, x):
    """``x = B^-1 b`` for a symmetric positive definite ``B = L L^T`` (``L`` lower, ``sz``)."""
    for i in range(sz):
        v = b[i]
        for k in range(i):
            v -= L[i, k] * x[k]
        x[i] = v / L[i, i]
    for i in range(sz - 1, -1, -1):
        v = x[i]
        for k in range(i + 1, sz):
            v -= L[k, i] * x[k]
        x[i] = v / L[i, i]


@njit(cache=True, error_model="numpy")
def block_solve(A, rhs, n, B):
    """Solve :func:`.compiled.assemble`'s whole KKT system ``A x = rhs`` (``[M Cq^T; Cq 0]``,
    flexible bodies without an oil film) by its block-diagonal mass matrix, in place in ``rhs``
    (``[qdd; lam]``, what :func:`.compiled.finish` reads).

    The mass matrix is diagonal but for each flexible body's (theta, xi) block (``M(xi)``, SPD:
    Cholesky) and zero for massless coordinates (a piston's rotation); with ``a`` the massive
    coordinates and ``b`` the massless ones, ``Y = M_a^-1 [Q_a, Cq_a^T]`` by blocks and the
    system left is the rigid path's reduced one,
    ``[0, Cq_b^T; Cq_b, -Cq_a Y_C] [qdd_b; lam] = [Q_b; gamma - Cq_a Y_Q]`` (LAPACK dgesv),
    then ``qdd_a = Y_Q - Y_C lam``, each sum over the constraint rows that touch a coordinate's
    block (``yr_rows[yr_ptr[i]:yr_ptr[i + 1]]``; Y is zero elsewhere and never read). For the
    flexible four-star (80 unknowns, 27 left) this costs a third of the LU of the whole system.
    Returns 0, 2 (singular) or 3 (a block not positive definite: the caller solves the whole
    system instead).
    """
    blk, singles, a_idx, massless, Y, S, r, ipiv, ints, L, col, x, yr_ptr, yr_rows = B
    m = rhs.size - n
    for i in singles:
        d = A[i, i]
        Y[i, 0] = rhs[i] / d
        for k in range(yr_ptr[i], yr_ptr[i + 1]):
            c = yr_rows[k]
            Y[i, 1 + c] = A[n + c, i] / d
    for bi in range(blk.shape[0]):
        s0, sz = blk[bi, 0], blk[bi, 1]
        for i in range(sz):
            for j in range(i + 1):
                v = A[s0 + i, s0 + j]
                for k in range(j):
                    v -= L[i, k] * L[j, k]
                if i == j:
                    if v <= 0.0:
                        return 3
                    L[i, i] = np.sqrt(v)
                else:
                    L[i, j] = v / L[j, j]
        for k in range(yr_ptr[s0] - 1, yr_ptr[s0 + 1]):  # Q, then the rows touching it
            c = 0 if k < yr_ptr[s0] else 1 + yr_rows[k]
            for i in range(sz):
                col[i] = rhs[s0 + i] if c == 0 else A[n + c - 1, s0 + i]
            _cholesky_solve(sz, L, col, x)
            for i in range(sz):
                Y[s0 + i, c] = x[i]
    nb = massless.size
    # the reduced system stored transposed: LAPACK reads a C-ordered array as its transpose
    S[:, :] = 0.0
    for bk in range(nb):
        i = massless[bk]
        r[bk] = rhs[i]
        for c in range(m):
            S[bk, nb + c] = A[n + c, i]
            S[nb + c, bk] = A[n + c, i]
    for c in range(m):
        r[nb + c] = rhs[n + c]
    for i in a_idx:
        for k1 in range(yr_ptr[i], yr_ptr[i + 1]):
            c1 = yr_rows[k1]
            cq = A[n + c1, i]
            if cq != 0.0:
                r[nb + c1] -= cq * Y[i, 0]
                for k2 in range(yr_ptr[i], yr_ptr[i + 1]):
                    c2 = yr_rows[k2]
                    S[nb + c2, nb + c1] -= cq * Y[i, 1 + c2]
    if r.size:
        ints[0], ints[1], ints[2] = r.size, 1, 0
        _dgesv(ints[0:].ctypes, ints[1:].ctypes, S.ctypes, ints[0:].ctypes, ipiv.ctypes,
               r.ctypes, ints[0:].ctypes, ints[2:].ctypes)
        if ints[2] != 0:
            return 2
    for c in range(m):
        rhs[n + c] = r[nb + c]
    for bk in range(nb):
        rhs[massless[bk]] = r[bk]
    for i in a_idx:
        v = Y[i, 0]
        for k in range(yr_ptr[i], yr_ptr[i + 1]):
            c = yr_rows[k]
            v -= Y[i, 1 + c] * r[nb + c]
        rhs[i] = v
    return 0


@njit(cache=True, error_model="numpy")
def _fun(t, y, dy, M, fs, ns):
    """One counted right-hand side into ``dy``: _OK, or BUDGET / NONFINITE / SINGULAR with the
    time in ``fs[_TFAIL]`` (the budget judged before the evaluation, as Multibody.rhs).

    :func:`.compiled.evaluate`, or with flexible bodies (``B`` not empty) its
    :func:`assemble` and :func:`finish` around :func:`block_solve` instead of the LU of the
    whole system."""
    tabs, work, drv, dv, vimp, gas_py, phi, Cq, diag, powers, lam, B = M
    ns[_NFEV] += 1
    if ns[_NFEV] > ns[_MAXNFEV]:
        fs[_TFAIL] = t
        return BUDGET
    n = (y.size - N_AUX) // 2
    drive_values(t, drv, dv)
    for i in range(n):
        dy[i] = y[n + i]
    status = 3
    if B[0].shape[0]:
        I, io, F, fo = tabs
        Q, cqd, A, rhs = work[0], work[1], work[2], work[3]
        assemble(t, y[:n], y[n:2 * n], dv, vimp, gas_py, I, io, F, fo, phi, Cq, diag, powers,
                 Q, cqd, A, rhs)
        status = block_solve(A, rhs, n, B)
        if status == 0:
            status = 0 if finish(rhs, Q, Cq, cqd, I, io, F, fo, dy[n:2 * n], lam, powers) else 1
    if status == 3:
        status = evaluate(t, y[:n], y[n:2 * n], dv, vimp, gas_py, tabs, work, phi, Cq, diag,
                          powers, dy[n:2 * n], lam)
    for i in range(N_AUX):
        dy[2 * n + i] = powers[i]
    if status == 0:
        return _OK
    fs[_TFAIL] = t
    return NONFINITE if status == 1 else SINGULAR


@njit(cache=True, error_model="numpy")
def _event_values(y, M, ev, out, g):
    """Every event's function at state ``y``: the penetration (onset, separation) or its rate
    (deepest penetration) of its joint (:func:`.compiled.clearance_kinematics`)."""
    tabs = M[0]
    I, io, F, fo = tabs
    n = (y.size - N_AUX) // 2
    ev_j, ev_kind = ev[0], ev[1]
    last = -1
    for e in range(ev_j.size):
        j = ev_j[e]
        if j != last:
            clearance_kinematics(j, y[:n], y[n:2 * n], I, io, F, fo, out)
            last = j
        g[e] = out[6] if ev_kind[e] == PEAK else out[5]


@njit(cache=True, error_model="numpy")
def _dense(x_t, t_old, h, y_old, Qd, out):
    """SciPy's RK dense output at ``x_t`` s: ``y_old + h Q [x, x^2, x^3, x^4]``."""
    x = (x_t - t_old) / h
    p0 = x
    p1 = p0 * x
    p2 = p1 * x
    p3 = p2 * x
    for i in range(out.size):
        out[i] = h * (Qd[i, 0] * p0 + Qd[i, 1] * p1 + Qd[i, 2] * p2 + Qd[i, 3] * p3) + y_old[i]


@njit(cache=True, error_model="numpy")
def _event_at(e, x_t, fs, h, V, Qd, M, ev, out):
    ytmp = V[5]
    _dense(x_t, fs[_TOLD], h, V[2], Qd, ytmp)
    tabs = M[0]
    I, io, F, fo = tabs
    n = (ytmp.size - N_AUX) // 2
    clearance_kinematics(ev[0][e], ytmp[:n], ytmp[n:2 * n], I, io, F, fo, out)
    return out[6] if ev[1][e] == PEAK else out[5]


@njit(cache=True, error_model="numpy")
def _brent(e, xa, xb, fs, h, V, Qd, M, ev, out):
    """Root of event ``e`` on the dense output in [xa, xb]: SciPy's brentq (zeros.c), xtol =
    rtol = 4 eps. Without a sign change (round-off at the bracket's end) the end ``xb``."""
    tol = 4.0 * np.finfo(np.float64).eps
    xpre, xcur = xa, xb
    fpre = _event_at(e, xpre, fs, h, V, Qd, M, ev, out)
    fcur = _event_at(e, xcur, fs, h, V, Qd, M, ev, out)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if np.signbit(fpre) == np.signbit(fcur):
        return xb
    xblk = fblk = spre = scur = 0.0
    for _ in range(100):
        if fpre != 0.0 and fcur != 0.0 and np.signbit(fpre) != np.signbit(fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (tol + tol * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre, scur = scur, stry  # good short step
            else:
                spre, scur = sbis, sbis  # bisect
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0.0 else -delta
        fcur = _event_at(e, xcur, fs, h, V, Qd, M, ev, out)
    return xcur


@njit(cache=True, error_model="numpy")
def start(fs, ns, V, K, atol, M, ev, out, ctl):
    """A segment's start at ``(fs[_T], V[0])``: ``f``, SciPy's initial step, the events."""
    y, f, ytmp = V[0], V[1], V[5]
    st = _fun(fs[_T], y, f, M, fs, ns)
    if st != _OK:
        return st
    t0, rtol = fs[_T], fs[_RTOL]
    interval = abs(fs[_TEND] - t0)
    scale = atol + np.abs(y) * rtol
    d0 = _rms(y / scale)
    d1 = _rms(f / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    for i in range(y.size):
        ytmp[i] = y[i] + h0 * f[i]
    f1 = K[1]
    st = _fun(t0 + h0, ytmp, f1, M, fs, ns)
    if st != _OK:
        return st
    d2 = _rms((f1 - f) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (-ctl[3])
    fs[_H] = min(100.0 * h0, h1, interval, fs[_MAXSTEP])
    _event_values(y, M, ev, out, ev[5])
    return _OK


@njit(cache=True, error_model="numpy")
def _step(fs, ns, V, K, atol, M, tab, ctl):
    """One accepted step of SciPy's ``RungeKutta._step_impl`` (RK45): _OK or a failure."""
    C, A, B, E, _P = tab
    safety, min_factor, max_factor, exponent = ctl[0], ctl[1], ctl[2], ctl[3]
    y, f, y_old, y_new, f_new, ytmp = V[0], V[1], V[2], V[3], V[4], V[5]
    t, t_end, rtol = fs[_T], fs[_TEND], fs[_RTOL]
    ny = y.size
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    h_abs = fs[_H]
    if h_abs > fs[_MAXSTEP]:
        h_abs = fs[_MAXSTEP]
    elif h_abs < min_step:
        h_abs = min_step
    rejected = False
    while True:
        if h_abs < min_step:
            return TOO_SMALL
        t_new = t + h_abs
        if t_new - t_end > 0.0:
            t_new = t_end
        h = t_new - t
        h_abs = abs(h)
        for i in range(ny):
            K[0, i] = f[i]
        for s in range(1, 6):
            for i in range(ny):
                acc = 0.0
                for k in range(s):
                    acc += K[k, i] * A[s, k]
                ytmp[i] = y[i] + acc * h
            st = _fun(t + C[s] * h, ytmp, K[s], M, fs, ns)
            if st != _OK:
                return st
        for i in range(ny):
            acc = 0.0
            for k in range(6):
                acc += K[k, i] * B[k]
            y_new[i] = y[i] + h * acc
        st = _fun(t + h, y_new, f_new, M, fs, ns)
        if st != _OK:
            return st
        for i in range(ny):
            K[6, i] = f_new[i]
        sq = 0.0
        for i in range(ny):
            acc = 0.0
            for k in range(7):
                acc += K[k, i] * E[k]
            r = acc * h / (atol[i] + max(abs(y[i]), abs(y_new[i])) * rtol)
            sq += r * r
        error_norm = np.sqrt(sq / ny)
        if error_norm < 1.0:
            if error_norm == 0.0:
                factor = max_factor
            else:
                factor = min(max_factor, safety * error_norm ** exponent)
            if rejected:
                factor = min(1.0, factor)
            h_abs *= factor
            break
        h_abs *= max(min_factor, safety * error_norm ** exponent)
        rejected = True
    fs[_TOLD] = t
    fs[_T] = t_new
    fs[_H] = h_abs
    for i in range(ny):
        y_old[i] = y[i]
        y[i] = y_new[i]
        f[i] = f_new[i]
    return _OK


@njit(cache=True, error_model="numpy")
def _dense_coefficients(K, P, Qd):
    """``Q = K^T P`` of SciPy's ``RkDenseOutput``."""
    for i in range(Qd.shape[0]):
        for c in range(4):
            acc = 0.0
            for k in range(7):
                acc += K[k, i] * P[k, c]
            Qd[i, c] = acc


@njit(cache=True, error_model="numpy")
def _after_step(fs, ns, V, K, Qd, M, tab, ev, out, io_bufs):
    """Events and output of the step just taken (``solve_ivp``'s loop body): active events
    located, recorded and, if one is terminal, the step cut there; output samples by the dense
    output, or the step itself. Returns True when a terminal event ended the segment."""
    ev_j, _kind, ev_dir, ev_use, ev_term, g, g_new, roots, order = ev
    t_out, y_out, own_t, own_y, rec_e, rec_t, rec_d, rec_r, rec_y = io_bufs
    y, y_old = V[0], V[2]
    t_old, t = fs[_TOLD], fs[_T]
    h = t - t_old
    P = tab[4]
    have_q = False
    _event_values(y, M, ev, out, g_new)
    na = 0
    terminal = False
    for e in range(ev_j.size):
        if not ev_use[e]:
            continue
        up = g[e] <= 0.0 and g_new[e] >= 0.0
        down = g[e] >= 0.0 and g_new[e] <= 0.0
        if (up and ev_dir[e] > 0.0) or (down and ev_dir[e] < 0.0):
            if not have_q:
                _dense_coefficients(K, P, Qd)
                have_q = True
            roots[na] = _brent(e, t_old, t, fs, h, V, Qd, M, ev, out)
            order[na] = e
            terminal = terminal or ev_term[e] != 0
            na += 1
    if terminal:  # sorted by time, cut after the first terminal one (solve_ivp)
        idx = np.argsort(roots[:na], kind="mergesort")
        r2, o2 = roots[:na][idx].copy(), order[:na][idx].copy()
        for k in range(na):
            roots[k], order[k] = r2[k], o2[k]
        for k in range(na):
            if ev_term[order[k]]:
                na = k + 1
                break
    ytmp = V[5]
    for k in range(na):
        e, te = order[k], roots[k]
        r = ns[_NREC]
        _dense(te, t_old, h, y_old, Qd, rec_y[r])
        n = (ytmp.size - N_AUX) // 2
        I, io, F, fo = M[0]
        clearance_kinematics(ev_j[e], rec_y[r][:n], rec_y[r][n:2 * n], I, io, F, fo, out)
        rec_e[r], rec_t[r], rec_d[r], rec_r[r] = e, te, out[5], out[6]
        ns[_NREC] = r + 1
    for e in range(ev_j.size):
        g[e] = g_new[e]
    if terminal:
        t = roots[na - 1]
        _dense(t, t_old, h, y_old, Qd, ytmp)
        fs[_T] = t
        for i in range(y.size):
            y[i] = ytmp[i]
    if ns[_OWN] == 0:
        while ns[_IOUT] < t_out.size and t_out[ns[_IOUT]] <= t:
            if not have_q:
                _dense_coefficients(K, P, Qd)
                have_q = True
            _dense(t_out[ns[_IOUT]], t_old, h, y_old, Qd, y_out[ns[_IOUT]])
            ns[_IOUT] += 1
    else:
        k = ns[_NOWN]
        own_t[k] = t
        for i in range(y.size):
            own_y[k, i] = y[i]
        ns[_NOWN] = k + 1
    return terminal


@njit(cache=True, error_model="numpy")
def advance(fs, ns, V, K, Qd, atol, M, tab, ctl, ev, out, io_bufs):
    """Steps until the run ends (DONE), a window ends (WINDOW: ``fs[_TWIN]`` s or
    ``ns[_NWIN]`` evaluations), a terminal event (TERMINAL), a record buffer is full (FULL) or
    a failure (BUDGET, NONFINITE, SINGULAR, TOO_SMALL)."""
    n_ev = ev[0].size
    rec_cap, own_cap = io_bufs[4].size, io_bufs[2].size
    while True:
        if fs[_T] == fs[_TEND]:
            return DONE
        if fs[_T] >= fs[_TWIN] or ns[_NFEV] >= ns[_NWIN]:
            return WINDOW
        if ns[_NREC] + n_ev > rec_cap or (ns[_OWN] and ns[_NOWN] + 1 > own_cap):
            return FULL
        st = _step(fs, ns, V, K, atol, M, tab, ctl)
        if st != _OK:
            return st
        if _after_step(fs, ns, V, K, Qd, M, tab, ev, out, io_bufs):
            return TERMINAL


# ------------------------------------------------------------------------------ Python driver
def blocks(sysm, k, use=True):
    """The tables of :func:`block_solve` for a system whose kernel solves the whole KKT system
    because of flexible bodies (not with an oil film: that keeps the KKT's exact drive row,
    see :class:`.CompiledSystem`); empty tables otherwise or with ``use`` False."""
    I, io, F, fo = k.tabs
    n, m = k.n, k.m
    full = bool(I[io[20]])
    fb = I[io[19]:io[20]].reshape(-1, 3)
    film = any(cj.viscosity is not None for cj in sysm.clearances)
    if not use or not full or film or not fb.size:
        e = np.zeros(0, np.int64)
        return (np.zeros((0, 2), np.int64), e, e, e, np.zeros((0, 0)), np.zeros((0, 0)),
                np.zeros(0), np.zeros(0, np.int32), np.zeros(3, np.int32), np.zeros((0, 0)),
                np.zeros(0), np.zeros(0), np.zeros(1, np.int64), e)
    mdiag = F[fo[2]:fo[3]]
    blk = np.array([(c0 + 2, 1 + kk) for c0, kk, _ in fb], np.int64).reshape(-1, 2)
    in_block = np.zeros(n, bool)
    for s0, sz in blk:
        in_block[s0:s0 + sz] = True
    singles = np.flatnonzero((mdiag > 0.0) & ~in_block).astype(np.int64)
    massless = np.flatnonzero((mdiag == 0.0) & ~in_block).astype(np.int64)
    a_idx = np.flatnonzero((mdiag > 0.0) | in_block).astype(np.int64)
    nr = massless.size + m
    big = int(blk[:, 1].max())
    # per coordinate the constraint rows touching it (its column of Cq's pattern), or its
    # block's (the union over the block: M_block^-1 mixes them)
    col_ptr, col_rows = I[io[16]:io[17]], I[io[17]:io[18]]
    rows = [set(col_rows[col_ptr[i]:col_ptr[i + 1]].tolist()) for i in range(n)]
    for s0, sz in blk:
        union = set().union(*rows[s0:s0 + sz])
        for i in range(s0, s0 + sz):
            rows[i] = union
    yr_rows = [sorted(r) for r in rows]
    yr_ptr = np.concatenate([[0], np.cumsum([len(r) for r in yr_rows])]).astype(np.int64)
    yr_flat = np.array([c for r in yr_rows for c in r], np.int64)
    return (blk, singles, a_idx, massless, np.zeros((n, m + 1)), np.zeros((nr, nr)),
            np.zeros(nr), np.zeros(nr, np.int32), np.zeros(3, np.int32), np.zeros((big, big)),
            np.zeros(big), np.zeros(big), yr_ptr, yr_flat)


def model(sysm, use_blocks: bool = True) -> tuple:
    """What the compiled right-hand side of the loop reads: the kernel's tables and work
    arrays (:class:`.CompiledSystem`, shared: its impact velocities ``vimp`` are the loop's),
    scratch arrays and the tables of :func:`block_solve` (empty without ``use_blocks``)."""
    k = sysm.kernel()
    nc = len(sysm.clearances)
    return (k.tabs, k._work, k.drv, np.zeros((len(k.drives), 3)), k.vimp, k.gas_py,
            np.empty(k.m), np.empty((k.m, k.n)), np.zeros((nc, _NDIAG)), np.zeros(N_AUX),
            np.empty(k.m), blocks(sysm, k, use_blocks))


def rhs(sysm, t, y, use_blocks: bool = True) -> np.ndarray:
    """The loop's right-hand side at ``(t, y)`` called from Python (tests): ``dy``.

    Raises
    ------
    NumericalError
        When the evaluation fails (non-finite, singular).
    """
    from ...errors import NumericalError

    dy = np.zeros(len(y))
    fs, ns = np.zeros(8), np.zeros(7, np.int64)
    ns[_MAXNFEV] = 1
    code = _fun(float(t), np.ascontiguousarray(y, float), dy, model(sysm, use_blocks), fs, ns)
    if code != _OK:
        raise NumericalError(f"right-hand side failed at t = {t} s (code {code})")
    return dy


def applicable(sysm, method: str) -> bool:
    """True when :func:`run` integrates ``sysm`` with ``method``: RK45 on a system whose whole
    right-hand side is compiled (:attr:`.CompiledSystem.loop_ready`)."""
    if method != "RK45":
        return False
    k = sysm.kernel()
    return k is not None and k.loop_ready


def run(sysm, y0, t_end, t_out, settings, atol, pbar=None, guard=None):
    """Integrate ``sysm`` from ``y0`` (positions, velocities, works) over ``[0, t_end]`` s.

    Parameters
    ----------
    sysm : Multibody
        With :func:`applicable` true.
    y0 : ndarray
        Initial state, ``2 n + N_AUX``.
    t_end : float
        s.
    t_out : ndarray or None
        Output times in ``(0, t_end]``, s, increasing; None: the steps themselves.
    settings : SolverSettings
        ``rtol``, ``max_step``, ``max_rhs_evals``.
    atol : ndarray
        Absolute tolerance per state component.
    pbar : tqdm or None
        Advanced to the simulated time at every return to Python.
    guard : ProjectionGuard or None
        Judged at every return to Python (``guard.check(t, evaluations)``).

    Returns
    -------
    tuple
        ``(t, y, onsets, separations, peaks, nfev, n_steps)``: output times (s), states
        (``(2 n + N_AUX, len(t))``), per clearance joint the onsets ``[(t, rate)]``,
        separations ``[t]`` and deepest penetrations ``[(t, state)]``, evaluations, accepted
        steps (0 with ``t_out``).

    Raises
    ------
    BudgetExceeded, NonFinite, Singular, StepFailed, EventAgain, Overrun
        As the ``solve_ivp`` path (:func:`~.run.integrate.integrate` words them); ``sysm.nfev``
        holds the evaluations spent.
    """
    from ..model.system import BudgetExceeded, NonFinite

    k = sysm.kernel()
    n, nc = sysm.n, len(sysm.clearances)
    ny = 2 * n + N_AUX
    memory = any(cj.needs_memory for cj in sysm.clearances)
    v_impact = np.array([cj.v_impact_min for cj in sysm.clearances], float)
    k.vimp[:] = v_impact
    M = model(sysm)
    y = np.array(y0, float)
    V = tuple(np.zeros(ny) for _ in range(6))
    V[0][:] = y
    K = np.zeros((7, ny))
    Qd = np.zeros((ny, 4))
    fs = np.zeros(8)
    ns = np.zeros(7, np.int64)
    fs[_TEND], fs[_RTOL] = t_end, settings.rtol
    fs[_MAXSTEP] = np.inf if settings.max_step is None else settings.max_step
    ns[_MAXNFEV] = settings.max_rhs_evals
    ne = 3 * nc
    ev_j = np.repeat(np.arange(nc), 3).astype(np.int64)
    ev_kind = np.tile(np.array([ON, OFF, PEAK], np.int64), nc)
    ev_dir = np.tile(np.array([1.0, -1.0, -1.0]), nc)
    ev_use = np.ones(ne, np.int64)
    ev_term = np.where(ev_kind == PEAK, 0, int(memory)).astype(np.int64)
    ev = (ev_j, ev_kind, ev_dir, ev_use, ev_term, np.zeros(ne), np.zeros(ne), np.zeros(ne),
          np.zeros(ne, np.int64))
    out = np.zeros(_NDIAG)
    own = t_out is None
    ns[_OWN] = int(own)
    t_out = np.zeros(0) if own else np.ascontiguousarray(t_out, float)
    y_out = np.zeros((t_out.size, ny))
    io_bufs = (t_out, y_out, np.zeros(_OWN_CAP), np.zeros((_OWN_CAP, ny)),
               np.zeros(_REC_CAP, np.int64), np.zeros(_REC_CAP), np.zeros(_REC_CAP),
               np.zeros(_REC_CAP), np.zeros((_REC_CAP, ny)))
    atol = np.ascontiguousarray(atol, float)
    onsets = [[] for _ in range(nc)]
    separations = [[] for _ in range(nc)]
    peaks = [[] for _ in range(nc)]
    own_t, own_y = [], []
    in_contact = [sysm.gap(j, y[:n]) > 0.0 for j in range(nc)]
    window = t_end / WINDOWS

    def fail(code):
        sysm.nfev = int(ns[_NFEV])
        t_fail = float(fs[_TFAIL])
        if code == BUDGET:
            raise BudgetExceeded(t_fail)
        if code == NONFINITE:
            raise NonFinite(t_fail)
        if code == SINGULAR:
            raise Singular(t_seg)
        raise StepFailed(float(fs[_T]))

    def drain():
        """Records and own steps out of the buffers; returns the fired and grazed events."""
        fired = grazed = None
        for r in range(int(ns[_NREC])):
            e, te = int(io_bufs[4][r]), float(io_bufs[5][r])
            j, kind = int(ev_j[e]), int(ev_kind[e])
            if memory and te <= t_seg:
                if kind != PEAK:
                    grazed = (j, kind)  # fired again where the integration restarted
                continue
            if kind == PEAK:  # also fires at the widest free flight: keep contacts only
                if io_bufs[6][r] > 0.0:
                    peaks[j].append((te, io_bufs[8][r].copy()))
                continue
            if kind == ON:
                onsets[j].append((te, float(io_bufs[7][r])))
            else:
                separations[j].append(te)
            if memory and (fired is None or te < fired[2]):
                fired = (j, kind, te, float(io_bufs[7][r]))
        ns[_NREC] = 0
        if own and ns[_NOWN]:
            c = int(ns[_NOWN])
            own_t.append(io_bufs[2][:c].copy())
            own_y.append(io_bufs[3][:c].T.copy())
            ns[_NOWN] = 0
        return fired, grazed

    def begin():
        for e in range(ne):
            kind = ev_kind[e]
            ev_use[e] = not (memory and kind != PEAK and in_contact[ev_j[e]] == (kind == ON))
        code = start(fs, ns, V, K, atol, M, ev, out, _CONTROL)
        if code != _OK:
            fail(code)

    t_seg, y_seg = 0.0, V[0].copy()
    stalled = 0
    begin()
    while True:
        fs[_TWIN] = fs[_T] + window
        ns[_NWIN] = ns[_NFEV] + EVALS_PER_RETURN
        code = advance(fs, ns, V, K, Qd, atol, M, _TABLEAU, _CONTROL, ev, out, io_bufs)
        fired, grazed = drain()
        t = float(fs[_T])
        if pbar is not None and t > pbar.n:
            pbar.update(t - pbar.n)
        if code >= BUDGET:
            fail(code)
        if guard is not None:
            sysm.nfev = int(ns[_NFEV])
            guard.check(t, int(ns[_NFEV]))
        if code == DONE:
            break
        if code != TERMINAL:
            continue
        if fired is not None:
            j, kind, _te, rate = fired
            in_contact[j] = kind == ON
            if kind == ON:
                v_impact[j] = max(rate, sysm.clearances[j].v_impact_min)
                k.vimp[:] = v_impact
            stalled = 0
        elif grazed is not None and stalled < 4:
            # a graze: the contact that began at the restart point ended there too (or the
            # reverse); the joint takes the state the event says and the integration goes on
            # from the same point
            j, kind = grazed
            in_contact[j] = kind == ON
            stalled += 1
            fs[_T] = t_seg
            V[0][:] = y_seg
        else:
            sysm.nfev = int(ns[_NFEV])
            raise EventAgain(t_seg)
        t_seg, y_seg = float(fs[_T]), V[0].copy()
        begin()
    sysm.nfev = int(ns[_NFEV])
    if own:
        tt = np.concatenate(own_t) if own_t else np.zeros(0)
        yy = np.concatenate(own_y, axis=1) if own_y else np.zeros((ny, 0))
        n_steps = tt.size
    else:
        tt, yy, n_steps = t_out, y_out.T.copy(), 0
    return tt, yy, onsets, separations, peaks, int(ns[_NFEV]), n_steps


def _flush_if_dependencies_changed() -> bool:
    """This module's cached loop calls :mod:`.compiled` and what it calls (numba issue #1833)."""
    from ..laws import lubrication, reynolds
    from ..model import clearance, joints
    from . import compiled

    return flush_if_changed(globals(), __name__,
                            (compiled, clearance, lubrication, reynolds, joints))


_flush_if_dependencies_changed()
