"""Free-free modal benchmark: the seed 000 crankshaft at ~50k, ~150k and ~300k P2 DOF.

Per phase wall time and peak resident memory for the default backend (PARDISO) and for scipy's
SuperLU on identical matrices (SuperLU up to ``--superlu-max-dofs``). Every (size, backend,
repeat) runs in a fresh subprocess so peak memory is not inherited; the table shows medians.

    .venv/bin/python benchmarks/modal_bench.py                 # default sizes, 3 repeats
    .venv/bin/python benchmarks/modal_bench.py --sizes 0.014 --repeats 1 --superlu-max-dofs 0

Falls back to a prismatic bar of similar DOF counts when ``crankmodal.geometry`` is missing.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

#: mesh sizes (m) of the four-star crankshaft giving ~85k, ~165k and ~300k P2 DOF (since the
#: curved-element repair of session 4: 85 401, 163 359 and 303 234 DOF; 0.0072 gave 303 915 before)
DEFAULT_SIZES = (0.0135, 0.0092, 0.0070)


def build_part(size: float):
    """The seed 000 crankshaft (full fidelity, P2) at mesh size ``size``; or a bar."""
    try:
        from crankmodal.geometry import stage as gs
        from crankmodal.scene import Scene

        p = gs.validate({"machine": "four_star_compressor", "part": "crankshaft",
                         "fidelity": "full", "mesh_size": size, "element_order": 2},
                        Scene(name="bench", base_dir=Path(".")))
        part, cached = gs.make_part(p)
        return part, cached, "four_star_compressor/crankshaft"
    except ImportError:
        from crankmodal.fem.testparts import bar

        n = max(2, round(0.05 / size * 2))
        return bar(0.4, 0.05, 0.05, (8 * n, n, n)), False, "bar 0.4 x 0.05 x 0.05 m"


def one(size: float, backend: str, n_modes: int) -> dict:
    """One measured run (called in a subprocess)."""
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material
    from crankmodal.fem.memory import PeakMemory, rss_bytes
    from crankmodal.fem.modal import solve_modes

    t0 = time.perf_counter()
    part, cached, name = build_part(size)
    t_mesh = time.perf_counter() - t0
    with PeakMemory() as mem_asm:
        t0 = time.perf_counter()
        model = assemble(part, material("crank_steel_seed000"))
        t_asm = time.perf_counter() - t0
    with PeakMemory() as mem_modal:
        modes = solve_modes(model, n_modes, backend=backend)
    return {
        "part": name, "size": size, "backend": modes.backend, "n_dofs": modes.n_dofs,
        "n_elements": model.n_elements, "mesh_s": t_mesh, "mesh_cached": cached,
        "assembly_s": t_asm, **model.timings,
        **modes.timings, "modal_s": sum(modes.timings.values()),
        "peak_assembly_gb": mem_asm.peak / 1e9, "peak_modal_gb": mem_modal.peak / 1e9,
        "peak_gb": max(mem_asm.peak, mem_modal.peak, rss_bytes()) / 1e9,
        "f_hz": [round(float(f), 2) for f in modes.frequencies_hz[:4]],
        "rigid": modes.rigid_body_modes, "n_solves": modes.n_solves, "solve_s": modes.solve_time,
        "residual_max": float(modes.residuals.max()),
    }


def first_touch_s(gib: float = 1.0) -> float:
    """Seconds a fresh process takes to write ``gib`` GiB of new memory: the machine's state.

    On the reference VM this moved between 0.3 and 3 s per GiB from one half hour to the next
    (host-side faults of memory the guest had handed back), and the factorisation, which writes
    ~2.8 GB of new factor at 300k DOF, moves with it.
    """
    code = ("import time, numpy as np; t = time.perf_counter(); "
            f"np.ones(int({gib} * 2**30 / 8)); print(time.perf_counter() - t)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(out.stdout.strip())


def measure(size, backend, n_modes, timeout):
    cmd = [sys.executable, __file__, "--one", str(size), backend, str(n_modes)]
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout} s"}
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["killed"])[-1][:200]
                + f" (exit {out.returncode})"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=float, nargs="*", default=list(DEFAULT_SIZES))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--n-modes", type=int, default=12)
    ap.add_argument("--superlu-max-dofs", type=int, default=200_000)
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--json", default=str(Path(__file__).parent / "out" / "modal_bench.json"),
                    help="write all runs and the table rows to this file")
    ap.add_argument("--one", nargs=3, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        print(json.dumps(one(float(a.one[0]), a.one[1], int(a.one[2]))))
        return
    runs, rows = [], []
    touch = [first_touch_s()]
    print(f"machine: writing 1 GiB of new memory took {touch[0]:.2f} s", file=sys.stderr)
    for size in a.sizes:
        dofs = None
        for backend in ("auto", "superlu"):
            if backend == "superlu" and (dofs is None or dofs > a.superlu_max_dofs):
                rows.append({"size": size, "backend": "superlu",
                             "error": f"skipped above {a.superlu_max_dofs} DOF"})
                continue
            reps = []
            for _ in range(a.repeats if backend == "auto" else 1):
                r = measure(size, backend, a.n_modes, a.timeout)
                runs.append(r)
                print(json.dumps(r), file=sys.stderr, flush=True)
                if "error" in r:
                    break
                reps.append(r)
            if not reps:
                rows.append({"size": size, "backend": backend, **runs[-1]})
                continue
            dofs = reps[0]["n_dofs"]
            med = {k: statistics.median(r[k] for r in reps)
                   for k in reps[0] if isinstance(reps[0][k], float) and k != "size"}
            med["mesh_s"] = max(r["mesh_s"] for r in reps if not r["mesh_cached"]) \
                if any(not r["mesh_cached"] for r in reps) else float("nan")
            rows.append({**reps[0], **med, "repeats": len(reps)})
    touch.append(first_touch_s())
    print(f"machine: writing 1 GiB of new memory took {touch[0]:.2f} s before the runs, "
          f"{touch[1]:.2f} s after")
    cols = ("n_dofs", "backend", "mesh_s", "assembly_s", "factorize_s", "lanczos_s", "solve_s",
            "modal_s", "peak_gb")
    print("| part | " + " | ".join(cols) + " | f1..f4 Hz |")
    print("|" + "---|" * (len(cols) + 2))
    for r in rows:
        if "error" in r:
            print(f"| {r.get('size')} | {r['backend']} | {r['error']} |")
            continue
        vals = [f"{r[c]:.2f}" if isinstance(r[c], float) else str(r[c]) for c in cols]
        print(f"| {r['part']} h={r['size']} | " + " | ".join(vals) + f" | {r['f_hz']} |")
    if a.json:
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        with open(a.json, "w") as fh:
            json.dump({"runs": runs, "rows": rows, "first_touch_gib_s": touch}, fh, indent=1)


if __name__ == "__main__":
    main()
