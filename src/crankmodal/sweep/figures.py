"""Maps of a sweep: each numeric output against the swept axes (PNG, one per output).

One numeric axis varying: the output against it. Two: a colour map (``pcolormesh`` on a full
grid, points coloured by value otherwise - LHS, random, a search's refined points). More than
two: the two axes with the most distinct values, each cell or point showing the largest value
over the other axes (the smallest for a minimising search; the title says so). Only text axes
varying (``joint = ["big_end_1", ...]``): bars per value. Failed points are crosses, a search's
best point is starred.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..results import savefig_atomic


def _numeric(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _slug(path: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", path)


def _reduce(xy_v: list[tuple], pick) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points ``(x, y, value)`` with equal (x, y) merged by ``pick`` (max or min)."""
    cells: dict = {}
    for x, y, v in xy_v:
        cells[(x, y)] = v if (x, y) not in cells else pick(cells[(x, y)], v)
    keys = list(cells)
    return (np.array([k[0] for k in keys], float), np.array([k[1] for k in keys], float),
            np.array([cells[k] for k in keys], float))


def _bars(ax, ok, bad, key, o):
    labels = list(dict.fromkeys(str(r["parameters"][key]) for r in ok + bad))
    vals = {str(r["parameters"][key]): r["outputs"][o] for r in ok}
    ax.bar(range(len(labels)), [vals.get(lab, np.nan) for lab in labels])
    ax.set_xticks(range(len(labels)), labels, rotation=30, ha="right")
    ax.set_xlabel(key)
    ax.set_ylabel(o)


def sweep_maps(records: list[dict], axis_keys: list[str], outputs: list[str], out_dir: Path,
               log_axes: set[str] = frozenset(), best_point: int | None = None,
               sense: str = "max") -> list[str]:
    """Write ``sweep_<output>.png`` per numeric output; returns the file names."""
    if not records:
        return []

    def distinct(k):
        return len({str(r["parameters"].get(k)) for r in records})

    varying = [k for k in axis_keys if distinct(k) > 1]
    numeric = [k for k in varying if all(_numeric(r["parameters"].get(k)) for r in records)]
    text = [k for k in varying if k not in numeric]
    if not numeric and len(text) != 1:
        return []
    numeric.sort(key=lambda k: -distinct(k))
    shown, rest = numeric[:2], numeric[2:] + text
    pick = min if sense == "min" else max
    from ..plotting import pyplot

    plt = pyplot()
    files = []
    for o in outputs:
        ok = [r for r in records if r["status"] == "ok" and _numeric(r["outputs"].get(o))]
        if not ok:
            continue
        bad = [r for r in records if r not in ok]
        best = next((r for r in ok if r["point"] == best_point), None)
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
        if not shown:
            _bars(ax, ok, bad, text[0], o)
        elif len(shown) == 1:
            x, _, v = _reduce([(r["parameters"][shown[0]], 0.0, r["outputs"][o]) for r in ok],
                              pick)
            order = np.argsort(x)
            ax.plot(x[order], v[order], "o-")
            ax.set_ylabel(o)
            for r in bad:
                ax.axvline(r["parameters"][shown[0]], color="r", ls=":", lw=0.8)
            if best is not None:
                ax.plot(best["parameters"][shown[0]], best["outputs"][o], "k*", ms=14)
        else:
            x, y, v = _reduce([(r["parameters"][shown[0]], r["parameters"][shown[1]],
                                r["outputs"][o]) for r in ok], pick)
            xs, ys = np.unique(x), np.unique(y)
            if len(x) == len(xs) * len(ys) and len(xs) > 1 and len(ys) > 1:
                z = np.full((len(ys), len(xs)), np.nan)
                z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = v
                im = ax.pcolormesh(xs, ys, z, shading="nearest")
            else:
                im = ax.scatter(x, y, c=v, s=36)
            fig.colorbar(im, ax=ax, label=o)
            if bad:
                ax.plot([r["parameters"][shown[0]] for r in bad],
                        [r["parameters"][shown[1]] for r in bad], "rx", label="failed")
                ax.legend(loc="best", fontsize="small")
            if best is not None:
                ax.plot(best["parameters"][shown[0]], best["parameters"][shown[1]], "w*",
                        ms=14, mec="k")
            ax.set_ylabel(shown[1])
            if shown[1] in log_axes:
                ax.set_yscale("log")
        if shown:
            ax.set_xlabel(shown[0])
            if shown[0] in log_axes:
                ax.set_xscale("log")
        title = f"{o}, {len(ok)} points"
        if rest and shown:
            title += f"; {sense} over {', '.join(rest)}"
        ax.set_title(title, fontsize="small")
        fig.tight_layout()
        name = f"sweep_{_slug(o)}.png"
        savefig_atomic(fig, out_dir / name, dpi=110)
        plt.close(fig)
        files.append(name)
    return files
