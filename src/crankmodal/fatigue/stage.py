"""Scene stage ``[fatigue]``: the fatigue verdict of a flexible body of the ``[dynamics]`` run.

Reads, after the dynamics ran, the body's modal coordinates ξ(t) over the last steady working
cycle(s) of the run (by crank angle: 360° per cycle, 720° for a four-stroke machine) and the
stress modes, points and mesh of its reduced body; classifies the crank's surface points into
fillets and oil-hole exits from the machine's crank parameters; and calls
:func:`~crankmodal.fatigue.verdict.fatigue_verdict` with the scene's factors and criterion
against the material's fatigue strength (``[material]`` when the scene has it, else the reduced
body's library material). Writes ``fatigue.npz`` (:meth:`FatigueResult.save`),
``fatigue_crank.png`` (the surface coloured by safety factor) and ``fatigue_haigh.png`` (bars
per location and the Haigh diagram), and returns the per-location table, the worst location,
its safety factor against the required one, the criterion and the factors.

An impacting run (clearance joints) is one trajectory of a sensitive system: with
``dynamics.ensemble = N`` every trajectory's cycle is assessed and the spread of the worst
safety factor (min, mean, max) is reported; a single impacting trajectory is warned.

Everything the scene can get wrong is refused at check time (:func:`validate`), before any
stage runs: a body that is not flexible, a body file without stress modes, a material without
fatigue data (``material.fatigue_strength``), a run too short for the cycle.
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..errors import SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table

SECTION = "fatigue"
REQUIRES = ("dynamics",)

#: IACS UR M53's acceptability factor Q (crankshafts of marine engines), the default required
#: fatigue safety factor
REQUIRED_SAFETY_FACTOR = 1.15
_BODY = re.compile(r"crank|coupler|rocker|rod_[1-9][0-9]*")

SCHEMA: dict[str, Field] = {
    "body": Field("str", "crank", "the [dynamics.flexible] body assessed: crank (its fillets and "
                  "oil-hole exits named), rod_<i>, coupler or rocker",
                  check=lambda v: None if _BODY.fullmatch(v) else
                  "must be crank, rod_<i> (i >= 1), coupler or rocker"),
    "cycles": Field("int", 1, "working cycles at the end of the run assessed together (the "
                    "stress extremes over all of them)", ge=1, le=50),
    "cycle_deg": Field("float", None, "crank angle of one working cycle, deg: 360 or 720 "
                       "(default: the [mechanism] machine's, 720 for four-stroke; else "
                       "dynamics.gas_cycle_deg)",
                       check=lambda v: None if v in (360.0, 720.0) else "must be 360 or 720"),
    "criterion": Field("str", "goodman", "mean-stress line: goodman or gerber",
                       choices=("goodman", "gerber")),
    "mean_stress": Field("str", "sines", "equivalent mean stress: sines (first invariant of the "
                         "mean tensor) or signed_von_mises", choices=("sines", "signed_von_mises")),
    "surface_finish": Field("str", None, "Marin surface factor from the finish (Shigley Table "
                            "6-2) and the material's ultimate strength",
                            choices=("ground", "machined", "cold-drawn", "hot-rolled",
                                     "as-forged")),
    "surface_factor": Field("float", None, "Marin surface factor (instead of surface_finish; "
                            "default 1)", gt=0.0, le=1.0),
    "size_diameter": Field("float", None, "m: Marin size factor of a round section of this "
                           "diameter (Shigley eq. 6-20, <= 0.254 m)", gt=0.0, le=0.254),
    "size_factor": Field("float", None, "Marin size factor (instead of size_diameter; default 1)",
                         gt=0.0, le=1.0),
    "reliability": Field("float", 0.5, "probability of survival of the strength (Shigley Table "
                         "6-5: 0.5, 0.9, 0.95, 0.99, 0.999, ...)", gt=0.0, lt=1.0),
    "other_factor": Field("float", 1.0, "further Marin factor (temperature, environment)",
                          gt=0.0, le=1.0),
    "notch_factor": Field("float", 1.0, "fatigue notch factor K_f on the stresses, for a notch "
                          "the mesh does not resolve (1 where the FE mesh resolves the fillets)",
                          ge=1.0),
    "required_safety_factor": Field("float", REQUIRED_SAFETY_FACTOR,
                                    "safety factor the verdict asks for (default: IACS UR M53's "
                                    "acceptability factor 1.15)", ge=1.0),
    "surface_only": Field("bool", True, "assess the outer-surface points only (fatigue cracks "
                          "start at the surface); false: every point of the stress modes"),
}


# ---- check time ----------------------------------------------------------------------------
def _table_of(body: str) -> str:
    """The ``[dynamics.flexible]`` table of a body name (``rod_2`` -> ``rods``)."""
    return "rods" if body.startswith("rod_") else body


def _flexible_table(p: dict, pd: dict) -> dict:
    """The body's validated ``[dynamics.flexible.<table>]``; refuses a rigid or frozen body."""
    table = _table_of(p["body"])
    spec = pd["flexible"].get(table)
    four_bar = pd["mechanism"] == "four_bar"
    if table in ("coupler", "rocker") and not four_bar or table == "rods" and four_bar:
        raise SceneError(f"fatigue.body: a {pd['mechanism']} has no {p['body']!r}")
    if spec is None:
        flex = [k for k in ("crank", "rods", "coupler", "rocker") if pd["flexible"].get(k)]
        raise SceneError(f"fatigue.body: {p['body']!r} is not a flexible body of this scene (no "
                         f"[dynamics.flexible.{table}]; flexible here: "
                         f"{', '.join(flex) or 'none'}): the verdict needs its stress modes")
    if spec["n_modes"] == 0:
        raise SceneError(f"fatigue.body: {p['body']!r} is frozen (dynamics.flexible.{table}."
                         f"n_modes = 0): a rigid body carries no elastic stress")
    return spec


def _body_file(spec: dict, table: str, scene):
    """A given flexbody file: its path and the body read (stress modes checked); else None."""
    if spec["file"] is None:
        return None, None  # reduced from the machine's part: the reduction stores them
    from ..errors import InputFileError
    from ..reduction.io import load_flexbody

    path = scene.resolve(spec["file"]) if scene is not None else spec["file"]
    try:
        fb = load_flexbody(path)
    except InputFileError as exc:  # the [dynamics] check names it first; kept for the API
        raise InputFileError(f"dynamics.flexible.{table}.file: {exc}") from None
    if fb.stress_modes is None:
        raise SceneError(f"fatigue.body: the file of {table!r} ({path}) holds no stress modes: "
                         "reduce the part with its mesh (the [reduction] stage stores them)")
    return path, fb


def _material(scene, spec: dict, fb, table: str):
    """The Material of the verdict: ``[material]``, else the body's library material."""
    from ..errors import ParameterError
    from ..fem.materials import material

    if scene is not None and "material" in scene.sections:
        from ..fem.material_stage import make_material
        from ..fem.material_stage import validate as validate_material

        mat, source = make_material(validate_material(scene.sections["material"], scene)), \
            "[material]"
    else:
        name = spec["material"] if fb is None else (fb.info or {}).get("material")
        source = f"dynamics.flexible.{table}.material" if fb is None else f"the file of {table}"
        try:
            mat = material(str(name))
        except ParameterError:
            raise SceneError(f"material.fatigue_strength: the body's material {name!r} ("
                             f"{source}) is not in the library; give a [material] section with "
                             "its strengths (fatigue_strength, ultimate_strength, Pa)") from None
    for key, what in (("fatigue_strength", "fully reversed, unnotched"),
                      ("ultimate_strength", "the mean-stress line needs it")):
        if getattr(mat, key) is None:
            raise SceneError(f"material.{key}: material {mat.name!r} (from {source}) has no "
                             f"{key.replace('_', ' ')} ({what}): give [material] {key} = ... "
                             f"(Pa) or a library material that has it (42CrMo, "
                             f"crank_steel_seed000, SG 700/2)")
    return mat


def material_mismatch(mat, body_material) -> str | None:
    """A warning when the verdict's material (``[material]``) is not elastically the one the
    body's stress modes were computed with (its library material ``body_material``)."""
    from ..errors import ParameterError
    from ..fem.materials import material

    try:
        ref = material(str(body_material))
    except ParameterError:
        return None  # not a library material: nothing to compare with
    diff = [k for k in ("E", "nu", "rho")
            if not math.isclose(getattr(mat, k), getattr(ref, k), rel_tol=1e-9)]
    if not diff:
        return None
    return (f"fatigue: [material] ({mat.name}) differs from the body's material "
            f"({ref.name}) in {', '.join(diff)}: the stress modes were computed with the "
            f"body's; [material] gives the strengths only")


def _mechanism_params(scene):
    raw = None if scene is None else scene.sections.get("mechanism")
    if raw is None:
        return None
    from ..mechanism.stage import validate as validate_mechanism

    return validate_mechanism(raw, scene)


def _cycle_deg(p: dict, pd: dict, mp) -> float:
    """One working cycle, deg: given, the [mechanism] machine's, or the dynamics gas cycle's."""
    if p["cycle_deg"] is not None:
        return float(p["cycle_deg"])
    if mp is not None:
        from ..mechanism.machine import machine_from_params

        return 360.0 * machine_from_params(mp, name=mp["machine"] or "machine").cycle_revolutions
    return float(pd.get("gas_cycle_deg") or 360.0)


def _check_window(p: dict, pd: dict, mp) -> None:
    """The run must hold the cycles after the ramp and one settling revolution."""
    speed = pd["speed_rpm"] or (mp or {}).get("speed_rpm")
    if not speed:
        return  # a torque drive without a speed: checked on the run's crank angle
    key = "dynamics.speed_rpm" if pd["speed_rpm"] else "mechanism.speed_rpm"
    rev_s = 60.0 / float(speed)
    need = settled_from(pd, rev_s) + p["cycles"] * p["cycle_deg"] / 360.0 * rev_s
    if pd["end_time"] < need * (1.0 - 1e-9):
        after = (f"dynamics.spectrum_start ({pd['spectrum_start']:g} s)"
                 if pd["spectrum_start"] is not None else
                 f"the ramp ({pd['ramp_time']:g} s) and one settling revolution")
        raise SceneError(f"dynamics.end_time: {pd['end_time']:g} s holds no {p['cycles']} steady "
                         f"cycle(s) of {p['cycle_deg']:g} deg for [fatigue] after {after} at "
                         f"{float(speed):g} rpm ({key}): give end_time >= {need:.4g} s (or "
                         f"fewer fatigue.cycles)")


def settled_from(pd: dict, revolution_s: float) -> float:
    """When the run is steady, s: ``dynamics.spectrum_start`` when given (the results window's
    start), else the end of the ramp plus one settling revolution."""
    if pd.get("spectrum_start") is not None:
        return float(pd["spectrum_start"])
    return float(pd["ramp_time"]) + revolution_s


def _crank_part(pd: dict, spec: dict, table: str):
    """``(CrankshaftParams, fidelity)`` of a crank reduced from the machine's part, else None."""
    if table != "crank" or pd["mechanism"] == "four_bar" or spec["file"] is not None \
            or not pd.get("machine"):
        return None
    from ..geometry.params import params_from_dict
    from ..resources import load_machine

    tables = load_machine(pd["machine"], key="dynamics.machine")
    if "crankshaft" not in tables:
        return None
    return (params_from_dict("crankshaft", dict(tables["crankshaft"]),
                             where=f"{pd['machine']}.toml [crankshaft]"), spec["fidelity"])


def factors_of(p: dict, material):
    """The :class:`~crankmodal.fatigue.factors.FatigueFactors` of validated keys."""
    from .factors import FatigueFactors, reliability_factor, size_factor, surface_factor

    with scene_keys(SECTION, {"finish": "surface_finish", "diameter": "size_diameter"}):
        surface = p["surface_factor"] if p["surface_factor"] is not None else \
            surface_factor(material.ultimate_strength, p["surface_finish"]) \
            if p["surface_finish"] is not None else 1.0
        size = p["size_factor"] if p["size_factor"] is not None else \
            size_factor(p["size_diameter"]) if p["size_diameter"] is not None else 1.0
        return FatigueFactors(surface=surface, size=size,
                              reliability=reliability_factor(p["reliability"]),
                              other=p["other_factor"], notch=p["notch_factor"])


def validate(raw: dict, scene) -> dict:
    """Check the ``[fatigue]`` table against the scene's ``[dynamics]`` (and ``[material]``,
    ``[mechanism]``): the body, its stress modes, the material's fatigue data, the factors,
    the cycle and the run's length. Returns the parameters with the Material, the factors,
    the crank's parameters and the cycle filled in."""
    from ..dynamics.scene.keys import validate_section

    p = validate_table(SECTION, raw, SCHEMA)
    for a, b in (("surface_finish", "surface_factor"), ("size_diameter", "size_factor")):
        if p[a] is not None and p[b] is not None:
            raise SceneError(f"fatigue.{b}: give either {a} or {b}, not both")
    if scene is None or "dynamics" not in scene.sections:
        raise SceneError("[fatigue] needs a [dynamics] section in the scene")
    pd = validate_section(scene.sections["dynamics"])
    spec = _flexible_table(p, pd)
    table = _table_of(p["body"])
    path, fb = _body_file(spec, table, scene)
    mat = _material(scene, spec, fb, table)
    mp = _mechanism_params(scene) if pd["from_mechanism"] else None
    p["cycle_deg"] = _cycle_deg(p, pd, mp)
    _check_window(p, pd, mp)
    p["factors"] = factors_of(p, mat)
    p["material"] = mat
    p["crank_part"] = _crank_part(pd, spec, table)
    p["unlocated"] = p["crank_part"] is None and table == "crank" and pd["mechanism"] != "four_bar"
    p["body_file"] = None if path is None else str(path)
    return p


# ---- run -----------------------------------------------------------------------------------
def _body(mech, name: str):
    """The flexible body ``name`` of the run's mechanism."""
    for b in mech.system.bodies:
        if b.name == name and getattr(b, "n_elastic", 0) > 0:
            return b
    have = [b.name for b in mech.system.bodies if getattr(b, "n_elastic", 0) > 0]
    raise SceneError(f"fatigue.body: the run has no flexible body {name!r} (flexible: "
                     f"{', '.join(have) or 'none'})")


def cycle_window(crank_angle, span_deg: float, t, t_min: float = 0.0):
    """Sample mask of the last ``span_deg`` of crank angle of a run.

    Parameters
    ----------
    crank_angle : ndarray, shape (K,)
        Crank angle over the run, rad (either sense of rotation).
    span_deg : float
        Crank angle of the window, deg.
    t : ndarray, shape (K,)
        Times, s.
    t_min : float
        The window must open at or after this time, s (the end of the start-up).

    Returns
    -------
    ndarray of bool, shape (K,)

    Raises
    ------
    SceneError
        Naming ``dynamics.end_time`` when the run's crank turns less than ``span_deg`` after
        ``t_min``.
    """
    a = np.unwrap(np.asarray(crank_angle, float))
    turned = np.abs(a - a[-1])
    span = math.radians(span_deg)
    sel = turned <= span * (1.0 + 1e-9) + 1e-12
    if turned.max() < span * (1.0 - 1e-6) or t[sel][0] < t_min - 1e-12:
        raise SceneError(f"dynamics.end_time: the run's crank turns "
                         f"{math.degrees(turned[t >= t_min].max(initial=0.0)):.4g} deg after "
                         f"{t_min:.4g} s, less than the {span_deg:g} deg [fatigue] assesses: "
                         "run longer")
    return sel


def _assess(p: dict, body, fb, hist, sel, S, nodes, locations, notes):
    from .verdict import fatigue_verdict

    xi = np.asarray(hist.modal[body.name], float)[sel, :body.n_elastic].T
    return fatigue_verdict(S, xi, p["material"], fb.stress_points, nodes=nodes,
                           locations=locations, factors=p["factors"], rule=p["criterion"],
                           mean_stress=p["mean_stress"], warnings=notes)


def _locations(p: dict, fb, nodes, notes):
    from ..errors import warn
    from .locations import crank_locations

    if p["crank_part"] is None:
        if p["unlocated"]:
            warn("fatigue: the crank's fillets and oil-hole exits are located from the "
                 "machine's crank parameters, which a given flexbody file does not carry: every "
                 "point is reported as 'elsewhere'", notes)
        return None
    params, fidelity = p["crank_part"]
    idx = np.arange(len(fb.stress_points)) if nodes is None else nodes
    with scene_keys(SECTION):
        return crank_locations(fb.stress_points, idx, params, fidelity)


def _ensemble(p, body, fb, members, t_min, span, S, nodes, locations, base) -> dict | None:
    """The worst safety factor of every trajectory's last cycle and their spread."""
    import warnings

    from ..errors import ModelWarning

    if not members:
        return None
    rows = [(base.min_safety_factor, base.worst_location)]
    for h in members:
        sel = cycle_window(h.crank_angle, span, h.t, t_min)
        with warnings.catch_warnings():  # the base run's warnings stand for every member's
            warnings.simplefilter("ignore", ModelWarning)
            r = _assess(p, body, fb, h, sel, S, nodes, locations, [])
        rows.append((r.min_safety_factor, r.worst_location))
    n = np.array([r[0] for r in rows])
    return {"n_trajectories": len(rows), "min_safety_factor": n.tolist(),
            "worst_location": [r[1] for r in rows],
            "spread": {"min": float(n.min()), "mean": float(n.mean()), "max": float(n.max()),
                       "std": (float(n.std(ddof=1)) if len(n) > 1 else 0.0)
                       if np.all(np.isfinite(n)) else None}}


def run(p: dict, ctx) -> dict:
    """Assess the body over the run's last cycle(s) (each ensemble member's too), write
    ``fatigue.npz`` and the figures; returns the results.json entry."""
    from ..errors import warn
    from ..reduction.io import load_flexbody
    from .locations import surface_nodes

    prod = ctx.products["dynamics"]
    mech, hist = prod["mechanism"], prod["history"]
    members = list(prod.get("members") or [])
    body = _body(mech, p["body"])
    fb = body.source if body.source is not None else load_flexbody(body.info["file"])
    if fb.stress_modes is None:
        raise SceneError(f"fatigue.body: the reduced body of {p['body']!r} "
                         f"({body.info.get('file')}) holds no stress modes")
    notes: list[str] = []
    text = material_mismatch(p["material"], (fb.info or {}).get("material"))
    if text:
        warn(text, notes)
    S = np.asarray(fb.stress_modes)[:, :, np.asarray(body.info["mode_columns"], int)]
    cells = fb.mesh_cells
    nodes = surface_nodes(cells) if p["surface_only"] and cells is not None else None
    locations = _locations(p, fb, nodes, notes)
    rev_hz = mech.revolution_hz
    span = p["cycle_deg"] * p["cycles"]
    t_min = settled_from(ctx.params["dynamics"], 1.0 / rev_hz)
    sel = cycle_window(hist.crank_angle, span, hist.t, t_min)
    res = _assess(p, body, fb, hist, sel, S, nodes, locations, notes)
    ens = _ensemble(p, body, fb, members, t_min, span, S, nodes, locations, res)
    if mech.system.clearances and ens is None:
        warn("fatigue: the run has clearance joints and one trajectory: its safety factor is "
             "one sample of an impacting system, not a result; give dynamics.ensemble >= 3 "
             "for the spread over trajectories", notes)
    out = res.to_dict()
    if res.worst_location is not None and \
            out["locations"].get("elsewhere", {}).get("safety_factor", np.inf) \
            < out["worst_location_safety_factor"]:
        e = out["locations"]["elsewhere"]
        warn(f"fatigue: the lowest safety factor ({e['safety_factor']:.3g}) is at no named "
             f"location (point {np.round(e['point_m'], 4).tolist()} m): a keyway, a support or "
             f"interface artefact, or a fillet zone too narrow for the mesh", notes)
    lowest = ens["spread"]["min"] if ens else res.min_safety_factor
    t_sel = hist.t[sel]
    out.update(body=p["body"], body_file=body.info.get("file"),
               window={"t_start_s": float(t_sel[0]), "t_end_s": float(t_sel[-1]),
                       "cycles": p["cycles"], "cycle_deg": p["cycle_deg"],
                       "n_samples": int(sel.sum())},
               required_safety_factor=p["required_safety_factor"],
               passed=bool(lowest >= p["required_safety_factor"]),
               warnings=notes, arrays="fatigue.npz")
    if ens:
        out["ensemble"] = ens
    if ctx.figures:
        out["figures"] = _figures(res, fb, ctx.out_dir, p["body"], p["required_safety_factor"])
    out["summary"] = summary_line(out)
    res.save(ctx.out_dir / "fatigue.npz")
    ctx.products[SECTION] = res
    return json_safe(out)


def json_safe(obj):
    """``obj`` with every infinite number (a safety factor where the stress does not vary and
    has no mean) as None: results.json refuses non-finite values; ``null`` reads "infinite"."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, (float, np.floating)) and math.isinf(obj):
        return None
    return obj


def _figures(res, fb, out_dir, body: str, required: float) -> list[str]:
    names = []
    res.plot_safety(out_dir / "fatigue_haigh.png", required=required)
    names.append("fatigue_haigh.png")
    if fb.mesh_points is not None and fb.mesh_cells is not None:
        res.plot_crank(fb.mesh_points, fb.mesh_cells, out_dir / "fatigue_crank.png",
                       title=f"{body}: fatigue safety factor, min {res.min_safety_factor:.3g}"
                             + (f"; worst {res.worst_location.replace('_', ' ')}"
                                if res.worst_location else ""))
        names.append("fatigue_crank.png")
    return names


def summary_line(out: dict) -> str:
    """One line: the worst location and its safety factor, the lowest anywhere, the required
    factor and the verdict, the criterion and the strength; an ensemble's spread."""
    from ..report.quantity import number

    worst = out["worst_location"]
    text = f"{out['body']}: "
    if worst:
        text += f"worst {worst.replace('_', ' ')} n = {number(out['worst_location_safety_factor'], 3)}, "
    text += f"lowest anywhere {number(out['min_safety_factor'], 3)}"
    ens = out.get("ensemble")
    if ens:
        s = ens["spread"]
        text += (f"; over {ens['n_trajectories']} trajectories the lowest ranges "
                 f"{number(s['min'], 3)}–{number(s['max'], 3)} (mean {number(s['mean'], 3)})")
    w = out["window"]
    text += (f" ({out['criterion']['rule']}, S_e {number(out['fatigue_strength_pa'] / 1e6, 4)} "
             f"MPa, last {w['cycles']} x {w['cycle_deg']:g} deg); required "
             f"{number(out['required_safety_factor'], 3)}: "
             f"{'passes' if out['passed'] else 'FAILS'}")
    return text


__all__ = ["REQUIRED_SAFETY_FACTOR", "SCHEMA", "cycle_window", "factors_of", "run",
           "summary_line", "validate"]
