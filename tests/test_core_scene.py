"""Scene parsing: overrides, machine defaults, top-level keys, section planning."""

import pytest

from crankmodal.errors import InputFileError, SceneError
from crankmodal.runner import plan
from crankmodal.scene import (
    apply_override,
    deep_merge,
    load_scene,
    parse_value,
    scene_from_dict,
)


def test_override_values_are_parsed_as_toml():
    assert parse_value("1480") == 1480
    assert parse_value("1.5e-4") == 1.5e-4
    assert parse_value("[1, 2]") == [1, 2]
    assert parse_value("true") is True
    assert parse_value("steel") == "steel"
    assert parse_value('"42"') == "42"


def test_override_creates_nested_tables():
    t = {"mechanism": {"speed_rpm": 1480}}
    apply_override(t, "mechanism.speed_rpm=740")
    apply_override(t, "dynamics.contact.stiffness=1e9")
    assert t == {"mechanism": {"speed_rpm": 740}, "dynamics": {"contact": {"stiffness": 1e9}}}


@pytest.mark.parametrize("bad", ["speed=3", "mechanism.speed_rpm", ".x=1", "a..b=1"])
def test_malformed_override_is_refused(bad):
    with pytest.raises(SceneError, match="--set"):
        apply_override({}, bad)


def test_deep_merge_keeps_unset_nested_defaults():
    base = {"gas": {"p_suction": 1e5, "kappa": 1.4}, "r": 0.035}
    over = {"gas": {"kappa": 1.3}, "l": 0.39}
    assert deep_merge(base, over) == {"gas": {"p_suction": 1e5, "kappa": 1.3}, "r": 0.035, "l": 0.39}
    assert base["gas"]["kappa"] == 1.4  # inputs untouched


def test_unknown_section_lists_the_allowed_ones():
    scene = scene_from_dict({"mechanismus": {}})
    with pytest.raises(SceneError, match=r"\[mechanismus\]: unknown section; allowed sections are: geometry"):
        plan(scene)


def test_unknown_top_level_scalar_is_refused():
    with pytest.raises(SceneError, match="speed: unknown top-level key"):
        scene_from_dict({"speed": 3})


def test_unknown_machine_lists_known_machines():
    with pytest.raises(SceneError, match="unknown machine 'v12'; known machines: .*four_star_compressor"):
        scene_from_dict({"mechanism": {"machine": "v12"}})


def test_missing_scene_file(tmp_path):
    with pytest.raises(InputFileError, match="file not found"):
        load_scene(tmp_path / "nope.toml")


def test_invalid_toml_is_a_scene_error(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[mechanism\nspeed = 3\n")
    with pytest.raises(SceneError, match="invalid TOML"):
        load_scene(p)


def test_relative_files_resolve_against_the_scene_folder(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('name = "x"\n[geometry]\nfile = "part.step"\n')
    scene = load_scene(p)
    assert scene.name == "x"
    assert scene.resolve("part.step") == tmp_path / "part.step"


def test_override_reaches_into_a_machine_array_of_tables():
    scene = scene_from_dict(
        {"dynamics": {"machine": "four_star_compressor"}},
        overrides=["dynamics.clearances.0.clearance=2e-4"],
    )
    clearances = scene.sections["dynamics"]["clearances"]
    assert clearances[0]["clearance"] == 2e-4
    assert "joint" in clearances[0]  # the rest of the machine's entry is kept


def test_override_index_out_of_range_is_refused():
    with pytest.raises(SceneError, match=r"dynamics\.clearances\.7 is not an entry"):
        scene_from_dict({"dynamics": {"machine": "four_star_compressor"}},
                        overrides=["dynamics.clearances.7.clearance=2e-4"])


def test_override_of_the_machine_itself_selects_its_defaults():
    scene = scene_from_dict({"mechanism": {"machine": "four_star_compressor"}},
                            overrides=["mechanism.machine=slider_crank_engine"])
    assert scene.sections["mechanism"]["machine"] == "slider_crank_engine"
    assert len(scene.sections["mechanism"]["cylinders"]) == 1
