"""Craig–Bampton basis, orthonormalisation and flexible-body data against independent oracles."""

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from crankmodal.errors import ParameterError, SceneError
from crankmodal.fem.assembly import assemble, rigid_body_modes
from crankmodal.fem.materials import Material
from crankmodal.fem.modal import solve_modes
from crankmodal.fem.testparts import bar
from crankmodal.reduction.craig_bampton import craig_bampton
from crankmodal.reduction.flexbody import inertia_invariants
from crankmodal.reduction.interfaces import (
    distributing_rows,
    interface_rigid_fields,
    make_interfaces,
    tie_transformation,
)
from crankmodal.reduction.reduce import reduce_body

STEEL = Material("steel", 2.1e11, 0.3, 7850.0)
L, B, H = 1.0, 0.05, 0.05


@pytest.fixture(scope="module")
def bar_model():
    part = bar(L, B, H, (20, 2, 2), order=2)
    return part, assemble(part, STEEL)


def _ends(part, kind):
    return make_interfaces(part, [{"region": "end_x0", "kind": kind},
                                  {"region": "end_x1", "kind": kind}])


def test_distributing_reduction_converges_to_full_free_free_frequencies(oracle, bar_model):
    """RBE3 adds no stiffness, so the reduced free-free spectrum is a Rayleigh–Ritz
    approximation of the full FE one: from above, improving with every added fixed-interface
    mode, and the first six elastic frequencies are within 0.5 % at 20 modes."""
    part, model = bar_model
    full = solve_modes(model, 6).frequencies_hz
    itf = _ends(part, "distributing")
    errors = []
    for k in (0, 5, 10, 20):
        body, _ = reduce_body(model, itf, fixed_interface_modes=k)
        f = body.elastic_frequencies_hz[:6]
        assert np.all(f >= full * (1 - 1e-9))  # Rayleigh–Ritz upper bounds
        errors.append(f / full - 1)
    errors = np.array(errors)
    assert np.all(np.diff(errors, axis=0) <= 1e-9)
    oracle(stage="reduction", quantity="Craig-Bampton (RBE3 ends, 20 modes), first elastic free-free frequency, Hz", reference="full FE model (second formulation)", tolerance="0.5 % (all six)", measured=full[0] * (1 + errors[-1][0]), expected=full[0])
    assert np.abs(errors[-1]).max() < 0.005, errors[-1]
    assert np.abs(errors[0]).max() > 0.05  # Guyan alone is far off: the test can fail


def test_rigid_reduction_converges_to_the_tied_full_model(oracle, bar_model):
    """RBE2 stiffens the ends: the oracle is the full model with the same ties, solved dense."""
    part, model = bar_model
    itf = _ends(part, "rigid")
    T, _ = tie_transformation(model.K.shape[0], itf, model.points)
    keep = np.flatnonzero(np.asarray(abs(T).sum(axis=0)).ravel() > 0)
    keep = keep[np.asarray((T.T @ (model.K @ T)).diagonal())[keep] > 0]
    Kt = (T.T @ model.K @ T).tocsc()[keep][:, keep]
    Mt = (T.T @ model.M @ T).tocsc()[keep][:, keep]
    lam = np.sort(spla.eigsh(Kt, 12, Mt, sigma=-1e3, which="LM", return_eigenvectors=False))
    tied = np.sqrt(np.abs(lam[6:12])) / (2 * np.pi)  # scipy ARPACK + SuperLU: another solver
    body, _ = reduce_body(model, itf, fixed_interface_modes=20)
    rel = body.elastic_frequencies_hz[:6] / tied - 1
    oracle(stage="reduction", quantity="Craig-Bampton (RBE2 ends, 20 modes), first elastic frequency, Hz", reference="full model with the same ties, ARPACK + SuperLU (second formulation)", tolerance="0.5 %, from above", measured=body.elastic_frequencies_hz[0], expected=tied[0])
    assert np.all(rel > -1e-9) and rel.max() < 0.005, rel


def test_constraint_modes_reproduce_static_interface_loads_exactly_rbe2(bar_model):
    """Guyan limit: a load on an interface node, the other interface clamped, gives the same
    interface motion and displacement field from the reduced matrices as a full static solve of
    the same tied model; and the tip deflection matches Timoshenko beam theory."""
    part, model = bar_model
    itf = _ends(part, "rigid")
    cb = craig_bampton(model, itf, n_modes=8)
    F = np.array([0.0, 1000.0, -400.0, 30.0, 20.0, -50.0])  # N, N m at end_x1
    # reduced: clamp interface 0 (coordinates 0-5), solve for everything else
    free = np.arange(6, cb.K.shape[0])
    rhs = np.zeros(len(free))
    rhs[:6] = F
    x = np.linalg.solve(cb.K[np.ix_(free, free)], rhs)
    assert np.abs(x[6:]).max() < 1e-10 * np.abs(x[:6]).max()  # modal amplitudes stay zero
    u_red = cb.V[:, free] @ x
    # full tied model, clamped at interface 0
    T, rest = tie_transformation(model.K.shape[0], itf, model.points)
    nr = len(rest)
    cols = np.r_[np.arange(nr), nr + 6 + np.arange(6)]
    Tt = T[:, cols]
    Kt = (Tt.T @ model.K @ Tt).tocsc()
    keep = np.flatnonzero(Kt.diagonal() > 0)  # drop unused DOFs (rigid surface rows are gone)
    f = np.zeros(Kt.shape[0])
    f[nr:] = F
    y = np.zeros(Kt.shape[0])
    y[keep] = spla.spsolve(Kt[keep][:, keep], f[keep])
    u_full = Tt @ y
    assert np.allclose(y[nr:], x[:6], rtol=0, atol=1e-9 * np.abs(x[:6]).max())
    assert np.abs(u_red - u_full).max() < 1e-9 * np.abs(u_full).max()
    # physics: cantilever with a tip force Fy, Timoshenko (shear coefficient 5/6)
    E, G = STEEL.E, STEEL.shear_modulus
    Iz = B * H ** 3 / 12
    x_only = np.linalg.solve(cb.K[np.ix_(free, free)][:6, :6], np.r_[0, 1000.0, 0, 0, 0, 0])
    beam = 1000.0 * L ** 3 / (3 * E * Iz) + 1000.0 * L / (5 / 6 * G * B * H)
    assert abs(x_only[1] / beam - 1) < 0.02


def test_reduced_mass_gives_bar_mass_centre_of_mass_and_inertia(bar_model):
    """Rigid fields in reduced coordinates, closed form for a prism ρ b h L."""
    part, model = bar_model
    body, _ = reduce_body(model, _ends(part, "distributing"), fixed_interface_modes=4)
    m = STEEL.rho * B * H * L
    assert body.mass_kg == pytest.approx(m, rel=1e-10)
    assert np.allclose(body.centre_of_mass, [L / 2, 0, 0], atol=1e-10 * L)
    J = m / 12 * np.diag([B * B + H * H, L * L + H * H, L * L + B * B])
    assert np.allclose(body.inertia, J, rtol=0, atol=1e-10 * J.max())
    c = np.array([L / 2, 0, 0])
    J_origin = J + m * (c @ c * np.eye(3) - np.outer(c, c))
    assert np.allclose(body.invariants["I7"], J_origin, rtol=0, atol=1e-10 * J_origin.max())
    assert body.invariants["I1"] == pytest.approx(m, rel=1e-12)
    assert np.allclose(body.invariants["I2"], m * c, atol=1e-10 * m)


@pytest.mark.parametrize("kind", ["rigid", "distributing"])
def test_orthonormalised_basis_is_m_orthonormal_k_diagonal_with_six_rigid_modes(bar_model, kind):
    part, model = bar_model
    itf = _ends(part, kind)
    body, cb = reduce_body(model, itf, fixed_interface_modes=12)
    Vo = cb.V @ body.cb_to_modal
    Mo = Vo.T @ (model.M @ Vo)
    Ko = Vo.T @ (model.K @ Vo)
    assert np.abs(Mo - np.eye(len(Mo))).max() < 1e-10
    off = Ko - np.diag(np.diag(Ko))
    assert np.abs(off).max() < 1e-10 * np.abs(np.diag(Ko)).max()
    assert np.allclose(np.diag(Ko), (2 * np.pi * body.frequencies_hz) ** 2, rtol=1e-8,
                       atol=1e-8 * np.diag(Ko).max())
    # rigid modes: exactly the span of the rigid-body fields of the solid
    assert body.rigid.sum() == 6 and np.all(body.rigid[:6])
    R = rigid_body_modes(model.points)
    P = Vo[:, :6]
    coef = np.linalg.lstsq(R, P, rcond=None)[0]
    assert np.abs(R @ coef - P).max() < 1e-10 * np.abs(P).max()
    # an independent dense eigen solution of the CB pencil finds the same six zero modes
    lam = sla.eigh(cb.K, cb.M, eigvals_only=True)
    assert np.sum(np.abs(lam) < 1e-6 * lam[6]) == 6
    # the interface map moves each interface node as the full field does
    Rb = interface_rigid_fields(itf)
    assert np.allclose(body.interface_map.reshape(-1, body.n_modes), body.cb_to_modal[:12])
    assert Rb.shape == (12, 6)
    # ... checked against the full field, not against how the map is stored: a rigid surface
    # follows its node rigidly, a distributing one has it at its mean motion (q = G u)
    _, G = distributing_rows(model.points, model.cells, itf)
    for r, i in enumerate(itf):
        q = body.interface_map[r]  # (6, n)
        if kind == "rigid":
            u = Vo.reshape(len(model.points), 3, -1)[i.nodes].reshape(-1, Vo.shape[1])
            moved = rigid_body_modes(model.points[i.nodes], i.centre) @ q
            assert np.abs(u - moved).max() < 1e-10 * np.abs(Vo).max()
        else:
            assert np.abs(G[6 * r:6 * r + 6] @ Vo - q).max() < 1e-10 * np.abs(q).max()


def test_elastic_modes_meet_mean_axis_conditions_and_unit_modal_mass(bar_model):
    """Free-free elastic modes are M-orthogonal to rigid motion: ∫ρφ = 0, ∫ρ x × φ = 0."""
    part, model = bar_model
    body, _ = reduce_body(model, _ends(part, "rigid"), fixed_interface_modes=6)
    inv = body.invariants
    scale = np.sqrt(body.mass_kg) * L
    assert np.abs(inv["I3"]).max() < 1e-10 * scale
    assert np.abs(inv["I4"]).max() < 1e-10 * scale * L
    assert np.allclose(inv["I6"], np.eye(len(inv["I6"])), atol=1e-10)
    assert np.allclose(inv["I5"], -inv["I5"].transpose(0, 2, 1), atol=1e-12)


def test_invariants_i8_i9_are_derivatives_of_the_deformed_inertia_tensor(bar_model):
    """J(x + εφ) = I7 + ε (I8 + I8ᵀ) + ε² I9[:, :, a, a]: central differences are exact for
    a quadratic, so they check I8 and I9 to round-off."""
    part, model = bar_model
    body, cb = reduce_body(model, _ends(part, "distributing"), fixed_interface_modes=6)
    Ms = model.M[0::3, 0::3]
    phi = (cb.V @ body.cb_to_modal)[:, ~body.rigid][:, [0, 3]]
    inv = inertia_invariants(model.points, Ms, phi)
    eps = 1e-3
    for a in range(2):
        d = phi[:, a].reshape(-1, 3)
        Jp = inertia_invariants(model.points + eps * d, Ms, phi[:, :1])["I7"]
        Jm = inertia_invariants(model.points - eps * d, Ms, phi[:, :1])["I7"]
        J0 = inv["I7"]
        first = (Jp - Jm) / (2 * eps)
        second = (Jp - 2 * J0 + Jm) / (2 * eps * eps)
        I8 = inv["I8"][:, :, a]
        assert np.allclose(first, I8 + I8.T, rtol=0, atol=1e-8 * np.abs(J0).max())
        assert np.allclose(second, inv["I9"][:, :, a, a], rtol=0, atol=1e-6 * np.abs(J0).max())


def test_cutoff_keeps_every_fixed_interface_mode_below_it(bar_model):
    part, model = bar_model
    itf = _ends(part, "rigid")
    ref = craig_bampton(model, itf, n_modes=30).fixed_interface_hz
    cut = 0.5 * (ref[9] + ref[10])
    cb = craig_bampton(model, itf, cutoff_hz=cut)
    assert cb.n_fixed_modes == 10
    assert np.allclose(cb.fixed_interface_hz, ref[:10], rtol=1e-9)


def test_a_cutoff_beyond_the_most_modes_kept_is_refused_not_truncated(bar_model):
    part, model = bar_model
    itf = _ends(part, "rigid")
    f10 = craig_bampton(model, itf, n_modes=10).fixed_interface_hz[-1]
    with pytest.raises(ParameterError, match=r"^cutoff_hz: 10 fixed-interface modes .* "
                                             r"reach only [\d.]+ Hz, below the cut-off") as info:
        craig_bampton(model, itf, cutoff_hz=2 * f10, max_modes=10)
    assert not isinstance(info.value, SceneError)  # the core names its argument (issue 20)
    assert craig_bampton(model, itf, cutoff_hz=0.999 * f10, max_modes=10).n_fixed_modes == 9


def test_fixed_interface_pairs_of_a_tube_are_both_kept_when_few_modes_are_asked():
    """Axisymmetric tube clamped at both ends (rigid end faces): its fixed-interface bending modes
    come in equal pairs, and a short Lanczos run must keep both (the basis would otherwise bend
    one way only)."""
    from crankmodal.fem.materials import material
    from crankmodal.fem.testparts import tube
    from crankmodal.reduction.interfaces import make_interfaces

    part = tube(0.02, 0.04, 0.3, divisions=(2, 16, 12), order=2)
    model = assemble(part, material("steel"))
    itf = make_interfaces(part, [{"region": "end_z0"}, {"region": "end_z1"}])
    ref = craig_bampton(model, itf, n_modes=12).fixed_interface_hz
    assert ref[1] == pytest.approx(ref[0], rel=1e-6) and ref[4] == pytest.approx(ref[3], rel=1e-6)
    for k in (1, 2, 4, 5):
        np.testing.assert_allclose(craig_bampton(model, itf, n_modes=k).fixed_interface_hz,
                                   ref[:k], rtol=1e-8)


def test_fixed_interface_modes_bring_back_the_partner_of_an_exactly_repeated_pair():
    """A constrained solver with the spectrum 1, 1, 2, 3, ... (M = I): a single-vector Lanczos
    run sees one vector of the double eigenspace; the completeness check must add the other."""
    import scipy.sparse as sp

    from crankmodal.reduction.craig_bampton import _fixed_interface_modes

    n = 200  # the rest far above: the run converges before its Krylov space closes and restarts
    d = np.r_[1.0, 1.0, 2.0, 3.0, np.linspace(10.0, 1000.0, n - 4)]

    class Diagonal:
        def solve(self, b):
            return b / d if b.ndim == 1 else b / d[:, None]

    lam, X = _fixed_interface_modes(sp.identity(n, format="csr"), Diagonal(), n, 3)
    np.testing.assert_allclose(np.sort(lam), [1, 1, 2], rtol=1e-10)
    np.testing.assert_allclose(X.T @ X, np.eye(3), atol=1e-10)


def test_craig_bampton_names_its_arguments():
    """Core errors name the argument (issue 20; the [reduction] stage's scene keys:
    test_reduction_stress_io_stage). Before: SceneError 'reduction.n_modes: ...'."""
    part = bar(0.2, 0.02, 0.02, (4, 1, 1), order=1)
    model = assemble(part, STEEL)
    itf = _ends(part, "rigid")
    cases = [((model, []), {"n_modes": 2}, "interfaces: at least one interface is needed"),
             ((model, itf), {"n_modes": 2, "cutoff_hz": 10.0},
              "cutoff_hz: give exactly one of n_modes or cutoff_hz"),
             ((model, itf), {}, "cutoff_hz: give exactly one of n_modes or cutoff_hz"),
             ((model, itf), {"n_modes": 40}, "n_modes: 40 modes need a finer mesh (36 interior DOFs)")]
    for args, kwargs, message in cases:
        with pytest.raises(ParameterError) as info:
            craig_bampton(*args, **kwargs)
        assert not isinstance(info.value, SceneError)
        assert str(info.value) == message and info.value.argument == message.split(":")[0]
