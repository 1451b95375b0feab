"""Shared fixtures: the repository paths and a helper that runs the CLI in a subprocess."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
SCENES = REPO / "scenes"


def run_cli(*args, cwd=None, timeout=600, warnings="ignore"):
    """Run ``python -m crankmodal.cli ARGS``; returns the CompletedProcess (text mode).

    ``warnings`` is the subprocess's ``PYTHONWARNINGS`` (``ignore``: stderr holds only what the
    error paths print)."""
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONWARNINGS=warnings)
    return subprocess.run(
        [sys.executable, "-m", "crankmodal.cli", *map(str, args)],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout,
        check=False,  # callers assert on the exit code (0, 2 or 3) themselves
    )


@pytest.fixture
def cli():
    return run_cli
