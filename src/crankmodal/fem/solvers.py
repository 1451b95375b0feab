"""Sparse symmetric factorisations behind one interface.

``factorize(A, backend)`` returns an object with ``solve(b)`` that reuses one factorisation for
every right-hand side (the shift-invert Lanczos loop calls it a few dozen times).

Backends
--------
``pardiso``
    Intel MKL PARDISO through the ``pypardiso`` wheel (pip-only: it brings MKL). Real symmetric
    positive-definite or indefinite LDLᵀ on the upper triangle; iterative refinement is off
    (with it on, residuals degraded to ~1e-6 and the time doubled on this machine). Every
    PARDISO call runs with :func:`solver_threads` MKL threads, set thread-locally: left to
    itself MKL ran PARDISO on one thread on a 2-core machine (factorisation 12 s instead of
    6 s at 169k DOF).
``superlu``
    scipy's SuperLU, always available; the last resort. A symmetric positive-definite matrix is
    factorised in SuperLU's symmetric mode (minimum-degree ordering of A + Aᵀ, diagonal pivots):
    at 85k DOF of the seed 000 crank 17.5 CPU-s against 33.4 with the general COLAMD ordering,
    and PARDISO's 1.8 (one thread each; benchmarks/factorisation_bench.py).
``auto``
    ``pardiso`` when importable, else ``superlu`` with one :class:`~crankmodal.errors.ModelWarning`
    line saying so and what it costs.

Evaluated and not used (benchmarks/README.md, "Factorisation backends"): ``python-mumps`` ships
no wheels (its sdist needs a MUMPS library installed by other means), and ``cholespy``'s wheels
(Linux x86-64, macOS, Windows; none for Linux aarch64) factorise the 85k-DOF crank in 29.5 CPU-s,
16x PARDISO and slower than SuperLU's symmetric mode.
"""

from __future__ import annotations

import ctypes
import functools
import os

import numpy as np
import scipy.sparse as sp

from ..errors import ParameterError, ResourceError

BACKENDS = ("auto", "pardiso", "superlu")


@functools.cache
def _mkl():
    """MKL's runtime library: where the ``mkl`` wheel puts it, else as pypardiso finds it.

    pypardiso's search (``find_library`` and a recursive glob of the environment) took 0.2-0.3 s.
    """
    import glob
    import sys

    for path in sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len):
        try:
            return ctypes.CDLL(path)
        except OSError:
            continue
    import pypardiso

    return pypardiso.PyPardisoSolver().libmkl


def solver_threads() -> int:
    """Threads for the sparse factorisation and solves.

    ``CRANKMODAL_THREADS``, else ``MKL_NUM_THREADS``, else the cores this process may run on.
    """
    for var in ("CRANKMODAL_THREADS", "MKL_NUM_THREADS"):
        v = os.environ.get(var, "").strip()
        if v.isdigit() and int(v) > 0:
            return int(v)
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def available_backends() -> list[str]:
    """Backends that can run here, the default first."""
    import importlib.util

    # find_spec, not import: importing pypardiso makes a solver, which searches for MKL (0.2 s)
    return (["pardiso"] if importlib.util.find_spec("pypardiso") else []) + ["superlu"]


def resolve_backend(backend: str) -> str:
    """The concrete backend ``auto`` stands for; checks an explicit one is installed.

    Raises
    ------
    ParameterError
        Naming ``backend``: unknown, or not installed here. A stage re-raises it under its scene
        key (``modal.backend``).
    """
    if backend not in BACKENDS:
        raise ParameterError("backend", f"must be one of {', '.join(BACKENDS)}; got {backend!r}")
    have = available_backends()
    if backend == "auto":
        if have[0] == "superlu":
            _warn_superlu_fallback()
        return have[0]
    if backend not in have:
        raise ParameterError("backend", f"{backend!r} is not installed (pip install pypardiso); "
                                        f"available: {', '.join(have)}")
    return backend


#: SuperLU's cost against PARDISO on the seed 000 crank (CPU seconds of one factorisation, one
#: thread each, symmetric mode): 85k DOF 17.5 / 1.8 s
SUPERLU_SLOWDOWN = 10


@functools.cache
def _warn_superlu_fallback() -> None:
    """Say once per process that ``auto`` fell back to SuperLU, and what that costs."""
    from ..errors import warn

    warn(f"fem: PARDISO (pypardiso, Intel MKL) is not installed here, so sparse factorisations "
         f"use scipy's SuperLU: about {SUPERLU_SLOWDOWN}x slower and hungrier on a crankshaft "
         f"mesh (pip install pypardiso where MKL has wheels: x86-64 Linux, Windows, macOS)")


class SuperLUFactor:
    """scipy SuperLU (COLAMD ordering) of a square sparse matrix.

    SuperLU cannot say beforehand how much memory its factor takes. Where the system tells what
    is available (:func:`~crankmodal.fem.memory.available_bytes`), the factorisation runs under
    an address-space limit of that much more than the process holds, so running out is a
    ``MemoryError`` SuperLU reports, turned into :class:`ResourceError` — not the kernel killing
    the run.
    """

    name = "superlu"

    def __init__(self, A, label: str = "", positive_definite: bool = False):
        from scipy.sparse.linalg import splu

        from .memory import address_space_limit, available_bytes

        n, avail = A.shape[0], available_bytes()
        # symmetric positive definite: minimum degree on A + A^T and diagonal pivots (SuperLU's
        # symmetric mode), half the time of the general COLAMD ordering on a crank mesh
        kw = ({"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.0,
               "options": {"SymmetricMode": True}} if positive_definite
              else {"permc_spec": "COLAMD"})
        try:
            with address_space_limit(avail):
                self._lu = splu(sp.csc_matrix(A), **kw)
        except MemoryError:
            room = "memory" if avail is None else f"the {avail / 1e9:.3g} GB available"
            raise ResourceError(
                f"{label}factorising {n} unknowns with SuperLU ran out of {room}: install "
                f"pypardiso (PARDISO needs a fraction of SuperLU's memory), or use a coarser mesh "
                f"or element_order = 1") from None

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.asarray(b, float))


class PardisoFactor:
    """MKL PARDISO of a real symmetric matrix (phases 11+22 once, phase 33 per solve).

    Parameters
    ----------
    A : sparse matrix
        Symmetric; only its upper triangle is used.
    upper : bool
        ``A`` already is that upper triangle (saves a copy).
    positive_definite : bool
        ``True``: Cholesky (mtype 2); ``False``: Bunch-Kaufman LDLᵀ (mtype -2).
    label : str
        Prefix of error messages (``"modal: "``).

    Between the analysis and the factorisation, PARDISO's estimate of the factor's peak memory
    (``memory_needed``, bytes) is checked against what the machine has left
    (:func:`check_memory`).
    """

    name = "pardiso"

    def __init__(self, A, positive_definite: bool = True, ordering: int = 2,
                 upper: bool = False, label: str = ""):
        mkl = _mkl()
        self._lib = mkl.pardiso
        self._set_threads = mkl.MKL_Set_Num_Threads_Local  # C interface: int by value
        self._threads = solver_threads()
        U = sp.csr_matrix(A) if upper else upper_triangle(A)
        U.sort_indices()
        if np.any(np.diff(U.indptr) == 0):
            raise ValueError("matrix has an empty row")
        self.n = U.shape[0]
        self._data = np.ascontiguousarray(U.data, dtype=np.float64)
        self._ia = U.indptr.astype(np.int32, copy=False)  # zero-based (iparm[34] = 1): no copies
        self._ja = U.indices.astype(np.int32, copy=False)
        self.mtype = 2 if positive_definite else -2
        self.pt = np.zeros(64, np.int64)
        self.iparm = np.zeros(64, np.int32)
        ip = self.iparm
        ip[0] = 1    # explicit parameters
        ip[1] = ordering  # 2: METIS nested dissection, 3: its parallel version, 0: AMD
        ip[7] = 0    # no iterative refinement unless pivots were perturbed (none for mtype 2)
        ip[9] = 8    # pivot perturbation 1e-8 (mtype -2)
        ip[10] = 0   # no scaling (symmetric)
        ip[12] = 0   # no weighted matching (symmetric)
        ip[17] = -1  # report nnz of the factor
        ip[20] = 1   # Bunch-Kaufman pivoting (mtype -2)
        ip[23] = 1   # two-level parallel factorisation: 17.1-17.5 s against 19.8-20.1 s at 302k DOF
        ip[34] = 1   # zero-based ia/ja
        if positive_definite:
            # variable-block storage of the 3-DOF nodes: METIS orders the compressed graph
            # (analysis 3.6 -> 1.35 s at 303k DOF) and the factor needs 0.3 GB less at its peak
            ip[36] = -80
        self._call(11, np.zeros((self.n, 1)))
        #: PARDISO's own estimate of the memory the factorisation takes at its peak, bytes
        self.memory_needed = 1024 * max(int(ip[14]), int(ip[15]) + int(ip[16]))
        check_memory(self.memory_needed, f"{label}factorising {self.n} unknowns", self._release)
        self._call(22, np.zeros((self.n, 1)))
        self.factor_nnz = int(self.iparm[17])
        self.n_negative = int(self.iparm[22])

    def _call(self, phase: int, b: np.ndarray) -> np.ndarray:
        b = np.asfortranarray(b, dtype=np.float64)
        x = np.zeros_like(b)
        err = ctypes.c_int32(0)
        i32 = ctypes.POINTER(ctypes.c_int32)
        f64 = ctypes.POINTER(ctypes.c_double)
        nrhs = 1 if b.ndim == 1 else b.shape[1]
        before = self._set_threads(ctypes.c_int(self._threads))
        try:
            self._lib(self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)),
                    ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(1)),
                    ctypes.byref(ctypes.c_int32(self.mtype)), ctypes.byref(ctypes.c_int32(phase)),
                    ctypes.byref(ctypes.c_int32(self.n)), self._data.ctypes.data_as(f64),
                    self._ia.ctypes.data_as(i32), self._ja.ctypes.data_as(i32),
                    np.zeros(0, np.int32).ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(nrhs)),
                    self.iparm.ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(0)),
                    b.ctypes.data_as(f64), x.ctypes.data_as(f64), ctypes.byref(err))
        finally:
            self._set_threads(ctypes.c_int(before))
        if err.value != 0:
            raise np.linalg.LinAlgError(f"PARDISO phase {phase} failed with error {err.value}"
                                        + (" (matrix not positive definite)"
                                           if err.value == -4 else ""))
        return x

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, float)
        return self._call(33, b).reshape(b.shape)

    def _release(self):
        """Free PARDISO's memory (phase -1); the handle is then empty."""
        if self.pt.any():
            self._call(-1, np.zeros((self.n, 1)))
            self.pt[:] = 0

    def __del__(self):
        try:
            self._release()
        except Exception:  # noqa: BLE001, S110 - interpreter shutdown: nothing left to free
            pass


def check_memory(needed: int, what: str, release=None) -> None:
    """Raise :class:`ResourceError` before allocating ``needed`` bytes the machine does not have.

    Without this, the kernel kills the run (no message, no results) once the factor outgrows the
    memory. ``release`` frees what was already allocated (PARDISO's analysis) first.
    """
    from .memory import available_bytes

    avail = available_bytes()
    if avail is None or needed <= avail:
        return
    if release is not None:
        release()
    raise ResourceError(
        f"{what} needs {needed / 1e9:.3g} GB (the solver's estimate) but {avail / 1e9:.3g} GB are "
        f"available: use a coarser mesh (a larger geometry.mesh_size; the factor grows about as "
        f"DOF^1.5), element_order = 1 for a first look, the simplified fidelity, or a machine with "
        f"more memory (CRANKMODAL_MEMORY_LIMIT, in GB, sets the available figure)")


def upper_triangle(A) -> sp.csr_matrix:
    """``triu(A)`` as CSR, by masking A's CSR arrays (scipy's ``triu`` goes through COO: 5x slower)."""
    A = sp.csr_matrix(A)
    rows = np.repeat(np.arange(A.shape[0], dtype=A.indices.dtype), np.diff(A.indptr))
    keep = A.indices >= rows
    indptr = np.zeros(A.shape[0] + 1, A.indptr.dtype)
    np.cumsum(np.bincount(rows[keep], minlength=A.shape[0]), out=indptr[1:])
    return sp.csr_matrix((A.data[keep], A.indices[keep], indptr), shape=A.shape)


def factorize(A, backend: str = "auto", positive_definite: bool = True, label: str = ""):
    """Factorise a symmetric sparse matrix once.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n)
    backend : {"auto", "pardiso", "superlu"}
    positive_definite : bool
        Whether ``A`` is known to be positive definite (Cholesky is used where possible).
    label : str
        Prefix of error messages, e.g. ``"static: "``.

    Returns
    -------
    object with ``solve(b)`` and ``name``.
    """
    name = resolve_backend(backend)
    if name == "pardiso":
        return PardisoFactor(A, positive_definite=positive_definite, label=label)
    return SuperLUFactor(A, label=label, positive_definite=positive_definite)


def factorize_shifted(K, M, sigma: float, backend: str = "auto", positive_definite: bool = True,
                      label: str = ""):
    """Factorise ``K - σM`` without keeping the full shifted matrix (PARDISO: upper triangle only).

    Saves one matrix of the size of K at the memory peak of a large modal solve.
    """
    name = resolve_backend(backend)
    if name == "pardiso":
        K, M = sp.csr_matrix(K), sp.csr_matrix(M)
        if (K.has_sorted_indices and M.has_sorted_indices and K.nnz == M.nnz
                and np.array_equal(K.indptr, M.indptr) and np.array_equal(K.indices, M.indices)):
            # one mesh, one pattern (assembled K and M): subtract the values, mask once
            U = upper_triangle(sp.csr_matrix((K.data - sigma * M.data, K.indices, K.indptr),
                                             shape=K.shape))
        else:
            U = upper_triangle(K)
            U -= sigma * upper_triangle(M)
        return PardisoFactor(U.tocsr(), positive_definite=positive_definite, upper=True,
                             label=label)
    return SuperLUFactor(K - sigma * M, label=label, positive_definite=positive_definite)


def factorize_submatrix(K, idx: np.ndarray, backend: str = "auto",
                        positive_definite: bool = True, label: str = ""):
    """Factorise ``K[idx][:, idx]`` without a full copy of it (PARDISO: upper triangle only).

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
        Symmetric.
    idx : ndarray of int
        Ascending row/column indices to keep (the upper triangle of the slice is then the slice
        of the upper triangle).
    """
    idx = np.asarray(idx)
    if np.any(np.diff(idx) <= 0):
        raise ValueError("idx must be strictly ascending")
    if resolve_backend(backend) == "pardiso":
        U = upper_triangle(K)[idx][:, idx]
        return PardisoFactor(U, positive_definite=positive_definite, upper=True, label=label)
    return SuperLUFactor(sp.csr_matrix(K)[idx][:, idx], label=label,
                         positive_definite=positive_definite)
