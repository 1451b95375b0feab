"""The compiled right-hand side (crankmodal.dynamics.kernel.compiled) against the Python path.

Oracle: the generic Python evaluation of the same system (``Multibody(compiled=False)``), state
by state for every normal and friction law and for round, worn and lubricated (short film)
bores, and whole smooth runs (ideal joints; a journal floating on its film: no impacts, so no
chaotic amplification of round-off) sample by sample. Runs with impacts are not compared
sample by sample: a 1e-9 change of rtol alone moves their impact sequence (see
benchmarks/README.md); the closed-form impact tests of test_dynamics_contact run on the compiled
path."""

import numpy as np
import pytest

from crankmodal.dynamics import Cylinder, crank_train
from crankmodal.dynamics.laws import contact
from crankmodal.dynamics.laws import objects as laws
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.model.system import AUX_NAMES, Multibody
from crankmodal.dynamics.run.integrate import SolverSettings, integrate
from crankmodal.dynamics.run.simulate import simulate

PARAMS = {"stiffness": 2e10, "exponent": 1.4, "damping": 800.0, "penetration": 5e-5,
          "restitution": 0.7, "radial_clearance": 1e-4}
FRICTION = {"mu_static": 0.12, "mu_dynamic": 0.08, "v_static": 1e-4, "v_dynamic": 1e-2}


#: the big end's bore variants: round and dry (the default), worn (seed 003's elliptical bore,
#: major axis 40 deg off the rod), lubricated (seed 001's short-bearing film, round bore)
BORES = {"round": {}, "worn": {"clearance_major": 1.6e-4, "wear_angle": 0.7},
         "film": {"viscosity": 0.0175, "bearing_length": 0.03}}


def _slider_crank(law, friction, params=PARAMS, bore="round"):
    cyls = [Cylinder(axis_angle=a, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                     rod_com=0.042, piston_mass=0.75, ring_friction=30.0,
                     gas_force=lambda x: 2000 + 1500 * np.cos(x)) for a in (0.0, 1.2)]
    kw = {"law": law, "law_params": params, "friction": friction, "friction_params": FRICTION}
    return crank_train(0.035, cyls, 3000.0, crank_mass=2.0, crank_inertia=0.01,
                       clearances={"big_end_1": {"clearance": 1e-4, "journal_radius": 0.02,
                                                 **BORES[bore]}},
                       contact_kw=kw, gravity=(0.0, -9.81))


def _states(mech, seed, count):
    """``count`` random states near the mechanism's start: ``(t, q, qd, y, v_impact)``."""
    n = mech.system.n
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = mech.q0 + rng.normal(0.0, 1.5e-4, n)
        qd = mech.qd0 + rng.normal(0.0, 0.3, n)
        t = rng.uniform(0.0, 0.05)
        yield t, q, qd, np.concatenate([q, qd, np.zeros(6)]), rng.uniform(0.01, 2.0)


# Two floating-point paths are never compared bit for bit: another x86-64 CPU compiles the kernel
# with other fused multiply-adds and vector widths, which moves the last bits (seen: 1.4e-15 m/s of
# 0.104 m/s in a penetration rate). Each quantity is a sum of at most a few hundred products, so the
# two paths differ by a few hundred ulps of the *terms'* size at most: RTOL = 1e-12 of a scale of the
# terms (the largest entry of the block, or the state's size) holds on any CPU with two orders to
# spare, and a wrong term (a sign, a missing factor) shows as O(1e-3) or more.
RTOL = 1e-12


def _close(actual, expected, scale, what=""):
    """``|actual - expected| <= RTOL * scale`` elementwise; ``scale`` is the size of the terms."""
    np.testing.assert_allclose(actual, expected, rtol=0, atol=RTOL * scale + 1e-300, err_msg=what)


def _both(sysm, fn, *args):
    sysm.compiled = False
    a = fn(*args)
    sysm.compiled = True
    b = fn(*args)
    return a, b


def _paths_agree_state_by_state(mech, seed, count):
    """Both paths' right-hand sides, multipliers, constraint terms and contact diagnostics agree
    at ``count`` random states; returns the number of states in contact and of the film's."""
    sysm = mech.system
    assert sysm.kernel() is not None
    cj = sysm.clearances[0]
    n = sysm.n
    in_contact = film = 0
    for t, q, qd, y, v_impact in _states(mech, seed, count):
        cj.v_impact = v_impact  # restitution laws read it at each call
        py, co = _both(sysm, sysm.rhs, t, y)
        scale = np.maximum(np.abs(py), 1e-300)
        for blk in (slice(0, n), slice(n, 2 * n), slice(2 * n, None)):
            np.testing.assert_allclose(co[blk], py[blk], rtol=0,
                                       atol=1e-11 * np.max(scale[blk]) + 1e-300)
        sp, sc = _both(sysm, sysm.solve, t, q, qd)
        np.testing.assert_allclose(sc["lam"], sp["lam"], rtol=0,
                                   atol=1e-11 * np.max(np.abs(sp["lam"])))
        q_scale, v_scale = np.max(np.abs(q)), np.max(np.abs(qd))  # m (and rad), m/s (rad/s)
        _close(sc["phi"], sp["phi"], q_scale, "phi")
        _close(sc["Cq"], sp["Cq"], np.max(np.abs(sp["Cq"])), "Cq")
        _close(sc["nu"], sp["nu"], np.max(np.abs(sp["nu"])), "nu")
        _close(sc["p_loads"], sp["p_loads"], np.max(np.abs(py[2 * n:])) + abs(sp["p_loads"]),
               "p_loads")
        kp, kc = sp["contacts"][0], sc["contacts"][0]
        # the contact's own scales: a length (the clearance, m), a speed, a force (the film's
        # too), and for a worn bore's d(clearance)/d(angle) the difference of its axes
        length = cj.clearance_major or cj.clearance
        force = max(abs(kp["fn"]), abs(kp["ft"]), kp["film"], 1.0)
        for key, scale in (("delta", length), ("d", length), ("r_b", length + cj.journal_radius),
                           ("dtheta", length), ("delta_dot", v_scale), ("v_slip", v_scale),
                           ("v_elastic", v_scale), ("omega_sum", v_scale), ("fn", force),
                           ("ft", force), ("film", force), ("p_damp", force * v_scale),
                           ("p_fric", force * v_scale)):
            _close(kc[key], kp[key], scale, key)
        for key, scale in (("e", length), ("n", 1.0), ("t", 1.0), ("grad", 1.0),
                           ("force", force), ("vrel", v_scale), ("Jj", 1.0 + q_scale),
                           ("Jb", 1.0 + q_scale)):
            _close(kc[key], kp[key], scale, key)
        _close(sysm.gap(0, q), cj.gap(sysm, q), length, "gap")
        _close(sysm.penetration_rate(0, q, qd), cj.kinematics(sysm, q, qd)["delta_dot"], v_scale,
               "penetration rate")
        in_contact += kp["delta"] > 0.0 and kp["fn"] > 0.0
        film += kp["film"] > 0.0
    return in_contact, film


@pytest.mark.parametrize("friction", contact.FRICTION_LAWS)
@pytest.mark.parametrize("law", contact.NORMAL_LAWS)
def test_compiled_rhs_and_solve_equal_the_python_path_state_by_state(law, friction):
    in_contact, _ = _paths_agree_state_by_state(_slider_crank(law, friction), 7, 12)
    assert in_contact >= 3


# every normal law once, the friction laws in turn: the bore's terms do not depend on the pair
@pytest.mark.parametrize("law,friction", [
    (law, contact.FRICTION_LAWS[i % len(contact.FRICTION_LAWS)])
    for i, law in enumerate(contact.NORMAL_LAWS)])
@pytest.mark.parametrize("bore", ["worn", "film"])
def test_worn_bores_and_short_films_compiled_equal_the_python_path_state_by_state(bore, law,
                                                                                  friction):
    """The kernel's worn bore (the gradient n - (c'/d) t, the rate's c' omega_bearing, the
    bearing's moment -fn c') and short-bearing film (force, its power booked as dissipation)
    against ClearanceJoint's own, at random states in and out of contact (the worn bore's
    clearance and the film's formula are the same Numba functions on both paths: their oracles
    are seed 003's ellipse in test_dynamics_worn and the integrated Reynolds pressure in
    test_dynamics_lubrication)."""
    mech = _slider_crank(law, friction, bore=bore)
    in_contact, film = _paths_agree_state_by_state(mech, 7, 16)
    assert 3 <= in_contact <= 15  # in contact and out of it
    assert film == (16 if bore == "film" else 0)


def test_a_smooth_run_is_the_same_on_both_paths():
    # ideal joints (no impacts): the two paths' histories agree to round-off amplified by the
    # integrator, with the same steps
    runs = []
    for compiled in (False, True):
        mech = _slider_crank("impact", "coulomb")
        mech.ideal.compiled = compiled
        runs.append(simulate(mech, 0.04, 1e-4, SolverSettings(rtol=1e-8, atol=1e-12),
                             ideal=True))
    py, co = runs
    # the paths' last bits differ by CPU (see RTOL), and an adaptive step accepted at the margin
    # on one path may be rejected on the other: the evaluations may differ by a few steps and the
    # histories by the integration tolerance (rtol 1e-8), never by a model difference (>= 1e-3)
    assert abs(co.nfev - py.nfev) <= 0.02 * py.nfev
    for a, b in ((co.main_bearing_force, py.main_bearing_force),
                 (co.piston_acceleration, py.piston_acceleration),
                 *((co.energy[k], py.energy[k]) for k in ("work_drive", "work_loads", "kinetic"))):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.max(np.abs(b)))


def test_a_smooth_lubricated_run_is_the_same_on_both_paths():
    """The big end floating on seed 001's short-bearing film (c = 0.021 mm, no dry contact in
    0.01 s: a smooth run, no impacts to amplify round-off), kernel against Python path sample
    by sample. LSODA keeps each step's error within rtol |y_i| + atol; the two paths' steps
    differ by round-off (and LSODA may switch method at other steps), so their histories differ
    by the integrator's error: positions, velocities and works within 100 x (rtol max|y_i| +
    atol) (seen: up to 53 x, the drive's work). The film's dissipation is more sensitive: the
    eccentricity is known to rtol |q| ~ 1e-9 m, 5e-5 of the clearance, and the film force
    grows as (1 - eps^2)^-2: within 1e-4 of its value (seen: 6.5e-6). The ideal joints' work is
    drift (zero up to round-off) and not compared. A model difference (a film term's sign or
    factor, its power) moves the journal by a fraction of the clearance, the film's dissipation
    by O(1)."""
    rtol, atol = 1e-8, 1e-13
    t_out = np.linspace(0.0, 0.01, 101)
    runs = []
    for compiled in (False, True):
        mech = _slider_crank("hertz", "none", bore="film")
        mech.system.clearances[0].clearance = 2.1e-5
        mech.system.compiled = compiled
        assert (mech.system.kernel() is not None) == compiled
        runs.append(integrate(mech.system, mech.q0, mech.qd0, 0.01, t_out,
                              SolverSettings(method="LSODA", rtol=rtol, atol=atol)))
    py, co = runs
    assert py.onsets == co.onsets == [[]]  # the film carries the load: no dry contact
    cj, sysm, n = mech.system.clearances[0], mech.system, mech.system.n
    eps = [cj.kinematics(sysm, y[:n], y[n:2 * n])["d"] / cj.clearance for y in py.y.T]
    assert 0.3 < max(eps) < cj.eps_max  # a loaded film
    assert py.y[2 * n + AUX_NAMES.index("dissipated_contact"), -1] > 0.0  # the film's power
    size = np.max(np.abs(py.y), axis=1)
    bound = 100.0 * (rtol * size + atol)
    i_ideal, i_film = (2 * n + AUX_NAMES.index(k) for k in ("work_constraints",
                                                            "dissipated_contact"))
    bound[i_film] = 1e-4 * size[i_film]
    bound[i_ideal] = np.inf
    assert np.all(np.abs(co.y - py.y) <= bound[:, None])


def test_a_free_journal_without_constraints_is_compiled_too():
    # no constraint rows: the reduced system is empty (the journal-in-bearing impact tests of
    # test_dynamics_contact run this case against closed forms)
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", 2.0, 1e-3, {"centre": (0.0, 0.0)})
    joint = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=1e-4,
                           journal_radius=0.01, law=laws.Hertz(stiffness=1e10),
                           friction=laws.Coulomb(**FRICTION))
    sysm = Multibody([journal], [], [joint], gravity=(0.0, -9.81))
    assert sysm.kernel() is not None
    y = np.array([1.2e-4, 3e-5, 0.1, 0.3, -0.2, 50.0, 0, 0, 0, 0, 0, 0])
    py, co = _both(sysm, sysm.rhs, 0.0, y)
    np.testing.assert_allclose(co, py, rtol=RTOL, atol=RTOL * np.max(np.abs(py)))
    assert py[3] < 0.0  # pushed back from the wall


def test_what_has_no_compiled_form_stays_on_the_python_path():
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", 1.0, 1e-3, {"centre": (0.0, 0.0)})

    def joint(**kw):
        return ClearanceJoint("c", journal, "centre", ground, "bore", clearance=1e-4,
                              journal_radius=0.01, law=laws.Hertz(stiffness=1e10), **kw)

    assert Multibody([journal], [], [joint()]).kernel() is not None
    assert Multibody([journal], [], [joint()], compiled=False).kernel() is None
    # worn bores, short films and finite films (the Reynolds table) are compiled too
    assert Multibody([journal], [], [joint(clearance_major=2e-4)]).kernel() is not None
    assert Multibody([journal], [], [joint(viscosity=0.02, bearing_length=0.02)]).kernel() \
        is not None
    assert Multibody([journal], [], [joint(viscosity=0.02, bearing_length=0.02,
                                           film_model="finite")]).kernel() is not None


def _synthetic_flexible(name, k, frames, rng, mass=1.5, j0=4e-3, tilt=0):
    """A FlexibleBody with random but admissible invariants (no FE): G symmetric positive
    definite, S antisymmetric, interface maps random; ``tilt`` stiffness-free coordinates."""
    from crankmodal.dynamics.flexible.body import FlexibleBody

    X = rng.normal(size=(k, k)) * 0.1
    G = np.eye(k) * 0.8 + X @ X.T * 0.1
    S = rng.normal(size=(k, k)) * 0.05
    S = S - S.T
    f = np.concatenate([np.sort(rng.uniform(300.0, 9000.0, k - tilt)), np.zeros(tilt)])
    itf = {nm: (np.array([x, y, 0.0]), rng.normal(size=(6, k)) * 0.05)
           for nm, (x, y) in frames.items()}
    return FlexibleBody(name, mass, j0, (0.0, 0.0), f, G, rng.normal(size=k) * 0.01, S, itf,
                        damping_ratio=0.03, c=rng.normal(size=k) * 1e-3, n_tilt=tilt)


def _flexible_train(seed=3, clearance=True, attach=False):
    rng = np.random.default_rng(seed)
    cyls = [Cylinder(axis_angle=a, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                     rod_com=0.042, piston_mass=0.75, ring_friction=30.0,
                     gas_force=lambda x: 2000 + 1500 * np.cos(x)) for a in (0.0, 1.2)]
    crank = _synthetic_flexible("crank", 7, {"main_a": (0.0, 0.0), "pin": (0.035, 0.0)}, rng,
                                mass=2.0, j0=0.01, tilt=2)
    rods = [_synthetic_flexible(f"rod_{i}", 5, {"big": (-0.042, 0.0), "small": (0.098, 0.0)},
                                rng, mass=0.9, j0=3.1e-3) for i in (1, 2)]
    if attach:  # point rotary inertias on interfaces (two on one rod, one on the tilted crank)
        crank.attach_inertia("pin", 4e-3)
        rods[0].attach_inertia("small", 2e-3)
        rods[0].attach_inertia("big", 1e-3)
    kw = {"law": "impact", "law_params": PARAMS, "friction": "coulomb",
          "friction_params": FRICTION}
    cl = {"big_end_1": {"clearance": 1e-4, "journal_radius": 0.02}} if clearance else None
    return crank_train(0.035, cyls, 3000.0, crank_body=crank,
                       crank_roles={"mains": ["main_a"], "pins": ["pin", "pin"],
                                    "drive": "main_a"},
                       rod_bodies=rods, clearances=cl, contact_kw=kw, gravity=(0.0, -9.81))


def _flexible_paths_agree(sysm, t, q, qd, y, vimp):
    """Both paths' right-hand sides (every block) and multipliers agree to 1e-10 of their
    largest entry at one state; returns ``(py_rhs, compiled_rhs, py_solve, compiled_solve)``."""
    n = sysm.n
    py, co = _both(sysm, sysm.rhs, t, y, vimp)
    for blk in (slice(0, n), slice(n, 2 * n), slice(2 * n, None)):
        np.testing.assert_allclose(co[blk], py[blk], rtol=0,
                                   atol=1e-10 * np.max(np.abs(py[blk])) + 1e-300)
    sp, sc = _both(sysm, sysm.solve, t, q, qd, vimp)
    np.testing.assert_allclose(sc["lam"], sp["lam"], rtol=0,
                               atol=1e-10 * np.max(np.abs(sp["lam"])))
    return py, co, sp, sc


def test_flexible_bodies_compiled_equal_the_python_path_state_by_state():
    """A flexible crank (5 modes + 2 tilts) and two flexible rods (5 modes), a clearance at the
    first big end (a flexible interface), gas and ring friction: the compiled kernel (full KKT
    with M(ξ)) against FlexibleBody's own methods joint by joint, at random states in and out of
    contact."""
    mech = _flexible_train()
    sysm = mech.system
    assert sysm.kernel() is not None and sysm.kernel()._size == sysm.n + sysm.m
    n = sysm.n
    in_contact = 0
    for t, q, qd, y, v_impact in _states(mech, 11, 10):
        vimp = np.array([v_impact])  # passed as the integrator passes it
        py, _, sp, sc = _flexible_paths_agree(sysm, t, q, qd, y, vimp)
        assert py[2 * n + 5] > 0.0  # modal damping power counted
        q_scale, v_scale = np.max(np.abs(q)), np.max(np.abs(qd))
        _close(sc["Cq"], sp["Cq"], np.max(np.abs(sp["Cq"])), "Cq")
        _close(sc["phi"], sp["phi"], q_scale, "phi")
        kp, kc = sp["contacts"][0], sc["contacts"][0]
        cj = sysm.clearances[0]
        length, force = cj.clearance, max(abs(kp["fn"]), abs(kp["ft"]), 1.0)
        # the flexible path sums over modes too: 10x the rigid tolerance (still 1e-11)
        for key, scale in (("delta", length), ("delta_dot", v_scale), ("v_slip", v_scale),
                           ("fn", force), ("ft", force), ("p_damp", force * v_scale),
                           ("p_fric", force * v_scale), ("force", force),
                           ("Jj", 1.0 + q_scale), ("Jb", 1.0 + q_scale)):
            _close(kc[key], kp[key], 10 * scale, key)
        _close(sysm.gap(0, q), cj.gap(sysm, q), length, "gap")
        in_contact += kp["fn"] > 0.0
    assert in_contact >= 3


def test_attached_inertias_compiled_equal_the_python_path_state_by_state():
    """Rotary inertias attached to interfaces (crank pin with tilts, both ends of one rod): the
    compiled kernel's M(ξ) terms (Σ J_s, Σ J_s r_z, Σ J_s r_z r_zᵀ packed into fb_f) against
    FlexibleBody.mass_matrix, via the accelerations and multipliers at random states; the
    attachments change the accelerations (so the comparison is not of two unchanged paths)."""
    mech = _flexible_train(attach=True)
    bare = _flexible_train(attach=False)
    sysm = mech.system
    assert sysm.kernel() is not None
    n = sysm.n
    for t, q, qd, y, v_impact in _states(mech, 5, 6):
        vimp = np.array([v_impact])
        _, co, _, _ = _flexible_paths_agree(sysm, t, q, qd, y, vimp)
        other = bare.system.rhs(t, y, vimp)[n:2 * n]
        assert np.max(np.abs(other - co[n:2 * n])) > 1e-3 * np.max(np.abs(co[n:2 * n]))


def test_the_kernel_integrates_every_power_the_system_names():
    from crankmodal.dynamics.kernel import compiled
    from crankmodal.dynamics.model import system

    assert compiled.N_AUX == system.N_AUX == len(system.AUX_NAMES)


def test_a_finite_film_runs_compiled_and_equals_the_python_path_state_by_state():
    """The finite-length film (Reynolds table) in the kernel: the same joint's forces and powers
    on both paths at random states (the film formula itself is checked against FITPACK and the
    direct Reynolds solve in test_dynamics_reynolds)."""
    cyls = [Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3.1e-3,
                     rod_com=0.042, piston_mass=0.75, gas_force=lambda x: 2000 + 1500 * np.cos(x))]
    mech = crank_train(0.035, cyls, 3000.0, crank_mass=2.0, crank_inertia=0.01,
                       clearances={"big_end_1": {"clearance": 2.1e-5, "journal_radius": 0.02,
                                                 "viscosity": 0.0175, "bearing_length": 0.042,
                                                 "film_model": "finite"}},
                       contact_kw={"law": "hertz", "law_params": {"stiffness": 3e11,
                                                                  "exponent": 1.5}})
    sysm = mech.system
    assert sysm.clearances[0].film_model == "finite" and sysm.kernel() is not None
    n = sysm.n
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, qd = mech.q0 + rng.normal(0, 1e-5, n), mech.qd0 + rng.normal(0, 0.3, n)
        y = np.concatenate([q, qd, np.zeros(6)])
        py, co = _both(sysm, sysm.rhs, 0.01, y)
        for blk in (slice(n, 2 * n), slice(2 * n, None)):
            _close(co[blk], py[blk], 10 * np.max(np.abs(py[blk])))
