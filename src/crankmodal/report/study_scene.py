"""The simplification study of a scene: ``crankmodal study simplification SCENE``.

The scene's ``[geometry]`` (a built machine part, or a CAD file), ``[material]`` and ``[modal]``
(supports, backend) say what to solve; the ``study_*`` keys of its ``[report]`` section (or
their defaults) say which fidelities, mesh sizes and element orders to run.
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import SceneError
from ..geometry.params import FIDELITIES
from .keys import SCHEMA as REPORT_SCHEMA
from .study import MAX_PROBES, SimplificationStudy, evaluate, write_study


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
    from ..errors import scene_keys
    from ..fem.assembly import assemble
    from ..fem.modal import solve_modes
    from ..fem.supports import select

    def solve(part):
        model = assemble(part, material)
        with scene_keys("modal"):  # as the [modal] stage: its supports, tol, backend
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


#: The study's models are points of the sweep engine, stored under ``<out>/models/``.
MODELS_DIR = "models"


def solve_model(out_dir, geometry: dict, modal: dict, material, fidelity: str, mesh_size: float,
                order: int, n_modes: int) -> dict:
    """One model of the study, as a sweep point (:func:`crankmodal.sweep.execute._call`): build
    the part, solve its modes, keep its nodes, surface nodes and mode shapes in
    ``out_dir/model.npz`` (for the MAC pairing, done once every model is in) and return its
    run (:class:`~crankmodal.report.study.SimplificationStudy`) without the shapes.

    ``material`` is a Material or the validated ``[material]`` table.
    """
    from pathlib import Path

    from ..results import atomic_path
    from .render import boundary_surface

    if isinstance(material, dict):
        from ..fem.material_stage import make_material

        material = make_material(material)
    from ..geometry.mesh import MeshSizeError

    t0 = time.perf_counter()
    try:
        part = part_builder(geometry)(fidelity, mesh_size, order)
    except MeshSizeError as exc:  # the core names 'size'; the scene's words, as the stage's
        from ..errors import ResourceError

        raise ResourceError(exc.worded("geometry.mesh_size", "geometry.params.")) from None
    t1 = time.perf_counter()
    modes = modes_solver(modal, material, n_modes)(part)
    t2 = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data).points
    with atomic_path(out / "model.npz") as tmp:
        np.savez(tmp, points=np.asarray(part.mesh.points, float),
                 shapes=np.asarray(modes.shapes, float), surface=np.asarray(surf, float))
    return {"fidelity": fidelity, "mesh_size": float(mesh_size), "order": int(order),
            "n_elements": part.n_elements, "n_nodes": part.n_nodes,
            "n_dofs": int(modes.n_dofs), "mesh_time_s": t1 - t0,
            "solve_time_s": t2 - t1, "wall_time_s": t2 - t0,
            "frequencies_hz": np.asarray(modes.frequencies_hz, float).tolist()}


def model_tasks(geometry, modal, material, s: dict, n_modes: int, store_dir) -> list[dict]:
    """Sweep tasks of the study's models, in its order: fidelity, order, size (coarse first).

    A model's key hashes the [geometry], [modal] and [material] it is solved with and its
    (fidelity, size, order, modes): a re-run of the same study skips the models recorded."""
    import hashlib
    import json

    base = json.dumps([geometry, modal, material if isinstance(material, dict) else
                       repr(material)], sort_keys=True, default=repr)
    tasks = []
    for fid in s["fidelities"]:
        for order in s["orders"]:
            for h in sorted(s["sizes"], reverse=True):
                model = {"fidelity": fid, "mesh_size": float(h), "order": int(order)}
                key = hashlib.sha256(f"{base}\0{fid}\0{float(h)!r}\0{int(order)}\0{n_modes}"
                                     .encode()).hexdigest()[:16]
                tasks.append({"index": len(tasks), "key": key, "parameters": model,
                              "call": "crankmodal.report.study_scene:solve_model",
                              "kwargs": {"geometry": geometry, "modal": modal,
                                         "material": material, "n_modes": n_modes, **model},
                              "dir": str(store_dir / "points" / key), "outputs": [],
                              "timeout_s": None, "figures": False, "round": 0})
    return tasks


def run_models_on_engine(geometry, modal, material, s: dict, n_modes: int, out_dir, log=None,
                         engine: str = "dask", client=None, scheduler=None, workers=None):
    """Every model of the study as a point of the sweep engine; the runs as
    :func:`crankmodal.report.study.run_models` returns them (with ``probe_shapes``).

    ``engine = "dask"``: on a Dask cluster (``client``, ``scheduler`` address, or a local
    cluster of ``workers`` processes, one BLAS thread each); ``"in-process"``: one after
    another here, with the same records (also the fallback when Dask is not installed).
    Records go to ``out_dir/models/records.jsonl`` as models finish; a re-run skips the
    recorded ones, a failed model is run again.

    Raises
    ------
    CrankmodalError
        The first failed model's error (its class's exit code: 2 input, 3 numerical).
    """
    import contextlib
    from pathlib import Path

    from ..errors import CrankmodalError, NumericalError
    from ..sweep.driver import LazyClient, run_tasks, run_tasks_in_process
    from ..sweep.store import RecordStore, folder_lock
    from .mac import sample_at

    if workers is not None and workers < 1:
        raise CrankmodalError(f"--workers: must be >= 1, got {workers}")
    store_dir = Path(out_dir).resolve() / MODELS_DIR
    store_dir.mkdir(parents=True, exist_ok=True)
    tasks = model_tasks(geometry, modal, material, s, n_modes, store_dir)
    if engine == "dask" and not scheduler and client is None:
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            engine = "in-process"
            if log:
                log("study: Dask is not installed ('sweep' extra): the models run one after "
                    "another in this process")
    with folder_lock(store_dir), contextlib.ExitStack() as stack:
        store = RecordStore(store_dir / "records.jsonl")
        done = {k: r for k, r in store.read().items() if r.get("status") == "ok"}
        if log and done:
            log(f"study: {sum(t['key'] in done for t in tasks)} of {len(tasks)} models "
                f"recorded in {store_dir}, not run again")
        if engine == "in-process":
            run_tasks_in_process(tasks, store, done, log)
        else:
            run_tasks(LazyClient(stack, client, scheduler, workers, log), tasks, store, done, log)
    for t in tasks:
        rec = done[t["key"]]
        if rec["status"] != "ok":
            cls = NumericalError if rec.get("exit_code") == 3 else CrankmodalError
            raise cls(f"study: model {SimplificationStudy.label(t['parameters'])}: "
                      f"{rec['error']}")
    runs, probes = [], None
    for t in tasks:
        rec = done[t["key"]]
        run = dict(rec["outputs"])
        with np.load(store_dir / rec["dir"] / "model.npz") as z:  # dir: relative to the store
            if probes is None:  # the first model's surface nodes, thinned out
                surf = z["surface"]
                probes = surf[::max(1, len(surf) // MAX_PROBES)]
            run["probe_shapes"], _ = sample_at(z["points"], z["shapes"], probes)
        runs.append(run)
        if log:
            log(f"  {SimplificationStudy.label(run)}: {run['n_elements']} elements, "
                f"{run['wall_time_s']:.1f} s, f1 = {run['frequencies_hz'][0]:.1f} Hz")
    return runs


def run_simplification(params: dict, out_dir, log=None, figures: bool = True, material=None,
                       engine: str = "in-process", client=None, scheduler=None, workers=None):
    """Run the study for validated scene parameters (section -> params).

    Every model (fidelity x mesh size x element order) is a point of the sweep engine
    (:func:`run_models_on_engine`): on a Dask cluster with ``engine = "dask"`` (``client``,
    ``scheduler``, ``workers``; what ``crankmodal study`` does), or one after another in this
    process (``"in-process"``, the default: the report stage inside ``crankmodal run``, which
    starts no cluster - it may itself be a sweep's point in a Dask worker).

    Returns
    -------
    (SimplificationStudy, dict of written paths)
    """
    from ..fem.material_stage import make_material
    from ..fem.modal_stage import SCHEMA as MODAL_SCHEMA
    from ..schema import validate as validate_table

    for need in ("geometry", "material"):
        if need not in params:
            raise SceneError(f"study: the scene needs a [{need}] section")
    g = params["geometry"]
    modal = params.get("modal") or validate_table("modal", {}, MODAL_SCHEMA)
    modal.setdefault("supports", [])
    rep = params.get("report") or validate_table("report", {}, REPORT_SCHEMA)
    # the workers rebuild the Material from its table (a given Material goes as it is)
    mat = material or params["material"]
    if not isinstance(mat, dict):
        mat = material
    else:
        make_material(mat)  # a bad [material] is refused here, not once per model
    part_builder(g)  # a mesh file that cannot be re-meshed is refused before any model runs
    s = study_settings(rep, g, modal)
    if log:
        log(f"study: {len(s['fidelities'])} fidelities x {len(s['sizes'])} sizes x "
            f"{len(s['orders'])} orders, {s['n_modes']} modes")
    # two spare modes, so a mode that a simplification moves up still finds its partner
    runs = run_models_on_engine(g, modal, mat, s, s["n_modes"] + 2, out_dir, log=log,
                                engine=engine, client=client, scheduler=scheduler,
                                workers=workers)
    measured = rep.get("measured_by_mode") if rep.get("study_reference") != "computed" else None
    st = evaluate(runs, s["n_modes"], measured_hz=measured,
                  tolerance=rep["tolerance"], compared_modes=rep.get("compared_modes"))
    title = f"Mesh-simplification study: {g.get('machine') or g.get('file')} {g.get('part', '')}"
    paths = write_study(st, out_dir, measured_hz=rep.get("measured_by_mode"), title=title,
                        figures=figures)
    return st, paths


def simplification_study(scene, out_dir, log=None, figures: bool = True, *, engine="dask",
                         client=None, scheduler=None, workers=None) -> dict:
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
    engine, client, scheduler, workers
        Where the models run (:func:`run_models_on_engine`): a local Dask cluster by default.

    Returns
    -------
    dict
        The study (``to_dict()``) with a one-line ``summary``; also written to ``study.json``.
    """
    from ..results import make_out_dir, write_json_atomic
    from ..runner import check

    params = check(scene)
    out_dir = make_out_dir(out_dir)
    st, paths = run_simplification(params, out_dir, log=log, figures=figures, engine=engine,
                                   client=client, scheduler=scheduler, workers=workers)
    out = {**st.to_dict(), "files": {k: str(v) for k, v in paths.items()},
           "summary": f"{len(st.runs)} models; recommended: {st.recommendation_text()}"}
    write_json_atomic(out_dir / "study.json", out)
    return out
