"""The factorisation backend where pypardiso cannot be installed (ARM, Apple silicon).

pypardiso is hidden from the import system (as on a machine without MKL wheels): ``auto`` must
fall back to SuperLU, say so in one warning line with the expected slowdown, record the backend
in the results, and give the same modes — oracle: the Timoshenko frequencies of a free-free bar
and, where PARDISO is installed, PARDISO's own factorisation of the same matrices.
"""

import sys
import warnings

import numpy as np
import pytest
from fem_beam_theory import timoshenko_frequencies
from fem_parts import bar

from crankmodal.errors import ModelWarning
from crankmodal.fem import assembly, modal, solvers
from crankmodal.fem.materials import material

STEEL = material("steel")


@pytest.fixture
def no_pypardiso(monkeypatch):
    """pypardiso absent: ``import pypardiso`` fails and find_spec says None."""
    monkeypatch.setitem(sys.modules, "pypardiso", None)
    solvers._warn_superlu_fallback.cache_clear()
    yield
    solvers._warn_superlu_fallback.cache_clear()


def test_auto_falls_back_to_superlu_with_one_warning_line_naming_the_slowdown(no_pypardiso):
    assert solvers.available_backends() == ["superlu"]
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert solvers.resolve_backend("auto") == "superlu"
        assert solvers.resolve_backend("auto") == "superlu"  # said once per process
    said = [w for w in seen if issubclass(w.category, ModelWarning)]
    assert len(said) == 1
    text = str(said[0].message)
    assert "\n" not in text and "SuperLU" in text and f"{solvers.SUPERLU_SLOWDOWN}x slower" in text
    with pytest.raises(Exception, match="pypardiso"):
        solvers.resolve_backend("pardiso")


def test_superlu_modes_of_a_free_free_bar_match_beam_theory_and_pardiso(no_pypardiso):
    L, b, h = 1.0, 0.05, 0.04
    model = assembly.assemble(bar(L, b, h, (24, 2, 2), order=2), STEEL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        m = modal.solve_modes(model, 4, eigensolver="lanczos")
    assert m.backend == "superlu" and m.to_dict()["backend"] == "superlu"
    # first bending about each axis against Timoshenko (free-free, shear coefficient of a rectangle)
    kappa = 10 * (1 + STEEL.nu) / (12 + 11 * STEEL.nu)
    for width, depth, f in ((b, h, m.frequencies_hz[0]), (h, b, m.frequencies_hz[1])):
        ft = timoshenko_frequencies(1, L, STEEL.E, STEEL.nu, STEEL.rho, width * depth,
                                    width * depth**3 / 12, kappa)[0]
        assert f == pytest.approx(ft, rel=0.01)


def test_superlu_symmetric_mode_solves_a_supported_bar_as_pardiso_does():
    """The symmetric-mode SuperLU (positive definite) against the general ordering and, where
    installed, PARDISO: one static solve of a cantilever, same displacements to 1e-9 (two direct
    factorisations of a matrix with condition ~1e8: agreement to ~1e-16 x 1e8 is expected)."""
    import scipy.sparse as sp

    model = assembly.assemble(bar(0.5, 0.04, 0.04, (12, 2, 2), order=1), STEEL)
    K = sp.csr_matrix(model.K)
    n = K.shape[0]
    fixed = np.zeros(n, bool)
    fixed[:3 * 9] = True  # keep it SPD: drop the first nodes' rows (any set that removes rigid motion)
    free = np.flatnonzero(~fixed)
    A = K[free][:, free] + sp.eye(len(free)) * 1e-6 * K.diagonal().max()
    rhs = np.random.default_rng(3).normal(size=len(free))
    sym = solvers.SuperLUFactor(A, positive_definite=True).solve(rhs)
    gen = solvers.SuperLUFactor(A, positive_definite=False).solve(rhs)
    scale = np.max(np.abs(gen))
    np.testing.assert_allclose(sym, gen, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(A @ sym, rhs, rtol=0, atol=1e-9 * np.max(np.abs(rhs)))
    if "pardiso" in solvers.available_backends():
        par = solvers.factorize(A, "pardiso").solve(rhs)
        np.testing.assert_allclose(par, gen, rtol=0, atol=1e-9 * scale)
