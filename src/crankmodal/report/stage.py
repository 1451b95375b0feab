"""The ``[report]`` scene section: modal report (HTML + Markdown), renders, plots, studies.

Needs ``[geometry]``, ``[material]`` and ``[modal]`` (it reads the Part, the Material and the
:class:`~crankmodal.fem.modal.Modes` from ``ctx.products``); a ``[static]`` section adds a von
Mises render. Writes ``report.html`` (self-contained), ``report.md``, ``mode_NN.png``,
``mode_sheet.png`` (+ ``mode_NN.gif`` when ``gif``), ``participation.png/.csv`` (supported
parts),
``mac.png/.csv`` (with ``reference``), ``von_mises.png``; with ``study = true`` also the
simplification study's files (see :mod:`crankmodal.report.study_scene`).
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError
from ..schema import Field
from ..schema import validate as validate_table

SECTION = "report"
REQUIRES = ("geometry", "material", "modal")

SCHEMA: dict[str, Field] = {
    "title": Field("str", None, "report title (default: the part's name and fidelity)"),
    "renders": Field("bool", True, "render every mode shape off-screen (pyvista) with one camera"),
    "max_renders": Field("int", 12, "render at most this many modes", ge=1, le=100),
    "gif": Field("bool", False, "also an animated GIF per rendered mode"),
    "stress": Field("bool", True, "render von Mises stress when the scene has [static]"),
    "measured_hz": Field("floats", None, "measured natural frequencies of the first modes, Hz "
                         "(seed 000 crank: [1356, 1489]; rod: [780, 1115, 1687])", gt=0.0),
    "measured_modes": Field("ints", None, "computed mode number (from 1) of each measured_hz "
                            "value (default 1, 2, ...)", ge=1),
    "reference": Field("str", None, "reference modes for the MAC matrix: another run's modes.vtu "
                       "or an .npz {points (m), shapes, frequencies_hz}; relative to the scene"),
    "reference_max_distance": Field("float", None, "drop reference points farther than this "
                                    "from every node, m (default 2 % of the part's size)", gt=0.0),
    "study": Field("bool", False, "also run the mesh-simplification study"),
    "study_fidelities": Field("strs", None, "fidelities of the study (default all three)",
                              choices=("full", "dechamfered", "simplified")),
    "study_sizes": Field("floats", None, "mesh sizes of the study, m (default: geometry "
                         "mesh_size x [2, 1.41, 1])", gt=0.0),
    "study_orders": Field("ints", None, "element orders of the study (default [1, 2])",
                          check=lambda v: None if set(v) <= {1, 2} and v else
                          "must be a non-empty list of 1 and/or 2"),
    "study_modes": Field("int", None, "modes tabulated in the study (default min(n_modes, 6))",
                         ge=1, le=50),
    "study_reference": Field("str", "auto", "reference of the study's errors: auto (measured_hz "
                             "when given, else computed), computed (Richardson of the finest "
                             "full model), measured", choices=("auto", "computed", "measured")),
    "compared_modes": Field("int", None, "modes entering a model's error (default: the measured "
                            "ones, else all tabulated)", ge=1),
    "tolerance": Field("float", 0.05, "admissible relative frequency error for the study's "
                       "recommendation", gt=0.0, lt=1.0),
}


def validate(raw: dict, scene) -> dict:
    p = validate_table(SECTION, raw, SCHEMA)
    if p["reference"] is not None:
        from ..errors import InputFileError

        path = scene.resolve(p["reference"])
        if not path.is_file():
            raise InputFileError(f"report.reference: file not found: {path}")
        if path.suffix.lower() not in (".vtu", ".npz"):
            raise SceneError(f"report.reference: must be a .vtu or .npz file, got {path.name}")
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
    from .mac import load_reference, mac_matrix, pair_modes, sample_at

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
    from ..fem.modal import Modes
    from ..results import to_jsonable
    from .modal_report import Report, modal_blocks, write_report

    part = ctx.products.get("geometry")
    modes = ctx.products.get("modal")
    if not isinstance(modes, Modes):
        raise SceneError("[report] needs the Modes of [modal] in the run")
    res = ctx.results
    modal_res = res.get("modal", {})
    geo_res = res.get("geometry") or part.summary()
    out_dir = ctx.out_dir
    out: dict = {}
    renders = None
    images = []
    n_r = min(p["max_renders"], len(modes.frequencies_hz))
    labels = modal_res.get("classes")
    if p["renders"] and ctx.figures:
        from .render import render_modes

        cells = part.mesh.cells[0].data
        renders = render_modes(part.mesh.points, cells, modes.frequencies_hz[:n_r],
                               modes.shapes[:, :n_r], out_dir,
                               labels=labels[:n_r] if labels else None, gif=p["gif"])
        out["renders"] = [str(x) for x in renders["modes"]]
        out["gifs"] = [str(x) for x in renders["gifs"]]
        if renders["sheet"]:
            out["contact_sheet"] = str(renders["sheet"])
        static = ctx.products.get("static")
        if static is not None and p["stress"]:
            from .render import render_scalar

            vm = render_scalar(renders["surface"], static.von_mises, out_dir / "von_mises.png",
                               f"von Mises stress, max {static.max_von_mises / 1e6:.4g} MPa",
                               renders["camera"], displacement=static.displacement)
            images.append((vm, "Static load case: von Mises stress on the deformed shape"))
            out["von_mises_render"] = str(vm)
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

        out["measured_comparison"] = compare_frequencies(modes.frequencies_hz, measured,
                                                         rtol=1.0)
        for r in out["measured_comparison"]:
            del r["rtol"], r["ok"]
    timings = {f"[{s}]": r["wall_time_s"] for s, r in res.items()
               if isinstance(r, dict) and "wall_time_s" in r}
    for k, v in (modal_res.get("timings_s") or {}).items():
        timings[f"modal: {k}"] = v
    title = p["title"] or f"Modal report: {part.name} ({part.fidelity}, P{part.element_order})"
    rep = Report(title)
    scene = ctx.scene
    rep.paragraph(f"Scene {scene.name!r}" + (f" ({scene.path})" if scene.path else "")
                  + (f": {' '.join(scene.description.split())}" if scene.description else "."))
    rep.table(["section", "wall time, s", "summary"],
              [[f"[{s}]", f"{r.get('wall_time_s', 0.0):.3g}", r.get("summary", "")]
               for s, r in res.items() if isinstance(r, dict)])
    rep = modal_blocks(rep, geometry=to_jsonable(geo_res),
                       material=to_jsonable(res.get("material", {})),
                       modal=to_jsonable(modal_res), renders=renders, mac=mac,
                       measured_hz=measured,
                       timings=timings, extra_images=images)
    if p["study"]:
        from .study_scene import run_simplification

        st, paths = run_simplification(ctx.params, out_dir, figures=ctx.figures,
                                       material=ctx.products.get("material"))
        rep.heading("Mesh-simplification study")
        rep.paragraph(f"Reference per mode: {', '.join(sorted(set(st.reference_source)))}; a "
                      f"model's error is the largest |f − f_ref|/f_ref over the first "
                      f"{st.compared_modes} modes, its cost the wall time to mesh and solve. "
                      f"Modes are paired with the reference model's by MAC on common surface "
                      f"points († marks a mode paired out of rank order).")
        rep.table(*st.table(measured))
        rep.paragraph(f"Recommendation (tolerance {100 * st.tolerance:.3g} %): "
                      f"{st.recommendation_text()}.")
        for key, cap in (("error_vs_time", "Error against run time, Pareto front dashed"),
                         ("convergence", "Frequency against DOF")):
            if key in paths:
                rep.image(paths[key], cap)
        for key in (k for k in paths if k.startswith("mac_")):
            rep.image(paths[key], f"MAC of the finest {key[4:]} model against the reference "
                                  f"model (common surface points)")
        out["study"] = st.to_dict()
    files = write_report(rep, out_dir)
    out.update({k: str(v) for k, v in files.items()})
    f = modes.frequencies_hz
    extra = ""
    if measured:
        worst = max((abs(r["rel_error"]) for r in out["measured_comparison"]
                     if r["rel_error"] is not None), default=0.0)
        extra = f", max {100 * worst:.1f} % off measured"
    out["summary"] = (f"report.html: {len(f)} modes {f[0]:.0f}-{f[-1]:.0f} Hz, "
                      f"{len(out.get('renders', []))} renders{extra}"
                      + (f"; study: {out['study']['recommendation']}" if p["study"] else ""))
    return out
