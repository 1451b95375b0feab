"""The simplification study of a scene: ``crankmodal study simplification SCENE``.

The scene's ``[geometry]`` (a built machine part, or a CAD file), ``[material]`` and ``[modal]``
(supports, backend) say what to solve; the ``study_*`` keys of its ``[report]`` section (or
their defaults) say which fidelities, mesh sizes and element orders to run.
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..geometry.params import FIDELITIES


def part_builder(geometry: dict):
    """``build(fidelity, mesh_size, order) -> Part`` for validated ``[geometry]`` parameters."""
    from ..geometry.mesh import MeshSettings

    def settings(h, order):
        return MeshSettings(size=h, order=order, refine=geometry["refine"],
                            optimize=geometry["optimize"])

    if geometry.get("file") is not None:
        from ..geometry.importers import CAD_SUFFIXES, import_cad

        if not geometry["file"].lower().endswith(CAD_SUFFIXES):
            raise SceneError("report.study: a mesh file cannot be re-meshed; give a CAD file "
                             "(STEP/IGES/BREP) or a machine part in [geometry]")
        return lambda fid, h, order: import_cad(geometry["file"], geometry["region_specs"],
                                                settings(h, order))
    from ..geometry.build import build_part

    name = (f"{geometry['machine']}/{geometry['part']}" if geometry.get("machine")
            else geometry["part"])
    return lambda fid, h, order: build_part(geometry["part_params"], fid, settings(h, order),
                                            name=name)


def modes_solver(modal: dict, material, n_modes: int):
    """``solve(part) -> Modes`` with the ``[modal]`` supports and backend."""
    from ..fem.assembly import assemble
    from ..fem.modal import solve_modes
    from ..fem.supports import select

    def solve(part):
        model = assemble(part, material)
        return solve_modes(model, n_modes, select(part, modal["supports"], "modal"),
                           backend=modal["backend"], tol=modal["tol"])

    return solve


def study_settings(report: dict, geometry: dict, modal: dict) -> dict:
    """Fidelities, sizes (m), orders and mode count of the study, defaults filled in."""
    h = geometry["mesh_size"]
    sizes = report.get("study_sizes") or [2.0 * h, np.sqrt(2.0) * h, h]
    fids = list(report.get("study_fidelities") or FIDELITIES)
    if geometry.get("file") is not None:
        fids = ["imported"]
    n = report.get("study_modes") or min(modal["n_modes"], 6)
    return {"fidelities": fids, "sizes": sorted(map(float, sizes), reverse=True),
            "orders": list(report.get("study_orders") or (1, 2)), "n_modes": int(n)}


def run_simplification(params: dict, out_dir, log=None, figures: bool = True, material=None):
    """Run the study for validated scene parameters (section -> params).

    Returns
    -------
    (SimplificationStudy, dict of written paths)
    """
    from ..fem.material_stage import make_material
    from ..fem.modal_stage import SCHEMA as MODAL_SCHEMA
    from ..schema import validate as validate_table
    from .stage import SCHEMA as REPORT_SCHEMA
    from .study import evaluate, run_models, write_study

    for need in ("geometry", "material"):
        if need not in params:
            raise SceneError(f"study: the scene needs a [{need}] section")
    g = params["geometry"]
    modal = params.get("modal") or validate_table("modal", {}, MODAL_SCHEMA)
    modal.setdefault("supports", [])
    rep = params.get("report") or validate_table("report", {}, REPORT_SCHEMA)
    mat = material or make_material(params["material"])
    s = study_settings(rep, g, modal)
    if log:
        log(f"study: {len(s['fidelities'])} fidelities x {len(s['sizes'])} sizes x "
            f"{len(s['orders'])} orders, {s['n_modes']} modes")
    # two spare modes, so a mode that a simplification moves up still finds its partner
    runs = run_models(part_builder(g), modes_solver(modal, mat, s["n_modes"] + 2),
                      s["fidelities"], s["sizes"], s["orders"], log=log)
    measured = rep.get("measured_by_mode") if rep.get("study_reference") != "computed" else None
    st = evaluate(runs, s["n_modes"], measured_hz=measured,
                  tolerance=rep["tolerance"], compared_modes=rep.get("compared_modes"))
    title = f"Mesh-simplification study: {g.get('machine') or g.get('file')} {g.get('part', '')}"
    paths = write_study(st, out_dir, measured_hz=rep.get("measured_by_mode"), title=title,
                        figures=figures)
    return st, paths


def simplification_study(scene, out_dir, log=None, figures: bool = True) -> dict:
    """``crankmodal study simplification SCENE --out DIR``: run the study, write its files.

    Parameters
    ----------
    scene : Scene
        With ``[geometry]``, ``[material]``, optionally ``[modal]`` (supports, backend) and
        ``[report]`` (``study_*`` keys, ``measured_hz``, ``tolerance``); other sections are
        validated but not run.
    out_dir : str or Path
        Receives ``study.md``, ``study.csv``, ``error_vs_time.png/.csv``,
        ``convergence.png/.csv`` and ``study.json``.
    log : callable, optional
        ``log(str)`` progress lines.

    Returns
    -------
    dict
        The study (``to_dict()``) with a one-line ``summary``; also written to ``study.json``.
    """
    from ..results import make_out_dir, write_json_atomic
    from ..runner import check

    params = check(scene)
    out_dir = make_out_dir(out_dir)
    st, paths = run_simplification(params, out_dir, log=log, figures=figures)
    out = {**st.to_dict(), "files": {k: str(v) for k, v in paths.items()},
           "summary": f"{len(st.runs)} models; recommended: {st.recommendation_text()}"}
    write_json_atomic(out_dir / "study.json", out)
    return out
