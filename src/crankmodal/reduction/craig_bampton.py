"""Craig–Bampton basis: static constraint modes and fixed-interface normal modes from ONE factor.

Partition of the mesh DOFs: ``S`` = DOFs on rigid (RBE2) interface surfaces, eliminated through
``u_S = R q`` (:func:`~crankmodal.reduction.interfaces.rigid_map`); ``I`` = every other DOF in
use, on which the distributing (RBE3) interfaces impose ``G u_I = q_d``. The boundary
coordinates ``q`` are the 6 DOFs of every interface node.

- Constraint modes (one per interface DOF ``j``): ``u_S = R e_j``, and ``u_I`` minimises the
  strain energy subject to ``G u_I = e_j`` (distributing part):
  ``[K_II Gᵀ; G 0] [u_I; λ] = [−K_IS R e_j; e_j]``.
- Fixed-interface modes: ``q = 0``, i.e. ``u_S = 0`` and ``G u_I = 0``; the pencil
  ``(K_II, M_II)`` on the null space of ``G``.

Both use one sparse Cholesky of the interior stiffness and a small dense saddle system
(``S = G K⁻¹ Gᵀ``, 6 rows per distributing interface), so the constrained inverse costs one
solve plus an ``n × 6m_d`` product: RBE3 costs about what RBE2 does, without forming ``Gᵀ G``
(dense per surface) or a Lagrange-augmented indefinite matrix. With at least one rigid interface
``K_II`` is positive definite. With distributing interfaces only it is the singular free-free
stiffness; then ``u = R a + w`` splits off the rigid motion ``R a`` exactly, ``w`` vanishing on
six DOFs of a statically determinate 3-2-1 support, and the factorised matrix is ``K_II``
without those six DOFs — positive definite, no spectral shift. Since ``G R = I`` per interface
and ``K R = 0``, the rigid amplitudes ``a`` join the Lagrange multipliers in the small system
``[S E; Eᵀ 0][λ; a] = [g − G K⁻¹f; −Rᵀf]``. The fixed-interface eigen solve is shift-invert
about 0 with that same factor (Lanczos on ``OP = P M``, ``P`` the constrained inverse).
``factorize_s`` in the timings includes the ``6 m_d`` solves for ``K⁻¹ Gᵀ``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError, ParameterError
from .interfaces import Interface, distributing_rows, rigid_map


@dataclass
class CraigBamptonBasis:
    """A Craig–Bampton reduction of an FE model.

    Attributes
    ----------
    V : ndarray, shape (n_dofs, 6 m + k)
        Basis in full mesh DOFs (node-interleaved): columns 0..6m−1 are constraint modes (unit
        interface DOF ``6 r + c``: ``c`` = x, y, z translations (m), then rotations (rad)), then
        the ``k`` fixed-interface modes (mass-normalised).
    K, M : ndarray, shape (6 m + k, 6 m + k)
        ``Vᵀ K V`` (N/m …) and ``Vᵀ M V`` (kg …), symmetric.
    n_boundary : int
        6 m.
    fixed_interface_hz : ndarray, shape (k,)
        Fixed-interface natural frequencies, Hz.
    interfaces : list of Interface
    n_interior : int
        DOFs in the factorised interior matrix.
    support : ndarray of int
        Mesh DOFs of the 3-2-1 support used for a floating interior (empty otherwise).
    backend : str
    residual : float
        Largest relative residual of the fixed-interface eigenpairs (constraint forces removed).
    timings : dict
        s per phase.
    """

    V: np.ndarray
    K: np.ndarray
    M: np.ndarray
    n_boundary: int
    fixed_interface_hz: np.ndarray
    interfaces: list
    n_interior: int
    support: np.ndarray
    backend: str
    residual: float
    timings: dict = field(default_factory=dict)

    @property
    def n_fixed_modes(self) -> int:
        return self.V.shape[1] - self.n_boundary


class ConstrainedSolver:
    """``u`` minimising ``½uᵀKu − uᵀf`` subject to ``G u = g``, with one factor.

    Parameters
    ----------
    factor : object with ``solve``
        Factor of ``K_FF``: ``K`` without the ``support`` DOFs (or all of ``K``).
    G : scipy.sparse.csr_matrix, shape (c, n)
        Constraint rows.
    n : int
        Size of ``K``.
    support : ndarray of int, optional
        Six DOFs of a statically determinate support of a floating body (empty otherwise).
    R : ndarray, shape (n, 6), optional
        Rigid fields of the floating body, with ``K R = 0`` and ``G R`` of full column rank.
    """

    def __init__(self, factor, G: sp.csr_matrix, n: int, support=(), R=None):
        self.factor, self.n = factor, n
        self.support = np.asarray(support, np.int64)
        self.free = np.setdiff1d(np.arange(n), self.support)
        self.R = None if R is None or not len(self.support) else np.asarray(R, float)
        self.GF = G[:, self.free].tocsr()
        c = G.shape[0]
        self.Y = (np.asarray(factor.solve(np.asarray(self.GF.T.todense()))).reshape(-1, c)
                  if c else np.zeros((len(self.free), 0)))
        S = self.GF @ self.Y
        blocks = [[0.5 * (S + S.T)]]
        if self.R is not None:
            E = G @ self.R
            blocks = [[blocks[0][0], E], [E.T, np.zeros((6, 6))]]
        self._A = np.block(blocks) if c or self.R is not None else np.zeros((0, 0))
        self._lu = None
        if self._A.size:
            from scipy.linalg import lu_factor

            self._lu = lu_factor(self._A)

    def solve(self, f: np.ndarray, g: np.ndarray | None = None) -> np.ndarray:
        """Minimiser ``u`` (same shape as ``f``); ``g`` (constraint values) defaults to 0."""
        from scipy.linalg import lu_solve

        f = np.asarray(f, float)
        vec = f.ndim == 1
        F = f[:, None] if vec else f
        x0 = np.asarray(self.factor.solve(F[self.free])).reshape(len(self.free), F.shape[1])
        c = self.GF.shape[0]
        u = np.zeros_like(F)
        if self._lu is not None:
            r1 = -(self.GF @ x0)
            if g is not None:
                r1 = r1 + (g[:, None] if vec else g)
            rhs = r1 if self.R is None else np.vstack([r1, -(self.R.T @ F)])
            sol = lu_solve(self._lu, rhs)
            x0 = x0 + self.Y @ sol[:c]
            if self.R is not None:
                u = self.R @ sol[c:]
        u[self.free] += x0
        return u[:, 0] if vec else u


def support_321(points: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Six DOFs (``3 p + c``) of a well-conditioned statically determinate support.

    Three far-apart, non-collinear ``nodes``; the six DOFs among their nine whose rigid-field
    rows are best conditioned (pivoted QR).
    """
    from scipy.linalg import qr

    from ..fem.assembly import rigid_body_modes

    x = points[nodes]
    p1 = int(np.argmax(np.linalg.norm(x - x.mean(0), axis=1)))
    p2 = int(np.argmax(np.linalg.norm(x - x[p1], axis=1)))
    d = (x[p2] - x[p1]) / np.linalg.norm(x[p2] - x[p1])
    rel = x - x[p1]
    p3 = int(np.argmax(np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)))
    pts = nodes[[p1, p2, p3]]
    dofs = (3 * pts[:, None] + np.arange(3)).ravel()
    Rr = rigid_body_modes(points[pts], points[pts].mean(0))
    _, _, piv = qr(Rr.T, pivoting=True)
    return np.sort(dofs[piv[:6]])


#: Constraint modes solved per block of this many right-hand sides.
CONSTRAINT_BLOCK = 18


def _fixed_interface_modes(M, solver, n, k):
    """Lowest ``k`` eigenpairs of (K, M) on ker G: shift-invert Lanczos about 0 with ``solver``.

    :func:`crankmodal.fem.modal.lanczos` (full reorthogonalisation, checked at every step), with
    only the basis kept (not M times it: half the memory of the 150-step run 60 modes take),
    then :func:`crankmodal.fem.modal.complete_modes` (8 more solves) for the second mode of an
    exactly repeated pair. Neither sorted nor normalised: :func:`crankmodal.fem.modal.sort_and_normalise` does that
    once the factor is freed (normalising here was the memory peak of a 274k-DOF reduction).

    At 255k P2 DOF (seed 000 crank, 9 interfaces) 60 modes took 153 solves: 28.6 s with
    distributing and 23.8 s with rigid interfaces where ARPACK (``eigsh``, ``ncv`` 90, tol 1e-12)
    took 40.0 s and 32.1 s; the 154-column basis is 0.3 GB more at the peak. (A block shift-invert
    Krylov with multi-RHS solves was tried: at 60 modes it needed ~280 vectors for residuals of
    1e-5 and cost more CPU than ARPACK.)
    """
    from threadpoolctl import threadpool_limits

    from ..fem.modal import LANCZOS_TOL, complete_modes, lanczos

    rng = np.random.default_rng(20240607)  # fixed: repeatable modes

    def fresh():  # a start vector in the constrained space (G x = 0)
        return solver.solve(M @ rng.standard_normal(n))

    def run(op, k_run, start, room):
        out = lanczos(op, M, start(), k_run, LANCZOS_TOL, min(room - 1, 4 * k_run + 40),
                      fresh=start, keep_mq=False)
        if not out.converged:
            raise NumericalError(
                f"reduction: {k_run} fixed-interface modes did not converge in {out.steps} "
                f"Lanczos steps; check the mesh for loose or degenerate elements, or keep fewer "
                f"modes")
        return out

    with threadpool_limits(limits=1, user_api="blas"):
        out = run(solver.solve, k, fresh, n)
        # the second mode of an exactly repeated pair (an axisymmetric part) escapes a
        # single-vector run: look for it as [modal] does
        lam, X, _ = complete_modes(solver.solve, fresh, M, run, 1.0 / out.theta, out.vectors,
                                   out.m_vectors, 0.0, k, what="reduction")
    return lam, X


def _residual_of(KX, MX, lam, G):
    """max ‖Kx − λMx − Gᵀμ‖ / ‖Kx‖ with μ the least-squares constraint force."""
    if KX.shape[1] == 0:
        return 0.0
    Rr = KX - MX * lam
    if G.shape[0]:
        GG = (G @ G.T).toarray()
        Rr = Rr - G.T @ np.linalg.solve(GG, G @ Rr)
    return float((np.linalg.norm(Rr, axis=0) / np.linalg.norm(KX, axis=0)).max())


def _restricted(K, I):
    """``K[I][:, I]`` as a LinearOperator through the full matrix (no copy)."""
    from scipy.sparse.linalg import LinearOperator

    def mv(x):
        y = np.zeros((K.shape[0],) + x.shape[1:])
        y[I] = x
        return (K @ y)[I]

    return LinearOperator((len(I), len(I)), matvec=mv, matmat=mv, dtype=float)


def craig_bampton(model, interfaces: list[Interface], n_modes: int | None = None,
                  cutoff_hz: float | None = None, backend: str = "auto",
                  max_modes: int = 400, tol: float = 1e-6) -> CraigBamptonBasis:
    """Craig–Bampton basis of an assembled model.

    Parameters
    ----------
    model : crankmodal.fem.assembly.FEModel
    interfaces : list of Interface
        At least one.
    n_modes : int, optional
        Fixed-interface modes to keep (0: Guyan reduction).
    cutoff_hz : float, optional
        Keep every fixed-interface mode up to this frequency, Hz (instead of ``n_modes``).
    backend : str
        Factorisation backend (``auto``, ``pardiso``, ``superlu``).
    max_modes : int
        Upper limit on the modes a cut-off may bring in.
    tol : float
        Admissible eigen-residual.

    Returns
    -------
    CraigBamptonBasis

    Raises
    ------
    ParameterError
        Naming ``interfaces`` (none given), ``cutoff_hz`` (given with ``n_modes``, or neither;
        a cut-off beyond ``max_modes`` modes), ``n_modes`` (more than the interior DOFs allow)
        or ``backend``; the ``[reduction]`` stage re-raises it under its scene key.
    NumericalError
        The interior stiffness cannot be factorised (a mechanism, inverted elements).
    """
    from ..fem.assembly import rigid_body_modes
    from ..fem.modal import sort_and_normalise
    from ..fem.solvers import factorize_submatrix

    if not interfaces:
        raise ParameterError("interfaces", "at least one interface is needed")
    if (n_modes is None) == (cutoff_hz is None):
        raise ParameterError("cutoff_hz", "give exactly one of n_modes or cutoff_hz")
    from ..progress import PhaseTimings

    timings = PhaseTimings("reduction: Craig–Bampton", 5)
    t0 = time.perf_counter()
    N = model.K.shape[0]
    m6 = 6 * len(interfaces)
    S, R = rigid_map(model.points, interfaces)
    used = np.repeat(model.used, 3)
    used[S] = False
    I = np.flatnonzero(used)
    K = sp.csr_matrix(model.K)
    M = sp.csr_matrix(model.M)
    K_IS_R = (K[I][:, S] @ R).tocsc() if len(S) else None  # sparse, 6 m columns
    M_II = _restricted(M, I)  # through M: a copy of M_II was 0.3 GB at the memory peak
    drows, Gfull = distributing_rows(model.points, model.cells, interfaces)
    G = Gfull[:, I].tocsr()
    # a distributing surface may share a boundary line with a rigid one: G u = G_I u_I + G_S R q
    G_SR = np.asarray((Gfull[:, S] @ R).todense()) if len(S) else np.zeros((len(drows), m6))
    support, Rf = np.zeros(0, np.int64), None
    if not len(S):  # a floating body: split off rigid motion, support it 3-2-1
        pts = np.flatnonzero(model.used)
        support = np.searchsorted(I, support_321(model.points, pts))
        Rf = rigid_body_modes(model.points)[I]
    free = np.setdiff1d(np.arange(len(I)), support)
    timings["partition_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    try:  # K_FF (or K_II), its upper triangle only
        fac = factorize_submatrix(K, I[free], backend, positive_definite=True,
                                  label="reduction: ")
    except np.linalg.LinAlgError as exc:
        raise NumericalError(f"reduction: factorising the interior stiffness failed ({exc}); "
                             f"the interfaces may not hold the part (a mechanism), or the mesh "
                             f"has inverted elements") from None
    solver = ConstrainedSolver(fac, G, len(I), support, Rf)
    timings["factorize_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    n_free = len(I) - len(drows)
    if cutoff_hz is not None:
        k = min(20, max_modes, n_free - 2)
        while True:
            lam, X = _fixed_interface_modes(M_II, solver, len(I), k)
            f = np.sqrt(np.abs(lam)) / (2 * np.pi)
            if f.max() > cutoff_hz or k >= min(max_modes, n_free - 2):
                break
            k = min(2 * k, max_modes, n_free - 2)
        if f.max() <= cutoff_hz and k < n_free - 2:  # stopped at max_modes, not at the cut-off
            raise ParameterError("cutoff_hz", f"{k} fixed-interface modes (the most kept) reach "
                                              f"only {f.max():.6g} Hz, below the cut-off "
                                              f"{cutoff_hz:g} Hz; lower cutoff_hz or give n_modes")
        keep = f <= cutoff_hz
        lam, X = lam[keep], X[:, keep]
    elif n_modes > 0:
        if n_modes >= n_free - 1:
            raise ParameterError("n_modes", f"{n_modes} modes need a finer mesh "
                                            f"({n_free} interior DOFs)")
        lam, X = _fixed_interface_modes(M_II, solver, len(I), n_modes)
    else:
        lam, X = np.zeros(0), np.zeros((len(I), 0))
    timings["fixed_interface_modes_s"] = time.perf_counter() - t0

    # constraint modes, a few right-hand sides at a time into one array: the n × 6m dense
    # temporaries of a one-shot solve (right-hand sides, their copies for the solver) were a
    # memory peak. After the fixed-interface modes, so the Lanczos basis and these never meet.
    t0 = time.perf_counter()
    gmat = -G_SR
    gmat[np.arange(len(drows)), drows] += 1.0
    Psi = np.empty((len(I), m6))
    for j in range(0, m6, CONSTRAINT_BLOCK):
        cols = slice(j, min(j + CONSTRAINT_BLOCK, m6))
        F = (-np.asarray(K_IS_R[:, cols].todense()) if len(S)
             else np.zeros((len(I), cols.stop - cols.start)))
        Psi[:, cols] = solver.solve(F, gmat[:, cols])
    del F, gmat
    timings["constraint_modes_s"] = time.perf_counter() - t0
    backend_name = fac.name
    del solver, fac  # release the factor (the largest allocation) before the dense products
    lam, X = sort_and_normalise(lam, X, M_II)
    if np.any(lam <= 0):
        raise NumericalError("reduction: a fixed-interface mode has zero frequency: the "
                             "interfaces leave a mechanism")

    t0 = time.perf_counter()
    V = np.zeros((N, m6 + X.shape[1]))
    V[I, :m6] = Psi
    V[I, m6:] = X
    del Psi, X
    if len(S):
        V[S, :m6] = R.toarray()
    KV = K @ V
    Kr = V.T @ KV
    MV = M @ V
    Mr = V.T @ MV
    Kr, Mr = 0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T)
    res = _residual_of(KV[I, m6:], MV[I, m6:], lam, G)  # X is zero on S
    del KV, MV
    timings["reduced_matrices_s"] = time.perf_counter() - t0
    if not np.isfinite(res) or res > tol:
        raise NumericalError(f"reduction: fixed-interface eigen-residual {res:.2e} > {tol:.0e}; "
                             f"check the mesh for degenerate elements, or try backend='superlu'")
    timings.close()
    return CraigBamptonBasis(V=V, K=Kr, M=Mr, n_boundary=m6,
                             fixed_interface_hz=np.sqrt(np.abs(lam)) / (2 * np.pi),
                             interfaces=list(interfaces), n_interior=len(I), support=I[support],
                             backend=backend_name, residual=res, timings=timings)
