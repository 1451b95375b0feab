"""The Python API examples that used to be the README's "Python API" section live on the docs page
docs/guide/python_api.md. Its quick sections run here in the default suite, as printed, in order,
in one namespace, in a temporary folder — each block asserts its numbers against an independent
oracle (CAD mass, F/A, Rayleigh-Ritz bounds, the two-rotor closed form, the slider-crank's
bearing force at top dead centre). The whole page, with the flexible crank it reduces (minutes),
runs in tests/test_api.py with ``-m slow``."""

import os
import re
from pathlib import Path

PAGE = Path(__file__).resolve().parent.parent / "docs" / "guide" / "python_api.md"
#: the first section not run here (it reduces the four-star crankshaft: the slow part)
SLOW_SECTION = "## A flexible crank in the crank train"


def python_blocks_before(text: str, stop: str) -> list[str]:
    """The ```python blocks of a Markdown page before the heading ``stop`` (lines inside fences,
    such as ``# comments`` in code, are not headings)."""
    blocks, fence, lang, body = [], False, "", []
    for line in text.splitlines(keepends=True):
        if line.startswith("```"):
            if not fence:
                fence, lang, body = True, line[3:].strip(), []
            else:
                fence = False
                if lang == "python":
                    blocks.append("".join(body))
            continue
        if fence:
            body.append(line)
        elif line.rstrip("\n") == stop:
            break
    return blocks


def test_blocks_are_taken_in_order_up_to_the_slow_section():
    text = ("# t\n```python\nA = 1\n# not a heading\n```\n## Two\n```toml\nx = 1\n```\n"
            "```python\nB = 2\n```\n## Slow\n```python\nC = 3\n```\n")
    assert python_blocks_before(text, "## Slow") == ["A = 1\n# not a heading\n", "B = 2\n"]
    assert python_blocks_before(text, "## Absent") == ["A = 1\n# not a heading\n", "B = 2\n",
                                                      "C = 3\n"]


def _quick_blocks() -> list[str]:
    text = PAGE.read_text(encoding="utf-8")
    assert SLOW_SECTION in text, f"{PAGE.name}: the section '{SLOW_SECTION}' moved; update this test"
    blocks = python_blocks_before(text, SLOW_SECTION)
    assert len(blocks) >= 5, f"{PAGE.name}: its quick python blocks are missing"
    return blocks


def test_python_api_page_uses_only_the_exported_names():
    import crankmodal

    code = "\n".join(_quick_blocks())
    assert "import crankmodal as cm" in code
    used = set(re.findall(r"\bcm\.(\w+)", code))
    assert used and used <= set(crankmodal.__all__), sorted(used - set(crankmodal.__all__))
    assert not re.search(r"^\s*(from|import) crankmodal\.", code, re.MULTILINE)


def test_python_api_page_quick_examples_run(tmp_path, monkeypatch):
    blocks = _quick_blocks()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", os.environ.get("MPLBACKEND", "Agg"))
    namespace: dict = {"__name__": "python_api_guide"}
    for i, code in enumerate(blocks):
        exec(compile(code, f"{PAGE.name} block {i + 1}", "exec"), namespace)  # noqa: S102
