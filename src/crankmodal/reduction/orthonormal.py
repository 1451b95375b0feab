"""Orthonormalisation of a Craig–Bampton basis, rigid-body modes, and mass properties.

The Craig–Bampton coordinates (interface DOFs + fixed-interface modal amplitudes) are replaced by
the eigenvectors of the reduced pencil ``(K_cb, M_cb)``: the new coordinates are M-orthonormal and
K-diagonal, the form Adams and MotionSolve read. The six rigid-body motions lie exactly in the
span of the constraint modes (both couplings reproduce a rigid motion), with reduced coordinates
``[R_b; 0]`` (:func:`~crankmodal.reduction.interfaces.interface_rigid_fields`). They are taken
out first — translations along and rotations about the principal axes through the centre of
mass, M-normalised — and the elastic modes come from the eigen solution on their M-orthogonal
complement, so rigid modes are exactly rigid (0 Hz) and elastic ones exactly free of them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import NumericalError


@dataclass
class MassProps:
    """Rigid-body mass properties.

    Attributes
    ----------
    mass : float
        kg.
    centre : ndarray, shape (3,)
        Centre of mass, m.
    inertia : ndarray, shape (3, 3)
        Inertia tensor about the centre of mass, kg m².
    principal_moments : ndarray, shape (3,)
        Ascending, kg m².
    principal_axes : ndarray, shape (3, 3)
        Columns are the principal axes (right-handed).
    """

    mass: float
    centre: np.ndarray
    inertia: np.ndarray
    principal_moments: np.ndarray
    principal_axes: np.ndarray

    def to_dict(self) -> dict:
        return {"mass_kg": self.mass, "centre_of_mass_m": self.centre.tolist(),
                "inertia_kgm2": self.inertia.tolist(),
                "principal_moments_kgm2": self.principal_moments.tolist(),
                "principal_axes": self.principal_axes.tolist()}


def mass_props_from_rigid(Mrig: np.ndarray) -> MassProps:
    """Mass properties from ``Rᵀ M R`` of the six rigid fields about the origin (6×6)."""
    m = float(np.trace(Mrig[:3, :3]) / 3)
    C = Mrig[:3, 3:]  # ∫ρ e_i·(e_k × x): first moments S = m c
    S = np.array([C[1, 2], C[2, 0], C[0, 1]])
    c = S / m
    J = Mrig[3:, 3:] - m * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
    J = 0.5 * (J + J.T)
    w, Q = np.linalg.eigh(J)
    if np.linalg.det(Q) < 0:
        Q[:, 2] *= -1
    return MassProps(mass=m, centre=c, inertia=J, principal_moments=w, principal_axes=Q)


@dataclass
class Orthonormal:
    """Orthonormal modal coordinates of a reduced body.

    Attributes
    ----------
    W : ndarray, shape (n, n)
        Craig–Bampton coordinates = ``W`` × modal coordinates.
    eigenvalues : ndarray, shape (n,)
        ω², rad²/s² (exactly 0 for the rigid modes), ascending.
    frequencies_hz : ndarray, shape (n,)
    rigid : ndarray of bool, shape (n,)
        The first six.
    mass_props : MassProps
    rigid_defect : float
        ‖K_cb R‖ / ‖K_cb‖‖R‖ of the rigid fields (≈ 1e-15 when the basis holds rigid motion).
    """

    W: np.ndarray
    eigenvalues: np.ndarray
    frequencies_hz: np.ndarray
    rigid: np.ndarray
    mass_props: MassProps
    rigid_defect: float


def orthonormalise(K: np.ndarray, M: np.ndarray, rigid_coords: np.ndarray,
                   tol: float = 1e-8) -> Orthonormal:
    """M-orthonormal, K-diagonal modal coordinates with the rigid-body modes first.

    Parameters
    ----------
    K, M : ndarray, shape (n, n)
        Reduced (Craig–Bampton) stiffness and mass.
    rigid_coords : ndarray, shape (n, 6)
        Reduced coordinates of the rigid fields about the origin (translations x, y, z,
        rotations about x, y, z).
    tol : float
        Largest admissible strain energy of the rigid fields relative to ``‖K‖``.

    Raises
    ------
    NumericalError
        If the rigid fields are not (numerically) free of strain energy.
    """
    from scipy.linalg import eigh, null_space

    Ra = np.asarray(rigid_coords, float)
    scale = np.abs(K).max()
    Rn = Ra / np.linalg.norm(Ra, axis=0)
    defect = float(np.abs(K @ Rn).max() / scale) if scale > 0 else 0.0
    if defect > tol:
        raise NumericalError(f"reduction: the reduced basis does not hold rigid-body motion "
                             f"(strain energy {defect:.1e} of ‖K‖); check the interfaces")
    mp = mass_props_from_rigid(Ra.T @ M @ Ra)
    # rigid modes: translations along and rotations about the principal axes through the COM
    c, Q = mp.centre, mp.principal_axes
    B = np.zeros((6, 6))
    B[:3, :3] = Q
    B[3:, 3:] = Q
    Rr = Ra @ (_shift(c) @ B)
    Rr = Rr / np.sqrt(np.einsum("ij,ij->j", Rr, M @ Rr))
    # the M-orthogonal complement of the rigid modes
    Z = null_space(Rr.T @ M)
    lam, Y = eigh(Z.T @ K @ Z, Z.T @ M @ Z)
    E = Z @ Y
    W = np.hstack([Rr, E])
    # one Gram–Schmidt sweep in the M inner product against round-off
    G = W.T @ M @ W
    L = np.linalg.cholesky(0.5 * (G + G.T))
    W = np.linalg.solve(L, W.T).T
    ev = np.concatenate([np.zeros(6), np.maximum(lam, 0.0)])
    if np.any(lam <= 0):
        raise NumericalError("reduction: an elastic mode of the reduced body has zero "
                             "frequency; the basis may be rank-deficient (duplicate interfaces?)")
    rigid = np.zeros(len(ev), bool)
    rigid[:6] = True
    return Orthonormal(W=W, eigenvalues=ev, frequencies_hz=np.sqrt(ev) / (2 * np.pi),
                       rigid=rigid, mass_props=mp, rigid_defect=defect)


def _shift(c: np.ndarray) -> np.ndarray:
    """6×6 map from rigid motion about a point ``c`` to rigid motion about the origin."""
    T = np.eye(6)
    # u = t + θ × (x − c) = (t − θ × c) + θ × x  →  t_origin = t − θ × c = t + c × θ
    T[:3, 3:] = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
    return T
