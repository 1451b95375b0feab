"""The ``[mechanism]`` scene stage: rigid-mechanism forces of a crank machine over one cycle.

Keys (SI units; angles in degrees where the name says ``_deg``) are declared below; a machine's
``[mechanism]`` table in ``geometry/<machine>.toml`` supplies the defaults. Writes
``mechanism_curves.npz`` and, with figures on, ``mechanism_*.png`` into the output folder, and
leaves the :class:`~crankmodal.mechanism.analysis.MechanismResults` in
``ctx.products["mechanism"]`` for later stages.
"""

from __future__ import annotations

import math

from ..errors import SceneError
from ..schema import Field
from ..schema import validate as validate_table

SECTION = "mechanism"
REQUIRES = ()

SCHEMA = {
    "machine": Field("str", None, "machine whose [mechanism] table gives the defaults"),
    "speed_rpm": Field("float", doc="crank speed, rev/min", gt=0),
    "crank_radius": Field("float", doc="crank radius r, m", gt=0),
    "rod_length": Field("float", None, "rod centre distance l, m (or give rod_ratio)", gt=0),
    "rod_ratio": Field("float", None, "crank-to-rod ratio lambda = r/l (or give rod_length)",
                       gt=0, lt=1),
    "rod_mass": Field("float", doc="connecting-rod mass, kg", ge=0),
    "rod_cg_from_big_end": Field("float", doc="rod centre of mass from the big-end centre, m",
                                 ge=0),
    "rod_inertia": Field("float", doc="rod moment of inertia about its centre of mass, kg m^2",
                         ge=0),
    "crank_unbalance": Field("float", 0.0, "crankshaft's own unbalance m*e at the crankpin, kg m",
                             ge=0),
    "atmospheric_pressure": Field("float", 1.0e5, "crankcase-side pressure on the pistons, Pa",
                                  gt=0),
    "cylinders": Field("tables", doc="one table per cylinder (see CYLINDER keys)",
                       check=lambda v: None if v else "needs at least one cylinder"),
    "gas": Field("table", {}, "working process (see GAS keys)"),
    "friction": Field("table", {}, "piston friction (see FRICTION keys)"),
    "n_points": Field("int", 720, "crank-angle samples per revolution", ge=36, le=100000),
    "max_order": Field("int", 2, "highest order of the order-resolved inertia forces",
                       ge=1, le=24),
    "harmonics": Field("str", "series", "'series' (seed Table 1, orders <= 2) or 'fourier'",
                       choices=("series", "fourier")),
}

CYLINDER = {
    "bank_angle_deg": Field("float", doc="cylinder axis from +y towards +x, deg"),
    "axial_offset": Field("float", 0.0, "z of the cylinder plane from the centre of symmetry, m"),
    "throw_angle_deg": Field("float", 0.0, "crankpin of this cylinder ahead of the reference, deg"),
    "piston_mass": Field("float", doc="piston group mass (piston, pin, rings), kg", ge=0),
    "bore": Field("float", doc="cylinder bore, m", gt=0),
    "suction_pressure": Field("float", None, "compressor: nominal suction pressure, Pa abs",
                              gt=0),
    "discharge_pressure": Field("float", None, "compressor: nominal discharge pressure, Pa abs",
                                gt=0),
    "relative_clearance": Field("float", None, "compressor: clearance / swept volume", gt=0,
                                lt=1),
    "cycle_phase_deg": Field("float", 0.0, "four-stroke: crank angle of firing TDC, deg",
                             ge=0, lt=720),
}

GAS = {
    "model": Field("str", "none", "'none', 'compressor' or 'four_stroke'",
                   choices=("none", "compressor", "four_stroke")),
    "compression_exponent": Field("float", 1.4, "polytropic exponent of compression", gt=1,
                                  le=2),
    "expansion_exponent": Field("float", 1.4, "polytropic exponent of expansion", gt=1, le=2),
    "pressure_coefficient": Field("float", 1.0, "compressor: lambda_p = ps'/ps = pd/pd'",
                                  gt=0, le=1),
    "valve_timing": Field("str", "pressure", "compressor: 'pressure' or 'seed' (fixed angles)",
                          choices=("pressure", "seed")),
    "seed_angles_deg": Field("floats", [97.0, 295.0],
                             "compressor, seed timing: end of compression and of expansion "
                             "after BDC, deg", length=2),
    "intake_pressure": Field("float", None, "four-stroke: pa, Pa abs", gt=0),
    "max_pressure": Field("float", None, "four-stroke: pz, Pa abs", gt=0),
    "exhaust_pressure": Field("float", None, "four-stroke: pb, Pa abs", gt=0),
    "compression_ratio": Field("float", None, "four-stroke: epsilon", gt=1),
    "constant_pressure_duration_deg": Field("float", 0.0, "four-stroke: theta at pz, deg", ge=0),
    "rise_end_deg": Field("float", 15.0, "four-stroke: end of the combustion rise, deg", gt=0),
    "exhaust_opening_deg": Field("float", 170.0, "four-stroke: exhaust opening, deg", le=360),
}

FRICTION = {
    "mechanical_efficiency": Field("float", None, "eta_m; absent: no piston friction",
                                   gt=0, le=1),
    "reciprocating_share": Field("float", 0.6, "share of friction power lost at the piston",
                                 ge=0, le=1),
    "indicated_power": Field("str", "seed", "'seed' (compressor formula) or 'cycle' (p-V area)",
                             choices=("seed", "cycle")),
}


def _validate_compressor(p: dict) -> None:
    g = p["gas"]
    a0, a1 = g["seed_angles_deg"]
    if g["valve_timing"] == "seed" and not 0 < a0 < 180 < a1 < 360:
        raise SceneError(
            "mechanism.gas.seed_angles_deg: need 0 < end of compression < 180 < end of "
            f"expansion < 360, got {g['seed_angles_deg']}"
        )
    for i, c in enumerate(p["cylinders"]):
        key = f"mechanism.cylinders[{i}]"
        for name in ("suction_pressure", "discharge_pressure", "relative_clearance"):
            if c[name] is None:
                raise SceneError(f"{key}.{name}: is required with gas.model = 'compressor'")
        lp = g["pressure_coefficient"]
        ps, pd = lp * c["suction_pressure"], c["discharge_pressure"] / lp
        if pd <= ps:
            raise SceneError(
                f"{key}.discharge_pressure: must exceed the suction pressure, got "
                f"{c['discharge_pressure']:g} <= {c['suction_pressure']:g} Pa"
            )
        expansion = (pd / ps) ** (1.0 / g["expansion_exponent"]) - 1.0
        c_max = 1.0 / expansion if expansion > 0 else math.inf  # ratio within rounding of 1
        if g["valve_timing"] == "pressure" and c["relative_clearance"] >= c_max:
            raise SceneError(
                f"{key}.relative_clearance: must be < {c_max:.4g} for the pressure ratio "
                f"{pd / ps:.4g} (with gas.pressure_coefficient = {lp:g}; the clearance gas "
                "would never re-expand to the suction pressure)"
            )


def _validate_four_stroke(p: dict) -> None:
    g = p["gas"]
    for name in ("intake_pressure", "max_pressure", "exhaust_pressure", "compression_ratio"):
        if g[name] is None:
            raise SceneError(f"mechanism.gas.{name}: is required with model = 'four_stroke'")
    try:
        p_c = g["intake_pressure"] * g["compression_ratio"] ** g["compression_exponent"]
    except OverflowError:
        p_c = math.inf
    if g["max_pressure"] < p_c:
        raise SceneError(
            f"mechanism.gas.max_pressure: must be >= the compression end pressure "
            f"pa eps^n1 = {p_c:g} Pa, got {g['max_pressure']:g}"
        )
    a_z = g["rise_end_deg"] + g["constant_pressure_duration_deg"]
    if not a_z < g["exhaust_opening_deg"]:
        raise SceneError(
            "mechanism.gas.exhaust_opening_deg: must come after rise_end_deg + "
            f"constant_pressure_duration_deg = {a_z:g} deg, got {g['exhaust_opening_deg']:g}"
        )


def validate(raw: dict, scene=None) -> dict:
    """Check the ``[mechanism]`` table; returns the parameters with defaults filled in."""
    p = validate_table(SECTION, raw, SCHEMA)
    p["cylinders"] = [
        validate_table(f"{SECTION}.cylinders[{i}]", c, CYLINDER)
        for i, c in enumerate(p["cylinders"])
    ]
    p["gas"] = validate_table(f"{SECTION}.gas", p["gas"], GAS)
    p["friction"] = validate_table(f"{SECTION}.friction", p["friction"], FRICTION)
    if (p["rod_length"] is None) == (p["rod_ratio"] is None):
        raise SceneError("mechanism.rod_length: give exactly one of rod_length and rod_ratio")
    r = p["crank_radius"]
    length = p["rod_length"] if p["rod_length"] is not None else r / p["rod_ratio"]
    if length <= r:
        raise SceneError(
            f"mechanism.rod_length: must be > crank_radius = {r:g} m for a full turn, got {length:g}"
        )
    if p["rod_cg_from_big_end"] > length:
        rule = "rod_length" if p["rod_length"] is not None else "crank_radius / rod_ratio"
        raise SceneError(
            f"mechanism.rod_cg_from_big_end: must be <= the rod length {rule} = {length:g} m, "
            f"got {p['rod_cg_from_big_end']:g}"
        )
    if p["harmonics"] == "series" and p["max_order"] > 2:
        raise SceneError(
            f"mechanism.max_order: the series has orders 1 and 2 only, got {p['max_order']}; "
            "use harmonics = 'fourier' for higher orders"
        )
    model = p["gas"]["model"]
    if model == "compressor":
        _validate_compressor(p)
    elif model == "four_stroke":
        _validate_four_stroke(p)
    f = p["friction"]
    if f["mechanical_efficiency"] is not None:
        if model == "none":
            raise SceneError("mechanism.friction.mechanical_efficiency: needs a gas model "
                             "(friction follows from the indicated power)")
        if f["indicated_power"] == "seed" and model != "compressor":
            raise SceneError("mechanism.friction.indicated_power: 'seed' is the compressor "
                             "formula; use 'cycle' with gas.model = " + repr(model))
    return p


def _summary(d: dict) -> str:
    from ..report.quantity import quantity_range

    parts = [f"{d['n_cylinders']} cyl at {d['speed_rpm']:g} rpm",
             f"|F1| {quantity_range(d['first_order_force_min_n'], d['first_order_force_max_n'], 'N')}"]
    if d["second_order_force_max_n"] is not None:
        parts.append("F2 cancelled" if d["second_order_force_cancelled"]
                     else f"|F2| max {d['second_order_force_max_n']:.0f} N")
        parts.append(f"|M2| max {d['second_order_moment_max_nm']:.3g} N m")
    parts.append(f"peak gas force {max(d['peak_gas_force_n']) / 1e3:.3g} kN")
    parts.append(f"peak side thrust {max(d['peak_side_thrust_n']):.0f} N")
    parts.append(f"mean crank torque {d['mean_crank_torque_nm']:.1f} N m")
    if d["indicated_power_w"] > 0:
        parts.append(f"indicated {d['indicated_power_w'] / 1e3:.3g} kW")
    return ", ".join(parts)


def run(params: dict, ctx) -> dict:
    """Analyse one working cycle; write curves (npz) and figures; return the key numbers."""
    import numpy as np

    from ..results import atomic_path
    from .analysis import analyse
    from .machine import machine_from_params

    name = params["machine"] or ctx.scene.name
    machine = machine_from_params(params, name=name)
    res = analyse(machine, params["n_points"], params["max_order"], params["harmonics"])
    ctx.products[SECTION] = res
    out = ctx.out_dir
    with atomic_path(out / "mechanism_curves.npz") as tmp:
        np.savez_compressed(tmp, **res.curves())
    files = ["mechanism_curves.npz"]
    if ctx.figures:
        from .plots import write_all

        files += write_all(res, out)
    d = res.to_dict()
    d["summary"] = _summary(d)
    d["files"] = files
    d["bank_angles_deg"] = [math.degrees(c.bank_angle) for c in machine.cylinders]
    return d
