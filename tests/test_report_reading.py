"""The scene report as an engineer reads it (issue 25 #15): bars shown as bars, numbers without
exponent notation, verdicts that name their tolerance, free-free effective masses explained, the
crank torque's sign stated, plot legends listing only curves that can be seen."""

import html as htmlmod
import re

import numpy as np
import pytest

from crankmodal.report.modal_report import Report, modal_blocks
from crankmodal.report.scene_report import dynamics_blocks
from crankmodal.runner import run
from crankmodal.scene import scene_from_dict

pytestmark = pytest.mark.filterwarnings("ignore::crankmodal.errors.ModelWarning")

J = [0.3, 0.6, 0.18]  # kg m^2
K = [1.32e5, 1.98e5]  # N m/rad
SCENE = {
    "mechanism": {"machine": "four_star_compressor"},
    "torsion": {"inertias": J, "stiffnesses": K, "operating_speed_rpm": 1480.0,
                "speed_range_rpm": [0.0, 3000.0]},
    "report": {},
}


@pytest.fixture(scope="module")
def mech_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("reading")
    res = run(scene_from_dict(SCENE, name="four_star_reading", base_dir=tmp), tmp / "out")
    return tmp / "out", res


def _text(html: str) -> str:
    """The page's visible text (pictures and tags removed, entities decoded)."""
    html = re.sub(r"<img [^>]*>", "", html)
    return htmlmod.unescape(re.sub(r"<[^>]+>", " ", html))


def _section(html: str, title_end: str) -> str:
    parts = re.split(r"<h2>(.*?)</h2>", html)
    found = [parts[k + 1] for k in range(1, len(parts) - 1, 2)
             if htmlmod.unescape(parts[k]).endswith(title_end)]
    assert len(found) == 1, title_end
    return found[0]


def test_html_shows_a_bar_as_a_bar_and_only_markdown_escapes_it():
    rep = Report("t")
    rep.table(["section", "summary"], [["[mechanism]", "|F1| 2959 N"]])
    assert "\\|" not in rep.to_html() and "<td>|F1| 2959 N</td>" in rep.to_html()
    assert "\\|F1\\|" in rep.to_markdown()


def test_mechanism_and_torsion_report_prints_no_exponents_and_no_escaped_bars(mech_report):
    out, _ = mech_report
    text = _text((out / "report.html").read_text())
    assert not re.findall(r"\S*\d[eE][+-]?\d+\S*", text)
    assert "\\|" not in text and "|F1|" in text
    # ranges with an en dash, never a hyphen between two numbers with a unit
    assert not re.search(r"\d-\d[\d.]* ?[kMGmµ]?(N|Hz|rpm)\b", text)


def test_dynamics_numbers_in_engineering_units():
    """The issue's 5.266e+04 N and 1.098e+04 W: as kN and kW."""
    rep = Report("t")
    dynamics_blocks(rep, {"main_bearing_force_peak_n": 52660.0, "drive_power_mean_w": 10980.0,
                          "energy_balance_error": 2.0e-6, "speed_rpm": 1480.0,
                          "ideal": {"main_bearing_force_peak_n": 6333.0}})
    text = _text(rep.to_html())
    assert "52.66 kN" in text and "10.98 kW" in text and "6333 N" in text
    assert not re.search(r"\d[eE][+-]?\d", text)


def test_crank_torque_sign_is_stated_and_the_compressor_takes_its_power_from_the_crank(
        mech_report):
    """Energy over a cycle at constant speed: the drive supplies the indicated power and the
    friction work, so the rods' mean torque on the crank is -(P_i / omega + W_f / 2 pi)."""
    out, res = mech_report
    m = res["mechanism"]
    expected = m["indicated_power_w"] / m["omega_rad_s"] + m["friction_work_per_cycle_j"] / (
        2 * np.pi)
    sec = _text(_section((out / "report.html").read_text(), "[mechanism]"))
    assert "positive in the sense of rotation" in sec
    found = re.search(r"the drive delivers ([\d.]+) N m on average", sec)
    assert found, sec
    assert float(found.group(1)) == pytest.approx(expected, rel=1e-3)  # 4 digits printed
    assert "mechanism_crank_torque.png" in m["files"]


def test_critical_speed_verdicts_name_the_margin_they_judge_against(mech_report):
    """Critical speeds from the chain's own eigenproblem (scipy), 60 f / q; each row's verdict
    agrees with |n_c - 1480| / 1480 against the required 10 %."""
    from scipy.linalg import eigh

    out, _ = mech_report
    kk = np.diag([K[0], K[0] + K[1], K[1]]) - np.diag(K, 1) - np.diag(K, -1)
    f = np.sqrt(np.clip(eigh(kk, np.diag(J), eigvals_only=True), 0, None)) / (2 * np.pi)
    sec = _section((out / "report.html").read_text(), "[torsion]")
    table = sec.split("Critical speeds")[1]
    rows = re.findall(r"<tr>(.*?)</tr>", table)[1:]
    assert rows
    for row in rows:
        cells = [htmlmod.unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)]
        mode, speed, verdict = int(cells[0]), float(cells[3]), cells[5]
        order = float(cells[2])
        assert speed == pytest.approx(60.0 * f[mode] / order, rel=5e-4)
        inside = abs(speed - 1480.0) / 1480.0 <= 0.10
        assert verdict == ("INSIDE ±10 %" if inside else "clear of ±10 %")


def _modal(held: bool) -> dict:
    em = 0.8 if held else 1e-14
    return {"frequencies_hz": [1192.3, 1589.2], "classes": ["bending", "bending"],
            "total_mass_kg": 8.1, "rigid_body_modes": 0 if held else 6,
            "effective_mass": {c: [em, 0.0] for c in ("x_kg", "y_kg", "z_kg", "rx_kgm2",
                                                      "ry_kgm2", "rz_kgm2")},
            "residuals": [1e-11, 1e-11]}


def test_free_free_modes_leave_out_the_zero_effective_mass_columns_and_say_why():
    rep = modal_blocks(Report("t"), geometry={}, material={}, modal=_modal(False),
                       versions_table=False)
    page = rep.to_html()
    assert "m_eff" not in page and "J_eff" not in page
    assert "6 rigid-body modes carry the whole mass" in page
    held = modal_blocks(Report("t"), geometry={}, material={}, modal=_modal(True),
                        versions_table=False).to_html()
    assert held.count("m_eff") == 3 and held.count("J_eff") == 3


def _captured_figures(monkeypatch, tmp_path, sections=("mechanism",)) -> dict:
    """Run the scene's ``sections`` and keep each figure as it is saved (name -> Figure)."""
    from crankmodal import results

    figs = {}
    save = results.savefig_atomic

    def spy(fig, path, **kw):
        figs[str(path).rsplit("/", 1)[-1]] = fig
        return save(fig, path, **kw)

    monkeypatch.setattr(results, "savefig_atomic", spy)
    run(scene_from_dict({k: SCENE[k] for k in sections}, name="m", base_dir=tmp_path),
        tmp_path / "out")
    return figs


def _visible(xy: np.ndarray, scale: float) -> bool:
    return float(np.max(np.abs(xy))) > 1e-3 * scale


def test_plot_legends_list_only_curves_that_can_be_seen(monkeypatch, tmp_path):
    """Four-star balance (seed 000): the 2nd order cancels and the counterweight takes the
    whole 1st-order resultant, so those two polar curves are zero and must not be in the
    legend; the series acceleration is drawn only when it differs visibly from the exact one."""
    figs = _captured_figures(monkeypatch, tmp_path)
    curves = np.load(tmp_path / "out" / "mechanism_curves.npz")
    ax = figs["mechanism_shaking_polar.png"].axes[0]
    scale = max(float(np.max(np.abs(line.get_xydata()))) for line in ax.get_lines())
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    for line in ax.get_lines():
        if line.get_label() in legend:
            assert _visible(line.get_xydata(), scale), line.get_label()
    zero_cw = curves["shaking_force"] + curves["counterweight_force"]
    assert not _visible(zero_cw / 1e3, scale) and not _visible(curves["order_force"][1] / 1e3,
                                                                scale)
    assert legend == ["total", "reciprocating order 1"]
    note = " ".join(t.get_text() for t in ax.texts)
    assert "with counterweight (zero)" in note and "reciprocating order 2 (zero)" in note
    # accelerations: a dashed series is drawn only if a reader can tell it from the exact curve
    ax1 = figs["mechanism_accelerations.png"].axes[0]
    a, a_s = curves["a"], curves["a_series"]
    diff, peak = float(np.max(np.abs(a - a_s))), float(np.max(np.abs(a)))
    dashed = [ln for ln in ax1.get_lines() if ln.get_linestyle() == "--"]
    if "dashed" in ax1.get_title():
        assert dashed and diff > 5e-3 * peak
    else:
        assert not dashed
        shown = re.search(r"within ([\d.]+) m/s²", ax1.get_title())
        assert shown and float(shown.group(1)) == pytest.approx(diff, rel=0.05)  # 2 digits
    # the crank torque's axis says its sign
    ylabel = figs["mechanism_crank_torque.png"].axes[0].get_ylabel()
    assert "on the crankshaft" in ylabel and "+ in the sense of rotation" in ylabel


def test_cancelled_forces_of_the_four_star_read_zero_not_piconewtons(mech_report):
    """Four-star balance (seed 000, Table 1): the 2nd-order forces of the four cylinders cancel
    and the counterweight takes the constant 1st-order resultant, so both compute to round-off
    (~1e-13 N) and the table says 0, against a 1st-order force of m_s r omega^2 per pair."""
    out, res = mech_report
    m = res["mechanism"]
    assert m["second_order_force_max_n"] < 1e-9 * m["first_order_force_max_n"]
    sec = _text(_section((out / "report.html").read_text(), "[mechanism]"))
    for label in ("2nd-order force, max", "1st-order residual with counterweight",
                  "shaking force with counterweight, max"):
        assert re.search(rf"{re.escape(label)}\s+0 N \(round-off\)", sec), label
    assert "pN" not in sec and "× 10⁻¹" not in sec


def test_per_revolution_statistics_carry_units_with_the_spread_in_the_means_prefix():
    from crankmodal.report.scene_report import _stat_rows

    stats = {"window": {}, "main_bearing_force": {
        "per_rev_peak": {"mean": 16600.0, "std": 3148.0, "sem": 1817.0},
        "rms": {"mean": 4611.0, "std": 0.07437, "sem": 0.03326}},
        "clearance_joints": {"big_end_1": {"impact_velocity": {
            "count_per_rev": {"mean": 35.67, "std": 9.018, "sem": 5.207},
            "max_per_rev": {"mean": 0.6244, "std": 0.2021, "sem": 0.1167}}}}}
    rows = {r[0]: r[1:] for r in _stat_rows(stats)}
    assert rows["main bearing force: per rev peak"] == ["16.6 kN", "3.148 kN", "1.817 kN"]
    assert rows["main bearing force: rms"] == ["4611 N", "0.07437 N", "0.03326 N"]
    assert rows["clearance joints: big end 1: impact velocity: count per rev"] == [
        "35.67", "9.018", "5.207"]
    assert rows["clearance joints: big end 1: impact velocity: max per rev"] == [
        "0.6244 m/s", "0.2021 m/s", "0.1167 m/s"]


def test_figure_titles_and_axis_labels_print_no_exponent_notation(monkeypatch, tmp_path):
    """The Holzer residual's axis read 'asinh(residual / 2.77e+04 N m)'."""
    figs = _captured_figures(monkeypatch, tmp_path, ("mechanism", "torsion"))
    assert "torsion_holzer_residual.png" in figs
    for name, fig in figs.items():
        for ax in fig.axes:
            for text in (ax.get_title(), ax.get_xlabel(), ax.get_ylabel()):
                assert not re.search(r"\d[eE][+-]?\d", text), (name, text)


@pytest.mark.parametrize("reference", [None, [100.0, 210.0]])
def test_convergence_title_promises_dashed_lines_only_when_they_are_drawn(monkeypatch, tmp_path,
                                                                         reference):
    from crankmodal.report import plots

    figs = []
    save = plots.savefig_atomic
    monkeypatch.setattr(plots, "savefig_atomic", lambda fig, p, **kw: (figs.append(fig),
                                                                       save(fig, p, **kw)))
    runs = [{"fidelity": "full", "order": 2, "n_dofs": n, "mesh_size": h,
             "frequencies_hz": [100.0 + 1e3 / n, 210.0 + 1e3 / n]}
            for n, h in ((1000, 0.02), (8000, 0.01))]
    plots.plot_convergence(runs, tmp_path / "c.png", reference_hz=reference)
    ax = figs[0].axes[0]
    dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"]
    assert ("dashed" in ax.get_title()) == bool(dashed) == (reference is not None)
