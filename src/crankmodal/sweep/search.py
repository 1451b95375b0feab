"""Searches: a coarse grid, then grids refined around the best point.

Round 0 is the sweep's own grid. Each further round centres a grid of ``num`` values per range
axis on the best point so far, spanning one step of the previous round either side (clipped to
the axis's range, geometric for a log axis), so the step halves for ``num = 5`` and the bracket
around the optimum shrinks geometrically; list axes stay at the best point's value. Points
already run (same key) are not run again. A grid does not assume a smooth output (impact
velocities jump between regimes), which a gradient optimiser would.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .axes import Axis, grid_step, tidy


def objective_value(record: dict, objective: str):
    """The record's objective as a float, or None (failed point, non-numeric value)."""
    if record.get("status") != "ok":
        return None
    v = record["outputs"].get(objective)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        return None
    return float(v)


def best(records: list[dict], objective: str, sense: str) -> dict | None:
    """The record with the largest (``sense = "max"``) or smallest objective; None if none."""
    scored = [(objective_value(r, objective), r) for r in records]
    scored = [(v, r) for v, r in scored if v is not None]
    if not scored:
        return None
    pick = max if sense == "max" else min
    return pick(scored, key=lambda vr: vr[0])[1]


def initial_steps(axes: list[Axis]) -> dict[str, float]:
    """The coarse grid's step of each range axis (in log space for a log axis)."""
    steps = {}
    for a in axes:
        if a.is_range and len(a.values) > 1:
            lo, hi = (math.log(a.start), math.log(a.stop)) if a.log else (a.start, a.stop)
            steps[a.key] = abs(hi - lo) / (len(a.values) - 1)
    return steps


def refine(axes: list[Axis], centre: dict, steps: dict[str, float], num: int):
    """The next round's points around ``centre`` and the steps after it.

    Returns
    -------
    points : list of dict
    steps : dict
        Half of ``2 step / (num - 1)``-spaced grids: the new step of each refined axis.
    """
    values, new_steps = [], {}
    for a in axes:
        c = centre[a.key]
        if a.key not in steps:
            values.append([c])
            continue
        h = steps[a.key]
        lo, hi = sorted((a.start, a.stop))
        if a.log:
            v = np.exp(np.linspace(math.log(c) - h, math.log(c) + h, num))
        else:
            v = np.linspace(c - h, c + h, num)
        v = np.clip(v, lo, hi)
        new_steps[a.key] = 2 * h / (num - 1)
        v = [round(float(x)) for x in v] if a.integer else \
            [tidy(float(x), grid_step(float(x), new_steps[a.key], a.log)) for x in v]
        values.append(list(dict.fromkeys(v)))  # clipped duplicates once
    keys = [a.key for a in axes]
    return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*values)], new_steps


def to_unit(axis: Axis, value: float) -> float:
    """A range axis's value as a coordinate in [0, 1] (log-scaled for a log axis)."""
    if axis.log:
        return (math.log(value) - math.log(axis.start)) / (math.log(axis.stop)
                                                            - math.log(axis.start))
    return (value - axis.start) / (axis.stop - axis.start)


def from_unit(axis: Axis, u: float):
    """The inverse of :func:`to_unit` (rounded on an integer axis)."""
    u = min(max(float(u), 0.0), 1.0)
    if axis.log:
        v = math.exp(math.log(axis.start) + u * (math.log(axis.stop) - math.log(axis.start)))
    else:
        v = axis.start + u * (axis.stop - axis.start)
    return round(v) if axis.integer else v


def optimise(axes: list[Axis], start: dict, evaluate, sense: str, method: str,
             max_points: int, xtol: float) -> int:
    """A scipy optimiser from the coarse grid's best point, over the range axes.

    Parameters
    ----------
    axes : list of Axis
        List axes stay at ``start``'s values.
    start : dict
        The starting point (the coarse grid's best).
    evaluate : callable
        ``evaluate(point) -> float or None``: one point run (None: failed or not a number,
        treated as the worst value).
    sense : {"max", "min"}
    method : {"powell", "nelder-mead"}
        :func:`scipy.optimize.minimize` methods that need no gradient (a point is a whole run;
        finite differences would double the runs and fail on the outputs' jumps).
    max_points : int
        Most runs the optimiser may ask for.
    xtol : float
        Tolerance on the axes scaled to [0, 1].

    Returns
    -------
    int
        Runs the optimiser asked for (repeated points are not run again by the caller).
    """
    from scipy.optimize import minimize

    free = [a for a in axes if a.is_range and a.start != a.stop]
    sign = -1.0 if sense == "max" else 1.0
    calls = 0

    def f(u):
        nonlocal calls
        calls += 1
        point = {**start, **{a.key: from_unit(a, ui) for a, ui in zip(free, u, strict=True)}}
        v = evaluate(point)
        return 1e300 if v is None else sign * v

    u0 = np.array([to_unit(a, start[a.key]) for a in free])
    if method == "powell":
        minimize(f, u0, method="Powell", bounds=[(0.0, 1.0)] * len(free),
                 options={"maxfev": max_points, "xtol": xtol, "ftol": 1e-12})
    else:
        minimize(f, u0, method="Nelder-Mead", bounds=[(0.0, 1.0)] * len(free),
                 options={"maxfev": max_points, "xatol": xtol, "fatol": 0.0,
                          "initial_simplex": _simplex(u0, 0.1)})
    return calls


def _simplex(u0, size: float) -> np.ndarray:
    """A starting simplex of ``size`` (in unit coordinates) around ``u0``, inside [0, 1]."""
    pts = [u0]
    for i in range(len(u0)):
        p = u0.copy()
        p[i] = p[i] + size if p[i] + size <= 1 else p[i] - size
        pts.append(p)
    return np.array(pts)
