"""Mass moments of inertia about the shaft axis: crank throw parts, flywheel, CAD solids.

Seed 004 (after Heldt) lumps at each throw:

- eq. 2, reciprocating parts: ``I_rec = c m_rec R^2`` with ``c = 0.508``; the mean over a
  revolution of the reciprocating parts' equivalent inertia is ``m R^2 (1/2 + lambda^2/8 + ...)``
  with ``lambda = R / l_rod``, so 0.508 corresponds to ``lambda ~ 0.25``;
- eq. 3, the rotating (big-end, ~2/3 of the rod) mass: ``I_rot = m_be R^2``;
- eq. 4, crankpin about the shaft axis by the parallel-axis theorem. The seed prints
  ``(pi/32 d^4 l + 8 R^2 d^2) rho``, whose second term has units mm^4 rather than mm^5; the
  parallel-axis term of a cylinder of mass ``rho pi/4 d^2 l`` is ``rho pi/4 d^2 l R^2``, used here;
- eq. 5, crank webs: (polar second moment of the web outline about the shaft axis) x T x rho.

All inputs SI (m, kg, kg/m^3); results in kg m^2.
"""

from __future__ import annotations

import math

import numpy as np

#: Seed 004 eq. 2 factor of the reciprocating mass.
SEED_RECIPROCATING_FACTOR = 0.508


def reciprocating_factor(crank_radius: float, rod_length: float) -> float:
    """Mean equivalent-inertia factor ``1/2 + lambda^2/8`` of reciprocating parts (dimensionless)."""
    lam = crank_radius / rod_length
    return 0.5 + lam**2 / 8.0


def reciprocating_inertia(
    mass: float, crank_radius: float, factor: float = SEED_RECIPROCATING_FACTOR
) -> float:
    """Equivalent inertia of the reciprocating mass, seed 004 eq. 2, kg m^2.

    Parameters
    ----------
    mass : float
        Piston, crosshead, nuts and the reciprocating third of the rod, kg.
    crank_radius : float
        m.
    factor : float
        0.508 in the seed; see :func:`reciprocating_factor`.
    """
    return factor * mass * crank_radius**2


def rotating_inertia(mass: float, crank_radius: float) -> float:
    """Inertia of the rotating big-end mass at the crank radius, seed 004 eq. 3, kg m^2."""
    return mass * crank_radius**2


def crankpin_inertia(
    diameter: float, length: float, crank_radius: float, density: float, bore: float = 0.0
) -> float:
    """Inertia of a (hollow) crankpin about the shaft axis, seed 004 eq. 4 (parallel axis), kg m^2."""
    own = math.pi / 32.0 * (diameter**4 - bore**4) * length
    offset = math.pi / 4.0 * (diameter**2 - bore**2) * length * crank_radius**2
    return density * (own + offset)


def web_inertia(polar_area_moment: float, thickness: float, density: float) -> float:
    """Inertia of a web from its outline's polar second moment about the shaft axis, eq. 5, kg m^2.

    Parameters
    ----------
    polar_area_moment : float
        ``int (x^2 + y^2) dA`` of the web outline about the shaft axis, m^4.
    thickness : float
        m.
    density : float
        kg/m^3.
    """
    return polar_area_moment * thickness * density


def rectangular_web_polar_moment(width: float, below_axis: float, beyond_axis: float) -> float:
    """Polar second moment about the shaft axis of a rectangular web outline, m^4.

    The rectangle spans ``x in [-width/2, width/2]`` across and ``y in [-below_axis, beyond_axis]``
    along the crank, the shaft axis at the origin.
    """
    h = below_axis + beyond_axis
    return width**3 * h / 12.0 + width * (beyond_axis**3 + below_axis**3) / 3.0


def disc_inertia(diameter: float, thickness: float, density: float, bore: float = 0.0) -> float:
    """Inertia of a (bored) disc about its axis, e.g. a flywheel, kg m^2."""
    return density * math.pi / 32.0 * (diameter**4 - bore**4) * thickness


def inertia_about_axis(
    mass_properties, density: float, axis_point=(0.0, 0.0, 0.0), axis_direction=(1.0, 0.0, 0.0)
) -> float:
    """Inertia of a CAD solid about the shaft axis, from its mass properties, kg m^2.

    Parameters
    ----------
    mass_properties : crankmodal.part.MassProperties
        Volume, centroid and inertia tensor per unit density about the centroid (SI).
    density : float
        kg/m^3.
    axis_point, axis_direction : array_like, shape (3,)
        A point on the shaft axis (m) and its direction (need not be unit).

    Returns
    -------
    float
        ``n . I_c . n + m d^2`` with ``d`` the distance from the centroid to the axis.
    """
    n = np.asarray(axis_direction, float)
    n = n / np.linalg.norm(n)
    ic = mass_properties.inertia(density)
    mass = mass_properties.mass(density)
    r = np.asarray(mass_properties.centroid, float) - np.asarray(axis_point, float)
    r_perp = r - (r @ n) * n
    return float(n @ ic @ n + mass * (r_perp @ r_perp))
