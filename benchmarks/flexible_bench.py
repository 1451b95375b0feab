"""Speed of the flexible-body dynamics (issue 17), run by hand on an idle machine.

Usage::

    .venv/bin/python benchmarks/flexible_bench.py [--end-time 0.1] [--methods auto RK45]
        [--four-star-end-time 1.0] [--skip-four-star]

(1) The flexible slider-crank of ``benchmarks/scenes/flexible_slider_crank.toml`` (the four-star's
crank with 20 in-plane modes and its rod with 14, 1500 rpm; target >= 0.05 simulated s per wall
s) with each solver method; (2) the four-star with a flexible crank (8 modes), four flexible rods
(4 modes) and one 0.1 mm clearance at big end 1, 1480 rpm (target <= 120 s for 1 s). The parts
are reduced once and cached (the first run takes longer). Writes
``benchmarks/out/flexible_bench.json``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CLI = [sys.executable, "-m", "crankmodal.cli"]


def run(scene, sets, out):
    cmd = CLI + ["run", str(scene), "--out", str(out), "--quiet", "--no-figures"]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, cwd=ROOT)
    return json.loads((Path(out) / "results.json").read_text())["dynamics"]


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--end-time", type=float, default=0.1)
    ap.add_argument("--methods", nargs="+", default=["auto", "RK45"])
    ap.add_argument("--four-star-end-time", type=float, default=1.0)
    ap.add_argument("--skip-four-star", action="store_true")
    a = ap.parse_args(argv)
    out = {"slider_crank": {}, "four_star": None}
    with tempfile.TemporaryDirectory() as tmp:
        scene = ROOT / "benchmarks" / "scenes" / "flexible_slider_crank.toml"
        for m in a.methods:
            r = run(scene, [f"dynamics.end_time={a.end_time}", f"dynamics.solver.method={m}"],
                    Path(tmp) / m)
            w = r["integration_wall_time_s"]
            out["slider_crank"][m] = {"end_time_s": a.end_time, "wall_s": w,
                                      "solver_method": r.get("solver_method", m),
                                      "sim_s_per_wall_s": a.end_time / w,
                                      "rhs_evals": r["rhs_evals"], "ms_per_rhs": 1e3 * w / r["rhs_evals"],
                                      "energy_balance_error": r["energy_balance_error"]}
            print(f"slider-crank 20 + 14 modes, {m} ({r.get('solver_method', m)}): {a.end_time} s in {w:.1f} s = "
                  f"{a.end_time / w:.4f} sim-s per wall-s (target >= 0.05), {r['rhs_evals']} RHS, "
                  f"{1e3 * w / r['rhs_evals']:.2f} ms each")
        if not a.skip_four_star:
            scene = ROOT / "scenes" / "seed000_flexible_both.toml"
            sets = [f"dynamics.end_time={a.four_star_end_time}", "dynamics.run_rigid=false",
                    ('dynamics.clearances=[{joint = "big_end_1", clearance = 1e-4, '
                     'journal_radius = 0.0225}]')]
            r = run(scene, sets, Path(tmp) / "four_star")
            w = r["integration_wall_time_s"]
            out["four_star"] = {"end_time_s": a.four_star_end_time, "wall_s": w,
                                "solver_method": r.get("solver_method"),
                                "rhs_evals": r["rhs_evals"]}
            print(f"four-star, flexible crank + 4 rods + 1 clearance: {a.four_star_end_time} s in "
                  f"{w:.1f} s (target <= 120 s), {r['rhs_evals']} RHS")
    path = ROOT / "benchmarks" / "out" / "flexible_bench.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))
    print(f"written: {path}")


if __name__ == "__main__":
    main()
