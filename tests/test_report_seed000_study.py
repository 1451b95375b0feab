"""Seed 000 Table 3 trend on the reconstructed four-star crankshaft (slow: gmsh builds)."""

import json

import pytest

from crankmodal.scene import load_scene

pytestmark = pytest.mark.slow


def test_seed000_dechamfered_crank_within_2_percent_and_simplified_2_to_8_percent_lower(tmp_path):
    from conftest import SCENES

    from crankmodal.report.study_scene import simplification_study

    scene = load_scene(SCENES / "seed000_crank_study.toml",
                       ["report.study_sizes=[0.02, 0.014]", "report.study_orders=[2]",
                        "report.study_modes=3", "report.tolerance=0.05"])
    out = simplification_study(scene, tmp_path, figures=True)
    runs = {(r["fidelity"], r["mesh_size"]): r for r in out["runs"]}
    full, dech, simp = (runs[(f, 0.014)] for f in ("full", "dechamfered", "simplified"))
    # seed Table 3, orders 1-3: de-chamfered -1.1 / 0.0 / +0.2 % of full; simplified (peripheral
    # details) -5.2 / -3.8 / -5.5 %. Ours: the envelope webs add mass at the web periphery, so
    # every order falls; the band 1.5-8 % holds the seed's values and fails a mass-keeping
    # simplification (< 0.5 %, the previous builder) as well as a broken one.
    for k in range(3):
        assert abs(dech["matched_hz"][k] / full["matched_hz"][k] - 1) < 0.02
        assert 0.92 < simp["matched_hz"][k] / full["matched_hz"][k] < 0.985
    # the seed's full and simplified meshes differ "by a factor of nearly 10"; at one mesh size
    # ours differ by the refinement of fillets, chamfers and drillings alone (about 3x)
    assert full["n_elements"] > 2.5 * simp["n_elements"]
    rec = out["runs"][out["recommended"]]
    assert rec["error"] <= 0.05
    assert all(r["error"] > 0.05 for r in out["runs"] if r["wall_time_s"] < rec["wall_time_s"])
    assert json.loads((tmp_path / "study.json").read_text())["recommended"] == out["recommended"]
    assert (tmp_path / "error_vs_time.png").is_file()
