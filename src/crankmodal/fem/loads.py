"""Consistent nodal loads on boundary regions: pressure, total force, remote force (RBE3), and
a pin's force on a bore (bearing load).

:class:`Load` is the user-facing object: ``Load.bearing(part, "small_end_bore", force=[F, 0, 0])``,
``Load.pressure``, ``Load.traction``, ``Load.remote`` on a region (by name, or the boundary
facets inside a box), holding the nodal force vector and a label; loads add. The functions below
it work on bare arrays (points, cells, facets) and return the nodal vector.

Region facets are corner triangles; on a ``tetra10`` mesh their mid-edge nodes are looked up in
the volume connectivity and the 6-node facets are integrated isoparametrically (a pressure on a
curved bore pushes along the true normal). Facets are oriented outward from the owning element.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import GeometryError, ParameterError
from ..topology import facet_midnodes

_TET_FACES = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
_TET_OPPOSITE = np.array([3, 2, 1, 0])
# degree-4 rule on the reference triangle (Strang-Fix / Dunavant, 6 points), weights sum to 1/2
_A, _B = 0.445948490915965, 0.091576213509771
_QX = np.array([[_A, _A], [1 - 2 * _A, _A], [_A, 1 - 2 * _A],
                [_B, _B], [1 - 2 * _B, _B], [_B, 1 - 2 * _B]])
_QW = 0.5 * np.array([0.223381589678011] * 3 + [0.109951743655322] * 3)


def _keys(a, n):
    a = np.sort(a, axis=-1).astype(np.int64)
    return (a[..., 0] * n + a[..., 1]) * n + a[..., 2]


def oriented_facets(cells: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """Find the element owning each facet.

    Returns
    -------
    f : ndarray (n_facets, 6)
        Corner columns filled, the three mid-node columns -1 (filled by the caller).
    opposite : ndarray (n_facets,)
        The owning element's vertex not on the facet (gives the outward side).
    element : ndarray (n_facets,)
    """
    n = int(max(cells.max(), facets.max())) + 1
    fk = _keys(cells[:, :4][:, _TET_FACES], n).ravel()
    order = np.argsort(fk)
    fk_sorted = fk[order]
    q = _keys(facets, n)
    pos = np.searchsorted(fk_sorted, q)
    pos = np.minimum(pos, len(fk_sorted) - 1)
    if np.any(fk_sorted[pos] != q):
        raise GeometryError("region: a facet is not a face of any element")
    idx = order[pos]
    tet, face = idx // 4, idx % 4
    opp = cells[tet, _TET_OPPOSITE[face]]
    out = np.full((len(facets), 6), -1, np.int64)
    out[:, :3] = facets
    return out, opp, tet


def facet_quadrature(points: np.ndarray, cells: np.ndarray, facets: np.ndarray):
    """Nodes, shape-function values and area-vector weights on region facets.

    Returns
    -------
    nodes : ndarray (n_facets, k)
        k = 6 on tetra10 meshes, 3 on tetra meshes.
    N : ndarray (n_q, k)
        Shape functions at the quadrature points.
    nda : ndarray (n_facets, n_q, 3)
        Outward normal times area element times quadrature weight, m².
    """
    f, opp, _ = oriented_facets(cells, facets)
    p = points
    nrm = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    inward = np.einsum("ij,ij->i", nrm, p[opp] - p[f[:, 0]]) > 0
    f[inward, 1], f[inward, 2] = f[inward, 2].copy(), f[inward, 1].copy()
    xi, eta = _QX[:, 0], _QX[:, 1]
    L = np.stack([1 - xi - eta, xi, eta])  # (3, q)
    dL = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])  # dL_i/d(xi, eta)
    if cells.shape[1] == 10:
        f[:, 3:] = facet_midnodes(f[:, :3], cells)
        pairs = ((0, 1), (1, 2), (2, 0))
        N = np.vstack([L * (2 * L - 1)] + [4 * L[a] * L[b] for a, b in pairs]).T  # (q, 6)
        dN = np.zeros((len(xi), 6, 2))
        for i in range(3):
            dN[:, i, :] = (4 * L[i] - 1)[:, None] * dL[i]
        for k, (a, b) in enumerate(pairs):
            dN[:, 3 + k, :] = 4 * (L[b][:, None] * dL[a] + L[a][:, None] * dL[b])
        nodes = f
    else:
        N = L.T
        dN = np.broadcast_to(dL, (len(xi), 3, 2))
        nodes = f[:, :3]
    X = points[nodes]  # (nf, k, 3)
    dxdxi = np.einsum("qk,fkc->fqc", dN[:, :, 0], X)
    dxdeta = np.einsum("qk,fkc->fqc", dN[:, :, 1], X)
    nda = np.cross(dxdxi, dxdeta) * _QW[None, :, None]
    return nodes, N, nda


def _scatter(n_points, nodes, vals):
    """Sum (n_facets, k, 3) nodal contributions into a (3 n_points,) vector."""
    f = np.zeros((n_points, 3))
    for c in range(3):
        f[:, c] = np.bincount(nodes.ravel(), weights=vals[..., c].ravel(), minlength=n_points)
    return f.ravel()


def pressure_load(points, cells, facets, pressure: float) -> np.ndarray:
    """Nodal forces (N) of a uniform pressure (Pa, positive pushing into the surface).

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Node coordinates, m.
    cells : ndarray
        The volume cells (tetra or tetra10 node order).
    facets : ndarray
        The loaded boundary facets (a region's ``facets``).
    pressure : float
        Pa.

    Returns
    -------
    ndarray, shape (3 n,)
        Consistent nodal forces, N, interleaved x, y, z.

    Examples
    --------
    1 MPa on the 30 x 20 mm end of a bar pushes it with 600 N along the inward normal (-x):

    >>> import crankmodal as cm
    >>> from crankmodal.fem import testparts
    >>> bar = testparts.bar(0.3, 0.03, 0.02, divisions=(6, 2, 2), order=2)
    >>> model = cm.assemble(bar, cm.material("steel"))
    >>> f = cm.pressure_load(model.points, model.cells, bar.regions["end_x1"].facets, 1e6)
    >>> print(f"{f.reshape(-1, 3).sum(axis=0)[0]:.1f} N")
    -600.0 N
    """
    nodes, N, nda = facet_quadrature(points, cells, facets)
    vals = -pressure * np.einsum("qk,fqc->fkc", N, nda)
    return _scatter(len(points), nodes, vals)


def nodal_areas(points, cells, facets):
    """∫ N_a dA over the region, m², per facet node: the distribution weights."""
    nodes, N, nda = facet_quadrature(points, cells, facets)
    da = np.linalg.norm(nda, axis=2)  # (f, q)
    return nodes, np.einsum("qk,fq->fk", N, da)


def traction_force(points, cells, facets, force) -> np.ndarray:
    """Nodal forces of a total force (N, 3-vector) spread as a uniform traction.

    Parameters
    ----------
    points, cells, facets
        As :func:`pressure_load`.
    force : array_like, shape (3,)
        The total force, N.

    Returns
    -------
    ndarray, shape (3 n,)
        Consistent nodal forces, N, summing to ``force``.
    """
    nodes, w = nodal_areas(points, cells, facets)
    t = np.asarray(force, float) / w.sum()
    return _scatter(len(points), nodes, w[..., None] * t)


def remote_force(points, cells, facets, force, point=None, moment=None) -> np.ndarray:
    """A force (N) and moment (N m) at ``point`` carried to a region by a distributing coupling.

    The RBE3-type coupling spreads them with area weights w_a: f_a = w_a (F/W + (J⁻¹ M_c) × r_a),
    r_a from the weighted centroid c, J = Σ w_a (``|r_a|²`` I − r_a r_aᵀ), M_c the moment about c.
    The nodal forces sum to F and their moment about c is M_c, and the region is not stiffened.

    Parameters
    ----------
    points, cells, facets
        As :func:`pressure_load`.
    force : array_like, shape (3,)
        The force, N.
    point : array_like, shape (3,), optional
        Where it acts, m (default: the region's weighted centroid).
    moment : array_like, shape (3,), optional
        A moment about ``point``, N m.

    Returns
    -------
    ndarray, shape (3 n,)
        Nodal forces, N, interleaved x, y, z.
    """
    nodes, w = nodal_areas(points, cells, facets)
    u, inv = np.unique(nodes.ravel(), return_inverse=True)
    wn = np.bincount(inv, weights=w.ravel())
    x = points[u]
    W = wn.sum()
    c = (wn[:, None] * x).sum(0) / W
    F = np.asarray(force, float)
    Mc = np.zeros(3) if moment is None else np.asarray(moment, float).copy()
    if point is not None:
        Mc += np.cross(np.asarray(point, float) - c, F)
    r = x - c
    J = (wn * (r * r).sum(1)).sum() * np.eye(3) - np.einsum("a,ai,aj->ij", wn, r, r)
    theta = np.linalg.lstsq(J, Mc, rcond=None)[0]
    fa = wn[:, None] * (F / W + np.cross(theta, r))
    out = np.zeros((len(points), 3))
    out[u] = fa
    return out.ravel()


def bearing_load(points, cells, facets, force, axis) -> np.ndarray:
    """A radial force (N) through a cylindrical bearing surface, as a pressure ``p0 cos θ``.

    θ is the angle between the force and the direction the surface is pressed in (minus its
    outward normal): a pin pressing a bore (a rod's eye) loads the wall on the force's side, a
    shell pressing a journal (a crankpin) loads the journal on the side facing away from it.
    Where cos θ ≤ 0 there is no pressure — the usual "bearing load" of a strength check
    (no clearance, no friction). ``p0`` is set so that the nodal forces add up to the force
    along it (analytically ``p0 = 2 |F| / (π R L)``); what a mesh that is not symmetric about the
    force leaves across it or along the axis is spread over the loaded facets as a uniform
    traction, so the nodal forces add up to the force to round-off.

    Parameters
    ----------
    force : (3,) array
        N, perpendicular to the axis (a pressure on a cylinder carries no axial force).
    axis : (3,) array
        The cylinder's axis direction (the force must be perpendicular to it).

    Raises
    ------
    ParameterError
        Naming ``force`` when it has a component along the axis.
    """
    F = np.asarray(force, float)
    d = np.asarray(axis, float) / np.linalg.norm(axis)
    fn = np.linalg.norm(F)
    if fn == 0.0:
        return np.zeros(3 * len(points))
    if abs(F @ d) > 1e-6 * fn:
        raise ParameterError("force", f"{F.tolist()} N has {F @ d:.4g} N along the bore axis; "
                                      f"a bearing load is radial (give the axial part as a force)")
    fhat = F / fn
    nodes, N, nda = facet_quadrature(points, cells, facets)  # outward normal x area weight
    da = np.linalg.norm(nda, axis=2)
    c = np.maximum(-np.einsum("fqc,c->fq", nda, fhat) / da, 0.0)  # cos θ on the loaded half
    t = -c[..., None] * nda  # traction per unit p0 (pushing into the surface), times the weight
    p0 = fn / float(np.einsum("fqc,c->", t, fhat))
    vals = p0 * np.einsum("qk,fqc->fkc", N, t)
    f = _scatter(len(points), nodes, vals)
    # a mesh not symmetric about F leaves the pressure's resultant off F across F and along the
    # axis (5e-5 |F| on the rod's small eye at 8 mm); that remainder goes to the loaded facets as
    # a uniform traction, so the nodal forces add up to F to round-off
    rest = F - f.reshape(-1, 3).sum(axis=0)
    loaded = np.asarray(facets)[(c > 0).any(axis=1)]
    return f + traction_force(points, cells, loaded, rest)


# --- the user-facing object ---------------------------------------------------------------------

def _vector3(value, argument: str) -> np.ndarray:
    """Three finite numbers as a float array; :class:`ParameterError` naming ``argument``."""
    try:
        v = np.asarray(value, float)
    except (TypeError, ValueError):
        v = None
    if v is None or v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ParameterError(argument, f"must be 3 finite numbers, got {value!r}")
    return v


def _mesh_arrays(part) -> tuple[np.ndarray, np.ndarray]:
    """The part's points (n, 3), m, and its volume cells (tetra or tetra10)."""
    from .assembly import _volume_block

    return (np.asarray(part.mesh.points, float)[:, :3],
            np.asarray(_volume_block(part.mesh).data, np.int64))


def region_facets(part, region, cells: np.ndarray | None = None):
    """Boundary facets of ``region``: a region name, or a box ``[xmin, xmax, ..., zmax]`` (m).

    A box takes the boundary facets whose three corners lie inside it (bounds included).

    Returns
    -------
    facets : ndarray (n, 3)
        Corner triangles.
    where : Region or None
        The named region (None for a box).
    name : str
        For labels: the region's name or ``box``.

    Raises
    ------
    ParameterError
        Naming ``region``: no such region, a malformed box, or a box holding no boundary facet.
    """
    from .supports import _checked_box, part_region

    if isinstance(region, str):
        reg = part_region(part, region, "region")
        return np.asarray(reg.facets), reg, region
    if not isinstance(region, (list, tuple, np.ndarray)):
        raise ParameterError("region", f"must be a region name or a box [xmin, xmax, ymin, ymax, "
                                       f"zmin, zmax] (m), got {region!r}")
    try:
        box = _checked_box(region, "")
    except ParameterError as exc:
        raise ParameterError("region", exc.text) from None
    from ..topology import boundary_facets

    points = np.asarray(part.mesh.points, float)[:, :3]
    facets = boundary_facets(_mesh_arrays(part)[1] if cells is None else cells)
    lo, hi = np.array(box[0::2]), np.array(box[1::2])
    inside = np.all((points[facets] >= lo) & (points[facets] <= hi), axis=(1, 2))
    if not inside.any():
        raise ParameterError("region", f"the box {box} holds no boundary facet of part "
                                       f"{part.name!r}")
    return facets[inside], None, "box"


@dataclass
class Load:
    """Nodal forces on a part's mesh points: plain data that adds (``load1 + load2``).

    Make one with :meth:`pressure`, :meth:`traction`, :meth:`remote` or :meth:`bearing` on a
    region (its name, or a box ``[xmin, xmax, ymin, ymax, zmin, zmax]`` taking the boundary
    facets inside), or from a vector of your own.

    Attributes
    ----------
    vector : ndarray, shape (3 n_points,)
        Nodal forces, N, node-interleaved (``3 * point + component``), as :func:`solve_static`
        and ``FEModel.K`` take them.
    label : str
        What it is, e.g. ``bearing on small_end_bore``.
    points : ndarray (n_points, 3) or None
        The mesh points, m (for :meth:`moment`); not copied.
    """

    vector: np.ndarray
    label: str = "load"
    points: np.ndarray | None = field(default=None, repr=False)

    @property
    def forces(self) -> np.ndarray:
        """Nodal forces, N, shape (n_points, 3)."""
        return np.asarray(self.vector).reshape(-1, 3)

    @property
    def resultant(self) -> np.ndarray:
        """Total force, N, shape (3,)."""
        return self.forces.sum(axis=0)

    def moment(self, about=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Total moment of the nodal forces about a point (m), N m, shape (3,)."""
        if self.points is None:
            raise ParameterError("points", f"{self.label} has no mesh points to take moments with")
        return np.cross(self.points - _vector3(about, "about"), self.forces).sum(axis=0)

    def __add__(self, other) -> Load:
        if isinstance(other, (int, float)) and other == 0:
            return self  # sum([...]) starts from 0
        if not isinstance(other, Load):
            return NotImplemented
        if np.shape(other.vector) != np.shape(self.vector):
            raise ParameterError("load", f"{other.label!r} has {np.size(other.vector)} entries, "
                                         f"{self.label!r} {np.size(self.vector)}: loads on "
                                         f"different meshes do not add")
        points = self.points if self.points is not None else other.points
        return Load(np.asarray(self.vector) + np.asarray(other.vector),
                    f"{self.label} + {other.label}", points)

    __radd__ = __add__

    def __mul__(self, factor: float) -> Load:
        if isinstance(factor, bool) or not isinstance(factor, (int, float, np.number)):
            return NotImplemented
        return Load(factor * np.asarray(self.vector), f"{factor:.4g} × {self.label}", self.points)

    __rmul__ = __mul__

    @classmethod
    def pressure(cls, part, region, pressure: float) -> Load:
        """A uniform pressure, Pa, positive pushing into the surface.

        Raises
        ------
        ParameterError
            Naming ``region`` or ``pressure`` (not a finite number).
        """
        if (isinstance(pressure, bool) or not isinstance(pressure, (int, float, np.floating))
                or not np.isfinite(pressure)):
            raise ParameterError("pressure", f"must be a number (Pa), got {pressure!r}")
        points, cells = _mesh_arrays(part)
        facets, _, name = region_facets(part, region, cells)
        return cls(pressure_load(points, cells, facets, float(pressure)),
                   f"pressure {pressure:.4g} Pa on {name}", points)

    @classmethod
    def traction(cls, part, region, force) -> Load:
        """A total force, N (3-vector), spread over the region as a uniform traction.

        Raises
        ------
        ParameterError
            Naming ``region`` or ``force``.
        """
        F = _vector3(force, "force")
        points, cells = _mesh_arrays(part)
        facets, _, name = region_facets(part, region, cells)
        return cls(traction_force(points, cells, facets, F), f"traction on {name}", points)

    @classmethod
    def remote(cls, part, region, force, point=None, moment=None) -> Load:
        """A force (N) at ``point`` (m; default the region's area centroid) plus a moment (N m),
        carried to the region by a distributing (RBE3-type) coupling: the nodal forces add up
        to ``force`` and their moment about ``point`` is ``moment``.

        Raises
        ------
        ParameterError
            Naming ``region``, ``force``, ``point`` or ``moment``.
        """
        F = _vector3(force, "force")
        P = None if point is None else _vector3(point, "point")
        M = None if moment is None else _vector3(moment, "moment")
        points, cells = _mesh_arrays(part)
        facets, _, name = region_facets(part, region, cells)
        return cls(remote_force(points, cells, facets, F, P, M), f"remote force on {name}",
                   points)

    @classmethod
    def bearing(cls, part, region, force) -> Load:
        """A pin's radial force (N) on a cylindrical bore or journal, as a pressure ``p0 cos θ``
        on the half it presses (see :func:`bearing_load`); the nodal forces add up to ``force``.

        Raises
        ------
        ParameterError
            Naming ``region`` (absent, or not cylindrical) or ``force`` (along the axis).
        """
        from .supports import fit_cylinder, region_cylinder

        F = _vector3(force, "force")
        points, cells = _mesh_arrays(part)
        facets, reg, name = region_facets(part, region, cells)
        if reg is not None:
            axis = region_cylinder(reg, name, points, "region").axis
        else:
            try:
                axis = fit_cylinder(points, facets).axis
            except ValueError as exc:
                raise ParameterError("region", f"needs a cylindrical region; the box's facets "
                                               f"are {exc}") from None
        return cls(bearing_load(points, cells, facets, F, axis), f"bearing on {name}", points)


def as_vector(load, n_points: int) -> np.ndarray:
    """The nodal force vector (3 n_points,), N, of a :class:`Load`, a list of loads or vectors
    (summed), or a vector.

    Raises
    ------
    ParameterError
        Naming ``load`` when it is none of these or not of length 3 n_points.
    """
    if isinstance(load, (list, tuple)) and load and all(
            isinstance(x, (Load, np.ndarray)) for x in load):
        parts = [as_vector(x, n_points) for x in load]
        return np.sum(parts, axis=0)
    v = load.vector if isinstance(load, Load) else load
    try:
        v = np.asarray(v, float)
    except (TypeError, ValueError):
        raise ParameterError("load", f"must be a Load, a list of them, or a vector of "
                                     f"3 n_points = {3 * n_points} nodal forces (N); got "
                                     f"{type(load).__name__}") from None
    if v.shape != (3 * n_points,):
        raise ParameterError("load", f"must have 3 n_points = {3 * n_points} entries (nodal "
                                     f"forces, N), got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ParameterError("load", "holds non-finite values")
    return v
