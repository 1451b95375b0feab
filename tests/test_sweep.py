"""Sweeps on Dask (crankmodal.sweep): point generation, bad input, a local 2-worker cluster,
failures recorded, resumption after a kill, and a search against a closed-form optimum."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from sweep_support import F1, MECH, ROOT, THROW, write_sweep

from crankmodal.cli import main
from crankmodal.errors import CrankmodalError, SceneError
from crankmodal.sweep import load_sweep, run_sweep
from crankmodal.sweep.axes import generate, parse_axis
from crankmodal.sweep.driver import plan_tasks
from crankmodal.sweep.store import RecordStore

# ---------------------------------------------------------------- generation


def test_grid_zip_range_and_log_axes():
    a = parse_axis("x", {"start": 0.0, "stop": 1.0, "num": 3})
    b = parse_axis("y", [10, 20])
    assert a.values == (0.0, 0.5, 1.0)
    pts = generate([a, b], "grid")
    assert len(pts) == 6 and pts[1] == {"x": 0.0, "y": 20}
    c = parse_axis("z", {"start": 1e-5, "stop": 1e-3, "num": 3, "log": True})
    assert np.allclose(c.values, [1e-5, 1e-4, 1e-3])
    z = generate([a, parse_axis("w", [1, 2, 3])], "zip")
    assert [p["w"] for p in z] == [1, 2, 3] and [p["x"] for p in z] == [0.0, 0.5, 1.0]
    with pytest.raises(SceneError, match="zip"):
        generate([a, b], "zip")
    assert parse_axis("n", {"start": 360, "stop": 720, "num": 3}).values == (360, 540, 720)


def test_lhs_is_stratified_and_random_is_seeded():
    a = parse_axis("x", {"start": 0.0, "stop": 10.0})
    b = parse_axis("y", {"start": 1.0, "stop": 100.0, "log": True})
    pts = generate([a, b], "lhs", samples=8, seed=3)
    # one sample in each eighth of each axis (log-eighths for the log axis)
    assert sorted(int(p["x"] / 10 * 8) for p in pts) == list(range(8))
    assert sorted(int(np.log10(p["y"]) / 2 * 8) for p in pts) == list(range(8))
    r1 = generate([a, b], "random", samples=5, seed=1)
    assert r1 == generate([a, b], "random", samples=5, seed=1)
    assert all(0 <= p["x"] <= 10 and 1 <= p["y"] <= 100 for p in r1)


# ---------------------------------------------------------------- bad input (nothing runs)


@pytest.mark.parametrize("text, match", [
    ("[axes]\nmechanism.speed_rpm = []\n", "axes.mechanism.speed_rpm: empty axis"),
    ("outputs = []\n", "axes: no axes"),
    ("[axes]\nmechanism.speed_rpm = {start = 1, num = 3}\n", "needs stop"),
    ("mode = 'zip'\n[axes]\na.b = [1, 2]\nc.d = [1]\n", "zip"),
    ("modes = 'grid'\n[axes]\na.b = [1]\n", "modes: unknown sweep key"),
    ("mode = 'lhs'\n[axes]\na.b = {start = 0, stop = 1}\n", "samples"),
])
def test_bad_sweep_file_is_one_line(tmp_path, text, match):
    with pytest.raises(SceneError, match=match):
        run_sweep(load_sweep(write_sweep(tmp_path, text)), tmp_path / "out")
    assert not (tmp_path / "out" / "records.jsonl").exists()


def test_bad_point_named_before_anything_runs(tmp_path, capsys):
    sw = write_sweep(tmp_path, "[axes]\nmechanism.speed_rpm = [1000, -5]\n"
                     "mechanism.no_such_key = [1]\n")
    assert main(["sweep", str(sw), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "point 0 (" in err and "no_such_key" in err
    sw = write_sweep(tmp_path, "[axes]\nmechanism.speed_rpm = [1000, -5]\n")
    assert main(["sweep", str(sw), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert "point 1 (mechanism.speed_rpm=-5)" in err and "mechanism.speed_rpm" in err
    assert not (tmp_path / "o" / "records.jsonl").exists()


def test_output_of_a_missing_section_refused(tmp_path):
    sw = write_sweep(tmp_path, "outputs = ['dynamics.x']\n[axes]\nmechanism.speed_rpm = [1000]\n")
    with pytest.raises(CrankmodalError, match=r"outputs: 'dynamics.x'.*no \[dynamics\]"):
        run_sweep(sw, tmp_path / "o")


def test_second_sweep_into_a_busy_folder_refused(tmp_path):
    from crankmodal.sweep.store import folder_lock

    sw = write_sweep(tmp_path, "[axes]\nmechanism.speed_rpm = [1000]\n")
    (tmp_path / "o").mkdir()
    with folder_lock(tmp_path / "o"), pytest.raises(CrankmodalError, match="another sweep"):
        run_sweep(sw, tmp_path / "o", scheduler="tcp://127.0.0.1:1")
    assert not (tmp_path / "o" / "records.jsonl").exists()


def test_unreachable_scheduler_is_exit_2_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("crankmodal.sweep.driver.CONNECT_TIMEOUT_S", 1)
    sw = write_sweep(tmp_path, "[axes]\nmechanism.speed_rpm = [1000]\n")
    t0 = time.perf_counter()
    rc = main(["sweep", str(sw), "--out", str(tmp_path / "o"), "--scheduler",
               "tcp://127.0.0.1:1"])
    assert rc == 2 and time.perf_counter() - t0 < 30
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tcp://127.0.0.1:1" in err[0] and "cannot reach" in err[0]


def test_without_dask_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if absent
    sw = write_sweep(tmp_path, "[axes]\nmechanism.speed_rpm = [1000]\n")
    assert main(["sweep", str(sw), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install 'crankmodal[sweep]'" in err[0]


# ---------------------------------------------------------------- on a local cluster


def test_small_sweep_on_two_workers(tmp_path, client):
    sw = write_sweep(tmp_path, f"outputs = ['{F1}', 'mechanism.peak_acceleration_m_s2.0']\n"
                     "[axes]\nmechanism.speed_rpm = [1000, 2000]\n"
                     f"{THROW} = {{start = 0, stop = 180, num = 3}}\n")
    res = run_sweep(sw, tmp_path / "o", client=client)
    assert res["n_points"] == 6 and res["n_ok"] == 6 and res["ran"] == 6
    rows = (tmp_path / "o" / "sweep.csv").read_text().splitlines()
    assert len(rows) == 7 and F1 in rows[0]
    recs = RecordStore(tmp_path / "o" / "records.jsonl").read()
    assert len(recs) == 6
    # first-order force of the four-star scales with speed^2; with both throws aligned it is
    # 2 m_rec r w^2 (seed 000 Table 1), read from the mechanism's own results.json
    by = {(r["parameters"]["mechanism.speed_rpm"], r["parameters"][THROW]): r for r in recs.values()}
    f1000, f2000 = by[(1000, 0)]["outputs"][F1], by[(2000, 0)]["outputs"][F1]
    assert f2000 / f1000 == pytest.approx(4.0, rel=1e-12)
    assert by[(1000, 0)]["outputs"]["mechanism.peak_acceleration_m_s2.0"] > 0
    assert json.loads((tmp_path / "o" / "sweep.json").read_text())["n_ok"] == 6
    assert (tmp_path / "o" / f"sweep_{F1}.png").read_bytes().endswith(b"IEND\xaeB`\x82")
    # the same sweep again runs nothing, and starts no cluster
    again = run_sweep(sw, tmp_path / "o", client=None, scheduler="tcp://127.0.0.1:1")
    assert again["ran"] == 0 and again["skipped"] == 6 and again["n_ok"] == 6
    assert again["dask"] == {}


def test_cli_on_a_cluster_by_address(tmp_path, client, capsys):
    """--scheduler: the same sweep on an existing cluster (here the module's, by its address)."""
    sw = write_sweep(tmp_path, f"outputs = ['{F1}']\n[axes]\nmechanism.speed_rpm = [900, 1100]\n")
    addr = client.scheduler.address
    assert main(["--quiet", "sweep", str(sw), "--out", str(tmp_path / "o"), "--scheduler", addr,
                 "--no-figures"]) == 0
    out = capsys.readouterr()
    assert f"dask: 2 workers at {addr}" in out.err and "2 points, 2 ok" in out.out
    assert json.loads((tmp_path / "o" / "sweep.json").read_text())["dask"]["scheduler"] == addr


def test_relative_out_folder(tmp_path, client, monkeypatch):
    monkeypatch.chdir(tmp_path)
    sw = write_sweep(tmp_path, f"outputs = ['{F1}']\n[axes]\nmechanism.speed_rpm = [1000]\n")
    res = run_sweep(sw, Path("rel") / "o", client=client, figures=False)
    assert res["n_ok"] == 1
    rec = next(iter(RecordStore(tmp_path / "rel" / "o" / "records.jsonl").read().values()))
    assert (tmp_path / "rel" / "o" / rec["dir"] / "results.json").is_file()


def test_text_axis_and_three_axes_maps(tmp_path, client):
    sw = write_sweep(tmp_path, f"outputs = ['{F1}']\n"
                     "[axes]\nmechanism.harmonics = ['series', 'fourier']\n")
    res = run_sweep(sw, tmp_path / "a", client=client)
    assert res["files"]["figures"] == [f"sweep_{F1}.png"]
    sw = write_sweep(tmp_path, f"outputs = ['{F1}']\nmode = 'lhs'\nsamples = 4\n[axes]\n"
                     "mechanism.speed_rpm = {start = 900.0, stop = 1500.0}\n"
                     f"{THROW} = {{start = 0.0, stop = 90.0}}\n"
                     "mechanism.n_points = [360, 720]\n", name="lhs.toml")
    res = run_sweep(sw, tmp_path / "b", client=client)
    assert res["n_ok"] == 4 and (tmp_path / "b" / f"sweep_{F1}.png").is_file()


def test_run_never_imports_dask(tmp_path):
    code = ("import sys; from crankmodal.cli import main; "
            f"rc = main(['--quiet', 'run', r'{MECH}', '--out', r'{tmp_path}', '--no-figures']); "
            "assert rc == 0 and 'dask' not in sys.modules and 'distributed' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)


def test_failing_points_recorded_and_sweep_goes_on(tmp_path, client):
    # point 1 (100 000 samples, 24 Fourier orders) takes 5-14 s: far past the 1.5 s limit
    sw = write_sweep(tmp_path, f"outputs = ['{F1}']\ntimeout_s = 1.5\nmode = 'zip'\n[axes]\n"
                     "mechanism.n_points = [360, 100000, 720, 1440]\n"
                     "mechanism.harmonics = ['series', 'fourier', 'series', 'series']\n"
                     "mechanism.max_order = [2, 24, 2, 2]\n")
    spec = load_sweep(sw)
    tasks = plan_tasks(spec, spec.points(), (tmp_path / "o").resolve())
    # point 2's output folder is a file: an OutputError (exit 2) inside the run
    Path(tasks[2]["dir"]).parent.mkdir(parents=True)
    Path(tasks[2]["dir"]).write_text("in the way")
    res = run_sweep(spec, tmp_path / "o", client=client)
    recs = {r["point"]: r for r in RecordStore(tmp_path / "o" / "records.jsonl").read().values()}
    assert res["n_points"] == 4 and res["n_ok"] == 2
    assert recs[0]["status"] == recs[3]["status"] == "ok"
    assert recs[1]["status"] == "timeout" and "timeout_s = 1.5" in recs[1]["error"]
    assert recs[2]["status"] == "error" and recs[2]["exit_code"] == 2
    assert "\n" not in recs[2]["error"] and recs[2]["outputs"][F1] is None
    assert res["status_counts"] == {"ok": 2, "timeout": 1, "error": 1}
    # a re-run skips all four; --retry-failed runs the two failed ones again (and only them)
    assert run_sweep(spec, tmp_path / "o", client=client)["ran"] == 0
    again = run_sweep(spec, tmp_path / "o", client=client, retry_failed=True)
    assert again["ran"] == 2 and again["skipped"] == 2 and again["n_ok"] == 2


def test_output_no_point_produces_after_the_run(tmp_path, client):
    sw = write_sweep(tmp_path, "outputs = ['mechanism.shaking_force_maxx_n']\n"
                     "[axes]\nmechanism.speed_rpm = [1000, 1200]\n")
    with pytest.raises(CrankmodalError, match="nearest: mechanism.shaking_force_max_n"):
        run_sweep(sw, tmp_path / "o", client=client)
    assert not (tmp_path / "o" / "sweep.json").exists()
    # fixed outputs: the recorded points are re-read, not recomputed
    sw.write_text(sw.read_text().replace("maxx", "max"))
    res = run_sweep(sw, tmp_path / "o", client=client)
    assert res["ran"] == 0 and res["output_ranges"]["mechanism.shaking_force_max_n"]["n"] == 2


def test_search_finds_the_closed_form_optimum(tmp_path, client):
    """Maximise the four-star's first-order force over cylinder 1's throw angle phi. Seed 000
    Table 1: each cylinder's first-order force is m r w^2 cos(theta + phi_i - beta_i) along its
    axis; with banks 0/180/270/90 deg the resultant is m r w^2 (2 sin theta, cos theta +
    cos(theta + phi)), whose maximum over theta and phi is found here by scipy, independently."""
    from scipy.optimize import minimize_scalar

    th = np.linspace(0, 2 * np.pi, 20001)

    def peak(phi_deg):
        f = np.radians(phi_deg)
        return np.max(np.hypot(2 * np.sin(th), np.cos(th) + np.cos(th + f))) / 2

    opt = minimize_scalar(lambda p: -peak(p), bounds=(0, 180), method="bounded",
                          options={"xatol": 1e-6})
    phi_star, ratio_star = opt.x, peak(opt.x)
    assert phi_star == pytest.approx(np.degrees(np.arccos(1 / 3)), abs=0.02)  # cos phi* = 1/3
    assert ratio_star == pytest.approx(2 / np.sqrt(3), rel=1e-7)
    sw = write_sweep(tmp_path, f"[axes]\n{THROW} = {{start = 0.0, stop = 180.0, num = 7}}\n"
                     f"[search]\nmaximize = '{F1}'\nrounds = 4\nnum = 5\n")
    res = run_sweep(sw, tmp_path / "o", client=client)
    s = res["search"]
    f_aligned = res["output_ranges"][F1]["min"]  # phi = 0 and 180: 2 m r w^2
    assert f_aligned == pytest.approx(2 * 1.76 * 0.035 * (1480 * np.pi / 30) ** 2, rel=1e-9)
    step = 30 / 2 ** 4
    assert abs(s["best_parameters"][THROW] - phi_star) <= step
    assert s["best_value"] / f_aligned == pytest.approx(ratio_star, rel=2e-4)
    assert len(s["rounds"]) == 5 and s["rounds"][-1]["step"][THROW] == pytest.approx(step)
    print(f"search: phi {s['best_parameters'][THROW]:.3f} deg (closed form {phi_star:.3f}), "
          f"force ratio {s['best_value'] / f_aligned:.6f} ({ratio_star:.6f})")


@pytest.mark.parametrize("method", ["powell", "nelder-mead"])
def test_scipy_search_finds_the_closed_form_optimum(tmp_path, client, method):
    """The same optimum by a scipy optimiser over point runs: phi* = arccos(1/3) = 70.53 deg,
    force 2/sqrt(3) x the aligned value."""
    sw = write_sweep(tmp_path, f"[axes]\n{THROW} = {{start = 0.0, stop = 180.0, num = 7}}\n"
                     f"[search]\nmaximize = '{F1}'\nmethod = '{method}'\nxtol = 1e-4\n"
                     "max_points = 25\n")
    res = run_sweep(sw, tmp_path / "o", client=client, figures=False)
    s = res["search"]
    f_aligned = res["output_ranges"][F1]["min"]
    print(f"{method}: phi {s['best_parameters'][THROW]:.4f} deg, ratio "
          f"{s['best_value'] / f_aligned:.8f}, {s['rounds'][-1]['evaluations']} evaluations")
    assert s["best_parameters"][THROW] == pytest.approx(np.degrees(np.arccos(1 / 3)), abs=0.1)
    assert s["best_value"] / f_aligned == pytest.approx(2 / np.sqrt(3), rel=1e-6)
    assert s["rounds"][-1]["evaluations"] <= 30


# ---------------------------------------------------------------- resumption after a kill


def test_resume_after_kill_runs_only_the_missing_points(tmp_path, client):
    # n_points = 5000: ~0.13 s a point, so the kill lands well before the last of the 12
    sw = write_sweep(tmp_path, f"outputs = ['{F1}']\nset = ['mechanism.n_points=5000']\n"
                     "[axes]\nmechanism.speed_rpm = {start = 900, stop = 2000, num = 12}\n")
    out = tmp_path / "o"
    env = {**os.environ, "CRANKMODAL_QUIET": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "crankmodal.cli", "sweep", str(sw), "--out",
                             str(out), "--workers", "1"], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rec = out / "records.jsonl"
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if rec.is_file() and rec.read_text().count("\n") >= 3:
                break
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGKILL)  # the driver, its cluster and workers
    finally:
        proc.wait()
    kept = len(RecordStore(rec).read())
    assert 3 <= kept < 12
    with open(rec, "a") as fh:  # a line cut by the kill
        fh.write('{"point": 11, "key": "tru')
    res = run_sweep(sw, out, client=client)
    assert res["ran"] == 12 - kept and res["skipped"] == kept and res["n_ok"] == 12
    assert len(RecordStore(rec).read()) == 12


@pytest.mark.parametrize("sweep_file", sorted((ROOT / "scenes" / "sweeps").glob("*.toml")),
                         ids=lambda p: p.stem)
def test_study_sweeps_validate(sweep_file, tmp_path):
    """The prepared study sweeps: every coarse point's scene checks, every output's section is
    in the scene (nothing runs)."""
    from crankmodal.sweep.driver import check_output_sections

    spec = load_sweep(sweep_file)
    tasks = plan_tasks(spec, spec.points(), tmp_path)
    check_output_sections(spec, tasks[0])
    assert len(tasks) >= 4


def test_local_workers_run_without_the_event_loop_monitors_that_take_the_gil(client):
    """A point is long pure Python: the worker's 20 ms tick, 10 ms profiler and 0.5 s system
    monitor took the GIL from it (a seed 003 point 20.7 s in a worker, 16.2 s in-process)."""
    from crankmodal.sweep.driver import WORKER_CONFIG

    def settings():
        import dask

        return {k: dask.config.get(k) for k in WORKER_CONFIG}

    for got in client.run(settings).values():
        assert got == WORKER_CONFIG
