"""Figures and numbers of the four sweep studies (README: Sweep studies), from their sweep.csv.

Run the sweeps first (``crankmodal sweep scenes/sweeps/<name>.toml --out out/sweeps/<name>``),
then ``.venv/bin/python scenes/sweeps/plot_studies.py [out/sweeps]``: writes
``docs/img/sweep_*.png`` and prints the numbers the README quotes.
"""

from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
IMG = ROOT / "docs" / "img"
ST = "dynamics.statistics."


def rows(folder: Path, name: str) -> list[dict]:
    path = folder / name / "sweep.csv"
    if not path.is_file():
        print(f"{name}: no {path}, skipped")
        return []
    return list(csv.DictReader(path.open()))


def num(r: dict, key: str) -> float:
    v = r.get(key)
    return float(v) if v not in (None, "") else math.nan


def counterweight(folder: Path) -> None:
    rs = rows(folder, "seed000_counterweight")
    if not rs:
        return
    cwk = "dynamics.crank_train.counterweight_mass_radius"
    x1, y1 = ("dynamics.main_bearing_order_amplitude_n.1.0",
              "dynamics.main_bearing_order_amplitude_n.1.1")
    peak = ST + "main_bearing_force.per_rev_peak.mean"
    target = 0.2688  # [mechanism] counterweight_mass_radius_kg_m
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for gas, style in (("none", "o-"), ("compressor", "s--")):
        sel = sorted((r for r in rs if r["mechanism.gas.model"] == gas and r["status"] == "ok"),
                     key=lambda r: num(r, cwk))
        mr = np.array([num(r, cwk) for r in sel])
        a1 = np.array([math.hypot(num(r, x1), num(r, y1)) / math.sqrt(2) for r in sel])
        pk = np.array([num(r, peak) for r in sel])
        label = "no gas" if gas == "none" else "with gas forces"
        axes[0].plot(mr, a1 / 1e3, style, label=label)
        axes[1].plot(mr, pk / 1e3, style, label=label)
        i = int(np.argmin(a1))
        # the V's vertex from the neighbours either side of the smallest point
        j, k = (i - 1, i) if a1[i - 1] < a1[min(i + 1, len(a1) - 1)] else (i, i + 1)
        w2 = (a1[0] - a1[-1]) / (mr[-1] - mr[0]) if gas == "none" else None
        print(f"counterweight, {label}: order-1 min {a1[i]:.0f} N at {mr[i]:.3f} kg m; "
              f"per-rev peak min {np.nanmin(pk):.0f} N at {mr[int(np.nanargmin(pk))]:.3f} kg m; "
              f"at 0: order 1 {a1[0]:.0f} N, peak {pk[0]:.0f} N")
        if w2 is not None:
            slope = (a1[0] - a1[1]) / (mr[1] - mr[0])
            vertex = 0.5 * (mr[j] + a1[j] / slope + mr[k] - a1[k] / slope)
            print(f"  V slope {slope:.0f} N/(kg m), vertex {vertex:.4f} kg m "
                  f"({100 * (vertex / target - 1):+.2f} % of {target})")
    for ax, what in zip(axes, ("order-1 amplitude of the main-bearing force, kN",
                               "per-revolution peak main-bearing force (mean), kN")):
        ax.axvline(target, color="k", lw=0.8, ls=":")
        ax.annotate("[mechanism] first-order\ncounterweight 0.2688 kg m", (target, 0.95),
                    xycoords=("data", "axes fraction"), ha="right", va="top", fontsize=8,
                    xytext=(-4, 0), textcoords="offset points")
        ax.set_xlabel("counterweight mass x radius opposite the pin, kg m")
        ax.set_ylabel(what)
        ax.grid(alpha=0.3)
        ax.legend(loc="lower left", fontsize=8)
    fig.suptitle("Seed 000 Fig. 22a: four-star main-bearing force against the counterweight "
                 "(1480 rpm, ideal joints)", fontsize=10)
    fig.tight_layout()
    fig.savefig(IMG / "sweep_counterweight.png", dpi=110)
    plt.close(fig)


def fig27(folder: Path) -> None:
    rs = rows(folder, "seed000_fig27_big_ends")
    if not rs:
        return
    jk = "dynamics.clearances.0.joint"
    rs = sorted(rs, key=lambda r: r[jk])
    names = [r[jk] for r in rs]
    mb = np.array([num(r, ST + "main_bearing_force.per_rev_peak.mean") for r in rs])
    mbs = np.array([num(r, ST + "main_bearing_force.per_rev_peak.sem") for r in rs])
    cf = np.array([num(r, ST + f"clearance_joints.{n}.contact_force.per_rev_peak.mean")
                   for r, n in zip(rs, names)])
    ipr = np.array([num(r, ST + f"clearance_joints.{n}.impact_velocity.count_per_rev.mean")
                    for r, n in zip(rs, names)])
    vmax = np.array([num(r, ST + f"clearance_joints.{n}.impact_velocity.max_per_rev.mean")
                     for r, n in zip(rs, names)])
    acc = np.array([[num(r, ST + f"piston_acceleration.{i}.per_rev_peak.mean")
                     for i in range(4)] for r in rs])
    raw = np.array([num(r, "dynamics.main_bearing_force_peak_n") for r in rs])
    for n, a, s, c, i, v, p, rw in zip(names, mb, mbs, cf, ipr, vmax, acc, raw):
        print(f"fig27 {n}: main bearing per-rev peak {a:.0f} +- {s:.0f} N (raw peak {rw:.0f} N), "
              f"joint contact per-rev peak {c:.0f} N, {i:.2f} impacts/rev, v_max/rev {v:.3f} "
              f"m/s, piston per-rev peaks {', '.join(f'{x:.0f}' for x in p)} m/s^2")
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.3))
    x = np.arange(len(names))
    axes[0].bar(x, mb / 1e3, yerr=mbs / 1e3, capsize=4, color="C0")
    axes[0].set_ylabel("main-bearing per-rev peak, kN (mean ± SE)")
    axes[1].bar(x, cf / 1e3, color="C1")
    axes[1].set_ylabel("contact force in the joint, per-rev peak, kN")
    axes[2].bar(x - 0.2, ipr, width=0.4, color="C2", label="impacts per revolution")
    ax2 = axes[2].twinx()
    ax2.bar(x + 0.2, vmax, width=0.4, color="C3", label="largest impact velocity / rev")
    axes[2].set_ylabel("impacts per revolution (mean)", color="C2")
    ax2.set_ylabel("largest impact velocity / rev (mean), m/s", color="C3")
    for ax in axes:
        ax.set_xticks(x, [n.replace("big_end_", "big end ") for n in names])
        ax.grid(alpha=0.3, axis="y")
    fig.suptitle("Seed 000 Fig. 27: 0.1 mm clearance in one big end at a time "
                 "(four-star, 1480 rpm, 0.5 s)", fontsize=10)
    fig.tight_layout()
    fig.savefig(IMG / "sweep_fig27_big_ends.png", dpi=110)
    plt.close(fig)


def surface(ax, fig, xs, ys, z, label, xlabel, ylabel, fmt="{:.3g}", vmin=None, vmax=None):
    ux, uy = np.unique(xs), np.unique(ys)
    grid = np.full((len(uy), len(ux)), np.nan)
    for x, y, v in zip(xs, ys, z):
        grid[np.searchsorted(uy, y), np.searchsorted(ux, x)] = v
    def edges(u):
        m = 0.5 * (u[1:] + u[:-1])
        return np.concatenate([[2 * u[0] - m[0]], m, [2 * u[-1] - m[-1]]])
    pc = ax.pcolormesh(edges(ux), edges(uy), grid, shading="flat", cmap="viridis", vmin=vmin,
                       vmax=vmax)
    for i, y in enumerate(uy):
        for j, x in enumerate(ux):
            if np.isfinite(grid[i, j]):
                ax.text(x, y, fmt.format(grid[i, j]), ha="center", va="center", fontsize=7,
                        color="w" if grid[i, j] < 0.5 * (np.nanmin(grid) + np.nanmax(grid)) else "k")
    fig.colorbar(pc, ax=ax, label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    return grid


def clearance_speed(folder: Path) -> None:
    rs = [r for r in rows(folder, "seed000_clearance_speed") if r.get("status") == "ok"]
    if not rs:
        return
    c = np.array([num(r, "dynamics.clearances.0.clearance") * 1e3 for r in rs])
    n = np.array([num(r, "mechanism.speed_rpm") for r in rs])
    mb = np.array([num(r, ST + "main_bearing_force.per_rev_peak.mean") for r in rs]) / 1e3
    pa = np.array([num(r, ST + "piston_acceleration.0.per_rev_peak.mean") for r in rs])
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    g1 = surface(axes[0], fig, c, n, mb, "main-bearing force, per-rev peak (mean), kN",
                 "big end 1 radial clearance, mm", "speed, rpm")
    g2 = surface(axes[1], fig, c, n, pa, "piston 1 acceleration, per-rev peak (mean), m/s²",
                 "big end 1 radial clearance, mm", "speed, rpm", fmt="{:.0f}")
    fig.suptitle("Seed 000 Figs. 24/25 as surfaces: four-star, clearance in big end 1 "
                 "(0.5 s, 0.1 s ramp)", fontsize=10)
    fig.tight_layout()
    fig.savefig(IMG / "sweep_clearance_speed.png", dpi=110)
    plt.close(fig)
    print(f"clearance x speed: {len(rs)} ok; clearances {np.unique(c)} mm, speeds {np.unique(n)}")
    print("  main bearing per-rev peak kN (rows speed, cols clearance):\n", np.round(g1, 2))
    print("  piston 1 per-rev peak m/s^2:\n", np.round(g2, 0))


def regime(folder: Path) -> None:
    rs = [r for r in rows(folder, "seed003_regime")]
    if not rs:
        return
    obj = ST + "clearance_joints.big_end_1.impact_velocity.max_per_rev.mean"
    ok = [r for r in rs if r["status"] == "ok" and r.get(obj) not in (None, "")]
    speed = np.array([num(r, "mechanism.speed_rpm") for r in ok])
    wear = np.array([num(r, "dynamics.clearances.0.clearance_major") * 1e3 for r in ok])
    pz = np.array([num(r, "mechanism.gas.max_pressure") / 1e6 for r in ok])
    v = np.array([num(r, obj) for r in ok])
    coarse = np.array([r.get("round", "0") in ("0", "", None) for r in ok])
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    for ax, p in zip(axes, sorted(set(np.round(pz[coarse], 3)))):
        sel = coarse & np.isclose(pz, p)
        surface(ax, fig, wear[sel], speed[sel], v[sel],
                "largest big-end impact velocity per rev (mean), m/s",
                "worn big end: major radial clearance, mm", "speed, rpm", vmin=0.0,
                vmax=float(np.nanmax(v[coarse])))
        ax.set_title(f"peak cylinder pressure {p:g} MPa", fontsize=9)
    b = int(np.nanargmax(v))
    ps = sorted(set(np.round(pz[coarse], 3)))
    axes[int(np.argmin([abs(p - pz[b]) for p in ps]))].plot(wear[b], speed[b], "r*", ms=14,
                                                             mec="k")
    fig.suptitle(f"Seed 003 diagnostic regime: best {v[b]:.3g} m/s at {speed[b]:.0f} rpm, "
                 f"{pz[b]:.2f} MPa, {wear[b]:.3f} mm (red star; search points not on the grid)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(IMG / "sweep_seed003_regime.png", dpi=110)
    plt.close(fig)
    print(f"seed003 regime: {len(rs)} points, {len(ok)} with the objective; best {v[b]:.4g} m/s "
          f"at {speed[b]:.0f} rpm, {pz[b]:.3f} MPa, wear {wear[b]:.4f} mm")
    for r in sorted(ok, key=lambda r: -num(r, obj))[:5]:
        print("   ", {k.split(".")[-1]: r[k] for k in ("mechanism.speed_rpm",
              "mechanism.gas.max_pressure", "dynamics.clearances.0.clearance_major", obj,
              "dynamics.clearance_joints.big_end_1.impact_velocity_max")})


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "out" / "sweeps"
    IMG.mkdir(parents=True, exist_ok=True)
    counterweight(folder)
    fig27(folder)
    clearance_speed(folder)
    regime(folder)


if __name__ == "__main__":
    main()
