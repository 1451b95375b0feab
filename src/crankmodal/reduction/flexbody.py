"""The flexible body a dynamics solver needs (and, optionally, its mesh and mode shapes).

A :class:`FlexibleBody` holds, in orthonormal modal coordinates ``ξ`` (rigid modes first):

- reduced mass (identity) and stiffness (``diag(ω²)``), and the Craig–Bampton matrices with the
  map ``W`` between the two coordinate sets;
- the interface map: ``q_r = Φ_r ξ`` gives the 6 DOFs (m, rad) of interface node ``r`` — constant
  matrices, so joint and bearing forces act on ``ξ`` through ``Φ_rᵀ``;
- rigid-body mass properties;
- Shabana's inertia invariants of the elastic modes for the floating frame of reference;
- optionally the mesh (points and tetra/tetra10 cells) and every mode shape on its nodes, for
  looking at the modes (a VTU) and for exporting the body to another multibody code
  (:mod:`crankmodal.reduction.export`).

Invariants (Shabana, *Dynamics of Multibody Systems*; the nine of an Adams MNF), for a body of
density ρ with undeformed positions ``x`` and elastic mode shapes ``φ_a`` (columns of ``Φ``), in
the part's coordinate frame, integrals over the volume with the consistent mass
(``∫ρ f g dV = fᵀ M_s g`` for FE fields, exact)::

    I1 = ∫ρ dV                         (scalar, kg)
    I2 = ∫ρ x dV                       (3,)        first moment, kg m
    I3 = ∫ρ Φ dV                       (3, n)      translation coupling
    I4 = ∫ρ x̃ Φ dV                     (3, n)      rotation coupling (x × φ_a)
    I5 = ∫ρ φ̃_a φ_b dV                 (3, n, n)   [:, a, b] = ∫ρ φ_a × φ_b
    I6 = ∫ρ Φᵀ Φ dV                    (n, n)      generalised mass (identity)
    I7 = ∫ρ x̃ᵀ x̃ dV                    (3, 3)      inertia tensor about the frame origin
    I8 = ∫ρ x̃ᵀ φ̃_a dV                  (3, 3, n)
    I9 = ∫ρ φ̃_aᵀ φ̃_b dV                (3, 3, n, n)

(``ã`` is the cross-product matrix, ``ã b = a × b``.) With free-free orthonormalised modes
``I3 = 0`` and ``I4 = 0``: the elastic modes satisfy the mean-axis (Tisserand) conditions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

_EPS = np.zeros((3, 3, 3))
_EPS[0, 1, 2] = _EPS[1, 2, 0] = _EPS[2, 0, 1] = 1.0
_EPS[0, 2, 1] = _EPS[2, 1, 0] = _EPS[1, 0, 2] = -1.0


@dataclass
class FlexibleBody:
    """A reduced flexible body (SI units).

    Attributes
    ----------
    name : str
    frequencies_hz : ndarray, shape (n,)
        Of the orthonormal modes; 0 for the six rigid ones (first).
    stiffness : ndarray, shape (n, n)
        ``diag(ω²)``, 1/s² (per unit modal mass).
    mass : ndarray, shape (n, n)
        Identity (kg per unit modal coordinate²).
    rigid : ndarray of bool, shape (n,)
    interface_names, interface_kinds : list of str
    interface_centres : ndarray, shape (m, 3)
        m.
    interface_axes : ndarray, shape (m, 3)
        Unit bore axes (NaN for a non-cylindrical region).
    interface_map : ndarray, shape (m, 6, n)
        ``q_r = interface_map[r] @ ξ``: translations (m) and rotations (rad) of interface node r.
    cb_stiffness, cb_mass : ndarray, shape (n, n)
        Craig–Bampton matrices (coordinates: 6 per interface, then fixed-interface modes).
    cb_to_modal : ndarray, shape (n, n)
        ``W``: Craig–Bampton coordinates = ``W ξ``.
    n_fixed_interface_modes : int
    fixed_interface_hz : ndarray
    mass_kg : float
    centre_of_mass : ndarray, shape (3,)
        m.
    inertia : ndarray, shape (3, 3)
        About the centre of mass, kg m².
    invariants : dict of str to ndarray
        ``I1`` … ``I9`` of the elastic modes (see the module docstring).
    n_full_dofs : int
    stress_modes : ndarray, shape (n_points, 6, n) or None
        Nodal stresses per unit modal coordinate, Pa (Voigt order xx, yy, zz, yz, xz, xy).
    stress_points : ndarray, shape (n_points, 3) or None
        Where those stresses sit, m.
    mesh_points : ndarray, shape (n_points, 3) or None
        The part's mesh points (undeformed, part frame), m.
    mesh_cells : ndarray of int, shape (n_elements, 4 or 10) or None
        Connectivity into ``mesh_points`` in meshio order.
    mesh_cell_type : str or None
        ``tetra`` or ``tetra10``.
    mode_shapes : ndarray, shape (n_points, 3, n) or None
        Nodal displacement (m) per unit modal coordinate ``ξ`` of every orthonormal mode (rigid
        first): ``u = mode_shapes @ ξ``; M-orthonormal against the FE mass matrix, stored as
        float32.
    interface_nodes : list of ndarray of int or None
        Per interface, the mesh points of its surface, sorted (with the mesh only).
    interface_weights : list of ndarray or None
        Per interface, ``∫_Γ N_a dA`` of each of those points, m² (the area each node carries;
        0 at the corners of P2 triangles): weights for a distributing (RBE3-like) coupling.
    info : dict
        Provenance (part, material, coupling, timings).
    """

    name: str
    frequencies_hz: np.ndarray
    stiffness: np.ndarray
    mass: np.ndarray
    rigid: np.ndarray
    interface_names: list
    interface_kinds: list
    interface_centres: np.ndarray
    interface_axes: np.ndarray
    interface_map: np.ndarray
    cb_stiffness: np.ndarray
    cb_mass: np.ndarray
    cb_to_modal: np.ndarray
    n_fixed_interface_modes: int
    fixed_interface_hz: np.ndarray
    mass_kg: float
    centre_of_mass: np.ndarray
    inertia: np.ndarray
    invariants: dict
    n_full_dofs: int
    stress_modes: np.ndarray | None = None
    stress_points: np.ndarray | None = None
    info: dict = field(default_factory=dict)
    mesh_points: np.ndarray | None = None
    mesh_cells: np.ndarray | None = None
    mesh_cell_type: str | None = None
    mode_shapes: np.ndarray | None = None
    interface_nodes: list | None = None
    interface_weights: list | None = None

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)

    @property
    def elastic_frequencies_hz(self) -> np.ndarray:
        return self.frequencies_hz[~self.rigid]

    @property
    def has_mesh(self) -> bool:
        """Whether the body carries its mesh and the mode shapes on it."""
        return self.mode_shapes is not None and self.mesh_points is not None

    def to_dict(self) -> dict:
        """JSON-able summary (no mode-sized arrays beyond the frequency list)."""
        return {
            "name": self.name,
            "n_modes": self.n_modes,
            "n_rigid": int(self.rigid.sum()),
            "n_fixed_interface_modes": self.n_fixed_interface_modes,
            "n_full_dofs": self.n_full_dofs,
            "elastic_frequencies_hz": self.elastic_frequencies_hz.tolist(),
            "interfaces": [{"name": n, "kind": k, "centre_m": c.tolist()} for n, k, c in
                           zip(self.interface_names, self.interface_kinds,
                               self.interface_centres)],
            "mass_kg": self.mass_kg,
            "centre_of_mass_m": self.centre_of_mass.tolist(),
            "inertia_kgm2": self.inertia.tolist(),
            "has_stress_modes": self.stress_modes is not None,
            "has_mode_shapes": self.has_mesh,
        }


def inertia_invariants(points: np.ndarray, Ms, shapes: np.ndarray) -> dict:
    """Shabana's nine inertia invariants of mode shapes.

    Parameters
    ----------
    points : ndarray, shape (n_points, 3)
        Undeformed positions, m.
    Ms : sparse matrix, shape (n_points, n_points)
        Scalar consistent mass matrix (the full one is ``Ms ⊗ I₃``), kg.
    shapes : ndarray, shape (3 n_points, n)
        Mode shapes, node-interleaved.

    Returns
    -------
    dict
        ``I1`` … ``I9`` with the shapes of the module docstring.
    """
    n = shapes.shape[1]
    P = shapes.reshape(len(points), 3, n)
    ones = np.ones(len(points))
    Ms1 = Ms @ ones
    MX = Ms @ points  # (p, 3)
    MP = np.stack([Ms @ P[:, j, :] for j in range(3)], axis=1)  # (p, 3, n)
    I1 = float(ones @ Ms1)
    I2 = points.T @ Ms1
    I3 = np.einsum("p,pjn->jn", ones, MP)
    XP = np.einsum("pl,pkn->lkn", points, MP)  # ∫ρ x_l φ_k
    I4 = np.einsum("ilk,lkn->in", _EPS, XP)
    PP = np.einsum("pla,pkb->lkab", P, MP)  # ∫ρ φ_a,l φ_b,k
    I5 = np.einsum("ilk,lkab->iab", _EPS, PP)
    I6 = np.einsum("llab->ab", PP)
    XX = points.T @ MX
    I7 = np.trace(XX) * np.eye(3) - XX
    xdotphi = np.einsum("lln->n", XP)
    I8 = np.einsum("ij,n->ijn", np.eye(3), xdotphi) - XP.transpose(1, 0, 2)  # δ_ij x·φ − φ_i x_j
    # I9[i, j, a, b] = δ_ij ∫φ_a·φ_b − ∫φ_b,i φ_a,j  with  PP[l, k, a, b] = ∫φ_a,l φ_b,k
    I9 = np.einsum("ij,ab->ijab", np.eye(3), I6) - np.einsum("jiab->ijab", PP)
    return {"I1": I1, "I2": I2, "I3": I3, "I4": I4, "I5": I5, "I6": I6, "I7": I7, "I8": I8,
            "I9": I9}


def flexible_body(model, cb, ortho, name: str = "body", stress_modes=None,
                  info: dict | None = None, mode_shapes: bool = False,
                  shape_dtype=np.float32) -> FlexibleBody:
    """Assemble the :class:`FlexibleBody` of a Craig–Bampton basis and its orthonormalisation.

    Parameters
    ----------
    model : FEModel
    cb : CraigBamptonBasis
    ortho : Orthonormal
    name : str
    stress_modes : ndarray, shape (n_points, 6, n), optional
        From :func:`crankmodal.reduction.stress_modes.stress_modes` of ``cb.V @ ortho.W``.
    info : dict, optional
    mode_shapes : bool
        Store the mesh (``model.points``, ``model.cells``) and every orthonormal mode shape
        ``cb.V @ ortho.W`` on its nodes.
    shape_dtype : numpy dtype
        Storage type of the mode shapes.
    """
    W = ortho.W
    n = W.shape[1]
    m = len(cb.interfaces)
    full = cb.V @ W if mode_shapes else None  # every mode on the mesh, once
    shapes = full[:, ~ortho.rigid] if mode_shapes else cb.V @ W[:, ~ortho.rigid]
    Ms = model.M[0::3, 0::3]
    inv = inertia_invariants(model.points, Ms, shapes)
    axes = np.array([i.axis if i.axis is not None else np.full(3, np.nan) for i in cb.interfaces])
    K = W.T @ cb.K @ W
    Mm = W.T @ cb.M @ W
    mp = ortho.mass_props
    areas = _interface_areas(model, cb.interfaces) if mode_shapes else None
    return FlexibleBody(
        name=name, frequencies_hz=ortho.frequencies_hz, stiffness=np.diag(ortho.eigenvalues),
        mass=np.eye(n), rigid=ortho.rigid,
        interface_names=[i.name for i in cb.interfaces],
        interface_kinds=[i.kind for i in cb.interfaces],
        interface_centres=np.array([i.centre for i in cb.interfaces]), interface_axes=axes,
        interface_map=W[:6 * m].reshape(m, 6, n), cb_stiffness=cb.K, cb_mass=cb.M,
        cb_to_modal=W, n_fixed_interface_modes=cb.n_fixed_modes,
        fixed_interface_hz=cb.fixed_interface_hz, mass_kg=mp.mass, centre_of_mass=mp.centre,
        inertia=mp.inertia, invariants=inv, n_full_dofs=int(model.n_dofs),
        stress_modes=stress_modes,
        stress_points=None if stress_modes is None else model.points,
        mesh_points=np.asarray(model.points, float) if mode_shapes else None,
        mesh_cells=np.asarray(model.cells) if mode_shapes else None,
        mesh_cell_type=("tetra10" if model.order == 2 else "tetra") if mode_shapes else None,
        mode_shapes=(full.reshape(len(model.points), 3, n).astype(shape_dtype)
                     if mode_shapes else None),
        interface_nodes=[a for a, _ in areas] if mode_shapes else None,
        interface_weights=[w for _, w in areas] if mode_shapes else None,
        info={**(info or {}), "k_modal_offdiag": float(np.abs(K - np.diag(np.diag(K))).max()
                                                       / max(np.abs(np.diag(K)).max(), 1e-300)),
              "m_orthonormality": float(np.abs(Mm - np.eye(n)).max())})


def _interface_areas(model, interfaces) -> list:
    """Per interface: (sorted surface nodes, ``∫_Γ N_a dA`` of each, m²)."""
    from .interfaces import surface_mass

    out = []
    for i in interfaces:
        nodes, Ms = surface_mass(model.points, i.facets, model.cells)
        out.append((np.asarray(nodes, int), np.asarray(Ms.sum(axis=1)).ravel()))
    return out
