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


# --- The validation page's data: oracle checks recorded by the tests that make them -----------
#: ``CRANKMODAL_ORACLES=docs/validation/oracles.json pytest ...`` writes the rows of the tests that
#: ran into that file (rows of tests that did not run are kept), from which the docs' Validation
#: page is generated (docs/_ext/crankmodal_docs.py). Without the variable nothing is written.
ORACLES_ENV = "CRANKMODAL_ORACLES"
ORACLE_STAGES = ("geometry", "fem", "reduction", "mechanism", "torsion", "dynamics", "flexible",
                 "report", "sweep")
_ORACLE_ROWS: list[dict] = []
_ORACLE_TESTS: set[str] = set()


def _oracle_number(name, x):
    import math

    if x is None:
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise TypeError(f"oracle {name} must be a number, got {x!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"oracle {name} must be finite, got {v!r}")
    return v


@pytest.fixture
def oracle(request):
    """Record one independent-oracle check for the Validation page; returns ``measured``.

    ``oracle(stage="fem", quantity="...", reference="closed form ...", tolerance="0.5 %",
    measured=f, expected=f_ref)``: ``stage`` one of :data:`ORACLE_STAGES`; ``reference`` names
    the independent source (closed form, published table, peer code, second formulation);
    ``tolerance`` is what the test asserts (text or number); ``expected`` may be None when the
    test checks a bound. Only records: the test still asserts on its own."""
    _ORACLE_TESTS.add(request.node.nodeid)

    def record(*, stage, quantity, reference, tolerance, measured, expected=None):
        if stage not in ORACLE_STAGES:
            raise ValueError(f"oracle stage {stage!r}: one of {', '.join(ORACLE_STAGES)}")
        _ORACLE_ROWS.append({
            "stage": stage, "quantity": str(quantity), "reference": str(reference),
            "tolerance": str(tolerance), "measured": _oracle_number("measured", measured),
            "expected": _oracle_number("expected", expected), "test": request.node.nodeid,
        })
        return measured

    return record


def pytest_sessionfinish(session, exitstatus):
    import json

    path = os.environ.get(ORACLES_ENV)
    if not path or not _ORACLE_TESTS:
        return
    path = Path(path)
    old = []
    if path.exists():
        old = json.loads(path.read_text(encoding="utf-8")).get("oracles", [])
    rows = [r for r in old if r["test"] not in _ORACLE_TESTS] + _ORACLE_ROWS
    rows.sort(key=lambda r: (r["stage"], r["test"], r["quantity"]))
    text = json.dumps({"oracles": rows}, indent=1, ensure_ascii=False) + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)


@pytest.fixture(scope="module")
def client():
    """One local Dask cluster of two worker processes per test module (as the sweep CLI makes
    it), for the sweep tests."""
    pytest.importorskip("dask.distributed")
    from crankmodal.sweep.driver import dask_client

    with dask_client(workers=2) as c:
        yield c
