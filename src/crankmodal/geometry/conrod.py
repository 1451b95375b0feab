"""Connecting rod from :class:`~crankmodal.geometry.params.ConrodParams` (gmsh OCC).

The rod lies in the x-y plane: big-end bore axis along z through the origin, small-end bore at
x = ``length``, mid-plane z = 0. The big-end cap (x < 0, across the split plane x = 0) and the
optional bushing are separate volumes bonded to the rod through shared (conformal) faces;
``mesh.cell_data["volume"]`` tells them apart.
"""

from __future__ import annotations

import math

import numpy as np

from .params import ConrodParams
from .regions import RegionSpec


def shank_pieces(p: ConrodParams) -> list:
    """Rectangles ``(y0, y1, z0, z1)`` whose union is the shank section (m), fillets aside."""
    h, b, tw, tf = p.shank_depth, p.shank_width, p.shank_web_thickness, p.shank_flange_thickness
    pieces = [(h / 2 - tf, h / 2, -b / 2, b / 2), (-h / 2, -h / 2 + tf, -b / 2, b / 2),
              (-h / 2 + tf, h / 2 - tf, -tw / 2, tw / 2)]
    if p.shank_section == "H":
        pieces = [(z0, z1, y0, y1) for y0, y1, z0, z1 in pieces]
    return pieces


def boss_root(p: ConrodParams) -> float:
    """y where the bolt-boss boxes start: their inner corners sit on the big-end eye, m."""
    rbo = p.big_end_outer_diameter / 2
    return math.sqrt(rbo ** 2 - (p.bolt_boss_height / 2) ** 2)


def bolt_offset(p: ConrodParams) -> float:
    """Distance of the bolt axes from the rod axis, m (default: the middle of the boss)."""
    rbo = p.big_end_outer_diameter / 2
    return p.bolt_offset if p.bolt_offset > 0 else 0.5 * (boss_root(p) + rbo + p.bolt_boss_width)


def _shank(gmsh, p: ConrodParams, full: bool) -> list:
    occ = gmsh.model.occ
    boxes = [(3, occ.addBox(0, y0, z0, p.length, y1 - y0, z1 - z0)) for y0, y1, z0, z1 in shank_pieces(p)]
    shank, _ = occ.fuse(boxes[:1], boxes[1:])
    occ.synchronize()
    if full and p.shank_fillet > 0:
        h, tw, tf = p.shank_depth, p.shank_web_thickness, p.shank_flange_thickness
        corners = [(sy * (h / 2 - tf), sz * tw / 2) for sy in (-1, 1) for sz in (-1, 1)]
        if p.shank_section == "H":
            corners = [(z, y) for y, z in corners]
        edges = []
        for _, c in gmsh.model.getEntities(1):
            _, y0, z0, _, y1, z1 = gmsh.model.getBoundingBox(1, c)
            for y, z in corners:
                if abs(y0 - y) < 1e-6 and abs(y1 - y) < 1e-6 and abs(z0 - z) < 1e-6 and abs(z1 - z) < 1e-6:
                    edges.append(c)
        shank = occ.fillet([t for _, t in shank], edges, [p.shank_fillet])
    return shank


def _on_eye(xyz: np.ndarray, centre_x: float, radius: float, tol: float = 1e-6) -> bool:
    """Whether all points lie on the eye cylinder of axis z through (centre_x, 0)."""
    return bool(np.all(np.abs(np.hypot(xyz[:, 0] - centre_x, xyz[:, 1]) - radius) < tol))


def small_end_transition_edges(gmsh, p: ConrodParams, tol: float = 1e-6) -> list:
    """Curves of the fused (bore-less) rod where the shank's outer faces meet the small eye.

    The section's outer faces are the planes |y| = y_max and |z| = z_max of its bounding box:
    the flanges' outer and side faces (I-section). Their curves on the small eye's cylinder, off
    the eye's own faces, are the concave edges the transition fillet rounds.
    """
    h, b = p.shank_depth, p.shank_width
    ymax, zmax = (h / 2, b / 2) if p.shank_section == "I" else (b / 2, h / 2)
    rso, half = p.small_end_outer_diameter / 2, p.small_end_width / 2
    edges = []
    for _, c in gmsh.model.getEntities(1):
        lo, hi = gmsh.model.getParametrizationBounds(1, c)
        xyz = np.asarray(gmsh.model.getValue(1, c, np.linspace(lo[0], hi[0], 7))).reshape(-1, 3)
        y, z = np.abs(xyz[:, 1]), np.abs(xyz[:, 2])
        inside = np.all(y <= ymax + tol) and np.all(z <= zmax + tol)
        on_face = np.all(np.abs(y - ymax) < tol) or np.all(np.abs(z - zmax) < tol)
        if inside and on_face and np.any(z < half - tol) and _on_eye(xyz, p.length, rso, tol):
            edges.append(c)
    return edges


def _small_end_fillet(gmsh, p: ConrodParams, body: list) -> list:
    """Round the flanges' outer and side faces into the small eye (one OCC fillet).

    The section's inner edges (web and flange inner faces) stay sharp: OCC fails on them
    together with these, or builds a self-intersecting blend. At a flange's outer corner the two
    fillets end capped by the flange's planes (OCC's corner for a convex edge between them).
    """
    occ = gmsh.model.occ
    occ.synchronize()
    body = occ.fillet([t for _, t in body], small_end_transition_edges(gmsh, p), [p.small_end_fillet])
    occ.synchronize()
    return body


def build_conrod(gmsh, p: ConrodParams, fidelity: str):
    """Make the connecting rod in the current gmsh model (synchronised on return).

    ``full`` has bolt holes and section fillets; ``dechamfered`` drops them; ``simplified``
    also drops the bolt bosses and the bushing (its bore becomes the bushing's bore).

    Returns
    -------
    volumes, specs, detail_radius
        As :func:`~crankmodal.geometry.crankshaft.build_crankshaft`.
    """
    occ = gmsh.model.occ
    full, simplified = fidelity == "full", fidelity == "simplified"
    L = p.length
    rbi, rbo, bb = p.big_end_bore / 2, p.big_end_outer_diameter / 2, p.big_end_width
    rb = p.small_end_bore / 2
    rsi = rb if simplified else rb + p.bushing_thickness
    rso, bs = p.small_end_outer_diameter / 2, p.small_end_width
    parts = [(3, occ.addCylinder(0, 0, -bb / 2, 0, 0, bb, rbo)),
             (3, occ.addCylinder(L, 0, -bs / 2, 0, 0, bs, rso))]
    if not simplified:
        y0, hb = boss_root(p), p.bolt_boss_height
        for s in (1, -1):
            lo = y0 if s > 0 else -(rbo + p.bolt_boss_width)
            parts.append((3, occ.addBox(-hb / 2, lo, -bb / 2, hb, rbo + p.bolt_boss_width - y0, bb)))
    parts += _shank(gmsh, p, full)
    body, _ = occ.fuse(parts[:1], parts[1:])
    if full and p.small_end_fillet > 0:  # on the plain body: bores and split plane come after
        body = _small_end_fillet(gmsh, p, body)
    tools = [(3, occ.addCylinder(0, 0, -bb, 0, 0, 2 * bb, rbi)),
             (3, occ.addCylinder(L, 0, -bs, 0, 0, 2 * bs, rsi))]
    if full and p.bolt_diameter > 0:
        yb, hb = bolt_offset(p), p.bolt_boss_height
        for s in (1, -1):
            tools.append((3, occ.addCylinder(-hb, s * yb, 0, 2 * hb, 0, 0, p.bolt_diameter / 2)))
    body, _ = occ.cut(body, tools)
    # split cap: a plane x = 0 across the big end; bushing: a bonded ring in the small end
    extra = []
    half = rbo + p.bolt_boss_width + 0.01 * rbo
    plane = occ.addRectangle(-bb, -half, 0, 2 * bb, 2 * half)
    occ.rotate([(2, plane)], 0, 0, 0, 0, 1, 0, -math.pi / 2)
    extra.append((2, plane))
    if not simplified and p.bushing_thickness > 0:
        ring = occ.addCylinder(L, 0, -bs / 2, 0, 0, bs, rsi)
        hole = occ.addCylinder(L, 0, -bs, 0, 0, 2 * bs, rb)
        bush, _ = occ.cut([(3, ring)], [(3, hole)])
        extra += bush
    occ.fragment(body, extra)
    occ.synchronize()
    # drop the parts of the cutting plane outside the solid
    for dim, tag in gmsh.model.getEntities(2):
        if not gmsh.model.getAdjacencies(2, tag)[0].size:
            occ.remove([(2, tag)], recursive=True)
    occ.synchronize()
    volumes = [t for _, t in gmsh.model.getEntities(3)]
    specs = [RegionSpec("big_end_bore", "cylinder", np.zeros(2), rbi, (-bb / 2, bb / 2)),
             RegionSpec("small_end_bore", "cylinder", np.array([L, 0.0]), rb, (-bs / 2, bs / 2))]
    detail = 0.5 * min(rb, p.shank_flange_thickness, p.shank_web_thickness)
    if full and p.bolt_diameter > 0:
        detail = max(detail, 0.51 * p.bolt_diameter)
    if full and p.small_end_fillet > 0:
        detail = max(detail, 1.02 * p.small_end_fillet)
    return volumes, specs, {"radius": detail, "faces": []}
