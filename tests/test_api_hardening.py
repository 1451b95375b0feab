"""The Python API refuses misuse as the CLI does, and its flexible path does what a scene does.

Probes (issue 25, item 5): wrong types, NaN/inf, negative, zero and absurd values through the
public functions; each must raise one ``ParameterError`` whose ``argument`` names the offending
argument (before this test existed, 48 of the first 49 raised a raw TypeError, ValueError,
ZeroDivisionError, MemoryError, LinAlgError, ... or ran on nonsense).

Flexible path (item 4): ``crank_train(..., crank_body=...)`` without ``crank_roles``, the
builders' ``spec`` with its documented defaults, ``simulate`` starting flexible bodies
quasi-statically as scenes do (oracle: the rigid twin, the same masses with the modes frozen, a
second formulation of the same machine), and ``SolverSettings()`` choosing the method as a
scene's ``method = "auto"`` does.
"""

import math

import numpy as np
import pytest

import crankmodal as cm
from crankmodal.errors import ParameterError

NAN, INF = math.nan, math.inf
R = 0.05  # crank radius of the test machines, m


def cyl(**kw):
    d = {"axis_angle": np.pi / 2, "rod_length": 0.2, "rod_mass": 1.0, "rod_inertia": 0.004,
         "rod_com": 0.06, "piston_mass": 0.8}
    return cm.Cylinder(**{**d, **kw})


def mech(**kw):
    return cm.crank_train(**{"crank_radius": R, "cylinders": [cyl()], "speed_rpm": 1500.0, **kw})


@pytest.fixture(scope="module")
def rigid():
    return mech()


@pytest.fixture(scope="module")
def bar_crank():
    """A flexible crank arm: a 50 mm steel bar (25 x 30 mm) reduced on its two end faces,
    named as a crankshaft's interfaces (``main_journal_1`` at x = 0, ``crankpin_1`` at
    x = 50 mm). Small (a few seconds, no gmsh) and stiff (first in-plane mode ~32 kHz)."""
    from crankmodal.fem.testparts import bar

    part = bar(R, 0.025, 0.03, (5, 3, 3), order=2)
    part.regions["main_journal_1"] = part.regions.pop("end_x0")
    part.regions["crankpin_1"] = part.regions.pop("end_x1")
    model = cm.assemble(part, cm.material("steel"))
    itf = cm.make_interfaces(part, [{"region": "main_journal_1", "kind": "distributing"},
                                    {"region": "crankpin_1", "kind": "distributing"}])
    reduced, _ = cm.reduce_body(model, itf, n_modes=4, name="crank")
    return reduced


FOUR_BAR = {"crank_length": 0.035, "coupler_length": 0.075, "rocker_length": 0.145,
            "rocker_pivot": (-0.008, 0.1598), "masses": (35.8, 2.27, 10.42),
            "inertias": (0.0155, 0.00114, 0.0528), "speed_rpm": 200.0}


def four_bar(**kw):
    return cm.four_bar(**{**FOUR_BAR, **kw})


def torsion_scene():
    return cm.scene_from_dict({"torsion": {"machine": "multi_bearing_compressor"}})


#: (id, call, argument named). ``m`` is a built rigid slider-crank, ``b`` the reduced bar crank.
PROBES = [
    # simulate
    ("simulate-output-step-74-GiB", lambda m, b: cm.simulate(m, 0.01, 1e-12), "output_step"),
    ("simulate-output-step-zero", lambda m, b: cm.simulate(m, 0.01, 0.0), "output_step"),
    ("simulate-output-step-str", lambda m, b: cm.simulate(m, 0.01, "1e-4"), "output_step"),
    ("simulate-output-step-over-t-end", lambda m, b: cm.simulate(m, 0.01, 0.02), "output_step"),
    ("simulate-t-end-nan", lambda m, b: cm.simulate(m, NAN, 1e-4), "t_end"),
    ("simulate-t-end-negative", lambda m, b: cm.simulate(m, -0.01, 1e-4), "t_end"),
    ("simulate-t-end-inf", lambda m, b: cm.simulate(m, INF, 1e-4), "t_end"),
    ("simulate-mech-str", lambda m, b: cm.simulate("mech", 0.01, 1e-4), "mech"),
    ("simulate-settings-str", lambda m, b: cm.simulate(m, 0.01, 1e-4, settings="RK45"),
     "settings"),
    ("simulate-energy-tolerance-negative",
     lambda m, b: cm.simulate(m, 0.01, 1e-4, energy_tolerance=-1.0), "energy_tolerance"),
    ("simulate-start-unknown", lambda m, b: cm.simulate(m, 0.01, 1e-4, start="relaxed"),
     "start"),
    # SolverSettings
    ("settings-method-unknown", lambda m, b: cm.SolverSettings(method="Euler"), "method"),
    ("settings-rtol-zero", lambda m, b: cm.SolverSettings(rtol=0.0), "rtol"),
    ("settings-atol-nan", lambda m, b: cm.SolverSettings(atol=NAN), "atol"),
    ("settings-max-step-negative", lambda m, b: cm.SolverSettings(max_step=-1.0), "max_step"),
    ("settings-max-rhs-evals-zero", lambda m, b: cm.SolverSettings(max_rhs_evals=0),
     "max_rhs_evals"),
    ("settings-max-rhs-evals-float", lambda m, b: cm.SolverSettings(max_rhs_evals=1e5),
     "max_rhs_evals"),
    # crank_train
    ("train-crank-radius-negative", lambda m, b: mech(crank_radius=-0.05), "crank_radius"),
    ("train-crank-radius-nan", lambda m, b: mech(crank_radius=NAN), "crank_radius"),
    ("train-cylinders-empty", lambda m, b: mech(cylinders=[]), "cylinders"),
    ("train-cylinders-dict", lambda m, b: mech(cylinders=[{"rod_length": 0.2}]), "cylinders[0]"),
    ("train-speed-nan", lambda m, b: mech(speed_rpm=NAN), "speed_rpm"),
    ("train-speed-negative", lambda m, b: mech(speed_rpm=-100.0), "speed_rpm"),
    ("train-crank-mass-negative", lambda m, b: mech(crank_mass=-1.0), "crank_mass"),
    ("train-direction-2", lambda m, b: mech(direction=2), "direction"),
    ("train-ramp-time-negative", lambda m, b: mech(ramp_time=-0.1), "ramp_time"),
    ("train-theta0-inf", lambda m, b: mech(theta0=INF), "theta0"),
    ("train-rod-too-short", lambda m, b: mech(cylinders=[cyl(rod_length=0.04)]),
     "cylinders[0].rod_length"),
    ("train-torque-without-inertia", lambda m, b: mech(drive_torque=10.0), "crank_inertia"),
    ("train-clearance-negative",
     lambda m, b: mech(clearances={"main": {"clearance": -1e-4, "journal_radius": 0.02}}),
     "clearances.main.clearance"),
    ("train-clearance-unknown-joint",
     lambda m, b: mech(clearances={"crosshead": {"clearance": 1e-4, "journal_radius": 0.02}}),
     "clearances.crosshead"),
    ("train-clearance-missing-radius", lambda m, b: mech(clearances={"main": {"clearance": 1e-4}}),
     "clearances.main.journal_radius"),
    ("train-clearance-without-stiffness",
     lambda m, b: mech(clearances={"main": {"clearance": 1e-4, "journal_radius": 0.02}}),
     "contact_kw"),
    ("train-crank-body-unknown-frames",
     lambda m, b: mech(crank_body=cm.RigidBody("crank", 1.0, 0.01, {"axis": (0.0, 0.0),
                                                                    "crankpin": (R, 0.0)})),
     "crank_roles"),
    ("train-crank-body-tuple", lambda m, b: mech(crank_body=cm.crank_body(b)), "crank_body"),
    ("train-crank-roles-two-pins",
     lambda m, b: mech(crank_body=cm.crank_body(b)[0],
                       crank_roles={"mains": ["main_1"], "pins": ["pin_1", "pin_1"],
                                    "drive": "drive"}), "crank_roles.pins"),
    ("train-flexible-crank-with-torque",
     lambda m, b: mech(crank_body=cm.crank_body(b)[0], drive_torque=10.0), "drive_torque"),
    ("train-rod-bodies-length", lambda m, b: mech(rod_bodies=[None, None]), "rod_bodies"),
    # Cylinder
    ("cylinder-rod-length-negative", lambda m, b: cyl(rod_length=-0.2), "rod_length"),
    ("cylinder-rod-mass-negative", lambda m, b: cyl(rod_mass=-1.0), "rod_mass"),
    ("cylinder-piston-mass-negative", lambda m, b: cyl(piston_mass=-0.8), "piston_mass"),
    ("cylinder-rod-inertia-nan", lambda m, b: cyl(rod_inertia=NAN), "rod_inertia"),
    ("cylinder-axis-angle-str", lambda m, b: cyl(axis_angle="up"), "axis_angle"),
    ("cylinder-gas-force-number", lambda m, b: cyl(gas_force=3000.0), "gas_force"),
    # four_bar
    ("four-bar-crank-length-negative", lambda m, b: four_bar(crank_length=-0.035),
     "crank_length"),
    ("four-bar-masses-two", lambda m, b: four_bar(masses=(35.8, 2.27)), "masses"),
    ("four-bar-branch-0", lambda m, b: four_bar(branch=0), "branch"),
    ("four-bar-not-assemblable", lambda m, b: four_bar(rocker_pivot=(-0.008, 1.0)),
     "rocker_pivot"),
    # flexible builders
    ("crank-body-damping-2", lambda m, b: cm.crank_body(b, {"damping_ratio": 2.0}),
     "spec.damping_ratio"),
    ("crank-body-n-modes-negative", lambda m, b: cm.crank_body(b, {"n_modes": -1}),
     "spec.n_modes"),
    ("crank-body-spec-unknown-key", lambda m, b: cm.crank_body(b, {"modes": 4}), "spec.modes"),
    ("crank-body-modes-and-cutoff",
     lambda m, b: cm.crank_body(b, {"n_modes": 2, "cutoff_hz": 1e4}), "spec.cutoff_hz"),
    ("crank-body-row-z-nan", lambda m, b: cm.crank_body(b, row_z=[NAN]), "row_z[0]"),
    ("crank-body-source-int", lambda m, b: cm.crank_body(42), "source"),
    ("rod-body-rod-length-negative", lambda m, b: cm.rod_body(b, rod_length=-0.2), "rod_length"),
    # materials
    ("material-E-inf", lambda m, b: cm.Material("x", E=INF, nu=0.3, rho=7850.0), "E"),
    ("material-rho-inf", lambda m, b: cm.Material("x", E=2.1e11, nu=0.3, rho=INF), "rho"),
    ("material-E-str", lambda m, b: cm.Material("x", E="210e9", nu=0.3, rho=7850.0), "E"),
    # torsion
    ("critical-speeds-nan", lambda m, b: cm.critical_speeds([NAN]), "natural_hz[0]"),
    ("critical-speeds-negative", lambda m, b: cm.critical_speeds([-10.0]), "natural_hz[0]"),
    ("critical-speeds-margin-negative",
     lambda m, b: cm.critical_speeds([100.0], required_margin=-0.1), "required_margin"),
    ("critical-speeds-max-order-1e12", lambda m, b: cm.critical_speeds([100.0], max_order=1e12),
     "max_order"),
    ("critical-speeds-max-order-inf", lambda m, b: cm.critical_speeds([100.0], max_order=INF),
     "max_order"),
    ("critical-speeds-range-inf",
     lambda m, b: cm.critical_speeds([100.0], speed_range_rpm=(0.0, INF)), "speed_range_rpm[1]"),
    ("two-rotor-inertia-nan", lambda m, b: cm.two_rotor(NAN, 1.0, 1e5), "inertia_flywheel"),
    ("two-rotor-stiffness-zero", lambda m, b: cm.two_rotor(1.0, 1.0, 0.0), "stiffness"),
    ("holzer-points-1e12",
     lambda m, b: cm.holzer(cm.TorsionalChain([1.0, 2.0], [1e5]), points_per_rotor=10**12),
     "points_per_rotor"),
    ("holzer-chain-str", lambda m, b: cm.holzer("chain"), "chain"),
    ("exact-modes-chain-list", lambda m, b: cm.exact_modes([1.0, 2.0]), "chain"),
    # bodies, laws, the integrator
    ("rigid-body-mass-negative", lambda m, b: cm.RigidBody("b", -1.0, 1.0, {"a": (0.0, 0.0)}),
     "mass"),
    ("rigid-body-inertia-nan", lambda m, b: cm.RigidBody("b", 1.0, NAN, {"a": (0.0, 0.0)}),
     "inertia"),
    ("rigid-body-frame-one-number", lambda m, b: cm.RigidBody("b", 1.0, 1.0, {"a": (0.0,)}),
     "frames.a"),
    ("make-law-unknown", lambda m, b: cm.make_law("hertzian", {}), "name"),
    ("make-law-stiffness-negative",
     lambda m, b: cm.make_law("hertz", {"stiffness": -1e9}), "stiffness"),
    ("make-friction-unknown", lambda m, b: cm.make_friction("viscous", {}), "name"),
    ("integrate-settings-str",
     lambda m, b: cm.integrate(m.system, m.q0, m.qd0, 0.01, None, "RK45"), "settings"),
    ("integrate-q0-short",
     lambda m, b: cm.integrate(m.system, m.q0[:3], m.qd0, 0.01, None, cm.SolverSettings()),
     "q0"),
    ("crank-model-throw-none",
     lambda m, b: cm.crank_model(None, {"diameter": 0.5, "thickness": 0.1}, 8e10, 7850.0),
     "throw"),
    ("crank-model-density-nan",
     lambda m, b: cm.crank_model(cm.load_machine("multi_bearing_compressor")["torsion"]["throw"],
                                 {"diameter": 0.5, "thickness": 0.1}, 8e10, NAN), "density"),
    ("cylinder-from-machine-none", lambda m, b: cm.Cylinder.from_machine(None, None), "machine"),
    # FE and reduction entry points
    ("assemble-part-str", lambda m, b: cm.assemble("rod.step", cm.material("steel")), "part"),
    ("solve-modes-model-str", lambda m, b: cm.solve_modes("model", 6), "model"),
    ("mass-properties-model-none", lambda m, b: cm.mass_properties(None), "model"),
    ("make-interfaces-part-str", lambda m, b: cm.make_interfaces("rod", []), "part"),
    ("select-supports-part-none", lambda m, b: cm.select_supports(None, []), "part"),
    ("save-flexbody-path-none", lambda m, b: cm.save_flexbody(None, b), "path"),
    ("save-flexbody-body-dict", lambda m, b: cm.save_flexbody("x.npz", {}), "body"),
    # scenes
    ("load-scene-none", lambda m, b: cm.load_scene(None), "path"),
    ("scene-from-dict-str", lambda m, b: cm.scene_from_dict("torsion"), "data"),
    ("run-scene-out-dir-none", lambda m, b: cm.run_scene(torsion_scene(), None), "out_dir"),
    ("run-scene-scene-dict", lambda m, b: cm.run_scene({"torsion": {}}, "out"), "scene"),
    ("check-scene-scene-str", lambda m, b: cm.check_scene("scene.toml"), "scene"),
]


def test_at_least_thirty_probes_with_distinct_names():
    assert len(PROBES) >= 30
    assert len({p[0] for p in PROBES}) == len(PROBES)


@pytest.mark.parametrize(("call", "argument"), [p[1:] for p in PROBES],
                         ids=[p[0] for p in PROBES])
def test_bad_argument_raises_parameter_error_naming_it(call, argument, rigid, bar_crank,
                                                       tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ParameterError) as info:
        call(rigid, bar_crank)
    assert info.value.argument == argument, str(info.value)
    assert str(info.value).startswith(f"{argument}: ")
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_the_memory_refusal_says_how_many_samples_and_which_step_fits(rigid):
    with pytest.raises(ParameterError, match=r"makes 1e\+10 output samples .* GB") as info:
        cm.simulate(rigid, 0.01, 1e-12)
    # the step it proposes is accepted (1e7 samples at most, the scene's limit)
    step = float(str(info.value).rsplit(">= ", 1)[1].split()[0])
    assert 0.01 / step <= 1e7 + 1


def test_the_missing_stiffness_message_gives_the_scene_default_from_the_radii():
    from crankmodal.dynamics.laws.contact import cylinder_stiffness

    with pytest.raises(ParameterError) as info:
        mech(clearances={"main": {"clearance": 1e-4, "journal_radius": 0.02}})
    K = cylinder_stiffness(0.02, 0.0201, 2.1e11, 0.3, 2.1e11, 0.3)
    assert f"{K:.3g}" in str(info.value)


def test_critical_speeds_at_the_order_limit_still_work():
    crit = cm.critical_speeds([100.0], max_order=100, speed_range_rpm=(0.0, 6000.0))
    assert len(crit.orders) == 100
    assert crit.in_range()[0]["speed_rpm"] == pytest.approx(60.0, rel=1e-12)  # 60 f / q_max


# ------------------------------------------------------------------ the flexible path (item 4)


def test_crank_body_takes_the_documented_defaults(bar_crank):
    crank, roles = cm.crank_body(bar_crank, {"n_modes": 2})
    assert roles == {"mains": ["main_1"], "pins": ["pin_1"], "drive": "drive"}
    assert crank.n_elastic == 2
    # modal damping 2 % (dynamics.flexible.crank.damping_ratio's default): C = 2 zeta omega,
    # omega from the file's frequencies
    f = crank.frequencies_hz
    assert np.allclose(crank.C / (4.0 * np.pi * f), 0.02, rtol=1e-9, atol=0)
    every, _ = cm.crank_body(bar_crank)  # no spec: every stored in-plane mode
    assert every.n_elastic >= crank.n_elastic


def test_crank_train_without_roles_uses_the_frames_crank_body_names(bar_crank):
    crank, roles = cm.crank_body(bar_crank, {"n_modes": 2}, crank_radius=R)
    given = cm.crank_train(R, [cyl()], 1500.0, crank_body=crank, crank_roles=roles)
    default = cm.crank_train(R, [cyl()], 1500.0, crank_body=crank)
    joints = [(c.name, c.frame_a, c.frame_b) for c in given.ideal.constraints
              if hasattr(c, "frame_b")]
    assert joints == [(c.name, c.frame_a, c.frame_b) for c in default.ideal.constraints
                      if hasattr(c, "frame_b")]
    assert default.main_joints == ["main"]
    # the same assembly: the crankpin where the rigid crank's is (R from the axis along x)
    sl = default.system.slices[id(default.crank)]
    pin = default.crank.frame_pose(default.q0[sl], "pin_1")[:2]
    assert np.allclose(pin, [R, 0.0], atol=1e-9 * R)


def test_solver_settings_default_is_auto_and_simulate_decides_it_as_the_scene_does(bar_crank):
    from crankmodal.dynamics.run.integrate import auto_method
    from crankmodal.dynamics.run.simulate import resolved

    assert cm.SolverSettings().method == "auto"
    rigid = mech()
    assert resolved(None, rigid).method == "RK45"  # rigid, ideal joints
    crank, _ = cm.crank_body(bar_crank, {"n_modes": 2}, crank_radius=R)
    flexible = mech(crank_body=crank)
    assert resolved(None, flexible).method == "Radau"  # flexible on ideal joints
    oiled = mech(clearances={"big_end_1": {"clearance": 5e-5, "journal_radius": 0.02,
                                           "viscosity": 0.02, "bearing_length": 0.02}},
                 contact_kw={"law_params": {"stiffness": 1e9, "damping": 300.0,
                                            "penetration": 1e-4}})
    assert resolved(None, oiled).method == "LSODA"
    # one decision: the scene's solver_settings calls the same function
    assert auto_method([(0.02, "coulomb", 0.01, False)], 1.0, False) == "LSODA"
    assert auto_method([(0.02, "coulomb", 0.01, False)], 157.0, False) == "RK45"
    assert cm.SolverSettings(method="LSODA").method == "LSODA"


def test_simulate_starts_a_flexible_crank_quasi_statically_without_the_start_up_blow(bar_crank):
    """At full speed from rest-free start, the undeformed crank (its springs carrying nothing
    while the 3 kN gas force and the inertia loads act) rings: its main bearing peaks at ~1.9x
    the rigid twin's. The default quasi-static start matches the rigid twin (the same masses,
    modes frozen: a second formulation of this stiff, 32 kHz arm) at t = 0 to 0.1 % and over
    the run to 2 % of its peak (measured 0.02 % and 0.7 %)."""
    crank, _ = cm.crank_body(bar_crank, {"n_modes": 2}, crank_radius=R)
    c = cyl(gas_force=lambda angle: 3000.0)

    def main_force(body, start=None):
        m = cm.crank_train(R, [c], 1500.0, crank_body=body)
        h = cm.simulate(m, 0.002, 1e-5, start=start)
        return np.hypot(*h.main_bearing_force.T), m

    f_rigid, _ = main_force(cm.rigid_twin(crank))
    f_qs, m_qs = main_force(crank)
    f_und, m_und = main_force(crank, start="undeformed")
    assert m_qs.start_info["iterations"] >= 1 and m_qs.start_info["residual"] < 1e-9
    assert m_und.start_info is None
    assert abs(f_qs[0] / f_rigid[0] - 1.0) < 1e-3
    assert np.max(np.abs(f_qs - f_rigid)) < 0.02 * f_rigid.max()
    assert f_und.max() > 1.5 * f_rigid.max()  # what the default start removes


def test_the_mechanism_start_and_a_state_set_by_the_caller_are_respected(bar_crank):
    """What the [dynamics] stage does for ``flexible.start = "undeformed"`` (``mech.start``),
    and a caller's own state (``q0`` changed): no quasi-static solve, the state runs as given;
    a builder's state gets it (its elastic coordinates move off zero: the arm bends)."""
    crank, _ = cm.crank_body(bar_crank, {"n_modes": 2}, crank_radius=R)
    c = cyl(gas_force=lambda angle: 3000.0)
    sl = slice(0, crank.ndof)  # the crank comes first
    undeformed = cm.crank_train(R, [c], 1500.0, crank_body=crank)
    undeformed.start = "undeformed"
    h = cm.simulate(undeformed, 1e-4, 1e-5)
    assert undeformed.start_info is None and np.all(h.modal["crank"][0] == 0.0)
    own = cm.crank_train(R, [c], 1500.0, crank_body=crank)
    own.q0 = own.q0.copy()
    assert own.as_built()
    own.q0[sl.start + 3] = 1e-9  # a struck first mode, m kg^1/2
    assert not own.as_built()
    h = cm.simulate(own, 1e-4, 1e-5)
    # the first sample is the state given (copied, not computed: 1e-12 relative is exact enough)
    assert own.start_info is None and h.modal["crank"][0][0] == pytest.approx(1e-9, rel=1e-12)
    built = cm.crank_train(R, [c], 1500.0, crank_body=crank)
    cm.simulate(built, 1e-4, 1e-5)
    assert built.start_info is not None and np.any(built.q0[sl][3:] != 0.0)
