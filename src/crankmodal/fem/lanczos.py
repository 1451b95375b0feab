"""Shift-invert Lanczos in the M-inner product (:func:`lanczos`), checked at every step, with
deflation of known vectors (:func:`deflated`) and a check for the modes a single-vector run
missed (:func:`complete_modes`: the second of an exactly repeated pair).

Generic: the operator, the mass matrix and the start vectors come from the caller (the modal
solve, the Craig–Bampton fixed-interface modes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import NumericalError

#: Lanczos tolerance on ‖Ay − θy‖_M / θ. For the seed 000 crank the pair residuals
#: ‖Kx − λMx‖/‖Kx‖ come out at 1e-8 (37 solves), 100x inside the 1e-6 check; 1e-9 gives 2e-7
#: (36 solves), 1e-8 fails the check (2e-6, 35 solves).
LANCZOS_TOL = 1e-10

#: Lanczos steps of the check for modes the main run missed (the second of a repeated pair).
COMPLETENESS_STEPS = 8

#: Extra eigensolver runs allowed for missed modes before giving up.
MAX_RESCUES = 3


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
