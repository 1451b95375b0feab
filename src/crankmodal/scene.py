"""Scenes: TOML files whose sections say what to compute.

A scene is read with :mod:`tomllib`, ``--set section.key=value`` overrides are applied, and every
section that names a ``machine`` gets that machine's table of the same name (from ``geometry/``)
as defaults underneath its own values. Stage-specific checking is done by each stage's
``validate`` (see :mod:`crankmodal.runner`).
"""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import SceneError
from .resources import load_machine, load_toml

#: Top-level scalar keys a scene may carry besides its sections.
TOP_LEVEL_KEYS = ("name", "description")


@dataclass
class Scene:
    """A parsed scene.

    Attributes
    ----------
    name : str
        Scene name (``name`` key, else the file stem); names the default output folder.
    base_dir : Path
        Folder against which relative file names in the scene are resolved.
    sections : dict
        Raw section tables, after overrides and machine defaults; not yet validated.
    path : Path or None
        The scene file, if read from one.
    description : str
        Free text.
    """

    name: str
    base_dir: Path
    sections: dict[str, dict] = field(default_factory=dict)
    path: Path | None = None
    description: str = ""

    def resolve(self, filename: str) -> Path:
        """A file name from the scene, relative to the scene's folder."""
        p = Path(filename).expanduser()
        return p if p.is_absolute() else (self.base_dir / p)


def deep_merge(base: dict, over: dict) -> dict:
    """``over`` on top of ``base``; nested tables merge, everything else is replaced."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def parse_value(text: str) -> Any:
    """A ``--set`` value: TOML syntax if it parses (``1480``, ``[1, 2]``, ``true``), else a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_override(tables: dict, assignment: str) -> None:
    """Apply one ``section.key[.sub]=value`` assignment in place.

    A numeric path element indexes an array of tables: ``dynamics.clearances.0.clearance=2e-4``.
    """
    if "=" not in assignment:
        raise SceneError(f"--set {assignment!r}: expected section.key=value")
    dotted, _, text = assignment.partition("=")
    parts = [p.strip() for p in dotted.strip().split(".")]
    if len(parts) < 2 or not all(parts):
        raise SceneError(f"--set {assignment!r}: expected section.key=value")
    node = tables
    for i, p in enumerate(parts):
        last = i == len(parts) - 1
        where = ".".join(parts[: i + 1])
        if isinstance(node, list):
            if not p.isdigit() or int(p) >= len(node):
                raise SceneError(f"--set {dotted}: {where} is not an entry of a {len(node)}-entry list")
            p = int(p)
        elif not isinstance(node, dict):
            raise SceneError(f"--set {dotted}: {'.'.join(parts[:i])} is not a table")
        if last:
            node[p] = parse_value(text.strip())
        else:
            if isinstance(node, dict):
                node = node.setdefault(p, {})
            else:
                node = node[p]


def scene_from_dict(
    data: dict,
    name: str = "scene",
    base_dir: Path | str = ".",
    overrides: list[str] | tuple[str, ...] = (),
    path: Path | None = None,
) -> Scene:
    """Build a :class:`Scene` from a TOML-like dict (the programmatic entry point).

    Parameters
    ----------
    data : dict
        Scene tables as a TOML file would hold them: ``name``, ``description`` and one table per
        section; a section's ``machine = "NAME"`` pulls its defaults from the machine file.
    name : str
        Scene name when ``data`` has none (names the output folder).
    base_dir : Path or str
        Folder that relative file names in the scene are resolved against.
    overrides : sequence of str
        ``section.key=value`` assignments in TOML syntax, as ``crankmodal run --set``.
    path : Path, optional
        The file the scene came from, if any.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        An unknown top-level key, a section that is not a table, an unknown machine or a bad
        override (the message names the key).

    Examples
    --------
    >>> import crankmodal as cm
    >>> scene = cm.scene_from_dict({"mechanism": {"machine": "four_star_compressor"}},
    ...                            name="api", overrides=["mechanism.speed_rpm=740"])
    >>> scene.name, sorted(scene.sections), scene.sections["mechanism"]["speed_rpm"]
    ('api', ['mechanism'], 740)
    """
    from collections.abc import Mapping

    from .arguments import instance

    instance("data", data, Mapping, "a dict of scene sections ({'torsion': {...}, ...})")
    data = copy.deepcopy(data)
    # A machine named by --set must be known before its defaults are merged; every other
    # override is applied on top of the merged tables, so it can reach into machine lists.
    for assignment in overrides:
        if assignment.partition("=")[0].strip().endswith(".machine"):
            apply_override(data, assignment)
    sections = {}
    for key, value in data.items():
        if key in TOP_LEVEL_KEYS:
            if not isinstance(value, str):
                raise SceneError(f"{key}: must be a string, got {value!r}")
            continue
        if not isinstance(value, dict):
            raise SceneError(
                f"{key}: unknown top-level key; a scene holds {', '.join(TOP_LEVEL_KEYS)} and sections"
            )
        sections[key] = with_machine_defaults(key, value)
    for assignment in overrides:
        apply_override(sections, assignment)
    return Scene(
        name=data.get("name", name),
        base_dir=Path(base_dir),
        sections=sections,
        path=path,
        description=data.get("description", ""),
    )


def with_machine_defaults(section: str, table: dict) -> dict:
    """Underlay the machine's table named like the section, when the section names a machine."""
    machine = table.get("machine")
    if machine is None:
        return table
    if not isinstance(machine, str):
        raise SceneError(f"{section}.machine: must be a string, got {machine!r}")
    tables = load_machine(machine, key=f"{section}.machine")
    defaults = tables.get(section)
    if defaults is None:
        return table
    return deep_merge(defaults, table)


def load_scene(path: str | Path, overrides: list[str] | tuple[str, ...] = ()) -> Scene:
    """Read a scene file.

    Parameters
    ----------
    path : str or Path
        The TOML scene.
    overrides : sequence of str
        ``section.key=value`` assignments applied before validation.
    """
    from .arguments import path as path_argument

    path = Path(path_argument("path", path))
    data = load_toml(path)
    return scene_from_dict(
        data, name=path.stem, base_dir=path.resolve().parent, overrides=overrides, path=path
    )
