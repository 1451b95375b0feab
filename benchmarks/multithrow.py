"""Multi-throw crank trains with a flexible crank (issue 29 performance): before and after.

Usage::

    .venv/bin/python benchmarks/multithrow.py [--repeats 3] [--cases seed004 inline4]
                                              [--ways scipy compiled]

Cases (issue 29's targets, medians):

* ``seed004``: ``scenes/seed004_dynamics.toml``, seed 004's two-throw crank (20 kept modes) on
  three journals, two rigid rods, motor through a coupling, 1 s at 1494.6 rpm: <= 20 s;
* ``inline4``: ``benchmarks/scenes/inline4_flexible_crank.toml``, the inline-4's four-throw crank
  (30 kept modes, reduced from ``geometry/inline4_engine.toml [crankshaft]``) on five journals,
  four rods, 1 s at 3000 rpm: <= 40 s.

Each case is built as the ``[dynamics]`` stage builds it (``method = auto``: Radau, flexible
bodies on ideal joints) and integrated two ways, interleaved so both see the same load:

* ``scipy``: SciPy's Radau step with the compiled Jacobian (what ran before
  :class:`crankmodal.dynamics.kernel.implicit.CompiledRadau`);
* ``compiled``: what ``integrate`` does now (the compiled Radau step).

The run's largest dynamic stress (the stage's :func:`~crankmodal.dynamics.results.validity.
dynamic_stress` over the results window) is timed two ways on the same modal history (once, on
the first repeat):
``stress_before`` superposes every stress point at every output sample (the former loop,
written out below), ``stress_after`` is :func:`crankmodal.dynamics.results.peak_stress.
peak_von_mises` (seminorm bounds, the same maximum).

Reported: medians over ``--repeats`` of CPU time (``time.process_time``, the figure to read on
the loaded shared machine) and wall time, evaluations, steps. Writes
``benchmarks/out/multithrow.json``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

#: name: (scene, end time s, --set overrides, what, target wall s)
CASES = {
    "seed004": ("scenes/seed004_dynamics.toml", 1.0, ["dynamics.spectrum_start=0.5"],
                "seed 004 crank (20 modes) on 3 journals + 2 rods, 1 s at 1494.6 rpm", 20.0),
    "inline4": ("benchmarks/scenes/inline4_flexible_crank.toml", 1.0, [],
                "inline-4 crank (30 modes) on 5 journals + 4 rods, 1 s at 3000 rpm", 40.0),
}
WAYS = ("scipy", "compiled")


def _stress_before(S, xi):
    """The former superposition: every point at every output sample (64 samples at once)."""
    from crankmodal.reduction.stress_modes import von_mises

    best = np.zeros(S.shape[0])
    for k0 in range(0, len(xi), 64):
        vm = von_mises(np.einsum("pik,tk->tpi", S, xi[k0:k0 + 64]), axis=-1)
        best = np.maximum(best, vm.max(axis=0))
    return float(best.max())


def run_once(case, way, stress=False):
    """One run: integration CPU and wall time, evaluations; with ``stress`` also the
    dynamic stress both ways."""
    from kernel_stiff import build

    from crankmodal.dynamics.kernel import implicit
    from crankmodal.dynamics.results.peak_stress import peak_von_mises
    from crankmodal.dynamics.run import simulate as sim

    scene, end_time, sets, _, _ = CASES[case]
    mech, settings, dt = build(scene, end_time, sets)
    saved = implicit.applicable
    if way == "scipy":
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
        implicit.applicable = saved
    out = {"cpu_s": got["cpu"], "wall_s": got["wall"], "rhs_evals": hist.nfev,
           "method": settings.method, "energy_balance_error": hist.energy_error(),
           "samples": int(hist.t.size)}
    if stress:
        body = next(b for b in mech.system.bodies if getattr(b, "n_elastic", 0) > 0)
        cols = np.asarray(body.info["mode_columns"], int)
        S = np.asarray(body.source.stress_modes[:, :, cols], float)
        sel = hist.t >= float(sets[0].split("=")[1]) if sets else hist.t >= end_time / 2
        xi = hist.modal[body.name][sel][:, :body.n_elastic]
        c0, w0 = time.process_time(), time.perf_counter()
        before = _stress_before(S, xi)
        out["stress_before"] = {"cpu_s": time.process_time() - c0,
                                "wall_s": time.perf_counter() - w0, "max_von_mises_pa": before}
        c0, w0 = time.process_time(), time.perf_counter()
        peak = peak_von_mises(S, xi)
        out["stress_after"] = {"cpu_s": time.process_time() - c0,
                               "wall_s": time.perf_counter() - w0,
                               "max_von_mises_pa": peak.value,
                               "points_superposed": peak.points_superposed,
                               "n_points": int(S.shape[0]), "samples": int(xi.shape[0])}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--ways", nargs="+", default=list(WAYS), choices=list(WAYS))
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "out" / "multithrow.json"))
    a = ap.parse_args(argv)
    path = Path(a.out)
    path.parent.mkdir(exist_ok=True)
    out = json.loads(path.read_text()) if path.is_file() else {}
    for case in a.cases:
        run_once(case, "compiled")  # warm-up: compilation and the reduced part's cache
        runs = {w: [] for w in a.ways}
        for rep in range(a.repeats):
            for way in a.ways:  # the dynamic stress both ways once (the before: minutes)
                runs[way].append(run_once(case, way, stress=way == "compiled" and rep == 0))
        _, end_time, _, what, target = CASES[case]
        res = {"what": what, "end_time_s": end_time, "target_wall_s": target,
               "load_average": list(__import__("os").getloadavg())}
        for way in a.ways:
            r = runs[way]
            cpu = statistics.median(x["cpu_s"] for x in r)
            wall = statistics.median(x["wall_s"] for x in r)
            res[way] = {"cpu_s": cpu, "wall_s": wall, "rhs_evals": r[-1]["rhs_evals"],
                        "method": r[-1]["method"], "cpu_runs": [x["cpu_s"] for x in r],
                        "wall_runs": [x["wall_s"] for x in r],
                        "energy_balance_error": r[-1]["energy_balance_error"]}
            print(f"{case:8s} {way:9s} CPU {cpu:7.2f} s  wall {wall:7.2f} s  "
                  f"{r[-1]['rhs_evals']:7d} RHS  (target {target:g} s)", flush=True)
            if "stress_after" in r[0]:
                for k in ("stress_before", "stress_after"):
                    res[k] = dict(r[0][k])
                    print(f"{case:8s} {k:13s} CPU {res[k]['cpu_s']:7.2f} s  wall "
                          f"{res[k]['wall_s']:7.2f} s  max {res[k]['max_von_mises_pa']:.6g} Pa",
                          flush=True)
        out[case] = res
        path.write_text(json.dumps(out, indent=2))
    print(f"written: {path}")


if __name__ == "__main__":
    main()
