"""The dense path of the modal solve: LAPACK on the full pencil (:func:`dense_pairs`), with the
known rigid-body pairs in place of LAPACK's (:func:`dense_with_rigid`), one shift-invert
refinement step (:func:`refine_pairs`), and when to take it (:func:`use_dense`)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError
from .modes import sort_and_normalise
from .rigid_modes import rigid_pairs

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
