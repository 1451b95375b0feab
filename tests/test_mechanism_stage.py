"""The [mechanism] stage: the shipped scenes, what they import, and every bad-input path."""

import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from crankmodal.errors import SceneError
from crankmodal.runner import check, run
from crankmodal.scene import load_scene, scene_from_dict

SCENES = Path(__file__).resolve().parent.parent / "scenes"
FOUR_STAR = SCENES / "four_star_mechanism.toml"
ENGINE = SCENES / "slider_crank_engine.toml"


def assert_clean_error(proc, key, message):
    """Exit status 2, one line on stderr naming the key and what is allowed, no traceback."""
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert key + ":" in lines[0] and message in lines[0], lines[0]


def test_mechanism_only_scene_leaves_gmsh_skfem_pyvista_unimported(tmp_path):
    # A clean interpreter: nothing imported by pytest or other tests can mask an import.
    code = textwrap.dedent(f"""
        import sys
        from crankmodal.runner import run
        from crankmodal.scene import load_scene
        res = run(load_scene({str(FOUR_STAR)!r}), {str(tmp_path / "o")!r}, figures=True)
        assert res["mechanism"]["summary"]
        heavy = [m for m in ("gmsh", "skfem", "pyvista") if m in sys.modules]
        print("HEAVY=" + ",".join(heavy))
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False, timeout=300, env={"MPLBACKEND": "Agg", "PATH": ""})
    assert proc.returncode == 0, proc.stderr
    assert "HEAVY=\n" in proc.stdout, proc.stdout


def test_four_star_scene_reproduces_the_seed_balance_and_writes_its_outputs(tmp_path):
    res = run(load_scene(FOUR_STAR), tmp_path, figures=True)["mechanism"]
    ms = 1.2 + 0.35 * 1.6  # machine file: piston group + 0.35 of the rod
    w = 1480 * math.pi / 30
    assert res["first_order_force_max_n"] == pytest.approx(2 * ms * 0.035 * w**2, rel=1e-9)
    assert res["first_order_magnitude_constant"] and res["second_order_force_cancelled"]
    assert res["second_order_moment_max_nm"] == pytest.approx(
        math.sqrt(10) * 0.016 * (0.035 / 0.392) * ms * 0.035 * w**2, rel=1e-9)
    # peak acceleration at TDC: r w^2 (1 + lambda), closed form
    # extreme accelerations r w^2 (1 +- lambda) at TDC/BDC (lambda < 1/4): seed Fig. 3's unequal
    # positive and negative maxima
    assert res["peak_acceleration_m_s2"] == pytest.approx([0.035 * w**2 * (1 + 0.035 / 0.392)] * 4)
    assert res["min_acceleration_m_s2"] == pytest.approx([-0.035 * w**2 * (1 - 0.035 / 0.392)] * 4)
    assert res["summary"].startswith("4 cyl at 1480 rpm")
    for name in res["files"]:
        assert (tmp_path / name).stat().st_size > 0
    assert len(res["files"]) == 6  # curves npz + 5 figures (crank torque added, issue 25 #15)
    saved = json.loads((tmp_path / "results.json").read_text())
    assert saved["mechanism"]["gas_work_per_cycle_j"] < 0  # a compressor absorbs work


def test_engine_scene_runs_two_revolutions_and_delivers_work(tmp_path):
    res = run(load_scene(ENGINE), tmp_path, figures=False)["mechanism"]
    assert res["cycle_revolutions"] == 2
    assert res["gas_work_per_cycle_j"] > 0 and res["mean_crank_torque_nm"] > 0
    assert res["files"] == ["mechanism_curves.npz"]


def test_cli_run_prints_the_mechanism_summary(cli, tmp_path):
    proc = cli("run", FOUR_STAR, "--out", tmp_path, "--no-figures")
    assert proc.returncode == 0, proc.stderr
    assert "[mechanism]" in proc.stdout and "F2 cancelled" in proc.stdout


def scene_text(tmp_path, mechanism: str, extra: str = "") -> str:
    """A scene file with a custom [mechanism] table (one cylinder unless given)."""
    s = tmp_path / "s.toml"
    s.write_text("[mechanism]\n" + textwrap.dedent(mechanism) + textwrap.dedent(extra))
    return s


BASE = """
speed_rpm = 1000
crank_radius = 0.05
rod_length = 0.2
rod_mass = 1.0
rod_cg_from_big_end = 0.06
rod_inertia = 0.003
"""
CYL = """
[[mechanism.cylinders]]
bank_angle_deg = 0
piston_mass = 1.0
bore = 0.1
"""
COMP_CYL = CYL + """suction_pressure = 1e5
discharge_pressure = 4e5
relative_clearance = 0.05
"""

SET_CASES = [
    ("mechanism.speed_rpm=-5", "mechanism.speed_rpm", "must be > 0"),
    ("mechanism.crank_radius=0.5", "mechanism.rod_length", "must be > crank_radius"),
    ("mechanism.rod_ratio=0.1", "mechanism.rod_length", "exactly one of rod_length and rod_ratio"),
    ("mechanism.rod_cg_from_big_end=1.0", "mechanism.rod_cg_from_big_end", "<= the rod length"),
    ("mechanism.rod_mass=-1", "mechanism.rod_mass", "must be >= 0"),
    ("mechanism.cylinders=[]", "mechanism.cylinders", "at least one cylinder"),
    ("mechanism.max_order=3", "mechanism.max_order", "harmonics = 'fourier'"),
    ("mechanism.harmonics='taylor'", "mechanism.harmonics", "must be one of series, fourier"),
    ("mechanism.n_points=10", "mechanism.n_points", "must be >= 36"),
    ("mechanism.speed=3", "mechanism.speed", "unknown key"),
    ("mechanism.gas.model='diesel'", "mechanism.gas.model", "must be one of"),
    ("mechanism.gas.compression_exponent=0.4", "mechanism.gas.compression_exponent", "must be > 1"),
    ("mechanism.gas.pressure_coefficient=1.5", "mechanism.gas.pressure_coefficient", "<= 1"),
    ("mechanism.gas.valve_timing='late'", "mechanism.gas.valve_timing", "pressure, seed"),
    ("mechanism.gas.seed_angles_deg=[200.0,300.0]", "mechanism.gas.seed_angles_deg",
     "end of compression < 180"),
    ("mechanism.friction.mechanical_efficiency=1.2", "mechanism.friction.mechanical_efficiency",
     "<= 1"),
    ("mechanism.friction.indicated_power='guess'", "mechanism.friction.indicated_power",
     "seed, cycle"),
]


@pytest.mark.parametrize("assignment,key,message", SET_CASES, ids=[c[1] + ":" + c[0].split("=")[1]
                                                                   for c in SET_CASES])
def test_bad_mechanism_value_on_the_command_line_exits_2_naming_the_key(cli, tmp_path, assignment,
                                                                         key, message):
    extra = ["--set", "mechanism.gas.valve_timing='seed'"] if "seed_angles" in assignment else []
    proc = cli("run", FOUR_STAR, "--out", tmp_path / "o", "--set", assignment, *extra)
    assert_clean_error(proc, key, message)
    assert not (tmp_path / "o" / "results.json").exists()


FILE_CASES = [
    (BASE + CYL.replace("bore = 0.1", ""), "mechanism.cylinders[0].bore", "is required"),
    (BASE + CYL.replace("bore = 0.1", "bore = -0.1"), "mechanism.cylinders[0].bore", "> 0"),
    (BASE + CYL + "colour = 'red'\n", "mechanism.cylinders[0].colour", "unknown key"),
    (BASE + CYL.replace("bank_angle_deg = 0", "bank_angle_deg = 'up'"),
     "mechanism.cylinders[0].bank_angle_deg", "must be a number"),
    (BASE + "[mechanism.gas]\nmodel = 'compressor'\n" + CYL,
     "mechanism.cylinders[0].suction_pressure", "required with gas.model = 'compressor'"),
    (BASE + "[mechanism.gas]\nmodel = 'compressor'\n"
     + COMP_CYL.replace("discharge_pressure = 4e5", "discharge_pressure = 0.5e5"),
     "mechanism.cylinders[0].discharge_pressure", "must exceed the suction pressure"),
    (BASE + "[mechanism.gas]\nmodel = 'compressor'\n"
     + COMP_CYL.replace("relative_clearance = 0.05", "relative_clearance = 0.9"),
     "mechanism.cylinders[0].relative_clearance", "never re-expand"),
    (BASE + "[mechanism.gas]\nmodel = 'four_stroke'\n" + CYL,
     "mechanism.gas.intake_pressure", "required with model = 'four_stroke'"),
    (BASE + "[mechanism.gas]\nmodel = 'four_stroke'\nintake_pressure = 1e5\nmax_pressure = 2e6\n"
     "exhaust_pressure = 1.1e5\ncompression_ratio = 18\n" + CYL,
     "mechanism.gas.max_pressure", "compression end pressure"),
    (BASE + "[mechanism.gas]\nmodel = 'four_stroke'\nintake_pressure = 1e5\nmax_pressure = 8e6\n"
     "exhaust_pressure = 1.1e5\ncompression_ratio = 18\nconstant_pressure_duration_deg = 200\n"
     + CYL, "mechanism.gas.exhaust_opening_deg", "must come after"),
    (BASE + "[mechanism.gas]\nmodel = 'four_stroke'\nintake_pressure = 1e5\nmax_pressure = 8e6\n"
     "exhaust_pressure = 1.1e5\ncompression_ratio = 18\n[mechanism.friction]\n"
     "mechanical_efficiency = 0.8\n" + CYL, "mechanism.friction.indicated_power",
     "'seed' is the compressor formula"),
    (BASE + "[mechanism.friction]\nmechanical_efficiency = 0.8\n" + CYL,
     "mechanism.friction.mechanical_efficiency", "needs a gas model"),
    (BASE.replace("crank_radius = 0.05\n", "") + CYL, "mechanism.crank_radius", "is required"),
]


@pytest.mark.parametrize("text,key,message", FILE_CASES, ids=[c[1] for c in FILE_CASES])
def test_bad_mechanism_table_in_a_scene_file_exits_2_naming_the_key(cli, tmp_path, text, key,
                                                                    message):
    assert_clean_error(cli("check", scene_text(tmp_path, text)), key, message)


def test_a_valid_hand_written_table_checks_and_runs(tmp_path):
    text = BASE + "[mechanism.gas]\nmodel = 'compressor'\n" + COMP_CYL
    scene = load_scene(scene_text(tmp_path, text))
    assert check(scene)["mechanism"]["gas"]["model"] == "compressor"
    res = run(scene, tmp_path / "o", figures=False)["mechanism"]
    assert res["n_cylinders"] == 1 and res["gas_work_per_cycle_j"] < 0


def test_validate_without_cylinders_names_the_key():
    scene = scene_from_dict({"mechanism": {"speed_rpm": 1.0, "crank_radius": 0.1,
                                           "rod_length": 0.3, "rod_mass": 1.0,
                                           "rod_cg_from_big_end": 0.1, "rod_inertia": 0.01}})
    with pytest.raises(SceneError, match=r"mechanism\.cylinders: is required"):
        check(scene)
