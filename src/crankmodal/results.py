"""Writing results: JSON-safe conversion and atomic file writes."""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from dataclasses import asdict, is_dataclass
from pathlib import Path
from typing import Any

from .errors import NumericalError, OutputError


def to_jsonable(obj: Any, path: str = "") -> Any:
    """Convert numpy scalars/arrays, dataclasses and paths into JSON types.

    Raises
    ------
    NumericalError
        If a value is NaN or infinite: a result must never carry silent garbage. The message
        names the key path.
    """
    if hasattr(obj, "to_dict") and callable(obj.to_dict):
        obj = obj.to_dict()
    elif is_dataclass(obj) and not isinstance(obj, type):
        obj = asdict(obj)
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v, f"{path}.{k}" if path else str(k)) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v, f"{path}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, Path):
        return str(obj)
    if hasattr(obj, "tolist") and hasattr(obj, "dtype"):  # numpy array or scalar
        return to_jsonable(obj.tolist(), path)
    if isinstance(obj, float):
        if not math.isfinite(obj):
            raise NumericalError(f"result {path} is {obj}: refusing to write non-finite values")
        return obj
    if obj is None or isinstance(obj, (bool, int, str)):
        return obj
    raise TypeError(f"result {path}: cannot write {type(obj).__name__} to JSON")


def output_error(exc: OSError, path: str | Path | None = None) -> OutputError:
    """The one-line :class:`~crankmodal.errors.OutputError` for an ``OSError`` met writing
    ``path``: the path and the system's reason. Without ``path``, the file the system names."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    if path is None:
        return OutputError(f"{exc.filename or 'a file'}: {reason}")
    return OutputError(f"cannot write {path}: {reason}")


def make_out_dir(path: str | Path) -> Path:
    """Create the output folder ``path`` (and its parents) if needed.

    Raises
    ------
    OutputError
        If ``path`` is a file, lies under a file, or cannot be created (read-only, full disk);
        the message names the folder.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"output folder {path} is a file, not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except NotADirectoryError:
        raise OutputError(f"cannot create output folder {path}: a parent of it is a file") from None
    except OSError as exc:
        raise OutputError(f"cannot create output folder {path}: {exc.strerror or exc}") from None
    return path


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """Write a file atomically through any writer that takes a file name.

    Yields a temporary path in the folder of ``path`` (created if missing), with the same suffix
    (``.modes.vtu.<random>.vtu``: writers that pick their format from the suffix, such as
    ``savefig``, ``meshio.write`` or PIL, and ``numpy.savez``, which appends ``.npz`` to any other
    name, see the real one). When the block ends normally the file is flushed to disk and renamed
    to ``path``, so a reader (or a run killed mid-write) sees the old file or the complete new
    one, never a truncated one. When the block raises, the temporary file is removed; an
    ``OSError`` (read-only folder, full disk) becomes an :class:`~crankmodal.errors.OutputError`
    naming ``path``.
    """
    path = Path(path)
    make_out_dir(path.parent)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise output_error(exc, path) from None
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; a result is an ordinary file
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)  # the data reaches the disk before the rename makes it the file
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:  # gone already, or the folder turned read-only: the first error counts
            pass
        if isinstance(exc, OSError):
            raise output_error(exc, path) from None
        raise


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_path`).

    A reader sees either the old file, or the complete new one, never a partial write. Text is
    written as UTF-8 whatever the locale (reports carry −, †, ², ...).
    """
    path = Path(path)
    if isinstance(data, str):
        data = data.encode("utf-8")
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return path


def savefig_atomic(fig, path: str | Path, **kwargs) -> Path:
    """``fig.savefig(path, **kwargs)`` through :func:`atomic_path` (the format from the suffix
    of ``path``)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, **kwargs)
    return path


def _umask() -> int:
    """The process's umask, read without changing it where Linux says it (Linux >= 4.7): setting
    and restoring it would let a file another thread creates meanwhile get mode 0666."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_json_atomic(path: str | Path, results: dict) -> Path:
    """Write a results dict as pretty JSON, atomically; non-finite values are refused."""
    text = json.dumps(to_jsonable(results), indent=2, allow_nan=False) + "\n"
    return write_atomic(path, text)
