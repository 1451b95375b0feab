"""PNG figures of a run with flexible bodies: main-bearing force flexible vs rigid, modal
coordinates (matplotlib on its own Agg canvas, imported here only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import pyplot as _plt
from .plots import _save, last_revolutions


def plot_main_bearing(hist, rigid, mech, sel, path: Path) -> Path:
    """Main-bearing force magnitude over the last revolution (flexible solid, rigid dashed),
    one panel for the sum and one per main journal, and the order amplitudes of the sum."""
    from .signals import order_amplitudes

    plt = _plt()
    joints = mech.main_joints if len(mech.main_joints) > 1 else []
    n = 2 + len(joints)
    fig, ax = plt.subplots(n, 1, figsize=(9, 2.6 * n))
    last = last_revolutions(hist, 1.0) & sel
    ang = hist.crank_angle[last]  # a coordinate of the run: continuous, no wrap
    deg = np.rad2deg(np.abs(ang - ang[0]))  # turned since the last revolution began
    series = [("main bearing (sum)", hist.main_bearing_force,
               None if rigid is None else rigid.main_bearing_force)]
    series += [(f"journal {j}", hist.joint_forces[j],
                None if rigid is None else rigid.joint_forces[j]) for j in joints]
    for a, (label, f, fr) in zip(ax, series):
        a.plot(deg, np.hypot(*f[last].T) / 1e3, lw=1.2, label="flexible")
        if fr is not None:
            a.plot(deg, np.hypot(*fr[last].T) / 1e3, "k--", lw=1.0, label="rigid twin")
        a.set(xlabel="crank angle in the last revolution [deg]", ylabel="|F| [kN]", title=label)
        a.grid(alpha=0.3)
        a.legend(loc="upper right", fontsize=8)
    orders = np.arange(13)
    t = hist.t[sel]
    rev = mech.revolution_hz
    if (t[-1] - t[0]) * rev >= 1.0 - 1e-9:
        af = order_amplitudes(t, hist.main_bearing_force[sel], rev, orders)
        w = 0.4
        ax[-1].bar(orders - w / 2, np.hypot(af[:, 0], af[:, 1]) / 1e3, w, label="flexible")
        if rigid is not None:
            ar = order_amplitudes(t, rigid.main_bearing_force[sel], rev, orders)
            ax[-1].bar(orders + w / 2, np.hypot(ar[:, 0], ar[:, 1]) / 1e3, w, color="0.4",
                       label="rigid twin")
        ax[-1].set(xlabel="order (per revolution)", ylabel="amplitude [kN]",
                   title="main-bearing force by order (x and y combined)", xticks=orders)
        ax[-1].legend(fontsize=8)
    return _save(plt, fig, path)


def plot_modal(hist, mech, path: Path) -> Path:
    """Modal coordinates of each flexible body against time (elastic modes only)."""
    plt = _plt()
    bodies = [b for b in mech.system.bodies if getattr(b, "n_elastic", 0) > 0]
    fig, ax = plt.subplots(len(bodies), 1, figsize=(9, 2.4 * len(bodies)), squeeze=False)
    for a, b in zip(ax[:, 0], bodies):
        xi = hist.modal[b.name][:, :b.n_elastic]
        for j in range(min(b.n_elastic, 6)):
            a.plot(hist.t, xi[:, j] * 1e3, lw=0.8, label=f"{b.frequencies_hz[j]:.0f} Hz")
        a.set(xlabel="t [s]", ylabel="ξ [mm kg^½]", title=f"{b.name}: modal coordinates")
        a.legend(fontsize=7, ncol=3, loc="upper right")
        a.grid(alpha=0.3)
    return _save(plt, fig, path)


def flexible_figures(hist, rigid, mech, sel, out: Path) -> list[str]:
    """Write the figures; return their file names."""
    figs = [plot_main_bearing(hist, rigid, mech, sel, out / "dynamics_flexible_main_bearing.png"),
            plot_modal(hist, mech, out / "dynamics_flexible_modes.png")]
    return [f.name for f in figs]
