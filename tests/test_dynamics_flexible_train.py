"""Flexible crank and rods in the four-star crank train, against oracles: frozen modes give the
rigid crank (one main joint) to 1e-9, the energy balance counts strain energy, clearance at a
flexible interface runs with the usual contact checks, and bad input is refused by key."""

from types import SimpleNamespace

import numpy as np
import pytest

from crankmodal.dynamics import flexbuild
from crankmodal.dynamics.analysis import simulate
from crankmodal.dynamics.bodies import RigidBody
from crankmodal.dynamics.bridge import cylinders_from_mechanism
from crankmodal.dynamics.mechanisms import crank_train
from crankmodal.dynamics.simulate import SolverSettings

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
    settings = SolverSettings(rtol=1e-11, atol=1e-14)
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
                 SolverSettings(rtol=1e-9, atol=1e-12))
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
    h = simulate(mech, 0.02, 5e-5, SolverSettings(rtol=1e-6, atol=1e-9))
    assert len(h.onsets["big_end_1"]) >= 1
    assert h.contact["big_end_1"]["penetration"].max() > 0
    assert h.energy_error() < 1e-3


def test_interfaces_at_the_wrong_places_are_refused(parts, tmp_path):
    from crankmodal.errors import SceneError

    with pytest.raises(SceneError, match="crank radius is 0.05"):
        flexbuild.crank_body(parts.crank, SPEC_CRANK, parts.rows, 0.05)
    with pytest.raises(SceneError, match="rod length is 0.3 m"):
        flexbuild.rod_body(parts.rod, SPEC_ROD, 0.3, "rod_1")
    with pytest.raises(SceneError, match="needs main_journal_"):
        flexbuild.crank_body(parts.rod, SPEC_CRANK, parts.rows, parts.radius)
