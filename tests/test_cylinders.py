"""The two meanings of "cylinder": a part's cylindrical surface (crankmodal.part) and a
machine's cylinder, whose multibody form (crankmodal.dynamics.Cylinder) is built from the
machine's (crankmodal.mechanism.machine.Cylinder)."""

import dataclasses
import math
import pickle

import numpy as np
import pytest

from crankmodal import part
from crankmodal.dynamics.bridge import cylinders_from_mechanism
from crankmodal.dynamics.mechanisms import Cylinder
from crankmodal.errors import ParameterError
from crankmodal.mechanism import machine as mm


def _surface():
    return part.CylindricalSurface(np.array([0.0, 0.0, 0.1]), np.array([0.0, 0.0, 1.0]), 0.03, 0.2)


def test_the_old_name_of_the_cylindrical_surface_is_an_alias_and_old_pickles_load():
    assert part.Cylinder is part.CylindricalSurface
    # a part pickled (geometry cache) before the rename names the class crankmodal.part.Cylinder
    old = pickle.dumps(_surface(), protocol=2).replace(b"\nCylindricalSurface\n", b"\nCylinder\n")
    assert b"\nCylinder\n" in old
    back = pickle.loads(old)
    assert isinstance(back, part.CylindricalSurface) and back.to_dict() == _surface().to_dict()
    region = part.Region("bore", np.zeros((0, 3), int), np.zeros(0, int), cylinder=_surface())
    assert pickle.loads(pickle.dumps(region)).cylinder.to_dict() == _surface().to_dict()


@pytest.mark.parametrize("bank_deg", [0.0, 30.0, 90.0, -45.0, 135.0, 225.0])
def test_from_machine_points_the_axis_where_the_machine_does(bank_deg):
    """The mechanism's unit axis (sin phi, cos phi) (angle from +y towards +x) is the dynamics'
    (cos a, sin a) (angle from +x counter-clockwise)."""
    rod = mm.Rod(length=0.28, mass=0.9, cg_from_big_end=0.07, inertia=0.0123)
    cyl = mm.Cylinder(math.radians(bank_deg), 0.05, 0.0, 1.7, 0.1)
    m = mm.Machine("m", 0.06, rod, 1480.0, (cyl,))
    dyn = Cylinder.from_machine(m, cyl, ring_friction=12.0)
    phi = cyl.bank_angle
    np.testing.assert_allclose([math.cos(dyn.axis_angle), math.sin(dyn.axis_angle)],
                               [math.sin(phi), math.cos(phi)], atol=1e-15)
    assert (dyn.rod_length, dyn.rod_mass, dyn.rod_inertia, dyn.rod_com) == (0.28, 0.9, 0.0123, 0.07)
    assert (dyn.piston_mass, dyn.z, dyn.offset, dyn.ring_friction) == (1.7, 0.05, 0.0, 12.0)


def test_from_machine_gives_the_cylinders_the_scene_bridge_builds():
    from crankmodal.mechanism.stage import validate as validate_mechanism
    from crankmodal.resources import load_machine

    mp = validate_mechanism(load_machine("four_star_compressor")["mechanism"], None)
    src = cylinders_from_mechanism(mp, ring_friction=30.0)
    m = mm.machine_from_params(mp)
    assert len(src["cylinders"]) == len(m.cylinders) == 4
    for built, c in zip(src["cylinders"], m.cylinders):
        assert built.gas_force is not None
        assert dataclasses.asdict(Cylinder.from_machine(m, c, built.gas_force, 30.0)) == \
            dataclasses.asdict(built)


def test_from_machine_refuses_a_cylinder_on_its_own_throw_naming_the_field():
    rod = mm.Rod(length=0.28, mass=0.9, cg_from_big_end=0.07, inertia=0.0123)
    cyl = mm.Cylinder(0.0, 0.0, math.radians(90.0), 1.7, 0.1)
    with pytest.raises(ParameterError, match=r"^cylinder.throw_angle: cylinders on separate "):
        Cylinder.from_machine(mm.Machine("m", 0.06, rod, 1480.0, (cyl,)), cyl)
