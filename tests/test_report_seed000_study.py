"""Seed 000 Table 3 trend on the reconstructed four-star crankshaft (slow: gmsh builds)."""

import json

import pytest

from crankmodal.scene import load_scene

pytestmark = pytest.mark.slow


def test_seed000_dechamfered_crank_within_2_percent_simplified_within_6_and_2nd_bending_lower(tmp_path):
    from conftest import SCENES

    from crankmodal.report.study_scene import simplification_study

    scene = load_scene(SCENES / "seed000_crank_study.toml",
                       ["report.study_sizes=[0.02, 0.014]", "report.study_orders=[2]",
                        "report.study_modes=3", "report.tolerance=0.05"])
    out = simplification_study(scene, tmp_path, figures=True)
    runs = {(r["fidelity"], r["mesh_size"]): r for r in out["runs"]}
    full, dech, simp = (runs[(f, 0.014)] for f in ("full", "dechamfered", "simplified"))
    # seed Table 3: 1336/1461 (full), 1321/1461 (de-chamfered), 1266/1405 (simplified) Hz
    for k in range(2):
        assert abs(dech["matched_hz"][k] / full["matched_hz"][k] - 1) < 0.02
        # the seed's simplified model is 5.2 / 3.8 % low; the reconstruction's simplifications
        # take mass and stiffness away nearly in proportion: within the seed's 6 % either way
        assert abs(simp["matched_hz"][k] / full["matched_hz"][k] - 1) < 0.06
    assert simp["matched_hz"][1] < full["matched_hz"][1]  # second bending: lower, as in the seed
    assert full["n_elements"] > 1.5 * simp["n_elements"]
    rec = out["runs"][out["recommended"]]
    assert rec["error"] <= 0.05
    assert all(r["error"] > 0.05 for r in out["runs"] if r["wall_time_s"] < rec["wall_time_s"])
    assert json.loads((tmp_path / "study.json").read_text())["recommended"] == out["recommended"]
    assert (tmp_path / "error_vs_time.png").is_file()
