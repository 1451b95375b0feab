"""Reports of crankmodal analyses: modal reports, mesh-simplification studies, renders.

Modules: :mod:`.mac` (modal assurance criterion), :mod:`.reference` (reference mode shapes
read from an untrusted file and checked whole), :mod:`.quantity` (every printed number:
engineering prefixes, en-dash ranges, no exponent notation), :mod:`.render` (off-screen pyvista
mode-shape and stress renders), :mod:`.plots` (matplotlib figures with CSV data),
:mod:`.study` (fidelity x mesh size x element order studies, Pareto front, recommendation),
:mod:`.modal_report` (self-contained HTML and Markdown), :mod:`.scene_report` (the report of
the whole scene: a section per stage with its verdict, tables and figures), :mod:`.testing`
(``assert_frequencies`` for users' test suites), :mod:`.stage` (the ``[report]`` section).
Nothing heavy is imported here.
"""

from .testing import assert_frequencies

__all__ = ["assert_frequencies"]
