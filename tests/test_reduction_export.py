"""The flexible body for others: mesh and mode shapes in the .npz, the modes VTU of the
[reduction] stage, and the export into Exudyn (skipped when Exudyn is not installed)."""

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import part_context

from crankmodal.fem.assembly import assemble
from crankmodal.fem.materials import Material
from crankmodal.fem.testparts import bar, tube
from crankmodal.reduction import export, stage
from crankmodal.reduction.interfaces import make_interfaces
from crankmodal.reduction.io import load_flexbody, save_flexbody
from crankmodal.reduction.reduce import reduce_body
from crankmodal.scene import Scene

STEEL = Material("steel", 2.1e11, 0.3, 7850.0)
L, B, H = 0.5, 0.03, 0.02  # in-plane width B (y) > height H (z): no degenerate bending pair


@pytest.fixture(scope="module")
def reduced():
    """A coarse P2 bar (945 DOF) reduced on its two end faces, with its mesh."""
    part = bar(L, B, H, (10, 2, 1), order=2)
    model = assemble(part, STEEL)
    itf = make_interfaces(part, [{"region": "end_x0", "kind": "rigid"},
                                 {"region": "end_x1", "kind": "rigid"}])
    body, cb = reduce_body(model, itf, fixed_interface_modes=12, name="bar", mesh=part.mesh)
    return part, model, body, cb


def _shapes(body):
    return np.asarray(body.mode_shapes, float).reshape(-1, body.n_modes)


def test_mode_shapes_are_the_basis_on_the_mesh_and_m_orthonormal(reduced):
    """The stored shapes are V W (float32), M-orthonormal and K-diagonal against the FE matrices
    of the part (tolerance: float32 rounding, 6e-8 per entry)."""
    part, model, body, cb = reduced
    assert body.mode_shapes.shape == (len(part.mesh.points), 3, body.n_modes)
    assert body.mode_shapes.dtype == np.float32
    assert body.mesh_cell_type == "tetra10" and np.array_equal(body.mesh_cells,
                                                               part.mesh.cells[0].data)
    assert np.array_equal(body.mesh_points, part.mesh.points)
    V = cb.V @ body.cb_to_modal
    assert np.abs(_shapes(body) - V).max() < 1e-6 * np.abs(V).max()
    S = _shapes(body)
    assert np.abs(S.T @ model.M @ S - np.eye(body.n_modes)).max() < 1e-6
    Kr = S.T @ model.K @ S
    w2 = np.diag(body.stiffness)
    assert np.abs(Kr - np.diag(w2)).max() < 1e-6 * w2.max()
    # the rigid modes are rigid: no strain energy
    assert np.abs(Kr[:6, :6]).max() < 1e-6 * w2[6]


def test_npz_carries_mesh_and_shapes_and_old_files_still_load(reduced, tmp_path):
    _, _, body, _ = reduced
    path = save_flexbody(tmp_path / "b.npz", body)
    back = load_flexbody(path)
    for k in ("mesh_points", "mesh_cells", "mode_shapes"):
        assert np.array_equal(getattr(back, k), getattr(body, k))
    assert back.mesh_cell_type == "tetra10" and back.has_mesh
    for a, b, w in zip(back.interface_nodes, body.interface_nodes, back.interface_weights):
        assert np.array_equal(a, b) and len(w) == len(a)
        assert w.sum() == pytest.approx(B * H, rel=1e-12)  # each end face's area
    with np.load(path, allow_pickle=False) as z:  # plain numpy
        assert z["mode_shapes"].shape == (len(body.mesh_points), 3, body.n_modes)
        assert str(z["mesh_cell_type"]) == "tetra10"
        new = ("mesh_points", "mesh_cells", "mesh_cell_type", "mode_shapes",
               "interface_node_counts", "interface_nodes", "interface_weights")
        old = {k: z[k] for k in z.files if k not in new}
    np.savez(tmp_path / "old.npz", **old)  # a version-1 file written before the mesh keys
    prev = load_flexbody(tmp_path / "old.npz")
    assert prev.mode_shapes is None and prev.mesh_points is None and not prev.has_mesh
    assert prev.interface_nodes is None and prev.interface_weights is None
    assert np.array_equal(prev.interface_map, body.interface_map)
    assert prev.to_dict() == {**body.to_dict(), "has_mode_shapes": False}


def test_no_mesh_no_shapes_and_a_clear_error(reduced, tmp_path):
    model = reduced[1]
    nomesh, _ = reduce_body(model, _interfaces(reduced), fixed_interface_modes=4, name="bar")
    assert nomesh.mode_shapes is None and not nomesh.has_mesh
    with pytest.raises(ValueError, match="carries no mesh"):
        export.write_modes_vtu(tmp_path / "m.vtu", nomesh)
    assert not (tmp_path / "m.vtu").exists()


def _interfaces(reduced):
    part = reduced[0]
    return make_interfaces(part, [{"region": "end_x0", "kind": "rigid"},
                                  {"region": "end_x1", "kind": "rigid"}])


def test_stage_writes_the_modes_vtu_equal_to_the_npz_shapes(tmp_path):
    """Oracle: the VTU's vectors are the .npz's shapes, and those are M-orthonormal against the
    FE mass matrix assembled afresh for the same part (and the stress modes stay optional)."""
    import meshio

    part = tube(0.02, 0.04, 0.06, divisions=(1, 12, 2), order=2)
    p = stage.validate({"coupling": "distributing", "n_modes": 6, "file": "tube.npz",
                        "stress_modes": False, "compare_full": False},
                       Scene(name="t", base_dir=Path(tmp_path)))
    res = stage.run(p, part_context(part, STEEL, tmp_path))
    assert Path(res["modes_vtu"]) == tmp_path / "tube_modes.vtu"
    assert "tube_modes.vtu" in res["files"]
    json.dumps(res, default=lambda a: np.asarray(a).tolist())
    body = load_flexbody(res["file"])
    assert body.stress_modes is None and body.has_mesh
    mesh = meshio.read(res["modes_vtu"])
    assert np.array_equal(mesh.points, body.mesh_points)
    assert np.array_equal(mesh.cells[0].data, body.mesh_cells)
    fe = body.elastic_frequencies_hz
    names = [k for k in mesh.point_data if k.startswith("mode_")]
    assert names == [f"mode_{i + 1:02d}_{f:.1f}Hz" for i, f in enumerate(fe)]
    for i, name in enumerate(names):
        assert np.array_equal(mesh.point_data[name], body.mode_shapes[:, :, 6 + i])
    S = _shapes(body)
    model = assemble(part, STEEL)
    assert np.abs(S.T @ model.M @ S - np.eye(body.n_modes)).max() < 1e-6
    w = np.sqrt(np.abs(np.diag(S.T @ model.K @ S)[6:])) / (2 * np.pi)
    assert np.allclose(w, fe, rtol=1e-6)


# ------------------------------------------------------------------------------------- Exudyn

def _skewed(body, model):
    """The body with its elastic shapes mixed with rigid motion (I3, I4 ≠ 0, I6 ≠ identity;
    K unchanged, rigid motion has no strain energy): every invariant term is non-zero."""
    from dataclasses import replace

    from crankmodal.reduction.flexbody import inertia_invariants

    S = np.array(body.mode_shapes, np.float32)
    rng = np.random.default_rng(3)
    S[:, :, 6:] += np.einsum("pjr,re->pje", S[:, :, :6],
                             rng.normal(size=(6, body.n_modes - 6)).astype(np.float32))
    el = np.asarray(S[:, :, 6:], float).reshape(-1, body.n_modes - 6)
    inv = inertia_invariants(model.points, model.M[0::3, 0::3], el)
    return replace(body, mode_shapes=S, invariants=inv)


@pytest.mark.parametrize("variant", ["body", "skewed"])
def test_exudyn_ffrf_terms_from_the_npz_equal_exudyns_own_from_the_full_matrices(
        reduced, tmp_path, variant):
    """Route 1 (invariants of the .npz) against route 2 (Exudyn's ObjectFFRFreducedOrderInterface
    computing every term from the full M and K): equal to the float32 rounding of the mode
    basis route 2 projects (1e-6 of each term's scale). The mean-axis terms (I3, I4) of the real
    body vanish, so the skewed body, where none does, checks their signs and layout."""
    pytest.importorskip("exudyn")
    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    _, model, body, _ = reduced
    if variant == "skewed":
        body = _skewed(body, model)
    ffile = load_flexbody(save_flexbody(tmp_path / "bar.npz", body))  # from the file alone
    mine = export.exudyn_ffrf_interface(ffile)
    theirs = ObjectFFRFreducedOrderInterface(export.exudyn_fem_interface(body, model))
    scale = {"mPhitTPsi": np.sqrt(body.mass_kg), "mPhitTPsiTilde": np.sqrt(body.mass_kg),
             "mXRefTildePsi": np.sqrt(body.mass_kg) * L}
    if variant == "skewed":
        assert np.abs(theirs.mPhitTPsi).max() > 0.1 * scale["mPhitTPsi"]
        assert np.abs(theirs.mXRefTildePsi).max() > 0.1 * scale["mXRefTildePsi"]
    for k in ("massMatrixReduced", "stiffnessMatrixReduced", "xRef", "inertiaLocal", "Mtt",
              "totalMass", "chiU", "chiUtilde", "mPsiTildePsi", "mPsiTildePsiTilde",
              "mPhitTPsi", "mPhitTPsiTilde", "mXRefTildePsi", "mXRefTildePsiTilde",
              "massMatrixFFRFreduced"):
        a, b = np.asarray(getattr(theirs, k), float), np.asarray(getattr(mine, k), float)
        assert a.shape == b.shape, k
        assert np.abs(a - b).max() <= 1e-6 * scale.get(k, np.abs(a).max()), k
    for k in ("nModes", "nNodes", "nODE2rot", "nODE2rigid", "nODE2FFRFreduced"):
        assert int(getattr(theirs, k)) == int(getattr(mine, k)), k
    assert mine.trigList == theirs.trigList


def test_exudyn_body_has_crankmodals_frequencies_mass_and_inertia(reduced):
    """The body assembled in Exudyn: its linearised free-free frequencies (6 zeros, then the
    elastic ones) equal crankmodal's (1e-9: both are the same diag(ω²) on identity mass, the
    rigid-elastic coupling vanishing by the mean-axis conditions); mass and inertia equal the
    closed form of the bar (consistent mass of a straight bar is exact: 1e-9)."""
    exu = pytest.importorskip("exudyn")
    from exudyn.solver import ComputeODE2Eigenvalues

    _, _, body, _ = reduced
    for node in ("NodeType.RotationEulerParameters", "NodeType.RotationRxyz"):
        cms = export.exudyn_ffrf_interface(body, rigid_body_node_type=node)
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        cms.AddObjectFFRFreducedOrder(mbs)
        mbs.Assemble()
        ev, _ = ComputeODE2Eigenvalues(mbs)
        f = np.sqrt(np.abs(np.sort(ev))) / (2 * np.pi)
        assert len(f) == body.n_modes
        assert np.abs(f[:6]).max() < 1e-6 * body.frequencies_hz[6]
        assert np.allclose(f[6:], body.elastic_frequencies_hz, rtol=1e-9, atol=0)
    m = STEEL.rho * L * B * H
    assert cms.totalMass == pytest.approx(m, rel=1e-9)
    assert np.allclose(cms.chiU, [L / 2, 0, 0], atol=1e-12)
    c = cms.chiU
    J = cms.inertiaLocal - m * (c @ c * np.eye(3) - np.outer(c, c))  # about the centre of mass
    ref = m / 12 * np.diag([B ** 2 + H ** 2, L ** 2 + H ** 2, L ** 2 + B ** 2])
    assert np.allclose(J, ref, rtol=1e-9, atol=1e-12 * ref.max())
    assert np.allclose(J, body.inertia, rtol=1e-9, atol=1e-12 * ref.max())


def test_a_body_struck_in_exudyn_rings_at_crankmodals_frequency(reduced):
    """Free body, first elastic mode given a unit modal velocity, 20 periods with Exudyn's
    generalised-α at spectral radius 1 (the trapezoidal rule, 100 steps a period). Oracle: the
    trapezoidal rule rings at (2/h) atan(ωh/2), 3.3e-4 below ω here; the measured zero-crossing
    frequency matches that within 2e-5, the amplitude is ξ̇₀/ω within 1e-3, the frame stays put
    (mean axis) and no other mode is excited."""
    exu = pytest.importorskip("exudyn")
    import exudyn.itemInterface as eii

    _, _, body, _ = reduced
    cms = export.exudyn_ffrf_interface(body)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    d = cms.AddObjectFFRFreducedOrder(mbs)
    v0 = np.zeros(cms.nModes)
    v0[0] = 1.0
    mbs.SetNodeParameter(d["nGenericODE2"], "initialCoordinates_t", list(v0))
    s_xi = mbs.AddSensor(eii.SensorNode(nodeNumber=d["nGenericODE2"], storeInternal=True,
                                        outputVariableType=exu.OutputVariableType.Coordinates))
    s_rb = mbs.AddSensor(eii.SensorNode(nodeNumber=d["nRigidBody"], storeInternal=True,
                                        outputVariableType=exu.OutputVariableType.Displacement))
    mbs.Assemble()
    f0 = body.elastic_frequencies_hz[0]
    n_per, periods = 100, 20
    h = 1.0 / (f0 * n_per)
    ss = exu.SimulationSettings()
    ss.timeIntegration.numberOfSteps = n_per * periods
    ss.timeIntegration.endTime = periods / f0
    ss.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    ss.timeIntegration.verboseMode = 0
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = h
    mbs.SolveDynamic(ss)
    data = mbs.GetSensorStoredData(s_xi)
    t, x = data[:, 0], data[:, 1]
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    tz = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    f_meas = (len(tz) - 1) / (tz[-1] - tz[0])
    w = 2 * np.pi * f0
    f_trap = 2 / h * np.arctan(w * h / 2) / (2 * np.pi)
    assert len(tz) >= periods - 1
    assert f_meas == pytest.approx(f_trap, rel=2e-5)
    assert f_meas == pytest.approx(f0, rel=1e-3)
    assert np.abs(x).max() * w == pytest.approx(1.0, rel=1e-3)
    assert np.abs(data[:, 2:]).max() < 1e-9 * np.abs(x).max()
    assert np.abs(mbs.GetSensorStoredData(s_rb)[:, 1:]).max() < 1e-9 * np.abs(x).max()


@pytest.mark.parametrize("order", [1, 2])
def test_surface_equals_exudyns_volume_to_surface_elements(order):
    """The vectorised surface is Exudyn's own (same triangles, node order and sequence)."""
    pytest.importorskip("exudyn")
    from exudyn.FEM import FEMinterface

    part = bar(0.2, 0.03, 0.02, (4, 2, 1), order=order)
    cells = np.asarray(part.mesh.cells[0].data)
    fem = FEMinterface()
    fem.nodes = {"Position": np.asarray(part.mesh.points, float)}
    fem.elements = [{"Name": "bar", "Tet10" if order == 2 else "Tet4": cells}]
    fem.VolumeToSurfaceElements()
    mine = export.exudyn_surface(cells)
    assert np.array_equal(mine["Trigs"], fem.surface[0]["Trigs"])
    assert ("Trigs6" in mine) == ("Trigs6" in fem.surface[0]) == (order == 2)
    if order == 2:
        assert np.array_equal(mine["Trigs6"], fem.surface[0]["Trigs6"])


def test_a_spinning_bar_moves_alike_in_exudyn_and_in_crankmodals_dynamics(reduced, tmp_path):
    """Cross-code oracle for the nonlinear floating-frame terms: the free bar spinning at
    500 rad/s about z, started bent in its first in-plane mode (2 mm modal amplitude), over 5
    periods, in crankmodal's planar FlexibleBody (RK45, rtol 1e-9) and as Exudyn's 3D
    ObjectFFRFreducedOrder (trapezoidal rule, 800 steps a period). The spin matters: the
    history differs from the still bar's cosine by 0.24 of the amplitude. The two codes agree to
    1.9e-4 of it (bound 3e-4: Exudyn's phase error 5 · 2π (ωh)²/12 = 1.6e-4, plus the
    out-of-plane share the planar body drops, 1.3e-4 of the amplitude excited in Exudyn), and on
    the axial mode the spin stretches (excursion 0.04 of the amplitude) to 7 % of its excursion
    (bound 10 %: Exudyn's phase error over 45 periods of the 5.7 kHz mode, 0.12 rad).
    A flipped sign of the centrifugal term (mPsiTildePsiTilde, I9) fails it (9e-4 of a0 off); the
    modal Coriolis coupling (mPsiTildePsi, I5) is too weak here to register: the skewed-basis
    test above checks that one."""
    exu = pytest.importorskip("exudyn")
    import exudyn.itemInterface as eii

    from crankmodal.dynamics.flexible.body import load_flexible_body
    from crankmodal.dynamics.model.system import Multibody
    from crankmodal.dynamics.run.integrate import SolverSettings, integrate

    _, _, body, _ = reduced
    flex = load_flexible_body(save_flexbody(tmp_path / "bar.npz", body), "bar",
                              damping_ratio=0.0)
    fe = body.elastic_frequencies_hz
    keep = [int(np.argmin(np.abs(fe - f))) for f in flex.frequencies_hz]  # planar -> 3D index
    axial = int(np.argmax(np.abs(flex.b)))
    spin, a0, periods, per = 500.0, 2e-3, 5, 800
    k = flex.n_coordinates
    t_end = periods / flex.frequencies_hz[0]
    t_out = np.linspace(0.0, t_end, 501)
    q0, qd0 = np.zeros(3 + k), np.zeros(3 + k)
    q0[3], qd0[2] = a0, spin
    sysm = Multibody([flex], [])
    q, qd = sysm.assemble(0.0, q0, qd0)
    xi = integrate(sysm, q, qd, t_end, t_out, SolverSettings(method="RK45", rtol=1e-9, atol=1e-13)).y[3:3 + k]

    cms = export.exudyn_ffrf_interface(body)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    v_origin = -np.cross([0.0, 0.0, spin], body.centre_of_mass)  # the frame origin is x = 0
    d = cms.AddObjectFFRFreducedOrder(mbs, initialVelocity=list(v_origin),
                                      initialAngularVelocity=[0.0, 0.0, spin])
    x0 = np.zeros(cms.nModes)
    x0[keep[0]] = a0
    mbs.SetNodeParameter(d["nGenericODE2"], "initialCoordinates", list(x0))
    sens = mbs.AddSensor(eii.SensorNode(nodeNumber=d["nGenericODE2"], storeInternal=True,
                                        outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ss.timeIntegration.numberOfSteps = per * periods
    ss.timeIntegration.endTime = t_end
    ss.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    ss.timeIntegration.verboseMode = 0
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = t_end / (per * periods)
    mbs.SolveDynamic(ss)
    data = mbs.GetSensorStoredData(sens)
    ex = np.array([np.interp(t_out, data[:, 0], data[:, 1 + i]) for i in range(cms.nModes)])

    still = a0 * np.cos(2 * np.pi * flex.frequencies_hz[0] * t_out)  # the bar not spinning
    assert np.abs(xi[0] - still).max() > 0.1 * a0
    assert np.abs(ex[keep[0]] - xi[0]).max() < 3e-4 * a0
    excursion = np.ptp(xi[axial])
    assert excursion > 1e-4 * a0
    assert np.abs(ex[keep[axial]] - xi[axial]).max() < 0.1 * excursion


def _pinned_pinned_fe_hz(model, itf, n=6):
    """Full FE bar with the same rigid end couplings, the interface nodes' translations fixed
    and their rotations free: its lowest frequencies, Hz (the first is the free rotation about
    the line through the pins, 0)."""
    import scipy.linalg as sla

    from crankmodal.reduction.interfaces import tie_transformation

    T, _ = tie_transformation(model.n_dofs, itf, model.points)
    K = (T.T @ model.K @ T).toarray()
    M = (T.T @ model.M @ T).toarray()
    m = K.shape[0]
    keep = np.setdiff1d(np.arange(m), [m - 12, m - 11, m - 10, m - 6, m - 5, m - 4])
    lam = sla.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], eigvals_only=True,
                   subset_by_index=(0, n - 1))
    return np.sqrt(np.abs(lam)) / (2 * np.pi)


def test_exudyn_joints_on_the_interface_markers_give_the_fe_pinned_pinned_bar(reduced, tmp_path):
    """Both end interfaces of the .npz body held by Exudyn spherical joints at the interface
    markers: the constrained body's frequencies are the full FE model's pinned–pinned ones
    (rigid end faces, translations fixed): Rayleigh–Ritz, so from above, the first four within
    1e-4 of the 12-mode basis (measured 2e-7 out of plane, 2.8e-6 in plane, then 3.9e-5,
    4.7e-5); the marker sits at the interface centre."""
    exu = pytest.importorskip("exudyn")
    import exudyn.itemInterface as eii
    from exudyn.solver import ComputeODE2Eigenvalues

    _, model, body, _ = reduced
    body = load_flexbody(save_flexbody(tmp_path / "bar.npz", body))
    cms = export.exudyn_ffrf_interface(body)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    obj = cms.AddObjectFFRFreducedOrder(mbs)["oFFRFreducedOrder"]
    ground = mbs.AddObject(eii.ObjectGround())
    markers = {}
    for name, c in zip(body.interface_names, body.interface_centres):
        markers[name] = export.exudyn_interface_marker(mbs, obj, body, name)
        mg = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground, localPosition=list(c)))
        mbs.AddObject(eii.SphericalJoint(markerNumbers=[mg, markers[name]]))
    with pytest.raises(ValueError, match="no interface 'bore'.*end_x0, end_x1"):
        export.exudyn_interface_marker(mbs, obj, body, "bore")
    mbs.Assemble()
    for name, c in zip(body.interface_names, body.interface_centres):
        pos = mbs.GetMarkerOutput(markers[name], exu.OutputVariableType.Position,
                                  configuration=exu.ConfigurationType.Reference)
        assert np.allclose(pos, c, atol=1e-12)
    ev, _ = ComputeODE2Eigenvalues(mbs)
    f = np.sort(np.sqrt(np.abs(ev)) / (2 * np.pi))
    fe = _pinned_pinned_fe_hz(model, _interfaces(reduced))
    assert f[0] < 1e-3 * fe[1] and fe[0] < 1e-3 * fe[1]  # rotation about the pin line
    assert np.all(f[1:6] >= fe[1:6] * (1 - 1e-9))
    assert np.allclose(f[1:5], fe[1:5], rtol=1e-4, atol=0)


def test_exudyn_fem_interface_file_round_trip_and_stress_mode_layout(reduced, tmp_path):
    """What an Exudyn user loads: fem.SaveToFile / FEMinterface.LoadFromFile keep the mesh, the
    elastic modes and ω², and the stress modes sit in Exudyn's post-processing layout (columns
    6a … 6a+5 = xx yy zz yz xz xy of elastic mode a)."""
    exu = pytest.importorskip("exudyn")
    from exudyn.FEM import FEMinterface

    _, model, body, _ = reduced
    assert body.stress_modes is not None
    fem = export.exudyn_fem_interface(body, model)
    fem.SaveToFile(str(tmp_path / "bar_fem"))
    back = FEMinterface()
    back.LoadFromFile(str(tmp_path / "bar_fem"))
    assert np.array_equal(back.GetNodePositionsAsArray(), body.mesh_points)
    assert np.array_equal(back.elements[0]["Tet10"], body.mesh_cells)
    S = np.asarray(body.mode_shapes[:, :, 6:], float).reshape(-1, body.n_modes - 6)
    assert np.array_equal(back.modeBasis["matrix"], S)
    assert np.allclose(np.sqrt(back.eigenValues) / (2 * np.pi), body.elastic_frequencies_hz,
                       rtol=1e-12)
    assert (back.GetMassMatrix() != model.M).nnz == 0
    P = back.postProcessingModes["matrix"]
    assert back.postProcessingModes["outputVariableType"] == exu.OutputVariableType.StressLocal
    for a in (0, 5):
        assert np.array_equal(P[:, 6 * a:6 * a + 6], body.stress_modes[:, :, 6 + a])
