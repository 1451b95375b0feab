"""The largest von Mises stress of a run found by bounds (dynamics.results.peak_stress) against
the brute-force superposition of every point at every time (an independent loop written here)."""

import numpy as np
import pytest

from crankmodal.dynamics.results.peak_stress import peak_von_mises


def _brute(S, xi):
    """Every point, every time: σ_p(t) = Σ_k S_pk ξ_k(t), von Mises written out per component."""
    best, where, when = 0.0, 0, 0
    for p in range(S.shape[0]):
        sig = xi @ S[p].T  # (t, 6)
        xx, yy, zz, yz, xz, xy = sig.T
        vm = np.sqrt(((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2) / 2
                     + 3 * (yz ** 2 + xz ** 2 + xy ** 2))
        j = int(np.argmax(vm))
        if vm[j] > best:
            best, where, when = float(vm[j]), p, j
    return best, where, when


def _modes_and_run(seed, n_points=3000, k=12, n_times=400, hot=5):
    """Stress modes decaying with the mode number, a few hot points (a fillet), and modal
    coordinates of a run: harmonics whose amplitude falls with the mode number."""
    rng = np.random.default_rng(seed)
    S = rng.normal(size=(n_points, 6, k)) * 1e9 / (1 + np.arange(k)) ** 2
    S[rng.choice(n_points, hot, replace=False)] *= 8.0
    t = np.linspace(0.0, 0.1, n_times)
    xi = np.stack([1e-3 / (1 + m) ** 1.5 * np.sin(2 * np.pi * (25 * (m + 1)) * t + m)
                   for m in range(k)], axis=1)
    return S, xi


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_peak_equals_brute_force_and_skips_points(seed):
    S, xi = _modes_and_run(seed)
    best, where, when = _brute(S, xi)
    got = peak_von_mises(S, xi, chunk=64)
    # the same sums in another order (matrix product against a per-point loop): equal within
    # round-off, 1e-12 of the value is 1e4 times the double precision of a 12-term sum
    assert got.value == pytest.approx(best, rel=1e-12)
    assert (got.point, got.time_index) == (where, when)
    assert got.points_superposed < S.shape[0] // 2  # the bounds leave most points out


def test_bound_holds_for_every_point_and_zero_run_gives_zero():
    """Seminorm bound: no point's stress exceeds Σ_k A_k vm(S_pk); a run at rest has none."""
    from crankmodal.reduction.stress_modes import von_mises

    S, xi = _modes_and_run(3, n_points=400)
    vm = von_mises(np.einsum("pik,tk->pit", S, xi), axis=1).max(axis=1)
    bound = von_mises(S, axis=1) @ np.abs(xi).max(axis=0)
    assert np.all(vm <= bound * (1 + 1e-12))
    zero = peak_von_mises(S, np.zeros_like(xi))
    assert zero.value == 0.0 and zero.points_superposed <= 256


def test_deflection_peak_equals_brute_force():
    """The in-plane deflection length (a Euclidean seminorm) by bounds: the same maximum."""
    from crankmodal.dynamics.results.peak_stress import peak_seminorm

    rng = np.random.default_rng(4)
    B = rng.normal(size=(2000, 2, 10)) / (1 + np.arange(10)) ** 2
    _, xi = _modes_and_run(4, k=10)
    u = np.einsum("pik,tk->pit", B, xi)
    a = np.hypot(u[:, 0], u[:, 1])
    p, j = np.unravel_index(int(np.argmax(a)), a.shape)
    got = peak_seminorm(B, xi, lambda v: np.hypot(v[:, 0], v[:, 1]), chunk=50)
    assert got.value == pytest.approx(a[p, j], rel=1e-12)  # summation order only, as above
    assert (got.point, got.time_index) == (p, j) and got.points_superposed < 2000
