"""Every worked example in notebooks/ runs (each asserts its numbers against closed forms)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

# notebooks marked "# crankmodal: slow-notebook" (minutes of simulation, e.g. seed_trends.py
# whose trends are asserted by slow tests) are run by hand, not here
NOTEBOOKS = sorted(p for p in (Path(__file__).resolve().parent.parent / "notebooks").glob("*.py")
                   if "# crankmodal: slow-notebook" not in p.read_text())


@pytest.mark.parametrize("script", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_and_its_checks_hold(script, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]


def test_there_is_at_least_one_notebook():
    assert NOTEBOOKS
