"""Linear static strength: supported solve, nodal stresses, von Mises, safety factors.

Stresses are evaluated at every node of every element (for P2 at its ten nodes, from the
quadratic displacement field, so they vary linearly inside the element) and averaged over the
elements sharing the node. Von Mises and principal stresses come from the averaged tensors.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .assembly import FEModel, skfem_mesh
from .loads import Load, as_vector
from .supports import Support, reduce_matrix, reduction


@dataclass
class StaticResult:
    """A static solution.

    Attributes
    ----------
    displacement : ndarray, shape (n_points, 3)
        m.
    stress : ndarray, shape (n_points, 3, 3)
        Nodal-averaged Cauchy stress, Pa (zero at unused points).
    von_mises : ndarray, shape (n_points,)
        Pa.
    principal : ndarray, shape (n_points, 3)
        Principal stresses, descending, Pa.
    max_von_mises : float
        Pa.
    max_location : ndarray, shape (3,)
        m.
    max_displacement : float
        m.
    safety_factor_yield, safety_factor_ultimate : float or None
        Strength / max von Mises.
    reaction : ndarray, shape (3,)
        Sum of the support reactions, N (balances the applied load).
    timings : dict
    """

    displacement: np.ndarray
    stress: np.ndarray
    von_mises: np.ndarray
    principal: np.ndarray
    max_von_mises: float
    max_location: np.ndarray
    max_displacement: float
    safety_factor_yield: float | None
    safety_factor_ultimate: float | None
    reaction: np.ndarray
    n_dofs: int
    timings: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "max_von_mises_pa": self.max_von_mises,
            "max_von_mises_location_m": self.max_location,
            "max_principal_pa": float(self.principal[:, 0].max()),
            "min_principal_pa": float(self.principal[:, 2].min()),
            "max_displacement_m": self.max_displacement,
            "safety_factor_yield": self.safety_factor_yield,
            "safety_factor_ultimate": self.safety_factor_ultimate,
            "reaction_n": self.reaction,
            "n_dofs": self.n_dofs,
            "timings_s": self.timings,
        }


def nodal_stress(model: FEModel, u: np.ndarray, mesh) -> np.ndarray:
    """Cauchy stress averaged at nodes, shape (n_points, 3, 3), Pa.

    Parameters
    ----------
    model : FEModel
    u : ndarray, shape (3 n_points,)
        Displacements, m.
    mesh : meshio.Mesh
        The part's mesh (for the scikit-fem basis).
    """
    from skfem import CellBasis

    from .assembly import local_to_cells

    m, element = skfem_mesh(mesh)
    X = np.asarray(element.doflocs, float).T  # reference nodes as "quadrature points"
    basis = CellBasis(m, element, quadrature=(X, np.ones(X.shape[1])))
    nodes = local_to_cells(basis, model.cells, model.points)  # (a, e)
    nloc = len(nodes)
    G = np.stack([basis.basis[a][0].grad for a in range(nloc)])  # (a, i, e, q)
    U = np.asarray(u).reshape(-1, 3)[nodes]  # (a, e, j)
    H = np.einsum("aieq,aej->eqji", G, U)  # ∂u_j/∂x_i -> H[e, q, j, i]
    eps = 0.5 * (H + H.transpose(0, 1, 3, 2))
    lam, mu = model.material.lame
    tr = np.einsum("eqii->eq", eps)
    sig = 2 * mu * eps
    for i in range(3):
        sig[:, :, i, i] += lam * tr
    # quadrature point q is the position of local node q
    owner = nodes.T  # (e, q): node at which each value sits
    n = len(model.points)
    count = np.bincount(owner.ravel(), minlength=n).astype(float)
    out = np.zeros((n, 3, 3))
    for i in range(3):
        for j in range(i, 3):
            s = np.bincount(owner.ravel(), weights=sig[:, :, i, j].ravel(), minlength=n)
            out[:, i, j] = out[:, j, i] = s / np.maximum(count, 1)
    return out


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of tensors (..., 3, 3), Pa."""
    s = stress
    dev = s - np.einsum("...ii->...", s)[..., None, None] / 3 * np.eye(3)
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", dev, dev))


def solve_static(model: FEModel, mesh, load: Load | list | np.ndarray, supports: list[Support],
                 backend: str = "auto") -> StaticResult:
    """Displacements and stresses under a load.

    Parameters
    ----------
    model : FEModel
    mesh : meshio.Mesh
        The part's mesh.
    load : Load, list of Load, or ndarray of shape (3 n_points,)
        Nodal forces, N (a list is summed).
    supports : list of Support
        Must remove every rigid-body mode.
    backend : str

    Raises
    ------
    ParameterError
        Naming ``supports`` if they leave a mechanism (with how many rigid-body modes remain),
        hold every node in every direction or are not :class:`Support` objects, ``load`` if it
        is not a load of this mesh, ``backend`` if it is unknown or not installed.
    """
    from ..progress import PhaseTimings
    from .modal import expected_rigid_modes
    from .solvers import factorize

    load = as_vector(load, len(model.points))
    supports = list(supports)
    for i, s in enumerate(supports):
        if not isinstance(s, Support):
            raise ParameterError(f"supports[{i}]", f"must be a Support (Support.region, "
                                                   f"Support.box or select_supports), got "
                                                   f"{type(s).__name__}")
    timings = PhaseTimings("static", 3)
    t0 = time.perf_counter()
    T = reduction(model.points, model.used, supports)
    free_rigid = expected_rigid_modes(model, T)
    if free_rigid:
        raise ParameterError("supports", f"leave the part a mechanism with {free_rigid} "
                                         f"rigid-body mode(s); fix more components (e.g. fix = "
                                         f"'xyz' on one region) before a static solve")
    K = reduce_matrix(model.K, T)
    timings["reduce_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    q = factorize(K, backend, positive_definite=True, label="static: ").solve(T.T @ load)
    u = T @ q
    timings["solve_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    residual = model.K @ u - load
    reaction = residual.reshape(-1, 3).sum(axis=0)  # K u - f is non-zero only at supports
    sig = nodal_stress(model, u, mesh)
    vm = von_mises(sig)
    vm[~model.used] = 0.0
    principal = np.linalg.eigvalsh(sig)[:, ::-1]
    i = int(np.argmax(vm))
    smax = float(vm[i])
    mat = model.material
    sf = lambda s: (float(s / smax) if s and smax > 0 else None)
    disp = u.reshape(-1, 3)
    timings["stress_s"] = time.perf_counter() - t0
    return StaticResult(displacement=disp, stress=sig, von_mises=vm, principal=principal,
                        max_von_mises=smax, max_location=model.points[i],
                        max_displacement=float(np.linalg.norm(disp, axis=1).max()),
                        safety_factor_yield=sf(mat.yield_strength),
                        safety_factor_ultimate=sf(mat.ultimate_strength),
                        reaction=reaction, n_dofs=int(K.shape[0]), timings=dict(timings))
