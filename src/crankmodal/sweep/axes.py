"""Sweep axes: the values of one ``--set`` key, and the points a sweep mode makes of them.

An axis is a list of values, or a range ``{start, stop, num}`` (``log = true`` for a geometric
range). ``grid`` is the full product, ``zip`` pairs the axes entry by entry, ``random`` and
``lhs`` (latin hypercube, :class:`scipy.stats.qmc.LatinHypercube`) draw ``samples`` points:
a range axis is sampled continuously between start and stop (log-uniformly with ``log``), a list
axis picks one of its entries.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError

MODES = ("grid", "zip", "random", "lhs")
RANGE_KEYS = ("start", "stop", "num", "log")


@dataclass(frozen=True)
class Axis:
    """One swept key.

    Attributes
    ----------
    key : str
        The ``--set`` path, e.g. ``mechanism.speed_rpm``.
    values : tuple
        The values of a grid/zip sweep (a range's ``num`` values, start and stop included).
    start, stop : float or None
        The bounds of a range axis (None for a list axis).
    log : bool
        Geometric range.
    integer : bool
        A range of integers (start and stop are integers): values are rounded.
    """

    key: str
    values: tuple
    start: float | None = None
    stop: float | None = None
    log: bool = False
    integer: bool = False

    @property
    def is_range(self) -> bool:
        return self.start is not None


def _number(key: str, name: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SceneError(f"axes.{key}.{name}: must be a finite number, got {v!r}")
    return v


#: Decimal digits kept below the leading digit of an axis's step (:func:`tidy`).
STEP_DIGITS = 9


def tidy(value: float, step: float) -> float:
    """``value`` rounded to :data:`STEP_DIGITS` decimal digits below the leading digit of
    ``step``, the resolution of the axis it lies on.

    ``start + i * step`` in binary floating point carries noise of about 1e-16 of the value
    (``np.linspace(0, 0.4, 17)[3]`` is 0.07500000000000001); the noise reached the point's
    ``--set`` value, its key and the CSV. Rounding far below the step removes it (0.075) and
    keeps every digit the grid has, for values up to ~1e6 steps from zero.

    Parameters
    ----------
    value : float
        A grid value, in the axis's unit.
    step : float
        The spacing of the grid around it (> 0), same unit; for a geometric axis the local
        spacing ``value * (ratio - 1)``.
    """
    if not (step > 0 and math.isfinite(step) and math.isfinite(value)):
        return value
    return round(value, STEP_DIGITS - math.floor(math.log10(step)))


def grid_step(value: float, step: float, log: bool) -> float:
    """The spacing around ``value`` of a grid of ``step`` (a log step for a geometric grid)."""
    return abs(value) * math.expm1(step) if log else step


def range_values(start: float, stop: float, num: int, log: bool = False,
                 integer: bool = False) -> tuple:
    """``num`` values from ``start`` to ``stop`` (both included), evenly or geometrically,
    each :func:`tidy` (0.075, not 0.07500000000000001)."""
    vals = np.geomspace(start, stop, num) if log else np.linspace(start, stop, num)
    if integer:
        return tuple(round(float(v)) for v in vals)
    if num < 2:
        return tuple(float(v) for v in vals)
    step = abs(math.log(stop / start) if log else stop - start) / (num - 1)
    return tuple(tidy(float(v), grid_step(float(v), step, log)) for v in vals)


def parse_axis(key: str, spec) -> Axis:
    """An :class:`Axis` from its sweep-file value (a list, or a ``{start, stop, num[, log]}``
    table); one-line :class:`SceneError` naming ``axes.<key>`` otherwise."""
    if isinstance(spec, list):
        if not spec:
            raise SceneError(f"axes.{key}: empty axis; give at least one value")
        return Axis(key, tuple(spec))
    if not isinstance(spec, dict):
        raise SceneError(f"axes.{key}: expected a list of values or a table "
                         f"{{start, stop, num[, log]}}, got {spec!r}")
    unknown = sorted(set(spec) - set(RANGE_KEYS))
    if unknown:
        raise SceneError(f"axes.{key}.{unknown[0]}: unknown range key; allowed: "
                         f"{', '.join(RANGE_KEYS)}")
    for need in ("start", "stop"):
        if need not in spec:
            raise SceneError(f"axes.{key}: a range needs {need} (keys: {', '.join(RANGE_KEYS)})")
    start, stop = _number(key, "start", spec["start"]), _number(key, "stop", spec["stop"])
    num = spec.get("num", 2)
    if isinstance(num, bool) or not isinstance(num, int) or num < 1:
        raise SceneError(f"axes.{key}.num: must be an integer >= 1, got {num!r}")
    log = spec.get("log", False)
    if not isinstance(log, bool):
        raise SceneError(f"axes.{key}.log: must be true or false, got {log!r}")
    if log and (start <= 0 or stop <= 0):
        raise SceneError(f"axes.{key}: a log range needs start and stop > 0, got "
                         f"{start!r}..{stop!r}")
    integer = isinstance(start, int) and isinstance(stop, int) and not log
    if num == 1 and start != stop:
        raise SceneError(f"axes.{key}: num = 1 needs start == stop (or give a list)")
    return Axis(key, range_values(start, stop, num, log, integer), float(start), float(stop),
                log, integer)


def flatten_axes(table: dict, prefix: str = "") -> dict:
    """``[axes]`` with dotted keys written bare (TOML nests them) back to ``{"a.b.c": spec}``.

    A table is a range when all its keys are range keys; otherwise it is a level of the path.
    """
    flat = {}
    for k, v in table.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict) and v and not set(v) <= set(RANGE_KEYS):
            flat.update(flatten_axes(v, key + "."))
        else:
            flat[key] = v
    return flat


def _sample(axis: Axis, u: float):
    """The value of ``axis`` at the unit coordinate ``u`` in [0, 1)."""
    if not axis.is_range:
        return axis.values[min(int(u * len(axis.values)), len(axis.values) - 1)]
    if axis.log:
        v = math.exp(math.log(axis.start) + u * (math.log(axis.stop) - math.log(axis.start)))
    else:
        v = axis.start + u * (axis.stop - axis.start)
    return round(float(v)) if axis.integer else float(v)


def generate(axes: list[Axis], mode: str = "grid", samples: int | None = None,
             seed: int = 0) -> list[dict]:
    """The sweep's points, each a ``{key: value}`` dict in axis order.

    Parameters
    ----------
    axes : list of Axis
    mode : {"grid", "zip", "random", "lhs"}
    samples : int, optional
        Number of points of ``random`` and ``lhs``.
    seed : int
        Seed of the random generators (the same seed gives the same points, so a re-run of a
        random sweep resumes).
    """
    keys = [a.key for a in axes]
    if mode == "grid":
        return [dict(zip(keys, combo, strict=True))
                for combo in itertools.product(*(a.values for a in axes))]
    if mode == "zip":
        lengths = {a.key: len(a.values) for a in axes}
        if len(set(lengths.values())) > 1:
            detail = ", ".join(f"{k} {n}" for k, n in lengths.items())
            raise SceneError(f"mode = 'zip' needs axes of one length; got {detail}")
        return [dict(zip(keys, combo, strict=True)) for combo in zip(*(a.values for a in axes))]
    if mode in ("random", "lhs"):
        if samples is None:
            raise SceneError(f"mode = {mode!r} needs samples = <number of points>")
        if mode == "random":
            u = np.random.default_rng(seed).random((samples, len(axes)))
        else:
            from scipy.stats import qmc

            u = qmc.LatinHypercube(d=len(axes), seed=seed).random(samples)
        return [{a.key: _sample(a, float(row[j])) for j, a in enumerate(axes)} for row in u]
    raise SceneError(f"mode: {mode!r} is not a sweep mode; allowed: {', '.join(MODES)}")
