"""Pages generated at build time, so they cannot drift from the code and the tests.

* ``reference/scene.md`` -- every scene section and key from the stages' ``SCHEMA`` dicts
  (:data:`SCENE_TABLES`): type, default, unit/meaning (the key's ``doc``), bounds and choices.
* ``validation.md`` -- the oracle table per stage from ``validation/oracles.json``, which the test
  suite writes (``CRANKMODAL_ORACLES=docs/validation/oracles.json``, see ``tests/conftest.py``).
* ``reference/api.md`` -- an autosummary of every name in ``crankmodal.__all__``, grouped by the
  subpackage it comes from, so a newly exported name is documented without editing a page.
* ``gallery/notebooks/*.ipynb`` -- copies of ``notebooks/*.ipynb`` (Sphinx reads only its source
  folder; a copy instead of a symlink works on every file system), shown as :func:`gallery_plan`
  says: with the outputs they carry, from an executed copy committed in ``gallery/executed/``
  (the slow ones), or executed at build (the quick ones; ``CRANKMODAL_DOCS_EXECUTE=0`` skips
  that, as ``tests/test_docs.py`` does: ``tests/test_notebooks.py`` runs them).

The generators are pure functions of the repository (``scene_markdown``, ``validation_markdown``)
so ``tests/test_docs.py`` can check them without building.
"""

from __future__ import annotations

import importlib
import json
import math
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent

#: (dotted scene table, module, attribute, what it is). Sub-tables follow their parent; a
#: ``[[...]]`` name is an array of tables.
SCENE_TABLES: list[tuple[str, str, str, str]] = [
    ("geometry", "crankmodal.geometry.stage", "SCHEMA",
     "Parametric crankshaft or connecting rod, STEP or mesh import: [geometry](../guide/geometry.md)."),
    ("material", "crankmodal.fem.material_stage", "SCHEMA",
     "Material of the finite-element model: [finite elements](../guide/fem.md)."),
    ("modal", "crankmodal.fem.modal_stage", "SCHEMA",
     "Free or supported modes: [finite elements](../guide/fem.md)."),
    ("static", "crankmodal.fem.static_stage", "SCHEMA",
     "Supports, loads and a static solve: [finite elements](../guide/fem.md)."),
    ("reduction", "crankmodal.reduction.stage", "SCHEMA",
     "Craig-Bampton reduction to a flexible body: [reduction](../guide/reduction.md)."),
    ("[reduction.interfaces]", "crankmodal.reduction.stage", "INTERFACE_SCHEMA",
     "One interface (boundary region) of the reduction."),
    ("torsion", "crankmodal.torsion.stage", "SCHEMA",
     "Torsional chain and critical speeds: [torsion](../guide/torsion.md)."),
    ("torsion.throw", "crankmodal.torsion.stage", "THROW_SCHEMA",
     "Crank-throw dimensions of a chain built from the crank (Ker Wilson)."),
    ("torsion.flywheel", "crankmodal.torsion.stage", "FLYWHEEL_SCHEMA",
     "The flywheel of a chain built from the crank."),
    ("[torsion.segments]", "crankmodal.torsion.stage", "SEGMENT_SCHEMA",
     "One plain shaft segment of the chain."),
    ("torsion.forced", "crankmodal.torsion.forced_stage", "SCHEMA",
     "Forced response, stress and verdict: [forced torsion](../guide/torsion_forced.md)."),
    ("[torsion.forced.harmonics]", "crankmodal.torsion.forced_stage", "HARMONIC",
     "One explicit harmonic torque on a rotor."),
    ("[torsion.forced.dampers]", "crankmodal.torsion.forced_stage", "DAMPER",
     "One viscous or tuned rubber damper."),
    ("[torsion.forced.sections]", "crankmodal.torsion.forced_stage", "SECTION",
     "Stress data of one shaft section."),
    ("torsion.forced.pressure_table", "crankmodal.torsion.forced_stage", "PRESSURE",
     "A measured cylinder-pressure cycle."),
    ("[torsion.forced.double_acting]", "crankmodal.torsion.forced_stage", "CRANK_END",
     "The crank end of a double-acting cylinder."),
    ("mechanism", "crankmodal.mechanism.stage", "SCHEMA",
     "Kinematics, inertia, gas and friction forces: [mechanism](../guide/mechanism.md)."),
    ("[mechanism.cylinders]", "crankmodal.mechanism.stage", "CYLINDER",
     "One cylinder (bank) of the machine."),
    ("mechanism.gas", "crankmodal.mechanism.stage", "GAS",
     "The gas-pressure model of the cylinders."),
    ("mechanism.friction", "crankmodal.mechanism.stage", "FRICTION",
     "Friction of the cylinders and bearings."),
    ("dynamics", "crankmodal.dynamics.scene.keys", "SCHEMA",
     "Crank-linkage dynamics with clearance joints: [dynamics](../guide/dynamics.md)."),
    ("dynamics.crank_train", "crankmodal.dynamics.scene.keys", "CRANK_TRAIN",
     "Slider-crank and four-star crank trains."),
    ("dynamics.four_bar", "crankmodal.dynamics.scene.keys", "FOUR_BAR",
     "The four-bar linkage."),
    ("[dynamics.clearances]", "crankmodal.dynamics.scene.keys", "CLEARANCE",
     "One clearance joint."),
    ("dynamics.contact", "crankmodal.dynamics.scene.keys", "CONTACT",
     "The normal contact law of the clearance joints."),
    ("dynamics.friction", "crankmodal.dynamics.scene.keys", "FRICTION",
     "The friction law of the clearance joints."),
    ("dynamics.solver", "crankmodal.dynamics.scene.keys", "SOLVER",
     "The time integrator."),
    ("dynamics.flexible", "crankmodal.dynamics.scene.keys", "FLEXIBLE",
     "Flexible (Craig-Bampton) bodies: [flexible bodies](../guide/flexible_bodies.md)."),
    ("dynamics.flexible.crank / dynamics.flexible.rods", "crankmodal.dynamics.scene.keys",
     "FLEX_BODY", "A flexible crank or connecting rods of a crank train."),
    ("dynamics.flexible.crank / .coupler / .rocker (four-bar)", "crankmodal.dynamics.scene.keys",
     "LINK_BODY", "A flexible link of the four-bar."),
    ("fatigue", "crankmodal.fatigue.stage", "SCHEMA",
     "Fatigue verdict of a flexible body of the dynamics run: [fatigue](../guide/fatigue.md)."),
    ("report", "crankmodal.report.keys", "SCHEMA",
     "The report of the whole scene: [reports](../guide/reports.md)."),
]

_TYPE_NAMES = {
    "float": "number", "int": "integer", "str": "string", "bool": "boolean",
    "floats": "list of numbers", "ints": "list of integers", "strs": "list of strings",
    "table": "table", "tables": "list of tables", "any": "any",
}


def schema_tables():
    """Yield ``(table, description, {key: Field})`` for every entry of :data:`SCENE_TABLES`."""
    for table, module, attr, what in SCENE_TABLES:
        yield table, what, getattr(importlib.import_module(module), attr)


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def _default(field) -> str:
    from crankmodal.schema import REQUIRED
    if field.default is REQUIRED:
        return "**required**"
    if field.default is None:
        return "(none)"
    v = field.default
    if isinstance(v, float) and (math.isinf(v) or math.isnan(v)):
        return f"`{v}`"
    if isinstance(v, str):
        return f'`"{v}"`'
    if isinstance(v, bool):
        return f"`{str(v).lower()}`"
    if isinstance(v, dict):
        return "`{}`" if not v else "(table)"
    return f"`{json.dumps(v) if isinstance(v, (list, tuple)) else v}`"


def _allowed(field) -> str:
    parts = []
    for name, op in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
        bound = getattr(field, name)
        if bound is not None:
            parts.append(f"{op} {bound:g}")
    if field.choices:
        parts.append("one of " + ", ".join(f"`{c}`" for c in field.choices))
    if field.length is not None:
        parts.append(f"length {field.length}")
    if field.check is not None:
        parts.append("checked (see meaning)")
    return "; ".join(parts) or "-"


def _guide_link(page: str, text: str) -> str:
    """A link into the user guide when the page exists (other pages are written in parallel)."""
    if (DOCS / "guide" / page).exists():
        return f"[{text}](../guide/{page})"
    return text


def scene_markdown() -> str:
    """The scene reference page (MyST Markdown), from the stages' schemas."""
    lines = [
        "# Scene reference",
        "",
        ("Generated from the stages' schemas (`SCHEMA` dicts of `crankmodal.schema.Field`) "
         "each time the site is built: what is listed here is exactly what `crankmodal check` "
         "accepts. Units are SI (m, kg, s, N, Pa, rad) unless the key's name or meaning says "
         "otherwise (`speed_rpm`, `*_deg`, `*_hz`). A `[[name]]` table is an array of tables. "
         "The sweep file (`SWEEP.toml`) is described in "
         + _guide_link("sweeps.md", "sweeps") + "."),
        "",
        ("A scene file holds `name = \"...\"` and one section per stage to run; a section may "
         "take `machine = \"NAME\"` to pull its defaults from `geometry/NAME.toml`."),
        "",
        "## Top-level keys",
        "",
        "| key | type | default | meaning |",
        "|---|---|---|---|",
    ]
    from crankmodal.scene import TOP_LEVEL_KEYS
    meaning = {"name": ("the file's stem",
                        "the scene's name; the default output folder is `out/<name>/`"),
               "description": ('`""`', "free text about the scene")}
    for key in TOP_LEVEL_KEYS:
        default, text = meaning.get(key, ("-", ""))
        lines.append(f"| `{key}` | string | {default} | {text} |")
    lines.append("")
    for table, what, schema in schema_tables():
        what = what.replace("[reports](../guide/reports.md)", _guide_link("reports.md", "reports"))
        lines += [f"## `[{table}]`", "", what, "",
                  "| key | type | default | allowed | meaning |",
                  "|---|---|---|---|---|"]
        for key, f in schema.items():
            lines.append(f"| `{key}` | {_TYPE_NAMES.get(f.type, f.type)} | {_default(f)} | "
                         f"{_cell(_allowed(f))} | {_cell(f.doc)} |")
        lines.append("")
    return "\n".join(lines)


STAGE_ORDER = ("geometry", "fem", "reduction", "mechanism", "torsion", "dynamics", "flexible",
               "report", "sweep")


def load_oracles(path: Path | None = None) -> list[dict]:
    """The oracle rows the tests recorded (``validation/oracles.json``)."""
    path = path or DOCS / "validation" / "oracles.json"
    data = json.loads(path.read_text(encoding="utf-8"))
    return data["oracles"]


def _num(x) -> str:
    if x is None:
        return "-"
    if isinstance(x, str):
        return _cell(x)
    return f"{x:.6g}"


def validation_markdown(rows: list[dict]) -> str:
    """The validation page: one table per stage of the recorded oracle checks."""
    stages = sorted({r["stage"] for r in rows},
                    key=lambda s: (STAGE_ORDER.index(s) if s in STAGE_ORDER else 99, s))
    lines = [
        "# Validation",
        "",
        ("Every number below was written by the test that checks it: the tests call the "
         "`oracle` fixture (`tests/conftest.py`) with the quantity, its independent reference "
         "(closed form, published table, peer code, second formulation), the tolerance the test "
         "asserts and the value it measured. Running the suite with "
         "`CRANKMODAL_ORACLES=docs/validation/oracles.json` rewrites "
         "`docs/validation/oracles.json`, from which this page is generated; nothing here is "
         "typed by hand. The relative error is |measured - expected| / |expected|; where the "
         "test checks a bound (no expected value) or a difference against zero, it is `-` and "
         "the measured column is the value or the difference itself."),
        "",
    ]
    for stage in stages:
        lines += [f"## {stage}", "",
                  "| quantity | reference | expected | measured | rel. error | tolerance | test |",
                  "|---|---|---|---|---|---|---|"]
        for r in sorted((r for r in rows if r["stage"] == stage), key=lambda r: r["test"]):
            exp, meas = r.get("expected"), r["measured"]
            err = "-"
            if isinstance(exp, (int, float)) and isinstance(meas, (int, float)) and exp != 0:
                err = f"{abs(meas - exp) / abs(exp):.2e}"
            lines.append(
                f"| {_cell(r['quantity'])} | {_cell(r['reference'])} | {_num(exp)} | "
                f"{_num(meas)} | {err} | {_cell(r['tolerance'])} | "
                f"`{_cell(r['test'].split('::', 1)[-1])}` |")
        lines.append("")
    return "\n".join(lines)


#: (title, what, home subpackages): the API reference's groups, in reading order
API_GROUPS = [
    ("Scenes and runs", "Load, check and run scenes; machine files.",
     ("scene", "runner", "resources", "cli")),
    ("Geometry", "Parametric parts, meshing, CAD and mesh import.", ("geometry", "part")),
    ("Finite elements", "Materials, assembly, supports and loads, modes and static solves.",
     ("fem",)),
    ("Reduction", "Craig-Bampton flexible bodies and their files.", ("reduction",)),
    ("Mechanism", "Kinematics and forces of crank mechanisms.", ("mechanism",)),
    ("Torsion", "Torsional chains, Ker Wilson crank models, critical speeds.", ("torsion",)),
    ("Dynamics", "Bodies, joints, contact and friction laws, mechanisms and the integrator.",
     ("dynamics",)),
    ("Reports and sweeps", "The report and the sweep engine.", ("report", "sweep")),
    ("Errors", "What crankmodal raises; the command line maps them to exit statuses.",
     ("errors",)),
]


def _home(name: str) -> str:
    """The crankmodal subpackage (or top-level module) that defines public ``name``."""
    import crankmodal

    obj = getattr(crankmodal, name)
    module = getattr(obj, "__module__", None) or "crankmodal"
    if not module.startswith("crankmodal."):
        table = getattr(crankmodal, "_EXPORTS", {})
        module = table.get(name, module) if isinstance(table, dict) else module
        module = module if isinstance(module, str) else "crankmodal"
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def api_markdown() -> str:
    """The API reference page: every public name, grouped by its home subpackage."""
    import crankmodal

    names = [n for n in crankmodal.__all__ if n != "__version__"]
    groups: dict[str, list[str]] = {g[0]: [] for g in API_GROUPS}
    other = []
    for name in names:
        home = _home(name)
        for title, _, homes in API_GROUPS:
            if home in homes:
                groups[title].append(name)
                break
        else:
            other.append(name)
    lines = ["# API reference", "",
             ("Every public name of `crankmodal` (the names in `crankmodal.__all__`, generated "
              "from it at build time; `import crankmodal` is cheap and each name is imported "
              "from its home module on first use). Units are SI (m, kg, s, N, Pa, rad; Hz where "
              "a name says so). `crankmodal.__version__` is the installed version. Worked "
              "examples are in the [Python API](../guide/python_api.md) guide."), ""]
    for title, text, _ in API_GROUPS + [("Other", "", ())]:
        members = groups.get(title, other if title == "Other" else [])
        if not members:
            continue
        lines += [f"## {title}", "", text, "", "```{eval-rst}", ".. currentmodule:: crankmodal",
                  "", ".. autosummary::", "   :toctree: generated", "   :nosignatures:", ""]
        lines += [f"   {n}" for n in sorted(members, key=lambda n: (n[0].islower(), n.lower()))]
        lines += ["```", ""]
    return "\n".join(lines)


def _write_if_changed(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


SLOW_MARK = "# crankmodal: slow-notebook"  # as tests/test_notebooks.py
EXECUTE_ENV = "CRANKMODAL_DOCS_EXECUTE"


def _code_cells(nb: dict) -> list[str]:
    return ["".join(c["source"]).strip() for c in nb["cells"] if c["cell_type"] == "code"]


def _has_outputs(nb: dict) -> bool:
    return any(c.get("outputs") for c in nb["cells"] if c["cell_type"] == "code")


def gallery_plan(execute: bool | None = None) -> dict[str, str]:
    """How each notebook of ``notebooks/`` is shown: ``"committed"`` (it carries its outputs),
    ``"executed copy"`` (``gallery/executed/NAME.ipynb``, run once and committed, used while its
    code cells equal the notebook's), ``"execute"`` (a quick notebook, run at build) or
    ``"code only"`` (a slow one without an executed copy, or quick ones when
    ``CRANKMODAL_DOCS_EXECUTE=0``)."""
    import os

    if execute is None:
        execute = os.environ.get(EXECUTE_ENV, "1") != "0"
    plan = {}
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        nb = json.loads(path.read_text(encoding="utf-8"))
        copy = DOCS / "gallery" / "executed" / path.name
        pair = path.with_suffix(".py")
        slow = pair.exists() and SLOW_MARK in pair.read_text(encoding="utf-8")
        if _has_outputs(nb):
            plan[path.stem] = "committed"
        elif copy.exists() and _code_cells(json.loads(copy.read_text(encoding="utf-8"))) \
                == _code_cells(nb):
            plan[path.stem] = "executed copy"
        elif execute and not slow:
            plan[path.stem] = "execute"
        else:
            plan[path.stem] = "code only"
    return plan


def copy_notebooks(dest: Path, execute: bool | None = None) -> dict[str, str]:
    """Copy the notebooks into ``dest`` as :func:`gallery_plan` says (only when changed): an
    executed copy in place of the notebook, a quick one marked for execution at build
    (myst-nb's per-notebook ``execution_mode``). Returns the plan."""
    dest.mkdir(parents=True, exist_ok=True)
    plan = gallery_plan(execute)
    for name, how in plan.items():
        src = ROOT / "notebooks" / f"{name}.ipynb"
        if how == "executed copy":
            src = DOCS / "gallery" / "executed" / f"{name}.ipynb"
        nb = json.loads(src.read_text(encoding="utf-8"))
        if how == "execute":
            nb.setdefault("metadata", {})["mystnb"] = {"execution_mode": "force"}
        text = json.dumps(nb, indent=1, ensure_ascii=False) + "\n"
        _write_if_changed(dest / f"{name}.ipynb", text)
    for stale in dest.glob("*.ipynb"):
        if stale.stem not in plan:
            stale.unlink()
    return plan


def generate(app=None) -> None:
    """Write the generated pages into the source folder (before Sphinx reads it)."""
    _write_if_changed(DOCS / "reference" / "scene.md", scene_markdown())
    _write_if_changed(DOCS / "reference" / "api.md", api_markdown())
    _write_if_changed(DOCS / "validation.md", validation_markdown(load_oracles()))
    copy_notebooks(DOCS / "gallery" / "notebooks")


def setup(app):
    # config-inited: before Sphinx lists the source files and autosummary reads api.md for its
    # stubs (a fresh clone has none of the generated pages)
    app.connect("config-inited", lambda app, config: generate(app))
    return {"parallel_read_safe": True, "parallel_write_safe": True}
