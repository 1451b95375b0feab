"""Numbers as an engineer reads them: engineering prefixes, no exponent notation, en-dash ranges.

One implementation for everything the report prints (tables, verdicts, stage summaries):

- :func:`quantity` — ``15990, "N"`` -> ``15.99 kN``; ``2.22e-4, "m"`` -> ``222 µm``; a unit
  without an SI prefix (rpm, %, °, kg, dimensionless) keeps its number plain (``1480 rpm``);
- :func:`quantity_range` — ``15990, 34560, "N"`` -> ``15.99–34.56 kN`` (one prefix for both ends,
  an en dash; ``-120 to -40 N m`` when an end is negative, where a dash would read as a minus);
- :func:`quantity_as` — a value with another's prefix (a spread beside its mean);
- :func:`quantities` — a list with one prefix (``3631, 3669 N``);
- :func:`percent` — a fraction as ``-12.1 %``;
- :func:`number` — a plain number with ``digits`` significant digits and no ``e+04``; outside
  ``1e-3 <= |x| < 1e6`` as ``1.2 × 10⁻⁵``.

Values are SI; the prefix is chosen from the value (1 <= mantissa < 1000, and plain from 1 to
9999 so that 1480 Hz stays 1480 Hz). Pure functions; nothing is imported.
"""

from __future__ import annotations

import math

#: units that take an SI prefix (written after the prefix: k + "N m" -> "kN m")
PREFIXABLE = frozenset({"N", "N m", "W", "J", "Pa", "Hz", "m", "s",
                        "N/m", "N s/m", "N m/rad", "V", "A"})

PREFIXES = {-12: "p", -9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M", 9: "G", 12: "T"}

EN_DASH = "–"

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _round_sig(x: float, digits: int) -> float:
    """``x`` rounded to ``digits`` significant digits."""
    if x == 0 or not math.isfinite(x):
        return x
    return round(x, digits - 1 - math.floor(math.log10(abs(x))))


def _fixed(x: float, digits: int) -> str:
    """``x`` with ``digits`` significant digits in fixed-point, trailing zeros dropped."""
    x = _round_sig(float(x), digits)
    if x == 0:
        return "0"
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(x))))
    s = f"{x:.{decimals}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def number(x, digits: int = 4) -> str:
    """A plain number: ``digits`` significant digits, never ``e+04``.

    Parameters
    ----------
    x : float
        Any value (dimensionless, or in the unit the caller states).
    digits : int
        Significant digits.

    Returns
    -------
    str
        ``'1480'``, ``'0.2688'``, ``'1.2 × 10⁻⁵'`` (outside 1e-3 <= |x| < 1e6), ``'nan'``.
    """
    x = float(x)
    if not math.isfinite(x):
        return str(x)
    r = _round_sig(x, digits)
    if r == 0 or 1e-3 <= abs(r) < 1e6:
        return _fixed(r, digits)
    e = math.floor(math.log10(abs(r)))
    return f"{_fixed(r / 10.0 ** e, digits)} × 10{str(e).translate(_SUPERSCRIPT)}"


def _exponent(x: float, digits: int) -> int | None:
    """Engineering exponent (multiple of 3) for ``x``: 0 from 1 to 9999, else mantissa 1-999;
    None beyond the prefixes (pico to tera)."""
    r = abs(_round_sig(x, digits))
    if r == 0 or not math.isfinite(r) or 1.0 <= r < 1e4:
        return 0
    e = 3 * math.floor(math.log10(r) / 3)
    return e if e in PREFIXES else None


def quantity(x, unit: str = "", digits: int = 4) -> str:
    """A value in SI units with an engineering prefix: ``quantity(15990, "N")`` -> ``15.99 kN``.

    Parameters
    ----------
    x : float
        Value in the SI unit ``unit`` (N, m, s, Pa, Hz, ...).
    unit : str
        The unit as printed. Units in :data:`PREFIXABLE` take a prefix (k, M, m, µ, ...);
        others (rpm, %, °, kg, '' for dimensionless) keep the plain :func:`number`.
    digits : int
        Significant digits.

    Returns
    -------
    str
    """
    if unit not in PREFIXABLE:
        return number(x, digits) + (f" {unit}" if unit else "")
    e = _exponent(float(x), digits)
    if e is None:
        return f"{number(x, digits)} {unit}"
    return f"{_fixed(float(x) / 10.0 ** e, digits)} {PREFIXES[e]}{unit}"


def quantity_as(x, reference, unit: str = "", digits: int = 4) -> str:
    """``x`` with the prefix :func:`quantity` gives ``reference``: a spread beside its mean
    (``quantity_as(0.3009, 6342, "N")`` -> ``0.3009 N``, not ``300.9 mN``)."""
    e = _exponent(float(reference), digits) if unit in PREFIXABLE else None
    if e is None:
        return quantity(x, unit, digits)
    return f"{_fixed(float(x) / 10.0 ** e, digits)} {PREFIXES[e]}{unit}"


def quantity_range(lo, hi, unit: str = "", digits: int = 4) -> str:
    """``lo``–``hi`` with one prefix for both ends: ``(15990, 34560, "N")`` -> ``15.99–34.56 kN``.

    An en dash joins the ends; when either end is negative they are joined by ``to``
    (``-120 to -40 N m``: a dash beside a minus sign reads as a subtraction). The prefix is
    that of the end with the larger magnitude. Ends equal as printed give one value.

    Parameters
    ----------
    lo, hi : float
        The ends, SI units.
    unit, digits
        As in :func:`quantity`.
    """
    lo, hi = float(lo), float(hi)
    if quantity(lo, unit, digits) == quantity(hi, unit, digits):
        return quantity(hi, unit, digits)  # equal as printed: one value, not 2959–2959 N
    join = " to " if min(lo, hi) < 0 else EN_DASH
    e = _exponent(max(abs(lo), abs(hi)), digits)
    if unit not in PREFIXABLE or e is None:
        return f"{number(lo, digits)}{join}{number(hi, digits)}" + (f" {unit}" if unit else "")
    s = 10.0 ** e
    return f"{_fixed(lo / s, digits)}{join}{_fixed(hi / s, digits)} {PREFIXES[e]}{unit}"


def quantities(values, unit: str = "", digits: int = 4) -> str:
    """Several values with one prefix (that of the largest magnitude) and the unit once:
    ``([3631, 3669], "N")`` -> ``3631, 3669 N``; ``([0.035, 0.392], "m")`` -> ``35, 392 mm``.
    Missing values (None) print as a dash."""
    vals = [None if v is None else float(v) for v in values]
    finite = [abs(v) for v in vals if v is not None and math.isfinite(v)]
    e = _exponent(max(finite), digits) if finite and unit in PREFIXABLE else None
    if e is None:
        text = ", ".join("–" if v is None else number(v, digits) for v in vals)
        return text + (f" {unit}" if unit else "")
    s = 10.0 ** e
    text = ", ".join("–" if v is None else _fixed(v / s, digits) for v in vals)
    return f"{text} {PREFIXES[e]}{unit}"


def percent(fraction, digits: int = 3, sign: bool = False) -> str:
    """A fraction as a percentage: ``percent(-0.1207, sign=True)`` -> ``-12.1 %``."""
    v = 100.0 * float(fraction)
    s = number(v, digits)
    return f"{'+' if sign and v > 0 else ''}{s} %"
