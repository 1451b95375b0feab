"""The right-hand side of an all-rigid system compiled with Numba.

For a system of rigid bodies joined by pins, sliders and angle drives, with round dry clearance
joints (any law of :mod:`.laws`), piston loads (gas force and ring friction) and crank torques,
:class:`CompiledSystem` evaluates what :meth:`Multibody.solve` and :meth:`Multibody.rhs` evaluate
in two Numba-compiled calls (``cache=True``: compiled once per machine, ~10-20 s, then loaded in
~0.6 s) around NumPy's LAPACK solve: :func:`assemble` (frame table, applied and contact forces,
constraint terms, and the KKT system reduced by the diagonal rigid-body mass matrix to the
multipliers and the massless coordinates) and :func:`finish` (accelerations, multipliers,
powers). The Python path costs ~0.25 ms per evaluation in some hundred small NumPy calls; this
one ~0.02 ms (four-star with one clearance joint).

The formulas are those of :mod:`.system`, :mod:`.fastpath`, :mod:`.clearance`, :mod:`.contact`
and :mod:`.loads`, written out per scalar; the results agree to round-off (the tests compare
both paths state by state). The system is read once, when the compiled form is built: changing
a joint's parameters afterwards is not seen. The impact velocities of restitution laws are
the integrator's state, passed at every call.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg.lapack import dgesv as _gesv

from .bodies import Ground, RigidBody
from .clearance import ClearanceJoint
from .loads import CrankTorque, PistonLoads

#: per clearance joint diagnostics written by the kernel (columns of ``diag``)
DIAG = ("ex", "ey", "nx", "ny", "d", "delta", "delta_dot", "v_slip", "fn", "ft", "fx", "fy",
        "v_elastic", "p_damp", "p_fric", "fel", "vrx", "vry", "omega_sum")
_D = {k: i for i, k in enumerate(DIAG)}
_S_CAP = 3.0


def applicable(sysm) -> bool:
    """True when every part of ``sysm`` has a compiled form (see the module docstring)."""
    from . import fastpath

    if sysm._table is None or not fastpath.applicable(sysm):
        return False
    for cj in sysm.clearances:
        if type(cj) is not ClearanceJoint or cj.clearance_major is not None \
                or cj.viscosity is not None:
            return False
        if not all(isinstance(b, (RigidBody, Ground)) for b in (cj.journal, cj.bearing)):
            return False
    for ld in sysm.loads:
        if type(ld) not in (PistonLoads, CrankTorque):
            return False
        if not isinstance(getattr(ld, "piston", ld.crank), RigidBody) \
                or not isinstance(ld.crank, RigidBody):
            return False
    return True


# ---------------------------------------------------------------------------------- scalar laws
@njit(cache=True)
def _johnson_x(delta, dR):
    """``x = F / K`` of Johnson's conformal-cylinder law at penetration ``delta`` (> 0)."""
    A = 4.0 * dR
    x_cap = A * np.exp(-_S_CAP)
    d_cap = x_cap * (_S_CAP - 1.0)
    if delta > d_cap:
        return x_cap + (delta - d_cap)
    L = np.log(A / delta)
    s = max(L + np.log(max(L - 1.0, 1.0)), _S_CAP)
    for _ in range(12):
        h = s - L - np.log(s - 1.0)
        s = max(s - h / (1.0 - 1.0 / (s - 1.0)), 2.0 + 1e-9)
    return delta / (s - 1.0)


@njit(cache=True)
def _chi(code, e, v):
    if code == 4:
        return 1.5 * (1.0 - e) / v
    if code == 6:
        return 1.6 * (1.0 - e) / (e * v)
    return 0.75 * (1.0 - e * e) / v  # lankarani_nikravesh, johnson_cylinder


@njit(cache=True)
def normal_force(code, p, delta, ddot, vimp):
    """Normal force of law ``code`` (:mod:`.laws`) with ``p = law.vector()``; ``delta > 0``."""
    K, n = p[0], p[1]
    if code == 0:
        f = K * delta**n
    elif code == 1:
        f = K * delta + p[2] * ddot
    elif code == 2:
        f = K * delta**n + p[2] * ddot
    elif code == 3:
        s = min(max(delta / p[3], 0.0), 1.0)
        f = K * delta**n + p[2] * (s * s * (3.0 - 2.0 * s)) * ddot
    elif code == 7:
        f = K * _johnson_x(delta, p[4]) * (1.0 + _chi(code, p[3], vimp) * ddot)
    else:
        f = K * delta**n * (1.0 + _chi(code, p[3], vimp) * ddot)
    return max(f, 0.0)


@njit(cache=True)
def elastic_force(code, p, delta):
    if code == 1:
        return p[0] * delta
    if code == 7:
        return p[0] * _johnson_x(delta, p[4])
    return p[0] * delta ** p[1]


@njit(cache=True)
def elastic_energy(code, p, delta):
    if code == 1:
        return p[0] * delta**2 / 2.0
    if code == 7:
        A = 4.0 * p[4]
        x = _johnson_x(delta, p[4])
        x_cap = A * np.exp(-_S_CAP)
        xs = min(x, x_cap)
        w = 0.5 * xs * xs * (np.log(A / xs) - 1.5)
        over = max(x - x_cap, 0.0)
        return p[0] * (w + x_cap * over + 0.5 * over * over)
    n = p[1]
    return p[0] * delta ** (n + 1.0) / (n + 1.0)


@njit(cache=True)
def _step(x, x0, h0, x1, h1):
    s = min(max((x - x0) / (x1 - x0), 0.0), 1.0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


@njit(cache=True)
def friction_coefficient(code, p, v):
    """Signed friction coefficient of law ``code`` with ``p = law.vector()``."""
    if code == 0:
        return 0.0
    a = abs(v)
    if code == 1:
        if a < p[2]:
            mu = _step(a, 0.0, 0.0, p[2], p[0])
        else:
            mu = _step(a, p[2], p[0], p[3], p[1])
    else:
        mu = p[1] * min(max((a - p[2]) / (p[3] - p[2]), 0.0), 1.0)
    return np.sign(v) * mu


# ---------------------------------------------------------------------------------- the kernel
@njit(cache=True)
def _frames(q, qd, fi, floc, gpose, pose, arm, bias, vel):
    kr = fi.size
    for k in range(kr):
        i = fi[k]
        th = q[i + 2]
        c, s = np.cos(th), np.sin(th)
        ax = c * floc[k, 0] - s * floc[k, 1]
        ay = s * floc[k, 0] + c * floc[k, 1]
        pose[k, 0] = q[i] + ax
        pose[k, 1] = q[i + 1] + ay
        pose[k, 2] = th + floc[k, 2]
        arm[k, 0] = ax
        arm[k, 1] = ay
        w = qd[i + 2]
        bias[k, 0] = -w * w * ax
        bias[k, 1] = -w * w * ay
        bias[k, 2] = 0.0
        vel[k, 0] = qd[i] - ay * w
        vel[k, 1] = qd[i + 1] + ax * w
        vel[k, 2] = w
    for g in range(gpose.shape[0]):
        k = kr + g
        for j in range(3):
            pose[k, j] = gpose[g, j]
            bias[k, j] = 0.0
            vel[k, j] = 0.0
        arm[k, 0] = 0.0
        arm[k, 1] = 0.0


@njit(cache=True)
def _add_force(Q, fcol, arm, k, fx, fy, mz):
    i = fcol[k]
    if i >= 0:
        Q[i] += fx
        Q[i + 1] += fy
        Q[i + 2] += -arm[k, 1] * fx + arm[k, 0] * fy + mz


@njit(cache=True)
def _clearance(j, pose, vel, cl_int, cl_f, out):
    """Kinematics of clearance joint ``j`` into ``out`` (a row of ``diag``)."""
    kj, kb = cl_int[j, 0], cl_int[j, 1]
    ex = pose[kj, 0] - pose[kb, 0]
    ey = pose[kj, 1] - pose[kb, 1]
    d = np.hypot(ex, ey)
    if d > 1e-300:
        nx, ny = ex / d, ey / d
    else:
        nx, ny = 1.0, 0.0
    vrx = vel[kj, 0] - vel[kb, 0]
    vry = vel[kj, 1] - vel[kb, 1]
    c, rj = cl_f[j, 0], cl_f[j, 1]
    out[0], out[1], out[2], out[3], out[4] = ex, ey, nx, ny, d
    out[5] = d - c
    out[6] = nx * vrx + ny * vry
    out[7] = -ny * vrx + nx * vry + rj * vel[kj, 2] - (rj + c) * vel[kb, 2]
    out[16], out[17] = vrx, vry
    out[18] = vel[kj, 2] + vel[kb, 2]


#: order of the integer tables packed into ``I`` (see :meth:`CompiledSystem._pack`)
INT_TABLES = ("fi", "fcol", "rev_rows", "rev_a", "rev_b", "side_rows", "side_k", "side_col",
              "pri_rows", "pri_k", "pri_col", "drive_rows", "drive_k", "cl_int", "pl_int",
              "gas_off", "tq_k", "is_drive", "col_ptr", "col_rows", "massless")
#: order of the float tables packed into ``F``
FLOAT_TABLES = ("floc", "gpose", "mdiag", "Q0", "Cq0", "side_sign", "pri_n", "pri_o", "pri_ang",
                "cl_f", "law_vec", "fric_vec", "pl_f", "gas_x", "gas_f", "gas_period", "tq_val",
                "baumgarte")


@njit(cache=True)
def _seg(a, o, i):
    return a[o[i]:o[i + 1]]


@njit(cache=True)
def assemble(t, q, qd, dv, vimp, gas_py, I, io, F, fo, phi, Cq, diag, powers, Q, cqd, A, rhs):
    """Everything up to the linear solve: the applied and contact forces ``Q``, constraint values
    ``phi`` and Jacobian ``Cq``, ``cqd = Cq qd``, clearance diagnostics ``diag`` (rows of
    :data:`DIAG`), ``powers[1:]`` = (loads, -, contact damping, friction) and the reduced system
    ``A x = rhs`` (see the comment below; :func:`finish` takes its solution), written in place.

    ``dv``: per drive (angle, speed, acceleration) at ``t``; ``vimp``: per clearance joint its
    impact velocity; ``gas_py``: gas forces of pistons without a table; ``I, io, F, fo``: the
    packed tables (:data:`INT_TABLES`, :data:`FLOAT_TABLES`).
    """
    n = q.size
    m = phi.size
    fi, fcol = _seg(I, io, 0), _seg(I, io, 1)
    rev_rows, rev_a, rev_b = _seg(I, io, 2), _seg(I, io, 3), _seg(I, io, 4)
    side_rows, side_k, side_col = _seg(I, io, 5), _seg(I, io, 6), _seg(I, io, 7)
    pri_rows, pri_k, pri_col = _seg(I, io, 8), _seg(I, io, 9), _seg(I, io, 10)
    drive_rows, drive_k = _seg(I, io, 11), _seg(I, io, 12)
    cl_int, pl_int = _seg(I, io, 13).reshape((-1, 4)), _seg(I, io, 14).reshape((-1, 3))
    gas_off, tq_k = _seg(I, io, 15), _seg(I, io, 16)
    col_ptr, col_rows, massless = _seg(I, io, 18), _seg(I, io, 19), _seg(I, io, 20)
    floc, gpose = _seg(F, fo, 0).reshape((-1, 3)), _seg(F, fo, 1).reshape((-1, 3))
    mdiag, Q0, Cq0 = _seg(F, fo, 2), _seg(F, fo, 3), _seg(F, fo, 4).reshape((m, n))
    side_sign, pri_n = _seg(F, fo, 5), _seg(F, fo, 6).reshape((-1, 2))
    pri_o, pri_ang = _seg(F, fo, 7).reshape((-1, 2)), _seg(F, fo, 8)
    cl_f, law_vec = _seg(F, fo, 9).reshape((-1, 3)), _seg(F, fo, 10).reshape((-1, 5))
    fric_vec, pl_f = _seg(F, fo, 11).reshape((-1, 4)), _seg(F, fo, 12).reshape((-1, 6))
    gas_x, gas_f, gas_period = _seg(F, fo, 13), _seg(F, fo, 14), _seg(F, fo, 15)
    tq_val, baumgarte = _seg(F, fo, 16), F[fo[17]]
    K = fcol.size
    pose = np.empty((K, 3))
    arm = np.empty((K, 2))
    bias = np.empty((K, 3))
    vel = np.empty((K, 3))
    _frames(q, qd, fi, floc, gpose, pose, arm, bias, vel)
    Q[:] = Q0
    # clearance joints (clearance.ClearanceJoint.forces, round dry bore)
    p_damp = 0.0
    p_fric = 0.0
    for j in range(cl_int.shape[0]):
        row = diag[j]
        _clearance(j, pose, vel, cl_int, cl_f, row)
        delta, ddot = row[5], row[6]
        fn = fel = mu = 0.0
        code = cl_int[j, 2]
        if delta > 0.0:
            fn = normal_force(code, law_vec[j], delta, ddot, max(vimp[j], cl_f[j, 2]))
            fel = elastic_force(code, law_vec[j], delta)
            mu = friction_coefficient(cl_int[j, 3], fric_vec[j], row[7])
        ft = -mu * fn
        nx, ny = row[2], row[3]
        fx = -fn * nx + ft * -ny
        fy = -fn * ny + ft * nx
        if fn != 0.0:
            rj, c = cl_f[j, 1], cl_f[j, 0]
            _add_force(Q, fcol, arm, cl_int[j, 0], fx, fy, rj * ft)
            _add_force(Q, fcol, arm, cl_int[j, 1], -fx, -fy, -(rj + c) * ft)
        row[8], row[9], row[10], row[11] = fn, ft, fx, fy
        row[12] = elastic_energy(code, law_vec[j], delta) if delta > 0.0 else 0.0
        row[13] = (fn - fel) * ddot
        row[14] = -ft * row[7]
        row[15] = fel
        p_damp += row[13]
        p_fric += row[14]
    # piston loads (loads.PistonLoads) and crank torques (loads.CrankTorque)
    p_loads = 0.0
    for i in range(pl_int.shape[0]):
        kp, kc, tab = pl_int[i, 0], pl_int[i, 1], pl_int[i, 2]
        a0, a1 = pl_f[i, 0], pl_f[i, 1]
        v = a0 * vel[kp, 0] + a1 * vel[kp, 1]
        f = 0.0
        if tab >= 0:
            x = pl_f[i, 5] * (pose[kc, 2] - pl_f[i, 2]) % gas_period[tab]
            f -= np.interp(x, gas_x[gas_off[tab]:gas_off[tab + 1]],
                           gas_f[gas_off[tab]:gas_off[tab + 1]])
        elif tab == -1:
            f -= gas_py[i]
        if pl_f[i, 3] > 0.0:
            f -= pl_f[i, 3] * np.tanh(v / pl_f[i, 4])
        if f != 0.0:
            _add_force(Q, fcol, arm, kp, f * a0, f * a1, 0.0)
        p_loads += f * v
    for i in range(tq_k.size):
        _add_force(Q, fcol, arm, tq_k[i], 0.0, 0.0, tq_val[i])
        p_loads += tq_val[i] * vel[tq_k[i], 2]
    # constraint terms (fastpath.RigidConstraintTable.terms)
    nu = np.zeros(m)
    gamma = np.zeros(m)
    Cq[:, :] = Cq0
    for r_i in range(rev_rows.size):
        r, a, b = rev_rows[r_i], rev_a[r_i], rev_b[r_i]
        phi[r] = pose[a, 0] - pose[b, 0]
        phi[r + 1] = pose[a, 1] - pose[b, 1]
        gamma[r] = -(bias[a, 0] - bias[b, 0])
        gamma[r + 1] = -(bias[a, 1] - bias[b, 1])
    for s_i in range(side_rows.size):
        r, k, s = side_rows[s_i], side_k[s_i], side_sign[s_i]
        Cq[r, side_col[s_i]] = -s * arm[k, 1]
        Cq[r + 1, side_col[s_i]] = s * arm[k, 0]
    for p_i in range(pri_rows.size):
        r, k = pri_rows[p_i], pri_k[p_i]
        n0, n1 = pri_n[p_i, 0], pri_n[p_i, 1]
        phi[r] = n0 * (pose[k, 0] - pri_o[p_i, 0]) + n1 * (pose[k, 1] - pri_o[p_i, 1])
        phi[r + 1] = pose[k, 2] - pri_ang[p_i]
        Cq[r, pri_col[p_i]] = -n0 * arm[k, 1] + n1 * arm[k, 0]
        gamma[r] = -(n0 * bias[k, 0] + n1 * bias[k, 1])
    for d_i in range(drive_rows.size):
        r, k = drive_rows[d_i], drive_k[d_i]
        phi[r] = pose[k, 2] - dv[d_i, 0]
        nu[r] = dv[d_i, 1]
        gamma[r] = dv[d_i, 2]
    # M qdd + Cq^T lam = Q, Cq qdd = gamma - 2 a phidot - a^2 phi = c with the diagonal M of
    # rigid bodies: the massive coordinates (a) eliminated, qdd_a = M_a^-1 (Q_a - Cq_a^T lam),
    # leaves for the massless ones (b, e.g. a piston's rotation) and lam
    #   [ 0     Cq_b^T              ] [ qdd_b ]   [ Q_b                    ]
    #   [ Cq_b  -Cq_a M_a^-1 Cq_a^T ] [ lam   ] = [ c - Cq_a M_a^-1 Q_a    ]
    # summed over the few rows each column of Cq touches (col_ptr, col_rows: its pattern)
    nb = massless.size
    A[:, :] = 0.0
    for r in range(m):
        acc = 0.0
        for i in range(n):
            acc += Cq[r, i] * qd[i]
        cqd[r] = acc
        rhs[nb + r] = gamma[r] - 2.0 * baumgarte * (acc - nu[r]) - baumgarte * baumgarte * phi[r]
    for i in range(n):
        if mdiag[i] == 0.0:
            continue
        mi = 1.0 / mdiag[i]
        qi = Q[i] * mi
        for a_i in range(col_ptr[i], col_ptr[i + 1]):
            ra = col_rows[a_i]
            ca = Cq[ra, i] * mi
            rhs[nb + ra] -= Cq[ra, i] * qi
            for b_i in range(col_ptr[i], col_ptr[i + 1]):
                rb = col_rows[b_i]
                A[nb + ra, nb + rb] -= ca * Cq[rb, i]
    for b_k in range(nb):
        i = massless[b_k]
        rhs[b_k] = Q[i]
        for a_i in range(col_ptr[i], col_ptr[i + 1]):
            r = col_rows[a_i]
            A[b_k, nb + r] = Cq[r, i]
            A[nb + r, b_k] = Cq[r, i]
    powers[1] = p_loads
    powers[3] = p_damp
    powers[4] = p_fric


@njit(cache=True)
def finish(sol, Q, Cq, cqd, I, io, F, fo, qdd, lam, powers):
    """Accelerations ``qdd``, multipliers ``lam`` and ``powers[0]``, ``powers[2]`` (drive, ideal
    joints) from the solution ``sol`` of :func:`assemble`'s system. Returns False on a
    non-finite result."""
    n, m = qdd.size, lam.size
    is_drive, col_ptr = _seg(I, io, 17), _seg(I, io, 18)
    col_rows, massless = _seg(I, io, 19), _seg(I, io, 20)
    mdiag = _seg(F, fo, 2)
    nb = massless.size
    for b_k in range(nb):
        qdd[massless[b_k]] = sol[b_k]
    for i in range(n):
        if mdiag[i] == 0.0:
            continue
        acc = Q[i]
        for a_i in range(col_ptr[i], col_ptr[i + 1]):
            acc -= Cq[col_rows[a_i], i] * sol[nb + col_rows[a_i]]
        qdd[i] = acc / mdiag[i]
    p_drive = 0.0
    p_all = 0.0
    for r in range(m):
        lam[r] = sol[nb + r]
        p = -lam[r] * cqd[r]
        p_all += p
        if is_drive[r]:
            p_drive += p
    powers[0] = p_drive
    powers[2] = p_all - p_drive
    ok = np.isfinite(p_all + powers[1] + powers[3] + powers[4])
    for i in range(n):
        ok = ok and np.isfinite(qdd[i])
    return ok


@njit(cache=True)
def clearance_kinematics(j, q, qd, I, io, F, fo, out):
    """Penetration (``out[5]``) and its rate (``out[6]``) of clearance joint ``j`` only."""
    fi, fcol = _seg(I, io, 0), _seg(I, io, 1)
    floc, gpose = _seg(F, fo, 0).reshape((-1, 3)), _seg(F, fo, 1).reshape((-1, 3))
    cl_int, cl_f = _seg(I, io, 13).reshape((-1, 4)), _seg(F, fo, 9).reshape((-1, 3))
    K = fcol.size
    pose = np.empty((K, 3))
    arm = np.empty((K, 2))
    bias = np.empty((K, 3))
    vel = np.empty((K, 3))
    _frames(q, qd, fi, floc, gpose, pose, arm, bias, vel)
    _clearance(j, pose, vel, cl_int, cl_f, out)


class CompiledSystem:
    """The tables of one :class:`~.system.Multibody` for :func:`assemble` and :func:`finish`."""

    def __init__(self, sysm):
        tab = sysm._table
        self.sysm = sysm
        self.n, self.m = sysm.n, sysm.m
        index = dict(tab.index)
        k_rigid = len(sysm._fi)
        gpose = [np.asarray(p, float) for p in tab.ground_pose]

        def key(body, frame):
            kk = (id(body), frame)
            if kk not in index:
                if not isinstance(body, Ground):
                    raise KeyError(f"frame {frame!r} of {body.name!r} is not registered")
                index[kk] = k_rigid + len(gpose)
                gpose.append(body.frame_pose(None, frame))
            return index[kk]

        cl_int, cl_f, law_vec, fric_vec = [], [], [], []
        for cj in sysm.clearances:
            cl_int.append((key(cj.journal, cj.journal_frame), key(cj.bearing, cj.bearing_frame),
                           cj.normal.code, cj.friction_law.code))
            cl_f.append((cj.clearance, cj.journal_radius, cj.v_impact_min))
            law_vec.append(cj.normal.vector())
            fric_vec.append(cj.friction_law.vector())
        pl_int, pl_f, gx, gf, off, period = [], [], [], [], [0], []
        self._py_gas = []
        tables = {}
        tq_k, tq_val = [], []
        for i, ld in enumerate(ld for ld in sysm.loads if type(ld) is PistonLoads):
            kp, kc = key(ld.piston, ld.frame), key(ld.crank, ld.crank_frame)
            tab_i = -2
            if ld.gas_force is not None:
                table = getattr(ld.gas_force, "table", None)
                if table is None:
                    tab_i = -1
                    self._py_gas.append((i, ld))
                else:
                    tid = id(ld.gas_force)
                    if tid not in tables:
                        tables[tid] = len(period)
                        xe, fe, per = table
                        gx.append(np.asarray(xe, float))
                        gf.append(np.asarray(fe, float))
                        off.append(off[-1] + len(xe))
                        period.append(float(per))
                    tab_i = tables[tid]
            pl_int.append((kp, kc, tab_i))
            pl_f.append((ld.axis[0], ld.axis[1], ld.tdc_angle, ld.friction_force,
                         ld.friction_velocity, float(ld.sense)))
        for ld in sysm.loads:
            if type(ld) is CrankTorque:
                tq_k.append(key(ld.crank, ld.frame))
                tq_val.append(ld.torque)
        fi = np.asarray(sysm._fi, np.int64)
        mdiag = np.zeros(self.n)
        Q0 = np.zeros(self.n)
        for b in sysm.bodies:
            s = sysm.slices[id(b)]
            M = b.mass_matrix(np.zeros(b.ndof))
            if np.count_nonzero(M - np.diag(np.diag(M))):
                raise ValueError("the compiled path needs diagonal rigid-body mass matrices")
            mdiag[s] = np.diag(M)
            Q0[s] = b.gravity_force(np.zeros(b.ndof), sysm.gravity) \
                + b.velocity_forces(np.zeros(b.ndof), np.zeros(b.ndof))
        # sparsity pattern of Cq by column: Cq0's entries and the rotation columns set per call
        pattern = tab.Cq0 != 0.0
        pattern[tab.side_rows, tab.side_col] = pattern[tab.side_rows + 1, tab.side_col] = True
        pattern[tab.pri_rows, tab.pri_col] = True
        col_rows = [np.flatnonzero(pattern[:, i]) for i in range(self.n)]
        col_ptr = np.concatenate([[0], np.cumsum([len(r) for r in col_rows])])
        nc, npl = len(sysm.clearances), len(pl_int)
        self.drives = tab.drives
        self.clearances = sysm.clearances
        ints = {"fi": fi, "fcol": np.concatenate([fi, -np.ones(len(gpose), np.int64)]),
                "rev_rows": tab.rev_rows, "rev_a": tab.rev_a, "rev_b": tab.rev_b,
                "side_rows": tab.side_rows, "side_k": tab.side_k, "side_col": tab.side_col,
                "pri_rows": tab.pri_rows, "pri_k": tab.pri_k, "pri_col": tab.pri_col,
                "drive_rows": [d[0] for d in tab.drives], "drive_k": [d[1] for d in tab.drives],
                "cl_int": cl_int, "pl_int": pl_int, "gas_off": off, "tq_k": tq_k,
                "is_drive": sysm._drive_rows, "col_ptr": col_ptr,
                "col_rows": np.concatenate(col_rows) if col_rows else [],
                "massless": np.flatnonzero(mdiag == 0.0)}
        floats = {"floc": sysm._floc, "gpose": gpose, "mdiag": mdiag, "Q0": Q0,
                  "Cq0": tab.Cq0, "side_sign": tab.side_sign, "pri_n": tab.pri_n,
                  "pri_o": tab.pri_o, "pri_ang": tab.pri_ang, "cl_f": cl_f, "law_vec": law_vec,
                  "fric_vec": fric_vec, "pl_f": pl_f, "gas_x": gx, "gas_f": gf,
                  "gas_period": period, "tq_val": tq_val, "baumgarte": [sysm.baumgarte]}
        self.I, self.io = _pack([ints[k] for k in INT_TABLES], np.int64)
        self.F, self.fo = _pack([floats[k] for k in FLOAT_TABLES], float)
        self.gas_py = np.zeros(npl)
        self.vimp = np.zeros(nc)
        self._diag = np.zeros((nc, len(DIAG)))
        self._kin = np.zeros(len(DIAG))
        self._zeros = np.zeros(self.n)
        # for solve's per-joint diagnostics
        self._cl_frames = [(int(a[0]), int(a[1])) for a in
                           self._table("cl_int").reshape(-1, 4)]
        self._fcol = [int(i) for i in self._table("fcol")]
        f = FLOAT_TABLES.index("floc")
        self._floc = self.F[self.fo[f]:self.fo[f + 1]].reshape(-1, 3).copy()
        self._scratch = (np.empty(self.m), np.empty(self.m), np.empty((self.m, self.n)),
                         np.zeros(5))
        nb = int(np.count_nonzero(mdiag == 0.0))
        self._work = (np.empty(self.n), np.empty(self.m), np.zeros((nb + self.m, nb + self.m)),
                      np.empty(nb + self.m))

    def _call(self, t, q, qd, qdd, lam, phi, Cq, diag, powers, v_impact=None):
        # one compiled specialisation: contiguous float arrays (a column of a history is not)
        q, qd = np.ascontiguousarray(q, float), np.ascontiguousarray(qd, float)
        dv = np.empty((len(self.drives), 3))
        for i, (_, _, prof) in enumerate(self.drives):
            dv[i, 0], dv[i, 1], dv[i, 2] = prof.angle(t), prof.speed(t), prof.acceleration(t)
        if v_impact is None:
            for j, cj in enumerate(self.clearances):
                self.vimp[j] = cj.v_impact
        else:
            self.vimp[:] = v_impact
        for i, ld in self._py_gas:
            th = self.sysm.frame_pose_only(ld.crank, ld.crank_frame, q)[2]
            self.gas_py[i] = ld.gas_force(ld.sense * (th - ld.tdc_angle))
        Q, cqd, A, rhs = self._work
        assemble(t, q, qd, dv, self.vimp, self.gas_py, self.I, self.io, self.F, self.fo, phi, Cq,
                 diag, powers, Q, cqd, A, rhs)
        # LAPACK gesv (as np.linalg.solve on the Python path) through SciPy's thin wrapper, in
        # place: compiling np.linalg.solve would cost 10 s more at the first run, and NumPy's
        # own wrapper twice the time of this call. A is symmetric, so its transpose is the
        # Fortran-ordered A that gesv overwrites without a copy.
        if rhs.size:
            _, _, sol, info = _gesv(A.T, rhs, overwrite_a=True, overwrite_b=True)
            if info > 0:
                raise np.linalg.LinAlgError("Singular matrix")
        else:  # no constraints and every coordinate with mass: nothing to solve
            sol = rhs
        return finish(sol, Q, Cq, cqd, self.I, self.io, self.F, self.fo, qdd, lam, powers)

    def rhs(self, t, y, v_impact=None):
        """``dy`` of :meth:`Multibody.rhs` (its modal damping power 0); None if not finite."""
        n = self.n
        dy = np.zeros(y.size)
        q, qd = y[:n], y[n:2 * n]
        dy[:n] = qd
        lam, phi, Cq, powers = self._scratch
        ok = self._call(t, q, qd, dy[n:2 * n], lam, phi, Cq, self._diag, powers, v_impact)
        dy[2 * n: 2 * n + 5] = powers
        return dy if ok else None

    def solve(self, t, q, qd, v_impact=None) -> dict:
        """What :meth:`Multibody.solve` returns."""
        n, m = self.n, self.m
        qdd, lam, phi, Cq = np.empty(n), np.empty(m), np.empty(m), np.empty((m, n))
        diag = np.zeros_like(self._diag)
        powers = np.zeros(5)
        self._call(t, q, qd, qdd, lam, phi, Cq, diag, powers, v_impact)
        nu = np.zeros(m)
        for r, _, prof in self.drives:
            nu[r] = prof.speed(t)
        contacts = []
        for j, cj in enumerate(self.clearances):
            row = diag[j]
            nx, ny = row[_D["nx"]], row[_D["ny"]]
            kj, kb = self._frames_of(j)
            contacts.append({
                "e": row[0:2].copy(), "n": np.array([nx, ny]), "t": np.array([-ny, nx]),
                "grad": np.array([nx, ny]), "dtheta": 0.0, "delta": float(row[_D["delta"]]),
                "delta_dot": float(row[_D["delta_dot"]]), "v_slip": float(row[_D["v_slip"]]),
                "Jj": self._jac(kj, q), "Jb": self._jac(kb, q),
                "r_b": cj.journal_radius + cj.clearance, "d": float(row[_D["d"]]),
                "vrel": row[16:18].copy(), "omega_sum": float(row[_D["omega_sum"]]),
                "fn": float(row[_D["fn"]]), "ft": float(row[_D["ft"]]), "force": row[10:12].copy(),
                "film": 0.0, "p_damp": float(row[_D["p_damp"]]),
                "p_fric": float(row[_D["p_fric"]]), "v_elastic": float(row[_D["v_elastic"]])})
        return {"qdd": qdd, "lam": lam, "phi": phi, "Cq": Cq, "nu": nu, "contacts": contacts,
                "p_loads": float(powers[1])}

    def _table(self, name):
        k = INT_TABLES.index(name)
        return self.I[self.io[k]:self.io[k + 1]]

    def _frames_of(self, j):
        return self._cl_frames[j]

    def _jac(self, k, q):
        i = self._fcol[k]
        if i < 0:
            return np.zeros((3, 0))
        floc = self._floc
        th = q[i + 2]
        c, s = np.cos(th), np.sin(th)
        ax = c * floc[k, 0] - s * floc[k, 1]
        ay = s * floc[k, 0] + c * floc[k, 1]
        return np.array([[1.0, 0.0, -ay], [0.0, 1.0, ax], [0.0, 0.0, 1.0]])

    def penetration(self, j, q, qd=None):
        """``(delta, delta_dot)`` of clearance joint ``j`` (``delta_dot`` 0 without ``qd``)."""
        out = self._kin
        q = np.ascontiguousarray(q, float)
        qd = self._zeros if qd is None else np.ascontiguousarray(qd, float)
        clearance_kinematics(j, q, qd, self.I, self.io, self.F, self.fo, out)
        return out[5], out[6]


def _pack(arrays, dtype):
    """One flat array of ``arrays`` (each flattened) and the offsets of each."""
    flat = [np.asarray(a, dtype).ravel() for a in arrays]
    offsets = np.concatenate([[0], np.cumsum([a.size for a in flat])]).astype(np.int64)
    return (np.concatenate(flat) if flat else np.zeros(0, dtype)), offsets
