"""A loaded journal on the wall of its bore: the two rigid-body contact modes and fast-slip friction.

A journal of mass m pressed into a fixed bore by a constant load F = m g is a pendulum of length
c + delta_s (c the radial clearance, delta_s = (F/K)**(1/n) the static Hertz penetration): it rocks
along the wall at omega_t**2 = g / (c + delta_s) and bounces on the contact spring at
omega_n**2 = n K delta_s**(n-1) / m. Seed 000's Table 4 contact (K = 1.581e10 N/m^1.5, n = 1.5,
c = 0.1 mm) puts both inside the 100-2000 Hz band of its main-bearing spectra, so a rigid model
with this contact does have resonances. With the journal spinning fast (slip speed far above
v_dynamic) Coulomb friction is a constant mu_d F: it moves the equilibrium up the wall by the
friction angle atan(mu_d) and adds no damping to the rocking mode.
"""

import numpy as np
import pytest

from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.results.signals import window_peaks
from crankmodal.dynamics.run.integrate import SolverSettings, integrate

MASS, G, C, K, N = 2.0, 1500.0, 1e-4, 1.581e10, 1.5  # kg, m/s^2, m, N/m^1.5, -
TABLE4_FRICTION = {"mu_static": 0.05, "mu_dynamic": 0.08, "v_static": 1e-4, "v_dynamic": 1e-2}
DELTA_S = (MASS * G / K) ** (1.0 / N)


def _loaded_journal(friction="none", inertia=1e-3):
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", MASS, inertia, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=C,
                           journal_radius=0.0225, law="hertz",
                           law_params={"stiffness": K, "exponent": N}, friction=friction,
                           friction_params=TABLE4_FRICTION)
    return Multibody([journal], [], [joint], gravity=np.array([0.0, -G]))


def _run(sysm, q0, qd0, t_end):
    t = np.linspace(0.0, t_end, 4001)
    out = integrate(sysm, q0, qd0, t_end, t, SolverSettings(rtol=1e-9, atol=1e-14))
    return t, out.y


def _frequency(t, x):
    """Mean frequency (Hz) from the upward zero crossings of ``x - mean(x)``."""
    s = x - x.mean()
    k = np.nonzero((s[:-1] < 0.0) & (s[1:] >= 0.0))[0]
    tc = t[k] - s[k] * (t[k + 1] - t[k]) / (s[k + 1] - s[k])
    return (len(tc) - 1) / (tc[-1] - tc[0])


def test_loaded_journal_rocks_along_the_wall_at_the_pendulum_frequency():
    L = C + DELTA_S
    phi0 = 0.03
    q0 = np.array([L * np.sin(phi0), -L * np.cos(phi0), 0.0])
    t, y = _run(_loaded_journal(), q0, np.zeros(3), 0.02)
    f_pendulum = np.sqrt(G / L) / (2.0 * np.pi)          # 589 Hz for these numbers
    assert _frequency(t, y[0]) == pytest.approx(f_pendulum, rel=2e-3)


def test_loaded_journal_bounces_on_the_hertz_spring_at_its_linearised_frequency():
    q0 = np.array([0.0, -(C + 1.01 * DELTA_S), 0.0])     # 1 % deeper than static
    t, y = _run(_loaded_journal(), q0, np.zeros(3), 0.01)
    k_contact = N * K * DELTA_S ** (N - 1.0)
    f_normal = np.sqrt(k_contact / MASS) / (2.0 * np.pi)  # 1.9 kHz for these numbers
    assert _frequency(t, y[1]) == pytest.approx(f_normal, rel=2e-3)


def test_fast_slip_coulomb_friction_shifts_the_journal_by_the_friction_angle_without_damping():
    # journal spinning at 150 rad/s (slip 3.4 m/s >> v_dynamic): friction mu_d F against the
    # slip; started at the bottom it swings about the friction angle and keeps its amplitude
    L = C + DELTA_S
    _, y = _run(_loaded_journal("coulomb", inertia=1e3), np.array([0.0, -L, 0.0]),
                np.array([0.0, 0.0, 150.0]), 0.02)
    phi = np.arctan2(y[0], -y[1])                        # angle up the wall from the bottom
    phi_friction = np.arctan(TABLE4_FRICTION["mu_dynamic"])
    assert np.mean(phi) == pytest.approx(-phi_friction, rel=0.02)
    first, last = np.ptp(phi[: phi.size // 4]), np.ptp(phi[-phi.size // 4:])
    assert first == pytest.approx(2.0 * phi_friction, rel=0.02)
    assert last > 0.97 * first


def test_window_peaks_separate_a_rare_spike_from_the_typical_peak():
    t = np.linspace(0.0, 1.0, 10001)
    x = 3.0 * np.sin(2.0 * np.pi * 50.0 * t)
    x[5000] = 40.0
    p = window_peaks(t, x, 0.1)
    assert p["n_windows"] == 10
    assert p["max"] == 40.0
    assert p["median"] == pytest.approx(3.0, rel=1e-3)
