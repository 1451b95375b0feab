"""Where crankmodal keeps what it can rebuild, and how it writes it.

Everything cached lives under ``$CRANKMODAL_CACHE`` (default ``~/.cache/crankmodal``), one
folder per kind (``parts``, ``flexbodies``, ``film_tables``). Entries are written atomically (a
temporary file renamed into place), so a crash never leaves half a file; a reader that finds an
entry damaged removes it with one warning line and rebuilds it.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def cache_root() -> Path:
    """``$CRANKMODAL_CACHE``, else ``~/.cache/crankmodal``."""
    return Path(os.environ.get("CRANKMODAL_CACHE") or Path.home() / ".cache" / "crankmodal")


def cache_folder(kind: str) -> Path:
    """The folder of one kind of cached entry, e.g. ``cache_folder("film_tables")``."""
    return cache_root() / kind


def discard_damaged(path: Path, what: str, why: str, then: str = "rebuilding it") -> None:
    """Remove a damaged cache entry with one warning line: ``"<what> <path> is damaged (<why>);
    <then>"`` (a results ``warnings`` entry where a stage collects them)."""
    from .errors import warn

    warn(f"{what} {path} is damaged ({why}); {then}")
    try:
        Path(path).unlink()
    except OSError:
        pass  # the rebuilt entry replaces it atomically anyway


def write_npz_atomically(path: Path, **arrays) -> Path:
    """``np.savez`` into a temporary file beside ``path``, then rename it into place.

    Returns ``path``. Raises ``OSError`` when the folder cannot be written (callers that only
    cache may ignore it: the value is still in hand).
    """
    import numpy as np

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.stem, suffix=".tmp.npz")
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
