"""PNG figures of a dynamics run (matplotlib, Agg backend, imported here only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...plotting import pyplot as _plt


def _save(plt, fig, path: Path) -> Path:
    """Lay out, write (PNG, 110 dpi) and close a figure."""
    from ...results import savefig_atomic

    fig.tight_layout()
    try:
        savefig_atomic(fig, path, dpi=110)
    finally:
        plt.close(fig)
    return path


def mark_window(ax, window, label: bool = True) -> None:
    """Shade the results (statistics) window ``(start, end)`` in s on a time axis; None: no
    window."""
    if window is None:
        return
    ax.axvspan(window[0], window[1], color="0.85", alpha=0.5, lw=0, zorder=0,
               label="statistics window" if label else None)


def last_revolutions(hist, n: float) -> np.ndarray:
    """Boolean mask of the output times within the last ``n`` crank revolutions (by the crank
    angle turned, either sense; the whole run when it is shorter)."""
    a = np.asarray(hist.crank_angle, float)
    if a.size == 0:
        return np.zeros(0, bool)
    return np.abs(a[-1] - a) <= 2.0 * np.pi * n


def plot_piston(hist, ideal, path: Path, piston: int = 0, revolutions: float = 2.0,
                window=None) -> Path:
    """Piston acceleration: the whole run against time (left; the statistics ``window``, s,
    shaded), and the last ``revolutions`` against crank angle (middle) and as an
    acceleration-velocity phase diagram (right). The ideal (clearance-free) run is drawn black
    and dashed on top of the run with clearance, so both stay visible where the clearance trace
    spikes around it."""
    plt = _plt()
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.3))
    sel = last_revolutions(hist, revolutions)
    # crank angle turned since the window's start (either sense), the same origin for both runs
    a0 = hist.crank_angle[sel][0] if sel.any() else 0.0
    sense = 1.0 if hist.crank_angle[-1] >= hist.crank_angle[0] else -1.0
    deg = np.degrees(sense * (hist.crank_angle[sel] - a0))
    kw = {"color": "tab:orange", "lw": 0.6, "alpha": 0.85, "zorder": 1}
    ax[0].plot(hist.t, hist.piston_acceleration[:, piston], label="with clearance", **kw)
    ax[1].plot(deg, hist.piston_acceleration[sel, piston], **kw)
    ax[2].plot(hist.piston_velocity[sel, piston], hist.piston_acceleration[sel, piston], **kw)
    if ideal is not None:
        isel = last_revolutions(ideal, revolutions)
        ideg = np.degrees(sense * (ideal.crank_angle[isel] - a0))
        kw = {"color": "black", "ls": "--", "lw": 1.4, "zorder": 3}
        ax[0].plot(ideal.t, ideal.piston_acceleration[:, piston], label="ideal joints", **kw)
        ax[1].plot(ideg, ideal.piston_acceleration[isel, piston], **kw)
        ax[2].plot(ideal.piston_velocity[isel, piston], ideal.piston_acceleration[isel, piston],
                   **kw)
    mark_window(ax[0], window)
    ax[0].set(xlabel="t [s]", ylabel="piston acceleration [m/s²]",
              title=f"piston {piston + 1}, whole run")
    ax[1].set(xlabel="crank angle turned in the window [°]", ylabel="piston acceleration [m/s²]",
              title=f"last {revolutions:g} revolutions")
    ax[2].set(xlabel="piston velocity [m/s]", ylabel="piston acceleration [m/s²]",
              title=f"phase diagram, last {revolutions:g} revolutions")
    ax[0].legend(loc="upper right")
    return _save(plt, fig, path)


def plot_bearing_force(hist, spectrum, path: Path, ideal_spectrum=None, ideal=None,
                       window=None) -> Path:
    """Main-bearing force components over time (the ``ideal``-joint run dashed black, the
    statistics ``window``, s, shaded) and their amplitude spectrum over the window (Hz and
    orders)."""
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    ax[0].plot(hist.t, hist.main_bearing_force[:, 0], lw=0.7, label="F_x")
    ax[0].plot(hist.t, hist.main_bearing_force[:, 1], lw=0.7, label="F_y")
    if ideal is not None:
        ax[0].plot(ideal.t, ideal.main_bearing_force[:, 0], "k--", lw=0.9, label="ideal joints")
        ax[0].plot(ideal.t, ideal.main_bearing_force[:, 1], "k--", lw=0.9)
    mark_window(ax[0], window)
    ax[0].set(xlabel="t [s]", ylabel="main-bearing force [N]")
    ax[0].legend(fontsize=8)
    f = spectrum.frequency_hz
    if ideal_spectrum is not None:
        ax[1].semilogy(ideal_spectrum.frequency_hz, ideal_spectrum.amplitude[:, 0] + 1e-9, "k--",
                       lw=0.8, label="ideal F_x")
    ax[1].semilogy(f, spectrum.amplitude[:, 0] + 1e-9, lw=0.8, label="F_x")
    ax[1].semilogy(f, spectrum.amplitude[:, 1] + 1e-9, lw=0.8, label="F_y")
    ax[1].set(xlabel="frequency [Hz]", ylabel="amplitude [N]", xlim=(0, min(f[-1], 2000.0)))
    sec = ax[1].secondary_xaxis("top", functions=(lambda x: x / _rev(spectrum),
                                                  lambda o: o * _rev(spectrum)))
    sec.set_xlabel("engine order")
    ax[1].legend()
    return _save(plt, fig, path)


def _rev(spectrum):
    k = np.flatnonzero(spectrum.order > 0)
    return spectrum.frequency_hz[k[0]] / spectrum.order[k[0]] if k.size else 1.0


def draw_orbit(ax, hist, name: str, clearance: float, sel: np.ndarray):
    """Draw one joint's orbit (in units of the clearance c) on ``ax`` over the samples ``sel``,
    a line coloured by time, and the clearance circle |e| = c bold on top; limits 1.15 c or the
    orbit's reach. Returns the orbit's ``LineCollection`` (its array: the segments' times, s)."""
    from matplotlib.collections import LineCollection

    d = hist.contact[name]
    xy = np.column_stack([d["ex_bearing"][sel], d["ey_bearing"][sel]]) / clearance
    t = np.asarray(hist.t)[sel]
    th = np.linspace(0, 2 * np.pi, 361)
    ax.plot(np.cos(th), np.sin(th), "k-", lw=2.5, zorder=3)
    lc = LineCollection(np.stack([xy[:-1], xy[1:]], axis=1), cmap="viridis", lw=0.9, zorder=2)
    lc.set_array(0.5 * (t[:-1] + t[1:]))
    ax.add_collection(lc)
    lim = max(1.15, 1.05 * float(np.abs(xy).max(initial=0.0)))
    ax.set(aspect="equal", xlim=(-lim, lim), ylim=(-lim, lim),
           xlabel="e_x / c (bearing frame)", ylabel="e_y / c")
    return lc


def plot_orbit(hist, clearances, path: Path, revolutions: float = 2.0) -> Path:
    """Journal-centre orbit relative to the bore (bearing body's frame), in units of the radial
    clearance c, over the last ``revolutions`` crank revolutions, coloured by time; the
    clearance circle (|e| = c, where contact starts) bold."""
    plt = _plt()
    n = max(len(clearances), 1)
    fig, axs = plt.subplots(1, n, figsize=(5.2 * n, 4.6), squeeze=False)
    sel = last_revolutions(hist, revolutions)
    for ax, (name, c) in zip(axs[0], clearances.items()):
        lc = draw_orbit(ax, hist, name, c, sel)
        ax.set_title(f"journal orbit, {name}, last {revolutions:g} revolutions\n"
                     f"(bold circle |e| = c: contact beyond it)")
        fig.colorbar(lc, ax=ax, label="t [s]", shrink=0.85)
    return _save(plt, fig, path)


def plot_contact(hist, path: Path, ideal=None, window=None) -> Path:
    """Per clearance joint: the contact normal force (and the oil film's force, if any)
    against the force the ``ideal`` pin carries there (dashed black), impacts marked, and the
    penetration; the statistics ``window``, s, shaded."""
    plt = _plt()
    fig, ax = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for name, d in hist.contact.items():
        ax[0].plot(hist.t, d["fn"], lw=0.7, label=f"{name} contact")
        film = d.get("film_force")
        if film is not None and np.any(np.asarray(film) > 0.0):
            ax[0].plot(hist.t, film, lw=0.7, label=f"{name} oil film")
        if ideal is not None and name in ideal.joint_forces:
            f = ideal.joint_forces[name]
            ax[0].plot(ideal.t, np.hypot(f[:, 0], f[:, 1]), "k--", lw=0.9,
                       label=f"{name}, ideal pin")
        ax[1].plot(hist.t, np.maximum(d["penetration"], 0.0) * 1e6, lw=0.7, label=name)
        ons = np.asarray(hist.onsets.get(name, []), float).reshape(-1, 2)
        if ons.size:
            ax[0].plot(ons[:, 0], np.zeros(len(ons)), "rv", ms=3)
    for k, a in enumerate(ax):
        mark_window(a, window, label=k == 0)
    ax[0].set(ylabel="joint force [N]")
    ax[1].set(xlabel="t [s]", ylabel="penetration [µm]")
    ax[0].legend(fontsize=8)
    return _save(plt, fig, path)


def plot_drive(hist, ideal, path: Path, window=None) -> Path:
    """Drive torque and power against time (ideal joints dashed, the statistics ``window``,
    s, shaded)."""
    plt = _plt()
    fig, ax = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    if ideal is not None:
        ax[0].plot(ideal.t, ideal.drive_torque, "k--", lw=0.8, label="ideal")
        ax[1].plot(ideal.t, ideal.drive_power, "k--", lw=0.8)
    ax[0].plot(hist.t, hist.drive_torque, lw=0.7, label="with clearance")
    ax[1].plot(hist.t, hist.drive_power, lw=0.7)
    for k, a in enumerate(ax):
        mark_window(a, window, label=k == 0)
    # the sign (issue 25 #15): about +z, while a crank turning from +y towards +x turns about -z
    ax[0].set(ylabel="drive torque on the crank\nabout +z [N m]")
    ax[1].set(xlabel="t [s]", ylabel="drive power = torque x crank\nspeed about +z [W] (> 0: delivered)")
    ax[0].legend()
    return _save(plt, fig, path)


def plot_energy(hist, path: Path, ideal=None, window=None) -> Path:
    """Energy bookkeeping: every term and the balance residual; the ``ideal``-joint run's
    kinetic energy dashed black, the statistics ``window``, s, shaded."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(10, 4.5))
    for k, v in hist.energy.items():
        ax.plot(hist.t, v, lw=1.2 if k == "residual" else 0.8, label=k)
    if ideal is not None and "kinetic" in ideal.energy:
        ax.plot(ideal.t, ideal.energy["kinetic"], "k--", lw=0.9, label="kinetic, ideal joints")
    mark_window(ax, window)
    ax.set(xlabel="t [s]", ylabel="energy [J]")
    ax.legend(fontsize=7)
    return _save(plt, fig, path)


def plot_study(study, path: Path) -> Path:
    """Error against wall time over the tolerance sequence: the single-trajectory peaks (left)
    and the per-revolution statistics (right; filled markers: converged, i.e. within the
    study's ``rel_tol`` of the tightest rtol from there on: ``convergence_criterion``)."""
    plt = _plt()
    stats = study.get("statistics") or {}
    fig, axs = plt.subplots(1, 2 if stats else 1, figsize=(13 if stats else 7, 4.5),
                            squeeze=False)
    ax = axs[0, 0]
    w = np.asarray(study["wall_time_s"])
    for k in ("d_peak_contact_force", "d_peak_piston_acceleration", "d_main_bearing_order_rms"):
        ax.loglog(w[:-1], np.maximum(np.asarray(study[k])[:-1], 1e-12), "o-", label=k[2:])
    for x, y, r in zip(w[:-1], np.asarray(study["d_peak_piston_acceleration"])[:-1],
                       study["rtol"][:-1]):
        ax.annotate(f"rtol {r:g}", (x, max(y, 1e-12)), fontsize=7)
    ax.set(xlabel="wall time [s]", ylabel="relative change vs tightest rtol",
           title="single-trajectory peaks")
    ax.legend(fontsize=8)
    if stats:
        ax = axs[0, 1]
        for name, c in stats.items():
            # a change of exactly zero (e.g. no impacts either way) has no place on a log axis
            d = np.array([np.nan if not v else v for v in c["rel_change"][:-1]])
            ok = np.asarray(c["converged"][:-1], bool)
            (line,) = ax.loglog(w[:-1], d, "-", lw=0.8, label=name)
            ax.loglog(w[:-1][ok], d[ok], "o", color=line.get_color(), ms=4)
            ax.loglog(w[:-1][~ok], d[~ok], "o", mfc="none", color=line.get_color(), ms=4)
        ax.axhline(0.01, color="k", ls=":", lw=0.8)
        for x, r in zip(w[:-1], study["rtol"][:-1]):
            ax.annotate(f"rtol {r:g}", (x, 0.02), xycoords=ax.get_xaxis_transform(), fontsize=7,
                        rotation=90, va="bottom")
        ax.set(xlabel="wall time [s]", ylabel="relative change vs tightest rtol",
               title="per-revolution statistics (filled: converged)")
        ax.legend(fontsize=5, ncol=2)
    return _save(plt, fig, path)
