"""The scene runner: validate every section, run only the stages asked for, write results.

Each stage is a module ``crankmodal.<pkg>.stage`` that imports nothing heavy at module level and
provides

``SECTION``
    the scene section it owns;
``REQUIRES``
    sections whose products it needs (they must be present in the scene);
``validate(raw: dict, scene: Scene) -> dict``
    checks the raw table, returns parameters (raises SceneError);
``run(params: dict, ctx: StageContext) -> dict``
    computes, writes its figures/arrays into ``ctx.out_dir``, stores any object later stages
    need in ``ctx.products[SECTION]``, and returns its JSON-able results.

Stage modules are imported only when their section is present, so a ``[mechanism]`` scene never
loads gmsh, scikit-fem or pyvista.
"""

from __future__ import annotations

import importlib
import time
from dataclasses import dataclass, field
from pathlib import Path

from . import __version__
from .errors import OutputError, SceneError
from .results import make_out_dir, output_error, write_json_atomic
from .scene import Scene

#: section -> stage module, in data-flow order (a stage runs after everything above it).
STAGES: dict[str, str] = {
    "geometry": "crankmodal.geometry.stage",
    "material": "crankmodal.fem.material_stage",
    "modal": "crankmodal.fem.modal_stage",
    "static": "crankmodal.fem.static_stage",
    "reduction": "crankmodal.reduction.stage",
    "torsion": "crankmodal.torsion.stage",
    "mechanism": "crankmodal.mechanism.stage",
    "dynamics": "crankmodal.dynamics.scene.stage",
    "fatigue": "crankmodal.fatigue.stage",
    "report": "crankmodal.report.stage",
}


@dataclass
class StageContext:
    """What a running stage sees: the scene, where to write, and earlier stages' products."""

    scene: Scene
    out_dir: Path
    products: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)
    results: dict = field(default_factory=dict)
    figures: bool = True


def stage_module(section: str):
    """Import the stage module owning ``section``."""
    if section not in STAGES:
        allowed = ", ".join(STAGES)
        raise SceneError(f"[{section}]: unknown section; allowed sections are: {allowed}")
    try:
        return importlib.import_module(STAGES[section])
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.startswith("crankmodal"):
            raise SceneError(
                f"[{section}]: this stage is not available in crankmodal {__version__} yet"
            ) from None
        raise


def plan(scene: Scene) -> list[str]:
    """Sections of the scene in run order, with their prerequisites checked."""
    order = [s for s in STAGES if s in scene.sections]
    for s in scene.sections:
        if s not in STAGES:
            stage_module(s)  # raises the unknown-section error
    if not order:
        raise SceneError(f"scene {scene.name!r} has no sections; allowed: {', '.join(STAGES)}")
    for s in order:
        for need in getattr(stage_module(s), "REQUIRES", ()):
            if need not in scene.sections:
                raise SceneError(f"[{s}] needs a [{need}] section in the scene")
    return order


def _check_scene(scene) -> Scene:
    from .arguments import instance

    return instance("scene", scene, Scene, "a Scene (load_scene, scene_from_dict, scene_path)")


def check(scene: Scene) -> dict[str, dict]:
    """Validate every section without running anything; returns the parameters per section.

    Parameters
    ----------
    scene : Scene
        From :func:`load_scene`, :func:`scene_from_dict` or :func:`scene_path`.

    Returns
    -------
    dict
        Section name -> its validated parameters (defaults filled in, SI units).

    Raises
    ------
    ParameterError
        ``scene`` is not a :class:`~crankmodal.scene.Scene`.
    SceneError
        A scene key is unknown, of the wrong type, or out of its range.

    Examples
    --------
    >>> import crankmodal as cm
    >>> scene = cm.scene_from_dict({"mechanism": {"machine": "four_star_compressor"}})
    >>> cm.check_scene(scene)["mechanism"]["speed_rpm"]
    1480.0
    >>> cm.check_scene(cm.scene_from_dict({"mechanism": {"speed_rpm": -5.0}}))
    Traceback (most recent call last):
    ...
    crankmodal.errors.SceneError: mechanism.speed_rpm: must be > 0, got -5.0
    """
    _check_scene(scene)
    return {s: stage_module(s).validate(scene.sections[s], scene) for s in plan(scene)}


def run(scene: Scene, out_dir: str | Path, figures: bool = True, log=None) -> dict:
    """Run a scene and write ``out_dir/results.json`` atomically.

    Parameters
    ----------
    scene : Scene
        The scene to run.
    out_dir : str or Path
        Output folder (created). A stale ``results.json`` there is removed once the scene has
        validated, so a failed run never leaves an old result looking new. Every file is
        written atomically (:func:`crankmodal.results.atomic_path`).
    figures : bool
        Write PNG plots.
    log : callable, optional
        ``log(str)`` for progress lines.

    Returns
    -------
    dict
        The results as written.

    Raises
    ------
    ParameterError
        ``scene`` is not a Scene, ``out_dir`` not a path, ``figures`` not a bool or ``log`` not
        callable (before anything runs).
    OutputError
        If the folder or a file in it cannot be written (a file in the way, read-only, disk
        full); no results.json is left.
    """
    from .arguments import instance, path

    _check_scene(scene)
    path("out_dir", out_dir)
    instance("figures", figures, bool, "True or False")
    if log is not None and not callable(log):
        from .errors import ParameterError

        raise ParameterError("log", f"must be None or a function of one str, got {log!r:.60}")
    params = check(scene)
    out_dir = make_out_dir(out_dir)
    try:
        (out_dir / "results.json").unlink(missing_ok=True)
    except OSError as exc:  # a read-only folder: say so before any stage computes
        raise output_error(exc, out_dir / "results.json") from None
    results: dict = {"crankmodal_version": __version__, "scene": scene.name}
    ctx = StageContext(scene=scene, out_dir=out_dir, params=params, results=results, figures=figures)
    for section, p in params.items():
        if log:
            log(f"[{section}] running")
        t0 = time.perf_counter()
        try:
            res = stage_module(section).run(p, ctx) or {}
        except OSError as exc:
            # A file that does not go through results.atomic_path (a plugin's writer, a reader):
            # one line naming the file and the system's reason, as for every I/O error.
            raise OutputError(f"[{section}]: {output_error(exc)}") from None
        res["wall_time_s"] = time.perf_counter() - t0
        results[section] = res
        if log:
            log(f"[{section}] done in {res['wall_time_s']:.2f} s")
    write_json_atomic(out_dir / "results.json", results)
    return results
