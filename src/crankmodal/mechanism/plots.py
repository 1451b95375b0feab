"""Figures of a :class:`~crankmodal.mechanism.analysis.MechanismResults` (matplotlib, Agg).

``plot_accelerations`` is seed 000 Fig. 3, ``plot_gas_force`` Fig. 4, ``plot_piston_forces``
Fig. 5; ``plot_shaking_polar`` is the polar diagram of the shaking force, ``plot_crank_torque``
the crank torque (rods on the crankshaft, positive in the sense of rotation). Legends list only
curves that can be seen (:func:`visible_curves`); the others are named in a note.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import COINCIDE_FRACTION, hidden_note, visible_curves
from ..plotting import pyplot as _pyplot


def _deg(res):
    return np.degrees(res.theta)


def _labels(res):
    return [f"cyl {i + 1} ({np.degrees(c.bank_angle):.0f} deg)"
            for i, c in enumerate(res.machine.cylinders)]


def plot_accelerations(res, path):
    """Piston accelerations of all cylinders and rod angular accelerations (seed 000 Fig. 3).

    The 2nd-order series is drawn dashed only where it can be seen beside the exact curve;
    otherwise the title gives its largest difference from the exact one."""
    from ..report.quantity import percent, quantity

    plt = _pyplot()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    a, a_series = np.asarray(res.a), np.asarray(res.a_series)
    peak = float(np.max(np.abs(a)))
    diff = float(np.max(np.abs(a - a_series)))
    dashed = diff > COINCIDE_FRACTION * peak
    for i, lab in enumerate(_labels(res)):
        line, = ax1.plot(_deg(res), a[:, i], label=lab)
        if dashed:
            ax1.plot(_deg(res), a_series[:, i], "--", lw=0.8, color=line.get_color())
        ax2.plot(_deg(res), res.beta_ddot[:, i], label=lab)
    ax1.set_ylabel("piston acceleration (m/s$^2$)")
    if dashed:
        ax1.set_title("piston acceleration: exact (solid), 2nd-order series (dashed)")
    else:
        ax1.set_title(f"piston acceleration, exact; the 2nd-order series is within "
                      f"{quantity(diff, 'm/s²', 2)} ({percent(diff / peak, 2)} of the peak)\n"
                      f"of it and not drawn", fontsize=10)
    ax2.set_ylabel("rod angular acceleration (rad/s$^2$)")
    ax2.set_xlabel("crank angle (deg)")
    _finish(plt, fig, (ax1, ax2), path)


def _finish(plt, fig, axes, path, grid="major"):
    """Grid and legend on every axis, then write the PNG and free the figure."""
    for ax in axes:
        ax.grid(True, which=grid, alpha=0.3)
        if ax.get_legend_handles_labels()[1]:
            ax.legend(fontsize=8)
    from ..results import savefig_atomic

    fig.tight_layout()
    try:
        savefig_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)


def plot_gas_force(res, path):
    """Gas force on each piston over the cycle, and the p-V diagrams (seed 000 Fig. 4)."""
    plt = _pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    for i, lab in enumerate(_labels(res)):
        ax1.plot(_deg(res), res.gas_force[:, i] / 1e3, label=lab)
        ax2.loglog(res.volume[:, i] * 1e6, res.pressure[:, i] / 1e6, label=lab)
    ax1.set_xlabel("crank angle (deg)")
    ax1.set_ylabel("gas force towards the crank (kN)")
    ax2.set_xlabel("cylinder volume (cm$^3$)")
    ax2.set_ylabel("pressure (MPa abs)")
    _finish(plt, fig, (ax1, ax2), path, grid="both")


def plot_piston_forces(res, path):
    """Combined piston force and side thrust of each cylinder (seed 000 Fig. 5)."""
    plt = _pyplot()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for i, lab in enumerate(_labels(res)):
        ax1.plot(_deg(res), res.piston_force[:, i] / 1e3, label=lab)
        ax2.plot(_deg(res), res.side_thrust[:, i] / 1e3, label=lab)
    ax1.set_ylabel("piston force (kN)")
    ax2.set_ylabel("side thrust (kN)")
    ax2.set_xlabel("crank angle (deg)")
    _finish(plt, fig, (ax1, ax2), path)


def plot_shaking_polar(res, path):
    """Polar diagram of the shaking force, with and without the counterweight, and per order.

    Only curves that can be seen are drawn (and listed in the legend); a zero curve (a cancelled
    order, a fully balanced shaking force) or one lying on another is named in a note."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    curves = [("total", res.shaking_force),
              ("with counterweight", res.shaking_force + res.counterweight_force)]
    curves += [(f"reciprocating order {k + 1}", f) for k, f in enumerate(res.order_force)]
    drawn, hidden = visible_curves([(lab, np.asarray(f, float) / 1e3) for lab, f in curves])
    for lab, f in drawn:
        f = np.vstack([f, f[:1]])
        ax.plot(f[:, 0], f[:, 1], label=lab)
    ax.plot(0, 0, "k+")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("F$_x$ (kN)")
    ax.set_ylabel("F$_y$ (kN)")
    ax.set_title("shaking force on the frame over one cycle")
    hidden_note(ax, hidden)
    _finish(plt, fig, (ax,), path)


def plot_crank_torque(res, path):
    """Crank torque over the cycle, total and per cylinder, with its mean.

    Sign convention (:mod:`crankmodal.mechanism`): the torque the rods exert on the
    crankshaft, positive in the sense of rotation (negative on average for a compressor)."""
    from ..report.quantity import quantity

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    per = np.asarray(res.cylinder_torque, float)
    curves = [(lab, per[:, i]) for i, lab in enumerate(_labels(res))]
    drawn, hidden = visible_curves([("total", np.asarray(res.crank_torque, float))] + curves)
    for lab, t in drawn:
        ax.plot(_deg(res), t, label=lab, **({"color": "k", "lw": 1.6} if lab == "total"
                                            else {"lw": 0.8}))
    mean = float(np.mean(res.crank_torque))
    ax.axhline(mean, color="k", ls=":", lw=1.0, label=f"mean {quantity(mean, 'N m')}")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("crank angle (deg)")
    ax.set_ylabel("torque of the rods on the crankshaft (N m)\n+ in the sense of rotation")
    ax.set_title("crank torque (< 0: taken from the crank, as in a compressor)", fontsize=10)
    hidden_note(ax, hidden)
    _finish(plt, fig, (ax,), path)


def write_all(res, out_dir) -> list[str]:
    """Write the figures into ``out_dir`` (the gas force only with a gas model); returns their
    file names."""
    out_dir = Path(out_dir)
    figs = {
        "mechanism_accelerations.png": plot_accelerations,
        "mechanism_gas_force.png": plot_gas_force,
        "mechanism_piston_forces.png": plot_piston_forces,
        "mechanism_shaking_polar.png": plot_shaking_polar,
        "mechanism_crank_torque.png": plot_crank_torque,
    }
    if res.machine.gas is None:  # no working process: no gas force to show
        del figs["mechanism_gas_force.png"]
    for name, fn in figs.items():
        fn(res, out_dir / name)
    return list(figs)
