"""The report of the whole scene (issue 20 #2): a scene running [mechanism], [torsion] and
[dynamics] gets one section per stage with its verdict and every figure it lists embedded; the
title names the machine; results.json names files relative to the output folder; the dynamics
orbit and piston plots show the last revolutions."""

import base64
import html as htmlmod
import json
import re
from pathlib import Path

import numpy as np
import pytest

from crankmodal.errors import SceneError
from crankmodal.runner import check, run
from crankmodal.scene import scene_from_dict

pytestmark = pytest.mark.filterwarnings("ignore::crankmodal.errors.ModelWarning")

SCENE = {
    "mechanism": {"machine": "four_star_compressor", "n_points": 90},
    "torsion": {"inertias": [0.3, 0.6, 0.18], "stiffnesses": [1.32e5, 1.98e5],
                "operating_speed_rpm": 1480.0, "speed_range_rpm": [0.0, 3000.0]},
    # 0.02 s ramp + about 1.2 revolutions at 1480 rpm: clearance impacts, orbit, spectrum
    "dynamics": {"machine": "four_star_compressor", "end_time": 0.07, "ramp_time": 0.02},
    "report": {},
}


@pytest.fixture(scope="module")
def scene_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("scene_report")
    res = run(scene_from_dict(SCENE, name="small_four_star", base_dir=tmp), tmp / "out")
    return tmp / "out", res


def _sections(html: str) -> dict:
    """``<h2>`` title -> the HTML up to the next ``<h2>``."""
    parts = re.split(r"<h2>(.*?)</h2>", html)
    return {htmlmod.unescape(parts[k]): parts[k + 1] for k in range(1, len(parts) - 1, 2)}


def _embedded(section_html: str) -> list[bytes]:
    return [base64.b64decode(m) for m in
            re.findall(r'<img src="data:image/png;base64,([^"]+)"', section_html)]


@pytest.mark.parametrize("stage, key", [("torsion", "files"), ("mechanism", "files"),
                                        ("dynamics", "figures")])
def test_each_stage_has_its_section_with_verdict_and_every_listed_figure_embedded(
        scene_report, stage, key):
    out, res = scene_report
    html = (out / "report.html").read_text()
    sec = [body for title, body in _sections(html).items() if title.endswith(f"[{stage}]")]
    assert len(sec) == 1, f"no single section for [{stage}]"
    pngs = [n for n in res[stage][key] if n.endswith(".png")]
    assert len(pngs) >= 3
    # each listed PNG is in its stage's section, byte for byte, in the listed order
    assert _embedded(sec[0]) == [(out / n).read_bytes() for n in pngs]
    assert htmlmod.escape(f"Summary: {res[stage]['summary']}") in sec[0]
    for w in res[stage].get("warnings") or []:
        assert htmlmod.escape(w) in sec[0]


def test_report_is_self_contained_titled_by_the_machine_with_the_stage_tables(scene_report):
    out, res = scene_report
    html = (out / "report.html").read_text()
    srcs = re.findall(r'(?:src|href)="([^"]*)"', html)
    assert srcs and all(s.startswith("data:image/") for s in srcs)
    title = re.search(r"<h1>(.*?)</h1>", html).group(1)
    assert title.startswith("Four star compressor") and "dynamics" in title
    # the numbers behind the verdicts: balance, critical speeds, clearance joint
    for text in ("Balance", "2nd-order force cancelled", "Critical speeds", "Clearance joints",
                 f"{res['torsion']['exact_hz'][0]:.4g}",
                 f"{res['mechanism']['counterweight_mass_radius_kg_m']:.4g}"):
        assert text in html
    n_png = sum(len([n for n in res[s].get(k, []) if n.endswith(".png")])
                for s, k in (("torsion", "files"), ("mechanism", "files"),
                             ("dynamics", "figures")))
    assert html.count("<img ") == n_png == res["report"]["figures_embedded"]
    assert res["report"]["sections"] == ["torsion", "mechanism", "dynamics"]


def test_results_name_files_relative_to_the_output_folder(scene_report):
    out, _ = scene_report
    res = json.loads((out / "results.json").read_text())
    assert res["report"]["html"] == "report.html" and res["report"]["markdown"] == "report.md"
    strings = []

    def walk(x):
        if isinstance(x, dict):
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
        elif isinstance(x, str):
            strings.append(x)

    walk(res)
    assert not [s for s in strings if str(out) in s or s.startswith("/")]
    md = (out / "report.md").read_text()
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert links and all(not Path(x).is_absolute() and (out / x).is_file() for x in links)


def test_report_keys_that_need_modes_are_refused_without_modal(tmp_path):
    for key, value in (("measured_hz", [1356.0]), ("study", True)):
        scene = scene_from_dict({"mechanism": SCENE["mechanism"], "report": {key: value}},
                                name="x", base_dir=tmp_path)
        with pytest.raises(SceneError, match=rf"report.{key}: needs the part's modes; the "
                                             rf"scene has no \[geometry\], \[material\], "
                                             rf"\[modal\]"):
            check(scene)


def test_a_nested_block_with_its_own_figures_becomes_a_subsection(tmp_path):
    """Generic: whatever a stage lists under a nested ``figures`` (here the flexible-vs-rigid
    block of [dynamics]) is shown under its own heading, once, with its comparison table."""
    from PIL import Image

    from crankmodal.report.modal_report import Report
    from crankmodal.report.scene_report import stage_section

    for k, name in enumerate(("a.png", "b.png", "flex_new.png")):
        Image.new("RGB", (4, 4), (40 * k, 0, 0)).save(tmp_path / name)
    res = {"summary": "ok", "figures": ["a.png", "flex_new.png", "b.png", "missing.png"],
           "flexible": {"figures": ["flex_new.png"],
                        "bodies": {"crank": {"n_modes": 6, "frequencies_hz": [1190.0],
                                             "mass_kg": 8.1,
                                             "interface_deflection_max_m": {"pin": 2e-6}}},
                        "rigid": {"main_bearing": {"peak_n": 6544.0, "rigid_peak_n": 6438.0,
                                                   "rms_n": 3000.0, "rigid_rms_n": 2990.0,
                                                   "relative_difference_rms": 0.026}}}}
    rep = Report("t")
    stage_section(rep, "dynamics", res, tmp_path)
    kinds = [(b[0], b[1] if b[0] != "img" else b[1].name) for b in rep.blocks
             if b[0] in ("h2", "h3", "img")]
    assert kinds == [("h2", "Dynamics [dynamics]"), ("img", "a.png"), ("img", "b.png"),
                     ("h3", "Flexible vs rigid"), ("img", "flex_new.png")]
    html = rep.to_html()
    assert "6544" in html and "2.6 % of rigid RMS" in html and "crank" in html


def test_last_revolutions_selects_by_crank_angle_turned_in_either_sense():
    from types import SimpleNamespace

    from crankmodal.dynamics.results.plots import last_revolutions

    a = np.linspace(0.0, 5 * 2 * np.pi, 501)  # five turns
    for sign in (1.0, -1.0):
        m = last_revolutions(SimpleNamespace(crank_angle=sign * a), 2)
        assert m.sum() == 201 and m[-201:].all()
    assert last_revolutions(SimpleNamespace(crank_angle=a[:50]), 2).all()


def _orbit_hist():
    from types import SimpleNamespace

    t = np.linspace(0.0, 1.0, 4001)
    ang = 2 * np.pi * 5 * t  # five revolutions
    # early: a tangle out to 3c; the last two revolutions: a spiral from 0.2 c to 0.9 c
    last = ang >= ang[-1] - 4 * np.pi
    r = np.where(last, 0.2 + 0.7 * (ang - ang[-1] + 4 * np.pi) / (4 * np.pi), 3.0) * 1e-4
    return SimpleNamespace(t=t, crank_angle=ang, contact={"j": {
        "ex_bearing": r * np.cos(7 * ang), "ey_bearing": r * np.sin(7 * ang)}}), last


def test_orbit_draws_the_last_revolutions_coloured_by_time_and_the_circle_bold():
    from matplotlib.figure import Figure

    from crankmodal.dynamics.results.plots import draw_orbit, last_revolutions

    hist, last = _orbit_hist()
    ax = Figure().subplots()
    lc = draw_orbit(ax, hist, "j", 1e-4, last_revolutions(hist, 2))
    times = np.asarray(lc.get_array())
    assert len(lc.get_segments()) == last.sum() - 1
    assert times.min() > hist.t[last][0] and times.max() < 1.0  # coloured by time, last 2 revs
    seg = np.concatenate(lc.get_segments())
    assert np.hypot(seg[:, 0], seg[:, 1]).max() == pytest.approx(0.9, abs=1e-6)  # in units of c
    (circle,) = ax.get_lines()
    assert circle.get_linewidth() >= 2.0 > lc.get_linewidth()[0] and circle.get_zorder() > 2
    assert np.hypot(*circle.get_data()) == pytest.approx(1.0)
    assert ax.get_xlim() == pytest.approx((-1.15, 1.15))  # the early 3c tangle is left out


def test_orbit_png_is_written_in_colour(tmp_path):
    from PIL import Image

    from crankmodal.dynamics.results.plots import plot_orbit

    hist, _ = _orbit_hist()
    img = np.asarray(Image.open(plot_orbit(hist, {"j": 1e-4}, tmp_path / "o.png")).convert("RGB"))
    img = img.astype(int)
    coloured = (img.max(axis=2) - img.min(axis=2)) > 80
    assert coloured.sum() > 1000 and np.all(img < 60, axis=2).sum() > 1000


def test_piston_plot_draws_the_ideal_run_dashed_on_top_and_the_last_revolutions(monkeypatch,
                                                                               tmp_path):
    """The ideal (clearance-free) curve was hidden under the clearance trace: it is drawn black,
    dashed, above it in every panel; the middle and right panels hold the last 2 revolutions."""
    from types import SimpleNamespace

    from crankmodal.dynamics.results import plots

    t = np.linspace(0.0, 0.25, 2501)
    ang = -2 * np.pi * 20.0 * t  # five revolutions, turning in the negative sense
    ideal = SimpleNamespace(t=t, crank_angle=ang, piston_velocity=np.sin(ang)[:, None],
                            piston_acceleration=np.cos(ang)[:, None])
    rough = SimpleNamespace(t=t, crank_angle=ang, piston_velocity=np.sin(ang)[:, None],
                            piston_acceleration=(np.cos(ang) + 5 * np.sin(40 * ang))[:, None])
    figs = []
    monkeypatch.setattr(plots, "_save", lambda plt, fig, path: figs.append(fig) or path)
    plots.plot_piston(rough, ideal, tmp_path / "p.png")
    axes = figs[0].axes
    assert len(axes) >= 2
    for ax in axes:
        lines = ax.get_lines()
        ideal_line = [ln for ln in lines if ln.get_linestyle() == "--"]
        other = [ln for ln in lines if ln.get_linestyle() != "--"]
        assert len(ideal_line) == 1 and other
        assert ideal_line[0].get_zorder() > max(ln.get_zorder() for ln in other)
    last = axes[1].get_lines()[0].get_xdata()
    assert len(last) == 1001 and min(last) == pytest.approx(0.0) and max(last) == pytest.approx(720)


def test_the_drive_torques_sign_is_stated_and_holds_in_the_run(scene_report):
    """Issue 25 #15: the four-star crank turns from +y towards +x, i.e. about -z, so the
    torque that drives it is negative about +z while the power it delivers (a compressor takes
    power) is positive; the report says so under the dynamics table."""
    out, _ = scene_report
    d = np.load(out / "dynamics.npz")
    late = d["t"] > 0.03  # after the 0.02 s ramp
    assert np.all(d["crank_speed"][late] < 0)
    assert np.mean(d["drive_torque"][late]) < 0 < np.mean(d["drive_power"][late])
    sec = next(b for t, b in _sections((out / "report.html").read_text()).items()
               if t.endswith("[dynamics]"))
    text = htmlmod.unescape(sec)
    assert "the drive torque is the torque the drive applies to the crank about +z" in text
    assert "its driving torque is negative while the power is positive" in text


def test_the_whole_report_text_prints_no_exponent_notation(scene_report):
    """Issue 25 #15 across every section, the stages' own summaries included (the dynamics
    summary's energy balance read 2.0e-06 and its spread 1.599e+04-3.456e+04 N)."""
    out, _ = scene_report
    page = re.sub(r"<img [^>]*>", "", (out / "report.html").read_text())
    text = htmlmod.unescape(re.sub(r"<[^>]+>", " ", page))
    # a scene key's value echoed for the user to edit keeps the form one types in TOML
    text = re.sub(r"\(now [^)]*\)", "", text)
    assert not re.findall(r"\S*\d[eE][+-]?\d+\S*", text)
    assert not re.search(r"\d-\d[\d.]* ?[kMGmµ]?(N|Hz|rpm)\b", text)
