"""The multi-throw crank train's subsection of the HTML report (dynamics.results.report)."""

import json

import pytest

from crankmodal.dynamics.results.report import train_section
from crankmodal.report.modal_report import Report


def _journal(mean, peak, share_mean, share_peak, first=0.9, second=0.1):
    return {"mean_n": mean, "peak_n": peak, "share_mean": share_mean, "share_peak": share_peak,
            "per_revolution_peak_n": {"mean": peak * 0.99, "sem": 12.0},
            "orders": [0, 1, 2, 3],
            "order_amplitude_n": [mean, first * peak, second * peak, 1.0]}


RES = {"main_journals": {"journals": ["main_1", "main_2", "main_3"],
                         "main_1": _journal(22879.0, 32782.0, 0.412, 0.411),
                         "main_2": _journal(9561.0, 15390.0, 0.172, 0.193, 0.12, 0.84),
                         "main_3": _journal(23110.0, 31670.0, 0.416, 0.397)},
       "torsion": {"orders": [0.0, 1.0, 2.0, 3.0],
                   "twist_free_end": {"amplitude": [3e-5, 1.8e-5, 5.85e-4, 6.9e-5],
                                      "mean": 3e-5, "half_peak_to_peak": 6.78e-4},
                   "coupling_torque": {"amplitude": [94.9, 5.7, 187.0, 6.1], "mean": 94.9,
                                       "half_peak_to_peak": 198.2}},
       "arrangement": {"throw_angles_deg": [0.0, 180.0], "cylinder_throws": [1, 2],
                       "firing_order": None}}


def _tables(rep):
    return [b for b in rep.blocks if b[0] == "table"]


def test_section_shows_journal_shares_torsion_orders_and_names_the_fatigue_verdict(tmp_path):
    rep = Report("t")
    fatigue = {"body": "crank", "worst_location": "main_journal_2_fillet_web_2",
               "worst_location_safety_factor": 2.97, "min_safety_factor": 2.97,
               "required_safety_factor": 1.15, "passed": True}
    figs = train_section(rep, json.loads(json.dumps(RES)), tmp_path, fatigue)
    assert [f.name for f in figs] == ["dynamics_journal_shares.png", "dynamics_torsion_orders.png"]
    assert all(f.stat().st_size > 1000 for f in figs)
    journals, torsion = _tables(rep)
    assert [r[0] for r in journals[2]] == ["main 1", "main 2", "main 3"]  # "journals" skipped
    assert [r[2] for r in journals[2]] == ["0.412", "0.172", "0.416"]
    assert journals[2][1][6].startswith("2: ")  # the middle journal's largest order is 2
    twist = torsion[2][0]
    assert twist[0].startswith("free-end twist") and twist[2] == "0.678 mrad"
    assert twist[3].startswith("2: 0.585 mrad")  # order 2 first, order 0 (the mean) left out
    text = " ".join(b[1] for b in rep.blocks if b[0] == "p")
    assert "main journal 2 fillet web 2 (n = 2.97)" in text and "passes" in text
    assert "Fatigue verdict [fatigue]" in text


def test_nothing_for_a_run_without_journals_or_torsion(tmp_path):
    rep = Report("t")
    assert train_section(rep, {"main_bearing_force_peak_n": 1.0}, tmp_path) == []
    assert rep.blocks == [] and not list(tmp_path.iterdir())


def test_without_figures_draws_nothing(tmp_path):
    rep = Report("t")
    assert train_section(rep, RES, tmp_path, figures=False) == []
    assert len(_tables(rep)) == 2 and not list(tmp_path.iterdir())


@pytest.mark.slow
def test_report_of_a_train_scene_has_the_section(tmp_path):
    """The inline-4 scene (rigid crank on two journals, motor on a coupling) with [report]."""
    from pathlib import Path

    from crankmodal import runner
    from crankmodal.scene import load_scene

    root = Path(__file__).resolve().parent.parent
    scene = load_scene(root / "scenes" / "inline4_dynamics.toml",
                       ["dynamics.end_time=0.16", "dynamics.spectrum_start=0.0337",
                        "report.title='inline-4'"])
    res = runner.run(scene, tmp_path)
    html = (tmp_path / "report.html").read_text()
    assert "Multi-throw crank train" in html and "main 1" in html and "coupling torque" in html
    assert res["report"]["train_figures"] == ["dynamics_journal_shares.png",
                                              "dynamics_torsion_orders.png"]
