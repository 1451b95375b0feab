"""Running a mechanism: simulate with checks, and the error-against-run-time study."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..errors import NumericalError
from .history import History, record
from .signals import order_amplitudes
from .simulate import SolverSettings, integrate
from .stats import REL_TOL, headline, statistics


def output_times(t_end: float, output_step: float) -> np.ndarray:
    """Uniform output times ``0, dt, ..., t_end`` (s)."""
    k = round(t_end / output_step)
    return np.linspace(0.0, k * output_step, k + 1)


def simulate(mech, t_end, output_step, settings: SolverSettings | None = None, ideal=False,
             energy_tolerance: float | None = 1e-3) -> History:
    """Integrate a mechanism and sample its history.

    Parameters
    ----------
    mech : Mechanism
    t_end, output_step : float
        s.
    settings : SolverSettings, optional
    ideal : bool
        Run the ideal-joint twin instead of the clearance model.
    energy_tolerance : float or None
        Largest admissible energy-balance residual relative to the energy exchanged in the run
        (:meth:`History.energy_scale`).

    Raises
    ------
    NumericalError
        Solver failure, or an energy balance that does not close, or a penetration so deep the
        contact law is meaningless (the message names the parameter to change).
    """
    settings = settings or SolverSettings()
    sysm = mech.ideal if ideal else mech.system
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
                f"journal radius: contact.stiffness = {cj.law_params.get('stiffness'):.3g} is "
                "too low for these loads; raise it")
    err = hist.energy_error()
    if energy_tolerance is not None and err > energy_tolerance:
        raise NumericalError(
            f"energy balance does not close: residual {err:.2e} of the energy exchanged "
            f"(tolerance {energy_tolerance:g}); tighten solver.rtol/solver.atol or lower "
            "solver.max_step_deg")
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


def tolerance_study(mech, t_end, output_step, rtols, t_start=0.0, base=None) -> dict:
    """The same run at a sequence of tolerances: key outputs against wall time.

    Differences are taken against the tightest tolerance. Returns lists per rtol; the
    single-trajectory peaks (``d_peak_*``) and, under ``statistics``, the per-revolution
    statistics of :mod:`stats` with their standard errors and which of them converge
    (:func:`statistics_convergence`).
    """
    base = base or SolverSettings()
    rows = []
    for rtol in sorted(rtols, reverse=True):
        s = replace(base, rtol=rtol, atol=base.atol * rtol / base.rtol)
        t0 = time.perf_counter()
        h = simulate(mech, t_end, output_step, s, energy_tolerance=None)
        wall = time.perf_counter() - t0
        rows.append((rtol, wall, h.nfev, key_outputs(h, mech.revolution_hz, t_start),
                     h.energy_error(), headline(statistics(h, mech.revolution_hz, t_start,
                                                           _v_min(mech)))))
    ref = rows[-1][3]
    out = {"rtol": [], "wall_time_s": [], "rhs_evals": [], "energy_error": [],
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
    out["statistics"] = statistics_convergence([r[0] for r in rows], [r[5] for r in rows])
    out["convergence_criterion"] = (f"|change against the tightest rtol| <= {N_SE:g} combined "
                                    f"standard errors or <= {REL_TOL:g} relative")
    return out


N_SE = 2.0  # a difference of two independent means within 2 standard errors: agreement


def statistics_convergence(rtols, heads) -> dict:
    """Relative change of each per-revolution statistic against the tightest tolerance.

    Parameters
    ----------
    rtols : list of float
        Loosest first; the last is the reference.
    heads : list of dict
        :func:`stats.headline` of each run, ``{name: (value, sem)}``.

    Returns
    -------
    dict
        name -> ``value``, ``sem``, ``rel_change`` (lists per rtol), ``converged`` (list of
        bool per rtol: the change is within ``N_SE`` combined standard errors or ``REL_TOL``),
        ``converged_from_rtol`` (the loosest rtol from which every tighter run agrees; None if
        only the reference does) and ``rel_sem`` (the reference's standard error over its value).
    """
    ref = heads[-1]
    out = {}
    for name, (v_ref, s_ref) in ref.items():
        rows = [h.get(name, (None, None)) for h in heads]
        rel, ok = [], []
        for v, s in rows:
            if v is None:
                rel.append(None)
                ok.append(False)
                continue
            d = abs(v - v_ref)
            rel.append(d / abs(v_ref) if v_ref else d)
            se = float(np.hypot(s or 0.0, s_ref or 0.0))
            ok.append(bool(d <= N_SE * se or rel[-1] <= REL_TOL))
        k = len(ok) - 1
        while k > 0 and ok[k - 1]:
            k -= 1
        out[name] = {"value": [r[0] for r in rows], "sem": [r[1] for r in rows],
                     "rel_change": rel, "converged": ok,
                     "converged_from_rtol": rtols[k] if k < len(ok) - 1 else None,
                     "rel_sem": (s_ref / abs(v_ref)) if (v_ref and s_ref is not None) else None}
    return out


def _v_min(mech) -> dict:
    return {cj.name: cj.v_impact_min for cj in mech.system.clearances}


def _rel(a, b):
    return abs(a - b) / abs(b) if b else abs(a - b)
