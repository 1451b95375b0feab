"""Benchmarks and seed-trend studies of crankmodal.dynamics.

Usage::

    .venv/bin/python benchmarks/dynamics_bench.py            # speed benchmarks (about 2 min)
    .venv/bin/python benchmarks/dynamics_bench.py --trends OUT_DIR   # seed 000 trend figures
    .venv/bin/python benchmarks/dynamics_bench.py --wear OUT_DIR     # seed 003 wear trend

Speed: (1) rigid slider-crank with one clearance joint: accepted steps per wall second and
simulated seconds per wall second; (2) four-star compressor (seed 000 machine), one 0.1 mm
clearance at the first-stage big end, 1480 rpm, 1 s simulated (target <= 60 s wall). Writes
``benchmarks/out/dynamics_bench.json``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from crankmodal.dynamics import Cylinder, SolverSettings, crank_train
from crankmodal.dynamics.analysis import simulate
from crankmodal.dynamics.build import build_mechanism, solver_settings
from crankmodal.dynamics.signals import amplitude_spectrum, impact_statistics
from crankmodal.dynamics.simulate import integrate
from crankmodal.runner import check
from crankmodal.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent


def slider_crank(clearance=1e-4, rpm=3000.0, stiffness=1e10, method="RK45"):
    cyl = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                   rod_com=0.042, piston_mass=0.75, gas_force=lambda a: 2000 + 1500 * np.cos(a))
    contact = dict(law="impact", law_params=dict(stiffness=stiffness, exponent=1.5, damping=300.0,
                                                 penetration=1e-4))
    return crank_train(0.035, [cyl], rpm, crank_mass=2.0, crank_inertia=0.01,
                       clearances={"big_end_1": {"clearance": clearance, "journal_radius": 0.02}},
                       contact_kw=contact)


def bench_slider_crank(t_end=0.2):
    rows = []
    for method in ("RK45", "LSODA", "Radau"):
        m = slider_crank()
        s = SolverSettings(method=method, max_step=np.deg2rad(2) / (3000 * np.pi / 30))
        out = integrate(m.system, m.q0, m.qd0, t_end, None, s)
        rows.append((method, out.n_steps, out.nfev, out.wall_time, out.n_steps / out.wall_time,
                     t_end / out.wall_time))
    print("\n| slider-crank, 1 clearance (0.1 mm), 3000 rpm, 0.2 s | steps | RHS evals | wall s |"
          " steps/s | sim s / wall s |\n|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.2f} | {r[4]:.0f} | {r[5]:.4f} |")
    return rows


def four_star_params(overrides=()):
    scene = load_scene(ROOT / "scenes" / "four_star_dynamics.toml", list(overrides))
    params = check(scene)
    return params["dynamics"], params["mechanism"]


def run_scene(scene, overrides):
    """Check a scene of ``scenes/`` with overrides, build its mechanism, simulate (720 per rev)."""
    params = check(load_scene(ROOT / "scenes" / scene, list(overrides)))
    p = params["dynamics"]
    mech = build_mechanism(p, params.get("mechanism"))
    h = simulate(mech, p["end_time"], 1.0 / (720 * mech.revolution_hz),
                 solver_settings(p, mech.revolution_hz * 60))
    return mech, h


def bench_four_star(t_end=1.0):
    p, mp = four_star_params([f"dynamics.end_time={t_end}"])
    mech = build_mechanism(p, mp)
    s = solver_settings(p, mech.revolution_hz * 60)
    t0 = time.perf_counter()
    h = simulate(mech, t_end, 1.0 / (360 * mech.revolution_hz), s)
    wall = time.perf_counter() - t0
    st = impact_statistics(h.onsets["big_end_1"])
    print(f"\nfour-star, 0.1 mm clearance at big_end_1, 1480 rpm (0.1 s ramp), {t_end:g} s simulated:"
          f" {wall:.1f} s wall (integration {h.wall_time:.1f} s, {h.nfev} RHS evaluations),"
          f" {st['impact_count']} impacts, energy balance {h.energy_error():.1e}")
    return wall


def trends(out: Path, t_end=0.3):
    """Seed 000 Figs. 24-26 and 19/20 trends, seed 003 impact velocity against wear."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    lines = []
    base = [f"dynamics.end_time={t_end}", "dynamics.ramp_time=0.0"]

    def run(extra):
        return run_scene("four_star_dynamics.toml", base + list(extra))

    # Fig. 24: clearance 0.10 / 0.15 / 0.20 mm at 1480 rpm
    fig, ax = plt.subplots(2, 3, figsize=(14, 7))
    spec_fig, sax = plt.subplots(figsize=(8, 4.5))
    _, ideal = run(["dynamics.clearances=[]"])
    sel = ideal.t > 0.1
    sp = amplitude_spectrum(ideal.t[sel], ideal.main_bearing_force[sel], 1480 / 60)
    sax.semilogy(sp.frequency_hz, sp.amplitude[:, 0] + 1e-3, "k", lw=0.8, label="ideal")
    for i, c in enumerate((1.0e-4, 1.5e-4, 2.0e-4)):
        mech, h = run([f"dynamics.clearances=[{{joint='big_end_1', clearance={c}, "
                       "journal_radius=0.02}]"])
        a, v = h.piston_acceleration[:, 0], h.piston_velocity[:, 0]
        ax[0, i].plot(h.t, a, lw=0.5)
        ax[0, i].set(title=f"clearance {c * 1e3:.2f} mm", xlabel="t [s]", ylabel="a [m/s²]")
        ax[1, i].plot(v, a, lw=0.3)
        ax[1, i].set(xlabel="v [m/s]", ylabel="a [m/s²]")
        st = impact_statistics(h.onsets["big_end_1"])
        rms_f = np.sqrt(np.mean(h.main_bearing_force[sel, 0] ** 2))
        lines.append(f"| clearance {c * 1e3:.2f} mm, 1480 rpm | {np.abs(a[sel]).max():.0f} | "
                     f"{st['impact_count']} | {st['impact_velocity_max']:.3f} | {rms_f:.0f} |")
        sp = amplitude_spectrum(h.t[sel], h.main_bearing_force[sel], 1480 / 60)
        sax.semilogy(sp.frequency_hz, sp.amplitude[:, 0] + 1e-3, lw=0.7,
                     label=f"{c * 1e3:.2f} mm")
    fig.tight_layout()
    fig.savefig(out / "trend_clearance_piston_acceleration.png", dpi=110)
    sax.set(xlim=(0, 1500), xlabel="frequency [Hz]", ylabel="main-bearing F_x amplitude [N]")
    sax.legend()
    spec_fig.tight_layout()
    spec_fig.savefig(out / "trend_clearance_spectrum.png", dpi=110)
    # Fig. 25: speed 148 / 740 / 1480 rpm at 0.1 mm
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    for i, rpm in enumerate((148.0, 740.0, 1480.0)):
        T = max(t_end, 3 * 60 / rpm)
        mech, h = run([f"dynamics.speed_rpm={rpm}", f"dynamics.end_time={T}"])
        st = impact_statistics(h.onsets["big_end_1"])
        ax[i].plot(h.t, h.piston_acceleration[:, 0], lw=0.5)
        ax[i].set(title=f"{rpm:g} rpm", xlabel="t [s]", ylabel="a [m/s²]")
        rate = st["impact_count"] / T
        lines.append(f"| 0.10 mm, {rpm:g} rpm | {np.abs(h.piston_acceleration[:, 0]).max():.0f} | "
                     f"{st['impact_count']} ({rate:.0f}/s) | {st['impact_velocity_max']:.3f} | - |")
    fig.tight_layout()
    fig.savefig(out / "trend_speed_piston_acceleration.png", dpi=110)
    # Figs. 19/20: friction off / on
    fig, sx = plt.subplots(figsize=(8, 4.5))
    for law in ("none", "coulomb"):
        mech, h = run([f"dynamics.friction.law='{law}'"])
        sp = amplitude_spectrum(h.t[sel], h.main_bearing_force[sel], 1480 / 60)
        sx.semilogy(sp.frequency_hz, sp.amplitude[:, 0] + 1e-3, lw=0.7, label=f"friction {law}")
        band = (sp.frequency_hz > 200) & (sp.frequency_hz < 1000)
        lines.append(f"| friction {law}, 0.10 mm | - | {len(h.onsets['big_end_1'])} | - | "
                     f"band 200-1000 Hz mean amplitude {sp.amplitude[band, 0].mean():.1f} N |")
    sx.set(xlim=(0, 1500), xlabel="frequency [Hz]", ylabel="main-bearing F_x amplitude [N]")
    sx.legend()
    fig.tight_layout()
    fig.savefig(out / "trend_friction_spectrum.png", dpi=110)
    print("\n| case | peak piston accel [m/s²] | impacts | max impact velocity [m/s] | "
          "RMS main-bearing F_x [N] |\n|---|---|---|---|---|")
    print("\n".join(lines))


def wear_trend(out: Path, t_end=0.08):
    """Seed 003: impact velocity in the worn big-end bearing against the wear (ellipse major axis)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for major in (5e-5, 1e-4, 1.5e-4, 2e-4):
        clear = (f"dynamics.clearances=[{{joint='big_end_1', clearance=5e-5, "
                 f"clearance_major={major}, journal_radius=0.024}}, {{joint='small_end_1', "
                 "clearance=2.5e-5, journal_radius=0.013}]")
        _, h = run_scene("slider_crank_dynamics.toml", [clear, f"dynamics.end_time={t_end}"])
        st = impact_statistics(h.onsets["big_end_1"])
        rows.append((major, st["impact_count"], st["impact_velocity_max"],
                     st["impact_velocity_rms"], h.energy_error()))
    print("\n| big-end wear: major-axis clearance [mm] (minor 0.05) | impacts | max impact "
          "velocity [m/s] | RMS impact velocity [m/s] | energy balance |\n|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0] * 1e3:.2f} | {r[1]} | {r[2]:.3f} | {r[3]:.3f} | {r[4]:.1e} |")
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([r[0] * 1e3 for r in rows], [r[2] for r in rows], "o-", label="max")
    ax.plot([r[0] * 1e3 for r in rows], [r[3] for r in rows], "s-", label="RMS")
    ax.set(xlabel="major-axis clearance of the worn big end [mm]",
           ylabel="impact velocity [m/s]", title="seed 003: impact velocity against wear")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "trend_wear_impact_velocity.png", dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trends", type=Path, default=None)
    ap.add_argument("--wear", type=Path, default=None)
    ap.add_argument("--four-star-time", type=float, default=1.0)
    a = ap.parse_args()
    if a.trends or a.wear:
        if a.trends:
            trends(a.trends)
        if a.wear:
            wear_trend(a.wear)
        return
    rows = bench_slider_crank()
    wall = bench_four_star(a.four_star_time)
    import json

    out = {"slider_crank_3000rpm_0p2s": [
        {"method": r[0], "steps": r[1], "rhs_evals": r[2], "wall_s": r[3], "steps_per_s": r[4],
         "sim_s_per_wall_s": r[5]} for r in rows],
        "four_star_1480rpm_wall_s": wall, "four_star_sim_s": a.four_star_time}
    path = ROOT / "benchmarks" / "out" / "dynamics_bench.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
