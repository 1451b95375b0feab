"""Admissibility of parameter sets, checked before any geometry kernel runs.

Every refusal of a part parameter is a :class:`~crankmodal.errors.GeometryError` with one line
naming the parameter, its admissible range for the other parameters as given, and the value
received (an unknown fidelity: a ParameterError naming ``fidelity``), e.g.::

    crankshaft.web_width: must be >= 0.0735 m (web must hold the pin and its fillet), got 0.06

Last, every length must lie in the sizes crankmodal builds (:func:`check_lengths`: 1 µm to
100 m, spanning at most five decades); that refusal is a :class:`LengthError`, a GeometryError
and a ParameterError naming ``<part>.<parameter>``.

The rules keep a small margin (``MARGIN``) between features so that the solids gmsh receives
have no slivers; the margins are part of the documented admissible space.
"""

from __future__ import annotations

import math

from ..errors import GeometryError, ParameterError
from .conrod import bolt_offset
from .params import FIDELITIES, ConrodParams, CrankshaftParams, length_fields

#: Relative clearance kept between neighbouring features (5 %).
MARGIN = 1.05

#: Small-end transition fillet per flange thickness, smallest and largest. On the seed 000 rod
#: (6 mm flanges) OCC builds and gmsh meshes every fillet from 1 to 5.5 mm, but below half the
#: flange thickness the corners where a flange's outer and side faces meet the eye come out
#: misshapen: the fillets' volume is 0.44-1.9 times the straight-corner closed form (3-5.5 mm:
#: 0.875-1.01).
SMALL_END_FILLET_PER_FLANGE = (0.5, 0.9)


#: The sizes crankmodal builds, m: every non-zero length of a part (and an imported mesh's extent)
#: lies in [MIN_LENGTH, MAX_LENGTH]. 1 µm is ten times OpenCASCADE's confusion tolerance (1e-7,
#: in metres here), below which its solids lose faces; 100 m is beyond any crank-linkage
#: machine (a marine two-stroke crankshaft is ~25 m). Outside, OpenCASCADE kills the
#: interpreter (a 1e15 m rod: segmentation fault) or builds nonsense (a 1e-310 m fillet).
MIN_LENGTH, MAX_LENGTH = 1e-6, 100.0

#: Largest ratio of a part's longest length to its shortest non-zero one. A feature 1e-5 of the
#: part is a hundred times below the finest mesh the element limit allows on it (5e6
#: tetrahedra: h of about L / 200), so it cannot change a result, and OpenCASCADE's booleans
#: are unreliable on solids whose lengths span more decades than its tolerances.
MAX_LENGTH_RATIO = 1e5


class LengthError(ParameterError, GeometryError):
    """A part length outside the sizes crankmodal builds (:data:`MIN_LENGTH`,
    :data:`MAX_LENGTH`, :data:`MAX_LENGTH_RATIO`): a ParameterError naming the parameter
    (``rod.length``) and a GeometryError, raised before any geometry kernel runs."""


def check_lengths(part: str, p) -> None:
    """Refuse a length of ``p`` outside [MIN_LENGTH, MAX_LENGTH] m (0 is allowed: a feature
    switched off), or lengths spanning more than MAX_LENGTH_RATIO.

    Raises
    ------
    LengthError
        Naming ``<part>.<parameter>``, its value and the admissible sizes.
    """
    lengths = {k: v for k, v in length_fields(p).items() if v != 0}
    for name, v in lengths.items():
        if not MIN_LENGTH <= v <= MAX_LENGTH:
            raise LengthError(f"{part}.{name}", f"must be 0 or in [{MIN_LENGTH:g}, {MAX_LENGTH:g}] m, "
                              f"the sizes crankmodal builds (OpenCASCADE fails outside them), "
                              f"got {v:.6g}")
    if lengths:
        small = min(lengths, key=lengths.get)
        large = max(lengths, key=lengths.get)
        if lengths[large] > MAX_LENGTH_RATIO * lengths[small]:
            raise LengthError(f"{part}.{small}", f"must be 0 or >= {lengths[large] / MAX_LENGTH_RATIO:.6g} m: "
                              f"at most {MAX_LENGTH_RATIO:.0e} times smaller than {large} = "
                              f"{lengths[large]:g} m (a finer feature than any mesh of the part "
                              f"resolves), got {lengths[small]!r}")


def _of_type(p, cls) -> None:
    if not isinstance(p, cls):  # build_part sends whatever is not a CrankshaftParams here
        raise ParameterError("params", f"must be a CrankshaftParams or ConrodParams, got "
                             f"{type(p).__name__} {p!r}"[:200])


def _refuse(part: str, name: str, rule: str, value) -> GeometryError:
    return GeometryError(f"{part}.{name}: must be {rule}, got {value!r}")


def _positive(part: str, p, names) -> None:
    for name in names:
        v = getattr(p, name)
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise _refuse(part, name, "> 0 m", v)


def _nonnegative(part: str, p, names) -> None:
    for name in names:
        v = getattr(p, name)
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
            raise _refuse(part, name, ">= 0 m (0 switches the feature off)", v)


def _at_least(part: str, name: str, value: float, lo: float, why: str) -> None:
    if not value >= lo:
        raise _refuse(part, name, f">= {lo:.6g} m ({why})", value)


def _at_most(part: str, name: str, value: float, hi: float, why: str) -> None:
    if not value <= hi:
        raise _refuse(part, name, f"in [0, {max(hi, 0.0):.6g}] m ({why})", value)


def check_fidelity(fidelity: str) -> str:
    """Return ``fidelity`` if it is one of :data:`FIDELITIES`; else a ParameterError naming
    ``fidelity``."""
    from ..errors import ParameterError

    if fidelity not in FIDELITIES:
        raise ParameterError("fidelity", f"must be one of {', '.join(FIDELITIES)}; got {fidelity!r}")
    return fidelity


def check_crankshaft(p: CrankshaftParams) -> CrankshaftParams:
    """Refuse an impossible crankshaft; return ``p`` unchanged when admissible.

    Raises
    ------
    GeometryError
        Naming the first offending parameter and its admissible range.
    """
    c = "crankshaft"
    _of_type(p, CrankshaftParams)
    if not p.phases_deg or not all(isinstance(a, (int, float)) and math.isfinite(a) for a in p.phases_deg):
        raise _refuse(c, "phases_deg", "a non-empty list of finite angles in degrees", p.phases_deg)
    _positive(c, p, ("throw_radius", "journal_diameter", "journal_length", "pin_diameter",
                     "pin_length", "web_thickness", "web_width"))
    _nonnegative(c, p, ("counterweight_radius", "journal_fillet", "pin_fillet", "journal_chamfer",
                        "oil_hole_diameter", "free_end_diameter", "free_end_length",
                        "flywheel_end_diameter", "flywheel_end_length", "flywheel_diameter",
                        "flywheel_thickness", "flywheel_rim_width", "flywheel_web_thickness",
                        "flywheel_hub_diameter", "keyway_width", "keyway_depth", "keyway_length"))
    if isinstance(p.rod_rows, bool) or not isinstance(p.rod_rows, int) or not 1 <= p.rod_rows <= 8:
        raise _refuse(c, "rod_rows", "an integer in [1, 8]", p.rod_rows)
    if p.web_shape not in ("stadium", "round"):
        raise _refuse(c, "web_shape", "one of stadium, round", p.web_shape)
    rj, rp, a, r = p.journal_diameter / 2, p.pin_diameter / 2, p.web_width / 2, p.throw_radius
    # webs must hold the journal and the pin with their fillets
    _at_least(c, "web_width", p.web_width, 2 * MARGIN * (rj + p.journal_fillet),
              "web must hold the journal and its fillet")
    reach = rp + p.pin_fillet if p.web_shape == "stadium" else r + rp + p.pin_fillet
    _at_least(c, "web_width", p.web_width, 2 * MARGIN * reach, "web must hold the pin and its fillet")
    if p.counterweight_radius > 0:
        _at_least(c, "counterweight_radius", p.counterweight_radius, MARGIN * 1.05 * a,
                  "counterweight must reach beyond the web; 0 for none")
        if not 10.0 <= p.counterweight_angle_deg <= 180.0:
            raise _refuse(c, "counterweight_angle_deg", "in [10, 180] degrees", p.counterweight_angle_deg)
    # journals and pins longer than their fillets (and chamfers)
    _at_least(c, "journal_length", p.journal_length, MARGIN * (2 * p.journal_fillet + p.journal_chamfer),
              "a journal must be longer than its two fillets and its chamfer")
    row = p.pin_length / p.rod_rows
    _at_least(c, "pin_length", p.pin_length, MARGIN * p.rod_rows * 2 * p.pin_fillet,
              "each rod row must be longer than two pin fillets")
    _at_most(c, "pin_fillet", p.pin_fillet, p.web_thickness / 2, "at most half the web thickness")
    _at_most(c, "journal_fillet", p.journal_fillet, p.web_thickness / 2, "at most half the web thickness")
    if p.oil_hole_diameter > 0:
        hi = min(0.4 * p.pin_diameter, 0.8 * (row - 2 * p.pin_fillet),
                 2 * (r - MARGIN * (rj + p.journal_fillet)))
        _at_most(c, "oil_hole_diameter", p.oil_hole_diameter, hi,
                 "the bore must fit the pin and each rod row, and leave the journal fillet whole; 0 for none")
    # stubs
    ends = (("free_end", p.free_end_diameter, p.free_end_length),
            ("flywheel_end", p.flywheel_end_diameter, p.flywheel_end_length))
    for name, d, length in ends:
        if length > 0 and not 0 < d <= p.journal_diameter:
            raise _refuse(c, f"{name}_diameter",
                          f"in (0, {p.journal_diameter:.6g}] m (a stub is not wider than the journal)", d)
    if p.journal_chamfer > 0:
        for name, d, length in ends:
            rs = d / 2 if length > 0 else rj
            _at_most(c, "journal_chamfer", p.journal_chamfer, 0.3 * rs, f"at most 30 % of the {name} radius")
            if length > 0:
                _at_most(c, "journal_chamfer", p.journal_chamfer, 0.4 * length, f"at most 40 % of {name}_length")
                if rs < rj:
                    _at_most(c, "journal_chamfer", p.journal_chamfer, 0.5 * (rj - rs) / MARGIN,
                             f"at most half the journal-to-{name} step")
    # flywheel
    if p.flywheel_diameter > 0 or p.flywheel_thickness > 0:
        _positive(c, p, ("flywheel_diameter", "flywheel_thickness"))
        if p.flywheel_end_length <= 0:
            raise _refuse(c, "flywheel_end_length", "> 0 m (the flywheel sits on the flywheel-end stub)",
                          p.flywheel_end_length)
        _at_least(c, "flywheel_end_length", p.flywheel_end_length, p.flywheel_thickness,
                  "the flywheel sits on the stub's last flywheel_thickness")
        _at_least(c, "flywheel_diameter", p.flywheel_diameter, 1.2 * max(p.journal_diameter, p.flywheel_end_diameter),
                  "the flywheel is wider than the shaft")
        if p.flywheel_web_thickness > 0:
            _at_most(c, "flywheel_web_thickness", p.flywheel_web_thickness, 0.8 * p.flywheel_thickness,
                     "a recessed web is thinner than the flywheel")
            _at_least(c, "flywheel_hub_diameter", p.flywheel_hub_diameter, MARGIN * 1.1 * p.flywheel_end_diameter,
                      "the hub must be wider than the stub")
            _at_least(c, "flywheel_rim_width", p.flywheel_rim_width, 0.02 * p.flywheel_diameter,
                      "a rim is needed around a recessed web")
            _at_most(c, "flywheel_hub_diameter", p.flywheel_hub_diameter,
                     (p.flywheel_diameter - 2 * p.flywheel_rim_width) / (1.1 * MARGIN), "the hub must fit inside the rim")
    # keyway
    if p.keyway_width > 0 or p.keyway_depth > 0 or p.keyway_length > 0:
        if p.free_end_length <= 0:
            raise _refuse(c, "free_end_length", "> 0 m when a keyway is cut into the free-end stub",
                          p.free_end_length)
        _positive(c, p, ("keyway_width", "keyway_depth", "keyway_length"))
        rs = p.free_end_diameter / 2
        _at_most(c, "keyway_width", p.keyway_width, 0.6 * p.free_end_diameter, "at most 60 % of the stub diameter")
        _at_most(c, "keyway_depth", p.keyway_depth, 0.4 * rs, "at most 40 % of the stub radius")
        _at_most(c, "keyway_length", p.keyway_length, (p.free_end_length - 2 * p.journal_chamfer) / MARGIN,
                 "within the free-end stub, clear of its chamfers")
    check_lengths(c, p)
    return p


def check_conrod(p: ConrodParams) -> ConrodParams:
    """Refuse an impossible connecting rod; return ``p`` unchanged when admissible."""
    c = "rod"
    _of_type(p, ConrodParams)
    _positive(c, p, ("length", "big_end_bore", "big_end_outer_diameter", "big_end_width",
                     "small_end_bore", "small_end_outer_diameter", "small_end_width",
                     "shank_depth", "shank_width", "shank_web_thickness", "shank_flange_thickness",
                     "bolt_boss_width", "bolt_boss_height"))
    _nonnegative(c, p, ("bushing_thickness", "shank_fillet", "small_end_fillet", "bolt_diameter", "bolt_offset"))
    if p.shank_section not in ("I", "H"):
        raise _refuse(c, "shank_section", "one of I, H", p.shank_section)
    rbi, rbo = p.big_end_bore / 2, p.big_end_outer_diameter / 2
    rsi = p.small_end_bore / 2 + p.bushing_thickness
    rso = p.small_end_outer_diameter / 2
    _at_least(c, "big_end_outer_diameter", p.big_end_outer_diameter, 2 * MARGIN * 1.1 * rbi, "wall around the bore")
    _at_least(c, "small_end_outer_diameter", p.small_end_outer_diameter, 2 * MARGIN * 1.1 * rsi,
              "wall around the bore and bushing")
    _at_least(c, "length", p.length, MARGIN * (rbo + rso + p.bolt_boss_height / 2),
              "the eyes and the bolt bosses must not overlap")
    # the section: depth along y, width along z (I), swapped for H
    depth, width = (p.shank_depth, p.shank_width) if p.shank_section == "I" else (p.shank_width, p.shank_depth)
    _at_most(c, "shank_depth" if p.shank_section == "I" else "shank_width", depth, 2 * rso / MARGIN,
             "the shank is narrower than the small-end eye")
    _at_most(c, "shank_depth" if p.shank_section == "I" else "shank_width", depth, 2 * rbi / MARGIN,
             "the shank is narrower than the big-end bore so it misses the bolt bosses")
    _at_most(c, "shank_width" if p.shank_section == "I" else "shank_depth", width,
             min(p.big_end_width, p.small_end_width), "the shank is no wider than the eyes")
    _at_most(c, "shank_flange_thickness", p.shank_flange_thickness, 0.4 * p.shank_depth,
             "two flanges must leave a web between them")
    _at_most(c, "shank_web_thickness", p.shank_web_thickness, 0.8 * p.shank_width, "the web is thinner than the flanges are wide")
    if p.shank_fillet > 0:
        room = min(p.shank_depth / 2 - p.shank_flange_thickness, (p.shank_width - p.shank_web_thickness) / 2)
        _at_most(c, "shank_fillet", p.shank_fillet, 0.5 * room, "half the free corner of the section")
    if p.small_end_fillet > 0:
        # the fillet runs onto the eye's cylinder beside the flanges (along z) and must end
        # before the eye's face
        zmax = (p.shank_width if p.shank_section == "I" else p.shank_depth) / 2
        _at_most(c, "small_end_fillet", p.small_end_fillet, (p.small_end_width / 2 - zmax) / MARGIN,
                 "the fillet must end on the eye's cylinder, before its face, beside the shank")
        lo, hi = (f * p.shank_flange_thickness for f in SMALL_END_FILLET_PER_FLANGE)
        if not lo <= p.small_end_fillet <= hi:
            raise _refuse(c, "small_end_fillet", f"0 or in [{lo:.6g}, {hi:.6g}] m ({SMALL_END_FILLET_PER_FLANGE[0]:g}-"
                          f"{SMALL_END_FILLET_PER_FLANGE[1]:g} x shank_flange_thickness, where OCC's corners "
                          "come out right)", p.small_end_fillet)
    _at_most(c, "bolt_boss_height", p.bolt_boss_height, 2 * math.sqrt(max(rbo ** 2 - (MARGIN * rbi) ** 2, 0.0)),
             "the bosses must start outside the bore")
    if p.bolt_diameter > 0:
        off = bolt_offset(p)  # the builder's own placement
        _at_least(c, "bolt_offset", off, MARGIN * (rbi + p.bolt_diameter / 2), "the bolt hole must miss the bore")
        _at_most(c, "bolt_offset", off, rbo + p.bolt_boss_width - MARGIN * p.bolt_diameter / 2,
                 "the bolt hole must stay inside the boss")
        _at_most(c, "bolt_diameter", p.bolt_diameter, min(0.8 * p.big_end_width, 0.8 * p.bolt_boss_width),
                 "the bolt hole fits the boss")
    check_lengths(c, p)
    return p
