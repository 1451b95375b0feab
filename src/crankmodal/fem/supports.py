"""Supports: node selections with fixed components, eliminated by a sparse transformation.

A support fixes displacement components of a set of nodes: any of ``x``, ``y``, ``z`` (global),
or ``radial`` for a cylindrical region (a bearing: the node may slide along the axis and turn
about it, but not move towards or away from it). Every constraint is a direction ``c`` with
``c·u = 0`` at a node; the free displacements of each node span the orthogonal complement, so
``u = T q`` with ``T`` sparse and orthonormal column by column. ``Tᵀ K T``, ``Tᵀ M T`` are the
supported matrices: exact elimination, no penalty to tune, positive definite when the supports
remove every rigid-body mode.

From Python a support is made directly, ``Support.region(part, "big_end_bore", fix="xyz")`` or
``Support.box(part, [xmin, xmax, ymin, ymax, zmin, zmax], fix="x")``; :func:`select_supports`
also takes the scene's tables (``{region = ..., fix = ...}``). These raise
:class:`~crankmodal.errors.ParameterError` naming the argument (``fix``, ``supports[1].region``);
:func:`select` is the stages' form, naming the scene key (``modal.supports[1].region``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import ParameterError, scene_keys

AXES = "xyz"


def _arg(key: str, name: str) -> str:
    """``key.name``, or ``name`` alone at the top level (``key`` empty)."""
    return f"{key}.{name}" if key else name


@dataclass
class Support:
    """Nodes and the components fixed on them.

    Make one with :meth:`Support.region` or :meth:`Support.box` (or :func:`select_supports`).

    Attributes
    ----------
    label : str
        For messages, e.g. ``supports[1] (region main_journal_1)``.
    nodes : ndarray of int
        Point indices.
    fix : str
        ``"x"``, ``"yz"``, ``"xyz"``, ... or ``"radial"``.
    cylinder : CylindricalSurface or None
        Axis of a radial support.
    """

    label: str
    nodes: np.ndarray
    fix: str
    cylinder: object = None

    @classmethod
    def region(cls, part, name: str, fix: str = "xyz", label: str | None = None) -> Support:
        """The nodes of the part's region ``name``, with ``fix`` held.

        Parameters
        ----------
        part : Part
        name : str
            A key of ``part.regions``.
        fix : str
            Distinct letters of ``x``, ``y``, ``z`` (global components held), or ``"radial"``
            (a cylindrical region: no motion towards or away from its axis).
        label : str, optional
            For messages; default ``region <name>``.

        Raises
        ------
        ParameterError
            Naming ``region`` (no such region) or ``fix`` (inadmissible, or ``radial`` on a
            region that is not cylindrical).
        """
        return _region_support(part, name, _checked_fix(fix, ""), "", label)

    @classmethod
    def box(cls, part, box, fix: str = "xyz", label: str | None = None) -> Support:
        """The part's mesh points inside ``box`` (bounds included), with ``fix`` held.

        Parameters
        ----------
        part : Part
        box : sequence of 6 float
            ``[xmin, xmax, ymin, ymax, zmin, zmax]``, m.
        fix : str
            Distinct letters of ``x``, ``y``, ``z`` (``radial`` needs a region).
        label : str, optional
            For messages; default ``box``.

        Raises
        ------
        ParameterError
            Naming ``box`` (malformed, or holding no node) or ``fix``.
        """
        fix = _checked_fix(fix, "")
        box = _checked_box(box, "")
        if fix == "radial":
            raise ParameterError("fix", "'radial' needs a cylindrical region, not a box")
        return _box_support(part, box, fix, "", label)


def check_fix(fix: str) -> str | None:
    """Error text for an inadmissible ``fix`` value, or None."""
    if fix == "radial":
        return None
    if not isinstance(fix, str) or not fix or set(fix) - set(AXES) or len(set(fix)) != len(fix):
        return f"fix must be 'radial' or distinct letters of x, y, z (e.g. 'xz'); got {fix!r}"
    return None


def _checked_fix(fix, key: str) -> str:
    msg = check_fix(fix)
    if msg:
        raise ParameterError(_arg(key, "fix"), msg)
    return fix


def _checked_box(box, key: str) -> list:
    if (not isinstance(box, (list, tuple, np.ndarray)) or len(box) != 6
            or not all(isinstance(b, (int, float, np.integer, np.floating))
                       and not isinstance(b, bool) for b in box)):
        raise ParameterError(_arg(key, "box"),
                             f"must be [xmin, xmax, ymin, ymax, zmin, zmax] in m, got {box!r}")
    if any(a > b for a, b in zip(box[0::2], box[1::2])):
        raise ParameterError(_arg(key, "box"), f"each min must be <= its max, got {box!r}")
    return [float(b) for b in box]


def _points(part) -> np.ndarray:
    return np.asarray(part.mesh.points, float)[:, :3]


def part_region(part, name, argument: str = "region"):
    """``part.regions[name]``; raises :class:`ParameterError` naming ``argument`` if absent."""
    if not isinstance(name, str):
        raise ParameterError(argument, f"must be a region name, got {name!r}")
    if name not in part.regions:
        known = ", ".join(sorted(part.regions)) or "none"
        raise ParameterError(argument, f"no region {name!r} in part {part.name!r}; "
                                       f"regions: {known}")
    return part.regions[name]


def _region_support(part, name, fix, key, label):
    reg = part_region(part, name, _arg(key, "region"))
    nodes = np.asarray(reg.nodes, np.int64)
    cyl = None
    if fix == "radial":
        cyl = region_cylinder(reg, name, _points(part), _arg(key, "fix"), "'radial' ")
    _require_nodes(part, nodes, key or "region")
    return Support(label=label or f"region {name}", nodes=nodes, fix=fix, cylinder=cyl)


def _box_support(part, box, fix, key, label):
    points = _points(part)
    lo, hi = np.array(box[0::2], float), np.array(box[1::2], float)
    nodes = np.flatnonzero(np.all((points >= lo) & (points <= hi), axis=1))
    _require_nodes(part, nodes, key or "box")
    return Support(label=label or "box", nodes=nodes, fix=fix)


def _require_nodes(part, nodes, argument):
    if len(nodes) == 0:
        points = _points(part)
        ext = np.column_stack([points.min(0), points.max(0)]).ravel()
        raise ParameterError(argument, f"selects no node (part bounding box "
                                       f"[{', '.join(f'{v:.4g}' for v in ext)}] m)")


def fit_cylinder(points: np.ndarray, facets: np.ndarray):
    """Least-squares cylinder through a region's nodes (axis from the facet normals).

    Returns a :class:`~crankmodal.part.CylindricalSurface`; raises ``ValueError`` if the region
    is flat or not cylindrical to 1 % of its radius.
    """
    from ..part import CylindricalSurface

    p = points[facets]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    _, sv, vt = np.linalg.svd(n, full_matrices=False)
    if sv[1] < 1e-3 * sv[0]:  # the normals of a cylinder turn about its axis; a plane's do not
        raise ValueError("flat (its facet normals do not turn)")
    axis = vt[-1]
    x = points[np.unique(facets)]
    s = x @ axis
    e1 = np.linalg.svd(n - np.outer(n @ axis, axis), full_matrices=False)[2][0]
    e2 = np.cross(axis, e1)
    u, v = x @ e1, x @ e2
    A = np.column_stack([2 * u, 2 * v, np.ones_like(u)])
    (cu, cv, c0), *_ = np.linalg.lstsq(A, u * u + v * v, rcond=None)
    radius = np.sqrt(c0 + cu * cu + cv * cv)
    err = np.abs(np.hypot(u - cu, v - cv) - radius).max()
    if not np.isfinite(radius) or err > 0.01 * radius:
        raise ValueError(f"not cylindrical (deviation {err:.3g} m from radius {radius:.3g} m)")
    centre = cu * e1 + cv * e2 + axis * 0.5 * (s.min() + s.max())
    return CylindricalSurface(centre=centre, axis=axis, radius=float(radius),
                              length=float(np.ptp(s)))


def region_cylinder(region, name: str, points: np.ndarray, argument: str, what: str = ""):
    """The region's exact cylinder from the geometry, else one fitted to its nodes.

    Raises :class:`ParameterError` naming ``argument`` (its text starting with ``what``) when the
    region is not cylindrical.
    """
    if region.cylinder is not None:
        return region.cylinder
    try:
        return fit_cylinder(points, np.asarray(region.facets))
    except ValueError as exc:
        raise ParameterError(argument, f"{what}needs a cylindrical region; region {name!r} is "
                                       f"{exc}") from None


def check_specs(specs) -> list:
    """Check support tables (and pass :class:`Support` objects) without a part.

    Returns the list with each table's ``fix`` defaulted to ``xyz``.

    Raises
    ------
    ParameterError
        Naming ``supports[i].<key>`` and what is allowed.
    """
    if specs is None:
        return []
    if not isinstance(specs, (list, tuple)):
        raise ParameterError("supports", f"must be a list of tables, got {specs!r}")
    out = []
    for i, spec in enumerate(specs):
        key = f"supports[{i}]"
        if isinstance(spec, Support):
            out.append(spec)
            continue
        if not isinstance(spec, dict):
            raise ParameterError(key, f"must be a table {{box = [...], fix = ...}} or "
                                      f"{{region = ..., fix = ...}}, got {spec!r}")
        unknown = set(spec) - {"box", "region", "fix"}
        if unknown:
            raise ParameterError(f"{key}.{min(unknown)}", "unknown key; allowed: box, region, fix")
        if ("box" in spec) == ("region" in spec):
            raise ParameterError(key, "give exactly one of 'box' or 'region'")
        fix = _checked_fix(spec.get("fix", "xyz"), key)
        if "box" in spec:
            _checked_box(spec["box"], key)
            if fix == "radial":
                raise ParameterError(f"{key}.fix", "'radial' needs a cylindrical region, not a box")
        elif not isinstance(spec["region"], str):
            raise ParameterError(f"{key}.region", f"must be a region name, got {spec['region']!r}")
        out.append({**spec, "fix": fix})
    return out


def validate_specs(specs, section: str = "modal") -> list[dict]:
    """:func:`check_specs` for a scene section: the error names ``<section>.supports[i].<key>``.

    Raises
    ------
    SceneError
    """
    with scene_keys(section):
        return check_specs(specs)


def select_supports(part, specs, label: str = "supports") -> list[Support]:
    """Supports on ``part`` from :class:`Support` objects and/or tables.

    Parameters
    ----------
    part : Part
    specs : list
        Each a :class:`Support` (kept as it is) or a table ``{"region": name, "fix": "xyz"}`` /
        ``{"box": [xmin, xmax, ymin, ymax, zmin, zmax], "fix": "x"}`` (m; ``fix`` defaults to
        ``"xyz"``; ``"radial"`` needs a cylindrical region).
    label : str
        Prefix of the tables' support labels: ``<label>[i] (region name)``.

    Raises
    ------
    ParameterError
        Unknown region, a box holding no node, a radial support on a non-cylindrical region, a
        malformed table, or a Support whose nodes are not points of the part; the argument is
        ``supports[i]...``.
    """
    from ..arguments import instance
    from ..part import Part

    instance("part", part, Part, "a Part (build_part, import_mesh)")
    specs = check_specs(specs)
    n_points = len(part.mesh.points)
    out = []
    for i, spec in enumerate(specs):
        key = f"supports[{i}]"
        if isinstance(spec, Support):
            nodes = np.asarray(spec.nodes)
            if nodes.size and (nodes.min() < 0 or nodes.max() >= n_points):
                raise ParameterError(f"{key}.nodes", f"point indices must lie in [0, {n_points}) "
                                                     f"(a Support made for another part?)")
            out.append(spec)
        elif "region" in spec:
            out.append(_region_support(part, spec["region"], spec["fix"], key,
                                       f"{label}[{i}] (region {spec['region']})"))
        else:
            out.append(_box_support(part, spec["box"], spec["fix"], key, f"{label}[{i}] (box)"))
    return out


def select(part, specs, section: str = "modal") -> list[Support]:
    """:func:`select_supports` for the tables of a scene section (the stages' form).

    Labels read ``<section>.supports[i] (region name)``.

    Raises
    ------
    SceneError
        Naming ``<section>.supports[i]...``.
    """
    with scene_keys(section):
        return select_supports(part, specs, f"{section}.supports")


def reduction(points: np.ndarray, used: np.ndarray, supports: list[Support]) -> sp.csr_matrix:
    """Sparse ``T`` (3 n_points × n_free) with ``u = T q`` satisfying every support.

    Points no element uses are left out as well (they have no stiffness or mass).

    Raises
    ------
    ParameterError
        Naming ``supports``: they leave no degree of freedom free (the text names them by
        label); a stage re-raises it under its scene key (``modal.supports: ...``).
    """
    n = len(points)
    fixed = np.zeros((n, 3), bool)
    fixed[~used] = True
    special: dict[int, list[np.ndarray]] = {}
    for s in supports:
        if s.fix == "radial":
            c = s.cylinder
            a = np.asarray(c.axis, float) / np.linalg.norm(c.axis)
            d = points[s.nodes] - np.asarray(c.centre, float)
            er = d - np.outer(d @ a, a)
            norm = np.linalg.norm(er, axis=1)
            ok = norm > 1e-9 * max(c.radius, 1e-12)
            er = er[ok] / norm[ok, None]
            for node, e in zip(s.nodes[ok], er):
                special.setdefault(int(node), []).append(e)
        else:
            for ch in s.fix:
                fixed[s.nodes, AXES.index(ch)] = True
    rows, cols, vals = [], [], []
    # plain components: identity columns
    simple = np.ones(n, bool)
    simple[list(special)] = False
    free = (~fixed) & simple[:, None]
    dofs = np.flatnonzero(free.ravel())
    rows.append(dofs)
    cols.append(np.arange(len(dofs)))
    vals.append(np.ones(len(dofs)))
    ncol = len(dofs)
    for node, dirs in sorted(special.items()):
        C = np.array(dirs + [np.eye(3)[k] for k in range(3) if fixed[node, k]])
        _, sv, Vt = np.linalg.svd(C)
        rank = int((sv > 1e-10).sum())
        basis = Vt[rank:]  # orthonormal free directions, (3 - rank, 3)
        for b in basis:
            rows.append(3 * node + np.arange(3))
            cols.append(np.full(3, ncol))
            vals.append(b)
            ncol += 1
    if ncol == 0 and supports:  # else the caller would ask for a finer mesh, which fixes nothing
        who = " and ".join(s.label for s in supports)
        held = "hold" if len(supports) > 1 else "holds"
        raise ParameterError("supports", f"{who} {held} every node the elements use in every "
                                         f"direction, so nothing is left free; support a part of "
                                         f"the mesh only (a smaller box or a region) or fix "
                                         f"fewer components")
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(3 * n, ncol))


def reduce_matrix(A: sp.spmatrix, T: sp.csr_matrix) -> sp.csr_matrix:
    """``Tᵀ A T``, by row/column selection when ``T`` only selects DOFs."""
    T = sp.csr_matrix(T)
    if T.shape[0] == T.shape[1] and T.nnz == T.shape[0] and np.all(T.data == 1.0) and np.array_equal(
            T.indices, np.arange(T.shape[0])):
        return sp.csr_matrix(A)  # nothing held: no copy
    if T.nnz == T.shape[1] and np.all(T.data == 1.0) and np.all(np.diff(T.indptr) <= 1):
        sel = np.empty(T.shape[1], np.int64)
        coo = T.tocoo()
        sel[coo.col] = coo.row
        if np.all(np.diff(sel) > 0):
            return sp.csr_matrix(A)[sel][:, sel].tocsr()
    return (T.T @ sp.csr_matrix(A) @ T).tocsr()
