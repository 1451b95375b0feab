"""The multi-throw crank train in the scene's HTML report: main-bearing shares, torsional
response by order, and the crank's fatigue verdict (issue 29's outputs).

Called by the ``[report]`` stage after the ``[dynamics]`` section
(:func:`crankmodal.report.stage.run`) with the ``dynamics`` results as written to
``results.json`` (``main_journals``, ``torsion``, ``arrangement``:
:func:`.journals.train_results`) and, when the scene ran ``[fatigue]``, its results: their
worst location is named here and the fatigue section itself (its per-location table and the
crank coloured by safety factor) is not repeated. The two figures are drawn from those numbers
(matplotlib, imported only when a figure is drawn).
"""

from __future__ import annotations

from pathlib import Path

#: torsional histories shown, with their unit, scale to it, and label
TORSION_SIGNALS = {"twist_free_end": ("mrad", 1e3, "free-end twist against the drive"),
                   "coupling_torque": ("N m", 1.0, "coupling torque"),
                   "coupling_twist": ("mrad", 1e3, "coupling twist")}


def _largest_orders(orders, amplitudes, n: int = 3) -> list[tuple[float, float]]:
    """The ``n`` largest non-zero orders (order 0, the mean, left out), largest first."""
    pairs = [(float(o), float(a)) for o, a in zip(orders, amplitudes) if float(o) > 0.0]
    return sorted(pairs, key=lambda p: -p[1])[:n]


def _order_text(o: float) -> str:
    return f"{o:g}"


def _journals(main_journals: dict) -> dict:
    """The per-journal blocks of ``main_journals`` (its ``journals`` list names them)."""
    return {k: v for k, v in main_journals.items() if isinstance(v, dict)}


def journal_rows(main_journals: dict) -> list[list]:
    """One row per main journal: mean and peak force with their shares, the per-revolution
    peak (mean ± standard error) and its two largest orders."""
    from ...report.scene_report import fmt

    rows = []
    for name, d in _journals(main_journals).items():
        rev = d.get("per_revolution_peak_n") or {}
        orders = _largest_orders(d.get("orders") or [], d.get("order_amplitude_n") or [], 2)
        rows.append([name.replace("_", " "), fmt(d.get("mean_n"), "N"),
                     fmt(d.get("share_mean"), digits=3), fmt(d.get("peak_n"), "N"),
                     fmt(d.get("share_peak"), digits=3),
                     None if rev.get("mean") is None else
                     f"{fmt(rev['mean'], 'N')} ± {fmt(rev.get('sem') or 0.0, 'N', digits=2)}",
                     ", ".join(f"{_order_text(o)}: {fmt(a, 'N', digits=3)}" for o, a in orders)
                     or None])
    return rows


def torsion_rows(torsion: dict) -> list[list]:
    """One row per torsional history shown: mean, half peak-to-peak and its largest orders."""
    from ...report.scene_report import fmt

    orders = torsion.get("orders") or []
    rows = []
    for key, (unit, scale, label) in TORSION_SIGNALS.items():
        d = torsion.get(key)
        if not isinstance(d, dict):
            continue
        big = _largest_orders(orders, d.get("amplitude") or [], 3)
        rows.append([label, fmt(d.get("mean"), unit, scale), fmt(d.get("half_peak_to_peak"),
                                                                   unit, scale),
                     ", ".join(f"{_order_text(o)}: {fmt(a, unit, scale, digits=3)}"
                               for o, a in big) or None])
    return rows


def plot_shares(main_journals: dict, path: Path) -> Path:
    """Bars of each journal's share of the mean and of the peak force."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from ...results import savefig_atomic

    journals = _journals(main_journals)
    names = list(journals)
    x = np.arange(len(names))
    mean = [journals[n].get("share_mean") or 0.0 for n in names]
    peak = [journals[n].get("share_peak") or 0.0 for n in names]
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    b1 = ax.bar(x - 0.2, mean, 0.4, label="share of the mean force")
    b2 = ax.bar(x + 0.2, peak, 0.4, label="share of the peak force")
    for bars in (b1, b2):
        ax.bar_label(bars, fmt="%.2f", fontsize=8)
    ax.set_xticks(x, [n.replace("_", " ") for n in names])
    ax.set_ylabel("share of the journals' sum")
    ax.set_ylim(0.0, max(mean + peak + [0.5]) * 1.2)
    ax.set_title("Main-bearing load shares")
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)  # never a half-written figure
    plt.close(fig)
    return path


def plot_torsion_orders(torsion: dict, path: Path) -> Path | None:
    """Amplitude by order of the free-end twist and the coupling torque (one panel each)."""
    shown = [k for k in ("twist_free_end", "coupling_torque") if isinstance(torsion.get(k), dict)]
    if not shown:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from ...results import savefig_atomic

    orders = np.asarray(torsion.get("orders") or [], float)
    fig, axes = plt.subplots(len(shown), 1, figsize=(6.4, 2.6 * len(shown)), squeeze=False)
    for ax, key in zip(axes[:, 0], shown):
        unit, scale, label = TORSION_SIGNALS[key]
        amp = np.asarray(torsion[key].get("amplitude") or [], float) * scale
        keep = orders[:amp.size] > 0.0
        ax.bar(orders[:amp.size][keep], amp[keep], width=0.35)
        ax.set_ylabel(f"amplitude, {unit}")
        ax.set_title(label, fontsize=10)
        ax.set_xticks(np.arange(0, orders.max() + 1 if orders.size else 13, 1))
    axes[-1, 0].set_xlabel("order (per crank revolution)")
    fig.suptitle("Torsional response by order")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)  # never a half-written figure
    plt.close(fig)
    return path


def fatigue_text(fatigue: dict) -> str | None:
    """The crank's fatigue verdict in one sentence (the Fatigue verdict section has the rest)."""
    from ...fatigue.report import _n

    worst = fatigue.get("worst_location")
    if not worst and fatigue.get("min_safety_factor") is None:
        return None
    verdict = "passes" if fatigue.get("passed") else "FAILS"
    return (f"Fatigue of the {fatigue.get('body', 'crank')}: lowest safety factor "
            f"{_n(fatigue.get('min_safety_factor'))}, worst named location "
            f"{str(worst).replace('_', ' ')} (n = {_n(fatigue.get('worst_location_safety_factor'))})"
            f" against the required {fatigue.get('required_safety_factor')}: {verdict}. The "
            f"per-location table and the crank coloured by safety factor are in the section "
            f"'Fatigue verdict [fatigue]'.")


def train_section(report, res: dict, out_dir, fatigue: dict | None = None,
                  figures: bool = True) -> list[Path]:
    """Append the multi-throw subsection for the ``dynamics`` results ``res`` (nothing for a
    run without ``main_journals`` or ``torsion``); returns the figures drawn into ``out_dir``."""
    mj, tor = res.get("main_journals"), res.get("torsion")
    if not mj and not tor:
        return []
    out = []
    report.heading("Multi-throw crank train", level=3)
    arr = res.get("arrangement") or {}
    if arr:
        throws = ", ".join(f"{a:g}" for a in arr.get("throw_angles_deg") or [])
        order = arr.get("firing_order")
        report.paragraph(f"Throws at {throws} deg; cylinders on throws "
                         f"{', '.join(str(t) for t in arr.get('cylinder_throws') or [])}"
                         + (f"; firing order {'-'.join(str(c) for c in order)}." if order else
                            "."))
    if mj:
        report.paragraph("Main journals over the results window: force of the crank on each "
                         "journal's housing; shares of the journals' summed mean and peak "
                         "forces (a crank on three or more journals shares its load by its "
                         "flexibility only).")
        report.table(["journal", "mean |F|", "share of mean", "peak |F|", "share of peak",
                      "per-revolution peak", "largest orders"], journal_rows(mj))
        if figures:
            out.append(plot_shares(mj, Path(out_dir) / "dynamics_journal_shares.png"))
            report.image(out[-1], "main-bearing load shares")
    if tor:
        rows = torsion_rows(tor)
        if rows:
            report.paragraph("Torsional response over whole working cycles: mean, half "
                             "peak-to-peak and the largest orders (per crank revolution).")
            report.table(["signal", "mean", "half peak-to-peak", "largest orders"], rows)
        if figures:
            p = plot_torsion_orders(tor, Path(out_dir) / "dynamics_torsion_orders.png")
            if p is not None:
                out.append(p)
                report.image(p, "torsional response by order")
    if fatigue:
        text = fatigue_text(fatigue)
        if text:
            report.paragraph(text)
    return out


__all__ = ["fatigue_text", "journal_rows", "plot_shares", "plot_torsion_orders",
           "torsion_rows", "train_section"]
