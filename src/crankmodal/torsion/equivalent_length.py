"""Equivalent shaft length of crank throws and shaft segments (Ker Wilson / Carter form).

A crankshaft is replaced, for torsion, by a straight shaft of one *reference diameter* ``d_ref``
whose length gives the same twist under the same torque. A plain segment of diameter ``d``
(bore ``d_i``) and length ``l`` counts as ``l d_ref**4 / (d**4 - d_i**4)``; a crank throw adds
its webs through an empirical term. The form of seed 004 eq. 1 (Ker Wilson), with hollow pins::

    L_eq = (2 B + c_e (T1 + T2)) d_ref^4 / (d_j^4 - d_ji^4)
           + c_p l_p d_ref^4 / (d_p^4 - d_pi^4)
           + c_w R d_ref^4 (1 / (T1 W^3) + 1 / (T2 W^3))

with ``(c_e, c_p, c_w) = (0.4, 3.288, 1.284)`` as printed in seed 004 and ``(0.4, 0.75, 0.75)``
for Carter's formula (``2b + 0.8 h + 0.75 a (D/d)^4 + 1.5 r D^4 / (h w^3)``). The seed prints
the web term as ``d_j^4 / (T W)``, which has units of mm^3, not mm; the web width enters cubed in
Carter's and Ker Wilson's formulas and is used cubed here.

All lengths in m, shear modulus in Pa, stiffness in N m/rad.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

#: (c_e, c_p, c_w) of the throw formula, by name.
THROW_FORMS: dict[str, tuple[float, float, float]] = {
    "seed004": (0.4, 3.288, 1.284),
    "carter": (0.4, 0.75, 0.75),
}


def polar_moment(diameter: float, bore: float = 0.0) -> float:
    """Polar second moment of area of a (hollow) circular section, m^4.

    Parameters
    ----------
    diameter : float
        Outer diameter, m.
    bore : float
        Inner diameter, m (0 for a solid section).
    """
    if not (diameter > 0.0 and 0.0 <= bore < diameter):
        raise ValueError(f"need diameter > bore >= 0, got diameter={diameter}, bore={bore}")
    return math.pi / 32.0 * (diameter**4 - bore**4)


def equivalent_segment_length(
    length: float, diameter: float, reference_diameter: float, bore: float = 0.0
) -> float:
    """Length of the reference-diameter shaft as stiff as a plain segment, m."""
    return length * polar_moment(reference_diameter) / polar_moment(diameter, bore)


def throw_equivalent_length(
    journal_length: float,
    journal_diameter: float,
    crankpin_length: float,
    crankpin_diameter: float,
    crank_radius: float,
    web_thickness: float | tuple[float, float],
    web_width: float,
    journal_bore: float = 0.0,
    crankpin_bore: float = 0.0,
    reference_diameter: float | None = None,
    form: str = "seed004",
) -> float:
    """Equivalent length of one crank throw (seed 004 eq. 1, hollow pins allowed), m.

    Parameters
    ----------
    journal_length : float
        ``B``: journal length on each side of the throw (the formula counts ``2 B``), m.
    journal_diameter, journal_bore : float
        ``d_j`` and its bore, m.
    crankpin_length : float
        ``l_p``, m.
    crankpin_diameter, crankpin_bore : float
        ``d_p`` and its bore, m.
    crank_radius : float
        ``R``, crank throw radius, m.
    web_thickness : float or (float, float)
        ``T1, T2`` (one value: both webs alike), m.
    web_width : float
        ``W``, m.
    reference_diameter : float, optional
        Diameter the length is referred to; default ``d_j`` (as in the seed).
    form : str
        ``"seed004"`` or ``"carter"`` coefficients, see :data:`THROW_FORMS`.

    Returns
    -------
    float
        Equivalent length at the reference diameter, m.
    """
    if form not in THROW_FORMS:
        raise ValueError(f"form must be one of {', '.join(THROW_FORMS)}, got {form!r}")
    c_e, c_p, c_w = THROW_FORMS[form]
    t1, t2 = (web_thickness, web_thickness) if isinstance(web_thickness, (int, float)) else web_thickness
    d_ref = journal_diameter if reference_diameter is None else reference_diameter
    j_ref = polar_moment(d_ref)
    journal = (2.0 * journal_length + c_e * (t1 + t2)) * j_ref / polar_moment(journal_diameter, journal_bore)
    pin = c_p * crankpin_length * j_ref / polar_moment(crankpin_diameter, crankpin_bore)
    webs = c_w * crank_radius * d_ref**4 * (1.0 / (t1 * web_width**3) + 1.0 / (t2 * web_width**3))
    return journal + pin + webs


def shaft_stiffness(shear_modulus: float, diameter: float, length: float, bore: float = 0.0) -> float:
    """Torsional stiffness ``G J / L`` of a circular shaft, N m/rad."""
    if not (shear_modulus > 0.0 and length > 0.0):
        raise ValueError(f"need G > 0 and length > 0, got G={shear_modulus}, length={length}")
    return shear_modulus * polar_moment(diameter, bore) / length


def series_stiffness(stiffnesses: Sequence[float]) -> float:
    """Stiffness of springs in series, ``1 / sum(1/k_i)``, N m/rad."""
    return 1.0 / sum(1.0 / k for k in stiffnesses)


def segments_stiffness(segments: Sequence[dict]) -> list[float]:
    """Stiffness of each shaft segment ``{"diameter", "length", "G", "bore"?}``, N m/rad."""
    return [
        shaft_stiffness(s["G"], s["diameter"], s["length"], s.get("bore", 0.0) or 0.0)
        for s in segments
    ]
