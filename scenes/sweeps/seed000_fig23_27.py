"""Seed 000 Figs. 23 and 27 as the seed ran them, as ensembles (docs/guide/seed_studies.md).

Fig. 23: drive power of the four-star with ideal joints and with a 0.1 mm big end 1 (IMPACT
contact, Coulomb friction), speed ramped to 1480 rpm in 0.1 s; the seed reports "torque power
amplitudes" of 819 W (ideal) and 6711 W (clearance). Run with and without the gas forces and with
gravity, so that each candidate meaning of the seed's numbers has a measured value.

Fig. 27: clearance added cumulatively (big end 1; 1 + 2; 1 + 2 + 3; all four, each 0.1 mm, the
others ideal); the main-bearing X (and Y) excitation force per revolution.

Every clearance case is an ensemble of trajectories started 1e-12 apart (as
``dynamics.ensemble``); each trajectory gives per-revolution values, its mean over the
revolutions is one sample, and the case's value is the mean over the trajectories with its
standard error (spread / sqrt(N)).

Usage (from the repository root; one process, the machine is shared)::

    .venv/bin/python scenes/sweeps/seed000_fig23_27.py fig23 [--trajectories 8] [--end-time 0.5]
    .venv/bin/python scenes/sweeps/seed000_fig23_27.py fig27 [--trajectories 8] [--end-time 0.5]
    .venv/bin/python scenes/sweeps/seed000_fig23_27.py plot      # docs/img/seed000_fig2*.png

Results go to ``out/seed_studies/fig23.json`` and ``fig27.json`` (``--out`` to change).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "four_star_dynamics.toml"
IMG = ROOT / "docs" / "img"
G = 9.80665  # m/s^2, standard gravity (ADAMS' default magnitude)
#: orders kept by the "filtered" power amplitude (impact spikes removed): 12 orders, 296 Hz
FILTER_ORDERS = 12
BIG_ENDS = ("big_end_1", "big_end_2", "big_end_3", "big_end_4")
FIG27_CASES = {f"case {k}": BIG_ENDS[:k] for k in range(1, 5)}


def scene(joints=("big_end_1",), gas: bool = True, gravity: bool = False,
          end_time: float = 0.5, overrides=()):
    """The Fig. 23/27 scene: ``four_star_dynamics.toml`` with clearance in ``joints``.

    Parameters
    ----------
    joints : sequence of str
        Big ends with a 0.1 mm radial clearance (the scene's big end 1 settings copied).
    gas : bool
        Keep the mechanism's gas forces; False: inertia only (``[mechanism.gas] model =
        "none"``, and the mechanism's piston friction, which follows from the indicated power,
        dropped; ``--set dynamics.gas_force_n`` does not reach a ``from_mechanism`` train).
    gravity : bool
        Gravity -9.80665 m/s^2 along y (the vertical cylinder 1 axis).
    end_time : float
        s.
    overrides : sequence of str
        Further ``section.key=value`` assignments.
    """
    from crankmodal.scene import load_scene

    sc = load_scene(SCENE, list(overrides) + [f"dynamics.end_time={end_time!r}"])
    dyn = sc.sections["dynamics"]
    one = dict(dyn["clearances"][0])
    dyn["clearances"] = [dict(one, joint=j) for j in joints]
    if not joints:
        dyn["clearances"] = []
    if not gas:
        sc.sections["mechanism"]["gas"] = {"model": "none"}
        sc.sections["mechanism"].pop("friction", None)
    if gravity:
        dyn["gravity"] = [0.0, -G]
    return sc


def prepare(sc):
    """Validated parameters, the mechanism, solver settings and output step of a scene."""
    from crankmodal.dynamics.run import timescales
    from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
    from crankmodal.runner import check

    params = check(sc)
    p = params["dynamics"]
    mech = build_mechanism(p, params["mechanism"])
    rev_hz = mech.revolution_hz
    settings = solver_settings(p, 60.0 * rev_hz)
    settings = replace(settings, time_scales=tuple(timescales.joint_time_scales(mech)))
    dt = p["output_step"] or 1.0 / (360.0 * rev_hz)
    return p, mech, settings, dt


def window(t, p, rev_hz):
    """Start (s) and revolution index of every sample of the results window (whole revolutions
    from one revolution after the ramp, as the stage's statistics)."""
    from crankmodal.dynamics.results.stats import results_window, revolution_blocks

    t0, _, n, _ = results_window(t, p["ramp_time"], p["spectrum_start"], rev_hz)
    block, n = revolution_blocks(t, t0, rev_hz)
    return t0, block, n


def power_per_rev(P, block, n) -> dict:
    """Per-revolution numbers of a drive-power record (W): mean, half range (max - min)/2,
    RMS of the fluctuation, the same half range of the record low-passed to orders <= 12
    (impact spikes removed), and the amplitudes of orders 1-8."""
    out = {k: np.zeros(n) for k in ("mean", "half_range", "rms_fluctuation",
                                    "half_range_filtered")}
    orders = np.zeros((n, 8))
    for i in range(n):
        x = np.asarray(P[block == i], float)
        X = np.fft.rfft(x)
        X[FILTER_ORDERS + 1:] = 0.0
        xf = np.fft.irfft(X, x.size)
        out["mean"][i] = x.mean()
        out["half_range"][i] = 0.5 * np.ptp(x)
        out["rms_fluctuation"][i] = x.std()
        out["half_range_filtered"][i] = 0.5 * np.ptp(xf)
        orders[i] = 2.0 * np.abs(np.fft.rfft(x)[1:9]) / x.size
    out.update({f"order_{k}": orders[:, k - 1] for k in range(1, 9)})
    return out


def force_per_rev(F, block, n) -> dict:
    """Per-revolution numbers of one component of the main-bearing force (N): peak |F|, mean
    (order 0), RMS of the fluctuation, order 1-4 amplitudes and the RMS above order 12
    (> 296 Hz)."""
    out = {k: np.zeros(n) for k in ("peak", "mean", "rms_fluctuation", "rms_above_12")}
    orders = np.zeros((n, 4))
    for i in range(n):
        x = np.asarray(F[block == i], float)
        X = np.fft.rfft(x) / x.size
        out["peak"][i] = np.max(np.abs(x))
        out["mean"][i] = x.mean()
        out["rms_fluctuation"][i] = x.std()
        out["rms_above_12"][i] = math.sqrt(2.0 * np.sum(np.abs(X[FILTER_ORDERS + 1:]) ** 2))
        orders[i] = 2.0 * np.abs(X[1:5])
    out.update({f"order_{k}": orders[:, k - 1] for k in range(1, 5)})
    return out


def trajectory_numbers(hist, p, rev_hz) -> dict:
    """Every per-revolution number of one trajectory, summarised over its revolutions
    (``crankmodal.dynamics.results.stats.summarise``)."""
    from crankmodal.dynamics.results.stats import summarise

    t0, block, n = window(hist.t, p, rev_hz)
    pw = power_per_rev(hist.drive_power, block, n)
    fx = force_per_rev(hist.main_bearing_force[:, 0], block, n)
    fy = force_per_rev(hist.main_bearing_force[:, 1], block, n)
    out = {"window_start_s": t0, "n_revolutions": n,
           "power": {k: summarise(v) for k, v in pw.items()},
           "force_x": {k: summarise(v) for k, v in fx.items()},
           "force_y": {k: summarise(v) for k, v in fy.items()},
           "impacts": int(sum(len(o) for o in hist.onsets.values())) if hist.onsets else 0,
           "rhs_evals": int(hist.nfev), "wall_time_s": float(hist.wall_time)}
    return out


def ensemble_of(rows: list[dict]) -> dict:
    """Mean over trajectories of each per-trajectory mean, its spread and standard error."""
    out = {}
    for group in [g for g in ("power", "force_x", "force_y") if g in rows[0]]:
        out[group] = {}
        for key in rows[0][group]:
            v = np.array([r[group][key]["mean"] for r in rows], float)
            s = float(v.std(ddof=1)) if v.size > 1 else 0.0
            out[group][key] = {"mean": float(v.mean()), "std": s, "sem": s / math.sqrt(v.size),
                               "min": float(v.min()), "max": float(v.max()),
                               "revolution_sem_median": float(np.median(
                                   [r[group][key]["sem"] for r in rows]))}
    out["n_trajectories"] = len(rows)
    out["n_revolutions"] = rows[0]["n_revolutions"]
    return out


def run_case(sc, n_traj: int, log=print, histories: Path | None = None) -> dict:
    """The ideal-joint twin (one trajectory: smooth) and ``n_traj`` clearance trajectories.

    ``histories``: an ``.npz`` file to write the drive power of the ideal twin and of the
    first trajectory to (``t`` s, ``ideal_drive_power``, ``drive_power`` W), for a time plot.
    """
    from crankmodal.dynamics.run.ensemble import EPS
    from crankmodal.dynamics.run.simulate import simulate

    p, mech, settings, dt = prepare(sc)
    rev_hz = mech.revolution_hz
    t_end, tol = p["end_time"], p["energy_tolerance"]
    t_wall = time.perf_counter()
    ideal = simulate(mech, t_end, dt, settings, ideal=True, energy_tolerance=tol)
    res = {"ideal": trajectory_numbers(ideal, p, rev_hz), "speed_rpm": 60.0 * rev_hz,
           "end_time_s": t_end, "joints": [c.name for c in mech.system.clearances],
           "gravity": list(p["gravity"]), "trajectories": []}
    keep = {"t": ideal.t, "ideal_drive_power": ideal.drive_power}
    del ideal
    for k in range(n_traj if mech.system.clearances else 0):
        m = replace(mech, q0=np.asarray(mech.q0, float) * (1.0 + k * EPS))
        h = simulate(m, t_end, dt, settings, energy_tolerance=tol)
        row = trajectory_numbers(h, p, rev_hz)
        res["trajectories"].append(row)
        if k == 0 and histories is not None:
            histories.parent.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(histories, drive_power=h.drive_power, **keep)
        log(f"  trajectory {k}: {row['impacts']} impacts, power mean "
            f"{row['power']['mean']['mean']:.0f} W, half range "
            f"{row['power']['half_range']['mean']:.0f} W (filtered "
            f"{row['power']['half_range_filtered']['mean']:.0f}), Fx per-rev peak "
            f"{row['force_x']['peak']['mean']:.0f} N, {row['wall_time_s']:.1f} s")
    if res["trajectories"]:
        res["ensemble"] = ensemble_of(res["trajectories"])
    res["wall_time_s"] = time.perf_counter() - t_wall
    return res


FIG23_CASES = {
    "gas": {"gas": True, "gravity": False},
    "inertia only": {"gas": False, "gravity": False},
    "inertia and gravity": {"gas": False, "gravity": True},
}


def fig23(n_traj: int, end_time: float, out: Path, cases=None) -> dict:
    """Fig. 23: drive power, ideal joints against the 0.1 mm big end 1, per loading."""
    results = _load(out / "fig23.json")
    for name, kw in FIG23_CASES.items():
        if cases and name not in cases:
            continue
        print(f"fig23 {name}", flush=True)
        slug = name.replace(" ", "_")
        results[name] = run_case(scene(("big_end_1",), end_time=end_time, **kw), n_traj,
                                 histories=out / f"fig23_{slug}.npz")
        _save(out / "fig23.json", results)
    return results


def fig27(n_traj: int, end_time: float, out: Path, cases=None) -> dict:
    """Fig. 27: big-end clearances added cumulatively (cases 1-4)."""
    results = _load(out / "fig27.json")
    for name, joints in FIG27_CASES.items():
        if cases and name not in cases:
            continue
        print(f"fig27 {name}: {', '.join(joints)}", flush=True)
        results[name] = run_case(scene(joints, end_time=end_time), n_traj)
        _save(out / "fig27.json", results)
    return results


def _load(path: Path) -> dict:
    """Cases already recorded (a run of some cases adds to them)."""
    return json.loads(path.read_text()) if path.is_file() else {}


def _save(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(data, indent=1))
    tmp.replace(path)


def plot(out: Path) -> None:
    """docs/img/seed000_fig23_power.png and seed000_fig27_cumulative.png from the JSON files."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f23 = out / "fig23.json"
    if f23.is_file():
        d = json.loads(f23.read_text())
        keys = ("half_range", "half_range_filtered", "rms_fluctuation", "order_4")
        labels = ("(max−min)/2", "(max−min)/2, orders ≤ 12", "RMS of fluctuation", "order 4")
        hist = out / "fig23_gas.npz"
        ncol = len(d) + (1 if hist.is_file() else 0)
        fig, axes = plt.subplots(1, ncol, figsize=(4.6 * ncol, 4.2), squeeze=False)
        if hist.is_file():
            z = np.load(hist)
            ax = axes[0][-1]
            ax.plot(z["t"], z["drive_power"] / 1e3, lw=0.5, color="C3",
                    label="0.1 mm big end 1 (trajectory 0)")
            t, pw = z["t"], z["drive_power"]
            fs = 1.0 / (t[1] - t[0])
            X = np.fft.rfft(pw)
            X[np.fft.rfftfreq(pw.size, 1.0 / fs) > FILTER_ORDERS * 1480.0 / 60.0] = 0.0
            ax.plot(t, np.fft.irfft(X, pw.size) / 1e3, color="C0", lw=1.0,
                    label="the same, orders <= 12 (296 Hz)")
            ax.plot(t, z["ideal_drive_power"] / 1e3, "k--", lw=0.9, label="ideal joints")
            lim = 3.0 * float(np.max(np.abs(z["ideal_drive_power"][z["t"] > 0.15]))) / 1e3
            ax.set_ylim(-lim, lim)
            ax.set_xlabel("time, s")
            ax.set_ylabel("drive power, kW (impact spikes clipped)")
            ax.set_title("gas: the time history (the seed's Fig. 23)", fontsize=9)
            ax.legend(fontsize=7, loc="lower right")
            ax.grid(alpha=0.3)
        for ax, (name, r) in zip(axes[0], d.items()):
            x = np.arange(len(keys))
            iv = [r["ideal"]["power"][k]["mean"] for k in keys]
            ax.bar(x - 0.2, iv, 0.4, label="ideal joints", color="0.4")
            if "ensemble" in r:
                e = r["ensemble"]["power"]
                ax.bar(x + 0.2, [e[k]["mean"] for k in keys], 0.4,
                       yerr=[2 * e[k]["sem"] for k in keys], capsize=3, color="C3",
                       label=f"0.1 mm big end 1 ({r['ensemble']['n_trajectories']} traj.)")
            ax.axhline(819.0, color="k", ls=":", lw=0.9)
            ax.axhline(6711.0, color="C3", ls=":", lw=0.9)
            ax.set_yscale("log")
            ax.set_xticks(x, labels, rotation=20, fontsize=7)
            ax.set_title(name, fontsize=9)
            ax.set_ylabel("drive power amplitude per revolution, W")
            ax.grid(alpha=0.3, axis="y")
        axes[0][0].legend(fontsize=7, loc="upper right")
        fig.suptitle("Seed 000 Fig. 23: drive-power amplitude after the start-up (dotted: the "
                     "seed's 819 W ideal, 6711 W clearance; bars ± 2 SE)", fontsize=9)
        fig.tight_layout()
        fig.savefig(IMG / "seed000_fig23_power.png", dpi=110)
        plt.close(fig)
    f27 = out / "fig27.json"
    if f27.is_file():
        d = json.loads(f27.read_text())
        names = list(d)
        groups = [g for g in ("force_x", "force_y") if g in d[names[0]]["ensemble"]]
        keys = (("peak", "per-rev peak |F{c}|"), ("order_1", "order 1 of F{c}"),
                ("rms_above_12", "F{c} RMS above order 12 (> 296 Hz)"),
                ("rms_fluctuation", "F{c} RMS of the fluctuation"))
        fig, axes = plt.subplots(len(groups), len(keys), figsize=(15, 3.6 * len(groups)),
                                 squeeze=False)
        x = np.arange(len(names))
        for row, g in zip(axes, groups):
            c = g[-1]
            for ax, (k, label) in zip(row, keys):
                e = [d[n]["ensemble"][g][k] for n in names]
                ax.bar(x, [v["mean"] / 1e3 for v in e], yerr=[2 * v["sem"] / 1e3 for v in e],
                       capsize=4, color="C0" if c == "x" else "C2")
                ax.plot(x, [v["min"] / 1e3 for v in e], "k_", ms=12)
                ax.plot(x, [v["max"] / 1e3 for v in e], "k_", ms=12)
                ideal = d[names[0]]["ideal"][g][k]["mean"] / 1e3
                ax.axhline(ideal, color="0.3", ls="--", lw=0.9, label="ideal joints")
                ax.set_xticks(x, [n.replace("case ", "") for n in names])
                ax.set_xlabel("case k: clearance in big ends 1..k")
                ax.set_title(label.format(c=c), fontsize=9)
                ax.set_ylabel("kN")
                ax.grid(alpha=0.3, axis="y")
        axes[0][0].legend(fontsize=7)
        n = d[names[0]]["ensemble"]["n_trajectories"]
        fig.suptitle(f"Seed 000 Fig. 27: main-bearing force with 0.1 mm clearance added "
                     f"cumulatively (mean of {n} trajectories ± 2 SE; ticks: smallest and "
                     f"largest trajectory; x along cylinders 3/4, y along cylinders 1/2)",
                     fontsize=9)
        fig.tight_layout()
        fig.savefig(IMG / "seed000_fig27_cumulative.png", dpi=110)
        plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=("fig23", "fig27", "plot"))
    ap.add_argument("--trajectories", type=int, default=8)
    ap.add_argument("--end-time", type=float, default=0.5)
    ap.add_argument("--case", action="append", help="only this case (repeatable)")
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "seed_studies")
    a = ap.parse_args(argv)
    if a.what == "fig23":
        fig23(a.trajectories, a.end_time, a.out, a.case)
    elif a.what == "fig27":
        fig27(a.trajectories, a.end_time, a.out, a.case)
    plot(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
