"""Meshing of the current gmsh model: size fields, P1/P2 tetrahedra, optimisation, quality.

Sizes: a global target ``mesh_size``; faces whose curvature radius is below ``detail_radius``
(fillets, chamfers, holes) get ``refine * mesh_size`` on them, graded back to ``mesh_size``
over ``2 * mesh_size`` (gmsh Distance + Threshold fields); curvature adapts the size on arcs
(``CURVATURE_ELEMENTS`` per full circle, never below ``refine * mesh_size``). The 3D algorithm
is gmsh's HXT on one thread (Delaunay if HXT refuses the surface mesh), so the same input gives
the same mesh (counts and coordinates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError, ParameterError, ResourceError

#: gmsh tetra10 -> meshio/VTK tetra10 node order (the last two edge nodes swap).
GMSH_TO_MESHIO_TET10 = np.array([0, 1, 2, 3, 4, 5, 6, 7, 9, 8])

#: Elements per full circle on curved faces.
CURVATURE_ELEMENTS = 16

#: Quality measure reported (gmsh's signed inverse condition number, 1 = regular tetrahedron).
QUALITY_MEASURE = "minSICN"


@dataclass(frozen=True)
class MeshSettings:
    """Meshing settings.

    Attributes
    ----------
    size : float
        Global target element size, m.
    order : int
        1 (linear) or 2 (quadratic, curved on curved faces).
    refine : float
        Size on detail faces as a fraction of ``size`` (0 < refine <= 1).
    optimize : bool
        Run gmsh's tetrahedral optimisation after meshing (sliver removal).
    """

    size: float
    order: int = 2
    refine: float = 0.4
    optimize: bool = True
    #: largest estimated tetrahedron count meshed (:func:`check_size`); not part of the mesh's
    #: identity (``to_dict``), only of what this run accepts
    max_elements: float = 5e6
    #: why ``max_elements`` is what it is, for the refusal's message
    limit_reason: str = "crankmodal's limit on the mesh size"

    def to_dict(self) -> dict:
        return {"size": self.size, "order": self.order, "refine": self.refine, "optimize": self.optimize}


def is_length(value) -> bool:
    """Whether ``value`` is a real number (not a bool), finite and > 0."""
    import math

    return (isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
            and math.isfinite(value) and value > 0)


def check_settings(settings) -> MeshSettings:
    """Return ``settings`` if it is a :class:`MeshSettings` in range; else a ParameterError
    naming ``settings`` (not one) or its field ``size``, ``order`` or ``refine``."""
    if not isinstance(settings, MeshSettings):
        raise ParameterError("settings", f"must be a MeshSettings, got {type(settings).__name__} "
                             f"{settings!r}")
    from .checks import MAX_LENGTH, MIN_LENGTH

    if not is_length(settings.size):
        raise ParameterError("size", f"must be > 0 m{' and finite' if settings.size == float('inf') else ''}, "
                             f"got {settings.size!r}")
    if not MIN_LENGTH <= settings.size <= MAX_LENGTH:  # gmsh would get a size it cannot mesh at
        raise ParameterError("size", f"must be in [{MIN_LENGTH:g}, {MAX_LENGTH:g}] m, the sizes "
                             f"crankmodal builds, got {settings.size!r}")
    if isinstance(settings.order, bool) or settings.order not in (1, 2):
        raise ParameterError("order", f"must be 1 or 2, got {settings.order!r}")
    if not (is_length(settings.refine) and settings.refine <= 1):
        raise ParameterError("refine", f"must be in (0, 1], got {settings.refine!r}")
    if settings.refine * settings.size < MIN_LENGTH:  # the size at fillets and holes
        raise ParameterError("refine", f"must be >= {MIN_LENGTH / settings.size:.3g} (refine x size "
                             f">= {MIN_LENGTH:g} m at the details), got {settings.refine!r}")
    return settings


#: Largest number of tetrahedra meshed: gmsh's own memory and time grow past several GB and
#: minutes above it, and the FE stages could not solve it on a workstation anyway.
MAX_ELEMENTS = 5e6

#: Tetrahedra per V/h^3 (the regular tetrahedron's 6 sqrt 2) and per A/h^2 (the refinement at
#: fillets, holes and curved faces): a least-squares fit to seven gmsh meshes (seed 000's crank
#: at 20, 12, 8 mm and rod at 8, 5 mm, seed 004's crank at 30, 20 mm; 8.6k-60k tetrahedra); the
#: estimate is within -35 % / +19 % of each count.
ELEMENTS_PER_VOLUME = 8.5
ELEMENTS_PER_AREA = 17.5

#: DOF per tetrahedron of a fine mesh: P2 (vertices ~0.2 and edges ~1.2 per tetrahedron, 3 DOF
#: each), P1 (vertices only).
DOF_PER_ELEMENT = {1: 0.6, 2: 4.2}


def estimate_elements(volume: float, area: float, size: float) -> float:
    """Tetrahedra gmsh makes for a solid at element size ``size``.

    Parameters
    ----------
    volume : float
        Solid volume, m^3.
    area : float
        Its surface area, m^2.
    size : float
        ``mesh_size``, m.

    Returns
    -------
    float
        ``8.5 V / h^3 + 17.5 A / h^2`` (see :data:`ELEMENTS_PER_VOLUME`).
    """
    # divided one power at a time: a subnormal size gives inf, not a ZeroDivisionError, and a
    # huge one 0, not an OverflowError
    return ELEMENTS_PER_VOLUME * (volume / size / size / size) + ELEMENTS_PER_AREA * (area / size / size)


def size_for_elements(volume: float, area: float, n_elements: float) -> float:
    """The element size whose :func:`estimate_elements` is ``n_elements``, m (bisection on
    log h: the estimate falls monotonically with h)."""
    lo, hi = 1e-9, 1e3
    for _ in range(100):
        mid = (lo * hi) ** 0.5
        if estimate_elements(volume, area, mid) > n_elements:
            lo = mid
        else:
            hi = mid
    return hi


class MeshSizeError(ParameterError, ResourceError):
    """A mesh ``size`` (:class:`MeshSettings`) that makes more tetrahedra than the limit.

    A :class:`~crankmodal.errors.ParameterError` naming ``size`` (and a
    :class:`~crankmodal.errors.ResourceError`, what :func:`check_size` raised before)::

        size: 0.0001 m makes about 8.8e+09 tetrahedra (V = 1037 cm3, A = 1035 cm2), over the
        limit of 5e+06 (crankmodal's limit on the mesh size); use size >= 0.0012 m

    :meth:`worded` says the same with the names a scene gives the size and the part's
    parameters (the ``[geometry]`` stage: ``geometry.mesh_size = 0.0001 m: about ...``).

    Attributes
    ----------
    size, smallest : float
        The size refused and the smallest the limit allows, m.
    count : float
        The estimate (``about``) or lower bound (``at least``) of the tetrahedra.
    """

    def __init__(self, size: float, bound: str, count: float, basis: str, limit: float,
                 reason: str, smallest: float, feature: str = "", dims: dict | None = None):
        self.size, self.bound, self.count, self.basis = size, bound, count, basis
        self.limit, self.reason, self.smallest = limit, reason, smallest
        self.feature, self.dims = feature, dict(dims or {})
        super().__init__("size", self._body(" makes", "", "size"))

    def __reduce__(self):  # picklable (a study's workers raise it in another process)
        return (MeshSizeError, (self.size, self.bound, self.count, self.basis, self.limit,
                                self.reason, self.smallest, self.feature, self.dims))

    def _body(self, verb: str, prefix: str, size_name: str) -> str:
        most = ""
        if self.feature:
            dims = ", ".join(f"{prefix}{k} = {x:g} m" for k, x in self.dims.items())
            most = f", most of it the {self.feature}: {dims}"
        # a subnormal size makes an infinite estimate
        count = f"{self.bound} {self.count:.2g}" if self.count < float("inf") else "more than 1e308"
        return (f"{self.size:g} m{verb} {count} tetrahedra ({self.basis}"
                f"{most}), over the limit of {self.limit:.2g} ({self.reason}); use "
                f"{size_name} >= {self.smallest:.2g} m")

    def worded(self, size_key: str, params_prefix: str = "") -> str:
        """The message with a scene's names: ``size_key`` (``geometry.mesh_size``) for the size,
        ``params_prefix`` (``geometry.params.``) before each part parameter named."""
        return f"{size_key} = " + self._body(":", params_prefix, size_key.rsplit(".", 1)[-1])


def check_size(volume: float, area: float, settings: MeshSettings) -> float:
    """Refuse a mesh size whose element count estimate exceeds ``settings.max_elements``.

    Called before gmsh meshes, so an absurd ``mesh_size`` (1e-4 m on a crank: 6e9 tetrahedra)
    is an error in a second instead of gmsh filling the memory.

    Returns
    -------
    float
        The estimate.

    Raises
    ------
    MeshSizeError
        Naming ``size``, the estimate, the limit and the smallest size it allows (a
        ParameterError and a ResourceError).
    """
    check_settings(settings)
    n = estimate_elements(volume, area, settings.size)
    if n > settings.max_elements:
        raise MeshSizeError(settings.size, "about", n,
                            f"V = {volume * 1e6:.4g} cm3, A = {area * 1e4:.4g} cm2",
                            settings.max_elements, settings.limit_reason,
                            size_for_elements(volume, area, settings.max_elements))
    return n


#: Tetrahedra per V/h^3 certainly made (a lower bound, for the check before any CAD exists): gmsh's
#: meshes of the parts above hold 18-67 per V/h^3 at their sizes, the bulk of a fine mesh ~8.5.
ELEMENTS_PER_VOLUME_FLOOR = 6.0


def volume_floor_terms(params) -> list[tuple[str, float, dict]]:
    """Lower bounds of the volumes of a built part's main features from its parameters alone,
    as ``(feature, m^3, {parameter: value})``; their sum is :func:`volume_floor`.

    Crankshaft: the journals (less their end chamfers) and crankpins as plain cylinders, less
    an oil drilling along each one's diagonal. Rod: the two eye rings (the small one without its
    bushing) less the bolt holes across the big end. Webs, shank, stubs and flywheel only add.
    """
    from math import hypot, pi

    from .params import PART_TYPES

    p = params
    if not isinstance(p, tuple(PART_TYPES.values())):
        raise ParameterError("params", f"must be a CrankshaftParams or ConrodParams, got "
                             f"{type(p).__name__}")
    if hasattr(p, "phases_deg"):  # CrankshaftParams
        n = len(p.phases_deg)
        lj = max(p.journal_length - 2.0 * p.journal_chamfer, 0.0)
        drill = pi / 4 * p.oil_hole_diameter**2
        journals = (n + 1) * (pi / 4 * p.journal_diameter**2 * lj
                              - drill * hypot(p.journal_diameter, p.journal_length))
        pins = n * (pi / 4 * p.pin_diameter**2 * p.pin_length
                    - drill * hypot(p.pin_diameter, p.pin_length))
        return [("journals", max(journals, 0.0),
                 {"journal_diameter": p.journal_diameter, "journal_length": p.journal_length}),
                ("crankpins", max(pins, 0.0),
                 {"pin_diameter": p.pin_diameter, "pin_length": p.pin_length})]
    big = pi / 4 * (p.big_end_outer_diameter**2 - p.big_end_bore**2) * p.big_end_width
    big -= 2 * pi / 4 * p.bolt_diameter**2 * p.big_end_outer_diameter
    bore = p.small_end_bore + 2.0 * p.bushing_thickness
    small = pi / 4 * (p.small_end_outer_diameter**2 - bore**2) * p.small_end_width
    return [("big end", max(big, 0.0), {"big_end_outer_diameter": p.big_end_outer_diameter,
                                        "big_end_width": p.big_end_width}),
            ("small end", max(small, 0.0), {"small_end_outer_diameter": p.small_end_outer_diameter,
                                            "small_end_width": p.small_end_width})]


def volume_floor(params) -> float:
    """A lower bound of a built part's volume from its parameters alone, m^3 (no CAD); see
    :func:`volume_floor_terms`."""
    return sum(v for _, v, _ in volume_floor_terms(params))


def check_size_floor(params, settings: MeshSettings) -> float:
    """:func:`check_size` before any CAD exists (``crankmodal check``): refuse a mesh size that
    makes more than ``settings.max_elements`` tetrahedra even on :func:`volume_floor` at
    :data:`ELEMENTS_PER_VOLUME_FLOOR` per V/h^3. Returns that lower bound.

    Raises
    ------
    MeshSizeError
        Naming ``size``, the bound, the feature that holds most of it with its parameters (a
        huge part is as likely the cause as a tiny size), the limit and the smallest size it
        allows.
    """
    check_settings(settings)
    terms = volume_floor_terms(params)
    v = sum(t[1] for t in terms)
    h = settings.size
    n = ELEMENTS_PER_VOLUME_FLOOR * (v / h / h / h)  # see estimate_elements: no pow overflow
    if n > settings.max_elements:
        feature, _, keys = max(terms, key=lambda t: t[1])
        h_min = (ELEMENTS_PER_VOLUME_FLOOR * v / settings.max_elements) ** (1.0 / 3.0)
        raise MeshSizeError(settings.size, "at least", n, f"6 V/h^3, V >= {v * 1e6:.4g} cm3",
                            settings.max_elements, settings.limit_reason, h_min, feature, keys)
    return n


def fe_mesh_settings(size: float, order: int = 2, refine: float = 0.4, optimize: bool = True,
                     fe_follows: bool = True) -> MeshSettings:
    """:class:`MeshSettings` whose element limit is :data:`MAX_ELEMENTS`, or fewer when an FE
    solve follows (``fe_follows``) and the memory available could not hold its factorisation.

    Parameters
    ----------
    size : float
        Target element size, m.
    order : int
        1 or 2.
    refine : float
        Size on detail faces as a fraction of ``size``.
    optimize : bool
        Optimise the tetrahedra after meshing.
    fe_follows : bool
        A stiffness matrix of this mesh will be factorised (modal, static, reduction).
    """
    limit, reason = MAX_ELEMENTS, "crankmodal's limit on the mesh size"
    if fe_follows:
        from ..fem.memory import available_bytes

        avail = available_bytes()
        fe = fe_element_limit(order, avail) if order in (1, 2) else None
        # 1.5x: the count estimate is within -35 % / +19 %, and the FE stage's own memory
        # check, on the real DOF count, decides the close cases
        if fe is not None and 1.5 * fe < limit:
            limit = 1.5 * fe
            reason = (f"1.5x the P{order} elements whose FE factorisation, "
                      f"0.42 GB x (DOF / 85k)^1.5, fits in the {avail / 1e9:.3g} GB available")
    return MeshSettings(size=size, order=order, refine=refine, optimize=optimize,
                        max_elements=limit, limit_reason=reason)


def fe_element_limit(order: int, available_bytes: float | None) -> float | None:
    """Largest element count whose FE factorisation fits in ``available_bytes``, or None.

    The factor's memory grows as DOF^1.5: 0.42 GB at 85k P2 DOF (2.78 GB measured at 303k, the
    formula gives 2.8; seed 004's 831k-DOF crank: 12.9 GB measured, 12.8 from the formula).
    """
    if not available_bytes:
        return None
    dof = 85e3 * (available_bytes / 0.42e9) ** (2.0 / 3.0)
    return dof / DOF_PER_ELEMENT[order]


def detail_faces(gmsh, detail_radius: float) -> list:
    """Curved faces whose largest principal curvature exceeds ``1/detail_radius``."""
    out = []
    for _, s in gmsh.model.getEntities(2):
        if gmsh.model.getType(2, s) == "Plane":
            continue
        lo, hi = gmsh.model.getParametrizationBounds(2, s)
        uv = np.array([[lo[0] + f * (hi[0] - lo[0]), lo[1] + g * (hi[1] - lo[1])]
                       for f in (0.25, 0.5, 0.75) for g in (0.25, 0.5, 0.75)]).ravel()
        k1, k2, *_ = gmsh.model.getPrincipalCurvatures(s, uv)
        kmax = np.max(np.abs(np.concatenate([np.asarray(k1), np.asarray(k2)])))
        if kmax * detail_radius > 1.0 + 1e-9:
            out.append(s)
    return out


def set_sizes(gmsh, settings: MeshSettings, detail: list) -> None:
    """Configure the size fields and meshing options on the current model."""
    opt = gmsh.option.setNumber
    h = settings.size
    opt("Mesh.MeshSizeMax", h)
    opt("Mesh.MeshSizeMin", settings.refine * h)
    opt("Mesh.MeshSizeFromCurvature", CURVATURE_ELEMENTS)
    opt("Mesh.MeshSizeExtendFromBoundary", 1)
    opt("Mesh.Algorithm", 6)
    opt("Mesh.Algorithm3D", 10)
    opt("Mesh.Optimize", 1 if settings.optimize else 0)
    opt("Mesh.OptimizeNetgen", 0)
    opt("Mesh.ElementOrder", 1)
    opt("Mesh.SecondOrderLinear", 0)
    # curved P2 elements can fold at small fillets: poor ones are repaired in generate()
    opt("Mesh.HighOrderOptimize", 0)
    opt("Mesh.HighOrderNumLayers", 1)  # small patches: seconds, not minutes, at 300k DOF
    opt("Mesh.HighOrderPassMax", 10)
    opt("Mesh.RandomSeed", 1)
    f = gmsh.model.mesh.field
    if detail:
        dist = f.add("Distance")
        f.setNumbers(dist, "SurfacesList", detail)
        f.setNumber(dist, "Sampling", 20)
        thr = f.add("Threshold")
        f.setNumber(thr, "InField", dist)
        f.setNumber(thr, "SizeMin", settings.refine * h)
        f.setNumber(thr, "SizeMax", h)
        f.setNumber(thr, "DistMin", 0.0)
        f.setNumber(thr, "DistMax", 2.0 * h)
        f.setAsBackgroundMesh(thr)


#: minSICN below which a linear mesh gets gmsh's Netgen optimisation pass.
SLIVER_SICN = 0.1

#: gmsh minSJ (scaled Jacobian: 1 for a straight-sided tetrahedron, <= 0 folded) below which
#: curved P2 tetrahedra are repaired: Netgen on the straight mesh, then gmsh's HighOrder optimiser
#: on the patches still below it. Curving the edges on a hole or fillet smaller than the local
#: size (the seed 000 crank's 5 mm oil holes and 2.5 mm fillets, the rod's 2 mm shank fillets)
#: folds some tetrahedra; the HighOrder optimiser alone, at 0.01, left them nearly flat
#: (minSICN 0.003-0.03). Measured after the repair: minSJ >= 0.2, minSICN >= 0.09.
CURVED_SJ = 0.2


def _min_quality(gmsh, element_type: int, measure: str) -> float:
    tags = gmsh.model.mesh.getElementsByType(element_type)[0]
    return float(min(gmsh.model.mesh.getElementQualities(tags, measure))) if len(tags) else 1.0


def _min_linear_quality(gmsh) -> float:
    return _min_quality(gmsh, 4, "minSICN")


def generate(gmsh, settings: MeshSettings) -> None:
    """Mesh the current model in 3D at the requested order (sizes already set).

    With ``settings.optimize`` the mesh is repaired only where it needs it, so meshes that are
    already good stay exactly as they were: Netgen's pass on a linear mesh with minSICN below
    :data:`SLIVER_SICN`, or (order 2) on one whose curved P2 elements have minSJ below
    :data:`CURVED_SJ`; then gmsh's HighOrder optimiser lifts the curved elements still below
    :data:`CURVED_SJ`. Without it, only folded P2 elements (minSJ <= 0.01) are untangled.
    """
    gmsh.model.mesh.generate(2)
    try:
        gmsh.model.mesh.generate(3)
    except Exception:  # noqa: BLE001 - gmsh raises plain Exception; HXT refuses some surface meshes Delaunay takes
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)
        gmsh.model.mesh.clear()
        gmsh.model.mesh.generate(3)
    # gmsh's default optimiser can leave a few slivers where faces nearly touch (a pin flush with
    # a journal, a counterweight sector at 180 deg); Netgen's pass removes them.
    netgen = settings.optimize and _min_linear_quality(gmsh) < SLIVER_SICN
    if netgen:
        gmsh.model.mesh.optimize("Netgen")
    if settings.order == 2:
        gmsh.model.mesh.setOrder(2)
        threshold = CURVED_SJ if settings.optimize else 0.01
        sj = _min_quality(gmsh, 11, "minSJ")
        if sj <= threshold and settings.optimize and not netgen:
            # better-shaped straight tetrahedra next to the curved faces fold far less
            gmsh.model.mesh.setOrder(1)
            gmsh.model.mesh.optimize("Netgen")
            gmsh.model.mesh.setOrder(2)
            sj = _min_quality(gmsh, 11, "minSJ")
        if sj <= threshold:
            gmsh.option.setNumber("Mesh.HighOrderThresholdMin", threshold)
            gmsh.model.mesh.optimize("HighOrder")
            sj = _min_quality(gmsh, 11, "minSJ")
        if sj <= 0:
            raise GeometryError("mesh: curved second-order elements fold over at a small feature; "
                                "use geometry.element_order = 1, a smaller mesh_size or refine")
    gmsh.model.mesh.renumberNodes()
    gmsh.model.mesh.renumberElements()


def to_meshio(gmsh):
    """The volume mesh of the current model as a meshio mesh, plus a gmsh-tag -> row mapper.

    Returns
    -------
    mesh : meshio.Mesh
        One ``tetra`` or ``tetra10`` block in meshio node order; ``cell_data["volume"]`` holds
        the gmsh volume tag of each cell.
    index : callable
        Maps gmsh node tags to rows of ``mesh.points``.
    """
    import meshio

    tags, coords, _ = gmsh.model.mesh.getNodes()
    tags = np.asarray(tags, dtype=np.int64)
    order = np.argsort(tags)
    tags = tags[order]
    points = np.asarray(coords).reshape(-1, 3)[order]

    def index(t):
        return np.searchsorted(tags, t)

    blocks, vols = [], []
    cell_type = None
    for _, v in gmsh.model.getEntities(3):
        types, _, ntags = gmsh.model.mesh.getElements(3, v)
        for et, nt in zip(types, ntags):
            if et == 4:
                kind, conn = "tetra", index(np.asarray(nt, np.int64)).reshape(-1, 4)
            elif et == 11:
                kind, conn = "tetra10", index(np.asarray(nt, np.int64)).reshape(-1, 10)[:, GMSH_TO_MESHIO_TET10]
            else:
                raise GeometryError(f"mesh: unexpected volume element type {et} (only tetrahedra are made)")
            cell_type = kind
            blocks.append(conn)
            vols.append(np.full(len(conn), v, dtype=np.int64))
    if not blocks:
        raise GeometryError("mesh: gmsh produced no volume elements; try a smaller geometry.mesh_size")
    used = np.unique(np.concatenate(blocks))
    if len(used) != len(points):  # drop nodes not on any tetrahedron (none expected)
        remap = -np.ones(len(points), dtype=np.int64)
        remap[used] = np.arange(len(used))
        points = points[used]
        blocks = [remap[b] for b in blocks]
        inner = index

        def index(t):
            return remap[inner(t)]

    mesh = meshio.Mesh(points, [(cell_type, np.concatenate(blocks))],
                       cell_data={"volume": [np.concatenate(vols)]})
    return mesh, index


def quality(gmsh, mesh) -> dict:
    """Element/node counts and min/mean of gmsh's minSICN over the tetrahedra."""
    q = []
    for _, v in gmsh.model.getEntities(3):
        _, etags, _ = gmsh.model.mesh.getElements(3, v)
        for et in etags:
            if len(et):
                q.append(np.asarray(gmsh.model.mesh.getElementQualities(et, QUALITY_MEASURE)))
    q = np.concatenate(q)
    return {
        "measure": QUALITY_MEASURE,
        "min": float(q.min()),
        "mean": float(q.mean()),
        "n_elements": len(mesh.cells[0].data),
        "n_nodes": len(mesh.points),
    }
