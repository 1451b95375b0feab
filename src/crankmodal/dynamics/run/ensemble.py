"""Ensembles of trajectories: the spread one trajectory of an impacting system cannot show.

A clearance joint's impact sequence depends on round-off: the same run started from a state
changed by 1e-13 (or computed with another, equally valid, order of arithmetic) follows another
sequence after the first impact, and over a few revolutions may settle in a quieter or a
rattling regime. :func:`run_ensemble` runs the mechanism from ``n`` starting states perturbed
at round-off level (relative ``k · eps``, k = 0 … n − 1) and reports, for the headline
per-revolution statistics, each trajectory's value and their mean, standard deviation, minimum
and maximum: the trajectory-to-trajectory spread, to set beside each run's standard error over
its revolutions. A smooth system (no impacts) gives the same numbers to the integration
tolerance.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

#: relative perturbation of the starting positions per trajectory (round-off level)
EPS = 1e-12


def headline(stats: dict, field: str = "mean") -> dict:
    """The per-revolution means a trajectory is summarised by (N, m/s^2, counts, m/s);
    ``field = "sem"``: their standard errors over the revolutions instead."""
    mb = stats["main_bearing_force"]
    out = {"main_bearing_per_rev_peak_n": mb["per_rev_peak"][field],
           "main_bearing_rms_n": mb["rms"][field]}
    pist = stats.get("piston_acceleration") or []
    if pist:  # the piston with the largest mean
        i = int(np.argmax([p["per_rev_peak"]["mean"] for p in pist]))
        out["piston_per_rev_peak_max_m_s2"] = pist[i]["per_rev_peak"][field]
    for name, j in (stats.get("clearance_joints") or {}).items():
        iv = j.get("impact_velocity", {})
        if "count_per_rev" in iv:
            out[f"{name}_impacts_per_rev"] = iv["count_per_rev"][field]
        if "max_per_rev" in iv:
            out[f"{name}_impact_velocity_max_per_rev_m_s"] = iv["max_per_rev"][field]
    return {k: v for k, v in out.items() if v is not None}


def headline_value(means, sems) -> dict:
    """One value for a quantity from per-trajectory means and standard errors, with its
    honest uncertainty.

    The value is the mean over the trajectories. When the trajectories disagree more than a
    trajectory's own standard error over its revolutions (their standard deviation above the
    RMS of their standard errors: the regime each settles in is decided by round-off), that
    trajectory-to-trajectory spread (standard deviation) is the uncertainty: another
    trajectory lands anywhere within it. Otherwise the revolutions of all trajectories pool
    and the uncertainty is the standard error of the pooled mean, the RMS standard error over
    ``sqrt(n)`` trajectories. One trajectory: its mean and standard error.

    Parameters
    ----------
    means, sems : sequence of float
        Per trajectory, in the quantity's unit.

    Returns
    -------
    dict
        ``value``, ``uncertainty`` (unit of the inputs), ``basis`` (``"ensemble spread"`` or
        ``"standard error"``), ``min``, ``max`` (over the trajectories), ``spread`` (their
        standard deviation, 0 for one), ``standard_error`` (RMS of the per-trajectory ones),
        ``n_trajectories``.
    """
    m = np.asarray(means, float)
    s = np.asarray(sems, float)
    n = int(m.size)
    within = float(np.sqrt(np.mean(s**2))) if n else 0.0
    spread = float(np.std(m, ddof=1)) if n > 1 else 0.0
    if spread > within:
        unc, basis = spread, "ensemble spread"
    else:
        unc, basis = within / np.sqrt(max(n, 1)), "standard error"
    return {"value": float(m.mean()), "uncertainty": float(unc), "basis": basis,
            "min": float(m.min()), "max": float(m.max()), "spread": spread,
            "standard_error": within, "n_trajectories": n}


def _unit(key: str) -> str:
    """Unit of a headline quantity, by the suffix of its key."""
    for end, unit in (("_n", "N"), ("_m_s2", "m/s^2"), ("_m_s", "m/s"), ("_per_rev", "1/rev")):
        if key.endswith(end):
            return unit
    return ""


def headlines(base_stats: dict, ensemble: dict | None = None) -> dict:
    """The headline block of a run: one value per quantity of :func:`headline`, with its
    uncertainty (:func:`headline_value`) over the ensemble's trajectories (or the run alone),
    and its ``unit``."""
    if ensemble:
        rows, sems = ensemble["per_trajectory"], ensemble["per_trajectory_sem"]
    else:
        rows, sems = [headline(base_stats)], [headline(base_stats, "sem")]
    out = {}
    for key in rows[0]:
        if all(key in r for r in rows) and all(key in s for s in sems):
            out[key] = dict(headline_value([r[key] for r in rows], [s[key] for s in sems]),
                            unit=_unit(key))
    return out


def _label(key: str) -> str:
    """Words for a headline key (``big_end_1_impacts_per_rev`` -> ``big_end_1 impacts/rev``)."""
    fixed = {"main_bearing_per_rev_peak_n": "main-bearing per-rev peak",
             "main_bearing_rms_n": "main-bearing RMS",
             "piston_per_rev_peak_max_m_s2": "piston accel per-rev peak"}
    if key in fixed:
        return fixed[key]
    for end, words in (("_impacts_per_rev", " impacts/rev"),
                       ("_impact_velocity_max_per_rev_m_s", " largest impact velocity/rev")):
        if key.endswith(end):
            return key[: -len(end)] + words
    return key


def headline_text(block: dict, n_revolutions: int) -> str:
    """The summary line's numbers: each quantity once, ``value ± uncertainty``, marked
    ``(spread)`` where the uncertainty is the trajectory-to-trajectory spread."""
    from ...report.quantity import number

    parts = []
    n_traj = 1
    for key, h in block.items():
        k = 1e3 if abs(h["value"]) >= 1e4 and h["unit"] in ("N", "m/s^2") else 1.0
        unit = ("k" if k > 1 else "") + (h["unit"] if h["unit"] != "1/rev" else "")
        text = f"{_label(key)} {number(h['value'] / k)}"  # never e+NN (issue 25 #15)
        if h["uncertainty"] > 0.0:
            text += f" ± {number(h['uncertainty'] / k, 2)}"
        parts.append(text + (f" {unit}" if unit else "")
                      + (" (spread)" if h["basis"] == "ensemble spread" else ""))
        n_traj = h["n_trajectories"]
    return (", ".join(parts) + f" (per-revolution means over {n_traj} trajector"
            f"{'ies' if n_traj > 1 else 'y'} x {n_revolutions} revs; ±: standard error, or the "
            f"trajectory-to-trajectory spread where marked)")


def run_ensemble(mech, base_stats: dict, n: int, t_end: float, dt: float, settings,
                 revolution_hz: float, t_start: float, v_min: dict,
                 energy_tolerance: float | None = 1e-3, eps: float = EPS,
                 histories: list | None = None) -> dict:
    """``n`` trajectories (the base run and ``n − 1`` perturbed ones) and their spread.

    Parameters
    ----------
    mech : Mechanism
    base_stats : dict
        The base run's ``statistics`` block.
    n : int
        Trajectories in all (≥ 2).
    t_end, dt : float
        Simulated and output time, s.
    settings : SolverSettings
    revolution_hz, t_start : float
        Hz, and the start of the first counted revolution, s.
    v_min : dict
        Impact-velocity floors per joint, m/s.
    histories : list, optional
        Receives the History of each perturbed trajectory (the base run's is the caller's), for
        a later stage that assesses every trajectory (the [fatigue] verdict).

    Returns
    -------
    dict
        ``n_trajectories``, ``perturbation`` (relative), ``per_trajectory`` (one headline dict
        each, the base run first), ``per_trajectory_sem`` (their standard errors over the
        revolutions) and, per headline quantity, ``mean``, ``std``, ``min``,
        ``max`` over the trajectories; ``statistics_spread``: the same four for every statistic
        of :func:`.stats.headline` (the names a tolerance study uses, so that it can state
        convergence across the ensemble too); ``wall_time_s``.
    """
    from ..results.stats import headline as stats_headline
    from ..results.stats import statistics
    from .simulate import simulate

    rows, sems = [headline(base_stats)], [headline(base_stats, "sem")]
    heads = [stats_headline(base_stats)]  # the tolerance study's statistics, for its verdict
    wall = 0.0
    for k in range(1, n):
        m = replace(mech, q0=np.asarray(mech.q0, float) * (1.0 + k * eps))
        h = simulate(m, t_end, dt, settings, energy_tolerance=energy_tolerance)
        wall += h.wall_time
        if histories is not None:
            histories.append(h)
        st = statistics(h, revolution_hz, t_start, v_min)
        rows.append(headline(st))
        sems.append(headline(st, "sem"))
        heads.append(stats_headline(st))
    return {"n_trajectories": n, "perturbation": eps, "per_trajectory": rows,
            "per_trajectory_sem": sems, "spread": _spread(rows), "statistics_spread": _spread([{k: v[0] for k, v in h.items()}
                                                           for h in heads]),
            "wall_time_s": wall}


def _spread(rows: list[dict]) -> dict:
    """Mean, std (ddof 1), min and max over trajectories of each quantity all of them have."""
    out = {}
    for key in [k for k in rows[0] if all(k in r for r in rows)]:
        v = np.array([r[key] for r in rows], float)
        out[key] = {"mean": float(v.mean()), "std": float(v.std(ddof=1)),
                    "min": float(v.min()), "max": float(v.max())}
    return out


__all__ = ["EPS", "headline", "headline_text", "headline_value", "headlines", "run_ensemble"]
