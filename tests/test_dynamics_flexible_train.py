"""Flexible crank and rods in the four-star crank train, against oracles: frozen modes give the
rigid crank (one main joint) to 1e-9, the energy balance counts strain energy, clearance at a
flexible interface runs with the usual contact checks, and bad input is refused by key."""

from types import SimpleNamespace

import numpy as np
import pytest

from crankmodal.dynamics.flexible import build as flexbuild
from crankmodal.dynamics.model.bodies import RigidBody
from crankmodal.dynamics.model.bridge import cylinders_from_mechanism
from crankmodal.dynamics.model.mechanisms import crank_train
from crankmodal.dynamics.run.integrate import SolverSettings
from crankmodal.dynamics.run.simulate import simulate

SPEC_CRANK = {"fidelity": "full", "mesh_size": 0.022, "element_order": 2,
              "material": "crank_steel_seed000", "fixed_interface_modes": 16, "n_modes": 6,
              "cutoff_hz": None, "damping_ratio": 0.02, "file": None}
SPEC_ROD = {"fidelity": "full", "mesh_size": 0.014, "element_order": 2, "material": "42CrMo",
            "fixed_interface_modes": 10, "n_modes": 3, "cutoff_hz": None, "damping_ratio": 0.02,
            "file": None}


@pytest.fixture(scope="module")
def parts():
    """The four-star's crank and rod reduced at coarse meshes (cached after the first run), and
    its cylinders (gas forces removed: the oracles want closed energy books)."""
    from crankmodal.mechanism.stage import validate as validate_mechanism
    from crankmodal.resources import load_machine

    mp = validate_mechanism(load_machine("four_star_compressor")["mechanism"], None)
    src = cylinders_from_mechanism(mp)
    cyl = [c for c in src["cylinders"]]
    for c in cyl:
        c.gas_force = None
    crank = flexbuild.reduced_part("four_star_compressor", "crankshaft", SPEC_CRANK, n_rods=4)
    rod = flexbuild.reduced_part("four_star_compressor", "rod", SPEC_ROD)
    return SimpleNamespace(crank=crank, rod=rod, cylinders=cyl, radius=src["crank_radius"],
                           rows=[c.z for c in cyl], lengths=[c.rod_length for c in cyl])


def _train(parts, crank=None, roles=None, rods=None, clearances=None, direction=-1):
    return crank_train(parts.radius, parts.cylinders, 1480.0, crank_body=crank,
                       crank_roles=roles, rod_bodies=rods, clearances=clearances,
                       kind="four_star", direction=direction)


def _flex(parts, n_crank, n_rod, zeta=0.02):
    c, roles = flexbuild.crank_body(parts.crank, dict(SPEC_CRANK, n_modes=n_crank,
                                                      damping_ratio=zeta),
                                    parts.rows, parts.radius)
    rods = [flexbuild.rod_body(parts.rod, dict(SPEC_ROD, n_modes=n_rod, damping_ratio=zeta),
                               L, f"rod_{i}", z=z)
            for i, (L, z) in enumerate(zip(parts.lengths, parts.rows), start=1)]
    return c, roles, rods


def test_frozen_modes_give_the_rigid_crank_on_one_main_bearing(parts):
    """Zero elastic modes kept (the crank on its two journals with its tilts, the rods as
    flexible bodies without modes) against RigidBody crank and rods with the same mass
    properties on ONE main joint: the total main-bearing force agrees to 1e-9 of its peak."""
    crank, roles, rods = _flex(parts, 0, 0)
    assert crank.n_tilt == 2 and crank.n_elastic == 0
    assert len(roles["mains"]) == 2
    frames = {n: tuple(crank.frames[n][0]) for n in ["main_1", "drive"] + roles["pins"]}
    rigid_crank = RigidBody("crank", crank.mass, crank.j0, frames)
    rigid_rods = [RigidBody(r.name, r.mass, r.j0, {n: tuple(r.frames[n][0]) for n in
                                                  ("big", "small")}) for r in rods]
    r_roles = {"mains": ["main_1"], "pins": roles["pins"], "drive": "drive"}
    settings = SolverSettings(method="RK45", rtol=1e-11, atol=1e-14)
    h_flex = simulate(_train(parts, crank, roles, rods), 0.01, 1e-4, settings)
    h_rig = simulate(_train(parts, rigid_crank, r_roles, rigid_rods), 0.01, 1e-4, settings)
    f, g = h_flex.main_bearing_force, h_rig.main_bearing_force
    assert np.hypot(*g.T).max() > 1e3  # the inertia forces load the bearing
    assert np.abs(f - g).max() < 1e-9 * np.hypot(*g.T).max()
    # the two journals share it (a beam on two supports): neither carries all of it
    j1 = np.hypot(*h_flex.joint_forces["main_1"].T)
    assert 0.2 < j1.mean() / np.hypot(*f.T).mean() < 0.8


def test_energy_balance_counts_the_strain_energy(parts):
    """No damping, no gas, prescribed speed: kinetic + strain energy change by the drive work
    alone (the residual counts strain energy), while the strain energy is not negligible."""
    crank, roles, rods = _flex(parts, 4, 2, zeta=0.0)
    h = simulate(_train(parts, crank, roles, rods), 0.01, 2e-5,
                 SolverSettings(method="RK45", rtol=1e-9, atol=1e-12))
    e = h.energy
    assert e["strain"].max() > 1e-3 * np.abs(e["work_drive"]).max() > 0
    assert h.energy_error() < 1e-5
    assert e["dissipated_modal"][-1] == 0.0


def test_clearance_at_a_flexible_big_end_runs_with_the_contact_checks(parts):
    """0.1 mm at the big end of flexible rod 1 on the flexible crank's pin band: impacts are
    found and counted, and the run's energy balance closes."""
    crank, roles, rods = _flex(parts, 4, 2)
    spec = {"big_end_1": {"clearance": 1e-4, "journal_radius": 0.0225,
                          "contact": {"law": "impact", "law_params": {
                              "stiffness": 1.581e10, "exponent": 1.5, "damping": 300.0,
                              "penetration": 1e-4}}}}
    mech = _train(parts, crank, roles, rods, clearances=spec)
    assert [cj.name for cj in mech.system.clearances] == ["big_end_1"]
    h = simulate(mech, 0.02, 5e-5, SolverSettings(method="RK45", rtol=1e-6, atol=1e-9))
    assert len(h.onsets["big_end_1"]) >= 1
    assert h.contact["big_end_1"]["penetration"].max() > 0
    assert h.energy_error() < 1e-3


def test_interfaces_at_the_wrong_places_are_refused(parts, tmp_path):
    # the builders name their argument (the scene path, naming dynamics.flexible.<body>.file,
    # is test_bad_flexible_input_exits_2_with_one_line_naming_the_key)
    from crankmodal.errors import ParameterError

    with pytest.raises(ParameterError, match=r"^source: .*crank radius is 0.05"):
        flexbuild.crank_body(parts.crank, SPEC_CRANK, parts.rows, 0.05)
    with pytest.raises(ParameterError, match=r"^source: .*rod length is 0.3 m"):
        flexbuild.rod_body(parts.rod, SPEC_ROD, 0.3, "rod_1")
    with pytest.raises(ParameterError, match=r"^source: .*needs main_journal_"):
        flexbuild.crank_body(parts.rod, SPEC_CRANK, parts.rows, parts.radius)


def _rod_static_fe(force):
    """The full FE rod (the reduction's mesh) with the same distributing (RBE3) couplings as
    constraints: the big-end bore's mean motion held (G_big u = 0), ``force`` (N) applied to
    the small-end interface towards the big end (load G_smallᵀ f): its shortening (m) and
    largest nodal von Mises stress (Pa, the reduction's stress recovery)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.material_stage import make_material
    from crankmodal.geometry.stage import make_part
    from crankmodal.geometry.stage import validate as validate_geometry
    from crankmodal.reduction.interfaces import distributing_rows, make_interfaces

    gp = validate_geometry({"machine": "four_star_compressor", "part": "rod",
                            "fidelity": SPEC_ROD["fidelity"], "mesh_size": SPEC_ROD["mesh_size"],
                            "element_order": SPEC_ROD["element_order"]},
                           SimpleNamespace(sections={"reduction": {}}))
    part, _ = make_part(gp)
    model = assemble(part, make_material({"name": SPEC_ROD["material"]}))
    itf = make_interfaces(part, [{"region": "big_end_bore", "kind": "distributing"},
                                 {"region": "small_end_bore", "kind": "distributing"}])
    _, G = distributing_rows(model.points, model.cells, itf)
    Gb, Gs = G[:6], G[6:]
    n = model.K.shape[0]
    kkt = sp.bmat([[model.K, Gb.T], [Gb, None]], format="csc")
    f = Gs.T @ np.array([-force, 0.0, 0.0, 0.0, 0.0, 0.0])
    u = spla.spsolve(kkt, np.concatenate([f, np.zeros(6)]))[:n]
    from crankmodal.reduction.stress_modes import stress_modes, stress_recovery, von_mises

    sig = stress_modes(stress_recovery(model, part.mesh), u[:, None])
    return -float((Gs @ u)[0]), float(von_mises(sig, axis=1).max())


def test_slow_crank_under_a_constant_piston_load_deflects_the_rod_as_the_static_fe(oracle, parts):
    """Quasi-static oracle: a slider-crank at 6 rpm with a constant 20 kN on the piston and a
    flexible rod (every in-plane mode stored, heavy modal damping to settle the start): the
    shortening of the rod between its bores equals the full FE static solve of the same rod
    under the rod force F / cos(beta): 148.02 µm both, 5e-7 apart (the Craig-Bampton basis
    holds the static response to interface loads exactly; the issue asks <= 1 %); and the
    dynamic stress from the stored stress modes equals that solve's largest von Mises."""
    from crankmodal.dynamics.model.mechanisms import Cylinder
    from crankmodal.dynamics.scene.flexstage import dynamic_stress

    F = 2.0e4
    rod = flexbuild.rod_body(parts.rod, dict(SPEC_ROD, n_modes=None, damping_ratio=0.7),
                             parts.lengths[0], "rod_1")
    cyl = Cylinder(axis_angle=0.0, rod_length=parts.lengths[0], rod_mass=rod.mass,
                   rod_inertia=rod.j0, rod_com=0.0, piston_mass=1.2,
                   gas_force=lambda angle: F)
    mech = crank_train(parts.radius, [cyl], 6.0, crank_mass=5.0, crank_inertia=0.01,
                       theta0=np.deg2rad(60.0), rod_bodies=[rod])
    h = simulate(mech, 0.03, 1e-3, SolverSettings(method="RK45", rtol=1e-9, atol=1e-13))
    xi = h.modal["rod_1"][-1, :rod.n_elastic]
    d_big, d_small = rod.frames["big"][1], rod.frames["small"][1]
    shortening = -float(((d_small - d_big) @ xi)[0])  # along the body x axis (big -> small)
    # the rod force from the rod angle at the end: F / cos(beta)
    th = h.crank_angle[-1]
    beta = np.arcsin(parts.radius * np.sin(th) / parts.lengths[0])
    ref, vm_ref = _rod_static_fe(F / np.cos(beta))
    assert ref > 1e-6
    oracle(stage="flexible", quantity="flexible rod shortening under 20 kN at 6 rpm, m", reference="full FE static solve of the rod, same couplings (second formulation)", tolerance="0.1 %", measured=shortening, expected=ref)
    assert shortening == pytest.approx(ref, rel=1e-3)
    st = dynamic_stress(rod, h.modal["rod_1"][-1:], h.t[-1:], h.crank_angle[-1:])
    assert vm_ref > 1e7
    assert st["max_von_mises_pa"] == pytest.approx(vm_ref, rel=1e-3)


def _flex_scene(tmp_path, crank=None, rods=None):
    from crankmodal.dynamics.flexible.build import flexbody_cache_dir  # noqa: F401 (the cache dir)

    lines = ['name = "flex_bad"', "[mechanism]", 'machine = "four_star_compressor"',
             "[dynamics]", 'machine = "four_star_compressor"', "clearances = []",
             "end_time = 0.001", "ramp_time = 0.0", "[dynamics.flexible]"]
    for key, spec in (("crank", crank), ("rods", rods)):
        if spec is not None:
            items = ", ".join(f"{k} = {v!r}".replace("'", '"') for k, v in spec.items())
            lines.append(f"{key} = {{ {items} }}")
    path = tmp_path / "scene.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("case, match", [
    ("other_npz", "dynamics.flexible.crank: .*not a crankmodal-flexbody"),
    ("version", "dynamics.flexible.crank: .*version 2"),
    ("missing", "dynamics.flexible.crank.file: no file"),
    ("too_many", "dynamics.flexible.crank.n_modes: .*99 asked, but the file stores"),
    ("damping", "dynamics.flexible.rods.damping_ratio"),
    ("no_journal", "dynamics.flexible.crank.file: .*needs main_journal_"),
    ("rod_length", "dynamics.flexible.rods.file: .*rod length is 0.392"),
    ("unknown", "dynamics.flexible.rods.n_mode"),
])
def test_bad_flexible_input_exits_2_with_one_line_naming_the_key(parts, tmp_path, case, match):
    """Every bad flexible-body input through `crankmodal run`: exit 2, one line naming the
    key, and no results.json written."""
    import re

    from conftest import run_in_process

    crank_ok = {"file": str(parts.crank), "n_modes": 2}
    rods_ok = {"file": str(parts.rod), "n_modes": 1}
    bad = tmp_path / "bad.npz"
    if case == "other_npz":
        np.savez(bad, a=np.zeros(3))
        crank, rods = {"file": str(bad)}, None
    elif case == "version":
        z = dict(np.load(parts.crank))
        z["version"] = np.array(2)
        np.savez(bad, **z)
        crank, rods = {"file": str(bad)}, None
    elif case == "missing":
        crank, rods = {"file": str(tmp_path / "nothing.npz")}, None
    elif case == "too_many":
        crank, rods = dict(crank_ok, n_modes=99), None
    elif case == "damping":
        crank, rods = None, dict(rods_ok, damping_ratio=-0.1)
    elif case == "no_journal":
        crank, rods = {"file": str(parts.rod)}, None
    elif case == "rod_length":
        z = dict(np.load(parts.rod))
        c = z["interface_centres"].copy()
        c[1, 0] *= 1.2  # the small end 20 % further out
        z["interface_centres"] = c
        np.savez(bad, **z)
        crank, rods = None, {"file": str(bad)}
    else:
        crank, rods = None, {"file": str(parts.rod), "n_mode": 1}
    out = tmp_path / "out"
    status, err = run_in_process("run", _flex_scene(tmp_path, crank, rods), "--out", out)
    lines = [ln for ln in err.strip().splitlines() if ln.strip() and not ln.startswith("[")]
    assert status == 2, err
    assert len(lines) == 1 and re.search(match, lines[0]), err  # only stage progress besides
    assert "Traceback" not in err
    assert not (out / "results.json").exists()


def test_redundant_journals_are_refused_before_the_run(parts):
    """A crank held at two journals without its tilts and with no elastic mode: four joint
    equations on two coordinates' worth of freedom; refused by name, not a singular solve."""
    from crankmodal.dynamics.flexible.body import load_flexible_body
    from crankmodal.dynamics.model.mechanisms import RedundantJoints

    crank, roles = flexbuild.crank_body(parts.crank, dict(SPEC_CRANK, n_modes=0), parts.rows,
                                        parts.radius)
    stiff = load_flexible_body(parts.crank, "crank", n_modes=0, orientation=crank.orientation)
    stiff.frames.update({k: v for k, v in crank.frames.items() if k not in stiff.frames})
    for name, (s0, _, _) in crank.frames.items():  # the same frames, without the tilt columns
        stiff.frames[name] = (s0, np.zeros((2, 0)), np.zeros(0))
    with pytest.raises(RedundantJoints, match="2 of its .* joint equations are redundant"):
        _train(parts, stiff, roles)


def test_quasi_static_start_removes_the_start_up_ringing(parts):
    """Started at full speed with the undeformed bodies, the four-star's main bearing sees a
    start-up blow of ~100x its running force; from the quasi-static state (elastic
    accelerations zero at t = 0, joints closed) the force stays at its running level and the
    run needs far fewer evaluations."""
    from crankmodal.dynamics.flexible.initial import quasi_static_start

    crank, roles, rods = _flex(parts, 4, 2)
    for c in parts.cylinders:
        c.gas_force = lambda a: 3.0e3
    try:
        mech = _train(parts, crank, roles, rods)
        s = SolverSettings(method="RK45", rtol=1e-6, atol=1e-9)
        h0 = simulate(mech, 0.005, 1e-5, s, start="undeformed")  # the builder's state
        q, qd, info = quasi_static_start(mech.system, mech.q0, mech.qd0)
    finally:
        for c in parts.cylinders:
            c.gas_force = None
    assert info["iterations"] >= 1 and info["residual"] < 1e-9
    out = mech.system.solve(0.0, q, qd)
    assert np.abs(out["phi"]).max() < 1e-10
    k = crank.n_elastic
    sl = mech.system.slices[id(crank)]
    assert np.abs(out["qdd"][sl][3:3 + k] / crank.K[:k]).max() < 1e-9
    assert np.abs(q[sl][3:3 + k]).max() > 1e-7  # it did deform
    mech.q0, mech.qd0 = q, qd  # the piston loads keep the 3 kN they were built with
    h1 = simulate(mech, 0.005, 1e-5, s, start="undeformed")  # q0 as set: quasi-static
    f0, f1 = np.hypot(*h0.main_bearing_force.T), np.hypot(*h1.main_bearing_force.T)
    assert f0.max() > 10 * f1.max()
    assert f1.max() < 3 * np.median(f1)
    # 476 of 950 evaluations since the crank's modes count their axial kinetic energy (crank_body)
    assert h1.nfev < 0.55 * h0.nfev
