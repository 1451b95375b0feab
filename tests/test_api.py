"""The package's public names: every one resolves, and importing the package stays light."""

import json
import subprocess
import sys

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
    assert json.loads(out) == ["crankmodal.fem.modal", "Part", "crankmodal.dynamics.analysis"]
    with pytest.raises(AttributeError, match="no attribute 'no_such_thing'"):
        crankmodal.no_such_thing  # noqa: B018


def test_the_core_objects_the_readme_composes_are_the_expected_kinds():
    # a name bound to the wrong object (e.g. the reduced .npz body where the multibody body is
    # meant) would still resolve; the two flexible-body types are distinct on purpose
    assert crankmodal.FlexibleBody.__module__ == "crankmodal.dynamics.flexible"
    assert crankmodal.ReducedBody.__module__ == "crankmodal.reduction.flexbody"
    assert crankmodal.Cylinder.__module__ == "crankmodal.dynamics.mechanisms"
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
