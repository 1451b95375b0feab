"""The forced study's tables in the HTML report's torsion section.

Called by :func:`crankmodal.report.scene_report.torsion_blocks` with the ``torsion.forced``
results; the figures (interference diagram with response, response vs speed, stress vs speed)
are embedded by the report from the stage's ``files``.
"""

from __future__ import annotations


def forced_blocks(report, forced: dict) -> None:
    """Verdict, per-section stresses and the separation margins of the forced study."""
    from ..report.quantity import percent
    from ..report.scene_report import fmt

    report.heading("Forced response, stress and verdict", level=3)
    chk, mar = forced.get("stress_check") or {}, forced.get("margins") or {}
    if forced.get("summary"):
        report.paragraph(f"Verdict: {forced['summary']}")
    allow = forced.get("allowable")
    if allow:
        report.paragraph(
            f"Allowable vibratory shear stress {fmt(allow['allowable_pa'], 'Pa')} = endurance limit "
            f"{fmt(allow['endurance_limit_pa'], 'Pa')} x size {allow['size_factor']:g} x surface "
            f"{allow['surface_factor']:g} x reliability {allow['reliability_factor']:g} / safety factor "
            f"{allow['safety_factor']:g}. Stresses are nominal K_t T / Z_p of the synthesised "
            "(all orders, phased) half peak-to-peak torque.")
    rows = []
    for s in chk.get("sections") or []:
        val = s.get("max_stress_pa")
        rows.append([s["section"], s["name"],
                     fmt(val, "Pa") if val is not None else fmt(s.get("max_torque_nm"), "N m"),
                     fmt(s["at_speed_rpm"], "rpm"),
                     percent(val / allow["allowable_pa"]) if allow and val is not None else None])
    if rows:
        report.table(["section", "name", "max vibratory stress", "at", "of allowable"], rows)
    band = mar.get("band", 0.0)
    crit = list(mar.get("violations") or []) or [c for c in mar.get("closest") or [] if c]
    if crit:
        report.paragraph(f"Separation from the operating speeds (band ±{percent(band)}, orders whose "
                         f"modal excitation is at least {percent(mar.get('significance', 0.0))} of the "
                         "mode's largest):")
        report.table(["operating, rpm", "mode", "natural, Hz", "order", "critical, rpm", "margin", "verdict"],
                     [[fmt(c["operating_speed_rpm"]), c["mode"], fmt(c["natural_hz"]), fmt(c["order"]),
                       fmt(c["critical_speed_rpm"]), percent(c["margin"], sign=True),
                       f"INSIDE ±{percent(band)}" if abs(c["margin"]) < band else f"clear of ±{percent(band)}"]
                      for c in crit])
    res = forced.get("resonances") or []
    if res:
        report.paragraph("Strongest resonances in the speed range (full tables in "
                         "torsion_forced_resonances.txt): response against the energy-balance estimate.")
        report.table(["mode", "order", "speed, rpm", "largest section torque", "reference rotor",
                      "full response, rad", "energy balance, rad"],
                     [[r["mode"], fmt(r["order"]), fmt(r["speed_rpm"]), fmt(r["max_section_torque_nm"], "N m"),
                       r["reference"], fmt(r["full_response_rad"]), fmt(r["energy_balance_rad"])]
                      for r in res[:6]])
