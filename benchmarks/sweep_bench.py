"""Benchmarks of crankmodal sweeps on Dask (issue 19). Run by hand on an idle machine.

Usage::

    .venv/bin/python benchmarks/sweep_bench.py                  # 16 dynamics points, 1000 cheap
    .venv/bin/python benchmarks/sweep_bench.py --dynamics-points 2 --cheap-points 4 \\
        --end-time 0.01                                          # a smoke check, seconds

(1) Speed-up: seed 003's slider-crank dynamics scene, big-end clearance x speed (16 points),
run one after another in this process (``execute_point`` in a loop: no Dask) and as a sweep on
a local cluster of 2 workers; reports the speed-up, the cluster start and the per-point
overhead ``(workers x sweep wall - sum of the points' own wall) / points``. Target: sweep
<= 0.6x serial, overhead <= 0.5 s per point. (2) Resumption: the same sweep from the CLI killed
(SIGKILL of its process group) when half the records are written, then re-run: the number of
points run again is printed against those recorded. (3) 1000 cheap ``[mechanism]`` points: the
client's resident memory (VmRSS) sampled through the sweep - first and last quarter. Writes
``benchmarks/out/sweep_bench.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DYN = ROOT / "scenes" / "slider_crank_dynamics.toml"
MECH = ROOT / "scenes" / "four_star_mechanism.toml"


def rss_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def dynamics_sweep(folder: Path, n: int, end_time: float | None) -> Path:
    speeds = 4 if n >= 4 else 1
    clear = max(1, n // speeds)
    text = (f'base = "{DYN}"\noutputs = ["dynamics.wall_time_s"]\n'
            + (f'set = ["dynamics.end_time={end_time!r}"]\n' if end_time else "")
            + "[axes]\n"
            f'"dynamics.clearances.0.clearance" = {{start = 2e-5, stop = 2e-4, num = {clear}, '
            f"log = {'true' if clear > 1 else 'false'}}}\n"
            f'"mechanism.speed_rpm" = {{start = 1500.0, stop = 4500.0, num = {speeds}}}\n')
    if clear == 1:
        text = text.replace("stop = 2e-4", "stop = 2e-5")
    if speeds == 1:
        text = text.replace("stop = 4500.0", "stop = 1500.0")
    p = folder / "dyn_sweep.toml"
    p.write_text(text)
    return p


def speedup(folder: Path, sweep: Path, workers: int) -> dict:
    from crankmodal.sweep import load_sweep, run_sweep
    from crankmodal.sweep.driver import dask_client, plan_tasks
    from crankmodal.sweep.execute import execute_point

    spec = load_sweep(sweep)
    tasks = plan_tasks(spec, spec.points(), (folder / "serial").resolve())
    t0 = time.perf_counter()
    serial = [execute_point(t) for t in tasks]
    t_serial = time.perf_counter() - t0
    t0 = time.perf_counter()
    with dask_client(workers=workers) as c:
        t_start = time.perf_counter() - t0
        t1 = time.perf_counter()
        res = run_sweep(spec, folder / "parallel", client=c)
        t_sweep = time.perf_counter() - t1
    recs = [json.loads(line) for line in (folder / "parallel" / "records.jsonl").open()]
    own = sum(r["wall_time_s"] for r in recs)
    n = len(tasks)
    return {"points": n, "workers": workers, "serial_s": t_serial,
            "serial_ok": sum(r["status"] == "ok" for r in serial), "cluster_start_s": t_start,
            "sweep_s": t_sweep, "sweep_ok": res["n_ok"], "ratio": t_sweep / t_serial,
            "ratio_with_start": (t_sweep + t_start) / t_serial, "speedup": t_serial / t_sweep,
            "overhead_per_point_s": (workers * t_sweep - own) / n}


def kill_and_resume(folder: Path, sweep: Path, workers: int) -> dict:
    from crankmodal.sweep import run_sweep
    from crankmodal.sweep.spec import load_sweep

    n = len(load_sweep(sweep).points())
    out = folder / "killed"
    rec = out / "records.jsonl"
    env = {**os.environ, "CRANKMODAL_QUIET": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "crankmodal.cli", "sweep", str(sweep),
                             "--out", str(out), "--workers", str(workers)], env=env,
                            start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    while proc.poll() is None:
        if rec.is_file() and rec.read_text().count("\n") >= max(1, n // 2):
            os.killpg(proc.pid, signal.SIGKILL)
            break
        time.sleep(0.05)
    proc.wait()
    kept = sum(1 for _ in rec.open()) if rec.is_file() else 0
    t0 = time.perf_counter()
    res = run_sweep(sweep, out, workers=workers)
    return {"points": n, "recorded_at_kill": kept, "run_again": res["ran"],
            "redone_beyond_missing": res["ran"] - (n - kept),
            "resume_s": time.perf_counter() - t0, "ok": res["n_ok"]}


def cheap(folder: Path, n: int, workers: int) -> dict:
    from crankmodal.sweep import run_sweep

    p = folder / "cheap.toml"
    p.write_text(f'base = "{MECH}"\noutputs = ["mechanism.shaking_force_max_n"]\n'
                 f'[axes]\n"mechanism.speed_rpm" = {{start = 500.0, stop = 3000.0, num = {n}}}\n')
    samples, stop = [], threading.Event()

    def sample():
        while not stop.is_set():
            samples.append((time.perf_counter(), rss_mb()))
            time.sleep(0.2)

    th = threading.Thread(target=sample, daemon=True)
    t0 = time.perf_counter()
    th.start()
    try:
        res = run_sweep(p, folder / "cheap", workers=workers)
    finally:
        stop.set()
        th.join()
    wall = time.perf_counter() - t0
    q = max(1, len(samples) // 4)
    return {"points": n, "ok": res["n_ok"], "wall_s": wall, "per_point_s": wall / n,
            "client_rss_mb_first_quarter_max": max(s for _, s in samples[:q]),
            "client_rss_mb_last_quarter_max": max(s for _, s in samples[-q:]),
            "client_rss_mb_max": max(s for _, s in samples)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dynamics-points", type=int, default=16)
    ap.add_argument("--cheap-points", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--end-time", type=float, default=None,
                    help="dynamics.end_time of every point (default: the scene's, 0.08 s)")
    ap.add_argument("--skip-kill", action="store_true")
    args = ap.parse_args()
    os.environ.setdefault("CRANKMODAL_QUIET", "1")
    out = {}
    with tempfile.TemporaryDirectory(prefix="sweep_bench_") as tmp:
        folder = Path(tmp)
        sweep = dynamics_sweep(folder, args.dynamics_points, args.end_time)
        out["speedup"] = s = speedup(folder, sweep, args.workers)
        print(f"dynamics, {s['points']} points: serial {s['serial_s']:.1f} s, {s['workers']} "
              f"workers {s['sweep_s']:.1f} s (+{s['cluster_start_s']:.1f} s cluster start): "
              f"ratio {s['ratio']:.2f} (target <= 0.6), speed-up {s['speedup']:.2f}, overhead "
              f"{s['overhead_per_point_s']:.3f} s per point (target <= 0.5)")
        if not args.skip_kill:
            out["resume"] = r = kill_and_resume(folder, sweep, args.workers)
            print(f"kill at 50 %: {r['recorded_at_kill']} of {r['points']} recorded, "
                  f"{r['run_again']} run again on resume, {r['ok']} ok")
        out["cheap"] = c = cheap(folder, args.cheap_points, args.workers)
        print(f"{c['points']} cheap points: {c['wall_s']:.1f} s ({c['per_point_s'] * 1e3:.0f} ms"
              f" per point); client RSS {c['client_rss_mb_first_quarter_max']:.0f} MB (first "
              f"quarter) -> {c['client_rss_mb_last_quarter_max']:.0f} MB (last quarter)")
    dest = ROOT / "benchmarks" / "out" / "sweep_bench.json"
    dest.parent.mkdir(exist_ok=True)
    dest.write_text(json.dumps(out, indent=2) + "\n")
    print(f"written: {dest}")


if __name__ == "__main__":
    main()
