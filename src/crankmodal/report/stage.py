"""The ``[report]`` scene section: the report of the whole scene (HTML + Markdown), renders,
plots, studies.

One section per stage the scene ran, each with its verdict (the stage's ``summary`` and
``warnings``), its key tables and every figure it lists (:mod:`crankmodal.report.scene_report`).
With ``[geometry]``, ``[material]`` and ``[modal]`` it adds the modal content (it reads the Part,
the Material and the :class:`~crankmodal.fem.modal.Modes` from ``ctx.products``); a ``[static]``
section adds a von Mises render. Writes ``report.html`` (self-contained), ``report.md``,
``mode_NN.png``, ``mode_sheet.png`` (+ ``mode_NN.gif`` when ``gif``), ``participation.png/.csv``
(supported parts), ``mac.png/.csv`` (with ``reference``), ``von_mises.png``; after a multi-throw
``[dynamics]`` run ``dynamics_journal_shares.png`` and ``dynamics_torsion_orders.png``
(:mod:`crankmodal.dynamics.results.report`, listed as ``train_figures``); with ``study = true`` also the
simplification study's files (see :mod:`crankmodal.report.study_scene`).
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..schema import validate as validate_table
from .keys import MODAL_KEYS, SCHEMA, SECTION

REQUIRES = ()


def validate(raw: dict, scene) -> dict:
    p = validate_table(SECTION, raw, SCHEMA)
    missing = [s for s in ("geometry", "material", "modal") if s not in scene.sections]
    for key in MODAL_KEYS:
        if missing and p[key]:
            raise SceneError(f"report.{key}: needs the part's modes; the scene has no "
                             + ", ".join(f"[{s}]" for s in missing))
    if p["reference"] is not None:
        from ..errors import InputFileError, scene_keys
        from .reference import load_reference

        path = scene.resolve(p["reference"])
        if not path.is_file():
            raise InputFileError(f"report.reference: file not found: {path}")
        if path.suffix.lower() not in (".vtu", ".npz"):
            raise SceneError(f"report.reference: must be a .vtu or .npz file, got {path.name}")
        # the whole file now (members, shapes, finite values), not after the FE solve
        with scene_keys(SECTION, {"path": "reference"}):
            load_reference(path)
        p["reference"] = str(path)
    if p["study_reference"] == "measured" and not p["measured_hz"]:
        raise SceneError("report.study_reference: 'measured' needs report.measured_hz")
    p["measured_by_mode"] = measured_by_mode(p["measured_hz"], p["measured_modes"])
    return p


def measured_by_mode(measured_hz, measured_modes=None) -> list | None:
    """Measured Hz at the index of its computed mode (None where nothing was measured)."""
    if not measured_hz:
        if measured_modes:
            raise SceneError("report.measured_modes: needs report.measured_hz")
        return None
    modes = measured_modes or list(range(1, len(measured_hz) + 1))
    if len(modes) != len(measured_hz) or len(set(modes)) != len(modes):
        raise SceneError(f"report.measured_modes: must be {len(measured_hz)} distinct mode "
                         f"numbers (one per measured_hz value), got {modes}")
    out = [None] * max(modes)
    for k, f in zip(modes, measured_hz):
        out[k - 1] = f
    return out


def _mac(part, modes, p, out_dir, figures):
    from .mac import mac_matrix, pair_modes, sample_at
    from .reference import load_reference

    pts, ref, f_ref = load_reference(p["reference"])
    diag = float(np.linalg.norm(np.ptp(part.mesh.points, axis=0)))
    dmax = p["reference_max_distance"] or 0.02 * diag
    ours, kept = sample_at(part.mesh.points, modes.shapes, pts, max_distance=dmax)
    if len(kept) < 3:
        raise SceneError(f"report.reference: only {len(kept)} reference points lie within "
                         f"{dmax:.3g} m of the part; same units (m) and placement?")
    refk = ref.reshape(len(pts), 3, -1)[kept].reshape(3 * len(kept), -1)
    keep_cols = np.linalg.norm(refk, axis=0) > 0
    refk, f_ref = refk[:, keep_cols], f_ref[keep_cols]
    mac = mac_matrix(ours, refk)
    out = {"matrix": mac, "pairs": pair_modes(mac, 0.5), "points_used": len(kept),
           "source": f"{p['reference']} ({len(kept)} of {len(pts)} points, "
                     f"{refk.shape[1]} modes)", "reference_hz": f_ref}
    if figures:
        from .plots import plot_mac

        rl = [f"{k + 1}: {f:.0f} Hz" for k, f in enumerate(modes.frequencies_hz)]
        cl = [f"{k + 1}: {f:.0f} Hz" if np.isfinite(f) else str(k + 1) for k, f in enumerate(f_ref)]
        out["image"] = plot_mac(mac, out_dir / "mac.png", rl, cl, title="MAC: modes vs reference")
    return out


def run(p: dict, ctx) -> dict:
    """Write ``report.html``/``report.md``: one section per stage the scene ran (its verdict,
    tables and every figure it lists), the modal content when the scene has [modal]."""
    from ..results import to_jsonable
    from .modal_report import Report, versions, write_report
    from .quantity import quantity, quantity_range
    from .scene_report import (
        MODAL_SECTIONS,
        overview_rows,
        relative_name,
        scene_title,
        stage_section,
    )

    out_dir = ctx.out_dir
    results = {s: to_jsonable(r) for s, r in ctx.results.items() if isinstance(r, dict)}
    fe_only = set(results) <= {*MODAL_SECTIONS, "static", "report"}
    modes = ctx.products.get("modal")
    part = ctx.products.get("geometry")
    out: dict = {}
    title = p["title"]
    if title is None:
        kind = "Modal report" if "modal" in results else "Report"
        title = (f"{kind}: {part.name} ({part.fidelity}, P{part.element_order})"
                 if fe_only and part is not None
                 else scene_title(ctx.scene, ctx.params, results))
    rep = Report(title)
    scene = ctx.scene
    rep.paragraph(f"Scene {scene.name!r}" + (f" ({scene.path})" if scene.path else "")
                  + (f": {' '.join(scene.description.split())}" if scene.description else "."))
    rep.table(["section", "wall time", "summary"], overview_rows(results))
    modal = _modal_section(p, ctx, rep, results, out) if "modal" in ctx.params else None
    for section, res in results.items():
        if (modal is not None and section in MODAL_SECTIONS) or section == SECTION:
            continue
        images = []
        vm = modal.get("von_mises") if modal else None
        if section == "static" and vm is None and modal is None:
            vm = _static_render(p, ctx)
            if vm is not None:
                out["von_mises_render"] = relative_name(vm, out_dir)
        if section == "static" and vm is not None:
            images.append((vm, "von Mises stress on the deformed shape"))
        stage_section(rep, section, res, out_dir, images=images)
        if section == "dynamics":  # a multi-throw train: journal shares, torsion, fatigue
            from ..dynamics.results.report import train_section

            drawn = train_section(rep, res, out_dir, results.get("fatigue"), ctx.figures)
            if drawn:
                out["train_figures"] = [relative_name(f, out_dir) for f in drawn]
    if p["study"]:
        _study(p, ctx, rep, out, modal["measured"] if modal else None)
    timings = {f"[{s}]": r["wall_time_s"] for s, r in results.items() if "wall_time_s" in r}
    for k, v in (results.get("modal", {}).get("timings_s") or {}).items():
        timings[f"modal: {k}"] = v
    rep.heading("Timings")
    rep.table(["step", "wall time"], [[k, quantity(v, "s", 3)] for k, v in timings.items()])
    rep.heading("Versions")
    rep.table(["package", "version"], [[k, v] for k, v in versions().items()])
    files = write_report(rep, out_dir)
    out.update({k: relative_name(v, out_dir) for k, v in files.items()})
    n_fig = sum(1 for b in rep.blocks if b[0] == "img")
    sections = [s for s in results if s != SECTION]
    out["sections"] = sections
    out["figures_embedded"] = n_fig
    head = f"report.html: {len(sections)} stages ({', '.join(sections)}), {n_fig} figures"
    if modes is not None and "modal" in results:
        f = modes.frequencies_hz
        extra = ""
        if modal and modal["measured"]:
            extra = ", " + measured_verdict(out["measured_comparison"], p["tolerance"])
        head += (f"; {len(f)} modes {quantity_range(f[0], f[-1], 'Hz')}, "
                 f"{len(out.get('renders', []))} renders{extra}")
    out["summary"] = head + (f"; study: {out['study']['recommendation']}" if p["study"] else "")
    return out


def measured_verdict(rows: list[dict], tolerance: float) -> str:
    """``1 of 2 measured frequencies within ±5 % (worst -12.1 %, mode 1)`` from the rows of
    :func:`~crankmodal.report.testing.compare_frequencies`."""
    from .quantity import percent

    done = [r for r in rows if r["rel_error"] is not None]
    text = (f"{sum(r['ok'] for r in rows)} of {len(rows)} measured frequencies within "
            f"±{percent(tolerance)}")
    if done:
        w = max(done, key=lambda r: abs(r["rel_error"]))
        text += f" (worst {percent(w['rel_error'], sign=True)}, mode {w['mode']})"
    return text


def _modal_section(p, ctx, rep, results, out) -> dict:
    """The FE part's section: renders, participation, MAC, measured comparison, the modal
    tables; fills ``out`` (names relative to the output folder). Returns ``measured`` and the
    von Mises render (for the [static] section)."""
    from ..fem.modal import Modes
    from .modal_report import modal_blocks
    from .scene_report import relative_name, verdict

    part = ctx.products.get("geometry")
    modes = ctx.products.get("modal")
    if not isinstance(modes, Modes):
        raise SceneError("[report] needs the Modes of [modal] in the run")
    modal_res = results.get("modal", {})
    geo_res = results.get("geometry") or to_jsonable_summary(part)
    out_dir = ctx.out_dir
    renders = None
    images = []
    von_mises = None
    n_r = min(p["max_renders"], len(modes.frequencies_hz))
    labels = modal_res.get("classes")
    if p["renders"] and ctx.figures:
        from .render import render_modes

        cells = part.mesh.cells[0].data
        renders = render_modes(part.mesh.points, cells, modes.frequencies_hz[:n_r],
                               modes.shapes[:, :n_r], out_dir,
                               labels=labels[:n_r] if labels else None, gif=p["gif"])
        out["renders"] = [relative_name(x, out_dir) for x in renders["modes"]]
        out["gifs"] = [relative_name(x, out_dir) for x in renders["gifs"]]
        if renders["sheet"]:
            out["contact_sheet"] = relative_name(renders["sheet"], out_dir)
        static = ctx.products.get("static")
        if static is not None and p["stress"]:
            from .render import render_scalar

            von_mises = render_scalar(renders["surface"], static.von_mises,
                                      out_dir / "von_mises.png",
                                      f"von Mises stress, max {static.max_von_mises / 1e6:.4g} MPa",
                                      renders["camera"], displacement=static.displacement)
            out["von_mises_render"] = relative_name(von_mises, out_dir)
    # free-free elastic modes carry no effective mass: the plot only says something when held
    held = float(np.sum(modes.effective_mass[:, :3])) > 1e-6 * modes.total_mass
    if ctx.figures and held:
        from .plots import plot_participation

        pp = plot_participation(modes.frequencies_hz, modes.effective_mass, modes.total_mass,
                                out_dir / "participation.png")
        images.append((pp, "Effective-mass participation"))
    mac = _mac(part, modes, p, out_dir, ctx.figures) if p["reference"] else None
    if mac:
        out["mac"] = {"matrix": mac["matrix"], "pairs": mac["pairs"],
                      "points_used": mac["points_used"]}
    measured = p.get("measured_by_mode")
    if measured:
        from .testing import compare_frequencies

        # rtol and ok: the verdict against report.tolerance, as the report's table shows it
        out["measured_comparison"] = compare_frequencies(modes.frequencies_hz, measured,
                                                         rtol=p["tolerance"])
    rep.heading(f"Part, material and modes: {part.name} [geometry] [material] [modal]")
    for s in MODAL_ORDER:
        if s in results:
            verdict(rep, results[s], label=s)
    if von_mises is not None and "static" not in results:
        images.append((von_mises, "Static load case: von Mises stress on the deformed shape"))
    modal_blocks(rep, geometry=geo_res, material=results.get("material", {}), modal=modal_res,
                 renders=renders, mac=mac, measured_hz=measured, tolerance=p["tolerance"],
                 extra_images=images, level=3,
                 versions_table=False)
    return {"measured": measured, "von_mises": von_mises}


MODAL_ORDER = ("geometry", "material", "modal")


def _static_render(p, ctx):
    """``von_mises.png`` of a scene with [static] but no [modal] (its own camera), or None."""
    part, static = ctx.products.get("geometry"), ctx.products.get("static")
    if not (p["renders"] and p["stress"] and ctx.figures and part is not None
            and static is not None):
        return None
    from .render import boundary_surface, part_camera, render_scalar

    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    return render_scalar(surf, static.von_mises, ctx.out_dir / "von_mises.png",
                         f"von Mises stress, max {static.max_von_mises / 1e6:.4g} MPa",
                         part_camera(surf.points), displacement=static.displacement)


def to_jsonable_summary(part) -> dict:
    """The part's summary as JSON types (when [geometry] left no results)."""
    from ..results import to_jsonable

    return to_jsonable(part.summary())


def _study(p, ctx, rep, out, measured) -> None:
    """The mesh-simplification study (``study = true``) as a section of the report."""
    from .quantity import percent
    from .study_scene import run_simplification

    st, paths = run_simplification(ctx.params, ctx.out_dir, figures=ctx.figures,
                                   material=ctx.products.get("material"))
    rep.heading("Mesh-simplification study")
    rep.paragraph(f"Reference per mode: {', '.join(sorted(set(st.reference_source)))}; a "
                  f"model's error is the largest |f − f_ref|/f_ref over the first "
                  f"{st.compared_modes} modes, its cost the wall time to mesh and solve. "
                  f"Modes are paired with the reference model's by MAC on common surface "
                  f"points († marks a mode paired out of rank order).")
    rep.table(*st.table(measured))
    rep.paragraph(f"Verdict: the cheapest model whose estimated error is within the tolerance "
                  f"±{percent(st.tolerance)} (report.tolerance): {st.recommendation_text()}.")
    for key, cap in (("error_vs_time", "Error against run time, Pareto front dashed"),
                     ("convergence", "Frequency against DOF")):
        if key in paths:
            rep.image(paths[key], cap)
    for key in (k for k in paths if k.startswith("mac_")):
        rep.image(paths[key], f"MAC of the finest {key[4:]} model against the reference "
                              f"model (common surface points)")
    out["study"] = st.to_dict()
