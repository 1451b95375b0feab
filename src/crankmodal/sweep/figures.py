"""Maps of a sweep: each numeric output against the swept axes (PNG, one per output).

One axis varying: the output against it. Two: a colour map (``pcolormesh`` on a full grid,
points coloured by value otherwise - LHS, random, a search's refined points). More than two:
the two axes with the most distinct values, each point coloured by value (the others mixed in,
said in the title). Failed points are crosses. A search's best point is starred.
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


def sweep_maps(records: list[dict], axis_keys: list[str], outputs: list[str], out_dir: Path,
               log_axes: set[str] = frozenset(), best_point: int | None = None) -> list[str]:
    """Write ``sweep_<output>.png`` per numeric output; returns the file names."""
    varying = [k for k in axis_keys
               if all(_numeric(r["parameters"].get(k)) for r in records)
               and len({r["parameters"][k] for r in records}) > 1]
    if not varying or not records:
        return []
    varying.sort(key=lambda k: -len({r["parameters"][k] for r in records}))
    shown, rest = varying[:2], varying[2:]
    from ..plotting import pyplot

    plt = pyplot()
    files = []
    for o in outputs:
        ok = [r for r in records if r["status"] == "ok" and _numeric(r["outputs"].get(o))]
        if not ok:
            continue
        bad = [r for r in records if r not in ok]
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
        x = np.array([r["parameters"][shown[0]] for r in ok], float)
        v = np.array([r["outputs"][o] for r in ok], float)
        if len(shown) == 1:
            order = np.argsort(x)
            ax.plot(x[order], v[order], "o-")
            ax.set_ylabel(o)
            for r in bad:
                ax.axvline(r["parameters"][shown[0]], color="r", ls=":", lw=0.8)
        else:
            y = np.array([r["parameters"][shown[1]] for r in ok], float)
            xs, ys = np.unique(x), np.unique(y)
            grid = len(ok) == len(xs) * len(ys) and len(set(zip(x, y, strict=True))) == len(ok)
            if grid and len(xs) > 1 and len(ys) > 1:
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
            ax.set_ylabel(shown[1])
            if shown[1] in log_axes:
                ax.set_yscale("log")
            for r in ok:
                if r["point"] == best_point:
                    ax.plot(r["parameters"][shown[0]], r["parameters"][shown[1]], "w*", ms=14,
                            mec="k")
        if len(shown) == 1 and best_point is not None:
            for r in ok:
                if r["point"] == best_point:
                    ax.plot(r["parameters"][shown[0]], r["outputs"][o], "k*", ms=14)
        if shown[0] in log_axes:
            ax.set_xscale("log")
        ax.set_xlabel(shown[0])
        title = f"{o}, {len(ok)} points"
        if rest:
            title += f" ({', '.join(rest)} mixed in)"
        ax.set_title(title, fontsize="small")
        fig.tight_layout()
        name = f"sweep_{_slug(o)}.png"
        savefig_atomic(fig, out_dir / name, dpi=110)
        plt.close(fig)
        files.append(name)
    return files
