"""Files crankmodal reads are untrusted (issue 25, items 6-8).

- Item 8: a damaged ``crankmodal-flexbody`` file of every kind (empty, truncated, bit-flipped,
  not a zip, a pickled member, bad JSON, a missing member, NaN, a negative or 1e12 Hz frequency,
  a wrong shape or type) is refused by :func:`~crankmodal.reduction.io.load_flexbody` with a
  :class:`~crankmodal.reduction.io.FlexbodyFileError` naming the file and the member, and by
  ``check`` and ``run`` with exit 2 and one line; a damaged *cached* flexbody (or part) is
  rebuilt with a one-line warning.
- Item 6: a part length outside the sizes crankmodal builds (1 µm to 100 m, five decades) is
  refused before OpenCASCADE sees it (it killed the interpreter: exit 139), through ``run`` and
  through ``build_part``.
- Item 7: a bar reduced without gmsh is refused by its exact tetrahedron count before any
  memory is taken; a subnormal mesh size is a refusal, not a ZeroDivisionError; an imported mesh
  scaled far outside metres is refused by its extent, not as "inverted elements".

The oracles are the file format's table (:mod:`crankmodal.reduction.io`), the documented size
limits, and the closed-form tetrahedron count of a structured bar (6 per grid cell).
"""

from __future__ import annotations

import re
import shutil
import struct
import zipfile
from pathlib import Path

import numpy as np
import pytest
from conftest import SCENES, run_in_process

from crankmodal.errors import (
    CrankmodalError,
    GeometryError,
    InputFileError,
    ModelWarning,
    ParameterError,
    ResourceError,
)

SPEC = {"mesh_size": 0.025, "element_order": 1, "material": "steel", "fixed_interface_modes": 4}
COUPLER = (0.075, (0.05, 0.077))  # the loom's coupler: pin distance, [width, thickness], m


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A sound flexbody: the loom's coupler as a coarse P1 bar, reduced (no gmsh, ~1 s)."""
    folder = tmp_path_factory.mktemp("good")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("CRANKMODAL_CACHE", str(folder / "cache"))
        from crankmodal.dynamics.flexible.build import reduced_bar

        path = reduced_bar(*COUPLER, SPEC, "dynamics.flexible.coupler")
    return shutil.copy(path, folder / "good.npz")


def members(path) -> dict:
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def rewrite(good, out, change):
    d = members(good)
    change(d)
    with open(out, "wb") as fh:
        np.savez(fh, **d)  # pickles object arrays, as a hostile or careless writer would


def poke(name, index, value):
    def change(d):
        a = np.array(d[name])
        a[index] = value
        d[name] = a
    return change


def flip_in(member):
    """Flip one bit in the middle of ``member``'s array data (its CRC no longer matches)."""
    def damage(good, out):
        data = bytearray(Path(good).read_bytes())
        with zipfile.ZipFile(good) as zf:
            info = zf.getinfo(f"{member}.npy")
        n, m = struct.unpack("<HH", data[info.header_offset + 26:info.header_offset + 30])
        start = info.header_offset + 30 + n + m
        data[start + info.compress_size - 8] ^= 0x10  # in the last value, past the npy header
        out.write_bytes(bytes(data))
    return damage


def huge_header(member):
    """``member`` replaced by an .npy whose header declares 1e12 float64 values (8 TB)."""
    def damage(good, out):
        import io

        d = members(good)
        del d[member]
        with open(out, "wb") as fh:
            np.savez(fh, **d)
        buf = io.BytesIO()
        np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False,
                                                   "shape": (10**12,)})
        with zipfile.ZipFile(out, "a") as zf:
            zf.writestr(f"{member}.npy", buf.getvalue() + bytes(64))
    return damage


def _npy(array) -> bytes:
    import io

    buf = io.BytesIO()
    np.save(buf, array)
    return buf.getvalue()


def _set(name, value):
    return lambda d: d.__setitem__(name, value)


#: kind -> (damage(good, out), the member the error names; "" for the file as a whole)
DAMAGES = {
    "empty": (lambda g, o: o.write_bytes(b""), ""),
    "truncated": (lambda g, o: o.write_bytes(Path(g).read_bytes()[:5000]), ""),
    "not a zip": (lambda g, o: o.write_text("frequencies_hz = 12.0\n"), ""),
    "a bare npy": (lambda g, o: o.write_bytes(_npy(np.zeros(3))), ""),
    "bit-flipped I9": (flip_in("I9"), "I9"),
    "bit-flipped interface_map": (flip_in("interface_map"), "interface_map"),
    "8 TB declared": (huge_header("frequencies_hz"), "frequencies_hz"),
    "version not a number": (lambda g, o: rewrite(g, o, _set("version", np.array("one"))), "version"),
    "version 2": (lambda g, o: rewrite(g, o, _set("version", np.array(2))), "version"),
    "pickled names": (lambda g, o: rewrite(g, o, _set(
        "interface_names", np.array(["end_x0", "end_x1", None], dtype=object)[:2])), "interface_names"),
    "pickled map": (lambda g, o: rewrite(g, o, lambda d: d.__setitem__(
        "interface_map", d["interface_map"].astype(object))), "interface_map"),
    "bad json": (lambda g, o: rewrite(g, o, _set("info_json", np.array("{not json"))), "info_json"),
    "json not an object": (lambda g, o: rewrite(g, o, _set("info_json", np.array("[1, 2]"))),
                           "info_json"),
    "nan mass": (lambda g, o: rewrite(g, o, poke("mass", (3, 3), np.nan)), "mass"),
    "zero modal mass": (lambda g, o: rewrite(g, o, poke("mass", (3, 3), 0.0)), "mass"),
    "nan mass_kg": (lambda g, o: rewrite(g, o, _set("mass_kg", np.array(np.nan))), "mass_kg"),
    "negative mass_kg": (lambda g, o: rewrite(g, o, _set("mass_kg", np.array(-2.0))), "mass_kg"),
    "nan frequency": (lambda g, o: rewrite(g, o, poke("frequencies_hz", 7, np.nan)), "frequencies_hz"),
    "negative frequency": (lambda g, o: rewrite(g, o, poke("frequencies_hz", 7, -100.0)),
                           "frequencies_hz"),
    "1e12 Hz frequency": (lambda g, o: rewrite(g, o, poke("frequencies_hz", 15, 1e12)),
                          "frequencies_hz"),
    "inf fixed-interface frequency": (lambda g, o: rewrite(g, o, poke("fixed_interface_hz", 0, np.inf)),
                                      "fixed_interface_hz"),
    "frequencies as text": (lambda g, o: rewrite(g, o, lambda d: d.__setitem__(
        "frequencies_hz", d["frequencies_hz"].astype(str))), "frequencies_hz"),
    "nan interface_map": (lambda g, o: rewrite(g, o, poke("interface_map", (0, 0, 7), np.nan)),
                          "interface_map"),
    "interface_map wrong shape": (lambda g, o: rewrite(g, o, lambda d: d.__setitem__(
        "interface_map", d["interface_map"][:, :5])), "interface_map"),
    "inf interface axis": (lambda g, o: rewrite(g, o, poke("interface_axes", (0, 0), np.inf)),
                           "interface_axes"),
    "nan I1": (lambda g, o: rewrite(g, o, _set("I1", np.array(np.nan))), "I1"),
    "nan I3": (lambda g, o: rewrite(g, o, poke("I3", (0, 0), np.nan)), "I3"),
    "I5 wrong shape": (lambda g, o: rewrite(g, o, lambda d: d.__setitem__("I5", d["I5"][:, :3])), "I5"),
    "rigid not booleans": (lambda g, o: rewrite(g, o, lambda d: d.__setitem__(
        "rigid", d["rigid"].astype(float))), "rigid"),
    "unknown interface kind": (lambda g, o: rewrite(g, o, _set(
        "interface_kinds", np.array(["distributing", "glue"]))), "interface_kinds"),
    "mesh cell out of range": (lambda g, o: rewrite(g, o, poke("mesh_cells", (0, 0), 10**6)),
                               "mesh_cells"),
    "interface node out of range": (lambda g, o: rewrite(g, o, poke("interface_nodes", 0, -1)),
                                    "interface_nodes"),
    "stress modes wrong shape": (lambda g, o: rewrite(g, o, lambda d: d.__setitem__(
        "stress_modes", d["stress_modes"][:, :5])), "stress_modes"),
}


#: the members every file has, from the format's table (reduction/io.py), but ``format``:
#: without it the file is no flexbody at all
REQUIRED = ["version", "name", "frequencies_hz", "stiffness", "mass", "rigid", "interface_names",
            "interface_kinds", "interface_centres", "interface_axes", "interface_map",
            "cb_stiffness", "cb_mass", "cb_to_modal", "n_fixed_interface_modes",
            "fixed_interface_hz", "mass_kg", "centre_of_mass", "inertia",
            *(f"I{i}" for i in range(1, 10)), "n_full_dofs", "info_json"]


@pytest.mark.parametrize("kind", list(DAMAGES))
def test_damaged_flexbody_is_refused_naming_the_file_and_the_member(good, kind, tmp_path):
    from crankmodal.reduction.io import FlexbodyFileError, load_flexbody

    damage, member = DAMAGES[kind]
    bad = tmp_path / "bad.npz"
    damage(good, bad)
    with pytest.raises(FlexbodyFileError) as info:
        load_flexbody(bad)
    exc = info.value
    assert isinstance(exc, InputFileError) and isinstance(exc, CrankmodalError)
    assert exc.member == member, str(exc)
    assert str(bad) in str(exc) and (f"member {member!r}" in str(exc) if member else True)


@pytest.mark.parametrize("member", REQUIRED)
def test_flexbody_missing_a_member_is_refused_naming_it(good, member, tmp_path):
    from crankmodal.reduction.io import FlexbodyFileError, load_flexbody

    bad = tmp_path / "bad.npz"
    rewrite(good, bad, lambda d: d.pop(member))
    with pytest.raises(FlexbodyFileError, match=f"member '{member}': missing"):
        load_flexbody(bad)


def test_sound_flexbody_loads_as_written(good):
    """The validation refuses nothing a writer makes: the file's own arrays come back."""
    from crankmodal.reduction.io import load_flexbody

    body = load_flexbody(good)
    z = members(good)
    assert body.n_modes == len(z["frequencies_hz"]) == 16 and int(body.rigid.sum()) == 6
    assert body.interface_names == ["end_x0", "end_x1"] and body.mesh_cell_type == "tetra"
    for k in ("frequencies_hz", "interface_map", "mass", "mode_shapes", "mesh_cells"):
        assert np.array_equal(getattr(body, k), z[k])  # the same stored numbers, no arithmetic
    assert body.invariants["I5"].shape == (3, 10, 10)


def four_bar_scene(tmp_path, npz) -> object:
    scene = tmp_path / "coupler.toml"
    scene.write_text('[dynamics]\nmachine = "loom_four_bar"\nend_time = 0.02\n'
                     '[dynamics.solver]\nmethod = "Radau"\n'
                     f'[dynamics.flexible]\ncoupler = {{ file = "{npz.name}" }}\n')
    return scene


def one_error_line(status, stderr, *fragments):
    lines = [s for s in stderr.strip().splitlines() if s.startswith("crankmodal:")]
    assert status == 2 and "Traceback" not in stderr, stderr
    assert len(lines) == 1 and lines[0].startswith("crankmodal: error: "), stderr
    for f in fragments:
        assert f in lines[0], lines[0]


CLI_DAMAGES = ["empty", "bit-flipped I9", "pickled names", "bad json", "nan mass",
               "1e12 Hz frequency", "negative frequency", "interface_map wrong shape"]


@pytest.mark.parametrize("command", ["check", "run"])
@pytest.mark.parametrize("kind", CLI_DAMAGES)
def test_damaged_flexbody_in_a_scene_exits_2_naming_file_and_member(good, kind, command, tmp_path):
    damage, member = DAMAGES[kind]
    bad = tmp_path / "coupler.npz"
    damage(good, bad)
    out = tmp_path / "out"
    extra = ("--out", out, "--no-figures") if command == "run" else ()
    status, stderr = run_in_process(command, four_bar_scene(tmp_path, bad), *extra)
    one_error_line(status, stderr, "dynamics.flexible.coupler", str(bad), member)
    assert not (out / "results.json").exists()


def test_damaged_cached_flexbody_is_rebuilt_with_a_warning(tmp_path, monkeypatch):
    from crankmodal.dynamics.flexible.build import reduced_bar
    from crankmodal.reduction.io import load_flexbody

    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "cache"))
    path = reduced_bar(*COUPLER, SPEC, "dynamics.flexible.coupler")
    first = load_flexbody(path).frequencies_hz
    for damage in (lambda p: p.write_bytes(p.read_bytes()[:4000]), lambda p: p.write_bytes(b""),
                   lambda p: flip_in("mass")(p, p)):
        damage(path)
        with pytest.warns(ModelWarning, match=r"dynamics.flexible.coupler: the cached flexbody .*"
                                              r"is damaged .*rebuilding it"):
            again = reduced_bar(*COUPLER, SPEC, "dynamics.flexible.coupler")
        assert again == path
        # the same reduction run again: equal to 1e-9, far above the solver's round-off
        # (LAPACK's eigensolver is deterministic on one machine, but not promised bit-exact)
        np.testing.assert_allclose(load_flexbody(again).frequencies_hz, first, rtol=1e-9, atol=0)


@pytest.mark.slow
def test_run_with_a_damaged_cached_flexbody_rebuilds_it_with_one_warning(cli, tmp_path, monkeypatch):
    """Through `crankmodal run` (a subprocess, warnings shown): before the fix every later run
    failed (exit 2, or an EOFError traceback for an emptied file) until the user deleted it."""
    import json

    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "cache"))
    scene = tmp_path / "bar.toml"
    scene.write_text('[dynamics]\nmachine = "loom_four_bar"\nend_time = 0.005\n'
                     '[dynamics.solver]\nmethod = "Radau"\n[dynamics.flexible]\ncoupler = { bar = '
                     '[0.05, 0.077], mesh_size = 0.025, element_order = 1, fixed_interface_modes = 4 }\n')
    first = cli("run", scene, "--out", tmp_path / "one", "--no-figures", warnings="default")
    assert first.returncode == 0, first.stderr
    (cached,) = (tmp_path / "cache" / "flexbodies").glob("bar_*.npz")
    cached.write_bytes(cached.read_bytes()[:3000])
    second = cli("run", scene, "--out", tmp_path / "two", "--no-figures", warnings="default")
    assert second.returncode == 0, second.stderr
    damaged = [s for s in second.stderr.splitlines() if "is damaged" in s]
    assert len(damaged) == 1 and damaged[0].startswith(
        f"crankmodal: warning: dynamics.flexible.coupler: the cached flexbody {cached}")
    assert damaged[0].endswith("rebuilding it")
    peaks = [json.loads((tmp_path / d / "results.json").read_text())["dynamics"]
             ["main_bearing_force_peak_n"] for d in ("one", "two")]
    # the same body rebuilt and the same run: equal far above the solvers' round-off
    assert peaks[1] == pytest.approx(peaks[0], rel=1e-9)


def test_damaged_cached_part_is_rebuilt_with_a_warning(tmp_path, monkeypatch):
    from crankmodal.fem.testparts import bar
    from crankmodal.geometry.cache import cache_dir, load_part, store_part

    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path))
    store_part("k", bar(divisions=(2, 1, 1), order=1))
    assert load_part("k").n_elements == 12  # 6 tetrahedra per cell
    entry = cache_dir() / "k.pkl"
    entry.write_bytes(entry.read_bytes()[:100])
    with pytest.warns(ModelWarning, match="geometry.cache: the cached part .* is damaged"):
        assert load_part("k") is None
    assert not entry.exists()
    import pickle

    entry.write_bytes(pickle.dumps({"not": "a part"}))
    with pytest.warns(ModelWarning, match="holds a dict, not a part"):
        assert load_part("k") is None


# --- item 6: lengths outside the sizes crankmodal builds ----------------------------------------

HUGE_OR_SUBNORMAL = [
    ("rod", "length", 1e15), ("rod", "length", 1e30), ("rod", "big_end_width", 1e20),
    ("rod", "shank_fillet", 1e-310), ("rod", "bushing_thickness", 5e-324),
    ("rod", "bolt_diameter", 1e-300),
    ("crankshaft", "journal_length", 1e20), ("crankshaft", "pin_fillet", 1e-310),
]


@pytest.fixture
def no_kernel(monkeypatch):
    """OpenCASCADE replaced by a failure: a length it would have been given (and crashed on,
    before the fix: exit 139) fails the test instead of killing it."""
    def kernel(*a, **k):
        raise AssertionError("OpenCASCADE reached")
    monkeypatch.setattr("crankmodal.geometry.build.gmsh_session", kernel)


@pytest.mark.parametrize("part, name, value", HUGE_OR_SUBNORMAL)
def test_build_part_refuses_a_length_outside_the_machine_size(part, name, value, no_kernel):
    from crankmodal.geometry import ConrodParams, CrankshaftParams, MeshSettings, build_part

    cls = ConrodParams if part == "rod" else CrankshaftParams
    with pytest.raises(ParameterError) as info:
        build_part(cls(**{name: value}), "full", MeshSettings(0.01, order=1))
    assert info.value.argument == f"{part}.{name}"
    assert isinstance(info.value, GeometryError)
    assert "[1e-06, 100] m" in str(info.value)


def test_length_limits_are_the_documented_ones():
    """0 and the bounds 1 µm, 100 m pass; just outside them, and a part spanning more than
    five decades (its smallest length < its largest / 1e5), is refused by name."""
    from dataclasses import replace

    from crankmodal.geometry.checks import LengthError, check_lengths
    from crankmodal.geometry.params import ConrodParams

    rod = ConrodParams(length=10.0, big_end_bore=5.0, big_end_outer_diameter=8.0)
    check_lengths("rod", replace(rod, shank_fillet=0.0, length=100.0))
    check_lengths("rod", replace(rod, shank_fillet=1e-3 * (1 + 1e-12)))  # 100 / 1e5
    check_lengths("rod", replace(ConrodParams(), shank_fillet=1e-6 * (1 + 1e-12), length=0.1))
    for changed, name in (({"length": 100.0 * (1 + 1e-12)}, "rod.length"),
                          ({"shank_fillet": 1e-6 * (1 - 1e-12)}, "rod.shank_fillet"),
                          ({"length": 100.0, "shank_fillet": 1e-3 * (1 - 1e-12)}, "rod.shank_fillet")):
        with pytest.raises(LengthError) as info:
            check_lengths("rod", replace(rod, **changed))
        assert info.value.argument == name


@pytest.mark.parametrize("command", ["check", "run"])
@pytest.mark.parametrize("name, value", [("length", "1e15"), ("length", "1e30"),
                                         ("shank_fillet", "1e-310")])
def test_huge_or_subnormal_rod_length_exits_2_through_the_cli(cli, name, value, command, tmp_path):
    """In a subprocess: before the fix ``run`` died of a segmentation fault (exit 139)."""
    extra = ("--out", tmp_path / "out", "--no-figures") if command == "run" else ()
    proc = cli(command, SCENES / "seed000_rod_static.toml", "--set",
               f"geometry.params.{name}={value}", *extra)
    one_error_line(proc.returncode, proc.stderr, f"geometry.params.{name}: must be 0 or in [1e-06, 100] m")
    assert not (tmp_path / "out" / "results.json").exists()


# --- item 7: element counts of parts built without gmsh, subnormal sizes, scaled meshes ------------

def test_bar_count_is_six_tetrahedra_per_grid_cell_and_refused_over_the_limit():
    from crankmodal.fem.testparts import bar, check_bar_size
    from crankmodal.geometry.mesh import MeshSizeError

    # the tester's 0.4 mm on the coupler: ceil(75/0.4) x ceil(50/0.4) x ceil(77/0.4) cells
    with pytest.raises(MeshSizeError) as info:
        check_bar_size((0.075, 0.05, 0.077), 4e-4, 5e6, "test")
    assert info.value.count == 6 * 188 * 125 * 193
    h = info.value.smallest
    assert 6 * np.prod(np.ceil(np.array([0.075, 0.05, 0.077]) / h)) <= 5e6
    assert 6 * np.prod(np.ceil(np.array([0.075, 0.05, 0.077]) / (h * (1 - 1e-6)))) > 5e6
    # a fine grid's count is about 6 V / h^3
    assert h == pytest.approx((6 * 0.075 * 0.05 * 0.077 / 5e6) ** (1 / 3), rel=0.05)
    assert check_bar_size((0.075, 0.05, 0.077), 0.0125, 5e6, "test") == (6, 4, 7)
    assert bar(0.075, 0.05, 0.077, (6, 4, 7), order=1).n_elements == 6 * 6 * 4 * 7
    with pytest.raises(ParameterError, match="divisions"):
        bar(1.0, 0.1, 0.1, (10**6, 10**5, 10**5))  # was a 71 PiB MemoryError


@pytest.mark.parametrize("size", [1e-6, 1e-300, 5e-324])
def test_reduced_bar_refuses_a_tiny_mesh_size_before_taking_memory(size, tmp_path, monkeypatch):
    from crankmodal.dynamics.flexible.build import reduced_bar

    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path))
    with pytest.raises(ResourceError, match=r"dynamics.flexible.coupler.mesh_size = .* tetrahedra"):
        reduced_bar(*COUPLER, dict(SPEC, mesh_size=size), "dynamics.flexible.coupler")


@pytest.mark.parametrize("assignment, key", [
    ("dynamics.flexible.coupler.mesh_size=1e-6", "dynamics.flexible.coupler.mesh_size"),
    ("dynamics.flexible.coupler.mesh_size=4e-4", "dynamics.flexible.coupler.mesh_size"),
    ("dynamics.flexible.coupler.mesh_size=1e-300", "dynamics.flexible.coupler.mesh_size"),
    ("dynamics.flexible.coupler.bar=[1e-300, 0.077]", "dynamics.flexible.coupler.bar"),
])
def test_check_refuses_a_bar_too_fine_or_too_small(assignment, key, tmp_path):
    scene = SCENES / "seed001_flexible_coupler.toml"
    status, stderr = run_in_process("check", scene, "--set", assignment)
    one_error_line(status, stderr, key)


@pytest.mark.parametrize("assignment, fragment", [
    ("dynamics.flexible.crank.mesh_size=1e-300",
     "dynamics.flexible.crank.mesh_size: must be in [1e-06, 100] m"),
    ("dynamics.flexible.crank.mesh_size=1e-4",
     "dynamics.flexible.crank.mesh_size = 0.0001 m: at least 1.8e+09 tetrahedra"),
])
def test_check_refuses_a_machine_part_reduced_here_too_fine(assignment, fragment):
    """The part a [dynamics.flexible] crank or rod reduces is checked by `check` (it passed, and
    `run` refused it only after the [mechanism] stage), under the table's own key."""
    status, stderr = run_in_process("check", SCENES / "seed000_flexible_crank.toml", "--set",
                                    assignment)
    one_error_line(status, stderr, fragment)


@pytest.mark.parametrize("assignment", ["dynamics.flexible.coupler.mesh_size=1e-6",
                                        "dynamics.flexible.coupler.bar=[1e-300, 0.077]"])
def test_run_refuses_a_bar_too_fine_or_too_small(assignment, tmp_path):
    out = tmp_path / "out"
    status, stderr = run_in_process("run", SCENES / "seed001_flexible_coupler.toml", "--set",
                                    assignment, "--out", out, "--no-figures")
    one_error_line(status, stderr, assignment.split("=")[0])
    assert not (out / "results.json").exists()


def test_subnormal_mesh_size_is_a_refusal_not_a_division_by_zero():
    from crankmodal.geometry.mesh import (
        MeshSettings,
        check_size,
        check_size_floor,
        estimate_elements,
    )
    from crankmodal.geometry.params import ConrodParams

    for size in (1e-300, 5e-324, 1e30):
        for call in (lambda s: check_size_floor(ConrodParams(), s), lambda s: check_size(1e-3, 1e-2, s)):
            with pytest.raises(ParameterError, match=r"size: must be in \[1e-06, 100\] m"):
                call(MeshSettings(size))
    # 8.5 V / h^3 + 17.5 A / h^2, overflowing to inf and underflowing to 0 without an exception
    assert estimate_elements(1e-3, 1e-2, 1e-300) == np.inf  # was a ZeroDivisionError
    assert estimate_elements(1e-3, 1e-2, 1e200) == 0.0  # was an OverflowError
    assert estimate_elements(1e-3, 1e-2, 0.01) == pytest.approx(8.5e3 + 17.5e2, rel=1e-12)
    status, stderr = run_in_process("check", SCENES / "seed000_rod_static.toml", "--set",
                                    "geometry.mesh_size=1e-300")
    one_error_line(status, stderr, "geometry.mesh_size: must be in [1e-06, 100] m")


@pytest.mark.parametrize("scale, fragment", [(1e200, "spans 1e+198 m"), (1e-200, "spans 1e-202 m"),
                                             (5e4, "millimetres")])
def test_mesh_scaled_outside_metres_is_refused_by_its_extent(scale, fragment, tmp_path):
    import meshio

    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], float) * 0.01 * scale
    mesh = tmp_path / "part.vtu"
    meshio.write(mesh, meshio.Mesh(points, [("tetra", np.array([[0, 1, 2, 3], [1, 2, 3, 4]]))]))
    scene = tmp_path / "s.toml"
    scene.write_text('[geometry]\nfile = "part.vtu"\n[material]\nname = "steel"\n'
                     '[modal]\nn_modes = 2\n')
    out = tmp_path / "out"
    status, stderr = run_in_process("run", scene, "--out", out)
    one_error_line(status, stderr, "geometry.file: part.vtu", fragment)
    assert not (out / "results.json").exists()
    from crankmodal.geometry.importers import import_mesh

    with pytest.raises(InputFileError, match=re.escape(fragment)):
        import_mesh(mesh)
