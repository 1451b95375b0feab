"""Output and input files that cannot be written or read (issue 18, items 7-9).

- every output file is written atomically (:func:`crankmodal.results.atomic_path`): a writer that
  fails or is interrupted leaves the old file or none, never a truncated one, and no temporary;
- an output folder that is a file, lies under a file, is read-only or full: exit 2, one line naming
  the path and the system's reason, no traceback, no results.json;
- a scene that is not UTF-8: exit 2, one line, and the stale results.json removed;
- an absurd ``geometry.mesh_size`` is refused from an element-count estimate before gmsh meshes.
"""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest
from conftest import SCENES
from conftest import run_cli as run_subprocess
from conftest import run_in_process as run_cli

from crankmodal.errors import OutputError
from crankmodal.results import atomic_path, savefig_atomic, write_atomic

TORSION = SCENES / "torsion_chain.toml"      # ~0.3 s, no gmsh
MECHANISM = SCENES / "four_star_mechanism.toml"  # ~2 s, writes an .npz and figures




def error_line(status, stderr, *fragments, code=2) -> str:
    """The single ``crankmodal: error:`` line (progress lines aside), checked."""
    assert status == code, stderr
    assert "Traceback" not in stderr, stderr
    lines = [s for s in stderr.strip().splitlines() if not s.startswith("[")]
    assert len(lines) == 1 and lines[0].startswith("crankmodal: error: "), stderr
    for f in fragments:
        assert f in lines[0], lines[0]
    return lines[0]


def temporaries(folder) -> list:
    """Files an interrupted atomic write would leave (``.<name>.<random><suffix>``)."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".")) if folder.is_dir() else []


# --- atomic writers ----------------------------------------------------------------------------

def test_atomic_path_keeps_the_suffix_and_replaces_only_on_success(tmp_path):
    target = tmp_path / "arrays.npz"
    with atomic_path(target) as tmp:
        assert tmp.parent == tmp_path and tmp.name.startswith(".arrays.npz.") and tmp.suffix == ".npz"
        np.savez_compressed(tmp, a=np.arange(3))  # savez appends nothing: the suffix is .npz
    assert np.load(target)["a"].tolist() == [0, 1, 2]
    assert temporaries(tmp_path) == []
    assert oct(target.stat().st_mode & 0o777) != oct(0o600)  # an ordinary file, not mkstemp's


@pytest.mark.parametrize("failure", [KeyboardInterrupt, ValueError])
def test_an_interrupted_writer_leaves_the_old_file_and_no_temporary(tmp_path, failure):
    target = tmp_path / "modes.vtu"
    target.write_text("old complete file")
    with pytest.raises(failure), atomic_path(target) as tmp:
        tmp.write_text("half a mes")
        raise failure()
    assert target.read_text() == "old complete file"
    assert temporaries(tmp_path) == []


def test_a_full_disk_in_a_writer_is_an_output_error_naming_the_file(tmp_path):
    target = tmp_path / "dynamics.npz"
    full = r"cannot write .*dynamics.npz: No space left on device"
    with pytest.raises(OutputError, match=full), atomic_path(target) as tmp:
        tmp.write_bytes(b"PK\x03\x04 truncated")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert not target.exists() and temporaries(tmp_path) == []


def test_modes_vtu_killed_mid_write_leaves_no_truncated_file(tmp_path, monkeypatch):
    """A kill during meshio's write of modes.vtu left a 0-byte or truncated file."""
    import meshio

    from crankmodal.fem.vtu import write_modes

    mesh = meshio.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float),
                       [("tetra", np.array([[0, 1, 2, 3]]))])
    shapes = np.ones((12, 1))
    target = write_modes(tmp_path / "modes.vtu", mesh, [100.0], shapes)
    good = target.read_bytes()
    real = meshio.write

    def killed(path, *args, **kw):
        real(path, *args, **kw)
        with open(path, "r+b") as fh:
            fh.truncate(10)
        raise KeyboardInterrupt

    monkeypatch.setattr(meshio, "write", killed)
    with pytest.raises(KeyboardInterrupt):
        write_modes(target, mesh, [200.0], shapes)
    assert target.read_bytes() == good
    assert temporaries(tmp_path) == []


def test_savefig_atomic_infers_the_format_from_the_real_suffix(tmp_path):
    from crankmodal.plotting import pyplot

    plt = pyplot()
    fig, ax = plt.subplots()
    ax.plot([0, 1])
    png = savefig_atomic(fig, tmp_path / "f.png")
    pdf = savefig_atomic(fig, tmp_path / "f.pdf")
    plt.close(fig)
    assert png.read_bytes()[:4] == b"\x89PNG" and pdf.read_bytes()[:4] == b"%PDF"
    assert temporaries(tmp_path) == []


def test_write_atomic_into_a_read_only_folder_names_the_file(tmp_path, monkeypatch):
    def refuse(*a, **kw):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr("crankmodal.results.tempfile.mkstemp", refuse)
    with pytest.raises(OutputError, match=r"cannot write .*t.txt: Read-only file system"):
        write_atomic(tmp_path / "t.txt", "x")


def test_a_flexible_body_without_npz_suffix_is_written_where_asked(tmp_path, monkeypatch):
    """np.savez appends .npz to a file name without it; the body goes through an open file."""
    from crankmodal.reduction import io as flexio
    from crankmodal.reduction.flexbody import FlexibleBody

    written = {}

    def fake_savez(fh, **data):
        written.update(data)
        fh.write(b"PK fake")

    body = object.__new__(FlexibleBody)  # save_flexbody takes reduced bodies only
    for k in flexio._ARRAYS:
        setattr(body, k, np.zeros(1))
    body.name, body.interface_names, body.interface_kinds = "b", ["a"], ["pin"]
    body.n_fixed_interface_modes, body.mass_kg, body.n_full_dofs = 0, 1.0, 6
    body.info, body.invariants, body.stress_modes = {}, {}, None
    monkeypatch.setattr(np, "savez", fake_savez)
    path = flexio.save_flexbody(tmp_path / "body.flex", body)
    assert path.read_bytes() == b"PK fake" and written["name"] == "b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["body.flex"]


# --- output folders through the CLI ------------------------------------------------------------

def test_out_that_is_a_file(tmp_path):
    out = tmp_path / "taken"
    out.write_text("a file of the user's")
    error_line(*run_cli("run", TORSION, "--out", out), str(out), "is a file, not a folder")
    assert out.read_text() == "a file of the user's"


def test_out_under_a_file(tmp_path):
    (tmp_path / "taken").write_text("")
    out = tmp_path / "taken" / "sub"
    error_line(*run_cli("run", TORSION, "--out", out), str(out), "a parent of it is a file")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a 0o555 folder")
def test_out_read_only_folder(tmp_path):
    out = tmp_path / "ro"
    out.mkdir()
    out.chmod(0o555)
    try:
        error_line(*run_cli("run", TORSION, "--out", out), str(out), "Permission denied")
        assert list(out.iterdir()) == []
    finally:
        out.chmod(0o755)


@pytest.mark.parametrize("code", [errno.EACCES, errno.EROFS])
def test_out_read_only_simulated(tmp_path, monkeypatch, code):
    """As root ignores permissions, the refusal a read-only folder gives is injected."""
    def refuse(*a, **kw):
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr("crankmodal.results.tempfile.mkstemp", refuse)
    out = tmp_path / "o"
    error_line(*run_cli("run", TORSION, "--out", out), str(out), os.strerror(code))
    assert not (out / "results.json").exists() and temporaries(out) == []


def test_out_on_a_full_disk_leaves_no_partial_npz_and_no_results(tmp_path, monkeypatch):
    """The .npz is half written when the disk fills: exit 2 naming it, the old one kept."""
    out = tmp_path / "o"
    out.mkdir()
    (out / "mechanism_curves.npz").write_bytes(b"old complete arrays")
    (out / "results.json").write_text("{}")  # stale

    def full(file, **arrays):
        with open(file, "wb") as fh:
            fh.write(b"PK\x03\x04 half")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(np, "savez_compressed", full)
    error_line(*run_cli("run", MECHANISM, "--out", out, "--no-figures"),
               "mechanism_curves.npz", "No space left on device")
    assert (out / "mechanism_curves.npz").read_bytes() == b"old complete arrays"
    assert not (out / "results.json").exists()
    assert temporaries(out) == []


def test_an_os_error_no_writer_caught_is_one_line_naming_the_file(tmp_path, monkeypatch):
    """A stage (a plugin's) whose own file write fails: exit 2 naming the stage and the file."""
    from crankmodal.torsion import stage

    def failing(p, ctx):
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(ctx.out_dir / "x.txt"))

    monkeypatch.setattr(stage, "run", failing)
    error_line(*run_cli("run", TORSION, "--out", tmp_path / "o"), "[torsion]", "x.txt",
               "Permission denied")
    assert not (tmp_path / "o" / "results.json").exists()


# --- scenes that are not UTF-8 -----------------------------------------------------------------

def encodings_of(text: str) -> dict[str, bytes]:
    """The bytes of a scene saved wrongly, by what is wrong."""
    with_accent = text.replace('description = "', 'description = "Moteur à café, ', 1)
    if with_accent == text:
        with_accent = '# Moteur à café\n' + text
    return {
        "latin-1": with_accent.encode("latin-1"),
        "utf-16 with BOM": text.encode("utf-16"),
        "truncated utf-8 sequence": text.encode() + "# €".encode()[:-1],
        "binary junk": bytes(np.random.default_rng(18).integers(0, 256, 300, dtype=np.uint8)),
    }


NOT_UTF8 = list(encodings_of(TORSION.read_text()))


@pytest.mark.parametrize("kind", NOT_UTF8)
def test_a_scene_that_is_not_utf8_is_one_line_and_removes_stale_results(tmp_path, kind):
    scene = tmp_path / "s.toml"
    scene.write_bytes(encodings_of(TORSION.read_text())[kind])
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.json").write_text("{}")
    line = error_line(*run_cli("run", scene, "--out", out), str(scene), "UTF-8")
    assert not (out / "results.json").exists(), line
    error_line(*run_cli("check", scene), str(scene), "UTF-8")


def test_a_scene_with_a_utf8_byte_order_mark_is_read(tmp_path):
    """A UTF-8 BOM (Notepad writes one) leaves the file UTF-8: it is dropped, not refused."""
    scene = tmp_path / "s.toml"
    scene.write_bytes(b"\xef\xbb\xbf" + TORSION.read_bytes())
    status, stderr = run_cli("check", scene)
    assert status == 0, stderr


def test_a_not_utf8_scene_names_line_and_column(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_bytes(b'name = "x"\n[torsion]\n# caf\xe9\n')
    error_line(*run_cli("check", scene), "byte 0xe9 at line 3, column 6")


# --- mesh size ---------------------------------------------------------------------------------

CRANK = SCENES / "seed000_crank_report.toml"


def test_an_absurd_mesh_size_is_refused_before_gmsh_meshes(tmp_path, monkeypatch):
    """mesh_size = 1e-4 m on the crank sat in gmsh with memory rising."""
    from crankmodal.geometry import build

    def never(*a, **kw):
        raise AssertionError("gmsh was asked to mesh")

    monkeypatch.setattr(build, "generate", never)
    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "cache"))
    line = error_line(*run_cli("run", CRANK, "--set", "geometry.mesh_size=1e-4",
                               "--out", tmp_path / "o", "--no-figures"),
                      "geometry.mesh_size = 0.0001 m", "tetrahedra", "use mesh_size >=")
    assert "e+09 tetrahedra" in line  # 8.5 V/h^3 with V = 1037 cm3: 8.8e9
    assert not (tmp_path / "o" / "results.json").exists()


def test_the_fe_memory_bounds_the_mesh_size(tmp_path, monkeypatch):
    """With 0.5 GB, a 4 mm P2 crank (~250k tetrahedra, ~1 M DOF, ~10 GB to factorise) is
    refused before meshing; the limit says why."""
    from crankmodal.geometry import build

    monkeypatch.setattr(build, "generate", lambda *a, **kw: pytest.fail("meshed"))
    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("CRANKMODAL_MEMORY_LIMIT", "0.5")
    error_line(*run_cli("run", CRANK, "--set", "geometry.mesh_size=0.004", "--out",
                        tmp_path / "o", "--no-figures"),
               "geometry.mesh_size = 0.004 m", "fits in the 0.5 GB available")


def test_fe_element_limit_against_the_measured_factor_memory():
    """docs/guide/fem.md: the factor takes 2.78 GB at 303k P2 DOF, 12.9 GB at 831k (seed 004)."""
    from crankmodal.geometry.mesh import DOF_PER_ELEMENT, fe_element_limit

    for gb, dof in ((2.78, 303e3), (12.9, 831e3)):
        assert fe_element_limit(2, gb * 1e9) * DOF_PER_ELEMENT[2] == pytest.approx(dof, rel=0.02)
    assert fe_element_limit(2, None) is None


def test_size_for_elements_inverts_the_estimate():
    from crankmodal.geometry.mesh import estimate_elements, size_for_elements

    h = size_for_elements(1.037e-3, 0.1035, 5e6)
    assert estimate_elements(1.037e-3, 0.1035, h) == pytest.approx(5e6, rel=1e-9)


def test_element_estimate_against_gmsh(monkeypatch, tmp_path):
    """The estimate against a mesh gmsh makes (the rod at 6 mm, P1, ~1 s): within the fit's
    -35 % / +19 % band."""
    from crankmodal.geometry import build
    from crankmodal.geometry.mesh import MeshSettings, estimate_elements
    from crankmodal.geometry.params import params_from_dict
    from crankmodal.resources import load_machine

    seen = {}
    real = build.check_size

    def spy(volume, area, settings):
        seen.update(volume=volume, area=area)
        return real(volume, area, settings)

    monkeypatch.setattr(build, "check_size", spy)
    prm = params_from_dict("rod", load_machine("four_star_compressor")["rod"], where="rod")
    part = build.build_part(prm, "full", MeshSettings(size=0.006, order=1))
    assert seen["volume"] == pytest.approx(part.cad_mass.volume, rel=1e-9)
    ratio = estimate_elements(seen["volume"], seen["area"], 0.006) / part.n_elements
    assert 0.6 < ratio < 1.25, ratio


@pytest.mark.parametrize("machine, part", [("four_star_compressor", "crankshaft"),
                                           ("four_star_compressor", "rod"),
                                           ("multi_bearing_compressor", "crankshaft")])
def test_volume_floor_is_below_the_cad_volume(machine, part):
    """The check's volume bound against OpenCASCADE's volume of the built solid (all fidelities)."""
    import importlib

    from crankmodal.geometry.mesh import volume_floor
    from crankmodal.geometry.params import params_from_dict
    from crankmodal.geometry.session import gmsh_session
    from crankmodal.resources import load_machine

    prm = params_from_dict(part, load_machine(machine)[part], where=part)
    module = importlib.import_module(f"crankmodal.geometry.{'crankshaft' if part == 'crankshaft' else 'conrod'}")
    builder = module.build_crankshaft if part == "crankshaft" else module.build_conrod
    floor = volume_floor(prm)
    for fidelity in ("full", "dechamfered", "simplified"):
        with gmsh_session(f"{part} {fidelity}", {}) as gmsh:
            volumes, _, _ = builder(gmsh, prm, fidelity)
            cad = sum(gmsh.model.occ.getMass(3, v) for v in volumes)
        assert 0.1 * cad < floor < cad, (fidelity, floor, cad)


@pytest.mark.parametrize("scene", ["seed000_crank_report", "seed000_rod_static"])
def test_check_refuses_an_absurd_mesh_size_of_a_built_part(scene, monkeypatch):
    """`check` used to pass mesh_size = 1e-4; the scenes' own sizes still pass."""
    monkeypatch.delenv("CRANKMODAL_MEMORY_LIMIT", raising=False)
    error_line(*run_cli("check", SCENES / f"{scene}.toml", "--set", "geometry.mesh_size=1e-4"),
               "geometry.mesh_size = 0.0001 m: at least", "tetrahedra", "use mesh_size >=")
    assert run_cli("check", SCENES / f"{scene}.toml")[0] == 0


def test_a_huge_part_is_refused_naming_its_dimension():
    """journal_length = 1e30 passed check; the refusal names the dimension as well as the size
    (the fuzz asks for the key it changed)."""
    error_line(*run_cli("check", CRANK, "--set", "geometry.params.journal_length=1e30"),
               "geometry.params.journal_length", "1e+30", "[1e-06, 100] m")


def test_a_cache_that_cannot_be_written_is_a_warning_not_an_error(tmp_path, monkeypatch):
    """The part cache only saves time: under a file (or read-only, full) the run goes on."""
    from test_core_cli import _bar_vtu

    _bar_vtu(tmp_path / "bar.vtu", (4, 1, 1))
    (tmp_path / "s.toml").write_text('[geometry]\nfile = "bar.vtu"\n')
    (tmp_path / "taken").write_text("")
    monkeypatch.setenv("CRANKMODAL_CACHE", str(tmp_path / "taken" / "cache"))
    proc = run_subprocess("run", tmp_path / "s.toml", "--out", tmp_path / "o", warnings="default")
    assert proc.returncode == 0, proc.stderr
    assert "crankmodal: warning: geometry.cache: cannot store the part" in proc.stderr
    assert (tmp_path / "o" / "results.json").is_file()


@pytest.mark.parametrize("argv", [["demo"], ["study", "simplification", SCENES / "seed000_crank_study.toml"]],
                         ids=["demo", "study"])
def test_demo_and_study_with_out_a_file(tmp_path, argv):
    out = tmp_path / "taken"
    out.write_text("mine")
    error_line(*run_cli(*argv, "--out", out), str(out), "is a file, not a folder")
    error_line(*run_cli(*argv, "--out", out / "sub"), "a parent of it is a file")
    assert out.read_text() == "mine"


def test_sigterm_during_a_write_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    """`kill` (SIGTERM) while mechanism_curves.npz is half written: exit 143, the previous file
    intact, no temporary, no results.json. Before, SIGTERM ended the process where it stood."""
    import signal

    out = tmp_path / "o"
    out.mkdir()
    (out / "mechanism_curves.npz").write_bytes(b"old complete arrays")

    def killed(file, **arrays):
        with open(file, "wb") as fh:
            fh.write(b"PK\x03\x04 half")
            os.kill(os.getpid(), signal.SIGTERM)
            fh.write(b" more")  # the handler raises by here

    monkeypatch.setattr(np, "savez_compressed", killed)
    before = signal.getsignal(signal.SIGTERM)
    status, stderr = run_cli("run", MECHANISM, "--out", out, "--no-figures")
    assert status == 143 and stderr.strip().endswith("crankmodal: terminated"), stderr
    assert signal.getsignal(signal.SIGTERM) is before  # main() restores the handler
    assert (out / "mechanism_curves.npz").read_bytes() == b"old complete arrays"
    assert not (out / "results.json").exists() and temporaries(out) == []


def test_write_mesh_is_atomic_and_its_errors_name_the_users_file(tmp_path):
    from test_core_cli import _bar_vtu

    _bar_vtu(tmp_path / "bar.vtu", (4, 1, 1))
    for name in ("m.msh", "m.xyz"):
        (tmp_path / f"{name}.toml").write_text(f'[geometry]\nfile = "bar.vtu"\nwrite_mesh = "{name}"\n')
    out = tmp_path / "o"
    status, _ = run_cli("run", tmp_path / "m.msh.toml", "--out", out)
    assert status == 0 and (out / "m.msh").stat().st_size > 0 and temporaries(out) == []
    line = error_line(*run_cli("run", tmp_path / "m.xyz.toml", "--out", out),
                      "geometry.write_mesh", str(out / "m.xyz"))
    assert ".m.xyz." not in line and temporaries(out) == []


def test_write_atomic_writes_utf8_whatever_the_locale(tmp_path):
    """Reports carry −, † and ²; in an ASCII locale (LC_ALL=C without Python's UTF-8 mode) they
    raised UnicodeEncodeError."""
    import subprocess
    import sys

    text = "f − f_ref †, 2.5 m²\n"
    env = dict(os.environ, LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    code = ("import sys; from crankmodal.results import write_atomic; "
            f"write_atomic(sys.argv[1], {text!a})")  # ascii(): no locale decoding of argv
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "r.md")], env=env,
                          capture_output=True, text=True, encoding="utf-8", check=False)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "r.md").read_bytes() == text.encode("utf-8")
