"""The cost of a dynamics run, estimated before it starts: refuse what cannot finish.

An explicit Runge-Kutta method (RK45, DOP853) takes steps no longer than the stiffest time scale
of the model allows (:mod:`.timescales`: ``h = 2 / |lambda|``, inside RK45's stability interval
of about 3.3), and no longer than ``solver.max_step`` anywhere. Three time scales are asked for:

* contact: the contact period ``2 pi sqrt(m / K_lin)`` and the damping time ``m / c`` of each
  clearance joint (its law answers ``K_lin`` and ``c``, :class:`~.laws.NormalLaw`);
* flexible bodies: ``omega_max`` of the stiffest kept elastic mode, step ``2 / omega_max``
  (:func:`.stepbound.stiffest_mode`);
* the smooth part: ``solver.max_step`` (``max_step_deg`` of crank).

The estimate takes the stiffest scale for the **whole run** (the big ends of the four-star and
slider-crank scenes are in contact 40-100 % of the time, and a kept mode bounds the step all the
time), plus the smooth part::

    N = evals_per_step * end_time * (1 / h_stiff + 1 / max_step)

Measured against runs (tests/test_dynamics_refuse.py, docs/guide/run_budget.md) it is within a
factor 3 either way when the step is stability-bound: the error control takes shorter steps than
stability needs through impacts, and longer ones while a joint flies free.

Implicit methods (LSODA, Radau, BDF) are stable on these scales: no estimate (None).

What the estimate cannot see: a run that changes regime on its way. The four-star with
``contact.stiffness`` >= 3e11 N/m^1.5 jams after 0.07-0.1 s: the journal rolls round its bore
without slip (dry whip) under 0.3-0.5 MN, and the Coulomb stiction band then limits the step to
``m v_static / (mu_static F_n)``, about 5e-9 s. Whether a journal sticks is not known before the
run, so that time scale does not enter the estimate; :func:`projection_guard` stops such a run as
soon as its evaluation rate shows it cannot finish (a NumericalError, exit 3), instead of
spending its whole budget.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .timescales import EVALS_PER_STEP, joint_time_scales

#: refuse when the estimate exceeds this multiple of ``solver.max_rhs_evals`` (the estimate's
#: measured spread is a factor 3 either way)
REFUSE_FACTOR = 3.0
#: warn (with the estimated wall time) above this fraction of ``solver.max_rhs_evals``
WARN_FRACTION = 0.2
#: processor time of one right-hand-side evaluation with its share of the solver's step and
#: events, s, measured on the four-star (RK45, 0.2 s): the compiled kernel's evaluation alone
#: 30 us, with scipy's step 60 us; the generic Python path 550-600 us. Measured as processor
#: time on a machine shared by many jobs (wall time there was 8 times longer): the wall-time
#: estimate holds for an idle core. In the compiled RK45 loop (:mod:`..kernel.integrator`) an
#: evaluation with its share of the step costs 11 us (rigid four-star, 142 k evaluations in
#: 1.56 s of processor time) to 24 us (flexible four-star).
COST_PER_EVAL = {"loop": 15e-6, "compiled": 60e-6, "python": 600e-6}
#: a run stops early when its present evaluation rate needs this multiple of the evaluations
#: left of its budget (:func:`projection_guard`)
GUARD_FACTOR = 1.5
#: the early stop judges only after this fraction of ``end_time``, :data:`GUARD_BUDGET_FRACTION`
#: of the budget and :data:`GUARD_MIN_EVALS` evaluations: a run's start-up can be stiff for a
#: while and then relax (an oil film from a centred journal: 5e6 evaluations per simulated
#: second for its first 13 %), and on a small budget the budget itself stops a run soon enough
GUARD_START_FRACTION = 0.1
GUARD_BUDGET_FRACTION = 0.02
GUARD_MIN_EVALS = 1000


@dataclass(frozen=True)
class Stiff:
    """One time scale that bounds an explicit step."""

    key: str        # what to change (law.stiffness, law.damping, flexible.<body>)
    step: float     # largest step it allows, s
    what: str       # what it is, with its numbers, for messages
    scale: object = None  # the TimeScale of :mod:`.timescales` (contact) or None (a mode)

    def advice(self, h_needed: float) -> str:
        """What to change so the step reaches ``h_needed`` s."""
        if self.scale is None:
            return (f"keep fewer modes ({self.key}.n_modes, or cutoff_hz below "
                    f"{2.0 / h_needed / (2.0 * np.pi):.3g} Hz) or use settings.method = 'Radau'")
        from .timescales import _allowed

        return f"{self.key} must be {_allowed(self.scale, h_needed)} for this budget"


@dataclass(frozen=True)
class RunEstimate:
    """The evaluations and wall time a run needs, before it runs (SI units)."""

    method: str
    end_time: float             # s
    evaluations: float | None   # right-hand-side evaluations; None for implicit methods
    stiff: Stiff | None         # the time scale that sets the step (None: the smooth part)
    smooth_evaluations: float   # of the smooth part (solver.max_step)
    cost_per_eval: float        # s

    @property
    def wall_time(self) -> float | None:
        """Estimated wall time, s."""
        return None if self.evaluations is None else self.evaluations * self.cost_per_eval


def _contact_scales(mech) -> list[Stiff]:
    """Contact period and damping time of every clearance joint (:mod:`.timescales`).

    A dashpot that ramps with the penetration (IMPACT's STEP, ``law.dashpot_varies``) is taken
    at the static penetration of the smaller, inertia load ``m omega**2 r`` (a load the joint
    carries through most of its contact, the gas force only near its peak): measured, the dashpot at the larger load of the gas
    force overestimated the evaluations 2-8 times (four-star, ``contact.damping`` = 1e5, 1e6).
    """
    from dataclasses import replace

    out = []
    low = {s.joint: s for s in joint_time_scales(mech, low_load=True)}
    for ts in joint_time_scales(mech):
        lo = low.get(ts.joint)
        if ts.law.dashpot_varies and lo is not None:
            period = replace(ts, damping=None, damping_time=None)  # its contact period alone
            out.append(Stiff(period.key, period.step, f"{period.describe()} at joint "
                             f"{ts.joint!r}", period))
            ts = lo
        out.append(Stiff(ts.key, ts.step, f"{ts.describe()} at joint {ts.joint!r}", ts))
    return out


def _mode_scale(mech) -> Stiff | None:
    """The stiffest kept elastic mode of the flexible bodies: step ``2 / omega_max``."""
    from ..flexible.stepbound import stiffest_mode

    bodies = [b for b in mech.system.bodies if getattr(b, "n_elastic", 0) > 0]
    top = stiffest_mode(bodies)
    if top is None:
        return None
    from ..scene.flexstage import flexible_key  # rod_2 -> dynamics.flexible.rods

    name, hz = top
    return Stiff(flexible_key(name).removeprefix("dynamics."), 2.0 / (2.0 * np.pi * hz),
                 f"the {hz:.4g} Hz mode of {name!r} (kept elastic mode)")


def estimate(mech, t_end: float, settings) -> RunEstimate:
    """Right-hand-side evaluations and wall time of a run of ``mech`` over ``t_end`` s.

    Parameters
    ----------
    mech : Mechanism
    t_end : float
        Simulated time, s.
    settings : SolverSettings
        With its method decided (not ``"auto"``).

    Returns
    -------
    RunEstimate
        ``evaluations`` None for the implicit methods.
    """
    from ..kernel import integrator

    kernel = mech.system.kernel() is not None
    path = ("loop" if integrator.applicable(mech.system, settings.method)
            else "compiled" if kernel else "python")
    cost = COST_PER_EVAL[path]
    per = EVALS_PER_STEP.get(settings.method)
    h_smooth = settings.max_step
    if per is None:
        return RunEstimate(settings.method, t_end, None, None, 0.0, cost)
    scales = _contact_scales(mech)
    mode = _mode_scale(mech)
    if mode is not None:
        scales.append(mode)
    smooth = per * t_end / h_smooth if h_smooth else float(per)

    def count(candidates):
        stiff = min(candidates, key=lambda s: s.step, default=None)
        if stiff is None or (h_smooth and stiff.step >= h_smooth):
            return smooth, None
        return smooth + per * t_end / stiff.step, stiff

    n, stiff = count(scales)
    return RunEstimate(settings.method, t_end, n, stiff, smooth, cost)


def _seconds(s: float) -> str:
    if s < 120.0:
        return f"{s:.2g} s"
    if s < 7200.0:
        return f"{s / 60.0:.2g} min"
    return f"{s / 3600.0:.2g} h"


def check(mech, t_end: float, settings) -> tuple[RunEstimate, list[str]]:
    """Refuse a run that cannot finish within ``settings.max_rhs_evals``; warn when it is long.

    Returns
    -------
    RunEstimate, list of str
        The estimate and the warnings (an estimate above :data:`WARN_FRACTION` of the budget,
        with the estimated wall time).

    Raises
    ------
    ParameterError
        Naming what is responsible (``law.stiffness``, ``law.damping``,
        ``flexible.<body>``) when the estimate exceeds
        :data:`REFUSE_FACTOR` times ``max_rhs_evals``: known from the input alone, before any
        integration, so refused as bad input (a scene relabels it ``dynamics.<key>``).
    """
    from ...errors import ParameterError

    memo_key = (t_end, settings.method, settings.max_rhs_evals, settings.max_step)
    memo = getattr(mech.system, "_budget_checked", None)
    if memo is not None and memo[0] == memo_key:  # checked and warned already (a scene,
        return memo[1], []                          # then simulate(); ensemble members)
    est = estimate(mech, t_end, settings)
    budget = settings.max_rhs_evals
    if est.evaluations is None:
        mech.system._budget_checked = (memo_key, est)
        return est, []
    if est.evaluations > REFUSE_FACTOR * budget and est.stiff is not None:
        stiff, n = est.stiff, est.evaluations
        per = EVALS_PER_STEP[settings.method]
        h_needed = per * t_end / max(budget - est.smooth_evaluations, 1.0)
        raise ParameterError(
            stiff.key,
            f"{stiff.what} limits settings.method = {settings.method!r} to steps of "
            f"{stiff.step:.2g} s: about {n:.3g} right-hand-side evaluations over t_end = "
            f"{t_end:g} s (about {_seconds(n * est.cost_per_eval)}), {n / budget:.3g} times "
            f"settings.max_rhs_evals = {budget}; {stiff.advice(h_needed)} (or raise "
            f"settings.max_rhs_evals, shorten t_end, or use settings.method = 'Radau')")
    warnings = []
    if est.evaluations > WARN_FRACTION * budget:
        s = est.stiff
        why = f"{s.what} limits the step to {s.step:.2g} s" if s else "settings.max_step"
        warnings.append(
            f"dynamics: {why} with settings.method = {settings.method!r}: about "
            f"{est.evaluations:.3g} right-hand-side evaluations ({100 * est.evaluations / budget:.0f} "
            f"% of settings.max_rhs_evals), estimated wall time {_seconds(est.wall_time)}; "
            f"the run may stop at its budget")
    mech.system._budget_checked = (memo_key, est)
    return est, warnings


def regime_note(mean_step: float, scales) -> str:
    """What an early-stopped run says when its steps (``mean_step`` s) are far shorter than the
    contact time scales ``scales`` (:class:`.timescales.TimeScale`) foresaw; else ``""``."""
    from .timescales import responsible

    ts = responsible(scales)
    if ts is None or mean_step > 0.1 * ts.step:
        return ""
    return (f"its steps are {ts.step / mean_step:.0f} times shorter than the contact time "
            f"scales foresee ({ts.step:.2g} s): the run changed regime (e.g. a journal jammed in "
            f"its bore with its friction inside the stiction band, friction.v_static); ")


class Overrun(Exception):
    """Raised by :func:`projection_guard` (``t``: simulated time, ``projected``: evaluations)."""

    def __init__(self, t: float, projected: float, rate: float):
        super().__init__(t, projected, rate)
        self.t, self.projected, self.rate = t, projected, rate


class ProjectionGuard:
    """The early stop of a run whose evaluation rate shows it cannot finish.

    Over every window of simulated time (default ``t_end / 100``) the evaluations per simulated
    second are measured; when that rate, kept over the time left, needs more than
    :data:`GUARD_FACTOR` times the evaluations left of ``max_rhs_evals``, :class:`Overrun` is
    raised, once :data:`GUARD_START_FRACTION` of ``t_end`` has passed and
    :data:`GUARD_BUDGET_FRACTION` of the budget (at least :data:`GUARD_MIN_EVALS`) is spent. A
    burst of short steps through one impact lasts far less than a window (the four-star's
    contacts last 0.1-1 ms against a 5 ms window), so it does not stop a run; a regime that
    holds for a window (a jammed journal, a stiff dashpot in long contact) does.

    The one rule for both integration paths: :func:`projection_guard` asks it at every
    evaluation of ``solve_ivp``'s right-hand side, the compiled loop
    (:mod:`~..kernel.integrator`) at every return to Python (every 1/200 of the run at most).

    Parameters
    ----------
    t_end : float
        Simulated time of the run, s.
    max_rhs_evals : int
        The run's budget of right-hand-side evaluations.
    window : float or None
        Simulated time over which the rate is measured, s (default ``t_end / 100``).
    """

    def __init__(self, t_end: float, max_rhs_evals: int, window: float | None = None):
        self.t_end, self.max_rhs_evals = t_end, max_rhs_evals
        self.window = window or t_end / 100.0
        self.start = max(GUARD_BUDGET_FRACTION * max_rhs_evals, GUARD_MIN_EVALS)
        self.t0, self.n0 = 0.0, 0

    def check(self, t: float, n: int) -> None:
        """Judge the run at simulated time ``t`` (s) after ``n`` evaluations.

        Raises
        ------
        Overrun
            When the present rate needs more than :data:`GUARD_FACTOR` times the evaluations
            left.
        """
        if t - self.t0 < self.window:
            return
        if n < self.start or t < GUARD_START_FRACTION * self.t_end:  # too early to judge
            self.t0, self.n0 = t, n
            return
        rate = (n - self.n0) / (t - self.t0)
        need = rate * (self.t_end - t)
        if need > GUARD_FACTOR * max(self.max_rhs_evals - n, 0):
            raise Overrun(t, n + need, rate)
        self.t0, self.n0 = t, n


def projection_guard(fun, t_end: float, max_rhs_evals: int, window: float | None = None):
    """``fun`` that stops a run whose evaluation rate shows it cannot finish: its
    :class:`ProjectionGuard` judges every evaluation (raises :class:`Overrun`)."""
    guard = ProjectionGuard(t_end, max_rhs_evals, window)
    count = [0]

    def guarded(t, y):
        count[0] += 1
        guard.check(t, count[0])
        return fun(t, y)

    return guarded
