# %% [markdown]
# # A crankmodal flexible body in another multibody code: Exudyn
#
# The reduced body's `.npz` carries its mesh and mode shapes, so it can leave crankmodal:
# `crankmodal.reduction.export` writes the modes as a VTU for ParaView and builds Exudyn's
# reduced-order floating-frame body (`ObjectFFRFreducedOrder`) from the `.npz` alone.
# Here: the four-star compressor's rod, reduced on its two eyes, exported and checked in Exudyn
# — the same free-free frequencies, the same mass and inertia — then held by a spherical joint
# at the big-end interface marker. Needs `pip install crankmodal[multibody]` (Exudyn); the
# notebook test is skipped when Exudyn is not installed.
# crankmodal: needs exudyn

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import crankmodal as cm
from crankmodal.reduction import export

work = Path(tempfile.mkdtemp(prefix="exudyn_export_"))

# %% [markdown]
# ## 1. The rod, reduced with its mesh, and its modes as a VTU

# %%
machine = cm.load_machine("four_star_compressor")
rod = cm.build_part(cm.params_from_dict("rod", machine["rod"]), "simplified",
                    cm.MeshSettings(size=0.008, order=2), name="rod")
steel = cm.material("steel")
model = cm.assemble(rod, steel)
itf = cm.make_interfaces(rod, [{"region": "big_end_bore", "kind": "distributing"},
                               {"region": "small_end_bore", "kind": "distributing"}])
body, _ = cm.reduce_body(model, itf, fixed_interface_modes=6, mesh=rod.mesh, name="rod")
body = cm.load_flexbody(cm.save_flexbody(work / "rod.npz", body))   # what another user receives
vtu = export.write_modes_vtu(work / "rod_modes.vtu", body)
print(f"{body.n_modes} modes ({len(body.elastic_frequencies_hz)} elastic); VTU for ParaView: "
      f"{vtu.name} with point vectors {export.mode_vtu_names(body)[:3]} ...")

# %% [markdown]
# ## 2. The body in Exudyn: frequencies, mass and inertia

# %%
import exudyn as exu
import exudyn.itemInterface as eii
from exudyn.solver import ComputeODE2Eigenvalues

cms = export.exudyn_ffrf_interface(body)
sc = exu.SystemContainer()
mbs = sc.AddSystem()
cms.AddObjectFFRFreducedOrder(mbs)
mbs.Assemble()
ev, _ = ComputeODE2Eigenvalues(mbs)
f_exu = np.sqrt(np.abs(np.sort(ev))) / (2 * np.pi)
print("Exudyn, free-free:", np.round(f_exu[6:12], 1), "Hz")
print("crankmodal       :", np.round(body.elastic_frequencies_hz[:6], 1), "Hz")
assert np.abs(f_exu[:6]).max() < 1e-6 * f_exu[6]                      # six rigid-body modes
assert np.allclose(f_exu[6:], body.elastic_frequencies_hz, rtol=1e-9)
print(f"mass: Exudyn {cms.totalMass:.6f} kg, CAD {rod.cad_mass.mass(steel.rho):.6f} kg")
assert abs(cms.totalMass / rod.cad_mass.mass(steel.rho) - 1) < 1e-4

# %% [markdown]
# ## 3. Held at the big end: a spherical joint on crankmodal's interface marker
# The marker is Exudyn's `MarkerSuperElementRigid` on the big-end bore's surface nodes, weighted
# like crankmodal's distributing coupling, placed at the exact bore centre.

# %%
sc = exu.SystemContainer()
mbs = sc.AddSystem()
obj = cms.AddObjectFFRFreducedOrder(mbs)["oFFRFreducedOrder"]
ground = mbs.AddObject(eii.ObjectGround())
marker = export.exudyn_interface_marker(mbs, obj, body, "big_end_bore")
centre = body.interface_centres[body.interface_names.index("big_end_bore")]
mg = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground, localPosition=list(centre)))
mbs.AddObject(eii.SphericalJoint(markerNumbers=[mg, marker]))
mbs.Assemble()
ev, _ = ComputeODE2Eigenvalues(mbs)
f_pin = np.sort(np.sqrt(np.abs(ev)) / (2 * np.pi))
n_free = int(np.sum(f_pin < 1e-3 * f_pin[-1]))
print(f"pinned at the big end: {n_free} free rotations, then", np.round(f_pin[n_free:n_free + 4], 1),
      "Hz")
assert n_free == 3                                                    # a ball joint keeps rotations

# %%
fig, ax = plt.subplots(figsize=(8, 3.6))
k = np.arange(1, 7)
ax.bar(k - 0.2, body.elastic_frequencies_hz[:6], 0.4, label="crankmodal (.npz)")
ax.bar(k + 0.2, f_exu[6:12], 0.4, label="Exudyn ObjectFFRFreducedOrder")
ax.set(xlabel="elastic mode", ylabel="Hz", xticks=k,
       title="four-star rod, free-free: the same body in two codes")
ax.legend()
fig.tight_layout()
plt.show()
