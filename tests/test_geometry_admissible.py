"""The admissible parameter space: random admissible cranks mesh well, others are refused by name.

Quality threshold: every tetrahedron of a coarse P1 mesh (about 5 elements around the pin) of
a random admissible dechamfered crank has gmsh minSICN >= MIN_SICN = 0.05 (regular tetrahedron:
1; gmsh flags elements below 0 as inverted). Observed minima are ~0.2.
"""

import dataclasses
import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from crankmodal.errors import GeometryError
from crankmodal.geometry import CrankshaftParams, MeshSettings, build_part
from crankmodal.geometry.checks import MARGIN, check_crankshaft

MIN_SICN = 0.05


@st.composite
def admissible_cranks(draw):
    """Cranks inside the admissible space (built feature by feature from its rules)."""
    n = draw(st.integers(1, 2))
    phases = tuple(draw(st.floats(0, 360)) for _ in range(n))
    dj = draw(st.floats(0.02, 0.08))
    dp = draw(st.floats(0.5, 1.0)) * dj
    r = draw(st.floats(0.3, 1.2)) * dj
    rows = draw(st.integers(1, 2))
    shape = draw(st.sampled_from(["stadium", "round"]))
    reach = dj / 2 if shape == "stadium" else max(dj / 2, r + dp / 2)
    reach = max(reach, dp / 2)
    width = 2 * MARGIN * reach * draw(st.floats(1.01, 1.6))
    cw = draw(st.sampled_from([0.0, 1.0])) * width / 2 * MARGIN * 1.05 * draw(st.floats(1.01, 1.8))
    return CrankshaftParams(
        phases_deg=phases, throw_radius=r, journal_diameter=dj, journal_length=draw(st.floats(0.3, 1.2)) * dj,
        pin_diameter=dp, pin_length=rows * draw(st.floats(0.4, 1.2)) * dp, rod_rows=rows,
        web_thickness=draw(st.floats(0.2, 0.6)) * dj, web_width=width, web_shape=shape,
        counterweight_radius=cw, counterweight_angle_deg=draw(st.floats(30, 180)),
        free_end_diameter=dj * 0.7, free_end_length=draw(st.sampled_from([0.0, 0.5 * dj])))


@pytest.fixture(scope="module", autouse=True)
def gmsh_once():
    """One gmsh initialisation for the module; each part then lives in its own model."""
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(interruptible=False)
    yield
    if owner:
        gmsh.finalize()


FAST = settings(max_examples=200, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


@FAST
@given(admissible_cranks())
def test_random_admissible_cranks_mesh_with_quality_above_threshold(p):
    check_crankshaft(p)
    part = build_part(p, "dechamfered", MeshSettings(p.pin_diameter / 1.5, 1))
    assert part.quality["min"] >= MIN_SICN
    assert part.n_elements > 0 and "main_journal_1" in part.regions
    assert abs(part.quality["mass_check"]["volume"]) < 0.05


# (parameter(s) a refusal may name, how to push the set out of the admissible space); a rule
# that couples parameters (a fillet must fit the web) may name either side of the coupling
VIOLATIONS = [
    ("throw_radius", lambda p: {"throw_radius": -p.throw_radius}),
    ("journal_diameter", lambda p: {"journal_diameter": 0.0}),
    ("web_width", lambda p: {"web_width": 0.9 * p.journal_diameter}),
    (("pin_fillet", "web_width", "pin_length"), lambda p: {"pin_fillet": 0.6 * p.web_thickness}),
    (("journal_length", "web_width"), lambda p: {"journal_fillet": 0.45 * p.web_thickness,
                                  "journal_length": 0.8 * p.web_thickness}),
    ("oil_hole_diameter", lambda p: {"oil_hole_diameter": 0.9 * p.pin_diameter}),
    ("counterweight_radius", lambda p: {"counterweight_radius": 0.5 * p.web_width}),
    ("rod_rows", lambda p: {"rod_rows": 0}),
    ("web_shape", lambda p: {"web_shape": "star"}),
    ("free_end_diameter", lambda p: {"free_end_diameter": 1.5 * p.journal_diameter, "free_end_length": 0.01}),
    ("flywheel_end_length", lambda p: {"flywheel_diameter": 5 * p.journal_diameter, "flywheel_thickness": 0.02}),
    ("keyway_depth", lambda p: {"keyway_width": 0.2 * p.free_end_diameter, "keyway_depth": p.free_end_diameter,
                                "keyway_length": 0.5 * p.free_end_length}),
]


@settings(max_examples=200, deadline=None, derandomize=True)
@given(admissible_cranks(), st.sampled_from(VIOLATIONS))
def test_parameters_outside_the_space_are_refused_naming_the_parameter(p, violation):
    names, push = violation
    names = (names,) if isinstance(names, str) else names
    if "keyway_depth" in names and p.free_end_length == 0:
        p = dataclasses.replace(p, free_end_length=0.5 * p.journal_diameter)
    bad = dataclasses.replace(p, **push(p))
    with pytest.raises(GeometryError) as err:
        check_crankshaft(bad)
    msg = str(err.value)
    assert msg.split(":")[0] in {f"crankshaft.{n}" for n in names}
    assert "must be" in msg and "\n" not in msg


def test_refusal_message_gives_the_admissible_range():
    p = CrankshaftParams(journal_diameter=0.06, journal_fillet=0.004, web_width=0.05)
    with pytest.raises(GeometryError, match=re.escape("crankshaft.web_width: must be >= 0.0714 m")):
        check_crankshaft(p)


def test_a_gmsh_failure_becomes_a_geometry_error_with_the_parameters(monkeypatch):
    import crankmodal.geometry.crankshaft as crank

    def broken(gmsh, p, fidelity):
        gmsh.model.occ.fillet([999], [1], [0.1])  # no such volume: gmsh raises

    monkeypatch.setattr(crank, "build_crankshaft", broken)
    with pytest.raises(GeometryError, match=r"geometry kernel failed.*parameters: \{'phases_deg'"):
        build_part(CrankshaftParams(), "full", MeshSettings(0.02, 1))
