"""PNG figures of the torsional checks (matplotlib, Agg backend, imported inside each function)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import pyplot as _pyplot


def _save(plt, fig, path) -> Path:
    """Write the PNG and free the figure."""
    from ..results import savefig_atomic

    fig.tight_layout()
    try:
        savefig_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)
    return Path(path)


def plot_holzer_residual(result, path: str | Path) -> Path:
    """Holzer residual over the frequency sweep, roots marked.

    The residual spans many decades, so it is drawn as ``asinh(r / s)`` with ``s`` its median
    magnitude: the sign changes (the roots) stay where they are.
    """
    plt = _pyplot()
    f = result.sweep_omega / (2.0 * np.pi)
    r = result.sweep_residual
    s = np.median(np.abs(r)) or 1.0
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(f, np.arcsinh(r / s), lw=1.2)
    ax.axhline(0.0, color="k", lw=0.6)
    for fr in result.frequencies_hz:
        ax.axvline(fr, color="C3", ls="--", lw=0.8)
        ax.annotate(f"{fr:.4g} Hz", (fr, 0.0), rotation=90, va="bottom", ha="right", fontsize=8)
    unit = "N m" if result.residual_kind == "torque_Nm" else "rad"
    ax.set_xlabel("trial frequency (Hz)")
    from ..report.quantity import quantity  # 27.7 kN m, not 2.77e+04 N m (issue 25 #15)

    ax.set_ylabel(f"asinh(residual / {quantity(s, unit, 3)})")
    ax.set_title("Holzer residual")
    return _save(plt, fig, path)


def plot_mode_shapes(chain, modes, path: str | Path, max_modes: int = 6) -> Path:
    """Rotor twist of the first modes along the shaft (m when lengths are known)."""
    plt = _pyplot()
    pos = chain.rotor_positions()
    x = np.arange(chain.n_rotors) if pos is None else pos
    fig, ax = plt.subplots(figsize=(7, 4))
    for m in range(min(max_modes, len(modes.frequencies_hz))):
        ax.plot(x, modes.shapes[m], "o-", label=f"mode {m + 1}: {modes.frequencies_hz[m]:.4g} Hz")
        for node in modes.nodes[m]:
            i = node["between"][0]
            j = node["between"][1]
            xn = x[i] + node["fraction"] * (x[j] - x[i])
            ax.plot([xn], [0.0], "kx")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("position along equivalent shaft (m)" if pos is not None else "rotor index")
    ax.set_ylabel("twist (normalised)")
    ax.set_title("Torsional mode shapes (x: nodes)")
    ax.legend(fontsize=8)
    return _save(plt, fig, path)


def plot_campbell(crit, path: str | Path) -> Path:
    """Interference (Campbell) diagram: order lines, natural frequencies, critical speeds."""
    plt = _pyplot()
    lo, hi = crit.speed_range_rpm
    n = np.linspace(lo, hi, 200)
    fig, ax = plt.subplots(figsize=(7, 5))
    fmax = max(crit.natural_hz.max() * 1.2 if len(crit.natural_hz) else 0.0, crit.orders[-1] * hi / 60.0)
    for q in crit.orders:
        ax.plot(n, q * n / 60.0, color="0.6", lw=0.8)
        ax.annotate(f"{q:g}", (hi, q * hi / 60.0), fontsize=7, color="0.4")
    for m, f in enumerate(crit.natural_hz):
        ax.axhline(f, color=f"C{m % 10}", lw=1.2, label=f"mode {m + 1}: {f:.4g} Hz")
    for r in crit.in_range():
        ax.plot(r["speed_rpm"], r["natural_hz"], "ro", ms=5)
    if crit.operating_rpm is not None:
        n0 = crit.operating_rpm
        ax.axvline(n0, color="k", ls="--", lw=1.0, label=f"operating {n0:.5g} rpm")
        ax.axvspan(n0 * (1 - crit.required_margin), n0 * (1 + crit.required_margin), color="y", alpha=0.2)
    ax.set_xlim(lo, hi)
    ax.set_ylim(0.0, fmax)
    ax.set_xlabel("shaft speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title("Interference diagram (red: critical speeds in range)")
    ax.legend(fontsize=8, loc="upper left")
    return _save(plt, fig, path)
