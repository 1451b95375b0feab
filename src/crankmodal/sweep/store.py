"""The record store: one JSON line per finished point, appended and fsync'd as it finishes.

JSON Lines because an append is the only write: a killed sweep leaves every finished point's
line intact, and at most a truncated last line (ignored on reading), so a re-run loses only the
points that were in flight. Reading keeps the last record of each key.

The file is untrusted on reading (edited by hand, copied, damaged): every line must be UTF-8
JSON of an object whose members have the types :func:`record_problem` checks. A line that is
not is skipped - its point counts as not run and runs again, as a point whose line a kill cut -
and :attr:`RecordStore.skipped` says which lines and why.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
from pathlib import Path, PurePosixPath

from ..errors import OutputError
from ..results import output_error


def _finite(obj):
    """NaN/inf outputs as None (JSON has no NaN; a reader of the table sees an empty cell)."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    return obj


def as_stored(obj):
    """``obj`` as a record line gives it back (tuples as lists, NaN/inf as None)."""
    return json.loads(json.dumps(_finite(obj)))


#: The statuses a record may have.
STATUSES = ("ok", "error", "timeout")


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def record_problem(rec) -> str | None:
    """What is wrong with a parsed record line, or None when every member has its type.

    A record is an object with ``key`` (non-empty str), ``point`` and ``round`` (int >= 0;
    ``round`` may be absent), ``parameters`` and ``outputs`` (objects), ``status`` (one of
    :data:`STATUSES`), ``exit_code`` (int or null), ``error`` (str or null), ``wall_time_s``
    (a number >= 0, s, or null) and ``dir`` (a relative path inside the sweep's folder: it is
    read from, so a record must not point elsewhere).
    """
    if not isinstance(rec, dict):
        return f"not a JSON object but {type(rec).__name__}"
    checks = (
        ("key", lambda v: isinstance(v, str) and v != "", "a non-empty string"),
        ("point", lambda v: _is_int(v) and v >= 0, "an integer >= 0"),
        ("parameters", lambda v: isinstance(v, dict), "an object"),
        ("status", lambda v: v in STATUSES, f"one of {', '.join(STATUSES)}"),
        ("exit_code", lambda v: v is None or _is_int(v), "an integer or null"),
        ("error", lambda v: v is None or isinstance(v, str), "a string or null"),
        ("outputs", lambda v: isinstance(v, dict), "an object"),
        ("wall_time_s", lambda v: v is None or _is_number(v) and v >= 0,
         "a number >= 0 or null"),
        ("dir", lambda v: isinstance(v, str) and v != "" and not PurePosixPath(v).is_absolute()
         and ".." not in PurePosixPath(v).parts, "a relative path inside the folder"),
    )
    for name, ok, what in checks:
        if name not in rec:
            return f"no {name!r}"
        if not ok(rec[name]):
            return f"{name!r} must be {what}, got {rec[name]!r:.40}"
    if "round" in rec and not (_is_int(rec["round"]) and rec["round"] >= 0):
        return f"'round' must be an integer >= 0, got {rec['round']!r:.40}"
    return None


class RecordStore:
    """Append-only ``records.jsonl`` of a sweep's folder.

    Attributes
    ----------
    skipped : list of (int, str)
        After :meth:`read`: the 1-based line numbers of the lines skipped as bad records, and why.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.skipped: list[tuple[int, str]] = []

    def read(self) -> dict[str, dict]:
        """``{key: record}`` of every complete, valid line (the last record of a key wins).

        A last line without its newline (cut by a kill) is ignored silently; any other line that
        is not UTF-8, not JSON or not a record (:func:`record_problem`) is skipped and listed in
        :attr:`skipped`. A skipped line's point is not recorded, so it runs again.
        """
        records: dict[str, dict] = {}
        self.skipped = []
        if not self.path.is_file():
            return records
        try:
            with open(self.path, "rb") as fh:
                lines = fh.read().split(b"\n")
        except OSError as exc:
            raise output_error(exc, self.path) from None
        for n, raw in enumerate(lines[:-1], start=1):  # lines[-1]: after the last newline
            if not raw.strip():
                continue
            try:
                rec = json.loads(raw.decode("utf-8"))
            except UnicodeDecodeError:
                self.skipped.append((n, "not UTF-8 text"))
                continue
            except (ValueError, RecursionError) as exc:  # JSONDecodeError, too deep, too long
                self.skipped.append((n, f"not JSON ({str(exc).splitlines()[0]:.60})"))
                continue
            problem = record_problem(rec)
            if problem:
                self.skipped.append((n, problem))
                continue
            records[rec["key"]] = rec
        return records

    def skipped_line(self) -> str | None:
        """One line on the lines :meth:`read` skipped (None when none was)."""
        if not self.skipped:
            return None
        shown = "; ".join(f"line {n}: {why}" for n, why in self.skipped[:3])
        more = f"; and {len(self.skipped) - 3} more" if len(self.skipped) > 3 else ""
        return (f"{self.path}: {len(self.skipped)} bad record line(s) skipped ({shown}{more}); "
                "their points run again")

    def append(self, record: dict) -> None:
        """Write one record as a line, flushed and fsync'd before returning."""
        line = json.dumps(_finite(record), allow_nan=False) + "\n"
        try:
            self._repair()
            with open(self.path, "a", encoding="utf-8") as fh:
                fh.write(line)
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as exc:
            raise output_error(exc, self.path) from None

    def _repair(self) -> None:
        """End a line a kill cut off, so the next record starts on its own line."""
        try:
            size = self.path.stat().st_size
        except FileNotFoundError:
            return
        if size:
            with open(self.path, "rb+") as fh:
                fh.seek(-1, os.SEEK_END)
                if fh.read(1) != b"\n":
                    fh.write(b"\n")


@contextlib.contextmanager
def folder_lock(folder: Path):
    """Hold ``folder/.sweep.lock`` (``flock``) for a sweep's run: a second sweep into the same
    folder would interleave its records and race on the tables, so it is refused by name."""
    import fcntl

    path = Path(folder) / ".sweep.lock"
    try:
        fh = open(path, "a+")  # noqa: SIM115 (held for the lock's lifetime, closed below)
    except OSError as exc:
        raise output_error(exc, path) from None
    try:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            fh.seek(0)
            owner = fh.read().strip() or "?"
            raise OutputError(f"{folder}: another sweep is running into this folder (pid "
                              f"{owner}); wait for it or give another --out") from None
        fh.seek(0)
        fh.truncate()
        fh.write(str(os.getpid()))
        fh.flush()
        yield
    finally:
        fh.close()  # releases the lock
