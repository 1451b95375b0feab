"""What bounds an explicit integrator's step when flexible bodies ride along.

An explicit Runge–Kutta method is stable on a lightly damped mode of angular frequency ``ω``
only while ``ω h`` stays inside its stability region on the imaginary axis (about 3.3 for
Dormand–Prince 5(4), RK45; about 4.6 for DOP853): a kept elastic mode of tens of kHz bounds the
step to microseconds, whatever the tolerance. ``solver.method = auto`` avoids this on ideal
joints (Radau, A-stable); with clearance joints RK45 stays (measured faster despite it, see
README "Flexible bodies"). :func:`step_bound` says after a run whether the stiffest kept mode
set the step, so a slow flexible run is never slow silently.
"""

from __future__ import annotations

import numpy as np

from ..run.timescales import EVALS_PER_STEP  # evaluations per accepted step (FSAL counted once)

#: ``ω h`` above which the step counts as bound by the mode (the stability limit of RK45 is
#: about 3.3 on the imaginary axis; its controller keeps the mean step near half of it: 1.5 on
#: the benchmark slider-crank's 22.6 kHz mode)
BOUND_OMEGA_H = 0.5


def stiffest_mode(bodies) -> tuple[str, float] | None:
    """``(body name, Hz)`` of the highest kept elastic mode of the flexible ``bodies``, or None."""
    best = None
    for b in bodies:
        f = np.asarray(b.frequencies_hz[:b.n_elastic], float)
        if f.size and (best is None or f.max() > best[1]):
            best = (b.name, float(f.max()))
    return best


def step_bound(bodies, method: str, t_end: float, nfev: int, key_of=None) -> dict | None:
    """Whether the stiffest kept mode bounded an explicit method's steps in a run.

    Parameters
    ----------
    bodies : list of FlexibleBody
    method : str
        The ``solve_ivp`` method that ran.
    t_end : float
        Simulated time, s.
    nfev : int
        Right-hand-side evaluations of the run.
    key_of : callable, optional
        ``key_of(body_name) -> scene key`` for the advice (e.g. ``dynamics.flexible.crank``).

    Returns
    -------
    dict or None
        None without elastic modes. Otherwise ``body``, ``frequency_hz``, ``method``, for an
        explicit method ``mean_step_s`` (``t_end`` over the steps implied by ``nfev``),
        ``omega_h`` and ``bound`` (True when ``ω h`` of the mean step reaches
        :data:`BOUND_OMEGA_H`), and ``advice`` when bound.
    """
    top = stiffest_mode(bodies)
    if top is None:
        return None
    name, f = top
    out = {"body": name, "frequency_hz": f, "method": method}
    per_step = EVALS_PER_STEP.get(method)
    if per_step is None or nfev <= 0:  # implicit: stable on the mode, steps set by accuracy
        out["bound"] = False
        return out
    h = t_end * per_step / nfev
    wh = 2.0 * np.pi * f * h
    out.update(mean_step_s=h, omega_h=wh, bound=bool(wh >= BOUND_OMEGA_H))
    if out["bound"]:
        key = key_of(name) if key_of else name
        out["advice"] = (f"{method} stepped {h:.2g} s on average: the {f:.4g} Hz mode of "
                         f"{name!r} bounds an explicit step (omega h = {wh:.2f}); fewer modes "
                         f"({key}.n_modes or cutoff_hz) run faster; on ideal joints "
                         f"solver.method = 'Radau' (what auto takes there) steps over it")
    return out
