"""Forced torsional response of a damped chain against independent oracles.

- two rotors under a harmonic torque: amplitude and phase against the closed form;
- synthesis (all orders, phased, half peak-to-peak) against a time integration of the ODE (scipy);
- resonance: the energy balance with the Holzer mode shape against the full response;
- dampers: a viscous damper ring against its own closed form on a single rotor.

Tolerances: the closed forms are evaluated in a second formulation (scalar algebra, not the
matrix solve), so agreement to 1e-9 relative is round-off of a 2x2 complex solve (~1e-15) with
ample margin; the time integration is checked to 1e-4 of the peak (DOP853 at rtol 1e-11 after the
transient has decayed below 1e-7 of the peak).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from crankmodal.errors import ParameterError
from crankmodal.torsion.chain import TorsionalChain
from crankmodal.torsion.damping import Damper
from crankmodal.torsion.excitation import rotor_excitation
from crankmodal.torsion.forced import (
    damped_train,
    energy_balance_amplitude,
    half_peak_to_peak,
    harmonic_response,
    steady_state,
)
from crankmodal.torsion.holzer import holzer

I1, I2, K = 0.3, 0.6, 1.32e5


def two_rotor_closed_form(w, T, c):
    """Rotor angles of I1 -[k, c]- I2 under T e^{i w t} on rotor 1 (scalar algebra)."""
    z = K + 1j * w * c
    den = w**2 * (I1 * I2 * w**2 - z * (I1 + I2))
    return T * (z - I2 * w**2) / den, T * z / den


@pytest.mark.parametrize("zeta", [0.0, 0.05])
def test_two_rotor_amplitude_and_phase_match_closed_form_1e9(zeta, oracle):
    chain = TorsionalChain([I1, I2], [K])
    wn = math.sqrt(K * (I1 + I2) / (I1 * I2))
    # a modal damping ratio zeta on the one elastic mode is a dashpot 2 zeta wn J_e across the
    # shaft (J_e = I1 I2 / (I1 + I2)): the closed form uses the dashpot
    c = 2 * zeta * wn * I1 * I2 / (I1 + I2)
    train = damped_train(chain, modal_damping=zeta)
    w = np.array([0.3, 0.97, 1.0, 1.6]) * wn
    if zeta == 0:
        w = w[w != wn]
    T = 120.0 * np.exp(0.4j)
    X = harmonic_response(train, w, np.tile([T, 0.0], (len(w), 1)))
    t1, t2 = two_rotor_closed_form(w, T, c)
    oracle(stage="torsion", quantity=f"two-rotor forced amplitude, zeta {zeta:g}",
           reference="closed form (scalar algebra of the two-rotor equations)", tolerance="1e-9 rel",
           measured=float(np.max(np.abs(np.concatenate([X[:, 0] / t1, X[:, 1] / t2]) - 1))), expected=0.0)
    np.testing.assert_allclose(np.abs(X[:, 0]), np.abs(t1), rtol=1e-9)
    np.testing.assert_allclose(np.abs(X[:, 1]), np.abs(t2), rtol=1e-9)
    np.testing.assert_allclose(np.angle(X[:, 0] / t1), 0.0, atol=1e-9)
    np.testing.assert_allclose(np.angle(X[:, 1] / t2), 0.0, atol=1e-9)
    # the same with the damping given as a relative section dashpot instead of modal damping
    train2 = damped_train(chain, modal_damping=0.0, section_damping=[c])
    X2 = harmonic_response(train2, w, np.tile([T, 0.0], (len(w), 1)))
    np.testing.assert_allclose(X2, X, rtol=1e-9)


def test_half_peak_to_peak_of_two_harmonics_matches_dense_sampling():
    # x = cos(p) + 0.8 cos(5 p + 1): extremes found on a 2e6-point grid (second evaluation)
    X = np.array([[1.0, 0.8 * np.exp(1j)]])
    half, _ = half_peak_to_peak(X, np.array([1, 5]))
    p = np.linspace(0, 2 * np.pi, 2_000_001)
    x = np.cos(p) + 0.8 * np.cos(5 * p + 1)
    assert half[0] == pytest.approx(0.5 * (x.max() - x.min()), rel=1e-9)


def _chain4():
    return TorsionalChain([0.4, 0.25, 0.25, 1.5], [2.0e5, 1.6e5, 2.4e5])


def test_synthesis_matches_time_integration_within_1e4_of_peak(oracle):
    from scipy.integrate import solve_ivp

    chain = _chain4()
    # absolute damping on every rotor so the rigid mode's drift from rest dies out too
    train = damped_train(chain, modal_damping=0.05, rotor_damping=[10.0, 10.0, 10.0, 10.0])
    harm = [{"rotor": 0, "order": 0.5, "amplitude": 40.0, "phase_deg": 10.0},
            {"rotor": 1, "order": 2.0, "amplitude": 90.0, "phase_deg": -70.0},
            {"rotor": 2, "order": 3.5, "amplitude": 60.0, "phase_deg": 200.0},
            {"rotor": 3, "order": 6.0, "amplitude": 25.0, "phase_deg": 45.0}]
    ex = rotor_excitation(4, 6.0, 2, harmonics=harm)
    rpm = 1150.0
    res = steady_state(train, ex, [rpm])
    Om = rpm * math.pi / 30
    Minv = 1.0 / np.diag(train.M)

    def torque(t):
        F = np.zeros(4)
        for h in harm:
            F[h["rotor"]] += h["amplitude"] * math.cos(h["order"] * Om * t + math.radians(h["phase_deg"]))
        return F

    def rhs(t, y):
        th, om = y[:4], y[4:]
        return np.concatenate([om, Minv * (torque(t) - train.C @ om - train.K @ th)])

    period = 4 * math.pi / Om  # one 720 deg cycle
    # slowest decay: the rigid mode, sum(c)/sum(I) = 40/2.4 = 16.7 per s, and mode 1 at
    # zeta omega = 21 per s; 16 cycles = 1.67 s leave e^-27 of the start transient
    n_cycles = 16
    sol = solve_ivp(rhs, (0, n_cycles * period), np.zeros(8), method="DOP853", rtol=1e-11, atol=1e-14,
                    t_eval=np.linspace((n_cycles - 1) * period, n_cycles * period, 40001))
    th = sol.y[:4]
    half_ode = 0.5 * (th.max(axis=1) - th.min(axis=1))
    peak = half_ode.max()
    oracle(stage="torsion", quantity="synthesised half peak-to-peak angle vs time integration",
           reference="scipy DOP853 integration of the chain ODE to steady state", tolerance="1e-4 of peak",
           measured=float(np.max(np.abs(res.amplitude_rad[0] - half_ode)) / peak), expected=0.0)
    np.testing.assert_allclose(res.amplitude_rad[0], half_ode, atol=1e-4 * peak)
    tw = chain.stiffnesses[:, None] * (th[:-1] - th[1:])
    half_t = 0.5 * (tw.max(axis=1) - tw.min(axis=1))
    np.testing.assert_allclose(res.section_torque_nm[0], half_t, atol=1e-4 * half_t.max())


@pytest.mark.parametrize("phased, bound", [(False, 1e-4), (True, 1e-3)])
def test_energy_balance_at_resonance_matches_full_response_for_light_damping(phased, bound, oracle):
    chain = _chain4()
    zeta = 0.01
    train = damped_train(chain, modal_damping=zeta)
    hz = holzer(chain)
    shape = hz.shapes[0]
    w = 2 * math.pi * hz.frequencies_hz[0]
    F = np.array([50.0, 80.0 * np.exp(0.3j if phased else 0.0), 30.0, 0.0])
    eb = energy_balance_amplitude(train, shape, w, F)
    full = np.abs(harmonic_response(train, [w], F[None])[0])
    ref = int(np.argmax(np.abs(shape)))
    rel = abs(eb[ref] / full[ref] - 1)
    oracle(stage="torsion", quantity=f"resonant amplitude, energy balance vs full ({'phased' if phased else 'in-phase'})",
           reference="energy balance with the Holzer mode shape (second formulation)", tolerance=bound,
           measured=rel, expected=0.0)
    # With modal damping the energy balance is exactly the resonant mode's share of the response;
    # the rest is the off-resonant modes (rigid and elastic). Under in-phase torques they move in
    # quadrature with the resonant mode and change the amplitude by O((2 zeta)^2 x their share)
    # (measured 4.7e-5 at zeta = 0.01, x4 per doubling of zeta); under phased torques they are not
    # in quadrature and the difference is O(2 zeta x their share) (measured 3.7e-4, x2 per doubling).
    assert rel < bound, rel


def test_viscous_damper_ring_on_one_rotor_matches_closed_form():
    # rotor J on a wall spring k, ring J_d coupled by c: closed form by substitution
    J, k, Jd, c = 1.0, 4.0e5, 0.25, 150.0
    chain = TorsionalChain([J], [k], fixed_end=True)
    train = damped_train(chain, modal_damping=0.0, dampers=[Damper(0, Jd, damping=c)])
    w = np.array([200.0, 600.0, 900.0])
    X = harmonic_response(train, w, np.ones((3, 1)) * 10.0)
    ring = 1j * w * c / (1j * w * c - Jd * w**2)  # ring angle / hub angle
    hub = 10.0 / (k - J * w**2 + 1j * w * c * (1 - ring))
    np.testing.assert_allclose(X[:, 0], hub, rtol=1e-9)
    np.testing.assert_allclose(X[:, 1], hub * ring, rtol=1e-9)


def test_negative_damping_and_bad_rotor_are_refused_naming_the_argument():
    chain = _chain4()
    with pytest.raises(ParameterError, match=r"rotor_damping\[2\]"):
        damped_train(chain, rotor_damping=[0, 0, -1.0, 0])
    with pytest.raises(ParameterError, match="modal_damping"):
        damped_train(chain, modal_damping=-0.01)
    with pytest.raises(ParameterError, match=r"section_damping"):
        damped_train(chain, section_damping=[1.0, 2.0])
    with pytest.raises(ParameterError, match=r"dampers\[0\].rotor"):
        damped_train(chain, dampers=[Damper(7, 0.1, damping=10.0)])
    with pytest.raises(ParameterError, match=r"harmonics\[0\].order"):
        rotor_excitation(4, 6.0, 1, harmonics=[{"rotor": 0, "order": 1.5, "amplitude": 1.0}])


@pytest.mark.parametrize("call, name", [
    (lambda tr, ex: rotor_excitation("4", 6.0, 2), "n_rotors"),
    (lambda tr, ex: rotor_excitation(4, 6.0, 3), "cycle_revolutions"),
    (lambda tr, ex: rotor_excitation(4, 6.0, 2, harmonics=[{"rotor": 0, "order": 1.0}]), r"harmonics\[0\].amplitude"),
    (lambda tr, ex: steady_state(tr, None, [100.0]), "excitation"),
    (lambda tr, ex: steady_state(tr, ex, [100.0, float("nan")]), r"speed_rpm\[1\]"),
    (lambda tr, ex: steady_state([1.0], ex, [100.0]), "train"),
    (lambda tr, ex: damped_train([0.4, 0.25]), "chain"),
])
def test_api_arguments_of_the_wrong_type_name_the_argument(call, name):
    train = damped_train(_chain4())
    ex = rotor_excitation(4, 6.0, 2, harmonics=[{"rotor": 0, "order": 1.0, "amplitude": 1.0}])
    with pytest.raises(ParameterError, match=name):
        call(train, ex)


def test_margins_count_only_significant_orders_and_match_hand_critical_speeds():
    from crankmodal.torsion.verdict import modal_excitation, separation_margins

    I, k = 0.5, 2.0e5
    train = damped_train(TorsionalChain([I, I], [k]))
    hz, shapes = train.natural_frequencies()
    f_n = math.sqrt(2 * k / I) / (2 * math.pi)  # equal rotors: closed form
    assert hz[0] == pytest.approx(f_n, rel=1e-12)
    # order 2 on both rotors in phase: the phase-vector sum on the shape [1, -1] is zero;
    # order 3 on rotor 1 only
    ex = rotor_excitation(2, 3.0, 1, harmonics=[{"rotor": 0, "order": 2.0, "amplitude": 50.0},
                                                {"rotor": 1, "order": 2.0, "amplitude": 50.0},
                                                {"rotor": 0, "order": 3.0, "amplitude": 20.0}])
    n2, n3 = 60 * f_n / 2, 60 * f_n / 3  # hand critical speeds
    ops = [1.03 * n2, 0.95 * n3]
    rel = np.array([modal_excitation(shapes, ex.at([n * math.pi / 30])[0]) for n in ops])
    rel /= rel.max(axis=2, keepdims=True)
    out = separation_margins(hz, ex.orders, rel, ops, 0.10, 0.10)
    # order 2 is inside the first band but cancels; order 3 is inside the second band
    assert [(v["order"], v["mode"]) for v in out["violations"]] == [(3.0, 1)]
    assert out["violations"][0]["margin"] == pytest.approx(n3 / ops[1] - 1, rel=1e-12)
    assert out["closest"][0]["order"] == 3.0 and not out["passes"]


def test_stress_check_worst_speed_and_stress_match_the_two_rotor_closed_form():
    from crankmodal.torsion.stress import Allowable, Section
    from crankmodal.torsion.verdict import stress_check

    zeta = 0.03
    wn = math.sqrt(K * (I1 + I2) / (I1 * I2))
    c = 2 * zeta * wn * I1 * I2 / (I1 + I2)
    train = damped_train(TorsionalChain([I1, I2], [K]), modal_damping=zeta)
    ex = rotor_excitation(2, 2.0, 1, harmonics=[{"rotor": 0, "order": 2.0, "amplitude": 80.0}])
    rpm = np.arange(100.0, 3000.0, 1.0)
    res = steady_state(train, ex, rpm)
    sec = Section.round(0.03, 0.01, 1.8)
    stress = np.column_stack([sec.stress(res.section_torque_nm[:, 0])])
    chk = stress_check(rpm, stress, np.abs(res.section_torque)[..., :1] * 1.8 / sec.section_modulus,
                       ex.orders, Allowable(2.0e8).stress, ["shaft"])
    w = 2 * rpm * math.pi / 30
    t1, t2 = two_rotor_closed_form(w, 80.0, c)
    tau = 1.8 * np.abs(K * (t1 - t2)) * 16 * 0.03 / (math.pi * (0.03**4 - 0.01**4))  # K_t T r / J_p
    assert chk["speed_rpm"] == rpm[np.argmax(tau)]
    assert chk["stress_pa"] == pytest.approx(tau.max(), rel=1e-9)
    assert chk["utilisation"] == pytest.approx(tau.max() / 1.0e8, rel=1e-9)
    assert chk["dominant_order"] == 2.0 and chk["passes"] == (tau.max() <= 1.0e8)


def test_tuned_rubber_damper_ring_matches_closed_form_with_complex_stiffness():
    J, k, Jd, kd, eta = 1.0, 4.0e5, 0.1, 3.5e4, 0.25
    chain = TorsionalChain([J], [k], fixed_end=True)
    train = damped_train(chain, modal_damping=0.0, dampers=[Damper(0, Jd, stiffness=kd, loss_factor=eta)])
    w = np.array([300.0, 590.0, 640.0, 900.0])
    X = harmonic_response(train, w, np.ones((4, 1)) * 10.0)
    z = kd * (1 + 1j * eta)  # rubber: complex stiffness
    ring = z / (z - Jd * w**2)
    hub = 10.0 / (k - J * w**2 + z * (1 - ring))
    np.testing.assert_allclose(X[:, 0], hub, rtol=1e-9)
    np.testing.assert_allclose(X[:, 1], hub * ring, rtol=1e-9)
