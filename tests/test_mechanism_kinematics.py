"""Slider-crank kinematics against independent oracles: geometry, finite differences, series."""

import numpy as np
import pytest

from crankmodal.mechanism.inertia import direction, normal
from crankmodal.mechanism.kinematics import (
    acceleration_harmonics,
    exact_motion,
    kinematic_ratio,
    motion_from_harmonics,
    series_motion,
)

R, OMEGA = 0.035, 1480 * np.pi / 30  # seed 000
PSI = np.linspace(0, 2 * np.pi, 2001)


def _max_errors(lam):
    e, s = exact_motion(PSI, R, lam, OMEGA), series_motion(PSI, R, lam, OMEGA)
    return np.array([
        np.abs(e.x - s.x).max() / R,
        np.abs(e.v - s.v).max() / (R * OMEGA),
        np.abs(e.a - s.a).max() / (R * OMEGA**2),
        np.abs(e.beta - s.beta).max(),
        np.abs(e.beta_dot - s.beta_dot).max() / OMEGA,
        np.abs(e.beta_ddot - s.beta_ddot).max() / OMEGA**2,
    ])


def test_series_kinematics_error_scales_like_lambda_cubed():
    # Oracle: the Taylor remainder of eq. 1 -> eq. 2 (seed 000) is O(lambda^3) for x, v, a and
    # for the rod angle and its derivatives; halving lambda must divide the error by 8.
    lams = np.array([0.025, 0.05, 0.1])
    errs = np.array([_max_errors(lam) for lam in lams])
    slopes = np.diff(np.log(errs), axis=0) / np.diff(np.log(lams))[:, None]
    assert np.all(np.abs(slopes - 3.0) < 0.05), slopes
    # and the constant is order one: below lambda^3 for every quantity
    assert np.all(errs <= lams[:, None] ** 3)


def test_seed_lambda_series_acceleration_within_0p1_percent_of_exact_peak(oracle):
    lam = 25 / 280  # seed 000
    e, s = exact_motion(PSI, R, lam, OMEGA), series_motion(PSI, R, lam, OMEGA)
    peak = R * OMEGA**2 * (1 + lam)  # exact TDC acceleration, closed form
    oracle(stage="mechanism", quantity="piston acceleration at TDC, seed 000 lambda, m/s^2", reference="closed form r w^2 (1 + lambda)", tolerance="1e-12", measured=e.a.max(), expected=peak)
    assert e.a.max() == pytest.approx(peak, rel=1e-12)
    assert np.abs(e.a - s.a).max() < 1e-3 * peak


def test_velocity_and_acceleration_equal_finite_differences_of_displacement():
    lam, h = 0.3, 1e-4
    psi = np.linspace(0.0, 2 * np.pi, 97)
    x = lambda p: exact_motion(p, R, lam, OMEGA).x
    beta = lambda p: exact_motion(p, R, lam, OMEGA).beta
    m = exact_motion(psi, R, lam, OMEGA)
    v_fd = OMEGA * (x(psi + h) - x(psi - h)) / (2 * h)
    a_fd = OMEGA**2 * (x(psi + h) - 2 * x(psi) + x(psi - h)) / h**2
    bd_fd = OMEGA * (beta(psi + h) - beta(psi - h)) / (2 * h)
    bdd_fd = OMEGA**2 * (beta(psi + h) - 2 * beta(psi) + beta(psi - h)) / h**2
    # central differences: O(h^2) truncation, O(eps/h^2) round-off -> ~1e-7 relative
    assert np.abs(m.v - v_fd).max() < 1e-7 * R * OMEGA
    assert np.abs(m.a - a_fd).max() < 1e-5 * R * OMEGA**2
    assert np.abs(m.beta_dot - bd_fd).max() < 1e-7 * OMEGA
    assert np.abs(m.beta_ddot - bdd_fd).max() < 1e-5 * OMEGA**2
    assert np.allclose(kinematic_ratio(psi, R, lam), m.v / OMEGA, rtol=0, atol=1e-15)


def test_exact_displacement_closes_the_crank_rod_loop():
    # Oracle: plane geometry. The crankpin at r u(psi) and the piston pin on the cylinder axis at
    # (r + l - x) e must be exactly one rod length apart, and the rod angle must be the angle of
    # that segment to the axis.
    lam = 0.35
    length = R / lam
    phi = np.deg2rad(30.0)
    m = exact_motion(PSI, R, lam, OMEGA)
    pin = R * direction(PSI + phi)
    piston = (R + length - m.x)[:, None] * direction(phi)
    rod = piston - pin
    assert np.allclose(np.hypot(rod[:, 0], rod[:, 1]), length, rtol=1e-13)
    sin_beta = -(rod @ normal(phi)) / length
    assert np.allclose(sin_beta, np.sin(m.beta), atol=1e-13)


@pytest.mark.parametrize("lam", [0.1, 0.25])
def test_acceleration_harmonics_match_the_classical_series(oracle, lam):
    # Oracle: the classical expansion of the piston acceleration (e.g. Den Hartog, Mechanical
    # Vibrations): A1 = 1, A2 = lam + lam^3/4 + 15 lam^5/128, A4 = -(lam^3/4 + 3 lam^5/16),
    # A6 = 9 lam^5/128, odd orders above 1 are zero. Truncation of the oracle: O(lam^7).
    A = acceleration_harmonics(lam, 6)
    tol = 2 * lam**7
    assert A[0] == pytest.approx(1.0, abs=1e-13)
    oracle(stage="mechanism", quantity=f"piston acceleration, 2nd harmonic coefficient, lambda = {lam}", reference="classical series (Den Hartog)", tolerance=f"{tol:.1e} abs", measured=A[1], expected=lam + lam**3 / 4 + 15 * lam**5 / 128)
    assert A[1] == pytest.approx(lam + lam**3 / 4 + 15 * lam**5 / 128, abs=tol)
    assert A[3] == pytest.approx(-(lam**3 / 4 + 3 * lam**5 / 16), abs=tol)
    assert A[5] == pytest.approx(9 * lam**5 / 128, abs=tol)
    assert np.abs(A[[2, 4]]).max() < 1e-13


def test_harmonic_series_rebuilds_the_exact_acceleration():
    lam = 0.3
    exact = exact_motion(PSI, R, lam, OMEGA).a
    for order, tol in ((2, lam**3), (4, lam**5), (8, lam**9)):
        rebuilt = motion_from_harmonics(PSI, R, OMEGA, acceleration_harmonics(lam, order))
        assert np.abs(rebuilt - exact).max() < tol * R * OMEGA**2


def test_impossible_crank_rod_ratio_is_rejected():
    with pytest.raises(ValueError, match="lambda"):
        exact_motion(PSI, R, 1.2, OMEGA)
