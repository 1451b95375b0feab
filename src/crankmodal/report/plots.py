"""Report figures with matplotlib (Agg), each PNG written with its data as a CSV next to it.

- :func:`plot_error_vs_time`: estimated error against wall time, log–log, one point per model,
  Pareto front and recommendation marked, tolerance drawn;
- :func:`plot_convergence`: frequency of each mode against DOF per (fidelity, order);
- :func:`plot_mac`: MAC matrix heat map with values;
- :func:`plot_participation`: effective-mass fractions per mode (x, y, z translations; a
  direction no mode moves is named in a note, not drawn).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ..results import atomic_path, savefig_atomic

_MARKERS = {"full": "o", "dechamfered": "s", "simplified": "^", "imported": "D"}
_COLOURS = {1: "tab:blue", 2: "tab:red"}


def _figure(figsize=(7.0, 4.8)):
    from ..plotting import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=figsize, constrained_layout=True)
    return plt, fig, ax


def _write_csv(path: Path, header, rows) -> Path:
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return path


def _plain_log_ticks(ax) -> None:
    """Log axes labelled 1, 2, 5, 10, 20, ... in plain numbers (matplotlib's default labels the
    minor ticks of a short decade as 3×10⁰, 4×10⁰, ... and they run into each other)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(NullFormatter())


def plot_error_vs_time(study, path) -> Path:
    """Error against run time (log–log) of a :class:`~.study.SimplificationStudy`.

    Writes ``path`` (PNG) and ``path`` with ``.csv``: label, fidelity, order, mesh size (m),
    elements, wall time (s), error, on the front, recommended.
    """
    path = Path(path)
    runs = study.runs
    t = np.array([r["wall_time_s"] for r in runs])
    e = np.array([r["error"] for r in runs])
    floor = max(1e-6, 0.3 * e[e > 0].min()) if np.any(e > 0) else 1e-6
    ep = np.maximum(e, floor)  # a zero error cannot sit on a log axis
    plt, fig, ax = _figure()
    seen = set()
    for i, r in enumerate(runs):
        key = (r["fidelity"], r["order"])
        ax.scatter(t[i], 100 * ep[i], marker=_MARKERS.get(r["fidelity"], "x"),
                   color=_COLOURS.get(r["order"], "k"), s=46, zorder=3,
                   label=f"{r['fidelity']} P{r['order']}" if key not in seen else None)
        seen.add(key)
        ax.annotate(f"{1e3 * r['mesh_size']:.3g}", (t[i], 100 * ep[i]), textcoords="offset points",
                    xytext=(5, 4), fontsize=7, color="0.35")
    fr = np.asarray(study.pareto, int)
    if len(fr):
        ax.step(t[fr], 100 * ep[fr], where="post", color="k", lw=1.2, ls="--", zorder=2,
                label="Pareto front")
    ax.axhline(100 * study.tolerance, color="tab:green", lw=1.0,
               label=f"tolerance {100 * study.tolerance:.3g} %")
    if study.recommended is not None:
        k = study.recommended
        ax.scatter(t[k], 100 * ep[k], s=260, facecolors="none", edgecolors="tab:green", lw=2,
                   zorder=4, label="recommended")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax)
    ax.set_xlabel("wall time to mesh and solve, s")
    ax.set_ylabel(f"estimated error (max over {study.compared_modes} modes), %")
    ax.set_title("Error against run time (labels: mesh size, mm)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    try:
        savefig_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)
    _write_csv(path.with_suffix(".csv"),
               ["label", "fidelity", "order", "mesh_size_m", "n_elements", "wall_time_s", "error",
                "pareto", "recommended"],
               [[study.label(r), r["fidelity"], r["order"], r["mesh_size"], r["n_elements"],
                 f"{r['wall_time_s']:.4g}", f"{r['error']:.6g}", int(i in study.pareto),
                 int(i == study.recommended)] for i, r in enumerate(runs)])
    return path


def plot_convergence(runs, path, reference_hz=None, n_modes: int | None = None) -> Path:
    """Frequency of each mode against DOF, one line per (fidelity, order) and mode.

    Parameters
    ----------
    runs : list of dict
        ``fidelity``, ``order``, ``n_dofs``, ``frequencies_hz``, ``mesh_size``.
    reference_hz : sequence, optional
        Drawn as dashed horizontal lines (the extrapolated values); the title mentions them
        only when they are drawn.
    """
    path = Path(path)
    n = n_modes or min(len(r.get("matched_hz", r["frequencies_hz"])) for r in runs)
    plt, fig, ax = _figure((7.5, 5.2))
    groups = {}
    for r in runs:
        groups.setdefault((r["fidelity"], r["order"]), []).append(r)
    rows = []
    cmap = plt.get_cmap("tab10")
    for (fid, order), rs in groups.items():
        rs = sorted(rs, key=lambda r: r["n_dofs"])
        dofs = [r["n_dofs"] for r in rs]
        for k in range(n):
            ax.plot(dofs, [r.get("matched_hz", r["frequencies_hz"])[k] for r in rs],
                    marker=_MARKERS.get(fid, "x"),
                    color=cmap(k % 10), ls="-" if order == 2 else ":", ms=4)
        for r in rs:
            rows.append([fid, order, r["mesh_size"], r["n_dofs"]]
                        + [f"{f:.6g}" for f in r.get("matched_hz", r["frequencies_hz"])[:n]])
    if reference_hz is not None:
        for k, f in enumerate(reference_hz[:n]):
            ax.axhline(f, color=cmap(k % 10), lw=0.8, ls="--", alpha=0.6)
    ax.set_xscale("log")
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("natural frequency, Hz")
    ax.set_title("Frequency against DOF (colour: mode"
                 + ("; dashed: extrapolated reference)" if reference_hz is not None else ")"))
    ax.grid(True, which="both", alpha=0.3)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="k", marker=_MARKERS.get(fid, "x"),
                      ls="-" if order == 2 else ":", label=f"{fid} P{order}")
               for fid, order in groups]  # black: colour stands for the mode
    ax.legend(handles=handles, fontsize=8, title="colour: mode", title_fontsize=8)
    try:
        savefig_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)
    _write_csv(path.with_suffix(".csv"), ["fidelity", "order", "mesh_size_m", "n_dofs"]
               + [f"f{k + 1}_hz" for k in range(n)], rows)
    return path


def plot_mac(mac, path, row_labels=None, col_labels=None, title="MAC",
             xlabel="reference modes", ylabel="modes") -> Path:
    """MAC heat map (0 white .. 1 dark) with each value printed; CSV of the matrix."""
    path = Path(path)
    mac = np.asarray(mac, float)
    m, k = mac.shape
    rl = row_labels or [str(i + 1) for i in range(m)]
    cl = col_labels or [str(j + 1) for j in range(k)]
    plt, fig, ax = _figure((max(4.8, 1.8 + 0.55 * k), max(3.8, 1.6 + 0.5 * m)))
    im = ax.imshow(mac, cmap="Blues", vmin=0.0, vmax=1.0)
    for i in range(m):
        for j in range(k):
            ax.text(j, i, f"{mac[i, j]:.2f}", ha="center", va="center", fontsize=7,
                    color="white" if mac[i, j] > 0.6 else "black")
    ax.set_xticks(range(k), cl, rotation=90, fontsize=7)
    ax.set_yticks(range(m), rl, fontsize=7)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    fig.colorbar(im, ax=ax, shrink=0.8)
    try:
        savefig_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)
    _write_csv(path.with_suffix(".csv"), [""] + list(cl),
               [[r] + [f"{v:.6f}" for v in row] for r, row in zip(rl, mac)])
    return path


def plot_participation(frequencies_hz, effective_mass, total_mass, path) -> Path:
    """Effective-mass fractions (x, y, z translation) per mode and their cumulative sums.

    Parameters
    ----------
    frequencies_hz : array_like, shape (n,)
    effective_mass : ndarray, shape (n, 6)
        kg for the first three columns (translations).
    total_mass : float
        kg.
    """
    path = Path(path)
    f = np.asarray(frequencies_hz, float)
    frac = np.asarray(effective_mass, float)[:, :3] / total_mass
    from ..plotting import ZERO_FRACTION, hidden_note

    plt, fig, ax = _figure((7.5, 4.5))
    x = np.arange(len(f))
    top = float(np.max(np.abs(frac))) if frac.size else 0.0
    hidden = []
    for c, name in enumerate("xyz"):
        if float(np.max(np.abs(frac[:, c]), initial=0.0)) <= ZERO_FRACTION * top:
            hidden.append(f"{name} translation (zero)")  # no bar, no flat line in the legend
            continue
        ax.bar(x + (c - 1) * 0.27, 100 * frac[:, c], width=0.27, label=f"{name} translation")
        ax.plot(x, 100 * np.cumsum(frac[:, c]), marker=".", lw=1,
                label=f"{name} cumulative")
    hidden_note(ax, hidden)
    ax.set_xticks(x, [f"{k + 1}\n{v:.0f} Hz" for k, v in enumerate(f)], fontsize=7)
    ax.set_ylabel("effective mass, % of total")
    ax.set_title("Mode participation: effective mass per mode and cumulative")
    ax.grid(True, axis="y", alpha=0.3)
    if ax.get_legend_handles_labels()[1]:
        ax.legend(fontsize=7, ncol=2)
    try:
        savefig_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)
    _write_csv(path.with_suffix(".csv"), ["mode", "frequency_hz", "x_fraction", "y_fraction",
                                          "z_fraction"],
               [[k + 1, f"{v:.6g}"] + [f"{q:.6g}" for q in frac[k]] for k, v in enumerate(f)])
    return path
