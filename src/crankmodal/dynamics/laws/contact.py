"""Normal contact force laws and friction laws for clearance joints: pure, vectorised functions.

Conventions (all laws): ``delta`` is the penetration depth in m (> 0 in contact), ``delta_dot``
its rate in m/s (> 0 while the bodies approach), ``v_impact`` the penetration rate at the onset
of the current contact in m/s (> 0). A law returns the normal force in N, compressive positive;
outside contact (``delta <= 0``) it returns 0. No law returns a tensile (adhesive) force: the
force is clipped at zero; the clearance joint books ``(F - F_elastic) delta_dot`` (with
:func:`elastic_force`) as dissipated power, so the clipped part counts as dissipation.

Stiffness ``K`` is in N/m**n for an exponent ``n`` (n = 1 linear, n = 1.5 Hertz, n ~ 1.1 for
cylinder-in-cylinder contact); for ``johnson_cylinder`` it is ``pi L E*`` in N/m (see
:func:`johnson_cylinder_force`).
"""

from __future__ import annotations

import numpy as np

#: Laws whose damping depends on the impact velocity (need ``v_impact``) and a restitution.
RESTITUTION_LAWS = ("hunt_crossley", "lankarani_nikravesh", "flores", "johnson_cylinder")
#: All normal force laws by name.
NORMAL_LAWS = ("hertz", "kelvin_voigt", "power_damped", "impact") + RESTITUTION_LAWS
#: Friction laws by name.
FRICTION_LAWS = ("none", "coulomb", "ambrosio")


def step(x, x0, h0, x1, h1):
    """ADAMS ``STEP``: cubic from ``h0`` at ``x0`` to ``h1`` at ``x1``, flat outside.

    Parameters
    ----------
    x : array_like
        Argument.
    x0, x1 : float
        Start and end of the ramp (``x1 > x0``).
    h0, h1 : float
        Values before ``x0`` and after ``x1``.
    """
    x = np.asarray(x, float)
    s = np.clip((x - x0) / (x1 - x0), 0.0, 1.0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


def _pos(delta):
    return np.maximum(np.asarray(delta, float), 0.0)


def hertz(delta, K, n=1.5):
    """Elastic Hertz-type force ``K delta**n`` (no dissipation)."""
    return K * _pos(delta) ** n


def kelvin_voigt(delta, delta_dot, K, c):
    """Linear spring-dashpot ``K delta + c delta_dot`` (c in N s/m), clipped at zero."""
    d = _pos(delta)
    f = K * d + c * np.asarray(delta_dot, float)
    return np.where(d > 0.0, np.maximum(f, 0.0), 0.0)


def power_damped(delta, delta_dot, K, n, c):
    """``K delta**n + c delta_dot`` (seed 003's ``c delta^alpha + beta delta_dot``), clipped at zero."""
    d = _pos(delta)
    f = K * d**n + c * np.asarray(delta_dot, float)
    return np.where(d > 0.0, np.maximum(f, 0.0), 0.0)


def impact(delta, delta_dot, K, n, c_max, d_max):
    """ADAMS ``IMPACT``: ``K delta**n + STEP(delta, 0, 0, d_max, c_max) delta_dot``, clipped at zero.

    Parameters
    ----------
    K : float
        Stiffness, N/m**n.
    n : float
        Force exponent.
    c_max : float
        Full damping coefficient, N s/m, reached at penetration ``d_max`` (m).
    """
    d = _pos(delta)
    f = K * d**n + step(d, 0.0, 0.0, d_max, c_max) * np.asarray(delta_dot, float)
    return np.where(d > 0.0, np.maximum(f, 0.0), 0.0)


def hysteresis_factor(law, restitution, v_impact):
    """The hysteresis factor ``chi`` (s/m) of ``K delta**n (1 + chi delta_dot)`` laws.

    Parameters
    ----------
    law : {"hunt_crossley", "lankarani_nikravesh", "flores"}
        Hunt & Crossley (1975): ``3 (1 - e) / (2 v)``; Lankarani & Nikravesh (1990):
        ``3 (1 - e**2) / (4 v)``; Flores et al. (2011): ``8 (1 - e) / (5 e v)``.
    restitution : float
        Coefficient of restitution ``e`` in (0, 1].
    v_impact : array_like
        Impact velocity, m/s (> 0).
    """
    e = float(restitution)
    v = np.asarray(v_impact, float)
    if law == "hunt_crossley":
        return 1.5 * (1.0 - e) / v
    if law == "lankarani_nikravesh":
        return 0.75 * (1.0 - e * e) / v
    if law == "flores":
        return 1.6 * (1.0 - e) / (e * v)
    if law == "johnson_cylinder":  # Lankarani-Nikravesh damping on Johnson's elastic force
        return 0.75 * (1.0 - e * e) / v
    raise ValueError(f"no hysteresis factor for law {law!r}")


def hysteresis(delta, delta_dot, K, n, chi):
    """``K delta**n (1 + chi delta_dot)``, clipped at zero (Hunt-Crossley family)."""
    d = _pos(delta)
    f = K * d**n * (1.0 + chi * np.asarray(delta_dot, float))
    return np.where(d > 0.0, np.maximum(f, 0.0), 0.0)


def normal_force(law, delta, delta_dot, params, v_impact=1.0):
    """Dispatch a normal force law by name.

    Parameters
    ----------
    law : str
        One of :data:`NORMAL_LAWS`.
    delta, delta_dot : array_like
        Penetration (m) and its rate (m/s).
    params : mapping
        ``stiffness`` (N/m**n), ``exponent``, and per law ``damping`` (N s/m, kelvin_voigt,
        power_damped and impact), ``penetration`` (m, impact: full damping depth), ``restitution``.
    v_impact : array_like
        Impact velocity of the current contact, m/s (restitution laws only).
    """
    K = params["stiffness"]
    n = params.get("exponent", 1.5)
    if law == "hertz":
        return hertz(delta, K, n)
    if law == "kelvin_voigt":
        return kelvin_voigt(delta, delta_dot, K, params["damping"])
    if law == "power_damped":
        return power_damped(delta, delta_dot, K, n, params["damping"])
    if law == "impact":
        return impact(delta, delta_dot, K, n, params["damping"], params["penetration"])
    if law == "johnson_cylinder":
        chi = hysteresis_factor(law, params["restitution"], v_impact)
        f = johnson_cylinder_force(delta, K, params["radial_clearance"])
        return np.where(_pos(delta) > 0.0,
                        np.maximum(f * (1.0 + chi * np.asarray(delta_dot, float)), 0.0), 0.0)
    if law in RESTITUTION_LAWS:
        chi = hysteresis_factor(law, params["restitution"], v_impact)
        return hysteresis(delta, delta_dot, K, n, chi)
    raise ValueError(f"unknown normal force law {law!r}; known: {', '.join(NORMAL_LAWS)}")


def elastic_force(law, delta, params):
    """The conservative part of a law: ``K delta`` (kelvin_voigt) or ``K delta**n`` (others)."""
    if law == "johnson_cylinder":
        return johnson_cylinder_force(delta, params["stiffness"], params["radial_clearance"])
    n = 1.0 if law == "kelvin_voigt" else params.get("exponent", 1.5)
    return params["stiffness"] * _pos(delta) ** n


def elastic_energy(law, delta, params):
    """Potential of :func:`elastic_force`, J: ``K delta**(n+1) / (n+1)``."""
    if law == "johnson_cylinder":
        return johnson_cylinder_energy(delta, params["stiffness"], params["radial_clearance"])
    n = 1.0 if law == "kelvin_voigt" else params.get("exponent", 1.5)
    return params["stiffness"] * _pos(delta) ** (n + 1.0) / (n + 1.0)


def coulomb_coefficient(v, mu_s, mu_d, v_s, v_d):
    """Friction coefficient with a static/dynamic transition (ADAMS style), signed like ``v``.

    ``|v| < v_s``: rises from 0 to ``mu_s`` (STEP); ``v_s..v_d``: STEP from ``mu_s`` to
    ``mu_d``; beyond ``v_d``: ``mu_d``. Velocities in m/s.
    """
    a = np.abs(np.asarray(v, float))
    mu = np.where(a < v_s, step(a, 0.0, 0.0, v_s, mu_s), step(a, v_s, mu_s, v_d, mu_d))
    return np.sign(v) * mu


def ambrosio_coefficient(v, mu_d, v0, v1):
    """Ambrosio's modified Coulomb coefficient ``mu_d c_d(v)``, signed like ``v``.

    ``c_d`` is 0 below ``v0``, linear from 0 to 1 between ``v0`` and ``v1``, 1 beyond (m/s).
    """
    a = np.abs(np.asarray(v, float))
    cd = np.clip((a - v0) / (v1 - v0), 0.0, 1.0)
    return np.sign(v) * mu_d * cd


def friction_coefficient(law, v, params):
    """Dispatch a friction law by name; returns the signed coefficient (force = -mu F_n)."""
    if law == "none":
        return np.zeros_like(np.asarray(v, float))
    if law == "coulomb":
        return coulomb_coefficient(v, params["mu_static"], params["mu_dynamic"],
                                   params["v_static"], params["v_dynamic"])
    if law == "ambrosio":
        return ambrosio_coefficient(v, params["mu_dynamic"], params["v_static"],
                                    params["v_dynamic"])
    raise ValueError(f"unknown friction law {law!r}; known: {', '.join(FRICTION_LAWS)}")


def cylinder_stiffness(r_journal, r_bearing, E_journal, nu_journal, E_bearing, nu_bearing):
    """Contact stiffness of a journal in a bearing bore, N/m**1.5.

    The expression used for revolute clearance joints by Lankarani & Nikravesh and Flores et al.:
    ``K = 4 / (3 (s_i + s_j)) * sqrt(R_i R_j / (R_j - R_i))`` with ``s = (1 - nu**2) / E``,
    radii in m, moduli in Pa; use with exponent 1.5.
    """
    s = (1.0 - nu_journal**2) / E_journal + (1.0 - nu_bearing**2) / E_bearing
    return 4.0 / (3.0 * s) * np.sqrt(r_journal * r_bearing / (r_bearing - r_journal))


# ------------------------------------------------------------------ conformal cylinders (Johnson)
#: ``s = ln(4 dR / x)`` at which :func:`johnson_cylinder_force` leaves Johnson's formula for its
#: tangent: there ``d delta / dF = 1 / (pi L E*)``, at ``delta = 8 e**-3 dR = 0.40 dR``. The
#: formula itself turns back at ``s = 2`` (``delta = 4 e**-2 dR = 0.54 dR``: no force beyond), so
#: a deeper penetration gets the straight continuation, far outside the law's validity anyway.
_S_CAP = 3.0


def effective_modulus(E_journal, nu_journal, E_bearing, nu_bearing):
    """Plane-strain contact modulus ``E* = 1 / ((1 - nu_i**2) / E_i + (1 - nu_j**2) / E_j)``, Pa."""
    return 1.0 / ((1.0 - nu_journal**2) / E_journal + (1.0 - nu_bearing**2) / E_bearing)


def johnson_cylinder_approach(F, K, dR):
    """Elastic approach of a journal in a conformal bore under a line load (Johnson), m.

    ``delta = (F / K) (ln(4 K dR / F) - 1)`` with ``K = pi L E*`` (N/m), ``dR`` the radial
    clearance (m) and ``F`` the contact force (N): Johnson, *Contact Mechanics* (1985), Sec. 5.6,
    in the form compared by Pereira, Ramalho & Ambrosio, Nonlinear Dyn. 63 (2011) 681-697
    ("Johnson's model" for internal cylinders). Valid for ``F`` well below ``4 K dR e**-3``
    (contact arc small against the circumference); larger forces get the tangent continuation
    of :func:`johnson_cylinder_force`.
    """
    F = np.maximum(np.asarray(F, float), 0.0)
    x = F / K
    A = 4.0 * dR
    x_cap = A * np.exp(-_S_CAP)
    xs = np.where(x > 0.0, np.minimum(x, x_cap), 1.0)
    d = np.where(x > 0.0, xs * (np.log(A / xs) - 1.0), 0.0)
    return d + np.maximum(x - x_cap, 0.0)  # slope 1/K beyond the cap


def _johnson_log_ratio(delta, dR):
    """``s = ln(4 dR / x)`` with ``x (s - 1) = delta`` (Johnson's relation), by Newton's method.

    In ``u = s``: ``h(s) = s - ln(4 dR / delta) - ln(s - 1) = 0``; ``h`` is increasing and convex
    for ``s > 2``, so from any start a Newton step lands on the right of the root and the
    iterates then decrease monotonically to it; 12 steps reach round-off from ``delta`` in
    ``[1e-300 dR, 0.4 dR]`` (checked against the closed form in the tests).
    """
    L = np.log(4.0 * dR / delta)
    s = np.maximum(L + np.log(np.maximum(L - 1.0, 1.0)), _S_CAP)
    for _ in range(12):
        h = s - L - np.log(s - 1.0)
        s = np.maximum(s - h / (1.0 - 1.0 / (s - 1.0)), 2.0 + 1e-9)
    return s


def johnson_cylinder_force(delta, K, dR):
    """Contact force of a journal in a conformal bore at penetration ``delta`` (Johnson), N.

    The inverse of :func:`johnson_cylinder_approach`: ``delta = (F / K) (ln(4 K dR / F) - 1)``
    solved for ``F`` (Newton in ``ln``, vectorised), with ``K = pi L E*`` in N/m (``L`` the
    bearing length, ``E*`` from :func:`effective_modulus`) and ``dR`` the radial clearance, m.
    Beyond ``delta_cap = 8 e**-3 dR`` (0.40 dR) the force continues along its tangent
    (stiffness ``K``), so it is defined, increasing and C1 for every penetration.
    """
    d = _pos(delta)
    A = 4.0 * dR
    x_cap = A * np.exp(-_S_CAP)
    d_cap = x_cap * (_S_CAP - 1.0)
    inside = (d > 0.0) & (d <= d_cap)
    dd = np.where(inside, d, d_cap)
    x = np.where(inside, dd / (_johnson_log_ratio(dd, dR) - 1.0), x_cap)
    x = np.where(d > d_cap, x_cap + (d - d_cap), x)
    return np.where(d > 0.0, K * x, 0.0)


def johnson_cylinder_energy(delta, K, dR):
    """Potential of :func:`johnson_cylinder_force`, J: ``K x**2 / 2 (s - 3/2)`` with ``x = F / K``
    and ``s = ln(4 dR / x)`` (from ``d delta = (s - 2) dx``), plus the straight continuation."""
    d = _pos(delta)
    A = 4.0 * dR
    x = johnson_cylinder_force(d, 1.0, dR)
    x_cap = A * np.exp(-_S_CAP)
    xs = np.where(x > 0.0, np.minimum(x, x_cap), 1.0)
    w = np.where(x > 0.0, 0.5 * xs * xs * (np.log(A / xs) - 1.5), 0.0)
    over = np.maximum(x - x_cap, 0.0)  # beyond the cap: F = K (x_cap + over), d delta = d over
    return K * (w + x_cap * over + 0.5 * over * over)


def johnson_cylinder_stiffness(delta, K, dR):
    """Tangent stiffness ``dF / d delta = K / (s - 2)`` of :func:`johnson_cylinder_force`, N/m."""
    d = _pos(delta)
    A = 4.0 * dR
    x = johnson_cylinder_force(d, 1.0, dR)
    s = np.log(A / np.maximum(x, 1e-300))
    return np.where(s > _S_CAP, K / (s - 2.0), K)
