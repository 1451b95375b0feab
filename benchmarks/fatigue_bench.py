"""Crankshaft fatigue verdict benchmark (issue 29, performance: "fatigue evaluation over one
cycle at every surface node of a 300k-DOF crank: <= 30 s").

A 300k-DOF P2 crank has 100 000 nodes. Its stress modes are synthesised (random numbers, the
arithmetic is the same as for real ones): 100 000 points x 6 components x 30 modes, over one
cycle of 360 steps, every point assessed (a real crank's surface is a fraction of its nodes,
so this is an upper bound). Timed: :func:`crankmodal.fatigue.fatigue_verdict` (chunked stress
history within its 64 MB budget, mean/amplitude, Goodman, yield check), with the modes stored
as float32 (as the reduction writes them) and as float64, and the fillet/oil-hole
classification of the 100 000 points on the seed 004 crank's parameters.

    .venv/bin/python benchmarks/fatigue_bench.py [--repeats 3] [--points 100000]

Wall and process CPU times, medians of the repeats; the machine is shared, so wall times are
"under load" (CPU time is the better guide there).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def verdict_case(n_points: int, n_modes: int, n_times: int, dtype) -> tuple[float, float]:
    from crankmodal.fatigue import fatigue_verdict
    from crankmodal.fem.materials import material

    rng = np.random.default_rng(29)
    S = (rng.standard_normal((n_points, 6, n_modes)) * 1e6).astype(dtype)  # Pa per unit ξ
    t = np.linspace(0.0, 2 * np.pi, n_times, endpoint=False)
    xi = np.array([np.sin((k % 6 + 1) * t + k) for k in range(n_modes)]) * 5.0
    points = rng.uniform(-0.2, 0.2, (n_points, 3))
    t0, c0 = time.perf_counter(), time.process_time()
    res = fatigue_verdict(S, xi, material("SG 700/2"), points)
    dt, dc = time.perf_counter() - t0, time.process_time() - c0
    assert res.safety_factor.shape == (n_points,)
    return dt, dc


def locations_case(n_points: int) -> tuple[float, float]:
    import tomllib

    from crankmodal.fatigue import crank_locations
    from crankmodal.geometry.params import params_from_dict

    with open(ROOT / "geometry" / "multi_bearing_compressor.toml", "rb") as fh:
        p = params_from_dict("crankshaft", tomllib.load(fh)["crankshaft"])
    rng = np.random.default_rng(4)
    x = rng.uniform([-0.12, -0.12, 0.0], [0.12, 0.12, 0.75], (n_points, 3))
    t0, c0 = time.perf_counter(), time.process_time()
    crank_locations(x, np.arange(n_points), p)
    return time.perf_counter() - t0, time.process_time() - c0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--modes", type=int, default=30)
    ap.add_argument("--times", type=int, default=360)
    a = ap.parse_args()
    cases = {
        f"verdict float32 modes ({a.points} pts x {a.modes} modes x {a.times} steps)":
            lambda: verdict_case(a.points, a.modes, a.times, np.float32),
        f"verdict float64 modes ({a.points} pts x {a.modes} modes x {a.times} steps)":
            lambda: verdict_case(a.points, a.modes, a.times, np.float64),
        f"crank_locations, seed 004 crank ({a.points} pts)": lambda: locations_case(a.points),
    }
    rows = {}
    for name, fn in cases.items():
        runs = [fn() for _ in range(a.repeats)]
        wall = [r[0] for r in runs]
        cpu = [r[1] for r in runs]
        rows[name] = {"wall_s": wall, "cpu_s": cpu, "wall_median_s": statistics.median(wall),
                      "cpu_median_s": statistics.median(cpu)}
        print(f"{name}: wall {' / '.join(f'{w:.2f}' for w in wall)} s (median "
              f"{statistics.median(wall):.2f}), CPU median {statistics.median(cpu):.2f} s")
    out = ROOT / "benchmarks" / "out"
    out.mkdir(parents=True, exist_ok=True)
    meta = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(),
            "load_average": os.getloadavg(), "repeats": a.repeats}
    (out / "fatigue_bench.json").write_text(json.dumps({"meta": meta, "cases": rows}, indent=1))


if __name__ == "__main__":
    main()
