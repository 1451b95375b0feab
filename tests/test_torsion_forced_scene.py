"""The [torsion.forced] scene section: the seed 004 train study, the peer code, bad input.

- Side by side with openTorsion (Aalto University): the same train (rotor and shaft damping) gives
  the same natural frequencies (1e-6) and, under the compressor's periodic torques, the same
  steady state (per order and synthesised by dense sampling here, 1e-4).
- The results.json contract fields and their shapes; every figure written.
- Bad input through the CLI: exit 2, one line naming the key, no results.json.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from conftest import SCENES, run_cli, run_in_process

from crankmodal.runner import check
from crankmodal.scene import load_scene

PROGRESS = re.compile(r"\[\w+\] (running|done in [0-9.]+ s)$")

SEED = SCENES / "seed004_forced_torsion.toml"


def _forced_params(overrides=()):
    return check(load_scene(SEED, overrides))["torsion"]["forced"]


def test_same_train_as_opentorsion_same_frequencies_and_steady_state(oracle):
    ot = pytest.importorskip("opentorsion", reason="openTorsion (the peer code) is in the 'test' extra")
    from crankmodal.torsion.forced import damped_train, steady_state

    f = _forced_params()
    chain = f["train"]  # the scene's train has modal damping; openTorsion takes element dampers
    inertias = np.diag(chain.M)
    ks = chain.section_stiffness
    c_rot = [0.5, 0.5, 2.0, 0.3]  # N m s/rad, chosen for the comparison
    c_sec = [8.0, 8.0, 6.0]
    from crankmodal.torsion.chain import TorsionalChain

    mine = damped_train(TorsionalChain(inertias, ks), modal_damping=0.0, rotor_damping=c_rot,
                        section_damping=c_sec)
    peer = ot.Assembly([ot.Shaft(i, i + 1, None, None, k=k, I=0.0, c=c) for i, (k, c) in enumerate(zip(ks, c_sec))],
                       disk_elements=[ot.Disk(i, I, c=c) for i, (I, c) in enumerate(zip(inertias, c_rot))])
    lam, _ = peer.undamped_modal_analysis()
    peer_hz = np.sort(np.sqrt(np.abs(lam.real)))[1:] / (2 * math.pi)
    my_hz, _ = mine.natural_frequencies()
    oracle(stage="torsion", quantity="seed 004 train natural frequencies vs openTorsion",
           reference="peer code openTorsion Assembly.undamped_modal_analysis", tolerance="1e-6 rel",
           measured=float(np.max(np.abs(my_hz / peer_hz - 1))), expected=0.0)
    np.testing.assert_allclose(my_hz, peer_hz, rtol=1e-6)

    rpm = 1494.6
    res = steady_state(mine, f["excitation"], [rpm])
    Om = rpm * math.pi / 30
    F = f["excitation"].at([Om])[0]  # (orders, rotors)
    omegas = f["excitation"].orders * Om
    exc = ot.PeriodicExcitation(len(inertias), omegas)
    for r in range(len(inertias)):
        exc.add_sines(r, omegas, np.abs(F[:, r]), np.angle(F[:, r]))
    q, _ = peer.ss_response(exc.excitation_matrix(), omegas, C=peer.C)
    T_peer, _ = peer.vibratory_torque(exc, C=peer.C)
    np.testing.assert_allclose(res.angle[0].T, q, rtol=1e-6, atol=1e-9 * np.abs(q).max())
    np.testing.assert_allclose(np.abs(res.section_torque[0].T), np.abs(T_peer), rtol=1e-6,
                               atol=1e-9 * np.abs(T_peer).max())
    # synthesis of the peer's orders by dense sampling over the cycle (no Newton refinement)
    k = np.rint(f["excitation"].orders * f["excitation"].cycle_revolutions).astype(int)
    phi = np.linspace(0, 2 * math.pi, 200_001)
    wave = np.exp(1j * np.outer(k, phi))
    th = (q[:, :, None] * wave[None]).real.sum(axis=1)
    tq = (T_peer[:, :, None] * wave[None]).real.sum(axis=1)
    half_th = 0.5 * (th.max(axis=1) - th.min(axis=1))
    half_tq = 0.5 * (tq.max(axis=1) - tq.min(axis=1))
    err = np.max(np.abs(res.section_torque_nm[0] - half_tq)) / half_tq.max()
    oracle(stage="torsion", quantity="seed 004 train synthesised section torque vs openTorsion orders",
           reference="peer code openTorsion ss_response/vibratory_torque, synthesised by dense sampling",
           tolerance="1e-4 of peak", measured=float(err), expected=0.0)
    np.testing.assert_allclose(res.amplitude_rad[0], half_th, atol=1e-4 * half_th.max())
    assert err <= 1e-4


def test_seed004_train_study_writes_contract_fields_figures_and_report(tmp_path):
    import tomllib

    from crankmodal.runner import run
    from crankmodal.scene import scene_from_dict

    data = tomllib.loads(SEED.read_text())
    data["report"] = {}
    run(scene_from_dict(data, name="seed004_forced", base_dir=SEED.parent), tmp_path, figures=True)
    t = json.loads((tmp_path / "results.json").read_text())["torsion"]
    f = t["forced"]
    n_s = len(f["speed_rpm"])
    assert f["speed_rpm"][0] == 300.0 and f["speed_rpm"][-1] == pytest.approx(1800.0)
    assert np.shape(f["amplitude_rad"]) == (n_s, 4)
    assert np.shape(f["section_torque_nm"]) == (n_s, 3)
    assert np.shape(f["section_stress_pa"]) == (n_s, 3)
    # stress = K_t T / Z_p per section (closed form of a round section)
    z = math.pi * 0.110**3 / 16
    np.testing.assert_allclose(np.asarray(f["section_stress_pa"])[:, 0],
                               1.6 * np.asarray(f["section_torque_nm"])[:, 0] / z, rtol=1e-12)
    # the mean power of the two cylinders is the mechanism stage's mean crank torque x omega
    mech = json.loads((tmp_path / "results.json").read_text())["mechanism"]
    assert sum(f["excitation"]["mean_torque_nm"]) == pytest.approx(mech["mean_crank_torque_nm"], rel=1e-9)
    assert f["stress_check"]["passes"] in (True, False) and "worst section" in f["summary"]
    for name in ("torsion_forced_interference.png", "torsion_forced_response.png",
                 "torsion_forced_stress.png", "torsion_forced_resonances.txt"):
        assert (tmp_path / name).stat().st_size > 0
    # the report's torsion section: verdict, section stresses, margins and the three figures
    md = (tmp_path / "report.md").read_text()
    assert "Forced response, stress and verdict" in md and "of allowable" in md
    for name in ("torsion_forced_interference", "torsion_forced_response", "torsion_forced_stress"):
        assert name in md


@pytest.mark.parametrize("override, key", [
    ("torsion.forced.firing_order=[1, 1]", "torsion.forced.firing_order"),
    ("torsion.forced.throw_rotors=[1, 2, 3]", "torsion.forced.throw_rotors"),
    ("torsion.forced.cylinder_throws=[1]", "torsion.forced.cylinder_throws"),
    ("torsion.forced.pressure_table={angle_deg=[0.0, 200.0, 100.0, 360.0], pressure_pa=[1e5, 3e5, 2e5, 1e5], cycle_deg=360.0}",
     "torsion.forced.pressure_table.angle_deg"),
    ("torsion.forced.pressure_table={angle_deg=[0.0, 100.0, 300.0], pressure_pa=[1e5, 3e5, 1e5], cycle_deg=360.0}",
     "torsion.forced.pressure_table.angle_deg"),
    ("torsion.forced.pressure_table={angle_deg=[0.0, 100.0, 360.0], pressure_pa=[1e5, 3e5, 2e5], cycle_deg=360.0}",
     "torsion.forced.pressure_table.pressure_pa"),
    ("torsion.forced.modal_damping=-0.01", "torsion.forced.modal_damping"),
    ("torsion.forced.section_damping=[0.0, -1.0, 6.0]", "torsion.forced.section_damping"),
    ("torsion.forced.rotor_damping=[0.0, 1.0]", "torsion.forced.rotor_damping"),
    ("torsion.forced.sections=[{diameter=0.1, bore=0.1}, {diameter=0.1}, {diameter=0.1}]",
     "torsion.forced.sections[0].bore"),
    ("torsion.forced.operating_speeds_rpm=[1900.0]", "torsion.forced.operating_speeds_rpm[0]"),
    ("torsion.forced.speed_band=0.5", "torsion.forced.speed_band"),
    ("torsion.forced.speed_step_rpm=1e-30", "torsion.forced.speed_step_rpm"),
    ("torsion.forced.double_acting=[{cylinder=1, rod_diameter=0.2}]", "torsion.forced.double_acting[0].rod_diameter"),
    ("torsion.forced.double_acting=[{cylinder=3, rod_diameter=0.03}]", "torsion.forced.double_acting[0].cylinder"),
])
def test_bad_forced_input_exits_2_with_one_line_naming_the_key(tmp_path, override, key):
    # in process (the CLI's main; an escaping exception would be raised here), the subprocess
    # path is the same code (see test_core_fuzz.test_in_process_answer_is_the_console_scripts)
    status, stderr = run_in_process("run", SEED, "--out", tmp_path, "--set", override)
    assert status == 2, stderr
    lines = [ln for ln in stderr.splitlines() if ln.strip() and not PROGRESS.match(ln)]
    assert len(lines) == 1 and key in lines[0], stderr
    assert "Traceback" not in stderr
    assert not (tmp_path / "results.json").exists()


def test_fe_beside_train_solid_chain_of_one_throw_is_the_two_rotor_closed_form():
    import tomllib

    from crankmodal.torsion.crank_model import crank_model
    from crankmodal.torsion.fe_beside import fe_beside_train

    t = tomllib.loads((SCENES.parent / "geometry" / "multi_bearing_compressor.toml").read_text())["torsion"]
    m = crank_model(t["throw"], t["flywheel"], t["G"], t["density"], 1)
    out = fe_beside_train([205.0], [300.0, 500.0, 900.0], ["bending about x", "torsion about z", "torsion about z"], m)
    j1 = m.throw_parts["crankpin"] + m.throw_parts["webs"]
    closed = math.sqrt(m.stiffness * (1 / j1 + 1 / m.flywheel_inertia)) / (2 * math.pi)
    first = out["rows"][0]
    assert first["fe_mode"] == 2 and first["fe_hz"] == 500.0 and first["chain_hz"] == 205.0
    assert first["solid_chain_hz"] == pytest.approx(closed, rel=1e-12)
    assert first["solid_chain_vs_fe"] == pytest.approx(closed / 500.0 - 1, rel=1e-12)
    assert "chain_hz" not in out["rows"][1]


@pytest.mark.slow
def test_fe_crank_torsion_modes_beside_the_forced_chain(tmp_path):
    scene = load_scene(SCENES / "torsion_seed004_crank_fe.toml",
                       ["geometry.mesh_size=0.03", "geometry.fidelity='dechamfered'", "modal.n_modes=8"])
    from crankmodal.runner import run

    res = run(scene, tmp_path, figures=False)
    fe = res["torsion"]["forced"]["fe_comparison"]
    classes = res["modal"]["classes"]
    assert fe["rows"] and all(classes[r["fe_mode"] - 1].startswith("torsion") for r in fe["rows"])
    # the solid-only chain is stiffer-per-inertia than the running one (no reciprocating inertia)
    assert fe["rows"][0]["solid_chain_hz"] > fe["rows"][0]["chain_hz"]


def test_orders_left_out_and_a_viscous_damper_are_warned():
    from crankmodal.scene import scene_from_dict

    def warnings_of(forced):
        sc = scene_from_dict({"mechanism": {"machine": "inline6_engine"},
                              "torsion": {"machine": "inline6_engine", "forced": forced}})
        return check(sc)["torsion"]["forced"]["validity_warnings"]

    w12 = warnings_of({"max_order": 12.0})
    assert any("order 15 above max_order" in w for w in w12)
    assert any("viscous damper ring free" in w for w in w12)
    w18 = warnings_of({"max_order": 18.0, "dampers": []})
    assert w18 == []


def test_found_by_the_fuzzer_firing_order_against_angles_and_an_undamped_train(tmp_path):
    # a throw angle that no longer fits the firing order names the angle keys too
    p = run_cli("check", SCENES / "torsion_inline4_engine.toml", "--set",
                "mechanism.cylinders.1.throw_angle_deg=0")
    assert p.returncode == 2 and "torsion.forced.firing_order" in p.stderr
    assert "mechanism.cylinders[i].throw_angle_deg" in p.stderr and "Traceback" not in p.stderr
    # no damping anywhere: the resonant response would be infinite
    p = run_cli("run", SEED, "--out", tmp_path, "--set", "torsion.forced.modal_damping=0",
                "--set", "torsion.forced.section_damping=[0.0, 0.0, 0.0]")
    assert p.returncode == 2 and "torsion.forced.modal_damping" in p.stderr
    assert not (tmp_path / "results.json").exists()
