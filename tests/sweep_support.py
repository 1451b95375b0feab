"""What the sweep tests share: the base scene, two keys of it and a sweep-file writer (their
local Dask cluster is the ``client`` fixture of conftest.py)."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "scenes" / "four_star_mechanism.toml"
THROW = "mechanism.cylinders.0.throw_angle_deg"
F1 = "mechanism.first_order_force_max_n"


def write_sweep(tmp_path, text, name="sw.toml"):
    p = tmp_path / name
    p.write_text(f'base = "{MECH}"\n' + text)
    return p
