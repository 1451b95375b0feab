"""Static strength against beam theory, Lamé's thick cylinder and load equilibrium."""

import numpy as np
import pytest
from fem_beam_theory import lame_thick_cylinder, rectangle_shear_coefficient
from fem_parts import bar, tube

from crankmodal.errors import ParameterError
from crankmodal.fem import assembly, loads, static, supports
from crankmodal.fem.materials import material

STEEL = material("steel")
L, B, H, P = 1.0, 0.05, 0.05, 1000.0
I = B * H**3 / 12


@pytest.fixture(scope="module")
def cantilever():
    part = bar(L, B, H, (40, 3, 3), order=2)
    model = assembly.assemble(part, STEEL)
    sup = supports.select(part, [{"region": "end_x0", "fix": "xyz"}], "static")
    return part, model, sup


def _timoshenko_tip(P, a, moment=0.0):
    G, k = STEEL.shear_modulus, rectangle_shear_coefficient(STEEL.nu)
    return P * a**3 / (3 * STEEL.E * I) + P * a / (k * G * B * H) + moment * a**2 / (2 * STEEL.E * I)


def test_cantilever_tip_deflection_within_1_percent_of_timoshenko(oracle, cantilever):
    part, model, sup = cantilever
    f = loads.traction_force(model.points, model.cells, part.regions["end_x1"].facets, [0, 0, -P])
    res = static.solve_static(model, part.mesh, f, sup)
    tip = -res.displacement[part.regions["end_x1"].nodes, 2].mean()
    # the 3-D clamp restrains the root's Poisson contraction: 0.5 % stiffer than beam theory
    oracle(stage="fem", quantity="cantilever tip deflection under an end load, m", reference="Timoshenko beam, closed form", tolerance="1 %", measured=tip, expected=_timoshenko_tip(P, L))
    assert tip == pytest.approx(_timoshenko_tip(P, L), rel=0.01)
    np.testing.assert_allclose(res.reaction, [0, 0, P], atol=1e-6 * P)


def test_cantilever_bending_stress_near_root_and_midspan_within_1_percent(cantilever):
    part, model, sup = cantilever
    f = loads.traction_force(model.points, model.cells, part.regions["end_x1"].facets, [0, 0, -P])
    res = static.solve_static(model, part.mesh, f, sup)
    x = model.points
    for xs in (0.1, 0.5):  # 0.1 L: two elements off the clamp's local singular corners
        top = np.isclose(x[:, 2], H / 2) & np.isclose(x[:, 0], xs)
        sigma = P * (L - xs) * (H / 2) / I
        assert res.stress[top, 0, 0].mean() == pytest.approx(sigma, rel=0.01)
        assert res.von_mises[top].mean() == pytest.approx(sigma, rel=0.01)
    # the maximum sits at the root (within 5 % of the length), above the beam-theory value
    assert res.max_location[0] < 0.05 * L
    assert res.max_von_mises >= P * L * (H / 2) / I
    assert res.safety_factor_yield == pytest.approx(STEEL.yield_strength / res.max_von_mises)


def test_remote_force_through_a_coupling_adds_the_lever_moment(cantilever):
    part, model, sup = cantilever
    e = 0.2  # force applied 0.2 m beyond the tip, axially in line
    f = loads.remote_force(model.points, model.cells, part.regions["end_x1"].facets,
                           [0, 0, -P], point=[L + e, 0, 0])
    F = f.reshape(-1, 3)
    np.testing.assert_allclose(F.sum(0), [0, 0, -P], atol=1e-9 * P)
    np.testing.assert_allclose(np.cross(model.points - [L + e, 0, 0], F).sum(0), 0, atol=1e-9 * P)
    res = static.solve_static(model, part.mesh, f, sup)
    tip = -res.displacement[part.regions["end_x1"].nodes, 2].mean()
    assert tip == pytest.approx(_timoshenko_tip(P, L, moment=P * e), rel=0.01)


def test_pressure_on_a_flat_face_sums_to_pressure_times_area_along_the_inward_normal(cantilever):
    part, model, _ = cantilever
    f = loads.pressure_load(model.points, model.cells, part.regions["top"].facets, 2e5)
    np.testing.assert_allclose(f.reshape(-1, 3).sum(0), [0, 0, -2e5 * L * B], rtol=1e-12, atol=1e-9)


def test_thick_cylinder_under_internal_pressure_matches_lame(oracle):
    a, b, p = 0.05, 0.1, 1e7
    part = tube(a, b, 0.02, (4, 8, 1), angle=np.pi / 2, order=2)  # quarter ring, plane strain
    model = assembly.assemble(part, STEEL)
    sup = supports.select(part, [{"region": "cut_0", "fix": "y"}, {"region": "cut_1", "fix": "x"},
                                 {"region": "end_z0", "fix": "z"}, {"region": "end_z1", "fix": "z"}])
    f = loads.pressure_load(model.points, model.cells, part.regions["bore"].facets, p)
    res = static.solve_static(model, part.mesh, f, sup)
    for r, name in ((a, "bore"), (b, "outer")):
        nodes = part.regions[name].nodes
        ur = np.hypot(res.displacement[nodes, 0], res.displacement[nodes, 1])
        u_exact = lame_thick_cylinder(r, a, b, p, STEEL.E, STEEL.nu)[0]
        oracle(stage="fem", quantity=f"thick cylinder under internal pressure, radial displacement at the {name}, m", reference="Lame, closed form", tolerance="0.2 %", measured=ur.mean(), expected=u_exact)
        np.testing.assert_allclose(ur, u_exact, rtol=2e-3)
    _, sr, st, sz = lame_thick_cylinder(a, a, b, p, STEEL.E, STEEL.nu)
    vm = np.sqrt(0.5 * ((sr - st) ** 2 + (st - sz) ** 2 + (sz - sr) ** 2))
    # the peak is at the bore; nodal averaging of P2 stresses gets it within 2 %
    oracle(stage="fem", quantity="thick cylinder under internal pressure, peak von Mises stress, Pa", reference="Lame, closed form", tolerance="2 %", measured=res.max_von_mises, expected=vm)
    assert res.max_von_mises == pytest.approx(vm, rel=0.02)
    assert np.hypot(*res.max_location[:2]) == pytest.approx(a, rel=1e-9)


def test_static_solve_on_a_mechanism_is_refused_with_the_count(cantilever):
    part, model, _ = cantilever
    # z fixed on the face x = 0 stops z-translation and rotation about x only
    sup = supports.select(part, [{"region": "end_x0", "fix": "z"}], "static")
    f = np.zeros(model.K.shape[0])
    with pytest.raises(ParameterError, match=r"^supports: .*mechanism with 4 rigid"):
        static.solve_static(model, part.mesh, f, sup)


def test_seed000_table2_rod_row_runs_from_its_scene_with_the_shank_at_f_over_a(tmp_path):
    """Seed 000 Table 2, connecting rod: big end fixed, the peak rod force (3303 N) on the small
    end through a distributing coupling. Oracle: the prismatic I-shank between the eyes carries
    σxx = −F/A exactly (P2 holds a uniform stress). The peak sits where the flange meets the
    small eye — the seed's "transition of the small end to the rod body" — and the safety factor
    is 42CrMo's 930 MPa over it."""
    from pathlib import Path

    from crankmodal.fem import static_stage
    from crankmodal.geometry import stage as gs
    from crankmodal.geometry.params import params_from_dict
    from crankmodal.scene import load_scene

    repo = Path(__file__).resolve().parent.parent
    scene = load_scene(repo / "scenes" / "seed000_rod_static.toml")
    geo = dict(scene.sections["geometry"], mesh_size=0.006, cache=False)
    part, _ = gs.make_part(gs.validate(geo, scene))
    mat = material(scene.sections["material"]["name"])
    model = assembly.assemble(part, mat)
    p = static_stage.validate(scene.sections["static"], scene)
    sup = supports.select(part, p["supports"], "static")
    f = static_stage.load_vector(part, model, p["loads"])
    res = static.solve_static(model, part.mesh, f, sup)

    import tomllib

    with open(repo / "geometry" / "four_star_compressor.toml", "rb") as fh:
        rod = params_from_dict("rod", tomllib.load(fh)["rod"])
    F = -p["loads"][0]["remote_force"][0]
    assert F == pytest.approx(3303.0)
    h, b, tw, tf = rod.shank_depth, rod.shank_width, rod.shank_web_thickness, rod.shank_flange_thickness
    A = 2 * b * tf + (h - 2 * tf) * tw
    np.testing.assert_allclose(res.reaction, -f.reshape(-1, 3).sum(axis=0), atol=1e-6 * F)
    x = model.points[:, 0]
    mid = model.used & (np.abs(x - rod.length / 2) < 0.003)
    np.testing.assert_allclose(res.stress[mid, 0, 0], -F / A, rtol=1e-3)  # -11.97 MPa
    # the peak: on a flange's outer face, between the shank and where it meets the small eye
    rso = rod.small_end_outer_diameter / 2
    junction = rod.length - np.sqrt(rso**2 - (h / 2) ** 2)
    loc = res.max_location
    assert abs(abs(loc[1]) - h / 2) < 1e-6
    assert junction - 0.006 < loc[0] < junction + 0.001
    assert 1.5 < res.max_von_mises / (F / A) < 4.0  # a concentration, seed: 29.95 / 11.97 = 2.5
    assert res.safety_factor_ultimate == pytest.approx(930e6 / res.max_von_mises)


def test_bearing_load_is_a_cosine_pressure_on_the_loaded_half_of_the_bore():
    """A pin's radial force on a bore: nodal forces add up to F exactly, sit only on the half
    facing F, and near θ = 0 equal cos θ times those of a uniform pressure p0 = 2F/(πRL)."""
    part = tube(0.02, 0.04, 0.05, divisions=(2, 32, 4), order=2)
    model = assembly.assemble(part, STEEL)
    reg = part.regions["bore"]
    cyl = reg.cylinder
    F = np.array([0.0, -3000.0, 0.0])
    f = loads.bearing_load(model.points, model.cells, reg.facets, F, cyl.axis)
    f3 = f.reshape(-1, 3)
    np.testing.assert_allclose(f3.sum(axis=0), F, atol=1e-9 * 3000)
    x = model.points - cyl.centre
    er = x - np.outer(x @ cyl.axis, cyl.axis)
    er /= np.maximum(np.linalg.norm(er, axis=1, keepdims=True), 1e-300)
    cos = er @ (F / 3000.0)
    loaded = np.linalg.norm(f3, axis=1) > 0
    assert np.all(cos[loaded] > -0.2)  # only facets reaching the loaded half carry load
    # (P2 corner nodes of a pressure can carry small negative shares: nodes, not signs, checked)
    p0 = 2 * 3000.0 / (np.pi * cyl.radius * cyl.length)
    uniform = loads.pressure_load(model.points, model.cells, reg.facets, p0).reshape(-1, 3)
    for edge in (0.99, 0.5):  # summed over bands (P2 shares move between a facet's nodes)
        band = reg.nodes[cos[reg.nodes] > edge]
        radial = np.einsum("ij,ij->i", f3[band], er[band]).sum()
        expect = (cos[band] * np.einsum("ij,ij->i", uniform[band], er[band])).sum()
        assert radial == pytest.approx(expect, rel=0.02)
    with pytest.raises(ParameterError, match="^force: .* along the bore axis"):
        loads.bearing_load(model.points, model.cells, reg.facets, [0, -3000.0, 50.0], cyl.axis)
    # a journal (the tube's outer surface) pressed by a shell: loaded on the side facing away
    # from the force, pushed inward
    out = part.regions["outer"]
    g3 = loads.bearing_load(model.points, model.cells, out.facets, F,
                            out.cylinder.axis).reshape(-1, 3)
    np.testing.assert_allclose(g3.sum(axis=0), F, atol=1e-9 * 3000)
    assert np.all(cos[np.linalg.norm(g3, axis=1) > 0] < 0.2)
