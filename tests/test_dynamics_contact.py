"""Contact laws of the clearance joint against closed-form impact results.

A free journal (no gravity, no friction) starts at the centre of a fixed bearing and flies
radially into the wall. Away from the wall no force acts, so the speed at which it reaches the
opposite wall is its rebound speed; the ratio to the first impact speed is the coefficient of
restitution the law produces.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from crankmodal.dynamics.laws import contact
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import AUX_NAMES, Multibody
from crankmodal.dynamics.run.integrate import SolverSettings, integrate

MASS = 2.0
CLEARANCE = 1e-4


def _journal_in_bearing(law, params, friction="none", friction_params=None, spin=0.0, vy=0.0):
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", MASS, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=CLEARANCE,
                           journal_radius=0.01, law=law, law_params=params, friction=friction,
                           friction_params=friction_params or {})
    sysm = Multibody([journal], [], [joint])
    return sysm, joint


def _first_two_impacts(law, params, v0=1.0, t_end=3e-3):
    sysm, _ = _journal_in_bearing(law, params)
    out = integrate(sysm, np.zeros(3), np.array([v0, 0.0, 0.0]), t_end, None,
                    SolverSettings(rtol=1e-9, atol=1e-13))
    onsets = out.onsets[0]
    return onsets, out.separations[0]


def _hunt_crossley_exact_restitution(a):
    """Root of  a (1 + e) = -ln((1 - a e) / (1 + a)),  a = chi v0, from m v dv = -K d^n (1 + chi v) dd."""
    return brentq(lambda e: a * (1.0 + e) + np.log((1.0 - a * e) / (1.0 + a)), 1e-12,
                  min(1.0, 1.0 / a - 1e-12) if a > 1 else 1.0)


@pytest.mark.parametrize("law", ["hunt_crossley", "lankarani_nikravesh", "flores"])
@pytest.mark.parametrize("e", [0.3, 0.9])
def test_hysteresis_law_rebound_matches_exact_energy_integral(law, e):
    # Oracle: for F = K d^n (1 + chi d'), the phase-plane integral gives e_out independent of K, n.
    v0 = 1.0
    a = float(contact.hysteresis_factor(law, e, v0)) * v0
    expected = _hunt_crossley_exact_restitution(a)
    onsets, _ = _first_two_impacts(law, {"stiffness": 1e10, "exponent": 1.5, "restitution": e}, v0)
    assert len(onsets) >= 2
    assert onsets[0][1] == pytest.approx(v0, rel=1e-6)  # event located on the dense output
    assert onsets[1][1] / v0 == pytest.approx(expected, rel=2e-5)


def test_lankarani_nikravesh_gives_its_restitution_for_hard_impacts(oracle):
    # LN (1990) is derived for e near 1: e = 0.9 requested, 0.9 delivered within 1.5 %.
    onsets, _ = _first_two_impacts("lankarani_nikravesh",
                                   {"stiffness": 1e10, "exponent": 1.5, "restitution": 0.9})
    oracle(stage="dynamics", quantity="Lankarani-Nikravesh law, coefficient of restitution", reference="the law's design value e = 0.9 (LN 1990)", tolerance="1.5 %", measured=onsets[1][1], expected=0.9)
    assert onsets[1][1] == pytest.approx(0.9, rel=0.015)


def test_flores_law_gives_its_restitution_over_a_wide_range(oracle):
    # Flores et al. (2011) target the whole range: e = 0.5 requested, exact integral 0.47 (6 %).
    onsets, _ = _first_two_impacts("flores", {"stiffness": 1e10, "exponent": 1.5,
                                              "restitution": 0.5})
    oracle(stage="dynamics", quantity="Flores law, coefficient of restitution", reference="the law's design value e = 0.5 (Flores et al. 2011)", tolerance="12 %", measured=onsets[1][1], expected=0.5)
    assert onsets[1][1] == pytest.approx(0.5, rel=0.12)


def test_hertz_impact_is_elastic_and_lasts_the_hertz_contact_time(oracle):
    # Oracle: Hertz (n = 3/2) contact time 2.9432 d_max / v0, d_max = (5 m v0^2 / 4 K)^(2/5).
    K, v0 = 1e10, 1.0
    onsets, seps = _first_two_impacts("hertz", {"stiffness": K, "exponent": 1.5}, v0)
    d_max = (2.5 * MASS * v0**2 / (2 * K)) ** 0.4
    assert onsets[1][1] == pytest.approx(v0, rel=1e-6)
    oracle(stage="dynamics", quantity="Hertz impact contact time, s", reference="closed form 2.9432 d_max / v0", tolerance="1e-4", measured=seps[0] - onsets[0][0], expected=2.9432 * d_max / v0)
    assert seps[0] - onsets[0][0] == pytest.approx(2.9432 * d_max / v0, rel=1e-4)


def test_impact_law_damping_ramp_is_continuous_and_dissipative():
    # ADAMS IMPACT: no damping force at first touch (STEP starts at 0), full damping beyond d_max.
    p = {"K": 1e8, "n": 1.5, "c_max": 100.0, "d_max": 1e-4}
    assert contact.impact(1e-12, 1.0, **p) == pytest.approx(0.0, abs=1e-6)
    deep = contact.impact(2e-4, 1.0, **p)
    assert deep == pytest.approx(1e8 * 2e-4**1.5 + 100.0)
    onsets, _ = _first_two_impacts("impact", {"stiffness": 1e10, "exponent": 1.5, "damping": 2000.0,
                                              "penetration": 1e-5})
    assert 0.0 < onsets[1][1] < 1.0


def test_coulomb_transition_and_ambrosio_law_are_odd_and_reach_their_coefficients():
    v = np.array([-1.0, -0.02, -1e-4, 0.0, 1e-4, 0.02, 1.0])
    mu = contact.coulomb_coefficient(v, mu_s=0.3, mu_d=0.1, v_s=1e-4, v_d=1e-2)
    np.testing.assert_allclose(mu, -mu[::-1])
    assert mu[3] == 0.0 and mu[4] == pytest.approx(0.3) and mu[5] == pytest.approx(0.1)
    amb = contact.ambrosio_coefficient(v, mu_d=0.1, v0=1e-4, v1=1e-2)
    assert amb[4] == 0.0 and amb[5] == pytest.approx(0.1) and amb[2] == 0.0


@pytest.mark.parametrize("friction", ["coulomb", "ambrosio"])
def test_spinning_journal_friction_energy_is_booked(friction):
    # A journal thrown off-centre with spin rubs the wall: kinetic energy lost = contact damping
    # + friction dissipation (energy balance closes), and friction does take energy out.
    sysm, _ = _journal_in_bearing("lankarani_nikravesh",
                                  {"stiffness": 1e9, "exponent": 1.5, "restitution": 0.7},
                                  friction, {"mu_static": 0.2, "mu_dynamic": 0.15,
                                             "v_static": 1e-4, "v_dynamic": 1e-2})
    y = integrate(sysm, np.zeros(3), np.array([0.5, 0.2, 200.0]), 4e-3, None,
                  SolverSettings(rtol=1e-8, atol=1e-13)).y
    ke0 = sysm.energy(np.zeros(3), np.array([0.5, 0.2, 200.0]))[0]
    ke, _ = sysm.energy(y[:3, -1], y[3:6, -1])
    el = sum(float(contact.elastic_energy(cj.law.name, cj.gap(sysm, y[:3, -1]), cj.law.params()))
             for cj in sysm.clearances)
    d_contact = y[6 + AUX_NAMES.index("dissipated_contact"), -1]
    d_friction = y[6 + AUX_NAMES.index("dissipated_friction"), -1]
    assert d_friction > 1e-3 * ke0
    assert ke + el - ke0 == pytest.approx(-(d_contact + d_friction), abs=1e-6 * ke0)


def test_cylinder_stiffness_grows_as_the_clearance_closes():
    # K ~ sqrt(R_i R_j / (R_j - R_i)): quartering the clearance doubles the stiffness.
    k1 = contact.cylinder_stiffness(0.02, 0.02 + 1e-4, 2.1e11, 0.3, 2.1e11, 0.3)
    k2 = contact.cylinder_stiffness(0.02, 0.02 + 0.25e-4, 2.1e11, 0.3, 2.1e11, 0.3)
    assert k2 / k1 == pytest.approx(2.0, rel=5e-3)  # R_j also shrinks slightly
    # steel on steel, R = 20 mm, c = 0.1 mm: 4/(3 * 2 * 0.91 / 2.1e11) * sqrt(0.02 * 0.0201 / 1e-4)
    assert k1 == pytest.approx(1.5385e11 * np.sqrt(0.02 * 0.0201 / 1e-4), rel=1e-3)


@pytest.mark.parametrize("direction,axis_clearance", [((-1.0, 0.0), 1.4e-4), ((0.0, -1.0), 1e-4)])
def test_worn_elliptical_bore_holds_a_loaded_journal_at_the_axis_clearance_plus_static_deflection(
        direction, axis_clearance):
    # Seed 003's worn bearing: bore semi-axes R + 0.14 mm (x) and R + 0.1 mm (y). A journal under
    # a constant load along an axis settles at that axis' clearance + m g / K (linear law).
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", MASS, 1e-3, {"centre": (0.0, 0.0)})
    K, g = 1e9, 2000.0
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=1e-4,
                           clearance_major=1.4e-4, journal_radius=0.01, law="kelvin_voigt",
                           law_params={"stiffness": K, "damping": 3e4})
    sysm = Multibody([journal], [], [joint], gravity=g * np.array(direction))
    y = integrate(sysm, np.zeros(3), np.zeros(3), 0.03, None, SolverSettings(rtol=1e-7, atol=1e-12)).y
    pos = y[:2, -1]
    expected = (axis_clearance + MASS * g / K) * np.array(direction)
    np.testing.assert_allclose(pos, expected, atol=1e-9)


def test_worn_bore_contact_on_a_spinning_bearing_conserves_energy():
    # Elastic (Hertz) contact in an elliptical bore that itself rotates: the force along the
    # gradient of the penetration and the bearing moment make the contact conservative.
    ground = Ground(frames={"o": (0.0, 0.0)})
    ring = RigidBody("ring", 3.0, 2e-3, {"bore": (0.0, 0.0)})
    journal = RigidBody("journal", MASS, 1e-3, {"centre": (0.0, 0.0)})
    from crankmodal.dynamics.model.joints import Revolute

    joint = ClearanceJoint("c", journal, "centre", ring, "bore", clearance=1e-4,
                           clearance_major=4e-4, wear_angle=0.3, journal_radius=0.01,
                           law="hertz", law_params={"stiffness": 1e10, "exponent": 1.5})
    sysm = Multibody([ring, journal], [Revolute("pivot", ring, "bore", ground, "o")], [joint])
    q0, qd0 = np.zeros(6), np.array([0.0, 0.0, 30.0, 0.4, 0.3, 0.0])
    out = integrate(sysm, q0, qd0, 0.008, None, SolverSettings(rtol=1e-9, atol=1e-14))
    y = out.y[:, -1]
    ke0 = sysm.energy(q0, qd0)[0]
    ke = sysm.energy(y[:6], y[6:12])[0]
    el = float(contact.elastic_energy("hertz", joint.gap(sysm, y[:6]), joint.law.params()))
    assert len(out.onsets[0]) >= 2
    assert ke + el == pytest.approx(ke0, rel=1e-6)


def test_impact_statistics_counts_a_bouncing_ball_by_velocity_and_by_flight_time():
    # closed form: a ball dropped onto a rigid floor at v0 with restitution e lands at
    # v_k = e^k v0 after flights 2 v_{k-1} / g; the contact itself takes no time
    from crankmodal.dynamics.results.signals import impact_statistics

    g, v0, e = 9.81, 2.0, 0.8
    v = v0 * e ** np.arange(30)
    t_on = np.concatenate([[0.0], np.cumsum(2.0 * v[:-1] / g)])
    onsets = list(zip(t_on, v))
    seps = list(t_on)                                   # leaves the floor at once
    all_ = impact_statistics(onsets, seps)
    assert all_["impact_count"] == all_["onset_count"] == 30
    assert all_["impact_velocity_max"] == pytest.approx(v0)
    k_v = int(np.floor(np.log(0.3) / np.log(e))) + 1     # e^k >= 0.3
    assert impact_statistics(onsets, seps, v_min=0.3 * v0)["impact_count"] == k_v
    tau = 0.1                                            # flight 2 v0 e^(k-1) / g >= tau
    k_f = 1 + int(np.floor(np.log(tau * g / (2 * v0)) / np.log(e))) + 1
    st = impact_statistics(onsets, seps, min_flight=tau)
    assert st["impact_count"] == k_f
    assert st["impact_velocity_mean"] == pytest.approx(np.mean(v[:k_f]))


def test_the_deepest_point_of_an_impact_is_an_event_however_coarse_the_output():
    # Oracle: Hertz d_max = (5 m v0^2 / 4 K)^(2/5), peak force K d_max^1.5. Only the start is
    # sampled, so no sample sees a contact; the events find each contact's deepest point.
    K, v0 = 1e10, 1.0
    sysm, joint = _journal_in_bearing("hertz", {"stiffness": K, "exponent": 1.5})
    out = integrate(sysm, np.zeros(3), np.array([v0, 0.0, 0.0]), 3e-3, np.array([0.0]),
                    SolverSettings(rtol=1e-9, atol=1e-13))
    d_max = (2.5 * MASS * v0**2 / (2 * K)) ** 0.4
    assert out.t.size == 1
    peaks = out.peaks[0]
    assert len(peaks) == len(out.onsets[0]) >= 2  # one deepest point per contact
    for _, y in peaks:
        k = joint.kinematics(sysm, y[:3], y[3:6])
        assert k["delta"] == pytest.approx(d_max, rel=1e-6)
        assert abs(k["delta_dot"]) < 1e-6 * v0
        assert contact.normal_force("hertz", k["delta"], k["delta_dot"], joint.law.params(),
                                    v0) == pytest.approx(K * d_max**1.5, rel=2e-6)


# ----------------------------------------------------------------- Johnson's conformal cylinders
E_STAR = 2.1e11 / (2 * (1 - 0.3**2))  # steel on steel, plane strain, Pa


def _johnson_delta(F, L, dR):
    """Johnson's closed form, written out: delta = F/(pi L E*) (ln(4 pi L E* dR / F) - 1)."""
    import math

    return F / (math.pi * L * E_STAR) * (math.log(4 * math.pi * L * E_STAR * dR / F) - 1.0)


@pytest.mark.parametrize("F", [1.0, 100.0, 1e4, 2e5])
def test_johnson_cylinder_force_inverts_the_closed_form_approach(F):
    # a 45 mm journal, 45 mm long, 0.1 mm clearance: 20 kN -> 5.9 um (the four-star's big end
    # penetrated 111 um under its IMPACT stiffness)
    L, dR = 0.045, 1e-4
    K = np.pi * L * E_STAR
    d = _johnson_delta(F, L, dR)
    assert float(contact.johnson_cylinder_approach(F, K, dR)) == pytest.approx(d, rel=1e-14)
    assert float(contact.johnson_cylinder_force(d, K, dR)) == pytest.approx(F, rel=1e-12)
    assert float(contact.normal_force("johnson_cylinder", d, 0.0, {
        "stiffness": K, "radial_clearance": dR, "restitution": 0.9})) == pytest.approx(F, rel=1e-12)
    if F == 1e4:
        assert d == pytest.approx(3.36e-6, rel=1e-3)  # micrometres; within the range (< 0.4 dR)


def test_johnson_cylinder_energy_and_stiffness_are_the_integral_and_slope_of_its_force():
    from scipy.integrate import quad

    K, dR = np.pi * 0.02 * E_STAR, 5e-5
    for d in (1e-8, 1e-6, 1.5e-5, 3e-5):  # the last beyond the tangent continuation (0.40 dR)
        w = quad(lambda x: float(contact.johnson_cylinder_force(x, K, dR)), 0.0, d,
                 epsabs=0.0, epsrel=1e-11, limit=200)[0]
        assert float(contact.johnson_cylinder_energy(d, K, dR)) == pytest.approx(w, rel=1e-8)
        h = d * 1e-6
        slope = (contact.johnson_cylinder_force(d + h, K, dR)
                 - contact.johnson_cylinder_force(d - h, K, dR)) / (2 * h)
        assert float(contact.johnson_cylinder_stiffness(d, K, dR)) == pytest.approx(slope, rel=1e-5)
    assert contact.johnson_cylinder_force(-1e-6, K, dR) == 0.0


@pytest.mark.parametrize("e", [0.3, 0.9])
def test_johnson_cylinder_rebound_matches_the_exact_energy_integral(e):
    # F = F_J(delta) (1 + chi delta'): the phase-plane integral gives the Hunt-Crossley restitution
    # for any elastic force, so the same oracle holds for Johnson's law with LN damping
    v0 = 1.0
    a = float(contact.hysteresis_factor("johnson_cylinder", e, v0)) * v0
    expected = _hunt_crossley_exact_restitution(a)
    params = {"stiffness": np.pi * 0.02 * E_STAR, "radial_clearance": CLEARANCE, "restitution": e}
    onsets, _ = _first_two_impacts("johnson_cylinder", params, v0)
    assert len(onsets) >= 2
    assert onsets[1][1] / v0 == pytest.approx(expected, rel=2e-5)


def test_johnson_cylinder_slider_crank_penetrates_micrometres_and_soft_impact_is_warned(tmp_path):
    # End to end: a 3 kN gas load on a 40 mm journal, 20 mm long, in a 0.1 mm clearance. Johnson's
    # law: micrometres and no warning. IMPACT at K = 1e9 (issue 18: 0.32 mm in the four-star):
    # a penetration warning naming the joint, the clearance and contact.stiffness.
    import copy
    import warnings as w

    from crankmodal.runner import run
    from crankmodal.scene import scene_from_dict

    base = {"dynamics": {
        "mechanism": "slider_crank", "speed_rpm": 3000.0, "end_time": 0.025, "run_ideal": False,
        "gas_force_deg": [0.0, 90.0, 180.0, 270.0, 360.0],
        "gas_force_n": [3000.0, 500.0, 0.0, 500.0, 3000.0],
        "crank_train": {"crank_radius": 0.035, "rod_length": 0.14},
        "clearances": [{"joint": "big_end_1", "clearance": 1e-4, "journal_radius": 0.02,
                        "bearing_length": 0.02}],
        "contact": {"law": "johnson_cylinder", "restitution": 0.8}}}
    with w.catch_warnings():
        w.simplefilter("ignore")
        res = run(scene_from_dict(copy.deepcopy(base), name="j"), tmp_path / "j",
                  figures=False)["dynamics"]
    j = res["clearance_joints"]["big_end_1"]
    assert j["law"] == "johnson_cylinder" and j["stiffness"] == pytest.approx(np.pi * 0.02 * E_STAR)
    # while in contact: median 3.2 um under a median 4.1 kN (the closed form's 3.16 um)
    arr = np.load(tmp_path / "j" / "dynamics.npz")
    pen, fn = arr["contact_big_end_1_penetration"], arr["contact_big_end_1_fn"]
    on = pen > 0.0
    assert 1e-6 < np.median(pen[on]) < 5e-6
    assert np.median(pen[on]) == pytest.approx(_johnson_delta(np.median(fn[on]), 0.02, 1e-4),
                                               rel=0.05)
    # the deepest point (the first impact, 0.7 m/s from the centred start) on the closed form
    F = j["peak_contact_force_n"]
    assert j["max_penetration_m"] == pytest.approx(_johnson_delta(F, 0.02, 1e-4), rel=0.3)
    assert not any("penetrates" in t for t in res["warnings"])
    soft = copy.deepcopy(base)
    soft["dynamics"]["contact"] = {"law": "impact", "stiffness": 1e9}
    with w.catch_warnings():
        w.simplefilter("ignore")
        res = run(scene_from_dict(soft, name="s"), tmp_path / "s", figures=False)["dynamics"]
    texts = [t for t in res["warnings"] if "penetrates" in t]
    assert len(texts) == 1
    assert "'big_end_1'" in texts[0] and "100 µm clearance" in texts[0]  # 1e-4 m
    assert "dynamics.contact.stiffness (now 1e+09)" in texts[0] and "johnson_cylinder" in texts[0]


def test_johnson_cylinder_needs_the_bearing_length():
    from crankmodal.errors import SceneError
    from crankmodal.runner import check
    from crankmodal.scene import scene_from_dict

    data = {"dynamics": {"mechanism": "slider_crank", "speed_rpm": 3000.0,
                         "clearances": [{"joint": "big_end_1"}],
                         "contact": {"law": "johnson_cylinder"}}}
    with pytest.raises(SceneError, match=r"dynamics.clearances\[0\].bearing_length: is required "
                                         "with contact.law = 'johnson_cylinder'"):
        check(scene_from_dict(data, name="t"))
