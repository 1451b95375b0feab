"""The right-hand side of a planar multibody system compiled with Numba.

For a system of rigid and planar flexible (floating-frame, modal) bodies joined by pins, sliders
and angle drives, with clearance joints (round or worn elliptical bores, dry or with the
short-bearing or the finite-length oil film; any law of :mod:`.laws`), piston loads (gas force and ring friction),
crank torques and torsional couplings, :class:`CompiledSystem` evaluates what
:meth:`Multibody.solve` and :meth:`Multibody.rhs` evaluate in two Numba-compiled calls
(``cache=True``: compiled once per machine, ~20 s, then loaded in ~1 s) around LAPACK's solve:
:func:`assemble` (frame table, flexible-body terms, applied and contact forces, constraint terms
and the linear system) and :func:`finish` (accelerations, multipliers, powers). An all-rigid
system without an oil film has its diagonal mass matrix eliminated first (the system left is the multipliers' and the
massless coordinates'); with a flexible body, whose ``M(ξ)`` is full in its (θ, ξ) block, the
whole KKT system is solved. The Python path costs ~0.25 ms (rigid four-star with one clearance
joint) to ~1 ms (flexible) per evaluation in some hundred small NumPy calls; this one ~0.02 ms
(rigid) to ~0.05 ms (flexible crank with 20 modes and rod with 14).

The formulas are those of :mod:`.system`, :mod:`.flexible`, :mod:`.clearance`,
:mod:`.contact` and :mod:`.loads`, written out per scalar; the results agree to round-off (the
tests compare both paths state by state). The worn bore's clearance
(:func:`.clearance.worn_bore_clearance`) and the short-bearing film
(:func:`.lubrication.film_arguments`, :func:`.lubrication.short_film`) are not copied: they are
Numba functions that the Python path calls too. Numba's cache does not see a change in a
function of another module that a cached function calls (numba issue #1833): a stamp of those
two modules beside the cache flushes this module's cached functions when they change
(:func:`_flush_if_dependencies_changed`, run at import). The system is read once, when the compiled form is
built: changing a joint's parameters afterwards is not seen. The impact velocities of
restitution laws are the integrator's state, passed at every call.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types

from ..flexible.body import FlexibleBody
from ..laws.lubrication import film_arguments, short_film
from ..laws.reynolds import film_spline, finite_film
from ..model.bodies import Ground, RigidBody
from ..model.clearance import ClearanceJoint, worn_bore_clearance
from ..model.joints import AngleDrive, Prismatic, Revolute, SpeedProfile, frames_of, speed_profile
from ..model.loads import CrankTorque, PistonLoads, TorsionalCoupling


def _lapack_symbol(name: str) -> str:
    """Register LAPACK's ``name`` (SciPy's ``cython_lapack``) with LLVM under a fixed symbol and
    return it: compiled code calls it by that symbol, resolved when the code is loaded, so the
    on-disk cache holds no process-specific address (a ctypes pointer would defeat it)."""
    import llvmlite.binding as llvm
    from numba.extending import get_cython_function_address

    symbol = f"crankmodal_{name}"
    llvm.add_symbol(symbol, get_cython_function_address("scipy.linalg.cython_lapack", name))
    return symbol


_I32P, _F64P = types.CPointer(types.int32), types.CPointer(types.float64)
#: LAPACK dgesv(n, nrhs, a, lda, ipiv, b, ldb, info), the solve of np.linalg.solve
_dgesv = types.ExternalFunction(_lapack_symbol("dgesv"),
                                types.void(_I32P, _I32P, _F64P, _I32P, _I32P, _F64P, _I32P, _I32P))

#: per clearance joint diagnostics written by the kernel (columns of ``diag``)
DIAG = ("ex", "ey", "nx", "ny", "d", "delta", "delta_dot", "v_slip", "fn", "ft", "fx", "fy",
        "v_elastic", "p_damp", "p_fric", "fel", "vrx", "vry", "omega_sum", "gx", "gy", "dtheta",
        "r_b", "film")
_D = {k: i for i, k in enumerate(DIAG)}
#: columns of the clearance joints' float table: clearance (minor for a worn bore), journal
#: radius, v_impact_min, clearance_major (-1: round bore), wear_angle, viscosity (film flag in
#: the integer table), bearing_length, eps_max
N_CL_F = 8
_S_CAP = 3.0
_BODIES = (RigidBody, FlexibleBody)
#: the powers the kernel integrates: system.AUX_NAMES (drive, loads, ideal joints, contact
#: damping, friction, modal damping); not imported from .system, which imports this module
N_AUX = 6


def applicable(sysm) -> bool:
    """True when every part of ``sysm`` has a compiled form (see the module docstring).

    Clearance joints: round and worn (elliptical) bores, dry or with the short-bearing film
    (``film_model = "short"``) or the finite-length film (``"finite"``: the Reynolds table of
    :mod:`.reynolds`, evaluated by its own :func:`.reynolds.finite_film` in both paths).
    """
    if not all(type(b) in _BODIES for b in sysm.bodies):
        return False
    if not all(type(c) in (Revolute, Prismatic, AngleDrive) for c in sysm.constraints):
        return False
    for cj in sysm.clearances:
        if type(cj) is not ClearanceJoint:
            return False
        if cj.viscosity is not None and cj.film_model not in ("short", "finite"):
            return False
        if not all(isinstance(b, (*_BODIES, Ground)) for b in (cj.journal, cj.bearing)):
            return False
    for ld in sysm.loads:
        if type(ld) not in (PistonLoads, CrankTorque, TorsionalCoupling):
            return False
        if type(ld) is TorsionalCoupling:
            if not all(isinstance(b, (*_BODIES, Ground)) for b in (ld.a, ld.b)):
                return False
            continue
        if not all(isinstance(b, _BODIES) for b in (getattr(ld, "piston", ld.crank), ld.crank)):
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
# A frame ``k`` of the table belongs to a body whose coordinates start at column ``fcol[k]``
# (-1: the ground, ``floc[k]`` then holds its global pose); ``floc[k]`` is its undeformed offset
# (x, y, angle) in the body frame. A frame of a flexible body has ``fmn[k]`` modal columns after
# the body's (x, y, θ), and ``fmodal[fmoff[k]:]`` holds its D (2 rows) and r_z (one row), each
# ``fmn[k]`` long; the kernel writes ``A(θ) D`` to ``AD[fadoff[k]:]`` (x row, then y row).
@njit(cache=True)
def _frames(q, qd, fr, pose, arm, bias, vel):
    fcol, floc, fmn, fmoff, fadoff, fmodal, AD = fr
    for k in range(fcol.size):
        i = fcol[k]
        if i < 0:
            for j in range(3):
                pose[k, j] = floc[k, j]
                bias[k, j] = 0.0
                vel[k, j] = 0.0
            arm[k, 0] = 0.0
            arm[k, 1] = 0.0
            continue
        th = q[i + 2]
        w = qd[i + 2]
        c, s = np.cos(th), np.sin(th)
        sx, sy, ang = floc[k, 0], floc[k, 1], floc[k, 2]
        vx = vy = wz = 0.0
        nk = fmn[k]
        if nk > 0:  # s = s0 + D ξ, angle + r_zᵀξ; A D ξ̇ and r_zᵀ ξ̇
            o, a0, m0 = fmoff[k], fadoff[k], i + 3
            for a in range(nk):
                xi, xd = q[m0 + a], qd[m0 + a]
                dx, dy, rz = fmodal[o + a], fmodal[o + nk + a], fmodal[o + 2 * nk + a]
                sx += dx * xi
                sy += dy * xi
                ang += rz * xi
                adx = c * dx - s * dy
                ady = s * dx + c * dy
                AD[a0 + a] = adx
                AD[a0 + nk + a] = ady
                vx += adx * xd
                vy += ady * xd
                wz += rz * xd
        ax = c * sx - s * sy
        ay = s * sx + c * sy
        pose[k, 0] = q[i] + ax
        pose[k, 1] = q[i + 1] + ay
        pose[k, 2] = th + ang
        arm[k, 0] = ax
        arm[k, 1] = ay
        bias[k, 0] = -w * w * ax - 2.0 * w * vy
        bias[k, 1] = -w * w * ay + 2.0 * w * vx
        bias[k, 2] = 0.0
        vel[k, 0] = qd[i] - ay * w + vx
        vel[k, 1] = qd[i + 1] + ax * w + vy
        vel[k, 2] = w + wz


@njit(cache=True, inline="always")
def _jrow(out, r, k, s, cx, cy, ct, fr, arm):
    """Add ``s (cx, cy, ct) · J_k`` (frame ``k``'s Jacobian rows combined) to row ``r`` of
    ``out``; with ``out`` a column (``r`` = 0 of a (1, n) view) it adds ``J_kᵀ f``."""
    fcol, _floc, fmn, fmoff, fadoff, fmodal, AD = fr
    i = fcol[k]
    if i < 0:
        return
    out[r, i] += s * cx
    out[r, i + 1] += s * cy
    out[r, i + 2] += s * (-cx * arm[k, 1] + cy * arm[k, 0] + ct)
    nk = fmn[k]
    if nk > 0:
        o, a0, m0 = fmoff[k], fadoff[k], i + 3
        for a in range(nk):
            out[r, m0 + a] += s * (cx * AD[a0 + a] + cy * AD[a0 + nk + a]
                                   + ct * fmodal[o + 2 * nk + a])


@njit(cache=True, inline="always")
def _pin_rows(Cq, r, k, s, fr, arm):
    """Add ``s`` times frame ``k``'s position rows (x, y) of its Jacobian to rows ``r`` and
    ``r + 1`` of ``Cq`` (a pin's two equations; :func:`_jrow` twice, in one pass)."""
    fcol, _floc, fmn, _fmoff, fadoff, _fmodal, AD = fr
    i = fcol[k]
    if i < 0:
        return
    Cq[r, i] += s
    Cq[r + 1, i + 1] += s
    Cq[r, i + 2] -= s * arm[k, 1]
    Cq[r + 1, i + 2] += s * arm[k, 0]
    nk = fmn[k]
    if nk > 0:
        a0, m0 = fadoff[k], i + 3
        for a in range(nk):
            Cq[r, m0 + a] += s * AD[a0 + a]
            Cq[r + 1, m0 + a] += s * AD[a0 + nk + a]


@njit(cache=True, inline="always")
def _add_force(Q2, fr, arm, k, fx, fy, mz):
    """``Q += J_kᵀ (fx, fy, mz)``: a force and moment at frame ``k`` (``Q2``: Q as (1, n))."""
    _jrow(Q2, 0, k, 1.0, fx, fy, mz, fr, arm)


@njit(cache=True)
def _clearance(j, pose, vel, cl_int, cl_f, out):
    """Kinematics of clearance joint ``j`` into ``out`` (a row of ``diag``), as
    :meth:`.ClearanceJoint.kinematics`: a worn bore's clearance ``c(phi)`` in the direction of
    the eccentricity (bearing frame) turns the penetration's gradient off the normal,
    ``grad = n - (c' / d) t``, and adds ``c' omega_bearing`` to its rate."""
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
    c, rj, c_major = cl_f[j, 0], cl_f[j, 1], cl_f[j, 3]
    dc = 0.0
    if c_major >= 0.0:  # worn bore (a round one has c_major = -1)
        c, dc = worn_bore_clearance(np.arctan2(ny, nx) - pose[kb, 2], rj, c, c_major,
                                    cl_f[j, 4])
    gx, gy = nx, ny
    if dc != 0.0 and d > 1e-300:
        gx = nx + (dc / d) * ny
        gy = ny - (dc / d) * nx
    out[0], out[1], out[2], out[3], out[4] = ex, ey, nx, ny, d
    out[5] = d - c
    out[6] = gx * vrx + gy * vry + dc * vel[kb, 2]
    out[7] = -ny * vrx + nx * vry + rj * vel[kj, 2] - (rj + c) * vel[kb, 2]
    out[16], out[17] = vrx, vry
    out[18] = vel[kj, 2] + vel[kb, 2]
    out[19], out[20], out[21], out[22] = gx, gy, dc, rj + c


@njit(cache=True)
def _flexible(q, qd, fb_int, fb_f, Q, A):
    """Each flexible body's quadratic velocity, elastic and modal damping forces into ``Q`` and
    its mass block ``M(ξ)`` (the θ, ξ rows and columns, with the constant terms of its attached
    rotary inertias ``Σ J_s``, ``Σ J_s r_z``, ``Σ J_s r_z r_zᵀ``) into ``A``, as
    :class:`~.flexible.FlexibleBody` computes them; returns the modal damping power, W."""
    p_modal = 0.0
    for bi in range(fb_int.shape[0]):
        c0, k, o = fb_int[bi, 0], fb_int[bi, 1], fb_int[bi, 2]
        j0 = fb_f[o + 1]
        ob, oc, oG = o + 2, o + 2 + k, o + 2 + 2 * k
        oS, oK = oG + k * k, oG + 2 * k * k
        oC = oK + k
        oJ = oC + k  # attached inertias: Σ J_s, then Σ J_s r_z (k), Σ J_s r_z r_zᵀ (k × k)
        oh, oH = oJ + 1, oJ + 1 + k
        t, m0 = c0 + 2, c0 + 3
        w = qd[t]
        cv = np.empty(k)
        mtt = j0
        q_th = 0.0
        for a in range(k):
            g = fb_f[ob + a]
            for b in range(k):
                g += fb_f[oG + a * k + b] * q[m0 + b]
            cv[a] = g  # b + G ξ
            mtt += (fb_f[ob + a] + g) * q[m0 + a]  # J0 + 2bᵀξ + ξᵀGξ
            q_th += g * qd[m0 + a]
        Q[t] += -2.0 * w * q_th
        A[t, t] = mtt + fb_f[oJ]
        for a in range(k):
            sx = 0.0
            h = fb_f[oc + a] + fb_f[oh + a]
            for b in range(k):
                sx += fb_f[oS + a * k + b] * qd[m0 + b]
                h += fb_f[oS + b * k + a] * q[m0 + b]  # c + Sᵀξ
                A[m0 + a, m0 + b] = fb_f[oG + a * k + b] + fb_f[oH + a * k + b]
            A[t, m0 + a] = h
            A[m0 + a, t] = h
            xd = qd[m0 + a]
            Q[m0 + a] += (w * w * cv[a] + 2.0 * w * sx - fb_f[oK + a] * q[m0 + a]
                          - fb_f[oC + a] * xd)
            p_modal += fb_f[oC + a] * xd * xd
    return p_modal


#: order of the integer tables packed into ``I`` (see :class:`CompiledSystem`)
INT_TABLES = ("fcol", "fmn", "fmoff", "fadoff", "rev_rows", "rev_a", "rev_b", "pri_rows",
              "pri_k", "drive_rows", "drive_k", "cl_int", "pl_int", "gas_off", "tq_k",
              "is_drive", "col_ptr", "col_rows", "massless", "fb_int", "full", "film_off",
              "cp_k")
#: order of the float tables packed into ``F``
FLOAT_TABLES = ("floc", "fmodal", "mdiag", "Q0", "pri_n", "pri_o", "pri_ang", "cl_f", "law_vec",
                "fric_vec", "pl_f", "gas_x", "gas_f", "gas_period", "tq_val", "baumgarte",
                "fb_f", "film_spl", "cp_f")


@njit(cache=True)
def _seg(a, o, i):
    return a[o[i]:o[i + 1]]


@njit(cache=True, inline="always")
def _frame_tables(I, io, F, fo):
    fcol, fmn, fmoff, fadoff = _seg(I, io, 0), _seg(I, io, 1), _seg(I, io, 2), _seg(I, io, 3)
    floc, fmodal = _seg(F, fo, 0).reshape((-1, 3)), _seg(F, fo, 1)
    n_ad = fadoff[-1] + 2 * fmn[-1] if fcol.size else 0  # fadoff is the running sum
    return fcol, floc, fmn, fmoff, fadoff, fmodal, np.empty(n_ad)


@njit(cache=True)
def assemble(t, q, qd, dv, vimp, gas_py, I, io, F, fo, phi, Cq, diag, powers, Q, cqd, A, rhs):
    """Everything up to the linear solve: the applied, contact and flexible-body forces ``Q``,
    constraint values ``phi`` and Jacobian ``Cq``, ``cqd = Cq qd``, clearance diagnostics
    ``diag`` (rows of :data:`DIAG`), ``powers[1:]`` = (loads, -, contact damping, friction,
    modal damping) and the linear system ``A x = rhs`` (see the comments below; :func:`finish`
    takes its solution), written in place.

    ``dv``: per drive (angle, speed, acceleration) at ``t``; ``vimp``: per clearance joint its
    impact velocity; ``gas_py``: gas forces of pistons without a table; ``I, io, F, fo``: the
    packed tables (:data:`INT_TABLES`, :data:`FLOAT_TABLES`).
    """
    n = q.size
    m = phi.size
    fr = _frame_tables(I, io, F, fo)
    rev_rows, rev_a, rev_b = _seg(I, io, 4), _seg(I, io, 5), _seg(I, io, 6)
    pri_rows, pri_k = _seg(I, io, 7), _seg(I, io, 8)
    drive_rows, drive_k = _seg(I, io, 9), _seg(I, io, 10)
    cl_int, pl_int = _seg(I, io, 11).reshape((-1, 5)), _seg(I, io, 12).reshape((-1, 3))
    gas_off, tq_k = _seg(I, io, 13), _seg(I, io, 14)
    col_ptr, col_rows, massless = _seg(I, io, 16), _seg(I, io, 17), _seg(I, io, 18)
    fb_int, full = _seg(I, io, 19).reshape((-1, 3)), _seg(I, io, 20)[0]
    mdiag, Q0 = _seg(F, fo, 2), _seg(F, fo, 3)
    pri_n, pri_o = _seg(F, fo, 4).reshape((-1, 2)), _seg(F, fo, 5).reshape((-1, 2))
    pri_ang = _seg(F, fo, 6)
    cl_f, law_vec = _seg(F, fo, 7).reshape((-1, N_CL_F)), _seg(F, fo, 8).reshape((-1, 5))
    fric_vec, pl_f = _seg(F, fo, 9).reshape((-1, 4)), _seg(F, fo, 10).reshape((-1, 6))
    gas_x, gas_f, gas_period = _seg(F, fo, 11), _seg(F, fo, 12), _seg(F, fo, 13)
    tq_val, baumgarte, fb_f = _seg(F, fo, 14), F[fo[15]], _seg(F, fo, 16)
    film_off, film_spl = _seg(I, io, 21), _seg(F, fo, 17)
    K = fr[0].size
    pose = np.empty((K, 3))
    arm = np.empty((K, 2))
    bias = np.empty((K, 3))
    vel = np.empty((K, 3))
    _frames(q, qd, fr, pose, arm, bias, vel)
    Q[:] = Q0
    Q2 = Q.reshape((1, n))
    A[:, :] = 0.0
    powers[5] = _flexible(q, qd, fb_int, fb_f, Q, A)
    # clearance joints (clearance.ClearanceJoint.forces: round or worn bore, dry or with the
    # short-bearing film)
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
        fx = -fn * row[19] + ft * -ny
        fy = -fn * row[20] + ft * nx
        p_film = 0.0
        row[23] = 0.0
        if cl_int[j, 4]:  # a film (1: short bearing, 2: finite length) on the minor clearance
            vrx, vry = row[16], row[17]
            eps, wedge, eps_dot = film_arguments(row[4], nx * vrx + ny * vry,
                                                 -ny * vrx + nx * vry, row[18], cl_f[j, 0],
                                                 cl_f[j, 7])
            if cl_int[j, 4] == 2:  # finite-length film: the Reynolds table
                f_r, f_t = finite_film(eps, wedge, eps_dot, cl_f[j, 5], cl_f[j, 1], cl_f[j, 6],
                                       cl_f[j, 0], film_spl[film_off[j]:])
            else:
                f_r, f_t = short_film(eps, wedge, eps_dot, cl_f[j, 5], cl_f[j, 1], cl_f[j, 6],
                                      cl_f[j, 0])
            ffx = f_r * nx + f_t * -ny
            ffy = f_r * ny + f_t * nx
            p_film = ffx * vrx + ffy * vry
            fx += ffx
            fy += ffy
            row[23] = np.hypot(ffx, ffy)
        if fn != 0.0 or row[23] != 0.0:  # a film force need not do work (p_film may be 0)
            rj = cl_f[j, 1]
            _add_force(Q2, fr, arm, cl_int[j, 0], fx, fy, rj * ft)
            _add_force(Q2, fr, arm, cl_int[j, 1], -fx, -fy, -row[22] * ft - fn * row[21])
        row[8], row[9], row[10], row[11] = fn, ft, fx, fy
        row[12] = elastic_energy(code, law_vec[j], delta) if delta > 0.0 else 0.0
        row[13] = (fn - fel) * ddot - p_film
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
            _add_force(Q2, fr, arm, kp, f * a0, f * a1, 0.0)
        p_loads += f * v
    for i in range(tq_k.size):
        _add_force(Q2, fr, arm, tq_k[i], 0.0, 0.0, tq_val[i])
        p_loads += tq_val[i] * vel[tq_k[i], 2]
    # torsional couplings (loads.TorsionalCoupling): T on frame a, -T on frame b
    cp_k, cp_f = _seg(I, io, 22).reshape((-1, 2)), _seg(F, fo, 18).reshape((-1, 3))
    for i in range(cp_k.shape[0]):
        ka, kb = cp_k[i, 0], cp_k[i, 1]
        wa, wb = vel[ka, 2], vel[kb, 2]
        tq = cp_f[i, 0] * (pose[kb, 2] - pose[ka, 2] - cp_f[i, 2]) + cp_f[i, 1] * (wb - wa)
        _add_force(Q2, fr, arm, ka, 0.0, 0.0, tq)
        _add_force(Q2, fr, arm, kb, 0.0, 0.0, -tq)
        p_loads += tq * (wa - wb)
    # constraint terms (the joints' blocks: pins, sliders on a ground line, angle drives)
    nu = np.zeros(m)
    gamma = np.zeros(m)
    Cq[:, :] = 0.0
    for r_i in range(rev_rows.size):
        r, a, b = rev_rows[r_i], rev_a[r_i], rev_b[r_i]
        phi[r] = pose[a, 0] - pose[b, 0]
        phi[r + 1] = pose[a, 1] - pose[b, 1]
        gamma[r] = -(bias[a, 0] - bias[b, 0])
        gamma[r + 1] = -(bias[a, 1] - bias[b, 1])
        _pin_rows(Cq, r, a, 1.0, fr, arm)
        _pin_rows(Cq, r, b, -1.0, fr, arm)
    for p_i in range(pri_rows.size):
        r, k = pri_rows[p_i], pri_k[p_i]
        n0, n1 = pri_n[p_i, 0], pri_n[p_i, 1]
        phi[r] = n0 * (pose[k, 0] - pri_o[p_i, 0]) + n1 * (pose[k, 1] - pri_o[p_i, 1])
        phi[r + 1] = pose[k, 2] - pri_ang[p_i]
        _jrow(Cq, r, k, 1.0, n0, n1, 0.0, fr, arm)
        _jrow(Cq, r + 1, k, 1.0, 0.0, 0.0, 1.0, fr, arm)
        gamma[r] = -(n0 * bias[k, 0] + n1 * bias[k, 1])
    for d_i in range(drive_rows.size):
        r, k = drive_rows[d_i], drive_k[d_i]
        phi[r] = pose[k, 2] - dv[d_i, 0]
        _jrow(Cq, r, k, 1.0, 0.0, 0.0, 1.0, fr, arm)
        nu[r] = dv[d_i, 1]
        gamma[r] = dv[d_i, 2]
    for r in range(m):
        acc = 0.0
        for i in range(n):
            acc += Cq[r, i] * qd[i]
        cqd[r] = acc
        gamma[r] = gamma[r] - 2.0 * baumgarte * (acc - nu[r]) - baumgarte * baumgarte * phi[r]
    powers[1] = p_loads
    powers[3] = p_damp
    powers[4] = p_fric
    if full:
        # with flexible bodies, the whole KKT system (M(q) is not diagonal):
        #   [ M   Cq^T ] [ qdd ]   [ Q ]
        #   [ Cq  0    ] [ lam ] = [ c ],  c = gamma - 2 a phidot - a^2 phi
        for i in range(n):
            if mdiag[i] != 0.0:
                A[i, i] = mdiag[i]
            rhs[i] = Q[i]
        for r in range(m):
            rhs[n + r] = gamma[r]
            for i in range(n):
                A[n + r, i] = Cq[r, i]
                A[i, n + r] = Cq[r, i]
        return
    # M qdd + Cq^T lam = Q, Cq qdd = c with the diagonal M of rigid bodies: the massive
    # coordinates (a) eliminated, qdd_a = M_a^-1 (Q_a - Cq_a^T lam), leaves for the massless
    # ones (b, e.g. a piston's rotation) and lam
    #   [ 0     Cq_b^T              ] [ qdd_b ]   [ Q_b                    ]
    #   [ Cq_b  -Cq_a M_a^-1 Cq_a^T ] [ lam   ] = [ c - Cq_a M_a^-1 Q_a    ]
    # summed over the few rows each column of Cq touches (col_ptr, col_rows: its pattern)
    nb = massless.size
    for r in range(m):
        rhs[nb + r] = gamma[r]
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


@njit(cache=True)
def finish(sol, Q, Cq, cqd, I, io, F, fo, qdd, lam, powers):
    """Accelerations ``qdd``, multipliers ``lam`` and ``powers[0]``, ``powers[2]`` (drive, ideal
    joints) from the solution ``sol`` of :func:`assemble`'s system. Returns False on a
    non-finite result."""
    n, m = qdd.size, lam.size
    is_drive, col_ptr = _seg(I, io, 15), _seg(I, io, 16)
    col_rows, massless = _seg(I, io, 17), _seg(I, io, 18)
    full = _seg(I, io, 20)[0]
    mdiag = _seg(F, fo, 2)
    if full:
        nb = n
        for i in range(n):
            qdd[i] = sol[i]
    else:
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
    ok = np.isfinite(p_all + powers[1] + powers[3] + powers[4] + powers[5])
    for i in range(n):
        ok = ok and np.isfinite(qdd[i])
    return ok


@njit(cache=True)
def drive_values(t, drv, dv):
    """Per angle drive its (angle, speed, acceleration) at ``t`` into ``dv`` (rad, rad/s,
    rad/s^2) from ``drv``, rows of :meth:`.SpeedProfile.table`."""
    for i in range(drv.shape[0]):
        dv[i, 0], dv[i, 1], dv[i, 2] = speed_profile(t, drv[i, 0], drv[i, 1], drv[i, 2],
                                                     drv[i, 3])


@njit(cache=True)
def evaluate(t, q, qd, dv, vimp, gas_py, tabs, work, phi, Cq, diag, powers, qdd, lam):
    """One right-hand side: :func:`assemble`, LAPACK's ``dgesv`` in place, :func:`finish`.

    ``tabs = (I, io, F, fo)``; ``work = (Q, cqd, A, rhs, ipiv, ints)`` (:class:`CompiledSystem`
    allocates them; ``ints``: three int32). Returns 0, 1 (a non-finite result) or 2 (a singular
    matrix). The Python-called path (:meth:`CompiledSystem.rhs`) and the compiled integrator
    loop (:mod:`.integrator`) both call this one function.
    """
    I, io, F, fo = tabs
    Q, cqd, A, rhs, ipiv, ints = work
    assemble(t, q, qd, dv, vimp, gas_py, I, io, F, fo, phi, Cq, diag, powers, Q, cqd, A, rhs)
    # LAPACK gesv (as np.linalg.solve on the Python path), in place: compiling np.linalg.solve
    # would cost 10 s more at the first run. A is symmetric, so its C-ordered storage is the
    # Fortran-ordered A that gesv overwrites.
    if rhs.size:
        ints[0], ints[1], ints[2] = rhs.size, 1, 0
        _dgesv(ints[0:].ctypes, ints[1:].ctypes, A.ctypes, ints[0:].ctypes, ipiv.ctypes,
               rhs.ctypes, ints[0:].ctypes, ints[2:].ctypes)
        if ints[2] != 0:  # > 0: an exactly zero pivot
            return 2
    ok = finish(rhs, Q, Cq, cqd, I, io, F, fo, qdd, lam, powers)
    return 0 if ok else 1


@njit(cache=True)
def clearance_kinematics(j, q, qd, I, io, F, fo, out):
    """Penetration (``out[5]``) and its rate (``out[6]``) of clearance joint ``j`` only."""
    fr = _frame_tables(I, io, F, fo)
    cl_int, cl_f = _seg(I, io, 11).reshape((-1, 5)), _seg(F, fo, 7).reshape((-1, N_CL_F))
    K = fr[0].size
    pose = np.empty((K, 3))
    arm = np.empty((K, 2))
    bias = np.empty((K, 3))
    vel = np.empty((K, 3))
    _frames(q, qd, fr, pose, arm, bias, vel)
    _clearance(j, pose, vel, cl_int, cl_f, out)


class CompiledSystem:
    """The tables of one :class:`~.system.Multibody` for :func:`assemble` and :func:`finish`."""

    def __init__(self, sysm):
        self.sysm = sysm
        self.n, self.m = n, m = sysm.n, sysm.m
        index = {}
        fcol, floc, fmn, fmodal, fmoff, fadoff = [], [], [], [], [], []
        self._frame_list = []

        def key(body, frame):
            kk = (id(body), frame)
            if kk not in index:
                index[kk] = len(fcol)
                self._frame_list.append((body, frame))
                nk = 0
                if isinstance(body, Ground):
                    fcol.append(-1)
                    floc.append(body.frame_pose(None, frame))
                elif isinstance(body, FlexibleBody):
                    s0, D, rz = body.frames[frame]
                    fcol.append(sysm.slices[id(body)].start)
                    floc.append((s0[0], s0[1], 0.0))
                    nk = body.n_coordinates
                    fmodal.append(np.concatenate([np.ravel(D), np.ravel(rz)]))
                else:
                    s, ph = body.local(frame)
                    fcol.append(sysm.slices[id(body)].start)
                    floc.append((s[0], s[1], ph))
                fmoff.append(sum(a.size for a in fmodal[:-1]) if nk else 0)
                fadoff.append(2 * sum(fmn))
                fmn.append(nk)
            return index[kk]

        # constraints (the rows of each joint's blocks) and their sparsity pattern
        rev_rows, rev_a, rev_b, pri_rows, pri_k, pri_n, pri_o, pri_ang = ([] for _ in range(8))
        self.drives = []
        row_frames = [[] for _ in range(m)]
        for c, r in zip(sysm.constraints, sysm.rows):
            r0 = r.start
            ks = [key(b, f) for b, f in frames_of(c)]
            for rr in range(r.start, r.stop):
                row_frames[rr] += ks
            if isinstance(c, Revolute):
                rev_rows.append(r0)
                rev_a.append(ks[0])
                rev_b.append(ks[1])
            elif isinstance(c, Prismatic):
                pri_rows.append(r0)
                pri_k.append(ks[0])
                pri_n.append((-c.axis[1], c.axis[0]))
                pri_o.append(np.asarray(c.origin, float))
                pri_ang.append(c.angle)
            else:  # AngleDrive
                self.drives.append((r0, ks[0], c.profile))
        cl_int, cl_f, law_vec, fric_vec = [], [], [], []
        film_off, film_spl = [], []  # per joint: offset of its finite film's table, or -1
        for cj in sysm.clearances:
            film = cj.viscosity is not None
            finite = film and cj.film_model == "finite"
            cl_int.append((key(cj.journal, cj.journal_frame), key(cj.bearing, cj.bearing_frame),
                           cj.normal.code, cj.friction_law.code, 2 if finite else int(film)))
            film_off.append(sum(a.size for a in film_spl) if finite else -1)
            if finite:
                film_spl.append(film_spline(cj.bearing_length / (2.0 * cj.journal_radius)))
            major = -1.0 if cj.clearance_major is None else cj.clearance_major
            cl_f.append((cj.clearance, cj.journal_radius, cj.v_impact_min, major, cj.wear_angle,
                         cj.viscosity if film else 0.0, cj.bearing_length, cj.eps_max))
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
        cp_k = [(key(ld.a, ld.frame_a), key(ld.b, ld.frame_b)) for ld in sysm.loads
                if type(ld) is TorsionalCoupling]
        cp_f = [(ld.stiffness, ld.damping, ld.offset) for ld in sysm.loads
                if type(ld) is TorsionalCoupling]
        # bodies: diagonal masses (rigid bodies; x, y of flexible ones), constant forces, and
        # the flexible bodies' invariants
        mdiag = np.zeros(n)
        Q0 = np.zeros(n)
        fb_int, fb_f = [], []
        for b in sysm.bodies:
            s = sysm.slices[id(b)]
            z = np.zeros(b.ndof)
            Q0[s] = b.gravity_force(z, sysm.gravity)
            if isinstance(b, FlexibleBody):
                mdiag[s.start:s.start + 2] = b.mass
                fb_int.append((s.start, b.n_coordinates, sum(a.size for a in fb_f)))
                Js, h, H = b.attached_terms()
                fb_f.append(np.concatenate([[b.mass, b.j0], b.b, b.c, np.ravel(b.G),
                                            np.ravel(b.S), b.K, b.C, [Js], h, np.ravel(H)]))
            else:
                Q0[s] += b.velocity_forces(z, z)
                mdiag[s] = np.diag(b.mass_matrix(z))
        # the whole KKT system with flexible bodies (M(xi) is full) and with an oil film: the
        # reduced system recovers a driven coordinate's acceleration from the multipliers,
        # qdd = (Q - Cq^T lam) / M, whose round-off (4e-3 rad/s^2 of a crank's, against 2e-11
        # from the KKT's own drive row) LSODA's finite-difference Jacobian turned into 1e-8 s
        # steps on a film started at the bearing centre (26 k evaluations for 3.7 ms against
        # the Python path's 1094 for 10 ms)
        full = bool(fb_int) or any(cj.viscosity is not None for cj in sysm.clearances)
        # sparsity pattern of Cq by column (the reduced system of an all-rigid one)
        pattern = np.zeros((m, n), bool)
        for r, ks in enumerate(row_frames):
            for k in ks:
                if fcol[k] >= 0:
                    pattern[r, fcol[k]:fcol[k] + 3 + fmn[k]] = True
        col_rows = [np.flatnonzero(pattern[:, i]) for i in range(n)]
        col_ptr = np.concatenate([[0], np.cumsum([len(r) for r in col_rows])])
        nc, npl = len(sysm.clearances), len(pl_int)
        self.clearances = sysm.clearances
        massless = np.zeros(0, np.int64) if full else np.flatnonzero(mdiag == 0.0)
        ints = {"fcol": fcol, "fmn": fmn, "fmoff": fmoff, "fadoff": fadoff,
                "rev_rows": rev_rows, "rev_a": rev_a, "rev_b": rev_b,
                "pri_rows": pri_rows, "pri_k": pri_k,
                "drive_rows": [d[0] for d in self.drives],
                "drive_k": [d[1] for d in self.drives],
                "cl_int": cl_int, "pl_int": pl_int, "gas_off": off, "tq_k": tq_k,
                "is_drive": sysm._drive_rows, "col_ptr": col_ptr,
                "col_rows": np.concatenate(col_rows) if col_rows else [],
                "massless": massless, "fb_int": fb_int, "full": [int(full)],
                "film_off": film_off, "cp_k": cp_k}
        floats = {"floc": floc, "fmodal": fmodal, "mdiag": mdiag, "Q0": Q0,
                  "pri_n": pri_n, "pri_o": pri_o, "pri_ang": pri_ang, "cl_f": cl_f,
                  "law_vec": law_vec, "fric_vec": fric_vec, "pl_f": pl_f, "gas_x": gx,
                  "gas_f": gf, "gas_period": period, "tq_val": tq_val,
                  "baumgarte": [sysm.baumgarte], "fb_f": fb_f, "film_spl": film_spl,
                  "cp_f": cp_f}
        self.I, self.io = _pack([_flat(ints[k]) for k in INT_TABLES], np.int64)
        self.F, self.fo = _pack([_flat(floats[k]) for k in FLOAT_TABLES], float)
        self.gas_py = np.zeros(npl)
        self.vimp = np.zeros(nc)
        self._diag = np.zeros((nc, len(DIAG)))
        self._kin = np.zeros(len(DIAG))
        self._zeros = np.zeros(n)
        # for solve's per-joint diagnostics
        self._cl_frames = [(int(a[0]), int(a[1])) for a in np.reshape(cl_int, (-1, 5))]
        self._scratch = (np.empty(m), np.empty(m), np.empty((m, n)), np.zeros(N_AUX))
        size = n + m if full else len(massless) + m
        self._size = size  # of the linear system: n + m with a flexible body
        self._work = (np.empty(n), np.empty(m), np.zeros((size, size)), np.empty(size),
                      np.zeros(size, np.int32), np.zeros(3, np.int32))
        self.tabs = (self.I, self.io, self.F, self.fo)
        # the drives' profiles as table rows (speed_profile's arguments), or None when one is
        # not a SpeedProfile (its own methods are then called from Python)
        profiles = [prof for _, _, prof in self.drives]
        self.drv = (np.array([p.table() for p in profiles], float).reshape(-1, 4)
                    if all(type(p) is SpeedProfile for p in profiles) else None)
        self._dv = np.zeros((len(self.drives), 3))

    def _call(self, t, q, qd, qdd, lam, phi, Cq, diag, powers, v_impact=None):
        # one compiled specialisation: contiguous float arrays (a column of a history is not)
        q, qd = np.ascontiguousarray(q, float), np.ascontiguousarray(qd, float)
        dv = self._dv
        if self.drv is not None:
            drive_values(float(t), self.drv, dv)
        else:
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
        status = evaluate(float(t), q, qd, dv, self.vimp, self.gas_py, self.tabs, self._work, phi,
                          Cq, diag, powers, qdd, lam)
        if status == 2:
            raise np.linalg.LinAlgError("Singular matrix")
        return status == 0

    @property
    def loop_ready(self) -> bool:
        """True when the whole right-hand side runs compiled (every drive a
        :class:`.SpeedProfile`, no gas force given as a Python function): the compiled
        integrator loop (:mod:`.integrator`) can then run this system."""
        return self.drv is not None and not self._py_gas

    def rhs(self, t, y, v_impact=None):
        """``dy`` of :meth:`Multibody.rhs`; None if not finite."""
        n = self.n
        dy = np.zeros(y.size)
        q, qd = y[:n], y[n:2 * n]
        dy[:n] = qd
        lam, phi, Cq, powers = self._scratch
        ok = self._call(t, q, qd, dy[n:2 * n], lam, phi, Cq, self._diag, powers, v_impact)
        dy[2 * n: 2 * n + N_AUX] = powers
        return dy if ok else None

    def solve(self, t, q, qd, v_impact=None) -> dict:
        """What :meth:`Multibody.solve` returns."""
        n, m = self.n, self.m
        qdd, lam, phi, Cq = np.empty(n), np.empty(m), np.empty(m), np.empty((m, n))
        diag = np.zeros_like(self._diag)
        powers = np.zeros(N_AUX)
        self._call(t, q, qd, qdd, lam, phi, Cq, diag, powers, v_impact)
        nu = np.zeros(m)
        for r, _, prof in self.drives:
            nu[r] = prof.speed(t)
        contacts = []
        for j in range(len(self.clearances)):
            row = diag[j]
            nx, ny = row[_D["nx"]], row[_D["ny"]]
            kj, kb = self._cl_frames[j]
            contacts.append({
                "e": row[0:2].copy(), "n": np.array([nx, ny]), "t": np.array([-ny, nx]),
                "grad": np.array([row[_D["gx"]], row[_D["gy"]]]),
                "dtheta": float(row[_D["dtheta"]]), "delta": float(row[_D["delta"]]),
                "delta_dot": float(row[_D["delta_dot"]]), "v_slip": float(row[_D["v_slip"]]),
                "Jj": self._jac(kj, q), "Jb": self._jac(kb, q),
                "r_b": float(row[_D["r_b"]]), "d": float(row[_D["d"]]),
                "vrel": row[16:18].copy(), "omega_sum": float(row[_D["omega_sum"]]),
                "fn": float(row[_D["fn"]]), "ft": float(row[_D["ft"]]), "force": row[10:12].copy(),
                "film": float(row[_D["film"]]), "p_damp": float(row[_D["p_damp"]]),
                "p_fric": float(row[_D["p_fric"]]), "v_elastic": float(row[_D["v_elastic"]])})
        return {"qdd": qdd, "lam": lam, "phi": phi, "Cq": Cq, "nu": nu, "contacts": contacts,
                "p_loads": float(powers[1])}

    def _jac(self, k, q):
        """Frame ``k``'s Jacobian, (3, ndof of its body): the body's own (diagnostics only)."""
        body, frame = self._frame_list[k]
        if isinstance(body, Ground):
            return np.zeros((3, 0))
        return body.frame_jacobian(np.asarray(q, float)[self.sysm.slices[id(body)]], frame)

    def penetration(self, j, q, qd=None):
        """``(delta, delta_dot)`` of clearance joint ``j`` (``delta_dot`` 0 without ``qd``)."""
        out = self._kin
        q = np.ascontiguousarray(q, float)
        qd = self._zeros if qd is None else np.ascontiguousarray(qd, float)
        clearance_kinematics(j, q, qd, self.I, self.io, self.F, self.fo, out)
        return out[5], out[6]


def _flat(a):
    """A table as one flat sequence (a list of rows or of arrays of any lengths)."""
    if isinstance(a, np.ndarray):
        return a.ravel()
    parts = [np.ravel(np.asarray(x, float)) for x in a]
    return np.concatenate(parts) if parts else np.zeros(0)


def _pack(arrays, dtype):
    """One flat array of ``arrays`` (each flattened) and the offsets of each."""
    flat = [np.asarray(a, dtype).ravel() for a in arrays]
    offsets = np.concatenate([[0], np.cumsum([a.size for a in flat])]).astype(np.int64)
    return (np.concatenate(flat) if flat else np.zeros(0, dtype)), offsets


def flush_if_changed(namespace: dict, name: str, modules) -> bool:
    """Flush the cached Numba functions of ``namespace`` (a module's ``globals()``, module
    ``name``) when a module of ``modules`` whose jitted functions they call changed.

    Numba keys a cached function on its own file only (numba issue #1833), so an edit or an
    upgrade of a called module would otherwise be served the old machine code. A stamp of those
    files' bytes kept beside the cache decides; returns whether it flushed.
    """
    import hashlib
    from pathlib import Path

    digest = hashlib.sha256(b"".join(Path(m.__file__).read_bytes()
                                     for m in modules)).hexdigest()
    # only the module's own functions: its namespace also holds the ones it imports, whose
    # caches belong to their modules (flushing them made the next process compile them again)
    cached = [f for f in namespace.values()
              if getattr(f, "_cache", None) is not None
              and getattr(getattr(f, "py_func", None), "__module__", None) == name]
    try:
        stamp = Path(cached[0]._cache._cache_path) / f"{name.rsplit('.', 1)[-1]}.deps"
    except (IndexError, AttributeError):  # no cached function, or numba's internals moved
        return False
    try:
        if stamp.read_text() == digest:
            return False
    except OSError:
        pass
    for f in cached:
        f._cache.flush()
    try:
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(digest)
    except OSError:
        pass  # a read-only cache: compiled again next time, never stale
    return True


def _flush_if_dependencies_changed() -> bool:
    """Flush this module's Numba cache when a module whose jitted functions it calls changed:
    ``worn_bore_clearance`` (clearance.py), ``film_arguments``/``short_film``
    (lubrication.py), ``finite_film`` (reynolds.py) and ``speed_profile`` (joints.py)."""
    from ..laws import lubrication, reynolds
    from ..model import clearance, joints

    return flush_if_changed(globals(), __name__, (clearance, lubrication, reynolds, joints))


_flush_if_dependencies_changed()
