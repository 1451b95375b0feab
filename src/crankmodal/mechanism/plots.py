"""Figures of a :class:`~crankmodal.mechanism.analysis.MechanismResults` (matplotlib, Agg).

``plot_accelerations`` is seed 000 Fig. 3, ``plot_gas_force`` Fig. 4, ``plot_piston_forces``
Fig. 5; ``plot_shaking_polar`` is the polar diagram of the shaking force.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import pyplot as _pyplot


def _deg(res):
    return np.degrees(res.theta)


def _labels(res):
    return [f"cyl {i + 1} ({np.degrees(c.bank_angle):.0f} deg)"
            for i, c in enumerate(res.machine.cylinders)]


def plot_accelerations(res, path):
    """Piston accelerations of all cylinders and rod angular accelerations (seed 000 Fig. 3)."""
    plt = _pyplot()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for i, lab in enumerate(_labels(res)):
        line, = ax1.plot(_deg(res), res.a[:, i], label=lab)
        ax1.plot(_deg(res), res.a_series[:, i], "--", lw=0.8, color=line.get_color())
        ax2.plot(_deg(res), res.beta_ddot[:, i], label=lab)
    ax1.set_ylabel("piston acceleration (m/s$^2$)")
    ax1.set_title("piston acceleration: exact (solid), 2nd-order series (dashed)")
    ax2.set_ylabel("rod angular acceleration (rad/s$^2$)")
    ax2.set_xlabel("crank angle (deg)")
    _finish(plt, fig, (ax1, ax2), path)


def _finish(plt, fig, axes, path, grid="major"):
    """Grid and legend on every axis, then write the PNG and free the figure."""
    for ax in axes:
        ax.grid(True, which=grid, alpha=0.3)
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
    """Polar diagram of the shaking force, with and without the counterweight, and per order."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    curves = [("total", res.shaking_force),
              ("with counterweight", res.shaking_force + res.counterweight_force)]
    curves += [(f"reciprocating order {k + 1}", f) for k, f in enumerate(res.order_force)]
    for lab, f in curves:
        f = np.vstack([f, f[:1]])
        ax.plot(f[:, 0] / 1e3, f[:, 1] / 1e3, label=lab)
    ax.plot(0, 0, "k+")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("F$_x$ (kN)")
    ax.set_ylabel("F$_y$ (kN)")
    ax.set_title("shaking force on the frame over one cycle")
    _finish(plt, fig, (ax,), path)


def write_all(res, out_dir) -> list[str]:
    """Write the four figures into ``out_dir``; returns their file names."""
    out_dir = Path(out_dir)
    figs = {
        "mechanism_accelerations.png": plot_accelerations,
        "mechanism_gas_force.png": plot_gas_force,
        "mechanism_piston_forces.png": plot_piston_forces,
        "mechanism_shaking_polar.png": plot_shaking_polar,
    }
    if res.machine.gas is None:  # no working process: no gas force to show
        del figs["mechanism_gas_force.png"]
    for name, fn in figs.items():
        fn(res, out_dir / name)
    return list(figs)
