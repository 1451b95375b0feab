"""The [material], [modal] and [static] stages: scene keys, results, files and bad input."""

import json
from pathlib import Path

import meshio
import numpy as np
import pytest
from fem_parts import bar

from crankmodal.errors import SceneError
from crankmodal.fem import material_stage, modal_stage, static_stage
from crankmodal.fem.materials import library, material
from crankmodal.results import to_jsonable
from crankmodal.runner import StageContext
from crankmodal.scene import Scene

SCENE = Scene(name="t", base_dir=Path("."))


@pytest.fixture
def ctx(tmp_path):
    c = StageContext(scene=SCENE, out_dir=tmp_path, figures=False)
    c.products["geometry"] = bar(1.0, 0.05, 0.04, (16, 2, 2))
    material_stage.run(material_stage.validate({"name": "steel"}, SCENE), c)
    return c


def test_library_holds_the_seed_materials_with_their_published_constants():
    sg = material("sg 700/2")  # seed 004 Table 2
    assert (sg.E, sg.nu, sg.rho) == (176e9, 0.275, 7200.0)
    crank = material("crank_steel_seed000")  # seed 000 §2.4
    assert (crank.E, crank.nu, crank.rho) == (2.1e11, 0.266, 7820.0)
    # seed 000 Table 2 ultimate strengths, MPa
    for name, su in (("ZL108", 195), ("20CrMnTi", 735), ("42CrMo", 930), ("GCr15", 520),
                     ("AlSn20Cu", 45)):
        assert material(name).ultimate_strength == su * 1e6
    for name in library():
        m = material(name)
        assert 0 < m.yield_strength <= m.ultimate_strength


def test_unknown_material_names_the_value_and_the_choices():
    with pytest.raises(SceneError, match=r"material.name: unknown material 'unobtainium'.*SG 700/2"):
        material_stage.validate({"name": "unobtainium"}, SCENE)


def test_explicit_constants_override_a_named_material_and_bad_ones_are_refused():
    p = material_stage.validate({"name": "steel", "E": 2.0e11}, SCENE)
    assert material_stage.make_material(p).E == 2.0e11
    with pytest.raises(SceneError, match="material.nu"):
        material_stage.validate({"E": 2e11, "nu": 0.5, "rho": 7800}, SCENE)
    with pytest.raises(SceneError, match="material.rho: is required"):
        material_stage.validate({"E": 2e11, "nu": 0.3}, SCENE)


def test_modal_stage_writes_fixed_result_keys_and_a_vtu_with_one_array_per_mode(ctx):
    res = modal_stage.run(modal_stage.validate({"n_modes": 5, "band": [10, 1000]}, SCENE), ctx)
    assert res["band_complete"] is True  # the fifth mode is at 1122 Hz
    assert res["rigid_body_modes"] == 6 and res["n_dofs"] == 3 * ctx.products["geometry"].n_nodes
    f = np.asarray(res["frequencies_hz"])
    assert len(f) == 5 and np.all(np.diff(f) >= 0)
    assert res["classes"][0] == "bending about y"
    for key in ("n_elements", "effective_mass", "timings_s", "peak_memory_bytes", "residual_max"):
        assert key in res
    json.dumps(to_jsonable(res))
    vtu = meshio.read(res["vtu"])
    assert len(vtu.point_data) == 5 and vtu.cells[0].type == "tetra10"


def test_a_band_reaching_above_the_modes_computed_is_flagged_as_incomplete(ctx):
    """The modes are the lowest n_modes: above the highest there may be more inside the band."""
    import warnings

    from crankmodal.errors import ModelWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = modal_stage.run(modal_stage.validate({"n_modes": 3, "band": [10, 1e5]}, SCENE), ctx)
    f3 = res["frequencies_hz"][-1]
    assert res["band_complete"] is False
    assert any(f"reach {f3:.1f} Hz, below the band's 100000 Hz" in w for w in res["warnings"])
    assert any(issubclass(w.category, ModelWarning) for w in caught)
    # a band whose top lies below the highest mode computed holds every mode inside it
    res = modal_stage.run(modal_stage.validate({"n_modes": 3, "band": [10, 0.99 * f3]}, SCENE),
                          ctx)
    assert res["band_complete"] is True and not any("modal.band" in w for w in res["warnings"])
    assert len(res["frequencies_in_band_hz"]) == 2


def test_supported_modal_and_static_stages_from_scene_tables(ctx):
    res = modal_stage.run(modal_stage.validate(
        {"n_modes": 3, "supports": [{"box": [-1, 1e-9, -1, 1, -1, 1], "fix": "xyz"}]}, SCENE), ctx)
    assert res["rigid_body_modes"] == 0
    st = static_stage.run(static_stage.validate(
        {"supports": [{"region": "end_x0"}],
         "loads": [{"region": "end_x1", "force": [0, 0, -100.0]}]}, SCENE), ctx)
    assert st["max_von_mises_pa"] > 0 and st["safety_factor_yield"] > 1
    assert Path(st["vtu"]).exists()
    json.dumps(to_jsonable(st))


@pytest.mark.parametrize("raw, match", [
    ({"supports": [{"region": "main_journal_9", "fix": "radial"}]},
     r"modal.supports\[0\].region: no region 'main_journal_9'"),
    ({"supports": [{"box": [0, 1, 0, 1, 5, 6], "fix": "x"}]}, r"modal.supports\[0\]: selects no node"),
    ({"supports": [{"region": "end_x0", "fix": "radial"}]},  # a flat face is no bore
     r"modal.supports\[0\].fix: 'radial' needs a cylindrical region; region 'end_x0' is flat"),
])
def test_supports_that_select_nothing_name_the_entry(ctx, raw, match):
    with pytest.raises(SceneError, match=match):
        modal_stage.run(modal_stage.validate({"n_modes": 2, **raw}, SCENE), ctx)


@pytest.mark.parametrize("raw, match", [
    ({"supports": [{"region": "a", "fix": "q"}]}, r"modal.supports\[0\].fix: fix must be"),
    ({"supports": [{"box": [0, 1, 0, 1], "fix": "x"}]}, r"modal.supports\[0\].box"),
    ({"supports": [{"box": [0, 1, 0, 1, 0, 1], "fix": "radial"}]}, "radial"),
    ({"supports": [{"region": "a", "box": [0, 1, 0, 1, 0, 1]}]}, "exactly one"),
    ({"n_modes": 0}, "modal.n_modes"),
    ({"backend": "mumps"}, "modal.backend"),
    ({"band": [2000, 10]}, "modal.band"),
])
def test_malformed_modal_tables_are_refused_before_running(raw, match):
    with pytest.raises(SceneError, match=match):
        modal_stage.validate(raw, SCENE)


@pytest.mark.parametrize("raw, match", [
    ({"supports": [{"region": "end_x0"}]}, "static.loads: is required"),
    ({"loads": [{"region": "end_x1", "pressure": 1e5}]}, "static.supports: is required"),
    ({"supports": [{"region": "end_x0"}], "loads": [{"region": "end_x1", "force": [1, 2]}]},
     r"static.loads\[0\].force"),
    ({"supports": [{"region": "end_x0"}], "loads": [{"region": "end_x1", "pressure": 1, "force": [1, 2, 3]}]},
     "exactly one"),
    ({"supports": [{"region": "end_x0"}], "loads": [{"region": "end_x1", "bearing_force": [1, 2]}]},
     r"static.loads\[0\].bearing_force: must be 3 numbers"),
])
def test_malformed_static_tables_are_refused(raw, match):
    with pytest.raises(SceneError, match=match):
        static_stage.validate(raw, SCENE)


def test_static_stage_refuses_a_mechanism_and_unknown_load_region(ctx):
    p = static_stage.validate({"supports": [{"region": "end_x0", "fix": "x"}],
                               "loads": [{"region": "end_x1", "pressure": 1e5}]}, SCENE)
    with pytest.raises(SceneError, match="mechanism"):
        static_stage.run(p, ctx)
    p = static_stage.validate({"supports": [{"region": "end_x0"}],
                               "loads": [{"region": "crankpin", "pressure": 1e5}]}, SCENE)
    with pytest.raises(SceneError, match=r"static.loads\[0\].region: no region 'crankpin'"):
        static_stage.run(p, ctx)
    p = static_stage.validate({"supports": [{"region": "end_x0"}],
                               "loads": [{"region": "end_x1", "bearing_force": [0, 1e3, 0]}]}, SCENE)
    with pytest.raises(SceneError, match=r"static.loads\[0\].bearing_force: needs a cylindrical "
                                         r"region; region 'end_x1' is flat"):
        static_stage.run(p, ctx)  # a flat end face has no bore to press on
