"""Forced torsional response benchmark (issue 28).

1. A 12-rotor chain, 24 orders (half orders to 12) on every rotor, 0-1.25 x operating speed
   (3000 rpm) at 1 rpm steps: per-order solve, synthesised angles and section torques, stresses
   in every section. Target <= 1 s.
2. The seed 004 train study from its scene (check + run, figures on). Target <= 10 s.

    .venv/bin/python benchmarks/torsion_forced_bench.py [--repeats 3]

Wall and process CPU times, medians of the repeats; the machine is shared, so wall times are
"under load" (CPU time is the better guide there; run with OMP_NUM_THREADS=1 to compare them).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def chain_case() -> tuple[float, float]:
    from crankmodal.torsion.chain import TorsionalChain
    from crankmodal.torsion.excitation import rotor_excitation
    from crankmodal.torsion.forced import damped_train, steady_state
    from crankmodal.torsion.stress import Section

    n = 12
    chain = TorsionalChain(np.r_[0.05, np.full(n - 2, 0.11), 3.2], np.full(n - 1, 3.0e6))
    harm = [{"rotor": r, "order": q, "amplitude": 500.0 / q, "phase_deg": 37.0 * r * q}
            for r in range(1, n - 1) for q in np.arange(1, 25) / 2]
    sections = [Section.round(0.1, 0.0, 2.0)] * (n - 1)
    t0, c0 = time.perf_counter(), time.process_time()
    train = damped_train(chain, 0.02)
    ex = rotor_excitation(n, 12.0, 2, harmonics=harm)
    res = steady_state(train, ex, np.arange(1.0, 3751.0))  # 0 rpm left out (no speed, no response)
    stress = np.column_stack([s.stress(res.section_torque_nm[:, i]) for i, s in enumerate(sections)])
    dt, dc = time.perf_counter() - t0, time.process_time() - c0
    assert stress.shape == (3750, n - 1)
    return dt, dc


def seed004_case() -> tuple[float, float]:
    from crankmodal.runner import run
    from crankmodal.scene import load_scene

    with tempfile.TemporaryDirectory() as d:
        t0, c0 = time.perf_counter(), time.process_time()
        run(load_scene(ROOT / "scenes" / "seed004_forced_torsion.toml"), d, figures=True)
        return time.perf_counter() - t0, time.process_time() - c0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    chain_case()  # warm-up (imports, BLAS)
    c = [chain_case() for _ in range(a.repeats)]
    s = [seed004_case() for _ in range(a.repeats)]
    for name, r, target in (("12 rotors x 24 orders x 3750 speeds", c, 1),
                            ("seed 004 train study from its scene (mechanism + torsion + forced, figures)", s, 10)):
        wall, cpu = [x[0] for x in r], [x[1] for x in r]
        print(f"{name}: wall median {statistics.median(wall):.2f} s (min {min(wall):.2f}), process CPU "
              f"median {statistics.median(cpu):.2f} s; target {target} s")


if __name__ == "__main__":
    main()
