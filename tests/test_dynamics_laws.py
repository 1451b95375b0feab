"""Contact and friction laws as objects (crankmodal.dynamics.laws.objects) against their closed forms,
the pure functions of crankmodal.dynamics.laws.contact, and the registry round trip."""

import numpy as np
import pytest

from crankmodal.dynamics.laws import contact
from crankmodal.dynamics.laws import objects as laws
from crankmodal.dynamics.model.bodies import Ground, RigidBody
from crankmodal.dynamics.model.clearance import ClearanceJoint

DELTA = np.array([-1e-6, 0.0, 1e-7, 3e-6, 2e-5, 8e-5])
RATE = np.array([0.3, -0.2, 0.5, -0.4, 1.2, -2.0])
FULL = {"stiffness": 3e10, "exponent": 1.4, "damping": 450.0, "penetration": 5e-5,
        "restitution": 0.6, "radial_clearance": 1e-4}


@pytest.mark.parametrize("name", contact.NORMAL_LAWS)
def test_each_normal_law_equals_the_dispatch_function(name):
    law = laws.make_law(name, FULL)
    assert type(law) is laws.LAWS[name] and law.name == name
    for v in (0.05, 1.3):
        np.testing.assert_array_equal(law.force(DELTA, RATE, v),
                                      contact.normal_force(name, DELTA, RATE, FULL, v))
    np.testing.assert_array_equal(law.elastic_force(DELTA), contact.elastic_force(name, DELTA, FULL))
    np.testing.assert_allclose(law.elastic_energy(DELTA), contact.elastic_energy(name, DELTA, FULL),
                               rtol=1e-15, atol=0.0)
    assert law.needs_impact_velocity == (name in contact.RESTITUTION_LAWS)


def test_normal_laws_against_closed_forms():
    K, n, c, d, e = 3e10, 1.4, 450.0, 5e-5, 0.6
    x, v, vi = 2e-5, 1.2, 0.8
    s = x / d
    closed = {
        "hertz": K * x**n,
        "kelvin_voigt": K * x + c * v,
        "power_damped": K * x**n + c * v,
        "impact": K * x**n + c * s * s * (3 - 2 * s) * v,
        "hunt_crossley": K * x**n * (1 + 1.5 * (1 - e) / vi * v),
        "lankarani_nikravesh": K * x**n * (1 + 0.75 * (1 - e * e) / vi * v),
        "flores": K * x**n * (1 + 1.6 * (1 - e) / (e * vi) * v),
    }
    for name, f in closed.items():
        assert float(laws.make_law(name, FULL).force(x, v, vi)) == pytest.approx(f, rel=1e-13)
    # the elastic energy is the integral of the elastic force
    for name in contact.NORMAL_LAWS:
        law = laws.make_law(name, FULL)
        xs = np.linspace(0.0, 3e-5, 20001)
        w = np.trapezoid(law.elastic_force(xs), xs)
        assert float(law.elastic_energy(3e-5)) == pytest.approx(w, rel=1e-6)
    # Johnson: the force inverts the approach delta = (F/K)(ln(4 K dR / F) - 1)
    jc = laws.JohnsonCylinder(stiffness=2e9, radial_clearance=1e-4, restitution=0.9)
    F = 3000.0
    delta = float(contact.johnson_cylinder_approach(F, 2e9, 1e-4))
    assert float(jc.elastic_force(delta)) == pytest.approx(F, rel=1e-12)


def test_friction_laws_equal_their_functions_and_closed_forms():
    v = np.array([-1.0, -0.02, -5e-5, 0.0, 5e-5, 3e-3, 0.02, 1.0])
    p = {"mu_static": 0.2, "mu_dynamic": 0.15, "v_static": 1e-4, "v_dynamic": 1e-2}
    for name in contact.FRICTION_LAWS:
        law = laws.make_friction(name, p)
        assert type(law) is laws.FRICTION[name] and law.name == name
        np.testing.assert_array_equal(law.coefficient(v), contact.friction_coefficient(name, v, p))
    assert float(laws.Coulomb(**p).coefficient(0.5)) == pytest.approx(0.15)
    assert float(laws.Coulomb(**p).coefficient(-1e-4)) == pytest.approx(-0.2)
    amb = laws.Ambrosio(mu_dynamic=0.15, v_static=1e-4, v_dynamic=1e-2)
    assert float(amb.coefficient(0.5 * (1e-4 + 1e-2))) == pytest.approx(0.075)
    assert float(laws.NoFriction().coefficient(3.0)) == 0.0


@pytest.mark.parametrize("name", contact.NORMAL_LAWS)
def test_registry_round_trip(name):
    law = laws.make_law(name, FULL)
    again = laws.make_law(law.name, law.params())
    assert again == law and again.params() == law.params()
    # only the law's own parameters are kept
    assert set(law.params()) <= set(FULL)


def test_friction_registry_round_trip():
    p = {"mu_static": 0.2, "mu_dynamic": 0.15, "v_static": 1e-4, "v_dynamic": 1e-2}
    for name in contact.FRICTION_LAWS:
        law = laws.make_friction(name, p)
        assert laws.make_friction(law.name, law.params()) == law


@pytest.mark.parametrize("cls, kw, key", [
    (laws.Hertz, {"stiffness": -1.0}, "stiffness"),
    (laws.Hertz, {"stiffness": 1e10, "exponent": 0.0}, "exponent"),
    (laws.KelvinVoigt, {"stiffness": 1e8, "damping": -3.0}, "damping"),
    (laws.Impact, {"stiffness": 1e10, "damping": 300.0, "penetration": 0.0}, "penetration"),
    (laws.HuntCrossley, {"stiffness": 1e10, "restitution": 1.5}, "restitution"),
    (laws.Flores, {"stiffness": 1e10, "restitution": 0.0}, "restitution"),
    (laws.JohnsonCylinder, {"stiffness": 1e9, "radial_clearance": float("nan"),
                            "restitution": 0.9}, "radial_clearance"),
    (laws.Coulomb, {"mu_static": -0.1, "mu_dynamic": 0.1, "v_static": 1e-4, "v_dynamic": 1e-2},
     "mu_static"),
    (laws.Ambrosio, {"mu_dynamic": 0.1, "v_static": 0.0, "v_dynamic": 1e-2}, "v_static"),
])
def test_constructors_refuse_bad_parameters_by_name(cls, kw, key):
    with pytest.raises(ValueError, match=key):
        cls(**kw)


def test_make_law_names_an_unknown_law_or_a_missing_parameter():
    with pytest.raises(ValueError, match="unknown normal force law 'hertzian'"):
        laws.make_law("hertzian", FULL)
    with pytest.raises(ValueError, match="'penetration'"):
        laws.make_law("impact", {"stiffness": 1e10, "damping": 300.0})
    with pytest.raises(ValueError, match="unknown friction law 'viscous'"):
        laws.make_friction("viscous", {})


def test_clearance_joint_takes_names_or_objects_alike():
    ground = Ground(frames={"bore": (0.0, 0.0)})
    journal = RigidBody("journal", 1.0, 1e-3, {"centre": (0.0, 0.0)})
    fp = {"mu_static": 0.2, "mu_dynamic": 0.15, "v_static": 1e-4, "v_dynamic": 1e-2}
    with pytest.warns(DeprecationWarning, match="law='impact', law_params"):
        by_name = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=1e-4,
                                 journal_radius=0.01, law="impact", law_params=FULL,
                                 friction="coulomb", friction_params=fp)
    obj = laws.Impact(stiffness=3e10, exponent=1.4, damping=450.0, penetration=5e-5)
    by_obj = ClearanceJoint("c", journal, "centre", ground, "bore", clearance=1e-4,
                            journal_radius=0.01, law=obj, friction=laws.Coulomb(**fp))
    assert by_name.law == by_obj.law == obj and by_name.normal == obj
    assert by_name.friction == by_obj.friction == by_obj.friction_law == laws.Coulomb(**fp)
    # the joint keeps the objects only; their names are the law's (results.json's
    # clearance_joints.*.law)
    assert by_obj.law.name == "impact" and by_obj.friction.name == "coulomb"
    assert by_name.law_params is None and by_name.friction_params is None
    assert not by_obj.needs_memory
    assert ClearanceJoint("c", journal, "centre", ground, "bore", clearance=1e-4,
                          journal_radius=0.01, law=laws.Flores(stiffness=1e10,
                                                               restitution=0.5)).needs_memory


# --- what the contact time scales ask of a law (crankmodal.dynamics.run.timescales) ---------------

LOADS = (40.0, 3e3, 1e5)  # N; Johnson's approach is valid below 4 K dR e**-3 = 6e5 N here


@pytest.mark.parametrize("name", contact.NORMAL_LAWS)
def test_static_penetration_carries_the_load_and_the_tangent_stiffness_is_its_slope(name):
    law = laws.make_law(name, FULL)
    for load in LOADS:
        d = law.static_penetration(load)
        assert d > 0.0
        np.testing.assert_allclose(law.elastic_force(d), load, rtol=1e-9)
        h = 1e-5 * d  # central difference of the elastic force
        slope = (law.elastic_force(d + h) - law.elastic_force(d - h)) / (2.0 * h)
        np.testing.assert_allclose(law.tangent_stiffness(load), slope, rtol=1e-6)


@pytest.mark.parametrize("name", contact.NORMAL_LAWS)
def test_the_dashpot_a_law_brings_of_its_own(name):
    law = laws.make_law(name, FULL)
    c, d_max = FULL["damping"], FULL["penetration"]
    for load in LOADS:
        d = law.static_penetration(load)
        s = min(d / d_max, 1.0)
        expected = {"kelvin_voigt": c, "power_damped": c,
                    "impact": c * s * s * (3.0 - 2.0 * s)}.get(name, 0.0)  # STEP's cubic
        assert law.dashpot(load) == pytest.approx(expected, rel=1e-12)
    has = name in ("kelvin_voigt", "power_damped", "impact")
    assert law.dashpot_setting == (c if has else None)
    assert law.dashpot_varies == (name == "impact")


@pytest.mark.parametrize("name", contact.NORMAL_LAWS)
def test_stiffness_for_tangent_gives_that_tangent_stiffness_at_the_same_load(name):
    law = laws.make_law(name, FULL)
    load = 3e3
    k_lin = law.tangent_stiffness(load)
    for factor in (0.1, 0.5, 20.0):
        K = law.stiffness_for_tangent(factor * k_lin, k_lin)
        again = laws.make_law(name, {**FULL, "stiffness": K}).tangent_stiffness(load)
        if law.tangent_scales_exactly:
            assert again == pytest.approx(factor * k_lin, rel=1e-10)
        else:  # johnson_cylinder: K_lin ~ K over a logarithm of F / K
            assert name == "johnson_cylinder"
            assert 0.5 * factor * k_lin < again < 2.0 * factor * k_lin
