"""Built solids against closed-form volumes of their primitives, and CAD vs mesh mass properties."""

import math

import numpy as np
import pytest

from crankmodal.geometry import ConrodParams, CrankshaftParams, MeshSettings, build_part
from crankmodal.geometry.conrod import build_conrod
from crankmodal.geometry.crankshaft import build_crankshaft
from crankmodal.geometry.massprops import cad_mass_properties
from crankmodal.geometry.session import gmsh_session

CRANK = CrankshaftParams(
    phases_deg=(0.0, 180.0), throw_radius=0.035, journal_diameter=0.052, journal_length=0.04,
    pin_diameter=0.05, pin_length=0.06, rod_rows=2, web_thickness=0.02, web_width=0.09,
    counterweight_radius=0.08, counterweight_angle_deg=120.0, journal_fillet=0.003, pin_fillet=0.003,
    journal_chamfer=0.0015, oil_hole_diameter=0.005, free_end_diameter=0.04, free_end_length=0.05,
    flywheel_end_diameter=0.045, flywheel_end_length=0.06, flywheel_diameter=0.2, flywheel_thickness=0.04,
    flywheel_rim_width=0.015, flywheel_web_thickness=0.015, flywheel_hub_diameter=0.07,
    keyway_width=0.012, keyway_depth=0.005, keyway_length=0.03)

ROD = ConrodParams(
    length=0.392, big_end_bore=0.044, big_end_outer_diameter=0.070, big_end_width=0.028,
    small_end_bore=0.024, small_end_outer_diameter=0.040, small_end_width=0.026, bushing_thickness=0.002,
    shank_depth=0.030, shank_width=0.022, shank_web_thickness=0.007, shank_flange_thickness=0.006,
    shank_fillet=0.002, bolt_boss_width=0.012, bolt_boss_height=0.030, bolt_diameter=0.008)


def crank_volume_closed_form(p: CrankshaftParams, simplified: bool) -> float:
    """Sum of cylinders, web slabs (stadium + counterweight sector; simplified: their envelope
    block), flywheel, minus keyway."""
    rj, rp, a, r = p.journal_diameter / 2, p.pin_diameter / 2, p.web_width / 2, p.throw_radius
    n = len(p.phases_deg)
    v = (n + 1) * math.pi * rj ** 2 * p.journal_length + n * math.pi * rp ** 2 * p.pin_length
    rs_f, rs_w = p.free_end_diameter / 2, p.flywheel_end_diameter / 2
    v += math.pi * rs_f ** 2 * p.free_end_length + math.pi * rs_w ** 2 * p.flywheel_end_length
    if simplified:  # the envelope block: web width by counterweight tip to pin end
        web = 2 * a * (max(a, p.counterweight_radius) + (r + a if p.web_shape == "stadium" else a))
    else:
        web = 2 * a * r + math.pi * a ** 2                    # stadium: rectangle + two half discs
        alpha = math.radians(p.counterweight_angle_deg) / 2
        web += alpha * (p.counterweight_radius ** 2 - a ** 2)  # sector beyond the web's end disc
    v += 2 * n * p.web_thickness * web
    rf, t = p.flywheel_diameter / 2, p.flywheel_thickness
    rin, rh = rf - p.flywheel_rim_width, p.flywheel_hub_diameter / 2
    fly = math.pi * rf ** 2 * t - math.pi * (rin ** 2 - rh ** 2) * (t - p.flywheel_web_thickness)
    if simplified:  # a plain disc of the same volume, the stub inside it
        v += fly * (1 - rs_w ** 2 / rf ** 2)
    else:
        v += fly - math.pi * rs_w ** 2 * t
        w, d = p.keyway_width / 2, p.keyway_depth
        seg = (w * math.sqrt(rs_f ** 2 - w ** 2) + rs_f ** 2 * math.asin(w / rs_f)) - 2 * w * (rs_f - d)
        v -= seg * p.keyway_length
    return v


def _strip(y0, y1, r):
    """Integral of sqrt(r^2 - y^2) dy from y0 to y1."""
    f = lambda y: 0.5 * (y * math.sqrt(r * r - y * y) + r * r * math.asin(y / r))
    return f(y1) - f(y0)


def rod_volume_closed_form(p: ConrodParams, simplified: bool) -> float:
    """Eyes (annuli), bolt-boss boxes less their circular segments, I-shank outside the eyes."""
    rbi, rbo, rso, rb = (p.big_end_bore / 2, p.big_end_outer_diameter / 2,
                         p.small_end_outer_diameter / 2, p.small_end_bore / 2)
    big = math.pi * (rbo ** 2 - rbi ** 2)
    if not simplified:
        hb = p.bolt_boss_height
        y0 = math.sqrt(rbo ** 2 - (hb / 2) ** 2)
        segment = rbo ** 2 * math.acos(y0 / rbo) - y0 * hb / 2
        big += 2 * (hb * (rbo + p.bolt_boss_width - y0) - segment)
    v = big * p.big_end_width + math.pi * (rso ** 2 - rb ** 2) * p.small_end_width
    h, b, tw, tf = p.shank_depth, p.shank_width, p.shank_web_thickness, p.shank_flange_thickness
    for y0, y1, width in ((h / 2 - tf, h / 2, b), (-h / 2, -h / 2 + tf, b), (-h / 2 + tf, h / 2 - tf, tw)):
        v += width * (p.length * (y1 - y0) - _strip(y0, y1, rbo) - _strip(y0, y1, rso))
    return v


def cad_volume(builder, params, fidelity):
    with gmsh_session("test", {}) as gmsh:
        volumes, _, _ = builder(gmsh, params, fidelity)
        return cad_mass_properties(gmsh, volumes).volume


@pytest.mark.parametrize("fidelity", ["dechamfered", "simplified"])
def test_crank_volume_equals_closed_form_of_primitives_within_1e_6(oracle, fidelity):
    v = cad_volume(build_crankshaft, CRANK, fidelity)
    oracle(stage="geometry", quantity=f"crankshaft volume ({fidelity}), m^3", reference="closed form of the primitives", tolerance="1e-6", measured=v, expected=crank_volume_closed_form(CRANK, fidelity == "simplified"))
    assert v == pytest.approx(crank_volume_closed_form(CRANK, fidelity == "simplified"), rel=1e-6)


@pytest.mark.parametrize("shape", ["round"])
def test_round_web_crank_volume_equals_closed_form(shape):
    import dataclasses

    p = dataclasses.replace(CRANK, web_shape=shape, web_width=0.13, keyway_length=0, keyway_width=0,
                            keyway_depth=0, counterweight_radius=0.1)
    a, r = p.web_width / 2, p.throw_radius
    expected = crank_volume_closed_form(p, False) - 2 * 2 * p.web_thickness * (2 * a * r)  # disc, not stadium
    assert cad_volume(build_crankshaft, p, "dechamfered") == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("fidelity", ["dechamfered", "simplified"])
def test_rod_volume_equals_closed_form_of_primitives_within_1e_6(oracle, fidelity):
    v = cad_volume(build_conrod, ROD, fidelity)
    oracle(stage="geometry", quantity=f"connecting-rod volume ({fidelity}), m^3", reference="closed form of the primitives", tolerance="1e-6", measured=v, expected=rod_volume_closed_form(ROD, fidelity == "simplified"))
    assert v == pytest.approx(rod_volume_closed_form(ROD, fidelity == "simplified"), rel=1e-6)


def test_full_crank_is_lighter_than_dechamfered_by_its_holes_and_keyway():
    # fillets add material, chamfers and oil drillings remove it: the net change is small
    full = cad_volume(build_crankshaft, CRANK, "full")
    dech = cad_volume(build_crankshaft, CRANK, "dechamfered")
    assert abs(full / dech - 1) < 0.01 and full != dech


@pytest.mark.parametrize("fidelity, order, tol", [("full", 1, 5e-3), ("dechamfered", 2, 1e-4)])
def test_cad_mass_properties_agree_with_mesh_integration(oracle, fidelity, order, tol):
    """CAD (OCC) volume, centroid and inertia vs the same integrated over the mesh: 0.5 % for P1
    (faceting) and 1e-4 for curved P2 at a moderate mesh (8-10 mm on a 0.45 m crank)."""
    part = build_part(CRANK, fidelity, MeshSettings(0.008 if order == 1 else 0.01, order))
    check = part.quality["mass_check"]
    oracle(stage="geometry", quantity=f"crankshaft mesh volume vs CAD ({fidelity}, P{order}), relative difference", reference="OpenCASCADE CAD volume (second formulation)", tolerance=f"{tol:g}", measured=abs(check["volume"]), expected=0.0)
    assert abs(check["volume"]) < tol
    assert abs(check["centroid"]) < tol
    assert abs(check["inertia"]) < tol
    # the inertia tensor is symmetric positive definite (a physical body)
    inertia = part.cad_mass.inertia_per_density
    assert np.allclose(inertia, inertia.T, atol=1e-12 * np.abs(inertia).max())
    assert np.all(np.linalg.eigvalsh(inertia) > 0)
