"""Free and supported modal analysis: shift-invert Lanczos with one sparse factorisation.

The pencil (K, M) is solved by shift-invert Lanczos (:func:`lanczos`) about a small *negative* shift σ:
``K - σM`` is then positive definite even for a free part (its rigid-body modes sit at λ = 0 > σ),
so one Cholesky/LDLᵀ serves every Lanczos step. The rigid-body motions the supports leave (6 per
connected free piece) are known in closed form: they are M-orthonormalised, their Rayleigh
quotients checked like any other pair, and deflated from the Lanczos operator, so Lanczos only
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
from .assembly import NU_ILL_CONDITIONED, FEModel, bulk_to_shear, mass_and_centre, rigid_body_modes
from .memory import PeakMemory
from .parallel import RowBlocks
from .supports import Support, reduce_matrix, reduction

#: Lanczos tolerance on ‖Ay − θy‖_M / θ. For the seed 000 crank the pair residuals
#: ‖Kx − λMx‖/‖Kx‖ come out at 1e-8 (37 solves), 100x inside the 1e-6 check; 1e-9 gives 2e-7
#: (36 solves), 1e-8 fails the check (2e-6, 35 solves).
LANCZOS_TOL = 1e-10

#: Lanczos steps of the check for modes the main run missed (the second of a repeated pair).
COMPLETENESS_STEPS = 8

#: Extra eigensolver runs allowed for missed modes before giving up.
MAX_RESCUES = 3

#: A computed mode is rigid when its frequency is below this fraction of a reference: the
#: highest computed one, or with many modes the (rigid + :data:`RIGID_REF_MODES`)-th lowest
#: (the 50th mode of a clamped 0.3 m bar is 1000x its first, 34 Hz, which counted as rigid).
RIGID_RATIO = 1e-3

#: Elastic modes above the rigid ones whose highest sets the reference of :data:`RIGID_RATIO`.
RIGID_REF_MODES = 12


def rigid_mask(f: np.ndarray, n_rigid: int = 6) -> np.ndarray:
    """Which frequencies (any unit) are rigid-body ones: below :data:`RIGID_RATIO` of the
    ``n_rigid + RIGID_REF_MODES``-th lowest (the highest when there are fewer)."""
    f = np.abs(np.asarray(f, float))
    if not len(f):
        return np.zeros(0, bool)
    ref = np.sort(f)[min(len(f), n_rigid + RIGID_REF_MODES) - 1]
    return f < RIGID_RATIO * ref


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
    rigid_mass : ndarray, shape (6,) or None
        What the six rigid-body fields carry (the totals the effective masses add up to over
        every mode): mass along x, y, z (kg) and moments of inertia about the axes through the
        centre of mass (kg m²).
    n_dofs : int
        Unconstrained degrees of freedom solved for.
    backend : str
        The sparse factorisation of the Lanczos run (``pardiso``, ``superlu``), or ``dense``
        when the pencil was solved dense (:func:`use_dense`).
    eigensolver : str
        ``lanczos`` (shift-invert, sparse) or ``dense`` (LAPACK, :func:`dense_pairs`).
    timings : dict
        Wall time per phase, s.
    n_solves, solve_time : int, float
        Factorisation solves of the Lanczos phase and their wall time, s (the rest of
        ``timings["lanczos_s"]`` is the loop's own work).
    memory : dict
        Peak resident memory, bytes.
    in_band : ndarray of bool or None
        Which elastic modes lie in the requested band.
    band_complete : bool or None
        Whether every mode of the band was computed: the highest computed mode reaches the
        band's top (the modes are the lowest ``n_modes``; above the highest there may be more).
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
    solve_time: float = 0.0
    rigid_mass: np.ndarray | None = None
    eigensolver: str = "lanczos"

    @property
    def band_complete(self) -> bool | None:
        if self.band is None:
            return None
        return bool(len(self.frequencies_hz)) and bool(self.frequencies_hz[-1] >= self.band[1])

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
            "eigensolver": self.eigensolver,
            "n_solves": self.n_solves,
            "solve_time_s": self.solve_time,
            "timings_s": self.timings,
            "peak_memory_bytes": self.memory.get("peak_rss_bytes"),
        }
        if self.rigid_mass is not None:  # cumulative share of the total, as modes are added
            tot = np.where(self.rigid_mass > 0, self.rigid_mass, 1.0)
            cum = np.cumsum(self.effective_mass, axis=0) / tot
            out["effective_mass_cumulative_fraction"] = {
                k: cum[:, i] for i, k in enumerate(("x", "y", "z", "rx", "ry", "rz"))}
        if self.band is not None:
            out["band_hz"] = list(self.band)
            out["frequencies_in_band_hz"] = self.frequencies_hz[self.in_band]
            out["band_complete"] = self.band_complete
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


@dataclass
class Lanczos:
    """Outcome of :func:`lanczos`.

    Attributes
    ----------
    theta : ndarray, shape (k,)
        The k largest Ritz values of the operator, descending.
    vectors : ndarray, shape (n, k)
        Their Ritz vectors, M-orthonormal.
    m_vectors : ndarray, shape (n, k)
        M times them (from the kept M Q: no product with M).
    residuals : ndarray, shape (k,)
        Residual norms ``‖A y − θ y‖_M`` (from the Lanczos relation, no extra products).
    steps : int
        Operator applications (solves) made.
    converged : bool
        Every residual is at most ``tol θ`` (and ``accept`` agreed).
    """

    theta: np.ndarray
    vectors: np.ndarray
    m_vectors: np.ndarray
    residuals: np.ndarray
    steps: int
    converged: bool


def lanczos(apply, M, v0: np.ndarray, k: int, tol: float, max_steps: int,
            fresh=None, accept=None, keep_mq: bool = True) -> Lanczos:
    """Largest eigenpairs of the M-self-adjoint operator ``A x = apply(M x)``.

    Lanczos in the M-inner product with full reorthogonalisation (twice, against every basis
    vector), checked at *every* step: it stops at the first step at which each of the ``k``
    largest Ritz pairs has ``‖A y − θ y‖_M ≤ tol θ``. For shift-invert (``apply = (K − σM)⁻¹``)
    these are the eigenvalues of (K, M) nearest σ, ``λ = σ + 1/θ``. ARPACK, which checks only
    after each restart cycle of ``ncv`` vectors, needed 40 solves for the 12 modes of the seed
    000 crank (the 36 of this loop only with a lucky ``ncv``).

    Parameters
    ----------
    apply : callable
        ``b -> A' b`` with ``A = A' M`` (one factorisation solve, plus any deflation).
    M : sparse matrix, shape (n, n)
        Mass matrix, symmetric positive (semi-)definite on the space ``apply`` maps into.
    v0 : ndarray, shape (n,)
        Start vector (in the range of ``apply``).
    k : int
        Wanted pairs.
    tol : float
        Relative residual; 0 runs exactly ``max_steps`` steps.
    max_steps : int
        Most operator applications; the basis (and ``M`` times it) is kept: 2 n max_steps floats.
    fresh : callable, optional
        ``() -> vector`` for a new start direction when the Krylov space closes (an invariant
        subspace, e.g. a small model or an exact repeated eigenvalue) before ``k`` pairs are found.
    accept : callable, optional
        ``(theta, X, MX) -> bool``, asked once the Lanczos estimates are within ``tol``; ``False``
        continues the iteration. The estimate bounds the residual of the operator, not
        ``‖Kx − λMx‖`` (which weighs the residual's stiff part: 3e4 times larger for a clamped
        beam), so the modal solve checks the pencil's residuals here.
    keep_mq : bool
        Keep ``M Q`` beside the basis (one product with M per step). ``False`` keeps only the
        last two columns of it and forms ``M w`` again after each reorthogonalisation pass: half
        the memory of a long run (60 fixed-interface modes: 150 steps) for one more product.

    Returns
    -------
    Lanczos
    """
    from scipy.linalg.blas import daxpy as axpy
    from scipy.linalg.blas import dgemv as gemv

    n = len(v0)
    cap = max_steps + 1
    # column-major: a column is contiguous, and the pages of columns never reached stay unmapped
    Q = np.empty((n, cap), order="F")
    # M Q, kept so each step costs one product with M; or only its last two columns
    MQ = np.empty((n, cap if keep_mq else 2), order="F")

    def mq(j):
        return MQ[:, j] if keep_mq else MQ[:, j % 2]

    alpha, beta = np.zeros(cap), np.zeros(cap)

    def orthogonalise(v, Mv, j):
        """v, Mv M-orthogonalised against Q[:, :j] in place; the M-norm left. A second pass only
        when the first cancelled (Kahan-Parlett: "twice is enough")."""
        norm = float(np.sqrt(max(v @ Mv, 0.0)))
        for _ in range(2 if j else 0):
            c = Q[:, :j].T @ Mv
            gemv(-1.0, Q[:, :j], c, beta=1.0, y=v, overwrite_y=True)
            if keep_mq:
                gemv(-1.0, MQ[:, :j], c, beta=1.0, y=Mv, overwrite_y=True)
            else:
                Mv[:] = M @ v
            norm, before = float(np.sqrt(max(v @ Mv, 0.0))), norm
            if norm > 0.7071 * before:
                break
        return norm

    def start(j, v):
        """Put v, M-orthogonalised against Q[:, :j], in column j; False if nothing is left."""
        v = np.array(v, float)
        Mv = np.array(M @ v, float)
        nv = orthogonalise(v, Mv, j)
        if not np.isfinite(nv) or nv == 0.0:
            return False
        Q[:, j], mq(j)[:] = v / nv, Mv / nv
        return True

    if not start(0, v0):
        raise NumericalError("modal: the Lanczos start vector is zero or not finite")
    theta = Y = res = None
    steps = 0
    from ..progress import bar

    pbar = bar(total=max_steps, desc="modal: Lanczos", unit="step")
    for j in range(max_steps):
        w = np.array(apply(mq(j)), float)  # own copy: updated in place below
        steps += 1
        pbar.update(1)
        Mw = np.array(M @ w, float)
        alpha[j] = float(Q[:, j] @ Mw)
        # the three-term recurrence first (two vectors), then full reorthogonalisation, which
        # then only removes rounding: a second pass is rarely needed (each pass reads the basis)
        axpy(Q[:, j], w, a=-alpha[j])  # in place: w, Mw are this step's own arrays
        axpy(mq(j), Mw, a=-alpha[j])
        if j:
            axpy(Q[:, j - 1], w, a=-beta[j])
            axpy(mq(j - 1), Mw, a=-beta[j])
        b = orthogonalise(w, Mw, j + 1)
        m = j + 1
        T = np.diag(alpha[:m]) + np.diag(beta[1:m], 1) + np.diag(beta[1:m], -1)
        theta, Y = np.linalg.eigh(T)
        theta, Y = theta[::-1][:k], Y[:, ::-1][:, :k]
        res = b * np.abs(Y[-1])
        scale = np.abs(theta).max()
        done = len(theta) == k and tol > 0 and bool(np.all(res <= tol * np.abs(theta)))
        X = MX = None
        if done and accept is not None:
            X = Q[:, :m] @ Y
            MX = MQ[:, :m] @ Y if keep_mq else M @ X
            done = bool(accept(theta, X, MX))
        if done or m == max_steps:
            break
        if b > 1e-13 * scale:
            np.multiply(w, 1.0 / b, out=Q[:, m])
            np.multiply(Mw, 1.0 / b, out=mq(m))
            beta[m] = b
        else:  # the Krylov space closed: its Ritz pairs are exact; go on from a new direction
            if fresh is None or not start(m, fresh()):
                break
            beta[m] = 0.0
    if X is None:
        X = Q[:, :steps] @ Y
        MX = MQ[:, :steps] @ Y if keep_mq else M @ X
    pbar.close()
    return Lanczos(theta=theta, vectors=X, m_vectors=MX, residuals=res, steps=steps,
                   converged=done)


def deflated(apply, fresh, D: np.ndarray, MD: np.ndarray):
    """The operator and start vectors with the M-orthonormal columns of ``D`` kept out.

    Returns ``(op, start)``: ``op(b) = P apply(b)`` and ``start() = P fresh()`` with the
    M-orthogonal projector ``P x = x − D (MDᵀ x)`` (``MD = M D``).
    """
    if not D.shape[1]:
        return apply, fresh

    def project(x):
        return x - D @ (MD.T @ x)

    return (lambda b: project(apply(b))), (lambda: project(fresh()))


def complete_modes(apply, fresh, M, run, lam: np.ndarray, X: np.ndarray, MX: np.ndarray,
                   sigma: float, k: int, what: str = "modal",
                   kept: tuple | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Find the modes a single-vector Lanczos run missed below the highest one it found.

    A Krylov space from one start vector holds one vector of each eigenspace: the second mode of
    an exactly repeated pair (an axisymmetric shaft or tube) can only come in through rounding.
    :data:`COMPLETENESS_STEPS` Lanczos steps from a fresh start, with the found modes kept out,
    look for a Ritz value above the highest found one; when there is one, ``run`` hunts the
    missed modes down (at most :data:`MAX_RESCUES` times) and the lowest ``k`` of all are kept.

    Parameters
    ----------
    apply : callable
        ``b -> (K − σM)⁻¹ b``.
    fresh : callable
        ``() -> vector``: a random start direction in the space ``apply`` maps into.
    M : sparse matrix or LinearOperator
    run : callable
        ``(op, k_run, start, room) -> Lanczos``: the caller's converged Lanczos run of ``k_run``
        pairs of the operator ``op`` from ``start()`` (``start`` also gives restarts), in at
        most ``room`` steps (the dimension left).
    lam, X, MX : ndarray
        Eigenvalues found (rad²/s²), their M-orthonormal vectors and M times them.
    sigma : float
        The shift, rad²/s² (``λ = σ + 1/θ``).
    k : int
        Pairs wanted.
    what : str
        Prefix of the error message.
    kept : (R, MR), optional
        M-orthonormal vectors to keep out as well (the known rigid-body modes), M times them.

    Returns
    -------
    lam, X, MX : the lowest ``k`` pairs (ascending when anything was added).

    Raises
    ------
    NumericalError
        Modes still escape after :data:`MAX_RESCUES` runs.
    """
    n = X.shape[0]
    for attempt in range(MAX_RESCUES + 1):
        D, MD = (X, MX) if kept is None else (np.hstack([kept[0], X]), np.hstack([kept[1], MX]))
        if n - D.shape[1] <= COMPLETENESS_STEPS + 1:
            break
        op, start = deflated(apply, fresh, D, MD)
        theta = lanczos(op, M, start(), 1, 0.0, COMPLETENESS_STEPS).theta[0]
        if theta <= (1 + 1e-6) / (lam.max() - sigma):
            break
        if attempt == MAX_RESCUES:
            raise NumericalError(
                f"{what}: modes below {np.sqrt(abs(lam.max())) / (2 * np.pi):.6g} Hz keep "
                f"escaping the Lanczos iteration (repeated frequencies); ask for more modes or "
                f"break the part's symmetry slightly")
        extra = run(op, min(k, n - D.shape[1] - 2), start, n - D.shape[1])
        lam = np.r_[lam, sigma + 1.0 / extra.theta]
        keep = np.argsort(lam)[:k]
        lam = lam[keep]
        X = np.hstack([X, extra.vectors])[:, keep]
        MX = np.hstack([MX, extra.m_vectors])[:, keep]
    return lam, X, MX


def stall_advice(model: FEModel) -> str:
    """What to change when the eigenpairs cannot be made accurate: the material or the mesh."""
    nu = float(model.material.nu)
    if nu >= NU_ILL_CONDITIONED:
        return (f"nu = {nu:.10g} makes the bulk modulus {bulk_to_shear(nu):.1e} times the shear "
                f"modulus; use nu <= 0.4999 (crankmodal has no mixed u-p elements)")
    return ("look for flat or needle elements (geometry.optimize = true, a larger "
            "geometry.refine) or extreme size ratios, or loosen modal.tol")


def default_shift(K, M) -> float:
    """A negative shift σ (rad²/s²) well below the lowest elastic eigenvalue, scale-free."""
    d = K.diagonal() / M.diagonal()
    return -1e-8 * float(np.median(d[d > 0]))


def pair_residuals(KX: np.ndarray, MX: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """``‖Kx − λMx‖ / ‖Kx‖`` of each pair; zero-frequency pairs relative to the first elastic one.

    A rigid-body mode has ``Kx ≈ 0``: its residual is measured against ``λ_e ‖Mx‖`` with λ_e the
    smallest eigenvalue not rigid by :func:`rigid_mask`, i.e. its strain energy
    must be ``tol`` of the first elastic mode's. (Against the shift |σ| ~ 1e-8 λ it would demand
    rounding-free vectors: the stiff part of a 1e-16 noise is ~1e-6 of |σ|.)
    """
    lam = np.asarray(lam, float)
    f = np.sqrt(np.abs(lam))
    elastic = ~rigid_mask(f)
    lam_e = lam[elastic].min() if np.any(elastic) else (np.abs(lam).max() or 1.0)
    num = np.linalg.norm(KX - MX * lam, axis=0)
    den = np.maximum(np.linalg.norm(KX, axis=0), abs(lam_e) * np.linalg.norm(MX, axis=0))
    return num / np.where(den > 0, den, 1.0)


def check_pairs(K, M, lam, X, tol: float = 1e-6, what: str = "modal",
                advice: str | None = None) -> tuple[np.ndarray, float]:
    """Residuals ‖Kx − λMx‖/‖Kx‖ and M-orthogonality of eigenpairs; raise when poor.

    Parameters
    ----------
    K, M : sparse matrices
    lam : ndarray, shape (k,)
    X : ndarray, shape (n, k)
        Mass-normalised vectors.
    tol : float
        Largest admissible residual (:func:`pair_residuals`) and |XᵀMX − I|.
    advice : str, optional
        What to change when the residuals fail, when the cause is known (a nearly
        incompressible material); default: the mesh, the units, the factorisation.

    Returns
    -------
    residuals : ndarray, orthogonality : float

    Raises
    ------
    NumericalError
    """
    MX = M @ X
    res = pair_residuals(K @ X, MX, lam)
    G = X.T @ MX
    orth = float(np.abs(G - np.eye(len(lam))).max())
    worst = int(np.argmax(res)) if len(res) else 0
    if not np.all(np.isfinite(res)) or (len(res) and res[worst] > tol):
        f = np.sqrt(abs(lam[worst])) / (2 * np.pi)
        raise NumericalError(
            f"{what}: eigenpair {worst + 1} ({f:.6g} Hz) has residual ‖Kx−λMx‖/‖Kx‖ = "
            f"{res[worst]:.2e} > {tol:.0e}; " + (advice or
            "check the mesh for degenerate or inverted elements and for units (points in m, "
            "E in Pa), or try backend='superlu'"))
    if not np.isfinite(orth) or orth > tol:
        i, j = np.unravel_index(np.argmax(np.abs(G - np.eye(len(lam)))), G.shape)
        raise NumericalError(
            f"{what}: modes {i + 1} and {j + 1} are not M-orthogonal (|XᵀMX − I| = {orth:.2e} "
            f"> {tol:.0e}); nearly repeated frequencies or a poorly conditioned mesh — refine "
            f"thin regions, ask for a few more modes, or try backend='superlu'")
    return res, orth


#: Free DOF up to which the pencil is always solved dense (:func:`dense_pairs`): with its
#: refinement step 0.4 s at 975 DOF, 1.5-3.6 s at 1275, 1-4 s at 1875 on the 2 shared cores,
#: against 0.05-0.26 s for 12 Lanczos modes; but it has no convergence to fail, and Lanczos
#: stalled or overflowed for 50 modes of several 350-700-DOF bars. Above it, many modes
#: (:data:`DENSE_FRACTION`) still go dense.
DENSE_MAX_DOF = 1000

#: Pairs wanted (rigid included) above this share of the free DOF go dense too, up to
#: :data:`DENSE_LIMIT_DOF`: 103 modes of a 3465-DOF bar (3 %) stalled after 452 Lanczos steps
#: (14 s) where the dense path took 3-5 s; the lowest share that failed in a scan of 8 bars was
#: 3 % (60 modes of 1875 DOF, 3.2 %, converged).
DENSE_FRACTION = 0.02

#: Largest dense problem (K, M and LAPACK's copies: ~1.2 GB; sygvx 23-25 s at 6k DOF).
DENSE_LIMIT_DOF = 6000


def dense_bytes(n: int) -> int:
    """Memory of :func:`dense_pairs` for ``n`` DOF: K, M and LAPACK's copies of both, bytes."""
    return 4 * 8 * n * n


def use_dense(n: int, k: int) -> bool:
    """Whether ``k`` pairs of an ``n``-DOF pencil are better solved dense than by Lanczos
    (and the dense matrices fit in the memory available; else Lanczos, whose factor is smaller
    and checked on its own)."""
    from .memory import available_bytes

    if not (n <= DENSE_MAX_DOF or (k > DENSE_FRACTION * n and n <= DENSE_LIMIT_DOF)):
        return False
    avail = available_bytes()
    return avail is None or dense_bytes(n) <= avail


def dense_pairs(K, M, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Lowest ``k`` eigenpairs of the pencil (K, M) by LAPACK (``scipy.linalg.eigh``).

    For small models, or many modes of a modest one, where a Krylov space of the size needed
    cannot be built cleanly. Rigid-body pairs are not deflated: they come out with
    λ ≈ 0 and are separated by the caller's frequency ratio, as the Lanczos ones are checked.

    Parameters
    ----------
    K, M : sparse matrices, shape (n, n)
        Reduced stiffness (N/m) and mass (kg); M positive definite.
    k : int
        Pairs wanted, ``1 <= k <= n``.

    Returns
    -------
    lam : ndarray, shape (k,)
        Ascending eigenvalues, rad²/s².
    X : ndarray, shape (n, k)
        Their vectors, ``XᵀMX = I``.

    Raises
    ------
    NumericalError
        M is not positive definite (elements of zero or negative volume).
    """
    from scipy.linalg import eigh

    from ..errors import ResourceError
    from .memory import available_bytes

    n = K.shape[0]
    avail = available_bytes()
    if avail is not None and dense_bytes(n) > avail:
        raise ResourceError(
            f"modal: the dense eigensolver needs {dense_bytes(n) / 1e9:.3g} GB for {n} DOF but "
            f"{avail / 1e9:.3g} GB are available: use modal.eigensolver = 'lanczos' or 'auto', "
            f"or a coarser mesh (CRANKMODAL_MEMORY_LIMIT, in GB, sets the available figure)")
    Kd = K.toarray() if sp.issparse(K) else np.array(K, float)
    Md = M.toarray() if sp.issparse(M) else np.array(M, float)
    try:
        lam, X = eigh(Kd, Md, subset_by_index=[0, k - 1], overwrite_a=True, overwrite_b=True)
    except np.linalg.LinAlgError as exc:
        raise NumericalError(f"modal: the dense eigensolver failed ({exc}); M is not positive "
                             f"definite: look for elements of zero or negative volume") from None
    return lam, X


def rigid_pairs(K, M, Rq: np.ndarray):
    """The known rigid-body motions as eigenpairs: ``(R, lam_r, Xr)`` with ``R`` the columns of
    ``Rq`` M-orthonormalised, ``lam_r`` (≈ 0, rad²/s²) and ``Xr`` the Rayleigh–Ritz pairs of
    (K, M) on them."""
    L = np.linalg.cholesky(Rq.T @ (M @ Rq))
    R = np.linalg.solve(L, Rq.T).T
    lam_r, W = np.linalg.eigh(R.T @ (K @ R))
    return R, lam_r, R @ W


def dense_with_rigid(K, M, Rq: np.ndarray, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`dense_pairs` with the known rigid-body pairs (:func:`rigid_pairs`) in place of
    LAPACK's: its zero-frequency vectors carry rounding of size eps λ_max, a residual over
    1e-6 of the first elastic mode for a 200:1 strip; the elastic vectors are M-projected off
    the exact rigid ones. A zero mode the connectivity did not predict stays among the
    elastic ones, for the caller's rigid count to catch."""
    r = Rq.shape[1]
    lam, X = dense_pairs(K, M, r + n_modes)
    _, lam_r, Xr = rigid_pairs(K, M, Rq)
    Xe = X[:, r:]
    Xe -= Xr @ ((M @ Xr).T @ Xe)
    Xe /= np.sqrt(np.einsum("ij,ij->j", Xe, M @ Xe))
    return np.r_[lam_r, lam[r:]], np.hstack([Xr, Xe])


def refine_pairs(K, M, X: np.ndarray, sigma: float, backend: str = "auto",
                 R: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One step of shift-invert subspace iteration and Rayleigh–Ritz on the columns of ``X``.

    A dense eigensolver's pairs have a normwise backward error ``eps ‖K‖``: relative to the
    lowest modes' ``‖Kx‖`` that is ``eps λ_max / λ``, over 1e-6 for a 200:1 strip (1.2e-6 at
    133 Hz). ``(K − σM)⁻¹ M`` shrinks each error component by ``(λ − σ)/(λ_j − σ)``: one step
    (one sparse factorisation, ``k`` solves) brings the residuals to the Lanczos ones.

    Parameters
    ----------
    K, M : sparse matrices
    X : ndarray, shape (n, k)
        Approximate eigenvectors.
    sigma : float
        Shift, rad²/s², below the lowest eigenvalue of the span.
    backend : str
        Sparse factorisation (:mod:`crankmodal.fem.solvers`).
    R : ndarray, shape (n, r), optional
        M-orthonormal vectors to keep out (the rigid-body modes).

    Returns
    -------
    lam : ndarray, shape (k,)
        Ascending, rad²/s².
    X : ndarray, shape (n, k)
        M-orthonormal.
    """
    from scipy.linalg import eigh

    from .solvers import factorize_shifted

    try:
        fac = factorize_shifted(K, M, sigma, backend, positive_definite=True, label="modal: ")
    except np.linalg.LinAlgError as exc:
        raise NumericalError(f"modal: factorising K - σM failed ({exc}); the mesh may have "
                             f"inverted elements, or an extra mechanism") from None
    Y = fac.solve(M @ X)
    del fac
    if R is not None and R.shape[1]:
        Y -= R @ ((M @ R).T @ Y)
    Y /= np.sqrt(np.einsum("ij,ij->j", Y, M @ Y))  # columns of one scale for the small pencil
    Kr, Mr = Y.T @ (K @ Y), Y.T @ (M @ Y)
    lam, W = eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
    return sort_and_normalise(lam, Y @ W, M)


def lanczos_pairs(model: FEModel, K, M, Rq: np.ndarray, deflate: bool, k: int,
                  shift: float | None, backend: str, tol: float, timings: dict):
    """Lowest ``k`` pairs of the reduced pencil by shift-invert Lanczos (one sparse factor).

    With ``deflate`` the columns of ``Rq`` (the rigid-body motions) are M-orthonormalised and
    kept out of the Krylov space, ``k`` counts elastic pairs only, and the rigid pairs are
    added to the result.

    Returns
    -------
    lam, X, K, M, backend_name, n_solves, solve_time
        Eigenvalues (rad²/s², unsorted), M-orthonormal vectors, K and M as
        :class:`~crankmodal.fem.parallel.RowBlocks`, the factorisation's name, its solves and
        their wall time (s).
    """
    from threadpoolctl import threadpool_limits

    from .solvers import factorize_shifted

    n = K.shape[0]
    sigma = default_shift(K, M) if shift is None else float(shift)
    if sigma >= 0:
        raise SceneError(f"modal.shift: must be < 0, got {sigma}")
    t0 = time.perf_counter()
    try:
        fac = factorize_shifted(K, M, sigma, backend, positive_definite=True,
                                label="modal: ")
    except np.linalg.LinAlgError as exc:
        raise NumericalError(f"modal: factorising K - σM failed ({exc}); the mesh may have "
                             f"inverted elements, or an extra mechanism") from None
    timings["factorize_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    K, M = RowBlocks(K), RowBlocks(M)  # products on every core: the loop's M·w, the checks
    n_solves, solve_time = [0], [0.0]
    rng = np.random.default_rng(20240607)  # fixed: repeatable modes
    if deflate:  # the rigid modes are known: M-orthonormalise them and keep them out
        Rq, lam_r, Xr = rigid_pairs(K, M, Rq)
    R0 = Rq if deflate else np.zeros((n, 0))  # M-orthonormal, kept out of the Krylov space
    MR0 = M @ R0

    def solve(b, _fac=fac):
        n_solves[0] += 1
        t = time.perf_counter()
        x = _fac.solve(b)
        solve_time[0] += time.perf_counter() - t
        return x

    last = {}

    def accept(theta, X, MX):
        """Pencil residuals of the candidate pairs 10x inside the final check (zero-frequency
        ones, whose residual is a rounding floor that more steps do not lower: inside it) —
        or inside it and no longer falling: a floor set by rounding, which more steps only
        pay for (with the rigid modes in the Krylov space, 1e8 times the elastic θ, it sat
        at 1.3-1.8e-7 on a 12k-DOF bar while 10x inside asked for 1e-7)."""
        lam_c = sigma + 1.0 / theta
        f = np.sqrt(np.abs(lam_c))
        margin = np.where(rigid_mask(f), 1.0, 0.1)
        r = pair_residuals(K @ X, MX, lam_c)
        before, last["r"] = last.get("r"), r
        if np.all(r <= margin * tol):
            return True
        return (before is not None and len(before) == len(r) and bool(np.all(r <= tol))
                and r.max() > 0.5 * before.max())

    def run(op, k_run, start, room):
        """Lowest k_run modes of the deflated pencil (raises when Lanczos does not converge)."""
        steps = min(room, max(4 * k_run + 40, 60))
        last.clear()  # the floor test compares calls within one run
        out = lanczos(op, M, start(), k_run, LANCZOS_TOL, steps, fresh=start, accept=accept)
        r = last.get("r")
        if (not out.converged and r is not None and model.material.nu < NU_ILL_CONDITIONED
                and len(r) > 1 and r[:len(r) // 2].max() <= tol):
            # the lowest pairs are fine, the highest sit on a floor: 103 modes of a 3.5k-DOF
            # bar stalled at 4e-4 where the dense solver's residuals were 1e-9 (not the mesh)
            raise NumericalError(
                f"modal: the eigen-residuals of the highest of {k_run} modes stall at "
                f"{r.max():.1e} > tol = {tol:.0e} (the lowest {len(r) // 2} are within it): "
                f"shift-invert Lanczos cannot resolve that many modes of {n} DOF; ask for fewer "
                f"(modal.n_modes), loosen modal.tol, or use modal.eigensolver = 'dense'")
        if not out.converged and "r" in last:  # the Lanczos estimates converged, the pairs not
            raise NumericalError(
                f"modal: the eigen-residuals ‖Kx − λMx‖/‖Kx‖ stall at {last['r'].max():.1e} "
                f"> tol = {tol:.0e}: K is too ill-conditioned for double precision — "
                + stall_advice(model))
        if not out.converged:
            raise NumericalError(
                f"modal: {k_run} modes did not converge in {out.steps} Lanczos steps "
                f"(largest relative residual {np.max(out.residuals / np.abs(out.theta)):.1e});"
                + (" " + stall_advice(model) if model.material.nu >= NU_ILL_CONDITIONED else
                   " check the mesh for loose or degenerate elements, or ask for fewer modes"))
        return out

    # one BLAS thread for the small dense work of the loop (two were 5-7x slower); PARDISO
    # sets its own MKL threads per call
    with threadpool_limits(limits=1, user_api="blas"):
        def fresh():
            return rng.standard_normal(n)

        op, start = deflated(solve, fresh, R0, MR0)
        main = run(op, k, start, n - R0.shape[1])
        lam, X, _ = complete_modes(solve, fresh, M, run, sigma + 1.0 / main.theta,
                                   main.vectors, main.m_vectors, sigma, k,
                                   kept=(R0, MR0) if R0.shape[1] else None)
    if deflate:
        lam, X = np.r_[lam_r, lam], np.hstack([Xr, X])
    backend_name = fac.name
    del solve, fac  # free the factor before the checks' n × k products
    timings["lanczos_s"] = time.perf_counter() - t0
    return lam, X, K, M, backend_name, n_solves[0], solve_time[0]


def solve_modes(model: FEModel, n_modes: int = 12, supports: list[Support] = (),
                backend: str = "auto", band: tuple | None = None, shift: float | None = None,
                tol: float = 1e-6, expected_rigid: int | None = None,
                eigensolver: str = "auto") -> Modes:
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
    eigensolver : str
        ``auto`` (:func:`use_dense` decides), ``lanczos`` or ``dense``.

    Returns
    -------
    Modes
    """
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
        n_elastic = n - n_rigid_expected
        if n_modes > n_elastic:
            raise SceneError(
                f"modal.n_modes: {n_modes} elastic modes asked, but the part has only "
                f"{n_elastic} ({n} free DOF less {n_rigid_expected} rigid-body modes); ask for at "
                f"most {n_elastic}, or refine the mesh")
        timings["reduce_s"] = time.perf_counter() - t0

        if eigensolver not in ("auto", "lanczos", "dense"):
            raise SceneError(f"modal.eigensolver: must be auto, lanczos or dense; got {eigensolver!r}")
        if eigensolver == "dense" or (eigensolver == "auto"
                                      and use_dense(n, n_rigid_expected + n_modes)):
            t0 = time.perf_counter()
            if deflate:
                lam, X = dense_with_rigid(K, M, Rq, n_modes)
            else:
                lam, X = dense_pairs(K, M, n_rigid_expected + n_modes)
            r = Rq.shape[1] if deflate else 0
            sigma = default_shift(K, M) if shift is None else float(shift)
            lam_e, X_e = refine_pairs(K, M, X[:, r:], sigma, backend, R=X[:, :r])
            lam, X = np.r_[lam[:r], lam_e], np.hstack([X[:, :r], X_e])
            timings.update(factorize_s=0.0, lanczos_s=0.0, dense_s=time.perf_counter() - t0)
            backend_name, eigensolver, n_solves, solve_time = "dense", "dense", 0, 0.0
        else:
            if n_rigid_expected + n_modes >= n - 1:  # only when asked for: auto goes dense
                raise SceneError(f"modal.eigensolver: Lanczos cannot find "
                                 f"{n_rigid_expected + n_modes} pairs of {n} DOF; use 'dense' "
                                 f"or 'auto'")
            lam, X, K, M, backend_name, n_solves, solve_time = lanczos_pairs(
                model, K, M, Rq, deflate, k, shift, backend, tol, timings)
            eigensolver = "lanczos"

        t0 = time.perf_counter()
        order = np.argsort(lam)  # M-orthonormal already (Lanczos, rigid basis): check_pairs checks
        lam, X = lam[order], X[:, order]
        advice = None
        if eigensolver == "dense" or model.material.nu >= NU_ILL_CONDITIONED:
            # LAPACK's dense solution is backward stable: poor pairs are the model's conditioning
            advice = "K is too ill-conditioned for double precision — " + stall_advice(model)
        res, orth = check_pairs(K, M, lam, X, tol=tol, advice=advice)
        f = np.sqrt(np.abs(lam)) / (2 * np.pi)
        rigid = rigid_mask(f, n_rigid_expected)
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
        MR = model.M @ R
        gamma = shapes[:, n_rigid:].T @ MR
        rigid_mass = np.einsum("ij,ij->j", R, MR)  # m, m, m, Jxx, Jyy, Jzz about the centre
        timings["checks_s"] = time.perf_counter() - t0
    fe = f[n_rigid:]
    in_band = None
    if band is not None:
        in_band = (fe >= band[0]) & (fe <= band[1])
    return Modes(frequencies_hz=fe, shapes=shapes[:, n_rigid:], rigid_body_modes=n_rigid,
                 rigid_frequencies_hz=f[:n_rigid], residuals=res[n_rigid:],
                 orthogonality=orth, effective_mass=gamma ** 2, total_mass=mtot, n_dofs=n,
                 backend=backend_name, timings=timings, memory=mem.to_dict(), in_band=in_band,
                 band=tuple(band) if band is not None else None, n_solves=n_solves,
                 solve_time=solve_time, rigid_mass=rigid_mass, eigensolver=eigensolver)
