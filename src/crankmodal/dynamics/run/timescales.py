"""Contact time scales of the clearance joints, estimated before a run.

A journal of effective mass ``m`` pressed into its bore by a law of tangent stiffness ``K_lin``
oscillates with the contact period ``T_K = 2 pi sqrt(m / K_lin)``; a law with a dashpot ``c``
relaxes with the damping time ``tau_c = m / c``. An explicit Runge-Kutta integrator is stable
only while its step ``h`` keeps ``h |lambda|`` inside its stability region (about 3.3 along both
axes for Dormand-Prince RK45); with the margin its error control keeps, a step of
``2 / |lambda|`` is taken here: ``h_K = T_K / pi`` (``lambda = i omega_n``) and
``h_c = 2 tau_c`` (``lambda = -c / m``). The shorter one over the run's ``end_time``, times the
evaluations per step, bounds the right-hand-side evaluations from below *if the joint is in
contact the whole time* (the big ends of the four-star and slider-crank scenes are, 80-100 % of
it, at their loads); :mod:`.budget` turns it into the run's estimate, refuses a run whose
estimate exceeds ``settings.max_rhs_evals`` and names the law parameter whose time scale is the
shorter (``law.stiffness`` or ``law.damping``: the joint law's arguments; a scene's stage names
its ``contact.stiffness`` / ``contact.damping`` keys).

Effective mass: ``1 / lambda_max`` of the 2x2 relative mobility of journal and bearing centres
(the acceleration of one against the other per unit force pair, through the mass matrix and
every ideal constraint at the initial state), i.e. the lightest direction; a bearing on the
ground or a driven crank counts as infinitely heavy through the constraints.

Representative load (for the tangent stiffness of non-linear laws): the larger of the peak gas
force on a piston and ``m omega**2 r`` (the effective mass on the crank radius at full speed);
``K_lin`` varies as its ``1 - 1/n`` power (``1/3`` for Hertz), so a rough load is enough.

What a law contributes (its static penetration, tangent stiffness and dashpot under that load,
and the stiffness that would give another tangent stiffness) the law object answers
(:class:`crankmodal.dynamics.laws.objects.NormalLaw`); this module knows no law by name.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..laws.objects import NormalLaw

#: evaluations of the right-hand side per accepted step of the explicit methods
EVALS_PER_STEP = {"RK45": 6, "DOP853": 12}


@dataclass
class TimeScale:
    """Contact time scales of one clearance joint (SI units)."""

    joint: str
    mass: float            # effective mass, kg
    load: float            # representative contact force, N
    k_lin: float           # tangent stiffness at that load, N/m
    period: float          # T_K = 2 pi sqrt(m / K_lin), s
    damping: float | None  # dashpot c, N s/m (None: the law has none of its own)
    damping_time: float | None  # m / c, s
    law: NormalLaw         # the joint's normal law (crankmodal.dynamics.laws.objects)

    @property
    def stiffness(self) -> float:
        """The law's stiffness parameter (``law.stiffness``)."""
        return self.law.stiffness

    @property
    def damping_set(self) -> float | None:
        """``law.damping`` as given, N s/m (None: the law has no dashpot)."""
        return self.law.dashpot_setting

    @property
    def firm(self) -> bool:
        """Whether the estimate is firm enough to refuse a run: not for a damping that depends
        on the penetration the run reaches (``impact``'s, :meth:`NormalLaw.dashpot`)."""
        return not (self.key == "law.damping" and self.law.dashpot_varies)

    @property
    def step(self) -> float:
        """Largest stable explicit step ``min(T_K / pi, 2 m / c)``, s."""
        h = self.period / np.pi
        if self.damping_time is not None:
            h = min(h, 2.0 * self.damping_time)
        return h

    @property
    def key(self) -> str:
        """The law parameter whose time scale is the shorter: ``law.damping`` or
        ``law.stiffness`` (a scene names its key)."""
        if self.damping_time is not None and 2.0 * self.damping_time < self.period / np.pi:
            return "law.damping"
        return "law.stiffness"

    def describe(self) -> str:
        """``law.<parameter> = value (its time scale)``, for messages."""
        if self.key == "law.damping":
            c = f"{self.damping:.3g} N s/m"
            if self.law.dashpot_varies:  # impact's STEP ramp: the value set is the full one
                c = f"{self.damping_set:.3g} N s/m ({self.damping:.3g} at the static penetration)"
            return (f"law.damping = {c} (damping time m/c = {self.damping_time:.2g} s with "
                    f"the effective mass {self.mass:.3g} kg)")
        return (f"law.stiffness = {self.stiffness:.3g} (contact period {self.period:.2g} s "
                f"with the effective mass {self.mass:.3g} kg at {self.load:.3g} N)")


def effective_mass(sysm, cj, q, qd) -> float:
    """Smallest effective mass of a clearance joint's journal against its bearing, kg.

    ``1 / lambda_max(G)`` with ``G`` the 2x2 relative mobility (m/s^2 per N) of the two centres
    under a unit force pair, from the constrained equations of motion at ``(q, qd)``.
    """
    n = sysm.n
    M = sysm.mass_matrix(q)
    _, Cq, _, _ = sysm.constraint_terms(0.0, q, qd)
    A = np.zeros((n + sysm.m, n + sysm.m))
    A[:n, :n] = M
    A[:n, n:] = Cq.T
    A[n:, :n] = Cq
    _, Jj, _ = sysm.frame(cj.journal, cj.journal_frame, q, qd)
    _, Jb, _ = sysm.frame(cj.bearing, cj.bearing_frame, q, qd)
    G = np.zeros((2, 2))
    for k in range(2):
        f = np.zeros(3)
        f[k] = 1.0
        Q = np.zeros(n + sysm.m)
        sysm.add_frame_force(Q[:n], cj.journal, Jj, f)
        sysm.add_frame_force(Q[:n], cj.bearing, Jb, -f)
        qdd = np.linalg.lstsq(A, Q, rcond=None)[0][:n]
        aj = sysm.frame_velocity(cj.journal, Jj, qdd)
        ab = sysm.frame_velocity(cj.bearing, Jb, qdd)
        G[:, k] = (aj - ab)[:2]
    lam = float(np.max(np.linalg.eigvalsh(0.5 * (G + G.T))))
    return 1.0 / lam if lam > 0.0 else float("inf")


def _peak_gas_force(sysm) -> float:
    peak = 0.0
    for load in sysm.loads:
        g = getattr(load, "gas_force", None)
        if callable(g):
            a = np.linspace(0.0, 4.0 * np.pi, 1441)
            peak = max(peak, float(np.max(np.abs([g(x) for x in a]))))
    return peak


def _crank_radius(crank) -> float:
    pts = [np.asarray(crank.local(f)[0], float) for f in crank.frames]
    return max((float(np.hypot(*(a - b)[:2])) for a in pts for b in pts), default=0.0)


def joint_time_scales(mech, low_load: bool = False) -> list[TimeScale]:
    """The time scales of every clearance joint of a mechanism at its initial state.

    ``low_load``: under the inertia load ``m omega**2 r`` alone (without the gas force), the
    smaller load whose static penetration bounds a penetration-dependent dashpot from below
    (:mod:`.budget`)."""
    sysm = mech.system
    if not sysm.clearances:
        return []
    omega = 2.0 * np.pi * mech.revolution_hz
    gas = _peak_gas_force(sysm)
    r = _crank_radius(mech.crank)
    out = []
    for cj in sysm.clearances:
        m = effective_mass(sysm, cj, mech.q0, mech.qd0)
        if not np.isfinite(m):
            continue
        load = max(0.0 if low_load else gas, m * omega**2 * r, 1.0)
        law = cj.law
        with np.errstate(all="ignore"):  # extreme exponents/stiffnesses: no estimate, no error
            k = float(np.float64(law.tangent_stiffness(np.float64(load))))
            c = float(np.float64(law.dashpot(np.float64(load))))
        if not (np.isfinite(k) and k > 0.0 and np.isfinite(c)):
            continue
        out.append(TimeScale(
            joint=cj.name, mass=m, load=load, k_lin=k, period=2.0 * np.pi * np.sqrt(m / k),
            damping=c if c > 0.0 else None, damping_time=m / c if c > 0.0 else None, law=law))
    return out


def estimated_evals(ts: TimeScale, t_end: float, method: str) -> float | None:
    """Right-hand-side evaluations an explicit method needs at step ``ts.step`` over ``t_end``
    s in contact; None for the implicit methods (LSODA, Radau, BDF: not stability-bound)."""
    per = EVALS_PER_STEP.get(method)
    return None if per is None else per * t_end / ts.step


def _allowed(ts: TimeScale, h_needed: float) -> str:
    """The largest value of the responsible key that keeps the step above ``h_needed``."""
    if ts.key == "law.damping":
        # the dashpot at the load scales with the value set (IMPACT's STEP ramp: c_max s(delta))
        scale = ts.damping_set / ts.damping if ts.damping_set else 1.0
        return f"<= {2.0 * ts.mass / h_needed * scale:.3g} N s/m"
    k_lin_max = 4.0 * ts.mass / h_needed**2
    k = ts.law.stiffness_for_tangent(k_lin_max, ts.k_lin)
    if not ts.law.tangent_scales_exactly:  # johnson_cylinder: K_lin ~ K up to a logarithm
        return f"about <= {k:.3g} N/m"
    return f"<= {k:.3g}"


def responsible(scales) -> TimeScale | None:
    """The joint with the shortest stable step (the one that limits an explicit integrator)."""
    return min(scales, key=lambda ts: ts.step, default=None)
