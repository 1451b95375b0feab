"""Typed supports and loads for the Python API (Support.region / Support.box, Load.*): their
oracles (resultants and moments in closed form, node counts of a structured grid, a cantilever
against Timoshenko), errors naming the argument, and the scene path keeping its scene keys."""

from pathlib import Path

import numpy as np
import pytest
from fem_beam_theory import rectangle_shear_coefficient
from fem_parts import bar, tube

import crankmodal as cm
from crankmodal.errors import ParameterError, SceneError
from crankmodal.fem import assembly, material_stage, static, static_stage, supports
from crankmodal.fem.loads import Load
from crankmodal.fem.materials import material
from crankmodal.fem.supports import Support, select_supports
from crankmodal.runner import StageContext
from crankmodal.scene import Scene

STEEL = material("steel")
L, B, H, P = 1.0, 0.05, 0.05, 1000.0


@pytest.fixture(scope="module")
def cantilever():
    part = bar(L, B, H, (40, 3, 3), order=2)
    return part, assembly.assemble(part, STEEL)


@pytest.fixture(scope="module")
def ring():
    return tube(0.02, 0.04, 0.05, divisions=(2, 32, 4), order=2)


def _timoshenko_tip(P, a):
    G, k, I = STEEL.shear_modulus, rectangle_shear_coefficient(STEEL.nu), B * H**3 / 12
    return P * a**3 / (3 * STEEL.E * I) + P * a / (k * G * B * H)


# --- supports --------------------------------------------------------------------------------

def test_support_box_holds_exactly_the_grid_layers_inside():
    """A structured 4 x 2 x 2 bar, x-layers every L/4 (P1) or L/8 (P2): a box reaching x = 0.3
    holds 2 layers of 3 x 3 corner nodes (P1) or 3 layers of 5 x 5 nodes (P2)."""
    for order, count, last in ((1, 2 * 9, 0.25), (2, 3 * 25, 0.25)):
        part = bar(1.0, 0.1, 0.1, (4, 2, 2), order=order)
        s = Support.box(part, [-1.0, 0.3, -1, 1, -1, 1], fix="x")
        assert len(s.nodes) == count and s.fix == "x" and s.label == "box"
        xs = np.unique(np.round(part.mesh.points[s.nodes, 0], 12))
        assert xs.max() == last and len(xs) == count // (9 if order == 1 else 25)
    # bounds are included: a box that is the plane x = 0 holds the end face's nodes
    face = Support.box(part, [0, 0, -1, 1, -1, 1])
    np.testing.assert_array_equal(face.nodes, part.regions["end_x0"].nodes)


def test_support_region_and_select_supports_take_objects_and_tables(ring):
    s = Support.region(ring, "bore", fix="radial")
    np.testing.assert_array_equal(s.nodes, ring.regions["bore"].nodes)
    assert s.cylinder is ring.regions["bore"].cylinder and s.label == "region bore"
    mixed = select_supports(ring, [s, {"region": "end_z0", "fix": "z"}])
    assert mixed[0] is s
    assert mixed[1].label == "supports[1] (region end_z0)" and mixed[1].fix == "z"
    # the scene's form labels by scene key
    assert supports.select(ring, [{"region": "end_z0"}], "static")[0].label == \
        "static.supports[0] (region end_z0)"
    assert cm.select_supports is select_supports and cm.Load is Load


# --- loads -----------------------------------------------------------------------------------

def test_bearing_load_adds_up_to_its_force_and_a_box_around_the_bore_gives_the_same(ring):
    F = np.array([1200.0, -3000.0, 0.0])
    load = Load.bearing(ring, "bore", force=F)
    np.testing.assert_allclose(load.resultant, F, rtol=0, atol=1e-12 * np.linalg.norm(F))
    assert load.label == "bearing on bore" and load.vector.shape == (3 * ring.n_nodes,)
    # the boundary facets inside |x|, |y| <= a are the bore's (an end-face facet reaches r = 0.03)
    a = 0.02 * (1 + 1e-9)
    boxed = Load.bearing(ring, [-a, a, -a, a, -1, 1], force=F)
    assert boxed.label == "bearing on box"
    np.testing.assert_allclose(boxed.vector, load.vector, rtol=0, atol=1e-12 * np.linalg.norm(F))


def test_bearing_load_on_an_unstructured_journal_still_adds_up_to_its_force(tmp_path):
    """gmsh's surface mesh is not symmetric about F: the cosine pressure alone misses F by
    7e-5 |F| across it and along the axis; the load as a whole must not."""
    from fem_parts import gmsh_rod

    rod = gmsh_rod(0.1, 0.02, size=0.008, order=2, tmp_path=tmp_path)
    F = np.array([0.0, -3000.0, 1000.0])  # radial: the rod's axis is x
    load = Load.bearing(rod, "surface", F)
    np.testing.assert_allclose(load.resultant, F, rtol=0, atol=1e-12 * np.linalg.norm(F))
    # pressed from outside (a journal), the side facing away from F carries p0 cos(theta): the
    # force-weighted mean of cos(theta) is -(int cos^2)/(int cos) = -pi/4 over that half
    x = rod.mesh.points[:, 1:]
    cos = x @ (F[1:] / np.linalg.norm(F)) / 0.02
    w = np.linalg.norm(load.forces, axis=1)
    assert (w * cos).sum() / w.sum() == pytest.approx(-np.pi / 4, abs=0.02)


def test_remote_load_has_the_given_force_and_the_given_moment_about_its_point(cantilever):
    part, _ = cantilever
    F, point, M = np.array([0.0, 200.0, -P]), np.array([L + 0.2, 0.01, 0.0]), np.array([5.0, 30.0, -8.0])
    load = Load.remote(part, "end_x1", force=F, point=point, moment=M)
    np.testing.assert_allclose(load.resultant, F, atol=1e-12 * P)
    np.testing.assert_allclose(load.moment(about=point), M, atol=1e-10 * P)
    # about the origin: M + point x F
    np.testing.assert_allclose(load.moment(), M + np.cross(point, F), atol=1e-10 * P)


def test_pressure_and_traction_resultants_and_loads_add(cantilever):
    part, _ = cantilever
    p = Load.pressure(part, "top", 2e5)
    np.testing.assert_allclose(p.resultant, [0, 0, -2e5 * L * B], rtol=1e-12, atol=1e-9)
    t = Load.traction(part, "end_x1", [0, 0, -P])
    np.testing.assert_allclose(t.resultant, [0, 0, -P], atol=1e-12 * P)
    both = p + t
    np.testing.assert_array_equal(both.vector, p.vector + t.vector)
    assert both.label == "pressure 2e+05 Pa on top + traction on end_x1"
    np.testing.assert_array_equal(sum([p, t]).vector, both.vector)
    np.testing.assert_allclose((2 * t).resultant, [0, 0, -2 * P], atol=1e-12 * P)
    other = Load.traction(bar(1.0, 0.1, 0.1, (2, 1, 1), order=1), "end_x1", [1.0, 0, 0])
    with pytest.raises(ParameterError, match=r"^load: .* loads on different meshes do not add"):
        t + other


def test_cantilever_from_support_and_load_objects_matches_timoshenko(cantilever):
    """Clamp by region, tip load by traction: tip deflection within 1 % of Timoshenko (the same
    oracle as the vector path); a list of loads solves as their sum."""
    part, model = cantilever
    clamp = [Support.region(part, "end_x0", fix="xyz")]
    tip = Load.traction(part, "end_x1", [0, 0, -P])
    res = cm.solve_static(model, part.mesh, tip, clamp)
    w = -res.displacement[part.regions["end_x1"].nodes, 2].mean()
    assert w == pytest.approx(_timoshenko_tip(P, L), rel=0.01)
    np.testing.assert_allclose(res.reaction, [0, 0, P], atol=1e-6 * P)
    half = 0.5 * tip
    res2 = cm.solve_static(model, part.mesh, [half, half], clamp)
    np.testing.assert_allclose(res2.displacement, res.displacement, rtol=0,
                               atol=1e-9 * np.abs(res.displacement).max())


# --- errors name the argument -----------------------------------------------------------------

def test_core_errors_name_the_argument_not_a_scene_key(cantilever, ring):
    part, model = cantilever
    cases = [
        (lambda: Support.region(part, "nope"), r"^region: no region 'nope' in part 'bar'"),
        (lambda: Support.region(part, "end_x0", fix="q"), r"^fix: fix must be 'radial'"),
        (lambda: Support.region(part, "end_x0", fix="radial"),
         r"^fix: 'radial' needs a cylindrical region; region 'end_x0' is flat"),
        (lambda: Support.box(part, [0, 1, 0, 1]), r"^box: must be \[xmin, xmax"),
        (lambda: Support.box(part, [0, 1, 0, 1, 5, 6]), r"^box: selects no node"),
        (lambda: Support.box(part, [0, 1, 0, 1, 0, 1], fix="radial"), r"^fix: 'radial' needs"),
        (lambda: select_supports(part, [{"region": "end_x0"}, {"region": "nope"}]),
         r"^supports\[1\]\.region: no region 'nope'"),
        (lambda: select_supports(part, [{"box": [0, 1, 0, 1, 5, 6]}]),
         r"^supports\[0\]: selects no node"),
        (lambda: select_supports(ring, [Support.region(part, "end_x0")]),
         r"^supports\[0\]\.nodes: point indices must lie in"),
        (lambda: Load.bearing(part, "end_x1", [0, 1e3, 0]),
         r"^region: needs a cylindrical region; region 'end_x1' is flat"),
        (lambda: Load.bearing(ring, "bore", [0, 1e3, 50.0]), r"^force: .* along the bore axis"),
        (lambda: Load.traction(part, "end_x1", [1, 2]), r"^force: must be 3 finite numbers"),
        (lambda: Load.pressure(part, "top", "high"), r"^pressure: must be a number"),
        (lambda: Load.pressure(part, [5, 6, 0, 1, 0, 1], 1.0), r"^region: the box .* holds no"),
        (lambda: Load.remote(part, "end_x1", [0, 0, 1], point=[1, 2]), r"^point: must be 3"),
        (lambda: cm.solve_static(model, part.mesh, np.zeros(5), []), r"^load: must have 3 n_points"),
        (lambda: cm.solve_static(model, part.mesh, Load.traction(part, "end_x1", [0, 0, -1.0]),
                                 [{"region": "end_x0"}]), r"^supports\[0\]: must be a Support"),
        (lambda: cm.solve_static(model, part.mesh, np.zeros(model.K.shape[0]),
                                 [Support.region(part, "end_x0", fix="z")]),
         r"^supports: leave the part a mechanism with 4 rigid-body mode\(s\)"),
    ]
    for call, match in cases:
        with pytest.raises(ParameterError, match=match) as info:
            call()
        assert not isinstance(info.value, SceneError), match
        assert info.value.exit_code == 2


# --- the scene path keeps its scene keys ------------------------------------------------------

SCENE = Scene(name="t", base_dir=Path("."))


@pytest.fixture
def ctx(tmp_path):
    c = StageContext(scene=SCENE, out_dir=tmp_path, figures=False)
    c.products["geometry"] = tube(0.02, 0.04, 0.05, divisions=(2, 16, 2), order=1)
    material_stage.run(material_stage.validate({"name": "steel"}, SCENE), c)
    return c


def _static(ctx, sup, loads):
    return static_stage.run(static_stage.validate({"supports": sup, "loads": loads, "vtu": False},
                                                  SCENE), ctx)


def test_static_stage_errors_keep_their_scene_keys(ctx):
    held = [{"region": "end_z0", "fix": "xyz"}]
    cases = [
        ([{"region": "end_z0", "fix": "z"}], [{"region": "end_z1", "pressure": 1e5}],
         r"^static\.supports: leave the part a mechanism with 3 rigid-body mode\(s\)"),
        ([{"region": "bore", "fix": "radial"}, {"region": "nope"}],
         [{"region": "end_z1", "pressure": 1e5}], r"^static\.supports\[1\]\.region: no region 'nope'"),
        (held, [{"region": "end_z1", "pressure": 1e5}, {"region": "hole", "pressure": 1.0}],
         r"^static\.loads\[1\]\.region: no region 'hole'"),
        (held, [{"region": "end_z1", "bearing_force": [0, 1e3, 0]}],
         r"^static\.loads\[0\]\.bearing_force: needs a cylindrical region; region 'end_z1' is flat"),
        (held, [{"region": "bore", "bearing_force": [0, 1e3, 10.0]}],
         r"^static\.loads\[0\]\.bearing_force: \[0\.0, 1000\.0, 10\.0\] N has 10 N along the bore axis"),
    ]
    for sup, loads, match in cases:
        with pytest.raises(SceneError, match=match):
            _static(ctx, sup, loads)
    with pytest.raises(SceneError, match=r"^modal\.supports\[1\]\.fix: fix must be"):
        supports.validate_specs([{"region": "a"}, {"region": "b", "fix": "w"}], "modal")


def test_static_stage_builds_the_same_loads_as_the_objects(ctx):
    """One path: the stage's applied force is the Load objects' resultant, the result the same."""
    part = ctx.products["geometry"]
    F = [0.0, -2e3, 0.0]
    res = _static(ctx, [{"region": "end_z0"}], [{"region": "bore", "bearing_force": F},
                                                 {"region": "end_z1", "pressure": 1e5}])
    load = Load.bearing(part, "bore", F) + Load.pressure(part, "end_z1", 1e5)
    np.testing.assert_allclose(res["applied_force_n"], load.resultant, rtol=1e-12)
    model = assembly.assemble(part, STEEL)
    direct = static.solve_static(model, part.mesh, load, [Support.region(part, "end_z0")])
    assert res["max_von_mises_pa"] == pytest.approx(direct.max_von_mises, rel=1e-10)
