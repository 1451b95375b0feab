"""Sparse factorisation backends on the seed 000 crankshaft: PARDISO, SuperLU (general COLAMD and
symmetric mode) and, where installed, cholespy (CHOLMOD).

Factorises ``K - sigma M`` (sigma below the first mode: positive definite, as the modal solver
does) of the four-star crankshaft at one mesh size and solves one right-hand side. Times are CPU
seconds of this process (``time.process_time``), which a loaded machine disturbs less than wall
time; run with one thread for a like-for-like comparison::

    CRANKMODAL_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 \\
        .venv/bin/python benchmarks/factorisation_bench.py --size 0.0135 --repeats 3
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import scipy.sparse as sp


def _matrix(size: float):
    from modal_bench import build_part

    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material

    part, _, _ = build_part(size)
    model = assemble(part, material("crank_steel_seed000"))
    sigma = -(2 * np.pi * 10.0) ** 2
    return (model.K - sigma * model.M).tocsr()


def _factor(name: str, A):
    from crankmodal.fem import solvers

    if name == "cholespy":
        from cholespy import CholeskySolverD, MatrixType

        L = sp.tril(A).tocsr()  # cholespy reads the lower triangle
        L.sort_indices()
        s = CholeskySolverD(A.shape[0], L.indptr.astype(np.int32), L.indices.astype(np.int32),
                            np.ascontiguousarray(L.data), MatrixType.CSR)

        def solve(b):
            x = np.zeros_like(b)
            s.solve(b.copy(), x)
            return x
        return solve
    if name == "superlu_colamd":
        return solvers.SuperLUFactor(A, positive_definite=False).solve
    if name == "superlu":
        return solvers.SuperLUFactor(A, positive_definite=True).solve
    return solvers.factorize(A, "pardiso").solve


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=0.0135, help="mesh size, m (0.0135: 85k DOF)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--backends", nargs="*",
                    default=["pardiso", "superlu", "superlu_colamd", "cholespy"])
    a = ap.parse_args(argv)
    A = _matrix(a.size)
    b = np.random.default_rng(0).normal(size=A.shape[0])
    print(f"{A.shape[0]} DOF")
    for name in a.backends:
        try:
            runs = []
            for _ in range(a.repeats):
                t = time.process_time()
                solve = _factor(name, A)
                runs.append(time.process_time() - t)
            x = solve(b)
        except ImportError as exc:
            print(f"{name:15s} not installed ({exc})")
            continue
        res = np.linalg.norm(A @ x - b) / np.linalg.norm(b)
        print(f"{name:15s} factorisation {statistics.median(runs):7.2f} CPU-s (median of "
              f"{a.repeats}), residual {res:.1e}")


if __name__ == "__main__":
    main()
