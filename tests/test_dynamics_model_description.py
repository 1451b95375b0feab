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
