"""The ``[dynamics]`` scene section: keys, checks, and the mechanism they describe."""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np

from ...errors import SceneError
from ...schema import Field, validate
from ..laws import contact
from ..model import clearance as _clearance  # the core's rules (a module: not a key table)
from ..run import rules as _rules
from ..run.rules import MAX_OUTPUT_SAMPLES, METHODS  # noqa: F401 (METHODS: public here)
from . import trains as _trains

MECHANISMS = ("slider_crank", "four_star", "four_bar")

SCHEMA = {
    "machine": Field("str", None, "machine file whose [dynamics] table gives the defaults"),
    "mechanism": Field("str", "slider_crank", "slider_crank, four_star or four_bar",
                       choices=MECHANISMS),
    "speed_rpm": Field("float", None, "crank speed (prescribed, or initial for a torque drive), "
                       "rpm; default: [mechanism] speed_rpm with from_mechanism", gt=0.0,
                       le=20000.0),
    "rotation": Field("str", "ccw", "sense of crank rotation in the x-y plane: ccw or cw "
                      "(from_mechanism sets cw)", choices=("ccw", "cw")),
    "from_mechanism": Field("bool", False, "take crank, rods, pistons, row offsets and gas forces "
                            "from the scene's [mechanism] section"),
    "ramp_time": Field("float", 0.0, "s, speed ramp from rest (ADAMS STEP); 0 starts at full speed",
                       ge=0.0),
    "drive_torque": Field("float", None, "N m; if given the speed is free and this torque drives"),
    "initial_angle_deg": Field("float", 0.0, "initial crank angle, deg from the x axis"),
    "end_time": _rules.RUN["end_time"],
    "output_step": _rules.RUN["output_step"],
    "spectrum_start": Field("float", None, "start of the spectrum window, s (default: after the "
                            "ramp and one revolution)", ge=0.0),
    "gravity": Field("floats", [0.0, 0.0], "gravity vector in the plane, m/s^2", length=2),
    "gas_force_deg": Field("floats", None, "crank angles from each cylinder's TDC of the gas-force "
                           "table, deg, increasing"),
    "gas_force_n": Field("floats", None, "gas force on the piston, N, positive towards the crank"),
    "gas_cycle_deg": Field("float", 360.0, "360 (compressor, two-stroke) or 720 (four-stroke)",
                           check=lambda v: None if v in (360.0, 720.0) else "must be 360 or 720"),
    "ring_friction_n": Field("float", 0.0, "piston ring friction force, N", ge=0.0),
    "energy_tolerance": _rules.RUN["energy_tolerance"],
    "run_ideal": Field("bool", True, "also run the ideal-joint twin (reference, contact loss)"),
    "crank_train": Field("table", {}, "slider-crank / four-star geometry and masses"),
    "four_bar": Field("table", {}, "four-bar geometry and masses"),
    "clearances": Field("tables", [], "clearance joints: [{joint, clearance (m), journal_radius (m)}]"),
    "contact": Field("table", {}, "normal contact law and parameters"),
    "friction": Field("table", {}, "friction law and parameters"),
    "solver": Field("table", {}, "integrator settings"),
    "flexible": Field("table", {}, "flexible (Craig-Bampton) bodies: crank = {...}, rods = {...} "
                      "(crank trains); crank, coupler, rocker = {...} (four-bar)"),
    "ensemble": Field("int", 1, "trajectories run from starting states perturbed at round-off "
                      "level (relative 1e-12 k): their spread is the uncertainty of an impacting "
                      "run that one trajectory cannot show", ge=1, le=64),
    "run_rigid": Field("bool", True, "with flexible bodies, also run the rigid twin (the same "
                       "parts' mass properties, modes frozen) for side-by-side results"),
}

CRANK_TRAIN = {
    "crank_radius": Field("float", 0.035, "m", gt=0.0),
    "rod_length": Field("float", 0.28, "m", gt=0.0),
    "rod_mass": Field("float", 0.9, "kg", gt=0.0),
    "rod_inertia": Field("float", None, "kg m^2 about the rod centre of mass (default 0.175 m L^2, "
                         "seed 003)", gt=0.0),
    "rod_com": Field("float", None, "distance of the rod centre of mass from the big end, m "
                     "(default 0.3 L)", ge=0.0),
    "piston_mass": Field("float", 1.2, "kg (piston, pin, rings)", gt=0.0),
    "crank_mass": Field("float", 0.0, "kg", ge=0.0),
    "crank_inertia": Field("float", 0.0, "kg m^2 about its centre of mass (add the flywheel here)",
                           ge=0.0),
    "crank_com": Field("float", 0.0, "centre of mass from the axis along the crank, m", ),
    "counterweight_mass_radius": Field("float", 0.0, "counterweight mass x radius opposite the "
                                       "crankpin, kg m (part of crank_mass: its centre of mass "
                                       "moves by -this/crank_mass)", ge=0.0),
    "offset": Field("float", 0.0, "piston-pin offset across the cylinder axis, m"),
    "cylinder_angles_deg": Field("floats", None, "cylinder axis angles from x, deg (slider_crank "
                                 "[0], four_star [90, 270, 0, 180])"),
    "row_z": Field("floats", None, "axial row position of each rod on the crankpin, m"),
    **_trains.TRAIN_KEYS,  # multi-throw trains: arrangement, journals, motor (.trains)
}

FOUR_BAR = {
    "lengths": Field("floats", [0.035, 0.075, 0.145], "crank AB, coupler BC, rocker DC, m",
                     length=3, gt=0.0),
    "rocker_pivot": Field("floats", [-0.008, 0.1598], "D relative to A, m (seed 001 mirrored)",
                           length=2),
    "masses": Field("floats", [35.8, 2.27, 10.42], "kg", length=3, gt=0.0),
    "inertias": Field("floats", [0.0155, 0.00114, 0.0528], "kg m^2 about the centres of mass",
                      length=3, ge=0.0),
    "com_fractions": Field("floats", [0.0, 0.5, 0.5], "centre of mass along crank/coupler/rocker",
                           length=3),
    "extra_rocker_inertia": Field("float", 0.3728, "sley and sword about D, kg m^2", ge=0.0),
    "branch": Field("int", -1, "assembly mode, 1 or -1", check=lambda v: None if v in (1, -1)
                    else "must be 1 or -1"),
}

CLEARANCE = {
    "joint": Field("str", "big_end_1", "joint name: main, big_end_i, small_end_i (crank trains); "
                   "A, B, C, D (four-bar)"),
    # bounds: the core's (ClearanceSpec's RULES); defaults and docs: the scene's
    "clearance": replace(_clearance.RULES["clearance"], default=1e-4, doc="radial clearance, m"),
    "journal_radius": replace(_clearance.RULES["journal_radius"], default=0.02, doc="m"),
    "clearance_major": replace(_clearance.RULES["clearance_major"], doc="worn bearing (seed "
                               "003): radial clearance along the major axis of the elliptical "
                               "bore, m (clearance is the minor one)"),
    "wear_angle_deg": Field("float", 0.0, "major axis of the worn bore from the bearing body's "
                            "axis (rod axis for big and small ends), deg"),
    "viscosity": replace(_clearance.RULES["viscosity"], doc="lubricant dynamic viscosity, Pa s: "
                         "adds the short-bearing (Ocvirk) film force"),
    "bearing_length": _clearance.RULES["bearing_length"],
    "film_model": replace(_clearance.RULES["film_model"], doc="film force with viscosity: short "
                          "(Ocvirk) or finite (Reynolds, tabulated per L/D)"),
}

CONTACT = {
    "law": Field("str", "impact", "normal force law (johnson_cylinder: conformal cylinders, "
                 "needs each clearance's bearing_length)", choices=contact.NORMAL_LAWS),
    "stiffness": Field("float", None, "N/m^exponent (default: from E, nu and the radii); "
                       "johnson_cylinder: pi L E* in N/m (default: from E, nu and bearing_length); "
                       "kelvin_voigt: N/m, required",
                       gt=0.0),
    "exponent": Field("float", 1.5, "force exponent", gt=0.0, le=3.0),
    "damping": Field("float", 300.0, "N s/m (impact: full damping; kelvin_voigt, power_damped)", ge=0.0),
    "penetration": Field("float", 1e-4, "impact: penetration of full damping, m", gt=0.0),
    "restitution": Field("float", 0.9, "hunt_crossley / lankarani_nikravesh / flores", gt=0.0,
                         le=1.0),
    "v_impact_min": Field("float", 1e-3, "floor of the impact velocity, m/s", gt=0.0),
    "E": Field("float", 2.1e11, "Young's modulus of journal and bearing, Pa", gt=0.0),
    "nu": Field("float", 0.3, "Poisson's ratio", ge=0.0, lt=0.5),
}

FRICTION = {
    "law": Field("str", "none", "none, coulomb or ambrosio", choices=contact.FRICTION_LAWS),
    "mu_static": Field("float", 0.05, "static coefficient", ge=0.0),
    "mu_dynamic": Field("float", 0.08, "dynamic coefficient", ge=0.0),
    "v_static": Field("float", 1e-4, "stiction transition velocity, m/s", gt=0.0),
    "v_dynamic": Field("float", 1e-2, "friction transition velocity, m/s", gt=0.0),
}

SOLVER = {  # the integrator's rules from the core (run.rules); the step bound in degrees here
    "method": _rules.SOLVER["method"],
    "rtol": _rules.SOLVER["rtol"],
    "atol": _rules.SOLVER["atol"],
    "max_step_deg": Field("float", 2.0, "largest step, deg of crank", gt=0.0, le=90.0),
    "max_rhs_evals": _rules.SOLVER["max_rhs_evals"],
    "baumgarte": _rules.SOLVER["baumgarte"],
    "study_rtols": Field("floats", [], "tolerances of the error-against-run-time study", gt=0.0,
                         lt=1.0),
}


FLEXIBLE = {
    "crank": Field("table", {}, "the crank as a flexible body (absent: rigid; crank = {} "
                   "flexible with the defaults)"),
    "rods": Field("table", {}, "every rod as a flexible body (absent: rigid; rods = {} flexible "
                  "with the defaults)"),
    "coupler": Field("table", {}, "four-bar: the coupler B-C as a flexible body (absent: rigid): "
                     "file = \"...npz\" or bar = [width, thickness]"),
    "rocker": Field("table", {}, "four-bar: the rocker D-C as a flexible body (absent: rigid): "
                    "file = \"...npz\" or bar = [width, thickness]"),
    "start": _rules.RUN["start"],
}

FLEX_BODY = {
    "file": Field("str", None, "a crankmodal-flexbody .npz (relative to the scene); default: the "
                  "machine's part reduced here and cached"),
    "n_modes": Field("int", None, "in-plane elastic modes kept, lowest first (0: frozen; default "
                     "all up to cutoff_hz, or all stored)", ge=0, le=400),
    "cutoff_hz": Field("float", None, "keep the in-plane elastic modes up to this frequency, Hz",
                       gt=0.0),
    "damping_ratio": Field("float", 0.02, "modal damping ratio of every kept mode", ge=0.0,
                           lt=1.0),
    "material": Field("str", "steel", "library material of the part (reduced here)"),
    "fidelity": Field("str", "full", "part fidelity (reduced here): full, dechamfered, simplified",
                      choices=("full", "dechamfered", "simplified")),
    "mesh_size": Field("float", None, "mesh size of the part reduced here, m (default: crank "
                       "0.016, rod 0.010)", gt=0.0),
    "element_order": Field("int", 2, "1 or 2", check=lambda v: None if v in (1, 2)
                           else "must be 1 or 2"),
    "fixed_interface_modes": Field("int", 20, "fixed-interface modes of the reduction here",
                                   ge=0, le=400),
}

DEFAULT_MESH_SIZE = {"crank": 0.016, "rods": 0.010}

#: four-bar links (``[dynamics.flexible]`` keys ``crank``, ``coupler``, ``rocker`` with
#: ``mechanism = "four_bar"``): from a file, or a prismatic bar between the pins reduced here
LINK_BODY = {
    "file": Field("str", None, "a crankmodal-flexbody .npz (relative to the scene) with the two "
                  "interfaces carrying the link's joints"),
    "bar": Field("floats", None, "[width in the plane, thickness], m: a prismatic bar of the "
                 "link's length between the pins (at its end faces) reduced here and cached",
                 length=2, gt=0.0),
    "interfaces": Field("strs", None, "the file's two interfaces carrying the link's joints, in "
                        "order: crank A, B; coupler B, C; rocker D, C (default: the file's two "
                        "interfaces in stored order)", length=2),
    "n_modes": FLEX_BODY["n_modes"],
    "cutoff_hz": FLEX_BODY["cutoff_hz"],
    "damping_ratio": FLEX_BODY["damping_ratio"],
    "material": Field("str", "steel", "library material of the bar reduced here"),
    "mesh_size": Field("float", None, "element edge of the bar reduced here, m (default: a "
                       "quarter of its smaller section side)", gt=0.0),
    "element_order": FLEX_BODY["element_order"],
    "fixed_interface_modes": FLEX_BODY["fixed_interface_modes"],
}
FOUR_BAR_LINKS = ("crank", "coupler", "rocker")
CRANK_TRAIN_BODIES = ("crank", "rods")


def flexible_keys(p) -> list[str]:
    """The ``[dynamics.flexible]`` bodies given (validated parameters)."""
    return [k for k in ("crank", "rods", "coupler", "rocker") if p["flexible"].get(k) is not None]


def _validate_link(key: str, raw: dict) -> dict:
    where = f"dynamics.flexible.{key}"
    b = validate(where, raw, LINK_BODY)
    if (b["file"] is None) == (b["bar"] is None):
        raise SceneError(f"{where}: give file = \"...npz\" (a reduced link) or bar = [width, "
                         "thickness] (m, a bar reduced here); the four-bar has no part of its own")
    if b["n_modes"] is not None and b["cutoff_hz"] is not None:
        raise SceneError(f"{where}.cutoff_hz: give either n_modes or cutoff_hz, not both")
    if b["bar"] is not None:
        if b["interfaces"] is not None:
            raise SceneError(f"{where}.interfaces: a bar reduced here has its joints at its end "
                             "faces; interfaces goes with file")
        if b["mesh_size"] is None:
            b["mesh_size"] = min(b["bar"]) / 4.0
    elif b["interfaces"] is not None and b["interfaces"][0] == b["interfaces"][1]:
        raise SceneError(f"{where}.interfaces: two different interfaces are needed, got "
                         f"{b['interfaces'][0]!r} twice")
    return b


def validate_flexible(raw: dict, mechanism: str = "slider_crank") -> dict:
    """``[dynamics.flexible]``: validated body tables (crank trains: ``crank``, ``rods``;
    the four-bar: ``crank``, ``coupler``, ``rocker``), None for a rigid one."""
    f = validate("dynamics.flexible", raw, FLEXIBLE)
    allowed = FOUR_BAR_LINKS if mechanism == "four_bar" else CRANK_TRAIN_BODIES
    for key in ("crank", "rods", "coupler", "rocker"):
        if not raw.get(key) and key not in raw:
            f[key] = None
            continue
        if key not in allowed:
            raise SceneError(f"dynamics.flexible.{key}: a {mechanism} has no {key}; its "
                             f"flexible bodies are {', '.join(allowed)}")
        if mechanism == "four_bar":
            f[key] = _validate_link(key, f[key])
            continue
        b = validate(f"dynamics.flexible.{key}", f[key], FLEX_BODY)
        if b["n_modes"] is not None and b["cutoff_hz"] is not None:
            raise SceneError(f"dynamics.flexible.{key}.cutoff_hz: give either n_modes or "
                             "cutoff_hz, not both")
        if b["mesh_size"] is None:
            b["mesh_size"] = DEFAULT_MESH_SIZE[key]
        f[key] = b
    return f


def validate_section(raw: dict) -> dict:
    """Validate ``[dynamics]`` and its sub-tables; return the parameters."""
    p = validate("dynamics", raw, SCHEMA)
    p["crank_train"] = validate("dynamics.crank_train", p["crank_train"], CRANK_TRAIN)
    p["four_bar"] = validate("dynamics.four_bar", p["four_bar"], FOUR_BAR)
    p["clearances"] = [validate(f"dynamics.clearances[{i}]", c, CLEARANCE)
                       for i, c in enumerate(p["clearances"])]
    p["contact"] = validate("dynamics.contact", p["contact"], CONTACT)
    p["friction"] = validate("dynamics.friction", p["friction"], FRICTION)
    p["solver"] = validate("dynamics.solver", p["solver"], SOLVER)
    p["flexible"] = validate_flexible(p["flexible"], p["mechanism"])
    _cross_checks(p)
    from .build import clearance_specs

    clearance_specs(p)  # the law objects and clearance specs refuse what the core refuses
    if p["mechanism"] == "four_bar":  # a bar reduced here: its size refused before it is meshed
        from ..flexible.build import check_bar

        for length, role in zip(p["four_bar"]["lengths"], FOUR_BAR_LINKS):
            spec = p["flexible"].get(role)
            if spec is not None and spec["bar"] is not None:
                check_bar(float(length), spec["bar"], spec, f"dynamics.flexible.{role}")
    elif isinstance(p.get("machine"), str):  # a machine's part reduced here: checked likewise
        from ..flexible.build import check_part

        for key, part in (("crank", "crankshaft"), ("rods", "rod")):
            spec = p["flexible"].get(key)
            if spec is not None and spec["file"] is None:
                check_part(p["machine"], part, spec)
    return p


def joint_names(p) -> list[str]:
    if p["mechanism"] == "four_bar":
        return ["A", "B", "C", "D"]
    n = len(cylinder_angles(p))
    return ["main"] + [f"{k}_{i}" for i in range(1, n + 1) for k in ("big_end", "small_end")]


def cylinder_angles(p) -> list[float]:
    a = p["crank_train"]["cylinder_angles_deg"]
    if a is not None:
        return a
    return [0.0] if p["mechanism"] == "slider_crank" else [90.0, 270.0, 0.0, 180.0]


def _cross_checks(p):
    if p["from_mechanism"]:
        if p["mechanism"] == "four_bar":
            raise SceneError("dynamics.from_mechanism: only crank trains (slider_crank, four_star) "
                             "come from [mechanism]")
    elif p["speed_rpm"] is None:
        raise SceneError("dynamics.speed_rpm: is required (crank speed, rpm, > 0) unless "
                         "from_mechanism = true")
    ct = p["crank_train"]
    if p["mechanism"] != "four_bar" and not p["from_mechanism"]:
        if ct["crank_radius"] >= ct["rod_length"] - abs(ct["offset"]):
            raise SceneError("dynamics.crank_train.rod_length: must exceed crank_radius + |offset| "
                             f"= {ct['crank_radius'] + abs(ct['offset']):g} m")
        if ct["row_z"] is not None and len(ct["row_z"]) != len(cylinder_angles(p)):
            raise SceneError(f"dynamics.crank_train.row_z: needs one entry per cylinder "
                             f"({len(cylinder_angles(p))})")
        if p["mechanism"] == "slider_crank" and len(cylinder_angles(p)) != 1:
            raise SceneError("dynamics.crank_train.cylinder_angles_deg: slider_crank has one "
                             "cylinder; use mechanism = 'four_star' for several")
    else:
        l1, l2, l3 = p["four_bar"]["lengths"]
        l0 = math.hypot(*p["four_bar"]["rocker_pivot"])
        s = sorted([l0, l1, l2, l3])
        if not (s[0] + s[3] <= s[1] + s[2] and min(s) == l1):
            raise SceneError("dynamics.four_bar.lengths: not a crank-rocker (Grashof with the "
                             "crank shortest) for the given rocker_pivot")
    _trains.check_train_keys(p)
    names = joint_names(p)
    seen = set()
    for i, c in enumerate(p["clearances"]):
        # main_1..N: a flexible crank's journals; any cylinder's joints of a [mechanism]
        # machine (crank_train refuses names its train does not have, under this key)
        multi = re.fullmatch(r"main_\d+", c["joint"]) or (
            p["from_mechanism"] and re.fullmatch(r"(big|small)_end_\d+", c["joint"]))
        if c["joint"] not in names and not multi:
            raise SceneError(f"dynamics.clearances[{i}].joint: must be one of {', '.join(names)}; "
                             f"got {c['joint']!r}")
        if p["contact"]["law"] == "johnson_cylinder" and c["bearing_length"] is None:
            raise SceneError(f"dynamics.clearances[{i}].bearing_length: is required with "
                             "contact.law = 'johnson_cylinder' (bearing length, m, > 0)")
        if c["joint"] in seen:
            raise SceneError(f"dynamics.clearances[{i}].joint: {c['joint']!r} given twice")
        seen.add(c["joint"])
    cont = p["contact"]
    if cont["law"] == "kelvin_voigt" and cont["stiffness"] is None and p["clearances"]:
        # the default from E, nu and the radii is the Hertz constant (N/m^1.5) of the power
        # laws: as a linear K (N/m) it would be a unit error
        from ..laws.contact import cylinder_stiffness

        c0 = p["clearances"][0]
        r = c0["journal_radius"]
        kh = cylinder_stiffness(r, r + c0["clearance"], cont["E"], cont["nu"], cont["E"], cont["nu"])
        k10 = 1.5 * kh ** (2.0 / 3.0) * 1e4 ** (1.0 / 3.0)
        raise SceneError(
            "dynamics.contact.stiffness: is required with contact.law = 'kelvin_voigt' (a linear "
            "K in N/m; the default from E, nu and the radii is the Hertz constant in N/m^1.5 of "
            f"the other laws); e.g. the tangent of that Hertz contact ({kh:.3g} N/m^1.5 at "
            f"{c0['joint']!r}) at a load F, 1.5 K^(2/3) F^(1/3): {k10:.3g} N/m at 10 kN")
    g, f = p["gas_force_deg"], p["gas_force_n"]
    if (g is None) != (f is None):
        raise SceneError("dynamics.gas_force_n: give both gas_force_deg and gas_force_n, or none")
    if g is not None:
        if len(g) != len(f) or len(g) < 2:
            raise SceneError("dynamics.gas_force_n: needs as many entries as gas_force_deg (>= 2)")
        if np.any(np.diff(g) <= 0) or g[0] < 0 or g[-1] > p["gas_cycle_deg"]:
            raise SceneError("dynamics.gas_force_deg: must increase within [0, gas_cycle_deg]")
    if ct["counterweight_mass_radius"] > 0 and p["mechanism"] != "four_bar" \
            and ct["crank_mass"] <= 0:
        raise SceneError("dynamics.crank_train.counterweight_mass_radius: needs crank_mass > 0 "
                         "(kg; the counterweight is part of the crank's mass), got crank_mass = "
                         f"{ct['crank_mass']:g}")
    motor = ct.get("motor_inertia") is not None  # a motor drives: the crank's part carries no
    # flywheel, a flexible crank has its own inertia (.trains)
    if p["drive_torque"] is not None and p["mechanism"] != "four_bar" and ct["crank_inertia"] <= 0 \
            and not (motor and p["flexible"]["crank"] is not None):
        raise SceneError("dynamics.crank_train.crank_inertia: must be > 0 (crank and flywheel, "
                         "kg m^2) when drive_torque sets the speed free")
    if p["flexible"]["crank"] is not None and p["drive_torque"] is not None and not motor:
        raise SceneError("dynamics.drive_torque: with a flexible crank the speed is "
                         "prescribed (the part carries no flywheel); remove drive_torque")
    if p["drive_torque"] is not None and p["ramp_time"] > 0:
        raise SceneError("dynamics.ramp_time: must be 0 with drive_torque (the torque drives)")
    if p["ramp_time"] >= p["end_time"] and p["ramp_time"] > 0:
        raise SceneError(f"dynamics.ramp_time: must be < end_time ({p['end_time']:g} s)")
    if p["spectrum_start"] is not None and p["spectrum_start"] >= p["end_time"]:
        raise SceneError(f"dynamics.spectrum_start: must be < end_time ({p['end_time']:g} s), "
                         f"got {p['spectrum_start']:g}")
    dt = p["output_step"]
    if dt is not None and not p["end_time"] / MAX_OUTPUT_SAMPLES <= dt <= p["end_time"]:
        raise SceneError(f"dynamics.output_step: must be in [end_time / {MAX_OUTPUT_SAMPLES:.0e}, "
                         f"end_time] = [{p['end_time'] / MAX_OUTPUT_SAMPLES:g}, "
                         f"{p['end_time']:g}] s, got {dt:g}")


def check_speed(p, speed_rpm: float, key: str = "dynamics.speed_rpm") -> None:
    """Checks that need the crank speed (``key`` names where it was given, rpm)."""
    limit = SCHEMA["speed_rpm"].le
    if speed_rpm > limit:
        raise SceneError(f"{key}: must be <= {limit:g} rpm for [dynamics], got {speed_rpm:g}")
    s = p["solver"]
    steps = 6.0 * speed_rpm * (p["end_time"] - p["ramp_time"]) / s["max_step_deg"]
    if steps > s["max_rhs_evals"]:
        raise SceneError(
            f"dynamics.solver.max_step_deg: {s['max_step_deg']:g} deg needs at least {steps:.3g} "
            f"steps at full speed, more than solver.max_rhs_evals = {s['max_rhs_evals']}; "
            "raise max_step_deg or max_rhs_evals, or shorten end_time")
