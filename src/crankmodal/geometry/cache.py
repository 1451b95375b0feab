"""On-disk cache of parts, keyed by everything that makes them.

A part is stored under ``$CRANKMODAL_CACHE/parts/<key>.pkl`` (default ``~/.cache/crankmodal``)
where ``key`` is the SHA-256 of its kind, parameters, fidelity, mesh settings, the crankmodal
and gmsh versions, the source of this geometry package (so an edited builder never serves a
stale part) and, for imports, the file's content hash. Files are written atomically;
an unreadable entry is removed with a one-line warning and rebuilt.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import tempfile
from pathlib import Path

from .. import __version__


def cache_dir() -> Path:
    """Folder of cached parts (``$CRANKMODAL_CACHE/parts`` or ``~/.cache/crankmodal/parts``)."""
    from ..caches import cache_folder

    return cache_folder("parts")


def file_digest(path) -> str:
    """SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _source_digest() -> str:
    h = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.read_bytes())
    return h.hexdigest()


def part_key(description: dict) -> str:
    """Cache key of a part from a JSON-able description of what makes it."""
    import gmsh

    payload = {"crankmodal": __version__, "gmsh": gmsh.__version__, "source": _source_digest(), **description}
    text = json.dumps(payload, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def load_part(key: str):
    """The cached part of ``key``, or None: absent, or damaged (unreadable, truncated, not a
    part), which is removed with a one-line warning so that the caller rebuilds it."""
    from ..part import Part

    path = cache_dir() / f"{key}.pkl"
    if not path.is_file():
        return None
    try:
        with open(path, "rb") as fh:
            part = pickle.load(fh)
        if isinstance(part, Part):
            return part
        why = f"holds a {type(part).__name__}, not a part"
    except Exception as exc:  # noqa: BLE001 - a truncated or stale entry is rebuilt, never trusted
        why = f"{type(exc).__name__}: {exc}"
    from ..caches import discard_damaged

    discard_damaged(path, "geometry.cache: the cached part", why)
    return None


def store_part(key: str, part) -> Path:
    """Write ``part`` to the cache atomically; return its path."""
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            pickle.dump(part, fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, folder / f"{key}.pkl")
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return folder / f"{key}.pkl"
