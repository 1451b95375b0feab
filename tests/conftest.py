"""Shared fixtures: the repository paths and helpers that run the CLI (subprocess, in process)."""

import contextlib
import io
import os
import subprocess
import sys
import warnings as _warnings
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


def run_in_process(*argv) -> tuple[int, str]:
    """``crankmodal ARGV`` in this process (so monkeypatches apply): (exit status, stderr).

    Warnings are ignored as :func:`run_cli` does, so stderr holds only the error path; an
    exception escaping ``main`` is raised (the defect a caller looks for)."""
    from crankmodal import cli

    err = io.StringIO()
    show = _warnings.showwarning
    try:
        with _warnings.catch_warnings(), contextlib.redirect_stderr(err), \
                contextlib.redirect_stdout(io.StringIO()):
            _warnings.simplefilter("ignore")
            status = cli.main([str(a) for a in argv])
    finally:
        _warnings.showwarning = show  # main() installs its own formatter
    return status, err.getvalue()


@pytest.fixture
def cli():
    return run_cli


def peak_hz(t, s) -> float:
    """Frequency of a signal's largest spectral peak, Hz (Hann window, 64x zero padding,
    parabolic interpolation of the peak bin)."""
    import numpy as np

    s = (s - s.mean()) * np.hanning(len(s))
    nfft = 64 * len(s)
    a = np.abs(np.fft.rfft(s, nfft))
    i = int(np.argmax(a[1:])) + 1
    d = 0.5 * (a[i - 1] - a[i + 1]) / (a[i - 1] - 2 * a[i] + a[i + 1])
    return (i + d) / (nfft * (t[1] - t[0]))


def part_context(part, material, out_dir):
    """A StageContext whose earlier stages made ``part`` and ``material`` (for calling one
    FE stage's ``run`` directly)."""
    from pathlib import Path

    from crankmodal.runner import StageContext
    from crankmodal.scene import Scene

    ctx = StageContext(scene=Scene(name="t", base_dir=Path(out_dir)), out_dir=Path(out_dir),
                       figures=False)
    ctx.products["geometry"] = part
    ctx.products["material"] = material
    return ctx
