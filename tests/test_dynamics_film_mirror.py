"""The short-bearing pi film for either sense of rotation and squeeze (issue 18 #1), and the
film force through the bearing centre (issue 18 #6).

Oracles: direct quadrature of the clipped short-bearing pressure, the finite-length Reynolds
solver at small L/D, Ocvirk's static equilibrium, and a Radau run of the same scene.
"""

import itertools

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from crankmodal.dynamics.laws.lubrication import short_bearing_force
from crankmodal.dynamics.laws.reynolds import solve_pressure
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import Multibody
from crankmodal.dynamics.run.integrate import SolverSettings, integrate
from crankmodal.runner import run
from crankmodal.scene import scene_from_dict

MU, R, L, C = 0.0175, 0.02, 0.042, 2.1e-5   # seed 001 Table 2


def _quadrature(eps, eps_dot, gamma_dot, omega, length=L):
    """Short-bearing pressure p = G (z^2 - L^2/4) / (2 h^3) clipped to p >= 0 (half-Sommerfeld),
    integrated with scipy's adaptive quadrature between the zeros of G (found numerically)."""
    def g(th):                               # G / (6 mu c); p >= 0 where G <= 0
        return eps * (omega - 2 * gamma_dot) * np.sin(th) - 2 * eps_dot * np.cos(th)

    grid = np.linspace(0.0, 2 * np.pi, 721)
    vals = g(grid)
    cuts = [brentq(g, a, b, xtol=1e-15) for a, b, fa, fb in
            zip(grid[:-1], grid[1:], vals[:-1], vals[1:]) if fa * fb < 0.0]
    edges = [0.0, *cuts, 2 * np.pi]

    def comp(fun):                           # F = -int p n R dtheta dz, int (z^2 - L^2/4) dz = -L^3/6
        val = sum(quad(lambda th: g(th) * fun(th) / (1 - eps * np.cos(th)) ** 3, a, b,
                       epsabs=1e-9, epsrel=1e-12)[0]
                  for a, b in itertools.pairwise(edges) if g(0.5 * (a + b)) < 0.0)
        return 6 * MU * C * R * length**3 / 12 / C**3 * val
    return comp(np.cos), comp(np.sin)


@pytest.mark.parametrize("gamma_dot", [0.0, 30.0])
def test_reversed_rotation_mirrors_the_film_force(gamma_dot):
    # Mirror theta -> -theta: the same radial force, the opposite tangential one. Before the
    # fix the pi film stayed on the same half and f_r(-omega) = -f_r(omega) pointed outward.
    eps = np.linspace(0.05, 0.95, 19)
    w = 150.0
    fr, ft = short_bearing_force(eps, 0.0, gamma_dot, w + 2 * gamma_dot, MU, R, L, C)
    fr_m, ft_m = short_bearing_force(eps, 0.0, -gamma_dot, -w - 2 * gamma_dot, MU, R, L, C)
    np.testing.assert_allclose(fr_m, fr, rtol=1e-12)
    np.testing.assert_allclose(ft_m, -ft, rtol=1e-12)
    assert np.all(fr < 0.0) and np.all(fr_m < 0.0)       # towards the centre: it carries load
    # the load direction is Ocvirk's attitude angle on the mirrored side
    s = 1 - eps**2
    np.testing.assert_allclose(np.degrees(np.arctan2(-ft_m, -fr_m)),
                               np.degrees(np.arctan(np.pi * np.sqrt(s) / (4 * eps))), atol=1e-9)


STATES = [  # eps, eps_dot (1/s), gamma_dot (rad/s), omega (rad/s)
    (0.3, 5.0, 0.0, 0.0),          # squeeze only, approaching the wall
    (0.3, -5.0, 0.0, 0.0),         # squeeze only, separating
    (0.6, 40.0, 50.0, 100.0),      # squeeze only: omega = 2 gamma_dot
    (0.6, -40.0, 50.0, 100.0),
    (0.9, 3.0, 0.0, 0.0),
    (0.7, -2.0, 20.0, 30.0),       # wedge reversed (omega - 2 gamma_dot < 0), separating
    (0.7, 2.0, 20.0, 30.0),
    (0.5, 0.0, 0.0, -100.0),       # clockwise journal
    (0.5, 30.0, 0.0, -100.0),
    (0.5, -30.0, 0.0, 100.0),
    (0.95, -1.0, 0.0, -300.0),
    (0.05, 7.0, -40.0, 10.0),
]


@pytest.mark.parametrize("eps,eps_dot,gamma_dot,omega", STATES)
def test_short_film_equals_quadrature_of_the_clipped_pressure(eps, eps_dot, gamma_dot, omega):
    # Oracle: scipy.integrate.quad of the pressure where it is positive, for any sign of the
    # wedge and squeeze terms. All 12 states failed before the fix (the film was the fixed half
    # pi < theta < 2 pi).
    fr, ft = short_bearing_force(eps, eps_dot, gamma_dot, omega, MU, R, L, C)
    fr_ref, ft_ref = _quadrature(eps, eps_dot, gamma_dot, omega)
    scale = np.hypot(fr_ref, ft_ref)
    assert fr == pytest.approx(fr_ref, abs=1e-9 * scale)
    assert ft == pytest.approx(ft_ref, abs=1e-9 * scale)


@pytest.mark.parametrize("eps", [0.1, 0.5, 0.9])
def test_pure_squeeze_resists_both_ways_on_the_side_it_squeezes(eps):
    # A journal approaching the wall (eps_dot > 0) is pushed back (f_r < 0) by the film on the
    # near side (-pi/2 < theta < pi/2); one moving away (eps_dot < 0) is held back (f_r > 0)
    # by the film on the far side; no tangential force either way. Closed forms: f_r =
    # -/+ mu R L^3 / c^2 eps_dot int cos^2 / (1 - eps cos)^3 over that half.
    k = MU * R * L**3 / C**2
    g = lambda t: np.cos(t) ** 2 / (1 - eps * np.cos(t)) ** 3
    near = quad(g, -np.pi / 2, np.pi / 2, epsabs=0.0, epsrel=1e-13)[0]
    far = quad(g, np.pi / 2, 3 * np.pi / 2, epsabs=0.0, epsrel=1e-13)[0]
    for ed, half in ((10.0, near), (-10.0, far)):
        fr, ft = short_bearing_force(eps, ed, 0.0, 0.0, MU, R, L, C)
        assert fr == pytest.approx(-k * ed * half, rel=1e-10)
        assert abs(ft) < 1e-10 * abs(fr)


@pytest.mark.parametrize("eps", [0.2, 0.5, 0.8])
@pytest.mark.parametrize("w,eps_dot", [(150.0, 0.0), (-150.0, 0.0), (0.0, 20.0), (0.0, -20.0),
                                       (150.0, 20.0), (-150.0, 20.0), (-150.0, -20.0),
                                       (150.0, -60.0)])
def test_short_film_agrees_with_the_finite_reynolds_film_at_small_length(eps, w, eps_dot):
    # Oracle: the finite-length Reynolds equation with Reynolds cavitation (both boundaries
    # free) at L/D = 0.05, where the short bearing is its limit: measured 0.11..0.95 % (the
    # larger at eps = 0.8). Before the fix 21 of these 24 failed: a reversed rotation off by
    # 50..173 %, a squeeze by 15 % .. 136 times.
    ld = 0.05
    length = 2 * R * ld
    f = solve_pressure(eps, ld, rotation=w, squeeze=eps_dot, inlet="free")[2]
    f = f * MU * R * length * (R / C) ** 2
    ref = np.array(short_bearing_force(eps, eps_dot, 0.0, w, MU, R, length, C))
    assert np.hypot(*(f - ref)) < 0.012 * np.hypot(*ref)


def _floating_journal(omega, t_end):
    """A journal spinning at ``omega`` (rad/s) in its oil film under a 2 kN load (-y)."""
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", 1.0, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=C, journal_radius=R,
                           law="hertz", law_params={"stiffness": 1e11, "exponent": 1.5},
                           viscosity=MU, bearing_length=L)
    sysm = Multibody([journal], [], [joint], gravity=(0.0, -2000.0))
    out = integrate(sysm, np.zeros(3), np.array([0.0, 0.0, omega]), t_end,
                    np.linspace(0.8 * t_end, t_end, 5),
                    SolverSettings(method="LSODA", rtol=1e-7, atol=1e-14))
    return out.y[0] / C, out.y[1] / C


def test_clockwise_journal_settles_at_the_mirror_image_of_the_counter_clockwise_one():
    # Oracle: Ocvirk's static equilibrium, |f| = k eps w sqrt(4 eps^2 + pi^2 s / 4) / s^2 = W
    # (k = mu R L^3 / 2c^2, s = 1 - eps^2) at the attitude angle atan(pi sqrt(s) / (4 eps)):
    # eps = 0.19758 and 75.61 deg for W = 2 kN at 200 rad/s. Measured after 0.25 s: 0.19758 and
    # the mirror image to 1e-9 c. Before the fix the clockwise journal whirled outward
    # (eps 0.66 at 0.1 s and growing).
    k, w, W = MU * R * L**3 / (2 * C**2), 200.0, 2000.0
    eps_eq = brentq(lambda e: k * e * w * np.sqrt(4 * e * e + np.pi**2 * (1 - e * e) / 4)
                    / (1 - e * e) ** 2 - W, 1e-6, 0.99)
    phi_eq = np.degrees(np.arctan(np.pi * np.sqrt(1 - eps_eq**2) / (4 * eps_eq)))
    ex, ey = _floating_journal(w, 0.25)
    ex_m, ey_m = _floating_journal(-w, 0.25)
    assert np.hypot(ex, ey) == pytest.approx(np.full(5, eps_eq), abs=2e-3)
    assert np.hypot(ex_m[-1], ey_m[-1]) == pytest.approx(eps_eq, abs=2e-4)
    # ccw: the journal sits on the +x side of the load line (-y), cw on the -x side
    assert np.degrees(np.arctan2(ex[-1], -ey[-1])) == pytest.approx(phi_eq, abs=0.3)
    np.testing.assert_allclose(ex_m, -ex, atol=1e-6)
    np.testing.assert_allclose(ey_m, ey, atol=1e-6)


TDC = {"dynamics": {
    "mechanism": "slider_crank", "speed_rpm": 3000.0, "initial_angle_deg": 0.0, "end_time": 0.01,
    "run_ideal": False, "gas_force_deg": [0.0, 360.0], "gas_force_n": [5000.0, 5000.0],
    "clearances": [{"joint": "main", "clearance": 5e-5, "journal_radius": 0.024,
                    "viscosity": 0.0175, "bearing_length": 0.02}],
    "solver": {"max_rhs_evals": 20000}}}


def test_oil_film_run_from_top_dead_centre_passes_the_bearing_centre_with_the_auto_solver(
        tmp_path):
    # Crank at TDC (cylinder along x), the main journal centred in its film, the load along the
    # cylinder. The whirl rate gamma_dot = (t . vrel) / |e| was cut to 0 below |e| = 1e-12 c;
    # eps gamma_dot = (t . vrel) / c is finite there, so the cut was a jump in the film force
    # on which LSODA (the auto method for films) stepped at ~5 ns: 20 000 evaluations ended at
    # t = 32 us with a NumericalError. Measured now: 1066 evaluations (Radau at rtol 1e-9:
    # 3402; RK45 52 670), the orbit within 7e-5 c of Radau's, the peak within 4e-7.
    import copy

    res, orbit = {}, {}
    for method in ("auto", "Radau"):
        data = copy.deepcopy(TDC)
        data["dynamics"]["solver"]["method"] = method
        if method == "Radau":
            data["dynamics"]["solver"]["rtol"] = 1e-9
        out = tmp_path / method
        res[method] = run(scene_from_dict(data, name="tdc"), out, figures=False)["dynamics"]
        with np.load(out / "dynamics.npz") as z:
            orbit[method] = (z["t"], z["contact_main_ex"], z["contact_main_ey"])
    assert res["auto"]["rhs_evals"] < 3000
    np.testing.assert_array_equal(orbit["auto"][0], orbit["Radau"][0])
    dev = np.hypot(orbit["auto"][1] - orbit["Radau"][1], orbit["auto"][2] - orbit["Radau"][2])
    assert dev.max() < 1e-3 * 5e-5
    assert np.hypot(orbit["auto"][1], orbit["auto"][2]).max() > 0.1 * 5e-5   # it did move
    assert res["auto"]["main_bearing_force_peak_n"] == pytest.approx(
        res["Radau"]["main_bearing_force_peak_n"], rel=1e-4)
