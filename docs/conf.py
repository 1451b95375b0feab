"""Sphinx configuration of the crankmodal documentation site.

Build (no network needed)::

    pip install -e ".[docs]"
    sphinx-build -W docs docs/_build/html

The scene reference, the validation tables and the gallery copies of the notebooks are generated
at build time by ``_ext/crankmodal_docs.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(DOCS.parent / "src"))

import crankmodal

project = "crankmodal"
author = "the crankmodal authors"
copyright = "the crankmodal authors"
release = crankmodal.__version__
version = release

extensions = [
    "myst_nb",  # MyST Markdown pages and Jupyter notebooks
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinx.ext.mathjax",
    "crankmodal_docs",  # scene reference, validation tables, gallery (generated)
]

# no network: no intersphinx. Notebooks are shown with the outputs they carry; the quick ones
# without outputs are marked for execution by _ext/crankmodal_docs.py (per-notebook metadata)
nb_execution_mode = "off"
nb_execution_in_temp = True  # their files go to a temporary folder, not into docs/
nb_execution_timeout = 900
nb_execution_raise_on_error = True
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}

autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False

exclude_patterns = ["_build", "_ext", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints",
                    "validation/*.json", "gallery/executed"]
templates_path = ["_templates"]

html_theme = "pydata_sphinx_theme"
html_title = f"crankmodal {release}"
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "navbar_align": "left",
    "header_links_before_dropdown": 8,
}
html_static_path: list[str] = []
html_last_updated_fmt = None
