"""Point rotary inertias attached to a flexible body's interface (the loom's sley on the rocker's
shaft D), against oracles independent of the mass-matrix formula: the kinetic energy is the bare
body's plus ½ J_s ω_D² with ω_D from the interface's Jacobian; the Lagrange equations of that
energy (finite differences) give no new velocity forces; frozen, the sley adds to J₀; a rocker
bar pinned at D with the sley rings at the full FE frequency with the inertia lumped on the D
RBE3 coupling (<= 1 %); the loom's rocker, quasi-static at speed, bends as a cantilever from the
sley under the coupler's force at C (F L³ / 3EI); the energy books close."""

import copy

import numpy as np
import pytest
import scipy.linalg as sla
from test_dynamics_flexible_fourbar import BARS, LOOM, SPEC, fe_bar

from crankmodal.dynamics.flexible import build as flexbuild
from crankmodal.dynamics.flexible.body import FlexibleBody
from crankmodal.dynamics.model.bodies import RigidBody
from crankmodal.dynamics.model.mechanisms import four_bar
from crankmodal.dynamics.run.integrate import SolverSettings
from crankmodal.dynamics.run.simulate import simulate

SLEY = LOOM["extra_rocker_inertia"]  # kg m², about D


def _body(rng, k=5, tilt=0):
    """A FlexibleBody with random admissible invariants (no FE) and frames ``D`` and ``C``."""
    X = rng.normal(size=(k, k)) * 0.1
    G = np.eye(k) * 0.8 + X @ X.T * 0.1
    S = rng.normal(size=(k, k)) * 0.05
    S = S - S.T
    f = np.concatenate([np.sort(rng.uniform(300.0, 9000.0, k - tilt)), np.zeros(tilt)])
    itf = {nm: (np.array([x, 0.01, 0.0]), rng.normal(size=(6, k)) * 0.05)
           for nm, x in (("D", -0.07), ("C", 0.075))}
    return FlexibleBody("rocker", 0.3, 2e-3, (0.0, 0.0), f, G, rng.normal(size=k) * 0.01, S, itf,
                        c=rng.normal(size=k) * 1e-3, n_tilt=tilt)


def _kinetic_by_frames(bare, attached, q, qd):
    """The bare body's own kinetic energy plus ½ J_s ω² of each attachment, ω the interface's
    angular velocity from its Jacobian row (not from the attached mass terms)."""
    return bare.kinetic_energy(q, qd) + sum(
        0.5 * J * float(bare.frame_jacobian(q, f)[2] @ qd) ** 2 for f, J in attached)


def test_kinetic_energy_is_the_bare_bodys_plus_half_js_omega_interface_squared():
    rng = np.random.default_rng(4)
    bare = _body(rng)
    body = copy.copy(bare)
    body.attach_inertia("D", SLEY)
    body.attach_inertia("C", 0.05)
    assert bare.attached == () and body.attached_inertia == pytest.approx(SLEY + 0.05)
    for _ in range(5):
        q = rng.normal(size=bare.ndof) * 0.3
        qd = rng.normal(size=bare.ndof) * 5.0
        qd[2] = rng.uniform(5.0, 20.0)  # rad/s: the swing
        qd[3:] *= 0.02  # m kg^½/s: elastic velocities small against the swing
        ref = _kinetic_by_frames(bare, body.attached, q, qd)
        assert body.kinetic_energy(q, qd) == pytest.approx(ref, rel=1e-13)
        assert body.kinetic_energy(q, qd) - bare.kinetic_energy(q, qd) > 1e-2 * ref


def test_attached_inertia_adds_no_velocity_forces():
    """``∂T/∂q − Ṁq̇`` by central differences of the frame-built kinetic energy (its momentum
    ``∂T/∂q̇`` and that differentiated along q̇) equals the body's ``velocity_forces``, which has
    no term for the attachment: ``T_s`` is quadratic in q̇ with a constant matrix."""
    rng = np.random.default_rng(5)
    bare = _body(rng, k=4)
    body = copy.copy(bare)
    body.attach_inertia("D", SLEY)
    q = rng.normal(size=bare.ndof) * 0.3
    qd = rng.normal(size=bare.ndof) * 5.0
    T = lambda q_, qd_: _kinetic_by_frames(bare, body.attached, q_, qd_)
    n, h = bare.ndof, 1e-5
    dTdq = np.array([(T(q + e, qd) - T(q - e, qd)) / (2 * h) for e in np.eye(n) * h])

    def momentum(q_):  # central differences are exact for T quadratic in q̇: unit steps
        return np.array([(T(q_, qd + e) - T(q_, qd - e)) / 2.0 for e in np.eye(n)])

    eps = 1e-5
    Mdot_qd = (momentum(q + eps * qd) - momentum(q - eps * qd)) / (2 * eps)
    ref = dTdq - Mdot_qd
    got = body.velocity_forces(q, qd)
    assert np.abs(got - ref).max() < 1e-7 * np.abs(ref).max()
    np.testing.assert_allclose(body.mass_matrix(q) @ qd, momentum(q), rtol=1e-7,
                               atol=1e-9 * np.abs(momentum(q)).max())


def test_frozen_and_rigid_twins_keep_the_attached_inertia():
    rng = np.random.default_rng(6)
    body = _body(rng, k=6, tilt=2)
    body.attach_inertia("D", SLEY)
    fro = body.frozen()
    assert fro.n_elastic == 0 and fro.attached == body.attached
    q, qd = np.zeros(fro.ndof), np.zeros(fro.ndof)
    qd[2] = 3.0
    assert fro.kinetic_energy(q, qd) == pytest.approx(0.5 * (body.j0 + SLEY) * 9.0, rel=1e-14)
    plain = _body(np.random.default_rng(6), k=6)
    plain.attach_inertia("D", SLEY)
    twin = flexbuild.rigid_twin(plain)
    assert isinstance(twin, RigidBody) and twin.inertia == pytest.approx(plain.j0 + SLEY)
    with pytest.raises(ValueError, match="no frame 'E'"):
        body.attach_inertia("E", 1.0)
    with pytest.raises(ValueError, match="attached inertia = -1.0"):
        body.attach_inertia("D", -1.0)


@pytest.fixture(scope="module")
def rocker_file():
    L, w, t, h = BARS["rocker"]
    return flexbuild.reduced_bar(L, (w, t), dict(SPEC, mesh_size=h), "dynamics.flexible.rocker")


def _rocker(rocker_file, **kw):
    return flexbuild.link_body(rocker_file, dict(SPEC, **kw), BARS["rocker"][0], "rocker")


def _pinned_hz(body, held=("D",)):
    """Frequencies of the body pinned at ``held`` (those interfaces' x, y held), linearised at
    rest."""
    q = np.zeros(body.ndof)
    N = sla.null_space(np.vstack([body.frame_jacobian(q, f)[:2] for f in held]))
    K = np.diag(np.concatenate([np.zeros(3), body.K]))
    lam = sla.eigh(N.T @ K @ N, N.T @ body.mass_matrix(q) @ N, eigvals_only=True)
    return np.sqrt(np.abs(lam)) / (2 * np.pi)


def _pinned_fe_hz(inertia, both=False):
    """The full FE rocker bar (the reduction's mesh and RBE3 couplings), D's mean translation
    held (penalty; ``both``: C's too), ``inertia`` lumped on D's rotation about z (``J gᵀg``
    added to the FE mass, g the RBE3 row of that rotation): the lowest nonzero mode with over
    90 % of its motion along y."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla


    model, G = fe_bar("rocker")
    G = sp.csr_matrix(G)
    g, C = G[5], G[0:3]  # end_x0 (D): rotation about z; translations
    if both:
        C = sp.vstack([C, G[6:9]])
    alpha = 1e6 * model.K.diagonal().max() / abs(C).max() ** 2
    lam, u = spla.eigsh((model.K + alpha * (C.T @ C)).tocsc(), 8,
                        (model.M + inertia * (g.T @ g)).tocsc(), sigma=-(2 * np.pi * 10) ** 2)
    f = np.sqrt(np.abs(lam)) / (2 * np.pi)
    share_y = np.sum(u[1::3] ** 2, axis=0) / np.sum(u ** 2, axis=0)
    j = int(np.flatnonzero((share_y > 0.9) & (f > 5.0))[0])
    return float(f[j])


def test_pinned_rocker_with_the_sley_rings_at_the_fe_frequency_with_the_inertia_lumped(
        rocker_file):
    """The rocker bar pinned at D with the sley attached there: its first bending frequency
    (790.4 Hz with the 6 stored in-plane modes) is the full FE's with 0.3728 kg m² lumped on
    D's RBE3 rotation (785.5 Hz) to 1 %; the sley spread into J₀ (the old form) gives 2067 Hz;
    without any sley both give the pinned-free 3335 / 3331 Hz."""
    body = _rocker(rocker_file)
    att = copy.copy(body)
    att.attach_inertia("D", SLEY)
    spread = copy.copy(body)
    spread.j0 = body.j0 + SLEY
    f_fe = _pinned_fe_hz(SLEY)
    f_att, f_spread = _pinned_hz(att)[1], _pinned_hz(spread)[1]
    assert _pinned_hz(att)[0] < 1e-2  # the swing about D
    assert abs(f_att / f_fe - 1) < 1e-2, (f_att, f_fe)
    assert f_spread > 2.0 * f_fe
    assert abs(_pinned_hz(body)[1] / _pinned_fe_hz(0.0) - 1) < 1e-2


def test_rocker_pinned_at_both_ends_swings_the_sley_on_its_bending_stiffness(oracle, rocker_file):
    """The loom at rest holds C (crank held, rigid coupler): the sley at D turns against the
    rocker's bending, a rotary spring 3EI/L (pinned far end), so it swings at
    √(3EI / (L J_s)) / 2π = 48.60 Hz (order 6.5 of 450 rpm). The reduced rocker with the sley
    attached: 48.51 Hz, the full FE with the sley lumped on D's RBE3 rotation 48.26 Hz (1 %),
    the closed form (2 %). The sley spread into J₀ (its mean axes turning against the modes'
    interface rotations) gives 385 Hz, 8 x too stiff."""
    L, w, t, _ = BARS["rocker"]
    body = _rocker(rocker_file)
    att = copy.copy(body)
    att.attach_inertia("D", SLEY)
    f = _pinned_hz(att, ("D", "C"))[0]
    closed = np.sqrt(3 * 2.1e11 * t * w ** 3 / 12 / (L * SLEY)) / (2 * np.pi)
    assert f == pytest.approx(_pinned_fe_hz(SLEY, both=True), rel=1e-2)
    oracle(stage="flexible", quantity="loom rocker with the sley attached at D, swing frequency, Hz", reference="closed form sqrt(3EI / (L J_s)) / 2 pi", tolerance="2 %", measured=f, expected=closed)
    assert f == pytest.approx(closed, rel=2e-2)
    spread = copy.copy(body)
    spread.j0 = body.j0 + SLEY
    assert _pinned_hz(spread, ("D", "C"))[0] > 5.0 * closed


def _quasi_static_bending(rocker, extra, crank_deg):
    """The loom at 450 rpm, quasi-static start at ``crank_deg``: the rocker's bending deflection
    of C off D's tangent (body axes, m) and the coupler's force on it across its axis at C, N."""
    from crankmodal.dynamics.flexible.initial import quasi_static_start

    m = four_bar(**dict(LOOM, extra_rocker_inertia=extra, theta0=np.deg2rad(crank_deg)),
                 rocker_body=rocker)
    m.q0, m.qd0, _ = quasi_static_start(m.system, m.q0, m.qd0)
    b = m.system.bodies[2]
    q = m.q0[m.system.slices[id(b)]]
    (sD, DD, rD), (sC, DC, _) = b.frames["D"], b.frames["C"]
    xi = q[3:]
    delta = float(((DC - DD) @ xi)[1] - np.hypot(*(sC - sD)) * (rD @ xi))
    h = simulate(m, 2e-6, 1e-6, SolverSettings(method="RK45", rtol=1e-9, atol=1e-13))
    c, s = np.cos(q[2]), np.sin(q[2])
    f_c = h.joint_forces["C"][0]
    return delta, float(-s * f_c[0] + c * f_c[1])


@pytest.mark.parametrize("crank_deg", [60.0, 240.0])
def test_quasi_static_loom_bends_the_rocker_as_a_cantilever_from_the_sley(rocker_file,
                                                                          crank_deg):
    """Quasi-static at full speed, the sley (0.3728 kg m², 200 x the bar's own 1.9e-3 about D)
    holds the rocker's D end like a clamp: C's deflection off D's tangent is F L³ / (3 E I) of
    the coupler's transverse force (1827 N at 60°: 1.104 mm, the closed form 1.105 mm) to 2 %.
    The sley spread into J₀ bends the bar 21-27 x less."""
    L, w, t, _ = BARS["rocker"]
    body = _rocker(rocker_file)
    delta, f_y = _quasi_static_bending(body, SLEY, crank_deg)
    closed = f_y * L ** 3 / (3 * 2.1e11 * t * w ** 3 / 12)
    # 977 N at 240 deg since the start solves positions and modes together (1267 N before: the
    # modes' accelerations were 27 m kg^0.5/s^2, within the omega^2-scaled tol, not at rest)
    assert abs(f_y) > 900.0
    assert abs(delta) == pytest.approx(abs(closed), rel=2e-2)
    spread = copy.copy(body)
    spread.j0 = body.j0 + SLEY
    delta_s, _ = _quasi_static_bending(spread, 0.0, crank_deg)
    assert abs(delta) > 10.0 * abs(delta_s)


def test_four_bar_attaches_the_sley_at_d_and_the_energy_books_close(rocker_file):
    """four_bar attaches extra_rocker_inertia at the flexible rocker's D interface (the caller's
    body untouched, info says where); undamped, started undeformed at full speed so the rocker
    rings against the sley: kinetic + strain energy change by the drive work alone."""
    body = _rocker(rocker_file, n_modes=3, damping_ratio=0.0)
    m = four_bar(**LOOM, rocker_body=body)
    rocker = m.system.bodies[2]
    assert body.attached == () and rocker.attached == (("D", SLEY),)
    assert rocker.j0 == body.j0
    assert rocker.info["extra_inertia_kgm2"] == SLEY
    assert rocker.info["extra_inertia_frame"] == "D"
    assert rocker.info["extra_inertia_interface"] == "end_x0"
    h = simulate(m, 0.01, 2e-5, SolverSettings(method="RK45", rtol=1e-9, atol=1e-12),
                 start="undeformed")
    e = h.energy
    assert e["strain"].max() > 1e-4 * np.abs(e["work_drive"]).max() > 0
    assert h.energy_error() < 1e-6
