"""The crankshaft fatigue verdict: stress over a cycle → criterion → safety factor per location.

:func:`fatigue_verdict` takes plain arrays (stress modes, modal coordinates over one steady
cycle, the points' coordinates, the surface points and their locations) and a material with
fatigue data, and returns a :class:`~crankmodal.fatigue.result.FatigueResult`. The steps:
:func:`~crankmodal.fatigue.cycle.cycle_extremes` (chunked), the criterion of
:mod:`crankmodal.fatigue.criterion` with the factors of :mod:`crankmodal.fatigue.factors`, and a
yield check (largest von Mises stress over the cycle against the yield strength).
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError, warn
from .criterion import (
    MEAN_STRESS,
    RULES,
    equivalent_alternating,
    equivalent_mean,
    mean_and_amplitude,
    safety_factor,
)
from .cycle import MEMORY_BYTES, cycle_extremes
from .factors import FatigueFactors
from .result import FatigueResult

#: below this proportionality at the worst point the verdict warns (see FatigueResult)
PROPORTIONAL = 0.95


def _strengths(material):
    from ..fem.materials import Material

    if not isinstance(material, Material):
        raise ParameterError("material", f"must be a Material (crankmodal.material(name) or "
                                         f"Material(...)), got {type(material).__name__}")
    if material.fatigue_strength is None:
        raise ParameterError("fatigue_strength", f"material {material.name!r} has no fatigue "
                             f"data: give Material(..., fatigue_strength=...) (Pa, fully "
                             f"reversed, unnotched) or a library material that has it "
                             f"(42CrMo, crank_steel_seed000, SG 700/2)")
    if material.ultimate_strength is None:
        raise ParameterError("ultimate_strength", f"material {material.name!r} has no "
                                                  f"ultimate strength (the mean-stress line needs it)")
    return material


def fatigue_verdict(stress_modes, modal_coordinates, material, points, *, nodes=None,
                    locations=None, factors: FatigueFactors | None = None,
                    static_stress=None, rule: str = "goodman", mean_stress: str = "sines",
                    memory_bytes: float = MEMORY_BYTES, warnings: list | None = None
                    ) -> FatigueResult:
    """Fatigue safety factor at every point asked for, and per location.

    Parameters
    ----------
    stress_modes : ndarray, shape (n_points, 6, n_modes)
        Pa per unit modal coordinate, Voigt xx, yy, zz, yz, xz, xy (a flexible body's
        ``stress_modes``; a unit-load static stress field is a mode too).
    modal_coordinates : ndarray, shape (n_modes, n_times)
        ξ(t) over one steady cycle.
    material : Material
        With ``fatigue_strength`` and ``ultimate_strength`` (``yield_strength`` for the yield
        check), Pa.
    points : ndarray, shape (n_points, 3)
        The stress modes' points, m (the part's frame).
    nodes : ndarray of int, optional
        The points assessed (e.g. the surface nodes); default all.
    locations : CrankLocations, optional
        Location of each of ``nodes`` (:func:`~crankmodal.fatigue.locations.crank_locations`);
        default: none named.
    factors : FatigueFactors, optional
        Marin factors and notch factor (default: all 1).
    static_stress : ndarray, shape (n_points, 6), optional
        Constant stress added over the cycle, Pa.
    rule : str
        ``goodman`` or ``gerber``.
    mean_stress : str
        ``sines`` (first invariant of the mean tensor) or ``signed_von_mises``.
    memory_bytes : float
        Bound on the stress history held at once, bytes.
    warnings : list, optional
        Receives the texts of the warnings issued (a stage's ``warnings``).

    Returns
    -------
    FatigueResult

    Raises
    ------
    ParameterError
        Naming ``fatigue_strength`` (material without fatigue data), ``ultimate_strength``,
        ``material``, ``stress_modes``, ``modal_coordinates``, ``static_stress``, ``nodes``,
        ``points``, ``locations``, ``factors``, ``rule`` or ``mean_stress``.

    Examples
    --------
    A bar in pure alternating shear of 100 MPa amplitude (one "mode": the stress per unit
    coordinate), SG 700/2 (280 MPa fully reversed): ``n = 280 / (sqrt(3) 100)``.

    >>> import numpy as np
    >>> from crankmodal.fem.materials import material
    >>> S = np.zeros((1, 6, 1)); S[0, 5, 0] = 1e8          # xy shear, Pa per unit ξ
    >>> xi = np.sin(np.linspace(0, 2 * np.pi, 361))[None, :]
    >>> res = fatigue_verdict(S, xi, material("SG 700/2"), np.zeros((1, 3)))
    >>> round(res.min_safety_factor, 4), round(280 / (3 ** 0.5 * 100), 4)
    (1.6166, 1.6166)
    """
    mat = _strengths(material)
    notes: list[str] = []
    factors = FatigueFactors() if factors is None else factors
    if not isinstance(factors, FatigueFactors):
        raise ParameterError("factors", f"must be FatigueFactors, got {type(factors).__name__}")
    if rule not in RULES:
        raise ParameterError("rule", f"must be one of {', '.join(RULES)}; got {rule!r}")
    if mean_stress not in MEAN_STRESS:
        raise ParameterError("mean_stress", f"must be one of {', '.join(MEAN_STRESS)}; got "
                                            f"{mean_stress!r}")
    ext = cycle_extremes(stress_modes, modal_coordinates, static_stress, nodes, memory_bytes)
    n_points = np.shape(stress_modes)[0]
    pts = np.asarray(points, float) if np.asarray(points).dtype.kind in "fiu" else None
    if pts is None or pts.shape != (n_points, 3) or not np.all(np.isfinite(pts)):
        raise ParameterError("points", f"must be ({n_points}, 3) finite coordinates (m), one "
                                       f"per stress-mode point, got {np.shape(points)}")
    idx = np.arange(n_points) if nodes is None else np.asarray(nodes, np.int64)
    names, kinds, label = [], [], np.full(len(idx), -1, np.int64)
    if locations is not None:
        lab = np.asarray(getattr(locations, "label", None))
        if lab.shape != (len(idx),):
            raise ParameterError("locations", f"must label the {len(idx)} nodes assessed, got "
                                              f"{lab.shape} labels")
        names, kinds, label = list(locations.names), list(locations.kinds), lab.astype(np.int64)
        if not locations.fillet_modelled and factors.notch == 1.0:
            warn("fatigue: the crank's fillets are not in the FE model (sharp corners): their "
                 "stress is mesh-dependent; give factors.notch (K_f) from a fillet chart, or "
                 "mesh the full fidelity fine enough to resolve them", notes)
    kf = factors.notch
    mean, amp = mean_and_amplitude(ext.stress_max, ext.stress_min)
    sa = kf * equivalent_alternating(amp)
    sm = kf * equivalent_mean(mean, mean_stress)
    se = factors.corrected(mat.fatigue_strength)
    n = safety_factor(sa, sm, se, mat.ultimate_strength, rule)
    vm_amp = sa / kf
    with np.errstate(divide="ignore", invalid="ignore"):
        prop = np.where(vm_amp > 0, np.minimum(ext.max_deviation_von_mises / vm_amp, 1.0), 1.0)
    w = int(np.argmin(n))
    if prop[w] < PROPORTIONAL:
        warn(f"fatigue: the loading at the worst point ({pts[idx[w]].round(5).tolist()} m) is "
             f"non-proportional: the largest von Mises stress of sigma(t) - sigma_m is "
             f"{prop[w]:.3g} of that of the component-wise amplitude, so the verdict there is "
             f"conservative by up to {1 / prop[w]:.3g}x (a critical-plane criterion would tell)",
             notes)
    if mat.yield_strength is not None:
        with np.errstate(divide="ignore"):
            ny = np.where(ext.max_von_mises > 0, mat.yield_strength / ext.max_von_mises, np.inf)
        i = int(np.argmin(ny))
        if ny[i] < 1.0:
            warn(f"fatigue: the stress passes the yield strength ({mat.yield_strength / 1e6:.4g} "
                 f"MPa) at {int((ny < 1).sum())} point(s), von Mises {ext.max_von_mises[i] / 1e6:.4g}"
                 f" MPa at {pts[idx[i]].round(5).tolist()} m: the linear stress and the "
                 f"fatigue verdict are not valid there", notes)
    else:
        ny = np.full(len(idx), np.nan)
        warn(f"fatigue: material {mat.name!r} has no yield strength; the yield check is skipped",
             notes)
    if mat.fatigue_strength_torsion is not None and \
            mat.fatigue_strength_torsion < 0.98 * mat.fatigue_strength / 3 ** 0.5:
        warn(f"fatigue: {mat.name!r}'s torsional fatigue strength "
             f"({mat.fatigue_strength_torsion / 1e6:.4g} MPa) is below von Mises' "
             f"fatigue_strength/sqrt(3) ({mat.fatigue_strength / 3 ** 0.5 / 1e6:.4g} MPa): the "
             f"von Mises criterion is unconservative where shear dominates", notes)
    if warnings is not None:
        warnings.extend(notes)
    return FatigueResult(
        nodes=idx, points=pts[idx], safety_factor=n, alternating=sa, mean=sm,
        max_von_mises=ext.max_von_mises, yield_safety_factor=ny, proportionality=prop,
        location_names=names, location_kinds=kinds, label=label,
        fatigue_strength=se, specimen_fatigue_strength=mat.fatigue_strength,
        ultimate_strength=mat.ultimate_strength,
        yield_strength=mat.yield_strength if mat.yield_strength is not None else float("nan"),
        factors=factors.to_dict(), rule=rule, mean_stress=mean_stress, material=mat.name,
        warnings=notes)
