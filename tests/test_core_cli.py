"""CLI error paths: exit status 2, one line on stderr naming the value, no traceback, no results."""

import pytest


def assert_clean_error(proc, *fragments, status=2):
    assert proc.returncode == status, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert "Traceback" not in proc.stderr
    assert len(lines) == 1, proc.stderr
    for f in fragments:
        assert f in lines[0], lines[0]


def test_missing_scene_file(cli, tmp_path):
    proc = cli("run", tmp_path / "missing.toml", "--out", tmp_path / "o")
    assert_clean_error(proc, "file not found", "missing.toml")
    assert not (tmp_path / "o" / "results.json").exists()


def test_unknown_section(cli, tmp_path):
    s = tmp_path / "s.toml"
    s.write_text("[mechanismus]\nx = 1\n")
    proc = cli("run", s, "--out", tmp_path / "o")
    assert_clean_error(proc, "[mechanismus]", "unknown section")
    assert not (tmp_path / "o").exists()


def test_invalid_toml(cli, tmp_path):
    s = tmp_path / "s.toml"
    s.write_text("[torsion\n")
    assert_clean_error(cli("check", s), "invalid TOML")


def test_empty_scene(cli, tmp_path):
    s = tmp_path / "s.toml"
    s.write_text('name = "empty"\n')
    assert_clean_error(cli("check", s), "has no sections")


def test_unknown_machine(cli, tmp_path):
    s = tmp_path / "s.toml"
    s.write_text('[mechanism]\nmachine = "v12"\n')
    assert_clean_error(cli("check", s), "unknown machine 'v12'")


def test_bad_override_syntax(cli, tmp_path):
    s = tmp_path / "s.toml"
    s.write_text('[mechanism]\nmachine = "four_star_compressor"\n')
    assert_clean_error(cli("check", s, "--set", "speed_rpm"), "--set", "section.key=value")


@pytest.mark.parametrize("argv", [[], ["frobnicate"], ["run"]])
def test_usage_errors(cli, argv):
    assert_clean_error(cli(*argv), "usage:")


@pytest.mark.parametrize("where", ["before", "after"])
def test_debug_shows_the_traceback(cli, tmp_path, where):
    """``--debug`` before or after the command; after it, the command's default must not undo a
    ``--debug`` given before it."""
    bad = ["run", tmp_path / "missing.toml"]
    proc = cli(*(["--debug", *bad] if where == "before" else [*bad, "--debug"]))
    assert proc.returncode != 0
    assert "Traceback" in proc.stderr and "file not found" in proc.stderr


TORSION = "[torsion]\ninertias = [0.3, 0.6]\nstiffnesses = [1.32e5]\n"
IMPOSSIBLE = ("--set", "torsion.inertias=[-1, 0.6]")


def test_a_failed_run_removes_the_results_of_an_earlier_run(cli, tmp_path):
    """SCENES.md: bad input leaves no results.json, also not the one of an earlier good run
    in the same --out folder; nothing else there is touched."""
    import json

    s = tmp_path / "s.toml"
    s.write_text(TORSION)
    out = tmp_path / "o"
    good = cli("run", s, "--out", out, "--no-figures")
    assert good.returncode == 0, good.stderr
    assert json.loads((out / "results.json").read_text())["scene"] == "s"
    others = sorted(f.name for f in out.iterdir() if f.name != "results.json")
    assert others  # the torsion stage writes its tables next to results.json
    assert_clean_error(cli("run", s, "--out", out, *IMPOSSIBLE), "torsion.inertias[0]", "> 0")
    assert not (out / "results.json").exists()
    assert sorted(f.name for f in out.iterdir()) == others


def test_a_failed_run_removes_the_results_in_the_default_folder(cli, tmp_path, monkeypatch):
    """Default folder out/<name key>; a scene that does not parse falls back to its file stem.
    Results in other folders are not touched."""
    monkeypatch.chdir(tmp_path)
    s = tmp_path / "s.toml"
    s.write_text('name = "chain"\n' + TORSION)
    assert cli("run", s, "--no-figures").returncode == 0
    results = tmp_path / "out" / "chain" / "results.json"
    assert results.is_file()
    bystander = tmp_path / "out" / "s" / "results.json"  # the stem's folder: not this scene's
    bystander.parent.mkdir()
    bystander.write_text("{}")
    assert_clean_error(cli("run", s, *IMPOSSIBLE), "torsion.inertias[0]")
    assert not results.exists() and bystander.exists()

    s.write_text("[torsion\n")  # no name to read: out/<stem> is the folder
    assert_clean_error(cli("run", s), "invalid TOML")
    assert not bystander.exists()


def test_an_unparsable_scene_removes_the_results_in_the_out_folder(cli, tmp_path):
    s = tmp_path / "s.toml"
    s.write_text("[torsion\n")
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.json").write_text("{}")
    (out / "torsion.png").write_text("")
    assert_clean_error(cli("run", s, "--out", out), "invalid TOML")
    assert sorted(f.name for f in out.iterdir()) == ["torsion.png"]


@pytest.mark.parametrize("command", [["demo"], ["study", "simplification", "SCENE"]])
def test_failed_demo_and_study_remove_their_stale_summary(cli, tmp_path, command):
    """``demo`` writes results.json, ``study`` study.json: a failure removes that file only."""
    from crankmodal.resources import scene_path

    summary = "study.json" if command[0] == "study" else "results.json"
    command = [scene_path("seed000_crank_study") if c == "SCENE" else c for c in command]
    out = tmp_path / "o"
    out.mkdir()
    (out / summary).write_text("{}")
    (out / "keep.csv").write_text("")
    proc = cli(*command, "--out", out, "--set", "modal.n_modes=-1")
    assert_clean_error(proc, "modal.n_modes", ">= 1")
    assert sorted(f.name for f in out.iterdir()) == ["keep.csv"]


def _bar_vtu(path, divisions=(10, 2, 2)):
    """A P1 bar written as a mesh file, its tetrahedra positively oriented as a mesher's."""
    import meshio
    import numpy as np

    from crankmodal.fem.testparts import bar

    part = bar(0.2, 0.02, 0.02, divisions, order=1)
    p, cells = part.mesh.points, part.mesh.cells[0].data.copy()
    e = p[cells[:, 1:]] - p[cells[:, :1]]
    flip = np.einsum("ij,ij->i", np.cross(e[:, 0], e[:, 1]), e[:, 2]) < 0
    cells[flip] = cells[flip][:, [0, 2, 1, 3]]
    meshio.write(path, meshio.Mesh(part.mesh.points, [("tetra", cells)]))


def test_a_model_too_large_for_the_memory_stops_before_the_factorisation(cli, tmp_path, monkeypatch):
    _bar_vtu(tmp_path / "bar.vtu")
    s = tmp_path / "s.toml"
    s.write_text('[geometry]\nfile = "bar.vtu"\n[material]\nname = "steel"\n[modal]\nn_modes = 4\n')
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", "1e-6")  # 1 kB
    proc = cli("run", s, "--out", tmp_path / "o")
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    error = [line for line in proc.stderr.splitlines() if "error" in line]
    assert len(error) == 1  # the stage progress lines, then one error line
    for f in ("modal: factorising", "GB", "coarser mesh", "CRANKMODAL_MEMORY_LIMIT"):
        assert f in error[0], error[0]
    assert not (tmp_path / "o" / "results.json").exists()


def test_model_warnings_are_one_plain_line_and_land_in_the_results(cli, tmp_path):
    """A band above the modes computed: the run succeeds and says so once, without Python's
    source-line noise."""
    import json

    s = tmp_path / "s.toml"
    s.write_text('[geometry]\nmachine = "four_star_compressor"\npart = "crankshaft"\n'
                 'fidelity = "simplified"\nmesh_size = 0.03\nelement_order = 1\n'
                 '[material]\nname = "steel"\n[modal]\nn_modes = 2\nband = [10.0, 1e5]\n')
    proc = cli("run", s, "--out", tmp_path / "o", "--no-figures", warnings="default")
    assert proc.returncode == 0, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("crankmodal: warning:")]
    assert len(lines) == 1 and lines[0].startswith("crankmodal: warning: modal.band: the 2 modes")
    assert "runner.py" not in proc.stderr
    res = json.loads((tmp_path / "o" / "results.json").read_text())["modal"]
    assert res["band_complete"] is False and res["warnings"][-1] in lines[0]


def test_superlu_running_out_of_memory_is_one_error_line_not_a_killed_process(cli, tmp_path,
                                                                             monkeypatch):
    """SuperLU gives no estimate beforehand: it factorises under an address-space limit of what
    is available, so running out is reported with advice (exit 2) and no result is written."""
    _bar_vtu(tmp_path / "bar.vtu", (40, 8, 8))  # 8.7k DOF: a SuperLU factor of tens of MB
    s = tmp_path / "s.toml"
    s.write_text('[geometry]\nfile = "bar.vtu"\n[material]\nname = "steel"\n'
                 '[modal]\nn_modes = 4\nbackend = "superlu"\n')
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", "0.001")  # 1 MB
    proc = cli("run", s, "--out", tmp_path / "o")
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    error = [line for line in proc.stderr.splitlines() if "error" in line]
    assert len(error) == 1, proc.stderr
    assert error[0].startswith("crankmodal: error: modal: factorising ") and \
        "with SuperLU ran out of the 0.001 GB available: install pypardiso" in error[0]
    assert not (tmp_path / "o" / "results.json").exists()
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", "20")  # the same run with room: fine
    assert cli("run", s, "--out", tmp_path / "o").returncode == 0
