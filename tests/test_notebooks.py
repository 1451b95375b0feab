"""The notebooks in notebooks/ are real Jupyter notebooks that run.

Each notebook is a jupytext pair: ``NAME.ipynb`` (opens in Jupyter as it is) and ``NAME.py``
(percent format). The tests check that every pair exists, is a valid nbformat-4 notebook and
holds the same cells, and execute the notebooks with nbclient on a Python kernel: the quick
ones (each well under a minute, small settings) in the default run, the ones marked
``# crankmodal: slow-notebook`` (minutes of simulation) with ``-m slow``; one marked
``# crankmodal: needs <module>`` (an export into another code) only where that module imports. Every notebook asserts
its numbers against closed forms or checks, so a run that finishes is a run whose checks held.
"""

import re
from pathlib import Path

import pytest

NB_DIR = Path(__file__).resolve().parent.parent / "notebooks"
SOURCES = sorted(NB_DIR.glob("*.py"))
SLOW_MARK = "# crankmodal: slow-notebook"
#: a notebook showing crankmodal's export into another code says so; it runs only where that
#: code is installed (e.g. "# crankmodal: needs exudyn")
NEEDS = re.compile(r"^# crankmodal: needs (\w+)", re.MULTILINE)


def _is_slow(path: Path) -> bool:
    return SLOW_MARK in path.read_text(encoding="utf-8")


QUICK = [p for p in SOURCES if not _is_slow(p)]
SLOW = [p for p in SOURCES if _is_slow(p)]


def _cells(nb) -> list[tuple[str, str]]:
    return [(c.cell_type, c.source.strip()) for c in nb.cells]


@pytest.mark.parametrize("source", SOURCES, ids=[p.stem for p in SOURCES])
def test_notebook_pair_exists_is_valid_and_in_sync(source):
    jupytext = pytest.importorskip("jupytext")
    nbformat = pytest.importorskip("nbformat")
    ipynb = source.with_suffix(".ipynb")
    assert ipynb.is_file(), f"{ipynb.name} missing: run `jupytext --sync {source}`"
    nb = nbformat.read(ipynb, as_version=4)
    nbformat.validate(nb)                       # opens in Jupyter as it is
    assert nb.metadata.get("kernelspec", {}).get("language") == "python"
    assert _cells(nb) == _cells(jupytext.read(source)), (
        f"{ipynb.name} and {source.name} differ: run `jupytext --sync {source}`")


def _execute(source: Path, tmp_path: Path):
    jupytext = pytest.importorskip("jupytext")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    for module in NEEDS.findall(source.read_text(encoding="utf-8")):
        pytest.importorskip(module, reason=f"{source.name} needs {module}")
    nb = jupytext.read(source)
    client = nbclient.NotebookClient(nb, timeout=1800, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # raises CellExecutionError with the failing cell and its traceback
    return nb


@pytest.mark.parametrize("source", QUICK, ids=[p.stem for p in QUICK])
def test_quick_notebook_runs_and_its_checks_hold(source, tmp_path, monkeypatch):
    monkeypatch.delenv("MPLBACKEND", raising=False)  # the notebook's own inline backend
    nb = _execute(source, tmp_path)
    # figures are shown inline (display data), not only written to files
    assert any(o.get("output_type") == "display_data" and "image/png" in o.get("data", {})
               for c in nb.cells for o in c.get("outputs", [])), f"{source.stem} shows no figure"


@pytest.mark.slow
@pytest.mark.parametrize("source", SLOW, ids=[p.stem for p in SLOW])
def test_slow_notebook_runs_and_its_checks_hold(source, tmp_path, monkeypatch):
    monkeypatch.delenv("MPLBACKEND", raising=False)
    _execute(source, tmp_path)


def test_the_notebooks_cover_the_api_walkthrough_and_every_seed():
    stems = {p.stem for p in SOURCES}
    assert "walkthrough" in stems
    for seed in ("seed000", "seed001", "seed003", "seed004"):
        assert any(s.startswith(seed) for s in stems), f"no notebook for {seed}"
    assert QUICK, "CI must execute at least one notebook"
