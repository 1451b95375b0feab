"""Hydrodynamic forces of a short journal bearing (Ocvirk) with pi-film cavitation.

Dynamically loaded short bearing (as used for lubricated revolute clearance joints by Flores
et al. 2006), with eccentricity ratio ``eps = e / c``, its rate ``eps_dot`` (1/s), the whirl rate
``gamma_dot`` of the line of centres (rad/s) and ``omega = omega_journal + omega_bearing``
(rad/s). Components of the film force on the journal, N: ``f_r`` along the eccentricity
(negative: towards the bearing centre) and ``f_t`` at +90 deg from it::

    f_r = -mu R L^3 / (2 c^2) [2 eps^2 (omega - 2 gamma_dot) / (1 - eps^2)^2
                               + pi (1 + 2 eps^2) eps_dot / (1 - eps^2)^(5/2)]
    f_t =  mu R L^3 / (2 c^2) [pi eps (omega - 2 gamma_dot) / (2 (1 - eps^2)^(3/2))
                               + 4 eps eps_dot / (1 - eps^2)^2]

These are the short-bearing Reynolds pressure ``p = G(theta) (z^2 - L^2/4) / (2 h^3)``,
``G = 6 mu c [eps (omega - 2 gamma_dot) sin theta - 2 eps_dot cos theta]``,
``h = c (1 - eps cos theta)`` (theta from the line of centres), integrated over the half
``pi < theta < 2 pi`` in which the entrained flow builds pressure (pi film; the other half is
taken as cavitated).
"""

from __future__ import annotations

import numpy as np


def short_bearing_force(eps, eps_dot, gamma_dot, omega, viscosity, radius, length, clearance):
    """Film force on the journal in the (radial, tangential) frame of the eccentricity, N.

    Parameters
    ----------
    eps : array_like
        Eccentricity ratio in [0, 1).
    eps_dot : array_like
        1/s.
    gamma_dot : array_like
        Whirl rate of the eccentricity direction, rad/s.
    omega : array_like
        Sum of the journal's and the bearing's angular velocities, rad/s.
    viscosity : float
        Dynamic viscosity, Pa s.
    radius, length, clearance : float
        Journal radius, bearing length, radial clearance, m.
    """
    eps = np.asarray(eps, float)
    s = 1.0 - eps * eps
    k = viscosity * radius * length**3 / (2.0 * clearance**2)
    w = np.asarray(omega, float) - 2.0 * np.asarray(gamma_dot, float)
    ed = np.asarray(eps_dot, float)
    f_r = -k * (2.0 * eps**2 * w / s**2 + np.pi * (1.0 + 2.0 * eps**2) * ed / s**2.5)
    f_t = k * (np.pi * eps * w / (2.0 * s**1.5) + 4.0 * eps * ed / s**2)
    return f_r, f_t


def attitude_angle(eps):
    """Static short-bearing attitude angle (deg) between the load and the line of centres."""
    eps = np.asarray(eps, float)
    return np.degrees(np.arctan(np.pi * np.sqrt(1.0 - eps**2) / (4.0 * eps)))
