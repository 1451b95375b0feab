"""Torsional checks of crankshafts the way design offices do them beside FE.

Modules, one concept each:

- :mod:`.equivalent_length` -- Ker Wilson / Carter equivalent length of a crank throw, shaft
  segments in series, stiffness ``k = G J / L``;
- :mod:`.inertias` -- throw and flywheel mass moments of inertia (seed 004 eqs. 2-5) and the
  inertia about the shaft axis of a CAD solid;
- :mod:`.mesh_inertias` -- the same rotor inertias integrated over a tetrahedral mesh of the part;
- :mod:`.crank_model` -- a chain of throws and a flywheel from crank dimensions;
- :mod:`.chain` -- the lumped torsional chain and its exact eigen solution;
- :mod:`.two_rotor` -- closed-form two-rotor frequency and node, and the reduction of a chain
  to two rotors;
- :mod:`.holzer` -- the Holzer method (residual torque sweep, bracketed roots, Holzer table);
- :mod:`.critical_speeds` -- orders x running speed against natural frequencies;
- :mod:`.fe_compare` -- the first FE torsional mode (as the FE classifier names it) beside the
  lumped-chain frequencies;
- :mod:`.excitation` -- each cylinder's tangential effort from the mechanism, its orders, and the
  harmonic torques on the rotors (the machine's arrangement: :mod:`crankmodal.mechanism.arrangement`);
- :mod:`.damping` -- rotor, section and modal damping, dampers as chain elements;
- :mod:`.forced` -- the damped train, per-order steady state and its phased synthesis, the
  energy-balance resonance amplitude;
- :mod:`.stress` -- section modulus, nominal shear stress, allowable vibratory stress;
- :mod:`.verdict` -- separation margins of significant orders and the stress check;
- :mod:`.resonance` -- Holzer-style tables at the resonances of a forced train;
- :mod:`.fe_beside` -- the FE crank's torsional modes beside the forced train's;
- :mod:`.forced_stage`, :mod:`.forced_plots`, :mod:`.forced_report` -- ``[torsion.forced]``, its
  figures and its report tables;
- :mod:`.plots` -- PNG figures (matplotlib imported inside the functions);
- :mod:`.stage` -- the ``[torsion]`` scene section.

Only numpy and scipy are imported here; nothing pulls in gmsh, scikit-fem or pyvista.
"""

from .chain import ChainModes, TorsionalChain, exact_modes
from .damping import Damper
from .excitation import CrankEnd, PressureTable, cylinder_efforts, rotor_excitation
from .forced import (
    DampedTrain,
    ForcedResponse,
    damped_train,
    energy_balance_amplitude,
    steady_state,
)
from .holzer import HolzerResult, holzer, holzer_table
from .stress import Allowable, Section
from .two_rotor import TwoRotorResult, reduce_to_two_rotors, two_rotor

__all__ = [
    "Allowable",
    "ChainModes",
    "CrankEnd",
    "DampedTrain",
    "Damper",
    "ForcedResponse",
    "HolzerResult",
    "PressureTable",
    "Section",
    "TorsionalChain",
    "TwoRotorResult",
    "cylinder_efforts",
    "damped_train",
    "energy_balance_amplitude",
    "exact_modes",
    "holzer",
    "holzer_table",
    "reduce_to_two_rotors",
    "rotor_excitation",
    "steady_state",
    "two_rotor",
]
