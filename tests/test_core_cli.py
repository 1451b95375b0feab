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


def test_debug_shows_the_traceback(cli, tmp_path):
    proc = cli("--debug", "run", tmp_path / "missing.toml")
    assert proc.returncode != 0
    assert "Traceback" in proc.stderr
