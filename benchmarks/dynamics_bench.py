"""Speed benchmarks of crankmodal.dynamics (the seed trends are in ``notebooks/seed_trends.py``).

Usage::

    .venv/bin/python benchmarks/dynamics_bench.py            # speed benchmarks (about 2 min)

Speed: (1) rigid slider-crank with one clearance joint: accepted steps per wall second and
simulated seconds per wall second; (2) four-star compressor (seed 000 machine), one 0.1 mm
clearance at the first-stage big end, 1480 rpm, 1 s simulated (issue 17 target <= 10 s wall),
``--repeats`` runs on the compiled right-hand side (median) and, with ``--python``, as many on
the Python path (``Multibody(compiled=False)``); (3) with ``--noise``, the same run with rtol
times (1 + k 1e-9), k = 1..3: the spread of the impact statistics from round-off alone. Writes
``benchmarks/out/dynamics_bench.json``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from crankmodal.dynamics import Cylinder, SolverSettings, crank_train
from crankmodal.dynamics.results.signals import impact_statistics
from crankmodal.dynamics.run.integrate import integrate
from crankmodal.dynamics.run.simulate import simulate
from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
from crankmodal.runner import check
from crankmodal.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent


def slider_crank(clearance=1e-4, rpm=3000.0, stiffness=1e10, method="RK45"):
    cyl = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                   rod_com=0.042, piston_mass=0.75, gas_force=lambda a: 2000 + 1500 * np.cos(a))
    contact = {"law": "impact", "law_params": {"stiffness": stiffness, "exponent": 1.5,
                                               "damping": 300.0, "penetration": 1e-4}}
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


def four_star_run(t_end=1.0, compiled=True, rtol_factor=1.0):
    """One four-star run (360 samples a revolution): wall time, evaluations, impact statistics."""
    from dataclasses import replace

    p, mp = four_star_params([f"dynamics.end_time={t_end}"])
    mech = build_mechanism(p, mp)
    mech.system.compiled = compiled
    s = solver_settings(p, mech.revolution_hz * 60)
    s = replace(s, rtol=s.rtol * rtol_factor)
    t0 = time.perf_counter()
    h = simulate(mech, t_end, 1.0 / (360 * mech.revolution_hz), s)
    wall = time.perf_counter() - t0
    st = impact_statistics(h.onsets["big_end_1"])
    # the converged per-revolution statistics (dynamics.statistics) after the ramp + 1 rev
    from crankmodal.dynamics.results.stats import statistics

    rs = statistics(h, mech.revolution_hz, p["ramp_time"] + 1.0 / mech.revolution_hz)
    mb = rs["main_bearing_force"]
    return {"compiled": compiled, "rtol_factor": rtol_factor, "wall_s": wall,
            "integration_s": h.wall_time, "rhs_evals": h.nfev,
            "impacts": int(st["impact_count"]),
            "v_impact_mean": float(st["impact_velocity_mean"]),
            "v_impact_max": float(st["impact_velocity_max"]),
            "fn_max": float(np.max(h.contact["big_end_1"]["fn"])),
            "energy_error": float(h.energy_error()),
            "mb_rms_mean": mb["rms"]["mean"], "mb_rms_sem": mb["rms"]["sem"],
            "mb_peak_mean": mb["per_rev_peak"]["mean"], "mb_peak_sem": mb["per_rev_peak"]["sem"]}


def bench_four_star(t_end=1.0, repeats=3, python=False, noise=False):
    # the first evaluation loads (or, after a change of compiled.py, compiles) the kernel
    four_star_run(0.11)
    rows = [four_star_run(t_end) for _ in range(repeats)]
    if python:
        rows += [four_star_run(t_end, compiled=False) for _ in range(repeats)]
    if noise:
        rows += [four_star_run(t_end, c, 1.0 + k * 1e-9) for c in ((True, False) if python
                                                                  else (True,))
                 for k in (1, 2, 3)]
    print(f"\n| four-star, 0.1 mm clearance at big_end_1, 1480 rpm, {t_end:g} s | path | rtol x |"
          " wall s | integration s | RHS evals | impacts | v_impact mean / max (m/s) |"
          " peak contact force (kN) | energy error | main bearing per-rev RMS (N, mean ± sem) |"
          " per-rev peak (N, mean ± sem) |\n|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| | {'compiled' if r['compiled'] else 'Python'} | {r['rtol_factor']:.9f} |"
              f" {r['wall_s']:.1f} | {r['integration_s']:.1f} | {r['rhs_evals']} |"
              f" {r['impacts']} | {r['v_impact_mean']:.3f} / {r['v_impact_max']:.3f} |"
              f" {r['fn_max'] / 1e3:.1f} | {r['energy_error']:.1e} |"
              f" {r['mb_rms_mean']:.0f} ± {r['mb_rms_sem']:.0f} |"
              f" {r['mb_peak_mean']:.0f} ± {r['mb_peak_sem']:.0f} |")
    for c in (True, False):
        w = [r["wall_s"] for r in rows if r["compiled"] == c and r["rtol_factor"] == 1.0]
        if w:
            print(f"{'compiled' if c else 'Python'}: median wall {np.median(w):.1f} s of {len(w)}")
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--four-star-time", type=float, default=1.0)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--python", action="store_true", help="also time the Python path")
    ap.add_argument("--noise", action="store_true", help="rtol x (1 + k 1e-9) runs, k = 1..3")
    ap.add_argument("--skip-slider-crank", action="store_true")
    a = ap.parse_args()
    rows = [] if a.skip_slider_crank else bench_slider_crank()
    four = bench_four_star(a.four_star_time, a.repeats, a.python, a.noise)
    import json

    walls = [r["wall_s"] for r in four if r["compiled"] and r["rtol_factor"] == 1.0]
    out = {"slider_crank_3000rpm_0p2s": [
        {"method": r[0], "steps": r[1], "rhs_evals": r[2], "wall_s": r[3], "steps_per_s": r[4],
         "sim_s_per_wall_s": r[5]} for r in rows],
        "four_star_1480rpm_wall_s": float(np.median(walls)), "four_star_sim_s": a.four_star_time,
        "four_star_runs": four}
    path = ROOT / "benchmarks" / "out" / "dynamics_bench.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
