"""Stiff runs (issue 27 item 3, implicit part): before and after in one run.

Usage::

    .venv/bin/python benchmarks/kernel_stiff.py [--repeats 3] [--cases flex loom coupler film]

Each case runs its scene (as the ``[dynamics]`` stage builds it, ``solver.method`` as the scene
or ``auto`` decides) three ways, interleaved so that the three see the same machine load:

* ``before``: SciPy's method with its own finite-difference Jacobian (``2 n + 6`` Python calls
  of the right-hand side per Jacobian);
* ``jacobian``: SciPy's method with the compiled Jacobian (:mod:`crankmodal.dynamics.kernel.
  jacobian`);
* ``after``: what ``integrate`` does now (Radau: the compiled step of :mod:`crankmodal.
  dynamics.kernel.implicit`; LSODA, BDF: the compiled Jacobian).

Reported per case and way: the medians over ``--repeats`` runs of the integration's CPU time
(``time.process_time``, the figure to read on a loaded machine) and wall time, the evaluations
and simulated seconds per wall second. Writes ``benchmarks/out/kernel_stiff.json``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: name: (scene, end time s, --set overrides, what)
CASES = {
    "flex": ("benchmarks/scenes/flexible_slider_crank.toml", 0.1, [],
             "slider-crank, crank 20 + rod 14 modes, 1500 rpm (Radau)"),
    "loom": ("scenes/loom_four_bar_dynamics.toml", 1.0, [],
             "seed 001 loom, lubricated coupler pin (LSODA)"),
    "coupler": ("scenes/seed001_flexible_coupler.toml", 0.4, ["dynamics.run_rigid=false"],
                "seed 001 loom, flexible coupler + lubricated pin (Radau)"),
    "film": ("scenes/slider_crank_dynamics.toml", 0.08,
             ["dynamics.clearances.0.viscosity=0.0175", "dynamics.clearances.0.bearing_length=0.03"],
             "seed 003 slider-crank, lubricated big end (LSODA; a worn bore takes no film)"),
}
WAYS = ("before", "jacobian", "after")


def build(scene, end_time, sets):
    """The mechanism, solver settings and output step of ``scene`` as the stage builds them."""
    from crankmodal.dynamics.run import timescales
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.dynamics.scene.keys import flexible_keys
    from crankmodal.runner import stage_module
    from crankmodal.scene import load_scene

    sc = load_scene(ROOT / scene, [f"dynamics.end_time={end_time}", *sets])
    p = stage_module("dynamics").validate(sc.sections["dynamics"], sc)
    mp = (stage_module("mechanism").validate(sc.sections["mechanism"], sc)
          if "mechanism" in sc.sections else None)
    bodies = None
    if flexible_keys(p):
        from crankmodal.dynamics.scene.flexstage import make_bodies

        bodies = make_bodies(p, mp)
    mech = build_mechanism(p, mp, bodies)
    settings = solver_settings(p, 60.0 * mech.revolution_hz, flexible=bodies is not None)
    settings = replace(settings, time_scales=tuple(timescales.joint_time_scales(mech)))
    mech.start = p["flexible"]["start"]
    dt = p["output_step"] or 1.0 / (360.0 * mech.revolution_hz)
    return mech, settings, dt


def run_once(case, way):
    """One run of ``case`` the ``way`` named: integration CPU and wall time, evaluations."""
    from crankmodal.dynamics.kernel import implicit
    from crankmodal.dynamics.run import simulate as sim

    scene, end_time, sets, _ = CASES[case]
    mech, settings, dt = build(scene, end_time, sets)
    saved = implicit.solver_options, implicit.applicable
    if way == "before":
        implicit.solver_options = lambda *a, **k: {}
    elif way == "jacobian":
        implicit.applicable = lambda *a, **k: False
    inner = sim.integrate
    got = {}

    def timed(*a, **k):
        c0, w0 = time.process_time(), time.perf_counter()
        out = inner(*a, **k)
        got["cpu"], got["wall"] = time.process_time() - c0, time.perf_counter() - w0
        return out

    sim.integrate = timed
    try:
        hist = sim.simulate(mech, end_time, dt, settings)
    finally:
        sim.integrate = inner
        implicit.solver_options, implicit.applicable = saved
    return {"cpu_s": got["cpu"], "wall_s": got["wall"], "rhs_evals": hist.nfev,
            "method": settings.method, "energy_balance_error": hist.energy_error()}


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    a = ap.parse_args(argv)
    out = {}
    for case in a.cases:
        for way in WAYS:  # warm-up: compilation and the reduced parts' caches
            run_once(case, way)
        runs = {w: [] for w in WAYS}
        for _ in range(a.repeats):
            for way in WAYS:
                runs[way].append(run_once(case, way))
        end_time = CASES[case][1]
        out[case] = {"what": CASES[case][3], "end_time_s": end_time}
        for way in WAYS:
            r = runs[way]
            cpu = statistics.median(x["cpu_s"] for x in r)
            wall = statistics.median(x["wall_s"] for x in r)
            out[case][way] = {"cpu_s": cpu, "wall_s": wall, "rhs_evals": r[-1]["rhs_evals"],
                              "method": r[-1]["method"], "cpu_runs": [x["cpu_s"] for x in r],
                              "wall_runs": [x["wall_s"] for x in r],
                              "sim_s_per_wall_s": end_time / wall,
                              "sim_s_per_cpu_s": end_time / cpu}
            print(f"{case:8s} {way:9s} {r[-1]['method']:6s} CPU {cpu:7.3f} s  wall {wall:7.3f} s  "
                  f"{r[-1]['rhs_evals']:7d} RHS  {end_time / wall:.3f} sim-s/wall-s  "
                  f"{end_time / cpu:.3f} sim-s/CPU-s", flush=True)
        b, f = out[case]["before"], out[case]["after"]
        print(f"{case:8s} after/before: CPU {b['cpu_s'] / f['cpu_s']:.2f}x, wall "
              f"{b['wall_s'] / f['wall_s']:.2f}x", flush=True)
    path = ROOT / "benchmarks" / "out" / "kernel_stiff.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))
    print(f"written: {path}")


if __name__ == "__main__":
    main()
