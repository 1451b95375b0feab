# %% [markdown]
# # crankmodal from Python: a walkthrough
#
# A script in jupytext "percent" format: open it in Jupyter (`jupytext --to notebook`) or VS Code,
# or run it as it is. `tests/test_notebooks.py` runs it in CI, so it cannot rot. Every number it
# prints is checked against an independent closed form on the line below it.

# %%
import math
import tempfile

import numpy as np

# %% [markdown]
# ## 1. A torsional chain: exact eigen solution, Holzer and the two-rotor closed form
# %%
from crankmodal.torsion import TorsionalChain, exact_modes, holzer, two_rotor

chain = TorsionalChain(inertias=np.array([0.3, 0.6, 0.18]), stiffnesses=np.array([1.32e5, 1.98e5]))
exact, hz = exact_modes(chain), holzer(chain)
print("exact  :", np.round(exact.frequencies_hz, 3), "Hz")
print("Holzer :", np.round(hz.frequencies_hz, 3), "Hz")
assert np.allclose(hz.frequencies_hz, exact.frequencies_hz, rtol=1e-8)

# two rotors on one shaft: f = sqrt(k (I1 + I2) / (I1 I2)) / 2 pi
I1, I2, k = 0.36172, 2.04661, 1.14223e6  # seed 004's throw, flywheel and shaft
f2 = two_rotor(I2, I1, k).frequency_hz  # (flywheel, other rotor, stiffness)
print(f"two-rotor: {f2:.1f} Hz (seed 004: 306.8 Hz)")
assert math.isclose(f2, math.sqrt(k * (I1 + I2) / (I1 * I2)) / (2 * math.pi), rel_tol=1e-12)

# %% [markdown]
# ## 2. The four-star compressor's mechanism, from its machine file

# %%
from crankmodal.runner import run
from crankmodal.scene import scene_from_dict

out = tempfile.mkdtemp()
res = run(scene_from_dict({"mechanism": {"machine": "four_star_compressor"}}), out,
          figures=False)["mechanism"]
print(res["summary"])
w = 1480 * math.pi / 30
m_s = 1.2 + 0.35 * 1.6  # piston group + reciprocating share of the rod (machine file)
# four-star balance (seed 000): first-order resultant constant at 2 m_s r w^2, second order gone
assert math.isclose(res["first_order_force_max_n"], 2 * m_s * 0.035 * w**2, rel_tol=1e-9)
assert res["second_order_force_cancelled"]

# %% [markdown]
# ## 3. Free-free modes of a steel bar (P2) against Euler-Bernoulli

# %%
from crankmodal.fem import testparts
from crankmodal.fem.assembly import assemble
from crankmodal.fem.materials import material
from crankmodal.fem.modal import solve_modes
from crankmodal.report import assert_frequencies

steel = material("steel")
L, b, h = 1.0, 0.05, 0.05
modes = solve_modes(assemble(testparts.bar(L, b, h, divisions=(24, 2, 2), order=2), steel), 2)
print("bar:", np.round(modes.frequencies_hz, 1), "Hz,", modes.rigid_body_modes, "rigid-body modes")
# free-free bending: f1 = (4.7300^2 / 2 pi L^2) sqrt(E I / rho A), a bending pair for a square bar;
# slender bar (L/h = 20): shear and rotary inertia lower it ~0.5 %
f1 = 4.730041**2 / (2 * math.pi * L**2) * math.sqrt(steel.E * b * h**3 / 12 / (steel.rho * b * h))
assert_frequencies(modes.frequencies_hz, [f1, f1], rtol=0.01)
assert modes.rigid_body_modes == 6
