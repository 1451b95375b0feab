"""Declarative validation of scene sections.

A stage declares its keys as a mapping ``name -> Field``; :func:`validate` checks a raw TOML table
against it and returns a new dict with defaults filled in. Every failure raises
:class:`~crankmodal.errors.SceneError` with the full dotted key and what is allowed, e.g.::

    mechanism.speed_rpm: must be > 0, got -5.0

Only the standard library and this module are imported, so validating a scene never pulls in a
heavy stage dependency.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from .errors import SceneError

REQUIRED = object()

_TYPE_NAMES = {
    "float": "a number",
    "int": "an integer",
    "str": "a string",
    "bool": "true or false",
    "floats": "a list of numbers",
    "ints": "a list of integers",
    "strs": "a list of strings",
    "table": "a table",
    "tables": "a list of tables",
    "any": "any value",
}


@dataclass(frozen=True)
class Field:
    """One scene key.

    Parameters
    ----------
    type : str
        One of ``float``, ``int``, ``str``, ``bool``, ``floats``, ``ints``, ``strs``, ``table``,
        ``tables``, ``any``. Integers are accepted where floats are expected.
    default : object
        Value used when the key is absent; ``REQUIRED`` makes the key mandatory; ``None`` means
        optional with no value.
    doc : str
        What the key means, with units; quoted in the "is required" message.
    gt, ge, lt, le : float, optional
        Bounds on a number (or on every element of a list of numbers).
    choices : tuple, optional
        Admissible values of a string (or of every element of a list of strings).
    length : int, optional
        Exact length of a list.
    check : callable, optional
        ``check(value) -> str | None``; a returned string is the error text.
    """

    type: str
    default: Any = REQUIRED
    doc: str = ""
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    choices: tuple | None = None
    length: int | None = None
    check: Callable[[Any], str | None] | None = None


def _fail(key: str, message: str) -> SceneError:
    return SceneError(f"{key}: {message}")


def _check_number(key: str, x: Any, f: Field) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise _fail(key, f"must be a number, got {x!r}")
    x = float(x) if f.type in ("float", "floats") else x
    if isinstance(x, float) and math.isnan(x):
        raise _fail(key, "must be a number, got nan")
    if isinstance(x, float) and math.isinf(x):
        raise _fail(key, f"must be a finite number, got {x!r}")
    for bound, op, text in (
        (f.gt, lambda a, b: a > b, ">"),
        (f.ge, lambda a, b: a >= b, ">="),
        (f.lt, lambda a, b: a < b, "<"),
        (f.le, lambda a, b: a <= b, "<="),
    ):
        if bound is not None and not op(x, bound):
            raise _fail(key, f"must be {text} {bound:g}, got {x!r}")
    return x


def _check_scalar(key: str, x: Any, kind: str, f: Field) -> Any:
    if kind == "float":
        return _check_number(key, x, f)
    if kind == "int":
        if isinstance(x, bool) or not isinstance(x, int):
            raise _fail(key, f"must be an integer, got {x!r}")
        return _check_number(key, x, f)
    if kind == "str":
        if not isinstance(x, str):
            raise _fail(key, f"must be a string, got {x!r}")
        if f.choices is not None and x not in f.choices:
            raise _fail(key, f"must be one of {', '.join(map(str, f.choices))}; got {x!r}")
        return x
    if kind == "bool":
        if not isinstance(x, bool):
            raise _fail(key, f"must be true or false, got {x!r}")
        return x
    if kind == "table":
        if not isinstance(x, Mapping):
            raise _fail(key, f"must be a table, got {x!r}")
        return dict(x)
    raise AssertionError(kind)


def check_value(key: str, value: Any, f: Field) -> Any:
    """Check one value against its field; return the normalised value."""
    t = f.type
    if t == "any":
        out = value
    elif t in ("floats", "ints", "strs", "tables"):
        if not isinstance(value, (list, tuple)):
            raise _fail(key, f"must be {_TYPE_NAMES[t]}, got {value!r}")
        if f.length is not None and len(value) != f.length:
            raise _fail(key, f"must have {f.length} entries, got {len(value)}")
        kind = {"floats": "float", "ints": "int", "strs": "str", "tables": "table"}[t]
        out = [_check_scalar(f"{key}[{i}]", v, kind, f) for i, v in enumerate(value)]
    else:
        out = _check_scalar(key, value, t, f)
    if f.check is not None:
        msg = f.check(out)
        if msg:
            raise _fail(key, msg)
    return out


def validate(section: str, raw: Mapping[str, Any], schema: Mapping[str, Field]) -> dict:
    """Validate a raw scene table against a schema.

    Parameters
    ----------
    section : str
        Dotted name of the table, used in messages (``"mechanism"``, ``"modal.supports[0]"``).
    raw : mapping
        The table as read from TOML (after machine defaults and ``--set`` overrides).
    schema : mapping of str to Field
        The admissible keys.

    Returns
    -------
    dict
        Every key of the schema, with defaults filled in (``None`` for optional absent keys).

    Raises
    ------
    SceneError
        On an unknown key, a missing required key, a wrong type or an out-of-range value.
    """
    if not isinstance(raw, Mapping):
        raise _fail(section, f"must be a table, got {raw!r}")
    unknown = sorted(set(raw) - set(schema))
    if unknown:
        allowed = ", ".join(sorted(schema))
        raise _fail(f"{section}.{unknown[0]}", f"unknown key; allowed keys are: {allowed}")
    out = {}
    for name, f in schema.items():
        key = f"{section}.{name}"
        if name in raw:
            out[name] = check_value(key, raw[name], f)
        elif f.default is REQUIRED:
            raise _fail(key, f"is required ({f.doc or _TYPE_NAMES[f.type]})")
        else:
            out[name] = f.default
    return out
