"""Hydrodynamic forces of a short journal bearing (Ocvirk) with pi-film cavitation.

Dynamically loaded short bearing (as used for lubricated revolute clearance joints by Flores
et al. 2006), with eccentricity ratio ``eps = e / c``, its rate ``eps_dot`` (1/s), the whirl rate
``gamma_dot`` of the line of centres (rad/s) and ``omega = omega_journal + omega_bearing``
(rad/s). Components of the film force on the journal, N: ``f_r`` along the eccentricity
(negative: towards the bearing centre) and ``f_t`` at +90 deg from it.

The short-bearing Reynolds pressure is ``p = G(theta) (z^2 - L^2/4) / (2 h^3)`` with
``h = c (1 - eps cos theta)`` (theta from the line of centres) and

    G = 6 mu c [a sin theta + b cos theta],   a = eps (omega - 2 gamma_dot),   b = -2 eps_dot.

``a`` is the wedge and ``b`` the squeeze source (both 1/s). The film keeps the half where the
generated pressure is positive, ``G <= 0`` (Gumbel / half-Sommerfeld pi film), i.e.
``theta0 < theta < theta0 + pi`` with ``theta0 = pi - atan2(b, a)``: the film turns with the sense
of the entrained flow and of the squeeze. Integrated in closed form with the Sommerfeld
substitution ``cos psi = (cos theta - eps) / (1 - eps cos theta)``::

    f_r = mu R L^3 / (2 c^2) [a I_sc + b I_cc],   f_t = mu R L^3 / (2 c^2) [a I_ss + b I_sc]

    I_sc = [-cos^2 theta / (2 H^2)],  I_ss = [psi/2 - sin 2psi / 4] / s^(3/2),
    I_cc = [psi/2 + sin 2psi / 4 + 2 eps sin psi + eps^2 psi] / s^(5/2)

(``H = 1 - eps cos theta``, ``s = 1 - eps^2``, brackets: difference over the film). For
``a > 0, b = 0`` (theta0 = pi) this is Ocvirk's

    f_r = -mu R L^3 / (2 c^2) 2 eps^2 (omega - 2 gamma_dot) / (1 - eps^2)^2
    f_t =  mu R L^3 / (2 c^2) pi eps (omega - 2 gamma_dot) / (2 (1 - eps^2)^(3/2)).

The wedge ``a`` is passed as such (:func:`short_bearing_film`): ``eps gamma_dot`` is the
tangential relative velocity over ``c``, finite at the bearing centre, where ``gamma_dot``
alone is not.
"""

from __future__ import annotations

import numpy as np


def _primitives(eps, theta):
    """Antiderivatives of sin cos / H^3, sin^2 / H^3, cos^2 / H^3 at ``theta`` (continuous)."""
    s = 1.0 - eps * eps
    c, sn = np.cos(theta), np.sin(theta)
    H = 1.0 - eps * c
    beta = eps / (1.0 + np.sqrt(s))
    # psi = 2 atan(sqrt((1 + eps) / (1 - eps)) tan(theta / 2)), written without branch jumps
    psi = theta + 2.0 * np.arctan2(beta * sn, 1.0 - beta * c)
    cp, sp = (c - eps) / H, np.sqrt(s) * sn / H
    i_sc = -c * c / (2.0 * H * H)
    i_ss = (0.5 * psi - 0.5 * sp * cp) / s**1.5
    i_cc = (0.5 * psi + 0.5 * sp * cp + 2.0 * eps * sp + eps * eps * psi) / s**2.5
    return i_sc, i_ss, i_cc


def short_bearing_film(eps, wedge, eps_dot, viscosity, radius, length, clearance):
    """Film force on the journal in the (radial, tangential) frame, from the wedge, N.

    Parameters
    ----------
    eps : array_like
        Eccentricity ratio in [0, 1).
    wedge : array_like
        ``eps (omega - 2 gamma_dot)``, 1/s: the journal's and bearing's angular velocities
        summed, minus twice the whirl rate, times ``eps`` (any sign; finite at ``eps = 0``).
    eps_dot : array_like
        1/s (positive: towards the wall).
    viscosity : float
        Dynamic viscosity, Pa s.
    radius, length, clearance : float
        Journal radius, bearing length, radial clearance, m.

    Returns
    -------
    f_r, f_t : ndarray
        Force along the eccentricity and at +90 deg from it, N.
    """
    eps = np.asarray(eps, float)
    a = np.asarray(wedge, float)
    b = -2.0 * np.asarray(eps_dot, float)
    theta0 = np.pi - np.arctan2(b, a)           # the film: where G <= 0, i.e. p >= 0
    lo = _primitives(eps, theta0)
    hi = _primitives(eps, theta0 + np.pi)
    i_sc, i_ss, i_cc = (h - l for h, l in zip(hi, lo))
    k = viscosity * radius * length**3 / (2.0 * clearance**2)
    return k * (a * i_sc + b * i_cc), k * (a * i_ss + b * i_sc)


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
    wedge = eps * (np.asarray(omega, float) - 2.0 * np.asarray(gamma_dot, float))
    return short_bearing_film(eps, wedge, eps_dot, viscosity, radius, length, clearance)


def attitude_angle(eps):
    """Static short-bearing attitude angle (deg) between the load and the line of centres."""
    eps = np.asarray(eps, float)
    return np.degrees(np.arctan(np.pi * np.sqrt(1.0 - eps**2) / (4.0 * eps)))
