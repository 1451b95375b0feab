"""Marin-type factors: from a specimen's fatigue strength to the part's.

The corrected (component) fatigue strength is

    S_e = k_surface k_size k_reliability k_other S_f

with ``S_f`` the material's fully reversed fatigue strength of unnotched polished specimens
(:attr:`crankmodal.fem.materials.Material.fatigue_strength`). A notch that the FE mesh does not
resolve (a fillet left out, a coarse mesh, an oil hole not drilled in the model) enters as the
fatigue notch factor ``K_f`` on the stresses, mean and alternating alike (Shigley's ``K_fm = K_f``
for a notch that does not yield). Where the mesh resolves the fillet the FE stress already is
the notch stress: keep ``notch_factor = 1`` there, or the notch is counted twice.

The helpers give the customary estimates (Shigley, *Mechanical Engineering Design*, 9th ed.,
§6-9): :func:`surface_factor` (eq. 6-19, Table 6-2), :func:`size_factor` (eq. 6-20, bending and
torsion of a round section) and :func:`reliability_factor` (Table 6-5).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ..errors import ParameterError

#: Shigley Table 6-2: ``k_a = a S_ut^b`` with S_ut in MPa
SURFACE_FINISH = {"ground": (1.58, -0.085), "machined": (4.51, -0.265),
                  "cold-drawn": (4.51, -0.265), "hot-rolled": (57.7, -0.718),
                  "as-forged": (272.0, -0.995)}
#: Shigley Table 6-5: reliability -> k_e (normal scatter of 8 % of the endurance limit)
RELIABILITY = {0.5: 1.0, 0.9: 0.897, 0.95: 0.868, 0.99: 0.814, 0.999: 0.753, 0.9999: 0.702,
               0.99999: 0.659, 0.999999: 0.620}


def _positive(name: str, value, hi: float | None = None) -> float:
    from numbers import Real

    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
        raise ParameterError(name, f"must be a finite number, got {value!r}")
    if not value > 0 or (hi is not None and value > hi):
        raise ParameterError(name, f"must be in (0, {hi:g}], got {value!r}" if hi is not None
                             else f"must be > 0, got {value!r}")
    return float(value)


def surface_factor(ultimate_strength: float, finish: str) -> float:
    """Marin surface factor ``k_a = a S_ut^b`` (Shigley eq. 6-19, Table 6-2), at most 1.

    Parameters
    ----------
    ultimate_strength : float
        Ultimate tensile strength, Pa.
    finish : str
        ``ground``, ``machined`` (or ``cold-drawn``), ``hot-rolled``, ``as-forged``.

    Returns
    -------
    float
        Dimensionless.
    """
    s = _positive("ultimate_strength", ultimate_strength)
    if finish not in SURFACE_FINISH:
        raise ParameterError("finish", f"must be one of {', '.join(SURFACE_FINISH)}; got {finish!r}")
    a, b = SURFACE_FINISH[finish]
    return min(1.0, a * (s / 1e6) ** b)


def size_factor(diameter: float) -> float:
    """Marin size factor of a round section in bending or torsion (Shigley eq. 6-20).

    ``k_b = (d / 7.62 mm)^-0.107`` for 2.79 <= d <= 51 mm, ``1.51 d^-0.157`` (d in mm) for
    51 < d <= 254 mm; 1 below 2.79 mm. Larger diameters are refused (outside the fit).

    Parameters
    ----------
    diameter : float
        m.
    """
    d = _positive("diameter", diameter) * 1e3
    if d > 254.0:
        raise ParameterError("diameter", f"must be <= 0.254 m (the fit's range), got {diameter!r}")
    if d < 2.79:
        return 1.0
    if d <= 51.0:
        return (d / 7.62) ** -0.107
    return 1.51 * d ** -0.157


def reliability_factor(reliability: float) -> float:
    """Marin reliability factor (Shigley Table 6-5; one of its tabulated reliabilities).

    Parameters
    ----------
    reliability : float
        0.5, 0.9, 0.95, 0.99, 0.999, ... (probability of survival).
    """
    for r, k in RELIABILITY.items():
        if isinstance(reliability, (int, float)) and not isinstance(reliability, bool) \
                and math.isclose(r, reliability, rel_tol=0, abs_tol=1e-12):
            return k
    raise ParameterError("reliability", f"must be one of {', '.join(map(str, RELIABILITY))}; "
                                        f"got {reliability!r}")


@dataclass(frozen=True)
class FatigueFactors:
    """The factors of the verdict (all dimensionless).

    Attributes
    ----------
    surface, size, reliability, other : float
        Marin factors in (0, 1] on the fatigue strength (``other``: temperature, environment,
        whatever else the engineer applies). Default 1: no reduction.
    notch : float
        Fatigue notch factor ``K_f >= 1`` on the stresses, for a notch the mesh does not
        resolve. 1 where the FE mesh resolves it (the FE stress then is the notch stress).
    """

    surface: float = 1.0
    size: float = 1.0
    reliability: float = 1.0
    other: float = 1.0
    notch: float = 1.0

    def __post_init__(self):
        for name in ("surface", "size", "reliability", "other"):
            object.__setattr__(self, name, _positive(name, getattr(self, name), 1.0))
        notch = _positive("notch", self.notch)
        if notch < 1.0:
            raise ParameterError("notch", f"must be >= 1 (a fatigue notch factor), got {notch!r}")
        object.__setattr__(self, "notch", notch)

    @property
    def strength_factor(self) -> float:
        """``k_surface k_size k_reliability k_other``."""
        return self.surface * self.size * self.reliability * self.other

    def corrected(self, fatigue_strength: float) -> float:
        """The part's fatigue strength ``S_e`` (Pa) from the specimen's (Pa)."""
        return self.strength_factor * fatigue_strength

    def to_dict(self) -> dict:
        return asdict(self)
