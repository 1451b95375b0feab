"""Stiffness and consistent mass of a Part on P1/P2 tetrahedra.

scikit-fem supplies the mesh (isoparametric for curved ``tetra10`` meshes), the element, the
quadrature and the mapped shape-function gradients; the 3×3 nodal blocks of the isotropic
elasticity form and of the mass form are then formed with ``einsum`` over all elements at once
and summed into a block-sparse matrix with one ``bincount`` per block entry. This is what
``skfem.asm(linear_elasticity(...))`` computes, without its loop over the 900 local P2 entry
pairs and with the quadrature the integrand needs (stiffness: degree 2(p-1), mass: degree 2p).

Degrees of freedom are node-interleaved on the Part's own mesh points:
``dof = 3 * point + component``, so regions (point indices) map to DOFs without a lookup.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import GeometryError, warn
from .memory import release_free_heap


@dataclass
class FEModel:
    """An assembled linear-elastic model.

    Attributes
    ----------
    points : ndarray, shape (n_points, 3)
        Mesh points, m (the Part's, unchanged).
    cells : ndarray of int, shape (n_elements, 4 or 10)
        Connectivity into ``points`` in meshio order.
    order : int
        1 or 2.
    K, M : scipy.sparse.csr_matrix, shape (3 n_points, 3 n_points)
        Stiffness (N/m) and consistent mass (kg); rows of points no element uses are empty.
    material : Material
    used : ndarray of bool, shape (n_points,)
        Points that belong to at least one element.
    timings : dict
        Wall time per phase, s.
    """

    points: np.ndarray
    cells: np.ndarray
    order: int
    K: sp.csr_matrix
    M: sp.csr_matrix
    material: object
    used: np.ndarray
    timings: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)

    @property
    def n_dofs(self) -> int:
        """Degrees of freedom of the points in use (3 per point)."""
        return int(3 * self.used.sum())

    @property
    def n_elements(self) -> int:
        return len(self.cells)


#: Poisson's ratio from which K's condition number (∝ bulk/shear modulus) is worth a warning
NU_ILL_CONDITIONED = 0.49999


def bulk_to_shear(nu: float) -> float:
    """Bulk over shear modulus, ``K/G = 2(1 + ν) / (3(1 − 2ν))``."""
    return 2.0 * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu)) if nu < 0.5 else float("inf")


def model_warnings(points: np.ndarray, order: int, nu: float) -> list[str]:
    """Warnings about a model before it is solved.

    - P1 tetrahedra lock volumetrically as ν → 0.5: stiffness and frequencies come out too high.
    - P2 does not lock, but K's conditioning grows as K/G ∝ 1/(1 − 2ν): from ν = 0.49999
      (K/G = 5e4) it is worth a word. The modes of a bar still pass the residual checks at
      ν = 0.499999; from ν = 0.4999999 they fail, with advice.
    - Points are taken in metres: a part larger than 20 m or smaller than 1 mm was most likely
      given in millimetres (or microns), which scales every frequency by 1000.
    """
    out = []
    if order == 1 and nu >= 0.45:
        out.append(f"nu = {nu:g} with P1 (linear) tetrahedra: volumetric locking makes the model "
                   f"too stiff; use element_order = 2")
    elif nu >= NU_ILL_CONDITIONED:
        ratio = bulk_to_shear(nu)
        out.append(f"nu = {nu:.10g}: the bulk modulus is {ratio:.1e} times the shear modulus, and "
                   f"K's condition number grows by that factor (~{np.log10(ratio):.0f} digits); "
                   f"the eigen-residual checks will say whether the modes are still accurate "
                   f"(a bar passes to nu = 0.499999; no mixed u-p elements)")
    size = float(np.ptp(points, axis=0).max()) if len(points) else 0.0
    if size > 20.0:
        out.append(f"part is {size:.4g} m across: points must be in metres (mm input? scale by "
                   f"1e-3)")
    elif 0 < size < 1e-3:
        out.append(f"part is {size:.4g} m across: points must be in metres")
    return out


def field_values(f) -> np.ndarray:
    """Values of a scikit-fem DiscreteField (``.value`` is deprecated in scikit-fem 12)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return np.asarray(f.value)


def stiffness_intorder(order: int) -> int:
    """Quadrature degree integrating ∇N_a·∇N_b exactly on straight tets: 2 (p - 1), at least 1."""
    return max(1, 2 * (order - 1))


def mass_intorder(order: int) -> int:
    """Quadrature degree integrating N_a N_b exactly on straight tets: 2 p."""
    return 2 * order


def skfem_mesh(mesh):
    """scikit-fem mesh and scalar Lagrange element for a meshio tetra/tetra10 mesh.

    Goes through :func:`skfem.io.meshio.from_meshio`, which knows meshio's (VTK) node order of
    ``tetra10``; hand-built P2 connectivity from gmsh's own order gives zero Jacobians.
    """
    import meshio
    from skfem import ElementTetP1, ElementTetP2
    from skfem.io.meshio import from_meshio

    block = _volume_block(mesh)
    m = from_meshio(meshio.Mesh(mesh.points, [(block.type, block.data)]))
    element = ElementTetP2() if block.type == "tetra10" else ElementTetP1()
    return m, element


def _volume_block(mesh):
    blocks = [c for c in mesh.cells if c.type in ("tetra", "tetra10")]
    if len(blocks) != 1:
        kinds = ", ".join(c.type for c in mesh.cells) or "none"
        raise GeometryError(
            f"mesh: need exactly one tetra or tetra10 cell block, got {kinds}")
    return blocks[0]


def local_to_cells(basis, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Column of ``cells`` holding each scikit-fem local basis function, per element.

    Matched by coordinates, so it does not depend on how scikit-fem orders or renumbers nodes.
    Returns an array of point indices, shape (n_local, n_elements).
    """
    doflocs = basis.doflocs.T  # (n_dofs, 3)
    edofs = basis.element_dofs  # (n_local, n_elements)
    xc = points[cells]  # (nel, nloc, 3)
    scale = np.ptp(points, axis=0).max()
    out = np.empty_like(edofs)
    for k in range(edofs.shape[0]):
        d = np.linalg.norm(xc - doflocs[edofs[k]][:, None, :], axis=2)  # (nel, nloc)
        j = d.argmin(axis=1)
        if d[np.arange(len(j)), j].max() > 1e-9 * scale:
            raise GeometryError("mesh: element nodes do not match scikit-fem's; "
                                "is the tetra10 node order meshio's?")
        out[k] = cells[np.arange(len(j)), j]
    return out


def _block_pattern(nodes: np.ndarray, n_points: int):
    """Node-pair pattern of all element blocks: CSR index arrays and the slot of every pair."""
    nloc, nel = nodes.shape
    rows = np.repeat(nodes, nloc, axis=0).ravel()  # pair (a, b): a major
    cols = np.tile(nodes, (nloc, 1)).ravel()
    key = rows.astype(np.int64) * n_points + cols
    uniq, slot = np.unique(key, return_inverse=True)
    r = (uniq // n_points).astype(np.int64)
    indptr = np.zeros(n_points + 1, np.int64)
    indptr[1:] = np.cumsum(np.bincount(r, minlength=n_points))
    return indptr, (uniq % n_points).astype(np.int64), slot.reshape(nloc * nloc, nel)


def assemble(part, material, timings: dict | None = None) -> FEModel:
    """Stiffness and consistent mass of a Part.

    Parameters
    ----------
    part : crankmodal.part.Part
        Mesh in metres, ``tetra`` (P1) or ``tetra10`` (P2).
    material : Material
        E (Pa), ν, ρ (kg/m³).
    timings : dict, optional
        Filled with ``mesh_s``, ``stiffness_s``, ``mass_s``.

    Returns
    -------
    FEModel
    """
    from ..arguments import instance
    from ..part import Part
    from .materials import Material

    instance("part", part, Part, "a Part (build_part, import_mesh)")
    instance("material", material, Material, "a Material (material(name))")
    import time

    from skfem import CellBasis

    timings = {} if timings is None else timings
    t0 = time.perf_counter()
    block = _volume_block(part.mesh)
    points = np.asarray(part.mesh.points, float)[:, :3]
    cells = np.asarray(block.data, np.int64)
    order = 2 if block.type == "tetra10" else 1
    m, element = skfem_mesh(part.mesh)
    basis_k = CellBasis(m, element, intorder=stiffness_intorder(order))
    nodes = local_to_cells(basis_k, cells, points)
    if np.any(basis_k.dx <= 0):
        raise GeometryError("mesh: elements with non-positive Jacobian (inverted or degenerate)")
    n = len(points)
    indptr, indices, slot = _block_pattern(nodes, n)
    nnz = len(indices)
    timings["mesh_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    lam, mu = material.lame
    # G[e, q, a, i] = dN_a/dx_i, weighted below by dx = w_q |det J|.
    G = np.stack([basis_k.basis[a][0].grad for a in range(len(nodes))], axis=0)  # (a, i, e, q)
    G = np.ascontiguousarray(G.transpose(2, 3, 0, 1))  # (e, q, a, i)
    Gw = G * basis_k.dx[:, :, None, None]
    blocks = np.zeros((nnz, 3, 3))
    nloc = len(nodes)
    # Process in element chunks to bound memory at large meshes.
    chunk = max(1, int(2.0e7 // (nloc * nloc * 9)))
    for s in range(0, len(cells), chunk):
        e = slice(s, s + chunk)
        A = np.einsum("eqai,eqbj->eabij", Gw[e], G[e], optimize=True)  # ∫ ∂_i N_a ∂_j N_b
        tr = np.einsum("eabii->eab", A)
        Ke = lam * A + mu * A.transpose(0, 1, 2, 4, 3)
        Ke[..., 0, 0] += mu * tr
        Ke[..., 1, 1] += mu * tr
        Ke[..., 2, 2] += mu * tr
        sl = slot[:, e].T.ravel()  # (e, a*b)
        Ke = Ke.reshape(-1, 3, 3)
        for i in range(3):
            for j in range(3):
                blocks[:, i, j] += np.bincount(sl, weights=Ke[:, i, j], minlength=nnz)
    K = sp.bsr_matrix((blocks, indices, indptr), shape=(3 * n, 3 * n)).tocsr()
    del blocks  # K is symmetric by construction (PARDISO reads only its upper triangle)
    timings["stiffness_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    basis_m = CellBasis(m, element, intorder=mass_intorder(order))
    if len(basis_m.basis) != nloc:
        raise AssertionError("scalar basis expected")
    nodes_m = local_to_cells(basis_m, cells, points) if order == 2 else nodes
    if not np.array_equal(nodes_m, nodes):
        raise AssertionError("basis orderings differ between quadrature rules")
    Nv = np.stack([field_values(basis_m.basis[a][0]) for a in range(nloc)], axis=1)  # (e, a, q)
    Me = material.rho * np.einsum("eaq,ebq,eq->eab", Nv, Nv, basis_m.dx, optimize=True)
    ms = np.bincount(slot.T.ravel(), weights=Me.reshape(-1), minlength=nnz)
    Ms = sp.csr_matrix((ms, indices, indptr), shape=(n, n))
    M = sp.kron(Ms, sp.identity(3, format="csr"), format="csr")
    timings["mass_s"] = time.perf_counter() - t0

    used = np.zeros(n, bool)
    used[cells.ravel()] = True
    notes = model_warnings(points[used], order, material.nu)
    for text in notes:
        warn(text)
    release_free_heap()  # the element arrays just freed would otherwise stay resident
    return FEModel(points=points, cells=cells, order=order, K=K, M=M, material=material,
                   used=used, timings=timings, warnings=notes)


def rigid_body_modes(points: np.ndarray, centre=None) -> np.ndarray:
    """The six rigid-body displacement fields of a point cloud.

    Columns: translations x, y, z, then rotations about x, y, z through ``centre`` (default:
    origin). Shape (3 n_points, 6), node-interleaved like :class:`FEModel`.
    """
    x = np.asarray(points, float) - (0.0 if centre is None else np.asarray(centre, float))
    n = len(x)
    R = np.zeros((n, 3, 6))
    R[:, 0, 0] = R[:, 1, 1] = R[:, 2, 2] = 1.0
    # rotation θ e_k: u = e_k × x
    R[:, 1, 3], R[:, 2, 3] = -x[:, 2], x[:, 1]
    R[:, 0, 4], R[:, 2, 4] = x[:, 2], -x[:, 0]
    R[:, 0, 5], R[:, 1, 5] = -x[:, 1], x[:, 0]
    return R.reshape(3 * n, 6)


def mass_and_centre(model: FEModel) -> tuple[float, np.ndarray]:
    """Mass (kg) and centre of mass (m) from M: ``1ᵀ M_s 1`` and ``1ᵀ M_s x / mass``.

    ``M_s`` is the scalar mass matrix (the x-component rows and columns of M).
    """
    Mx = model.M[0::3, 0::3]
    ones = np.ones(len(model.points))
    mass = float(ones @ (Mx @ ones))
    # first moments: Σ_ab M_ab x_b over the x-component rows
    first = np.array([ones @ (Mx @ model.points[:, k]) for k in range(3)])
    return mass, first / mass


def mass_properties(model: FEModel) -> dict:
    """Mass (kg), centre of mass (m) and inertia tensor about it (kg m²) from M.

    ``Rᵀ M R`` of the rigid-body fields is exact for the consistent mass matrix, so this is an
    independent check of M against the CAD's mass properties.

    Parameters
    ----------
    model : FEModel

    Returns
    -------
    dict
        ``mass`` (kg), ``centre`` (m, shape (3,)), ``inertia`` (kg m², (3, 3) about the centre).

    Examples
    --------
    A 300 x 30 x 20 mm steel bar weighs rho V = 1.413 kg:

    >>> import crankmodal as cm
    >>> from crankmodal.fem import testparts
    >>> bar = testparts.bar(0.3, 0.03, 0.02, divisions=(6, 2, 2), order=2)
    >>> mp = cm.mass_properties(cm.assemble(bar, cm.material("steel")))
    >>> print(f"{mp['mass']:.4f} kg")
    1.4130 kg
    """
    from ..arguments import instance

    instance("model", model, FEModel, "an FEModel (assemble)")
    mass, c = mass_and_centre(model)
    Rc = rigid_body_modes(model.points, c)[:, 3:]
    inertia = Rc.T @ (model.M @ Rc)
    return {"mass": mass, "centre": c, "inertia": inertia}
