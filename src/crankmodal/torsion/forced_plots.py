"""Figures of the forced torsional study (matplotlib imported inside each function)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .plots import _save


def _bands(ax, operating, band):
    for n in operating:
        ax.axvspan(n * (1 - band), n * (1 + band), color="0.85", zorder=0)
        ax.axvline(n, color="0.5", lw=0.8, zorder=0)


def plot_interference(res, natural_hz, operating, band, path: str | Path) -> Path:
    """Interference (Campbell) diagram: order lines coloured by the largest section torque."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LogNorm

    fig, ax = plt.subplots(figsize=(8, 5.5))
    n = res.speed_rpm
    torque = np.abs(res.section_torque).max(axis=2)  # (speeds, orders)
    vmax = max(torque.max(), 1e-12)
    norm = LogNorm(vmin=vmax * 1e-3, vmax=vmax)
    fmax = max(res.orders.max() * n[-1] / 60.0, 1.0)
    for j, q in enumerate(res.orders):
        f = q * n / 60.0
        pts = np.column_stack([n, f])
        segs = np.stack([pts[:-1], pts[1:]], axis=1)
        lc = LineCollection(segs, cmap="viridis", norm=norm, lw=2.0)
        lc.set_array(np.clip(torque[:-1, j], vmax * 1e-3, None))
        ax.add_collection(lc)
        ax.text(n[-1], f[-1], f" {q:g}", fontsize=7, va="center", clip_on=True)
    for f in natural_hz:
        if f <= fmax * 1.05:
            ax.axhline(f, color="C3", lw=1.0, ls="--")
    _bands(ax, operating, band)
    ax.set_xlim(n[0], n[-1] * 1.06)
    ax.set_ylim(0, min(fmax, 1.3 * max([f for f in natural_hz if f <= fmax] or [fmax]))
                if len(natural_hz) else fmax)
    ax.set_xlabel("shaft speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title("Orders coloured by their largest section torque; natural frequencies dashed",
                 fontsize=9)
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, label="N m")
    return _save(plt, fig, path)


def plot_response(res, train, path: str | Path, max_orders: int = 8) -> Path:
    """Vibratory torque vs speed in the most loaded section: per order and synthesised."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sec = int(np.argmax(res.section_torque_nm.max(axis=0)))
    per = np.abs(res.section_torque[:, :, sec])
    top = np.argsort(per.max(axis=0))[::-1][:max_orders]
    fig, ax = plt.subplots(figsize=(8, 5))
    for j in sorted(top):
        ax.semilogy(res.speed_rpm, per[:, j], lw=1.0, label=f"order {res.orders[j]:g}")
    ax.semilogy(res.speed_rpm, res.section_torque_nm[:, sec], "k", lw=2.0, label="synthesised")
    ax.set_xlabel("shaft speed (rpm)")
    ax.set_ylabel("vibratory torque (N m)")
    i, j = train.section_pairs[sec]
    name = ("wall" if i < 0 else train.labels[i]) + " - " + train.labels[j]
    ax.set_title(f"Section {sec + 1} ({name}): per order and synthesised (half peak-to-peak)", fontsize=9)
    ax.legend(fontsize=7, ncol=2)
    ax.grid(True, which="both", alpha=0.3)
    return _save(plt, fig, path)


def plot_stress(speed_rpm, stress, names, allowable, operating, band, is_stress: bool,
                path: str | Path) -> Path:
    """Synthesised vibratory stress of every section vs speed, the allowable and the bands."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5))
    scale = 1e-6 if is_stress else 1.0
    for i, nm in enumerate(names):
        ax.plot(speed_rpm, stress[:, i] * scale, lw=1.2, label=f"{i + 1}: {nm}")
    if allowable is not None:
        ax.axhline(allowable * scale, color="C3", lw=1.5, ls="--", label="allowable")
    _bands(ax, operating, band)
    ax.set_xlabel("shaft speed (rpm)")
    ax.set_ylabel("vibratory shear stress (MPa)" if is_stress else "vibratory torque (N m)")
    ax.set_title("Synthesised vibratory stress per section (grey: operating speed bands)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    return _save(plt, fig, path)
