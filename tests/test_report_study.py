"""Simplification study: Pareto front and recommendation (hand-checked), a tiny bar study whose
Richardson reference is checked against Timoshenko theory, and the written table and plots."""

import csv

import numpy as np
import pytest

from crankmodal.report.study import (
    evaluate,
    pareto_front,
    recommend,
    run_models,
    write_study,
)

# (cost s, error) hand-checked: C is beaten by B, E by D, G duplicates B (the first one is kept)
POINTS = {"A": (1.0, 0.10), "B": (2.0, 0.05), "C": (3.0, 0.06), "D": (4.0, 0.01),
          "E": (4.0, 0.02), "F": (0.5, 0.20), "G": (2.0, 0.05)}


def test_pareto_front_of_hand_checked_points_by_increasing_cost():
    names = list(POINTS)
    cost, err = np.array(list(POINTS.values())).T
    assert [names[i] for i in pareto_front(cost, err)] == ["F", "A", "B", "D"]


@pytest.mark.parametrize("tol, expected", [(0.05, "B"), (0.099, "B"), (0.1, "A"), (0.5, "F"),
                                           (0.01, "D"), (0.009, None)])
def test_recommendation_is_the_cheapest_point_within_tolerance(tol, expected):
    names = list(POINTS)
    cost, err = np.array(list(POINTS.values())).T
    k = recommend(cost, err, tol)
    assert (None if k is None else names[k]) == expected
    if k is not None:
        assert k in pareto_front(cost, err)


# A bar stands in for the crankshaft: "dechamfered" is 1 % thicker, "simplified" 5 % thinner, so
# the flat bending frequency (∝ thickness) moves by about +1 % and -5 %.
L, B, H = 0.24, 0.024, 0.012
THICKNESS = {"full": H, "dechamfered": 1.01 * H, "simplified": 0.95 * H}


def build_bar(fidelity, h, order):
    from crankmodal.fem import testparts

    t = THICKNESS[fidelity]
    part = testparts.bar(L, B, t, divisions=(round(L / h), max(1, round(B / h)),
                                             max(1, round(t / h))), order=order)
    part.fidelity = fidelity
    return part


def solve(part):
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material
    from crankmodal.fem.modal import solve_modes

    return solve_modes(assemble(part, material("steel")), 3)


@pytest.fixture(scope="module")
def bar_runs():
    return run_models(build_bar, solve, ["full", "dechamfered", "simplified"], [0.012, 0.006],
                      [1, 2])


def test_study_table_has_every_fidelity_size_and_order(bar_runs):
    keys = {(r["fidelity"], r["mesh_size"], r["order"]) for r in bar_runs}
    assert len(bar_runs) == len(keys) == 12
    for r in bar_runs:
        assert r["wall_time_s"] >= r["solve_time_s"] > 0
        assert len(r["frequencies_hz"]) == 3 and r["n_dofs"] > 0
    full = [r for r in bar_runs if r["fidelity"] == "full"]
    assert all(r["n_elements"] == 6 * np.prod([round(L / r["mesh_size"]), round(B / r["mesh_size"]),
                                                round(H / r["mesh_size"])]) for r in full)


def test_richardson_reference_of_the_full_bar_is_within_0p1_percent_of_timoshenko(bar_runs):
    from fem_beam_theory import rectangle_shear_coefficient, timoshenko_frequencies

    from crankmodal.fem.materials import material

    steel = material("steel")
    st = evaluate([dict(r) for r in bar_runs], 3, tolerance=0.01)
    assert st.reference_source[0].startswith("Richardson (full, P2")
    f_flat = timoshenko_frequencies(1, L, steel.E, steel.nu, steel.rho, B * H, B * H ** 3 / 12,
                                    rectangle_shear_coefficient(steel.nu))[0]
    assert st.reference_hz[0] == pytest.approx(f_flat, rel=0.001)  # measured: 0.03 %


def test_simplified_variant_is_several_percent_low_and_never_recommended_at_1_percent(bar_runs):
    st = evaluate([dict(r) for r in bar_runs], 3, tolerance=0.01, compared_modes=1)
    simp = [r for r in st.runs if r["fidelity"] == "simplified" and r["order"] == 2]
    assert all(-0.06 < r["rel_diff"][0] < -0.04 for r in simp)  # f ∝ thickness: -5 %
    dech = [r for r in st.runs if r["fidelity"] == "dechamfered" and r["order"] == 2]
    assert all(0.0 < r["rel_diff"][0] < 0.02 for r in dech)
    k = st.recommended
    assert k is not None and st.runs[k]["fidelity"] != "simplified"
    assert st.runs[k]["error"] <= 0.01
    cheaper = [r for r in st.runs if r["wall_time_s"] < st.runs[k]["wall_time_s"]]
    assert all(r["error"] > 0.01 for r in cheaper)
    assert k in st.pareto


def test_measured_values_take_over_the_reference_of_their_modes(bar_runs):
    st = evaluate([dict(r) for r in bar_runs], 3, measured_hz=[1000.0], tolerance=0.5)
    assert st.reference_source[0] == "measured" and st.reference_source[1] != "measured"
    assert st.compared_modes == 1
    r = st.runs[0]
    assert r["rel_diff"][0] == pytest.approx(r["frequencies_hz"][0] / 1000.0 - 1.0, rel=1e-12)
    assert r["error"] == pytest.approx(abs(r["rel_diff"][0]), rel=1e-12)


def test_written_table_csv_and_error_vs_time_plot(tmp_path, bar_runs):
    f_meas = round(1.01 * evaluate([dict(r) for r in bar_runs], 3).reference_hz[0])
    st = evaluate([dict(r) for r in bar_runs], 3, measured_hz=[f_meas], tolerance=0.03)
    paths = write_study(st, tmp_path, measured_hz=[f_meas], title="bar study")
    assert {"mac_dechamfered", "mac_simplified"} <= set(paths)  # full is the reference itself
    md = paths["markdown"].read_text()
    assert f"| experiment | | | | {f_meas} | / | / | |" in md
    assert "**(recommended)**" in md and "Pareto" in md
    with open(paths["csv"]) as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 12 and sum(int(r["recommended"]) for r in rows) == 1
    assert sum(int(r["pareto"]) for r in rows) == len(st.pareto)
    with open(tmp_path / "error_vs_time.csv") as fh:
        assert len(list(csv.reader(fh))) == 13
    from PIL import Image

    for name in ("error_vs_time.png", "convergence.png"):
        assert Image.open(tmp_path / name).size[0] > 500


def test_modes_that_swap_order_in_a_variant_are_paired_by_mac_not_by_rank():
    """A variant 2.5x thicker than wide: its flat and edgewise bending modes change places."""
    def build(fidelity, h, order):
        from crankmodal.fem import testparts

        t = H if fidelity == "full" else 2.5 * H
        part = testparts.bar(L, B, t, divisions=(round(L / h), round(B / h), max(1, round(t / h))),
                             order=order)
        part.fidelity = fidelity
        return part

    st = evaluate(run_models(build, solve, ["full", "simplified"], [0.012, 0.006], [2]), 2)
    full = [r for r in st.runs if r["fidelity"] == "full"][-1]
    for r in (r for r in st.runs if r["fidelity"] == "simplified"):
        assert r["mode_of"][:2] == [1, 0] and min(r["pair_mac"][:2]) > 0.9
        # edgewise bending (about z) depends on the width only: the same frequency within 1 %
        assert r["matched_hz"][1] == pytest.approx(full["frequencies_hz"][1], rel=0.01)
        # flat bending scales with thickness: 2.5x (shear makes it a little less)
        assert 2.3 < r["rel_diff"][0] + 1 < 2.5
    assert "† (mode 2)" in st.table_markdown()


def test_study_models_run_on_the_sweep_engine_and_resume(tmp_path):
    """crankmodal study's models are points of the sweep engine (a 2-worker Dask cluster): the
    same study as one after another in this process (frequencies to 1e-9, the same pairing and
    MAC), a record per model in models/records.jsonl, and a re-run after losing a record runs
    only that model."""
    pytest.importorskip("dask.distributed")
    from conftest import SCENES

    from crankmodal.report.study_scene import simplification_study
    from crankmodal.scene import load_scene
    from crankmodal.sweep.driver import dask_client
    from crankmodal.sweep.store import RecordStore

    scene = load_scene(SCENES / "seed000_rod_report.toml",
                       ["report.study_sizes=[0.03]", "report.study_orders=[1]",
                        "report.study_fidelities=['full', 'simplified']", "report.study_modes=2"])
    here = simplification_study(scene, tmp_path / "a", figures=False, engine="in-process")
    lines = []
    with dask_client(workers=2) as client:
        dask = simplification_study(scene, tmp_path / "b", figures=False, client=client,
                                    log=lines.append)
        assert any(s.startswith("dask: 2 workers") for s in lines)
        records = tmp_path / "b" / "models" / "records.jsonl"
        assert len(RecordStore(records).read()) == 2
        # a kill that lost the last model's record: only it runs again
        kept = records.read_text().splitlines(keepends=True)[:1]
        records.write_text("".join(kept))
        lines.clear()
        again = simplification_study(scene, tmp_path / "b", figures=False, client=client,
                                     log=lines.append)
    assert sorted(here) == sorted(dask) and len(dask["runs"]) == 2
    for a, b in zip(here["runs"], dask["runs"]):
        assert (a["fidelity"], a["mesh_size"], a["n_elements"]) == \
               (b["fidelity"], b["mesh_size"], b["n_elements"])
        np.testing.assert_allclose(b["frequencies_hz"], a["frequencies_hz"], rtol=1e-9)
        assert a["mode_of"] == b["mode_of"]
        np.testing.assert_allclose(b["mac_to_reference"], a["mac_to_reference"], atol=1e-9)
    assert here["recommended"] == dask["recommended"]
    assert "study: 1 of 2 models recorded" in "\n".join(lines)
    assert len(records.read_text().splitlines()) == 2
    np.testing.assert_allclose([r["frequencies_hz"] for r in again["runs"]],
                               [r["frequencies_hz"] for r in dask["runs"]], rtol=1e-9)
