"""Running a mechanism: simulate with checks, and the error-against-run-time study."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ...errors import NumericalError
from ..results.history import History, record
from ..results.signals import order_amplitudes
from ..results.stats import REL_TOL, headline, statistics
from .integrate import SolverSettings, integrate


def output_times(t_end: float, output_step: float) -> np.ndarray:
    """Uniform output times ``0, dt, ..., t_end`` (s)."""
    k = round(t_end / output_step)
    return np.linspace(0.0, k * output_step, k + 1)


#: floats held per output sample, per coordinate of the integrator's state (``2 n + N_AUX``):
#: the solver's output and its concatenated copy (2), and the history recorded from it, which
#: measured 1.3-1.7 per state coordinate (32-41 floats against 24-36 for a slider-crank, a
#: two-cylinder train and a clearance joint), bounded here by 2
FLOATS_PER_STATE_SAMPLE = 4


def check_output(sysm, t_end: float, output_step: float) -> int:
    """Refuse a run whose output samples would not fit: more than the scene limit
    (:data:`~.rules.MAX_OUTPUT_SAMPLES`) or more memory than the machine has.

    Returns
    -------
    int
        The number of output samples.

    Raises
    ------
    ParameterError
        Naming ``output_step``, with the samples, the memory estimate and the smallest step
        that fits.
    """
    from ...errors import ParameterError
    from ...fem.memory import available_bytes
    from ..model.system import N_AUX
    from .rules import MAX_OUTPUT_SAMPLES

    samples = t_end / output_step + 1.0
    per_sample = 8.0 * FLOATS_PER_STATE_SAMPLE * (2 * sysm.n + N_AUX)
    avail = available_bytes()
    limit = float(MAX_OUTPUT_SAMPLES)
    reason = f"crankmodal's limit of {MAX_OUTPUT_SAMPLES:.0e} samples"
    if avail and 0.5 * avail / per_sample < limit:
        limit, reason = 0.5 * avail / per_sample, f"half the {avail / 1e9:.3g} GB available"
    if samples > limit:
        raise ParameterError("output_step", f"{output_step:g} s makes {samples:.3g} output "
                             f"samples of {t_end:g} s (about {samples * per_sample / 1e9:.3g} "
                             f"GB at {per_sample:.0f} bytes each), over {reason}; use "
                             f"output_step >= {t_end / (limit - 1.0):.3g} s")
    return round(samples)


def _check_run(mech, t_end, output_step, settings, energy_tolerance, start):
    """The arguments of :func:`simulate`, by the run rules (:mod:`.rules`, which the
    ``[dynamics]`` keys share)."""
    from ... import arguments as arg
    from ..model.mechanisms import Mechanism
    from .rules import RUN

    arg.instance("mech", mech, Mechanism, "a Mechanism (crank_train, four_bar)")
    t_end = arg.check("t_end", t_end, RUN["end_time"])
    output_step = arg.check("output_step", output_step, RUN["output_step"])
    if output_step > t_end:
        from ...errors import ParameterError

        raise ParameterError("output_step", f"must be <= t_end ({t_end:g} s), got "
                             f"{output_step:g}")
    if settings is not None:
        arg.instance("settings", settings, SolverSettings, "a SolverSettings or None")
    energy_tolerance = arg.check("energy_tolerance", energy_tolerance,
                                 RUN["energy_tolerance"], optional=True)
    arg.check("start", start, RUN["start"], optional=True)
    return t_end, output_step, energy_tolerance


def resolved(settings: SolverSettings | None, mech) -> SolverSettings:
    """``settings`` (default :class:`SolverSettings`) with ``method = "auto"`` decided for
    ``mech`` (:func:`~.simulate.auto_method`, as a scene decides it)."""
    from .integrate import system_method

    settings = settings or SolverSettings()
    if settings.method != "auto":
        return settings
    return replace(settings, method=system_method(mech.system, 2.0 * np.pi * mech.revolution_hz))


def simulate(mech, t_end, output_step, settings: SolverSettings | None = None, ideal=False,
             energy_tolerance: float | None = 1e-3, start: str | None = None) -> History:
    """Integrate a mechanism and sample its history.

    Parameters
    ----------
    mech : Mechanism
    t_end : float
        Simulated time, s (``0 < t_end <= 100``, as ``dynamics.end_time``).
    output_step : float
        Output sampling step, s (``<= t_end``; refused when its samples would not fit in
        memory, :func:`check_output`).
    settings : SolverSettings, optional
        Default ``SolverSettings()``; its ``method = "auto"`` is decided for this mechanism as
        a scene decides it (:func:`~.simulate.auto_method`).
    ideal : bool
        Run the ideal-joint twin instead of the clearance model.
    energy_tolerance : float or None
        Largest admissible energy-balance residual relative to the energy exchanged in the run
        (:meth:`History.energy_scale`), > 0; None: not checked.
    start : {"quasi_static", "undeformed"} or None
        Initial elastic state of flexible bodies (None: ``mech.start``, by default
        ``"quasi_static"``, as scenes start). ``quasi_static``: unless done already, the
        bodies are first deformed to rest under the loads at ``t = 0``
        (:meth:`~.mechanisms.Mechanism.start_quasi_static`, which replaces ``mech.q0`` and
        ``mech.qd0`` and records ``mech.start_info``), so a run at full speed does not begin
        with a start-up blow; ``undeformed``: ``mech.q0`` as it is (as built: undeformed).
        A state you set yourself (``mech.q0``, ``mech.qd0`` changed since the builder made
        them, :meth:`~.mechanisms.Mechanism.as_built`) is always run as given. No effect on
        bodies without elastic modes.

    Raises
    ------
    ParameterError
        An argument out of its range, naming it (``output_step: 1e-12 s makes 1e+10 output
        samples ...``); or a run that cannot finish within ``settings.max_rhs_evals``, estimated
        before it starts (:func:`~.budget.check`), naming the key that limits the step
        (``contact.damping: ...``).
    NumericalError
        Solver failure, or an energy balance that does not close, or a penetration so deep the
        contact law is meaningless (the message names the parameter to change).
    """
    t_end, output_step, energy_tolerance = _check_run(mech, t_end, output_step, settings,
                                                      energy_tolerance, start)
    sysm = mech.ideal if ideal else mech.system
    check_output(sysm, t_end, output_step)
    settings = resolved(settings, mech)
    if not ideal:  # refuse what cannot finish within max_rhs_evals, before it runs (.budget)
        from ...errors import warn
        from .budget import check as check_budget

        for text in check_budget(mech, t_end, settings)[1]:
            warn(text)
    if (start or mech.start) == "quasi_static" and mech.start_info is None and mech.as_built():
        mech.start_quasi_static()
    for cj in sysm.clearances:
        cj.v_impact = cj.v_impact_min
    integ = integrate(sysm, mech.q0, mech.qd0, t_end, output_times(t_end, output_step), settings)
    hist = record(mech, sysm, integ)
    hist.nfev, hist.wall_time = integ.nfev, integ.wall_time
    for cj in sysm.clearances:
        depth = hist.peak("penetration", np.maximum(hist.contact[cj.name]["penetration"], 0.0),
                          cj.name)
        if depth > 0.1 * cj.journal_radius:
            raise NumericalError(
                f"clearance joint {cj.name!r}: penetration {depth:.3g} m exceeds 10 % of the "
                f"journal radius: law.stiffness = "
                f"{getattr(cj.law, 'stiffness', float('nan')):.3g} is "
                "too low for these loads; raise it")
    err = hist.energy_error()
    if energy_tolerance is not None and err > energy_tolerance:
        raise NumericalError(
            f"energy balance does not close: residual {err:.2e} of the energy exchanged "
            f"(tolerance {energy_tolerance:g}); tighten settings.rtol/settings.atol or lower "
            "settings.max_step")
    return hist


def key_outputs(hist: History, revolution_hz: float, t_start: float, orders=(1, 2, 3, 4)) -> dict:
    """The quantities a tolerance study compares: peaks and main-bearing order amplitudes."""
    sel = hist.t >= t_start
    # the samples after t_start and each contact's deepest point after it (events)
    fn = max((hist.peak("fn", c["fn"][sel], name, since=t_start)
              for name, c in hist.contact.items()), default=0.0)
    acc = float(np.max(hist.peak("piston_acceleration", hist.piston_acceleration[sel],
                                 since=t_start), initial=0.0))
    t = hist.t[sel]
    n_rev = int(np.floor((t[-1] - t[0]) * revolution_hz + 1e-9)) if t.size > 1 else 0
    if n_rev >= 1:
        keep = t <= t[0] + n_rev / revolution_hz + 1e-12
        amps = order_amplitudes(t[keep], hist.main_bearing_force[sel][keep], revolution_hz, orders)
        rms = np.sqrt(0.5 * np.sum(amps**2, axis=1))
    else:
        rms = np.full(len(orders), np.nan)
    return {"peak_contact_force": fn, "peak_piston_acceleration": acc,
            "main_bearing_order_rms": rms}


def tolerance_study(mech, t_end, output_step, rtols, t_start=0.0, base=None, ensemble=None,
                    rel_tol=REL_TOL) -> dict:
    """The same run at a sequence of tolerances: key outputs against wall time.

    Each row is exactly the run ``--set dynamics.solver.rtol=<rtol>`` gives: only ``rtol``
    changes, every other setting of ``base`` (``atol``, whose default follows the clearance and
    not ``rtol``, the method, the step bound) stays. Differences are taken against the tightest
    tolerance. Returns lists per rtol; the single-trajectory peaks (``d_peak_*``) and, under
    ``statistics``, the per-revolution statistics of :mod:`stats` with their standard errors and
    whether each converged (:func:`statistics_convergence`: within ``rel_tol`` across the study
    and, given an ``ensemble`` (:func:`.ensemble.run_ensemble`), across its trajectories).
    """
    base = base or SolverSettings()
    rows = []
    for rtol in sorted(rtols, reverse=True):
        s = replace(base, rtol=rtol)
        t0 = time.perf_counter()
        h = simulate(mech, t_end, output_step, s, energy_tolerance=None)
        wall = time.perf_counter() - t0
        rows.append((rtol, wall, h.nfev, key_outputs(h, mech.revolution_hz, t_start),
                     h.energy_error(), headline(statistics(h, mech.revolution_hz, t_start,
                                                           _v_min(mech)))))
    ref = rows[-1][3]
    out = {"rtol": [], "atol": base.atol, "wall_time_s": [], "rhs_evals": [], "energy_error": [],
           "peak_contact_force": [], "peak_piston_acceleration": [],
           "d_peak_contact_force": [], "d_peak_piston_acceleration": [],
           "d_main_bearing_order_rms": []}
    for rtol, wall, nfev, k, e, _ in rows:
        out["rtol"].append(rtol)
        out["wall_time_s"].append(wall)
        out["rhs_evals"].append(nfev)
        out["energy_error"].append(e)
        out["peak_contact_force"].append(k["peak_contact_force"])
        out["peak_piston_acceleration"].append(k["peak_piston_acceleration"])
        out["d_peak_contact_force"].append(_rel(k["peak_contact_force"], ref["peak_contact_force"]))
        out["d_peak_piston_acceleration"].append(
            _rel(k["peak_piston_acceleration"], ref["peak_piston_acceleration"]))
        d = np.abs(k["main_bearing_order_rms"] - ref["main_bearing_order_rms"])
        scale = np.maximum(np.abs(ref["main_bearing_order_rms"]), 1e-300)
        out["d_main_bearing_order_rms"].append(float(np.nan_to_num(np.max(d / scale), nan=0.0)))
    spread = (ensemble or {}).get("statistics_spread")
    out["statistics"] = statistics_convergence([r[0] for r in rows], [r[5] for r in rows],
                                               spread, rel_tol)
    out["convergence_criterion"] = criterion_text(rel_tol, spread is not None,
                                                  (ensemble or {}).get("n_trajectories"))
    out["rel_tol"] = rel_tol
    return out


N_SE = 2.0  # a difference of two independent means within 2 standard errors: agreement


def criterion_text(rel_tol: float, with_ensemble: bool, n_trajectories=None) -> str:
    """What ``converged`` means in a tolerance study (results ``convergence_criterion``)."""
    text = (f"converged at an rtol: the statistic's change against the tightest rtol is <= "
            f"{rel_tol:g} relative at that rtol and at every tighter one")
    if with_ensemble:
        text += (f", and its spread (max - min) over the {n_trajectories or ''} ensemble "
                 f"trajectories is <= {rel_tol:g} of their mean").replace("  ", " ")
    return text + (f"; within_sem: the change is within {N_SE:g} combined standard errors "
                   "(agreement within the noise of the revolutions, not convergence)")


def statistics_convergence(rtols, heads, spread=None, rel_tol=REL_TOL) -> dict:
    """Whether each per-revolution statistic converged across a tolerance study (and ensemble).

    A statistic is converged at an rtol when its change against the tightest rtol is within
    ``rel_tol`` (relative) there and at every tighter rtol of the study, *and*, when an
    ensemble ran, its spread (max - min) over the ensemble's trajectories is within ``rel_tol``
    of their mean: the number is then known to ``rel_tol`` whichever tolerance or round-off
    trajectory produced it. Agreement within the standard errors of the revolutions alone is
    reported (``within_sem``) but is not convergence: a statistic that reads 31.2 / 17.3 /
    25.2 kN at three tolerances agrees within standard errors of 7 kN and is known to no better.

    Parameters
    ----------
    rtols : list of float
        Loosest first; the last is the reference.
    heads : list of dict
        :func:`stats.headline` of each run, ``{name: (value, sem)}``.
    spread : dict, optional
        ``{name: {"mean", "std", "min", "max"}}`` of the same statistics over an ensemble's
        trajectories (:func:`.ensemble.run_ensemble`'s ``statistics_spread``).
    rel_tol : float
        The stated tolerance (relative).

    Returns
    -------
    dict
        name -> ``value``, ``sem``, ``rel_change`` (lists per rtol), ``within_sem`` (list of
        bool: the change within ``N_SE`` combined standard errors), ``converged`` (list of bool
        per rtol, as above; the reference's entry is the ensemble's verdict), ``study_rel_change``
        (the largest change over the whole study, relative), ``ensemble_rel_spread`` (None
        without an ensemble), ``converged_from_rtol`` (the loosest rtol from which it converged;
        None if none but the reference) and ``rel_sem`` (the reference's standard error over its
        value).
    """
    ref = heads[-1]
    out = {}
    for name, (v_ref, s_ref) in ref.items():
        rows = [h.get(name, (None, None)) for h in heads]
        rel, within = [], []
        for v, s in rows:
            if v is None:
                rel.append(None)
                within.append(False)
                continue
            d = abs(v - v_ref)
            rel.append(d / abs(v_ref) if v_ref else d)
            within.append(bool(d <= N_SE * float(np.hypot(s or 0.0, s_ref or 0.0))))
        ens = ensemble_rel_spread((spread or {}).get(name)) if spread is not None else None
        ens_ok = ens is None or ens <= rel_tol
        ok, tail = [], True
        for r in reversed(rel):  # converged at i: every rtol from i to the tightest within tol
            tail = tail and r is not None and r <= rel_tol
            ok.append(bool(tail and ens_ok))
        ok.reverse()
        k = len(ok) - 1
        while k > 0 and ok[k - 1]:
            k -= 1
        known = [r for r in rel if r is not None]
        out[name] = {"value": [r[0] for r in rows], "sem": [r[1] for r in rows],
                     "rel_change": rel, "within_sem": within, "converged": ok,
                     "study_rel_change": max(known) if len(known) == len(rel) else None,
                     "ensemble_rel_spread": ens,
                     "converged_from_rtol": rtols[k] if k < len(ok) - 1 and ok[k] else None,
                     "rel_sem": (s_ref / abs(v_ref)) if (v_ref and s_ref is not None) else None}
    return out


def change_from(c: dict, at: int) -> float | None:
    """Largest relative change of a statistic (:func:`statistics_convergence` entry) against the
    tightest rtol, over the rows from index ``at`` to the tightest; None if a row lacks it."""
    rel = c["rel_change"][at:]
    return None if any(r is None for r in rel) else max(rel)


def convergence_tag(c: dict, at: int, rel_tol: float = REL_TOL) -> str:
    """`` (converged: 0.3 %)`` or `` (NOT converged: 55 % across the study, 80 % across the
    ensemble)`` for a statistic at study row ``at`` (the run's rtol)."""
    if not c or len(c["converged"]) < 2:
        return ""
    d = change_from(c, at)
    if c["converged"][at]:
        return f" (converged: {_pct(d)} %)"
    return " (NOT converged: " + _by_how_much(c, at, rel_tol) + ")"


def _pct(x: float) -> str:
    """A relative number in percent: two significant digits, whole percent from 10 %, never
    ``e-05`` (:func:`crankmodal.report.quantity.number`)."""
    from ...report.quantity import number

    return f"{100 * x:.0f}" if 100 * x >= 10 else number(100 * x, 2)


def _by_how_much(c: dict, at: int, rel_tol: float) -> str:
    d, e = change_from(c, at), c.get("ensemble_rel_spread")
    parts = ["missing at some rtol" if d is None else f"{_pct(d)} % across the study"]
    if e is not None:
        parts.append(f"{_pct(e)} % across the ensemble" if np.isfinite(e)
                     else "not in every ensemble trajectory")
    return ", ".join(parts) + f", tolerance {100 * rel_tol:g} %"


def convergence_line(study: dict, at: int, n_trajectories=None, most: int = 3) -> str:
    """The summary's verdict on a study's statistics at row ``at`` (the run's rtol): how many
    converged and, for the ``most`` worst that did not, by how much."""
    conv = study["statistics"]
    tol = study.get("rel_tol", REL_TOL)
    rt = study["rtol"]
    ok = [k for k, c in conv.items() if c["converged"][at]]
    where = f"from rtol {rt[at]:g} to {rt[-1]:g}"
    if n_trajectories:
        where += f" and across the {n_trajectories}-trajectory ensemble"
    text = (f"{len(ok)}/{len(conv)} per-rev statistics converged to {100 * tol:g} % {where}")
    bad = [k for k in conv if k not in ok]
    if bad:
        def size(k):
            d, e = change_from(conv[k], at), conv[k].get("ensemble_rel_spread")
            return max(np.inf if d is None else d, 0.0 if e is None else e)

        bad.sort(key=size, reverse=True)
        shown = [f"{k} ({_by_how_much(conv[k], at, tol).rsplit(', tolerance', 1)[0]})"
                 for k in bad[:most]]
        text += "; NOT converged: " + "; ".join(shown)
        if len(bad) > most:
            text += f"; and {len(bad) - most} more (results tolerance_study.statistics)"
    return text


def ensemble_rel_spread(s: dict | None) -> float | None:
    """``(max - min) / |mean|`` of a statistic over an ensemble's trajectories; infinite when
    the ensemble lacks it (a statistic one trajectory had and another not) and the spread is
    unknown; the absolute spread when the mean is 0."""
    if s is None:
        return float("inf")
    d = float(s["max"]) - float(s["min"])
    return d / abs(s["mean"]) if s["mean"] else d


def _v_min(mech) -> dict:
    return {cj.name: cj.v_impact_min for cj in mech.system.clearances}


def _rel(a, b):
    return abs(a - b) / abs(b) if b else abs(a - b)
