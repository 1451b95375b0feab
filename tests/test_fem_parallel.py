"""Row-block sparse products on threads: the same numbers as scipy's, no copy of the matrix."""

import numpy as np
import pytest
import scipy.sparse as sp

from crankmodal.fem import parallel


@pytest.fixture
def matrix():
    rng = np.random.default_rng(5)
    return sp.random(900, 700, density=0.05, random_state=rng, format="csr")  # uneven rows


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_row_blocks_multiply_like_scipy_without_copying(matrix, threads, monkeypatch):
    monkeypatch.setattr(parallel, "MIN_NNZ", 0)
    rb = parallel.RowBlocks(matrix, threads=threads)
    assert len(rb.blocks) == threads
    assert sum(b.shape[0] for _, b in rb.blocks) == matrix.shape[0]
    for _, b in rb.blocks:  # views of the matrix's own arrays
        assert np.shares_memory(b.data, matrix.data)
        assert np.shares_memory(b.indices, matrix.indices)
    rng = np.random.default_rng(0)
    x, X = rng.standard_normal(700), rng.standard_normal((700, 5))
    np.testing.assert_array_equal(rb @ x, matrix @ x)
    np.testing.assert_array_equal(rb @ X, matrix @ X)
    # the entries, not the rows, are split evenly
    nnz = [b.nnz for _, b in rb.blocks]
    assert max(nnz) - min(nnz) <= matrix.getnnz(axis=1).max()


def test_small_matrices_stay_on_the_calling_thread(matrix):
    assert len(parallel.RowBlocks(matrix, threads=2).blocks) == 1  # nnz < MIN_NNZ
