# %% [markdown]
# # Seed 001: the loom's four-bar beating-up mechanism with a coupler-pin clearance
#
# Xue et al., *Dynamic Analysis of Four-Bar Beating-up Mechanism with Joint Clearance*, J. Donghua
# Univ. 27 (2010). A crank-rocker (Table 1) drives the sley of a ZA 203 air-jet loom at 450 rpm;
# the coupler pin C runs in oil with 0.021 mm clearance (Table 2). The seed gives the bearing's
# dimensionless film force (Table 3), the zero-clearance force at C (smallest 20 N at 92°, fastest
# turns of its direction at 92° and 322°) and the journal-centre trace with the crank angles where
# the journal comes close to the bearing centre (contact-loss risk).
# This notebook reruns `scenes/loom_four_bar_dynamics.toml` (machine `geometry/loom_four_bar.toml`)
# and sets the results next to the seed's numbers.

# %%
import matplotlib.pyplot as plt
import numpy as np

import crankmodal as cm
from crankmodal.dynamics.laws.reynolds import steady_bearing
from crankmodal.dynamics.results.signals import force_direction
from crankmodal.dynamics.scene.build import build_mechanism, solver_settings


def table(rows, header):
    """A plain-text table."""
    cells = [header] + [[f"{v:.4g}" if isinstance(v, float) else str(v) for v in r] for r in rows]
    w = [max(len(r[i]) for r in cells) for i in range(len(header))]
    for k, r in enumerate(cells):
        print("  ".join(c.rjust(w[i]) for i, c in enumerate(r)))
        if k == 0:
            print("  ".join("-" * n for n in w))


# %% [markdown]
# ## 1. Table 3: the bearing's dimensionless film force and attitude angle (L/D = 1)
# crankmodal's finite-bearing Reynolds solver (cavitation by Reynolds' condition). The seed's
# table is not a full 360° bearing: it is a centrally loaded 150° partial arc (one parameter,
# identified from its 14 numbers; README, *[dynamics]*).

# %%
T3_EPS = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7])
T3_LOAD = np.array([0.197, 0.415, 0.680, 1.029, 1.524, 2.296, 3.654])
T3_PHI = np.array([75.11, 63.59, 55.55, 50.08, 45.32, 40.54, 36.02])
arc = [steady_bearing(e, 1.0, 96, 16, arc_deg=150.0) for e in T3_EPS]
full = [steady_bearing(e, 1.0, 96, 16) for e in T3_EPS]
table([[e, a.load, s, a.attitude_deg, p, f.load] for e, a, s, p, f in
       zip(T3_EPS, arc, T3_LOAD, T3_PHI, full)],
      ["eps", "X, 150 deg arc", "X, seed", "phi deg, 150 arc", "phi deg, seed", "X, full 360"])
assert np.allclose([a.load for a in arc], T3_LOAD, rtol=0.025)
assert np.allclose([a.attitude_deg for a in arc], T3_PHI, atol=1.5)

# %%
fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
ax[0].plot(T3_EPS, T3_LOAD, "ks", label="seed 001 Table 3")
ax[0].plot(T3_EPS, [a.load for a in arc], "o-", label="crankmodal, 150° arc")
ax[0].plot(T3_EPS, [f.load for f in full], "--", label="crankmodal, full bearing")
ax[0].set(xlabel="eccentricity ratio", ylabel="dimensionless load X", yscale="log")
ax[1].plot(T3_EPS, T3_PHI, "ks")
ax[1].plot(T3_EPS, [a.attitude_deg for a in arc], "o-")
ax[1].plot(T3_EPS, [f.attitude_deg for f in full], "--")
ax[1].set(xlabel="eccentricity ratio", ylabel="attitude angle (deg)")
ax[0].legend()
fig.tight_layout()
plt.show()

# %% [markdown]
# ## 2. The coupler-pin force without clearance (ideal joints), one revolution

# %%
RPM = 450.0
T = 60.0 / RPM
params = cm.check_scene(cm.load_scene(cm.scene_path("loom_four_bar_dynamics"),
                                      [f"dynamics.end_time={T!r}"]))
p = params["dynamics"]
mech = build_mechanism(p)
ideal = cm.simulate(mech, T, T / 720, solver_settings(p, RPM), ideal=True)
deg = np.degrees(ideal.crank_angle) % 360.0
F = ideal.joint_forces["C"]
mag = np.hypot(F[:, 0], F[:, 1])
angle, rate = force_direction(ideal.t, F)
late = deg > 200.0
rows = [["smallest |F_C|, N", float(mag.min()), 20.0],
        ["... at crank angle, deg", float(deg[np.argmin(mag)]), 92.0],
        ["fastest turn of F_C, deg", float(deg[np.argmax(np.abs(rate))]), 92.0],
        ["second fast turn, deg", float(deg[late][np.argmax(np.abs(rate[late]))]), 322.0]]
table(rows, ["zero clearance", "crankmodal", "seed 001"])
assert abs(rows[1][1] - 92.0) < 3.0 and abs(rows[3][1] - 322.0) < 8.0

# %%
order = np.argsort(deg)
fig, ax = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
ax[0].plot(deg[order], mag[order])
ax[0].set(ylabel="|F_C| (N)", title="coupler-pin force, ideal joints, 450 rpm", yscale="log")
ax[1].plot(deg[order], np.degrees(np.unwrap(angle))[order] % 360.0, ".", ms=2)
for a in ax:
    for d in (92.0, 322.0):
        a.axvline(d, color="C3", ls=":", lw=1)
ax[1].set(xlabel="crank angle (deg)", ylabel="direction of F_C (deg)", xlim=(0, 360))
fig.tight_layout()
plt.show()

# %% [markdown]
# ## 3. The lubricated clearance joint: journal-centre trace
# The scene's joint C in oil (Table 2: c = 0.021 mm, R = 20 mm, L = 42 mm, 0.0175 Pa s), one
# revolution after one revolution of settling. The seed's journal comes close to the bearing
# centre (its contact-loss risk) at 72–114° and 302–338° of crank angle, where the load turns
# fastest; crankmodal's quasi-static reading of Table 3 puts those windows at 90–96° and
# 309–323° (README, *[dynamics]*, `pytest -m slow` checks it). Below: the dynamic film, whose
# closest approaches to the centre are printed with their crank angles — a second revolution
# from a centred start, not yet a settled orbit, and not the quasi-static reading.

# %%
params = cm.check_scene(cm.load_scene(cm.scene_path("loom_four_bar_dynamics"),
                                      [f"dynamics.end_time={2 * T!r}"]))
p = params["dynamics"]
mech = build_mechanism(p)
hist = cm.simulate(mech, 2 * T, T / 360, solver_settings(p, RPM))
c = hist.contact["C"]
last = hist.t >= T - 1e-12
ex, ey = c["ex"][last] / 2.1e-5, c["ey"][last] / 2.1e-5
eps = np.hypot(ex, ey)
cdeg = np.degrees(hist.crank_angle[last]) % 360.0
print(f"eccentricity ratio over the second revolution: {eps.min():.3f} .. {eps.max():.2f}; "
      f"{hist.nfev} RHS evaluations, {hist.wall_time:.1f} s")
for lo, hi in ((30.0, 200.0), (200.0, 360.0)):
    m = (cdeg >= lo) & (cdeg < hi)
    k = np.argmin(eps[m])
    print(f"  closest to the centre between {lo:.0f} and {hi:.0f} deg: eps {eps[m][k]:.3f} "
          f"at {cdeg[m][k]:.1f} deg")
assert np.all(eps < 1.0)

# %%
fig, ax = plt.subplots(figsize=(5, 5))
th = np.linspace(0, 2 * np.pi, 200)
ax.plot(np.cos(th), np.sin(th), "k", lw=2, label="clearance circle")
sc = ax.scatter(ex, ey, c=np.degrees(hist.crank_angle[last]) % 360.0, s=4, cmap="twilight")
fig.colorbar(sc, ax=ax, label="crank angle (deg)")
ax.set(aspect="equal", xlabel="e_x / c", ylabel="e_y / c", title="journal centre at C, 450 rpm")
ax.legend(loc="lower right", fontsize=8)
fig.tight_layout()
plt.show()
