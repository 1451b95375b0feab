"""The fatigue criterion: mean and alternating stress tensors, their equivalents, Goodman/Gerber.

Per point, from the largest and smallest value of every stress component over one steady cycle:

    σ_m = (max + min) / 2,   σ_a = (max − min) / 2      (component-wise, Voigt)

Equivalent alternating stress: the von Mises stress of the amplitude tensor ``σ_a``. Equivalent
mean stress (``mean_stress``):

- ``"sines"`` (default): the first invariant of the mean tensor, ``σ_xx,m + σ_yy,m + σ_zz,m``
  (Sines 1959: a mean shear stress does not lower the fatigue strength, a mean hydrostatic
  tension does; uniaxially it is the mean stress itself);
- ``"signed_von_mises"``: the von Mises stress of ``σ_m`` with the sign of its first invariant
  (conservative for mean shear).

Mean-stress correction (``rule``), with ``S_e`` the corrected fatigue strength and ``S_u`` the
ultimate strength, the safety factor ``n`` scales mean and alternating stress together:

- Goodman: ``σ_a / S_e + σ_m / S_u = 1 / n``;
- Gerber: ``n σ_a / S_e + (n σ_m / S_u)² = 1``, i.e. ``n = ½ (S_u/σ_m)² (σ_a/S_e)
  [−1 + sqrt(1 + (2 σ_m S_e / (S_u σ_a))²)]``;
- for a compressive equivalent mean (``σ_m < 0``) both give ``n = S_e / σ_a`` (no credit is
  taken for compression; Shigley §6-12).

Limit: the component-wise amplitude is exact for proportional loading (every component a
multiple of one time function, e.g. one load case or one mode). Under non-proportional loading
(principal axes that turn over the cycle: bending and torsion out of phase) it over-estimates
the amplitude of no plane in particular and is generally conservative, but it is not a
critical-plane criterion (Findley, Dang Van) and does not see the amplitude's rotation.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..reduction.stress_modes import von_mises

MEAN_STRESS = ("sines", "signed_von_mises")
RULES = ("goodman", "gerber")


def mean_and_amplitude(stress_max: np.ndarray, stress_min: np.ndarray):
    """Component-wise mean and amplitude tensors, Pa.

    Parameters
    ----------
    stress_max, stress_min : ndarray, shape (n, 6)
        Largest and smallest value of each Voigt component over the cycle, Pa.

    Returns
    -------
    mean, amplitude : ndarray, shape (n, 6)
        Pa.
    """
    return 0.5 * (stress_max + stress_min), 0.5 * (stress_max - stress_min)


def equivalent_alternating(amplitude: np.ndarray) -> np.ndarray:
    """Von Mises stress of the amplitude tensors (n, 6), Pa."""
    return von_mises(amplitude, axis=1)


def equivalent_mean(mean: np.ndarray, rule: str = "sines") -> np.ndarray:
    """Equivalent mean stress of the mean tensors (n, 6), Pa (see the module docstring)."""
    if rule not in MEAN_STRESS:
        raise ParameterError("mean_stress", f"must be one of {', '.join(MEAN_STRESS)}; got {rule!r}")
    first = mean[:, 0] + mean[:, 1] + mean[:, 2]
    if rule == "sines":
        return first
    return np.where(first < 0, -1.0, 1.0) * von_mises(mean, axis=1)


def safety_factor(alternating, mean, fatigue_strength: float, ultimate_strength: float,
                  rule: str = "goodman") -> np.ndarray:
    """Fatigue safety factor on a proportional load line (mean and alternating scaled together).

    Parameters
    ----------
    alternating : array_like
        Equivalent alternating stress, Pa (>= 0), notch factor already applied.
    mean : array_like
        Equivalent mean stress, Pa, notch factor already applied.
    fatigue_strength : float
        Corrected fatigue strength ``S_e``, Pa.
    ultimate_strength : float
        ``S_u``, Pa.
    rule : str
        ``goodman`` or ``gerber``.

    Returns
    -------
    ndarray
        ``n``; ``inf`` where both stresses are zero.
    """
    if rule not in RULES:
        raise ParameterError("rule", f"must be one of {', '.join(RULES)}; got {rule!r}")
    sa = np.asarray(alternating, float)
    sm = np.asarray(mean, float)
    se, su = float(fatigue_strength), float(ultimate_strength)
    pos = np.maximum(sm, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        if rule == "goodman":
            n = 1.0 / (sa / se + pos / su)
        else:
            x = 2.0 * pos * se / (su * sa)
            n = 0.5 * (su / pos) ** 2 * (sa / se) * (-1.0 + np.sqrt(1.0 + x * x))
            # σ_m → 0: the bracket loses all digits; its limit is the fully reversed S_e / σ_a.
            # σ_a → 0: the limit is S_u / σ_m. Both taken where the series is exact enough.
            small = x < 1e-4
            n = np.where(small, se / sa, n)
            n = np.where(sa == 0, su / pos, n)
    return np.where((sa == 0) & (pos == 0), np.inf, n)
