# %% [markdown]
# # Seed trends of the clearance-joint dynamics (issue 7)
#
# Reproduces, at modest end times, the trends the seeds report for clearance joints and writes
# the figures to ``docs/img/dyn_*.png`` and the numbers to ``docs/img/dyn_seed_trends.json``:
#
# (a) seed 000 Fig. 24: larger big-end clearance -> larger piston acceleration peaks;
# (b) seed 000 Fig. 25: higher speed -> more frequent, harder impacts;
# (c) seed 000 Fig. 26: clearance broadens the main-bearing force spectrum;
# (d) seed 000 Figs. 19/20: friction and the main-bearing spectrum;
# (e) seed 001: loom coupler-pin journal trace, bearing-force direction, Table 3;
# (f) seed 003: impact velocity in a worn (elliptical) big end rising with wear.
#
# Run time about 5 min on one core. Not part of the default test run: notebooks marked
# ``# crankmodal: slow-notebook`` run with ``pytest -m slow tests/test_notebooks.py``; the
# asserted trends are the slow tests in ``tests/test_dynamics_seed_trends.py``. Run from inside
# the source tree (Jupyter in ``notebooks/``, or ``python notebooks/seed_trends.py``) it updates
# ``docs/img``; anywhere else it writes the figures and numbers to ``./seed_trends_out``.
# crankmodal: slow-notebook

# %%
import json
import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import crankmodal as cm
from crankmodal.dynamics.laws.reynolds import steady_bearing
from crankmodal.dynamics.results.signals import (
    amplitude_spectrum,
    contact_loss_indicator,
    force_direction,
    impact_statistics,
    order_amplitudes,
    window_peaks,
)
from crankmodal.dynamics.run.integrate import integrate
from crankmodal.dynamics.run.simulate import simulate
from crankmodal.dynamics.scene.build import build_mechanism, solver_settings
from crankmodal.runner import check
from crankmodal.scene import load_scene


def source_tree() -> Path | None:
    """The crankmodal checkout the notebook runs in (cwd or a parent holding pyproject.toml and
    docs/img), else None."""
    for d in (Path.cwd(), *Path.cwd().parents):
        if (d / "pyproject.toml").is_file() and (d / "docs" / "img").is_dir():
            return d
    return None


def done(fig):
    """Show a saved figure inline in Jupyter; in a plain script, just release it."""
    if "ipykernel" in sys.modules:
        plt.show()
    else:
        plt.close(fig)


ROOT = source_tree()
IMG = ROOT / "docs" / "img" if ROOT else Path.cwd() / "seed_trends_out"
IMG.mkdir(parents=True, exist_ok=True)
T_START = time.perf_counter()
RESULTS = {}


def run_scene(scene, overrides, ideal=False, dt=None):
    """Mechanism and history of a scene with overrides (output every ``dt`` s, default 0.5 deg
    of crank)."""
    params = check(load_scene(cm.scene_path(Path(scene).stem), overrides))
    p = params["dynamics"]
    mech = build_mechanism(p, params.get("mechanism"))
    h = simulate(mech, p["end_time"], dt or 1.0 / (720 * mech.revolution_hz),
                 solver_settings(p, 60 * mech.revolution_hz), ideal=ideal)
    return mech, h


# %% [markdown]
# ## Four-star compressor, one big-end clearance (seed 000 Sec. 3.2)
# IMPACT law and Coulomb friction of the seed's Table 4, gas forces of its Fig. 4, speed ramped
# over 0.1 s. Statistics over whole revolutions from ``WINDOW_START`` on. An *impact* is a
# contact onset with approach velocity >= 1 mm/s (every onset here is a real bounce: contact
# 0.4-1 ms, flights 0.15-0.45 ms, onsets and separations alternate); a *collision event* also
# needs a free flight of >= 0.5 ms before it, so a rattle of short bounces counts once -- what a
# time trace shows as one spike.

# %%
WINDOW_START = 0.15     # s: 0.05 s after the end of the 0.1 s ramp
V_MIN, MIN_FLIGHT = 1e-3, 5e-4


def four_star(c, rpm, friction="coulomb", n_rev=5):
    """Four-star run with clearance ``c`` (m) at ``big_end_1`` (None: ideal joints)."""
    end = WINDOW_START + n_rev * 60.0 / rpm
    ov = [f"dynamics.end_time={end}", "dynamics.ramp_time=0.1", f"dynamics.speed_rpm={rpm}",
          f"dynamics.friction.law='{friction}'",
          (f"dynamics.clearances=[{{joint='big_end_1', clearance={c or 1e-4}, "
           "journal_radius=0.0225}]")]
    _, h = run_scene("four_star_dynamics.toml", ov, ideal=c is None)
    rev_hz = rpm / 60.0
    sel = (h.t >= WINDOW_START - 1e-12) & (h.t <= WINDOW_START + n_rev / rev_hz + 1e-12)
    out = {"c_mm": None if c is None else c * 1e3, "rpm": rpm, "friction": friction,
           "revolutions": n_rev, "wall_s": h.wall_time}
    a = h.piston_acceleration[sel, 0]
    out.update(acc_peak_pos=float(a.max()), acc_peak_neg=float(a.min()),
               acc_p99=float(np.percentile(np.abs(a), 99.0)), acc_rms=float(np.sqrt(np.mean(a**2))))
    if c is not None:
        ons = [o for o in h.onsets["big_end_1"] if WINDOW_START <= o[0] <= h.t[sel][-1]]
        seps = h.separations["big_end_1"]
        imp = impact_statistics(ons, seps, v_min=V_MIN)
        ev = impact_statistics(ons, seps, v_min=V_MIN, min_flight=MIN_FLIGHT)
        out.update(impacts_per_rev=imp["impact_count"] / n_rev,
                   impacts_per_s=imp["impact_count"] / n_rev * rev_hz,
                   events_per_rev=ev["impact_count"] / n_rev,
                   v_impact_mean=imp["impact_velocity_mean"],
                   v_impact_rms=imp["impact_velocity_rms"],
                   v_impact_max=imp["impact_velocity_max"],
                   contact_force_peak=float(h.contact["big_end_1"]["fn"][sel].max()))
    # main-bearing x force (seed Figs. 19/20/26): order lines and what lies between them
    fx = h.main_bearing_force[sel, 0]
    orders = np.arange(0, 41)
    amps = order_amplitudes(h.t[sel], fx, rev_hz, orders)
    var = float(np.var(fx[:-1]))
    line = float(0.5 * np.sum(amps[1:] ** 2))
    spec = amplitude_spectrum(h.t[sel], fx, rev_hz)
    band = (spec.frequency_hz > 100.0) & (spec.frequency_hz < 2000.0)
    k = int(np.argmax(np.where(band, spec.amplitude, 0.0)))
    out.update(fx_order1=float(amps[1]), fx_rms=float(np.sqrt(var)),
               broadband_fraction=max(0.0, 1.0 - line / var) if var > 0 else 0.0,
               fx_rms_above_100hz=float(np.sqrt(np.sum(spec.amplitude[spec.frequency_hz > 100.0] ** 2)
                                                / 2.0)),
               band_peak_hz=float(spec.frequency_hz[k]), band_peak_n=float(spec.amplitude[k]))
    return out, h, spec, sel


def row(label, r):
    keys = ("acc_peak_pos", "acc_peak_neg", "acc_p99", "impacts_per_rev", "impacts_per_s",
            "events_per_rev", "v_impact_mean", "v_impact_max", "fx_order1", "broadband_fraction",
            "band_peak_hz", "band_peak_n", "wall_s")
    print(f"{label:>18s} " + " ".join(f"{k}={r[k]:.4g}" for k in keys if r.get(k) is not None))


def trace_and_phase(axes, x, h, sel, title, xlabel):
    """First-stage piston acceleration over ``x`` (top) and its acceleration-velocity phase
    diagram (bottom), as seed 000 Figs. 24/25 pair them."""
    axes[0].plot(x, h.piston_acceleration[sel, 0], lw=0.5)
    axes[0].set(title=title, xlabel=xlabel, ylabel="piston 1 accel (m/s²)")
    axes[1].plot(h.piston_velocity[sel, 0], h.piston_acceleration[sel, 0], lw=0.3)
    axes[1].set(xlabel="piston velocity (m/s)", ylabel="accel (m/s²)")


# %% [markdown]
# ### (a) and (c): clearance 0.10 / 0.15 / 0.20 mm at 1480 rpm

# %%
runs_c = {}
for c in (None, 1.0e-4, 1.5e-4, 2.0e-4):
    runs_c[c] = four_star(c, 1480.0)
    row(f"c = {c}", runs_c[c][0])
RESULTS["clearance_1480rpm"] = [r[0] for r in runs_c.values()]

fig, ax = plt.subplots(2, 4, figsize=(16, 6.5))
for j, (c, (r, h, spec, sel)) in enumerate(runs_c.items()):
    th = np.degrees(h.crank_angle[sel]) - np.degrees(h.crank_angle[sel][0])
    trace_and_phase(ax[:, j], th, h, sel, "ideal" if c is None else f"clearance {c * 1e3:.2f} mm",
                    "crank angle from window start (deg)")
fig.suptitle("Seed 000 Fig. 24: first-stage piston, 1480 rpm, IMPACT + Coulomb")
fig.tight_layout()
fig.savefig(IMG / "dyn_clearance_acceleration.png", dpi=110)
done(fig)

fig, ax = plt.subplots(figsize=(9, 4.5))
for c, (r, h, spec, sel) in runs_c.items():
    ax.semilogy(spec.frequency_hz, np.maximum(spec.amplitude, 1e-3), lw=0.7,
                label="ideal" if c is None else f"{c * 1e3:.2f} mm")
ax.set(xlim=(0, 2000), ylim=(1e-1, None), xlabel="frequency (Hz)", ylabel="|F_x| main bearing (N)",
       title="Seed 000 Fig. 26: main-bearing x force spectrum, 1480 rpm (Hann)")
ax.legend()
fig.tight_layout()
fig.savefig(IMG / "dyn_clearance_spectrum.png", dpi=110)
done(fig)

# %% [markdown]
# ### (b): 148 / 740 / 1480 rpm at 0.10 mm (seed 000 Fig. 25)
# The seed's gas force is a function of crank angle (its Fig. 4 SPLINE), so it is the same at
# every speed while the inertia forces scale with speed squared -- as here. For a fair
# comparison every speed gets the same record: 0.405 s from 0.15 s (1 / 5 / 10 revolutions) and
# the same output step (20 us; 0.5 deg of crank would be 563 us at 148 rpm, longer than a
# contact, and hid the 148-rpm peaks). "Acceleration amplitude" (the seed does not define it)
# is reported twice: the largest value of the record (one event) and the median of the peaks
# of 20-ms windows (what every stretch of the trace reaches); impacts by their median
# approach velocity and median peak contact force.

# %%
SPAN, DT_SPEED = 0.405, 2.0e-5


def four_star_speed(rpm, friction="coulomb", c=1.0e-4):
    """Equal-length, equally sampled four-star record at ``rpm`` (statistics of Fig. 25)."""
    ov = [f"dynamics.end_time={WINDOW_START + SPAN}", "dynamics.ramp_time=0.1",
          f"dynamics.speed_rpm={rpm}", f"dynamics.friction.law='{friction}'",
          f"dynamics.clearances=[{{joint='big_end_1', clearance={c}, journal_radius=0.0225}}]"]
    _, h = run_scene("four_star_dynamics.toml", ov, dt=DT_SPEED)
    sel = (h.t >= WINDOW_START - 1e-12) & (h.t <= WINDOW_START + SPAN + 1e-12)
    t, a = h.t[sel], h.piston_acceleration[sel, 0]
    ons = np.array([o for o in h.onsets["big_end_1"]
                    if WINDOW_START <= o[0] <= WINDOW_START + SPAN and o[1] >= V_MIN]).reshape(-1, 2)
    seps = np.sort(np.asarray(h.separations["big_end_1"], float))
    fn = h.contact["big_end_1"]["fn"][sel]
    f_imp = []                      # peak normal force of each impact (onset to separation)
    for t_on, _ in ons:
        k = np.searchsorted(seps, t_on)
        m = (t >= t_on) & (t <= (seps[k] if k < seps.size else t[-1]))
        if m.any():
            f_imp.append(fn[m].max())
    wp = window_peaks(t, a, 0.02)
    out = {"rpm": rpm, "friction": friction, "span_s": SPAN, "output_step_s": DT_SPEED,
           "acc_peak": wp["max"], "acc_window_peak_median": wp["median"],
           "impacts_per_s": ons.shape[0] / SPAN,
           "v_impact_median": float(np.median(ons[:, 1])), "v_impact_mean": float(ons[:, 1].mean()),
           "v_impact_max": float(ons[:, 1].max()),
           "impact_force_median": float(np.median(f_imp)), "contact_force_peak": float(fn.max()),
           "piston_velocity_amplitude": float(np.abs(h.piston_velocity[sel, 0]).max()),
           "wall_s": h.wall_time}
    return out, h, sel


runs_n = {rpm: four_star_speed(rpm) for rpm in (148.0, 740.0, 1480.0)}
for rpm, (r, _, _) in runs_n.items():
    print(f"{rpm:6g} rpm " + " ".join(f"{k}={v:.4g}" for k, v in r.items()
                                     if isinstance(v, float) and k != "rpm"))
RESULTS["speed_0p1mm"] = [runs_n[k][0] for k in sorted(runs_n)]

fig, ax = plt.subplots(2, 3, figsize=(14, 6.5))
for j, rpm in enumerate(sorted(runs_n)):
    r, h, sel = runs_n[rpm]
    t = h.t[sel]
    trace_and_phase(ax[:, j], (t - t[0]) * 1e3, h, sel,
                    f"{rpm:g} rpm: median 20-ms peak {r['acc_window_peak_median']:.0f} m/s², "
                    f"max {r['acc_peak']:.0f}", "time from 0.15 s (ms)")
    ax[1, j].set_title(f"{r['impacts_per_s']:.0f} impacts/s, median v {r['v_impact_median']:.2f} m/s",
                       fontsize=9)
fig.suptitle("Seed 000 Fig. 25: clearance 0.10 mm at three speeds (IMPACT + Coulomb, Table 4)")
fig.tight_layout()
fig.savefig(IMG / "dyn_speed_acceleration.png", dpi=110)
done(fig)

# %% [markdown]
# ### (d): friction off / on at 0.10 mm, 1480 rpm (seed 000 Figs. 19/20)
# The seed's Sec. 3.1.2 model is rigid with an IMPACT contact at the first-stage big end (the
# clearance is not stated; 0.10 mm, its installation clearance, is used). A rigid model with
# this contact has two resonances of the rod on the contact: the rod rocking about its small
# end with the big-end bore rolling on the pin, f_t = sqrt(F / (c m_t)) / 2 pi (a pendulum of
# length c under the big-end load F; m_t = I_small / l^2 = 0.96 kg), and the rod + piston
# bouncing on the Hertz spring, f_n = sqrt(1.5 K^(2/3) F^(1/3) / m_n) / 2 pi (m_n = 2.8 kg).
# The seed's 225 Hz is, at 1480 rpm (24.67 Hz), the 9th engine order (222 Hz). The clearance
# response changes from cycle to cycle, so a line or band read from one 5-revolution record
# moves by ~10 % between records: each run is 20 revolutions, cut into four 5-revolution
# blocks, and every number is reported as the mean and sample spread over the blocks. Both
# main-bearing components: x (across cylinder 1) and y (along it). Order lines 7-11 are exact
# Fourier amplitudes; "between the lines" is the RMS of a rectangular-window spectrum over
# whole revolutions with the order bins removed (the part that is not periodic in the crank
# angle); band RMS is the Hann spectrum's (ENBW 1.5 bins), as for Fig. 26.
#
# Measured (four independent 20-revolution records per case: ramp 0.1 s twice, 0.08 s and
# 0.05 s): in the y force friction pulls the 9th-order line back
# towards the ideal joints' 108 N -- no friction 138-148 N, Coulomb 119-125 N -- and raises the
# 300-500 Hz content between the lines (300-419 -> 446-605 N); in the x force neither moves
# (order 9: 54-60 N both). Not a resonance: with ideal joints the line is already there (the
# gas and inertia forces' 9th harmonic), and the between-line content rises smoothly through
# 200-250 Hz with no peak. 150-300 Hz between the lines is not raised (75-91 N both).

# %%
N_REV_D, BLOCK_D = 20, 5


def block_bands(h, rev_hz, comp, n_rev=N_REV_D):
    """Per-block order lines 7-11 and band RMS of one main-bearing force component over
    ``n_rev`` revolutions from ``WINDOW_START``."""
    T = 1.0 / rev_hz
    rows = []
    for b in range(n_rev // BLOCK_D):
        t0 = WINDOW_START + b * BLOCK_D * T
        m = (h.t >= t0 - 1e-9) & (h.t < t0 + BLOCK_D * T - 1e-9)
        t, x = h.t[m], h.main_bearing_force[m, comp]
        hann = amplitude_spectrum(t, x, rev_hz)
        rect = amplitude_spectrum(t, x, rev_hz, window="rect")
        off_line = np.abs(rect.order - np.round(rect.order)) > 0.5 / BLOCK_D
        row_ = {f"order{k}_n": float(a)
                for k, a in zip(range(7, 12), order_amplitudes(t, x, rev_hz, range(7, 12)))}
        for lo, hi in ((150.0, 300.0), (300.0, 500.0)):
            mb = (rect.frequency_hz >= lo) & (rect.frequency_hz < hi) & off_line
            row_[f"between_lines_{lo:g}_{hi:g}_hz_rms_n"] = float(
                np.sqrt(np.sum(rect.amplitude[mb] ** 2) / 2.0))
        for lo, hi in ((500.0, 1000.0), (1000.0, 2000.0)):
            mb = (hann.frequency_hz >= lo) & (hann.frequency_hz < hi)
            row_[f"{lo:g}_{hi:g}_hz_rms_n"] = float(np.sqrt(np.sum(hann.amplitude[mb] ** 2) / 3.0))
        rows.append(row_)
    return {k: {"mean": float(np.mean([r[k] for r in rows])),
                "spread": float(np.std([r[k] for r in rows], ddof=1)) if len(rows) > 1 else 0.0,
                "blocks": [r[k] for r in rows]} for k in rows[0]}


runs_f = {"none": four_star(1.0e-4, 1480.0, friction="none", n_rev=N_REV_D),
          "coulomb": four_star(1.0e-4, 1480.0, friction="coulomb", n_rev=N_REV_D)}
row("no friction", runs_f["none"][0])
row("Coulomb", runs_f["coulomb"][0])
RESULTS["friction_0p1mm_1480rpm"] = []
for name, (r, h, spec, sel) in (("none", runs_f["none"]), ("coulomb", runs_f["coulomb"]),
                                ("ideal", runs_c[None])):
    # the ideal joints' record (5 revolutions, section (a)) is periodic: one block
    stats = {c: block_bands(h, r["rpm"] / 60.0, j, r["revolutions"]) for j, c in enumerate("xy")}
    RESULTS["friction_0p1mm_1480rpm"].append(dict(r, case=name, block_revolutions=BLOCK_D,
                                                  blocks=stats))
    for c in "xy":
        s = stats[c]
        print(f"{name:>8s} {c}: " + " ".join(f"{k.replace('_hz_rms_n', '').replace('_n', '')}="
                                             f"{v['mean']:.0f}±{v['spread']:.0f}"
                                             for k, v in s.items()))

fig, ax = plt.subplots(1, 2, figsize=(13, 4.5), sharey=True)
for name, (r, h, spec, sel) in (("ideal joints", runs_c[None]), ("no friction", runs_f["none"]),
                                ("Coulomb (Table 4)", runs_f["coulomb"])):
    s = amplitude_spectrum(h.t[sel], h.main_bearing_force[sel], r["rpm"] / 60.0)
    for j in range(2):
        ax[j].semilogy(s.frequency_hz, np.maximum(s.amplitude[:, j], 1e-3), lw=0.6, label=name)
for j, c in enumerate("xy"):
    ax[j].axvline(225.0, color="k", ls=":", lw=0.8)
    ax[j].set(xlim=(0, 2000), ylim=(1e-1, 1e4), xlabel="frequency (Hz)",
              title=f"main-bearing {c} force (dotted: 225 Hz)")
ax[0].set_ylabel("amplitude (N)")
ax[0].legend()
fig.suptitle("Seed 000 Figs. 19/20: 1480 rpm, 0.10 mm, with and without friction "
             f"({N_REV_D} revolutions, Hann)")
fig.tight_layout()
fig.savefig(IMG / "dyn_friction_spectrum.png", dpi=110)
done(fig)

# %% [markdown]
# ## (e) Seed 001: loom four-bar, lubricated coupler pin C
# Table 3 against the film models; then the seed's instability angles from the zero-clearance
# (ideal-joint) force at the coupler pin C, and its quasi-static journal trace: at every crank
# angle the journal sits where the steady film carries that force at the equivalent speed
# ``U = R |w_rocker + w_coupler - 2 w_F|`` (``w_F`` the rate of the force direction), inverted from
# the 150-deg partial-bearing table that reproduces Table 3, at the attitude angle of that table.
# Next to it the journal centre of the full dynamic run (short-bearing film, dry contact beyond
# eps = 1).
#
# The machine file reads the seed in its own crank-angle convention: crankmodal's frame is the
# seed's Fig. 1 frame mirrored (x_D = -8 mm), the rocker hanging from D towards +x, and the
# coupler inertia read as 11.4 kg cm^2 (printed 114). The table of readings below shows what each
# choice does to the angles the seed names.

# %%
T3_EPS = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7])
T3_LOAD = np.array([0.197, 0.415, 0.680, 1.029, 1.524, 2.296, 3.654])
T3_PHI = np.array([75.11, 63.59, 55.55, 50.08, 45.32, 40.54, 36.02])
tab = {}
for name, kw in (("full_360", {}), ("partial_150", {"arc_deg": 150.0})):
    b = [steady_bearing(e, 1.0, 192, 32, **kw) for e in T3_EPS]
    tab[name] = {"load": [x.load for x in b], "attitude_deg": [x.attitude_deg for x in b]}
s = 1 - T3_EPS**2
tab["short_ocvirk"] = {"load": (T3_EPS * np.sqrt(16 * T3_EPS**2 + np.pi**2 * s) / s**2).tolist(),
                       "attitude_deg": np.degrees(np.arctan(np.pi * np.sqrt(s) / (4 * T3_EPS))).tolist()}
print(f"{'model':>14s} {'max load err':>13s} {'max angle err (deg)':>20s}")
for name, v in tab.items():
    le = np.abs(np.array(v["load"]) / T3_LOAD - 1).max()
    pe = np.abs(np.array(v["attitude_deg"]) - T3_PHI).max()
    v.update(max_load_error=float(le), max_attitude_error_deg=float(pe))
    print(f"{name:>14s} {le:13.3%} {pe:20.2f}")
RESULTS["seed001_table3"] = tab

# %%
SEED001 = {"min_force_n": 20.0, "min_force_crank_deg": 92.0,
           "fast_direction_crank_deg": [92.0, 322.0],
           "inside_eps_0p1_crank_deg": [[72, 114], [178, 192], [302, 338]],
           "eps_min_at_92_and_322": [0.001, 0.004]}
LOOM = cm.scene_path("loom_four_bar_dynamics")
NEAR = {"92": (40.0, 140.0), "322": (250.0, 359.5)}   # crank-angle windows of the two events, deg


def loom_ideal(overrides=()):
    """Ideal-joint (zero-clearance) history of the loom scene over one revolution, 0.5 deg."""
    return run_scene(LOOM.name, ["dynamics.end_time=0.1333333333333333", *overrides], ideal=True)


def crank_deg_of(h, seed_frame=True):
    """Crank angle in the seed's convention (0..360 deg): ccw from +x, or 180 - theta unmirrored."""
    th = np.degrees(h.crank_angle)
    return th % 360.0 if seed_frame else (180.0 - th) % 360.0


def c_force_events(h, deg):
    """Smallest C force and fastest direction change in each window of the seed's two events."""
    F = h.joint_forces["C"]
    mag = np.hypot(F[:, 0], F[:, 1])
    _, rate = force_direction(h.t, F)
    out = {}
    for key, (lo, hi) in NEAR.items():
        sel = (deg >= lo) & (deg <= hi)
        i = int(np.argmin(np.where(sel, mag, np.inf)))
        j = int(np.argmax(np.where(sel, np.abs(rate), -1.0)))
        out[key] = {"min_force_n": float(mag[i]), "min_force_crank_deg": float(deg[i]),
                    "fastest_direction_crank_deg": float(deg[j]),
                    "direction_rate_rad_s": float(abs(rate[j]))}
    out["global_min_force_crank_deg"] = float(deg[np.argmin(mag)])
    return out


def intervals(deg, mask):
    """Crank-angle intervals (deg) where ``mask`` holds, joined across 360 -> 0."""
    order = np.argsort(deg)
    d, m = deg[order], mask[order]
    runs, start = [], None
    for k in range(d.size + 1):
        on = k < d.size and m[k]
        if on and start is None:
            start = d[k]
        if not on and start is not None:
            runs.append([float(start), float(d[k - 1])])
            start = None
    if len(runs) > 1 and runs[0][0] <= d[0] and runs[-1][1] >= d[-1]:
        runs = [[runs[-1][0], runs[0][1] + 360.0]] + runs[1:-1]
    return runs


READINGS = {   # name: (overrides, crank angle in the seed frame?)
    "scene: mirrored frame, branch -1, I_BC 11.4 kg cm^2": ([], True),
    "printed I_BC = 114 kg cm^2": (["dynamics.four_bar.inertias=[0.0155, 0.0114, 0.0528]"], True),
    "gravity -y (seed silent)": (["dynamics.gravity=[0.0, -9.81]"], True),
    "unmirrored (x_D = +8 mm), branch -1": (["dynamics.four_bar.rocker_pivot=[0.008, 0.1598]"], True),
    "session 2: unmirrored, branch 1, I_BC 114": (
        ["dynamics.four_bar.rocker_pivot=[0.008, 0.1598]", "dynamics.four_bar.branch=1",
         "dynamics.four_bar.inertias=[0.0155, 0.0114, 0.0528]"], True),
    "unmirrored, branch 1, cw, angle clockwise from -x": (
        ["dynamics.four_bar.rocker_pivot=[0.008, 0.1598]", "dynamics.four_bar.branch=1",
         "dynamics.rotation='cw'"], False),
}
readings = {}
print(f"{'reading':52s} {'min |F| near 92':>18s} {'near 322':>16s} {'fast dir.':>13s}")
for name, (ovr, seed_frame) in READINGS.items():
    _, h = loom_ideal(ovr)
    ev = c_force_events(h, crank_deg_of(h, seed_frame))
    readings[name] = ev
    a, b = ev["92"], ev["322"]
    print(f"{name:52s} {a['min_force_n']:6.1f} N @{a['min_force_crank_deg']:6.1f} "
          f"{b['min_force_n']:6.1f} N @{b['min_force_crank_deg']:6.1f} "
          f"{a['fastest_direction_crank_deg']:6.1f} {b['fastest_direction_crank_deg']:6.1f}")

# %%
params = check(load_scene(LOOM, [
    "dynamics.end_time=0.4",
    ("dynamics.clearances=[{joint='C', clearance=2.1e-5, journal_radius=0.02, viscosity=0.0175, "
     "bearing_length=0.042}]")]))
p = params["dynamics"]
mech = build_mechanism(p)
rev_hz = mech.revolution_hz
settings = solver_settings(p, 60 * rev_hz)
dt = 1.0 / (720 * rev_hz)
hist = simulate(mech, p["end_time"], dt, settings)
ideal = simulate(mech, p["end_time"], dt, settings, ideal=True)
n = mech.ideal.n
integ = integrate(mech.ideal, mech.q0, mech.qd0, p["end_time"], ideal.t, settings)
w = {b.name: integ.y[n + mech.ideal.slices[id(b)].start + 2] for b in mech.ideal.bodies}
phi_bc = integ.y[mech.ideal.slices[id(next(b for b in mech.ideal.bodies
                                            if b.name == "coupler"))].start + 2]
last = ideal.t >= ideal.t[-1] - 1.0 / rev_hz - 1e-12          # last revolution
F = ideal.joint_forces["C"]          # rocker (journal) on coupler (bearing): the journal's load
beta, beta_dot = force_direction(ideal.t, F)
R_j, L_b, c_j, mu = 0.02, 0.042, 2.1e-5, 0.0175
w_eq = w["rocker"] + w["coupler"] - 2.0 * beta_dot
X = np.hypot(F[:, 0], F[:, 1]) * (c_j / R_j) ** 2 / (mu * R_j * np.maximum(np.abs(w_eq), 1e-12) * L_b)
eps_grid = np.concatenate([[0.0], np.linspace(0.05, 0.95, 19), [0.99]])
steady = [steady_bearing(e, 1.0, 96, 16, arc_deg=150.0) for e in eps_grid[1:]]
load_grid = np.array([0.0] + [b.load for b in steady])
att_grid = np.array([90.0] + [b.attitude_deg for b in steady])
eps_qs = np.interp(X, load_grid, eps_grid, right=1.0)     # beyond eps 0.99: on the wall
# journal centre: along the load, turned by the attitude angle in the sense of w_eq; in the
# coupler (hole) frame, as the seed's Fig. 7
psi_qs = beta + np.sign(w_eq) * np.radians(np.interp(eps_qs, eps_grid, att_grid)) - phi_bc
crank_deg = np.degrees(ideal.crank_angle) % 360.0
loss = contact_loss_indicator(ideal.t[last], F[last], ideal.crank_angle[last])
events = c_force_events(ideal, crank_deg)
eps_at = {k: float(eps_qs[last & (np.abs(crank_deg - events[k]["min_force_crank_deg"]) < 0.26)][0])
          for k in NEAR}
ecc = np.hypot(hist.contact["C"]["ex"], hist.contact["C"]["ey"]) / c_j
loom = {"events": events, "readings": readings, "contact_loss": loss,
        "quasi_static_eps_min": float(eps_qs[last].min()),
        "quasi_static_eps_min_crank_deg": float(crank_deg[last][np.argmin(eps_qs[last])]),
        "quasi_static_eps_at_events": eps_at,
        "quasi_static_inside_eps_0p1_crank_deg": intervals(crank_deg[last], eps_qs[last] < 0.1),
        "quasi_static_wall_crank_deg": intervals(crank_deg[last], eps_qs[last] >= 0.99),
        "dynamic_eps_max": float(ecc[last].max()), "dynamic_eps_min": float(ecc[last].min()),
        "dynamic_impacts": impact_statistics(hist.onsets["C"], v_min=1e-3)["impact_count"],
        "seed": SEED001}
print(json.dumps({k: v for k, v in loom.items() if k != "readings"}, indent=1))
RESULTS["seed001_loom"] = loom

fig = plt.figure(figsize=(14, 4.6))
axp = fig.add_subplot(1, 3, 1, projection="polar")
axp.plot(psi_qs[last], eps_qs[last], lw=0.8, label="quasi-static (Table 3 model)")
for a in range(0, 360, 30):
    k = int(np.flatnonzero(last)[np.argmin(np.abs(crank_deg[last] - a))])
    axp.annotate(f"{a}", (psi_qs[k], eps_qs[k]), fontsize=6, color="C0")
ex, ey = hist.contact["C"]["ex_bearing"], hist.contact["C"]["ey_bearing"]
axp.plot(np.arctan2(ey, ex)[last], ecc[last], lw=0.6, label="dynamic run")
tt = np.linspace(0, 2 * np.pi, 200)
axp.plot(tt, np.full_like(tt, 0.1), "k:", lw=0.6)
axp.set_rmax(1.05)
axp.set_title("journal centre in the coupler frame / c (seed 001 Fig. 7)", fontsize=9, pad=14)
axp.legend(fontsize=7, loc="lower left")
ax2 = fig.add_subplot(1, 3, 2)
ax2.plot(crank_deg[last], np.degrees(beta[last]) % 360.0, ".", ms=1.5)
ax2.set(xlabel="crank angle (deg)", ylabel="direction of the C force (deg)",
        title="bearing-force direction (seed 001 Fig. 9)")
ax3 = fig.add_subplot(1, 3, 3)
ax3.plot(crank_deg[last], np.hypot(F[last, 0], F[last, 1]), ".", ms=1.5, label="|F| ideal (N)")
ax3.plot(crank_deg[last], np.abs(beta_dot[last]), ".", ms=1.5, label="|dβ/dt| (rad/s)")
ax3.plot(crank_deg[last], eps_qs[last] * 1e3, ".", ms=1.5, label="quasi-static eps x 1000")
ax3.set(yscale="log", xlabel="crank angle (deg)", title="contact-loss criterion (seed 001 Eq. 4)")
for ax in (ax2, ax3):
    for a in SEED001["fast_direction_crank_deg"]:
        ax.axvline(a, color="k", ls=":", lw=0.7)
    for lo, hi in SEED001["inside_eps_0p1_crank_deg"]:
        ax.axvspan(lo, hi, color="0.85", zorder=0)
ax3.legend(fontsize=7)
fig.tight_layout()
fig.savefig(IMG / "dyn_loom_journal.png", dpi=110)
done(fig)

# %% [markdown]
# ## (f) Seed 003: worn, elliptical big end
# Seed 003 (Kulaev) gives the model, not numbers: worn con-rod bearings as ellipses with
# semi-axes ``(D + Delta_max)/2`` and ``(D + Delta_min)/2`` (so its Deltas are *diametral*; the
# scene's ``clearance`` and ``clearance_major`` are the radial halves), the major axis at
# ``gamma`` from the rod axis, the penetration measured along the eccentricity against the
# ellipse's polar radius ``b / sqrt(1 - eps^2 cos^2 phi)``, contact ``c delta^alpha + beta
# delta_dot``, friction in the big end and the four-stroke gas cycle of its Sec. 2. It prints no
# parameter values, no wear cases and no result: the trend "impact velocity rises with wear" is
# the premise of its diagnostic method, not a published curve. Here: the machine of
# ``geometry/slider_crank_engine.toml`` (all values chosen), big end with minor-axis clearance
# 0.05 mm and the major axis along the rod (gamma = 0, where gas and inertia load the big end),
# major-axis clearance rising from 0.05 (round) to 0.2 mm; small end round, 0.025 mm.
#
# The seed starts each run with the journals seated against the bore under the static load of the
# firing TDC; crankmodal starts them at the bore centre, so the first milliseconds show a start
# impact (0.7 m/s in every case) that says nothing about wear. Statistics are therefore taken
# over whole four-stroke cycles (720 deg = 0.04 s at 3000 rpm) after the first one; from the
# second cycle on the runs are periodic (cycle-to-cycle spread of the largest impact velocity
# shown as ``impact_velocity_max_per_cycle``).

# %%
CYCLE = 2 * 60.0 / 3000.0          # s, one four-stroke cycle at the machine's 3000 rpm
N_CYCLES = 2                        # steady cycles after the first (start-up) one
worn = []
orbits = {}
for major in (5e-5, 7.5e-5, 1e-4, 1.5e-4, 2e-4):
    mech, h = run_scene("slider_crank_dynamics.toml", [
        f"dynamics.end_time={(1 + N_CYCLES) * CYCLE}",
        (f"dynamics.clearances=[{{joint='big_end_1', clearance=5e-5, clearance_major={major}, "
         "journal_radius=0.024}, {joint='small_end_1', clearance=2.5e-5, journal_radius=0.013}]")])
    ons = np.asarray(h.onsets["big_end_1"], float).reshape(-1, 2)
    steady = ons[ons[:, 0] >= CYCLE - 1e-12]
    st = impact_statistics(steady, v_min=1e-3)
    per_cycle = [float(np.max(steady[(steady[:, 0] >= k * CYCLE) & (steady[:, 0] < (k + 1) * CYCLE)
                                     & (steady[:, 1] >= 1e-3), 1], initial=0.0))
                 for k in range(1, 1 + N_CYCLES)]
    start = impact_statistics(ons[ons[:, 0] < CYCLE], v_min=1e-3)["impact_velocity_max"]
    worn.append({"clearance_minor_mm": 0.05, "clearance_major_mm": major * 1e3,
                 **st, "impacts_per_cycle": st["impact_count"] / N_CYCLES,
                 "impact_velocity_max_per_cycle": per_cycle,
                 "start_impact_velocity_max": start,
                 "crank_angle_of_impacts_deg": [round(float(t * 3000 / 60 * 360) % 720, 1)
                                                for t, v in steady if v >= 1e-3][:8],
                 "energy_error": h.energy_error(), "wall_s": h.wall_time})
    sel = h.t >= CYCLE
    c = h.contact["big_end_1"]
    orbits[major] = (c["ex_bearing"][sel], c["ey_bearing"][sel])
    print({k: v for k, v in worn[-1].items() if k != "crank_angle_of_impacts_deg"})
RESULTS["seed003_worn"] = worn

fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [1, 1.6]})
mj = [w_["clearance_major_mm"] for w_ in worn]
ax.plot(mj, [w_["impact_velocity_max"] for w_ in worn], "o-", label="max, steady cycles")
ax.plot(mj, [w_["impact_velocity_mean"] for w_ in worn], "s-", label="mean, steady cycles")
ax.plot(mj, [w_["start_impact_velocity_max"] for w_ in worn], "x:", c="0.5",
        label="start-up impact (first cycle)")
ax.set(xlabel="major-axis radial clearance of the big end (mm); minor 0.05 mm",
       ylabel="big-end impact velocity (m/s)", title="Seed 003: impact velocity against wear")
ax.legend(fontsize=8)
phi = np.linspace(0.0, 2 * np.pi, 721)
for k, major in enumerate((1e-4, 2e-4)):
    ex, ey = orbits[major]
    off = 0.0 if k == 0 else 0.5                       # mm, side by side
    ax2.plot(ex * 1e3 + off, ey * 1e3, lw=0.6, c=f"C{k}", label=f"orbit, major {major * 1e3:g} mm")
    a, b = 0.024 + major, 0.024 + 5e-5
    rho = a * b / np.sqrt((b * np.cos(phi)) ** 2 + (a * np.sin(phi)) ** 2) - 0.024
    ax2.plot(rho * np.cos(phi) * 1e3 + off, rho * np.sin(phi) * 1e3, "k--", lw=0.7)
ax2.set(aspect="equal", xlabel="journal centre along the rod axis (mm)", ylabel="across (mm)",
        title="crankpin centre in the big end (steady cycles); dashed: contact locus")
ax2.legend(fontsize=8, loc="upper right")
fig.tight_layout()
fig.savefig(IMG / "dyn_worn_impact_velocity.png", dpi=110)
done(fig)

# %%
RESULTS["run_time_s"] = time.perf_counter() - T_START
(IMG / "dyn_seed_trends.json").write_text(json.dumps(RESULTS, indent=1, default=float))
print(f"total {RESULTS['run_time_s']:.0f} s; figures and numbers in {IMG}")

