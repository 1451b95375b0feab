"""The package's public names: every one resolves, and importing the package stays light."""

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import crankmodal

HEAVY = ("gmsh", "skfem", "pyvista", "matplotlib", "meshio", "numba", "dask")


def _fresh(code: str) -> str:
    """Run ``code`` in a new interpreter (nothing imported yet) and return its stdout."""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


def test_import_crankmodal_loads_no_heavy_dependency():
    out = _fresh("import sys, json, crankmodal; "
                 f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))")
    assert json.loads(out) == []


def test_every_exported_name_resolves_to_its_home_module_object():
    import importlib

    assert len(crankmodal._EXPORTS) >= 40
    for name, (module, attr) in crankmodal._EXPORTS.items():
        value = getattr(crankmodal, name)
        assert value is getattr(importlib.import_module(module), attr), name
        assert name in dir(crankmodal)
    assert set(crankmodal.__all__) == {"__version__", *crankmodal._EXPORTS}


def test_star_import_gives_the_public_names_and_an_unknown_name_is_an_attribute_error():
    out = _fresh("from crankmodal import *; import json; "
                 "print(json.dumps([solve_modes.__module__, Part.__name__, simulate.__module__]))")
    assert json.loads(out) == ["crankmodal.fem.modal", "Part", "crankmodal.dynamics.run.simulate"]
    with pytest.raises(AttributeError, match="no attribute 'no_such_thing'"):
        crankmodal.no_such_thing  # noqa: B018


def test_the_core_objects_the_readme_composes_are_the_expected_kinds():
    # a name bound to the wrong object (e.g. the reduced .npz body where the multibody body is
    # meant) would still resolve; the two flexible-body types are distinct on purpose
    assert crankmodal.FlexibleBody.__module__ == "crankmodal.dynamics.flexible.body"
    assert crankmodal.ReducedBody.__module__ == "crankmodal.reduction.flexbody"
    assert crankmodal.Cylinder.__module__ == "crankmodal.dynamics.model.mechanisms"
    # the geometric cylinder (a bore or journal surface) is the other "cylinder"
    assert crankmodal.CylindricalSurface.__module__ == "crankmodal.part"
    assert crankmodal.CylindricalSurface is not crankmodal.Cylinder
    assert issubclass(crankmodal.SceneError, crankmodal.CrankmodalError)
    assert callable(crankmodal.run_scene) and callable(crankmodal.select_supports)


def test_a_subpackage_not_yet_imported_is_reachable_as_an_attribute():
    out = _fresh("import crankmodal, json; "
                 "print(json.dumps([crankmodal.resources.__name__, "
                 "crankmodal.scene_path('seed004_torsion').name]))")
    assert json.loads(out) == ["crankmodal.resources", "seed004_torsion.toml"]


GUIDE = Path(__file__).resolve().parent.parent / "docs" / "guide" / "python_api.md"


def python_blocks(text: str) -> list[str]:
    """The ```python blocks of a Markdown page, in order."""
    return re.findall(r"^```python\n(.*?)^```", text, re.DOTALL | re.MULTILINE)


def test_python_blocks_are_found_in_order():
    text = "# t\n```python\nA = 1\n```\ntext\n```toml\nx = 1\n```\n```python\nB = 2\n```\n"
    assert python_blocks(text) == ["A = 1\n", "B = 2\n"]


def test_the_python_api_page_uses_only_exported_names():
    code = "\n".join(python_blocks(GUIDE.read_text(encoding="utf-8")))
    assert "import crankmodal as cm" in code
    used = set(re.findall(r"\bcm\.(\w+)", code))
    assert used and used <= set(crankmodal.__all__), sorted(used - set(crankmodal.__all__))
    assert not re.search(r"^\s*(from|import) crankmodal\.", code, re.MULTILINE)


@pytest.mark.slow
def test_the_python_api_page_runs_as_printed(tmp_path, monkeypatch):
    """Every block of docs/guide/python_api.md, in order, in one namespace, in a temporary
    folder; each asserts its numbers against the oracle stated beside it (CAD mass, F/A,
    Rayleigh-Ritz, the two-rotor closed form, the slider-crank's force at top dead centre with
    and without the crank's own mass, the quasi-static start against the rigid twin)."""
    blocks = python_blocks(GUIDE.read_text(encoding="utf-8"))
    assert len(blocks) >= 7
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {"__name__": "python_api_guide"}
    for i, code in enumerate(blocks, start=1):
        exec(compile(code, f"docs/guide/python_api.md block {i}", "exec"), namespace)  # noqa: S102
