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


def headline(stats: dict) -> dict:
    """The per-revolution means a trajectory is summarised by (N, m/s^2, counts, m/s)."""
    out = {"main_bearing_per_rev_peak_n": stats["main_bearing_force"]["per_rev_peak"]["mean"],
           "main_bearing_rms_n": stats["main_bearing_force"]["rms"]["mean"]}
    pist = stats.get("piston_acceleration") or []
    if pist:
        out["piston_per_rev_peak_max_m_s2"] = max(p["per_rev_peak"]["mean"] for p in pist)
    for name, j in (stats.get("clearance_joints") or {}).items():
        iv = j.get("impact_velocity", {})
        if "count_per_rev" in iv:
            out[f"{name}_impacts_per_rev"] = iv["count_per_rev"]["mean"]
        if "max_per_rev" in iv:
            out[f"{name}_impact_velocity_max_per_rev_m_s"] = iv["max_per_rev"]["mean"]
    return out


def run_ensemble(mech, base_stats: dict, n: int, t_end: float, dt: float, settings,
                 revolution_hz: float, t_start: float, v_min: dict,
                 energy_tolerance: float | None = 1e-3, eps: float = EPS) -> dict:
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

    Returns
    -------
    dict
        ``n_trajectories``, ``perturbation`` (relative), ``per_trajectory`` (one headline dict
        each, the base run first) and, per headline quantity, ``mean``, ``std``, ``min``,
        ``max`` over the trajectories; ``statistics_spread``: the same four for every statistic
        of :func:`.stats.headline` (the names a tolerance study uses, so that it can state
        convergence across the ensemble too); ``wall_time_s``.
    """
    from .analysis import simulate
    from .stats import headline as stats_headline
    from .stats import statistics

    rows = [headline(base_stats)]
    heads = [stats_headline(base_stats)]  # the tolerance study's statistics, for its verdict
    wall = 0.0
    for k in range(1, n):
        m = replace(mech, q0=np.asarray(mech.q0, float) * (1.0 + k * eps))
        h = simulate(m, t_end, dt, settings, energy_tolerance=energy_tolerance)
        wall += h.wall_time
        st = statistics(h, revolution_hz, t_start, v_min)
        rows.append(headline(st))
        heads.append(stats_headline(st))
    return {"n_trajectories": n, "perturbation": eps, "per_trajectory": rows,
            "spread": _spread(rows), "statistics_spread": _spread([{k: v[0] for k, v in h.items()}
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


__all__ = ["EPS", "headline", "run_ensemble"]
