"""Issue 20: core functions name their argument (ParameterError); the stage that read the value
from a scene names the scene key (SceneError) with the same text. Materials, the factorisation
backend and the mesh-size refusal (the torsion, reduction and FE-solve cores have theirs next to
their own tests)."""

from pathlib import Path

import pytest
from fem_parts import bar

from crankmodal.errors import ParameterError, SceneError
from crankmodal.scene import Scene

SCENE = Scene(name="t", base_dir=Path("."))


def _core(call, argument, text):
    with pytest.raises(ParameterError) as info:
        call()
    assert not isinstance(info.value, SceneError)
    assert info.value.argument == argument and info.value.text == text
    assert str(info.value) == f"{argument}: {text}"


# --- materials ----------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, argument, text", [
    ({"E": -1.0}, "E", "must be > 0 Pa, got -1.0 (mine)"),
    ({"nu": 0.5}, "nu", "must be in (-1, 0.5), got 0.5 (mine)"),
    ({"rho": 0.0}, "rho", "must be > 0 kg/m^3, got 0.0 (mine)"),
    ({"yield_strength": -3.0}, "yield_strength", "must be > 0 Pa, got -3.0 (mine)"),
])
def test_material_names_its_argument(kwargs, argument, text):
    from crankmodal.fem.materials import Material

    _core(lambda: Material("mine", **{"E": 2.1e11, "nu": 0.3, "rho": 7850.0, **kwargs}),
          argument, text)


def test_material_by_name_names_the_argument_and_the_stage_the_key():
    from crankmodal.fem import material_stage
    from crankmodal.fem.materials import library, material

    text = f"unknown material 'unobtainium'; known: {', '.join(library())}"
    _core(lambda: material("unobtainium"), "name", text)
    with pytest.raises(SceneError) as info:
        material_stage.validate({"name": "unobtainium"}, SCENE)
    assert str(info.value) == f"material.name: {text}"


def test_the_material_stage_names_the_scene_key_of_a_bad_constant():
    """The schema refuses these first in a scene; make_material of a table that skipped it
    (or a library entry out of range) still names the scene key."""
    from crankmodal.fem import material_stage

    with pytest.raises(SceneError) as info:
        material_stage.make_material({"E": 2e11, "nu": 0.6, "rho": 7800.0})
    assert str(info.value) == "material.nu: must be in (-1, 0.5), got 0.6 (custom)"
    with pytest.raises(SceneError) as info:
        material_stage.make_material({"name": "steel", "rho": -1.0})
    assert str(info.value).startswith("material.rho: must be > 0 kg/m^3, got -1.0 (")


# --- factorisation backend ----------------------------------------------------------------------

def test_the_backend_names_its_argument(monkeypatch):
    from crankmodal.fem import solvers

    _core(lambda: solvers.resolve_backend("mumps"), "backend",
          "must be one of auto, pardiso, superlu; got 'mumps'")
    monkeypatch.setattr(solvers, "available_backends", lambda: ["superlu"])
    _core(lambda: solvers.resolve_backend("pardiso"), "backend",
          "'pardiso' is not installed (pip install pypardiso); available: superlu")


def test_the_static_stage_names_the_scene_key_of_a_backend_not_installed(tmp_path, monkeypatch):
    """Before: 'backend: ...' without the section (the core spoke half a scene key)."""
    from crankmodal.fem import material_stage, solvers, static_stage
    from crankmodal.runner import StageContext

    ctx = StageContext(scene=SCENE, out_dir=tmp_path, figures=False)
    ctx.products["geometry"] = bar(0.1, 0.02, 0.02, (4, 1, 1), order=1)
    material_stage.run(material_stage.validate({"name": "steel"}, SCENE), ctx)
    monkeypatch.setattr(solvers, "available_backends", lambda: ["superlu"])
    p = static_stage.validate({"supports": [{"region": "end_x0"}], "backend": "pardiso",
                               "loads": [{"region": "end_x1", "pressure": 1e5}], "vtu": False},
                              SCENE)
    with pytest.raises(SceneError) as info:
        static_stage.run(p, ctx)
    assert str(info.value) == ("static.backend: 'pardiso' is not installed (pip install "
                               "pypardiso); available: superlu")


# --- mesh size ----------------------------------------------------------------------------------

def test_the_element_count_refusal_names_size_and_the_geometry_stage_its_scene_key():
    """check_size (build_part, import_cad) and check_size_floor (the stage's check) named
    'geometry.mesh_size' from the core; now 'size', and the stage words it as before."""
    import pickle

    from crankmodal.errors import ResourceError
    from crankmodal.geometry.mesh import MeshSettings, MeshSizeError, check_size, check_size_floor
    from crankmodal.geometry.params import params_from_dict
    from crankmodal.resources import load_machine

    settings = MeshSettings(size=1e-4, max_elements=5e6, limit_reason="the limit")
    with pytest.raises(ParameterError) as info:
        check_size(1.037e-3, 0.1035, settings)
    exc = info.value
    assert isinstance(exc, MeshSizeError) and isinstance(exc, ResourceError)
    assert not isinstance(exc, SceneError) and exc.argument == "size"
    # 8.5 V/h^3 + 17.5 A/h^2 = 8.8e9 + 0.18e9
    assert str(exc) == ("size: 0.0001 m makes about 9e+09 tetrahedra (V = 1037 cm3, "
                        "A = 1035 cm2), over the limit of 5e+06 (the limit); use size >= 0.0013 m")
    assert exc.worded("geometry.mesh_size", "geometry.params.") == (
        "geometry.mesh_size = 0.0001 m: about 9e+09 tetrahedra (V = 1037 cm3, A = 1035 cm2), "
        "over the limit of 5e+06 (the limit); use mesh_size >= 0.0013 m")
    assert str(pickle.loads(pickle.dumps(exc))) == str(exc)  # a study's worker raises it

    rod = params_from_dict("rod", load_machine("four_star_compressor")["rod"], where="rod")
    with pytest.raises(MeshSizeError) as info:
        check_size_floor(rod, settings)
    assert str(info.value).startswith("size: 0.0001 m makes at least 3.1e+08 tetrahedra (6 V/h^3, "
                                      "V >= 51.35 cm3, most of it the big end: "
                                      "big_end_outer_diameter = 0.075 m, big_end_width = 0.015 m)")
    assert info.value.worded("geometry.mesh_size", "geometry.params.").startswith(
        "geometry.mesh_size = 0.0001 m: at least 3.1e+08 tetrahedra (6 V/h^3, V >= 51.35 cm3, "
        "most of it the big end: geometry.params.big_end_outer_diameter = 0.075 m, "
        "geometry.params.big_end_width = 0.015 m), over the limit of 5e+06 (the limit); "
        "use mesh_size >= ")


def test_the_geometry_stage_refuses_the_mesh_size_in_its_scene_words(tmp_path, monkeypatch):
    from crankmodal.errors import ResourceError
    from crankmodal.geometry import build, stage
    from crankmodal.scene import scene_from_dict

    raw = {"machine": "four_star_compressor", "part": "rod", "mesh_size": 1e-4}
    with pytest.raises(SceneError, match=r"^geometry\.mesh_size = 0\.0001 m: at least 3\.1e\+08 "
                                         r"tetrahedra .* geometry\.params\.big_end_width = "):
        stage.validate(raw, scene_from_dict({"geometry": raw}, name="t"))
    # the closer estimate on the CAD solid, before gmsh meshes (build_part's check_size)
    monkeypatch.setattr(build, "generate", lambda *a, **k: pytest.fail("meshed"))
    raw = {**raw, "mesh_size": 0.01, "cache": False}
    p = stage.validate(raw, scene_from_dict({"geometry": raw}, name="t"))
    monkeypatch.setattr(stage, "mesh_settings", lambda p: build.MeshSettings(  # above the floor
        size=p["mesh_size"], order=1, max_elements=1000, limit_reason="a thousand"))
    with pytest.raises(ResourceError, match=r"^geometry\.mesh_size = 0\.01 m: about [\d.e+]+ "
                                            r"tetrahedra \(V = .*\(a thousand\); use mesh_size >= "):
        stage.make_part(p)


def test_a_study_model_refuses_the_mesh_size_in_the_scene_words(tmp_path, monkeypatch):
    """The report study builds its parts with build_part: its refusal reads as before
    ('geometry.mesh_size = ...'), not the core's 'size: ...'."""
    from crankmodal.errors import ResourceError
    from crankmodal.geometry import build, stage
    from crankmodal.report.study_scene import solve_model
    from crankmodal.scene import scene_from_dict

    monkeypatch.setattr(build, "generate", lambda *a, **k: pytest.fail("meshed"))
    raw = {"machine": "four_star_compressor", "part": "rod", "mesh_size": 0.01}
    g = stage.validate(raw, scene_from_dict({"geometry": raw}, name="t"))
    with pytest.raises(ResourceError, match=r"^geometry\.mesh_size = 0\.0001 m: about [\d.e+]+ "
                                            r"tetrahedra \(V = .*; use mesh_size >= "):
        solve_model(tmp_path, g, {}, {"name": "steel"}, "simplified", 1e-4, 1, 4)


@pytest.mark.parametrize("fidelity, settings, argument, text", [
    ("coarse", {"size": 0.01}, "fidelity",
     "must be one of full, dechamfered, simplified; got 'coarse'"),
    ("full", {"size": 0.0}, "size", "must be > 0 m, got 0.0"),
    ("full", {"size": 0.01, "order": 3}, "order", "must be 1 or 2, got 3"),
    ("full", {"size": 0.01, "refine": 1.5}, "refine", "must be in (0, 1], got 1.5"),
])
def test_build_part_names_its_argument(fidelity, settings, argument, text):
    """Before: GeometryError 'geometry.fidelity: ...', 'geometry.mesh_size: ...' from the core."""
    from crankmodal.geometry.build import build_part
    from crankmodal.geometry.mesh import MeshSettings
    from crankmodal.geometry.params import params_from_dict
    from crankmodal.resources import load_machine

    rod = params_from_dict("rod", load_machine("four_star_compressor")["rod"], where="rod")
    _core(lambda: build_part(rod, fidelity, MeshSettings(**settings)), argument, text)


def test_the_geometry_stage_names_the_scene_key_of_a_mesh_setting(monkeypatch):
    """The schema refuses these first in a scene; settings that skipped it still read as the
    scene's keys (geometry.element_order)."""
    from crankmodal.geometry import build, stage
    from crankmodal.scene import scene_from_dict

    raw = {"machine": "four_star_compressor", "part": "rod", "cache": False}
    p = stage.validate(raw, scene_from_dict({"geometry": raw}, name="t"))
    monkeypatch.setattr(stage, "mesh_settings", lambda p: build.MeshSettings(size=0.01, order=3))
    with pytest.raises(SceneError) as info:
        stage.make_part(p)
    assert str(info.value) == "geometry.element_order: must be 1 or 2, got 3"


def test_a_parameter_error_survives_pickling():
    # a Dask worker sends the exception it raised back to the client
    import pickle

    from crankmodal.errors import ParameterError

    err = pickle.loads(pickle.dumps(ParameterError("n_modes", "must be >= 1, got 0")))
    assert type(err) is ParameterError
    assert (err.argument, err.text, str(err)) == ("n_modes", "must be >= 1, got 0",
                                                  "n_modes: must be >= 1, got 0")
