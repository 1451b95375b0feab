"""The [report] stage end to end on a small bar: HTML self-contained, renders, MAC, bad input."""

import json
import re

import meshio
import numpy as np
import pytest

from crankmodal.errors import InputFileError, SceneError
from crankmodal.fem import testparts
from crankmodal.runner import run
from crankmodal.scene import scene_from_dict

pytest.importorskip("pyvista")

L, B, H = 0.3, 0.03, 0.02


def _scene(tmp_path, report):
    p1 = testparts.bar(L, B, H, divisions=(32, 4, 4), order=1)
    pts, t = p1.mesh.points, p1.mesh.cells[0].data.copy()
    a, b, c = (pts[t[:, k]] - pts[t[:, 0]] for k in (1, 2, 3))
    neg = np.einsum("ij,ij->i", np.cross(a, b), c) < 0
    t[neg] = t[neg][:, [0, 2, 1, 3]]  # the importer wants positive Jacobians
    meshio.write(tmp_path / "bar.vtu", meshio.Mesh(pts, [("tetra", t)]))
    box = lambda x: [x - 1e-6, x + 1e-6, -1.0, 1.0, -1.0, 1.0]
    return scene_from_dict({
        "geometry": {"file": "bar.vtu", "element_order": 1,
                     "regions": [{"name": "root", "box": box(0.0)}, {"name": "tip", "box": box(L)}]},
        "material": {"name": "steel"},
        "modal": {"n_modes": 3, "vtu": False, "supports": [{"region": "root", "fix": "xyz"}]},
        "static": {"supports": [{"region": "root", "fix": "xyz"}],
                   "loads": [{"region": "tip", "force": [0.0, 0.0, -100.0]}], "vtu": False},
        "report": report}, name="bar_report", base_dir=tmp_path)


@pytest.fixture(scope="module")
def bar_report(tmp_path_factory):
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material
    from crankmodal.fem.modal import solve_modes

    tmp = tmp_path_factory.mktemp("report")
    from crankmodal.fem.supports import select, validate_specs

    # reference "test modes": an independent P2 model of the cantilever, at its own nodes
    p2 = testparts.bar(L, B, H, divisions=(16, 2, 2), order=2)
    clamp = select(p2, validate_specs([{"region": "end_x0", "fix": "xyz"}]))
    m2 = solve_modes(assemble(p2, material("steel")), 3, clamp)
    np.savez(tmp / "ref.npz", points=p2.mesh.points, shapes=m2.shapes,
             frequencies_hz=m2.frequencies_hz)
    scene = _scene(tmp, {"title": "Bar", "measured_hz": [1200.0, 1700.0], "reference": "ref.npz",
                         "max_renders": 2})
    res = run(scene, tmp / "out")
    return tmp / "out", res


def test_report_html_is_self_contained_with_every_image_embedded(bar_report):
    out, res = bar_report
    html = (out / "report.html").read_text()
    srcs = re.findall(r'(?:src|href)="([^"]*)"', html)
    assert srcs and all(s.startswith("data:image/") for s in srcs)
    assert "http://" not in html and "https://" not in html
    # the sheet (each mode once, issue 25 #15), von Mises, participation and MAC
    assert len(srcs) == 4
    for f in res["modal"]["frequencies_hz"]:
        assert f"{f:.2f}" in html


def test_markdown_twin_links_pngs_that_exist(bar_report):
    out, _ = bar_report
    md = (out / "report.md").read_text()
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert len(links) == 4 and all((out / x).is_file() for x in links)
    assert "| 1 | 1200.0 |" in md  # measured comparison row


def test_mac_against_an_independent_p2_model_pairs_mode_k_with_mode_k(bar_report):
    out, res = bar_report
    pairs = res["report"]["mac"]["pairs"]
    assert [(i, j) for i, j, _ in pairs] == [(0, 0), (1, 1), (2, 2)]
    assert min(v for *_, v in pairs) > 0.95
    rows = (out / "mac.csv").read_text().splitlines()
    assert len(rows) == 4


def test_results_carry_the_measured_comparison_and_a_summary(bar_report):
    out, res = bar_report
    rep = json.loads((out / "results.json").read_text())["report"]
    cmp = rep["measured_comparison"]
    f = res["modal"]["frequencies_hz"]
    assert cmp[0]["rel_error"] == pytest.approx(f[0] / 1200.0 - 1.0, rel=1e-12)
    assert "report.html" in rep["summary"] and "renders" in rep["summary"]
    assert (out / "von_mises.png").is_file() and len(rep["renders"]) == 2
    # file names relative to the output folder (issue 20)
    assert rep["renders"] == ["mode_01.png", "mode_02.png"] and rep["html"] == "report.html"
    assert rep["von_mises_render"] == "von_mises.png" and rep["contact_sheet"] == "mode_sheet.png"
    assert rep["sections"] == ["geometry", "material", "modal", "static"]


def test_cantilever_first_mode_carries_61_percent_of_the_mass_in_participation_csv(bar_report):
    """Euler-Bernoulli cantilever: the first mode's effective mass is 0.6131 of the total."""
    out, _ = bar_report
    rows = (out / "participation.csv").read_text().splitlines()
    first = dict(zip(rows[0].split(","), rows[1].split(",")))
    assert float(first["z_fraction"]) == pytest.approx(0.6131, abs=0.01)
    assert float(first["x_fraction"]) < 1e-6


def test_bad_report_keys_name_the_key_and_the_range(tmp_path):
    from crankmodal.runner import check

    with pytest.raises(SceneError, match=r"report.tolerance: must be < 1"):
        check(_scene(tmp_path, {"tolerance": 1.5}))
    with pytest.raises(SceneError, match=r"report.study_orders: must be a non-empty list"):
        check(_scene(tmp_path, {"study_orders": [3]}))
    with pytest.raises(InputFileError, match=r"report.reference: file not found"):
        check(_scene(tmp_path, {"reference": "nope.npz"}))
    with pytest.raises(SceneError, match=r"report.colour: unknown key"):
        check(_scene(tmp_path, {"colour": "red"}))


def test_study_of_an_imported_mesh_says_it_cannot_remesh(tmp_path):
    from crankmodal.report.study_scene import simplification_study

    with pytest.raises(SceneError, match="report.study: a mesh file cannot be re-meshed"):
        simplification_study(_scene(tmp_path, {}), tmp_path / "out")


def test_without_figures_the_report_has_tables_but_no_pictures_and_no_pyvista_run(tmp_path):
    res = run(_scene(tmp_path, {"measured_hz": [200.0]}), tmp_path / "out", figures=False)
    html = (tmp_path / "out" / "report.html").read_text()
    assert "<img" not in html and "<table>" in html
    assert not list((tmp_path / "out").glob("*.png"))
    assert res["report"]["measured_comparison"][0]["expected_hz"] == 200.0


def test_measured_modes_place_each_measured_value_at_its_computed_mode(tmp_path):
    from crankmodal.report.stage import measured_by_mode

    assert measured_by_mode([1115.0, 780.0], [3, 1]) == [780.0, None, 1115.0]
    assert measured_by_mode([780.0, 1115.0]) == [780.0, 1115.0]
    with pytest.raises(SceneError, match="report.measured_modes: must be 2 distinct"):
        measured_by_mode([780.0, 1115.0], [1, 1])
    with pytest.raises(SceneError, match="report.measured_modes: needs report.measured_hz"):
        measured_by_mode(None, [1])


def test_markdown_cells_with_a_bar_keep_the_table_columns():
    from crankmodal.report.modal_report import Report

    rep = Report("t")
    rep.table(["section", "summary"], [["[mechanism]", "|F1| 2959 N"]])
    row = next(ln for ln in rep.to_markdown().splitlines() if ln.startswith("| [mechanism]"))
    assert row.replace("\\|", "").count("|") == 3  # two cells: three unescaped bars


def test_a_static_scene_without_modal_reports_part_material_and_stress_with_its_render(tmp_path):
    """[report] no longer needs [modal] (issue 20): geometry, material and static each get their
    section; the von Mises render (own camera) is embedded in the static one."""
    scene = _scene(tmp_path, {})
    del scene.sections["modal"]
    res = run(scene, tmp_path / "out")
    html = (tmp_path / "out" / "report.html").read_text()
    heads = re.findall(r"<h2>(.*?)</h2>", html)
    assert [h for h in heads if h.endswith("]")] == ["Part and mesh [geometry]",
                                                     "Material [material]",
                                                     "Static stress [static]"]
    static = html.split("<h2>Static stress [static]</h2>")[1].split("<h2>")[0]
    assert static.count("<img ") == 1 and f"{res['static']['max_von_mises_pa'] / 1e6:.4g}" in static
    assert res["report"]["von_mises_render"] == "von_mises.png"
    assert re.search(r"<h1>Report: ", html) and res["report"]["sections"] == ["geometry",
                                                                              "material", "static"]


def _embedded(html: str) -> list[bytes]:
    import base64

    return [base64.b64decode(m) for m in re.findall(r'<img src="data:image/\w+;base64,([^"]+)"',
                                                     html)]


def test_measured_verdicts_name_their_tolerance_and_agree_with_it(bar_report):
    """Issue 25 #15: a difference from the measured frequency is judged against
    report.tolerance (5 % by default), and the row says so."""
    out, res = bar_report
    html = (out / "report.html").read_text()
    f = res["modal"]["frequencies_hz"]
    assert "against the tolerance ±5 % (report.tolerance)" in html
    for k, measured in enumerate([1200.0, 1700.0]):
        err = f[k] / measured - 1.0
        row = re.search(rf"<tr><td[^>]*>{k + 1}</td><td[^>]*>{measured:.1f}</td>(.*?)</tr>",
                        html).group(1)
        assert ("within ±5 %" if abs(err) <= 0.05 else "OUTSIDE ±5 %") in row
    cmp = res["report"]["measured_comparison"]
    assert [r["ok"] for r in cmp] == [abs(f[k] / m - 1.0) <= 0.05
                                      for k, m in enumerate([1200.0, 1700.0])]
    assert all(r["rtol"] == 0.05 for r in cmp)


def test_each_mode_render_is_shown_once(bar_report, tmp_path):
    """Issue 25 #15: the contact sheet holds every mode, so the single renders are not embedded
    again; with gif = true the animations show the modes, and neither sheet nor stills."""
    out, res = bar_report
    pics = _embedded((out / "report.html").read_text())
    assert pics.count((out / "mode_sheet.png").read_bytes()) == 1
    for name in res["report"]["renders"]:
        assert (out / name).read_bytes() not in pics
    res = run(_scene(tmp_path, {"gif": True, "max_renders": 2, "stress": False}),
              tmp_path / "out")
    pics = _embedded((tmp_path / "out" / "report.html").read_text())
    gifs = [(tmp_path / "out" / g).read_bytes() for g in res["report"]["gifs"]]
    assert len(gifs) == 2 and all(pics.count(g) == 1 for g in gifs)
    for name in res["report"]["renders"] + ["mode_sheet.png"]:
        assert (tmp_path / "out" / name).read_bytes() not in pics


def test_modal_report_text_has_no_exponent_notation_and_no_escaped_bars(bar_report):
    """Issue 25 #15, on the FE part's report (mode table residuals, timings, static stress):
    every number engineering-formatted; pictures and tags left out of the text."""
    import html as htmlmod

    out, _ = bar_report
    page = re.sub(r"<img [^>]*>", "", (out / "report.html").read_text())
    text = htmlmod.unescape(re.sub(r"<[^>]+>", " ", page))
    assert not re.findall(r"\S*\d[eE][+-]?\d+\S*", text)
    assert "\\|" not in text


def test_participation_legend_lists_only_directions_a_mode_moves(bar_report, tmp_path,
                                                                 monkeypatch):
    """The cantilever's first modes bend (y, z): their axial (x) effective mass is round-off,
    so x gets neither bars nor a flat cumulative line in the legend, and the note names it."""
    from crankmodal.report import plots

    out, _ = bar_report
    rows = [r.split(",") for r in (out / "participation.csv").read_text().splitlines()[1:]]
    f = [float(r[1]) for r in rows]
    frac = np.array([[float(v) for v in r[2:5]] for r in rows])
    assert frac[:, 0].max() < 1e-4 * frac.max()  # bending: no axial mass (FE: 6e-6 of 0.61)
    figs = []
    save = plots.savefig_atomic
    monkeypatch.setattr(plots, "savefig_atomic", lambda fig, p, **kw: (figs.append(fig),
                                                                       save(fig, p, **kw)))
    plots.plot_participation(f, np.hstack([frac, np.zeros((len(f), 3))]), 1.0,
                             tmp_path / "p.png")
    ax = figs[0].axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert not [t for t in legend if t.startswith("x ")]
    assert "not drawn: x translation (zero)" in [t.get_text() for t in ax.texts]
    for name in "yz":
        if frac[:, "xyz".index(name)].max() > 1e-3 * frac.max():
            assert f"{name} translation" in legend and f"{name} cumulative" in legend
