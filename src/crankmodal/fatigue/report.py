"""The ``[fatigue]`` stage's tables in the scene's HTML report.

Called by :func:`crankmodal.report.scene_report.stage_section` with the ``fatigue`` results; the
figures (``fatigue_crank.png``, ``fatigue_haigh.png``) are embedded by the report from the
stage's ``figures``. Nothing heavy is imported.
"""

from __future__ import annotations


def _n(v) -> str:
    """A safety factor; None (results.json's infinite: no stress) as ∞."""
    return "∞" if v is None else f"{v:.3g}"


def fatigue_blocks(report, res: dict) -> None:
    """The criterion and strength, the ensemble's spread, and the per-location table (worst
    point of each location, lowest first)."""
    from ..report.scene_report import fmt

    f = res.get("factors") or {}
    crit = res.get("criterion") or {}
    report.paragraph(
        f"Criterion: {str(crit.get('rule', '')).capitalize()} with the {crit.get('mean_stress')} "
        f"mean stress; equivalent alternating stress: {crit.get('equivalent_alternating')}. "
        f"Fatigue strength of the part S_e = {fmt(res.get('fatigue_strength_pa'), 'Pa')} = "
        f"{res.get('material')}'s {fmt(res.get('specimen_fatigue_strength_pa'), 'Pa')} x surface "
        f"{f.get('surface', 1.0):.3g} x size {f.get('size', 1.0):.3g} x reliability "
        f"{f.get('reliability', 1.0):.3g} x other {f.get('other', 1.0):.3g}; K_f = "
        f"{f.get('notch', 1.0):.3g} on the stresses; ultimate strength "
        f"{fmt(res.get('ultimate_strength_pa'), 'Pa')}. Required safety factor "
        f"{res.get('required_safety_factor')}: {'passes' if res.get('passed') else 'FAILS'}.")
    ens = res.get("ensemble")
    if ens:
        s = ens["spread"]
        report.paragraph(
            f"Ensemble of {ens['n_trajectories']} trajectories (an impacting run: each "
            f"trajectory's last cycle assessed): lowest safety factor min {_n(s['min'])}, mean "
            f"{_n(s['mean'])}, max {_n(s['max'])}.")
        report.table(["trajectory", "lowest safety factor", "worst location"],
                     [[k + 1, _n(n), (w or "-").replace("_", " ")]
                      for k, (n, w) in enumerate(zip(ens["min_safety_factor"],
                                                     ens["worst_location"]))])
    locs = res.get("locations") or {}
    rows = []
    inf = float("inf")
    for name, d in sorted(locs.items(), key=lambda kv: (kv[1]["safety_factor"] is None,
                                                         kv[1]["safety_factor"] or inf)):
        rows.append([name.replace("_", " "), d.get("kind"), _n(d["safety_factor"]),
                     fmt(d.get("alternating_pa"), "Pa"), fmt(d.get("mean_pa"), "Pa"),
                     fmt(d.get("max_von_mises_pa"), "Pa"),
                     f"{d['proportionality']:.3g}" if d.get("proportionality") is not None
                     else None, d.get("n_points")])
    if rows:
        report.table(["location", "kind", "safety factor", "alternating (eq.)", "mean (eq.)",
                      "max von Mises", "proportionality", "points"], rows)
