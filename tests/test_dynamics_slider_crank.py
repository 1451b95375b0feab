"""Slider-crank dynamics against an independent Newton-Euler inverse dynamics, and clearance -> 0."""

import numpy as np
import pytest

from crankmodal.dynamics import Cylinder, SolverSettings, crank_train, simulate

R, L, E_OFF = 0.035, 0.14, 0.006
M1, B1, I1 = 2.0, -0.01, 0.01          # crank: mass, centre of mass along the crank, inertia
M2, A2, I2 = 0.9, 0.042, 0.175 * 0.9 * 0.14**2   # rod: mass, CoM from big end, inertia
M3 = 0.75
RPM = 3000.0
W = RPM * np.pi / 30


def gas(angle):
    return 2000.0 + 1500.0 * np.cos(angle)


def _mech(clearances=None, contact=None, rpm=RPM, **kw):
    cyl = Cylinder(axis_angle=0.0, rod_length=L, rod_mass=M2, rod_inertia=I2, rod_com=A2,
                   piston_mass=M3, offset=E_OFF, gas_force=gas)
    return crank_train(R, [cyl], rpm, crank_mass=M1, crank_inertia=I1, crank_com=B1,
                       clearances=clearances, contact_kw=contact, **kw)


def _positions(th):
    """Closed-form positions: crank CoM, rod CoM and angle, piston x."""
    P = R * np.array([np.cos(th), np.sin(th)])
    xp = R * np.cos(th) + np.sqrt(L**2 - (R * np.sin(th) - E_OFF) ** 2)
    X = np.array([xp, E_OFF])
    G2 = P + A2 * (X - P) / L
    phi = np.arctan2(E_OFF - P[1], xp - P[0])
    return B1 * np.array([np.cos(th), np.sin(th)]), G2, phi, X


def _derivs(th, h=1e-4):
    """Velocity and acceleration of every coordinate by 4th-order central differences in theta."""
    f = [np.concatenate([np.ravel(v) for v in _positions(th + k * h)]) for k in (-2, -1, 0, 1, 2)]
    d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
    d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
    return f[2], d1 * W, d2 * W * W


def _newton_euler(th):
    """Inverse dynamics at constant speed: main-bearing force, big-end force, drive torque."""
    x, v, a = _derivs(th)
    a1, a2, phidd, a3 = a[0:2], a[2:4], a[4], a[5:7]
    G2, X = x[2:4], x[5:7]
    P = R * np.array([np.cos(th), np.sin(th)])
    fg = gas(th)
    # piston (x): m3 a3x = F_rod_on_piston_x - fg; unknowns: big-end force Fb (crank on rod),
    # piston-on-rod force Fs with Fs_x known, Fs_y from the rod moment equation
    fs_x = -(M3 * a3[0] + fg)
    sb, ss = P - G2, X - G2
    # rod: M2 a2 = Fb + Fs ; I2 phidd = sb x Fb + ss x Fs
    A = np.array([[1, 0, 0], [0, 1, 1], [-sb[1], sb[0], ss[0]]], float)
    rhs = np.array([M2 * a2[0] - fs_x, M2 * a2[1], I2 * phidd - (-ss[1] * fs_x)])
    fbx, fby, _fsy = np.linalg.solve(A, rhs)  # the piston's side force is not compared
    fb = np.array([fbx, fby])
    main = -fb - M1 * a1          # force of the crank on the ground
    ke = 0.5 * (M1 * v[0:2] @ v[0:2] + (I1) * W**2 + M2 * v[2:4] @ v[2:4] + I2 * v[4] ** 2
                + M3 * v[5:7] @ v[5:7])
    # drive torque from power: T w = dKE/dt + fg * v_piston
    return main, fb, ke, v[5]


@pytest.fixture(scope="module")
def ideal_history():
    m = _mech()
    return simulate(m, 60.0 / RPM, 60.0 / RPM / 360, SolverSettings(rtol=1e-9, atol=1e-12),
                    ideal=True)


def test_ideal_slider_crank_bearing_forces_equal_newton_euler_inverse_dynamics(oracle, ideal_history):
    h = ideal_history
    ref = np.array([np.concatenate(_newton_euler(th)[:2]) for th in h.crank_angle])
    scale = np.abs(ref).max()
    oracle(stage="dynamics", quantity="ideal slider-crank main-bearing force, largest deviation over the cycle / peak", reference="Newton-Euler inverse dynamics (second formulation)", tolerance="1e-5 of peak", measured=np.abs(h.main_bearing_force - ref[:, :2]).max() / scale, expected=0.0)
    np.testing.assert_allclose(h.main_bearing_force, ref[:, :2], atol=1e-5 * scale)
    np.testing.assert_allclose(h.joint_forces["big_end_1"], ref[:, 2:], atol=1e-5 * scale)


def test_ideal_slider_crank_drive_torque_equals_power_balance(ideal_history):
    h = ideal_history
    th = h.crank_angle
    h_th = 1e-4
    ke = [np.array([_newton_euler(t + k * h_th)[2] for t in th]) for k in (-1, 1)]
    vp = np.array([_newton_euler(t)[3] for t in th])
    dke = (ke[1] - ke[0]) / (2 * h_th) * W          # dKE/dt = W dKE/dtheta
    torque = (dke + gas(th) * vp) / W
    np.testing.assert_allclose(h.drive_torque, torque, atol=1e-5 * np.abs(torque).max())


def test_ideal_slider_crank_piston_acceleration_equals_closed_form(ideal_history):
    h = ideal_history
    a = np.array([_derivs(t)[2][5] for t in h.crank_angle])
    np.testing.assert_allclose(h.piston_acceleration[:, 0], a, atol=1e-6 * np.abs(a).max())


def test_clearance_to_zero_converges_to_the_ideal_joint_solution():
    # Second revolution (start-up transient gone); impact law, steel-like stiffness.
    T = 2 * 60.0 / RPM
    contact = {"law": "impact", "law_params": {"stiffness": 1e10, "exponent": 1.5,
                                               "damping": 2000.0, "penetration": 1e-6}}
    errs = []
    ideal = None
    for c in (1e-4, 1e-5, 1e-6):
        m = _mech({"big_end_1": {"clearance": c, "journal_radius": 0.02}}, contact)
        if ideal is None:
            ideal = simulate(m, T, T / 720, ideal=True)
        h = simulate(m, T, T / 720)
        sel = h.t > T / 2
        da = np.abs(h.piston_acceleration - ideal.piston_acceleration)[sel].max()
        df = np.abs(h.main_bearing_force - ideal.main_bearing_force)[sel].max()
        errs.append((da / np.abs(ideal.piston_acceleration).max(),
                     df / np.abs(ideal.main_bearing_force).max()))
    errs = np.array(errs)
    assert np.all(np.diff(errs[:, 0]) < 0) and np.all(np.diff(errs[:, 1]) < 0)
    assert errs[-1, 0] < 0.06 and errs[-1, 1] < 0.06


@pytest.mark.parametrize("friction", ["coulomb", "ambrosio"])
def test_energy_balance_closes_with_clearance_friction_and_speed_ramp(friction):
    T = 0.03
    contact = {"law": "lankarani_nikravesh",
               "law_params": {"stiffness": 1e10, "exponent": 1.5, "restitution": 0.5},
               "friction": friction,
               "friction_params": {"mu_static": 0.1, "mu_dynamic": 0.08, "v_static": 1e-4,
                                   "v_dynamic": 1e-2}}
    m = _mech({"big_end_1": {"clearance": 1e-4, "journal_radius": 0.02}}, contact,
              ramp_time=0.01, gravity=(0.0, -9.81))
    # LSODA: sliding starts from rest, where the stiction slope makes the problem stiff
    h = simulate(m, T, T / 600, SolverSettings(method="LSODA"), energy_tolerance=None)
    assert h.energy["dissipated_friction"][-1] > 0.0
    assert h.energy["dissipated_contact"][-1] > 0.0
    assert h.energy_error() < 1e-4
    assert h.crank_speed[-1] == pytest.approx(W, rel=1e-6)


def test_offset_slider_crank_with_clearance_records_impacts_with_positive_velocities():
    contact = {"law": "impact", "law_params": {"stiffness": 1e10, "exponent": 1.5,
                                               "damping": 300.0, "penetration": 1e-4}}
    m = _mech({"big_end_1": {"clearance": 2e-4, "journal_radius": 0.02},
               "small_end_1": {"clearance": 1e-4, "journal_radius": 0.01}}, contact)
    h = simulate(m, 0.02, 0.02 / 400)
    v = np.array([o[1] for ons in h.onsets.values() for o in ons])
    assert v.size > 0 and np.all(v > 0)
    for cj in m.system.clearances:
        d = h.contact[cj.name]
        ecc = np.hypot(d["ex"], d["ey"])
        # the journal leaves the clearance circle only by the Hertz depth of the peak force
        depth = (d["fn"].max() / 1e10) ** (1 / 1.5)
        assert np.all(ecc <= cj.clearance + 1.5 * depth)
        assert ecc.max() > cj.clearance


def test_torque_drive_speeds_the_flywheel_up_by_the_work_it_does():
    # Free speed: a constant torque on crank + flywheel; with no gas the work T * dtheta goes
    # into kinetic energy, so the mean speed rises and the balance closes.
    cyl = Cylinder(axis_angle=0.0, rod_length=L, rod_mass=M2, rod_inertia=I2, rod_com=A2,
                   piston_mass=M3)
    m = crank_train(R, [cyl], 600.0, crank_mass=M1, crank_inertia=0.5, drive_torque=20.0)
    h = simulate(m, 0.2, 0.001)
    dtheta = h.crank_angle[-1] - h.crank_angle[0]
    dke = h.energy["kinetic"][-1] - h.energy["kinetic"][0]
    assert dke == pytest.approx(20.0 * dtheta, rel=1e-5)
    assert h.crank_speed[-1] > 600.0 * np.pi / 30 * 1.05


def test_tolerance_study_errors_shrink_towards_the_tightest_tolerance():
    from crankmodal.dynamics import tolerance_study

    m = _mech()
    T = 60.0 / RPM
    # atol stays as given at every rtol (as --set dynamics.solver.rtol leaves it): 1e-12 m so
    # that rtol is the tolerance that binds (with the default 1e-9 m the errors at 1e-3 and
    # 1e-5 were both atol's, 4.5e-8)
    study = tolerance_study(m, T, T / 360, [1e-3, 1e-5, 1e-8], base=SolverSettings(atol=1e-12))
    assert study["rtol"] == [1e-3, 1e-5, 1e-8]
    d = study["d_peak_piston_acceleration"]
    assert d[-1] == 0.0 and d[0] > d[1]
    assert study["energy_error"][0] > study["energy_error"][2]
    assert study["rhs_evals"][0] < study["rhs_evals"][2]
