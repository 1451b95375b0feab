"""MAC: closed-form chain modes (Euclidean-orthogonal), permutations, scale, cross-mesh pairing."""

import numpy as np
import pytest

from crankmodal.report.mac import load_reference, mac_matrix, pair_modes, sample_at


def chain_modes(n_masses, n_modes):
    """Exact modes of a fixed-fixed chain of equal masses and springs: sin(k π j / (n + 1)).

    With M ∝ I they are orthogonal in the plain dot product, so their MAC is exactly I.
    """
    j = np.arange(1, n_masses + 1)[:, None]
    k = np.arange(1, n_modes + 1)[None, :]
    return np.sin(k * np.pi * j / (n_masses + 1))


def test_mac_of_orthogonal_chain_modes_with_themselves_is_identity_to_1e_12():
    phi = chain_modes(30, 8)
    np.testing.assert_allclose(mac_matrix(phi, phi), np.eye(8), atol=1e-12)


def test_mac_with_a_permuted_rescaled_set_is_the_permutation_matrix():
    phi = chain_modes(30, 6)
    perm = np.array([2, 0, 5, 1, 4, 3])
    psi = phi[:, perm] * np.array([-3.0, 0.5, 2.0, -1.0, 7.0, 1e-3])  # sign and scale are free
    mac = mac_matrix(phi, psi)
    P = np.zeros((6, 6))
    P[perm, np.arange(6)] = 1.0
    np.testing.assert_allclose(mac, P, atol=1e-12)
    assert [(i, j) for i, j, _ in pair_modes(mac)] == [(i, int(np.flatnonzero(perm == i)[0]))
                                                       for i in range(6)]


def test_mac_of_two_unit_vectors_is_cos_squared_of_their_angle():
    a = np.array([[1.0], [0.0]])
    for theta in (0.1, 0.7, 1.3):
        b = np.array([[np.cos(theta)], [np.sin(theta)]])
        assert mac_matrix(a, b)[0, 0] == pytest.approx(np.cos(theta) ** 2, rel=1e-12)


def test_mac_rejects_mismatched_dofs_and_zero_shapes():
    with pytest.raises(ValueError, match="n_dofs"):
        mac_matrix(np.ones((6, 2)), np.ones((9, 2)))
    with pytest.raises(ValueError, match="zero"):
        mac_matrix(np.ones((6, 1)), np.zeros((6, 1)))


def test_sample_at_nearest_node_recovers_interleaved_rows_and_drops_far_points():
    pts = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0]])
    shapes = np.arange(18.0).reshape(9, 2)  # node n, component c -> row 3n + c
    at = np.array([[0.9, 0.05, 0], [0.0, 0.0, 0.01], [5.0, 5.0, 5.0]])
    s, kept = sample_at(pts, shapes, at, max_distance=0.2)
    assert kept.tolist() == [0, 1]
    np.testing.assert_array_equal(s, np.vstack([shapes[3:6], shapes[0:3]]))


def test_p1_and_p2_bar_modes_pair_one_to_one_with_mac_above_0p98(oracle, tmp_path):
    """Two independent discretisations of one bar: the cross-mesh MAC pairs mode k with mode k."""
    from crankmodal.fem import testparts
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material
    from crankmodal.fem.modal import solve_modes
    from crankmodal.fem.vtu import write_modes

    steel = material("steel")
    p2 = testparts.bar(0.3, 0.03, 0.02, divisions=(24, 2, 2), order=2)
    p1 = testparts.bar(0.3, 0.03, 0.02, divisions=(48, 4, 4), order=1)  # P2 nodes are P1 nodes
    m2 = solve_modes(assemble(p2, steel), 4)
    m1 = solve_modes(assemble(p1, steel), 4)
    # the P2 modes go through a modes.vtu file, as a reference from another run would
    write_modes(tmp_path / "modes.vtu", p2.mesh, m2.frequencies_hz, m2.shapes)
    pts, ref, f_ref = load_reference(tmp_path / "modes.vtu")
    np.testing.assert_allclose(f_ref, m2.frequencies_hz, rtol=1e-3)
    ours, kept = sample_at(p1.mesh.points, m1.shapes, pts, max_distance=1e-9)
    refk = ref.reshape(len(pts), 3, -1)[kept].reshape(3 * len(kept), -1)
    mac = mac_matrix(ours, refk)
    pairs = pair_modes(mac)
    assert [(i, j) for i, j, _ in pairs] == [(k, k) for k in range(4)]
    oracle(stage="report", quantity="MAC of P1 against P2 bar modes, smallest diagonal", reference="second discretisation (P1 vs P2)", tolerance="> 0.98", measured=min(v for *_, v in pairs))
    assert min(v for *_, v in pairs) > 0.98


def test_npz_reference_of_measurement_points_loads_with_its_frequencies(tmp_path):
    pts = np.random.default_rng(1).random((5, 3))
    shapes = np.random.default_rng(2).random((5, 3, 2))
    np.savez(tmp_path / "test_modes.npz", points=pts, shapes=shapes,
             frequencies_hz=[1356.0, 1489.0])
    _, s, f = load_reference(tmp_path / "test_modes.npz")
    np.testing.assert_array_equal(s[:, 1], shapes[:, :, 1].ravel())
    assert f.tolist() == [1356.0, 1489.0]
