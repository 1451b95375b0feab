"""The sweep file (SWEEP.toml): what to vary, what to collect, how to search.

.. code-block:: toml

    base = "four_star_mechanism.toml"   # the base scene, relative to this file
    mode = "grid"                       # grid | zip | random | lhs
    samples = 16                        # random / lhs: number of points
    seed = 0                            # random / lhs
    set = ["mechanism.n_points=360"]    # fixed overrides of every point
    outputs = ["mechanism.first_order_force_max_n"]
    timeout_s = 600                     # per point; a point over it is recorded as "timeout"
    max_failed = 0.1                    # share of failed points above which the sweep failed
    figures = false                     # the points' own PNGs

    [axes]
    "mechanism.speed_rpm" = [1000, 1480, 2000]
    "mechanism.cylinders.0.throw_angle_deg" = { start = 0, stop = 180, num = 7 }

    [search]                            # optional: refine around the best point
    maximize = "mechanism.first_order_force_max_n"   # or minimize = "..."
    method = "grid"                     # grid (rounds of num values) | powell | nelder-mead
    rounds = 3
    num = 5
    max_points = 60                     # powell / nelder-mead: most runs
    xtol = 1e-3                         # powell / nelder-mead: on the axes scaled to [0, 1]
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputFileError, SceneError
from ..resources import decode_utf8, load_toml
from .axes import MODES, Axis, flatten_axes, generate, parse_axis

KEYS = ("base", "mode", "samples", "seed", "set", "outputs", "timeout_s", "max_failed",
        "figures", "axes", "search", "name", "description")
SEARCH_KEYS = ("maximize", "minimize", "method", "rounds", "num", "max_points", "xtol")
SEARCH_METHODS = ("grid", "powell", "nelder-mead")
#: Default share of a sweep's points that may fail (error, timeout) before the sweep counts as
#: failed: ``crankmodal sweep`` then exits with status 4 (:data:`.driver.FAILED_EXIT`).
MAX_FAILED = 0.1


@dataclass
class SweepSpec:
    """A checked sweep.

    Attributes
    ----------
    base : Path
        The base scene file.
    base_text : str
        Its text, sent to the workers (they need no copy of the sweep file) and hashed into
        every point's key.
    axes : list of Axis
    mode : str
    outputs : list of str
        results.json paths (``section.key[.sub][.index]``).
    fixed : list of str
        ``--set`` assignments applied to every point.
    samples, seed : int
        Of random / lhs sweeps.
    timeout_s : float or None
        Wall-time limit of one point, s.
    max_failed : float
        Share of the points (0 to 1) that may fail before the sweep counts as failed (the CLI
        exits with status 4).
    figures : bool
        Let each point write its PNGs.
    search : dict or None
        ``{"objective": path, "sense": "max"|"min", "rounds": int, "num": int}``.
    name : str
    """

    base: Path
    base_text: str
    axes: list[Axis]
    mode: str = "grid"
    outputs: list[str] = field(default_factory=list)
    fixed: list[str] = field(default_factory=list)
    samples: int | None = None
    seed: int = 0
    timeout_s: float | None = None
    max_failed: float = MAX_FAILED
    figures: bool = False
    search: dict | None = None
    name: str = "sweep"

    def points(self) -> list[dict]:
        """The first (for a search: coarse) set of points, ``{key: value}`` each."""
        return generate(self.axes, self.mode, self.samples, self.seed)

    @property
    def base_digest(self) -> str:
        return hashlib.sha256(self.base_text.encode()).hexdigest()


def check_max_failed(name: str, value) -> float:
    """``value`` as a share of the points in [0, 1]; a :class:`SceneError` naming ``name``
    (the sweep key, the ``--max-failed`` option or the API argument) otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= 1:
        raise SceneError(f"{name}: must be a share of the points from 0 to 1 (0.1 = 10 %), "
                         f"got {value!r}")
    return float(value)


def _typed(key, value, kinds, what):
    if isinstance(value, bool) and bool not in kinds or not isinstance(value, kinds):
        raise SceneError(f"{key}: must be {what}, got {value!r}")
    return value


def parse_search(table, axes: list[Axis], mode: str) -> dict:
    """The ``[search]`` table checked: one of maximize/minimize, rounds >= 0, num >= 3."""
    if not isinstance(table, dict):
        raise SceneError(f"search: must be a table ({', '.join(SEARCH_KEYS)}), got {table!r}")
    unknown = sorted(set(table) - set(SEARCH_KEYS))
    if unknown:
        raise SceneError(f"search.{unknown[0]}: unknown key; allowed: {', '.join(SEARCH_KEYS)}")
    goals = [k for k in ("maximize", "minimize") if k in table]
    if len(goals) != 1:
        raise SceneError("search: give exactly one of maximize = '<results path>' or "
                         "minimize = '<results path>'")
    objective = _typed(f"search.{goals[0]}", table[goals[0]], (str,), "a results.json path")
    rounds = _typed("search.rounds", table.get("rounds", 2), (int,), "an integer >= 0")
    num = _typed("search.num", table.get("num", 5), (int,), "an integer >= 3")
    if rounds < 0 or num < 3:
        raise SceneError(f"search: rounds must be >= 0 and num >= 3, got {rounds}, {num}")
    method = _typed("search.method", table.get("method", "grid"), (str,),
                    f"one of {', '.join(SEARCH_METHODS)}")
    if method not in SEARCH_METHODS:
        raise SceneError(f"search.method: {method!r}; allowed: {', '.join(SEARCH_METHODS)}")
    max_points = _typed("search.max_points", table.get("max_points", 60), (int,),
                        "an integer >= 1")
    xtol = _typed("search.xtol", table.get("xtol", 1e-3), (int, float), "a number in (0, 1)")
    if max_points < 1 or not 0 < xtol < 1:
        raise SceneError(f"search: max_points must be >= 1 and 0 < xtol < 1, got {max_points}, "
                         f"{xtol}")
    if mode != "grid":
        raise SceneError(f"search: refinement starts from a grid; mode is {mode!r}, use 'grid'")
    if not any(a.is_range for a in axes):
        raise SceneError("search: needs at least one range axis {start, stop, num} to refine")
    return {"objective": objective, "sense": "max" if goals[0] == "maximize" else "min",
            "rounds": rounds, "num": num, "method": method, "max_points": max_points,
            "xtol": float(xtol)}


def parse_sweep(data: dict, base_dir: Path | str = ".", name: str = "sweep") -> SweepSpec:
    """Check a sweep table (a parsed SWEEP.toml) and read its base scene.

    Raises
    ------
    SceneError
        One line naming the offending key and what is allowed (unknown key, empty axis, ...).
    InputFileError
        The base scene is missing.
    """
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise SceneError(f"{unknown[0]}: unknown sweep key; allowed: {', '.join(KEYS)}")
    if "base" not in data:
        raise SceneError("base: missing; name the base scene, e.g. base = \"scene.toml\"")
    base = Path(_typed("base", data["base"], (str,), "a scene file name")).expanduser()
    base = base if base.is_absolute() else Path(base_dir) / base
    if not base.is_file():
        raise InputFileError(f"base: scene file not found: {base}")
    try:
        base_text = decode_utf8(base.read_bytes(), base)
    except OSError as exc:
        raise InputFileError(f"base: {base}: cannot read: {exc.strerror}") from None
    load_toml(base)  # syntax errors named now, not once per point
    mode = _typed("mode", data.get("mode", "grid"), (str,), f"one of {', '.join(MODES)}")
    if mode not in MODES:
        raise SceneError(f"mode: {mode!r} is not a sweep mode; allowed: {', '.join(MODES)}")
    raw_axes = data.get("axes")
    if not isinstance(raw_axes, dict) or not raw_axes:
        raise SceneError("axes: no axes; give [axes] with at least one "
                         "\"section.key\" = [values] or {start, stop, num}")
    axes = [parse_axis(k, v) for k, v in flatten_axes(raw_axes).items()]
    outputs = _typed("outputs", data.get("outputs", []), (list,), "a list of results.json paths")
    for o in outputs:
        if not isinstance(o, str) or not o or "." not in o:
            raise SceneError(f"outputs: {o!r} is not a results.json path like "
                             "'mechanism.shaking_force_max_n'")
    fixed = _typed("set", data.get("set", []), (list,), "a list of 'section.key=value'")
    for s in fixed:
        if not isinstance(s, str) or "=" not in s:
            raise SceneError(f"set: {s!r} is not a 'section.key=value' assignment")
    samples = data.get("samples")
    if samples is not None:
        _typed("samples", samples, (int,), "an integer >= 1")
        if samples < 1:
            raise SceneError(f"samples: must be >= 1, got {samples}")
    seed = _typed("seed", data.get("seed", 0), (int,), "an integer")
    timeout = data.get("timeout_s")
    if timeout is not None:
        _typed("timeout_s", timeout, (int, float), "a number of seconds > 0")
        if not (math.isfinite(timeout) and timeout > 0):
            raise SceneError(f"timeout_s: must be > 0, got {timeout!r}")
    figures = _typed("figures", data.get("figures", False), (bool,), "true or false")
    max_failed = check_max_failed("max_failed", data.get("max_failed", MAX_FAILED))
    search = parse_search(data["search"], axes, mode) if "search" in data else None
    if search and search["objective"] not in outputs:
        outputs = [*outputs, search["objective"]]
    if mode in ("random", "lhs") and samples is None:
        raise SceneError(f"samples: mode = {mode!r} needs samples = <number of points>")
    return SweepSpec(base=base, base_text=base_text, axes=axes, mode=mode, outputs=list(outputs),
                     fixed=list(fixed), samples=samples, seed=seed,
                     timeout_s=None if timeout is None else float(timeout),
                     max_failed=float(max_failed), figures=figures,
                     search=search, name=_typed("name", data.get("name", name), (str,), "a string"))


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and check a SWEEP.toml (see the module docstring for its keys)."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"file not found: {path}")
    return parse_sweep(load_toml(path), path.resolve().parent, name=path.stem)
