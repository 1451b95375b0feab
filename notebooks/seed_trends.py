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
# Run time about 5 min on one core. Not part of the default test run (tests/test_notebooks.py
# skips notebooks marked ``# crankmodal: slow-notebook``); the asserted trends are the slow
# tests in ``tests/test_dynamics_seed_trends.py``.
# crankmodal: slow-notebook

# %%
import json
import time
from pathlib import Path

import numpy as np

from crankmodal.dynamics.analysis import simulate
from crankmodal.dynamics.build import build_mechanism, solver_settings
from crankmodal.dynamics.reynolds import steady_bearing
from crankmodal.dynamics.signals import (
    amplitude_spectrum,
    contact_loss_indicator,
    force_direction,
    impact_statistics,
    order_amplitudes,
)
from crankmodal.dynamics.simulate import integrate
from crankmodal.plotting import pyplot
from crankmodal.runner import check
from crankmodal.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
IMG = ROOT / "docs" / "img"
IMG.mkdir(parents=True, exist_ok=True)
plt = pyplot()
T_START = time.perf_counter()
RESULTS = {}


def run_scene(scene, overrides, ideal=False):
    """Mechanism and history of a scene with overrides (output every 0.5 deg of crank)."""
    params = check(load_scene(ROOT / "scenes" / scene, overrides))
    p = params["dynamics"]
    mech = build_mechanism(p, params.get("mechanism"))
    h = simulate(mech, p["end_time"], 1.0 / (720 * mech.revolution_hz),
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
plt.close(fig)

fig, ax = plt.subplots(figsize=(9, 4.5))
for c, (r, h, spec, sel) in runs_c.items():
    ax.semilogy(spec.frequency_hz, np.maximum(spec.amplitude, 1e-3), lw=0.7,
                label="ideal" if c is None else f"{c * 1e3:.2f} mm")
ax.set(xlim=(0, 2000), ylim=(1e-1, None), xlabel="frequency (Hz)", ylabel="|F_x| main bearing (N)",
       title="Seed 000 Fig. 26: main-bearing x force spectrum, 1480 rpm (Hann)")
ax.legend()
fig.tight_layout()
fig.savefig(IMG / "dyn_clearance_spectrum.png", dpi=110)
plt.close(fig)

# %% [markdown]
# ### (b): 148 / 740 / 1480 rpm at 0.10 mm

# %%
runs_n = {1480.0: runs_c[1.0e-4]}
for rpm, n_rev in ((740.0, 3), (148.0, 1)):
    runs_n[rpm] = four_star(1.0e-4, rpm, n_rev=n_rev)
    row(f"{rpm:g} rpm", runs_n[rpm][0])
RESULTS["speed_0p1mm"] = [runs_n[k][0] for k in sorted(runs_n)]

fig, ax = plt.subplots(2, 3, figsize=(13, 6.5))
for j, rpm in enumerate(sorted(runs_n)):
    r, h, spec, sel = runs_n[rpm]
    t = h.t[sel]
    trace_and_phase(ax[:, j], (t - t[0]) * 1e3, h, sel,
                    f"{rpm:g} rpm: {r['impacts_per_s']:.0f} impacts/s, "
                    f"mean {r['v_impact_mean']:.2f} m/s", "time in window (ms)")
fig.suptitle("Seed 000 Fig. 25: clearance 0.10 mm at three speeds")
fig.tight_layout()
fig.savefig(IMG / "dyn_speed_acceleration.png", dpi=110)
plt.close(fig)

# %% [markdown]
# ### (d): friction off / on at 0.10 mm, 1480 rpm

# %%
runs_f = {"coulomb": runs_c[1.0e-4], "none": four_star(1.0e-4, 1480.0, friction="none")}
row("no friction", runs_f["none"][0])
RESULTS["friction_0p1mm_1480rpm"] = [runs_f["none"][0], runs_f["coulomb"][0]]
fig, ax = plt.subplots(figsize=(9, 4.5))
for name, (r, h, spec, sel) in runs_f.items():
    ax.semilogy(spec.frequency_hz, np.maximum(spec.amplitude, 1e-3), lw=0.7,
                label=f"friction {name}")
ax.set(xlim=(0, 2000), ylim=(1e-1, None), xlabel="frequency (Hz)", ylabel="|F_x| main bearing (N)",
       title="Seed 000 Figs. 19/20: main-bearing x force with and without friction")
ax.legend()
fig.tight_layout()
fig.savefig(IMG / "dyn_friction_spectrum.png", dpi=110)
plt.close(fig)

# %% [markdown]
# ## (e) Seed 001: loom four-bar, lubricated coupler pin C
# Table 3 against the film models, then the seed's quasi-static journal trace: at every crank
# angle the journal sits where the steady film carries the zero-clearance bearing force at the
# equivalent speed ``U = R |w_rocker + w_coupler - 2 w_F|`` (``w_F`` the rate of the force
# direction), inverted from the 150-deg partial-bearing table that reproduces Table 3. Next to
# it, the journal centre of the full dynamic run (short-bearing film, dry contact beyond eps=1).

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
params = check(load_scene(ROOT / "scenes" / "loom_four_bar_dynamics.toml", [
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
integ = integrate(mech.ideal, mech.q0, mech.qd0, p["end_time"],
                  np.linspace(0, round(p["end_time"] / dt) * dt, round(p["end_time"] / dt) + 1),
                  settings)
n = mech.ideal.n
w = {b.name: integ.y[n + mech.ideal.slices[id(b)].start + 2] for b in mech.ideal.bodies
     if b.name in ("coupler", "rocker")}
last = ideal.t >= ideal.t[-1] - 1.0 / rev_hz - 1e-12          # last revolution
F = ideal.joint_forces["C"]
beta, beta_dot = force_direction(ideal.t, F)
R_j, L_b, c_j, mu = 0.02, 0.042, 2.1e-5, 0.0175
U = R_j * np.abs(w["rocker"] + w["coupler"] - 2.0 * beta_dot)
X = np.hypot(F[:, 0], F[:, 1]) * (c_j / R_j) ** 2 / (mu * np.maximum(U, 1e-12) * L_b)
eps_grid = np.concatenate([[0.0], np.linspace(0.05, 0.95, 19), [0.99]])
load_grid = np.array([0.0] + [steady_bearing(e, 1.0, 96, 16, arc_deg=150.0).load
                              for e in eps_grid[1:]])
eps_qs = np.interp(X, load_grid, eps_grid, right=1.0)     # beyond eps 0.99: on the wall
crank_deg = np.degrees(ideal.crank_angle) % 360.0
loss = contact_loss_indicator(ideal.t[last], F[last], ideal.crank_angle[last])
inner = last & (eps_qs < 0.1)
loom = {"contact_loss": loss, "quasi_static_eps_min": float(eps_qs[last].min()),
        "quasi_static_eps_min_crank_deg": float(crank_deg[last][np.argmin(eps_qs[last])]),
        "crank_deg_inside_eps_0p1": crank_deg[inner].round(1).tolist()[:: max(1, inner.sum() // 40)],
        "quasi_static_wall_crank_deg": crank_deg[last & (eps_qs >= 0.99)].round(1).tolist(),
        "dynamic_eps_max": float(np.max(np.hypot(hist.contact["C"]["ex"], hist.contact["C"]["ey"])
                                        [last]) / c_j),
        "dynamic_eps_min": float(np.min(np.hypot(hist.contact["C"]["ex"], hist.contact["C"]["ey"])
                                        [last]) / c_j),
        "dynamic_impacts": impact_statistics(hist.onsets["C"], v_min=1e-3)["impact_count"],
        "seed": {"min_force_n": 20.0, "min_force_crank_deg": 92.0,
                 "fast_direction_crank_deg": [92.0, 322.0],
                 "inside_eps_0p1_crank_deg": [[72, 114], [178, 192], [302, 338]]}}
print(json.dumps({k: v for k, v in loom.items() if k != "crank_deg_inside_eps_0p1"}, indent=1))
RESULTS["seed001_loom"] = loom

fig = plt.figure(figsize=(14, 4.6))
axp = fig.add_subplot(1, 3, 1, projection="polar")
phi_b = np.unwrap(np.arctan2(-F[:, 1], -F[:, 0]))           # load on the journal, bearing side
axp.plot(phi_b[last], eps_qs[last], lw=0.8, label="quasi-static (Table 3 model)")
ex, ey = hist.contact["C"]["ex_bearing"], hist.contact["C"]["ey_bearing"]
axp.plot(np.arctan2(ey, ex)[last], np.hypot(ex, ey)[last] / c_j, lw=0.6, label="dynamic run")
axp.set_rmax(1.05)
axp.set_title("journal centre / clearance (seed 001 Fig. 7)")
axp.legend(fontsize=7, loc="lower left")
ax2 = fig.add_subplot(1, 3, 2)
ax2.plot(crank_deg[last], np.degrees(beta[last]) % 360.0, ".", ms=1.5)
ax2.set(xlabel="crank angle (deg)", ylabel="direction of the C force (deg)",
        title="bearing-force direction (seed 001 Fig. 9)")
ax3 = fig.add_subplot(1, 3, 3)
ax3.plot(crank_deg[last], np.hypot(F[last, 0], F[last, 1]), ".", ms=1.5, label="|F| ideal (N)")
ax3.plot(crank_deg[last], np.abs(beta_dot[last]), ".", ms=1.5, label="|dβ/dt| (rad/s)")
ax3.set(yscale="log", xlabel="crank angle (deg)", title="contact-loss criterion (seed 001 Eq. 4)")
ax3.legend()
fig.tight_layout()
fig.savefig(IMG / "dyn_loom_journal.png", dpi=110)
plt.close(fig)

# %% [markdown]
# ## (f) Seed 003: worn, elliptical big end
# Minor-axis clearance 0.05 mm, major-axis clearance rising (wear), small end 0.025 mm.

# %%
worn = []
for major in (5e-5, 1e-4, 2e-4):
    mech, h = run_scene("slider_crank_dynamics.toml", [
        "dynamics.end_time=0.08",
        (f"dynamics.clearances=[{{joint='big_end_1', clearance=5e-5, clearance_major={major}, "
         "journal_radius=0.024}, {joint='small_end_1', clearance=2.5e-5, journal_radius=0.013}]")])
    st = impact_statistics(h.onsets["big_end_1"], v_min=1e-3)
    worn.append({"clearance_major_mm": major * 1e3, **st, "wall_s": h.wall_time})
    print(worn[-1])
RESULTS["seed003_worn"] = worn
fig, ax = plt.subplots(figsize=(6, 4))
mj = [w_["clearance_major_mm"] for w_ in worn]
ax.plot(mj, [w_["impact_velocity_max"] for w_ in worn], "o-", label="max")
ax.plot(mj, [w_["impact_velocity_rms"] for w_ in worn], "s-", label="rms")
ax.set(xlabel="major-axis clearance of the worn big end (mm)", ylabel="impact velocity (m/s)",
       title="Seed 003: impact velocity against wear")
ax.legend()
fig.tight_layout()
fig.savefig(IMG / "dyn_worn_impact_velocity.png", dpi=110)
plt.close(fig)

# %%
RESULTS["run_time_s"] = time.perf_counter() - T_START
(IMG / "dyn_seed_trends.json").write_text(json.dumps(RESULTS, indent=1, default=float))
print(f"total {RESULTS['run_time_s']:.0f} s; figures and numbers in {IMG}")
