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


# -- seed 000 Sec. 3.2 sweeps, as in notebooks/seed_trends.py (0.1 s ramp, statistics over three
# revolutions from 0.15 s); numbers of the 5-revolution notebook run in the comments

def _four_star(c, rpm, n_rev=3, friction="coulomb"):
    from crankmodal.dynamics.signals import order_amplitudes

    t0 = 0.15
    h = _run("four_star_dynamics.toml", [
        f"dynamics.end_time={t0 + n_rev * 60.0 / rpm}", "dynamics.ramp_time=0.1",
        f"dynamics.speed_rpm={rpm}", f"dynamics.friction.law='{friction}'",
        f"dynamics.clearances=[{{joint='big_end_1', clearance={c}, journal_radius=0.0225}}]"])
    sel = h.t >= t0 - 1e-12
    ons = [o for o in h.onsets["big_end_1"] if o[0] >= t0]
    st = impact_statistics(ons, h.separations["big_end_1"], v_min=1e-3)
    fx = h.main_bearing_force[sel, 0]
    amps = order_amplitudes(h.t[sel], fx, rpm / 60.0, range(1, 41))
    return {"acc_peak": float(np.abs(h.piston_acceleration[sel, 0]).max()),
            "impacts_per_s": st["impact_count"] / (n_rev * 60.0 / rpm),
            "v_mean": st["impact_velocity_mean"],
            "broadband": 1.0 - 0.5 * float(np.sum(amps**2)) / float(np.var(fx[:-1]))}


@pytest.mark.slow
def test_seed000_fig26_clearance_broadens_the_main_bearing_spectrum_and_fig24_raises_peaks():
    # broadband = share of the x-force variance between the engine-order lines 1..40: ideal
    # joints 2e-6; 0.10 / 0.15 / 0.20 mm: 0.24 / 0.67 / 0.83; piston acceleration peaks
    # 6.5e3 / 4.2e4 / 6.0e4 m/s^2 (ideal 916)
    r = [_four_star(c, 1480.0) for c in (1.0e-4, 1.5e-4, 2.0e-4)]
    bb = [x["broadband"] for x in r]
    acc = [x["acc_peak"] for x in r]
    assert 0.1 < bb[0] < bb[1] < bb[2]
    assert acc[0] > 3.0 * 916.0 and acc[1] > 1.3 * acc[0] and acc[2] > 1.1 * acc[1]


@pytest.mark.slow
def test_seed000_fig25_higher_speed_gives_more_frequent_harder_impacts_than_148_rpm():
    # impacts per second at 0.10 mm: 148 / 740 / 1480 rpm -> 442 / 798 / 854 (5 revolutions);
    # the impact velocity rises from 148 to 740 rpm but not from 740 to 1480 rpm (not asserted)
    r = [_four_star(1.0e-4, rpm, n_rev=n) for rpm, n in ((148.0, 1), (740.0, 3), (1480.0, 3))]
    rate = [x["impacts_per_s"] for x in r]
    # 740 -> 1480 rpm adds only 7 %, within the scatter of three revolutions: not asserted
    assert rate[0] < 0.8 * rate[1] and rate[0] < 0.8 * rate[2]
    assert r[1]["v_mean"] > 1.5 * r[0]["v_mean"] and r[2]["v_mean"] > 1.3 * r[0]["v_mean"]


@pytest.mark.slow
def test_seed000_figs19_20_friction_broadens_the_main_bearing_band():
    # broadband share 0.12 without and 0.24 with Table 4 Coulomb friction (0.10 mm, 1480 rpm):
    # friction raises the mean impact velocity 0.20 -> 0.32 m/s. The seed's 225 Hz peak that
    # friction suppresses has no counterpart in the rigid model (its largest component above
    # 100 Hz is the 5th order line, 331 N with and without friction): not asserted
    dry = _four_star(1.0e-4, 1480.0, friction="none")
    fr = _four_star(1.0e-4, 1480.0)
    assert fr["broadband"] > 1.3 * dry["broadband"]
