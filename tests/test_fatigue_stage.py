"""The ``[fatigue]`` scene stage (issue 29 item 3): the verdict of a flexible body of the
``[dynamics]`` run, its refusals, its outputs and its report section.

Oracles:

- **Scaling of a linear model** (slow): with the gas off, the crank train's only loads are the
  inertia forces of the pistons and rods, ``∝ ω²`` at a constant speed; far below the crank's
  first mode (1199 Hz) its response is quasi-static, so the stress at every point scales as
  ``ω²`` and, for Goodman's line (homogeneous of degree −1 in the stresses), every safety
  factor as ``1/ω²``: doubling the speed divides each location's safety factor by 4. The
  deviation is the dynamic amplification ``(Ω/ω_n)²`` (at most (2 × 20 Hz / 1199 Hz)² = 1.1e-3
  at 1200 rpm) and the centrifugal softening of the same order, so 5e-3 holds with margin.
- **Crank-angle window** (fast): the samples of the last 360° of a run turning at constant speed
  are those of the last revolution's duration, in either sense of rotation (closed form).
- Bad input through the CLI: exit 2, one line naming the key, nothing written.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from conftest import SCENES, run_in_process

from crankmodal.errors import SceneError

SCENE = SCENES / "seed000_crank_fatigue.toml"


# ---- the crank-angle window ---------------------------------------------------------------
@pytest.mark.parametrize("sense", [1.0, -1.0])
def test_cycle_window_is_the_last_revolution_by_crank_angle(sense):
    from crankmodal.fatigue.stage import cycle_window

    rev_hz, dt = 25.0, 1.0 / (25.0 * 360.0)  # 1 deg steps
    t = np.arange(0, round(0.2 / dt) + 1) * dt
    angle = sense * 2 * np.pi * rev_hz * t % (2 * np.pi)  # wrapped, as a sensor would give it
    sel = cycle_window(angle, 360.0, t, t_min=0.1)
    assert sel.sum() == 361  # 0..360 deg inclusive
    assert t[sel][0] == pytest.approx(0.2 - 1 / rev_hz, abs=1e-12)
    assert cycle_window(angle, 720.0, t).sum() == 721


def test_cycle_window_refuses_a_run_too_short_naming_end_time():
    from crankmodal.fatigue.stage import cycle_window

    t = np.linspace(0.0, 0.05, 91)
    angle = 2 * np.pi * 25.0 * t  # 450 deg in all
    with pytest.raises(SceneError, match=r"^dynamics\.end_time: .*less than the 360 deg"):
        cycle_window(angle, 360.0, t, t_min=0.02)


# ---- bad input through the CLI ------------------------------------------------------------
BAD = [
    (["fatigue.body='rod_1'"], r"^fatigue\.body: 'rod_1' is not a flexible body"),
    (["dynamics.flexible.crank.n_modes=0"], r"^fatigue\.body: 'crank' is frozen"),
    (["fatigue.body='rocker'"], r"^fatigue\.body: a four_star has no 'rocker'"),
    (["dynamics.flexible.crank.material='steel'"],
     r"^material\.fatigue_strength: material 'steel' .*has no fatigue strength"),
    (["material.name='steel'"], r"^material\.fatigue_strength: material 'steel' \(from \[material\]\)"),
    (["material.E=2.1e11", "material.nu=0.3", "material.rho=7850.0"],
     r"^material\.fatigue_strength: material 'custom'"),
    (["fatigue.surface_factor=0.8"], r"^fatigue\.surface_factor: give either surface_finish or"),
    (["fatigue.reliability=0.97"], r"^fatigue\.reliability: must be one of 0\.5, 0\.9"),
    (["fatigue.cycle_deg=540.0"], r"^fatigue\.cycle_deg: must be 360 or 720"),
    (["fatigue.criterion='soderberg'"], r"^fatigue\.criterion: must be one of goodman, gerber"),
    (["fatigue.notch_factor=0.9"], r"^fatigue\.notch_factor: must be >= 1"),
    (["fatigue.size_factor=0.9"], r"^fatigue\.size_factor: give either size_diameter or"),
    (["fatigue.sizefactor=0.9"], r"^fatigue\.sizefactor: unknown key"),
    (["dynamics.end_time=0.15"], r"^dynamics\.end_time: 0\.15 s holds no 1 steady cycle"),
    (["fatigue.cycles=3"], r"^dynamics\.end_time: 0\.2 s holds no 3 steady cycle"),
]


@pytest.mark.parametrize("overrides, message", BAD, ids=[b[1][1:40] for b in BAD])
def test_bad_fatigue_input_exits_2_naming_the_key(overrides, message, tmp_path):
    out = tmp_path / "out"
    args = ["run", SCENE, "--out", out]
    for o in overrides:
        args += ["--set", o]
    status, err = run_in_process(*args)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert re.search(message, lines[0].removeprefix("crankmodal: error: ")), lines[0]
    assert not (out / "results.json").exists()
    assert not (out / "fatigue.npz").exists() and not (out / "dynamics.npz").exists()


def test_bad_fatigue_input_through_a_subprocess_has_no_traceback(cli, tmp_path):
    r = cli("check", SCENE, "--set", "fatigue.body='rod_1'")
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert "fatigue.body" in r.stderr


def test_a_body_file_without_stress_modes_is_refused_at_check(tmp_path, monkeypatch):
    """The loom's coupler (a coarse P1 bar, reduced here) saved without its stress modes."""
    from dataclasses import replace

    from crankmodal.dynamics.flexible.build import reduced_bar
    from crankmodal.reduction.io import load_flexbody, save_flexbody

    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "cache"))
    path = reduced_bar(0.075, (0.05, 0.077), {"mesh_size": 0.025, "element_order": 1,
                                              "material": "steel", "fixed_interface_modes": 4},
                       "dynamics.flexible.coupler")
    fb = load_flexbody(path)
    assert fb.stress_modes is not None  # the reduction stores them: the file below drops them
    bare = save_flexbody(tmp_path / "bare.npz", replace(fb, stress_modes=None,
                                                        stress_points=None))
    scene = tmp_path / "coupler_fatigue.toml"
    scene.write_text(f"""
[dynamics]
machine = "loom_four_bar"
end_time = 0.4
[dynamics.flexible]
coupler = {{ file = "{bare.name}" }}
[material]
name = "42CrMo"
[fatigue]
body = "coupler"
""")
    status, err = run_in_process("check", scene)
    assert status == 2
    assert re.match(r"crankmodal: error: fatigue\.body: the file of 'coupler' .*holds no stress modes",
                    err.strip()), err


# ---- the oracle: safety factors of a linear model scale as 1/load --------------------------
CRANK = {"n_modes": 8, "material": "crank_steel_seed000", "mesh_size": 0.014,
         "fixed_interface_modes": 30}


def inertia_only_scene(speed_rpm: float, report: bool = False, ensemble: int = 1):
    """The seed-000 four-star at ``speed_rpm``, gas and friction off (its loads: the pistons'
    and rods' inertia, ∝ ω²), the crank flexible, one revolution assessed after a 0.05 s ramp
    and one settling revolution."""
    import crankmodal as cm
    from crankmodal.resources import load_machine

    mech = dict(load_machine("four_star_compressor")["mechanism"])
    mech.pop("friction", None)
    mech.update(gas={"model": "none"}, speed_rpm=speed_rpm)
    rev_s = 60.0 / speed_rpm
    data = {"mechanism": mech,
            "dynamics": {"machine": "four_star_compressor", "clearances": [], "run_rigid": False,
                         "ramp_time": 0.05, "end_time": 0.05 + 2 * rev_s + 1e-9,
                         "ensemble": ensemble, "flexible": {"crank": dict(CRANK)}},
            "fatigue": {"body": "crank", "surface_finish": "machined", "size_diameter": 0.045,
                        "reliability": 0.99}}
    if report:
        data["report"] = {}
    return cm.scene_from_dict(data, name=f"inertia_{speed_rpm:g}")


@pytest.mark.slow
def test_safety_factors_of_inertia_loads_scale_as_one_over_speed_squared(tmp_path, oracle):
    import crankmodal as cm
    from crankmodal.fatigue import FatigueResult

    slow = cm.run_scene(inertia_only_scene(600.0, ensemble=2), tmp_path / "600",
                        figures=False)["fatigue"]
    fast = cm.run_scene(inertia_only_scene(1200.0, report=True), tmp_path / "1200")["fatigue"]
    ratio = {k: slow["locations"][k]["safety_factor"] / fast["locations"][k]["safety_factor"]
             for k in slow["locations"]}
    worst = slow["worst_location"]
    oracle(stage="flexible", quantity=f"[fatigue] safety factor at {worst}, inertia loads only, "
           "600 rpm over 1200 rpm", reference="closed form: linear quasi-static model, stresses "
           "∝ ω², Goodman n ∝ 1/ω²", tolerance="5e-3", measured=ratio[worst], expected=4.0)
    assert set(ratio) == set(fast["locations"]) and len(ratio) >= 7  # 6 named + elsewhere
    for name, r in ratio.items():
        assert r == pytest.approx(4.0, rel=5e-3), name
    assert fast["worst_location"] == worst
    assert "fillet" in worst or "oil_hole" in worst
    assert slow["min_safety_factor"] / fast["min_safety_factor"] == pytest.approx(4.0, rel=5e-3)
    # the outputs: the saved result is the reported one, the figures and the report section
    loaded = FatigueResult.load(tmp_path / "1200" / "fatigue.npz")
    assert loaded.min_safety_factor == pytest.approx(fast["min_safety_factor"], rel=1e-12)
    assert fast["figures"] == ["fatigue_haigh.png", "fatigue_crank.png"]
    assert all((tmp_path / "1200" / f).stat().st_size > 10_000 for f in fast["figures"])
    html = (tmp_path / "1200" / "report.html").read_text(encoding="utf-8")
    assert "Fatigue verdict [fatigue]" in html and worst.replace("_", " ") in html
    assert fast["window"]["cycle_deg"] == 360.0 and fast["window"]["n_samples"] == 361
    # an ensemble assesses every trajectory; a smooth run's trajectories (started 1e-12 apart)
    # agree to the integration tolerance (rtol 1e-6 on the modal coordinates: 1e-4 is loose)
    ens = slow["ensemble"]
    assert ens["n_trajectories"] == 2 and ens["worst_location"] == [worst, worst]
    assert ens["min_safety_factor"][0] == slow["min_safety_factor"]
    assert ens["spread"]["max"] == pytest.approx(ens["spread"]["min"], rel=1e-4)
    assert "ensemble" not in fast
    saved = json.loads((tmp_path / "1200" / "results.json").read_text())["fatigue"]
    assert saved["worst_location"] == worst and saved["passed"] is True


def test_material_of_other_elastic_constants_than_the_body_is_warned():
    from dataclasses import replace

    from crankmodal.fatigue.stage import material_mismatch
    from crankmodal.fem.materials import material

    body = material("crank_steel_seed000")
    assert material_mismatch(replace(body, fatigue_strength=4e8), body.name) is None
    text = material_mismatch(replace(body, E=1.76e11, rho=7200.0), body.name)
    assert "in E, rho:" in text and "strengths only" in text
    assert material_mismatch(body, "a custom material") is None


@pytest.mark.slow
def test_an_impacting_run_reports_the_spread_over_its_trajectories(tmp_path):
    """The four-star with its seed clearance in big end 1 (impacting): every trajectory's cycle
    is assessed and the verdict holds for the lowest; one impacting trajectory is warned."""
    import crankmodal as cm

    def scene(ensemble):
        return cm.scene_from_dict(
            {"mechanism": {"machine": "four_star_compressor"},
             "dynamics": {"machine": "four_star_compressor", "end_time": 0.2, "run_rigid": False,
                          "run_ideal": False, "ensemble": ensemble,
                          "flexible": {"crank": dict(CRANK)}},
             "fatigue": {"body": "crank", "required_safety_factor": 5.3}}, name="impacting")

    res = cm.run_scene(scene(2), tmp_path / "ens", figures=False)["fatigue"]
    ens = res["ensemble"]
    n = ens["min_safety_factor"]
    assert ens["n_trajectories"] == 2 and n[0] == res["min_safety_factor"]
    assert ens["spread"]["min"] == min(n) and ens["spread"]["max"] == max(n)
    assert res["passed"] is (min(n) >= 5.3)
    assert "over 2 trajectories the lowest ranges" in res["summary"]
    assert not any("one trajectory" in w for w in res["warnings"])
    one = cm.run_scene(scene(1), tmp_path / "one", figures=False)["fatigue"]
    assert "ensemble" not in one
    assert any("clearance joints and one trajectory" in w for w in one["warnings"])


def test_an_unstressed_location_is_written_as_null_not_infinity():
    from crankmodal.fatigue.stage import json_safe
    from crankmodal.results import to_jsonable

    out = json_safe({"locations": {"a": {"safety_factor": np.inf, "n": 3}},
                     "spread": [1.5, np.float64(np.inf)], "text": "x"})
    assert out == {"locations": {"a": {"safety_factor": None, "n": 3}},
                   "spread": [1.5, None], "text": "x"}
    to_jsonable(out)  # refuses non-finite values: passes now


def test_report_section_lists_every_location_lowest_first():
    from crankmodal.fatigue.report import fatigue_blocks
    from crankmodal.report.modal_report import Report

    res = {"criterion": {"rule": "goodman", "mean_stress": "sines",
                         "equivalent_alternating": "von Mises of the amplitude tensor"},
           "factors": {"surface": 0.74, "size": 0.83, "reliability": 0.814, "other": 1.0,
                       "notch": 1.0},
           "fatigue_strength_pa": 2.3e8, "specimen_fatigue_strength_pa": 4.65e8,
           "ultimate_strength_pa": 9.3e8, "material": "42CrMo", "required_safety_factor": 1.5,
           "passed": True,
           "ensemble": {"n_trajectories": 2, "min_safety_factor": [5.2, 5.4],
                        "worst_location": ["crankpin_1_fillet_web_2", None],
                        "spread": {"min": 5.2, "mean": 5.3, "max": 5.4}},
           "locations": {name: {"kind": "k", "safety_factor": n, "alternating_pa": 1e7,
                                "mean_pa": 2e7, "max_von_mises_pa": 3e7,
                                "proportionality": 1.0, "n_points": 10}
                         for name, n in (("elsewhere", 9.0), ("crankpin_1_fillet_web_2", 5.2),
                                         ("main_journal_1_fillet_web_1", None))}}
    rep = Report("t")
    fatigue_blocks(rep, res)
    html = rep.to_html()
    i, j, k = (html.find(s) for s in ("crankpin 1 fillet web 2", "elsewhere",
                                      "main journal 1 fillet web 1"))
    assert -1 < i < j < k  # lowest first, the unstressed (∞) last
    assert "230 MPa" in html and "5.2" in html and "∞" in html
