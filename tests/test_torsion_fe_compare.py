"""Picking torsional modes out of FE mode shapes (synthetic fields on a cylinder)."""

import numpy as np
import pytest

from crankmodal.torsion.fe_compare import classify_modes, compare_with_fe, torsional_participation


@pytest.fixture(scope="module")
def cylinder():
    # nodes filling a shaft of radius 0.05 m, length 1 m, along z, axis through (0.1, -0.2, 0)
    rng = np.random.default_rng(3)
    n = 4000
    r = 0.05 * np.sqrt(rng.uniform(0, 1, n))
    t = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(0, 1, n)
    return np.column_stack([0.1 + r * np.cos(t), -0.2 + r * np.sin(t), z])


def _twist(p, phi):
    x, y = p[:, 0] - 0.1, p[:, 1] + 0.2
    return np.column_stack([-y * phi, x * phi, np.zeros(len(p))])


def test_twist_with_a_node_is_torsion(cylinder):
    u = _twist(cylinder, np.cos(np.pi * cylinder[:, 2]))  # first free-free torsion mode of a shaft
    assert torsional_participation(cylinder, u, (0.1, -0.2, 0.0), (0, 0, 1)) > 0.99


def test_bending_and_axial_modes_are_not_torsion(cylinder):
    z = cylinder[:, 2]
    bend = np.column_stack([np.sin(np.pi * z), np.zeros_like(z), np.zeros_like(z)])
    axial = np.column_stack([np.zeros_like(z), np.zeros_like(z), np.cos(np.pi * z)])
    for u in (bend, axial):
        assert torsional_participation(cylinder, u, (0.1, -0.2, 0.0), (0, 0, 1)) < 0.02
    mixed = bend * 0.001 + _twist(cylinder, 1.0)  # small bending on a twist: still torsion
    classes = classify_modes(cylinder, [bend, mixed, axial], (0.1, -0.2, 0.0), (0, 0, 1))
    assert classes == ["other", "torsion", "other"]


def test_compare_with_fe_picks_first_torsional_mode():
    out = compare_with_fe({"exact_hz": [310.0, 900.0], "holzer_hz": [310.0, 900.0], "two_rotor_hz": 300.0},
                          [120.0, 305.0, 620.0], ["other", "torsion", "torsion"])
    assert out["fe_mode"] == 2
    rows = {r["method"]: r for r in out["rows"]}
    assert rows["exact chain"]["difference_of_fe"] == pytest.approx(5 / 305)
    none = compare_with_fe({"exact_hz": [310.0]}, [120.0], ["other"])
    assert none["fe_mode"] is None and "difference_of_fe" not in none["rows"][0]
    with pytest.raises(ValueError, match="fe_mode_classes"):
        compare_with_fe({"exact_hz": [310.0]}, [120.0, 130.0], ["other"])
