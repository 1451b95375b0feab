"""Scene stage ``[dynamics]``: crank-linkage dynamics with clearance joints.

Runs the mechanism with its clearance joints (and, by default, its ideal-joint twin as the
reference), writes ``dynamics.npz`` with every time history, PNG figures, and returns the summary
numbers: peaks, impact statistics, main-bearing force per order, drive torque and power, the
energy balance and the seed-001 contact-loss indicator.
"""

from __future__ import annotations

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

    try:
        if p is not None and p["mechanism"] == "four_bar":
            from ..flexible.build import link_body
            from .flexstage import body_keys, link_length

            with body_keys(key):
                link_body(spec["file"], spec, link_length(p, key), key)
            return
        load_flexible_body(spec["file"], key, n_modes=spec["n_modes"], cutoff_hz=spec["cutoff_hz"],
                           damping_ratio=spec["damping_ratio"])
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


def run(params: dict, ctx) -> dict:
    from dataclasses import replace

    from ...errors import warn
    from ...results import atomic_path
    from ..results.signals import (
        amplitude_spectrum,
        contact_durations,
        contact_loss_indicator,
        force_direction,
        impact_statistics,
        order_amplitudes,
    )
    from ..results.stats import converged_summary, statistics
    from ..results.validity import penetration_warning
    from ..run import timescales
    from ..run.simulate import key_outputs, simulate, tolerance_study
    from .build import build_mechanism, solver_settings

    p = params
    bodies = None
    from .keys import flexible_keys

    if flexible_keys(p):
        from .flexstage import make_bodies

        bodies = make_bodies(p, ctx.params.get("mechanism"))
    mech = _build(build_mechanism, p, ctx.params.get("mechanism"), bodies)
    rev_hz = mech.revolution_hz
    settings = solver_settings(p, 60.0 * rev_hz, flexible=bodies is not None)
    dt = p["output_step"] or 1.0 / (360.0 * rev_hz)
    t_end = p["end_time"]
    # contact time scales before the run: refuse what cannot finish within the budget, warn,
    # and let a failed run's advice name the key that limits the step
    scales = timescales.joint_time_scales(mech)
    settings = replace(settings, time_scales=tuple(scales))
    early_warnings = []
    if bodies is not None:
        from .flexstage import truncation_warnings

        for text in truncation_warnings(p, bodies):
            warn(text, into=early_warnings)
    from ...errors import scene_keys
    from ..run.budget import check as check_budget

    with scene_keys("dynamics"):  # refuse what cannot finish (contact.damping: ... -> dynamics.)
        for text in check_budget(mech, t_end, settings)[1]:
            warn(text, into=early_warnings)
    start_info = None
    mech.start = p["flexible"]["start"]  # simulate() leaves an "undeformed" start as built
    if bodies is not None and p["flexible"]["start"] == "quasi_static":
        start_info = mech.start_quasi_static()  # on the ideal-joint twin, as simulate() does
    elif bodies is not None and p["ramp_time"] == 0.0:
        text = _start_warning(mech, p, rev_hz)
        if text:
            warn(text, into=early_warnings)
    tol = p["energy_tolerance"]
    hist = simulate(mech, t_end, dt, settings, energy_tolerance=tol)
    ideal = None
    if p["run_ideal"] and mech.system.clearances:
        ideal = simulate(mech, t_end, dt, settings, ideal=True, energy_tolerance=tol)
    rigid = None
    if bodies is not None and p["run_rigid"]:
        from .flexstage import rigid_twins

        rigid_mech = _build(build_mechanism, p, ctx.params.get("mechanism"), rigid_twins(bodies),
                            twin=True)
        rigid_settings = replace(solver_settings(p, 60.0 * rev_hz), time_scales=tuple(scales))
        rigid = simulate(rigid_mech, t_end, dt, rigid_settings, energy_tolerance=tol)
    sel, n_rev, start_up = _window(hist, p, rev_hz)
    if start_up:
        warn(_start_up_warning(p, rev_hz), into=early_warnings)
    orders = list(range(13))
    res = {"mechanism": mech.kind, "speed_rpm": 60.0 * rev_hz, "revolution_hz": rev_hz,
           "end_time_s": t_end, "output_step_s": dt, "rhs_evals": hist.nfev,
           "integration_wall_time_s": hist.wall_time, "solver_method": settings.method}
    f = hist.main_bearing_force
    # peaks: in the results window (the start-up left out, as for every other number), the
    # samples and each contact's deepest point (an event: samples miss short impacts)
    tw = (float(hist.t[sel][0]), float(hist.t[sel][-1]))
    res["peak_window_s"] = list(tw)
    res["main_bearing_force_peak_n"] = hist.peak("main_bearing_force",
                                                 np.hypot(f[sel, 0], f[sel, 1]), None, *tw)
    mm = hist.main_bearing_moment
    res["main_bearing_moment_peak_nm"] = float(np.max(np.hypot(mm[sel, 0], mm[sel, 1])))
    if n_rev >= 1:
        amps = order_amplitudes(hist.t[sel], f[sel], rev_hz, orders)
        res["main_bearing_orders"] = orders
        res["main_bearing_order_amplitude_n"] = amps.tolist()  # rows: order; columns: x, y
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
    joints = {}
    res["warnings"] = early_warnings
    for cj in mech.system.clearances:
        d = hist.contact[cj.name]
        dur = contact_durations(hist.onsets[cj.name], hist.separations[cj.name])
        j = {"clearance_m": cj.clearance, "law": cj.law,
             "stiffness": float(cj.law_params["stiffness"]),
             "peak_contact_force_n": hist.peak("fn", d["fn"][sel], cj.name, *tw),
             "max_penetration_m": hist.peak("penetration",
                                            np.maximum(d["penetration"][sel], 0.0), cj.name, *tw),
             "contact_fraction": float(np.mean(d["penetration"][sel] > 0.0)),
             # largest |e| / c in the window; with an oil film, the thinnest film c (1 - eps)
             "eccentricity_ratio_max": float(np.max(np.hypot(d["ex"][sel], d["ey"][sel]))
                                             / cj.clearance),
             "contact_duration_median_s": float(np.median(dur)) if dur.size else None}
        j.update(impact_statistics(hist.onsets[cj.name], v_min=cj.v_impact_min))
        if dur.size and np.median(dur) < 2.0 * dt:
            warn(short_contact_warning(cj, float(np.median(dur)), dt), into=res["warnings"])
        # validity over the whole run, the start-up included: a law outside it there is too
        text = penetration_warning(cj, hist.peak("penetration",
                                                 np.maximum(d["penetration"], 0.0), cj.name),
                                   hist.peak("fn", d["fn"], cj.name),
                                   p["contact"]["E"], p["contact"]["nu"])
        if text:
            warn(text, into=res["warnings"])
        if ideal is not None:
            j["contact_loss"] = contact_loss_indicator(ideal.t[sel], ideal.joint_forces[cj.name][sel],
                                                       ideal.crank_angle[sel])
        if getattr(cj, "viscosity", None):
            j["min_film_thickness_m"] = max(cj.clearance * (1.0 - j["eccentricity_ratio_max"]),
                                            0.0)
        joints[cj.name] = j
    res["clearance_joints"] = joints
    # per-revolution statistics: what converges (a single trajectory's peak does not)
    v_min = {cj.name: cj.v_impact_min for cj in mech.system.clearances}
    res["statistics"] = statistics(hist, rev_hz, float(hist.t[sel][0]), v_min)
    if p["ensemble"] > 1:
        from ..run.ensemble import run_ensemble

        res["ensemble"] = run_ensemble(mech, res["statistics"], p["ensemble"], t_end, dt,
                                       settings, rev_hz, float(hist.t[sel][0]), v_min,
                                       energy_tolerance=tol)
    from ..run.ensemble import headlines

    res["headline"] = headlines(res["statistics"], res.get("ensemble"))
    if ideal is not None:  # the same window as the run with clearance
        fi = ideal.main_bearing_force[sel]
        res["ideal"] = {"main_bearing_force_peak_n": float(np.max(np.hypot(fi[:, 0], fi[:, 1]))),
                        "piston_acceleration_peak":
                            np.max(np.abs(ideal.piston_acceleration[sel]), axis=0).tolist()
                            if ideal.piston_acceleration.size else [],
                        "drive_power_mean_w": float(np.mean(ideal.drive_power[sel]))}
        ist = statistics(ideal, rev_hz, float(hist.t[sel][0]), v_min)
        res["ideal"]["main_bearing_per_rev_peak_n"] = ist["main_bearing_force"]["per_rev_peak"]["mean"]
        res["ideal"]["main_bearing_rms_n"] = ist["main_bearing_force"]["rms"]["mean"]
        for key, h in res["headline"].items():
            if key in res["ideal"]:
                h["ideal"] = res["ideal"][key]
    if bodies is not None:
        from .flexstage import flexible_results

        res["flexible"] = flexible_results(mech, hist, rigid, sel, rev_hz, bodies,
                                           warnings=res["warnings"])
        res["flexible"]["rigid_integration_wall_time_s"] = None if rigid is None else rigid.wall_time
        res["flexible"]["start"] = {"state": p["flexible"]["start"], **(start_info or {})}
        from ..flexible.stepbound import step_bound
        from .flexstage import flexible_bodies_of

        bound = step_bound(flexible_bodies_of(mech), settings.method, t_end, hist.nfev,
                           key_of=_flexible_key)
        if bound is not None:
            res["flexible"]["step_bound"] = bound
    study = None
    if p["solver"]["study_rtols"]:
        rt = sorted(set(p["solver"]["study_rtols"]) | {settings.rtol / 10})
        study = tolerance_study(mech, t_end, dt, rt, t_start=float(hist.t[sel][0]), base=settings,
                                ensemble=res.get("ensemble"))
        res["tolerance_study"] = study
    arrays = hist.arrays()
    if rigid is not None:
        arrays.update({f"rigid_{k}": v for k, v in rigid.arrays().items()})
    if ideal is not None:
        arrays.update({f"ideal_{k}": v for k, v in ideal.arrays().items()})
        for cj in mech.system.clearances:
            beta, rate = force_direction(ideal.t, ideal.joint_forces[cj.name])
            arrays[f"ideal_force_direction_{cj.name}"] = beta
            arrays[f"ideal_force_direction_rate_{cj.name}"] = rate
    spec = None
    if n_rev >= 1:
        spec = amplitude_spectrum(hist.t[sel], hist.main_bearing_force[sel], rev_hz)
        arrays["spectrum_frequency_hz"] = spec.frequency_hz
        arrays["spectrum_order"] = spec.order
        arrays["spectrum_main_bearing_amplitude"] = spec.amplitude
    out = ctx.out_dir
    with atomic_path(out / "dynamics.npz") as tmp:
        np.savez_compressed(tmp, **arrays)
    res["arrays"] = "dynamics.npz"
    if ctx.figures:
        res["figures"] = _figures(hist, ideal, mech, sel, study, out, spec)
        if bodies is not None:
            from ..results.flexplots import flexible_figures

            res["flexible"]["figures"] = flexible_figures(hist, rigid, mech, sel, out)
            res["figures"] += res["flexible"]["figures"]
    k = key_outputs(hist, rev_hz, float(hist.t[sel][0]))
    n_imp = sum(j["impact_count"] for j in joints.values())
    if mech.pistons:
        motion = f"piston accel peak {k['peak_piston_acceleration']:.4g} m/s^2"
    else:
        motion = f"rocker accel peak {res['angular_acceleration_peak'].get('rocker', 0.0):.4g} rad/s^2"
    from ...report.quantity import number, quantity  # never e+NN in a summary (issue 25 #15)

    if "ensemble" in res and n_rev >= 1 and study is None:
        # one value per quantity, with the ensemble's spread where the trajectories disagree
        # (with a tolerance study: its convergence summary over the ensemble, below)
        from ..run.ensemble import headline_text as ensemble_text

        headline_text = ensemble_text(res["headline"], n_rev)
    elif mech.system.clearances and res["statistics"]["window"]["n_revolutions"] >= 2:
        # a clearance run: one trajectory's peak is not a result, the per-revolution mean is
        headline_text = converged_summary(res["statistics"], study, settings.rtol,
                                          res.get("ensemble", {}).get("n_trajectories"))
    else:
        headline_text = (f"main-bearing peak {quantity(res['main_bearing_force_peak_n'], 'N')}, "
                         f"{motion}")
    res["summary"] = (f"{mech.kind} at {60.0 * rev_hz:g} rpm, {t_end:g} s: {headline_text}, "
                      f"{n_imp} impacts, energy balance "
                      f"{number(res['energy_balance_error'], 2)}")
    for name, j in joints.items():
        if "min_film_thickness_m" in j:
            res["summary"] += (f"; {name} oil film: thinnest {1e6 * j['min_film_thickness_m']:.3g}"
                               f" um (eccentricity ratio {j['eccentricity_ratio_max']:.3g})")
    if "ensemble" in res:
        from ...report.quantity import quantity_range  # 15.99–34.56 kN, not 1.599e+04-3.456e+04

        e = res["headline"]["main_bearing_per_rev_peak_n"]
        res["summary"] += (f"; the {p['ensemble']} trajectories (started 10⁻¹² apart) range "
                           f"{quantity_range(e['min'], e['max'], 'N')} in that peak")
    if bodies is not None:
        names = ", ".join(f"{n} {d['n_modes']} modes" for n, d in res["flexible"]["bodies"].items())
        res["summary"] += f"; flexible: {names}"
        from ..results.validity import validity_summary

        res["summary"] += validity_summary(res["flexible"]["bodies"])
        cmp = res["flexible"].get("rigid", {}).get("main_bearing")
        if cmp:
            res["summary"] += (f"; main bearing flexible vs rigid: peak {cmp['peak_n']:.4g} vs "
                               f"{cmp['rigid_peak_n']:.4g} N, RMS of the difference "
                               f"{100 * cmp['relative_difference_rms']:.2g} % of the rigid RMS")
        sb = res["flexible"].get("step_bound")
        if sb and sb["bound"]:
            res["summary"] += (f"; {sb['method']} steps ({sb['mean_step_s']:.2g} s) bound by the "
                               f"{sb['frequency_hz']:.4g} Hz mode of {sb['body']}")
    ctx.products[SECTION] = {"mechanism": mech, "history": hist, "ideal": ideal, "rigid": rigid}
    return res


def _flexible_key(body_name: str) -> str:
    """The ``[dynamics.flexible]`` table of a flexible body (for advice)."""
    from .flexstage import flexible_key

    return flexible_key(body_name)


def _figures(hist, ideal, mech, sel, study, out, spec=None):
    """Write the PNG figures; ``spec``: the main-bearing spectrum if already computed."""
    from ..results import plots
    from ..results.signals import amplitude_spectrum

    figs = []
    rev = mech.revolution_hz
    if spec is None:
        spec = amplitude_spectrum(hist.t[sel], hist.main_bearing_force[sel], rev)
    ispec = None if ideal is None else amplitude_spectrum(ideal.t[sel],
                                                          ideal.main_bearing_force[sel], rev)
    window = (float(hist.t[sel][0]), float(hist.t[sel][-1]))  # shaded on every time plot
    figs.append(plots.plot_bearing_force(hist, spec, out / "dynamics_main_bearing.png", ispec,
                                         ideal, window))
    if hist.piston_acceleration.shape[1]:
        figs.append(plots.plot_piston(hist, ideal, out / "dynamics_piston.png", window=window))
    if mech.system.clearances:
        cl = {cj.name: cj.clearance for cj in mech.system.clearances}
        figs.append(plots.plot_orbit(hist, cl, out / "dynamics_orbit.png"))
        figs.append(plots.plot_contact(hist, out / "dynamics_contact.png", ideal, window))
    figs.append(plots.plot_drive(hist, ideal, out / "dynamics_drive.png", window))
    figs.append(plots.plot_energy(hist, out / "dynamics_energy.png", ideal, window))
    if study is not None:
        figs.append(plots.plot_study(study, out / "dynamics_tolerance_study.png"))
    return [f.name for f in figs]
