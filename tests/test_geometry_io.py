"""STEP round trip, meshio imports with named groups, the scene stage and its cache."""

import numpy as np
import pytest

from crankmodal.errors import GeometryError, InputFileError, SceneError
from crankmodal.geometry import CrankshaftParams, MeshSettings, build_part
from crankmodal.geometry.importers import import_cad, import_mesh, region_specs
from crankmodal.runner import StageContext
from crankmodal.scene import scene_from_dict

CRANK = CrankshaftParams(phases_deg=(0.0, 120.0), throw_radius=0.035, journal_diameter=0.05,
                         journal_length=0.04, pin_diameter=0.045, pin_length=0.05, web_width=0.08,
                         counterweight_radius=0.07, free_end_diameter=0.03, free_end_length=0.03)


def test_step_round_trip_keeps_the_volume_and_named_journals(tmp_path):
    step = tmp_path / "crank.step"
    built = build_part(CRANK, "dechamfered", MeshSettings(0.012, 1), step_file=step)
    specs = region_specs([{"name": "main_journal_1", "axis": [0, 0, 0, 0, 0, 1], "radius": 0.025},
                          {"name": "free_end_face", "box": [-1, 1, -1, 1, -1e-9, 1e-9]}])
    imported = import_cad(step, specs, MeshSettings(0.012, 1))
    assert imported.cad_mass.volume == pytest.approx(built.cad_mass.volume, rel=1e-6)
    assert imported.cad_mass.centroid == pytest.approx(built.cad_mass.centroid, abs=1e-9)
    # the geometric definition picks every face on the r = 25 mm cylinder about z: all journals
    j = imported.regions["main_journal_1"]
    assert j.cylinder.radius == pytest.approx(0.025)
    area = j.area(imported.mesh.points)
    assert 0.99 < area / (3 * np.pi * 0.05 * 0.04) <= 1 + 1e-9
    # a 16-gon inscribed in the 15 mm end disc (curvature sizing) has sin(2pi/16)/(2pi/16) of its area
    disc = np.pi * 0.015 ** 2 * np.sin(2 * np.pi / 16) / (2 * np.pi / 16)
    assert imported.regions["free_end_face"].area(imported.mesh.points) == pytest.approx(disc, rel=0.01)


def _box_msh(path, order):
    import gmsh

    from crankmodal.geometry.session import gmsh_session

    with gmsh_session("box", {}):
        gmsh.model.occ.addBox(0, 0, 0, 0.1, 0.02, 0.03)
        gmsh.model.occ.synchronize()
        left = [s for _, s in gmsh.model.getEntitiesInBoundingBox(-1e-6, -1, -1, 1e-6, 1, 1, dim=2)]
        gmsh.model.addPhysicalGroup(2, left, name="left_end")
        gmsh.model.addPhysicalGroup(3, [1], name="solid")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.01)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.setOrder(order)
        gmsh.write(str(path))


@pytest.mark.parametrize("order", [1, 2])
def test_gmsh_msh_physical_groups_become_regions(tmp_path, order):
    path = tmp_path / "box.msh"
    _box_msh(path, order)
    part = import_mesh(path)
    assert part.element_order == order
    assert part.regions["left_end"].area(part.mesh.points) == pytest.approx(0.02 * 0.03, rel=1e-9)
    assert np.allclose(part.mesh.points[part.regions["left_end"].nodes, 0], 0.0)
    assert part.quality["mesh_mass"]["volume_m3"] == pytest.approx(0.1 * 0.02 * 0.03, rel=1e-9)


def test_vtu_and_abaqus_meshes_import_with_named_sets(tmp_path):
    import meshio

    path = tmp_path / "box.msh"
    _box_msh(path, 1)
    m = meshio.read(path)
    tets = next(b for b in m.cells if b.type == "tetra")
    vtu = tmp_path / "box.vtu"
    meshio.write(vtu, meshio.Mesh(m.points, [tets]))
    part = import_mesh(vtu, region_specs([{"name": "right_end", "box": [0.1, 0.1, 0, 0.02, 0, 0.03]}]))
    assert part.regions["right_end"].area(part.mesh.points) == pytest.approx(0.02 * 0.03, rel=1e-9)
    inp = tmp_path / "box.inp"
    right = np.where(np.isclose(m.points[:, 0], 0.1))[0]
    meshio.write(inp, meshio.Mesh(m.points, [tets], point_sets={"RIGHT": right}))
    part = import_mesh(inp)
    assert part.regions["RIGHT"].area(part.mesh.points) == pytest.approx(0.02 * 0.03, rel=1e-9)


def test_missing_or_unreadable_files_are_refused(tmp_path):
    with pytest.raises(InputFileError, match="geometry.file"):
        import_mesh(tmp_path / "nothing.vtu")
    bad = tmp_path / "bad.vtu"
    bad.write_text("not a mesh")
    with pytest.raises(InputFileError, match="geometry.file"):
        import_mesh(bad)
    with pytest.raises(GeometryError, match=r"regions\[0\].radius"):
        region_specs([{"name": "j", "axis": [0, 0, 0, 0, 0, 1], "radius": -1}])


def _run_stage(section, tmp_path, monkeypatch):
    from crankmodal.geometry import stage

    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "cache"))
    scene = scene_from_dict({"geometry": section}, base_dir=tmp_path)
    params = stage.validate(scene.sections["geometry"], scene)
    ctx = StageContext(scene=scene, out_dir=tmp_path)
    return stage.run(params, ctx), ctx


def test_scene_stage_builds_caches_and_hands_on_a_part(tmp_path, monkeypatch):
    section = {"machine": "four_star_compressor", "part": "crankshaft", "fidelity": "simplified",
               "mesh_size": 0.015, "element_order": 1, "write_mesh": "crank.vtu"}
    first, ctx = _run_stage(section, tmp_path, monkeypatch)
    part = ctx.products["geometry"]
    assert first["cached"] is False and (tmp_path / "crank.vtu").is_file()
    assert "main_journal_1" in first["regions"] and "tetrahedra" in first["summary"]
    second, ctx2 = _run_stage(section, tmp_path, monkeypatch)
    assert second["cached"] is True
    assert np.array_equal(ctx2.products["geometry"].mesh.points, part.mesh.points)


@pytest.mark.parametrize("section, key", [
    ({"machine": "four_star_compressor", "fidelity": "coarse"}, "geometry.fidelity"),
    ({"machine": "four_star_compressor", "params": {"oil_hole_diameter": 0.03}}, "geometry.params.oil_hole_diameter"),
    ({"machine": "four_star_compressor", "params": {"journal_lenght": 0.2}}, "geometry.params.journal_lenght"),
    ({"machine": "four_star_compressor", "element_order": 3}, "geometry.element_order"),
    ({"file": "missing.step"}, "geometry.file"),
    ({}, "geometry"),
])
def test_bad_geometry_sections_are_refused_with_the_key_named(tmp_path, section, key):
    from crankmodal.errors import CrankmodalError
    from crankmodal.geometry import stage

    scene = scene_from_dict({"geometry": section}, base_dir=tmp_path)
    with pytest.raises(CrankmodalError) as err:
        stage.validate(scene.sections["geometry"], scene)
    assert key in str(err.value) and "\n" not in str(err.value)
    assert isinstance(err.value, (SceneError, InputFileError))
