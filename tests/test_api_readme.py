"""The docs' "Python API by example" page (docs/guide/api_examples.md, the README's former "Python
API" section) runs as printed: every ```python block of the page, in order, in one namespace, in
a temporary folder (each block asserts its numbers against an independent oracle: CAD mass, F/A,
Rayleigh-Ritz bounds, the two-rotor closed form, the main-bearing force at top dead centre)."""

import os
import re
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parent.parent / "docs" / "guide" / "api_examples.md"
HEADING = "# Python API by example"


def api_blocks(text: str) -> list[str]:
    """The ```python blocks between ``HEADING`` and the next heading of its level or above
    (lines inside fences, such as ``# comments`` in code, are not headings)."""
    level = len(HEADING.split(" ")[0])
    blocks, inside, fence, lang, body = [], False, False, "", []
    for line in text.splitlines(keepends=True):
        if line.startswith("```"):
            if not fence:
                fence, lang, body = True, line[3:].strip(), []
            else:
                fence = False
                if inside and lang == "python":
                    blocks.append("".join(body))
            continue
        if fence:
            body.append(line)
            continue
        m = re.match(r"^(#+) ", line)
        if m and len(m.group(1)) <= level:
            inside = line.rstrip("\n") == HEADING
    return blocks


def test_api_blocks_are_found_in_a_section_and_only_there():
    text = ("x\n```python\nA\n```\n# Python API by example\nintro\n```python\nB = 1\n```\n"
            "## sub\n```python\nC = 2\n```\n# Next\n```python\nD\n```\n")
    assert api_blocks(text) == ["B = 1\n", "C = 2\n"]
    assert api_blocks(text[text.index("# Python"):]) == ["B = 1\n", "C = 2\n"]
    assert api_blocks("# no such section\n```python\nA\n```\n") == []


def _readme_blocks() -> list[str]:
    blocks = api_blocks(PAGE.read_text(encoding="utf-8"))
    assert len(blocks) >= 5, f"{PAGE.name}: its python blocks under '{HEADING}' are missing"
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
        exec(compile(code, f"{PAGE.name} block {i + 1}", "exec"), namespace)  # noqa: S102
