"""Seed 004's flexible two-throw crank on its main journals (issue 29), against oracles:

- the quasi-static start on three journals (positions and modes solved together): its journal
  reactions against the static condensation of the same reduced body under the same loads
  (``[K -Cᵀ; C 0]``, a second formulation; tests/test_crank_bodies.py ties that condensation
  to a full FE static solve of the mesh within 1 %), and the start-up ringing of the modal
  coordinates gone;
- frozen modes on two journals against the rigid crank train: the total main-bearing force
  and drive torque, and each journal's force against the lever rule plus the Euler couple of
  the crank's FE inertia tensor (closed form);
- torsion: the crank struck at rest rings at the torsional frequency of the linearised
  constrained body (and, slow, of the full FE modal solve of the same mesh with the same
  journal supports); in a speed sweep the free end's twist peaks where order x speed equals
  it;
- energy: the books close with the strain energy counted.

The crank is seed 004's at a coarse mesh (0.04 m, 12 fixed-interface modes), reduced once into
the user cache (about 40 s the first time).
"""

from types import SimpleNamespace

import numpy as np
import pytest

from crankmodal.dynamics import Cylinder, crank_train
from crankmodal.dynamics.run.integrate import SolverSettings
from crankmodal.dynamics.run.simulate import simulate
from crankmodal.mechanism.arrangement import Arrangement

MACHINE = "multi_bearing_compressor"
SPEC004 = {"fidelity": "simplified", "mesh_size": 0.04, "element_order": 2,
           "material": "SG 700/2", "fixed_interface_modes": 12}
TWO_THROWS = Arrangement(throw_angles=(0.0, np.pi), cylinder_throws=(0, 1),
                         bank_angles=(0.0, 0.0))


@pytest.fixture(scope="module")
def seed004():
    """The coarse reduced crank's file and seed 004's cylinders (gas forces, arrangement)."""
    from crankmodal.dynamics.flexible.build import reduced_part
    from crankmodal.dynamics.model.bridge import cylinders_from_mechanism
    from crankmodal.mechanism.stage import validate as validate_mechanism
    from crankmodal.resources import load_machine

    path = reduced_part(MACHINE, "crankshaft", SPEC004, n_rods=2)
    src = cylinders_from_mechanism(validate_mechanism(load_machine(MACHINE)["mechanism"], None))
    return SimpleNamespace(path=path, **src)


def _crank(seed004, **spec):
    from crankmodal.dynamics.flexible.build import crank_body

    return crank_body(seed004.path, spec, None, seed004.crank_radius, throws=[1, 2])


def _constant(force):
    return lambda psi: force


# ------------------------------------------------------------- quasi-static start, 3 journals
def _condensed_reactions(body, roles, q, pin_forces):
    """Journal reactions (force of the crank on each housing, N) of the planar body pinned at
    its journals and held in rotation at its drive, under constant pin forces, by static
    condensation: ``[K -Cᵀ; C 0][q; μ] = [Q; 0]`` at the body pose ``q``."""
    q = np.array(q, float)
    q[3:] = 0.0
    K = np.zeros((body.ndof, body.ndof))
    K[3:, 3:] = np.diag(body.K)
    C = np.vstack([body.frame_jacobian(q, m)[:2] for m in roles["mains"]]
                  + [body.frame_jacobian(q, roles["drive"])[2:3]])
    Q = sum(body.frame_jacobian(q, p)[:2].T @ np.asarray(f, float)
            for p, f in zip(roles["pins"], pin_forces))
    n, c = body.ndof, len(C)
    A = np.block([[K, -C.T], [C, np.zeros((c, c))]])
    mu = np.linalg.solve(A, np.concatenate([Q, np.zeros(c)]))[n:n + 2 * len(roles["mains"])]
    return -mu.reshape(-1, 2)


def test_quasi_static_start_on_three_journals_gives_the_static_condensation_reactions(
        seed004, oracle):
    """Held at cylinder 1's top dead centre (speed 0), constant gas forces 12 and 7 kN: the
    start's journal reactions (multipliers of the KKT solve at t = 0) equal the static
    condensation of the same body within 1e-6 of the load (seen 1.7e-8: the start is the
    geometrically exact static state, the condensation its linearisation; the modes bend the
    crank by microns). The middle journal carries 72 % (a two-bearing split gives it none).
    Before, the start held the modes while closing the joints and stopped at a constraint
    residual of 7e-9 m (NumericalError): a crank bent over three journals cannot close them
    with its modes held."""
    body, roles = _crank(seed004, damping_ratio=0.2)
    loads = (12e3, 7e3)
    cyls = [Cylinder(axis_angle=np.pi / 2, rod_length=0.24, rod_mass=1e-3, rod_inertia=1e-6,
                     rod_com=0.08, piston_mass=1e-3, gas_force=_constant(f)) for f in loads]
    mech = crank_train(0.06, cyls, 0.0, direction=-1, arrangement=TWO_THROWS,
                       crank_body=body, crank_roles=roles, theta0=np.pi / 2)
    info = mech.start_quasi_static()
    assert info["residual"] < 1e-9
    sysm = mech.ideal
    out = sysm.solve(0.0, mech.q0, mech.qd0)
    assert np.abs(out["phi"]).max() < 1e-12
    rows = {c.name: r for c, r in zip(sysm.constraints, sysm.rows)}
    got = np.array([out["lam"][rows[f"main_{j}"]] for j in (1, 2, 3)])
    # both rods push straight down on their pins (their axes vertical at top dead centre)
    expected = _condensed_reactions(body, roles, mech.q0[:body.ndof],
                                    [(0.0, -f) for f in loads])
    diff = np.abs(got - expected).max() / sum(loads)
    oracle(stage="dynamics", quantity="seed 004 crank on three journals, quasi-static start: "
           "journal reactions, largest difference / total pin load",
           reference="static condensation of the same reduced body (second formulation)",
           tolerance="1e-6", measured=diff, expected=0.0)
    assert diff < 1e-6
    assert got.sum(axis=0) == pytest.approx([0.0, -sum(loads)], abs=1e-6 * sum(loads))
    assert -got[1, 1] > 0.5 * sum(loads)
    xi = mech.q0[3:3 + body.n_elastic]
    assert np.abs(xi).max() > 1e-6  # it did bend


def test_quasi_static_start_of_a_torque_driven_train_keeps_its_free_angles(seed004):
    """Seed 004's scene set-up (motor through the coupling, constant motor torque: the train's
    angle and the coupling's twist are free): the start converges (elastic residual < 1e-9,
    seen 2e-17 in 2 steps) and leaves the free angles where the builder put them (seen
    4e-9 rad). Unweighted least-change steps turned the crank by 0.7 rad; NumPy's default
    cut-off in the velocity projection made a 156 rad/s step and stalled at 1e-4."""
    from crankmodal.dynamics.model.drive import MotorDrive

    body, roles = _crank(seed004, n_modes=12)
    mech = crank_train(seed004.crank_radius, seed004.cylinders, seed004.speed_rpm,
                       direction=-1, arrangement=seed004.arrangement, crank_body=body,
                       crank_roles=roles, motor=MotorDrive(0.10, 1.5e4, 6.0),
                       drive_torque=-95.76)
    q0, qd0 = mech.q0.copy(), mech.qd0.copy()
    info = mech.start_quasi_static()
    assert info["residual"] < 1e-9
    sysm = mech.ideal
    im = sysm.slices[id(mech.motor)].start + 2
    assert abs(mech.q0[2] - q0[2]) < 1e-6 and abs(mech.q0[im] - q0[im]) < 1e-6
    assert mech.qd0[im] == pytest.approx(qd0[im], rel=1e-12)
    out = sysm.solve(0.0, mech.q0, mech.qd0)
    assert np.abs(out["phi"]).max() < 1e-12
    _, Cq, nu, _ = sysm.constraint_terms(0.0, mech.q0, mech.qd0)
    assert np.abs(Cq @ mech.qd0 - nu).max() < 1e-9
    assert np.abs(mech.q0[3:3 + body.n_elastic]).max() > 1e-6


def _ringing(X, freqs, dt):
    """Per mode, the largest departure of its coordinate from its moving mean over one period
    of the mode (the ringing at the mode's frequency; the slow quasi-static motion at orders
    1-2 of the revolution passes the mean), m kg^½."""
    out = []
    for a, f in enumerate(freqs):
        w = max(1, round(1.0 / (f * dt)))
        mean = np.convolve(X[:, a], np.ones(w) / w, mode="same")
        out.append(np.abs(X[w:-w, a] - mean[w:-w]).max())
    return np.array(out)


def test_quasi_static_start_on_three_journals_removes_the_start_up_ringing(seed004):
    """Seed 004 at 1494.6 rpm (gas, 12 modes, 2 % damping), first revolution: started
    undeformed, every mode rings (the middle journal's peak 180 kN); from the quasi-static
    start the ringing of each mode is under 10 % of that (seen 0.2-4.8 %) and the middle
    journal's peak is its running level (seen 17 kN)."""
    rev = seed004.speed_rpm / 60.0
    dt = 1.0 / (720.0 * rev)
    settings = SolverSettings(method="RK45", rtol=1e-7, atol=1e-10)
    ring, peak = {}, {}
    for start in ("undeformed", "quasi_static"):
        body, roles = _crank(seed004, n_modes=12)
        mech = crank_train(seed004.crank_radius, seed004.cylinders, seed004.speed_rpm,
                           direction=-1, arrangement=seed004.arrangement, crank_body=body,
                           crank_roles=roles)
        h = simulate(mech, 1.0 / rev, dt, settings, ideal=True, start=start)
        k = body.n_elastic
        ring[start] = _ringing(h.modal["crank"][:, :k], body.frequencies_hz[:k], dt)
        peak[start] = np.hypot(*h.joint_forces["main_2"].T).max()
    assert np.all(ring["quasi_static"] < 0.1 * ring["undeformed"])
    assert peak["quasi_static"] < 0.2 * peak["undeformed"]


# ------------------------------------------------------------- frozen modes on two journals
def test_frozen_modes_on_two_journals_give_the_rigid_crank_train(seed004):
    """The crank with no elastic mode (its two tilts only) on its outer journals 1 and 3, seed
    004's cylinders with gas at 1494.6 rpm, one revolution, against a RigidBody crank with the
    same mass, polar moment and frames on one main joint: the total main-bearing force and
    the drive torque within 1e-9 of their peaks (seen 1.5e-11, 3e-11). Each journal's force
    against the rigid run's lever rule (rods' forces at their throws, the rest at the centre
    of mass) plus the couple of the crank's FE inertia tensor about its centre of mass
    (Euler: M = (I_xz α - I_yz ω², I_yz α + I_xz ω²), carried by the journal pair): within
    1e-9 of the total's peak (seen 2e-11; without the couple 0.63)."""
    from crankmodal.dynamics.model.bodies import RigidBody
    from crankmodal.dynamics.results.journals import journal_forces
    from crankmodal.reduction.io import load_flexbody

    body, roles = _crank(seed004, n_modes=0)
    assert body.n_elastic == 0 and body.n_tilt == 2
    frames = {n: tuple(body.frames[n][0]) for n in ["main_1", "drive"] + roles["pins"]}
    rigid = RigidBody("crank", body.mass, body.j0, frames)
    rev = seed004.speed_rpm / 60.0
    settings = SolverSettings(method="RK45", rtol=1e-11, atol=1e-14)

    def run(crank, crank_roles):
        mech = crank_train(seed004.crank_radius, seed004.cylinders, seed004.speed_rpm,
                           direction=-1, arrangement=seed004.arrangement, crank_body=crank,
                           crank_roles=crank_roles)
        return mech, simulate(mech, 1.0 / rev, 1.0 / (360.0 * rev), settings, ideal=True)

    _, hf = run(body, dict(roles, mains=["main_1", "main_3"]))
    mr, hr = run(rigid, {"mains": ["main_1"], "pins": roles["pins"], "drive": "drive"})
    f, g = hf.main_bearing_force, hr.main_bearing_force
    peak = np.hypot(*g.T).max()
    assert peak > 1e4
    assert np.abs(f - g).max() < 1e-9 * peak
    assert np.abs(hf.drive_torque - hr.drive_torque).max() < 1e-9 * np.abs(hr.drive_torque).max()
    # per journal: the lever rule on the rigid run, in the body's axial coordinates
    fb = load_flexbody(seed004.path)
    z1, z3 = body.info["mains_z_m"][0], body.info["mains_z_m"][2]
    mr.journals_z = [z1, z3]
    mr.rows_z = {f"big_end_{i}": t["z_m"] for i, t in enumerate(body.info["throws"], start=1)}
    mr.crank.z = float(fb.centre_of_mass[2])
    lever = journal_forces(mr, hr)
    inertia = np.asarray(fb.inertia, float)  # tensor: off-diagonals are -∫x z dm
    w, a, th = hr.crank_speed, hr.angular_acceleration["crank"], hr.crank_angle
    mx = inertia[0, 2] * a - inertia[1, 2] * w ** 2  # body axes, the moment on the crank
    my = inertia[1, 2] * a + inertia[0, 2] * w ** 2
    c, s = np.cos(th), np.sin(th)
    moment = np.column_stack([c * mx - s * my, s * mx + c * my])
    # a pair +Q at journal 3, -Q at journal 1 on the crank: (z3 - z1) e_z x Q = M
    pair = np.column_stack([moment[:, 1], -moment[:, 0]]) / (z3 - z1)
    for name, expected in (("main_1", lever["main_1"] + pair),
                           ("main_2", lever["main_2"] - pair)):
        assert np.abs(hf.joint_forces[name] - expected).max() < 1e-9 * peak
    assert np.abs(pair).max() > 0.1 * peak  # the couple matters


# ------------------------------------------------------------------------------- energy
def test_energy_closes_with_the_strain_energy_on_three_journals(seed004):
    """Seed 004's flexible crank on three journals (12 modes, undamped), gas and inertia at
    1494.6 rpm, started undeformed so that the modes ring: kinetic + strain energy change by
    the drive's and the gas forces' work alone: residual under 1e-6 of the energy exchanged
    (seen 1e-11), while the strain energy reaches 1.5e-3 of it (the residual without it)."""
    body, roles = _crank(seed004, n_modes=12, damping_ratio=0.0)
    mech = crank_train(seed004.crank_radius, seed004.cylinders, seed004.speed_rpm,
                       direction=-1, arrangement=seed004.arrangement, crank_body=body,
                       crank_roles=roles)
    rev = seed004.speed_rpm / 60.0
    h = simulate(mech, 0.5 / rev, 1.0 / (720.0 * rev),
                 SolverSettings(method="RK45", rtol=1e-10, atol=1e-13), ideal=True,
                 start="undeformed")
    e = h.energy
    assert e["strain"].max() > 5e-4 * h.energy_scale()
    assert e["dissipated_modal"][-1] == 0.0
    assert h.energy_error() < 1e-6


# ------------------------------------------------------------------------------- torsion
#: mean reciprocating inertia per throw, m_rec r² / 2 (seed 004's 22.194 kg at 0.06 m), kg m²
J_RECIPROCATING = 22.194 * 0.06 ** 2 / 2


def _tiny_cylinders(gas_force=None):
    """Rods and pistons of micrograms: the throws' reciprocating inertia is attached instead."""
    return [Cylinder(axis_angle=np.pi / 2, rod_length=0.24, rod_mass=1e-6, rod_inertia=1e-9,
                     rod_com=0.08, piston_mass=1e-6, gas_force=gas_force) for _ in range(2)]


def _torsion_train(seed004, n_modes, zeta, speed_rpm=0.0, gas_force=None):
    """The crank (flywheel in its mesh) on its three journals with each throw's mean
    reciprocating inertia attached to its crankpin. At rest (speed 0) it is driven by a
    1e-3 kg m² motor through a 1 N m/rad coupling with no torque (its rotation free: the
    coupling mode is at 5 Hz and moves the crank's torsion by ~1e-6), else at a prescribed
    speed at the flywheel face."""
    from crankmodal.dynamics.model.drive import MotorDrive

    body, roles = _crank(seed004, n_modes=n_modes, damping_ratio=zeta)
    for pin in roles["pins"]:
        body.attach_inertia(pin, J_RECIPROCATING)
    kw = {"drive_torque": 0.0, "motor": MotorDrive(1e-3, 1.0)} if speed_rpm == 0.0 else {}
    mech = crank_train(0.06, _tiny_cylinders(gas_force), speed_rpm, direction=-1,
                       arrangement=TWO_THROWS, crank_body=body, crank_roles=roles, **kw)
    return mech, body


def _torsional_mode_hz(mech, body):
    """The torsional frequency of the train linearised at its start: the undamped modes of
    ``K`` (the crank's modal stiffness) and ``M`` (every body, the attached inertias) on the
    null space of the joints' Jacobian; the mode twisting the free end most against the drive
    frame (per unit modal mass), Hz."""
    import scipy.linalg as sla

    from crankmodal.dynamics.results.torsional import free_end_frame

    sysm = mech.ideal
    q0 = mech.q0
    M = sysm.mass_matrix(q0)
    _, Cq, _, _ = sysm.constraint_terms(0.0, q0, np.zeros(sysm.n))
    sl = sysm.slices[id(body)]
    K = np.zeros_like(M)
    k = body.n_coordinates
    K[sl.start + 3:sl.stop, sl.start + 3:sl.stop] = np.diag(body.K[:k])
    N = sla.null_space(Cq)
    lam, V = sla.eigh(N.T @ K @ N, N.T @ M @ N)
    f = np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)
    twist = np.zeros(sysm.n)
    twist[sl.start + 3:sl.stop] = (body.frames[free_end_frame(mech)][2]
                                   - body.frames[mech.drive_frame][2])
    return float(f[np.argmax(np.abs(twist @ N @ V) * (f > 1.0))])


def _strike_free_end(mech, body, impulse=1.0):
    """Velocities after an impulsive torque (N m s) on the free-end journal of the train at
    rest: ``[M Cqᵀ; Cq 0][v; μ] = [J_fᵀ (0, 0, impulse); 0]``."""
    from crankmodal.dynamics.results.torsional import free_end_frame

    sysm = mech.ideal
    q0, n, m = mech.q0, mech.ideal.n, mech.ideal.m
    M = sysm.mass_matrix(q0)
    _, Cq, _, _ = sysm.constraint_terms(0.0, q0, np.zeros(n))
    sl = sysm.slices[id(body)]
    Jf = np.zeros((3, n))
    Jf[:, sl] = body.frame_jacobian(q0[sl], free_end_frame(mech))
    A = np.block([[M, Cq.T], [Cq, np.zeros((m, m))]])
    rhs = np.concatenate([Jf.T @ np.array([0.0, 0.0, impulse]), np.zeros(m)])
    mech.qd0 = np.linalg.solve(A, rhs)[:n]
    return mech


def _peak_hz(t, x):
    """Frequency of the largest spectral peak of ``x`` (Hann window, 16 x zero padding,
    parabolic interpolation of the log magnitude), Hz."""
    n = 16 * len(x)
    X = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(len(x)), n))
    k = int(np.argmax(X))
    a, b, c = np.log(X[k - 1:k + 2])
    return (k + 0.5 * (a - c) / (a - 2 * b + c)) / (n * (t[1] - t[0]))


def _ring_hz(seed004, n_modes, periods, settings):
    mech, body = _torsion_train(seed004, n_modes, 0.0)
    f_lin = _torsional_mode_hz(mech, body)
    _strike_free_end(mech, body)
    h = simulate(mech, periods / f_lin, 1.0 / (40.0 * f_lin), settings, ideal=True,
                 start="undeformed")
    return _peak_hz(h.t, h.torsion["twist_free_end"]), f_lin


def test_crank_struck_at_rest_rings_at_its_linearised_torsional_frequency(seed004, oracle):
    """The crank + flywheel + the throws' mean reciprocating inertia on its three journals,
    struck at the free end at rest (6 modes, undamped): the free end's twist against the
    flywheel face rings at the torsional mode of the same train linearised (eigenvalues on
    the joints' null space), 0.5 % asked, seen 9e-8 (467.454 Hz)."""
    f_ring, f_lin = _ring_hz(seed004, 6, 30, SolverSettings(method="RK45", rtol=1e-7,
                                                            atol=1e-10))
    oracle(stage="dynamics", quantity="seed 004 crank + flywheel + reciprocating inertia on "
           "three journals, struck at rest: torsional ringing frequency, Hz",
           reference="undamped modes of the same train linearised at rest (second "
           "formulation)", tolerance="0.5 %", measured=f_ring, expected=f_lin)
    assert 300.0 < f_lin < 700.0
    assert f_ring == pytest.approx(f_lin, rel=1e-4)


def _fe_torsional_hz(seed004):
    """The same crank as a full FE modal solve: the mean x, y translation of each journal
    surface held by penalty springs ``α GᵀG`` (distributing rows of the reduction's
    interfaces; α 1e5 x the stiffness diagonal, 1e3 gives the same frequency to 1e-6), each
    crankpin's mean rotation about z carrying J_RECIPROCATING (``M + J gᵀg``); the mode
    twisting journal 1 against the flywheel face most, Hz."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from crankmodal.fem.assembly import assemble
    from crankmodal.reduction import parts
    from crankmodal.reduction.interfaces import distributing_rows

    inputs = parts.check_part(MACHINE, "crankshaft", SPEC004)
    part, _ = parts.machine_part(inputs)
    itf = parts.part_interfaces(part, parts.crank_interface_specs(part.regions, 1))
    names = [i.name for i in itf]
    model = assemble(part, inputs.material)
    points = np.asarray(part.mesh.points, float)[:, :3]
    rows, G = distributing_rows(points, np.asarray(part.mesh.cells[0].data), itf)
    pos = {r: i for i, r in enumerate(rows)}

    def row(name, k):
        return G[pos[6 * names.index(name) + k]]

    Gj = sp.vstack([row(f"main_journal_{j}", k) for j in (1, 2, 3) for k in (0, 1)]).tocsr()
    K, M = model.K.tocsr(), model.M.tocsr()
    for i in (1, 2):
        g = row(f"crankpin_{i}_row_1", 5)
        M = M + J_RECIPROCATING * (g.T @ g)
    GtG = (Gj.T @ Gj).tocsr()
    alpha = 1e5 * K.diagonal().max() / GtG.diagonal().max()
    w, V = spla.eigsh((K + alpha * GtG).tocsc(), k=8, M=M.tocsc(),
                      sigma=(2 * np.pi * 100.0) ** 2, which="LM")
    f = np.sqrt(np.abs(w)) / (2 * np.pi)
    twist = np.asarray((row("main_journal_1", 5) - row("flywheel_end_face", 5)) @ V).ravel()
    return float(f[np.argmax(np.abs(twist) * (f > 1.0))])


@pytest.mark.slow
def test_crank_struck_at_rest_rings_at_the_fe_torsional_frequency(seed004, oracle):
    """As above with 12 modes, against the full FE modal solve of the same mesh with the same
    journal supports and attached inertias (0.5 %). Measured: 462.93 Hz against 461.23 Hz
    (+0.37 %; 6 modes give 467.45 Hz, +1.3 %: the torsion needs the modes up to ~2 kHz)."""
    f_ring, f_lin = _ring_hz(seed004, 12, 30, SolverSettings(method="RK45", rtol=1e-7,
                                                             atol=1e-10))
    f_fe = _fe_torsional_hz(seed004)
    oracle(stage="dynamics", quantity="seed 004 crank + flywheel + reciprocating inertia on "
           "three journals, struck at rest: torsional ringing frequency, Hz",
           reference="full FE modal solve of the same mesh, journals held, the same inertias",
           tolerance="0.5 %", measured=f_ring, expected=f_fe)
    assert f_ring == pytest.approx(f_lin, rel=1e-4)
    assert f_ring == pytest.approx(f_fe, rel=5e-3)


@pytest.mark.slow
def test_speed_sweep_of_the_free_end_twist_peaks_where_order_times_speed_is_the_torsional_frequency(
        seed004):
    """Both pistons pushed by a pure twelfth-order force ``F0 cos 12ψ`` (6 modes, 2 % damping,
    the flywheel face at a prescribed speed): over a sweep of speeds around 60 f_t / 12 (f_t
    the torsional frequency of the same train linearised at rest with its flywheel face held,
    425.73 Hz: 2128.6 rpm), the free end's order-12 twist peaks at that speed within 0.5 %
    (parabola through the three largest; seen 0.9970; a 2 % damped mode's peak lies at
    sqrt(1 - 2ζ²) = 0.9996 of it, the spin softening at 223 rad/s moves it by ~0.1 %) and
    falls to under 0.7 of the peak 3 % to either side (seen 0.51, 0.44). Order 12, not 4: at the
    7000 rpm of order 4 the spin softening (ω² 6 % of the mode's) shifts the peak by 3 %."""
    from crankmodal.dynamics.results.torsional import torsional_sweep

    order, zeta = 12.0, 0.02
    mech, body = _torsion_train(seed004, 6, zeta, speed_rpm=1000.0)
    f_t = _torsional_mode_hz(mech, body)
    n_res = 60.0 * f_t / order
    ratios = np.array([0.97, 0.985, 0.995, 1.0, 1.005, 1.015, 1.03])

    def make(n):
        return _torsion_train(seed004, 6, zeta, speed_rpm=n,
                              gas_force=lambda psi: 2e3 * np.cos(order * psi))[0]

    res = torsional_sweep(make, n_res * ratios, revolutions=2.0, settle_revolutions=6.0,
                          orders=[order],
                          settings=SolverSettings(method="RK45", rtol=1e-7, atol=1e-10))
    amp = np.array([a[0] for a in res["amplitude"]])
    k = int(np.argmax(amp))
    assert 0 < k < len(amp) - 1
    x, y = ratios[k - 1:k + 2], amp[k - 1:k + 2]
    c2, c1, _ = np.polyfit(x, y, 2)
    peak = -c1 / (2 * c2)
    assert peak == pytest.approx(1.0, abs=5e-3)
    assert amp[0] < 0.7 * amp.max() and amp[-1] < 0.7 * amp.max()
