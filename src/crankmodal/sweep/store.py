"""The record store: one JSON line per finished point, appended and fsync'd as it finishes.

JSON Lines because an append is the only write: a killed sweep leaves every finished point's
line intact, and at most a truncated last line (ignored on reading), so a re-run loses only the
points that were in flight. Reading keeps the last record of each key.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
from pathlib import Path

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


class RecordStore:
    """Append-only ``records.jsonl`` of a sweep's folder."""

    def __init__(self, path: str | Path):
        self.path = Path(path)

    def read(self) -> dict[str, dict]:
        """``{key: record}`` of every complete line (the last record of a key wins)."""
        records: dict[str, dict] = {}
        if not self.path.is_file():
            return records
        with open(self.path, encoding="utf-8") as fh:
            for line in fh:
                if not line.endswith("\n"):
                    break  # a line cut by a kill: that point was in flight
                try:
                    rec = json.loads(line)
                except json.JSONDecodeError:
                    continue
                if isinstance(rec, dict) and "key" in rec:
                    records[rec["key"]] = rec
        return records

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
