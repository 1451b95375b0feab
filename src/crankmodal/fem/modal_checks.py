"""Checks of computed eigenpairs: the pencil residuals ``‖Kx − λMx‖ / ‖Kx‖``
(:func:`pair_residuals`), M-orthogonality (:func:`check_pairs`), and what to change when they
fail (:func:`stall_advice`)."""

from __future__ import annotations

import numpy as np

from ..errors import NumericalError
from .assembly import NU_ILL_CONDITIONED, FEModel, bulk_to_shear
from .modes import rigid_mask


def stall_advice(model: FEModel) -> str:
    """What to change when the eigenpairs cannot be made accurate: the material or the mesh."""
    nu = float(model.material.nu)
    if nu >= NU_ILL_CONDITIONED:
        return (f"nu = {nu:.10g} makes the bulk modulus {bulk_to_shear(nu):.1e} times the shear "
                f"modulus; use nu <= 0.4999 (crankmodal has no mixed u-p elements)")
    return ("look for flat or needle elements (geometry.optimize = true, a larger "
            "geometry.refine) or extreme size ratios, or loosen modal.tol")


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
