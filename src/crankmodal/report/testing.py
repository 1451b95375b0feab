"""Frequency tolerances for test suites: ``assert_frequencies(results, expected, rtol=...)``.

Use it in a user's own pytest suite to pin a part's natural frequencies::

    from crankmodal.report.testing import assert_frequencies

    def test_crankshaft_first_two_bending_modes(tmp_path):
        res = crankmodal.runner.run(crankmodal.scene.load("crank.toml"), tmp_path)
        assert_frequencies(res, [1356.0, 1489.0], rtol=0.05)

``results`` may be a ``results.json`` dict (its ``modal.frequencies_hz`` is used), a path to
``results.json``, a :class:`~crankmodal.fem.modal.Modes`, or a plain sequence of Hz. ``expected``
is a sequence (compared by order, ``None`` skips an order) or a mapping ``{mode number (1-based):
Hz}``; ``rtol`` is a number or one per expected value.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def frequencies_of(results) -> np.ndarray:
    """Elastic frequencies (Hz) from a results dict/file, a Modes object or a sequence."""
    if isinstance(results, (str, Path)):
        results = json.loads(Path(results).read_text())
    if isinstance(results, dict):
        if "modal" in results:
            results = results["modal"]
        if "frequencies_hz" not in results:
            raise ValueError("assert_frequencies: results has no modal.frequencies_hz")
        return np.asarray(results["frequencies_hz"], float)
    if hasattr(results, "frequencies_hz"):
        return np.asarray(results.frequencies_hz, float)
    return np.asarray(results, float)


def compare_frequencies(results, expected, rtol=0.01) -> list[dict]:
    """Rows ``{mode, expected_hz, computed_hz, rel_error, rtol, ok}`` (mode numbers from 1)."""
    f = frequencies_of(results)
    if isinstance(expected, dict):
        items = sorted((int(k), v) for k, v in expected.items())
    else:
        items = [(i + 1, v) for i, v in enumerate(expected)]
    items = [(k, float(v)) for k, v in items if v is not None]
    tol = np.broadcast_to(np.asarray(rtol, float), (len(items),)) if np.ndim(rtol) == 0 \
        else np.asarray(rtol, float)
    if len(tol) != len(items):
        raise ValueError(f"assert_frequencies: {len(tol)} tolerances for {len(items)} "
                         f"expected frequencies")
    rows = []
    for (k, fe), t in zip(items, tol):
        if k < 1:
            raise ValueError(f"assert_frequencies: mode numbers start at 1, got {k}")
        fc = float(f[k - 1]) if k <= len(f) else None
        err = None if fc is None else (fc - fe) / fe
        rows.append({"mode": k, "expected_hz": fe, "computed_hz": fc, "rel_error": err,
                     "rtol": float(t), "ok": err is not None and abs(err) <= t})
    return rows


def assert_frequencies(results, expected, rtol=0.01) -> list[dict]:
    """Assert computed natural frequencies match a table within relative tolerances.

    Parameters
    ----------
    results : dict, path, Modes or sequence
        See the module docstring.
    expected : sequence or dict
        Hz, by order (``None`` skips one) or ``{mode number: Hz}``.
    rtol : float or sequence of float
        Admissible ``|f − f_expected| / f_expected``, per value or for all.

    Returns
    -------
    list of dict
        The comparison rows (when every one passes).

    Raises
    ------
    AssertionError
        Listing every mode out of tolerance (or missing) with its error.
    """
    rows = compare_frequencies(results, expected, rtol)
    bad = [r for r in rows if not r["ok"]]
    if bad:
        lines = []
        for r in bad:
            if r["computed_hz"] is None:
                lines.append(f"  mode {r['mode']}: expected {r['expected_hz']:.6g} Hz, "
                             f"not computed (only {len(frequencies_of(results))} modes)")
            else:
                lines.append(f"  mode {r['mode']}: {r['computed_hz']:.6g} Hz vs expected "
                             f"{r['expected_hz']:.6g} Hz, error {100 * r['rel_error']:+.3g} % "
                             f"(tolerance ±{100 * r['rtol']:.3g} %)")
        raise AssertionError(f"{len(bad)} of {len(rows)} frequencies out of tolerance:\n"
                             + "\n".join(lines))
    return rows
