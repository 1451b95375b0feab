"""Scene-section validation: every failure names the dotted key and what is allowed."""

import math

import pytest

from crankmodal.errors import SceneError
from crankmodal.schema import REQUIRED, Field, validate

SCHEMA = {
    "speed_rpm": Field("float", REQUIRED, "crank speed, rpm", gt=0),
    "n_modes": Field("int", 12, "elastic modes", ge=1, le=500),
    "law": Field("str", "impact", "contact law", choices=("impact", "hertz")),
    "phases": Field("floats", None, "deg"),
    "pair": Field("floats", None, "two numbers", length=2),
    "on": Field("bool", True, ""),
}


def test_defaults_are_filled_and_ints_accepted_as_floats():
    p = validate("mechanism", {"speed_rpm": 1480}, SCHEMA)
    assert p == {"speed_rpm": 1480.0, "n_modes": 12, "law": "impact", "phases": None,
                 "pair": None, "on": True}
    assert isinstance(p["speed_rpm"], float)


@pytest.mark.parametrize(
    "raw, message",
    [
        ({}, "mechanism.speed_rpm: is required"),
        ({"speed_rpm": -5}, "mechanism.speed_rpm: must be > 0, got -5.0"),
        ({"speed_rpm": "fast"}, "mechanism.speed_rpm: must be a number, got 'fast'"),
        ({"speed_rpm": True}, "mechanism.speed_rpm: must be a number, got True"),
        ({"speed_rpm": math.nan}, "mechanism.speed_rpm: must be a number, got nan"),
        ({"speed_rpm": math.inf}, "mechanism.speed_rpm: must be a finite number, got inf"),
        ({"speed_rpm": 1, "phases": [0, -math.inf]},
         "mechanism.phases[1]: must be a finite number, got -inf"),
        ({"speed_rpm": 1, "n_modes": 2.5}, "mechanism.n_modes: must be an integer, got 2.5"),
        ({"speed_rpm": 1, "n_modes": 0}, "mechanism.n_modes: must be >= 1, got 0"),
        ({"speed_rpm": 1, "law": "soft"}, "mechanism.law: must be one of impact, hertz; got 'soft'"),
        ({"speed_rpm": 1, "phases": [0, "x"]}, "mechanism.phases[1]: must be a number, got 'x'"),
        ({"speed_rpm": 1, "pair": [1, 2, 3]}, "mechanism.pair: must have 2 entries, got 3"),
        ({"speed_rpm": 1, "on": "yes"}, "mechanism.on: must be true or false, got 'yes'"),
        ({"speed_rpm": 1, "spede": 3}, "mechanism.spede: unknown key; allowed keys are: "),
    ],
)
def test_bad_values_name_the_key_and_the_rule(raw, message):
    with pytest.raises(SceneError) as exc:
        validate("mechanism", raw, SCHEMA)
    assert str(exc.value).startswith(message)
    assert "\n" not in str(exc.value)
