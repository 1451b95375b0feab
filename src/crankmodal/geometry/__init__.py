"""Parametric crankshaft and connecting-rod geometry (gmsh OCC), meshing and import.

The usual entry point is :func:`build_part`; the scene stage is :mod:`.stage`. Importing this
package does not import gmsh.
"""

from .build import build_part
from .mesh import MeshSettings
from .params import FIDELITIES, ConrodParams, CrankshaftParams, params_from_dict

__all__ = ["FIDELITIES", "ConrodParams", "CrankshaftParams", "MeshSettings", "build_part", "params_from_dict"]
