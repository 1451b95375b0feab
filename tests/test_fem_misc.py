"""Mode names, solver backends, the gmsh P2 path and the convergence helper."""

import numpy as np
import pytest
from fem_beam_theory import timoshenko_frequencies
from fem_parts import bar, gmsh_rod

from crankmodal.fem import assembly, classify, convergence, modal, solvers
from crankmodal.fem.materials import material

STEEL = material("steel")


def test_classifier_names_bending_torsion_and_axial_modes_of_a_bar_at_their_theory_frequencies():
    L, b, h = 1.0, 0.06, 0.04
    model = assembly.assemble(bar(L, b, h, (30, 3, 2)), STEEL)
    m = modal.solve_modes(model, 10)
    names = [c["label"] for c in classify.classify(model.points, m.shapes)]
    f = m.frequencies_hz
    assert names[0] == "bending about y" and names[1] == "bending about z"
    f_axial = np.sqrt(STEEL.E / STEEL.rho) / (2 * L)  # free-free bar, first axial mode
    assert names[int(np.argmin(abs(f - f_axial)))] == "axial along x"
    assert f[names.index("axial along x")] == pytest.approx(f_axial, rel=0.005)
    # Saint-Venant torsion of a 3:2 rectangle: J = β b h³, β(1.5) = 0.196
    J = 0.196 * b * h**3
    f_torsion = np.sqrt(STEEL.shear_modulus * J / (STEEL.rho * b * h * (b * b + h * h) / 12)) / (2 * L)
    assert f[names.index("torsion about x")] == pytest.approx(f_torsion, rel=0.02)


@pytest.mark.skipif("pardiso" not in solvers.available_backends(), reason="pypardiso missing")
def test_pardiso_and_superlu_give_the_same_modes():
    model = assembly.assemble(bar(1.0, 0.05, 0.04, (12, 2, 2)), STEEL)
    # Lanczos, whatever the default (the dense path uses the factor only to refine)
    a = modal.solve_modes(model, 6, backend="pardiso", eigensolver="lanczos")
    b = modal.solve_modes(model, 6, backend="superlu", eigensolver="lanczos")
    np.testing.assert_allclose(a.frequencies_hz, b.frequencies_hz, rtol=1e-9)


def test_gmsh_second_order_rod_reads_through_meshio_and_matches_timoshenko(tmp_path):
    """The tetra10 node order trap: gmsh → .msh → meshio → scikit-fem must give valid P2."""
    Lr, r = 0.6, 0.02
    part = gmsh_rod(Lr, r, 0.012, order=2, tmp_path=tmp_path)
    model = assembly.assemble(part, STEEL)
    m = modal.solve_modes(model, 4)
    kappa = 6 * (1 + STEEL.nu) / (7 + 6 * STEEL.nu)  # Cowper, solid circle
    ft = timoshenko_frequencies(2, Lr, STEEL.E, STEEL.nu, STEEL.rho, np.pi * r * r,
                                np.pi * r**4 / 4, kappa)
    # bending pairs (degenerate by symmetry): the mesh's facetted circle costs ~0.1 %
    np.testing.assert_allclose(m.frequencies_hz[[0, 1, 2, 3]], np.repeat(ft, 2), rtol=5e-3)
    assert m.rigid_body_modes == 6


def test_richardson_recovers_the_limit_of_an_h4_sequence():
    h = np.array([0.04, 0.02, 0.01])
    f = 100.0 + 3e6 * h[:, None] ** 4 * np.array([1.0, -2.0])
    f_inf, q = convergence.richardson(h, f, order=2)
    np.testing.assert_allclose(f_inf, 100.0, rtol=1e-12)
    np.testing.assert_allclose(q, 4.0, rtol=1e-9)


def test_convergence_study_error_estimate_brackets_the_true_p1_error():
    L, b = 1.0, 0.05

    def build(size, order):
        n = max(1, round(b / size))
        return bar(L, b, b, (round(L / size), n, n), order=order)

    table = convergence.study(build, [0.05, 0.025, 0.0125], orders=(1,), material=STEEL,
                              n_modes=2)
    ref = modal.solve_modes(assembly.assemble(build(0.025, 2), STEEL), 2).frequencies_hz
    finest = table.rows[-1]
    true_err = np.abs(np.array(finest["frequencies_hz"]) / ref - 1)
    est = np.array(finest["estimated_error"])
    assert np.all(est > 0.5 * true_err) and np.all(est < 2.0 * true_err), (est, true_err)
    for row in table.rows:
        assert row["n_dofs"] > 0 and row["wall_time_s"] > 0 and row["peak_memory_bytes"] > 0


def test_upper_triangle_equals_scipy_triu_on_a_random_symmetric_matrix():
    import scipy.sparse as sp

    from crankmodal.fem.solvers import upper_triangle

    A = sp.random(300, 300, density=0.05, format="csr", random_state=3)
    A = (A + A.T).tocsr()
    A.data[A.indptr[5]:A.indptr[6]] = 0.0  # a row of explicit zeros
    U = upper_triangle(A)
    assert U.shape == A.shape and (U != sp.triu(A)).nnz == 0
    assert np.all(U.tocoo().col >= U.tocoo().row)


def test_solver_threads_follow_the_environment_and_a_pardiso_solve_is_exact(monkeypatch):
    import scipy.sparse as sp

    from crankmodal.fem import solvers

    monkeypatch.setenv("CRANKMODAL_THREADS", "1")
    assert solvers.solver_threads() == 1
    monkeypatch.delenv("CRANKMODAL_THREADS")
    monkeypatch.setenv("MKL_NUM_THREADS", "3")
    assert solvers.solver_threads() == 3
    monkeypatch.delenv("MKL_NUM_THREADS")
    assert solvers.solver_threads() >= 1
    # a 3-DOF-per-node SPD matrix (the variable-block path) against a dense solve
    n = 3 * 40
    rng = np.random.default_rng(1)
    B = sp.random(n, n, density=0.05, random_state=2)
    A = (B @ B.T + sp.identity(n) * n).tocsr()
    b = rng.standard_normal(n)
    x = solvers.factorize(A, "pardiso").solve(b)
    np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-10, atol=1e-14)


def test_available_memory_follows_the_environment_and_the_system(monkeypatch):
    from crankmodal.errors import SceneError
    from crankmodal.fem.memory import available_bytes

    monkeypatch.delenv("CRANKMODAL_MEMORY_LIMIT", raising=False)
    avail = available_bytes()
    assert avail is None or 0 < avail < 1 << 50
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", "2.5")
    assert available_bytes() == 2_500_000_000
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", "lots")
    with pytest.raises(SceneError, match="CRANKMODAL_MEMORY_LIMIT.*'lots'"):
        available_bytes()


def test_a_factor_larger_than_the_memory_is_refused_before_it_is_allocated(monkeypatch):
    """PARDISO's analysis says what the factor will take; over the limit, a ResourceError with
    advice instead of the kernel killing the run."""
    from crankmodal.errors import ResourceError

    model = assembly.assemble(bar(0.2, 0.02, 0.02, (20, 4, 4), order=2), STEEL)
    fac = solvers.factorize(model.K + model.M, "pardiso")
    needed = fac.memory_needed  # what it took (analysis estimate), bytes
    assert 1e6 < needed < 1e9
    del fac
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", str(0.5 * needed / 1e9))
    with pytest.raises(ResourceError, match=r"needs [\d.e-]+ GB .* available: use a coarser mesh"):
        solvers.factorize(model.K + model.M, "pardiso")
    with pytest.raises(ResourceError, match="^modal: factorising"):
        modal.solve_modes(model, 4)
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", str(2 * needed / 1e9))
    assert solvers.factorize(model.K + model.M, "pardiso").memory_needed == needed



def test_convergence_study_names_a_bad_support_by_argument():
    from crankmodal.errors import ParameterError
    from crankmodal.fem import convergence
    from crankmodal.fem.testparts import bar

    with pytest.raises(ParameterError, match=r"^supports\[0\]\.region: no region 'nope'"):
        convergence.study(lambda h, o: bar(0.2, 0.02, 0.02, (4, 1, 1), order=o), [0.05],
                          orders=(1,), material=STEEL, supports=[{"region": "nope"}])
