"""``report.reference`` is read whole while the scene is validated (issue 25 #10): NaN points, a
file that is not an .npz, pickled members, missing members or shapes that do not match stop the
run with exit 2 naming ``report.reference`` and the member — before any mesh is read or solved
(the geometry stage is never entered), never a traceback after the FE solve."""

import numpy as np
import pytest

from crankmodal.errors import ParameterError, SceneError
from crankmodal.fem import testparts
from crankmodal.runner import run, stage_module
from crankmodal.scene import load_scene

P = 5  # reference points


def _good():
    rng = np.random.default_rng(7)
    return {"points": rng.random((P, 3)) * 0.3, "shapes": rng.random((3 * P, 2)),
            "frequencies_hz": np.array([1356.0, 1489.0])}


def _write_npz(path, **arrays):
    with open(path, "wb") as fh:  # np.savez on a handle keeps the name (no .npz appended)
        np.savez(fh, **arrays)


def _bad_files(tmp):
    """``name -> (file, fragment the message must contain)``."""
    g = _good()
    cases = {}

    def case(name, fragment, **changes):
        arrays = {**g, **changes}
        _write_npz(tmp / f"{name}.npz", **{k: v for k, v in arrays.items() if v is not None})
        cases[name] = (f"{name}.npz", fragment)

    nan_points = g["points"].copy()
    nan_points[2, 1] = np.nan
    case("nan_points", "member 'points' has 1 NaN or infinite value", points=nan_points)
    inf_shapes = g["shapes"].copy()
    inf_shapes[4, 0] = np.inf
    case("inf_shapes", "member 'shapes' has 1 NaN", shapes=inf_shapes)
    case("no_shapes", "member 'shapes' is missing", shapes=None)
    case("short_shapes", "member 'shapes' must have shape (3 p, k)", shapes=g["shapes"][:-1])
    case("flat_points", "member 'points' must have shape (p, 3)", points=g["points"][:, :2])
    case("freq_count", "member 'frequencies_hz' must have one value per mode",
         frequencies_hz=np.array([1356.0]))
    case("pickled", "member 'points'", points=np.array([object()] * P, dtype=object))
    (tmp / "text.npz").write_text("points,shapes\n1,2\n")
    cases["text"] = ("text.npz", "not an .npz archive numpy can read")
    import meshio

    bad_mode = g["shapes"][:, 0].reshape(P, 3).copy()
    bad_mode[1, 2] = np.nan
    meshio.write(tmp / "nan_mode.vtu", meshio.Mesh(g["points"], [("vertex", np.arange(P)[:, None])],
                                                   point_data={"mode_01_1356.0Hz": bad_mode}))
    cases["nan_mode"] = ("nan_mode.vtu", "member 'mode_01_1356.0Hz' has 1 NaN")
    np.save(tmp / "single.npy", g["shapes"])
    (tmp / "single.npy").rename(tmp / "single.npz")
    cases["single"] = ("single.npz", "not an .npz archive (a single array)")
    return cases


@pytest.fixture(scope="module")
def bad(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("refs")
    part = testparts.bar(0.3, 0.03, 0.02, divisions=(8, 2, 2), order=1)
    import meshio

    pts, t = part.mesh.points, part.mesh.cells[0].data.copy()
    a, b, c = (pts[t[:, k]] - pts[t[:, 0]] for k in (1, 2, 3))
    neg = np.einsum("ij,ij->i", np.cross(a, b), c) < 0
    t[neg] = t[neg][:, [0, 2, 1, 3]]
    meshio.write(tmp / "bar.vtu", meshio.Mesh(pts, [("tetra", t)]))
    return tmp, _bad_files(tmp)


def _scene(tmp, reference):
    path = tmp / f"scene_{reference.split('.')[0]}.toml"
    path.write_text(f'name = "badref"\n[geometry]\nfile = "bar.vtu"\nelement_order = 1\n'
                    f'[material]\nname = "steel"\n[modal]\nn_modes = 3\n'
                    f'[report]\nreference = "{reference}"\n')
    return path


CASES = ["nan_points", "inf_shapes", "no_shapes", "short_shapes", "flat_points", "freq_count",
         "pickled", "text", "single", "nan_mode"]


@pytest.mark.parametrize("name", CASES)
def test_a_bad_reference_stops_the_run_before_the_part_is_read(bad, name, monkeypatch):
    tmp, cases = bad
    file, fragment = cases[name]
    entered = []
    geometry = stage_module("geometry")
    monkeypatch.setattr(geometry, "run", lambda p, ctx: entered.append(1))
    with pytest.raises(SceneError) as err:
        run(load_scene(_scene(tmp, file)), tmp / f"out_{name}")
    assert str(err.value).startswith(f"report.reference: {file}: ")
    assert fragment in str(err.value)
    assert not entered, "the geometry stage ran before the reference was checked"
    assert not (tmp / f"out_{name}" / "results.json").exists()


@pytest.mark.parametrize("name", ["nan_points", "text", "pickled", "short_shapes"])
def test_cli_exits_2_with_one_line_naming_the_key_and_the_member(bad, cli, name):
    tmp, cases = bad
    file, fragment = cases[name]
    proc = cli("run", _scene(tmp, file), "--out", tmp / f"cli_{name}")
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr  # no "[geometry] running": nothing ran
    assert "report.reference" in lines[0] and fragment in lines[0]
    assert not (tmp / f"cli_{name}" / "results.json").exists()


def test_the_core_loader_names_its_argument_and_reads_a_good_file(bad):
    from crankmodal.report.reference import load_reference

    tmp, cases = bad
    with pytest.raises(ParameterError, match=r"^path: nan_points.npz: member 'points'"):
        load_reference(tmp / cases["nan_points"][0])
    g = _good()
    _write_npz(tmp / "good.npz", **{**g, "shapes": g["shapes"].reshape(P, 3, 2)})
    pts, shapes, f = load_reference(tmp / "good.npz")
    assert pts.shape == (P, 3) and f.tolist() == [1356.0, 1489.0]
    # (p, 3, k) is read node-interleaved: row 3 i + c is point i, component c (a reshape and
    # a float64 copy, no arithmetic: equal bit for bit by construction)
    np.testing.assert_array_equal(shapes, g["shapes"])
