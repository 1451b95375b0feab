"""The fatigue verdict on FE stress: a round shaft in alternating torsion against the closed
form, and built cranks (gmsh, P2) whose worst point is at a fillet; the fillet and oil-hole
classification against the geometry's own torus and bore surfaces."""

import math

import numpy as np
import pytest
from fem_parts import gmsh_rod

from crankmodal.fatigue import (
    FatigueFactors,
    FatigueResult,
    crank_locations,
    fatigue_verdict,
    surface_nodes,
)
from crankmodal.fem import assembly, static, supports
from crankmodal.fem.loads import Load
from crankmodal.fem.materials import material
from crankmodal.geometry import CrankshaftParams, MeshSettings, build_part
from crankmodal.geometry.crankshaft import layout
from crankmodal.reduction.stress_modes import stress_modes, stress_recovery

STEEL = material("42CrMo")
CYCLE = np.sin(np.linspace(0.0, 2 * np.pi, 73))[None, :]  # pure alternating, no mean
#: a small one-throw crank (52k DOF at 12 mm, P2): fillets 2 mm, free-end stub 40 mm
CRANK = {"phases_deg": (0.0,), "throw_radius": 0.035, "journal_diameter": 0.05,
         "journal_length": 0.04, "pin_diameter": 0.04, "pin_length": 0.04,
         "web_thickness": 0.016, "web_width": 0.07, "journal_fillet": 0.002,
         "pin_fillet": 0.002, "free_end_diameter": 0.04, "free_end_length": 0.06}


def _unit_stress(part, load, fixed):
    """Stress modes (n_points, 6, 1) of a static solve: the stress per unit load factor."""
    model = assembly.assemble(part, STEEL)
    sup = supports.select(part, fixed, "static")
    u = static.solve_static(model, part.mesh, load, sup).displacement.reshape(-1)
    return model.points, stress_modes(stress_recovery(model, part.mesh), u[:, None])


@pytest.fixture(scope="module")
def crank_in_torsion():
    """The crank without oil holes, clamped at its free end, a torque of 1 kN m at the other."""
    part = build_part(CrankshaftParams(**CRANK), "full", MeshSettings(0.012, 2))
    load = Load.remote(part, "flywheel_end_face", force=[0, 0, 0], moment=[0, 0, 1000.0])
    points, S = _unit_stress(part, load, [{"region": "free_end_face", "fix": "xyz"}])
    return part, points, S


@pytest.fixture(scope="module")
def crank_with_oil_hole():
    part = build_part(CrankshaftParams(**CRANK, oil_hole_diameter=0.005), "full",
                      MeshSettings(0.012, 2))
    return part


def test_round_shaft_fe_torsion_gives_the_closed_form_safety_factor_within_2_percent(
        oracle, tmp_path):
    """tau = 16 T / (pi d^3) at the surface; n = (S_f / sqrt(3)) k / tau. The FE surface stress
    (P2, 8 mm elements on a 40 mm shaft, nodal averaging) scatters node by node by -1.6/+1.0 %
    about it (-0.6/+0.3 % at 5 mm): the verdict's minimum is held to 2 %, the median to 0.2 %."""
    L, R, T = 0.2, 0.02, 500.0
    part = gmsh_rod(L, R, 0.008, 2, tmp_path)
    load = Load.remote(part, "end_x1", force=[0, 0, 0], moment=[T, 0, 0])
    x, S = _unit_stress(part, load, [{"region": "end_x0", "fix": "xyz"}])
    mid = np.flatnonzero((np.abs(np.hypot(x[:, 1], x[:, 2]) - R) < 1e-6 * R)
                         & (x[:, 0] > 0.3 * L) & (x[:, 0] < 0.7 * L))  # Saint-Venant: ends away
    f = FatigueFactors(surface=0.85, size=0.87, reliability=0.897)
    res = fatigue_verdict(S, CYCLE, STEEL, x, nodes=mid, factors=f)
    tau = 16.0 * T / (math.pi * (2 * R) ** 3)
    expected = 0.85 * 0.87 * 0.897 * STEEL.fatigue_strength / math.sqrt(3.0) / tau
    oracle(stage="fem", quantity="fatigue safety factor, round shaft in alternating torsion, "
           "FE surface (min over mid-length nodes)", reference="tau = 16 T / (pi d^3), closed form",
           tolerance="2 %", measured=res.min_safety_factor, expected=expected)
    assert res.min_safety_factor == pytest.approx(expected, rel=0.02)
    assert np.median(res.safety_factor) == pytest.approx(expected, rel=0.002)


def test_crank_in_alternating_torsion_plain_section_matches_closed_form_and_worst_is_a_fillet(
        oracle, crank_in_torsion):
    """Issue 29's fatigue oracle: under a pure alternating torque the free-end stub (a plain
    40 mm shaft section) gives the closed-form safety factor (P2 at 12 mm: nodes within
    -1.1/+0.7 %, held to 2 %); the worst location is a fillet, and no other surface point is
    worse."""
    part, x, S = crank_in_torsion
    surf = surface_nodes(part.mesh.cells[0].data)
    locs = crank_locations(x, surf, part)
    res = fatigue_verdict(S, CYCLE, STEEL, x, nodes=surf, locations=locs)
    xs = x[surf]
    stub = (np.abs(np.hypot(xs[:, 0], xs[:, 1]) - 0.02) < 1e-7) & (xs[:, 2] > 0.02) & (xs[:, 2] < 0.04)
    tau = 16.0 * 1000.0 / (math.pi * 0.04 ** 3)
    expected = STEEL.fatigue_strength / math.sqrt(3.0) / tau
    section = float(np.median(res.safety_factor[stub]))
    oracle(stage="fem", quantity="fatigue safety factor in the crank's plain stub, alternating "
           "torque", reference="tau = 16 T / (pi d^3), closed form", tolerance="2 % (every node)",
           measured=section, expected=expected)
    np.testing.assert_allclose(res.safety_factor[stub], expected, rtol=0.02)
    summary = res.to_dict()
    worst = summary["worst_location"]
    assert "fillet" in worst and summary["locations"][worst]["kind"].endswith("fillet")
    assert summary["locations"]["elsewhere"]["safety_factor"] > summary["min_safety_factor"]
    assert summary["min_safety_factor"] == summary["worst_location_safety_factor"]


def test_fillet_and_oil_hole_classification_covers_the_geometry_surfaces(crank_with_oil_hole):
    """Every surface node on a fillet's torus (the geometry's rolling-ball surface) carries
    that fillet's label; every node on the radial drilling's bore, that oil hole's."""
    part = crank_with_oil_hole
    p = CrankshaftParams(**CRANK, oil_hole_diameter=0.005)
    x = part.mesh.points
    surf = surface_nodes(part.mesh.cells[0].data)
    locs = crank_locations(x, surf, part)
    lab = {n: locs.label == k for k, n in enumerate(locs.names)}
    xs = x[surf]
    lay = layout(p)
    (z0, z1, _), = lay.pins
    f, rp, rj, r = 0.002, 0.02, 0.025, 0.035
    rho_p, rho_j = np.hypot(xs[:, 0] - r, xs[:, 1]), np.hypot(xs[:, 0], xs[:, 1])
    tori = {  # (radial distance, fillet centre (rho, z), name)
        "crankpin_1_fillet_web_1": (rho_p, rp + f, z0 + f),
        "crankpin_1_fillet_web_2": (rho_p, rp + f, z1 - f),
        "main_journal_1_fillet_web_1": (rho_j, rj + f, z0 - p.web_thickness - f),
        "main_journal_2_fillet_web_2": (rho_j, rj + f, z1 + p.web_thickness + f),
    }
    for name, (rho, rc, zc) in tori.items():
        on = (np.abs(np.hypot(rho - rc, xs[:, 2] - zc) - f) < 2e-5) & (rho < rc) \
             & (np.abs(xs[:, 2] - zc) < f)
        assert on.sum() >= 20, name
        assert np.all(lab[name][on]), name
    zc, ro = 0.5 * (z0 + z1), 0.0025
    bore = (np.abs(np.hypot(xs[:, 1], xs[:, 2] - zc) - ro) < 2e-5) & (xs[:, 0] > r + 0.5 * rp)
    assert bore.sum() >= 10 and np.all(lab["crankpin_1_oil_hole_row_1"][bore])


def test_crank_under_a_tangential_pin_load_reports_a_fillet_and_draws_its_figures(
        crank_with_oil_hole, tmp_path):
    """A tangential crankpin force (the torque-producing gas-force component), the crank clamped
    at its free end and held radially at its second journal: the worst point is at a fillet
    (the pin bends in the plane of the force), not at the oil hole (on the pin's neutral
    plane of that bending)."""
    part = crank_with_oil_hole
    load = Load.bearing(part, "crankpin_1_row_1", force=[0.0, 1e4, 0.0])
    x, S = _unit_stress(part, load, [{"region": "free_end_face", "fix": "xyz"},
                                     {"region": "main_journal_2", "fix": "radial"}])
    cells = part.mesh.cells[0].data
    surf = surface_nodes(cells)
    res = fatigue_verdict(S, CYCLE, STEEL, x, nodes=surf, locations=crank_locations(x, surf, part))
    locs = res.locations()
    assert locs[res.worst_location]["kind"].endswith("fillet")
    assert locs["crankpin_1_oil_hole_row_1"]["safety_factor"] > res.min_safety_factor
    assert res.min_safety_factor == locs[res.worst_location]["safety_factor"]
    png = res.plot_crank(x, cells, tmp_path / "crank.png")
    bars = res.plot_safety(tmp_path / "safety.png")
    assert png.stat().st_size > 20_000 and bars.stat().st_size > 20_000
    back = FatigueResult.load(res.save(tmp_path / "crank_fatigue.npz"))
    assert back.worst_location == res.worst_location


@pytest.mark.slow
def test_seed004_crank_under_a_pulsating_gas_force_is_worst_at_a_fillet(tmp_path):
    """Seed 004's crank (SG 700/2, full fidelity, 5 mm fillets; 110k DOF at 30 mm, ~1 min) on its
    three main journals, its free-end stub held (the motor coupling), a pulsating 0-50 kN gas
    force on crankpin 1 (mean = amplitude, so Goodman's mean term counts): the worst location is
    a fillet (measured: main journal 2 at web 2, n = 13.5; the plain surface's worst 21.3)."""
    import tomllib

    from conftest import REPO

    from crankmodal.geometry.params import params_from_dict

    with open(REPO / "geometry" / "multi_bearing_compressor.toml", "rb") as fh:
        p = params_from_dict("crankshaft", tomllib.load(fh)["crankshaft"])
    part = build_part(p, "full", MeshSettings(0.03, 2))
    mat = material("SG 700/2")
    model = assembly.assemble(part, mat)
    sup = supports.select(part, [{"region": f"main_journal_{k}", "fix": "radial"}
                                 for k in (1, 2, 3)] + [{"region": "free_end_stub", "fix": "xyz"}],
                          "static")
    u = static.solve_static(model, part.mesh, Load.bearing(part, "crankpin_1_row_1",
                                                           force=[-5e4, 0, 0]), sup)
    S = stress_modes(stress_recovery(model, part.mesh), u.displacement.reshape(-1)[:, None])
    surf = surface_nodes(part.mesh.cells[0].data)
    res = fatigue_verdict(S, 0.5 + 0.5 * CYCLE, mat, model.points, nodes=surf,
                          locations=crank_locations(model.points, surf, part))
    locs = res.locations()
    assert locs[res.worst_location]["kind"].endswith("fillet")
    assert locs["elsewhere"]["safety_factor"] > res.min_safety_factor
    assert locs[res.worst_location]["mean_pa"] > 0.1 * locs[res.worst_location]["alternating_pa"]
    res.plot_crank(model.points, part.mesh.cells[0].data, tmp_path / "seed004.png")
