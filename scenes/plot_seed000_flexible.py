"""Seed 000 Figs. 16-18 side by side: the main-bearing force of the four-star crank train with a
flexible crank (a), four flexible rods (b) and both (c), each against its rigid twin.

Run the three scenes first, then this script::

    for v in crank rods both; do crankmodal run scenes/seed000_flexible_$v.toml --out OUT/$v; done
    python scenes/plot_seed000_flexible.py OUT docs/img/seed000_flexible.png

``plot_seed000_flexible.py truncation OUT/sweep.csv PNG`` draws the modal-truncation study of
``scenes/sweeps/seed000_flexible_truncation.toml`` (error against run time).

Prints a Markdown table of the numbers (peak, RMS, the RMS of the flexible-minus-rigid
difference, orders 1-3, the ripple above order 12, the dynamic stress) and writes the figure.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

CASES = (("crank", "(a) flexible crank (seed Fig. 17)"),
         ("rods", "(b) four flexible rods (seed Fig. 18)"),
         ("both", "(c) crank and rods flexible"))


def last_revolution(t, angle):
    ang = np.unwrap(angle)
    m = np.abs(ang - ang[-1]) <= 2 * np.pi + 1e-9
    return m, np.rad2deg(np.abs(ang[m] - ang[m][0]))


def ripple(t, f, rev_hz, above=12):
    """RMS of the part of |F| above order ``above`` (whole revolutions ``t``), N."""
    x = np.hypot(*f.T)
    spec = np.fft.rfft(x - x.mean())
    order = np.fft.rfftfreq(len(x), t[1] - t[0]) / rev_hz
    spec[order <= above] = 0.0
    return float(np.sqrt(np.mean(np.fft.irfft(spec, len(x)) ** 2)))


def main(root: Path, figure: Path) -> None:
    from crankmodal.plotting import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(len(CASES), 1, figsize=(9, 8.4), sharex=True)
    rows = []
    for a, (key, title) in zip(ax, CASES):
        res = json.loads((root / key / "results.json").read_text())["dynamics"]
        z = np.load(root / key / "dynamics.npz")
        t, ang = z["t"], z["crank_angle"]
        m, deg = last_revolution(t, ang)
        ff, fr = z["main_bearing_force"], z["rigid_main_bearing_force"]
        a.plot(deg, np.hypot(*fr[m].T) / 1e3, "k--", lw=1.2, label="rigid twin")
        a.plot(deg, np.hypot(*ff[m].T) / 1e3, lw=1.0, label="flexible")
        a.plot(deg, np.hypot(*(ff - fr)[m].T) / 1e3, lw=0.8, color="tab:red",
               label="|flexible − rigid|")
        a.set(ylabel="main-bearing |F| [kN]", title=title)
        a.grid(alpha=0.3)
        a.legend(loc="lower center", bbox_to_anchor=(0.5, 0.1), fontsize=8, ncol=3)
        flex = res["flexible"]
        cmp = flex["rigid"]["main_bearing"]
        rev = res["revolution_hz"]
        start = t >= t[-1] - 4.0 / rev - 1e-12  # the last 4 revolutions (after ramp + 1)
        modes = ", ".join(f"{n} {b['n_modes']}" for n, b in flex["bodies"].items()
                          if n in ("crank", "rod_1"))
        stress = {n: b["dynamic_stress"]["max_von_mises_pa"] / 1e6
                  for n, b in flex["bodies"].items() if "dynamic_stress" in b}
        rows.append({
            "case": title, "modes": modes,
            "peak": (cmp["peak_n"], cmp["rigid_peak_n"]), "rms": (cmp["rms_n"], cmp["rigid_rms_n"]),
            "diff": cmp["relative_difference_rms"],
            "o": [(cmp["order_amplitude_n"][k], cmp["rigid_order_amplitude_n"][k]) for k in (1, 2, 3)],
            "ripple": (ripple(t[start], ff[start], rev), ripple(t[start], fr[start], rev)),
            "stress": stress, "wall": (res["integration_wall_time_s"],
                                       flex.get("rigid_integration_wall_time_s"))})
    ax[-1].set(xlabel="crank angle in the last revolution [deg]", xlim=(0, 360))
    fig.suptitle("Seed 000, four-star at 1480 rpm, ideal gas forces: flexible vs rigid", y=0.995)
    fig.tight_layout()
    from crankmodal.results import savefig_atomic

    savefig_atomic(fig, figure, dpi=110)
    plt.close(fig)
    print("| case | modes kept | peak flex / rigid (N) | RMS flex / rigid (N) | RMS of difference "
          "| order 1 (N) | order 2 (N) | order 3 (N) | ripple above order 12, flex / rigid (N) "
          "| max von Mises (MPa) | wall flex / rigid (s) |")
    print("|" + "---|" * 11)
    for r in rows:
        o = " | ".join(f"{x:.0f} / {y:.0f}" for x, y in r["o"])
        st = ", ".join(f"{n} {v:.1f}" for n, v in r["stress"].items() if n in ("crank", "rod_1"))
        print(f"| {r['case']} | {r['modes']} | {r['peak'][0]:.0f} / {r['peak'][1]:.0f} | "
              f"{r['rms'][0]:.0f} / {r['rms'][1]:.0f} | {100 * r['diff']:.2f} % | {o} | "
              f"{r['ripple'][0]:.1f} / {r['ripple'][1]:.1f} | {st} | "
              f"{r['wall'][0]:.1f} / {r['wall'][1]:.1f} |")




def truncation(csv_path: Path, figure: Path) -> None:
    """Error against run time of the truncation sweep (``seed000_flexible_truncation.toml``):
    each output's relative change from the most modes at the tightest tolerance."""
    import csv

    from crankmodal.plotting import pyplot
    from crankmodal.results import savefig_atomic

    with open(csv_path, newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["status"] == "ok"]
    key = "dynamics.flexible."
    outs = {"RMS of flexible − rigid": key + "rigid.main_bearing.difference_rms_n",
            "peak": key + "rigid.main_bearing.peak_n",
            "order 3": key + "rigid.main_bearing.order_amplitude_n.3"}
    n = np.array([int(r[key + "crank.n_modes"]) for r in rows])
    rt = np.array([float(r["dynamics.solver.rtol"]) for r in rows])
    wall = np.array([float(r["dynamics.integration_wall_time_s"]) for r in rows])
    ref = int(np.argmax(n * 1e9 - rt))  # most modes, tightest tolerance
    plt = pyplot()
    fig, (ax_n, ax_w) = plt.subplots(1, 2, figsize=(11, 4.5))
    print("| crank modes | rtol | wall (s) | RHS evaluations | " + " | ".join(
        f"{k} (N), error" for k in outs) + " |")
    print("|" + "---|" * (4 + len(outs)))
    floor = 1e-6  # errors below are drawn at the floor (log axes)
    for (label, col), colour in zip(outs.items(), ("tab:blue", "tab:red", "tab:green")):
        v = np.array([float(r[col]) for r in rows])
        err = np.maximum(np.abs(v / v[ref] - 1.0), floor)
        for tol, mk, ls in ((1e-5, "o", "-"), (1e-7, "s", "--")):
            m = (rt == tol) & (np.arange(len(v)) != ref)
            o = np.argsort(n[m])
            # left: convergence with the modes kept; right: the same errors against their cost
            ax_n.semilogy(n[m][o], err[m][o], marker=mk, ls=ls, color=colour,
                          label=f"{label}, rtol {tol:g}")
            ax_w.loglog(wall[m], err[m], marker=mk, ls="none", color=colour,
                        label=f"{label}, rtol {tol:g}")
            for x, y, k in zip(wall[m], err[m], n[m]):
                ax_w.annotate(f"{k}", (x, y), xytext=(3, 3), textcoords="offset points",
                              fontsize=7, color=colour)
    for i in np.argsort(n * 10 + np.log10(rt)):
        cells = []
        for col in outs.values():
            v = float(rows[i][col])
            e = abs(v / float(rows[ref][col]) - 1.0)
            cells.append(f"{v:.1f}, {100 * e:.2f} %")
        print(f"| {n[i]} | {rt[i]:g} | {wall[i]:.1f} | {rows[i]['dynamics.rhs_evals']} | "
              + " | ".join(cells) + " |")
    ylabel = f"relative error against {n[ref]} modes, rtol {rt[ref]:g}"
    ax_n.set(xlabel="crank modes kept", ylabel=ylabel, title="convergence with the modes kept")
    ax_w.set(xlabel="integration wall time [s]", ylabel=ylabel,
             title="error against run time (labels: crank modes)")
    for ax in (ax_n, ax_w):
        ax.grid(alpha=0.3, which="both")
        ax.set_ylim(floor / 2, 2.0)
    ax_n.legend(fontsize=7)
    fig.suptitle("Flexible crank (seed 000 Fig. 17 scene), main-bearing force: modal truncation")
    fig.tight_layout()
    savefig_atomic(fig, figure, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    if sys.argv[1] == "truncation":  # plot_seed000_flexible.py truncation OUT/sweep.csv PNG
        truncation(Path(sys.argv[2]), Path(sys.argv[3]))
    else:
        main(Path(sys.argv[1]), Path(sys.argv[2]))
