"""Modal analysis against beam theory, rigid-body physics and its own numerical checks."""

import numpy as np
import pytest
from fem_beam_theory import rectangle_shear_coefficient, timoshenko_frequencies
from fem_parts import bar, tube

from crankmodal.errors import ModelWarning, NumericalError
from crankmodal.fem import assembly, modal, supports
from crankmodal.fem.materials import material

STEEL = material("steel")
L, B, H = 1.0, 0.05, 0.04  # bending about y (z-motion, I = B H^3/12) is the lowest


@pytest.fixture(scope="module")
def bar_model():
    part = bar(L, B, H, (40, 3, 3), order=2)  # moderate mesh: 12 k DOF
    return part, assembly.assemble(part, STEEL)


@pytest.fixture(scope="module")
def free_modes(bar_model):
    return modal.solve_modes(bar_model[1], 8)


def _theory(ends, n, inertia):
    return timoshenko_frequencies(n, L, STEEL.E, STEEL.nu, STEEL.rho, B * H, inertia,
                                  rectangle_shear_coefficient(STEEL.nu), ends=ends)


def test_free_free_bar_first_bending_modes_within_0p5_percent_of_timoshenko(oracle, free_modes):
    f = free_modes.frequencies_hz
    # the eight lowest: bending about y (3), about z (3), interleaved; pick by theory
    fy = _theory("free-free", 3, B * H**3 / 12)
    fz = _theory("free-free", 2, H * B**3 / 12)
    for ft in np.concatenate([fy, fz]):
        err = np.min(np.abs(f / ft - 1))
        oracle(stage="fem", quantity=f"free-free steel bar, bending mode near {ft:.0f} Hz (P2 tetrahedra)", reference="Timoshenko beam, closed form", tolerance="0.5 %", measured=f[np.argmin(np.abs(f / ft - 1))], expected=ft)
        assert err < 0.005, (ft, f)


def test_free_part_has_six_rigid_body_modes(free_modes):
    assert free_modes.rigid_body_modes == 6
    assert np.all(free_modes.rigid_frequencies_hz < 1e-3 * free_modes.frequencies_hz[0])


def test_clamped_cantilever_first_bending_within_0p5_percent_of_timoshenko(oracle, bar_model):
    part, model = bar_model
    sup = supports.select(part, [{"region": "end_x0", "fix": "xyz"}])
    m = modal.solve_modes(model, 4, sup)
    assert m.rigid_body_modes == 0
    fy = _theory("clamped-free", 2, B * H**3 / 12)
    fz = _theory("clamped-free", 1, H * B**3 / 12)
    for ft in np.concatenate([fy, fz]):
        # the fully clamped 3-D root is slightly stiffer than a Timoshenko clamp
        oracle(stage="fem", quantity=f"clamped cantilever bar, bending mode near {ft:.0f} Hz", reference="Timoshenko beam, closed form", tolerance="0.5 %", measured=m.frequencies_hz[np.argmin(np.abs(m.frequencies_hz / ft - 1))], expected=ft)
        assert np.min(np.abs(m.frequencies_hz / ft - 1)) < 0.005, (ft, m.frequencies_hz)
    # first cantilever mode carries 61.3 % of the mass in its direction (Euler-Bernoulli
    # 0.6131; shear and 3-D effects are < 1 % at L/h = 25)
    oracle(stage="fem", quantity="cantilever first mode, effective mass fraction", reference="Euler-Bernoulli cantilever, 0.6131", tolerance="1 %", measured=m.effective_mass[0, 2] / m.total_mass, expected=0.6131)
    assert m.effective_mass[0, 2] / m.total_mass == pytest.approx(0.6131, rel=0.01)
    # the first two z-bending modes together: 0.6131 + 0.1883 (Euler-Bernoulli)
    cum = m.to_dict()["effective_mass_cumulative_fraction"]
    assert cum["z"][-1] == pytest.approx(0.8014, rel=0.015)
    assert np.all(np.diff(cum["z"]) >= 0) and cum["z"][-1] < 1
    assert m.rigid_mass[:3] == pytest.approx([m.total_mass] * 3, rel=1e-12)


def test_mass_matrix_integrates_to_exact_mass_and_inertia_of_a_bar(oracle, bar_model):
    part, model = bar_model
    mp = assembly.mass_properties(model)
    oracle(stage="fem", quantity="bar mass from the FE mass matrix, kg", reference="OpenCASCADE volume x density (second formulation)", tolerance="1e-12", measured=mp["mass"], expected=part.cad_mass.mass(STEEL.rho))
    assert mp["mass"] == pytest.approx(part.cad_mass.mass(STEEL.rho), rel=1e-12)
    np.testing.assert_allclose(mp["centre"], part.cad_mass.centroid, atol=1e-12)
    np.testing.assert_allclose(mp["inertia"], part.cad_mass.inertia(STEEL.rho),
                               rtol=1e-10, atol=1e-12)


def test_curved_p2_tube_mass_and_inertia_match_the_exact_annulus_to_1e_4():
    part = tube(0.05, 0.1, 0.1, (3, 16, 2), order=2)
    mp = assembly.mass_properties(assembly.assemble(part, STEEL))
    assert mp["mass"] == pytest.approx(part.cad_mass.mass(STEEL.rho), rel=1e-4)
    np.testing.assert_allclose(np.diag(mp["inertia"]), np.diag(part.cad_mass.inertia(STEEL.rho)),
                               rtol=2e-4)


def test_elastic_modes_are_mass_normalised_and_orthogonal_to_rigid_motion(bar_model, free_modes):
    model = bar_model[1]
    X = free_modes.shapes
    np.testing.assert_allclose(X.T @ (model.M @ X), np.eye(X.shape[1]), atol=1e-8)
    assert free_modes.residuals.max() < 1e-6
    # free-free elastic modes have no effective mass (momentum is conserved)
    assert free_modes.effective_mass.max() < 1e-8 * free_modes.total_mass


def test_same_input_gives_identical_modes(bar_model, free_modes):
    again = modal.solve_modes(bar_model[1], 8)
    np.testing.assert_array_equal(again.frequencies_hz, free_modes.frequencies_hz)
    np.testing.assert_array_equal(again.shapes, free_modes.shapes)


def test_sub_millimetre_part_scales_frequencies_inversely_with_size():
    """A 0.5 mm bar has exactly 2000× the frequencies of a 1 m bar: the solver is scale-free."""
    big = modal.solve_modes(assembly.assemble(bar(1.0, 0.05, 0.04, (16, 2, 2)), STEEL), 4)
    with pytest.warns(ModelWarning, match="metres"):
        small_model = assembly.assemble(bar(5e-4, 2.5e-5, 2e-5, (16, 2, 2)), STEEL)
    small = modal.solve_modes(small_model, 4)
    np.testing.assert_allclose(small.frequencies_hz, 2e3 * big.frequencies_hz, rtol=1e-7)
    assert small.rigid_body_modes == 6


def test_part_given_in_millimetres_warns_about_units():
    with pytest.warns(ModelWarning, match="mm input"):
        assembly.assemble(bar(1000.0, 50.0, 40.0, (8, 1, 1), order=1), STEEL)


def test_p1_with_nearly_incompressible_material_warns_about_locking():
    rubberish = material("steel").__class__(name="x", E=1e7, nu=0.49, rho=1000.0)
    with pytest.warns(ModelWarning, match="locking"):
        assembly.assemble(bar(1.0, 0.1, 0.1, (4, 1, 1), order=1), rubberish)


def test_p2_near_incompressible_material_warns_and_fails_loudly_with_advice():
    """P2 does not lock, but K/G = 2(1+ν)/(3(1−2ν)) ruins K's conditioning as ν → 0.5: the bar
    converges with a warning at ν = 0.49999 (its bending pair within 0.1 % of ν = 0.4999's) and
    stops with the cause named at ν = 0.4999999 instead of returning poor modes."""
    def model(nu):
        mat = material("steel").__class__(name="x", E=1e7, nu=nu, rho=1000.0)
        return assembly.assemble(bar(1.0, 0.1, 0.1, (10, 2, 2), order=2), mat)

    f_ref = modal.solve_modes(model(0.4999), 2).frequencies_hz
    with pytest.warns(ModelWarning, match=r"nu = 0.49999: the bulk modulus is 5.0e\+04"):
        near = model(0.49999)
    np.testing.assert_allclose(modal.solve_modes(near, 2).frequencies_hz, f_ref, rtol=1e-3)
    with pytest.warns(ModelWarning):
        bad = model(0.4999999)
    with pytest.raises(NumericalError, match=r"ill-conditioned .* nu = 0.4999999 makes the bulk "
                                             r"modulus 5.0e\+06 .* use nu <= 0.4999"):
        modal.solve_modes(bad, 4)


def test_residual_check_fires_on_a_wrong_eigenvalue(bar_model, free_modes):
    model = bar_model[1]
    lam = (2 * np.pi * free_modes.frequencies_hz) ** 2
    with pytest.raises(NumericalError, match="residual"):
        modal.check_pairs(model.K, model.M, lam * 1.001, free_modes.shapes)


def test_orthogonality_check_fires_on_nearly_parallel_modes(bar_model, free_modes):
    model = bar_model[1]
    X = free_modes.shapes[:, :2].copy()
    X[:, 1] = X[:, 0] + 1e-3 * X[:, 1]
    X /= np.sqrt(np.einsum("ij,ij->j", X, model.M @ X))
    lam = np.full(2, (2 * np.pi * free_modes.frequencies_hz[0]) ** 2)
    with pytest.raises(NumericalError, match="M-orthogonal"):
        modal.check_pairs(model.K, model.M, lam, X, tol=1e-2)


def test_radial_bearing_leaves_axial_sliding_and_spin_then_an_axial_stop_leaves_spin():
    part = tube(0.02, 0.05, 0.2, (2, 12, 6), order=2)
    model = assembly.assemble(part, STEEL)
    radial = supports.select(part, [{"region": "bore", "fix": "radial"}])
    assert modal.solve_modes(model, 3, radial).rigid_body_modes == 2
    stop = supports.select(part, [{"region": "bore", "fix": "radial"},
                                  {"region": "end_z0", "fix": "z"}])
    m = modal.solve_modes(model, 3, stop)
    assert m.rigid_body_modes == 1  # seed 004's "rotation about the crankshaft axis kept free"


def test_radial_support_fits_the_cylinder_when_the_region_has_none():
    part = tube(0.02, 0.05, 0.2, (2, 12, 6), order=2)
    bore = part.regions["bore"]
    part.regions["bore"] = type(bore)(bore.name, bore.facets, bore.nodes, None)
    sup = supports.select(part, [{"region": "bore", "fix": "radial"}])
    np.testing.assert_allclose(abs(sup[0].cylinder.axis[2]), 1.0, atol=1e-9)
    assert sup[0].cylinder.radius == pytest.approx(0.02, rel=1e-3)


def _merged(parts_points_cells):
    """One Part from several (points, cells) P2 meshes; coincident points are merged."""
    import meshio

    from crankmodal.part import Part

    pts = np.vstack([p for p, _ in parts_points_cells])
    offs = np.cumsum([0] + [len(p) for p, _ in parts_points_cells[:-1]])
    cells = np.vstack([c + o for (_, c), o in zip(parts_points_cells, offs)])
    key = np.round(pts / 1e-9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.sort(first)  # keep the points in their first-seen order
    remap = np.searchsorted(order, first)[inv.ravel()]
    return Part(name="merged", mesh=meshio.Mesh(pts[order], [("tetra10", remap[cells])]))


def test_two_separate_bars_have_twelve_rigid_modes_and_each_elastic_mode_twice(free_modes):
    part = bar(L, B, H, (40, 3, 3), order=2)
    p, c = part.mesh.points, part.mesh.cells[0].data
    two = _merged([(p, c), (p + [0.0, 0.3, 0.0], c)])
    m = modal.solve_modes(assembly.assemble(two, STEEL), 8)
    assert m.rigid_body_modes == 12
    np.testing.assert_allclose(m.frequencies_hz[::2], free_modes.frequencies_hz[:4], rtol=1e-8)
    np.testing.assert_allclose(m.frequencies_hz[1::2], free_modes.frequencies_hz[:4], rtol=1e-8)


def test_bars_joined_at_one_corner_point_reveal_the_hinge_the_connectivity_hides():
    """One shared node: the connectivity says one piece (6 rigid modes), the stiffness has 9."""
    part = bar(0.3, B, H, (12, 2, 2), order=2)
    p, c = part.mesh.points, part.mesh.cells[0].data
    hinged = _merged([(p, c), (p + [0.3, B, H], c)])
    with pytest.raises(NumericalError, match="found 9 zero-frequency modes"):
        modal.solve_modes(assembly.assemble(hinged, STEEL), 4)


def test_deflating_the_known_rigid_modes_changes_nothing_but_the_work(bar_model, free_modes):
    plain = modal.solve_modes(bar_model[1], 8, expected_rigid=6)  # rigid modes found by Lanczos
    np.testing.assert_allclose(free_modes.frequencies_hz, plain.frequencies_hz, rtol=1e-9)
    assert free_modes.n_solves < plain.n_solves
    mac = np.abs(np.sum(free_modes.shapes * (bar_model[1].M @ plain.shapes), axis=0))
    assert np.all(mac > 1 - 1e-6)


def test_repeated_pairs_of_a_tube_are_both_found_when_few_modes_are_asked():
    """Axisymmetric: bending modes come in equal pairs; a short Lanczos run must not drop one."""
    model = assembly.assemble(tube(0.02, 0.04, 0.12, divisions=(2, 16, 6), order=2), STEEL)
    many = modal.solve_modes(model, 12).frequencies_hz
    assert np.isclose(many[0], many[1], rtol=1e-6)  # a pair, as theory says
    for n in (1, 2, 3, 4):
        np.testing.assert_allclose(modal.solve_modes(model, n).frequencies_hz, many[:n],
                                   rtol=1e-8)


def test_a_thin_strip_with_one_element_through_its_thickness_bends_as_beam_theory_says():
    """A 200 × 5 × 1 mm strip (L/h = 200), one P2 element through the 1 mm: the first three
    bending modes about the weak axis within 0.5 % of Timoshenko (measured +0.06 / +0.23 /
    +0.48 %), and every pair passes the residual checks."""
    Ls, Bs, Hs = 0.2, 0.005, 0.001
    m = modal.solve_modes(assembly.assemble(bar(Ls, Bs, Hs, (40, 1, 1), order=2), STEEL), 4)
    ft = timoshenko_frequencies(3, Ls, STEEL.E, STEEL.nu, STEEL.rho, Bs * Hs, Bs * Hs**3 / 12,
                                rectangle_shear_coefficient(STEEL.nu), ends="free-free")
    for f in ft:
        assert np.min(np.abs(m.frequencies_hz / f - 1)) < 0.005, (f, m.frequencies_hz)
    assert m.residuals.max() < 1e-6


@pytest.mark.parametrize("eigensolver", ["lanczos", "dense"])
def test_needle_elements_stop_the_run_with_advice_instead_of_returning_poor_pairs(eigensolver):
    """A 0.1 mm strip in 20 mm long elements (200:1): K's condition number puts the residual
    floor far above tol; the run must say so and name the likely cause, whichever eigensolver
    ran (its 567 DOF go dense by default)."""
    model = assembly.assemble(bar(0.2, 0.005, 0.0001, (10, 1, 1), order=2), STEEL)
    with pytest.raises(NumericalError, match="ill-conditioned .*needle elements"):
        modal.solve_modes(model, 4, eigensolver=eigensolver)


def test_nearly_repeated_bending_pairs_of_a_square_bar_are_both_found_and_perpendicular():
    """Square section: each bending frequency is a pair, split only by the tetrahedral mesh
    (3e-5 here). Both members must come back, each on Timoshenko's value, bending in
    perpendicular planes."""
    a = 0.04
    m = modal.solve_modes(assembly.assemble(bar(L, a, a, (40, 3, 3), order=2), STEEL), 4)
    f = m.frequencies_hz
    ft = timoshenko_frequencies(2, L, STEEL.E, STEEL.nu, STEEL.rho, a * a, a**4 / 12,
                                rectangle_shear_coefficient(STEEL.nu), ends="free-free")
    np.testing.assert_allclose(f, np.repeat(ft, 2), rtol=0.005)
    assert abs(f[1] / f[0] - 1) < 1e-3 and abs(f[3] / f[2] - 1) < 1e-3
    for i in (0, 2):
        dirs = []
        for j in (i, i + 1):
            u = m.shapes[:, j].reshape(-1, 3)[:, 1:]  # transverse (y, z) motion of every node
            dirs.append(np.linalg.eigh(u.T @ u)[1][:, -1])  # the direction it bends in
        assert abs(dirs[0] @ dirs[1]) < 1e-2


def test_completeness_check_finds_the_partner_a_single_vector_lanczos_cannot_see():
    """K = diag(1, 1, 2, 3, ...): from any start vector the Krylov space holds one vector of the
    double eigenspace, so Lanczos alone returns 1, 2, 3; the check must bring back 1, 1, 2."""
    import scipy.sparse as sp

    n = 40
    d = np.r_[1.0, 1.0, np.arange(2.0, n)]
    M = sp.identity(n, format="csr")
    sigma = -0.5

    def apply(b):
        return b / (d - sigma)

    main = modal.lanczos(apply, M, np.ones(n), 3, 1e-12, n - 1)
    np.testing.assert_allclose(np.sort(sigma + 1 / main.theta), [1, 2, 3], rtol=1e-12)
    rng = np.random.default_rng(0)

    def run(op, k, start, room):
        return modal.lanczos(op, M, start(), k, 1e-12, min(room, n - 1), fresh=start)

    lam, X, MX = modal.complete_modes(apply, lambda: rng.standard_normal(n), M, run,
                                      sigma + 1 / main.theta, main.vectors, main.m_vectors,
                                      sigma, 3)
    np.testing.assert_allclose(lam, [1, 1, 2], rtol=1e-12)
    np.testing.assert_allclose(X.T @ X, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(MX, M @ X, atol=1e-14)
    # the first two span the double eigenspace (DOFs 0, 1), the third is DOF 2 alone
    assert np.abs(X[2:, :2]).max() < 1e-10
    assert np.abs(np.delete(X[:, 2], 2)).max() < 1e-10


def _pencil(n=60, seed=3):
    """A small SPD pencil (K, M) with distinct eigenvalues, and its dense solution."""
    import scipy.linalg as sla
    import scipy.sparse as sp

    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    K = A @ A.T + n * np.eye(n)
    B = rng.standard_normal((n, n))
    M = B @ B.T / n + np.eye(n)
    return sp.csr_matrix(K), sp.csr_matrix(M), sla.eigh(K, M)


def test_lanczos_matches_a_dense_generalised_eigensolver():
    K, M, (lam_ref, _) = _pencil()
    sigma = -1.0
    S = np.linalg.inv((K - sigma * M).toarray())
    out = modal.lanczos(lambda b: S @ b, M, np.ones(K.shape[0]), 5, 1e-12, 59)
    assert out.converged
    lam = np.sort(sigma + 1.0 / out.theta)
    np.testing.assert_allclose(lam, lam_ref[:5], rtol=1e-10)
    X = out.vectors
    np.testing.assert_allclose(X.T @ (M @ X), np.eye(5), atol=1e-10)  # M-orthonormal
    np.testing.assert_allclose(out.m_vectors, M @ X, atol=1e-10)
    r = K @ X - (M @ X) * (sigma + 1.0 / out.theta)
    assert np.linalg.norm(r, axis=0).max() < 1e-8 * np.abs(K).max()


def test_lanczos_without_the_m_basis_gives_the_same_pairs():
    """keep_mq=False keeps two columns of M Q and forms M w again after reorthogonalising."""
    K, M, (lam_ref, _) = _pencil()
    sigma = -1.0
    S = np.linalg.inv((K - sigma * M).toarray())
    np.testing.assert_allclose(np.sort(sigma + 1 / modal.lanczos(
        lambda b: S @ b, M, np.ones(K.shape[0]), 5, 1e-12, 59, keep_mq=False).theta),
        lam_ref[:5], rtol=1e-10)
    full = modal.lanczos(lambda b: S @ b, M, np.ones(K.shape[0]), 5, 1e-12, 59)
    lean = modal.lanczos(lambda b: S @ b, M, np.ones(K.shape[0]), 5, 1e-12, 59, keep_mq=False)
    assert lean.converged and lean.steps == full.steps
    np.testing.assert_allclose(lean.theta, full.theta, rtol=1e-12)
    np.testing.assert_allclose(np.abs(lean.vectors), np.abs(full.vectors), atol=1e-9)
    np.testing.assert_allclose(lean.m_vectors, M @ lean.vectors, atol=1e-12)


def test_lanczos_restarts_when_the_krylov_space_closes_and_accept_can_ask_for_more():
    import scipy.sparse as sp

    n = 40
    d = np.arange(1.0, n + 1.0)
    M = sp.identity(n, format="csr")
    v0 = np.zeros(n)
    v0[[0, 5, 9]] = 1.0  # the Krylov space of v0 is 3-dimensional
    apply = lambda b: b / d  # (K - 0 M)^-1 for K = diag(d)
    closed = modal.lanczos(apply, M, v0, 4, 1e-12, 20)
    assert not closed.converged and closed.steps == 3  # nothing left to explore
    rng = np.random.default_rng(0)
    fresh = modal.lanczos(apply, M, v0, 4, 1e-12, 39, fresh=lambda: rng.standard_normal(n))
    assert fresh.converged
    np.testing.assert_allclose(np.sort(1.0 / fresh.theta), [1.0, 2.0, 3.0, 4.0], rtol=1e-10)
    calls = []
    picky = modal.lanczos(apply, M, rng.standard_normal(n), 2, 1e-6, 39,
                          accept=lambda th, X, MX: calls.append(len(calls)) or len(calls) > 2)
    assert picky.converged and len(calls) == 3  # asked three times, went on twice


def test_lanczos_needs_no_more_solves_than_arpack_for_the_same_modes(bar_model):
    """The per-step convergence check: never more operator applications than ARPACK's restarts."""
    from scipy.sparse.linalg import LinearOperator, eigsh

    from crankmodal.fem.solvers import factorize_shifted

    model = bar_model[1]
    K, M = model.K, model.M
    sigma = modal.default_shift(K, M)
    fac = factorize_shifted(K, M, sigma)
    count = [0]

    def solve(b):
        count[0] += 1
        return fac.solve(b)

    n, k = K.shape[0], 14  # 6 rigid + 8 elastic
    v0 = np.random.default_rng(1).standard_normal(n)
    lam_a, _ = eigsh(K, k=k, M=M, sigma=sigma, OPinv=LinearOperator((n, n), solve), v0=v0,
                     tol=1e-10, ncv=2 * k + 1)
    arpack = count[0]
    count[0] = 0
    out = modal.lanczos(solve, M, v0, k, 1e-10, 200)
    assert out.converged and count[0] <= arpack
    np.testing.assert_allclose(np.sort(sigma + 1.0 / out.theta)[6:], np.sort(lam_a)[6:],
                               rtol=1e-8)
