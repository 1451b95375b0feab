"""Nominal shear stress of shaft sections and the allowable vibratory stress.

Nominal torsional shear stress of a round section: ``tau = K_t T / Z_p`` with the polar section
modulus ``Z_p = J_p / r = pi (d^4 - d_i^4) / (16 d)`` (or a given ``Z_p`` for a non-round
section, e.g. a crank web) and a stress-concentration factor ``K_t`` (fillet, keyway, oil hole).

Allowable vibratory (alternating) shear stress for infinite life::

    tau_allow = tau_e k_size k_surface k_reliability / SF

``tau_e``: torsional endurance limit of the material (Pa; e.g. ~0.29 x the tensile strength for
steels and nodular irons, or the value of a class rule); Marin factors for size, surface and
reliability (each 1.0 by default = no reduction; Shigley, *Mechanical Engineering Design*, ch. 6
gives them); safety factor ``SF`` 2.0 by default (issue 28: customary for infinite life).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

#: default safety factor on the endurance limit for infinite life
DEFAULT_SAFETY_FACTOR = 2.0


def polar_section_modulus(diameter: float, bore: float = 0.0) -> float:
    """``Z_p = pi (d^4 - d_i^4) / (16 d)`` of a round (hollow) shaft, m^3.

    Raises
    ------
    ParameterError
        ``diameter`` not > 0, or ``bore`` not in [0, diameter).
    """
    if not (math.isfinite(diameter) and diameter > 0):
        raise ParameterError("diameter", f"must be > 0 (m), got {diameter!r}")
    if not (math.isfinite(bore) and 0 <= bore < diameter):
        raise ParameterError("bore", f"must be >= 0 and < diameter ({diameter:g} m), got {bore!r}")
    from .equivalent_length import polar_moment

    return polar_moment(diameter, bore) / (diameter / 2.0)  # J_p / r


@dataclass(frozen=True)
class Section:
    """A shaft section's stress data.

    Attributes
    ----------
    section_modulus : float
        Polar section modulus ``Z_p``, m^3.
    stress_concentration : float
        ``K_t`` >= 1.
    diameter, bore : float or None
        m, when the section is round (for the record).
    """

    section_modulus: float
    stress_concentration: float = 1.0
    diameter: float | None = None
    bore: float | None = None

    def __post_init__(self):
        if not (math.isfinite(self.section_modulus) and self.section_modulus > 0):
            raise ParameterError("section_modulus", f"must be > 0 (m^3), got {self.section_modulus!r}")
        if not (math.isfinite(self.stress_concentration) and self.stress_concentration >= 1.0):
            raise ParameterError("stress_concentration", f"must be >= 1, got {self.stress_concentration!r}")

    @classmethod
    def round(cls, diameter: float, bore: float = 0.0, stress_concentration: float = 1.0):
        return cls(polar_section_modulus(diameter, bore), stress_concentration, diameter, bore)

    def stress(self, torque):
        """Nominal shear stress ``K_t T / Z_p`` (Pa) of a torque (N m)."""
        return self.stress_concentration * np.asarray(torque) / self.section_modulus

    def to_dict(self) -> dict:
        return {"section_modulus_m3": self.section_modulus,
                "stress_concentration": self.stress_concentration,
                "diameter_m": self.diameter, "bore_m": self.bore}


@dataclass(frozen=True)
class Allowable:
    """Allowable vibratory shear stress for infinite life.

    Attributes
    ----------
    endurance_limit : float
        Torsional endurance limit ``tau_e``, Pa.
    size_factor, surface_factor, reliability_factor : float
        Marin factors in (0, 1].
    safety_factor : float
        >= 1 (default 2.0).
    """

    endurance_limit: float
    size_factor: float = 1.0
    surface_factor: float = 1.0
    reliability_factor: float = 1.0
    safety_factor: float = DEFAULT_SAFETY_FACTOR

    def __post_init__(self):
        if not (math.isfinite(self.endurance_limit) and self.endurance_limit > 0):
            raise ParameterError("endurance_limit", f"must be > 0 (Pa), got {self.endurance_limit!r}")
        for name in ("size_factor", "surface_factor", "reliability_factor"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0 < v <= 1):
                raise ParameterError(name, f"must be in (0, 1], got {v!r}")
        if not (math.isfinite(self.safety_factor) and self.safety_factor >= 1):
            raise ParameterError("safety_factor", f"must be >= 1, got {self.safety_factor!r}")

    @property
    def stress(self) -> float:
        """``tau_e k_size k_surface k_reliability / SF``, Pa."""
        return (self.endurance_limit * self.size_factor * self.surface_factor
                * self.reliability_factor / self.safety_factor)

    def to_dict(self) -> dict:
        return {"endurance_limit_pa": self.endurance_limit, "size_factor": self.size_factor,
                "surface_factor": self.surface_factor,
                "reliability_factor": self.reliability_factor,
                "safety_factor": self.safety_factor, "allowable_pa": self.stress}
