"""Craig–Bampton benchmark: the seed 000 crankshaft at ~300k P2 DOF, 9 interfaces, 60 modes.

Interfaces: both main journals, the two crankpin rows cut into two bands each (one per rod big
end, four rods), the two shaft-end stubs (coupling and flywheel hub seats) and the flywheel-end
face — 9 interface nodes, 54 boundary DOFs. Each coupling
(``rigid`` = RBE2-like, ``distributing`` = RBE3-like, on all nine) runs in a fresh subprocess so
peak memory is its own. Wall times depend on what else runs: the process CPU time of the basis
(both threads) and the 1-minute load average are reported beside them. Reported per run: basis time (partition, factorisation, constraint
modes, fixed-interface modes, reduced matrices, orthonormalisation), stress modes for 60 and for
all orthonormal modes, peak resident memory.

    .venv/bin/python benchmarks/reduction_bench.py                  # ~300k DOF, both couplings
    .venv/bin/python benchmarks/reduction_bench.py --size 0.014     # ~80k DOF, quick

Falls back to a prismatic bar of similar size when ``crankmodal.geometry`` is missing.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

DEFAULT_SIZE = 0.0075  # m: ~285k P2 DOF for the four-star crankshaft


#: interfaces of the crankshaft: 2 journals, 2 crankpin rows in 2 bands each, 2 stubs, 1 face
CRANK_SPECS = [{"region": "main_journal_1", "segments": 1},
               {"region": "main_journal_2", "segments": 1},
               {"region": "crankpin_1_row_1", "segments": 2},
               {"region": "crankpin_1_row_2", "segments": 2},
               {"region": "free_end_stub", "segments": 1},
               {"region": "flywheel_end_stub", "segments": 1},
               {"region": "flywheel_end_face", "segments": 1}]
BAR_SPECS = [{"region": "end_x0", "segments": 1}, {"region": "end_x1", "segments": 1}]


def build(size: float):
    """Part and interface specs: the crankshaft (9 interfaces) or a bar (2).

    The part is the modal benchmark's (``modal_bench.py`` in this folder).
    """
    from modal_bench import build_part

    part, _, name = build_part(size)
    return part, (CRANK_SPECS if "crankshaft" in name else BAR_SPECS), name


def one(size: float, coupling: str, n_modes: int, backend: str) -> dict:
    """One measured run (in its own process)."""
    import resource

    import numpy as np

    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material
    from crankmodal.fem.memory import PeakMemory, rss_bytes
    from crankmodal.reduction.craig_bampton import craig_bampton
    from crankmodal.reduction.interfaces import interface_rigid_fields, make_interfaces
    from crankmodal.reduction.orthonormal import orthonormalise
    from crankmodal.reduction.stage import interface_specs
    from crankmodal.reduction.stress_modes import stress_modes, stress_recovery

    part, specs, name = build(size)
    t0 = time.perf_counter()
    model = assemble(part, material("crank_steel_seed000"))
    t_asm = time.perf_counter() - t0
    with PeakMemory() as mem:
        t0 = time.perf_counter()
        itf = make_interfaces(part, interface_specs(part, {"interfaces": [
            {**s, "kind": coupling} for s in specs], "coupling": coupling}))
        t_itf = time.perf_counter() - t0
        ru = resource.getrusage(resource.RUSAGE_SELF)
        cpu0 = ru.ru_utime + ru.ru_stime
        with PeakMemory() as mem_basis:
            cb = craig_bampton(model, itf, n_modes=n_modes, backend=backend)
        t0 = time.perf_counter()
        Ra = np.vstack([interface_rigid_fields(itf), np.zeros((cb.n_fixed_modes, 6))])
        ortho = orthonormalise(cb.K, cb.M, Ra)
        t_orth = time.perf_counter() - t0
        basis_s = t_itf + sum(cb.timings.values()) + t_orth
        ru = resource.getrusage(resource.RUSAGE_SELF)
        basis_cpu = ru.ru_utime + ru.ru_stime - cpu0
        with PeakMemory() as mem_stress:
            t0 = time.perf_counter()
            rec = stress_recovery(model, part.mesh)
            t_rec = time.perf_counter() - t0
            Vo = cb.V @ ortho.W
            t0 = time.perf_counter()
            stress_modes(rec, Vo[:, 6:66], dtype=np.float32)
            t_s60 = time.perf_counter() - t0
            ru = resource.getrusage(resource.RUSAGE_SELF)
            cpu0 = ru.ru_utime + ru.ru_stime
            t0 = time.perf_counter()
            stress_modes(rec, Vo, dtype=np.float32)
            t_sall = time.perf_counter() - t0
            ru = resource.getrusage(resource.RUSAGE_SELF)
            sall_cpu = ru.ru_utime + ru.ru_stime - cpu0
    f = ortho.frequencies_hz[~ortho.rigid]
    return {"part": name, "size": size, "coupling": coupling, "backend": cb.backend,
            "n_dofs": int(model.n_dofs), "n_elements": model.n_elements,
            "n_interfaces": len(itf), "n_boundary": cb.n_boundary, "n_modes": cb.n_fixed_modes,
            "n_reduced": len(ortho.frequencies_hz), "assembly_s": t_asm,
            "interfaces_s": t_itf, **cb.timings, "orthonormalise_s": t_orth, "basis_s": basis_s,
            "basis_cpu_s": basis_cpu, "stress_all_cpu_s": sall_cpu,
            "load_average": os.getloadavg()[0],
            "stress_recovery_setup_s": t_rec, "stress_60_s": t_s60,
            "stress_all_s": t_sall, "peak_gb": max(mem.peak, rss_bytes()) / 1e9,
            "rss_before_gb": mem.baseline / 1e9, "peak_basis_gb": mem_basis.peak / 1e9,
            "peak_stress_gb": mem_stress.peak / 1e9,
            "f_elastic_hz": [round(float(x), 1) for x in f[:6]],
            "fixed_interface_hz": [round(float(x), 1) for x in cb.fixed_interface_hz[:3]],
            "eigen_residual": cb.residual, "rigid_defect": ortho.rigid_defect}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=DEFAULT_SIZE, help="mesh size, m")
    ap.add_argument("--modes", type=int, default=60, help="fixed-interface modes")
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--couplings", default="rigid,distributing")
    ap.add_argument("--one", nargs=4, metavar=("SIZE", "COUPLING", "MODES", "BACKEND"))
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(float(a.one[0]), a.one[1], int(a.one[2]), a.one[3])))
        return
    rows = []
    for coupling in a.couplings.split(","):
        cmd = [sys.executable, __file__, "--one", str(a.size), coupling, str(a.modes), a.backend]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if out.returncode != 0:
            rows.append({"coupling": coupling, "error": out.stderr.strip().splitlines()[-1:]})
        else:
            rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
        print(json.dumps(rows[-1]), flush=True)
    ok = [r for r in rows if "error" not in r]
    if ok:
        r0 = ok[0]
        print(f"\n{r0['part']}: {r0['n_dofs']} DOF, {r0['n_elements']} P2 tets, "
              f"{r0['n_interfaces']} interfaces, {r0['n_modes']} fixed-interface modes, "
              f"backend {r0['backend']}")
        cols = ("coupling", "factorize_s", "constraint_modes_s", "fixed_interface_modes_s",
                "reduced_matrices_s", "basis_s", "basis_cpu_s", "stress_60_s", "stress_all_s",
                "peak_gb", "load_average")
        print(" | ".join(cols))
        for r in ok:
            print(" | ".join(str(r[c]) if isinstance(r[c], str) else f"{r[c]:.2f}" for c in cols))
        if len(ok) == 2:
            print(f"distributing / rigid basis time: {ok[1]['basis_s'] / ok[0]['basis_s']:.2f}")
    outdir = Path(__file__).with_name("out")
    outdir.mkdir(exist_ok=True)
    (outdir / "reduction_bench.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
