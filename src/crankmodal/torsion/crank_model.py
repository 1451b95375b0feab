"""A torsional chain from crank dimensions: throws and flywheel (seed 004's reduction).

Each throw is a rotor whose inertia is the sum of seed 004 eqs. 2-5 (reciprocating mass, rotating
big-end mass, crankpin, two webs); the flywheel is a bored disc. Every shaft spring is one throw's
Ker Wilson equivalent length at the reference diameter (seed 004: "from the flywheel to the centre
of the crankshaft"), ``k = G J_ref / L_eq``. Rotors run ``throw 1 .. throw n, flywheel``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .chain import TorsionalChain
from .equivalent_length import polar_moment, throw_equivalent_length
from .inertias import (
    crankpin_inertia,
    disc_inertia,
    reciprocating_inertia,
    rectangular_web_polar_moment,
    rotating_inertia,
    web_inertia,
)


@dataclass
class CrankModel:
    """What the crank dimensions give, before the chain is solved.

    Attributes
    ----------
    equivalent_length : float
        One throw's equivalent length at the reference diameter, m.
    reference_diameter : float
        m.
    polar_moment : float
        ``J`` of the reference diameter, m^4.
    stiffness : float
        ``G J / L_eq``, N m/rad.
    throw_parts : dict
        Inertia of each part of one throw, kg m^2 (``reciprocating``, ``rotating``,
        ``crankpin``, ``webs``).
    throw_inertia : float
        Their sum, kg m^2.
    flywheel_inertia : float
        kg m^2.
    chain : TorsionalChain
    """

    equivalent_length: float
    reference_diameter: float
    polar_moment: float
    stiffness: float
    throw_parts: dict
    throw_inertia: float
    flywheel_inertia: float
    chain: TorsionalChain

    def to_dict(self) -> dict:
        return {
            "equivalent_length_m": self.equivalent_length,
            "reference_diameter_m": self.reference_diameter,
            "polar_moment_m4": self.polar_moment,
            "stiffness_Nm_per_rad": self.stiffness,
            "throw_inertias_kgm2": self.throw_parts,
            "throw_inertia_kgm2": self.throw_inertia,
            "flywheel_inertia_kgm2": self.flywheel_inertia,
        }


def throw_parts_inertia(throw: dict, density: float) -> dict:
    """Inertia of each part of one throw (seed 004 eqs. 2-5), kg m^2.

    ``throw`` holds the keys of the ``[torsion.throw]`` table (SI).
    """
    R = throw["crank_radius"]
    web_j = rectangular_web_polar_moment(throw["web_width"], throw["web_below_axis"], throw["web_beyond_axis"])
    return {
        "reciprocating": reciprocating_inertia(throw["reciprocating_mass"], R, throw["reciprocating_factor"]),
        "rotating": rotating_inertia(throw["big_end_mass"], R),
        "crankpin": crankpin_inertia(throw["crankpin_diameter"], throw["crankpin_length"], R, density,
                                     throw["crankpin_bore"]),
        "webs": 2.0 * web_inertia(web_j, throw["web_thickness"], density),
    }


def crank_model(
    throw: dict,
    flywheel: dict,
    shear_modulus: float,
    density: float,
    n_throws: int = 1,
    form: str = "seed004",
    reference_diameter: float | None = None,
) -> CrankModel:
    """Build the chain of ``n_throws`` identical throws and a flywheel.

    Parameters
    ----------
    throw : dict
        ``journal_diameter, journal_length, journal_bore, crankpin_diameter, crankpin_length,
        crankpin_bore, crank_radius, web_thickness, web_width, web_below_axis, web_beyond_axis,
        reciprocating_mass, reciprocating_factor, big_end_mass`` (m, kg).
    flywheel : dict
        ``diameter, thickness, bore`` (m).
    shear_modulus : float
        Pa.
    density : float
        kg/m^3.
    n_throws : int
    form : str
        Equivalent-length coefficients (``seed004`` or ``carter``).
    reference_diameter : float, optional
        Default the journal diameter.

    Raises
    ------
    ParameterError
        By the ``[torsion]`` keys' rules (one rule for scenes and this function): naming
        ``throw.<key>`` or ``flywheel.<key>`` (unknown, missing, out of range; optional keys
        get the scene's defaults), ``shear_modulus``, ``density``, ``n_throws``, ``form`` or
        ``reference_diameter``.
    """
    from .. import arguments as arg
    from .stage import FLYWHEEL_SCHEMA, SCHEMA, THROW_SCHEMA

    throw = arg.table_by("throw", throw, THROW_SCHEMA)
    flywheel = arg.table_by("flywheel", flywheel, FLYWHEEL_SCHEMA)
    shear_modulus = arg.check("shear_modulus", shear_modulus, SCHEMA["G"])
    density = arg.check("density", density, SCHEMA["density"])
    n_throws = arg.check("n_throws", n_throws, SCHEMA["n_throws"])
    form = arg.check("form", form, SCHEMA["equivalent_length_form"])
    reference_diameter = arg.number("reference_diameter", reference_diameter, gt=0.0,
                                    optional=True)
    d_ref = throw["journal_diameter"] if reference_diameter is None else reference_diameter
    l_eq = throw_equivalent_length(
        journal_length=throw["journal_length"],
        journal_diameter=throw["journal_diameter"],
        crankpin_length=throw["crankpin_length"],
        crankpin_diameter=throw["crankpin_diameter"],
        crank_radius=throw["crank_radius"],
        web_thickness=throw["web_thickness"],
        web_width=throw["web_width"],
        journal_bore=throw["journal_bore"],
        crankpin_bore=throw["crankpin_bore"],
        reference_diameter=d_ref,
        form=form,
    )
    j_ref = polar_moment(d_ref)
    k = shear_modulus * j_ref / l_eq
    parts = throw_parts_inertia(throw, density)
    i_throw = sum(parts.values())
    i_fly = disc_inertia(flywheel["diameter"], flywheel["thickness"], density, flywheel["bore"])
    chain = TorsionalChain(
        inertias=[i_throw] * n_throws + [i_fly],
        stiffnesses=[k] * n_throws,
        lengths=[l_eq] * n_throws,
        labels=[f"throw {i + 1}" for i in range(n_throws)] + ["flywheel"],
    )
    return CrankModel(l_eq, d_ref, j_ref, k, parts, i_throw, i_fly, chain)
