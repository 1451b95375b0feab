# %% [markdown]
# # crankmodal from Python: a walkthrough
#
# Every stage of crankmodal as plain Python objects, from `import crankmodal` to a dynamics run
# with a flexible connecting rod — the README's *Python API* section, with figures. Each number
# is checked against an independent oracle on the lines below it (closed forms, the CAD mass,
# Rayleigh–Ritz bounds), so the notebook cannot silently rot: `tests/test_notebooks.py` runs it.
#
# Coarse meshes keep it to about half a minute. `import crankmodal` itself loads no gmsh,
# scikit-fem, pyvista or matplotlib; each name is imported when first used.

# %%
import math

import matplotlib.pyplot as plt
import numpy as np

import crankmodal as cm

print(cm.__version__, "-", len(cm.__all__), "public names, e.g.", ", ".join(cm.__all__[:8]), "...")

# %% [markdown]
# ## 1. FE against a closed form: a free steel bar
# `crankmodal.fem.testparts` makes structured meshes for checks like this one.

# %%
from crankmodal.fem import testparts

steel = cm.material("steel")
L, b, h = 1.0, 0.05, 0.05
bar_modes = cm.solve_modes(cm.assemble(testparts.bar(L, b, h, divisions=(24, 2, 2), order=2),
                                       steel), n_modes=2)
# free-free bending: f1 = (4.7300^2 / 2 pi L^2) sqrt(E I / rho A), a pair for a square bar;
# at L/h = 20 shear and rotary inertia lower it by ~0.5 %
f1 = 4.730041**2 / (2 * math.pi * L**2) * math.sqrt(steel.E * b * h**3 / 12 / (steel.rho * b * h))
print("bar:", np.round(bar_modes.frequencies_hz, 1), "Hz; Euler-Bernoulli", round(f1, 1), "Hz")
assert np.allclose(bar_modes.frequencies_hz, f1, rtol=0.01) and bar_modes.rigid_body_modes == 6

# %% [markdown]
# ## 2. Geometry → FE → modes: the four-star compressor's connecting rod
# The machine file `geometry/four_star_compressor.toml` holds the rod's dimensions;
# `build_part` makes the CAD solid (gmsh/OpenCASCADE), meshes it and names its regions.

# %%
machine = cm.load_machine("four_star_compressor")
rod_params = cm.params_from_dict("rod", machine["rod"])
rod = cm.build_part(rod_params, "simplified", cm.MeshSettings(size=0.008, order=2), name="rod")
print(rod.n_elements, "P2 elements,", rod.n_nodes, "nodes; regions:", sorted(rod.regions))
model = cm.assemble(rod, steel)
modes = cm.solve_modes(model, n_modes=6)
print("free-free:", np.round(modes.frequencies_hz, 1), "Hz")
assert modes.rigid_body_modes == 6
assert abs(modes.total_mass / rod.cad_mass.mass(steel.rho) - 1) < 1e-4   # FE mass = CAD mass

# %%
P = rod.mesh.points
fig, ax = plt.subplots(2, 1, figsize=(9, 4.5), sharex=True)
for a, mode in zip(ax, (0, 1)):
    u = modes.shapes[:, mode].reshape(-1, 3)
    comp = int(np.argmax(np.abs(u).max(axis=0)))
    a.scatter(P[:, 0] * 1e3, u[:, comp], s=1)
    a.set(ylabel=f"u_{'xyz'[comp]} (m/√kg)",
          title=f"mode {mode + 1}: {modes.frequencies_hz[mode]:.0f} Hz, bending in {'xyz'[comp]}")
ax[-1].set_xlabel("x along the rod (mm)")
fig.tight_layout()
plt.show()

# %% [markdown]
# ## 3. Supports, a bearing load and a static solve
# A `Support` holds a region's nodes (`Support.region`, or the nodes inside a box with
# `Support.box`); a `Load` holds the nodal forces of a pressure, a traction, a remote force or a
# pin's bearing load on a region (loads add: `a + b`, `sum(...)`, `2 * a`). Big-end eye clamped,
# 10 kN pull on the small-end eye as a pin pressing the bore.

# %%
clamp = [cm.Support.region(rod, "big_end_bore", fix="xyz")]
clamped = cm.solve_modes(model, n_modes=3, supports=clamp)
print("clamped at the big end:", np.round(clamped.frequencies_hz, 1), "Hz")
assert clamped.rigid_body_modes == 0 and clamped.frequencies_hz[0] < modes.frequencies_hz[0]
F = 10e3                                                     # N along +x, the rod's axis
pull = cm.Load.bearing(rod, "small_end_bore", force=[F, 0.0, 0.0])
assert np.allclose(pull.resultant, [F, 0.0, 0.0], rtol=0, atol=1e-9 * F)
static = cm.solve_static(model, rod.mesh, pull, clamp)
p = rod_params
area = 2 * p.shank_width * p.shank_flange_thickness \
    + p.shank_web_thickness * (p.shank_depth - 2 * p.shank_flange_thickness)
mid = np.abs(model.points[:, 0] - p.length / 2) < 0.01
print(f"max von Mises {static.max_von_mises / 1e6:.1f} MPa; mid-shank sigma_xx "
      f"{np.median(static.stress[mid, 0, 0]) / 1e6:.2f} MPa, F/A {F / area / 1e6:.2f} MPa")
assert np.allclose(static.reaction, [-F, 0.0, 0.0], atol=1e-4 * F)   # equilibrium
assert abs(np.median(static.stress[mid, 0, 0]) / (F / area) - 1) < 0.05

# %% [markdown]
# A mistake names the argument: a region the part does not have raises `ParameterError`.

# %%
try:
    cm.Load.bearing(rod, "crankpin", force=[F, 0.0, 0.0])
    raise AssertionError("a region the rod does not have must be refused")
except cm.ParameterError as err:
    print(err)
    assert err.argument == "region"

# %%
fig, ax = plt.subplots(figsize=(9, 3.2))
used = static.von_mises > 0
ax.scatter(P[used, 0] * 1e3, static.von_mises[used] / 1e6, s=1, c=P[used, 1], cmap="coolwarm")
ax.axhline(F / area / 1e6, color="k", ls="--", lw=1, label="F / A of the I-shank")
ax.set(xlabel="x along the rod (mm)", ylabel="von Mises (MPa)",
       title="10 kN pull on the small eye, big eye clamped (colour: y)")
ax.legend()
fig.tight_layout()
plt.show()

# %% [markdown]
# ## 4. Reduction → a flexible body
# Craig–Bampton on the two eyes (distributing couplings), saved as a `crankmodal-flexbody`
# `.npz`, read back as a planar floating-frame body for the multibody solver.

# %%
import tempfile
from pathlib import Path

work = Path(tempfile.mkdtemp(prefix="crankmodal_walkthrough_"))
interfaces = cm.make_interfaces(rod, [{"region": "big_end_bore", "kind": "distributing"},
                                      {"region": "small_end_bore", "kind": "distributing"}])
reduced, _ = cm.reduce_body(model, interfaces, fixed_interface_modes=6, name="rod")
cm.save_flexbody(work / "rod.npz", reduced)
print("reduced free-free:", np.round(reduced.elastic_frequencies_hz[:6], 1), "Hz")
assert np.all(reduced.elastic_frequencies_hz[:6] >= modes.frequencies_hz * (1 - 1e-6))  # Ritz
assert np.allclose(reduced.elastic_frequencies_hz[:6], modes.frequencies_hz, rtol=0.01)
rod_flex = cm.load_flexible_body(work / "rod.npz", "rod_1", n_modes=3, damping_ratio=0.02)
rod_flex.alias("big", "big_end_bore")
rod_flex.alias("small", "small_end_bore")
print("in-plane modes kept:", np.round(rod_flex.frequencies_hz, 1), "Hz")

# %% [markdown]
# ## 5. Torsion: seed 004's crank as a two-rotor chain

# %%
tors = cm.load_machine("multi_bearing_compressor")["torsion"]
crank = cm.crank_model(tors["throw"], tors["flywheel"], shear_modulus=tors["G"],
                       density=tors["density"], form=tors["equivalent_length_form"])
f_exact = cm.exact_modes(crank.chain).frequencies_hz[0]
f_holzer = cm.holzer(crank.chain).frequencies_hz[0]
I1, I2 = crank.throw_inertia, crank.flywheel_inertia
f_closed = math.sqrt(crank.stiffness * (I1 + I2) / (I1 * I2)) / (2 * math.pi)
print(f"L_eq {crank.equivalent_length * 1e3:.2f} mm; first mode exact {f_exact:.2f}, "
      f"Holzer {f_holzer:.2f}, closed form {f_closed:.2f} Hz")
assert math.isclose(f_exact, f_closed, rel_tol=1e-9) and math.isclose(f_holzer, f_closed, rel_tol=1e-8)
crit = cm.critical_speeds([f_exact], order_type="compressor", max_order=12,
                          speed_range_rpm=tors["speed_range_rpm"],
                          operating_rpm=tors["operating_speed_rpm"])
print("nearest critical speed:", crit.nearest())

# %%
rpm = np.linspace(*tors["speed_range_rpm"], 200)
fig, ax = plt.subplots(figsize=(7, 4))
for n in range(1, 13):
    ax.plot(rpm, n * rpm / 60.0, color="0.6", lw=0.8)
    ax.text(rpm[-1], n * rpm[-1] / 60.0, f" {n}", fontsize=7, va="center")
ax.axhline(f_exact, color="C3", label=f"first torsional mode {f_exact:.0f} Hz")
ax.axvline(tors["operating_speed_rpm"], color="C0", ls="--", label="operating speed")
ax.set(xlabel="crank speed (rpm)", ylabel="frequency (Hz)", ylim=(0, 1.3 * f_exact),
       title="Campbell diagram: orders 1-12 against the torsional mode")
ax.legend(loc="upper left")
fig.tight_layout()
plt.show()


# %% [markdown]
# ## 6. A dynamics run built from body objects
# A single-cylinder slider-crank at 1480 rpm with the flexible rod of section 4 (3 in-plane
# modes, 2 % damping), inertia loads only, beside its rigid twin (the rod's modes frozen).
# Oracle: the crank has no mass of its own, so the main bearing carries the rod's and piston's
# centre-of-mass acceleration; at top dead centre that is m_rot r ω² + m_rec r ω² (1 + r/L) with
# the exact two-mass split.

# %%
def slider_crank(rod_body):
    cyl = cm.Cylinder(axis_angle=np.pi / 2, rod_length=0.392, rod_mass=rod_body.mass,
                      rod_inertia=0.0, rod_com=0.0, piston_mass=1.2)
    return cm.crank_train(0.035, [cyl], speed_rpm=1480.0, crank_inertia=0.05,
                          rod_bodies=[rod_body])


runs = {}
for label, body in (("flexible", rod_flex), ("rigid", cm.rigid_twin(rod_flex))):
    runs[label] = cm.simulate(slider_crank(body), 0.081, 1e-4,
                              cm.SolverSettings(rtol=1e-7, atol=1e-9))
r, Lr, w = 0.035, 0.392, 1480 * np.pi / 30
m_rec = 1.2 + rod_flex.mass * np.hypot(*rod_flex.frames["big"][0]) / Lr
m_rot = rod_flex.mass - (m_rec - 1.2)
f_tdc = m_rot * r * w**2 + m_rec * r * w**2 * (1 + r / Lr)
peaks = {k: np.hypot(*h.main_bearing_force[h.t > 0.04].T).max() for k, h in runs.items()}
print({k: round(float(v), 1) for k, v in peaks.items()}, "N; closed form at TDC", round(f_tdc, 1), "N")
assert abs(peaks["rigid"] / f_tdc - 1) < 1e-3 and abs(peaks["flexible"] / peaks["rigid"] - 1) < 0.01

# %%
fig, ax = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
for label, h in runs.items():
    sel = h.t > 0.04
    deg = np.degrees(h.crank_angle[sel])
    ax[0].plot(deg, np.hypot(*h.main_bearing_force[sel].T), label=label,
               ls="-" if label == "flexible" else "--")
ax[0].axhline(f_tdc, color="k", lw=0.8, ls=":", label="closed form at TDC")
ax[0].set(ylabel="|main-bearing force| (N)", title="slider-crank, 1480 rpm, inertia loads",
          ylim=(0, 1.3 * f_tdc))
ax[0].legend(loc="upper center", ncols=3)
h = runs["flexible"]
sel = h.t > 0.04
xi = h.modal["rod_1"]                      # (samples, modes): the rod's modal coordinates
for k in range(xi.shape[1]):
    ax[1].plot(np.degrees(h.crank_angle[sel]), xi[sel, k], label=f"mode {k + 1}")
ax[1].set(xlabel="crank angle (deg)", ylabel="modal amplitude (m √kg)")
ax[1].legend()
fig.tight_layout()
plt.show()

# %% [markdown]
# ## 7. Scenes from Python
# The CLI's `crankmodal run` is `run_scene`; the stages write their PNGs on their own Agg
# canvas (no global backend switch), shown here inline.

# %%
from IPython.display import Image, display

res = cm.run_scene(cm.scene_from_dict({"torsion": {"machine": "multi_bearing_compressor"}}),
                   work / "torsion")
print(res["torsion"]["summary"])
display(Image(filename=str(work / "torsion" / "torsion_campbell.png"), width=640))
