"""The README's "Python API" section runs as printed: every ```python block under that heading,
in order, in one namespace, in a temporary folder (each block asserts its numbers against an
independent oracle: CAD mass, F/A, Rayleigh-Ritz bounds, the two-rotor closed form, the
main-bearing force at top dead centre)."""

import os
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
HEADING = "## Python API"


def api_blocks(text: str) -> list[str]:
    """The ```python blocks between ``## Python API`` and the next level-2 heading."""
    start = text.find("\n" + HEADING + "\n")
    if start < 0:
        return []
    section = text[start + 1:]
    nxt = re.search(r"^## ", section[len(HEADING):], re.MULTILINE)
    if nxt:
        section = section[:len(HEADING) + nxt.start()]
    return re.findall(r"^```python\n(.*?)^```", section, re.DOTALL | re.MULTILINE)


def test_api_blocks_are_found_in_a_section_and_only_there():
    text = ("# x\n```python\nA\n```\n## Python API\nintro\n```python\nB = 1\n```\n"
            "### sub\n```python\nC = 2\n```\n## Next\n```python\nD\n```\n")
    assert api_blocks(text) == ["B = 1\n", "C = 2\n"]
    assert api_blocks("# no such section\n```python\nA\n```\n") == []


def _readme_blocks() -> list[str]:
    blocks = api_blocks(README.read_text(encoding="utf-8"))
    if not blocks:
        pytest.skip(f"README.md has no '{HEADING}' section with python blocks yet "
                    "(its text is in /work/helpers/readme_C.md until merged)")
    return blocks


def test_readme_python_api_uses_only_the_exported_names():
    import crankmodal

    code = "\n".join(_readme_blocks())
    assert "import crankmodal as cm" in code
    used = set(re.findall(r"\bcm\.(\w+)", code))
    assert used and used <= set(crankmodal.__all__), sorted(used - set(crankmodal.__all__))
    assert not re.search(r"^\s*(from|import) crankmodal\.", code, re.MULTILINE)


def test_readme_python_api_examples_run(tmp_path, monkeypatch):
    blocks = _readme_blocks()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", os.environ.get("MPLBACKEND", "Agg"))
    namespace: dict = {"__name__": "readme_python_api"}
    for i, code in enumerate(blocks):
        exec(compile(code, f"README.md {HEADING} block {i + 1}", "exec"), namespace)  # noqa: S102
