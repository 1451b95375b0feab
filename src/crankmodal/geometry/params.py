"""Parameter sets of the built parts (SI units: m, degrees for angles).

A parameter set describes a part at every fidelity; the fidelity (``full``, ``dechamfered``,
``simplified``) is passed separately so that a study changes one thing only. Zero switches an
optional feature off (``counterweight_radius = 0``: no counterweight, ``oil_hole_diameter = 0``:
no oil holes, ...). Admissibility is checked by :mod:`crankmodal.geometry.checks` before any
geometry kernel runs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..errors import GeometryError

#: Fidelities of a built part, most detailed first.
FIDELITIES = ("full", "dechamfered", "simplified")


@dataclass(frozen=True)
class CrankshaftParams:
    """A crankshaft along +z, free end at z = 0, flywheel end last.

    Layout along the axis: free-end stub, main journal 1, then per throw web / crankpin / web /
    main journal, then the flywheel-end stub with the flywheel on its last ``flywheel_thickness``.
    Throw ``i`` has its crankpin axis at ``throw_radius`` in the direction ``phases_deg[i]``
    measured from +x towards +y.

    Attributes
    ----------
    phases_deg : tuple of float
        Phase angle of every throw, degrees; its length is the number of throws.
    throw_radius : float
        Crank radius r (shaft axis to crankpin axis), m.
    journal_diameter, journal_length : float
        Main journals (all equal), m.
    pin_diameter, pin_length : float
        Crankpins (all equal), m. ``pin_length`` is the length between the two webs.
    rod_rows : int
        Connecting-rod rows carried by each crankpin; the pin surface is split into this many
        equal named regions ``crankpin_<i>_row_<k>``.
    web_thickness, web_width : float
        Crank webs, m. ``web_width`` is the width across the web (twice its end radius).
    web_shape : str
        ``stadium`` (round-ended bar from the journal to the pin axis, end radius web_width/2)
        or ``round`` (disc about the shaft axis of diameter web_width). At the ``simplified``
        fidelity every web and its counterweight become their straight-sided envelope, a block
        web_width wide from the counterweight tip to the web's pin end (heavier than the
        contour: see :func:`~crankmodal.geometry.crankshaft.web_block`).
    counterweight_radius : float
        Outer radius of the counterweight sector opposite the pin, m (0: none).
    counterweight_angle_deg : float
        Included angle of the counterweight sector, degrees (<= 180).
    journal_fillet, pin_fillet : float
        Fillet radii at journal-to-web and pin-to-web transitions, m (full fidelity only).
    journal_chamfer : float
        45-degree chamfer on the free shaft ends and on journal-to-stub steps, m (full only).
    oil_hole_diameter : float
        Oil drilling of every throw (full only), m: an axial bore along the crankpin axis
        through both webs and the pin, and a radial cross-drilling to the pin surface at the
        middle of every rod row.
    free_end_diameter, free_end_length : float
        Free-end stub, m (length 0: none).
    flywheel_end_diameter, flywheel_end_length : float
        Flywheel-end stub, m (length 0: none).
    flywheel_diameter, flywheel_thickness : float
        Flywheel disc on the last ``flywheel_thickness`` of the flywheel-end stub, m (0: none).
    flywheel_rim_width, flywheel_web_thickness, flywheel_hub_diameter : float
        Flywheel detail (full and dechamfered), m: a rim of full thickness, a thinner centred
        web and a hub of full thickness. ``flywheel_web_thickness = 0``: plain disc. The
        simplified flywheel is a plain disc of the same diameter and volume, flush with the
        stub's end.
    keyway_width, keyway_depth, keyway_length : float
        Flat-ended keyway at +y in the middle of the free-end stub, m (0: none; full and
        dechamfered only).
    """

    phases_deg: tuple = (0.0,)
    throw_radius: float = 0.035
    journal_diameter: float = 0.060
    journal_length: float = 0.040
    pin_diameter: float = 0.050
    pin_length: float = 0.060
    rod_rows: int = 1
    web_thickness: float = 0.020
    web_width: float = 0.090
    web_shape: str = "stadium"
    counterweight_radius: float = 0.0
    counterweight_angle_deg: float = 120.0
    journal_fillet: float = 0.0
    pin_fillet: float = 0.0
    journal_chamfer: float = 0.0
    oil_hole_diameter: float = 0.0
    free_end_diameter: float = 0.0
    free_end_length: float = 0.0
    flywheel_end_diameter: float = 0.0
    flywheel_end_length: float = 0.0
    flywheel_diameter: float = 0.0
    flywheel_thickness: float = 0.0
    flywheel_rim_width: float = 0.0
    flywheel_web_thickness: float = 0.0
    flywheel_hub_diameter: float = 0.0
    keyway_width: float = 0.0
    keyway_depth: float = 0.0
    keyway_length: float = 0.0

    @property
    def n_throws(self) -> int:
        return len(self.phases_deg)

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["phases_deg"] = list(self.phases_deg)
        return d


@dataclass(frozen=True)
class ConrodParams:
    """A connecting rod in the x-y plane: big-end bore axis on z at the origin, small end at +x.

    Attributes
    ----------
    length : float
        Centre distance big-end bore to small-end bore, m.
    big_end_bore, big_end_outer_diameter, big_end_width : float
        Big-end eye, m (width along the bore axis).
    small_end_bore, small_end_outer_diameter, small_end_width : float
        Small-end eye, m. With a bushing, ``small_end_bore`` is the bushing's bore.
    bushing_thickness : float
        Radial wall of the small-end bushing, m (0: none); meshed as a second volume in contact-
        free bond with the eye, cells flagged in ``mesh.cell_data["bushing"]``.
    shank_depth, shank_width : float
        I-section overall depth (in the rod plane, along y) and flange width (along z), m.
    shank_web_thickness, shank_flange_thickness : float
        I-section web and flange thickness, m. ``shank_section = "H"`` turns the section by 90°
        (the web lies in the rod plane's normal direction).
    shank_section : str
        ``I`` or ``H``.
    shank_fillet : float
        Inner web-to-flange fillet of the section, m (full only).
    small_end_fillet : float
        Transition fillet of the small-end eye to the shank, m (full only; 0: a sharp edge):
        rounds the edges where the flanges' outer and side faces meet the eye's outer cylinder
        (the section's inner faces stay sharp). Without it the peak stress at that edge grows
        with mesh refinement (a re-entrant edge). Admissible: half to 0.9 times the flange
        thickness (see :func:`~crankmodal.geometry.checks.check_conrod`).
    bolt_boss_width, bolt_boss_height : float
        Bolt bosses either side of the big end across the cap split (plane x = 0): extent
        along y beyond the eye's outer radius and along x (both sides of the split), m.
    bolt_diameter, bolt_offset : float
        Cap bolts along x through the bosses at y = ±bolt_offset, m (holes in full only).
    """

    length: float = 0.280
    big_end_bore: float = 0.060
    big_end_outer_diameter: float = 0.090
    big_end_width: float = 0.030
    small_end_bore: float = 0.025
    small_end_outer_diameter: float = 0.042
    small_end_width: float = 0.028
    bushing_thickness: float = 0.0
    shank_depth: float = 0.032
    shank_width: float = 0.024
    shank_web_thickness: float = 0.008
    shank_flange_thickness: float = 0.007
    shank_section: str = "I"
    shank_fillet: float = 0.0
    small_end_fillet: float = 0.0
    bolt_boss_width: float = 0.014
    bolt_boss_height: float = 0.030
    bolt_diameter: float = 0.010
    bolt_offset: float = 0.0

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


PART_TYPES = {"crankshaft": CrankshaftParams, "rod": ConrodParams}


def length_fields(params) -> dict:
    """The lengths (m) of a parameter set: every float field but the angles (``*_deg``)."""
    return {f.name: getattr(params, f.name) for f in dataclasses.fields(params)
            if isinstance(f.default, float) and not f.name.endswith("_deg")}


def params_from_dict(part: str, table: dict, where: str = "") -> CrankshaftParams | ConrodParams:
    """Build a parameter set from a TOML-like table, refusing unknown keys and wrong types.

    Parameters
    ----------
    part : str
        ``crankshaft`` or ``rod``.
    table : dict
        Keys of the dataclass; missing keys take their defaults.
    where : str
        Prefix of the error messages, e.g. ``"four_star_compressor.toml [crankshaft]"``.
    """
    if part not in PART_TYPES:
        raise GeometryError(f"{where or 'geometry'}.part: must be one of {', '.join(PART_TYPES)}; got {part!r}")
    cls = PART_TYPES[part]
    prefix = where or part
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(table) - set(fields))
    if unknown:
        raise GeometryError(f"{prefix}.{unknown[0]}: unknown parameter; allowed: {', '.join(fields)}")
    values = {}
    for name, value in table.items():
        default = fields[name].default
        if isinstance(default, tuple):
            if not isinstance(value, (list, tuple)) or not value or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in value
            ):
                raise GeometryError(f"{prefix}.{name}: must be a non-empty list of numbers, got {value!r}")
            values[name] = tuple(float(v) for v in value)
        elif isinstance(default, str):
            if not isinstance(value, str):
                raise GeometryError(f"{prefix}.{name}: must be a string, got {value!r}")
            values[name] = value
        elif isinstance(default, int):  # bool is an int too
            if isinstance(value, bool) or not isinstance(value, int):
                raise GeometryError(f"{prefix}.{name}: must be an integer, got {value!r}")
            values[name] = value
        else:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise GeometryError(f"{prefix}.{name}: must be a number (m or deg), got {value!r}")
            values[name] = float(value)
    return cls(**values)
