"""Isotropic linear-elastic materials and the TOML material library.

>>> m = material("SG 700/2")
>>> round(m.E / 1e9), m.nu, m.rho
(176, 0.275, 7200.0)
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ..errors import ParameterError

LIBRARY = Path(__file__).with_name("materials.toml")


@dataclass(frozen=True)
class Material:
    """An isotropic linear-elastic material.

    Attributes
    ----------
    name : str
    E : float
        Young's modulus, Pa.
    nu : float
        Poisson's ratio, in (-1, 0.5).
    rho : float
        Density, kg/m³.
    yield_strength, ultimate_strength : float or None
        Pa; safety factors need them.
    description : str
    fatigue_strength : float or None
        Fully reversed (R = -1) fatigue strength of unnotched, polished specimens, Pa, at
        ``fatigue_cycles`` (bending or axial, as the library's comment says); the crankshaft
        fatigue verdict (:mod:`crankmodal.fatigue`) needs it.
    fatigue_strength_torsion : float or None
        Fully reversed torsional fatigue strength, Pa; None: derived by von Mises,
        ``fatigue_strength / sqrt(3)`` (:attr:`torsional_fatigue_strength`).
    fatigue_cycles : float or None
        Number of cycles at which the fatigue strengths hold (e.g. 1e7).

    Raises
    ------
    ParameterError
        Naming the argument (``E``, ``nu``, ``rho``, ``yield_strength``,
        ``ultimate_strength``) out of its range; the ``[material]`` stage re-raises it as
        ``material.<key>``.
    """

    name: str
    E: float
    nu: float
    rho: float
    yield_strength: float | None = None
    ultimate_strength: float | None = None
    description: str = ""
    fatigue_strength: float | None = None
    fatigue_strength_torsion: float | None = None
    fatigue_cycles: float | None = None

    def __post_init__(self):
        import math
        from numbers import Real

        for key, optional in (("E", False), ("nu", False), ("rho", False),
                              ("yield_strength", True), ("ultimate_strength", True),
                              ("fatigue_strength", True), ("fatigue_strength_torsion", True),
                              ("fatigue_cycles", True)):
            v = getattr(self, key)
            if v is None and optional:
                continue
            if isinstance(v, bool) or not isinstance(v, Real) or not math.isfinite(v):
                raise ParameterError(key, f"must be a finite number, got {v!r} ({self.name})")
            object.__setattr__(self, key, float(v))
        for key, value, ok, text in (
            ("E", self.E, self.E > 0, "> 0 Pa"),
            ("nu", self.nu, -1.0 < self.nu < 0.5, "in (-1, 0.5)"),
            ("rho", self.rho, self.rho > 0, "> 0 kg/m^3"),
        ):
            if not ok:
                raise ParameterError(key, f"must be {text}, got {value!r} ({self.name})")
        for key in ("yield_strength", "ultimate_strength", "fatigue_strength",
                    "fatigue_strength_torsion"):
            v = getattr(self, key)
            if v is not None and not v > 0:
                raise ParameterError(key, f"must be > 0 Pa, got {v!r} ({self.name})")
        if self.fatigue_cycles is not None and not self.fatigue_cycles >= 1:
            raise ParameterError("fatigue_cycles", f"must be >= 1, got {self.fatigue_cycles!r} "
                                                   f"({self.name})")

    @property
    def lame(self) -> tuple[float, float]:
        """Lamé parameters (λ, μ), Pa."""
        return lame_parameters(self.E, self.nu)

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + ν)), Pa."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def torsional_fatigue_strength(self) -> float | None:
        """Fully reversed torsional fatigue strength, Pa: ``fatigue_strength_torsion`` if given,
        else the von Mises value ``fatigue_strength / sqrt(3)``; None without fatigue data."""
        if self.fatigue_strength_torsion is not None:
            return self.fatigue_strength_torsion
        if self.fatigue_strength is None:
            return None
        return self.fatigue_strength / 3.0 ** 0.5

    def to_dict(self) -> dict:
        return {
            "name": self.name, "E_pa": self.E, "nu": self.nu, "rho_kg_m3": self.rho,
            "yield_strength_pa": self.yield_strength,
            "ultimate_strength_pa": self.ultimate_strength,
            "fatigue_strength_pa": self.fatigue_strength,
            "fatigue_strength_torsion_pa": self.torsional_fatigue_strength,
            "fatigue_cycles": self.fatigue_cycles,
            "description": self.description,
        }


def lame_parameters(E: float, nu: float) -> tuple[float, float]:
    """Lamé parameters (λ, μ) in Pa from Young's modulus (Pa) and Poisson's ratio."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


@lru_cache(maxsize=1)
def library() -> dict[str, dict]:
    """The material library as raw tables, keyed by name."""
    with open(LIBRARY, "rb") as fh:
        return tomllib.load(fh)


def material(name: str) -> Material:
    """A material of the library by name (case-insensitive).

    Parameters
    ----------
    name : str
        A name of the library (``steel``, ``42CrMo``, ...).

    Returns
    -------
    Material
        E and the strengths in Pa, rho in kg/m^3.

    Examples
    --------
    >>> import crankmodal as cm
    >>> steel = cm.material("Steel")
    >>> steel.E, steel.nu, steel.rho
    (210000000000.0, 0.3, 7850.0)

    Raises
    ------
    ParameterError
        Naming ``name`` if it is not in the library; the message lists the known names (the
        ``[material]`` stage re-raises it as ``material.name``).
    """
    lib = library()
    by_lower = {k.lower(): k for k in lib}
    key = by_lower.get(str(name).strip().lower())
    if key is None:
        raise ParameterError("name", f"unknown material {name!r}; known: {', '.join(lib)}")
    return Material(name=key, **lib[key])
