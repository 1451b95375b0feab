"""Bad arguments of the modal solve: the core names its argument (ParameterError), a stage that
read the value from a scene names the scene key (SceneError), with the same text."""

from pathlib import Path

import pytest
from fem_parts import bar

from crankmodal.errors import ParameterError, SceneError
from crankmodal.fem import assembly, material_stage, modal, modal_stage
from crankmodal.fem.materials import material
from crankmodal.runner import StageContext
from crankmodal.scene import Scene

SCENE = Scene(name="t", base_dir=Path("."))
TINY = (0.1, 0.02, 0.02, (4, 1, 1))  # 60 free DOF, 54 elastic modes


@pytest.fixture(scope="module")
def tiny_model():
    return assembly.assemble(bar(*TINY, order=1), material("steel"))


@pytest.mark.parametrize("kwargs, argument, text", [
    ({"n_modes": 0}, "n_modes", "must be >= 1, got 0"),
    ({"n_modes": 55}, "n_modes", ("55 elastic modes asked, but the part has only 54 (60 free DOF "
                                 "less 6 rigid-body modes); ask for at most 54, or refine the mesh")),
    ({"n_modes": 4, "eigensolver": "arpack"}, "eigensolver",
     "must be auto, lanczos or dense; got 'arpack'"),
    ({"n_modes": 54, "eigensolver": "lanczos"}, "eigensolver",
     "Lanczos cannot find 60 pairs of 60 DOF; use 'dense' or 'auto'"),
    ({"n_modes": 4, "shift": 1.0}, "shift", "must be < 0, got 1.0"),
    ({"n_modes": 4, "shift": float("nan"), "eigensolver": "dense"}, "shift", "must be < 0, got nan"),
])
def test_the_core_names_its_argument_not_a_scene_key(tiny_model, kwargs, argument, text):
    with pytest.raises(ParameterError) as info:
        modal.solve_modes(tiny_model, **kwargs)
    assert not isinstance(info.value, SceneError)
    assert info.value.argument == argument and info.value.text == text
    assert str(info.value) == f"{argument}: {text}"


@pytest.fixture
def tiny_ctx(tmp_path):
    c = StageContext(scene=SCENE, out_dir=tmp_path, figures=False)
    c.products["geometry"] = bar(*TINY, order=1)
    material_stage.run(material_stage.validate({"name": "steel"}, SCENE), c)
    return c


@pytest.mark.parametrize("raw, message", [
    ({"n_modes": 55}, ("modal.n_modes: 55 elastic modes asked, but the part has only 54 (60 free "
                      "DOF less 6 rigid-body modes); ask for at most 54, or refine the mesh")),
    ({"n_modes": 54, "eigensolver": "lanczos"},
     "modal.eigensolver: Lanczos cannot find 60 pairs of 60 DOF; use 'dense' or 'auto'"),
])
def test_the_modal_stage_names_the_scene_key_with_the_same_text(tiny_ctx, raw, message):
    with pytest.raises(SceneError) as info:
        modal_stage.run(modal_stage.validate({"vtu": False, **raw}, SCENE), tiny_ctx)
    assert str(info.value) == message
