"""A reduced flexible body for others: its modes as a VTU, and an export into Exudyn.

Both need a body that carries its mesh and mode shapes (``body.has_mesh``: the ``[reduction]``
stage always writes them; :func:`~crankmodal.reduction.reduce.reduce_body` when given the mesh).

VTU (ParaView)
    :func:`write_modes_vtu` writes the volume mesh with one point vector per elastic mode, named
    ``mode_01_812.3Hz`` (the first elastic mode, which is modal coordinate ``ξ[6]``), holding the
    M-orthonormal shape itself (m per unit ξ, not rescaled): *Warp By Vector* with a scale
    factor animates it.

Exudyn (https://github.com/jgerstmayr/EXUDYN, an optional dependency: ``pip install
crankmodal[multibody]``)
    Exudyn's reduced-order floating-frame body ``ObjectFFRFreducedOrder`` is built by its Python
    helper ``ObjectFFRFreducedOrderInterface`` from a ``FEMinterface`` (nodes, elements, the
    full sparse mass and stiffness matrices and a mode basis). Two routes:

    - :func:`exudyn_ffrf_interface` (from the ``.npz`` alone): the helper is filled from the
      body's Shabana inertia invariants, which are exactly the mass-matrix projections Exudyn
      computes from the full matrices (table below); no full matrix is needed.
    - :func:`exudyn_fem_interface` with ``model`` (the FE model of the same part and material,
      :func:`crankmodal.fem.assembly.assemble`): a ``FEMinterface`` with the full ``M`` and
      ``K``, on which ``ObjectFFRFreducedOrderInterface(fem)`` computes everything itself (or
      which ``fem.SaveToFile`` stores for Exudyn users).

    :func:`exudyn_interface_marker` places a rigid marker at one of crankmodal's interface
    nodes (joints, loads); :func:`exudyn_surface` is Exudyn's surface extraction, vectorised.

    The elastic modes (crankmodal's ``ξ[6:]``) are Exudyn's mode basis ``Ψ``: they satisfy the
    mean-axis conditions, so Exudyn's floating frame (its rigid-body node, in the part's frame)
    carries the rigid motion. Exudyn's terms from the invariants (``M`` the full mass matrix,
    ``x`` the node positions, ``ã`` the cross-product matrix, block ``a`` of ``Ψ̃`` is
    ``φ̃_a``)::

        massMatrixReduced   ΨᵀMΨ        = I6 (identity)     stiffnessMatrixReduced = diag(ω²)
        totalMass           = I1         chiU = I2 / I1      inertiaLocal  x̃ᵀMx̃ = I7
        mPhitTPsi           ΦₜᵀMΨ       = I3                 mPhitTPsiTilde  block a = (I3[:, a])~
        mXRefTildePsi       x̃ᵀMΨ        = −I4                mXRefTildePsiTilde block a = I8[:, :, a]
        mPsiTildePsi        block a, column b = −I5[:, a, b]
        mPsiTildePsiTilde   block (a, b) = I9[:, :, a, b]

    The invariants come from the float64 shapes, the mode basis Exudyn draws with and reads
    nodal outputs from is the stored float32 one (the two routes agree to 1.4e-8).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .flexbody import FlexibleBody

#: Exudyn element names of meshio's cell types (both number a tetra10's mid nodes on the edges
#: 01, 12, 02, 03, 13, 23).
_EXUDYN_CELLS = {"tetra": "Tet4", "tetra10": "Tet10"}


#: Exudyn's faces of a tetrahedron (``FEMinterface.VolumeToSurfaceElements``), in its order.
_EXUDYN_TET_FACES = np.array([[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]])
#: Local mid node of a tetra10 edge (meshio order = Exudyn's Tet10: 01, 12, 02, 03, 13, 23).
_TET10_MID = np.full((4, 4), -1)
for _k, (_a, _b) in enumerate(((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))):
    _TET10_MID[_a, _b] = _TET10_MID[_b, _a] = 4 + _k


def exudyn_surface(cells: np.ndarray) -> dict:
    """The boundary triangles Exudyn's ``FEMinterface.VolumeToSurfaceElements`` makes, vectorised.

    Same triangles, node order and sequence (element by element, faces in Exudyn's order), in
    milliseconds instead of Exudyn's pure-Python neighbour search (72 s on a 20 728-element
    tetra10 connecting rod).

    Parameters
    ----------
    cells : ndarray of int, shape (e, 4 or 10)
        tetra or tetra10 connectivity (meshio order).

    Returns
    -------
    dict
        ``{"Name": "meshSurface", "Trigs": (t, 3)}`` plus ``"Trigs6"`` (t, 6) for tetra10
        (corners, then the mid nodes of edges 01, 12, 20).
    """
    cells = np.asarray(cells, int)
    faces = cells[:, _EXUDYN_TET_FACES].reshape(-1, 3)  # element-major, Exudyn's face order
    _, inv, counts = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True,
                               return_counts=True)
    keep = np.flatnonzero(counts[inv.ravel()] == 1)
    out = {"Name": "meshSurface", "Trigs": faces[keep]}
    if cells.shape[1] == 10:
        el, fk = np.divmod(keep, 4)
        loc = _EXUDYN_TET_FACES[fk]  # (t, 3) local corners
        mids = np.stack([cells[el, _TET10_MID[loc[:, a], loc[:, b]]]
                         for a, b in ((0, 1), (1, 2), (2, 0))], axis=1)
        out["Trigs6"] = np.hstack([faces[keep], mids])
    return out


def _need_mesh(body: FlexibleBody, what: str) -> None:
    if not body.has_mesh:
        raise ValueError(f"{what}: flexible body {body.name!r} carries no mesh and mode shapes "
                         "(reduce it with the mesh, as the [reduction] stage does)")


def elastic_shapes(body: FlexibleBody, dtype=float) -> np.ndarray:
    """The elastic mode shapes as a node-interleaved matrix.

    Returns
    -------
    ndarray, shape (3 n_points, n_elastic)
        Column ``a`` is the displacement field (m per unit ξ) of elastic mode ``a``.
    """
    _need_mesh(body, "elastic_shapes")
    S = body.mode_shapes[:, :, ~body.rigid]
    return np.asarray(S, dtype).reshape(-1, S.shape[2])


def mode_vtu_names(body: FlexibleBody) -> list[str]:
    """Point-array names of the elastic modes in the VTU (``mode_01_812.3Hz`` …)."""
    from ..fem.vtu import mode_array_names

    return mode_array_names(body.elastic_frequencies_hz)


def write_modes_vtu(path, body: FlexibleBody) -> Path:
    """Write the body's mesh with one point vector per elastic mode (atomically).

    Parameters
    ----------
    path : str or Path
        ``.vtu`` file.
    body : FlexibleBody
        With its mesh and mode shapes.

    Returns
    -------
    Path
        The file; arrays named by :func:`mode_vtu_names` hold ``body.mode_shapes[:, :, 6 + a]``
        unchanged (float32, m per unit modal coordinate).
    """
    import meshio

    from ..fem.vtu import write_point_data

    _need_mesh(body, "write_modes_vtu")
    el = np.flatnonzero(~body.rigid)
    data = {name: np.ascontiguousarray(body.mode_shapes[:, :, k])
            for name, k in zip(mode_vtu_names(body), el)}
    mesh = meshio.Mesh(np.asarray(body.mesh_points, float),
                       [(body.mesh_cell_type, np.asarray(body.mesh_cells))])
    return write_point_data(path, mesh, data)


def exudyn_fem_interface(body: FlexibleBody, model=None, stress: bool = True):
    """An Exudyn ``FEMinterface`` of the body's mesh and elastic modes.

    Parameters
    ----------
    body : FlexibleBody
        With its mesh and mode shapes.
    model : crankmodal.fem.assembly.FEModel, optional
        The FE model the body was reduced from (same part, material and mesh). Its full sparse
        ``M`` (kg) and ``K`` (N/m) become ``fem.massMatrix`` and ``fem.stiffnessMatrix``, which
        ``exudyn.FEM.ObjectFFRFreducedOrderInterface(fem)`` needs; without it the interface holds
        the mesh, surface and modes only (enough for :func:`exudyn_ffrf_interface`).
    stress : bool
        Pass the stored stress modes on as Exudyn post-processing modes (``StressLocal``, Pa per
        unit ξ, Voigt order xx yy zz yz xz xy, which is Exudyn's).

    Returns
    -------
    exudyn.FEM.FEMinterface
        ``modeBasis`` (type ``NormalModes``) holds the elastic modes (``ξ[6:]``),
        ``eigenValues`` their ω² (rad²/s²).

    Raises
    ------
    ImportError
        Exudyn is not installed.
    ValueError
        The body has no mesh, or ``model`` does not match it.
    """
    from exudyn.FEM import FEMinterface

    _need_mesh(body, "exudyn_fem_interface")
    pts = np.asarray(body.mesh_points, float)
    fem = FEMinterface()
    fem.metaData = {"source": "crankmodal", "name": body.name}
    fem.nodes = {"Position": pts}
    fem.elements = [{"Name": body.name,
                     _EXUDYN_CELLS[body.mesh_cell_type]: np.asarray(body.mesh_cells, int)}]
    fem.surface = [exudyn_surface(body.mesh_cells)]  # = fem.VolumeToSurfaceElements(), fast
    fem.modeBasis = {"matrix": elastic_shapes(body), "type": "NormalModes"}
    fem.eigenValues = np.diag(body.stiffness)[~body.rigid].copy()
    if model is not None:
        if model.points.shape != pts.shape or not np.allclose(model.points, pts, rtol=0,
                                                               atol=1e-12):
            raise ValueError(f"exudyn_fem_interface: model has {len(model.points)} points, not "
                             f"the body's mesh ({len(pts)} points)")
        fem.massMatrix = model.M.tocsr()
        fem.stiffnessMatrix = model.K.tocsr()
    if stress and body.stress_modes is not None:
        import exudyn as exu

        S = np.asarray(body.stress_modes[:, :, ~body.rigid], float)  # (p, 6, ne)
        fem.postProcessingModes = {"matrix": S.transpose(0, 2, 1).reshape(len(pts), -1),
                                   "outputVariableType": exu.OutputVariableType.StressLocal}
    return fem


def _skew_blocks(V: np.ndarray) -> np.ndarray:
    """(3, n) columns → (3, 3 n): block a is the cross-product matrix of column a."""
    n = V.shape[1]
    out = np.zeros((3, 3 * n))
    for a in range(n):
        x, y, z = V[:, a]
        out[:, 3 * a:3 * a + 3] = [[0, -z, y], [z, 0, -x], [-y, x, 0]]
    return out


def exudyn_ffrf_interface(body: FlexibleBody,
                          rigid_body_node_type: str = "NodeType.RotationEulerParameters",
                          stress: bool = True):
    """Exudyn's ``ObjectFFRFreducedOrderInterface`` of the body, from the ``.npz`` alone.

    The constant mass terms are the body's inertia invariants (module docstring), so no full
    mass or stiffness matrix is needed. Add the body to an Exudyn system with
    ``cms.AddObjectFFRFreducedOrder(mbs, positionRef=…, rotationMatrixRef=…)``.

    Parameters
    ----------
    body : FlexibleBody
        With its mesh and mode shapes (the mode basis for drawing and nodal outputs).
    rigid_body_node_type : str
        Exudyn rigid-body node of the floating frame (``NodeType.RotationEulerParameters``,
        ``NodeType.RotationRxyz``, ``NodeType.RotationRotationVector``).
    stress : bool
        Carry the stress modes as Exudyn post-processing modes.

    Returns
    -------
    exudyn.FEM.ObjectFFRFreducedOrderInterface
    """
    from exudyn.FEM import ObjectFFRFreducedOrderInterface, StrNodeType2NodeType

    fem = exudyn_fem_interface(body, stress=stress)
    el = ~body.rigid
    inv = body.invariants
    ne = int(el.sum())
    cms = ObjectFFRFreducedOrderInterface()
    cms.modeBasis = fem.modeBasis["matrix"]
    cms.trigList = fem.GetSurfaceTriangles6() or fem.GetSurfaceTriangles()
    cms.postProcessingModes = fem.postProcessingModes
    cms.massMatrixReduced = np.asarray(inv["I6"], float).copy()
    cms.stiffnessMatrixReduced = np.asarray(body.stiffness, float)[np.ix_(el, el)].copy()
    cms.nModes = ne
    cms.nNodes = len(body.mesh_points)
    cms.dim3D = 3
    cms.rigidBodyNodeType = StrNodeType2NodeType(rigid_body_node_type)
    cms.nODE2rot = 4 if str(cms.rigidBodyNodeType) == "NodeType.RotationEulerParameters" else 3
    cms.nODE2rigid = 3 + cms.nODE2rot
    cms.nODE2FFRFreduced = cms.nODE2rigid + ne
    cms.xRef = np.asarray(body.mesh_points, float).flatten()
    cms.inertiaLocal = np.asarray(inv["I7"], float).copy()
    cms.totalMass = float(inv["I1"])
    cms.Mtt = cms.totalMass * np.eye(3)
    cms.chiU = np.asarray(inv["I2"], float) / cms.totalMass
    cms.chiUtilde = _skew_blocks(cms.chiU[:, None])
    I3 = np.asarray(inv["I3"], float)
    cms.mPhitTPsi = I3.copy()
    cms.mPhitTPsiTilde = _skew_blocks(I3)
    cms.mXRefTildePsi = -np.asarray(inv["I4"], float)
    cms.mXRefTildePsiTilde = np.asarray(inv["I8"], float).transpose(0, 2, 1).reshape(3, 3 * ne)
    # [3a + i, b] = −I5[i, a, b];  [3a + i, 3b + j] = I9[i, j, a, b]
    cms.mPsiTildePsi = -np.asarray(inv["I5"], float).transpose(1, 0, 2).reshape(3 * ne, ne)
    cms.mPsiTildePsiTilde = np.asarray(inv["I9"], float).transpose(2, 0, 3, 1).reshape(3 * ne,
                                                                                       3 * ne)
    cms.massMatrixFFRFreduced = np.zeros((cms.nODE2FFRFreduced, cms.nODE2FFRFreduced))
    cms.massMatrixFFRFreduced[0:3, 0:3] = cms.Mtt
    cms.massMatrixFFRFreduced[cms.nODE2rigid:, cms.nODE2rigid:] = cms.massMatrixReduced
    return cms


def exudyn_interface_marker(mbs, object_number, body: FlexibleBody, name: str, **kwargs):
    """An Exudyn rigid marker at one of the body's interface nodes, for joints and loads.

    A ``MarkerSuperElementRigid`` on the interface's surface nodes, weighted by the area each
    carries (``body.interface_weights``, the weights of crankmodal's distributing coupling),
    with its offset moving it from their weighted mean to the interface centre (the exact bore
    centre; the offset is 0 for a full bore).

    Parameters
    ----------
    mbs : exudyn.MainSystem
    object_number : exudyn.ObjectIndex
        The ``ObjectFFRFreducedOrder`` (``cms.AddObjectFFRFreducedOrder(mbs)["oFFRFreducedOrder"]``).
    body : FlexibleBody
        The same body, with its mesh (files written before the interface nodes were stored
        cannot place markers).
    name : str
        Interface name (``body.interface_names``).
    **kwargs
        Passed on to ``MarkerSuperElementRigid`` (e.g. ``useAlternativeApproach``).

    Returns
    -------
    exudyn.MarkerIndex
    """
    import exudyn.itemInterface as eii

    if name not in body.interface_names:
        raise ValueError(f"exudyn_interface_marker: no interface {name!r} in body {body.name!r}; "
                         f"interfaces: {', '.join(body.interface_names)}")
    if body.interface_nodes is None or body.interface_weights is None:
        raise ValueError(f"exudyn_interface_marker: body {body.name!r} stores no interface nodes "
                         "(reduce it with the mesh, as the [reduction] stage does)")
    r = body.interface_names.index(name)
    nodes, w = np.asarray(body.interface_nodes[r]), np.asarray(body.interface_weights[r], float)
    keep = w > 1e-12 * w.max()  # the corners of flat P2 triangles carry no area
    nodes, w = nodes[keep], w[keep] / w[keep].sum()
    offset = np.asarray(body.interface_centres[r]) - w @ np.asarray(body.mesh_points)[nodes]
    return mbs.AddMarker(eii.MarkerSuperElementRigid(
        bodyNumber=object_number, meshNodeNumbers=[int(i) for i in nodes],
        weightingFactors=w.tolist(), offset=offset.tolist(), **kwargs))
