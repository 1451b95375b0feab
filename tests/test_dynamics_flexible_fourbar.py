"""Flexible links in the four-bar (seed-001 loom geometry), against oracles: frozen modes give
the rigid four-bar to 1e-9, the energy balance counts strain energy, a slowly driven four-bar
under gravity stretches its flexible coupler as the full FE static solve, a struck coupler rings
at its pinned-pinned FE frequency, and bad input is refused by key (exit 2)."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from crankmodal.dynamics.flexible import build as flexbuild
from crankmodal.dynamics.model.bodies import RigidBody
from crankmodal.dynamics.model.mechanisms import four_bar
from crankmodal.dynamics.run.integrate import SolverSettings
from crankmodal.dynamics.run.simulate import simulate
from crankmodal.errors import ParameterError, SceneError

LOOM = {"crank_length": 0.035, "coupler_length": 0.075, "rocker_length": 0.145,
        "rocker_pivot": (-0.008, 0.1598), "masses": (35.8, 2.27, 10.42),
        "inertias": (0.0155, 0.00114, 0.0528), "extra_rocker_inertia": 0.3728, "branch": -1,
        "speed_rpm": 450.0}
SPEC = {"element_order": 2, "material": "steel", "fixed_interface_modes": 8, "n_modes": None,
        "cutoff_hz": None, "damping_ratio": 0.02, "interfaces": None}
#: slender steel bars between the pins: (length, in-plane width, thickness, mesh size), m
BARS = {"crank": (0.035, 0.02, 0.02, 0.01), "coupler": (0.075, 0.012, 0.008, 0.006),
        "rocker": (0.145, 0.02, 0.012, 0.012)}


def fe_bar(role):
    """The full FE model of a link's test bar (``BARS[role]``: steel, P2, the mesh the
    reduction uses) and its two end faces' distributing (RBE3) rows ``G`` (12, ndof): the
    oracle the reduced links are checked against. Returns ``(model, G)``."""
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import Material
    from crankmodal.fem.testparts import bar
    from crankmodal.reduction.interfaces import distributing_rows, make_interfaces

    L, w, t, h = BARS[role]
    div = tuple(max(1, int(np.ceil(d / h))) for d in (L, w, t))
    part = bar(L, w, t, div, order=2)
    model = assemble(part, Material("steel", 2.1e11, 0.3, 7850.0))
    itf = make_interfaces(part, [{"region": n, "kind": "distributing"}
                                 for n in ("end_x0", "end_x1")])
    return model, distributing_rows(model.points, model.cells, itf)[1]


@pytest.fixture(scope="module")
def bars():
    """The three links as coarse P2 bars reduced on their end faces (cached after a first run)."""
    out = {}
    for role, (L, w, t, h) in BARS.items():
        out[role] = flexbuild.reduced_bar(L, (w, t), dict(SPEC, mesh_size=h),
                                          f"dynamics.flexible.{role}")
    return SimpleNamespace(**out)


def _link(bars, role, **kw):
    return flexbuild.link_body(getattr(bars, role), dict(SPEC, **kw), BARS[role][0], role)


def _rigid(body):
    return RigidBody(body.name, body.mass, body.j0,
                     {n: tuple(body.frames[n][0]) for n in body.frames})


def test_frozen_links_give_the_rigid_four_bar(bars):
    """All three links flexible with 0 elastic modes against RigidBody links with the same mass,
    inertia and frames (the sley's inertia added to both rockers): joint forces, drive torque
    and the links' angular accelerations agree to 1e-9 of their peaks."""
    flex = {f"{r}_body": _link(bars, r, n_modes=0) for r in BARS}
    rigid = {k: _rigid(b) for k, b in flex.items()}
    s = SolverSettings(method="RK45", rtol=1e-11, atol=1e-14)
    T = 60.0 / LOOM["speed_rpm"]
    hf = simulate(four_bar(**LOOM, **flex), 0.25 * T, T / 360, s)
    hr = simulate(four_bar(**LOOM, **rigid), 0.25 * T, T / 360, s)
    for j in "ABCD":
        f, g = hf.joint_forces[j], hr.joint_forces[j]
        peak = np.hypot(*g.T).max()
        assert peak > 100.0  # the inertia forces load every joint
        assert np.abs(f - g).max() < 1e-9 * peak, j
    assert np.abs(hf.drive_torque - hr.drive_torque).max() < 1e-9 * np.abs(hr.drive_torque).max()
    for body in ("coupler", "rocker"):
        a, b = hf.angular_acceleration[body], hr.angular_acceleration[body]
        assert np.abs(b).max() > 100.0  # rad/s^2: it swings
        assert np.abs(a - b).max() < 1e-9 * np.abs(b).max(), body


def test_energy_balance_counts_the_strain_energy(bars):
    """Undamped flexible coupler and rocker, prescribed speed, no gravity: kinetic + strain
    energy change by the drive work alone, with the strain energy not negligible."""
    m = four_bar(**LOOM, coupler_body=_link(bars, "coupler", n_modes=4, damping_ratio=0.0),
                 rocker_body=_link(bars, "rocker", n_modes=3, damping_ratio=0.0))
    h = simulate(m, 0.01, 2e-5, SolverSettings(method="RK45", rtol=1e-9, atol=1e-12))
    e = h.energy
    assert e["strain"].max() > 1e-4 * np.abs(e["work_drive"]).max() > 0
    assert h.energy_error() < 1e-6
    assert e["dissipated_modal"][-1] == 0.0


def _coupler_static_fe(load_c, g_body):
    """The full FE coupler bar (the reduction's mesh and RBE3 couplings): the B end face's mean
    motion held, ``load_c`` (N, body axes) on the C interface and its own weight (``g_body``,
    m/s², body axes) on the mesh; returns the elongation between the interfaces, m."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla


    model, G = fe_bar("coupler")
    Gb, Gc = G[:6], G[6:]
    n = model.K.shape[0]
    kkt = sp.bmat([[model.K, Gb.T], [Gb, None]], format="csc")
    f = Gc.T @ np.array([load_c[0], load_c[1], 0.0, 0.0, 0.0, 0.0])
    f = f + model.M @ np.tile([g_body[0], g_body[1], 0.0], n // 3)
    u = spla.spsolve(kkt, np.concatenate([f, np.zeros(6)]))[:n]
    return float((Gc @ u)[0] - (Gb @ u)[0])


def test_slow_four_bar_under_gravity_stretches_the_coupler_as_the_static_fe(bars):
    """Quasi-static oracle: the loom four-bar at 1 rpm under gravity (the rocker's and sley's
    weight hang on the coupler), the coupler flexible with every stored in-plane mode and
    heavy modal damping: its elongation between the pins from the modal coordinates equals the
    full FE static solve of the bar under the joint force at C (the force of the run) and its
    own weight, to 1 % (and F L / (E A) to 2 %)."""
    from crankmodal.dynamics.flexible.initial import quasi_static_start

    g = np.array([0.0, -9.81])
    coupler = _link(bars, "coupler", damping_ratio=0.7)  # every stored in-plane mode
    slow = dict(LOOM, speed_rpm=1.0, theta0=np.deg2rad(60.0))
    m = four_bar(**slow, coupler_body=coupler, gravity=g)
    m.q0, m.qd0, _ = quasi_static_start(m.system, m.q0, m.qd0)
    h = simulate(m, 0.05, 1e-3, SolverSettings(method="RK45", rtol=1e-9, atol=1e-14))
    xi = h.modal["coupler"][-1]
    d_b, d_c = coupler.frames["B"][1], coupler.frames["C"][1]
    elongation = float(((d_c - d_b) @ xi)[0])  # along the body x axis (B -> C)
    # the coupler's direction at the end: the rigid four-bar at the same crank angle
    phi = four_bar(**dict(slow, theta0=h.crank_angle[-1])).q0[5]
    A = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    load_c = A.T @ h.joint_forces["C"][-1]  # the rocker's force on the coupler, body axes
    assert abs(load_c[0]) > 30.0  # N, the rocker's weight on the coupler (compressed here)
    ref = _coupler_static_fe(load_c, A.T @ g)
    assert elongation == pytest.approx(ref, rel=1e-2)
    L, w, t, _ = BARS["coupler"]
    assert elongation == pytest.approx(load_c[0] * L / (2.1e11 * w * t), rel=2e-2)


def test_quasi_static_start_loads_a_stiff_coupler_at_once(bars):
    """The loom's coupler as a stubby bar of its own mass (50 x 77 mm, first mode 17 kHz): from
    the quasi-static start its joints carry the rigid twin's forces at t = 0 (to 1e-3 of the
    peak). Scaled by ω², the undeformed state already looked converged to the old test (1e-9)
    while the joints carried 30 N of the rigid 1 400 N, and the run rang at 650 kN."""
    from crankmodal.dynamics.flexible.initial import quasi_static_start

    spec = dict(SPEC, mesh_size=0.025, fixed_interface_modes=6)
    path = flexbuild.reduced_bar(0.075, (0.05, 0.077), spec, "dynamics.flexible.coupler")
    coupler = flexbuild.link_body(path, spec, 0.075, "coupler")
    m = four_bar(**LOOM, coupler_body=coupler)
    q, qd, info = quasi_static_start(m.system, m.q0, m.qd0)
    assert info["iterations"] >= 1
    lam = m.system.solve(0.0, q, qd)["lam"][:8]
    r = four_bar(**LOOM, coupler_body=flexbuild.rigid_twin(coupler))
    lam_r = r.system.solve(0.0, r.q0, r.qd0)["lam"][:8]
    assert np.abs(lam_r).max() > 1000.0
    assert np.abs(lam - lam_r).max() < 1e-3 * np.abs(lam_r).max()


def test_quasi_static_start_with_the_seed_clearance_at_c_starts_centred(tmp_path):
    """The loom with the seed's lubricated clearance at C on a flexible coupler: the stage
    solves the quasi-static start on the ideal-joint twin, so the run starts with the journal
    at its bearing centre (penetration -c). Across the clearance itself Newton had converged
    (7 iterations) to a coupler bent 35 µm into the bore, held by the film force past the wall
    (1.3 MN at t = 0)."""
    from conftest import run_in_process

    lines = ['name = "fourbar_clearance"', "[dynamics]", 'machine = "loom_four_bar"',
             "end_time = 0.002", "output_step = 1e-4", "[dynamics.flexible]",
             "coupler = { bar = [0.05, 0.077], mesh_size = 0.025, fixed_interface_modes = 6 }"]
    scene = tmp_path / "scene.toml"
    scene.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    status, err = run_in_process("run", scene, "--out", out, "--no-figures")
    assert status == 0, err
    z = np.load(out / "dynamics.npz")
    assert z["contact_C_penetration"][0] == pytest.approx(-2.1e-5, abs=1e-9)  # m: centred
    assert np.abs(z["contact_C_film_force"][:3]).max() < 1e4  # N (was 1.3e6)
    # method auto: a flexible body with an oil film runs Radau (LSODA stalled on this one),
    # which is stable on the coupler's 17-61 kHz modes: its step is not bound by them
    res = json.loads((out / "results.json").read_text())["dynamics"]
    assert res["solver_method"] == "Radau"
    sb = res["flexible"]["step_bound"]
    assert sb["body"] == "coupler" and sb["frequency_hz"] > 1e4 and not sb["bound"]


def test_a_truncated_rocker_carrying_the_sley_is_warned_and_a_complete_one_not(bars):
    from crankmodal.dynamics.scene.flexstage import truncation_warnings

    p = {"mechanism": "four_bar", "four_bar": {"extra_rocker_inertia": 0.3728}}
    stored = len(_link(bars, "rocker").left_out()["offered_hz"])
    assert stored >= 3
    cut = {"links": {"rocker": _link(bars, "rocker", n_modes=2)}}
    full = {"links": {"rocker": _link(bars, "rocker")}}
    assert len(truncation_warnings(p, cut)) == 1
    assert f"keeps 2 of the {stored} stored" in truncation_warnings(p, cut)[0]
    assert truncation_warnings(p, full) == []
    assert truncation_warnings(dict(p, four_bar={"extra_rocker_inertia": 0.0}), cut) == []
    assert truncation_warnings(p, {"links": {"coupler": _link(bars, "coupler", n_modes=1)}}) == []


def test_link_bodies_at_the_wrong_length_or_without_their_frames_are_refused(bars):
    # the builder (Python API) names its argument; a scene names the key (the stage's
    # body_keys, and the bad-input cases below through `crankmodal run`)
    with pytest.raises(ParameterError, match=r"^source: .*coupler length is 0.08 m"):
        flexbuild.link_body(bars.coupler, SPEC, 0.08, "coupler")
    with pytest.raises(ParameterError, match=r"^interfaces: .*no interface 'pin'"):
        flexbuild.link_body(bars.rocker, dict(SPEC, interfaces=["end_x0", "pin"]), 0.145,
                            "rocker")
    from crankmodal.dynamics.scene.flexstage import body_keys

    with pytest.raises(SceneError, match=r"^dynamics.flexible.coupler.file: .*coupler length is "
                                         r"0.08 m"), body_keys("coupler"):
        flexbuild.link_body(bars.coupler, SPEC, 0.08, "coupler")
    body = _link(bars, "coupler", n_modes=0)
    with pytest.raises(ParameterError, match="coupler_body: its frames 'B' and 'C' are 0.075 m "
                                             "apart, the coupler length is 0.07 m"):
        four_bar(**dict(LOOM, coupler_length=0.07), coupler_body=body)
    with pytest.raises(ParameterError, match="rocker_body: needs frames 'D' and 'C'"):
        four_bar(**LOOM, rocker_body=body)


def _coupler_pinned_pinned_fe_hz():
    """In-plane pinned-pinned bending frequency of the full FE coupler bar with the same RBE3
    couplings: both interfaces' mean translations held (a penalty 1e6 x the stiffest diagonal),
    their rotations free; the lowest mode with over 90 % of its motion along y."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla


    model, G = fe_bar("coupler")
    C = sp.vstack([G[0:3], G[6:9]]).tocsr()
    alpha = 1e6 * model.K.diagonal().max() / abs(C).max() ** 2
    lam, u = spla.eigsh((model.K + alpha * (C.T @ C)).tocsc(), 6, model.M.tocsc(), sigma=0.0)
    share_y = np.sum(u[1::3] ** 2, axis=0) / np.sum(u ** 2, axis=0)
    j = int(np.argmax(share_y > 0.9))
    assert share_y[j] > 0.9
    return float(np.sqrt(lam[j]) / (2 * np.pi))


def test_struck_coupler_rings_at_its_pinned_pinned_fe_frequency(bars):
    """The loom four-bar at rest (crank held by its drive), the slender coupler struck in its
    first in-plane mode: it rings at the full FE pinned-pinned bending frequency (4810.2 Hz;
    4834.8 Hz, +0.5 %, with the 3 lowest in-plane modes kept here, 4810.9 Hz with all 7 stored,
    6x slower). The heavy rocker and sley (0.48 kg m² about D, 23 kg at C) hold C nearly still."""
    from conftest import peak_hz

    f_fe = _coupler_pinned_pinned_fe_hz()
    coupler = _link(bars, "coupler", n_modes=3, damping_ratio=0.0)
    m = four_bar(**dict(LOOM, speed_rpm=0.0), coupler_body=coupler)
    sl = m.system.slices[id(coupler)]
    m.qd0 = np.zeros_like(m.qd0)
    m.qd0[sl.start + 3] = 0.05  # m kg^½ / s
    m.q0, m.qd0 = m.system.assemble(0.0, m.q0, m.qd0)
    t_end = 12 / f_fe
    h = simulate(m, t_end, t_end / 2000, SolverSettings(method="RK45", rtol=1e-8, atol=1e-13))
    xi = h.modal["coupler"][:, 0]
    assert np.ptp(xi) > 1e-8  # (the joints take most of the strike: 0.05 -> 7e-4 m kg^½/s)
    assert abs(peak_hz(h.t, xi) / f_fe - 1) < 1e-2, (peak_hz(h.t, xi), f_fe)


def _scene(tmp_path, flexible: dict, mechanism_lines=()):
    lines = ['name = "fourbar_flex"', "[dynamics]", 'machine = "loom_four_bar"',
             "clearances = []", "end_time = 0.01", *mechanism_lines, "[dynamics.flexible]"]
    for key, spec in flexible.items():
        items = ", ".join(f"{k} = {v!r}".replace("'", '"') for k, v in spec.items())
        lines.append(f"{key} = {{ {items} }}")
    path = tmp_path / "scene.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_scene_runs_a_flexible_coupler_and_rocker_against_the_rigid_twin(bars, tmp_path):
    """`crankmodal run` on the loom with a flexible coupler from a file and a flexible rocker
    reduced here as a bar: results name both bodies, their joints' interfaces and the
    comparison with the rigid twin at A (the "main bearing") and at B, C and D, and the
    flexible rocker's angular acceleration."""
    import json

    from conftest import run_in_process

    out = tmp_path / "out"
    scene = _scene(tmp_path, {"coupler": {"file": str(bars.coupler), "n_modes": 3},
                              "rocker": {"bar": [0.02, 0.012], "mesh_size": 0.012,
                                         "fixed_interface_modes": 8, "n_modes": 2}})
    status, err = run_in_process("run", scene, "--out", out, "--no-figures")
    assert status == 0, err
    # the rocker carries the loom's sley with 2 of its stored modes: warned, by key
    warned = json.loads((out / "results.json").read_text())["dynamics"]["warnings"]
    assert any(w.startswith("dynamics.flexible.rocker.n_modes: keeps 2 of the ") for w in warned)
    res = json.loads((out / "results.json").read_text())
    d = next(v for v in _walk(res) if isinstance(v, dict) and "bodies" in v and "rigid" in v)
    assert set(d["bodies"]) == {"coupler", "rocker"}
    assert d["bodies"]["coupler"]["interfaces"] == {"B": "end_x0", "C": "end_x1"}
    assert d["bodies"]["rocker"]["extra_inertia_kgm2"] == pytest.approx(0.3728)
    assert d["bodies"]["rocker"]["extra_inertia_frame"] == "D"  # attached at the shaft
    assert d["bodies"]["rocker"]["extra_inertia_interface"] == "end_x0"
    assert set(d["rigid"]) == {"main_bearing", "B", "C", "D"}
    assert d["rigid"]["C"]["rigid_peak_n"] > 100.0
    assert "bar_" in d["files"]["rocker"]
    # the flexible rocker's swing (its frame, the mean axes) is reported as a rigid one's
    dyn = next(v for v in _walk(res) if isinstance(v, dict) and "angular_acceleration_peak" in v)
    assert dyn["angular_acceleration_peak"]["rocker"] > 100.0  # rad/s^2
    assert "rocker accel peak 0 " not in dyn["summary"]


def _walk(d):
    yield d
    if isinstance(d, dict):
        for v in d.values():
            yield from _walk(v)
    elif isinstance(d, list):
        for v in d:
            yield from _walk(v)


@pytest.mark.parametrize("case, match", [
    ("missing", "dynamics.flexible.coupler.file: no file"),
    ("interface", "dynamics.flexible.coupler.interfaces: .*no interface 'pin'"),
    ("distance", "dynamics.flexible.rocker.file: .*rocker length is 0.145 m"),
    ("too_many", "dynamics.flexible.coupler.n_modes: .*99 asked, but the file stores"),
    ("damping", "dynamics.flexible.coupler.damping_ratio"),
    ("rods", "dynamics.flexible.rods: a four_bar has no rods"),
    ("neither", "dynamics.flexible.coupler: give file"),
    ("both", "dynamics.flexible.coupler: give file"),
    ("crank_train", "dynamics.flexible.coupler: a slider_crank has no coupler"),
    ("same_twice", "dynamics.flexible.coupler.interfaces: two different interfaces"),
    ("crank_torque", "dynamics.drive_torque: with a flexible crank the speed is prescribed"),
])
def test_bad_four_bar_flexible_input_exits_2_naming_the_key(bars, tmp_path, case, match):
    """Every bad four-bar link input through `crankmodal run`: exit 2, one line naming the key,
    no results.json."""
    import re

    from conftest import run_in_process

    ok = {"file": str(bars.coupler), "n_modes": 1}
    mech = ()
    flex = {"missing": {"coupler": {"file": str(tmp_path / "nothing.npz")}},
            "interface": {"coupler": dict(ok, interfaces=["end_x0", "pin"])},
            "distance": {"rocker": ok},
            "too_many": {"coupler": dict(ok, n_modes=99)},
            "damping": {"coupler": dict(ok, damping_ratio=-0.1)},
            "rods": {"rods": ok},
            "neither": {"coupler": {"n_modes": 1}},
            "both": {"coupler": dict(ok, bar=[0.01, 0.01])},
            "crank_train": {"coupler": ok},
            "same_twice": {"coupler": dict(ok, interfaces=["end_x0", "end_x0"])},
            "crank_torque": {"crank": {"bar": [0.02, 0.02]}}}[case]
    if case == "crank_train":
        mech = ('mechanism = "slider_crank"', "speed_rpm = 1000.0")
    if case == "crank_torque":
        mech = ("drive_torque = 10.0",)
    out = tmp_path / "out"
    status, err = run_in_process("run", _scene(tmp_path, flex, mech), "--out", out)
    lines = [ln for ln in err.strip().splitlines() if ln.strip() and not ln.startswith("[")]
    assert status == 2, err
    assert len(lines) == 1 and re.search(match, lines[0]), err
    assert "Traceback" not in err
    assert not (out / "results.json").exists()


def test_four_bar_figure_draws_joints_a_to_d_flexible_rigid_and_difference(bars, tmp_path,
                                                                          monkeypatch):
    """`crankmodal run` with figures on the loom with a flexible coupler: the flexible-vs-rigid
    figure has one panel per four-bar joint A, B, C, D (none titled "main bearing"), each with
    the flexible and rigid-twin force magnitudes (kN) and, on a twin axis, |F_flex - F_rigid|
    (N) equal to that of the arrays in dynamics.npz over the last revolution drawn."""
    from conftest import run_in_process

    from crankmodal.dynamics.results import flexplots

    drawn = {}
    save = flexplots._save

    def spy(plt, fig, path):
        drawn[path.name] = [(a.get_title(), [(ln.get_label(), ln.get_xydata()) for ln in a.lines])
                            for a in fig.axes]
        return save(plt, fig, path)

    monkeypatch.setattr(flexplots, "_save", spy)
    out = tmp_path / "out"
    status, err = run_in_process("run", _scene(tmp_path, {"coupler": {"file": str(bars.coupler),
                                                                      "n_modes": 3}}),
                                 "--out", out)
    assert status == 0, err
    assert (out / "dynamics_flexible_main_bearing.png").stat().st_size > 0
    axes = drawn["dynamics_flexible_main_bearing.png"]
    titled = [(t, lines) for t, lines in axes if t]
    joints = [(t, lines) for t, lines in titled if t.startswith("joint ") and "order" not in t]
    assert [t.split()[1] for t, _ in joints] == ["A", "B", "C", "D"]
    assert all("of the four-bar" in t for t, _ in joints)
    assert not any("main bearing" in t or "main-bearing" in t for t, _ in titled)
    # the difference curves: the untitled twin axes, one per joint panel, in joint order
    diffs = [lines for t, lines in axes if not t and lines]
    assert len(diffs) == 4
    z = np.load(out / "dynamics.npz")
    for (title, lines), twin in zip(joints, diffs):
        j = title.split()[1]
        (_, flex), (_, rig) = [(n, xy) for n, xy in lines if n in ("flexible", "rigid twin")]
        (name, dxy), = twin
        assert name.startswith("|flexible - rigid|")
        f, g = z[f"joint_force_{j}"], z[f"rigid_joint_force_{j}"]
        n = flex.shape[0]  # the last samples: the last revolution (here the whole short run)
        assert np.allclose(flex[:, 1], np.hypot(*f[-n:].T) / 1e3)
        assert np.allclose(rig[:, 1], np.hypot(*g[-n:].T) / 1e3)
        assert np.allclose(dxy[:, 1], np.hypot(*(f - g)[-n:].T))
        assert dxy[:, 1].max() > 0.0  # the flexible coupler differs from its rigid twin
