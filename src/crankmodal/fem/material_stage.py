"""The ``[material]`` scene section: a library material by ``name``, or explicit E, ν, ρ.

Explicit values override the named material's; strengths (Pa) are needed for safety factors.
Puts the :class:`~crankmodal.fem.materials.Material` in ``ctx.products["material"]``.
"""

from __future__ import annotations

from ..errors import SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table

SECTION = "material"
REQUIRES = ()

SCHEMA: dict[str, Field] = {
    "name": Field("str", None, "material of the library (crankmodal/fem/materials.toml), e.g. 'SG 700/2'"),
    "E": Field("float", None, "Young's modulus, Pa", gt=0.0),
    "nu": Field("float", None, "Poisson's ratio", gt=-1.0, lt=0.5),
    "rho": Field("float", None, "density, kg/m^3", gt=0.0),
    "yield_strength": Field("float", None, "yield (0.2 % proof) strength, Pa", gt=0.0),
    "ultimate_strength": Field("float", None, "ultimate tensile strength, Pa", gt=0.0),
    "fatigue_strength": Field("float", None, "fully reversed fatigue strength of unnotched "
                              "specimens, Pa (the crankshaft fatigue verdict needs it)", gt=0.0),
    "fatigue_strength_torsion": Field("float", None, "fully reversed torsional fatigue strength, "
                                      "Pa (default fatigue_strength / sqrt(3))", gt=0.0),
    "fatigue_cycles": Field("float", None, "cycles at which the fatigue strengths hold", ge=1.0),
}


def validate(raw: dict, scene) -> dict:
    from .materials import material

    p = validate_table(SECTION, raw, SCHEMA)
    if p["name"] is not None:
        with scene_keys(SECTION):  # unknown name -> material.name: ...
            material(p["name"])
    else:
        missing = [k for k in ("E", "nu", "rho") if p[k] is None]
        if missing:
            raise SceneError(f"material.{missing[0]}: is required when no 'name' is given "
                             f"(give name = one of the library, or E, nu and rho)")
    return p


def make_material(p: dict):
    """The Material a validated ``[material]`` table describes."""
    from dataclasses import replace

    from .materials import Material, material

    over = {k: p[k] for k in ("E", "nu", "rho", "yield_strength", "ultimate_strength",
                              "fatigue_strength", "fatigue_strength_torsion", "fatigue_cycles")
            if p.get(k) is not None}
    with scene_keys(SECTION):  # the Material's own checks, named by their scene keys
        if p.get("name"):
            base = material(p["name"])
            return replace(base, **over) if over else base
        return Material(name="custom", **over)


def run(p: dict, ctx) -> dict:
    mat = make_material(p)
    ctx.products[SECTION] = mat
    summary = f"{mat.name}: E {mat.E / 1e9:.4g} GPa, nu {mat.nu:.4g}, rho {mat.rho:.5g} kg/m^3"
    return {**mat.to_dict(), "summary": summary}
