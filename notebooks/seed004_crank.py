# %% [markdown]
# # Seed 004: modal analysis of a compressor crankshaft — torsion and FE modes
#
# Yadav, Wadkar, Patil, *Modal Analysis of Compressor Crankshaft*. The seed reduces its crank
# (Table 1 dimensions, Table 2 material) to a throw against a flywheel through a Ker Wilson
# equivalent length, solves the two-rotor system and a Holzer table, checks the critical speed
# against the forcing frequency (24.91 Hz), and computes FE modes on three simply supported
# bearings (Table 3). This notebook reruns crankmodal's ready scenes on the reconstructed machine
# (`geometry/multi_bearing_compressor.toml`) and sets each result next to the seed's.
# The FE part uses a coarse 40 mm mesh here (the README's converged run: 12.5 mm, 831k DOF).

# %%
import math
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from IPython.display import Image, display

import crankmodal as cm

OUT = Path(tempfile.mkdtemp(prefix="seed004_"))


def table(rows, header):
    """A plain-text table."""
    cells = [header] + [[f"{v:.5g}" if isinstance(v, float) else str(v) for v in r] for r in rows]
    w = [max(len(r[i]) for r in cells) for i in range(len(header))]
    for k, r in enumerate(cells):
        print("  ".join(c.rjust(w[i]) for i, c in enumerate(r)))
        if k == 0:
            print("  ".join("-" * n for n in w))


# %% [markdown]
# ## 1. The seed's own numbers, through the two-rotor closed form
# Seed 004 lumps one throw (I1 = 0.36172 kg m²) against the flywheel (I2 = 2.04661 kg m²) on a
# shaft of k = G J / L_eq = 1.14223e6 N m/rad and reports 306.8 Hz with the node 129.7 mm from
# the flywheel.

# %%
I1, I2, k = 0.36172, 2.04661, 1.14223e6
two = cm.two_rotor(I2, I1, k, length=0.86326)
table([["two-rotor frequency, Hz", two.frequency_hz, 306.8],
       ["node from the flywheel, mm", two.node_from_flywheel_m * 1e3, 129.7]],
      ["seed data", "crankmodal", "seed 004"])
assert math.isclose(two.frequency_hz, math.sqrt(k * (I1 + I2) / (I1 * I2)) / (2 * math.pi),
                    rel_tol=1e-12)
assert abs(two.frequency_hz - 306.8) < 0.05

# %% [markdown]
# ## 2. From the dimensions: `scenes/seed004_torsion.toml`
# Ker Wilson length, throw-part inertias (seed eqs. 2–5), flywheel disc, then exact, Holzer and
# two-rotor frequencies and the critical speeds against compressor orders 1–12.

# %%
res = cm.run_scene(cm.load_scene(cm.scene_path("seed004_torsion")), OUT / "torsion")
t = res["torsion"]
cmod = t["crank_model"]
print(t["summary"])
table([
    ["equivalent length L_eq, mm", cmod["equivalent_length_m"] * 1e3, 863.26],
    ["polar moment J, mm^4", cmod["polar_moment_m4"] * 1e12, 14373768.0],
    ["stiffness k, N m/rad", cmod["stiffness_Nm_per_rad"], 1.14223e6],
    ["throw inertia I1, kg m^2", t["two_rotor"]["inertia_lumped_kgm2"], 0.36172],
    ["flywheel inertia I2, kg m^2", t["two_rotor"]["inertia_flywheel_kgm2"], 2.04661],
    ["two-rotor frequency, Hz", t["two_rotor_hz"], 306.8],
    ["Holzer (refined root), Hz", float(t["holzer_hz"][0]), "332.6 (a trial row)"],
    ["node from flywheel, mm", t["two_rotor"]["node_from_flywheel_m"] * 1e3, 129.7],
], ["seed 004, from the dimensions", "crankmodal", "seed 004"])
assert abs(float(t["holzer_hz"][0]) / t["two_rotor_hz"] - 1) < 1e-8

# %% [markdown]
# The seed's listed throw-part inertias add up to 0.34133 kg m², not the 0.36172 it uses; with
# the sum, 314 Hz — crankmodal's value. Its Holzer "332.6 Hz" is a trial row with the stiffness
# of the shaft from the node to the throw only (README, *[torsion]*).

# %%
for name in ("torsion_campbell.png", "torsion_mode_shapes.png"):
    display(Image(filename=str(OUT / "torsion" / name), width=640))

# %% [markdown]
# ## 3. Critical speed against the forcing frequency
# The seed checks order 1: 24.91 Hz forcing against ~307 Hz, far apart. crankmodal checks every
# order up to 12 over 0–1800 rpm:

# %%
cs = t["critical_speeds"]
rows = [[c["order"], c["speed_rpm"]] for c in cs["critical_speeds_in_range"]]
table(rows, ["order", "critical speed, rpm"])
print(f"operating speed {cs['operating_speed_rpm']} rpm = {cs['operating_speed_rpm'] / 60:.2f} Hz "
      "(seed: forcing frequency 24.91 Hz)")

# %% [markdown]
# ## 4. FE modes on three bearings (Table 3)
# The crank on three radial journal supports and an axial stop (`scenes/seed004_crank.toml`),
# here at 40 mm and P2 without the report's renders (mode 1: 336.0 Hz, at 20 mm 334.7 Hz).
# Seed Table 3: 307.2 / 307.3 Hz for its first pair (a bending pair).

# %%
scene = cm.load_scene(cm.scene_path("seed004_crank"), ["geometry.mesh_size=0.04"])
fe_scene = cm.scene_from_dict({k: v for k, v in scene.sections.items() if k != "report"},
                              name="seed004_fe", base_dir=scene.base_dir)
fe = cm.run_scene(fe_scene, OUT / "fe", figures=False)
f = np.asarray(fe["modal"]["frequencies_hz"])
seed_fe = [307.2, 307.3]
table([[f"mode {i + 1}", float(f[i]), seed_fe[i] if i < 2 else "-"] for i in range(len(f))],
      ["3 bearings + axial stop", "crankmodal P2 40 mm, Hz", "seed 004 Table 3, Hz"])
print(fe["modal"]["summary"])

# %%
fig, ax = plt.subplots(figsize=(7, 3.6))
ax.plot(np.arange(1, len(f) + 1), f, "o-", label="crankmodal FE (P2, 40 mm)")
ax.plot([1, 2], seed_fe, "s", label="seed 004 Table 3")
ax.axhline(t["two_rotor_hz"], color="C3", ls="--", label="two-rotor torsion (crankmodal)")
ax.axhline(306.8, color="C2", ls=":", label="two-rotor torsion (seed)")
ax.set(xlabel="mode", ylabel="Hz", title="seed 004 crank on three bearings")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()

# %% [markdown]
# The reconstructed crank's first pair lies above the seed's (+8 % at the converged 12.5 mm mesh,
# README); its first FE *torsion* mode (569 Hz) is far above the chain's 314 Hz: the seed's
# 863 mm Ker Wilson length is much longer than the crank's real torsional path, and the seed
# compares its Holzer value with FE mode 1, a bending mode.
