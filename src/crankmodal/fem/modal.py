"""Free and supported modal analysis: shift-invert Lanczos with one sparse factorisation.

The pencil (K, M) is solved with ARPACK in shift-invert mode about a small *negative* shift σ:
``K - σM`` is then positive definite even for a free part (its rigid-body modes sit at λ = 0 > σ),
so one Cholesky/LDLᵀ serves every Lanczos step. The rigid-body motions the supports leave (6 per
connected free piece) are known in closed form: they are M-orthonormalised, their Rayleigh
quotients checked like any other pair, and deflated from the Lanczos operator, so ARPACK only
looks for elastic modes (a quarter fewer solves). A zero-frequency mode among those — a loose
piece or a mechanism the connectivity did not predict — is caught by the rigid-count check. Every returned pair is checked:
``‖Kx − λMx‖ / ‖Kx‖`` and ``|XᵀMX − I|``; poor results raise :class:`NumericalError` with advice.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError, SceneError
from .assembly import FEModel, mass_and_centre, rigid_body_modes
from .memory import PeakMemory
from .supports import Support, reduce_matrix, reduction

#: ARPACK's convergence tolerance: residuals come out near 1e-8, far inside the 1e-6 check,
#: with a third fewer solves than at 1e-12.
ARPACK_TOL = 1e-9

#: Lanczos steps of the check for modes the main run missed (the second of a repeated pair).
COMPLETENESS_STEPS = 8

#: Extra eigensolver runs allowed for missed modes before giving up.
MAX_RESCUES = 3

#: A computed mode is rigid when its frequency is below this fraction of the highest computed one.
RIGID_RATIO = 1e-3


@dataclass
class Modes:
    """Result of a modal analysis.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (n,)
        Elastic natural frequencies, ascending, Hz.
    shapes : ndarray, shape (3 n_points, n)
        Mass-normalised elastic mode shapes (ΦᵀMΦ = I), node-interleaved, m/√kg.
    rigid_body_modes : int
        Zero-frequency modes found and left out.
    rigid_frequencies_hz : ndarray
        Their computed frequencies (numerically ~0), Hz.
    residuals : ndarray, shape (n,)
        ‖Kφ − λMφ‖ / ‖Kφ‖ of each elastic pair.
    orthogonality : float
        max |ΦᵀMΦ − I| over every returned pair (rigid ones included).
    effective_mass : ndarray, shape (n, 6)
        Effective modal masses for translations x, y, z (kg) and rotations about axes through
        the centre of mass (kg m²).
    total_mass : float
        kg, from M.
    n_dofs : int
        Unconstrained degrees of freedom solved for.
    backend : str
    timings : dict
        Wall time per phase, s.
    memory : dict
        Peak resident memory, bytes.
    in_band : ndarray of bool or None
        Which elastic modes lie in the requested band.
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    rigid_body_modes: int
    rigid_frequencies_hz: np.ndarray
    residuals: np.ndarray
    orthogonality: float
    effective_mass: np.ndarray
    total_mass: float
    n_dofs: int
    backend: str
    timings: dict = field(default_factory=dict)
    memory: dict = field(default_factory=dict)
    in_band: np.ndarray | None = None
    band: tuple | None = None
    n_solves: int = 0

    def to_dict(self) -> dict:
        out = {
            "frequencies_hz": self.frequencies_hz,
            "rigid_body_modes": self.rigid_body_modes,
            "rigid_frequencies_hz": self.rigid_frequencies_hz,
            "n_dofs": self.n_dofs,
            "residual_max": float(self.residuals.max()) if len(self.residuals) else 0.0,
            "residuals": self.residuals,
            "m_orthogonality_max": self.orthogonality,
            "effective_mass": {
                k: self.effective_mass[:, i] for i, k in enumerate(
                    ("x_kg", "y_kg", "z_kg", "rx_kgm2", "ry_kgm2", "rz_kgm2"))},
            "total_mass_kg": self.total_mass,
            "backend": self.backend,
            "n_solves": self.n_solves,
            "timings_s": self.timings,
            "peak_memory_bytes": self.memory.get("peak_rss_bytes"),
        }
        if self.band is not None:
            out["band_hz"] = list(self.band)
            out["frequencies_in_band_hz"] = self.frequencies_hz[self.in_band]
        return out


def allowed_rigid_modes(model: FEModel, T: sp.spmatrix) -> np.ndarray:
    """Rigid-body motions the supports leave, in the coordinates q of ``u = T q``.

    6 per connected piece of the mesh, less the combinations the supports forbid.

    Returns
    -------
    ndarray, shape (n_free, r)
        Columns span the allowed rigid motions (not normalised); ``r`` is their number.
    """
    from scipy.sparse.csgraph import connected_components

    n = len(model.points)
    cells = model.cells
    rows = np.repeat(cells[:, 0], cells.shape[1] - 1)
    cols = cells[:, 1:].ravel()
    g = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    used_labels = np.unique(labels[model.used])
    scale = np.ptp(model.points[model.used], axis=0).max()
    blocks = []
    for lab in used_labels:
        sel = (labels == lab) & model.used
        c = model.points[sel].mean(axis=0)
        R = rigid_body_modes(model.points, c)
        R[:, 3:] /= scale
        mask = np.repeat(sel, 3)
        R[~mask] = 0.0
        blocks.append(R)
    R = np.hstack(blocks)
    T = sp.csr_matrix(T)
    Q = R - T @ (T.T @ R)  # part of each rigid field the supports forbid
    _, sv, Vt = np.linalg.svd(Q, full_matrices=False)  # Q is tall: Vt is square
    rank = int((sv > 1e-8 * np.sqrt(n)).sum())
    return T.T @ (R @ Vt[rank:].T)


def expected_rigid_modes(model: FEModel, T: sp.spmatrix) -> int:
    """Rigid-body modes the supports leave: 6 per connected piece minus what T removes."""
    return allowed_rigid_modes(model, T).shape[1]


def sort_and_normalise(lam: np.ndarray, X: np.ndarray, M, chunk: int = 8):
    """Eigenpairs in ascending order with ``xᵀMx = 1``, normalised in place.

    Columns are scaled a few at a time, so no second n × k array is made (that copy was the
    memory peak of a 274k-DOF Craig–Bampton reduction).
    """
    if np.any(np.diff(lam) < 0):
        order = np.argsort(lam)
        lam, X = lam[order], X[:, order]
    for j in range(0, X.shape[1], chunk):
        Xj = X[:, j:j + chunk]
        Xj /= np.sqrt(np.einsum("ij,ij->j", Xj, M @ Xj))
    return lam, X


def top_ritz_value(apply, M, v: np.ndarray, steps: int) -> float:
    """Largest Ritz value of ``steps`` Lanczos steps of ``x -> apply(M x)`` in the M-inner product.

    A lower bound of the largest eigenvalue of the M-self-adjoint operator, close to it after a
    few steps when it stands apart (the check for eigenpairs a Lanczos run has missed). Fully
    reorthogonalised, so ``steps`` vectors of length n are kept.
    """
    Q = np.zeros((len(v), steps + 1))
    MQ = np.zeros_like(Q)  # M Q, kept so that each step costs one product with M
    Mv = M @ v
    nv = np.sqrt(v @ Mv)
    Q[:, 0], MQ[:, 0] = v / nv, Mv / nv
    alpha, beta = [], []
    for j in range(steps):
        w = apply(MQ[:, j])
        Mw = M @ w
        alpha.append(float(Q[:, j] @ Mw))
        for _ in range(2):  # full reorthogonalisation, twice is enough
            c = Q[:, :j + 1].T @ Mw
            w -= Q[:, :j + 1] @ c
            Mw -= MQ[:, :j + 1] @ c
        b = float(np.sqrt(max(w @ Mw, 0.0)))
        if b <= 1e-12 * abs(alpha[-1]) or j == steps - 1:
            break
        beta.append(b)
        Q[:, j + 1], MQ[:, j + 1] = w / b, Mw / b
    T = np.diag(alpha) + np.diag(beta, 1) + np.diag(beta, -1)
    return float(np.linalg.eigvalsh(T).max())


def default_shift(K, M) -> float:
    """A negative shift σ (rad²/s²) well below the lowest elastic eigenvalue, scale-free."""
    d = K.diagonal() / M.diagonal()
    return -1e-8 * float(np.median(d[d > 0]))


def check_pairs(K, M, lam, X, tol: float = 1e-6, shift: float = 0.0,
                what: str = "modal") -> tuple[np.ndarray, float]:
    """Residuals ‖Kx − λMx‖/‖Kx‖ and M-orthogonality of eigenpairs; raise when poor.

    Parameters
    ----------
    K, M : sparse matrices
    lam : ndarray, shape (k,)
    X : ndarray, shape (n, k)
        Mass-normalised vectors.
    tol : float
        Largest admissible residual and |XᵀMX − I|.
    shift : float
        |σ| used to scale the residual of (near) zero eigenvalues, whose ‖Kx‖ vanishes.

    Returns
    -------
    residuals : ndarray, orthogonality : float

    Raises
    ------
    NumericalError
    """
    KX = K @ X
    MX = M @ X
    num = np.linalg.norm(KX - MX * lam, axis=0)
    den = np.maximum(np.linalg.norm(KX, axis=0), abs(shift) * np.linalg.norm(MX, axis=0))
    res = num / np.where(den > 0, den, 1.0)
    G = X.T @ MX
    orth = float(np.abs(G - np.eye(len(lam))).max())
    worst = int(np.argmax(res)) if len(res) else 0
    if not np.all(np.isfinite(res)) or (len(res) and res[worst] > tol):
        f = np.sqrt(abs(lam[worst])) / (2 * np.pi)
        raise NumericalError(
            f"{what}: eigenpair {worst + 1} ({f:.6g} Hz) has residual ‖Kx−λMx‖/‖Kx‖ = "
            f"{res[worst]:.2e} > {tol:.0e}; check the mesh for degenerate or inverted elements "
            f"and for units (points in m, E in Pa), or try backend='superlu'")
    if not np.isfinite(orth) or orth > tol:
        i, j = np.unravel_index(np.argmax(np.abs(G - np.eye(len(lam)))), G.shape)
        raise NumericalError(
            f"{what}: modes {i + 1} and {j + 1} are not M-orthogonal (|XᵀMX − I| = {orth:.2e} "
            f"> {tol:.0e}); nearly repeated frequencies or a poorly conditioned mesh — refine "
            f"thin regions, ask for a few more modes, or try backend='superlu'")
    return res, orth


def solve_modes(model: FEModel, n_modes: int = 12, supports: list[Support] = (),
                backend: str = "auto", band: tuple | None = None, shift: float | None = None,
                tol: float = 1e-6, expected_rigid: int | None = None) -> Modes:
    """Lowest ``n_modes`` elastic modes of a model, free or supported.

    Parameters
    ----------
    model : FEModel
    n_modes : int
        Elastic modes wanted.
    supports : list of Support
        Empty: free-free.
    backend : str
        ``auto``, ``pardiso`` or ``superlu`` (see :mod:`crankmodal.fem.solvers`).
    band : (f_lo, f_hi) or None
        Hz; flags which modes fall inside.
    shift : float, optional
        Spectral shift σ < 0, rad²/s² (default: scale-free, far below the first elastic mode).
    tol : float
        Admissible residual and M-orthogonality defect.
    expected_rigid : int, optional
        Rigid-body modes to expect (default: from the mesh connectivity and the supports).

    Returns
    -------
    Modes
    """
    from scipy.sparse.linalg import LinearOperator, eigsh
    from threadpoolctl import threadpool_limits

    from .solvers import factorize_shifted

    if n_modes < 1:
        raise SceneError(f"modal.n_modes: must be >= 1, got {n_modes}")
    timings: dict = {}
    with PeakMemory() as mem:
        t0 = time.perf_counter()
        T = reduction(model.points, model.used, list(supports))
        K = reduce_matrix(model.K, T)
        M = reduce_matrix(model.M, T)
        Rq = allowed_rigid_modes(model, T)
        n_rigid_expected = Rq.shape[1] if expected_rigid is None else int(expected_rigid)
        deflate = expected_rigid is None and Rq.shape[1] > 0
        n = K.shape[0]
        k = n_modes if deflate else n_rigid_expected + n_modes
        if k >= n - 1:
            raise SceneError(f"modal.n_modes: {n_modes} modes need a finer mesh "
                             f"(only {n} free DOFs)")
        sigma = default_shift(K, M) if shift is None else float(shift)
        if sigma >= 0:
            raise SceneError(f"modal.shift: must be < 0, got {sigma}")
        timings["reduce_s"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        try:
            fac = factorize_shifted(K, M, sigma, backend, positive_definite=True)
        except np.linalg.LinAlgError as exc:
            raise NumericalError(f"modal: factorising K - σM failed ({exc}); the mesh may have "
                                 f"inverted elements, or an extra mechanism") from None
        timings["factorize_s"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        n_solves = [0]
        rng = np.random.default_rng(20240607)  # fixed: repeatable modes
        if deflate:  # the rigid modes are known: M-orthonormalise them and keep them out
            L = np.linalg.cholesky(Rq.T @ (M @ Rq))
            Rq = np.linalg.solve(L, Rq.T).T
            lam_r, W = np.linalg.eigh(Rq.T @ (K @ Rq))
            Xr = Rq @ W
        R0 = Rq if deflate else np.zeros((n, 0))  # M-orthonormal, kept out of the Krylov space
        D, MD = R0, M @ R0

        def project(x):
            return x - D @ (MD.T @ x) if D.shape[1] else x

        def solve(b, _fac=fac):
            n_solves[0] += 1
            return project(_fac.solve(b))

        op = LinearOperator((n, n), matvec=solve, dtype=float)
        # with the completeness check below, a shorter basis is safe when the rigid modes are
        # deflated (40 instead of 43 solves for 12 modes of the seed 000 crank)
        ncv = min(n - 1, max(2 * k + 1, 20 if deflate else k + 20))
        # one BLAS thread for ARPACK's small dense work (two were 5-7x slower); PARDISO sets
        # its own MKL threads per call
        with threadpool_limits(limits=1, user_api="blas"):
            lam, X = eigsh(K, k=k, M=M, sigma=sigma, which="LM", OPinv=op,
                           v0=project(rng.standard_normal(n)), tol=ARPACK_TOL, ncv=ncv)
            # completeness: a single-vector Lanczos cannot see the second mode of an exactly
            # repeated pair (an axisymmetric shaft or tube). Look below the highest mode found
            # with a few Lanczos steps from a fresh start; if one is there, hunt it down.
            for attempt in range(MAX_RESCUES + 1):
                if n - D.shape[1] - len(lam) <= COMPLETENESS_STEPS + 1:
                    break
                lam, X = sort_and_normalise(lam, X, M)
                D = np.hstack([R0, X])
                MD = M @ D
                theta = top_ritz_value(solve, M, project(rng.standard_normal(n)),
                                       COMPLETENESS_STEPS)
                if theta <= (1 + 1e-6) / (lam.max() - sigma):
                    break
                if attempt == MAX_RESCUES:
                    raise NumericalError(
                        f"modal: modes below {np.sqrt(abs(lam.max())) / (2 * np.pi):.6g} Hz "
                        f"keep escaping the Lanczos iteration (repeated frequencies); ask for "
                        f"more modes (n_modes) or break the part's symmetry slightly")
                lam2, X2 = eigsh(K, k=min(k, n - D.shape[1] - 2), M=M, sigma=sigma,
                                 which="LM", OPinv=op, v0=project(rng.standard_normal(n)),
                                 tol=ARPACK_TOL, ncv=min(n - D.shape[1] - 1, ncv))
                lam, X = np.r_[lam, lam2], np.hstack([X, X2])
                keep = np.argsort(lam)[:k]
                lam, X = lam[keep], X[:, keep]
        if deflate:
            lam, X = np.r_[lam_r, lam], np.hstack([Xr, X])
        backend_name = fac.name
        del op, solve, fac  # free the factor before the checks' n × k products
        timings["eigsh_s"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        lam, X = sort_and_normalise(lam, X, M)
        res, orth = check_pairs(K, M, lam, X, tol=tol, shift=sigma)
        f = np.sqrt(np.abs(lam)) / (2 * np.pi)
        rigid = f < RIGID_RATIO * f.max()
        n_rigid = int(rigid.sum())
        if not np.all(rigid[:n_rigid]) or n_rigid != n_rigid_expected:
            raise NumericalError(
                f"modal: found {n_rigid} zero-frequency modes where the supports leave "
                f"{n_rigid_expected}; lowest frequencies {np.array2string(f[:8], precision=4)} Hz "
                f"— look for loose elements or pieces of the mesh, or supports that do not hold")
        if np.any(lam[n_rigid:] <= 0):
            raise NumericalError("modal: negative eigenvalue among the elastic modes; "
                                 "check for inverted elements")
        shapes = T @ X
        mtot, c = mass_and_centre(model)
        R = rigid_body_modes(model.points, c)
        gamma = shapes[:, n_rigid:].T @ (model.M @ R)
        timings["checks_s"] = time.perf_counter() - t0
    fe = f[n_rigid:]
    in_band = None
    if band is not None:
        in_band = (fe >= band[0]) & (fe <= band[1])
    return Modes(frequencies_hz=fe, shapes=shapes[:, n_rigid:], rigid_body_modes=n_rigid,
                 rigid_frequencies_hz=f[:n_rigid], residuals=res[n_rigid:],
                 orthogonality=orth, effective_mass=gamma ** 2, total_mass=mtot, n_dofs=n,
                 backend=backend_name, timings=timings, memory=mem.to_dict(), in_band=in_band,
                 band=tuple(band) if band is not None else None, n_solves=n_solves[0])
