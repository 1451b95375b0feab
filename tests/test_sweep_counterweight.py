"""The counterweight sweep (seed 000 Fig. 22a) on the sweep engine: dynamics.crank_train.
counterweight_mass_radius, and the sweep's minimum of the main-bearing force against the
[mechanism] stage's first-order counterweight."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from crankmodal.errors import SceneError
from crankmodal.runner import check
from crankmodal.scene import load_scene
from crankmodal.sweep import load_sweep, run_sweep

ROOT = Path(__file__).resolve().parents[1]
DYN = ROOT / "scenes" / "four_star_dynamics.toml"
CW = "dynamics.crank_train.counterweight_mass_radius"
X1, Y1 = ("dynamics.main_bearing_order_amplitude_n.1.0",
          "dynamics.main_bearing_order_amplitude_n.1.1")


@pytest.mark.parametrize("sets, match", [
    ([f"{CW}=0.2"], r"counterweight_mass_radius: needs crank_mass > 0"),
    (["dynamics.crank_train.crank_mass=5.0", f"{CW}=-0.1"], r"counterweight_mass_radius: must be >= 0"),
])
def test_counterweight_key_refused_by_name(sets, match):
    with pytest.raises(SceneError, match=match):
        check(load_scene(DYN, overrides=sets))


def test_counterweight_sweep_minimum_is_the_mechanism_counterweight(tmp_path):
    """Oracle: the rigid mechanism's counterweight 2 m_s r + 4 m_rot r = 0.2688 kg m (its
    counterweight_mass_radius_kg_m). The rod's inertia is set to m a b, for which the two-mass
    rod of [mechanism] is exact; the order-1 amplitude of the main-bearing force is then
    |mr - mr*| w^2 (a V), whose vertex is found from the two grid points either side."""
    pytest.importorskip("dask.distributed")
    rod_m, a, L = 1.6, 0.1372, 0.392
    sweep = tmp_path / "cw.toml"
    sweep.write_text(
        f'base = "{DYN}"\n'
        'set = ["dynamics.clearances=[]", "dynamics.ramp_time=0.0", "dynamics.end_time=0.1",\n'
        '       "dynamics.crank_train.crank_mass=5.0", "mechanism.friction={}",\n'
        '       "mechanism.gas.model=\\"none\\"", '
        f'"mechanism.rod_inertia={rod_m * a * (L - a)!r}"]\n'
        f'outputs = ["{X1}", "{Y1}", "mechanism.counterweight_mass_radius_kg_m",\n'
        '           "mechanism.omega_rad_s"]\n'
        f'[axes]\n"{CW}" = [0.0, 0.2, 0.26, 0.28, 0.34]\n')
    res = run_sweep(load_sweep(sweep), tmp_path / "out", workers=2, figures=False)
    assert res["n_ok"] == 5, res
    import csv

    rows = list(csv.DictReader((tmp_path / "out" / "sweep.csv").open()))
    mr = [float(r[CW]) for r in rows]
    amp = [math.hypot(float(r[X1]), float(r[Y1])) / math.sqrt(2) for r in rows]
    w2 = float(rows[0]["mechanism.omega_rad_s"]) ** 2
    target = float(rows[0]["mechanism.counterweight_mass_radius_kg_m"])
    assert target == pytest.approx(2 * (1.2 + 0.35 * rod_m) * 0.035 + 4 * 0.65 * rod_m * 0.035)
    # the V's slope is w^2 (kg m -> N), checked on the unbalanced end
    assert amp[0] == pytest.approx(target * w2, rel=5e-3)
    i = min(range(len(mr)), key=amp.__getitem__)
    assert mr[i] == 0.26  # the grid point nearest 0.2688
    # the vertex from the neighbours either side: (mr_lo + A_lo/w^2 + mr_hi - A_hi/w^2) / 2
    vertex = 0.5 * (mr[2] + amp[2] / w2 + mr[3] - amp[3] / w2)
    print(f"vertex {vertex:.6f} kg m, mechanism {target:.6f} kg m")
    assert vertex == pytest.approx(target, rel=5e-3)
