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
from numba import njit


@njit(cache=True)
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


@njit(cache=True)
def short_film(eps, wedge, eps_dot, viscosity, radius, length, clearance):
    """:func:`short_bearing_film` for scalars (the one implementation of the formula).

    Compiled (Numba), so that the right-hand side kernel of :mod:`.compiled` calls this very
    function; arguments and returns as :func:`short_bearing_film`, floats, N.
    """
    a = wedge
    b = -2.0 * eps_dot
    theta0 = np.pi - np.arctan2(b, a)           # the film: where G <= 0, i.e. p >= 0
    lo_sc, lo_ss, lo_cc = _primitives(eps, theta0)
    hi_sc, hi_ss, hi_cc = _primitives(eps, theta0 + np.pi)
    i_sc, i_ss, i_cc = hi_sc - lo_sc, hi_ss - lo_ss, hi_cc - lo_cc
    k = viscosity * radius * length**3 / (2.0 * clearance**2)
    return k * (a * i_sc + b * i_cc), k * (a * i_ss + b * i_sc)


@njit(cache=True)
def _short_film_many(eps, wedge, eps_dot, viscosity, radius, length, clearance, f_r, f_t):
    for i in range(eps.size):
        f_r[i], f_t[i] = short_film(eps[i], wedge[i], eps_dot[i], viscosity, radius, length,
                                    clearance)


@njit(cache=True)
def film_arguments(d, v_normal, v_tangential, omega_sum, clearance, eps_max):
    """The film's arguments ``(eps, wedge, eps_dot)`` from a joint's kinematics.

    Parameters
    ----------
    d : float
        Eccentricity ``|e|``, m.
    v_normal, v_tangential : float
        Journal velocity relative to the bearing along ``e / |e|`` and at +90 deg from it, m/s.
    omega_sum : float
        Journal's plus bearing's angular velocity, rad/s.
    clearance : float
        Radial clearance ``c``, m.
    eps_max : float
        Eccentricity ratio at which the film is frozen.

    Returns
    -------
    eps, wedge, eps_dot : float
        ``min(d / c, eps_max)``; ``eps (omega - 2 gamma_dot)``, 1/s; ``v_normal / c``, 1/s.

    Notes
    -----
    The wedge is written with ``eps gamma_dot = v_tangential / c``: no ``1 / |e|``, so it stays
    smooth through the bearing centre (``gamma_dot`` alone is singular there); beyond
    ``eps_max`` the film is frozen at ``eps_max``, as is its whirl term.
    """
    eps = min(d / clearance, eps_max)
    whirl = v_tangential / clearance * (eps * clearance / d if d > eps_max * clearance else 1.0)
    return eps, eps * omega_sum - 2.0 * whirl, v_normal / clearance


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
        Force along the eccentricity and at +90 deg from it, N (the broadcast shape of the
        array arguments); :func:`short_film` element by element.
    """
    e, w, ed = np.broadcast_arrays(*(np.asarray(x, float) for x in (eps, wedge, eps_dot)))
    f_r, f_t = np.empty(e.shape), np.empty(e.shape)
    _short_film_many(np.ravel(e), np.ravel(w), np.ravel(ed), float(viscosity), float(radius),
                     float(length), float(clearance), f_r.reshape(-1), f_t.reshape(-1))
    return f_r, f_t


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
