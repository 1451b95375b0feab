"""assert_frequencies: tolerance arithmetic, input forms, and the pytest plugin fixture."""

import json
import subprocess
import sys

import numpy as np
import pytest

from crankmodal.report.testing import assert_frequencies, compare_frequencies


def test_frequencies_within_tolerance_pass_and_report_their_errors():
    rows = assert_frequencies([1336.0, 1461.0, 2201.0], [1356.0, 1489.0], rtol=0.02)
    assert rows[0]["rel_error"] == pytest.approx(-20 / 1356, rel=1e-12)
    assert all(r["ok"] for r in rows)


def test_a_frequency_just_outside_its_tolerance_fails_naming_the_mode():
    # seed 000 Table 3: simplified model 1266 Hz vs measured 1356 Hz is -6.6 %
    with pytest.raises(AssertionError, match=r"mode 1: 1266 Hz vs expected 1356 Hz, error -6\.6"):
        assert_frequencies([1266.0, 1405.0], [1356.0, 1489.0], rtol=[0.065, 0.06])
    assert_frequencies([1266.0, 1405.0], [1356.0, 1489.0], rtol=[0.067, 0.06])


def test_mapping_and_none_select_modes_and_missing_modes_fail():
    f = [780.0, 1115.0, 1687.0]
    assert_frequencies(f, {3: 1687.0}, rtol=1e-9)
    assert_frequencies(f, [None, 1115.0], rtol=1e-9)
    with pytest.raises(AssertionError, match="not computed"):
        assert_frequencies(f, {4: 2000.0}, rtol=0.5)
    with pytest.raises(ValueError, match="tolerances"):
        compare_frequencies(f, [780.0, 1115.0], rtol=[0.1])


def test_results_dict_file_and_modes_object_are_accepted(tmp_path):
    res = {"crankmodal_version": "x", "modal": {"frequencies_hz": [100.0, 200.0]}}
    (tmp_path / "results.json").write_text(json.dumps(res))
    for r in (res, tmp_path / "results.json", str(tmp_path / "results.json")):
        assert_frequencies(r, [100.5, 199.0], rtol=0.01)

    class Modes:
        frequencies_hz = np.array([100.0, 200.0])

    with pytest.raises(AssertionError):
        assert_frequencies(Modes(), [100.0, 210.0], rtol=0.01)


def test_fe_bar_first_bending_frequencies_match_timoshenko_within_0p5_percent():
    """The helper on a real model: free-free bar vs the transfer-matrix Timoshenko oracle."""
    from fem_beam_theory import rectangle_shear_coefficient, timoshenko_frequencies

    from crankmodal.fem import testparts
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.classify import classify
    from crankmodal.fem.materials import material
    from crankmodal.fem.modal import solve_modes

    steel = material("steel")
    L, b, h = 0.4, 0.03, 0.02
    part = testparts.bar(L, b, h, divisions=(32, 3, 2), order=2)
    model = assemble(part, steel)
    modes = solve_modes(model, 4)
    labels = [c["label"] for c in classify(model.points, modes.shapes)]
    flat = [f for f, lab in zip(modes.frequencies_hz, labels) if lab == "bending about y"]
    theory = timoshenko_frequencies(2, L, steel.E, steel.nu, steel.rho, b * h, b * h ** 3 / 12,
                                    rectangle_shear_coefficient(steel.nu))
    assert_frequencies(flat, theory, rtol=0.005)


def test_pytest_plugin_fixture_passes_and_fails_in_a_user_suite(tmp_path):
    # the fixture comes from crankmodal's pytest11 entry point: a user's suite needs no setup
    (tmp_path / "test_user.py").write_text(
        "def test_ok(assert_frequencies):\n"
        "    assert_frequencies([780.0, 1120.0], [780.0, 1115.0], rtol=0.01)\n"
        "def test_bad(assert_frequencies):\n"
        "    assert_frequencies([700.0], [780.0], rtol=0.05)\n")
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           str(tmp_path / "test_user.py")],
                          check=False, capture_output=True, text=True, cwd=tmp_path,
                          timeout=120)
    assert "1 failed, 1 passed" in proc.stdout, proc.stdout + proc.stderr
    assert "error -10.3 %" in proc.stdout
