"""Supports: node selections with fixed components, eliminated by a sparse transformation.

A support fixes displacement components of a set of nodes: any of ``x``, ``y``, ``z`` (global),
or ``radial`` for a cylindrical region (a bearing: the node may slide along the axis and turn
about it, but not move towards or away from it). Every constraint is a direction ``c`` with
``c·u = 0`` at a node; the free displacements of each node span the orthogonal complement, so
``u = T q`` with ``T`` sparse and orthonormal column by column. ``Tᵀ K T``, ``Tᵀ M T`` are the
supported matrices: exact elimination, no penalty to tune, positive definite when the supports
remove every rigid-body mode.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import SceneError

AXES = "xyz"


@dataclass
class Support:
    """Nodes and the components fixed on them.

    Attributes
    ----------
    label : str
        For messages, e.g. ``supports[1] (region main_journal_1)``.
    nodes : ndarray of int
        Point indices.
    fix : str
        ``"x"``, ``"yz"``, ``"xyz"``, ... or ``"radial"``.
    cylinder : Cylinder or None
        Axis of a radial support.
    """

    label: str
    nodes: np.ndarray
    fix: str
    cylinder: object = None


def check_fix(fix: str) -> str | None:
    """Error text for an inadmissible ``fix`` value, or None."""
    if fix == "radial":
        return None
    if not isinstance(fix, str) or not fix or set(fix) - set(AXES) or len(set(fix)) != len(fix):
        return f"fix must be 'radial' or distinct letters of x, y, z (e.g. 'xz'); got {fix!r}"
    return None


def fit_cylinder(points: np.ndarray, facets: np.ndarray):
    """Least-squares cylinder through a region's nodes (axis from the facet normals).

    Returns a :class:`~crankmodal.part.Cylinder`; raises ``ValueError`` if the region is flat or
    not cylindrical to 1 % of its radius.
    """
    from ..part import Cylinder

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
    return Cylinder(centre=centre, axis=axis, radius=float(radius), length=float(np.ptp(s)))


def region_cylinder(region, name: str, points: np.ndarray, what: str):
    """The region's exact cylinder from the geometry, else one fitted to its nodes.

    Raises :class:`SceneError` starting with ``what`` when the region is not cylindrical.
    """
    if region.cylinder is not None:
        return region.cylinder
    try:
        return fit_cylinder(points, np.asarray(region.facets))
    except ValueError as exc:
        raise SceneError(f"{what} needs a cylindrical region; region {name!r} is {exc}") from None


def validate_specs(specs, section: str = "modal") -> list[dict]:
    """Check support tables without a part; returns them with ``fix`` defaulted to ``xyz``.

    Raises
    ------
    SceneError
        Naming ``<section>.supports[i].<key>`` and what is allowed.
    """
    if specs is None:
        return []
    if not isinstance(specs, (list, tuple)):
        raise SceneError(f"{section}.supports: must be a list of tables, got {specs!r}")
    out = []
    for i, spec in enumerate(specs):
        key = f"{section}.supports[{i}]"
        if not isinstance(spec, dict):
            raise SceneError(f"{key}: must be a table {{box = [...], fix = ...}} or "
                             f"{{region = ..., fix = ...}}, got {spec!r}")
        unknown = set(spec) - {"box", "region", "fix"}
        if unknown:
            raise SceneError(f"{key}.{min(unknown)}: unknown key; allowed: box, region, fix")
        if ("box" in spec) == ("region" in spec):
            raise SceneError(f"{key}: give exactly one of 'box' or 'region'")
        fix = spec.get("fix", "xyz")
        msg = check_fix(fix)
        if msg:
            raise SceneError(f"{key}.fix: {msg}")
        if "box" in spec:
            box = spec["box"]
            if (not isinstance(box, (list, tuple)) or len(box) != 6
                    or not all(isinstance(b, (int, float)) and not isinstance(b, bool)
                               for b in box)):
                raise SceneError(f"{key}.box: must be [xmin, xmax, ymin, ymax, zmin, zmax] in m, "
                                 f"got {box!r}")
            if any(a > b for a, b in zip(box[0::2], box[1::2])):
                raise SceneError(f"{key}.box: each min must be <= its max, got {box!r}")
            if fix == "radial":
                raise SceneError(f"{key}.fix: 'radial' needs a cylindrical region, not a box")
        elif not isinstance(spec["region"], str):
            raise SceneError(f"{key}.region: must be a region name, got {spec['region']!r}")
        out.append({**spec, "fix": fix})
    return out


def select(part, specs, section: str = "modal") -> list[Support]:
    """Supports from scene tables ``{box = [...], fix = ...}`` / ``{region = ..., fix = ...}``.

    Raises
    ------
    SceneError
        Unknown region, a box holding no node, a radial support on a non-cylindrical region, or a
        malformed table; the message names ``<section>.supports[i]``.
    """
    specs = validate_specs(specs, section)
    points = np.asarray(part.mesh.points, float)[:, :3]
    out = []
    for i, spec in enumerate(specs):
        key = f"{section}.supports[{i}]"
        fix = spec["fix"]
        cyl = None
        if "region" in spec:
            name = spec["region"]
            if name not in part.regions:
                known = ", ".join(sorted(part.regions)) or "none"
                raise SceneError(f"{key}.region: no region {name!r} in part {part.name!r}; "
                                 f"regions: {known}")
            reg = part.regions[name]
            nodes = np.asarray(reg.nodes, np.int64)
            label = f"{key} (region {name})"
            if fix == "radial":
                cyl = region_cylinder(reg, name, points, f"{key}.fix: 'radial'")
        else:
            box = spec["box"]
            lo, hi = np.array(box[0::2], float), np.array(box[1::2], float)
            inside = np.all((points >= lo) & (points <= hi), axis=1)
            nodes = np.flatnonzero(inside)
            label = f"{key} (box)"
        if len(nodes) == 0:
            ext = np.column_stack([points.min(0), points.max(0)]).ravel()
            raise SceneError(f"{key}: selects no node (part bounding box "
                             f"[{', '.join(f'{v:.4g}' for v in ext)}] m)")
        out.append(Support(label=label, nodes=nodes, fix=fix, cylinder=cyl))
    return out


def reduction(points: np.ndarray, used: np.ndarray, supports: list[Support]) -> sp.csr_matrix:
    """Sparse ``T`` (3 n_points × n_free) with ``u = T q`` satisfying every support.

    Points no element uses are left out as well (they have no stiffness or mass).

    Raises
    ------
    SceneError
        The supports leave no degree of freedom free (naming them).
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
        raise SceneError(f"{who}: {held} every node the elements use in every direction, so "
                         f"nothing is left free; support a part of the mesh only (a smaller "
                         f"box or a region) or fix fewer components")
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
