"""The verdict of a forced torsional study: separation margins and the stress check.

Separation: a natural frequency ``f`` is excited by order ``q`` at ``n_c = 60 f / q`` rpm; inside
the band ``n_op (1 +- b)`` of an operating speed it is too close (default ``b`` = 10 %; issue 28:
10-20 % customary for the uncertainty of the model). Only *significant* orders count: those
whose modal excitation ``|phi_m . F_q|`` (the phase-vector sum over the throws, at the operating
speed) reaches ``significance`` x the largest one of the same mode.

Stress: the synthesised vibratory stress of every section at every speed of the range against the
allowable (:class:`~.stress.Allowable`); the worst section, its speed and the order that
dominates there are named.
"""

from __future__ import annotations

import numpy as np


def modal_excitation(shapes: np.ndarray, force: np.ndarray) -> np.ndarray:
    """``|phi_m . F_q|`` per mode and order (N m x shape units).

    Parameters
    ----------
    shapes : ndarray, shape (n_modes, N)
    force : ndarray, shape (n_orders, n), complex
        Order torques on the first n DOFs.
    """
    n = force.shape[1]
    return np.abs(shapes[:, :n] @ force.T)


def separation_margins(natural_hz, orders, relative_excitation, operating_rpm, band: float,
                       significance: float) -> dict:
    """Critical speeds of significant orders inside each operating band.

    Parameters
    ----------
    natural_hz : ndarray, shape (n_modes,)
    orders : ndarray, shape (n_orders,)
    relative_excitation : ndarray, shape (n_ops, n_modes, n_orders)
        Modal excitation of each order relative to the largest of its mode, at each operating
        speed.
    operating_rpm : sequence of float
    band : float
        Fraction each side of the operating speed.
    significance : float
        Relative excitation from which an order counts.

    Returns
    -------
    dict
        ``violations`` (list of rows: operating speed, mode, natural Hz, order, critical rpm,
        margin, relative excitation), ``closest`` (the significant critical speed nearest each
        operating speed, with its margin), ``band``, ``significance``.
    """
    from .critical_speeds import CriticalSpeeds

    orders = np.asarray(orders, float)
    crit = CriticalSpeeds(np.asarray(natural_hz, float), orders, (0.0, np.inf)).all_criticals()
    violations, closest = [], []
    for o, n_op in enumerate(operating_rpm):
        best = None
        for c in crit:
            j = int(np.argmin(np.abs(orders - c["order"])))
            rel = float(relative_excitation[o, c["mode"] - 1, j])
            if rel < significance:
                continue
            margin = (c["speed_rpm"] - n_op) / n_op
            row = {"operating_speed_rpm": float(n_op), "mode": c["mode"], "natural_hz": c["natural_hz"],
                   "order": c["order"], "critical_speed_rpm": c["speed_rpm"], "margin": float(margin),
                   "relative_excitation": rel}
            if abs(margin) < band:
                violations.append(row)
            if best is None or abs(margin) < abs(best["margin"]):
                best = row
        closest.append(best)
    return {"band": band, "significance": significance, "violations": violations,
            "closest": closest, "passes": not violations}


def stress_check(speed_rpm, stress, order_stress, orders, allowable_pa: float | None,
                 section_names) -> dict:
    """Synthesised vibratory stress against the allowable over the speed range.

    Parameters
    ----------
    speed_rpm : ndarray, shape (n_speeds,)
    stress : ndarray, shape (n_speeds, n_sections)
        Synthesised vibratory shear stress, Pa.
    order_stress : ndarray, shape (n_speeds, n_orders, n_sections)
        Stress amplitude of each order alone, Pa.
    orders : ndarray
    allowable_pa : float or None
        None: no allowable given; the worst section is still named, by stress.
    section_names : list of str

    Returns
    -------
    dict
        ``worst_section`` (1-based), ``section``, ``speed_rpm``, ``stress_pa``, ``dominant_order``,
        ``allowable_pa``, ``utilisation`` (stress / allowable), ``passes``, and per section the
        maximum stress and its speed.
    """
    ref = 1.0 if allowable_pa is None else allowable_pa
    ratio = stress / ref
    s, sec = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    dom = int(np.argmax(order_stress[s, :, sec]))
    per = [{"section": i + 1, "name": section_names[i],
            "max_stress_pa": float(stress[:, i].max()),
            "at_speed_rpm": float(speed_rpm[int(np.argmax(stress[:, i]))])}
           for i in range(stress.shape[1])]
    out = {"worst_section": int(sec) + 1, "section": section_names[sec],
           "speed_rpm": float(speed_rpm[s]), "stress_pa": float(stress[s, sec]),
           "dominant_order": float(orders[dom]), "allowable_pa": allowable_pa,
           "sections": per}
    if allowable_pa is not None:
        out["utilisation"] = float(stress[s, sec] / allowable_pa)
        out["passes"] = bool(stress[s, sec] <= allowable_pa)
    return out


def summary_line(stress: dict, margins: dict) -> str:
    """One line naming the worst section, speed and order, and the margin verdict."""
    s = (f"worst section {stress['worst_section']} ({stress['section']}) "
         f"{stress['stress_pa'] / 1e6:.3g} MPa at {stress['speed_rpm']:.5g} rpm, order "
         f"{stress['dominant_order']:g}")
    if stress.get("allowable_pa") is not None:
        s += (f": {100 * stress['utilisation']:.0f} % of the allowable "
              f"{stress['allowable_pa'] / 1e6:.3g} MPa ({'passes' if stress['passes'] else 'FAILS'})")
    v = margins["violations"]
    if v:
        w = min(v, key=lambda r: abs(r["margin"]))
        s += (f"; {len(v)} critical speed(s) inside the {100 * margins['band']:.0f} % bands, "
              f"closest mode {w['mode']} order {w['order']:g} at {w['critical_speed_rpm']:.5g} rpm "
              f"({100 * w['margin']:+.1f} %)")
    else:
        c = [r for r in margins["closest"] if r is not None]
        if c:
            w = min(c, key=lambda r: abs(r["margin"]))
            s += (f"; margins pass (closest mode {w['mode']} order {w['order']:g} at "
                  f"{w['critical_speed_rpm']:.5g} rpm, {100 * w['margin']:+.1f} %)")
    return s
