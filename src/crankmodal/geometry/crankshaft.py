"""Crankshaft solid from :class:`~crankmodal.geometry.params.CrankshaftParams` (gmsh OCC).

The shaft axis is z; the free end is at z = 0. :func:`layout` places the features along the
axis (pure arithmetic, no gmsh); :func:`build_crankshaft` makes the solid in the current gmsh
model and returns the volumes plus :class:`~crankmodal.geometry.regions.RegionSpec` entries
that name its bearing surfaces.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .params import CrankshaftParams
from .regions import RegionSpec, find_circles


@dataclass
class CrankLayout:
    """Axial positions of the features, m (intervals are ``(z0, z1)``)."""

    free_end: tuple | None
    journals: list = field(default_factory=list)
    webs: list = field(default_factory=list)      # (z0, z1, phase_rad)
    pins: list = field(default_factory=list)      # (z0, z1, phase_rad)
    flywheel_end: tuple | None = None
    flywheel: tuple | None = None
    length: float = 0.0


def layout(p: CrankshaftParams) -> CrankLayout:
    """Axial layout of the crankshaft features (see the module docstring)."""
    z = 0.0
    out = CrankLayout(free_end=None)
    if p.free_end_length > 0:
        out.free_end = (0.0, p.free_end_length)
        z = p.free_end_length
    out.journals.append((z, z + p.journal_length))
    z += p.journal_length
    for phase in p.phases_deg:
        ph = math.radians(phase)
        out.webs.append((z, z + p.web_thickness, ph))
        z += p.web_thickness
        out.pins.append((z, z + p.pin_length, ph))
        z += p.pin_length
        out.webs.append((z, z + p.web_thickness, ph))
        z += p.web_thickness
        out.journals.append((z, z + p.journal_length))
        z += p.journal_length
    if p.flywheel_end_length > 0:
        out.flywheel_end = (z, z + p.flywheel_end_length)
        z += p.flywheel_end_length
        if p.flywheel_thickness > 0:
            out.flywheel = (z - p.flywheel_thickness, z)
    out.length = z
    return out


def web_block(p: CrankshaftParams) -> tuple[float, float, float]:
    """Simplified web: ``(u0, u1, half)`` of the straight-sided block in the throw's frame, m.

    The block spans the web's width (``-half .. half`` across the throw) and reaches from the
    counterweight's tip (or the web's back edge) at ``u0`` to the web's pin end at ``u1``: the
    envelope of the forged contour that a quick FE model extrudes instead of its round ends and
    counterweight arc. It keeps the outline's extent, not its area: the corners it fills add
    mass at the web's periphery (inertia, hardly any stiffness).
    """
    a, r = p.web_width / 2, p.throw_radius
    u1 = r + a if p.web_shape == "stadium" else a
    return -max(a, p.counterweight_radius), u1, a


def _web(occ, p: CrankshaftParams, z0: float, phase: float, simplified: bool) -> list:
    """Web (and counterweight) solids of one web slab, in the throw's frame rotated by phase."""
    a, r, t = p.web_width / 2, p.throw_radius, p.web_thickness
    parts = []
    if simplified:
        u0, u1, half = web_block(p)
        parts.append(occ.addBox(u0, -half, z0, u1 - u0, 2 * half, t))
    else:
        parts.append(occ.addCylinder(0, 0, z0, 0, 0, t, a))
        if p.web_shape == "stadium":
            parts.append(occ.addCylinder(r, 0, z0, 0, 0, t, a))
            parts.append(occ.addBox(0, -a, z0, r, 2 * a, t))
        if p.counterweight_radius > 0:
            angle = math.radians(p.counterweight_angle_deg)
            cw = occ.addCylinder(0, 0, z0, 0, 0, t, p.counterweight_radius, angle=angle)
            occ.rotate([(3, cw)], 0, 0, 0, 0, 0, 1, math.pi - angle / 2)
            parts.append(cw)
    dimtags = [(3, s) for s in parts]
    occ.rotate(dimtags, 0, 0, 0, 0, 0, 1, phase)
    return dimtags


def flywheel_thickness(p: CrankshaftParams, simplified: bool) -> float:
    """Axial thickness of the flywheel disc, m.

    The simplified flywheel is a plain disc of the detailed one's diameter and volume (mass).
    """
    t, rf = p.flywheel_thickness, p.flywheel_diameter / 2
    if not simplified or p.flywheel_web_thickness <= 0:
        return t
    rin, rh = rf - p.flywheel_rim_width, p.flywheel_hub_diameter / 2
    recess = (t - p.flywheel_web_thickness) * (rin ** 2 - rh ** 2)
    return t - recess / rf ** 2


def _flywheel(occ, p: CrankshaftParams, z0: float, simplified: bool) -> list:
    t, rf = p.flywheel_thickness, p.flywheel_diameter / 2
    if simplified or p.flywheel_web_thickness <= 0:
        t = flywheel_thickness(p, simplified)
        return [(3, occ.addCylinder(0, 0, z0 + p.flywheel_thickness - t, 0, 0, t, rf))]
    disc = occ.addCylinder(0, 0, z0, 0, 0, t, rf)
    rin, rh = rf - p.flywheel_rim_width, p.flywheel_hub_diameter / 2
    depth = (t - p.flywheel_web_thickness) / 2
    recesses = []
    for zr in (z0, z0 + t - depth):
        ring = occ.addCylinder(0, 0, zr, 0, 0, depth, rin)
        hub = occ.addCylinder(0, 0, zr, 0, 0, depth, rh)
        out, _ = occ.cut([(3, ring)], [(3, hub)])
        recesses += out
    out, _ = occ.cut([(3, disc)], recesses)
    return out


def _fillets(gmsh, p: CrankshaftParams, lay: CrankLayout, body: list) -> list:
    """Fillet every journal-to-web and pin-to-web circle."""
    occ = gmsh.model.occ
    rj, rp, r = p.journal_diameter / 2, p.pin_diameter / 2, p.throw_radius
    wanted = []
    for z0, z1, ph in lay.pins:
        for zz in (z0, z1):
            if p.pin_fillet > 0:
                wanted.append(((r * math.cos(ph), r * math.sin(ph), zz), rp, p.pin_fillet))
            if p.journal_fillet > 0:
                wanted.append(((0.0, 0.0, zz - p.web_thickness if zz == z0 else zz + p.web_thickness),
                               rj, p.journal_fillet))
    curves, radii = [], []
    for centre, rad, fr in wanted:
        for c in find_circles(gmsh, centre, rad):
            curves.append(c)
            radii.append(fr)
    body = occ.fillet([t for _, t in body], curves, radii)
    occ.synchronize()
    return body


def _chamfers(gmsh, p: CrankshaftParams, lay: CrankLayout, body: list) -> list:
    """Chamfer the free shaft ends and the journal-to-stub steps (45 degrees)."""
    occ = gmsh.model.occ
    rj = p.journal_diameter / 2
    ends = [(0.0, p.free_end_diameter / 2 if lay.free_end else rj)]
    if not lay.flywheel:
        ends.append((lay.length, p.flywheel_end_diameter / 2 if lay.flywheel_end else rj))
    if lay.free_end and p.free_end_diameter / 2 < rj:
        ends.append((lay.free_end[1], rj))
    if lay.flywheel_end and p.flywheel_end_diameter / 2 < rj:
        ends.append((lay.flywheel_end[0], rj))
    curves, faces = [], []
    for zz, rad in ends:
        for c in find_circles(gmsh, (0.0, 0.0, zz), rad):
            up, _ = gmsh.model.getAdjacencies(1, c)
            plane = [s for s in up if gmsh.model.getType(2, s) == "Plane"]
            if plane:
                curves.append(c)
                faces.append(plane[0])
    if curves:
        body = occ.chamfer([t for _, t in body], curves, faces, [p.journal_chamfer] * len(curves))
        occ.synchronize()
    return body


def build_crankshaft(gmsh, p: CrankshaftParams, fidelity: str):
    """Make the crankshaft solid in the current gmsh model (OCC kernel, synchronised on return).

    Parameters
    ----------
    gmsh : module
        The initialised gmsh module.
    p : CrankshaftParams
        Admissible parameters (see :func:`~crankmodal.geometry.checks.check_crankshaft`).
    fidelity : str
        ``full``: fillets, chamfers, oil holes, keyway and flywheel recesses;
        ``dechamfered``: no fillets, chamfers or oil holes;
        ``simplified`` ("peripheral detail modification", seed 000 Fig. 12c): also every web
        with its counterweight as one straight-sided block, its envelope (:func:`web_block`),
        a plain flywheel of the same mass and no keyway. The block keeps the contour's extent,
        not its area, as an analyst's quick extrusion does: the filled corners add mass at the
        web periphery and almost no stiffness, so every mode drops a few per cent (seed 000
        Table 3: 2-6 %). A simplification that kept the mass (blocks of the contour's area, as
        before) left the free modes within 0.5 % of ``dechamfered``.

    Returns
    -------
    volumes : list of int
        Volume tags of the solid (several when rod rows split a crankpin).
    specs : list of RegionSpec
        Named bearing and end surfaces to look up on the final model.
    detail : dict
        ``radius``: curved faces of smaller radius are refined (fillets, chamfers, holes), m;
        ``faces``: further faces to refine (the keyway's).
    """
    occ = gmsh.model.occ
    lay = layout(p)
    full, simplified = fidelity == "full", fidelity == "simplified"
    rj, rp, r = p.journal_diameter / 2, p.pin_diameter / 2, p.throw_radius
    solids = []
    if lay.free_end:
        solids.append((3, occ.addCylinder(0, 0, 0, 0, 0, p.free_end_length, p.free_end_diameter / 2)))
    for z0, z1 in lay.journals:
        solids.append((3, occ.addCylinder(0, 0, z0, 0, 0, z1 - z0, rj)))
    for z0, z1, ph in lay.pins:
        solids.append((3, occ.addCylinder(r * math.cos(ph), r * math.sin(ph), z0, 0, 0, z1 - z0, rp)))
    for z0, _, ph in lay.webs:
        solids += _web(occ, p, z0, ph, simplified)
    if lay.flywheel_end:
        z0, z1 = lay.flywheel_end
        solids.append((3, occ.addCylinder(0, 0, z0, 0, 0, z1 - z0, p.flywheel_end_diameter / 2)))
    if lay.flywheel:
        solids += _flywheel(occ, p, lay.flywheel[0], simplified)
    body, _ = occ.fuse(solids[:1], solids[1:])
    occ.synchronize()

    if full and (p.journal_fillet > 0 or p.pin_fillet > 0):
        body = _fillets(gmsh, p, lay, body)
    if full and p.journal_chamfer > 0:
        body = _chamfers(gmsh, p, lay, body)

    tools = []
    if full and p.oil_hole_diameter > 0:
        ro = p.oil_hole_diameter / 2
        for z0, z1, ph in lay.pins:
            cx, cy = r * math.cos(ph), r * math.sin(ph)
            tools.append((3, occ.addCylinder(cx, cy, z0 - p.web_thickness, 0, 0,
                                             z1 - z0 + 2 * p.web_thickness, ro)))
            row = (z1 - z0) / p.rod_rows
            for k in range(p.rod_rows):
                zc = z0 + (k + 0.5) * row
                tools.append((3, occ.addCylinder(cx, cy, zc, 1.5 * rp * math.cos(ph),
                                                 1.5 * rp * math.sin(ph), 0, ro)))
    if not simplified and p.keyway_length > 0:
        rs = p.free_end_diameter / 2
        kz0 = 0.5 * (p.free_end_length - p.keyway_length)
        tools.append((3, occ.addBox(-p.keyway_width / 2, rs - p.keyway_depth, kz0,
                                    p.keyway_width, p.keyway_depth + rs, p.keyway_length)))
    if tools:
        body, _ = occ.cut(body, tools)
    occ.synchronize()

    # split each crankpin surface into rod rows with discs across the pin
    if p.rod_rows > 1:
        discs = []
        for z0, z1, ph in lay.pins:
            for k in range(1, p.rod_rows):
                zz = z0 + k * (z1 - z0) / p.rod_rows
                discs.append((2, occ.addDisk(r * math.cos(ph), r * math.sin(ph), zz, 1.2 * rp, 1.2 * rp)))
        body, _ = occ.fragment(body, discs)
        occ.synchronize()
        body = [(d, t) for d, t in gmsh.model.getEntities(3)]

    specs = _region_specs(p, lay, simplified)
    radius = 0.5 * min(rj, rp, *(x / 2 for x in (p.free_end_diameter, p.flywheel_end_diameter) if x > 0))
    faces = []
    if not simplified and p.keyway_length > 0:  # the keyway's flat faces are a detail too
        rs, kz0 = p.free_end_diameter / 2, 0.5 * (p.free_end_length - p.keyway_length)
        box = (-p.keyway_width / 2, rs - p.keyway_depth, kz0, p.keyway_width / 2, rs, kz0 + p.keyway_length)
        faces = [s for _, s in gmsh.model.getEntitiesInBoundingBox(*(b - 1e-6 for b in box[:3]),
                                                                     *(b + 1e-6 for b in box[3:]), dim=2)]
    return [t for _, t in body], specs, {"radius": radius, "faces": faces}


def _region_specs(p: CrankshaftParams, lay: CrankLayout, simplified: bool) -> list:
    rj, rp, r = p.journal_diameter / 2, p.pin_diameter / 2, p.throw_radius
    specs = []
    for k, (z0, z1) in enumerate(lay.journals, start=1):
        specs.append(RegionSpec(f"main_journal_{k}", "cylinder", np.zeros(2), rj, (z0, z1)))
    for i, (z0, z1, ph) in enumerate(lay.pins, start=1):
        axis = np.array([r * math.cos(ph), r * math.sin(ph)])
        row = (z1 - z0) / p.rod_rows
        for k in range(p.rod_rows):
            specs.append(RegionSpec(f"crankpin_{i}_row_{k + 1}", "cylinder", axis, rp,
                                    (z0 + k * row, z0 + (k + 1) * row)))
    # shaft-end seats (coupling / pulley hub, flywheel hub): interfaces for a drive or a rotor
    if lay.free_end and p.free_end_diameter > 0:
        specs.append(RegionSpec("free_end_stub", "cylinder", np.zeros(2), p.free_end_diameter / 2,
                                lay.free_end))
    if lay.flywheel_end and p.flywheel_end_diameter > 0:
        z0, z1 = lay.flywheel_end
        if lay.flywheel:
            z1 = lay.flywheel[1] - flywheel_thickness(p, simplified)
        if z1 > z0:
            specs.append(RegionSpec("flywheel_end_stub", "cylinder", np.zeros(2),
                                    p.flywheel_end_diameter / 2, (z0, z1)))
    specs.append(RegionSpec("free_end_face", "plane_z", np.zeros(2), math.inf, (0.0, 0.0)))
    specs.append(RegionSpec("flywheel_end_face", "plane_z", np.zeros(2), math.inf, (lay.length, lay.length)))
    if lay.flywheel:
        z0 = lay.flywheel[1] - flywheel_thickness(p, simplified)
        specs.append(RegionSpec("flywheel_face", "plane_z", np.zeros(2), p.flywheel_diameter / 2, (z0, z0)))
    return specs
