"""The typed model description (issue 27 item 1): clearance specs and law objects in the core,
scene keys only in the stage.

Oracles: the admissible ranges are those written in the fields' rules (a bad value names the
argument, not a scene key); the name form of the laws builds the same law object as the typed
form (dataclass equality of the parameters) and the same kernel tables.
"""

import pytest

from crankmodal.dynamics.laws.objects import Coulomb, Impact, NoFriction
from crankmodal.dynamics.model.clearance import ClearanceSpec
from crankmodal.errors import ParameterError

LAW = Impact(stiffness=1e10, damping=300.0, penetration=1e-4)


def test_clearance_spec_defaults_are_a_dry_round_frictionless_bore():
    spec = ClearanceSpec(1e-4, 0.02, LAW)
    assert spec.friction == NoFriction()
    assert spec.clearance_major is None and spec.viscosity is None
    assert spec.bearing_length is None and spec.film_model == "short"


@pytest.mark.parametrize("bad, argument", [
    ({"clearance": -1e-4}, "clearance"),
    ({"clearance": 0.02}, "clearance"),
    ({"journal_radius": float("nan")}, "journal_radius"),
    ({"clearance_major": 5e-5}, "clearance_major"),
    ({"viscosity": 0.01}, "bearing_length"),
    ({"viscosity": 0.01, "bearing_length": 0.02, "clearance_major": 2e-4}, "viscosity"),
    ({"film_model": "long"}, "film_model"),
    ({"normal": "impact"}, "normal"),
    ({"friction": {"mu_static": 0.1}}, "friction"),
    ({"v_impact_min": 0.0}, "v_impact_min"),
])
def test_clearance_spec_refuses_naming_the_field(bad, argument):
    kw = {"clearance": 1e-4, "journal_radius": 0.02, "normal": LAW}
    kw.update(bad)
    with pytest.raises(ParameterError) as err:
        ClearanceSpec(**kw)
    assert err.value.argument == argument
    assert "dynamics" not in str(err.value)  # the core never words a scene key


def test_clearance_spec_makes_the_joint_it_describes():
    from crankmodal.dynamics.model.bodies import Ground, RigidBody

    fr = Coulomb(mu_static=0.1, mu_dynamic=0.08, v_static=1e-4, v_dynamic=1e-2)
    spec = ClearanceSpec(1e-4, 0.02, LAW, fr, clearance_major=1.5e-4, wear_angle=0.3)
    g = Ground(frames={"o": (0.0, 0.0)})
    b = RigidBody("b", 1.0, 1e-3, frames={"p": (0.0, 0.0)})
    cj = spec.joint("pin", b, "p", g, "o")
    assert cj.normal is LAW and cj.friction_law is fr
    assert (cj.clearance, cj.clearance_major, cj.wear_angle) == (1e-4, 1.5e-4, 0.3)


# --- the core names its arguments; the stage relabels them with scene keys ---------------------

@pytest.mark.parametrize("make, argument", [
    (lambda: Impact(stiffness=-1e10, damping=300.0, penetration=1e-4), "stiffness"),
    (lambda: Coulomb(mu_static=0.1, mu_dynamic=0.08, v_static=1e-2, v_dynamic=1e-4),
     "v_dynamic"),
])
def test_a_bad_law_parameter_names_the_argument_not_a_scene_key(make, argument):
    with pytest.raises(ParameterError) as err:
        make()
    assert err.value.argument == argument and "dynamics" not in str(err.value)


def test_a_bad_law_parameter_by_name_names_the_argument():
    from crankmodal.dynamics.model.bodies import Ground, RigidBody
    from crankmodal.dynamics.model.clearance import ClearanceJoint

    g = Ground(frames={"o": (0.0, 0.0)})
    b = RigidBody("b", 1.0, 1e-3, frames={"p": (0.0, 0.0)})
    with pytest.raises(ParameterError) as err:  # refused before the deprecation warning
        ClearanceJoint("c", b, "p", g, "o", 1e-4, 0.02, law="impact",
                       law_params={"stiffness": 1e10, "damping": -3.0, "penetration": 1e-4})
    assert err.value.argument == "damping" and "dynamics" not in str(err.value)
    with pytest.raises(ParameterError) as err:
        ClearanceJoint("c", b, "p", g, "o", 1e-4, 0.02)
    assert err.value.argument == "law"
    # the joint checks its geometry by ClearanceSpec's rules
    for kw, argument in (({"clearance": -1e-4}, "clearance"), ({"journal_radius": 0.0},
                                                               "journal_radius"),
                         ({"film_model": "long"}, "film_model")):
        args = dict({"clearance": 1e-4, "journal_radius": 0.02}, **kw)
        with pytest.raises(ParameterError) as err:
            ClearanceJoint("c", b, "p", g, "o", law=LAW, **args)
        assert err.value.argument == argument


SCENE = """
[dynamics]
mechanism = "slider_crank"
speed_rpm = 3000.0
end_time = 0.01
[dynamics.crank_train]
crank_radius = 0.035
rod_length = 0.14
[[dynamics.clearances]]
joint = "big_end_1"
clearance = 1e-4
journal_radius = 0.02
{clearance}
[dynamics.contact]
law = "lankarani_nikravesh"
stiffness = 1e10
[dynamics.friction]
law = "coulomb"
{friction}
"""


@pytest.mark.parametrize("clearance, friction, message", [
    ("", "v_static = 1e-2\nv_dynamic = 1e-4",
     "dynamics.friction.v_dynamic: must be > v_static (0.01 m/s), got 0.0001"),
    ("clearance_major = 5e-5", "",
     "dynamics.clearances[0].clearance_major: must be >= clearance (0.0001 m), got 5e-05"),
    ("viscosity = 0.01", "",
     "dynamics.clearances[0].bearing_length: is required with viscosity"),
])
def test_the_cli_relabels_the_cores_refusal_with_the_scene_key(tmp_path, clearance, friction,
                                                               message):
    from conftest import run_in_process

    scene = tmp_path / "s.toml"
    scene.write_text(SCENE.format(clearance=clearance, friction=friction))
    status, err = run_in_process("run", scene, "--out", tmp_path / "out")
    assert status == 2
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out" / "results.json").exists()


# --- the deprecated name form: a warning and the same system -----------------------------------

def _train(clearances, contact_kw=None):
    from crankmodal.dynamics.model.mechanisms import Cylinder, crank_train

    cyl = Cylinder(axis_angle=0.0, rod_length=0.14, rod_mass=0.9, rod_inertia=3e-3,
                   rod_com=0.04, piston_mass=1.2)
    return crank_train(0.035, [cyl], 3000.0, crank_inertia=0.05, clearances=clearances,
                       contact_kw=contact_kw)


def test_the_name_form_warns_and_builds_the_same_kernel_tables():
    import numpy as np

    from crankmodal.dynamics.kernel.compiled import CompiledSystem

    law = {"stiffness": 3e10, "exponent": 1.4, "damping": 450.0, "penetration": 5e-5}
    fr = {"mu_static": 0.2, "mu_dynamic": 0.15, "v_static": 1e-4, "v_dynamic": 1e-2}
    geometry = {"clearance": 1e-4, "journal_radius": 0.02}
    with pytest.warns(DeprecationWarning, match="deprecated"):
        by_name = _train({"big_end_1": geometry},
                         {"law": "impact", "law_params": law, "friction": "coulomb",
                          "friction_params": fr})
    typed = {"big_end_1": ClearanceSpec(**geometry, normal=Impact(**law), friction=Coulomb(**fr))}
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        by_object = _train(typed)
    a, b = CompiledSystem(by_name.system), CompiledSystem(by_object.system)
    # the tables hold the same input numbers copied (no arithmetic on them): equal exactly
    assert np.array_equal(a.I, b.I) and np.array_equal(a.io, b.io)
    assert np.array_equal(a.F, b.F) and np.array_equal(a.fo, b.fo)
    assert by_name.system.clearances[0].law == Impact(**law)


# --- one name per meaning: n_coordinates, fixed_interface_modes ---------------------------------

def test_reduce_body_fixed_interface_modes_and_its_deprecated_name():
    """The old keyword gives the same reduced body (same basis size and frequencies) and warns;
    the argument's errors name fixed_interface_modes."""
    import numpy as np

    from crankmodal.dynamics.flexible.body import planar_body
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import Material
    from crankmodal.fem.testparts import bar
    from crankmodal.reduction.interfaces import make_interfaces
    from crankmodal.reduction.reduce import reduce_body

    part = bar(0.5, 0.03, 0.02, (10, 2, 1), order=2)
    model = assemble(part, Material("steel", 2.1e11, 0.3, 7850.0))
    itf = make_interfaces(part, [{"region": "end_x0", "kind": "rigid"},
                                 {"region": "end_x1", "kind": "rigid"}])
    body, _ = reduce_body(model, itf, fixed_interface_modes=4, name="bar", stress=False)
    with pytest.warns(DeprecationWarning, match="fixed_interface_modes"):
        old, _ = reduce_body(model, itf, n_modes=4, name="bar", stress=False)
    assert body.n_modes == old.n_modes == 12 + 4  # 2 interfaces x 6 + 4 fixed-interface
    np.testing.assert_allclose(old.frequencies_hz, body.frequencies_hz, rtol=1e-12)
    with pytest.raises(ParameterError) as err:
        reduce_body(model, itf, fixed_interface_modes=10**6, name="bar", stress=False)
    assert err.value.argument == "fixed_interface_modes"
    flex = planar_body(body, "bar", n_modes=3)
    assert flex.n_elastic == 3 and flex.n_coordinates == 3 + flex.n_tilt
    with pytest.warns(DeprecationWarning, match="n_coordinates"):
        assert flex.n_modes == flex.n_coordinates


# --- the solver's rules live in the core; the scene keys share them ------------------------------

def test_solver_settings_import_no_scene_module():
    import subprocess
    import sys

    code = ("import sys\n"
            "from crankmodal.dynamics.run.integrate import SolverSettings\n"
            "SolverSettings(method='RK45', rtol=1e-8, atol=1e-12, max_rhs_evals=10)\n"
            "bad = [m for m in sys.modules if m.startswith('crankmodal.dynamics.scene')]\n"
            "assert not bad, bad\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, check=False)
    assert out.returncode == 0, out.stderr[-1500:]


@pytest.mark.parametrize("field, value", [("rtol", 1.0), ("method", "Euler"), ("atol", 0.0),
                                          ("max_rhs_evals", 0)])
def test_solver_settings_and_the_scene_refuse_the_same_values(field, value):
    from crankmodal.dynamics.run.integrate import SolverSettings
    from crankmodal.dynamics.scene.keys import validate_section
    from crankmodal.errors import SceneError

    with pytest.raises(ParameterError) as err:
        SolverSettings(**{field: value})
    assert err.value.argument == field
    with pytest.raises(SceneError, match=rf"^dynamics\.solver\.{field}: {err.value.text[:12]}"):
        validate_section({"speed_rpm": 3000.0, "solver": {field: value}})


# --- advice: the core names its arguments, the stage the scene keys -----------------------------

SOFT = """
[dynamics]
mechanism = "slider_crank"
speed_rpm = 1480.0
end_time = 0.01
output_step = 1e-4
run_ideal = false
gas_force_deg = [0.0, 180.0, 360.0]
gas_force_n = [3500.0, 500.0, 3500.0]
[dynamics.crank_train]
crank_radius = 0.035
rod_length = 0.14
crank_mass = 2.0
crank_inertia = 0.01
[[dynamics.clearances]]
joint = "big_end_1"
clearance = 1e-4
journal_radius = 0.02
[dynamics.contact]
law = "lankarani_nikravesh"
stiffness = 1e5
restitution = 0.5
[dynamics.solver]
method = "LSODA"
"""


def test_a_too_soft_contact_names_the_argument_in_the_core_and_the_key_in_a_scene(tmp_path):
    from conftest import run_in_process

    from crankmodal.dynamics.scene.build import relabel

    # the stage's mapping: whole words only, the key in full
    assert relabel("law.stiffness = 1e+05 is too low; tighten settings.rtol") == \
        "contact.stiffness = 1e+05 is too low; tighten solver.rtol"
    assert relabel("my_law.stiffness, law.stiffness_x") == "my_law.stiffness, law.stiffness_x"
    scene = tmp_path / "soft.toml"
    scene.write_text(SOFT)
    status, err = run_in_process("run", scene, "--out", tmp_path / "out")
    assert status == 3
    assert "contact.stiffness = 1e+05 is too low" in err and "law." not in err
    assert not (tmp_path / "out" / "results.json").exists()


def test_the_penetration_warning_names_the_law_argument_by_default():
    from types import SimpleNamespace

    from crankmodal.dynamics.results.validity import penetration_warning
    from crankmodal.dynamics.scene.build import CONTACT_WORDS

    cj = SimpleNamespace(name="big_end_1", clearance=1e-4, journal_radius=0.02,
                         bearing_length=0.02, law=Impact(stiffness=1e9, damping=300.0,
                                                         penetration=1e-4))
    api = penetration_warning(cj, 1e-4, 1e4)  # 100 % of the clearance
    assert "raise law.stiffness (now 1e+09)" in api and "dynamics." not in api
    scene = penetration_warning(cj, 1e-4, 1e4, words=CONTACT_WORDS)
    assert "raise dynamics.contact.stiffness (now 1e+09)" in scene
    assert "dynamics.contact.law = 'johnson_cylinder'" in scene
