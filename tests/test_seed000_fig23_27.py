"""Seed 000 Figs. 23 and 27 (scenes/sweeps/seed000_fig23_27.py, docs/guide/seed_studies.md).

Fig. 23: the drive power of the four-star with ideal joints at constant speed against an
independent oracle, the energy method: P = d(T + V)/dt with T = 1/2 w^2 J(theta) from the exact
slider-crank geometry of each cylinder (the dynamics computes it from the constraint
multipliers instead), and gravity's P = g w r (2 m_p + m_r (4 - 2 a/l)) sin(theta) in closed form.
Fig. 27 and the clearance side of Fig. 23: only what the ensembles separate.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "scenes" / "sweeps" / "seed000_fig23_27.py"


def study():
    spec = importlib.util.spec_from_file_location("seed000_fig23_27", STUDY)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def mechanism_params():
    """The validated [mechanism] parameters of the Fig. 23 scene (geometry and masses only)."""
    from crankmodal.runner import check

    return check(study().scene(gas=False))["mechanism"]


def energy_power(mp, gravity: float = 0.0, n: int = 4096):
    """Drive power over one revolution at constant speed by the energy method (W), on ``n``
    crank angles theta (from +y towards +x, the [mechanism] convention).

    Exact slider-crank geometry per cylinder (bank angle phi from +y): pin p = r (sin t, cos t),
    piston s = x u with u = (sin phi, cos phi), x = r cos psi + l cos beta, sin beta =
    (r/l) sin psi, psi = t - phi; rod centre of mass c = p + (a/l)(s - p). The velocities per
    unit crank rate come from a complex-step derivative (exact to round-off), J(theta) =
    sum m_p |s'|^2 + m_r |c'|^2 + J_r beta'^2, and P = 1/2 w^3 J'(theta) + w V'(theta) with
    the derivatives in theta taken spectrally (the functions are periodic and smooth).
    """
    r, l = mp["crank_radius"], mp["rod_length"]
    m_r, a, J_r = mp["rod_mass"], mp["rod_cg_from_big_end"], mp["rod_inertia"]
    w = 2.0 * math.pi * mp["speed_rpm"] / 60.0
    t = 2.0 * math.pi * np.arange(n) / n
    h = 1e-30

    def parts(th, phi):
        psi = th - phi
        sb = r * np.sin(psi) / l
        beta = np.arcsin(sb)
        x = r * np.cos(psi) + l * np.cos(beta)
        u = (math.sin(phi), math.cos(phi))
        p = (r * np.sin(th), r * np.cos(th))
        s = (x * u[0], x * u[1])
        c = tuple(pi + a / l * (si - pi) for pi, si in zip(p, s))
        return s, c, beta

    J = np.zeros(n)
    V = np.zeros(n)
    for cyl in mp["cylinders"]:
        phi = math.radians(cyl["bank_angle_deg"])
        s_d, c_d, b_d = parts(t + 1j * h, phi)
        J += (cyl["piston_mass"] * (np.imag(s_d[0]) ** 2 + np.imag(s_d[1]) ** 2) / h ** 2
              + m_r * (np.imag(c_d[0]) ** 2 + np.imag(c_d[1]) ** 2) / h ** 2
              + J_r * (np.imag(b_d) / h) ** 2)
        s, c, _ = parts(t, phi)
        V += gravity * (cyl["piston_mass"] * s[1] + m_r * c[1])
    k = np.fft.rfftfreq(n, 1.0 / n)

    def d(f):
        return np.fft.irfft(1j * k * np.fft.rfft(f), n)

    return 0.5 * w ** 3 * d(J) + w * d(V)


def orders(P, n_orders=8):
    """Amplitudes of orders 1..n_orders of one revolution of P (W)."""
    return 2.0 * np.abs(np.fft.rfft(P)[1:n_orders + 1]) / P.size


@pytest.mark.slow
@pytest.mark.parametrize("gravity", [False, True])
def test_fig23_ideal_drive_power_is_the_energy_method_power(gravity):
    """Inertia only: the four-star's drive power is order 4 (orders 1-3 cancel over the
    0/180/270/90 deg banks), 61.2 W; with gravity the unbalanced first-order mass adds
    g w r (2 m_p + m_r (4 - 2 a/l)) = g w 0.2688 kg m = 408.5 W at order 1. The dynamics
    (constraint multipliers times crank speed, integrated at rtol 1e-6) within 1e-4 of the
    oracle's order amplitudes (integration error ~1e-7 relative here; 1e-4 leaves room for any
    x86-64 CPU and tolerance choice) and 1e-3 of its half range (1-degree sampling)."""
    from crankmodal.dynamics.run.simulate import simulate

    mod = study()
    mp = mechanism_params()
    g = mod.G if gravity else 0.0
    oracle = energy_power(mp, g)
    o_ref = orders(oracle)
    sc = mod.scene(joints=(), gas=False, gravity=gravity, end_time=0.2)
    p, mech, settings, dt = mod.prepare(sc)
    hist = simulate(mech, p["end_time"], dt, settings, ideal=True)
    num = mod.trajectory_numbers(hist, p, mech.revolution_hz)["power"]
    w = 2.0 * math.pi * mp["speed_rpm"] / 60.0
    big = o_ref.max()
    for k in range(1, 9):
        assert abs(num[f"order_{k}"]["mean"] - o_ref[k - 1]) <= 1e-4 * big, (k, num, o_ref)
    # the half range of 1-degree samples misses an order-4 peak by up to 1 - cos(2 deg) = 6.1e-4
    assert num["half_range"]["mean"] == pytest.approx(0.5 * np.ptp(oracle), rel=1e-3)
    assert abs(num["mean"]["mean"]) <= 1e-4 * big
    if gravity:
        r, l = mp["crank_radius"], mp["rod_length"]
        mr = r * (2 * 1.2 + mp["rod_mass"] * (4 - 2 * mp["rod_cg_from_big_end"] / l))
        assert mr == pytest.approx(0.2688, rel=1e-3)  # [mechanism]'s first-order counterweight
        assert num["order_1"]["mean"] == pytest.approx(g * w * mr, rel=1e-4)  # 408.5 W
    else:
        assert o_ref[3] == pytest.approx(61.2, abs=0.05)  # order 4 only
        assert np.all(o_ref[[0, 1, 2, 4, 5, 6]] < 1e-9 * o_ref[3])


def separated(a: dict, b: dict, k: float = 2.0) -> bool:
    """``b`` larger than ``a`` by more than ``k`` combined standard errors (ensemble means)."""
    return b["mean"] - a["mean"] > k * math.hypot(a["sem"], b["sem"])


@pytest.mark.slow
def test_fig23_clearance_raises_the_drive_power_beyond_the_ideal():
    """Ensembles of 6 trajectories (0.5 s, 8 revolutions each). What the full study (12
    trajectories) separates by 6-10 standard errors: with the gas forces the 0.1 mm big end
    costs mean drive power (11.45 +- 0.12 kW against the ideal 10.29 kW: friction and contact
    damping) and raises the impact-filtered (orders <= 12) amplitude (6.61 +- 0.09 kW against
    6.02 kW); inertia only, that amplitude is 1.66 +- 0.21 kW against the ideal 61 W."""
    mod = study()
    gas = mod.run_case(mod.scene(gas=True), 6, log=lambda s: None)
    e, i = gas["ensemble"]["power"], gas["ideal"]["power"]
    ideal = {"sem": 0.0}
    assert separated(dict(ideal, mean=i["mean"]["mean"]), e["mean"])
    assert separated(dict(ideal, mean=i["half_range_filtered"]["mean"]), e["half_range_filtered"])
    dry = mod.run_case(mod.scene(gas=False), 6, log=lambda s: None)
    e, i = dry["ensemble"]["power"], dry["ideal"]["power"]
    assert i["half_range_filtered"]["mean"] == pytest.approx(61.17, rel=1e-3)
    assert e["half_range_filtered"]["mean"] - 3 * e["half_range_filtered"]["sem"] > 5 * 61.17


@pytest.mark.slow
def test_fig27_cumulative_clearances_ordering_where_the_ensembles_separate_it():
    """Seed 000 Fig. 27 cases 1-4 (0.1 mm in big ends 1..k), 6 trajectories each. The full
    study's per-revolution peak of the main-bearing X force: 13.4 +- 0.4, 17.0 +- 0.4,
    29.1 +- 1.6, 32.5 +- 1.9 kN: case 1 < case 2 < case 3 each by about 7 standard errors
    (asserted here at 2), case 3 against case 4 by 1.4 (undecided: not asserted). The seed
    has case 2 the largest and case 3 below it; the order-1 amplitude stays the ideal
    joints' (4550 N) within 0.3 % in every case."""
    mod = study()
    res = {name: mod.run_case(mod.scene(joints, end_time=0.5), 6, log=lambda s: None)
           for name, joints in mod.FIG27_CASES.items()}
    peak = [res[f"case {k}"]["ensemble"]["force_x"]["peak"] for k in range(1, 5)]
    assert separated(peak[0], peak[1])
    assert separated(peak[1], peak[2])
    ideal_1 = res["case 1"]["ideal"]["force_x"]["order_1"]["mean"]
    for r in res.values():
        assert r["ensemble"]["force_x"]["order_1"]["mean"] == pytest.approx(ideal_1, rel=3e-3)
