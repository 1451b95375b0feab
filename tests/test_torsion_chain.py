"""Lumped torsional chain: closed forms, Holzer against the eigen solution, continuum convergence."""

import numpy as np
import pytest

from crankmodal.errors import ParameterError, SceneError
from crankmodal.torsion import (
    TorsionalChain,
    exact_modes,
    holzer,
    reduce_to_two_rotors,
    two_rotor,
)
from crankmodal.torsion.holzer import holzer_residual


def test_two_rotor_frequency_matches_closed_form_and_both_solvers(oracle):
    # omega^2 = k (I1 + I2) / (I1 I2): the textbook two-rotor result, written out here.
    i1, i2, k = 0.8, 3.1, 2.5e5
    f_closed = np.sqrt(k * (i1 + i2) / (i1 * i2)) / (2 * np.pi)
    chain = TorsionalChain([i1, i2], [k])
    assert two_rotor(i1, i2, k).frequency_hz == pytest.approx(f_closed, rel=1e-14)
    assert exact_modes(chain).frequencies_hz[0] == pytest.approx(f_closed, rel=1e-12)
    oracle(stage="torsion", quantity="two-rotor natural frequency by Holzer, Hz", reference="closed form sqrt(k (I1 + I2) / (I1 I2)) / 2 pi", tolerance="1e-12", measured=holzer(chain).frequencies_hz[0], expected=f_closed)
    assert holzer(chain).frequencies_hz[0] == pytest.approx(f_closed, rel=1e-12)
    assert reduce_to_two_rotors(chain).frequency_hz == pytest.approx(f_closed, rel=1e-14)


def test_two_rotor_node_divides_shaft_in_inverse_ratio_of_inertias():
    # Zero net angular momentum: I1 theta1 + I2 theta2 = 0 and a linear twist along the shaft put
    # the node at L I2 / (I1 + I2) from rotor 1 (the heavier rotor sits nearer the node).
    i1, i2, k, L = 0.36, 2.05, 1.1e6, 0.86
    chain = TorsionalChain([i1, i2], [k], lengths=[L])
    node_exact = exact_modes(chain).nodes[0]
    node_holzer = holzer(chain).nodes[0]
    assert len(node_exact) == 1 and len(node_holzer) == 1
    assert node_exact[0]["position_m"] == pytest.approx(L * i2 / (i1 + i2), rel=1e-12)
    assert node_holzer[0]["position_m"] == pytest.approx(L * i2 / (i1 + i2), rel=1e-10)
    red = reduce_to_two_rotors(chain)
    assert red.flywheel_index == 1
    assert red.node_from_flywheel_m == pytest.approx(L * i1 / (i1 + i2), rel=1e-14)


def _random_chain(rng, n, fixed):
    inertias = 10 ** rng.uniform(-2, 1, n)
    stiff = 10 ** rng.uniform(4, 7, n if fixed else n - 1)
    return TorsionalChain(inertias, stiff, fixed_end=fixed)


@pytest.mark.parametrize("fixed", [False, True])
@pytest.mark.parametrize("n", [2, 3, 5, 8, 13])
def test_holzer_roots_equal_eigenvalues_to_1e8(n, fixed):
    # Independent oracle: scipy.linalg.eigh of K theta = omega^2 M theta. Tolerance 1e-8 relative.
    rng = np.random.default_rng(1000 * n + fixed)
    for _ in range(4):
        chain = _random_chain(rng, n, fixed)
        ex = exact_modes(chain).frequencies_hz
        hz = holzer(chain).frequencies_hz
        assert len(ex) == n - (0 if fixed else 1)
        np.testing.assert_allclose(hz, ex, rtol=1e-8)


def test_holzer_mode_shapes_and_nodes_equal_eigenvectors():
    chain = TorsionalChain([0.3, 0.6, 0.18, 1.2], [1.32e5, 1.98e5, 0.7e5])
    ex, hz = exact_modes(chain), holzer(chain)
    np.testing.assert_allclose(hz.shapes, ex.shapes, atol=1e-9)
    # mode m of an unbranched free-free chain has m nodes (Sturm sequence property)
    assert [len(n) for n in ex.nodes] == [1, 2, 3]
    for ne, nh in zip(ex.nodes, hz.nodes):
        for a, b in zip(ne, nh):
            assert a["between"] == b["between"]
            assert a["fraction"] == pytest.approx(b["fraction"], abs=1e-9)


def test_holzer_residual_vanishes_at_roots_and_carries_rigid_mode_at_zero():
    chain = TorsionalChain([0.3, 0.6, 0.18], [1.32e5, 1.98e5])
    w = 2 * np.pi * exact_modes(chain).frequencies_hz
    scale = chain.inertias.sum() * w**2  # torque of the rotors' inertia at unit twist
    assert np.all(np.abs(holzer_residual(chain, w)) < 1e-9 * scale)
    assert abs(holzer_residual(chain, [1e-6])[0]) < 1e-9


def _uniform_shaft(n_elem, L, d, G, rho, fixed):
    J = np.pi / 32 * d**4
    h = L / n_elem
    if fixed:  # wall at x = 0, rotors at x = h .. L, the free end carries half an element
        inertias = np.full(n_elem, rho * J * h)
        inertias[-1] /= 2
        stiff = np.full(n_elem, G * J / h)
    else:
        inertias = np.full(n_elem + 1, rho * J * h)
        inertias[[0, -1]] /= 2
        stiff = np.full(n_elem, G * J / h)
    return TorsionalChain(inertias, stiff, fixed_end=fixed)


@pytest.mark.parametrize("fixed", [False, True])
def test_discretised_uniform_shaft_converges_to_continuum_at_second_order(oracle, fixed):
    # Continuous shaft: free-free f_n = n c / (2 L), fixed-free f_n = (2n - 1) c / (4 L), c = sqrt(G/rho).
    # Lumped inertias converge from below with error ~ (n pi h / 2L)^2 / 6: observed order 2.
    L, d, G, rho = 1.2, 0.05, 8.0e10, 7850.0
    c = np.sqrt(G / rho)
    modes = np.arange(1, 4)
    f_true = (modes * c / (2 * L)) if not fixed else ((2 * modes - 1) * c / (4 * L))
    errs = []
    for n_elem in (20, 40, 80, 160):
        f = exact_modes(_uniform_shaft(n_elem, L, d, G, rho, fixed)).frequencies_hz[:3]
        errs.append((f - f_true) / f_true)
    errs = np.array(errs)
    assert np.all(errs < 0)  # lumped mass: frequencies from below
    order = np.log2(errs[-2] / errs[-1])
    oracle(stage="torsion", quantity=f"lumped uniform shaft ({'fixed-free' if fixed else 'free-free'}), observed order of convergence, mode 1", reference="continuum shaft n c / 2L: second order", tolerance="0.02", measured=order[0], expected=2.0)
    np.testing.assert_allclose(order, 2.0, atol=0.02)
    assert np.all(np.abs(errs[-1]) < 2.5e-4)  # mode 3, 160 elements: (3 pi / 320)^2 / 6 = 1.4e-4
    # Holzer on the same 40-element chain finds the same lowest frequencies
    ch = _uniform_shaft(40, L, d, G, rho, fixed)
    np.testing.assert_allclose(holzer(ch).frequencies_hz[:5], exact_modes(ch).frequencies_hz[:5], rtol=1e-8)


def test_two_rotor_reduction_lumps_rest_at_its_inertia_weighted_position():
    # Seed 004's reduction: flywheel (heavier end) against the other rotors lumped at their
    # inertia-weighted position. Oracle: the closed form with that lumped rotor, computed by hand.
    chain = TorsionalChain([0.2, 0.2, 0.2, 2.0], [1e6, 1e6, 1e6], lengths=[0.1, 0.1, 0.1])
    red = reduce_to_two_rotors(chain)
    assert red.flywheel_index == 3
    # rest at x = 0, 0.1, 0.2 (mean 0.1); flywheel at 0.3: shaft 0.2 m, two springs of 0.1 m in series
    assert red.length == pytest.approx(0.2)
    assert red.stiffness == pytest.approx(0.5e6)
    f = np.sqrt(0.5e6 * (2.0 + 0.6) / (2.0 * 0.6)) / (2 * np.pi)
    assert red.frequency_hz == pytest.approx(f, rel=1e-12)
    # the estimate is an approximation of the first exact mode, within 10 % here
    assert red.frequency_hz == pytest.approx(exact_modes(chain).frequencies_hz[0], rel=0.10)
    assert reduce_to_two_rotors(TorsionalChain([1.0, 2.0], [1e5, 1e5], fixed_end=True)) is None


@pytest.mark.parametrize(
    "inertias, stiffnesses, fixed, message",
    [
        ([0.3, -0.6, 0.18], [1e5, 1e5], False, "inertias[1]: must be > 0 and finite, got -0.6"),
        ([0.3, 0.6, 0.18], [1e5, 0.0], False, "stiffnesses[1]: must be > 0 and finite, got 0.0"),
        ([0.3, 0.6, 0.18], [1e5], False,
         "stiffnesses: needs 2 entries for 3 inertias (free at both ends), got 1"),
        ([0.3, 0.6], [1e5], True,
         "stiffnesses: needs 2 entries for 2 inertias (fixed end: wall spring first), got 1"),
        ([0.3], [], False, "inertias: a free-free chain needs at least 2 rotors, got 1"),
    ],
)
def test_bad_chain_raises_parameter_error_naming_the_argument(inertias, stiffnesses, fixed,
                                                              message):
    """The core names its argument (issue 20); the [torsion] stage adds the scene key
    (test_torsion_scene). Before: SceneError 'torsion.inertias[1]: ...' from the core."""
    with pytest.raises(ParameterError) as info:
        TorsionalChain(inertias, stiffnesses, fixed_end=fixed)
    assert not isinstance(info.value, SceneError)
    assert str(info.value) == message
    assert info.value.argument == message.split(":")[0]


def test_bad_lengths_and_two_rotor_flywheel_name_their_arguments():
    with pytest.raises(ParameterError, match=r"^lengths: need 1 positive lengths$"):
        TorsionalChain([0.3, 0.6], [1e5], lengths=[-0.1])
    chain = TorsionalChain([0.3, 0.6], [1e5])
    assert not hasattr(chain, "key")  # the core knows no scene key
    with pytest.raises(ParameterError) as info:
        reduce_to_two_rotors(chain, "middle")
    assert not isinstance(info.value, SceneError) and info.value.argument == "flywheel"
    assert str(info.value) == "flywheel: must be auto, first or last; got 'middle'"
