"""Free and supported modal analysis: shift-invert Lanczos with one sparse factorisation.

The pencil (K, M) is solved by shift-invert Lanczos (:func:`lanczos`) about a small *negative* shift σ:
``K - σM`` is then positive definite even for a free part (its rigid-body modes sit at λ = 0 > σ),
so one Cholesky/LDLᵀ serves every Lanczos step. The rigid-body motions the supports leave (6 per
connected free piece) are known in closed form: they are M-orthonormalised, their Rayleigh
quotients checked like any other pair, and deflated from the Lanczos operator, so Lanczos only
looks for elastic modes (a quarter fewer solves). A zero-frequency mode among those — a loose
piece or a mechanism the connectivity did not predict — is caught by the rigid-count check. Every returned pair is checked:
``‖Kx − λMx‖ / ‖Kx‖`` and ``|XᵀMX − I|``; poor results raise :class:`NumericalError` with advice.

The pieces live in their own modules: the result :class:`~.modes.Modes` (:mod:`.modes`), the
Lanczos iteration (:mod:`.lanczos`), the closed-form rigid-body motions (:mod:`.rigid_modes`),
the pair checks (:mod:`.modal_checks`) and the dense path (:mod:`.dense_eigen`). This module
orchestrates them (:func:`solve_modes`) and re-exports their names, which were all defined here.
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import NumericalError, ParameterError
from .assembly import NU_ILL_CONDITIONED, FEModel, mass_and_centre, rigid_body_modes
from .dense_eigen import (
    DENSE_FRACTION,
    DENSE_LIMIT_DOF,
    DENSE_MAX_DOF,
    dense_bytes,
    dense_pairs,
    dense_with_rigid,
    refine_pairs,
    use_dense,
)
from .lanczos import (
    COMPLETENESS_STEPS,
    LANCZOS_TOL,
    MAX_RESCUES,
    Lanczos,
    complete_modes,
    deflated,
    lanczos,
)
from .memory import PeakMemory
from .modal_checks import check_pairs, pair_residuals, stall_advice
from .modes import RIGID_RATIO, RIGID_REF_MODES, Modes, rigid_mask, sort_and_normalise
from .parallel import RowBlocks
from .rigid_modes import allowed_rigid_modes, expected_rigid_modes, rigid_pairs
from .supports import Support, reduce_matrix, reduction

__all__ = [
    "COMPLETENESS_STEPS", "DENSE_FRACTION", "DENSE_LIMIT_DOF", "DENSE_MAX_DOF", "LANCZOS_TOL",
    "MAX_RESCUES", "RIGID_RATIO", "RIGID_REF_MODES", "Lanczos", "Modes",
    "allowed_rigid_modes", "check_pairs", "complete_modes", "default_shift", "deflated",
    "dense_bytes", "dense_pairs", "dense_with_rigid", "expected_rigid_modes", "lanczos",
    "lanczos_pairs", "pair_residuals", "refine_pairs", "rigid_mask", "rigid_pairs",
    "solve_modes", "sort_and_normalise", "stall_advice", "use_dense",
]


def default_shift(K, M) -> float:
    """A negative shift σ (rad²/s²) well below the lowest elastic eigenvalue, scale-free."""
    d = K.diagonal() / M.diagonal()
    return -1e-8 * float(np.median(d[d > 0]))


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
        raise ParameterError("shift", f"must be < 0, got {sigma}")
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

    Raises
    ------
    ParameterError
        ``n_modes`` below 1 or above the elastic DOF, ``shift`` not negative, ``eigensolver``
        unknown, Lanczos asked for nearly every pair, ``supports`` holding every node in
        every direction, or ``backend`` unknown or not installed (the message names the argument; a stage
        re-raises it under its scene key with :class:`crankmodal.errors.scene_keys`).
    NumericalError
        The pairs fail their checks, or the rigid-body count is not the expected one.

    Examples
    --------
    A free steel bar 300 x 30 x 20 mm (P2 tetrahedra): six rigid-body modes, and the first
    bending mode within 2 % of Euler-Bernoulli's ``(4.730 / L)**2 sqrt(E I / (rho A)) / 2 pi``:

    >>> import math
    >>> import crankmodal as cm
    >>> from crankmodal.fem import testparts
    >>> bar = testparts.bar(0.3, 0.03, 0.02, divisions=(12, 2, 2), order=2)
    >>> steel = cm.material("steel")
    >>> modes = cm.solve_modes(cm.assemble(bar, steel), n_modes=4)
    >>> modes.rigid_body_modes
    6
    >>> I, A = 0.03 * 0.02**3 / 12, 0.03 * 0.02
    >>> eb = (4.730 / 0.3)**2 * math.sqrt(steel.E * I / (steel.rho * A)) / (2 * math.pi)
    >>> bool(abs(modes.frequencies_hz[0] / eb - 1) < 0.02)
    True
    """
    from ..arguments import instance
    from .assembly import FEModel

    instance("model", model, FEModel, "an FEModel (assemble)")
    if n_modes < 1:
        raise ParameterError("n_modes", f"must be >= 1, got {n_modes}")
    if shift is not None and not float(shift) < 0:
        raise ParameterError("shift", f"must be < 0, got {float(shift)}")
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
            raise ParameterError(
                "n_modes", f"{n_modes} elastic modes asked, but the part has only "
                f"{n_elastic} ({n} free DOF less {n_rigid_expected} rigid-body modes); ask for at "
                f"most {n_elastic}, or refine the mesh")
        timings["reduce_s"] = time.perf_counter() - t0

        if eigensolver not in ("auto", "lanczos", "dense"):
            raise ParameterError("eigensolver",
                                 f"must be auto, lanczos or dense; got {eigensolver!r}")
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
                raise ParameterError("eigensolver", f"Lanczos cannot find "
                                     f"{n_rigid_expected + n_modes} pairs of {n} DOF; use "
                                     f"'dense' or 'auto'")
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
