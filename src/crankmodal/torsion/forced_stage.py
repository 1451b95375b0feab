"""The ``[torsion.forced]`` sub-section: steady-state forced response, stress and verdict.

Read by the ``[torsion]`` stage (:mod:`.stage`) after its chain is built. Everything is checked
and built at check time (:func:`validate`), so bad input stops the run before anything is
written. The machine's excitation comes from the scene's ``[mechanism]`` section (cylinders,
rod, masses, gas cycle) when ``throw_rotors`` is given; explicit ``harmonics`` add to it.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table
from .damping import DEFAULT_MODAL_DAMPING
from .stress import DEFAULT_SAFETY_FACTOR

KEY = "torsion.forced"


def _range_check(v):
    return None if v[0] < v[1] else f"must be [min, max] with min < max, got {v}"


SCHEMA: dict[str, Field] = {
    "speed_range_rpm": Field("floats", None, "speed range [min, max], rpm (default: torsion.speed_range_rpm)",
                             gt=0.0, length=2, check=_range_check),
    "speed_step_rpm": Field("float", 5.0, "speed step, rpm", gt=0.0),
    "modal_damping": Field("float", DEFAULT_MODAL_DAMPING,
                           "damping ratio of every elastic mode (other damping adds to it)", ge=0.0, lt=1.0),
    "harmonics": Field("tables", [], "explicit harmonic torques {rotor (1-based), order, amplitude (N m), phase_deg}"),
    "max_order": Field("float", None, "highest order (default: torsion.max_order)", gt=0.0, le=48.0),
    "throw_rotors": Field("ints", None, "rotor (1-based) carrying each throw; the [mechanism] section's "
                          "cylinders excite them", ge=1),
    "cylinder_throws": Field("ints", None, "throw (1-based) of each [mechanism] cylinder (default: one each)", ge=1),
    "firing_order": Field("ints", None, "four-stroke: cylinders (1-based) in firing order", ge=1),
    "pressure_table": Field("table", None, "measured cylinder pressure: angle_deg, pressure_pa, cycle_deg"),
    "double_acting": Field("tables", [], "double-acting cylinders {cylinder (1-based), rod_diameter (m), "
                           "relative_clearance of the crank end}"),
    "n_points": Field("int", 720, "crank-angle samples per revolution of the excitation", ge=72, le=20000),
    "rotor_damping": Field("floats", None, "absolute damping of each rotor, N m s/rad", ge=0.0),
    "section_damping": Field("floats", None, "relative damping across each shaft section, N m s/rad", ge=0.0),
    "dampers": Field("tables", [], "dampers {rotor, inertia, damping, stiffness, loss_factor}"),
    "sections": Field("tables", None, "per shaft section {diameter, bore | section_modulus, stress_concentration}"),
    "endurance_limit": Field("float", None, "torsional endurance limit of the shaft material, Pa", gt=0.0),
    "size_factor": Field("float", 1.0, "Marin size factor", gt=0.0, le=1.0),
    "surface_factor": Field("float", 1.0, "Marin surface factor", gt=0.0, le=1.0),
    "reliability_factor": Field("float", 1.0, "Marin reliability factor", gt=0.0, le=1.0),
    "safety_factor": Field("float", DEFAULT_SAFETY_FACTOR, "safety factor on the endurance limit", ge=1.0),
    "operating_speeds_rpm": Field("floats", None, "operating speeds, rpm (default: torsion.operating_speed_rpm "
                                  "or mechanism.speed_rpm)", gt=0.0),
    "speed_band": Field("float", 0.10, "separation band each side of an operating speed (fraction)", ge=0.0, lt=1.0),
    "significance": Field("float", 0.10, "relative modal excitation from which an order counts", ge=0.0, le=1.0),
    "drive_section": Field("int", None, "shaft section (1-based) of the drive (coupling, motor); default the last",
                           ge=1),
}

HARMONIC = {
    "rotor": Field("int", doc="rotor, 1-based", ge=1),
    "order": Field("float", doc="order of the shaft speed", gt=0.0),
    "amplitude": Field("float", doc="N m", ge=0.0),
    "phase_deg": Field("float", 0.0, "deg: T = amplitude cos(order theta + phase)"),
}
DAMPER = {
    "rotor": Field("int", doc="rotor (1-based) carrying the damper hub", ge=1),
    "inertia": Field("float", doc="seismic ring inertia, kg m^2", gt=0.0),
    "damping": Field("float", 0.0, "viscous coefficient hub-ring, N m s/rad", ge=0.0),
    "stiffness": Field("float", 0.0, "spring hub-ring (tuned rubber damper), N m/rad", ge=0.0),
    "loss_factor": Field("float", 0.0, "rubber loss factor", ge=0.0),
}
SECTION = {
    "diameter": Field("float", None, "m", gt=0.0),
    "bore": Field("float", 0.0, "m", ge=0.0),
    "section_modulus": Field("float", None, "polar section modulus Z_p, m^3 (instead of diameter)", gt=0.0),
    "stress_concentration": Field("float", 1.0, "K_t", ge=1.0),
    "name": Field("str", None, "label"),
}
CRANK_END = {
    "cylinder": Field("int", doc="[mechanism] cylinder, 1-based", ge=1),
    "rod_diameter": Field("float", doc="piston-rod diameter, m", gt=0.0),
    "relative_clearance": Field("float", None, "crank-end clearance / its swept volume (default: the cylinder's)",
                                gt=0.0, lt=1.0),
}
PRESSURE = {
    "angle_deg": Field("floats", doc="crank angle from firing TDC (four-stroke) or TDC, deg, increasing, "
                       "closing the cycle"),
    "pressure_pa": Field("floats", doc="absolute cylinder pressure, Pa"),
    "cycle_deg": Field("float", 720.0, "cycle length, deg", choices=None),
}


def _cycle_revolutions(tp: dict, f: dict, machine) -> int:
    if f["pressure_table"] is not None:
        return 2 if f["pressure_table"]["cycle_deg"] == 720.0 else 1
    if machine is not None:
        return machine.cycle_revolutions
    return 2 if tp["order_type"] == "four_stroke" else 1


def _machine(scene):
    """The scene's ``[mechanism]`` machine, validated by its own stage."""
    raw = None if scene is None else scene.sections.get("mechanism")
    if raw is None:
        return None
    from ..mechanism.machine import machine_from_params
    from ..mechanism.stage import validate as validate_mechanism

    p = validate_mechanism(raw, scene)
    return machine_from_params(p, name=p["machine"] or "machine")


def _sections(tp: dict, f: dict, chain, model):
    from .stress import Section

    n_sec = len(chain.stiffnesses)
    if f["sections"] is None:
        if tp.get("segments"):
            with scene_keys("torsion.segments"):
                return [Section.round(s["diameter"], s["bore"]) for s in tp["segments"]], \
                    [f"segment {i + 1}" for i in range(n_sec)]
        if model is not None:
            t = tp["throw"]
            return [Section.round(t["journal_diameter"], t["journal_bore"])] * n_sec, \
                [f"{chain.labels[i]} - {chain.labels[i + 1]}" for i in range(n_sec)]
        return None, [f"section {i + 1}" for i in range(n_sec)]
    if len(f["sections"]) != n_sec:
        raise SceneError(f"{KEY}.sections: needs one table per shaft section ({n_sec}), got {len(f['sections'])}")
    out, names = [], []
    for i, raw in enumerate(f["sections"]):
        key = f"{KEY}.sections[{i}]"
        s = validate_table(key, raw, SECTION)
        if (s["diameter"] is None) == (s["section_modulus"] is None):
            raise SceneError(f"{key}.diameter: give exactly one of diameter (m) or section_modulus (m^3)")
        if s["diameter"] is not None and not s["bore"] < s["diameter"]:
            raise SceneError(f"{key}.bore: must be < diameter ({s['diameter']:g} m), got {s['bore']:g}")
        with scene_keys(key):
            out.append(Section.round(s["diameter"], s["bore"], s["stress_concentration"])
                       if s["diameter"] is not None
                       else Section(s["section_modulus"], s["stress_concentration"]))
        names.append(s["name"] or _default_name(chain, i))
    return out, names


def _default_name(chain, i):
    if chain.fixed_end:
        return "wall - " + chain.labels[0] if i == 0 else f"{chain.labels[i - 1]} - {chain.labels[i]}"
    return f"{chain.labels[i]} - {chain.labels[i + 1]}"


#: largest per-order response kept in memory (speeds x orders x DOF complex numbers, 160 MB)
MAX_RESPONSE_SIZE = 1.0e7
#: an order above max_order whose torque exceeds this fraction of the largest is warned
TRUNCATION_WARNING = 0.05


def _validity_warnings(f: dict, excitation, train, machine, ops, eff) -> list[str]:
    """What the model leaves out that this scene depends on (texts for results.json warnings)."""
    out = []
    if machine is not None and eff is not None:
        n_op = (ops[0] if ops else machine.speed_rpm) * math.pi / 30.0
        spec = np.abs(np.fft.rfft(eff.torque(n_op).sum(axis=1)))[1:]
        k_kept = len(excitation.orders)
        if len(spec) > k_kept and spec[k_kept:].max() > TRUNCATION_WARNING * spec.max():
            q = (k_kept + 1 + int(np.argmax(spec[k_kept:]))) / excitation.cycle_revolutions
            out.append(f"torsion.forced: order {q:g} above max_order carries "
                       f"{100 * spec[k_kept:].max() / spec.max():.1f} % of the largest order's torque "
                       "on the crank; raise max_order")
    if any(d.kind == "viscous" for d in train.dampers):
        out.append("torsion.forced: natural frequencies and margins are those with the viscous damper "
                   "ring free (zero damping); with the ring locked they are lower -- the forced response "
                   "includes the damper exactly")
    if f["modal_damping"] > 0.1:
        out.append(f"torsion.forced.modal_damping: {f['modal_damping']:g} is far above the 0.01-0.05 of "
                   "crank trains (resonant amplification 1/(2 zeta) below 5)")
    return out


def validate(tp: dict, scene, chain, model) -> dict:
    """Check ``[torsion.forced]`` and build the train, excitation and stress data.

    ``tp`` is the validated ``[torsion]`` table, ``chain``/``model`` what it built.
    """
    from ..mechanism.arrangement import arrangement_of_machine
    from .damping import Damper
    from .excitation import CrankEnd, PressureTable, cylinder_efforts, rotor_excitation
    from .forced import damped_train
    from .stress import Allowable

    f = validate_table(KEY, tp["forced"], SCHEMA)
    n = chain.n_rotors
    f["harmonics"] = [validate_table(f"{KEY}.harmonics[{i}]", h, HARMONIC) for i, h in enumerate(f["harmonics"])]
    dampers_raw = [validate_table(f"{KEY}.dampers[{i}]", d, DAMPER) for i, d in enumerate(f["dampers"])]
    if f["pressure_table"] is not None:
        f["pressure_table"] = validate_table(f"{KEY}.pressure_table", f["pressure_table"], PRESSURE)
        if f["pressure_table"]["cycle_deg"] not in (360.0, 720.0):
            raise SceneError(f"{KEY}.pressure_table.cycle_deg: must be 360 or 720, got "
                             f"{f['pressure_table']['cycle_deg']:g}")

    # speeds
    rng = f["speed_range_rpm"] or tp["speed_range_rpm"]
    if rng is None:
        raise SceneError(f"{KEY}.speed_range_rpm: is required (rpm, [min, max]) when torsion.speed_range_rpm "
                         "and operating_speed_rpm are not given")
    lo = max(rng[0], f["speed_step_rpm"]) if rng[0] <= 0 else rng[0]
    count = (rng[1] - lo) / f["speed_step_rpm"]
    if not count < 200_000:
        raise SceneError(f"{KEY}.speed_step_rpm: gives {count:.3g} speeds in {rng} rpm; at most 200000")
    speeds = np.arange(lo, rng[1] + 1e-9 * rng[1], f["speed_step_rpm"])
    if len(speeds) < 2:
        raise SceneError(f"{KEY}.speed_step_rpm: must leave at least two speeds in {rng}, got {f['speed_step_rpm']:g}")

    # machine and excitation
    machine = None
    if f["throw_rotors"] is not None:
        machine = _machine(scene)
        if machine is None:
            raise SceneError(f"{KEY}.throw_rotors: the machine's excitation needs a [mechanism] section in the scene")
    else:
        for k in ("cylinder_throws", "firing_order", "pressure_table", "double_acting"):
            if f[k]:
                raise SceneError(f"{KEY}.{k}: needs throw_rotors (and a [mechanism] section)")
        if not f["harmonics"]:
            raise SceneError(f"{KEY}.harmonics: give harmonic torques, or throw_rotors with a [mechanism] section")
    cr = _cycle_revolutions(tp, f, machine)
    max_order = f["max_order"] or tp["max_order"]
    efforts, arrangement = None, None
    if machine is not None:
        table = None
        if f["pressure_table"] is not None:
            pt = f["pressure_table"]
            with scene_keys(f"{KEY}.pressure_table"):
                table = PressureTable(np.radians(pt["angle_deg"]), np.asarray(pt["pressure_pa"], float),
                                      2 if pt["cycle_deg"] == 720.0 else 1)
        try:
            with scene_keys(KEY):
                arrangement = arrangement_of_machine(
                    machine, None if f["cylinder_throws"] is None else [t - 1 for t in f["cylinder_throws"]],
                    None if f["firing_order"] is None else [c - 1 for c in f["firing_order"]],
                    cycle_revolutions=cr)
                arrangement.firing_angles()  # the order against the angles, checked here
        except SceneError as exc:
            if "does not fit in one working cycle" not in str(exc):
                raise
            # the order is a permutation, so the cylinders' angles are what does not fit it
            raise SceneError(f"{exc} -- check the firing order against mechanism.cylinders[i].throw_angle_deg "
                             "and bank_angle_deg") from None
        ends: list = []
        for i, d in enumerate(f["double_acting"]):
            key = f"{KEY}.double_acting[{i}]"
            d = validate_table(key, d, CRANK_END)
            n_cyl = len(machine.cylinders)
            if d["cylinder"] > n_cyl or d["cylinder"] - 1 in [e.cylinder for e in ends]:
                raise SceneError(f"{key}.cylinder: must be one of the cylinders 1..{n_cyl}, each once, "
                                 f"got {d['cylinder']}")
            bore = machine.cylinders[d["cylinder"] - 1].bore
            if not d["rod_diameter"] < bore:
                raise SceneError(f"{key}.rod_diameter: must be < the bore ({bore:g} m), got {d['rod_diameter']:g}")
            if (table is None and getattr(machine.gas, "kind", None) != "compressor") or (table and cr != 1):
                raise SceneError(f"{key}.cylinder: double acting needs mechanism.gas.model = 'compressor' "
                                 "or a 360 deg pressure_table")
            with scene_keys(key):
                ends.append(CrankEnd(d["cylinder"] - 1, d["rod_diameter"], d["relative_clearance"]))
        with scene_keys(KEY):
            efforts = cylinder_efforts(machine, arrangement, table, f["n_points"], tuple(ends))
    harmonics = [{**h, "rotor": h["rotor"] - 1} for h in f["harmonics"]]
    with scene_keys(KEY):
        excitation = rotor_excitation(
            n, max_order, cr, efforts,
            None if f["throw_rotors"] is None else [r - 1 for r in f["throw_rotors"]], harmonics)
        dampers = []
        for i, d in enumerate(dampers_raw):
            with scene_keys(f"{KEY}.dampers[{i}]"):
                dampers.append(Damper(d["rotor"] - 1, d["inertia"], d["damping"], d["stiffness"],
                                      d["loss_factor"]))
        train = damped_train(chain, f["modal_damping"], f["rotor_damping"], f["section_damping"], dampers)

    if not (np.any(train.C) or np.any(train.D)):
        raise SceneError(f"{KEY}.modal_damping: the train has no damping at all (modal, rotor, section or "
                         "damper), so its response at a resonance is infinite; give modal_damping > 0")

    # stress and verdict data
    sections, names = _sections(tp, f, chain, model)
    allowable = None
    if f["endurance_limit"] is not None:
        if sections is None:
            raise SceneError(f"{KEY}.sections: the stress check (endurance_limit) needs the shaft sections "
                             "(diameter/bore or section_modulus per section)")
        with scene_keys(KEY):
            allowable = Allowable(f["endurance_limit"], f["size_factor"], f["surface_factor"],
                                  f["reliability_factor"], f["safety_factor"])
    ops = f["operating_speeds_rpm"]
    if ops is None:
        ops = [tp["operating_speed_rpm"]] if tp["operating_speed_rpm"] else (
            [machine.speed_rpm] if machine is not None else [])
    for i, n_op in enumerate(ops):
        a, b = n_op * (1 - f["speed_band"]), n_op * (1 + f["speed_band"])
        if a < speeds[0] - 1e-9 or b > speeds[-1] + 1e-9:
            inside = speeds[0] - 1e-9 <= n_op <= speeds[-1] + 1e-9
            if inside or not f["operating_speeds_rpm"]:
                key = f"{KEY}.speed_band"  # the band, not the speed, leaves the range
            else:
                key = f"{KEY}.operating_speeds_rpm[{i}]"
            raise SceneError(f"{key}: the band {a:.5g}..{b:.5g} rpm around {n_op:g} rpm lies outside the "
                             f"speed range {speeds[0]:.5g}..{speeds[-1]:.5g} rpm")
    size = len(speeds) * len(excitation.orders) * train.n_dofs
    if size > MAX_RESPONSE_SIZE:
        raise SceneError(
            f"{KEY}.speed_step_rpm: {len(speeds)} speeds x {len(excitation.orders)} orders x {train.n_dofs} DOF "
            f"= {size:.3g} complex amplitudes ({16 * 2 * size / 1e9:.2g} GB with the section torques); at most "
            f"{MAX_RESPONSE_SIZE:.0e}: raise the step, narrow the range or lower max_order")
    warnings = _validity_warnings(f, excitation, train, machine, ops, efforts)
    drive = f["drive_section"] or len(chain.stiffnesses)
    if drive > len(chain.stiffnesses):
        raise SceneError(f"{KEY}.drive_section: must be 1..{len(chain.stiffnesses)}, got {drive}")
    f.update(speeds=speeds, excitation=excitation, train=train, machine=machine, arrangement=arrangement,
             efforts=efforts, section_objects=sections, section_names=names, allowable=allowable,
             operating=list(ops), drive=drive - 1, cycle_revolutions=cr, crank_model=model,
             validity_warnings=warnings)
    return f


def run(f: dict, ctx, chain) -> dict:
    """Solve, check, tabulate and plot; returns the ``torsion.forced`` results."""
    from ..results import write_atomic
    from .forced import steady_state
    from .resonance import resonance_tables
    from .verdict import modal_excitation, separation_margins, stress_check, summary_line

    train, ex = f["train"], f["excitation"]
    res = steady_state(train, ex, f["speeds"])
    natural_hz, shapes = train.natural_frequencies()
    ops = f["operating"]
    rel = np.zeros((len(ops), len(natural_hz), len(ex.orders)))
    for o, n_op in enumerate(ops):
        me = modal_excitation(shapes, ex.at([n_op * math.pi / 30.0])[0])
        rel[o] = me / np.maximum(me.max(axis=1, keepdims=True), 1e-300)
    margins = separation_margins(natural_hz, ex.orders, rel, ops, f["speed_band"], f["significance"])

    secs = f["section_objects"]
    if secs is not None:  # each section's own K_t T / Z_p
        stress = np.column_stack([s.stress(res.section_torque_nm[:, i]) for i, s in enumerate(secs)])
        order_stress = np.stack([s.stress(np.abs(res.section_torque[..., i])) for i, s in enumerate(secs)],
                                axis=-1)
    else:  # no section data: the check runs on torque (N m) and names the worst section by torque
        stress = res.section_torque_nm
        order_stress = np.abs(res.section_torque)
    allow = None if f["allowable"] is None else f["allowable"].stress
    check = stress_check(res.speed_rpm, stress, order_stress, ex.orders, allow, f["section_names"])
    if secs is None:
        check["stress_pa"] = None
        check["torque_nm"] = float(res.section_torque_nm.max())
        for row in check["sections"]:
            row["max_torque_nm"] = row.pop("max_stress_pa")
    tables = resonance_tables(train, res, natural_hz, shapes, ex, f["speeds"])
    summary = summary_line(check, margins) if secs is not None else (
        f"largest vibratory torque {check['torque_nm']:.4g} N m in section {check['worst_section']} "
        f"({check['section']}) at {check['speed_rpm']:.5g} rpm (no section data: no stress)")
    out = ctx.out_dir
    write_atomic(out / "torsion_forced_resonances.txt", "\n\n".join(t["text"] for t in tables) + "\n")
    files = ["torsion_forced_resonances.txt"]
    if ctx.figures:
        from .forced_plots import plot_interference, plot_response, plot_stress

        files.append(plot_interference(res, natural_hz, f["operating"], f["speed_band"],
                                       out / "torsion_forced_interference.png").name)
        files.append(plot_response(res, train, out / "torsion_forced_response.png").name)
        files.append(plot_stress(res.speed_rpm, stress, f["section_names"], allow, f["operating"],
                                 f["speed_band"], secs is not None, out / "torsion_forced_stress.png").name)
    ctx.products["torsion.forced"] = {"response": res, "train": train, "excitation": ex}
    d = f["drive"]
    result = {
        "speed_rpm": res.speed_rpm,
        "amplitude_rad": res.amplitude_rad[:, : train.n_rotors],
        "section_torque_nm": res.section_torque_nm,
        "section_stress_pa": stress if secs is not None else None,
        "orders": ex.orders,
        "cycle_revolutions": f["cycle_revolutions"],
        "damper_amplitude_rad": res.amplitude_rad[:, train.n_rotors:] if train.dampers else None,
        "drive_section": d + 1,
        "drive_torque_nm": res.section_torque_nm[:, d],
        "natural_hz": natural_hz,
        "mode_shapes": shapes,
        "train": train.to_dict(),
        "sections": None if secs is None else [{"name": nm, **s.to_dict()}
                                               for nm, s in zip(f["section_names"], secs)],
        "allowable": None if f["allowable"] is None else f["allowable"].to_dict(),
        "stress_check": check,
        "margins": margins,
        "resonances": [{k: v for k, v in t.items() if k != "text"} for t in tables],
        "operating_speeds_rpm": ops,
        "files": files,
        "summary": summary,
        "warnings": list(f["validity_warnings"]),
    }
    from ..errors import warn

    for w in f["validity_warnings"]:
        warn(w)
    modal = ctx.results.get("modal")
    if modal and modal.get("classes"):  # the FE crank of the same scene, mode by mode
        from .fe_beside import fe_beside_train

        result["fe_comparison"] = fe_beside_train(natural_hz, modal["frequencies_hz"], modal["classes"],
                                                  f["crank_model"])
    if f["arrangement"] is not None:
        result["arrangement"] = f["arrangement"].to_dict()
        eff = f["efforts"]
        w0 = f["machine"].omega
        result["excitation"] = {
            "speed_rpm": f["machine"].speed_rpm,
            "mean_torque_nm": eff.mean_torque(w0),
            "mean_power_w": float(eff.mean_torque(w0).sum() * w0),
            "throw_rotors": f["throw_rotors"],
        }
    return result
