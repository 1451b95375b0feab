"""Seed 000 Figs. 16-18 side by side: the main-bearing force of the four-star crank train with a
flexible crank (a), four flexible rods (b) and both (c), each against its rigid twin.

Run the three scenes first, then this script::

    for v in crank rods both; do crankmodal run scenes/seed000_flexible_$v.toml --out OUT/$v; done
    python scenes/plot_seed000_flexible.py OUT docs/img/seed000_flexible.png

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
              f"{r['wall'][0]:.0f} / {r['wall'][1]:.0f} |")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
