"""Numbers as the report prints them (issue 25 #15): engineering prefixes, never ``e+04``, ranges
with an en dash. The oracle is the printed text read back: prefix and mantissa give the value
again, within the rounding of the digits printed."""

import math
import re

import pytest

from crankmodal.report.quantity import (
    EN_DASH,
    number,
    percent,
    quantities,
    quantity,
    quantity_range,
)

PREFIX = {"p": 1e-12, "n": 1e-9, "µ": 1e-6, "m": 1e-3, "": 1.0, "k": 1e3, "M": 1e6, "G": 1e9,
          "T": 1e12}
SUPER = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")


def read_back(text: str, unit: str) -> float:
    """The value a reader takes from ``text`` (``15.99 kN``, ``1.5 × 10⁻¹³ N``)."""
    body = text[: -len(unit)].strip() if unit else text.strip()
    m = re.fullmatch(r"(-?[\d.]+) × 10([⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)", body)
    if m:
        return float(m.group(1)) * 10.0 ** int(m.group(2).translate(SUPER))
    m = re.fullmatch(r"(-?[\d.]+) ?([pnµmkMGT]?)", body)
    assert m, text
    return float(m.group(1)) * PREFIX[m.group(2)]


def test_the_issues_range_reads_in_kilonewtons_with_an_en_dash():
    assert quantity_range(1.599e4, 3.456e4, "N") == f"15.99{EN_DASH}34.56 kN"
    assert quantity(2.22e-4, "m") == "222 µm"
    assert quantity(1480.0, "Hz") == "1480 Hz" and quantity(1480.0, "rpm") == "1480 rpm"
    assert quantity(-77.38, "N m") == "-77.38 N m"
    assert quantity_range(-116.8, -37.19, "N m") == "-116.8 to -37.19 N m"
    assert quantity_range(2959.0, 2959.2, "N") == "2959 N"  # equal as printed: one value
    assert quantities([0.035, 0.392], "m") == "35, 392 mm"
    assert percent(-0.12074, sign=True) == "-12.1 %" and percent(0.05) == "5 %"


@pytest.mark.parametrize("unit", ["N", "Pa", "Hz", "s", "m", "rpm", "kg", ""])
def test_every_magnitude_prints_without_exponent_notation_and_reads_back(unit):
    for e in range(-15, 16):
        for mant in (1.0, 1.234567, 9.99951, 4.2):
            x = mant * 10.0 ** e
            for v in (x, -x):
                text = quantity(v, unit)
                assert not re.search(r"\de[+-]?\d", text), text
                assert text.endswith(unit)
                # 4 significant digits printed: the reading is within half a unit of the 4th
                assert read_back(text, unit) == pytest.approx(v, rel=5.001e-4), text


def test_a_range_has_one_prefix_and_reads_back_at_both_ends():
    for lo, hi in ((1.599e4, 3.456e4), (2.5e-5, 3.1e-4), (0.0, 1.2e7), (950.0, 1.05e4)):
        text = quantity_range(lo, hi, "N")
        a, b = text[:-1].split(EN_DASH)  # 'N' dropped: '15.99', '34.56 k'
        prefix = b.split()[1] if len(b.split()) > 1 else ""
        assert read_back(f"{a} {prefix}N", "N") == pytest.approx(lo, rel=5.001e-4)
        assert read_back(b + "N", "N") == pytest.approx(hi, rel=5.001e-4)


def test_plain_numbers_switch_to_powers_of_ten_outside_a_readable_span():
    assert number(2.0e-6) == "2 × 10⁻⁶"
    assert number(1.5e-13, 2) == "1.5 × 10⁻¹³"
    assert number(0.2688) == "0.2688" and number(123456.0) == "123500"
    assert number(math.nan) == "nan"


def test_a_spread_takes_the_prefix_of_its_mean():
    from crankmodal.report.quantity import quantity_as

    assert quantity_as(1817.0, 16600.0, "N") == "1.817 kN"
    assert quantity_as(0.3009, 6342.0, "N") == "0.3009 N"
    assert quantity_as(9.018, 35.67, "") == "9.018"
