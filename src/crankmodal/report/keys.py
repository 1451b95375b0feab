"""The ``[report]`` scene section's keys (:data:`SCHEMA`).

Their own module because two modules read them: the report stage (:mod:`.stage`, which
validates the section) and the simplification study (:mod:`.study_scene`, which fills the
``study_*`` defaults when a scene has no ``[report]``). The stage runs the study, so the study
importing the keys from the stage made the import cycle ``stage <-> study_scene``.
"""

from __future__ import annotations

from ..schema import Field

SECTION = "report"

SCHEMA: dict[str, Field] = {
    "title": Field("str", None, "report title (default: the part's name and fidelity)"),
    "renders": Field("bool", True, "render every mode shape off-screen (pyvista) with one camera"),
    "max_renders": Field("int", 12, "render at most this many modes", ge=1, le=100),
    "gif": Field("bool", False, "also an animated GIF per rendered mode"),
    "stress": Field("bool", True, "render von Mises stress when the scene has [static]"),
    "measured_hz": Field("floats", None, "measured natural frequencies of the first modes, Hz "
                         "(seed 000 crank: [1356, 1489]; rod: [780, 1115, 1687])", gt=0.0),
    "measured_modes": Field("ints", None, "computed mode number (from 1) of each measured_hz "
                            "value (default 1, 2, ...)", ge=1),
    "reference": Field("str", None, "reference modes for the MAC matrix: another run's modes.vtu "
                       "or an .npz {points (m), shapes, frequencies_hz}; relative to the scene"),
    "reference_max_distance": Field("float", None, "drop reference points farther than this "
                                    "from every node, m (default 2 % of the part's size)", gt=0.0),
    "study": Field("bool", False, "also run the mesh-simplification study"),
    "study_fidelities": Field("strs", None, "fidelities of the study (default all three)",
                              choices=("full", "dechamfered", "simplified")),
    "study_sizes": Field("floats", None, "mesh sizes of the study, m (default: geometry "
                         "mesh_size x [2, 1.41, 1])", gt=0.0),
    "study_orders": Field("ints", None, "element orders of the study (default [1, 2])",
                          check=lambda v: None if set(v) <= {1, 2} and v else
                          "must be a non-empty list of 1 and/or 2"),
    "study_modes": Field("int", None, "modes tabulated in the study (default min(n_modes, 6))",
                         ge=1, le=50),
    "study_reference": Field("str", "auto", "reference of the study's errors: auto (measured_hz "
                             "when given, else computed), computed (Richardson of the finest "
                             "full model), measured", choices=("auto", "computed", "measured")),
    "compared_modes": Field("int", None, "modes entering a model's error (default: the measured "
                            "ones, else all tabulated)", ge=1),
    "tolerance": Field("float", 0.05, "admissible relative frequency error |f - f_ref| / f_ref: "
                       "the verdict of each measured_hz value and the study's recommendation",
                       gt=0.0, lt=1.0),
}


#: keys that need the FE part's modes ([geometry], [material] and [modal] in the scene)
MODAL_KEYS = ("measured_hz", "measured_modes", "reference", "study")
