"""The report of a whole scene: one section per stage that ran, each with its verdict.

Every function here reads a stage's results as written to ``results.json`` (plain JSON types,
file names relative to the output folder) and appends blocks to a
:class:`~crankmodal.report.modal_report.Report`: the stage's one-line ``summary`` and its
``warnings`` as the verdict, a table of its key numbers, and every figure the stage lists under
``figures`` (or ``files``) — generically, so a stage that draws a new figure shows it in the
report without a change here. A nested block with its own ``figures`` list (e.g.
``dynamics.flexible``) becomes a subsection. Nothing heavy is imported.
"""

from __future__ import annotations

from pathlib import Path

from .modal_report import _MIME, Report
from .quantity import percent, quantities, quantity, quantity_as, quantity_range

#: sections drawn by :func:`crankmodal.report.modal_report.modal_blocks` (the FE part's modes)
MODAL_SECTIONS = ("geometry", "material", "modal")

TITLES = {
    "geometry": "Part and mesh",
    "material": "Material",
    "modal": "Free and supported modes",
    "static": "Static stress",
    "reduction": "Craig–Bampton reduction",
    "torsion": "Torsional chain and critical speeds",
    "mechanism": "Mechanism: kinematics, forces, balance, crank torque",
    "dynamics": "Dynamics",
    "fatigue": "Fatigue verdict",
}


def machine_name(params: dict) -> str | None:
    """The machine a scene's sections name (``machine`` of [mechanism], [dynamics], [geometry],
    [torsion], the first found), as readable words: ``four_star_compressor`` -> ``Four star
    compressor``; None when no section names one."""
    for s in ("mechanism", "dynamics", "geometry", "torsion"):
        m = (params.get(s) or {}).get("machine")
        if isinstance(m, str) and m:
            words = m.replace("_", " ").replace("-", " ").split()
            return " ".join(words)[:1].upper() + " ".join(words)[1:]
    return None


def scene_title(scene, params: dict, results: dict) -> str:
    """Default report title: the machine and what the scene ran (``Four star compressor:
    mechanism, modal, dynamics``), else the scene's name."""
    stages = [s for s in results if s in TITLES and s not in ("geometry", "material")]
    machine = machine_name(params)
    head = machine or scene.name
    return f"{head}: {', '.join(stages)}" if stages else head


def fmt(v, unit: str = "", scale: float = 1.0, digits: int = 4) -> str | None:
    """A number (or a list of numbers) for a table cell, scaled, with ``digits`` significant
    digits and the unit (:mod:`.quantity`: an SI unit takes an engineering prefix, ``15.99 kN``;
    never ``e+04``); None (shown as a dash) for a missing value."""
    if v is None:
        return None
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (list, tuple)):
        if not v:
            return None
        return quantities([None if x is None else x * scale for x in v], unit, digits)
    if isinstance(v, int) and scale == 1.0:
        return str(v) + (f" {unit}" if unit else "")
    if isinstance(v, (int, float)):
        return quantity(v * scale, unit, digits)
    return str(v)


def verdict(report: Report, res: dict, label: str | None = None) -> None:
    """The stage's one-line summary and each of its warnings as paragraphs (``label``: the
    section's name, where one heading covers several sections).

    A summary states numbers; it is labelled "Summary". "Verdict" is kept for comparisons
    with a stated tolerance (measured frequencies, critical-speed margins)."""
    if res.get("summary"):
        report.paragraph(f"Summary{f' [{label}]' if label else ''}: {res['summary']}")
    for w in res.get("warnings") or []:
        report.paragraph(f"Warning: {w}")


def listed_figures(res: dict, out_dir: Path, nested: bool = False) -> list[Path]:
    """Pictures a results block lists under ``figures`` and ``files`` that exist in ``out_dir``
    (names relative to it, or absolute paths), in order, without repeats. With ``nested``, also
    those of its sub-blocks (any depth)."""
    names: list = []
    for key in ("figures", "files"):
        v = res.get(key)
        names += list(v.values()) if isinstance(v, dict) else list(v or [])
    if nested:
        for v in res.values():
            if isinstance(v, dict):
                names += [str(p) for p in listed_figures(v, out_dir, nested=True)]
    out: list[Path] = []
    for n in names:
        if not isinstance(n, str):
            continue
        p = Path(n) if Path(n).is_absolute() else Path(out_dir) / n
        if p.suffix.lower() in _MIME and p.is_file() and p not in out:
            out.append(p)
    return out


def caption(path: Path) -> str:
    """``dynamics_main_bearing.png`` -> ``dynamics main bearing``."""
    return path.stem.replace("_", " ")


def figure_blocks(report: Report, res: dict, out_dir: Path, exclude=()) -> list[Path]:
    """Embed every figure ``res`` lists (not those in ``exclude``); returns them."""
    figs = [p for p in listed_figures(res, out_dir) if p not in set(exclude)]
    for p in figs:
        report.image(p, caption(p))
    return figs


def subsections(report: Report, res: dict, out_dir: Path, shown: list[Path]) -> None:
    """Each nested block of ``res`` with its own ``figures`` list as a subsection: heading, its
    table of comparisons when it has one, its figures (generic: a new block shows up as is)."""
    for key, sub in res.items():
        if not (isinstance(sub, dict) and isinstance(sub.get("figures"), list)):
            continue
        report.heading(SUBTITLES.get(key, key.replace("_", " ").capitalize()), level=3)
        if key == "flexible":
            flexible_blocks(report, sub)
        shown += figure_blocks(report, sub, out_dir, exclude=shown)


SUBTITLES = {"flexible": "Flexible vs rigid"}


#: a force or moment below this fraction of the table's largest is round-off of a cancellation
ROUND_OFF = 1e-9


def _rows(res: dict, spec, round_off: bool = False) -> list[list]:
    """Table rows ``[label, formatted value]`` for the keys of ``spec`` present in ``res``.

    With ``round_off``, a scalar below :data:`ROUND_OFF` of the largest value of the same unit
    in the table prints as ``0 N (round-off)``: a cancelled order or a fully balanced force
    computes to 1e-13 N, which is zero, not a force in piconewtons."""
    top: dict = {}
    for key, _, unit, scale in spec:
        v = res.get(key)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            top[unit] = max(top.get(unit, 0.0), abs(v * scale))
    rows = []
    for key, label, unit, scale in spec:
        v = res.get(key)
        if v is None:
            continue
        if (round_off and isinstance(v, float) and top.get(unit, 0.0) > 0
                and abs(v * scale) <= ROUND_OFF * top[unit]):
            rows.append([label, f"0 {unit} (round-off)"])
        else:
            rows.append([label, fmt(v, unit, scale)])
    return rows


MECHANISM_KINEMATICS = (
    ("n_cylinders", "cylinders", "", 1.0), ("speed_rpm", "speed", "rpm", 1.0),
    ("crank_radius_m", "crank radius", "m", 1.0), ("rod_length_m", "rod length", "m", 1.0),
    ("crank_rod_ratio", "crank / rod ratio λ", "", 1.0),
    ("bank_angles_deg", "bank angles", "°", 1.0),
    ("reciprocating_mass_kg", "reciprocating mass", "kg", 1.0),
    ("peak_acceleration_m_s2", "peak piston acceleration", "m/s²", 1.0),
)
MECHANISM_BALANCE = (
    ("first_order_force_max_n", "1st-order force, max", "N", 1.0),
    ("first_order_force_min_n", "1st-order force, min", "N", 1.0),
    ("first_order_magnitude_constant", "1st-order magnitude constant (rotating)", "", 1.0),
    ("second_order_force_max_n", "2nd-order force, max", "N", 1.0),
    ("second_order_force_cancelled", "2nd-order force cancelled", "", 1.0),
    ("second_order_moment_max_nm", "2nd-order moment, max", "N m", 1.0),
    ("rotating_force_n", "rotating-mass force", "N", 1.0),
    ("shaking_force_max_n", "shaking force, max", "N", 1.0),
    ("shaking_force_min_n", "shaking force, min", "N", 1.0),
    ("shaking_moment_max_nm", "shaking moment, max", "N m", 1.0),
    ("counterweight_mass_radius_kg_m", "counterweight m·r for 1st order", "kg m", 1.0),
    ("counterweight_angle_deg", "counterweight angle", "°", 1.0),
    ("first_order_residual_with_counterweight_n", "1st-order residual with counterweight", "N",
     1.0),
    ("shaking_force_with_counterweight_max_n", "shaking force with counterweight, max", "N",
     1.0),
)
MECHANISM_FORCES = (
    ("peak_gas_force_n", "peak gas force", "N", 1.0),
    ("peak_piston_force_n", "peak piston force", "N", 1.0),
    ("peak_side_thrust_n", "peak side thrust", "N", 1.0),
    ("peak_rod_force_n", "peak rod force", "N", 1.0),
    ("friction_work_per_cycle_j", "friction work per cycle", "J", 1.0),
    ("gas_work_per_cycle_j", "gas work per cycle", "J", 1.0),
    ("indicated_power_w", "indicated power", "W", 1.0),
    ("mean_crank_torque_nm", "crank torque on the crankshaft, mean (+ in the sense of rotation)",
     "N m", 1.0),
    ("max_crank_torque_nm", "crank torque on the crankshaft, max", "N m", 1.0),
    ("min_crank_torque_nm", "crank torque on the crankshaft, min", "N m", 1.0),
)

#: the crank torque's sign, as :mod:`crankmodal.mechanism` defines it
CRANK_TORQUE_CONVENTION = ("Sign convention: the crank torque is the torque the connecting rods "
                           "exert on the crankshaft, positive in the sense of rotation. It is "
                           "positive on average for an engine and negative for a compressor, "
                           "whose drive supplies the opposite torque.")


def crank_torque_note(res: dict) -> str | None:
    """The sign convention and what this run's mean crank torque means under it; None when
    the results carry no crank torque."""
    mean = res.get("mean_crank_torque_nm")
    if mean is None:
        return None
    if mean < 0:
        what = (f"here the mean {quantity(mean, 'N m')} is taken from the crank: the drive "
                f"delivers {quantity(-mean, 'N m')} on average")
    else:
        what = (f"here the mean {quantity(mean, 'N m')} is delivered to the crank (the machine "
                f"drives)")
    return f"{CRANK_TORQUE_CONVENTION} {what[0].upper()}{what[1:]}."


def mechanism_blocks(report: Report, res: dict) -> None:
    """Kinematics, the balance table (orders, shaking force and moment, counterweight) and the
    forces and crank torque of one working cycle."""
    for name, spec in (("Kinematics", MECHANISM_KINEMATICS), ("Balance", MECHANISM_BALANCE),
                       ("Forces and crank torque", MECHANISM_FORCES)):
        rows = _rows(res, spec, round_off=spec is MECHANISM_BALANCE)
        if rows:
            report.heading(name, level=3)
            report.table(["quantity", "value"], rows)
    note = crank_torque_note(res)
    if note:
        report.paragraph(note)


def torsion_blocks(report: Report, res: dict) -> None:
    """Natural frequencies three ways and the critical speeds near the operating speed."""
    ex, hz = res.get("exact_hz") or [], res.get("holzer_hz") or []
    if ex:
        two = res.get("two_rotor_hz")
        report.table(["mode", "exact, Hz", "Holzer, Hz", "two-rotor, Hz"],
                     [[k + 1, fmt(f), fmt(hz[k]) if k < len(hz) else None,
                       fmt(two) if k == 0 and two is not None else None]
                      for k, f in enumerate(ex)])
    if res.get("forced"):  # issue 28: the forced study's own tables (torsion/forced_report.py)
        from ..torsion.forced_report import forced_blocks

        forced_blocks(report, res["forced"])
    crit = res.get("critical_speeds")
    if not crit:
        return
    near = list(crit.get("within_required_margin") or [])
    best = crit.get("nearest_to_operating")
    if best and best not in near:
        near.insert(0, best)
    required = crit.get("required_margin", 0.0)
    rng = crit.get("speed_range_rpm") or []
    report.heading("Critical speeds", level=3)
    report.paragraph(f"Operating speed {fmt(crit.get('operating_speed_rpm'), 'rpm')}; "
                     f"{len(crit.get('critical_speeds_in_range') or [])} critical speeds in "
                     + (quantity_range(rng[0], rng[1], "rpm") if len(rng) == 2 else "the range")
                     + f". Verdict per critical speed: its margin from the operating speed "
                     f"against the required ±{percent(required)} (torsion.required_margin). "
                     f"Those within the margin (or the nearest):")
    report.table(["mode", "natural, Hz", "order", "critical speed, rpm", "margin", "verdict"],
                 [[c.get("mode"), fmt(c.get("natural_hz")), fmt(c.get("order")),
                   fmt(c.get("speed_rpm")),
                   None if c.get("margin") is None else percent(c["margin"], sign=True),
                   None if c.get("margin") is None else
                   (f"INSIDE ±{percent(required)}" if abs(c["margin"]) <= required
                    else f"clear of ±{percent(required)}")]
                  for c in near])


def static_blocks(report: Report, res: dict) -> None:
    """Peak stresses, displacement and safety factors of the static load case."""
    rows = _rows(res, (("max_von_mises_pa", "max von Mises", "Pa", 1.0),
                       ("max_von_mises_location_m", "at", "m", 1.0),
                       ("max_principal_pa", "max principal", "Pa", 1.0),
                       ("min_principal_pa", "min principal", "Pa", 1.0),
                       ("max_displacement_m", "max displacement", "m", 1.0),
                       ("safety_factor_yield", "safety factor, yield", "", 1.0),
                       ("safety_factor_ultimate", "safety factor, ultimate", "", 1.0),
                       ("reaction_n", "reaction", "N", 1.0), ("n_dofs", "DOF", "", 1.0)))
    if rows:
        report.table(["quantity", "value"], rows)


def reduction_blocks(report: Report, res: dict) -> None:
    """Sizes of the reduced body and its frequencies against the full FE model."""
    report.table(["quantity", "value"], _rows(res, (
        ("n_full_dofs", "full DOF", "", 1.0), ("n_boundary_dofs", "interface DOF", "", 1.0),
        ("n_fixed_interface_modes", "fixed-interface modes", "", 1.0),
        ("n_reduced", "reduced coordinates", "", 1.0), ("mass_kg", "mass", "kg", 1.0),
        ("m_orthonormality", "M-orthonormality defect", "", 1.0),
        ("basis_time_s", "basis time", "s", 1.0))))
    fr = res.get("frequencies_hz") or []
    full = res.get("full_frequencies_hz") or []
    rel = res.get("relative_difference") or []
    if fr:
        report.table(["mode", "reduced, Hz", "full FE, Hz", "difference"],
                     [[k + 1, fmt(f), fmt(full[k]) if k < len(full) else None,
                       f"{100 * rel[k]:+.3f} %" if k < len(rel) else None]
                      for k, f in enumerate(fr[:12])])


#: the drive's sign in [dynamics] (its torque is about +z; the crank's sense of rotation may
#: be -z, as for the crank trains, whose angle runs from +y towards +x)
DRIVE_CONVENTION = ("Sign convention: the drive torque is the torque the drive applies to the "
                    "crank about +z; the drive power is that torque times the crank's angular "
                    "speed about +z, positive when the drive delivers power. A crank turning "
                    "from +y towards +x (the crank trains) turns about −z, so its driving torque "
                    "is negative while the power is positive.")


def dynamics_blocks(report: Report, res: dict) -> None:
    """Key numbers against the ideal-joint run, the clearance joints, per-revolution
    statistics."""
    ideal = res.get("ideal") or {}
    rows = [["main-bearing force peak", fmt(res.get("main_bearing_force_peak_n"), "N"),
             fmt(ideal.get("main_bearing_force_peak_n"), "N")],
            ["main-bearing moment peak", fmt(res.get("main_bearing_moment_peak_nm"), "N m"), None],
            ["piston acceleration peak", fmt(res.get("piston_acceleration_peak"), "m/s²"),
             fmt(ideal.get("piston_acceleration_peak"), "m/s²")],
            ["drive torque peak, |T|", fmt(res.get("drive_torque_peak_nm"), "N m"), None],
            ["drive power mean", fmt(res.get("drive_power_mean_w"), "W"),
             fmt(ideal.get("drive_power_mean_w"), "W")],
            ["energy balance error", fmt(res.get("energy_balance_error"), digits=2), None],
            ["constraint drift max", fmt(res.get("constraint_drift_max"), digits=2), None],
            ["integration wall time", fmt(res.get("integration_wall_time_s"), "s", digits=3),
             None]]
    report.paragraph(f"{res.get('mechanism', '')} at {fmt(res.get('speed_rpm'), 'rpm')}, "
                     f"{fmt(res.get('end_time_s'), 's')} simulated.")
    rows = [r for r in rows if r[1] is not None]
    if ideal:
        report.table(["quantity", "this run", "ideal joints"], rows)
    else:
        report.table(["quantity", "value"], [r[:2] for r in rows])
    if res.get("drive_power_mean_w") is not None:
        report.paragraph(DRIVE_CONVENTION)
    joints = res.get("clearance_joints") or {}
    if joints:
        report.heading("Clearance joints", level=3)
        report.table(["joint", "clearance, µm", "law", "peak contact force, N",
                      "max penetration, µm", "impacts", "contact fraction",
                      "impact velocity max, m/s"],
                     [[n, fmt(j.get("clearance_m"), scale=1e6), j.get("law"),
                       fmt(j.get("peak_contact_force_n")),
                       fmt(j.get("max_penetration_m"), scale=1e6), j.get("impact_count"),
                       fmt(j.get("contact_fraction"), digits=3),
                       fmt(j.get("impact_velocity_max"), digits=3)] for n, j in joints.items()])
    stats = res.get("statistics") or {}
    srows = list(_stat_rows(stats))
    if srows:
        w = stats.get("window") or {}
        report.heading("Per-revolution statistics", level=3)
        report.paragraph(f"Over {w.get('n_revolutions')} revolutions from "
                         f"{fmt(w.get('start_s'), 's')} to {fmt(w.get('end_s'), 's')}: mean, "
                         f"standard deviation and standard error of each revolution's value.")
        report.table(["quantity", "mean", "std", "standard error"], srows)


def statistic_unit(name: str) -> str:
    """The SI unit of a per-revolution statistic from its path (``main bearing force: rms`` ->
    N); '' for counts and what the path does not tell."""
    if "count" in name:
        return ""
    for word, unit in (("moment", "N m"), ("torque", "N m"), ("force", "N"),
                       ("acceleration", "m/s²"), ("velocity", "m/s"), ("penetration", "m")):
        if word in name:
            return unit
    return ""


def _stat_rows(stats: dict, prefix: str = ""):
    """Rows for every scalar ``{mean, std, sem}`` leaf of a statistics block (any depth; the
    per-order vectors stay in results.json)."""
    for key, v in stats.items():
        if key == "window" or not isinstance(v, dict):
            continue
        name = f"{prefix}{key}".replace("_", " ")
        if "mean" in v:
            if isinstance(v["mean"], (int, float)):
                unit, mean = statistic_unit(name), v["mean"]
                yield [name, fmt(mean, unit)] + [
                    None if v.get(k) is None else quantity_as(v[k], mean, unit)
                    for k in ("std", "sem")]
        else:
            yield from _stat_rows(v, f"{prefix}{key}: ")


def flexible_blocks(report: Report, flex: dict) -> None:
    """The flexible bodies (modes kept, peak modal amplitude, dynamic stress) and every force
    compared with the rigid twin (peak, RMS, RMS of the difference)."""
    bodies = flex.get("bodies") or {}
    if bodies:
        report.table(["body", "modes", "frequencies, Hz", "mass, kg",
                      "max interface deflection, µm", "dynamic stress max, MPa"],
                     [[n, b.get("n_modes"), fmt((b.get("frequencies_hz") or [])[:6]),
                       fmt(b.get("mass_kg")), _max_deflection_um(b.get("interface_deflection_max_m")),
                       fmt((b.get("dynamic_stress") or {}).get("max_von_mises_pa"), scale=1e-6)]
                      for n, b in bodies.items()])
    rigid = flex.get("rigid") or {}
    if rigid:
        report.table(["force", "peak flexible, N", "peak rigid, N", "RMS flexible, N",
                      "RMS rigid, N", "RMS of the difference"],
                     [[n, fmt(c.get("peak_n")), fmt(c.get("rigid_peak_n")), fmt(c.get("rms_n")),
                       fmt(c.get("rigid_rms_n")),
                       None if c.get("relative_difference_rms") is None
                       else f"{100 * c['relative_difference_rms']:.3g} % of rigid RMS"]
                      for n, c in rigid.items() if isinstance(c, dict)])


def _max_deflection_um(d) -> str | None:
    """Largest value of a (possibly nested) dict/list of deflections, in µm."""
    vals: list[float] = []

    def walk(x):
        if isinstance(x, dict):
            for v in x.values():
                walk(v)
        elif isinstance(x, (list, tuple)):
            for v in x:
                walk(v)
        elif isinstance(x, (int, float)) and not isinstance(x, bool):
            vals.append(abs(float(x)))

    walk(d)
    return fmt(max(vals), scale=1e6, digits=3) if vals else None


def fatigue_blocks(report: Report, res: dict) -> None:
    """Criterion, strengths, the ensemble's spread and the per-location safety factors."""
    from ..fatigue.report import fatigue_blocks as blocks  # nothing heavy imported

    blocks(report, res)


def geometry_blocks(report: Report, res: dict) -> None:
    """The part and its mesh (a scene without [modal]; with it the modal section has them)."""
    q = res.get("quality") or {}
    rows = _rows(res, (("name", "part", "", 1.0), ("fidelity", "fidelity", "", 1.0),
                       ("element_order", "element order", "", 1.0),
                       ("n_elements", "elements", "", 1.0), ("n_nodes", "nodes", "", 1.0)))
    if q.get("measure"):
        rows.append([f"quality ({q['measure']}) min / mean", f"{q['min']:.3f} / {q['mean']:.3f}"])
    report.table(["quantity", "value"], rows)


def material_blocks(report: Report, res: dict) -> None:
    """The material's constants (a scene without [modal])."""
    report.table(["quantity", "value"], _rows(res, (
        ("name", "name", "", 1.0), ("E_pa", "E", "GPa", 1e-9), ("nu", "ν", "", 1.0),
        ("rho_kg_m3", "ρ", "kg/m³", 1.0), ("yield_strength_pa", "yield strength", "MPa", 1e-6),
        ("ultimate_strength_pa", "ultimate strength", "MPa", 1e-6))))


STAGE_BLOCKS = {"geometry": geometry_blocks, "material": material_blocks,
                "static": static_blocks, "reduction": reduction_blocks,
                "torsion": torsion_blocks, "mechanism": mechanism_blocks,
                "dynamics": dynamics_blocks, "fatigue": fatigue_blocks}


def stage_section(report: Report, section: str, res: dict, out_dir: Path,
                  images=()) -> None:
    """One stage's section: heading, verdict, its tables (known stages), ``images`` (extra
    ``(path, caption)`` pairs, e.g. a render), every figure it lists, then its nested blocks
    with their own figures as subsections."""
    report.heading(f"{TITLES.get(section, section.capitalize())} [{section}]")
    verdict(report, res)
    if section in STAGE_BLOCKS:
        STAGE_BLOCKS[section](report, res)
    for path, cap in images:
        report.image(path, cap)
    nested = [p for k, v in res.items() if isinstance(v, dict) and isinstance(v.get("figures"),
                                                                             list)
              for p in listed_figures(v, out_dir)]
    shown = figure_blocks(report, res, out_dir, exclude=nested)
    subsections(report, res, out_dir, shown)


def overview_rows(results: dict) -> list[list]:
    """One row per stage: section, wall time, summary (and the number of warnings)."""
    rows = []
    for s, r in results.items():
        if not isinstance(r, dict):
            continue
        n_w = len(r.get("warnings") or [])
        text = r.get("summary", "") + (f" ({n_w} warning{'s' * (n_w > 1)})" if n_w else "")
        rows.append([f"[{s}]", quantity(r.get("wall_time_s", 0.0), "s", 3), text])
    return rows


def relative_name(path, out_dir) -> str:
    """``path`` relative to ``out_dir`` when inside it (POSIX separators), else as given."""
    p = Path(path)
    try:
        return p.resolve().relative_to(Path(out_dir).resolve()).as_posix()
    except ValueError:
        return str(p)
