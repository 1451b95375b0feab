"""Argument checks of the Python API, by the scene schema's rules.

A core function checks its arguments at entry with the :class:`~crankmodal.schema.Field` of the
scene key that carries the same quantity (``dynamics.crank_train.crank_radius`` for
``crank_train(crank_radius=...)``), so a bound is written once and the scene and the API refuse
the same values. The failure is a :class:`~crankmodal.errors.ParameterError` naming the
argument (``crank_radius: must be > 0, got -0.05``); a stage that passes a scene value re-raises
it under the scene key (:class:`~crankmodal.errors.scene_keys`).

>>> from crankmodal.schema import Field
>>> number("crank_radius", 0.05, gt=0.0)
0.05
>>> try:
...     number("crank_radius", float("nan"), gt=0.0)
... except Exception as exc:
...     print(type(exc).__name__, exc)
ParameterError crank_radius: must be a number, got nan
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from .errors import ParameterError, SceneError
from .schema import Field, check_value


def _plain(value: Any) -> Any:
    """NumPy scalars and arrays as Python numbers and lists (the schema checks Python types)."""
    tolist = getattr(value, "tolist", None)
    if tolist is not None and type(value).__module__ == "numpy":
        return tolist()
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if isinstance(value, list) and any(type(v).__module__ == "numpy" for v in value):
        return [_plain(v) for v in value]
    return value


def check(name: str, value: Any, field: Field, optional: bool = False) -> Any:
    """``value`` checked against ``field`` (types, finiteness, bounds, choices, length).

    Parameters
    ----------
    name : str
        The argument's name (a dotted path for a nested value: ``clearances.main.clearance``).
    value : object
        As given; NumPy scalars and arrays are accepted where Python numbers and lists are.
    field : Field
        The rule: a scene key's field, or one made for the argument.
    optional : bool
        None passes (returned as None).

    Returns
    -------
    object
        The normalised value (a float for ``float``, a list for the list types).

    Raises
    ------
    ParameterError
        Naming ``name`` (``name[i]`` for an element of a list).
    """
    if value is None and optional:
        return None
    try:
        return check_value(name, _plain(value), field)
    except SceneError as exc:
        key, _, text = str(exc).partition(": ")
        raise ParameterError(key, text) from None


def table_by(name: str, value: Any, schema: Mapping[str, Field]) -> dict:
    """A dict checked against a scene table's schema (unknown keys, required keys, every
    value's rule), its defaults filled in; failures name ``name.<key>``."""
    from .schema import validate

    try:
        return validate(name, _plain(value) if value is not None else value, schema)
    except SceneError as exc:
        key, _, text = str(exc).partition(": ")
        raise ParameterError(key, text) from None


def number(name: str, value: Any, gt=None, ge=None, lt=None, le=None, optional=False) -> float:
    """A finite real number within the bounds given (``optional``: None passes)."""
    return check(name, value, Field("float", gt=gt, ge=ge, lt=lt, le=le), optional)


def integer(name: str, value: Any, gt=None, ge=None, lt=None, le=None) -> int:
    """An integer (not a bool) within the bounds given."""
    return check(name, value, Field("int", gt=gt, ge=ge, lt=lt, le=le))


def numbers(name: str, value: Any, length: int | None = None, gt=None, ge=None, lt=None,
            le=None) -> list[float]:
    """A list (or tuple, or array) of finite numbers, of ``length`` entries if given."""
    return check(name, value, Field("floats", length=length, gt=gt, ge=ge, lt=lt, le=le))


def one_of(name: str, value: Any, choices: tuple) -> Any:
    """One of ``choices`` (compared with ``==``)."""
    if isinstance(value, bool) or value not in choices:
        raise ParameterError(name, f"must be one of {', '.join(map(repr, choices))}; "
                             f"got {value!r}")
    return value


def instance(name: str, value: Any, kind, what: str) -> Any:
    """``value`` an instance of ``kind`` (a type or tuple); ``what`` says what is expected."""
    if not isinstance(value, kind):
        raise ParameterError(name, f"must be {what}, got {type(value).__name__} {value!r:.60}")
    return value


def table(name: str, value: Any, allowed, required=()) -> dict:
    """A mapping whose keys are among ``allowed`` and include ``required``; None is ``{}``."""
    if value is None:
        value = {}
    if not isinstance(value, Mapping):
        raise ParameterError(name, f"must be a dict, got {type(value).__name__} {value!r:.60}")
    for key in value:
        if key not in allowed:
            raise ParameterError(f"{name}.{key}", "unknown key; allowed keys are: "
                                 + ", ".join(sorted(allowed)))
    for key in required:
        if key not in value:
            raise ParameterError(f"{name}.{key}", "is required")
    return dict(value)


def path(name: str, value: Any) -> Any:
    """A file-system path: a ``str`` or ``os.PathLike`` (not empty)."""
    if not isinstance(value, (str, os.PathLike)) or not str(value).strip():
        raise ParameterError(name, f"must be a path (str or pathlib.Path), got {value!r:.60}")
    return value


class prefixed:
    """Re-raise a :class:`~crankmodal.errors.ParameterError` of the block under
    ``<prefix>.<argument>``: a function that passes its argument ``spec``'s values on to
    another core function names them as its own (``spec.n_modes``)."""

    def __init__(self, prefix: str):
        self.prefix = prefix

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if isinstance(exc, ParameterError):
            raise ParameterError(f"{self.prefix}.{exc.argument}", exc.text) from None
        return False


__all__ = ["check", "instance", "integer", "number", "numbers", "one_of", "path", "prefixed",
           "table", "table_by"]
