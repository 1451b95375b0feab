"""Table and figure of seed 003's resolved diagnostic regime (seed003_regime_full.toml).

Run the sweep first::

    crankmodal sweep scenes/sweeps/seed003_regime_full.toml --workers 1 \\
        --out out/sweeps/seed003_regime_full
    .venv/bin/python scenes/sweeps/plot_seed003_regime_full.py [out/sweeps/seed003_regime_full]

Prints a Markdown table (every point: the per-revolution and the per-cycle largest big-end
impact velocity with their standard errors) and writes ``docs/img/seed003_regime_full.png``.

Per cycle as well as per revolution: the engine is a four-stroke (one cycle = two
revolutions), so the per-revolution largest impact velocity alternates between the firing
revolution and the quiet one; the mean over revolutions is half the per-cycle one and its
standard error is dominated by that alternation. The per-cycle values are computed here from
each point's impact events (``impacts_big_end_1`` in ``dynamics.npz``: time, approach velocity)
over the same window as ``dynamics.statistics`` (whole cycles from its start), with the same
1 mm/s floor (``v_impact_min``).
"""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
IMG = ROOT / "docs" / "img"
ST = "dynamics.statistics.clearance_joints.big_end_1.impact_velocity.max_per_rev."
V_MIN = 1e-3  # m/s, the scene's v_impact_min (default)


def per_cycle(point_dir: Path) -> dict:
    """Largest big-end impact velocity of each four-stroke cycle (m/s): mean, sem, n."""
    res = json.loads((point_dir / "results.json").read_text())["dynamics"]
    win = res["statistics"]["window"]
    rev_hz = res["revolution_hz"]
    n_cyc = int(win["n_revolutions"]) // 2
    ev = np.load(point_dir / "dynamics.npz")["impacts_big_end_1"].reshape(-1, 2)
    b = np.floor((ev[:, 0] - win["start_s"]) * rev_hz / 2.0 + 1e-9).astype(int)
    keep = (b >= 0) & (b < n_cyc) & (ev[:, 1] >= V_MIN)
    vmax = np.zeros(n_cyc)
    np.maximum.at(vmax, b[keep], ev[keep, 1])
    sem = float(vmax.std(ddof=1) / math.sqrt(n_cyc)) if n_cyc > 1 else math.nan
    return {"mean": float(vmax.mean()) if n_cyc else math.nan, "sem": sem, "n": n_cyc}


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "out" / "sweeps" / \
        "seed003_regime_full"
    rows = [r for r in csv.DictReader((folder / "sweep.csv").open()) if r["status"] == "ok"]
    recs = {}
    for line in (folder / "records.jsonl").open():
        r = json.loads(line)
        recs[r["point"]] = r
    sj = json.loads((folder / "sweep.json").read_text())
    table = []
    for r in rows:
        rec = recs[int(r["point"])]
        cyc = per_cycle(folder / rec["dir"])
        table.append({"point": int(r["point"]), "round": int(r.get("round") or 0),
                      "rpm": float(r["mechanism.speed_rpm"]),
                      "pz": float(r["mechanism.gas.max_pressure"]) / 1e6,
                      "wear": float(r["dynamics.clearances.0.clearance_major"]) * 1e3,
                      "rev": float(r[ST + "mean"]), "rev_sem": float(r[ST + "sem"]),
                      "n_rev": int(float(r["dynamics.statistics.window.n_revolutions"])),
                      "cyc": cyc["mean"], "cyc_sem": cyc["sem"], "n_cyc": cyc["n"],
                      "wall": rec["wall_time_s"]})
    table.sort(key=lambda t: (t["round"], t["rpm"], t["pz"], t["wear"]))
    print("| rpm | p_z MPa | wear mm | per rev m/s | SE | per cycle m/s | SE | revs | wall s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for t in table:
        tag = "" if t["round"] == 0 else " (search)"
        print(f"| {t['rpm']:.0f}{tag} | {t['pz']:.2f} | {t['wear']:.4f} | {t['rev']:.3f} | "
              f"{t['rev_sem']:.3f} | {t['cyc']:.3f} | {t['cyc_sem']:.3f} | {t['n_rev']} | "
              f"{t['wall']:.0f} |")
    best = max(table, key=lambda t: t["rev"])
    bestc = max(table, key=lambda t: t["cyc"])
    print(f"best per rev: {best}")
    print(f"best per cycle: {bestc}")
    print(f"sweep: {sj.get('n_points')} points, wall {sum(t['wall'] for t in table):.0f} s "
          f"summed over points; search best {sj.get('search', {}).get('best_parameters')}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = [t for t in table if t["round"] == 0]
    pzs = sorted({round(t["pz"], 3) for t in grid})
    speeds = sorted({t["rpm"] for t in grid})
    wears = sorted({round(t["wear"], 4) for t in grid})
    vmax = max(t["cyc"] for t in grid)
    fig, axes = plt.subplots(1, len(pzs), figsize=(4.6 * len(pzs), 4.2), squeeze=False)
    for ax, pz in zip(axes[0], pzs):
        z = np.full((len(speeds), len(wears)), np.nan)
        for t in grid:
            if round(t["pz"], 3) == pz:
                z[speeds.index(t["rpm"]), wears.index(round(t["wear"], 4))] = t["cyc"]
        pc = ax.pcolormesh(np.arange(len(wears) + 1), np.arange(len(speeds) + 1), z,
                           vmin=0.0, vmax=vmax, cmap="viridis")
        for t in grid:
            if round(t["pz"], 3) == pz:
                i, j = speeds.index(t["rpm"]), wears.index(round(t["wear"], 4))
                ax.text(j + 0.5, i + 0.5, f"{t['cyc']:.3f}\n±{t['cyc_sem']:.3f}", ha="center",
                        va="center", fontsize=7,
                        color="w" if t["cyc"] < 0.5 * vmax else "k")
        ax.set_xticks(np.arange(len(wears)) + 0.5, [f"{w:.3f}" for w in wears])
        ax.set_yticks(np.arange(len(speeds)) + 0.5, [f"{s:.0f}" for s in speeds])
        ax.set_xlabel("worn big end: major radial clearance, mm")
        if ax is axes[0][0]:
            ax.set_ylabel("speed, rpm")
        ax.set_title(f"peak cylinder pressure {pz:g} MPa", fontsize=9)
    fig.colorbar(pc, ax=axes[0].tolist(),
                 label="largest big-end impact velocity per cycle (mean), m/s")
    fig.suptitle(f"Seed 003 diagnostic regime, 0.4 s per point: best per cycle "
                 f"{bestc['cyc']:.3g} ± {bestc['cyc_sem']:.2g} m/s at {bestc['rpm']:.0f} rpm, "
                 f"{bestc['pz']:.2f} MPa, {bestc['wear']:.3f} mm", fontsize=10)
    fig.savefig(IMG / "seed003_regime_full.png", dpi=110, bbox_inches="tight")
    plt.close(fig)


if __name__ == "__main__":
    main()
