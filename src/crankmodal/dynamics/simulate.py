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

from ..errors import NumericalError
from ..progress import bar
from .system import N_AUX, BudgetExceeded, NonFinite


@dataclass
class SolverSettings:
    """Integration settings.

    Parameters
    ----------
    method : str
        ``solve_ivp`` method: ``RK45`` (default: impacts limit the step through the error
        control long before stiffness does; measured 1.5-5x fewer evaluations than LSODA and
        Radau for contact stiffness 1e10..1e13), ``LSODA``, ``Radau``, ``BDF``, ``DOP853``.
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
        of a failed run then names the key that limits the step (``contact.damping`` or
        ``contact.stiffness``).
    """

    method: str = "RK45"
    rtol: float = 1e-6
    atol: float = 1e-9
    velocity_scale: float = 1000.0
    max_step: float | None = None
    max_rhs_evals: int = 2_000_000
    time_scales: tuple = ()


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
        from .stepbound import stiffest_mode

        mode = stiffest_mode([b for b in sysm.bodies if getattr(b, "n_elastic", 0) > 0])
        if mode is None:
            return "tighten nothing: ideal joints only; check the speed and masses"
        body, hz = mode
        change = ("raise solver.max_rhs_evals" if method in ("Radau", "BDF")
                  else "use solver.method = 'Radau'")
        return (f"ideal joints only: the stiffest kept mode ({hz:.4g} Hz of {body!r}) is the "
                f"stiff part: {change} or keep fewer modes of {body!r} (n_modes / cutoff_hz of "
                f"its [dynamics.flexible] table)")
    other = _OTHER_METHODS.get(method, "'Radau'")
    if settings is not None and settings.time_scales:
        from .timescales import responsible

        ts = responsible(settings.time_scales)
        return (f"joint {ts.joint!r} limits the step to {ts.step:.2g} s through "
                f"{ts.describe()}: lower {ts.key}, use solver.method = {other}, or raise "
                f"solver.max_rhs_evals")
    cj = sysm.clearances[0]
    K = cj.law_params.get("stiffness", float("nan"))
    return (f"the contact of joint {cj.name!r} is the stiff part (contact.stiffness = {K:.3g}, "
            f"clearance = {cj.clearance:.3g} m) or its friction near stiction: lower "
            f"contact.stiffness, use solver.method = {other}, or raise solver.max_rhs_evals")


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


def integrate(sysm, q0, qd0, t_end, t_out, settings: SolverSettings) -> Integration:
    """Integrate a :class:`~.system.Multibody` from a consistent state.

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

    Raises
    ------
    NumericalError
        If the budget of right-hand-side evaluations is exceeded, the solver fails, or a
        non-finite value appears; the message names the stiff parameter.
    """
    from scipy.integrate import solve_ivp

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
    if own_steps or (t_out.size and t_out[0] <= 0.0):
        ts.append(np.array([0.0]))
        ys.append(y[:, None].copy())
    pbar = bar(total=t_end, desc="dynamics", unit="s",
               bar_format="{desc}: {n:.3g}/{total:.3g} s simulated |{bar}| "
                          "[{elapsed}<{remaining}, {rate_noinv_fmt}]")
    # the integrator's contact memory: per clearance joint the impact velocity of its contact
    # in progress (restitution laws; constant between the restarts at onsets), passed to the
    # right-hand side, not stored in the joints
    v_impact = np.array([cj.v_impact_min for cj in sysm.clearances], float)

    def rhs(t, y):
        return sysm.rhs(t, y, v_impact)

    # a disabled bar (not a terminal, --quiet) leaves the right-hand side untouched
    fun = rhs if pbar.disable else _progress_rhs(rhs, pbar)
    while t < t_end:
        evs, tags = _events(sysm, in_contact, memory)
        te = None if own_steps else t_out[(t_out > t) & (t_out <= t_end)]
        try:
            with warnings.catch_warnings():
                # the work integrals have zero Jacobian columns; scipy's finite-difference
                # step growth overflows harmlessly on them
                warnings.filterwarnings("ignore", category=RuntimeWarning, module="scipy")
                sol = solve_ivp(fun, (t, t_end), y, method=settings.method, t_eval=te,
                                events=evs or None, rtol=settings.rtol, atol=atol, **kw)
        except BudgetExceeded as exc:
            pbar.close()
            raise NumericalError(
                f"integration stopped at t = {exc.t:.6g} s after {settings.max_rhs_evals} "
                f"right-hand-side evaluations; {_stiffness_advice(sysm, settings)}") from None
        except NonFinite as exc:
            pbar.close()
            raise NumericalError(
                f"non-finite accelerations at t = {exc.t:.6g} s; {_stiffness_advice(sysm, settings)}"
            ) from None
        except np.linalg.LinAlgError:
            pbar.close()
            raise NumericalError(
                f"singular constraint Jacobian near t = {t:.6g} s: the mechanism passes a "
                "dead point; check link lengths and the assembly branch") from None
        if sol.status == -1:
            pbar.close()
            raise NumericalError(f"integrator failed at t = {sol.t[-1]:.6g} s ({sol.message}); "
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
        fired = None
        for k, (j, kind) in enumerate(tags):
            for te_k, ye_k in zip(sol.t_events[k], sol.y_events[k]):
                if memory and te_k <= t:
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
        else:
            t = t_end
        if t > pbar.n:
            pbar.update(t - pbar.n)
    pbar.close()
    tt = np.concatenate(ts) if ts else np.zeros(0)
    yy = np.concatenate(ys, axis=1) if ys else np.zeros((2 * n + N_AUX, 0))
    return Integration(t=tt, y=yy, onsets=onsets, separations=separations, peaks=peaks,
                       nfev=sysm.nfev, n_steps=n_steps, wall_time=time.perf_counter() - t0)
