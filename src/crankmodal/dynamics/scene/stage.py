"""Scene stage ``[dynamics]``: crank-linkage dynamics with clearance joints.

Runs the mechanism with its clearance joints (and, by default, its ideal-joint twin as the
reference), and returns the summary numbers: peaks, impact statistics, main-bearing force per
order, drive torque and power, the energy balance and the seed-001 contact-loss indicator. The
runs become a :class:`~crankmodal.dynamics.results.result.DynamicsResult`, which draws the PNG
figures and saves ``dynamics.npz`` (every time history). :func:`run` reads as its steps:
:func:`_model`, :func:`_runs`, :func:`_run_numbers`, :func:`_joint_results`,
:func:`_statistics`, :func:`_flexible_results`, :func:`_tolerance_study`, :func:`_result`,
figures, :func:`_summary_line`, save.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

SECTION = "dynamics"
REQUIRES = ()


def validate(raw: dict, scene) -> dict:
    from pathlib import Path

    from ...errors import SceneError
    from .keys import check_speed, flexible_keys, validate_section

    p = validate_section(raw)
    for key in flexible_keys(p):
        spec = p["flexible"][key]
        if spec["file"] is not None:
            path = scene.resolve(spec["file"]) if scene is not None else Path(spec["file"])
            if not path.is_file():
                raise SceneError(f"dynamics.flexible.{key}.file: no file {str(path)!r}")
            spec["file"] = str(path)
            _probe_flexbody(key, spec, p)
    if p["from_mechanism"] and (scene is None or "mechanism" not in scene.sections):
        raise SceneError("dynamics.from_mechanism: needs a [mechanism] section in the scene")
    from .trains import check_arrangement

    check_arrangement(p, scene)  # throws and firing order against the machine, before any run
    if p["speed_rpm"] is not None:
        check_speed(p, p["speed_rpm"])
    elif p["from_mechanism"]:  # [mechanism] has validated its own speed_rpm before this
        speed = scene.sections["mechanism"].get("speed_rpm")
        if isinstance(speed, (int, float)) and not isinstance(speed, bool):
            check_speed(p, speed, "mechanism.speed_rpm")
    return p


def _build(build, p, mechanism_params, bodies, twin=False):
    """``build(p, mechanism_params, bodies)``, redundant joints relabelled with the scene key."""
    from ...errors import SceneError
    from ..model.mechanisms import RedundantJoints

    try:
        return build(p, mechanism_params, bodies)
    except RedundantJoints as exc:
        if bodies and bodies.get("crank") is not None:
            n = len(bodies["crank"][1]["mains"])
            if twin:
                raise SceneError(f"dynamics.run_rigid: the rigid twin of a crank on {n} main "
                                 f"journals is statically indeterminate ({exc}); set "
                                 "run_rigid = false") from None
            raise SceneError(f"dynamics.flexible.crank.n_modes: too few elastic modes for a "
                             f"crank on {n} main journals ({exc}); keep more modes") from None
        raise SceneError(f"dynamics: {exc}") from None


def _start_warning(mech, p, rev_hz) -> str | None:
    """A flexible run started at full speed: the undeformed bodies ring through their modes."""
    slow = None
    for b in mech.system.bodies:
        k = getattr(b, "n_elastic", 0)
        if k:
            w, z = 2 * np.pi * b.frequencies_hz[:k], b.zeta[:k]
            t = float(np.max(5.0 / np.maximum(z * w, 1e-300)))  # e^-5 of every kept mode
            slow = t if slow is None else max(slow, t)
    if slow is None:
        return None
    t0 = p["spectrum_start"] if p["spectrum_start"] is not None else 1.0 / rev_hz
    if slow <= t0:
        return None
    return (f"dynamics.ramp_time: the flexible bodies start undeformed at full speed; the "
            f"start-up rings through their modes and decays to e^-5 only after {slow:.3g} s "
            f"(modal damping), after the results window opens at {t0:.3g} s; give a ramp "
            f"(e.g. ramp_time = 0.1), a later spectrum_start or flexible.start = "
            f"'quasi_static'")


def _probe_flexbody(key: str, spec: dict, p=None) -> None:
    """Read a given flexbody file before any stage runs: format, version, modes asked (and for
    a four-bar link its interfaces and their distance)."""
    from ...errors import InputFileError, SceneError
    from ..flexible.body import load_flexible_body
    from .flexstage import body_keys

    try:
        if p is not None and p["mechanism"] == "four_bar":
            from ..flexible.build import link_body
            from .flexstage import link_length

            with body_keys(key):
                link_body(spec["file"], spec, link_length(p, key), key)
            return
        with body_keys(key):
            load_flexible_body(spec["file"], key, n_modes=spec["n_modes"],
                               cutoff_hz=spec["cutoff_hz"], damping_ratio=spec["damping_ratio"])
    except (SceneError, InputFileError) as exc:
        if str(exc).startswith("dynamics."):
            raise
        raise type(exc)(f"dynamics.flexible.{key}: {exc}") from None


def short_contact_warning(cj, duration: float, dt: float) -> str:
    """The warning for contacts shorter than two output steps: the sampled histories miss them."""
    from ..laws.contact import cylinder_stiffness

    text = (f"dynamics: the contacts of joint {cj.name!r} last {duration:.2g} s (median), "
            f"under two output steps ({dt:.2g} s): the sampled force histories and the "
            f"main-bearing spectrum miss the impacts (the peaks in results.json are taken at "
            f"each contact's deepest point); lower dynamics.output_step below {duration / 4:.2g} s")
    K = cj.normal.hertz_stiffness  # N/m^1.5, or None: not comparable with steel's value
    if K is not None:
        r = cj.journal_radius
        k_steel = float(cylinder_stiffness(r, r + cj.clearance, 2.1e11, 0.3, 2.1e11, 0.3))
        if K > 100.0 * k_steel:
            text += (f", or check contact.stiffness = {K:.3g} N/m^1.5: {K / k_steel:.2g} times "
                     f"a steel journal in a steel bore of these radii ({k_steel:.3g})")
    return text


def _window(hist, p, rev_hz):
    """Sample mask of the results window (:func:`.stats.results_window`: whole revolutions
    after the start-up), its number of revolutions and whether it had to include the start-up."""
    from ..results.stats import results_window

    t0, t1, n_rev, start_up = results_window(hist.t, p["ramp_time"], p["spectrum_start"], rev_hz)
    return (hist.t >= t0 - 1e-12) & (hist.t <= t1 + 1e-12), n_rev, start_up


def _start_up_warning(p, rev_hz) -> str:
    """The results window had to open at the ramp's end: the run is too short."""
    need = p["ramp_time"] + 2.0 / rev_hz
    return (f"dynamics.end_time: {p['end_time']:g} s leaves no whole revolution after the "
            f"ramp ({p['ramp_time']:g} s) and one settling revolution, so the results window "
            f"(peaks, spectrum, statistics) opens at {p['ramp_time']:g} s and includes the "
            f"start-up transient; give end_time >= {need:.4g} s or a spectrum_start")


@dataclass
class _Model:
    """The built mechanism and what its runs share (stage-internal)."""

    mech: object
    bodies: dict | None  # the flexible bodies' builds (None: a rigid run)
    settings: object  # SolverSettings, the contact time scales in
    rev_hz: float  # Hz
    dt: float  # output step, s
    t_end: float  # s
    warnings: list  # texts, in the order issued
    start_info: dict | None  # the quasi-static start's numbers


@dataclass
class _Runs:
    """The run with clearance and its twins (stage-internal)."""

    hist: object  # History
    ideal: object = None  # History of the ideal-joint twin
    rigid: object = None  # History of the rigid twin of a flexible run
    members: list = None  # Histories of the ensemble's perturbed trajectories (dynamics.ensemble)


def run(params: dict, ctx) -> dict:
    """Run the ``[dynamics]`` section: build, integrate (with the ideal and rigid twins),
    summarise, draw and save; returns the results.json entry (see :class:`DynamicsResult`)."""
    from ...errors import warn
    from .build import scene_words

    p = params
    model = _model(p, ctx)
    with scene_words():  # the core's advice names its arguments; a scene user changes keys
        runs = _runs(model, p, ctx)
    sel, n_rev, start_up = _window(runs.hist, p, model.rev_hz)
    if start_up:
        warn(_start_up_warning(p, model.rev_hz), into=model.warnings)
    res = _run_numbers(model, runs.hist, sel, n_rev)
    res["warnings"] = model.warnings
    res["clearance_joints"] = _joint_results(model, runs, sel, p)
    from ..results.journals import train_results  # multi-throw trains: journals, torsion

    res.update(train_results(model.mech, runs.hist, float(runs.hist.t[sel][0])))
    _statistics(res, model, runs, sel, p)
    if model.bodies is not None:
        res["flexible"] = _flexible_results(model, runs, sel, p, res["warnings"])
    study = _tolerance_study(res, model, runs.hist, sel, p)
    result = _result(model, runs, sel, n_rev, res)
    res["arrays"] = "dynamics.npz"
    if ctx.figures:
        res["figures"], flexible = result.figures(ctx.out_dir)
        if model.bodies is not None:
            res["flexible"]["figures"] = flexible
    res["summary"] = _summary_line(res, model, runs.hist, sel, n_rev, study, p)
    result.save(ctx.out_dir / "dynamics.npz")
    ctx.products[SECTION] = {"mechanism": model.mech, "history": runs.hist, "ideal": runs.ideal,
                             "rigid": runs.rigid, "result": result, "members": runs.members}
    return dict(res)  # the runner adds its wall_time_s to the copy, not to the saved summary


def _model(p: dict, ctx) -> _Model:
    """Build the mechanism (its flexible bodies first) and its solver settings; refuse what
    cannot finish within the run budget, warn of truncated modes, set the start."""
    from ...errors import scene_keys, warn
    from ..run import timescales
    from ..run.budget import check as check_budget
    from .build import build_mechanism, relabel, scene_words, solver_settings
    from .keys import flexible_keys

    bodies = None
    if flexible_keys(p):
        from .flexstage import make_bodies

        bodies = make_bodies(p, ctx.params.get("mechanism"))
    mech = _build(build_mechanism, p, ctx.params.get("mechanism"), bodies)
    rev_hz = mech.revolution_hz
    settings = solver_settings(p, 60.0 * rev_hz, flexible=bodies is not None)
    # contact time scales before the run: refuse what cannot finish within the budget, warn,
    # and let a failed run's advice name the key that limits the step
    settings = replace(settings, time_scales=tuple(timescales.joint_time_scales(mech)))
    model = _Model(mech, bodies, settings, rev_hz, p["output_step"] or 1.0 / (360.0 * rev_hz),
                   p["end_time"], [], None)
    if bodies is not None:
        from .flexstage import truncation_warnings

        for text in truncation_warnings(p, bodies):
            warn(text, into=model.warnings)
    # refuse what cannot finish: the core names the law's parameter (law.damping), the scene
    # its key (dynamics.contact.damping), in the advice too
    with scene_words(), scene_keys("dynamics", {"law": "contact"}):
        for text in check_budget(mech, model.t_end, settings)[1]:
            warn(relabel(text), into=model.warnings)
    mech.start = p["flexible"]["start"]  # simulate() leaves an "undeformed" start as built
    if bodies is not None and p["flexible"]["start"] == "quasi_static":
        model.start_info = mech.start_quasi_static()  # on the ideal-joint twin, as simulate() does
    elif bodies is not None and p["ramp_time"] == 0.0:
        text = _start_warning(mech, p, rev_hz)
        if text:
            warn(text, into=model.warnings)
    return model


def _runs(model: _Model, p: dict, ctx) -> _Runs:
    """Integrate the run with clearance, its ideal-joint twin (``run_ideal``) and, with
    flexible bodies, its rigid twin (``run_rigid``)."""
    from ..run.simulate import simulate
    from .build import build_mechanism, solver_settings

    mech, t_end, dt, tol = model.mech, model.t_end, model.dt, p["energy_tolerance"]
    runs = _Runs(simulate(mech, t_end, dt, model.settings, energy_tolerance=tol),
                 members=[] if "fatigue" in ctx.scene.sections else None)  # kept for [fatigue]
    if p["run_ideal"] and mech.system.clearances:
        runs.ideal = simulate(mech, t_end, dt, model.settings, ideal=True, energy_tolerance=tol)
    if model.bodies is not None and p["run_rigid"]:
        from .flexstage import rigid_twins

        rigid_mech = _build(build_mechanism, p, ctx.params.get("mechanism"),
                            rigid_twins(model.bodies), twin=True)
        settings = replace(solver_settings(p, 60.0 * model.rev_hz),
                           time_scales=model.settings.time_scales)
        runs.rigid = simulate(rigid_mech, t_end, dt, settings, energy_tolerance=tol)
    return runs


def _run_numbers(model: _Model, hist, sel, n_rev: int) -> dict:
    """The run's settings and cost, and its peaks, orders, drive and energy over the results
    window ``sel`` (the start-up left out). Peaks: the samples and each contact's deepest
    point (an event: samples miss short impacts)."""
    from ..results.signals import order_amplitudes

    rev_hz, f = model.rev_hz, hist.main_bearing_force
    res = {"mechanism": model.mech.kind, "speed_rpm": 60.0 * rev_hz, "revolution_hz": rev_hz,
           "end_time_s": model.t_end, "output_step_s": model.dt, "rhs_evals": hist.nfev,
           "integration_wall_time_s": hist.wall_time, "solver_method": model.settings.method}
    tw = (float(hist.t[sel][0]), float(hist.t[sel][-1]))
    res["peak_window_s"] = list(tw)
    res["main_bearing_force_peak_n"] = hist.peak("main_bearing_force",
                                                 np.hypot(f[sel, 0], f[sel, 1]), None, *tw)
    mm = hist.main_bearing_moment
    res["main_bearing_moment_peak_nm"] = float(np.max(np.hypot(mm[sel, 0], mm[sel, 1])))
    if n_rev >= 1:
        orders = list(range(13))
        res["main_bearing_orders"] = orders
        res["main_bearing_order_amplitude_n"] = order_amplitudes(  # rows: order; columns: x, y
            hist.t[sel], f[sel], rev_hz, orders).tolist()
    res["piston_acceleration_peak"] = hist.peak("piston_acceleration",
                                                hist.piston_acceleration[sel], None,
                                                *tw).tolist()
    res["angular_acceleration_peak"] = {name: float(np.max(np.abs(v[sel])))
                                        for name, v in hist.angular_acceleration.items()}
    res["drive_torque_peak_nm"] = float(np.max(np.abs(hist.drive_torque[sel])))
    res["drive_power_mean_w"] = float(np.mean(hist.drive_power[sel]))
    res["drive_power_peak_w"] = float(np.max(np.abs(hist.drive_power[sel])))
    res["energy"] = {k: float(v[-1]) for k, v in hist.energy.items()}
    res["energy_balance_error"] = hist.energy_error()
    res["constraint_drift_max"] = float(hist.constraint_drift.max())
    return res


def _joint_results(model: _Model, runs: _Runs, sel, p: dict) -> dict:
    """Per clearance joint: peaks, contact fraction, eccentricity, impacts, the ideal twin's
    contact-loss indicator, the thinnest oil film; warns (into ``model.warnings``) of contacts
    shorter than two output steps and of laws outside their validity."""
    from ...errors import warn
    from ..results.signals import contact_durations, contact_loss_indicator, impact_statistics
    from ..results.validity import penetration_warning
    from .build import CONTACT_WORDS

    hist, ideal = runs.hist, runs.ideal
    tw = (float(hist.t[sel][0]), float(hist.t[sel][-1]))
    joints = {}
    for cj in model.mech.system.clearances:
        d = hist.contact[cj.name]
        dur = contact_durations(hist.onsets[cj.name], hist.separations[cj.name])
        j = {"clearance_m": cj.clearance, "law": cj.law.name,
             "stiffness": float(cj.law.stiffness),
             "peak_contact_force_n": hist.peak("fn", d["fn"][sel], cj.name, *tw),
             "max_penetration_m": hist.peak("penetration",
                                            np.maximum(d["penetration"][sel], 0.0), cj.name, *tw),
             "contact_fraction": float(np.mean(d["penetration"][sel] > 0.0)),
             # largest |e| / c in the window; with an oil film, the thinnest film c (1 - eps)
             "eccentricity_ratio_max": float(np.max(np.hypot(d["ex"][sel], d["ey"][sel]))
                                             / cj.clearance),
             "contact_duration_median_s": float(np.median(dur)) if dur.size else None}
        j.update(impact_statistics(hist.onsets[cj.name], v_min=cj.v_impact_min))
        if dur.size and np.median(dur) < 2.0 * model.dt:
            warn(short_contact_warning(cj, float(np.median(dur)), model.dt), into=model.warnings)
        # validity over the whole run, the start-up included: a law outside it there is too
        text = penetration_warning(cj, hist.peak("penetration",
                                                 np.maximum(d["penetration"], 0.0), cj.name),
                                   hist.peak("fn", d["fn"], cj.name),
                                   p["contact"]["E"], p["contact"]["nu"], CONTACT_WORDS)
        if text:
            warn(text, into=model.warnings)
        if ideal is not None:
            j["contact_loss"] = contact_loss_indicator(
                ideal.t[sel], ideal.joint_forces[cj.name][sel], ideal.crank_angle[sel])
        if getattr(cj, "viscosity", None):
            j["min_film_thickness_m"] = max(cj.clearance * (1.0 - j["eccentricity_ratio_max"]),
                                            0.0)
        joints[cj.name] = j
    return joints


def _revolutions_per_cycle(mech) -> int:
    """Revolutions of the machine's working cycle: its gas tables' period (a four-stroke
    engine's 720 degrees: 2), 1 without a tabulated gas force."""
    from ..model.loads import PistonLoads

    periods = [ld.gas_force.table[2] for ld in mech.system.loads
               if type(ld) is PistonLoads and getattr(ld.gas_force, "table", None) is not None]
    return max([int(round(per / (2.0 * np.pi))) for per in periods] or [1])


def _statistics(res: dict, model: _Model, runs: _Runs, sel, p: dict) -> None:
    """Per-revolution statistics (what converges: a single trajectory's peak does not), the
    ensemble's spread, the headline numbers and the ideal twin's, into ``res``."""
    from ..results.stats import statistics
    from ..run.ensemble import headlines, run_ensemble

    hist, rev_hz = runs.hist, model.rev_hz
    t0 = float(hist.t[sel][0])
    v_min = {cj.name: cj.v_impact_min for cj in model.mech.system.clearances}
    res["statistics"] = statistics(hist, rev_hz, t0, v_min, _revolutions_per_cycle(model.mech))
    if p["ensemble"] > 1:
        res["ensemble"] = run_ensemble(model.mech, res["statistics"], p["ensemble"], model.t_end,
                                       model.dt, model.settings, rev_hz, t0, v_min,
                                       energy_tolerance=p["energy_tolerance"],
                                       histories=runs.members)
    res["headline"] = headlines(res["statistics"], res.get("ensemble"))
    if runs.ideal is None:
        return
    ideal = runs.ideal  # over the same window as the run with clearance
    fi = ideal.main_bearing_force[sel]
    res["ideal"] = {"main_bearing_force_peak_n": float(np.max(np.hypot(fi[:, 0], fi[:, 1]))),
                    "piston_acceleration_peak":
                        np.max(np.abs(ideal.piston_acceleration[sel]), axis=0).tolist()
                        if ideal.piston_acceleration.size else [],
                    "drive_power_mean_w": float(np.mean(ideal.drive_power[sel]))}
    ist = statistics(ideal, rev_hz, t0, v_min)
    res["ideal"]["main_bearing_per_rev_peak_n"] = ist["main_bearing_force"]["per_rev_peak"]["mean"]
    res["ideal"]["main_bearing_rms_n"] = ist["main_bearing_force"]["rms"]["mean"]
    for key, h in res["headline"].items():
        if key in res["ideal"]:
            h["ideal"] = res["ideal"][key]


def _flexible_results(model: _Model, runs: _Runs, sel, p: dict, warnings: list) -> dict:
    """The flexible bodies' results: modes kept, validity, flexible against the rigid twin,
    the start and the step bound of their modes."""
    from ..flexible.stepbound import step_bound
    from .flexstage import flexible_bodies_of, flexible_results

    out = flexible_results(model.mech, runs.hist, runs.rigid, sel, model.rev_hz, model.bodies,
                           warnings=warnings)
    out["rigid_integration_wall_time_s"] = None if runs.rigid is None else runs.rigid.wall_time
    out["start"] = {"state": p["flexible"]["start"], **(model.start_info or {})}
    bound = step_bound(flexible_bodies_of(model.mech), model.settings.method, model.t_end,
                       runs.hist.nfev, key_of=_flexible_key)
    if bound is not None:
        out["step_bound"] = bound
    return out


def _tolerance_study(res: dict, model: _Model, hist, sel, p: dict) -> dict | None:
    """The tolerance study (``solver.study_rtols``, and a tenth of ``rtol``) into ``res``."""
    from ..run.simulate import tolerance_study

    if not p["solver"]["study_rtols"]:
        return None
    rt = sorted(set(p["solver"]["study_rtols"]) | {model.settings.rtol / 10})
    res["tolerance_study"] = tolerance_study(model.mech, model.t_end, model.dt, rt,
                                             t_start=float(hist.t[sel][0]), base=model.settings,
                                             ensemble=res.get("ensemble"))
    return res["tolerance_study"]


def _result(model: _Model, runs: _Runs, sel, n_rev: int, res: dict):
    """The :class:`DynamicsResult` of the runs: ``res`` its summary, the main-bearing spectrum
    over the window and the direction of each ideal pin's force."""
    from ..results.result import DynamicsResult, MachineInfo
    from ..results.signals import amplitude_spectrum, force_direction

    hist = runs.hist
    spec = None
    if n_rev >= 1:
        spec = amplitude_spectrum(hist.t[sel], hist.main_bearing_force[sel], model.rev_hz)
    directions = {}
    if runs.ideal is not None:
        directions = {cj.name: force_direction(runs.ideal.t, runs.ideal.joint_forces[cj.name])
                      for cj in model.mech.system.clearances}
    return DynamicsResult(history=hist, machine=MachineInfo.of(model.mech),
                          window_s=tuple(res["peak_window_s"]), summary=res, ideal=runs.ideal,
                          rigid=runs.rigid, spectrum=spec, ideal_force_direction=directions)


def _summary_line(res: dict, model: _Model, hist, sel, n_rev: int, study, p: dict) -> str:
    """The one-line summary: the headline numbers (the ensemble's or per-revolution means for
    a clearance run, peaks otherwise), impacts, energy balance, oil films, flexible bodies."""
    from ...report.quantity import number, quantity  # never e+NN in a summary (issue 25 #15)
    from ..results.stats import converged_summary
    from ..run.simulate import key_outputs

    mech, rev_hz = model.mech, model.rev_hz
    if "ensemble" in res and n_rev >= 1 and study is None:
        # one value per quantity, with the ensemble's spread where the trajectories disagree
        # (with a tolerance study: its convergence summary over the ensemble, below)
        from ..run.ensemble import headline_text as ensemble_text

        headline_text = ensemble_text(res["headline"], n_rev)
    elif mech.system.clearances and res["statistics"]["window"]["n_revolutions"] >= 2:
        # a clearance run: one trajectory's peak is not a result, the per-revolution mean is
        headline_text = converged_summary(res["statistics"], study, model.settings.rtol,
                                          res.get("ensemble", {}).get("n_trajectories"))
    else:
        k = key_outputs(hist, rev_hz, float(hist.t[sel][0]))
        if mech.pistons:
            motion = f"piston accel peak {k['peak_piston_acceleration']:.4g} m/s^2"
        else:
            motion = (f"rocker accel peak {res['angular_acceleration_peak'].get('rocker', 0.0):.4g}"
                      f" rad/s^2")
        headline_text = (f"main-bearing peak {quantity(res['main_bearing_force_peak_n'], 'N')}, "
                         f"{motion}")
    n_imp = sum(j["impact_count"] for j in res["clearance_joints"].values())
    text = (f"{mech.kind} at {60.0 * rev_hz:g} rpm, {model.t_end:g} s: {headline_text}, "
            f"{n_imp} impacts, energy balance {number(res['energy_balance_error'], 2)}")
    for name, j in res["clearance_joints"].items():
        if "min_film_thickness_m" in j:
            text += (f"; {name} oil film: thinnest {1e6 * j['min_film_thickness_m']:.3g}"
                     f" um (eccentricity ratio {j['eccentricity_ratio_max']:.3g})")
    if "ensemble" in res:
        from ...report.quantity import quantity_range  # 15.99–34.56 kN, not 1.599e+04-3.456e+04

        e = res["headline"]["main_bearing_per_rev_peak_n"]
        text += (f"; the {p['ensemble']} trajectories (started 10⁻¹² apart) range "
                 f"{quantity_range(e['min'], e['max'], 'N')} in that peak")
    if model.bodies is not None:
        text += _flexible_summary(res["flexible"])
    return text


def _flexible_summary(flex: dict) -> str:
    """The summary's flexible part: modes kept, validity, flexible against rigid, step bound."""
    from ..results.validity import validity_summary

    names = ", ".join(f"{n} {d['n_modes']} modes" for n, d in flex["bodies"].items())
    text = f"; flexible: {names}" + validity_summary(flex["bodies"])
    cmp = flex.get("rigid", {}).get("main_bearing")
    if cmp:
        text += (f"; main bearing flexible vs rigid: peak {cmp['peak_n']:.4g} vs "
                 f"{cmp['rigid_peak_n']:.4g} N, RMS of the difference "
                 f"{100 * cmp['relative_difference_rms']:.2g} % of the rigid RMS")
    sb = flex.get("step_bound")
    if sb and sb["bound"]:
        text += (f"; {sb['method']} steps ({sb['mean_step_s']:.2g} s) bound by the "
                 f"{sb['frequency_hz']:.4g} Hz mode of {sb['body']}")
    return text


def _flexible_key(body_name: str) -> str:
    """The ``[dynamics.flexible]`` table of a flexible body (for advice)."""
    from .flexstage import flexible_key

    return flexible_key(body_name)
