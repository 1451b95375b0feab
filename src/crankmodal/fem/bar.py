"""Prismatic bar parts on a structured tetrahedral grid (no gmsh): a link between two pins.

A bar along x with named end faces, P1 or straight-sided P2 tetrahedra from scikit-fem's tensor
grid; :func:`check_bar_size` refuses a grid over the element limit before any memory is taken.
Production uses it for a four-bar link that has no part of its own
(:func:`crankmodal.reduction.parts.reduced_bar`); tests use it as a fast part
(:mod:`crankmodal.fem.testparts` re-exports it).
"""

from __future__ import annotations

import numpy as np

from ..part import MassProperties, Part, Region
from ..topology import TET10_EDGES, boundary_facets, facet_nodes


def elevate_to_p2(points: np.ndarray, tets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Add straight mid-edge nodes: (points, tetra) → (points, tetra10 in meshio order)."""
    e = np.sort(tets[:, TET10_EDGES], axis=2).reshape(-1, 2)
    uniq, inv = np.unique(e, axis=0, return_inverse=True)
    mids = 0.5 * (points[uniq[:, 0]] + points[uniq[:, 1]])
    t10 = np.hstack([tets, len(points) + inv.reshape(len(tets), 6)])
    return np.vstack([points, mids]), t10


def region(name: str, points, cells, facets, select, cylinder=None) -> Region:
    """Region of the boundary facets whose centroid satisfies ``select(xyz) -> bool array``."""
    c = points[facets].mean(axis=1)
    f = facets[np.asarray(select(c), bool)]
    return Region(name=name, facets=f, nodes=facet_nodes(f, cells), cylinder=cylinder)


def _mesh(points, tets, order):
    import meshio

    if order == 2:
        points, tets = elevate_to_p2(points, tets)
        return meshio.Mesh(points, [("tetra10", tets)])
    return meshio.Mesh(points, [("tetra", tets)])


def _grid(n):
    from skfem import MeshTet

    m = MeshTet.init_tensor(*(np.linspace(0.0, 1.0, k + 1) for k in n))
    return m.p.T.copy(), m.t.T.copy()


#: Tetrahedra per hexahedral cell of the structured grid (scikit-fem's ``MeshTet.init_tensor``).
TETS_PER_CELL = 6


def _check_dims(dims, names=("length", "width", "height")) -> None:
    """Refuse box sides that are not finite numbers > 0 m (a ParameterError naming the side)."""
    from ..errors import ParameterError
    from ..geometry.mesh import is_length

    if not isinstance(dims, (tuple, list)) or len(dims) != 3:
        raise ParameterError("dims", f"must be three lengths (m), got {dims!r}")
    for name, d in zip(names, dims):
        if not is_length(d):
            raise ParameterError(name, f"must be a number > 0 m, got {d!r}")


def bar_divisions(dims, size: float) -> tuple:
    """Cells along each side of a box ``dims`` (m) at about ``size`` (m) per edge:
    ``max(1, ceil(d / size))`` each, as floats (``inf`` for a subnormal size, so that
    :func:`bar_elements` can refuse it before any integer or array is made)."""
    return tuple(max(1.0, float(np.ceil(d / size))) for d in dims)


def bar_elements(divisions) -> float:
    """Tetrahedra of a :func:`bar` with ``divisions`` cells: ``6 nx ny nz``."""
    n = float(TETS_PER_CELL)
    for d in divisions:  # Python floats: an overflow is inf, without a warning
        n *= float(d)
    return n


def check_bar_size(dims, size: float, max_elements: float, reason: str) -> tuple:
    """The integer divisions of a bar ``dims`` (m) meshed at ``size`` (m), refused when its
    tetrahedra exceed ``max_elements`` (before any memory is taken: a 1 µm size on a 75 mm
    coupler is 2e17 tetrahedra, a 2 PiB grid).

    Raises
    ------
    MeshSizeError
        Naming ``size``, the count, the limit (``reason`` says why it is what it is) and the
        smallest size it allows.
    """
    from ..errors import ParameterError
    from ..geometry.mesh import MeshSizeError, is_length

    if not is_length(size):
        raise ParameterError("size", f"must be a number > 0 m, got {size!r}")
    if not is_length(max_elements):
        raise ParameterError("max_elements", f"must be a number > 0, got {max_elements!r}")
    _check_dims(dims)
    div = bar_divisions(dims, size)
    n = bar_elements(div)
    if n > max_elements:
        lo, hi = min(dims) * 1e-9, max(dims)  # bisection on log h: the count falls with h
        for _ in range(200):
            mid = (lo * hi) ** 0.5
            lo, hi = (mid, hi) if bar_elements(bar_divisions(dims, mid)) > max_elements else (lo, mid)
        grid = " x ".join(f"{d:.3g}" for d in div)
        box = " x ".join(f"{d:g}" for d in dims)
        raise MeshSizeError(size, "exactly", n, f"6 per cell of a {grid} grid on the {box} m bar",
                            max_elements, reason, hi)
    return tuple(int(d) for d in div)


def bar(length=1.0, width=0.05, height=0.05, divisions=(20, 2, 2), order=2) -> Part:
    """A prismatic bar along x, cross-section width (y) × height (z), m, centred on the x axis.

    Regions: ``end_x0`` (x = 0), ``end_x1`` (x = length), ``top`` (z = +h/2), ``bottom``.

    Raises
    ------
    ParameterError
        Naming ``divisions`` when they make more than
        :data:`~crankmodal.geometry.mesh.MAX_ELEMENTS` tetrahedra (refused before the grid is
        made, instead of a MemoryError).
    """
    from ..errors import ParameterError
    from ..geometry.mesh import MAX_ELEMENTS

    _check_dims((length, width, height), ("length", "width", "height"))
    if (not isinstance(divisions, (tuple, list)) or len(divisions) != 3
            or not all(isinstance(d, (int, np.integer)) and not isinstance(d, bool) and d >= 1
                       for d in divisions)):
        raise ParameterError("divisions", f"must be three integers >= 1, got {divisions!r}")
    if isinstance(order, bool) or order not in (1, 2):
        raise ParameterError("order", f"must be 1 or 2, got {order!r}")
    if bar_elements(divisions) > MAX_ELEMENTS:
        raise ParameterError("divisions", f"{tuple(divisions)} makes {bar_elements(divisions):.3g} "
                             f"tetrahedra, over crankmodal's limit of {MAX_ELEMENTS:.3g}")
    p, t = _grid(divisions)
    scale = np.array([length, width, height])
    p = p * scale - np.array([0.0, width / 2, height / 2])
    mesh = _mesh(p, t, order)
    pts, cells = mesh.points, mesh.cells[0].data
    fac = boundary_facets(cells)
    tol = 1e-9 * length
    regions = {
        "end_x0": region("end_x0", pts, cells, fac, lambda c: c[:, 0] < tol),
        "end_x1": region("end_x1", pts, cells, fac, lambda c: c[:, 0] > length - tol),
        "top": region("top", pts, cells, fac, lambda c: c[:, 2] > height / 2 - tol),
        "bottom": region("bottom", pts, cells, fac, lambda c: c[:, 2] < -height / 2 + tol),
    }
    b, h, L = width, height, length
    inertia = np.diag([b * h * L * (b * b + h * h) / 12, b * h * L * (L * L + h * h) / 12,
                       b * h * L * (L * L + b * b) / 12])
    cad = MassProperties(volume=b * h * L, centroid=np.array([L / 2, 0, 0]),
                         inertia_per_density=inertia)
    return Part(name="bar", mesh=mesh, regions=regions, fidelity="full",
                params={"length": length, "width": width, "height": height}, cad_mass=cad)


__all__ = ["TETS_PER_CELL", "bar", "bar_divisions", "bar_elements", "check_bar_size",
           "elevate_to_p2", "region"]
