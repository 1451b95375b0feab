"""Where the machine parameter files (``geometry/``) and ready scenes (``scenes/``) live.

In a source checkout (editable install) they are the top-level folders of the repository; in a
wheel they are packaged under ``crankmodal/_data``. ``CRANKMODAL_MACHINES`` (a path list) adds
folders of the user's own machine files, searched first.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

from .errors import InputFileError, SceneError

_PKG = Path(__file__).resolve().parent
_REPO = _PKG.parent.parent


def _dirs(kind: str) -> list[Path]:
    dirs = []
    if kind == "geometry":
        for p in os.environ.get("CRANKMODAL_MACHINES", "").split(os.pathsep):
            if p:
                dirs.append(Path(p))
    dirs += [_REPO / kind, _PKG / "_data" / kind]
    return [d for d in dirs if d.is_dir()]


def list_machines() -> list[str]:
    """Names of the machine parameter files found, sorted."""
    names = {p.stem for d in _dirs("geometry") for p in d.glob("*.toml")}
    return sorted(names)


def machine_path(name: str, key: str = "machine") -> Path:
    """Path of the parameter file of machine ``name``; ``key`` is the scene key naming it.

    Raises
    ------
    SceneError
        If no such machine exists; the message lists the known ones.
    """
    for d in _dirs("geometry"):
        p = d / f"{name}.toml"
        if p.is_file():
            return p
    known = ", ".join(list_machines()) or "none"
    raise SceneError(f"{key}: unknown machine {name!r}; known machines: {known}")


def load_toml(path: Path) -> dict:
    """Read a TOML file, turning I/O and syntax errors into one-line user errors."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"file not found: {path}")
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None
    except OSError as exc:
        raise InputFileError(f"{path}: cannot read: {exc.strerror}") from None


def load_machine(name: str, key: str = "machine") -> dict:
    """The parameter tables of machine ``name`` (SI units), as a dict of tables; ``key`` is the
    scene key naming it, for the error message."""
    return load_toml(machine_path(name, key))


def scene_path(name: str) -> Path:
    """Path of a ready scene shipped with crankmodal (``scenes/<name>.toml``)."""
    for d in _dirs("scenes"):
        p = d / f"{name}.toml"
        if p.is_file():
            return p
    raise InputFileError(f"no ready scene named {name!r}")
