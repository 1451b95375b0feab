"""The compiled integrator loop (issue 27 item 3) against solve_ivp, before and after in one run.

Usage::

    .venv/bin/python benchmarks/kernel_loop.py [--repeats 3] [--skip-flexible]

Three runs, each integrated ``--repeats`` times by ``scipy.integrate.solve_ivp`` ("before":
``integrate(..., compiled_loop=False)``) and by the compiled loop ("after"), alternating:

1. the rigid four-star (``scenes/four_star_dynamics.toml``, seed 000), one 0.1 mm clearance at
   big end 1, 1 s at 1480 rpm (target <= 2.0 s of integration);
2. seed 003's worn slider-crank (``scenes/slider_crank_dynamics.toml``, 0.08 s; target <= 0.4 s);
3. the flexible four-star (``scenes/seed000_flexible_both.toml``: crank 8 modes, four rods 4
   modes) with one 0.1 mm clearance at big end 1, 1 s (RK45 with impacts; target <= 5 s).

Each figure is the integration alone (``History.wall_time``: integrate(), events and output,
not the history's post-processing) as wall time, and the process's CPU time over the same
call of ``simulate`` (``time.process_time``: the machine is shared, so the wall time of one
run says little). Medians over the repeats. Also: the first-use compilation of the loop
(a fresh ``NUMBA_CACHE_DIR``, in a subprocess) and the cached load. Writes
``benchmarks/out/kernel_loop.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from functools import partial
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def _mechanism(scene, overrides):
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.runner import check
    from crankmodal.scene import load_scene

    params = check(load_scene(ROOT / "scenes" / scene, list(overrides)))
    p = params["dynamics"]
    mech = build_mechanism(p, params.get("mechanism"))
    return mech, p, solver_settings(p, mech.revolution_hz * 60)


def _flexible_mechanism(overrides):
    """The flexible four-star of seed000_flexible_both.toml, built as the [dynamics] stage
    builds it (its parts reduced by the stages, cached on disk after the first run)."""
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.dynamics.scene.flexstage import make_bodies
    from crankmodal.runner import check
    from crankmodal.scene import load_scene

    params = check(load_scene(ROOT / "scenes" / "seed000_flexible_both.toml", list(overrides)))
    p = params["dynamics"]
    bodies = make_bodies(p, params.get("mechanism"))
    mech = build_mechanism(p, params.get("mechanism"), bodies)
    mech.start = p["flexible"]["start"]
    if p["flexible"]["start"] == "quasi_static":
        mech.start_quasi_static()
    return mech, p, solver_settings(p, mech.revolution_hz * 60, flexible=True)


def timed(build, t_end, loop, samples_per_rev=720):
    """One simulate() of a fresh mechanism: integration wall time, CPU time, evaluations,
    method and the impacts counted at the first clearance joint."""
    from crankmodal.dynamics.run import simulate as sim_mod
    from crankmodal.dynamics.run.integrate import integrate

    mech, _, settings = build()
    saved = sim_mod.integrate
    cpu_integration = []

    def integrate_timed(*args, **kw):
        c = time.process_time()
        try:
            return integrate(*args, compiled_loop=loop, **kw)
        finally:
            cpu_integration.append(time.process_time() - c)

    sim_mod.integrate = integrate_timed
    try:
        c0 = time.process_time()
        h = sim_mod.simulate(mech, t_end, 1.0 / (samples_per_rev * mech.revolution_hz),
                             settings)
        cpu = time.process_time() - c0
    finally:
        sim_mod.integrate = saved
    name = next(iter(h.onsets), None)
    return {"loop": loop, "integration_wall_s": h.wall_time,
            "integration_cpu_s": sum(cpu_integration), "simulate_cpu_s": cpu,
            "rhs_evals": int(h.nfev), "method": getattr(h, "method", settings.method),
            "impacts": len(h.onsets[name]) if name else 0}


def compare(label, build, t_end, repeats):
    timed(build, min(t_end, 0.01), True)  # load the compiled code once
    rows = []
    for _ in range(repeats):
        for loop in (False, True):
            r = timed(build, t_end, loop)
            r["case"] = label
            rows.append(r)
            print(f"{label:38s} {'loop ' if loop else 'scipy'} integration "
                  f"{r['integration_wall_s']:6.2f} s wall {r['integration_cpu_s']:6.2f} s CPU, "
                  f"simulate {r['simulate_cpu_s']:6.2f} s CPU, {r['rhs_evals']} RHS, "
                  f"{r['impacts']} impacts", flush=True)
    med = {}
    for loop in (False, True):
        sel = [r for r in rows if r["loop"] == loop]
        med["loop" if loop else "scipy"] = {
            k: float(np.median([r[k] for r in sel]))
            for k in ("integration_wall_s", "integration_cpu_s", "simulate_cpu_s",
                      "rhs_evals", "impacts")}
    return rows, med


_COMPILE = """
import time, numpy as np
t0 = time.perf_counter()
from crankmodal.dynamics import Cylinder, SolverSettings, crank_train
from crankmodal.dynamics.run.integrate import integrate
cyl = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3, rod_com=0.042,
               piston_mass=0.75)
m = crank_train(0.035, [cyl], 3000.0, crank_mass=2.0, crank_inertia=0.01)
t1, c1 = time.perf_counter(), time.process_time()
integrate(m.system, m.q0, m.qd0, 1e-3, None, SolverSettings(method="RK45"))
print(time.perf_counter() - t1, time.process_time() - c1)
"""


def compile_times():
    """First use (fresh cache directory) and cached load, s (wall, CPU): a slider-crank's first
    integrate() (the kernel and the loop compiled or loaded) in a new process."""
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=tmp)
        for key in ("first_use_s", "cached_s"):
            r = subprocess.run([sys.executable, "-c", _COMPILE], env=env, capture_output=True,
                               text=True, check=True, cwd=ROOT)
            wall, cpu = (float(x) for x in r.stdout.split()[-2:])
            out[key] = wall
            out[key.replace("_s", "_cpu_s")] = cpu
            print(f"loop + kernel {key}: {wall:.2f} s wall, {cpu:.2f} s CPU", flush=True)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--skip-flexible", action="store_true")
    ap.add_argument("--skip-compile", action="store_true")
    ap.add_argument("--only-flexible", action="store_true")
    a = ap.parse_args(argv)
    out = {"load_average": os.getloadavg()}
    if not a.skip_compile:
        out["compile"] = compile_times()
    cases = [("rigid four-star 0.1 mm, 1 s, 1480 rpm",
              partial(_mechanism, "four_star_dynamics.toml", ["dynamics.end_time=1.0"]), 1.0),
             ("seed 003 worn slider-crank, 0.08 s",
              partial(_mechanism, "slider_crank_dynamics.toml", []), 0.08)]
    if not a.skip_flexible:
        clearance = ('dynamics.clearances=[{joint = "big_end_1", clearance = 1e-4, '
                     'journal_radius = 0.0225}]')
        cases.append(("flexible four-star + 0.1 mm, 1 s", partial(_flexible_mechanism, [
            "dynamics.end_time=1.0", "dynamics.run_rigid=false", clearance]), 1.0))
    if a.only_flexible:
        cases = cases[2:]
    out["cases"] = {}
    for label, build, t_end in cases:
        rows, med = compare(label, build, t_end, a.repeats)
        out["cases"][label] = {"runs": rows, "median": med}
    out["load_average_end"] = os.getloadavg()
    print("\n| run | scipy: integration wall / CPU (s) | loop: integration wall / CPU (s) | RHS "
          "scipy / loop | speed-up (integration CPU) |\n|---|---|---|---|---|")
    for label, c in out["cases"].items():
        s, lp = c["median"]["scipy"], c["median"]["loop"]
        print(f"| {label} | {s['integration_wall_s']:.2f} / {s['integration_cpu_s']:.2f} | "
              f"{lp['integration_wall_s']:.2f} / {lp['integration_cpu_s']:.2f} | "
              f"{s['rhs_evals']:.0f} / {lp['rhs_evals']:.0f} | "
              f"{s['integration_cpu_s'] / lp['integration_cpu_s']:.1f}x |")
    path = ROOT / "benchmarks" / "out" / ("kernel_loop_flexible.json" if a.only_flexible
                                          else "kernel_loop.json")
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))
    print(f"written: {path}")


if __name__ == "__main__":
    main()
