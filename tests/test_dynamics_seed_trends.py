"""Seed trends (long runs, excluded from the default test run: ``pytest -m slow``)."""

from pathlib import Path

import numpy as np
import pytest

from crankmodal.dynamics.analysis import simulate
from crankmodal.dynamics.build import build_mechanism, solver_settings
from crankmodal.dynamics.signals import impact_statistics
from crankmodal.runner import check
from crankmodal.scene import load_scene

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def _run(scene, overrides):
    params = check(load_scene(SCENES / scene, overrides))
    p = params["dynamics"]
    mech = build_mechanism(p, params.get("mechanism"))
    return simulate(mech, p["end_time"], 1.0 / (720 * mech.revolution_hz),
                    solver_settings(p, 60 * mech.revolution_hz))


@pytest.mark.slow
def test_seed000_larger_big_end_clearance_gives_larger_piston_acceleration_peaks():
    peaks = []
    for c in (1.0e-4, 2.0e-4):
        h = _run("four_star_dynamics.toml", [
            "dynamics.end_time=0.2", "dynamics.ramp_time=0.0",
            f"dynamics.clearances=[{{joint='big_end_1', clearance={c}, journal_radius=0.02}}]"])
        peaks.append(np.abs(h.piston_acceleration[h.t > 0.05, 0]).max())
    assert peaks[1] > 1.5 * peaks[0]


@pytest.mark.slow
def test_seed003_impact_velocity_in_the_worn_big_end_rises_with_wear():
    vmax = []
    for major in (5e-5, 2e-4):
        h = _run("slider_crank_dynamics.toml", [
            "dynamics.end_time=0.08",
            f"dynamics.clearances=[{{joint='big_end_1', clearance=5e-5, clearance_major={major}, "
            "journal_radius=0.024}, {joint='small_end_1', clearance=2.5e-5, journal_radius=0.013}]"])
        vmax.append(impact_statistics(h.onsets["big_end_1"])["impact_velocity_max"])
    assert vmax[1] > 1.2 * vmax[0]
