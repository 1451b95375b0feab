"""Time integration: error-controlled stiff/non-stiff solvers with contact-onset events.

Contact onset and separation of every clearance joint are located as events (zero crossings of
the penetration). Laws whose damping depends on the impact velocity (Hunt-Crossley family)
restart the integrator at each onset and separation so the impact velocity is a constant of the
contact and the right-hand side stays a smooth function of the state; the other laws only record
the events. A step limit of a fraction of a crank revolution keeps a large free-flight step from
jumping over a whole impact.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ...errors import NumericalError
from ...progress import bar
from ..model.system import N_AUX, BudgetExceeded, Multibody, NonFinite


@dataclass
class SolverSettings:
    """Integration settings.

    Parameters
    ----------
    method : str
        ``auto`` (default, as in scenes: chosen by :func:`auto_method` for the mechanism
        :func:`~.analysis.simulate` or :func:`integrate` runs) or a ``solve_ivp`` method: ``RK45`` (impacts limit
        the step through the error control long before stiffness does; measured 1.5-5x fewer
        evaluations than LSODA and Radau for contact stiffness 1e10..1e13), ``LSODA``,
        ``Radau``, ``BDF``, ``DOP853``.
    rtol : float
        Relative tolerance.
    atol : float
        Absolute tolerance on positions, m (velocities get ``atol`` times ``velocity_scale``).
    velocity_scale : float
        1/s; absolute tolerance of velocities = ``atol * velocity_scale``.
    max_step : float or None
        Largest step, s.
    max_rhs_evals : int
        Budget of right-hand-side evaluations; beyond it the run stops with a NumericalError.
    time_scales : tuple of TimeScale
        The clearance joints' contact time scales (:mod:`.timescales`), if estimated: the advice
        of a failed run then names the law parameter that limits the step (``law.damping`` or
        ``law.stiffness``).

    Raises
    ------
    ParameterError
        Naming the field out of its range (the ``[dynamics.solver]`` keys' rules: ``method``
        one of :data:`~.rules.METHODS`, ``0 < rtol < 1``, ``atol > 0``,
        ``max_rhs_evals >= 1``; ``velocity_scale > 0``, ``max_step`` None or ``> 0`` s).
    """

    method: str = "auto"
    rtol: float = 1e-6
    atol: float = 1e-9
    velocity_scale: float = 1000.0
    max_step: float | None = None
    max_rhs_evals: int = 2_000_000
    time_scales: tuple = ()

    def __post_init__(self):
        from ... import arguments as arg
        from .rules import METHODS, SOLVER

        arg.one_of("method", self.method, METHODS)
        self.rtol = arg.check("rtol", self.rtol, SOLVER["rtol"])
        self.atol = arg.check("atol", self.atol, SOLVER["atol"])
        self.velocity_scale = arg.number("velocity_scale", self.velocity_scale, gt=0.0)
        self.max_step = arg.number("max_step", self.max_step, gt=0.0, optional=True)
        self.max_rhs_evals = arg.check("max_rhs_evals", self.max_rhs_evals,
                                       SOLVER["max_rhs_evals"])
        if not isinstance(self.time_scales, tuple):
            self.time_scales = tuple(self.time_scales)


def auto_method(joints, omega: float, flexible: bool) -> str:
    """The integration method of ``method = "auto"`` (scenes and :func:`~.analysis.simulate`).

    RK45, the fastest measured, also for stiff contact; LSODA when a joint's friction sticks
    (slow sliding) or with an oil film; with flexible bodies Radau on ideal joints or with an
    oil film.

    Parameters
    ----------
    joints : sequence of (float, str, float, bool)
        Per clearance joint: journal radius (m), friction law name (``"none"`` without
        friction), the friction law's transition velocity ``v_dynamic`` (m/s), and whether it is
        lubricated (a viscosity given).
    omega : float
        Crank speed, rad/s.
    flexible : bool
        The mechanism has flexible bodies with elastic modes.

    Returns
    -------
    str
        A ``solve_ivp`` method name.
    """
    joints = list(joints)
    method = "RK45"
    r_max = max((j[0] for j in joints), default=0.0)
    v_dyn = [j[2] for j in joints if j[1] != "none"]
    # near stiction the friction law's slope mu_s / v_s makes the problem stiff when the
    # journal slides slowly at the working speed (a brief start-up ramp is cheaper in RK45:
    # measured 10 k against 51 k evaluations for the four-star's 0.1 s ramp)
    if v_dyn and r_max * abs(omega) < 10.0 * max(v_dyn):
        method = "LSODA"
    # an oil film is stiff near the wall ((1 - eps^2)^-5/2): measured 0.8 s LSODA, minutes RK45
    lubricated = any(j[3] for j in joints)
    if lubricated:
        method = "LSODA"
    # flexible bodies on ideal joints: their stiffest modes (kHz) bound an explicit step by
    # stability, which A-stable Radau IIA steps over. Measured (benchmarks/README.md):
    # slider-crank, crank 20 + rod 14 modes to 22.6 kHz, 0.1 s: Radau 19 k evaluations,
    # 0.10 simulated s per wall s, against RK45 59 k, 0.038, and Radau nearer a tight
    # reference (4e-4 against 2e-3 of the peak). With impacts RK45 stays: four-star with a
    # flexible crank and rods and one clearance, 0.3 s: RK45 64 k evaluations in 4.9 s,
    # Radau 236 k in 128 s (every contact onset restarts it with a new Jacobian).
    # with an oil film too (measured: the loom's coupler with the seed's lubricated C
    # joint, LSODA stalled at 0.17 of 0.4 s after 2 M evaluations, Radau ran it in 95 k;
    # the four-star with a lubricated big end and flexible rods, Radau 2.5 k evaluations in
    # 2.2 s against LSODA's 9.1 k in 6.6 s)
    if flexible and (not joints or lubricated):
        method = "Radau"
    return method


def system_method(sysm, omega: float | None = None, qd0=None) -> str:
    """:func:`auto_method` for a built :class:`~.system.Multibody` at crank speed ``omega``
    (rad/s): its clearance joints and whether a body keeps elastic modes. Without ``omega``:
    the speed of its angle drive, else the fastest body rotation in ``qd0`` (rad/s)."""
    if omega is None:
        from ..model.joints import AngleDrive

        drives = [abs(c.profile.omega) for c in sysm.constraints if isinstance(c, AngleDrive)]
        spins = [abs(float(qd0[sysm.slices[id(b)].start + 2])) for b in sysm.bodies] \
            if qd0 is not None else []
        omega = max(drives or spins or [0.0])
    joints = [(cj.journal_radius, cj.friction.name,
               float(getattr(cj.friction, "v_dynamic", 0.0)), cj.viscosity is not None)
              for cj in sysm.clearances]
    flexible = any(getattr(b, "n_elastic", 0) > 0 for b in sysm.bodies)
    return auto_method(joints, omega, flexible)


@dataclass
class Integration:
    """Raw integration output: states at the output times and the contact events."""

    t: np.ndarray
    y: np.ndarray
    onsets: list = field(default_factory=list)       # per clearance joint: [(t, v_impact)]
    separations: list = field(default_factory=list)  # per clearance joint: [t]
    peaks: list = field(default_factory=list)        # per clearance joint: [(t, state)] at the
    #                                                  deepest penetration of each contact
    nfev: int = 0
    n_steps: int = 0
    wall_time: float = 0.0


def _events(sysm, in_contact, memory):
    """Event functions and their tags ``(joint, kind)``: contact onset (``on``) and separation
    (``off``) as zero crossings of the penetration, and the deepest penetration of a contact
    (``peak``: the penetration rate falling through zero) — the instant of the impact's peak
    force, which output samples a few contact durations apart would miss."""
    n = sysm.n
    evs, tags = [], []
    for j in range(len(sysm.clearances)):
        for kind, direction in (("on", 1.0), ("off", -1.0)):
            if memory and in_contact[j] == (kind == "on"):
                continue

            def g(t, y, j=j):
                return sysm.gap(j, y[:n])

            g.direction = direction
            g.terminal = memory
            evs.append(g)
            tags.append((j, kind))

        def rate(t, y, j=j):
            return sysm.penetration_rate(j, y[:n], y[n:2 * n])

        rate.direction = -1.0
        rate.terminal = False
        evs.append(rate)
        tags.append((j, "peak"))
    return evs, tags


#: what to try instead of each method on a stiff run (never the method in use)
_OTHER_METHODS = {"RK45": "'LSODA' or 'Radau'", "DOP853": "'LSODA' or 'Radau'",
                  "LSODA": "'Radau'", "Radau": "'LSODA' or 'BDF'", "BDF": "'Radau'"}


def _stiffness_advice(sysm, settings: SolverSettings | None = None) -> str:
    """What to change after a failed or over-budget run: the key that limits the step (from
    ``settings.time_scales``; the stiffness when not estimated) and a method other than the
    one in use. With ideal joints only: the stiffest kept elastic mode of the flexible bodies
    (Radau, or fewer modes), else the speed and masses."""
    method = settings.method if settings is not None else "RK45"
    if not sysm.clearances:
        from ..flexible.stepbound import stiffest_mode

        mode = stiffest_mode([b for b in sysm.bodies if getattr(b, "n_elastic", 0) > 0])
        if mode is None:
            return "tighten nothing: ideal joints only; check the speed and masses"
        body, hz = mode
        change = ("raise settings.max_rhs_evals" if method in ("Radau", "BDF")
                  else "use settings.method = 'Radau'")
        return (f"ideal joints only: the stiffest kept mode ({hz:.4g} Hz of {body!r}) is the "
                f"stiff part: {change} or keep fewer modes of {body!r} (n_modes / cutoff_hz of "
                f"its [dynamics.flexible] table)")
    other = _OTHER_METHODS.get(method, "'Radau'")
    if settings is not None and settings.time_scales:
        from .timescales import responsible

        ts = responsible(settings.time_scales)
        return (f"joint {ts.joint!r} limits the step to {ts.step:.2g} s through "
                f"{ts.describe()}: lower {ts.key}, use settings.method = {other}, or raise "
                f"settings.max_rhs_evals")
    cj = sysm.clearances[0]
    K = getattr(cj.law, "stiffness", float("nan"))
    return (f"the contact of joint {cj.name!r} is the stiff part (law.stiffness = {K:.3g}, "
            f"clearance = {cj.clearance:.3g} m) or its friction near stiction: lower "
            f"law.stiffness, use settings.method = {other}, or raise settings.max_rhs_evals")


def _per_step(settings) -> float:
    """Right-hand-side evaluations per step of ``settings.method`` (1 for the implicit ones)."""
    from .timescales import EVALS_PER_STEP

    return float(EVALS_PER_STEP.get(settings.method, 1))


def _progress_rhs(rhs, pbar):
    """``rhs`` that advances ``pbar`` to the simulated time reached, at most every 0.1 s of
    wall time (one clock read per evaluation)."""
    state = {"next": 0.0}

    def fun(t, y):
        now = time.perf_counter()
        if now >= state["next"]:
            state["next"] = now + 0.1
            if t > pbar.n:
                pbar.update(t - pbar.n)
        return rhs(t, y)

    return fun


def _failure(exc, sysm, settings, t: float) -> NumericalError:
    """The NumericalError of a stopped run (both paths): budget, early stop, non-finite
    accelerations, a singular matrix (near ``t`` s, or the time the exception carries), a step
    below the floating-point spacing, a contact event firing again at its restart point."""
    from ..kernel.integrator import EventAgain, StepFailed
    from .budget import Overrun, regime_note

    advice = _stiffness_advice(sysm, settings)
    if isinstance(exc, BudgetExceeded):
        return NumericalError(
            f"integration stopped at t = {exc.t:.6g} s after {settings.max_rhs_evals} "
            f"right-hand-side evaluations; {advice}")
    if isinstance(exc, Overrun):
        return NumericalError(
            f"integration stopped at t = {exc.t:.6g} s after {sysm.nfev} right-hand-side "
            f"evaluations: at its present {exc.rate:.3g} per simulated second (mean step "
            f"{_per_step(settings) / exc.rate:.2g} s) the run needs about {exc.projected:.3g}, "
            f"over settings.max_rhs_evals = {settings.max_rhs_evals}; "
            f"{regime_note(_per_step(settings) / exc.rate, settings.time_scales)}{advice}")
    if isinstance(exc, NonFinite):
        return NumericalError(f"non-finite accelerations at t = {exc.t:.6g} s; {advice}")
    if isinstance(exc, np.linalg.LinAlgError):
        return NumericalError(
            f"singular constraint Jacobian near t = {getattr(exc, 't', t):.6g} s: the mechanism "
            "passes a dead point; check link lengths and the assembly branch")
    if isinstance(exc, StepFailed):
        return NumericalError(
            f"integrator failed at t = {exc.t:.6g} s (Required step size is less than spacing "
            f"between numbers.); {advice}")
    if isinstance(exc, EventAgain):
        return NumericalError(
            f"integration stopped at t = {exc.t:.6g} s: a contact event fired again at the "
            f"point the integration restarted from; {advice}")
    raise TypeError(f"not a run failure: {exc!r}")


def integrate(sysm, q0, qd0, t_end, t_out, settings: SolverSettings,
              compiled_loop: bool = True) -> Integration:
    """Integrate a :class:`~.system.Multibody` from a consistent state.

    RK45 on a system whose whole right-hand side is compiled runs in the compiled integrator
    loop (:mod:`~..kernel.integrator`: SciPy's RK45 and its event location, inside Numba);
    every other method and system runs ``scipy.integrate.solve_ivp``.

    Parameters
    ----------
    sysm : Multibody
    q0, qd0 : ndarray
        Consistent initial positions and velocities.
    t_end : float
        s.
    t_out : ndarray or None
        Output times in ``[0, t_end]``, s; None returns the solver's own steps (then
        ``n_steps`` counts the accepted steps).
    settings : SolverSettings
    compiled_loop : bool
        False keeps ``solve_ivp`` for RK45 too (the reference of the compiled loop's tests).

    Raises
    ------
    ParameterError
        Naming ``sysm``, ``q0``, ``qd0`` (not ``sysm.n`` finite numbers), ``t_end``, ``t_out``
        (negative, or not strictly increasing) or ``settings``.
    NumericalError
        If the budget of right-hand-side evaluations is exceeded, the solver fails, or a
        non-finite value appears; the message names the stiff parameter.
    """
    from scipy.integrate import solve_ivp

    from ... import arguments as arg

    arg.instance("settings", settings, SolverSettings, "a SolverSettings")
    arg.instance("sysm", sysm, Multibody, "a Multibody (mech.system)")
    q0 = np.asarray(arg.numbers("q0", np.ravel(q0), length=sysm.n), float)
    qd0 = np.asarray(arg.numbers("qd0", np.ravel(qd0), length=sysm.n), float)
    t_end = arg.number("t_end", t_end, gt=0.0)
    if t_out is not None:
        t_out = np.asarray(arg.numbers("t_out", np.ravel(t_out), ge=0.0), float)
        if np.any(np.diff(t_out) <= 0.0):  # both paths sample the steps in order
            from ...errors import ParameterError

            raise ParameterError("t_out", "must be strictly increasing times, s")
    if settings.method == "auto":  # simulate() decides it at the mechanism's speed already
        from dataclasses import replace

        settings = replace(settings, method=system_method(sysm, qd0=qd0))
    n = sysm.n
    y = np.concatenate([q0, qd0, np.zeros(N_AUX)])
    atol = np.concatenate([np.full(n, settings.atol), np.full(n, settings.atol * settings.velocity_scale),
                           np.full(N_AUX, 1e-3)])
    memory = any(cj.needs_memory for cj in sysm.clearances)
    in_contact = [sysm.gap(j, q0) > 0.0 for j in range(len(sysm.clearances))]
    onsets = [[] for _ in sysm.clearances]
    separations = [[] for _ in sysm.clearances]
    peaks = [[] for _ in sysm.clearances]
    ts, ys = [], []
    t = 0.0
    own_steps = t_out is None
    t_out = np.zeros(0) if own_steps else np.asarray(t_out, float)
    sysm.nfev, sysm.max_nfev = 0, settings.max_rhs_evals
    n_steps = 0
    t0 = time.perf_counter()
    kw = {} if settings.max_step is None else {"max_step": settings.max_step}
    stalled = 0  # restarts in a row that made no progress (grazes)
    if own_steps or (t_out.size and t_out[0] <= 0.0):
        ts.append(np.array([0.0]))
        ys.append(y[:, None].copy())
    pbar = bar(total=t_end, desc="dynamics", unit="s",
               bar_format="{desc}: {n:.3g}/{total:.3g} s simulated |{bar}| "
                          "[{elapsed}<{remaining}, {rate_noinv_fmt}]")
    from .budget import Overrun, ProjectionGuard

    if compiled_loop:
        from ..kernel import integrator

        if integrator.applicable(sysm, settings.method):
            try:
                tt, yy, onsets, separations, peaks, _, n_steps = integrator.run(
                    sysm, y, t_end, None if own_steps else t_out[(t_out > 0.0) & (t_out <= t_end)],
                    settings, atol, None if pbar.disable else pbar,
                    ProjectionGuard(t_end, settings.max_rhs_evals))
            except (BudgetExceeded, NonFinite, np.linalg.LinAlgError, integrator.StepFailed,
                    integrator.EventAgain, Overrun) as exc:
                pbar.close()
                raise _failure(exc, sysm, settings, 0.0) from None
            pbar.close()
            ts.append(tt)
            ys.append(yy)
            return Integration(t=np.concatenate(ts), y=np.concatenate(ys, axis=1),
                               onsets=onsets, separations=separations, peaks=peaks,
                               nfev=sysm.nfev, n_steps=n_steps,
                               wall_time=time.perf_counter() - t0)
    # the integrator's contact memory: per clearance joint the impact velocity of its contact
    # in progress (restitution laws; constant between the restarts at onsets), passed to the
    # right-hand side, not stored in the joints
    v_impact = np.array([cj.v_impact_min for cj in sysm.clearances], float)

    def rhs(t, y):
        return sysm.rhs(t, y, v_impact)

    # a disabled bar (not a terminal, --quiet) leaves the right-hand side untouched
    fun = rhs if pbar.disable else _progress_rhs(rhs, pbar)
    from .budget import Overrun, projection_guard  # stop what cannot finish

    fun = projection_guard(fun, t_end, settings.max_rhs_evals)
    from ..kernel.implicit import solver_options  # Radau compiled; BDF, LSODA: the Jacobian

    stiff = solver_options(sysm, settings.method, v_impact, atol, settings.rtol)
    method = stiff.pop("method", settings.method)
    kw.update(stiff)
    while t < t_end:
        evs, tags = _events(sysm, in_contact, memory)
        te = None if own_steps else t_out[(t_out > t) & (t_out <= t_end)]
        try:
            with warnings.catch_warnings():
                # the work integrals have zero Jacobian columns; scipy's finite-difference
                # step growth overflows harmlessly on them
                warnings.filterwarnings("ignore", category=RuntimeWarning, module="scipy")
                sol = solve_ivp(fun, (t, t_end), y, method=method, t_eval=te,
                                events=evs or None, rtol=settings.rtol, atol=atol, **kw)
        except (BudgetExceeded, Overrun, NonFinite, np.linalg.LinAlgError) as exc:
            pbar.close()
            raise _failure(exc, sysm, settings, t) from None
        if sol.status == -1:
            pbar.close()
            # with t_eval, sol.t holds only the output times reached: none when it failed
            # before the first one, so the failure time is that of the restart point then
            t_fail = sol.t[-1] if len(sol.t) else t
            raise NumericalError(f"integrator failed at t = {t_fail:.6g} s ({sol.message}); "
                                 f"{_stiffness_advice(sysm, settings)}")
        st = np.asarray(sol.t, float)
        sy = np.asarray(sol.y, float).reshape(y.size, -1)
        if own_steps:
            n_steps += st.size - 1
            st, sy = st[1:], sy[:, 1:]
        if st.size:
            ts.append(st)
            ys.append(sy)
        t_stop = t_end
        fired = grazed = None
        for k, (j, kind) in enumerate(tags):
            for te_k, ye_k in zip(sol.t_events[k], sol.y_events[k]):
                if memory and te_k <= t:
                    if kind != "peak":
                        grazed = (j, kind)  # fired again where the integration restarted
                    continue
                if kind == "peak":  # also fires at the widest free flight: keep contacts only
                    if sysm.gap(j, ye_k[:n]) > 0.0:
                        peaks[j].append((float(te_k), np.array(ye_k, float)))
                    continue
                if kind == "on":
                    v = sysm.penetration_rate(j, ye_k[:n], ye_k[n:2 * n])
                    onsets[j].append((float(te_k), float(v)))
                else:
                    separations[j].append(float(te_k))
                if memory and te_k < t_stop:
                    t_stop, fired = te_k, (j, kind, ye_k)
        if sol.status == 1 and fired is not None:
            j, kind, ye = fired
            in_contact[j] = kind == "on"
            if kind == "on":
                v_impact[j] = max(onsets[j][-1][1], sysm.clearances[j].v_impact_min)
            t, y = float(t_stop), np.array(ye, float)
            stalled = 0
        elif sol.status == 1 and grazed is not None and stalled < 4:
            # a graze: the contact that began at the restart point ended there too (or the
            # reverse), within the event location's resolution; the joint takes the state the
            # event says and the integration goes on from the same point (finishing here
            # returned a history cut short without a word: 0.091 of 0.3 s)
            j, kind = grazed
            in_contact[j] = kind == "on"
            stalled += 1
        elif sol.status == 1:
            # a terminal contact event at the restart point itself, skipped above: finishing
            # here returned a history cut short without a word (seen: 0.091 of 0.3 s)
            pbar.close()
            from ..kernel.integrator import EventAgain

            raise _failure(EventAgain(t), sysm, settings, t)
        else:
            t = t_end
        if t > pbar.n:
            pbar.update(t - pbar.n)
    pbar.close()
    tt = np.concatenate(ts) if ts else np.zeros(0)
    yy = np.concatenate(ys, axis=1) if ys else np.zeros((2 * n + N_AUX, 0))
    return Integration(t=tt, y=yy, onsets=onsets, separations=separations, peaks=peaks,
                       nfev=sysm.nfev, n_steps=n_steps, wall_time=time.perf_counter() - t0)
