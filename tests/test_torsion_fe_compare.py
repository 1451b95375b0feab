"""The first FE torsional mode beside the lumped-chain frequencies.

Which FE modes are torsion is decided by the FE stage's classifier (``crankmodal.fem.classify``,
tested against bar theory in ``tests/test_fem_misc.py``); here only the side-by-side table.
"""

import pytest

from crankmodal.torsion.fe_compare import compare_with_fe


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
