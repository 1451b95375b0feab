"""Critical speeds: orders x speed against natural frequencies."""

import numpy as np
import pytest

from crankmodal.errors import ParameterError, SceneError
from crankmodal.torsion.critical_speeds import critical_speeds, excitation_orders


def test_four_stroke_orders_are_half_steps_and_compressor_orders_integers():
    np.testing.assert_array_equal(excitation_orders("four_stroke", 3), [0.5, 1, 1.5, 2, 2.5, 3])
    np.testing.assert_array_equal(excitation_orders("compressor", 4.7), [1, 2, 3, 4])


def test_critical_speed_is_where_order_line_meets_natural_frequency():
    # 100 Hz excited by order 2 at 3000 rpm, by order 4 at 1500 rpm, by order 1 at 6000 rpm
    cs = critical_speeds([100.0], "compressor", 4, (1000.0, 4000.0), operating_rpm=1400.0)
    speeds = [r["speed_rpm"] for r in cs.in_range()]
    np.testing.assert_allclose(speeds, [1500.0, 2000.0, 3000.0])
    for r in cs.in_range():
        assert r["order"] * r["speed_rpm"] / 60 == pytest.approx(r["natural_hz"])
    near = cs.nearest()
    assert near["order"] == 4 and near["margin"] == pytest.approx(100 / 1400)
    assert [r["order"] for r in cs.too_close()] == [4.0]
    assert cs.first_order_check()["forcing_hz"] == pytest.approx(1400 / 60)


def test_bounds_of_speed_range_are_inclusive():
    cs = critical_speeds([50.0], "compressor", 2, (1500.0, 3000.0))
    assert [r["speed_rpm"] for r in cs.in_range()] == [1500.0, 3000.0]


@pytest.mark.parametrize("rng", [(1000.0, 1000.0), (2000.0, 1000.0), (-5.0, 100.0)])
def test_empty_speed_range_is_refused(rng):
    with pytest.raises(ParameterError, match=r"^speed_range_rpm: need 0 <= min < max") as info:
        critical_speeds([100.0], "compressor", 4, rng)
    assert not isinstance(info.value, SceneError) and info.value.argument == "speed_range_rpm"


def test_bad_order_type_and_order_are_refused():
    """The core names its argument; the [torsion] stage names the scene key (test_torsion_scene)."""
    with pytest.raises(ParameterError) as info:
        excitation_orders("six_stroke", 4)
    assert not isinstance(info.value, SceneError) and info.value.argument == "order_type"
    assert str(info.value) == ("order_type: must be one of compressor, two_stroke, four_stroke; "
                               "got 'six_stroke'")
    with pytest.raises(ParameterError, match=r"^max_order: must be >= 1 for compressor, got 0.5$"):
        excitation_orders("compressor", 0.5)
    with pytest.raises(ParameterError, match=r"^operating_rpm: must be > 0, got -3.0$"):
        critical_speeds([100.0], "compressor", 4, (0.0, 100.0), -3.0)
