"""Stress modes, the .npz format and the [reduction] scene section."""

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import part_context

from crankmodal.errors import InputFileError, SceneError
from crankmodal.fem.assembly import assemble
from crankmodal.fem.materials import Material
from crankmodal.fem.static import nodal_stress
from crankmodal.fem.testparts import bar, tube
from crankmodal.reduction import stage
from crankmodal.reduction.interfaces import make_interfaces
from crankmodal.reduction.io import load_flexbody, save_flexbody
from crankmodal.reduction.reduce import reduce_body
from crankmodal.reduction.stress_modes import stress_modes, stress_recovery, von_mises
from crankmodal.scene import Scene

STEEL = Material("steel", 2.1e11, 0.3, 7850.0)
L, B, H = 0.6, 0.04, 0.05


@pytest.fixture(scope="module")
def clamped_bar():
    part = bar(L, B, H, (12, 2, 2), order=2)
    model = assemble(part, STEEL)
    itf = make_interfaces(part, [{"region": "end_x0", "kind": "rigid"},
                                 {"region": "end_x1", "kind": "rigid"}])
    body, cb = reduce_body(model, itf, fixed_interface_modes=6, mesh=part.mesh,
                           stress_dtype=np.float64)
    return part, model, body, cb


def test_stress_modes_equal_the_fe_stress_recovery_mode_by_mode(clamped_bar):
    part, model, body, cb = clamped_bar
    V = cb.V @ body.cb_to_modal
    scale = np.abs(body.stress_modes).max()  # round-off of the rigid modes is relative to this
    for k in (0, 7, body.n_modes - 1):
        ref = nodal_stress(model, V[:, k], part.mesh)  # Pa, (n, 3, 3)
        ref_v = ref[:, [0, 1, 2, 1, 0, 0], [0, 1, 2, 2, 2, 1]]
        assert np.abs(body.stress_modes[:, :, k] - ref_v).max() < 1e-10 * scale


def test_rigid_modes_carry_no_stress(clamped_bar):
    _, _, body, _ = clamped_bar
    s = body.stress_modes
    assert np.abs(s[:, :, :6]).max() < 1e-8 * np.abs(s[:, :, 6:]).max()


def test_superposed_stress_modes_give_f_over_a_in_a_pulled_bar(clamped_bar):
    """Axial force F on end_x1 with end_x0 clamped (Guyan solve in CB coordinates), mapped to
    orthonormal coordinates ξ = Wᵀ M_cb c: Σ σ_k ξ_k is F / A away from the ends (1 %)."""
    _, model, body, cb = clamped_bar
    F = 2.0e4
    free = np.arange(6, cb.K.shape[0])
    rhs = np.zeros(len(free))
    rhs[0] = F
    c = np.zeros(cb.K.shape[0])
    c[free] = np.linalg.solve(cb.K[np.ix_(free, free)], rhs)
    xi = body.cb_to_modal.T @ (cb.M @ c)
    sig = body.stress_modes @ xi  # (n_points, 6)
    mid = np.abs(model.points[:, 0] - L / 2) < 0.2 * L
    assert np.allclose(sig[mid, 0], F / (B * H), rtol=0.01)
    assert np.abs(sig[mid, 1:]).max() < 0.01 * F / (B * H)
    vm = von_mises(sig[:, :, None])[:, 0]
    assert np.allclose(vm[mid], F / (B * H), rtol=0.01)


def test_chunking_does_not_change_stress_modes(clamped_bar):
    part, model, _, _ = clamped_bar
    rec = stress_recovery(model, part.mesh)
    X = np.random.default_rng(1).standard_normal((model.K.shape[0], 3))
    assert np.allclose(stress_modes(rec, X, chunk=7), stress_modes(rec, X, chunk=10 ** 6),
                       rtol=1e-12, atol=1e-3)


def test_npz_round_trip_and_plain_numpy_reading(clamped_bar, tmp_path):
    _, _, body, _ = clamped_bar
    path = save_flexbody(tmp_path / "b.npz", body)
    back = load_flexbody(path)
    assert back.to_dict() == body.to_dict()
    for k in ("stiffness", "mass", "interface_map", "cb_to_modal", "inertia", "stress_modes"):
        assert np.array_equal(getattr(back, k), getattr(body, k))
    for k, v in body.invariants.items():
        assert np.array_equal(back.invariants[k], v)
    assert back.info == json.loads(json.dumps(body.info))
    with np.load(path, allow_pickle=False) as z:  # no crankmodal needed
        assert str(z["format"]) == "crankmodal-flexbody" and int(z["version"]) == 1
        assert list(z["interface_names"]) == ["end_x0", "end_x1"]
        assert z["interface_map"].shape == (2, 6, body.n_modes)
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(InputFileError, match="not a readable"):
        load_flexbody(tmp_path / "bad.npz")
    with pytest.raises(InputFileError):
        load_flexbody(tmp_path / "missing.npz")


def test_stage_reduces_a_tube_and_matches_the_full_model(tmp_path):
    part = tube(0.02, 0.04, 0.12, divisions=(2, 16, 6), order=2)
    p = stage.validate({"coupling": "distributing", "n_modes": 16, "n_compare": 4},
                       Scene(name="t", base_dir=Path(tmp_path)))
    res = stage.run(p, part_context(part, STEEL, tmp_path))
    assert [i["name"] for i in res["interfaces"]] == ["bore", "outer"]  # cylindrical regions
    assert res["rigid_body_modes"] == 6
    assert np.abs(res["relative_difference"]).max() < 0.005
    assert Path(res["file"]).is_file() and "summary" in res
    json.dumps(res, default=lambda a: np.asarray(a).tolist())
    body = load_flexbody(res["file"])
    assert body.stress_modes.dtype == np.float32
    assert body.mass_kg == pytest.approx(res["mass_kg"])


def test_stage_validation_names_the_key(tmp_path):
    sc = Scene(name="t", base_dir=Path(tmp_path))
    with pytest.raises(SceneError, match="reduction.cutoff_hz"):
        stage.validate({"n_modes": 5, "cutoff_hz": 100.0}, sc)
    with pytest.raises(SceneError, match=r"reduction.interfaces\[0\].kind"):
        stage.validate({"interfaces": [{"region": "a", "kind": "welded"}]}, sc)
    with pytest.raises(SceneError, match="reduction.file"):
        stage.validate({"file": "out.h5"}, sc)
    with pytest.raises(SceneError, match="reduction.bogus"):
        stage.validate({"bogus": 1}, sc)
    p = stage.validate({"interfaces": [{"region": "nope"}]}, sc)
    with pytest.raises(SceneError, match=r"interfaces\[0\].region: no region 'nope'"):
        stage.run(p, part_context(bar(0.2, 0.02, 0.02, (4, 1, 1), order=1), STEEL, tmp_path))


def test_the_stage_names_the_scene_key_of_a_core_parameter_error(tmp_path):
    """make_interfaces and craig_bampton name their arguments; the stage re-raises under the
    scene key with the same text (issue 20). A region cut into segments gives one spec per band,
    so the scene's interfaces[1] is make_interfaces' interfaces[2] here (before: the message said
    reduction.interfaces[2], a table the scene does not have)."""
    sc = Scene(name="t", base_dir=Path(tmp_path))
    small = part_context(bar(0.2, 0.02, 0.02, (4, 1, 1), order=1), STEEL, tmp_path)
    p = stage.validate({"interfaces": [{"region": "end_x0"}, {"region": "end_x1"}],
                        "n_modes": 40, "compare_full": False}, sc)
    with pytest.raises(SceneError) as info:
        stage.run(p, small)
    assert str(info.value) == "reduction.n_modes: 40 modes need a finer mesh (36 interior DOFs)"
    p = stage.validate({"interfaces": [{"region": "end_x0"}, {"region": "end_x0"}]}, sc)
    with pytest.raises(SceneError) as info:
        stage.run(p, small)
    assert str(info.value) == ("reduction.interfaces[1].region: 'end_x0' lies inside interface "
                               "'end_x0'; interfaces must not overlap")
    ring = part_context(tube(0.02, 0.04, 0.05, divisions=(1, 16, 2), order=1), STEEL, tmp_path)
    p = stage.validate({"interfaces": [{"region": "bore", "segments": 2},
                                       {"region": "bore_seg2"}, {"region": "outer"}]}, sc)
    p["interfaces"][1]["region"] = "bore"  # the stage checks the scene's names first
    with pytest.raises(SceneError) as info:
        stage.run(p, ring)
    assert str(info.value) == ("reduction.interfaces[1].region: 'bore' lies inside interface "
                               "'bore_seg1'; interfaces must not overlap")
