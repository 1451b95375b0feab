"""The two meanings of "cylinder": a part's cylindrical surface (crankmodal.part) and a
machine's cylinder, whose multibody form (crankmodal.dynamics.Cylinder) is built from the
machine's (crankmodal.mechanism.machine.Cylinder)."""

import math
import pickle

import numpy as np
import pytest

from crankmodal import part
from crankmodal.dynamics.model.bridge import cylinders_from_mechanism
from crankmodal.dynamics.model.mechanisms import Cylinder
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


def _four_star_params():
    from crankmodal.mechanism.stage import validate as validate_mechanism
    from crankmodal.resources import load_machine

    return validate_mechanism(load_machine("four_star_compressor")["mechanism"], None)


def test_the_scene_bridge_builds_the_machine_cylinders_with_their_gas_forces():
    """The bridge's cylinders (built by from_machine) carry the machine's fields, written out
    here, and a gas force that returns the mechanism analysis' gas force at its own angles."""
    from crankmodal.mechanism.analysis import analyse

    mp = _four_star_params()
    src = cylinders_from_mechanism(mp, ring_friction=30.0)
    m = mm.machine_from_params(mp)
    assert len(src["cylinders"]) == len(m.cylinders) == 4
    res = analyse(m, n_per_rev=720)
    for i, (built, c) in enumerate(zip(src["cylinders"], m.cylinders)):
        assert built.axis_angle == np.pi / 2 - c.bank_angle
        assert (built.rod_length, built.rod_mass, built.rod_inertia, built.rod_com) == \
            (m.rod.length, m.rod.mass, m.rod.inertia, m.rod.cg_from_big_end)
        assert (built.piston_mass, built.z, built.offset, built.ring_friction) == \
            (c.piston_mass, c.axial_offset, 0.0, 30.0)
        psi = np.asarray(res.psi[:, i])
        np.testing.assert_allclose([built.gas_force(a) for a in psi],
                                   np.asarray(res.gas_force)[:, i], rtol=1e-12, atol=1e-9)
    assert (src["crank_radius"], src["direction"], src["speed_rpm"]) == \
        (m.crank_radius, -1, m.speed_rpm)


def test_the_scene_bridge_puts_a_cylinder_on_its_own_throw_by_the_machines_arrangement():
    """Multi-throw trains (issue 29): a cylinder at another throw angle gets its own throw
    (it was refused before); the arrangement is the forced torsion's
    (arrangement_of_machine), so both stages read one description."""
    from crankmodal.mechanism.arrangement import arrangement_of_machine

    mp = _four_star_params()
    mp["cylinders"][2]["throw_angle_deg"] = 90.0
    src = cylinders_from_mechanism(mp)
    m = mm.machine_from_params(mp)
    assert src["arrangement"] == arrangement_of_machine(m)  # one throw per cylinder
    assert src["arrangement"].cylinder_throw_angles()[2] == pytest.approx(math.pi / 2)


def test_from_machine_takes_a_cylinder_on_its_own_throw_the_throw_is_the_arrangements():
    rod = mm.Rod(length=0.28, mass=0.9, cg_from_big_end=0.07, inertia=0.0123)
    cyl = mm.Cylinder(0.0, 0.0, math.radians(90.0), 1.7, 0.1)
    built = Cylinder.from_machine(mm.Machine("m", 0.06, rod, 1480.0, (cyl,)), cyl)
    assert built.axis_angle == pytest.approx(math.pi / 2)
