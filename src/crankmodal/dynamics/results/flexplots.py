"""PNG figures of a run with flexible bodies: main-bearing force (a four-bar: joints A-D)
flexible vs rigid, modal coordinates (matplotlib on its own Agg canvas, imported here only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...plotting import pyplot as _plt
from .plots import _save, last_revolutions

#: what each joint of the four-bar connects (for the panel titles)
FOUR_BAR_JOINTS = {"A": "crank pivot", "B": "crank-coupler", "C": "coupler-rocker",
                   "D": "rocker pivot"}


def _force_series(hist, rigid, machine) -> list[tuple[str, np.ndarray, np.ndarray | None]]:
    """The forces drawn: (title, flexible, rigid twin or None), each an (n, 2) array in N.

    A four-bar: its joints A, B, C, D. A crank train: the main-bearing sum, then each main
    journal when there are several."""
    if machine.kind == "four_bar":
        return [(f"joint {j} ({what}) of the four-bar", hist.joint_forces[j],
                 None if rigid is None else rigid.joint_forces[j])
                for j, what in FOUR_BAR_JOINTS.items() if j in hist.joint_forces]
    joints = machine.main_joints if len(machine.main_joints) > 1 else []
    series = [("main bearing (sum)", hist.main_bearing_force,
               None if rigid is None else rigid.main_bearing_force)]
    return series + [(f"journal {j}", hist.joint_forces[j],
                      None if rigid is None else rigid.joint_forces[j]) for j in joints]


def plot_main_bearing(hist, rigid, machine, sel, path: Path) -> Path:
    """Joint forces over the last revolution (flexible solid, rigid twin dashed) and the order
    amplitudes of the main-bearing force; ``machine``: a
    :class:`~crankmodal.dynamics.results.result.MachineInfo` (``kind``, ``main_joints``,
    ``revolution_hz``), ``sel``: the results window's samples.

    A crank train: one panel for the main-bearing force magnitude (the sum) and one per main
    journal. A four-bar: one panel per joint A, B, C, D, each with the magnitude of the
    flexible-minus-rigid force vector on a right-hand axis (N), and the orders of joint A."""
    from .signals import order_amplitudes

    plt = _plt()
    four_bar = machine.kind == "four_bar"
    series = _force_series(hist, rigid, machine)
    n = 1 + len(series)
    fig, ax = plt.subplots(n, 1, figsize=(9, 2.6 * n))
    # the window's last revolution: a window of whole working cycles may end before the run
    idx = np.flatnonzero(sel)
    last = (sel & (np.abs(hist.crank_angle[idx[-1]] - hist.crank_angle) <= 2.0 * np.pi)
            if idx.size else last_revolutions(hist, 1.0))
    ang = hist.crank_angle[last]  # a coordinate of the run: continuous, no wrap
    deg = np.rad2deg(np.abs(ang - ang[0]))  # turned since the last revolution began
    for a, (label, f, fr) in zip(ax, series):
        lines = a.plot(deg, np.hypot(*f[last].T) / 1e3, lw=1.2, label="flexible")
        if fr is not None:
            lines += a.plot(deg, np.hypot(*fr[last].T) / 1e3, "k--", lw=1.0, label="rigid twin")
            if four_bar:
                b = a.twinx()
                lines += b.plot(deg, np.hypot(*(f[last] - fr[last]).T), color="tab:red",
                                lw=0.8, label="|flexible - rigid| (right)")
                b.set_ylabel("|ΔF| [N]", color="tab:red")
                b.tick_params(axis="y", colors="tab:red")
                b.set_ylim(bottom=0.0)
        a.set(xlabel="crank angle in the last revolution [deg]", ylabel="|F| [kN]", title=label)
        a.grid(alpha=0.3)
        if four_bar:  # one row at the top middle, clear of the peaks and the ringing
            a.legend(lines, [ln.get_label() for ln in lines], loc="upper center", fontsize=8,
                     ncol=len(lines))
        else:
            a.legend(loc="upper right", fontsize=8)
    orders = np.arange(13)
    t = hist.t[sel]
    rev = machine.revolution_hz
    if (t[-1] - t[0]) * rev >= 1.0 - 1e-9:
        af = order_amplitudes(t, hist.main_bearing_force[sel], rev, orders)
        w = 0.4
        ax[-1].bar(orders - w / 2, np.hypot(af[:, 0], af[:, 1]) / 1e3, w, label="flexible")
        if rigid is not None:
            ar = order_amplitudes(t, rigid.main_bearing_force[sel], rev, orders)
            ax[-1].bar(orders + w / 2, np.hypot(ar[:, 0], ar[:, 1]) / 1e3, w, color="0.4",
                       label="rigid twin")
        what = "joint A (crank pivot)" if four_bar else "main-bearing"
        ax[-1].set(xlabel="order (per revolution)", ylabel="amplitude [kN]",
                   title=f"{what} force by order (x and y combined)", xticks=orders)
        ax[-1].legend(fontsize=8)
    return _save(plt, fig, path)


def plot_modal(hist, machine, path: Path) -> Path:
    """Modal coordinates of each flexible body against time (elastic modes only, the first
    six); ``machine.flexible``: body name -> its elastic modes' frequencies, Hz."""
    plt = _plt()
    bodies = list(machine.flexible.items())
    fig, ax = plt.subplots(len(bodies), 1, figsize=(9, 2.4 * len(bodies)), squeeze=False)
    for a, (name, freqs) in zip(ax[:, 0], bodies):
        xi = hist.modal[name][:, :len(freqs)]
        for j in range(min(len(freqs), 6)):
            a.plot(hist.t, xi[:, j] * 1e3, lw=0.8, label=f"{freqs[j]:.0f} Hz")
        a.set(xlabel="t [s]", ylabel="ξ [mm kg^½]", title=f"{name}: modal coordinates")
        a.legend(fontsize=7, ncol=3, loc="upper right")
        a.grid(alpha=0.3)
    return _save(plt, fig, path)
