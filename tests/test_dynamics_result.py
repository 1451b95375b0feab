"""DynamicsResult: the stage's dynamics.npz read back (round trip), damaged files refused by
file and member, the documented results fields present, and the figures drawn from a file.

Oracles: the round trip compares the arrays the stage saved with those read back (the same
numbers, so 1e-12 relative is far above any difference a correct reader can make: none; it is
not a bit-equality claim on two computations); the documented fields are the names
docs/guide/dynamics.md, flexible_bodies.md and main_job.md give (SCENES.md: what the README's
pages document is public), each checked to be in the docs as well as in the output.
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from crankmodal.dynamics.results.result import DynamicsResult, MachineInfo
from crankmodal.errors import InputFileError, ParameterError
from crankmodal.runner import run
from crankmodal.scene import scene_from_dict

DOCS = Path(__file__).resolve().parents[1] / "docs" / "guide"
#: a slider crank with a dry big-end clearance and friction: 3.5 revolutions at 3000 rpm, so the
#: results window (after the settling revolution) holds 2 whole revolutions
SCENE = {"dynamics": {
    "mechanism": "slider_crank", "speed_rpm": 3000.0, "end_time": 0.07,
    "gas_force_deg": [0.0, 90.0, 180.0, 270.0, 360.0],
    "gas_force_n": [3000.0, 500.0, 0.0, 500.0, 3000.0],
    "crank_train": {"crank_radius": 0.035, "rod_length": 0.14},
    "clearances": [{"joint": "big_end_1", "clearance": 1e-4, "journal_radius": 0.02,
                    "bearing_length": 0.02}],
    "contact": {"law": "johnson_cylinder"}, "friction": {"law": "coulomb"}}}


def _run_keeping_result(scene: dict, out: Path, monkeypatch) -> tuple[dict, DynamicsResult]:
    """Run a scene through the runner (results.json, dynamics.npz, figures) and keep the
    DynamicsResult the stage saved."""
    kept = []
    save = DynamicsResult.save

    def spy(self, path):
        kept.append(self)
        return save(self, path)

    with monkeypatch.context() as m:
        m.setattr(DynamicsResult, "save", spy)
        res = run(scene_from_dict(scene, name="result"), out, figures=True)
    assert len(kept) == 1
    return res, kept[0]


@pytest.fixture(scope="module")
def stage_run(tmp_path_factory):
    mp = pytest.MonkeyPatch()  # module scope: the fixture's own
    out = tmp_path_factory.mktemp("dyn") / "out"
    try:
        res, result = _run_keeping_result(SCENE, out, mp)
    finally:
        mp.undo()
    return out, res, result


def _close(a, b, path="") -> None:
    """Nested dict/list equality, floats within 1e-12 relative."""
    if isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a:
            _close(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _close(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert b == pytest.approx(a, rel=1e-12, abs=0.0), path
    else:
        assert a == b, path


def _same_history(h, g) -> None:
    for k in ("t", "crank_angle", "crank_speed", "piston_position", "piston_velocity",
              "piston_acceleration", "main_bearing_force", "main_bearing_moment",
              "drive_torque", "drive_power", "constraint_drift"):
        np.testing.assert_allclose(getattr(g, k), getattr(h, k), rtol=1e-12, atol=0.0,
                                   err_msg=k)
    for attr in ("joint_forces", "energy", "angular_acceleration", "modal", "torsion"):
        a, b = getattr(h, attr), getattr(g, attr)
        assert list(a) == list(b), attr
        for k in a:
            np.testing.assert_allclose(b[k], a[k], rtol=1e-12, atol=0.0, err_msg=f"{attr}.{k}")
    for attr in ("contact", "peaks"):
        a, b = getattr(h, attr), getattr(g, attr)
        assert {n: list(d) for n, d in a.items()} == {n: list(d) for n, d in b.items()}
        for n in a:
            for k in a[n]:
                np.testing.assert_allclose(b[n][k], a[n][k], rtol=1e-12, atol=0.0)
    _close({n: [list(e) for e in v] for n, v in h.onsets.items()},
           {n: [list(e) for e in v] for n, v in g.onsets.items()})
    _close({n: list(v) for n, v in h.separations.items()},
           {n: list(v) for n, v in g.separations.items()})
    assert g.nfev == h.nfev and g.wall_time == pytest.approx(h.wall_time, rel=1e-12)


def test_saved_result_loads_back_equal_to_the_run(stage_run, tmp_path):
    out, res, result = stage_run
    loaded = DynamicsResult.load(out / "dynamics.npz")
    _same_history(result.history, loaded.history)
    _same_history(result.ideal, loaded.ideal)
    assert result.ideal is not None and loaded.rigid is None and result.rigid is None
    assert loaded.machine == result.machine
    assert loaded.machine == MachineInfo("slider_crank", 50.0, ("main",), 1, {"big_end_1": 1e-4})
    _close(list(result.window_s), list(loaded.window_s))
    _close(result.to_dict(), loaded.to_dict())
    on_disk = json.loads((out / "results.json").read_text())["dynamics"]
    assert on_disk.pop("wall_time_s") > 0.0  # the runner's timing of the stage, not the run's
    _close(on_disk, loaded.to_dict())
    a, b = result.arrays(), loaded.arrays()
    assert sorted(a) == sorted(b)
    for k in a:
        assert a[k].shape == b[k].shape, k
        np.testing.assert_allclose(b[k], a[k], rtol=1e-12, atol=0.0, err_msg=k)
    # derived numbers from the loaded arrays: the energy balance results.json reports
    assert loaded.energy_balance_error == pytest.approx(res["dynamics"]["energy_balance_error"],
                                                        rel=1e-12)
    # and a loaded result saves the same file again
    again = DynamicsResult.load(loaded.save(tmp_path / "again.npz"))
    for k, v in again.arrays().items():
        np.testing.assert_allclose(v, a[k], rtol=1e-12, atol=0.0, err_msg=k)


def test_torsional_histories_round_trip(stage_run, tmp_path):
    """A crank train with a motor or a flexible crank records ``torsion`` histories
    (``torsion_<name>`` in the file): they come back by name, whatever underscores it holds."""
    out, _, _ = stage_run
    result = DynamicsResult.load(out / "dynamics.npz")
    t = result.history.t
    result.history.torsion = {"motor_speed": 300.0 + np.sin(t), "twist_free_end": 1e-3 * t}
    loaded = DynamicsResult.load(result.save(tmp_path / "torsion.npz"))
    _same_history(result.history, loaded.history)
    assert list(loaded.history.torsion) == ["motor_speed", "twist_free_end"]


def test_loaded_result_draws_the_stage_figures(stage_run, tmp_path):
    out, res, _ = stage_run
    loaded = DynamicsResult.load(out / "dynamics.npz")
    names, flexible = loaded.figures(tmp_path)
    assert names == res["dynamics"]["figures"] and flexible == []
    for name in names:
        assert (tmp_path / name).stat().st_size > 1000
    assert loaded.plot_orbits(tmp_path / "o.png").stat().st_size > 1000
    with pytest.raises(ParameterError, match="no tolerance study"):
        loaded.plot_tolerance_study(tmp_path / "s.png")


# ---- the documented fields ---------------------------------------------------------------
#: results.json ``dynamics`` fields the guide names (page, dotted path from ``dynamics``;
#: ``<joint>``: the run's clearance joint)
DOCUMENTED = [
    ("dynamics.md", "main_bearing_force_peak_n"), ("dynamics.md", "energy_balance_error"),
    ("dynamics.md", "solver_method"), ("dynamics.md", "warnings"), ("dynamics.md", "summary"),
    ("main_job.md", "headline"), ("main_job.md", "peak_window_s"),
    ("dynamics.md", "clearance_joints.<joint>.law"),
    ("dynamics.md", "clearance_joints.<joint>.contact_duration_median_s"),
    ("dynamics.md", "statistics.window.start_s"), ("dynamics.md", "statistics.window.end_s"),
    ("dynamics.md", "statistics.window.n_revolutions"),
    *[("dynamics.md", f"statistics.main_bearing_force.{k}.{s}")
      for k in ("per_rev_peak", "rms") for s in ("mean", "std", "sem", "median", "min", "max",
                                                 "n")],
    *[("dynamics.md", f"statistics.main_bearing_force.{k}.{s}")  # and their `_y`, below
      for k in ("order_amplitude_x", "band_rms_x") for s in ("mean", "sem")],
    ("dynamics.md", "statistics.main_bearing_force.band_rms_x.edges_hz"),
    ("dynamics.md", "statistics.piston_acceleration"),
    ("dynamics.md", "statistics.clearance_joints.<joint>.contact_force.per_rev_peak"),
    ("dynamics.md", "statistics.clearance_joints.<joint>.contact_force.rms"),
    *[("dynamics.md", f"statistics.clearance_joints.<joint>.impact_velocity.{k}")
      for k in ("p50", "p90", "max", "p50_sem", "p90_sem", "count_per_rev", "max_per_rev")],
    ("reports.md", "figures"), ("scenes.md", "arrays"),
]
#: dynamics.npz arrays the guide names, and those outside scripts in this repository read
#: (scenes/plot_seed000_flexible.py: t, crank_angle, main_bearing_force)
DOCUMENTED_ARRAYS = [("dynamics.md", "peaks_<joint>_*"), ("reports.md", "drive_torque")]
SCRIPT_ARRAYS = ["t", "crank_angle", "main_bearing_force"]
#: the PNGs the guide names
DOCUMENTED_FIGURES = ["dynamics_main_bearing", "_piston", "_orbit", "_contact", "_drive",
                      "_energy"]


def _documented(page: str, name: str) -> bool:
    """Whether the guide page names ``name``: each of its dotted parts is a dotted part of a
    name in backticks there."""
    prose = re.sub(r"```.*?```", "", (DOCS / page).read_text(), flags=re.DOTALL)  # no code
    spans = re.findall(r"`([^`]+)`", prose)
    parts = {piece for span in spans for piece in span.split(".")}
    return all(part in parts for part in name.replace("<joint>.", "").split("."))


def _get(d: dict, path: str, joint: str):
    for part in path.replace("<joint>", joint).split("."):
        assert isinstance(d, dict) and part in d, path
        d = d[part]
    return d


def test_the_stage_writes_every_documented_field(stage_run):
    """SCENES.md: every results field and array the README's guide documents is public."""
    out, _, _ = stage_run
    dyn = json.loads((out / "results.json").read_text())["dynamics"]
    for page, path in DOCUMENTED:
        assert _documented(page, path), f"{page} no longer documents {path}"
        _get(dyn, path, "big_end_1")
        if path.endswith(("_x.mean", "_x.sem")):
            _get(dyn, path.replace("_x.", "_y."), "big_end_1")
    with np.load(out / "dynamics.npz") as z:
        names = set(z.files)
    for page, name in DOCUMENTED_ARRAYS:
        assert f"`{name}`" in (DOCS / page).read_text(), name
        pattern = re.escape(name.replace("<joint>", "big_end_1")).replace(r"\*", ".+")
        assert any(re.fullmatch(pattern, n) for n in names), name
    assert set(SCRIPT_ARRAYS) <= names
    text = (DOCS / "dynamics.md").read_text()
    for fig in DOCUMENTED_FIGURES:
        assert f"`{fig}`" in text
        assert f"dynamics{fig}.png" in dyn["figures"] or f"{fig}.png" in dyn["figures"]


# ---- damaged files -------------------------------------------------------------------------
def _members(path: Path) -> dict:
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def _write(path: Path, members: dict) -> Path:
    np.savez(path, **members)
    return path


def _meta(members: dict) -> dict:
    return json.loads(str(members["meta_json"]))


def _damage(kind: str, m: dict) -> tuple[dict, str, str]:
    """Damage the members ``m``; returns them, the member the error must name and a phrase."""
    if kind == "missing member":
        del m["contact_big_end_1_fn"]
        return m, "contact_big_end_1_fn", "missing"
    if kind == "wrong shape":
        m["main_bearing_force"] = m["main_bearing_force"][:, :1]
        return m, "main_bearing_force", r"shape \(\d+, 2\)"
    if kind == "NaN":
        m["energy_residual"] = m["energy_residual"].copy()
        m["energy_residual"][3] = np.nan
        return m, "energy_residual", "non-finite"
    if kind == "wrong dtype":
        m["drive_torque"] = m["drive_torque"].astype(str)
        return m, "drive_torque", "floating-point"
    if kind == "integer times":
        m["t"] = np.arange(m["t"].size)
        return m, "t", "floating-point"
    if kind == "times not increasing":
        m["ideal_t"] = m["ideal_t"][::-1].copy()
        return m, "ideal_t", "increasing"
    if kind == "pickled object":
        m["impacts_big_end_1"] = np.array([{"a": 1}], dtype=object)
        return m, "impacts_big_end_1", "pickled objects are never loaded"
    if kind == "NaN in the metadata":
        text = str(m["meta_json"]).replace('"window_s": [', '"window_s": [NaN, ', 1)
        m["meta_json"] = np.array(text)
        return m, "meta_json", "NaN"
    if kind == "window outside the run":
        meta = _meta(m)
        meta["window_s"] = [5.0, 6.0]
        m["meta_json"] = np.array(json.dumps(meta))
        return m, "meta_json", "window_s"
    if kind == "layout not a table":
        meta = _meta(m)
        meta["layout"]["history"]["contact"] = ["big_end_1"]
        m["meta_json"] = np.array(json.dumps(meta))
        return m, "meta_json", "contact"
    if kind == "clearance not a length":
        meta = _meta(m)
        meta["machine"]["clearances"]["big_end_1"] = -1e-4
        m["meta_json"] = np.array(json.dumps(meta))
        return m, "meta_json", r"machine.clearances.big_end_1: must be a number > 0"
    if kind == "another format":
        m["format"] = np.array("crankmodal-flexbody")
        return m, "format", "crankmodal-dynamics"
    if kind == "written before the layout was kept":
        for k in ("format", "version", "meta_json"):
            del m[k]
        return m, "meta_json", "run the scene again"
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", [
    "missing member", "wrong shape", "NaN", "wrong dtype", "integer times",
    "times not increasing", "pickled object", "NaN in the metadata", "window outside the run",
    "layout not a table", "clearance not a length", "another format",
    "written before the layout was kept"])
def test_a_damaged_file_is_refused_naming_the_file_and_member(stage_run, tmp_path, kind):
    out, _, _ = stage_run
    members, member, phrase = _damage(kind, _members(out / "dynamics.npz"))
    bad = _write(tmp_path / "damaged.npz", members)
    with pytest.raises(InputFileError) as exc:
        DynamicsResult.load(bad)
    text = str(exc.value)
    assert text.startswith(f"{bad}: member {member!r}: ") and "\n" not in text
    assert re.search(phrase, text), text


def test_not_a_file_or_not_an_archive_is_refused(tmp_path):
    with pytest.raises(InputFileError, match="not found"):
        DynamicsResult.load(tmp_path / "nothing.npz")
    (tmp_path / "text.npz").write_text("not a zip")
    with pytest.raises(InputFileError, match=r"text.npz: not a readable .npz file"):
        DynamicsResult.load(tmp_path / "text.npz")
    with pytest.raises(ParameterError, match="^path: must be a path"):
        DynamicsResult.load(42)


# ---- flexible bodies -----------------------------------------------------------------------
@pytest.mark.slow
def test_flexible_loom_result_round_trips_and_draws_its_modes(tmp_path, monkeypatch):
    """The loom four-bar with a flexible rocker (a reduced steel bar) and its rigid twin: the
    rigid twin's histories, the modal coordinates and the machine's modes come back; the
    flexible figures draw from the file; the documented flexible fields are written."""
    scene = {"dynamics": {"machine": "loom_four_bar", "clearances": [], "end_time": 0.01,
                          "flexible": {"rocker": {"bar": [0.02, 0.012], "mesh_size": 0.012,
                                                  "fixed_interface_modes": 8, "n_modes": 2}}}}
    out = tmp_path / "out"
    res, result = _run_keeping_result(scene, out, monkeypatch)
    loaded = DynamicsResult.load(out / "dynamics.npz")
    _same_history(result.history, loaded.history)
    _same_history(result.rigid, loaded.rigid)
    assert loaded.ideal is None and loaded.machine == result.machine
    assert list(loaded.machine.flexible) == ["rocker"]
    assert len(loaded.machine.flexible["rocker"]) == 2
    assert loaded.history.modal["rocker"].shape[1] >= 2
    names, flexible = loaded.figures(tmp_path / "figs")
    assert names == res["dynamics"]["figures"]
    assert flexible == ["dynamics_flexible_main_bearing.png", "dynamics_flexible_modes.png"]
    flex = res["dynamics"]["flexible"]
    text = (DOCS / "flexible_bodies.md").read_text()
    for key in ("rigid_integration_wall_time_s", "figures", "files"):
        assert f"`{key}`" in text and key in flex
    for key in ("n_modes", "frequencies_hz", "damping_ratio", "mass_kg", "interfaces"):
        assert f"`{key}`" in text and key in flex["bodies"]["rocker"]
    with np.load(out / "dynamics.npz") as z:
        assert "modal_rocker" in z.files and "rigid_main_bearing_force" in z.files
