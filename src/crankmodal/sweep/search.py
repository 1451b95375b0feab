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

from .axes import Axis


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
        v = [round(float(x)) for x in v] if a.integer else [float(x) for x in v]
        values.append(list(dict.fromkeys(v)))  # clipped duplicates once
        new_steps[a.key] = 2 * h / (num - 1)
    keys = [a.key for a in axes]
    return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*values)], new_steps
