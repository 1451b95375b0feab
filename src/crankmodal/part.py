"""The ``Part``: what crosses the geometry -> FE boundary.

A part is a volume mesh (meshio, SI metres, ``tetra`` or ``tetra10`` cells in meshio's node
order), named regions on its boundary, mass properties from the CAD, and the parameters and
fidelity that made it. Nothing here imports gmsh or scikit-fem.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class CylindricalSurface:
    """Exact geometry of a cylindrical boundary surface of a part (a bearing bore or a journal).

    A geometric surface, not a cylinder of a machine (that is
    :class:`crankmodal.mechanism.machine.Cylinder`, and its multibody form
    :class:`crankmodal.dynamics.Cylinder`). Formerly named ``Cylinder``: that name stays an alias.

    Attributes
    ----------
    centre : ndarray, shape (3,)
        Point on the axis at the middle of the cylinder's length, m.
    axis : ndarray, shape (3,)
        Unit axis direction.
    radius : float
        m.
    length : float
        m.
    """

    centre: np.ndarray
    axis: np.ndarray
    radius: float
    length: float

    def to_dict(self) -> dict:
        return {
            "centre": np.asarray(self.centre, float).tolist(),
            "axis": np.asarray(self.axis, float).tolist(),
            "radius": float(self.radius),
            "length": float(self.length),
        }


#: Former name of :class:`CylindricalSurface`, kept so that code importing it and parts pickled
#: under it (the geometry cache) still load. New code: :class:`CylindricalSurface`.
Cylinder = CylindricalSurface


@dataclass
class Region:
    """A named boundary region of a part.

    Attributes
    ----------
    name : str
        e.g. ``main_journal_1``, ``crankpin_row_1``, ``big_end_bore``.
    facets : ndarray of int, shape (n_facets, 3)
        Corner-node indices (into ``Part.mesh.points``) of the boundary triangles of the region.
    nodes : ndarray of int
        Sorted unique indices of every mesh node on those facets (mid-side nodes included for
        second-order meshes).
    cylinder : CylindricalSurface or None
        Exact cylindrical surface the region lies on, when known from the geometry.
    """

    name: str
    facets: np.ndarray
    nodes: np.ndarray
    cylinder: CylindricalSurface | None = None

    def area(self, points: np.ndarray) -> float:
        """Sum of the flat facet areas, m² (slightly below a curved surface's true area)."""
        p = points[self.facets]
        return float(0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum())


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of a solid of uniform density.

    Attributes
    ----------
    volume : float
        m³.
    centroid : ndarray, shape (3,)
        m.
    inertia_per_density : ndarray, shape (3, 3)
        Inertia tensor about the centroid divided by density, m⁵ (multiply by ρ for kg m²).
    """

    volume: float
    centroid: np.ndarray
    inertia_per_density: np.ndarray

    def mass(self, rho: float) -> float:
        """kg, for density ``rho`` in kg/m³."""
        return self.volume * rho

    def inertia(self, rho: float) -> np.ndarray:
        """Inertia tensor about the centroid, kg m²."""
        return np.asarray(self.inertia_per_density) * rho

    def to_dict(self) -> dict:
        return {
            "volume_m3": float(self.volume),
            "centroid_m": np.asarray(self.centroid, float).tolist(),
            "inertia_per_density_m5": np.asarray(self.inertia_per_density, float).tolist(),
        }


@dataclass
class Part:
    """A meshed part with named regions.

    Attributes
    ----------
    name : str
        e.g. ``four_star_compressor/crankshaft``.
    mesh : meshio.Mesh
        Volume mesh in metres with one ``tetra`` or ``tetra10`` cell block.
    regions : dict of str to Region
        Named boundary regions.
    fidelity : str
        ``full``, ``dechamfered``, ``simplified`` or ``imported``.
    params : dict
        The parameters that built the part (empty for an imported one).
    cad_mass : MassProperties or None
        From the CAD solid (None for a mesh imported without CAD).
    quality : dict
        Mesh statistics: element and node counts, min/mean quality and the measure's name.
    """

    name: str
    mesh: Any
    regions: dict[str, Region] = field(default_factory=dict)
    fidelity: str = "imported"
    params: dict = field(default_factory=dict)
    cad_mass: MassProperties | None = None
    quality: dict = field(default_factory=dict)

    @property
    def cell_type(self) -> str:
        return self.mesh.cells[0].type

    @property
    def element_order(self) -> int:
        return 2 if self.cell_type == "tetra10" else 1

    @property
    def n_elements(self) -> int:
        return len(self.mesh.cells[0].data)

    @property
    def n_nodes(self) -> int:
        return len(self.mesh.points)

    def summary(self) -> dict:
        """JSON-able description (no arrays of mesh size)."""
        return {
            "name": self.name,
            "fidelity": self.fidelity,
            "element_order": self.element_order,
            "n_elements": self.n_elements,
            "n_nodes": self.n_nodes,
            "regions": {
                k: {"n_facets": len(r.facets), "n_nodes": len(r.nodes),
                    "area_m2": r.area(self.mesh.points),
                    **({"cylinder": r.cylinder.to_dict()} if r.cylinder else {})}
                for k, r in self.regions.items()
            },
            "quality": self.quality,
            **({"cad_mass": self.cad_mass.to_dict()} if self.cad_mass else {}),
        }
