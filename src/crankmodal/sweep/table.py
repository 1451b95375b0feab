"""The collected table of a sweep (CSV) and the checks of its output paths.

CSV, not Parquet: it needs no extra dependency (Parquet needs pyarrow, ~100 MB), every tool
reads it (pandas, a spreadsheet, ``csv``), and a sweep's table is small (one row per point). A
list-valued output is written as its JSON text in one cell.
"""

from __future__ import annotations

import csv
import difflib
import io
import json
import math
from pathlib import Path

from ..results import write_atomic
from .execute import collect

FIXED_COLUMNS = ("point", "round", "key", "status", "exit_code", "wall_time_s")


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, (list, dict)):
        return json.dumps(v)
    if isinstance(v, float) and not math.isfinite(v):
        return ""
    return v


def refresh_outputs(record: dict, outputs: list[str], root: Path) -> dict:
    """A finished point's record with ``outputs`` re-read from its results.json when the sweep
    now asks for outputs the record lacks or has empty (so fixing ``outputs`` needs no re-run)."""
    have = record.get("outputs") or {}
    if record.get("status") != "ok" or all(have.get(o) is not None for o in outputs):
        return record
    path = root / record["dir"] / "results.json"
    try:
        results = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # untrusted: unreadable, not UTF-8 or JSON
        return record
    if not isinstance(results, dict):
        return record
    return {**record, "outputs": collect(results, outputs)}


def flat_paths(obj, prefix: str = "") -> list[str]:
    """Every dotted path of a results dict (for suggesting the nearest one)."""
    out = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.extend(flat_paths(v, f"{prefix}{k}."))
    out.append(prefix[:-1])
    return [p for p in out if p]


def missing_outputs(records: list[dict], outputs: list[str]) -> list[str]:
    """Outputs that no successful point produced (empty when no point succeeded)."""
    ok = [r for r in records if r.get("status") == "ok"]
    if not ok:
        return []
    return [o for o in outputs if all(r["outputs"].get(o) is None for r in ok)]


def suggestion(record: dict, root: Path, path: str) -> str:
    """'; nearest: a.b.c' from a successful point's results.json, or ''."""
    try:
        results = json.loads((root / record["dir"] / "results.json").read_text(encoding="utf-8"))
    except (OSError, ValueError, KeyError, RecursionError):
        return ""
    close = difflib.get_close_matches(path, flat_paths(results), n=2, cutoff=0.6)
    return f"; nearest: {', '.join(close)}" if close else ""


def write_csv(path: Path, records: list[dict], axis_keys: list[str], outputs: list[str]) -> Path:
    """The table: one row per point (axes, outputs, status, error), written atomically."""
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow([*FIXED_COLUMNS, *axis_keys, *outputs, "error", "dir"])
    for r in records:
        w.writerow([_cell(r.get(c)) for c in FIXED_COLUMNS]
                   + [_cell(r["parameters"].get(k)) for k in axis_keys]
                   + [_cell(r["outputs"].get(o)) for o in outputs]
                   + [_cell(r.get("error")), r.get("dir", "")])
    return write_atomic(path, buf.getvalue())


def summarise(records: list[dict], outputs: list[str]) -> dict:
    """Per numeric output: min and max over the successful points, and which points."""
    out = {}
    for o in outputs:
        vals = [(r["outputs"].get(o), r["point"]) for r in records if r.get("status") == "ok"]
        vals = [(v, p) for v, p in vals
                if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)]
        if vals:
            lo, hi = min(vals), max(vals)
            out[o] = {"min": lo[0], "min_point": lo[1], "max": hi[0], "max_point": hi[1],
                      "n": len(vals)}
    return out
