"""Where the machine parameter files (``geometry/``) and ready scenes (``scenes/``) live.

In a source checkout (editable install) they are the top-level folders of the repository; in a
wheel they are packaged under ``crankmodal/_data``. ``CRANKMODAL_MACHINES`` (a path list) adds
folders of the user's own machine files, searched first.
"""

from __future__ import annotations

import codecs
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
    """Names of the machine parameter files found, sorted.

    The folders searched are ``$CRANKMODAL_MACHINES`` (a path list, first), the repository's
    ``geometry/`` and the wheel's packaged machines.

    Returns
    -------
    list of str
        Names for ``machine = "..."`` in a scene and for :func:`load_machine`.

    Examples
    --------
    >>> import crankmodal as cm
    >>> "four_star_compressor" in cm.list_machines()
    True
    """
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
    """Read a TOML file, turning I/O, encoding and syntax errors into one-line user errors."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"file not found: {path}")
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise InputFileError(f"{path}: cannot read: {exc.strerror}") from None
    try:
        return tomllib.loads(decode_utf8(raw, path))
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None


#: Byte-order marks of the encodings a TOML file must not be in, by name.
_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
         (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16"))


def decode_utf8(raw: bytes, path) -> str:
    """The text of a TOML file, which must be UTF-8 (TOML 1.0); a UTF-8 byte-order mark is dropped.

    Raises
    ------
    SceneError
        Naming the file, the encoding it seems to be in (UTF-16/32 by their byte-order mark) or
        the first byte that is not UTF-8 (line and column), and what to do.
    """
    for bom, name in _BOMS:  # UTF-32-LE's mark starts with UTF-16-LE's: longest first
        if raw.startswith(bom):
            raise SceneError(f"{path}: {name} text (it starts with a {name} byte-order mark); "
                             "TOML files must be UTF-8: save it as UTF-8")
    # A UTF-8 byte-order mark (Windows editors write one) is still UTF-8: drop it, as
    # "utf-8-sig" would, instead of refusing a file that is in the right encoding.
    raw = raw.removeprefix(codecs.BOM_UTF8)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise SceneError(f"{path}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at line {line}, "
                         f"column {column}: {exc.reason}); TOML files must be UTF-8: "
                         "save it as UTF-8") from None


def load_machine(name: str, key: str = "machine") -> dict:
    """The parameter tables of machine ``name`` (SI units), as a dict of tables.

    Parameters
    ----------
    name : str
        A machine of :func:`list_machines` (``geometry/<name>.toml``, or a folder on
        ``CRANKMODAL_MACHINES``).
    key : str
        The scene key naming it, for the error message.

    Returns
    -------
    dict
        One table per section or part (``mechanism``, ``crankshaft``, ``rod``, ...).

    Examples
    --------
    >>> import crankmodal as cm
    >>> sorted(cm.load_machine("four_star_compressor"))
    ['crankshaft', 'dynamics', 'mechanism', 'rod']
    """
    return load_toml(machine_path(name, key))


def scene_path(name: str) -> Path:
    """Path of a ready scene shipped with crankmodal (``scenes/<name>.toml``).

    Parameters
    ----------
    name : str
        The scene's file stem, e.g. ``four_star_compressor`` (the main job).

    Returns
    -------
    Path

    Examples
    --------
    >>> import crankmodal as cm
    >>> cm.scene_path("four_star_compressor").name
    'four_star_compressor.toml'
    """
    for d in _dirs("scenes"):
        p = d / f"{name}.toml"
        if p.is_file():
            return p
    raise InputFileError(f"no ready scene named {name!r}")
