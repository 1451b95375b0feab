"""The [torsion] scene section: inputs, results.json, errors, and what a chain scene imports."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from crankmodal.errors import SceneError
from crankmodal.runner import check, run
from crankmodal.scene import load_scene, scene_from_dict

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def _run(tmp_path, table, figures=False):
    return run(scene_from_dict({"torsion": table}, name="t"), tmp_path, figures=figures)["torsion"]


def test_chain_scene_writes_fixed_result_names_and_figures(tmp_path):
    res = run(load_scene(SCENES / "torsion_chain.toml"), tmp_path, figures=True)
    t = json.loads((tmp_path / "results.json").read_text())["torsion"]
    assert t == json.loads(json.dumps(t))
    # three rotors free-free: two elastic modes, ascending, Holzer = eigen
    assert len(t["exact_hz"]) == 2 and t["exact_hz"][0] < t["exact_hz"][1]
    np.testing.assert_allclose(t["holzer_hz"], t["exact_hz"], rtol=1e-8)
    assert isinstance(t["two_rotor_hz"], float)
    assert [len(n) for n in t["nodes"]] == [1, 2]
    assert len(t["mode_shapes"]) == 2 and len(t["mode_shapes"][0]) == 3
    assert t["critical_speeds"]["orders"][0] == 0.5  # four-stroke
    for name in ("torsion_holzer_residual.png", "torsion_mode_shapes.png", "torsion_campbell.png",
                 "torsion_holzer_tables.txt"):
        assert (tmp_path / name).stat().st_size > 0
    assert "summary" in res["torsion"]


def test_segments_of_one_shaft_give_same_frequencies_as_stiffnesses(tmp_path):
    G, d, L = 8.0e10, 0.05, 0.4
    k = G * np.pi / 32 * d**4 / L
    seg = {"inertias": [0.3, 0.6, 0.18], "G": G,
           "segments": [{"diameter": d, "length": L}, {"diameter": d, "length": L / 2}]}
    a = _run(tmp_path / "a", seg)
    b = _run(tmp_path / "b", {"inertias": [0.3, 0.6, 0.18], "stiffnesses": [k, 2 * k]})
    np.testing.assert_allclose(a["exact_hz"], b["exact_hz"], rtol=1e-12)
    assert "position_m" in a["nodes"][0][0] and "position_m" not in b["nodes"][0][0]


def test_fixed_end_chain_has_no_rigid_mode_and_no_two_rotor(tmp_path):
    # one rotor on a spring to a wall: omega^2 = k / I
    res = _run(tmp_path, {"inertias": [2.0], "stiffnesses": [8.0e4], "fixed_end": True})
    assert res["exact_hz"] == pytest.approx([np.sqrt(4.0e4) / (2 * np.pi)], rel=1e-12)
    assert res["holzer_hz"] == pytest.approx(res["exact_hz"], rel=1e-12)
    assert res["two_rotor_hz"] is None and res["rigid_body_modes"] == 0


@pytest.mark.parametrize(
    "table, key",
    [
        ({"inertias": [0.3, -0.6], "stiffnesses": [1e5]}, r"torsion\.inertias\[1\]"),
        ({"inertias": [0.3, 0.6], "stiffnesses": [0.0]}, r"torsion\.stiffnesses\[0\]"),
        ({"inertias": [0.3, 0.6, 0.1], "stiffnesses": [1e5]}, r"torsion\.stiffnesses"),
        ({"inertias": [0.3, 0.6], "stiffnesses": [1e5], "speed_range_rpm": [900.0, 900.0]},
         r"torsion\.speed_range_rpm"),
        ({"inertias": [0.3, 0.6], "stiffnesses": [1e5], "operating_speed_rpm": -3.0},
         r"torsion\.operating_speed_rpm"),
        ({"inertias": [0.3, 0.6]}, r"torsion\.stiffnesses"),
        ({"stiffnesses": [1e5]}, r"torsion\.inertias"),
        ({"inertias": [0.3, 0.6], "segments": [{"diameter": 0.05, "length": 0.2}]}, r"torsion\.segments\[0\]\.G"),
        ({"inertias": [0.3, 0.6, 0.2], "G": 8e10, "segments": [{"diameter": 0.05, "length": 0.2}]},
         r"torsion\.segments"),
        ({"machine": "multi_bearing_compressor", "inertias": [0.3, 0.6], "stiffnesses": [1e5]},
         r"torsion\.inertias"),
        ({"machine": "multi_bearing_compressor", "throw": {"crankpin_bore": 0.2}}, r"torsion\.throw\.crankpin_bore"),
        ({"inertias": [0.3, 0.6], "stiffnesses": [1e5], "order_type": "rotary"}, r"torsion\.order_type"),
        ({"inertias": [0.3, 0.6], "stiffnesses": [1e5], "omega": 3}, r"torsion\.omega"),
        ({"machine": "multi_bearing_compressor", "fixed_end": True}, r"torsion\.fixed_end"),
    ],
)
def test_bad_torsion_input_raises_scene_error_naming_key(table, key):
    with pytest.raises(SceneError, match=key):
        check(scene_from_dict({"torsion": table}, name="bad"))


@pytest.mark.parametrize(
    "table, message",
    [
        ({"inertias": [0.3, 0.6, 0.1], "stiffnesses": [1e5]},
         "torsion.stiffnesses: needs 2 entries for 3 inertias (free at both ends), got 1"),
        ({"inertias": [0.3], "stiffnesses": [1e5]},
         "torsion.inertias: a free-free chain needs at least 2 rotors, got 1"),
        ({"inertias": [0.3, 0.6], "stiffnesses": [1e5], "max_order": 0.4},
         "torsion.max_order: must be >= 1 for compressor, got 0.4"),
    ],
)
def test_the_stage_names_the_scene_key_of_a_core_parameter_error(table, message):
    """The chain and the orders raise ParameterError by argument; the stage re-raises it under
    the scene key with the same text (issue 20)."""
    with pytest.raises(SceneError) as info:
        check(scene_from_dict({"torsion": table}, name="bad"))
    assert str(info.value) == message


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("two_rotor_flywheel", "middle",
         "torsion.two_rotor_flywheel: must be auto, first or last; got 'middle'"),
        ("operating_speed_rpm", -3.0, "torsion.operating_speed_rpm: must be > 0, got -3.0"),
    ],
)
def test_the_stage_maps_core_arguments_to_their_scene_keys(tmp_path, key, value, message):
    """reduce_to_two_rotors(flywheel=) and critical_speeds(operating_rpm=) are named by their
    scene keys when the stage calls them (the schema refuses these values first in a scene; here
    the validated table is altered to reach the core)."""
    from crankmodal.runner import StageContext
    from crankmodal.scene import Scene
    from crankmodal.torsion import stage

    scene = Scene(name="t", base_dir=Path("."))
    p = stage.validate({"inertias": [0.3, 0.6], "stiffnesses": [1e5],
                        "speed_range_rpm": [0.0, 3000.0]}, scene)
    p[key] = value
    with pytest.raises(SceneError) as info:
        stage.run(p, StageContext(scene=scene, out_dir=tmp_path, figures=False))
    assert str(info.value) == message


def test_cli_bad_chain_exits_2_with_one_line_and_no_results(tmp_path, cli):
    out = tmp_path / "out"
    p = cli("run", SCENES / "torsion_chain.toml", "--out", out, "--set", "torsion.inertias=[0.3, 0.0, 0.18]")
    assert p.returncode == 2
    assert p.stderr.strip().splitlines()[-1].startswith("crankmodal: error: torsion.inertias[1]")
    assert "Traceback" not in p.stderr
    assert not (out / "results.json").exists()


def test_chain_scene_in_fresh_process_imports_no_gmsh_skfem_pyvista(tmp_path):
    code = (
        "import sys, json\n"
        "from crankmodal.scene import load_scene\n"
        "from crankmodal.runner import run\n"
        f"run(load_scene({str(SCENES / 'torsion_chain.toml')!r}), {str(tmp_path)!r}, figures=True)\n"
        "print(json.dumps(sorted(m for m in ('gmsh', 'skfem', 'pyvista') if m in sys.modules)))\n"
    )
    p = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, MPLBACKEND="Agg"))
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout.strip().splitlines()[-1]) == []
    assert (tmp_path / "torsion_campbell.png").exists()
