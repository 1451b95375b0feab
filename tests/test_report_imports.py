"""The report package's modules import one another one way (no cycle, function-level imports
included): the stage runs the study, the study reads the [report] keys from report.keys."""

import ast
from pathlib import Path

import crankmodal

PACKAGE = Path(crankmodal.__file__).parent / "report"


def _imports(path: Path) -> set[str]:
    """Modules of crankmodal.report that ``path`` imports anywhere (module or function level)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            names = [node.module] if node.module else [a.name for a in node.names]
            out.update(n.split(".")[0] for n in names)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("crankmodal.report."):
            out.add(node.module.split(".")[2])
    return out


def test_the_report_modules_import_each_other_without_a_cycle():
    graph = {p.stem: _imports(p) & {q.stem for q in PACKAGE.glob("*.py")} - {p.stem}
             for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    assert "study_scene" in graph["stage"] and "keys" in graph["study_scene"]  # the parse sees them

    def reaches(start, goal, seen=()):
        return any(d == goal or (d not in seen and reaches(d, goal, (*seen, d)))
                   for d in graph.get(start, ()))

    cycles = sorted(m for m in graph if reaches(m, m))
    assert not cycles, {m: sorted(graph[m]) for m in cycles}
