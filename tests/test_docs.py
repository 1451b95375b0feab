"""The documentation site (docs/): it builds with warnings as errors and without network, its
internal links resolve, every scene key and every public name is documented, the validation data
the tests write is sound, the main entry points' Examples run, and the README stays short and
points at pages that exist."""

import doctest
import importlib
import json
import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from conftest import ORACLE_STAGES, REPO

DOCS = REPO / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
import crankmodal_docs

#: modules whose docstring Examples are executed (the main entry points)
DOCTEST_MODULES = (
    "crankmodal.scene",
    "crankmodal.runner",
    "crankmodal.resources",
    "crankmodal.fem.materials",
    "crankmodal.fem.assembly",
    "crankmodal.fem.loads",
    "crankmodal.torsion.chain",
    "crankmodal.torsion.holzer",
    "crankmodal.torsion.two_rotor",
    "crankmodal.dynamics.laws.objects",
    "crankmodal.fem.modal",
)
#: public names that must carry an executed Examples section
WITH_EXAMPLES = ("scene_from_dict", "check_scene", "load_machine", "list_machines", "scene_path",
                 "material", "mass_properties", "pressure_load", "solve_modes", "TorsionalChain",
                 "exact_modes", "holzer", "two_rotor", "make_law", "make_friction")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """Build the site once (html, warnings as errors, no network); the output folder.

    The build runs on a snapshot of the source tree (docs/ and what its pages include), so that
    the pages it generates do not land in the working tree and another build running at the
    same time cannot interleave with this one."""
    import shutil

    out = tmp_path_factory.mktemp("site")
    tree = out / "tree"
    shutil.copytree(REPO, tree, ignore=shutil.ignore_patterns(
        ".git", ".venv", "out", "__pycache__", "_build", "*.egg-info", ".cache", ".pytest_cache",
        ".hypothesis", "generated", "*.nbi", "*.nbc"))
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONWARNINGS="ignore")
    # the quick notebooks are not executed here (tests/test_notebooks.py runs them; the real build
    # does, 2-3 min more): the build is checked with their committed or executed-copy outputs
    env["CRANKMODAL_DOCS_EXECUTE"] = "0"
    env["PYTHONPATH"] = os.pathsep.join([str(tree / "src"), env.get("PYTHONPATH", "")])
    # no proxy either: a build that tried the network would fail here, not hang
    env.update(http_proxy="http://0.0.0.0:9", https_proxy="http://0.0.0.0:9")
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q",
         "-d", str(out / "doctrees"), str(tree / "docs"), str(out / "html")],
        env=env, capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, proc.stderr[-6000:]
    return out / "html"


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"])
        if tag == "a" and a.get("name"):
            self.ids.add(a["name"])
        for key in ("href", "src"):
            if a.get(key) and tag in ("a", "img", "link", "script"):
                self.links.append(a[key])


def _parse(path: Path) -> _Links:
    p = _Links()
    p.feed(path.read_text(encoding="utf-8"))
    return p


def test_site_builds_and_every_internal_link_and_anchor_resolves(site):
    pages = sorted(p for p in site.rglob("*.html")
                   if p.relative_to(site).parts[0] not in ("_static", "_sources"))
    assert len(pages) > 100  # guide, reference (one page per public name), gallery, theory
    parsed = {p: _parse(p) for p in pages}
    broken = []
    for page, p in parsed.items():
        for link in p.links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "javascript:")):
                continue
            target = page if not parts.path else (page.parent / unquote(parts.path)).resolve()
            if not target.exists():
                broken.append(f"{page.relative_to(site)}: {link}")
                continue
            if (parts.fragment and target.suffix == ".html" and target in parsed
                    and unquote(parts.fragment) not in parsed[target].ids):
                broken.append(f"{page.relative_to(site)}: {link} (no such anchor)")
    assert not broken, "\n".join(broken[:40])


def test_every_scene_key_has_a_description_and_is_on_the_reference_page(site):
    from crankmodal.runner import STAGES
    from crankmodal.schema import Field

    listed = {id(schema) for _, _, schema in crankmodal_docs.schema_tables()}
    # every section the runner knows has its table, every Field table of a stage is listed
    tables = [t for t, *_ in crankmodal_docs.SCENE_TABLES]
    assert set(STAGES) <= set(tables)
    for module in {m for _, m, _, _ in crankmodal_docs.SCENE_TABLES} | set(STAGES.values()):
        mod = importlib.import_module(module)
        for name, value in vars(mod).items():
            if isinstance(value, dict) and value and all(isinstance(v, Field)
                                                         for v in value.values()):
                assert id(value) in listed, f"{module}.{name} is not in the scene reference"
    text = (site / "reference" / "scene.html").read_text(encoding="utf-8")
    n = 0
    for table, _, schema in crankmodal_docs.schema_tables():
        for key, field in schema.items():
            assert field.doc.strip(), f"{table}.{key} has no description"
            assert f"<code class=\"docutils literal notranslate\"><span class=\"pre\">{key}</span>" \
                   f"</code>" in text, key
            n += 1
    assert n > 200


def test_every_public_name_is_in_the_api_reference(site):
    import crankmodal

    text = (site / "reference" / "api.html").read_text(encoding="utf-8")
    for name in crankmodal.__all__:
        if name == "__version__":
            assert "__version__" in text
            continue
        assert (site / "reference" / "generated" / f"crankmodal.{name}.html").exists(), name
        assert f"crankmodal.{name}.html" in text, name
        assert (getattr(crankmodal, name).__doc__ or "").strip(), f"{name} has no docstring"


def test_main_entry_points_carry_examples_and_their_doctests_pass():
    import crankmodal

    for name in WITH_EXAMPLES:
        assert "Examples\n" in getattr(crankmodal, name).__doc__, name
    finder, runner = doctest.DocTestFinder(), doctest.DocTestRunner(verbose=False)
    n = 0
    for module in DOCTEST_MODULES:
        mod = importlib.import_module(module)
        for test in finder.find(mod, module):
            if test.examples:
                test.globs = dict(test.globs)
                runner.run(test, out=lambda s: None)
                n += len(test.examples)
    results = runner.summarize(verbose=False)
    assert results.failed == 0, f"{results.failed} of {results.attempted} doctest examples failed"
    assert n >= 30


def test_validation_data_is_valid_and_every_stage_has_rows():
    rows = crankmodal_docs.load_oracles()
    stages = {r["stage"] for r in rows}
    # the stages the site has a guide page for; sweeps compare against the same oracles
    assert {"geometry", "fem", "reduction", "mechanism", "torsion", "dynamics",
            "flexible", "report"} <= stages
    for r in rows:
        assert r["stage"] in ORACLE_STAGES
        assert r["quantity"] and r["reference"] and r["tolerance"], r
        assert isinstance(r["measured"], float), r
        assert r["expected"] is None or isinstance(r["expected"], float), r
        path, _, name = r["test"].partition("::")
        source = (REPO / path).read_text(encoding="utf-8")
        assert f"def {name.split('[')[0]}(" in source, r["test"]
        assert "oracle(" in source, r["test"]
    # every table row is on the page, with its relative error
    page = crankmodal_docs.validation_markdown(rows)
    assert page.count("\n| ") - len(stages) == len(rows)


def test_validation_page_is_generated_from_the_json_not_typed():
    rows = [{"stage": "fem", "quantity": "q", "reference": "closed form", "tolerance": "1 %",
             "measured": 1.01, "expected": 1.0, "test": "tests/x.py::test_y"}]
    page = crankmodal_docs.validation_markdown(rows)
    assert "| q | closed form | 1 | 1.01 | 1.00e-02 | 1 % | `test_y` |" in page


def test_readme_is_short_and_links_only_to_files_that_exist():
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 200
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    test_command = re.search(r"^python3 -m venv .*pytest -q$", text, re.MULTILINE).group(0)
    assert test_command in ci
    assert "python3 -m venv .venv && .venv/bin/pip install -q -e . && .venv/bin/crankmodal demo" \
        in text
    for link in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if urlsplit(link).scheme:
            continue
        assert (REPO / link).exists(), link
    # no leftover editing text, and no statement that the reduction does not feed the dynamics
    assert '"' not in "".join(re.findall(r"^#+ .*$", text, re.MULTILINE))
    assert "not yet used" not in text


def test_every_notebook_is_shown_with_its_figures_when_the_site_is_built():
    """Committed outputs, an executed copy whose code equals the notebook's, or executed at
    build (quick ones); only the notebooks named here are shown as code only."""
    code_only = set()  # the slow ones (seed000_crank_and_flexible: 7 min) have executed copies
    plan = crankmodal_docs.gallery_plan(execute=True)
    assert set(plan) == {p.stem for p in (REPO / "notebooks").glob("*.ipynb")}
    assert {n for n, how in plan.items() if how == "code only"} <= code_only, plan
    assert plan["walkthrough"] == "committed"
    # an executed copy whose code no longer matches the notebook is not used
    for copy in (DOCS / "gallery" / "executed").glob("*.ipynb"):
        assert plan[copy.stem] == "executed copy", copy.name


@pytest.mark.parametrize("page", ["README.md", "docs/getting_started.md"])
def test_the_python_and_toml_examples_of_the_front_pages_run(page, tmp_path, monkeypatch):
    """The README's and Getting started's Python blocks run as printed (in a temporary folder),
    and their TOML scenes pass ``check_scene``."""
    import tomllib

    import crankmodal as cm

    text = (REPO / page).read_text(encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "docs_example"}
    blocks = re.findall(r"^```python\n(.*?)^```", text, re.DOTALL | re.MULTILINE)
    assert blocks
    for i, code in enumerate(blocks):
        exec(compile(code, f"{page} python block {i + 1}", "exec"), namespace)  # noqa: S102
    for block in re.findall(r"^```toml\n(.*?)^```", text, re.DOTALL | re.MULTILINE):
        cm.check_scene(cm.scene_from_dict(tomllib.loads(block), base_dir=REPO / "scenes"))


def test_oracle_json_round_trips():
    path = DOCS / "validation" / "oracles.json"
    data = json.loads(path.read_text(encoding="utf-8"))
    assert list(data) == ["oracles"] and data["oracles"]
