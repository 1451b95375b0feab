"""The clearance revolute joint: a journal moving freely inside a bearing bore.

The joint sees two interface frames only: the journal centre (on one body) and the bearing
centre (on another). With eccentricity vector ``e = p_journal - p_bearing`` the penetration is
``delta = |e| - c`` (``c`` the radial clearance); in contact a normal force pushes the journal
back towards the bearing centre and a friction force acts along the surfaces against their
relative slip. Free flight, impact and continuous contact all follow from the same force law.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ...errors import ParameterError
from ...schema import REQUIRED, Field
from ..laws import objects as laws
from ..laws.lubrication import film_arguments, short_film

FILM_MODELS = ("short", "finite")

#: the rules of a clearance joint's geometry and film arguments (the ``[[dynamics.clearances]]``
#: scene keys take theirs from here)
RULES = {
    "clearance": Field("float", REQUIRED, "radial clearance, m", gt=0.0, le=0.01),
    "journal_radius": Field("float", REQUIRED, "journal radius, m", gt=0.0),
    "clearance_major": Field("float", None, "radial clearance along the major axis of a worn "
                             "(elliptical) bore, m", gt=0.0, le=0.01),
    "wear_angle": Field("float", 0.0, "direction of the worn bore's major axis, rad"),
    "viscosity": Field("float", None, "lubricant dynamic viscosity, Pa s", gt=0.0),
    "bearing_length": Field("float", None, "bearing length for the film force, m", gt=0.0),
    "film_model": Field("str", "short", "film force: short (Ocvirk) or finite (Reynolds)",
                        choices=FILM_MODELS),
    "v_impact_min": Field("float", 1e-3, "floor of the impact velocity, m/s", gt=0.0),
}


@dataclass(frozen=True)
class ClearanceSpec:
    """What makes a joint a clearance joint: the bore, the journal, the laws and the film.

    The typed description a mechanism builder (:func:`~.mechanisms.crank_train`,
    :func:`~.mechanisms.four_bar`) turns into a :class:`ClearanceJoint` between two bodies
    (:meth:`joint`). The constructor checks every field and raises
    :class:`~crankmodal.errors.ParameterError` naming it.

    Parameters
    ----------
    clearance : float
        Radial clearance ``c = R_bearing - R_journal``, m, in (0, 0.01]; the minor-axis one of a
        worn bore.
    journal_radius : float
        m, > 0.
    normal : NormalLaw
        Normal contact force law (:mod:`..laws.objects`, e.g. ``Impact(...)``).
    friction : FrictionLaw
        Friction law (default :class:`~..laws.objects.NoFriction`).
    v_impact_min : float
        Floor of the impact velocity of the restitution laws, m/s, > 0.
    clearance_major : float or None
        Radial clearance along the major axis of a worn (elliptical) bore, m, >= ``clearance``;
        None for a round bore.
    wear_angle : float
        Direction of that major axis in the bearing body's frame, rad.
    viscosity : float or None
        Lubricant dynamic viscosity, Pa s (round bores only); None for a dry joint.
    bearing_length : float or None
        Bearing length, m: required with ``viscosity``; None or 0 without a film.
    film_model : str
        ``"short"`` (Ocvirk) or ``"finite"`` (Reynolds, tabulated per L/D).

    Examples
    --------
    >>> from crankmodal.dynamics.laws.objects import Impact
    >>> spec = ClearanceSpec(1e-4, 0.02, Impact(stiffness=1e10, damping=300.0,
    ...                                         penetration=1e-4))
    >>> spec.friction.name
    'none'
    """

    clearance: float
    journal_radius: float
    normal: laws.NormalLaw
    friction: laws.FrictionLaw = field(default_factory=laws.NoFriction)
    v_impact_min: float = 1e-3
    clearance_major: float | None = None
    wear_angle: float = 0.0
    viscosity: float | None = None
    bearing_length: float | None = None
    film_model: str = "short"

    def __post_init__(self):
        from ... import arguments as arg

        for name, rule in RULES.items():
            value = getattr(self, name)
            if name == "bearing_length" and value == 0.0:  # 0: no film (the API's old default)
                value = None
            object.__setattr__(self, name, arg.check(name, value, rule,
                                                     optional=rule.default is not REQUIRED))
        arg.instance("normal", self.normal, laws.NormalLaw, "a NormalLaw (e.g. Impact(...), "
                     "or make_law(name, params))")
        arg.instance("friction", self.friction, laws.FrictionLaw, "a FrictionLaw (e.g. "
                     "Coulomb(...), NoFriction(), or make_friction(name, params))")
        if self.clearance_major is not None and self.clearance_major < self.clearance:
            raise ParameterError("clearance_major", f"must be >= clearance "
                                 f"({self.clearance:g} m), got {self.clearance_major:g}")
        if self.viscosity is not None and self.bearing_length is None:
            raise ParameterError("bearing_length", "is required with viscosity (bearing "
                                 "length, m, > 0)")
        if self.viscosity is not None and self.clearance_major is not None:
            raise ParameterError("viscosity", "the film model needs a round bore; give "
                                 "clearance_major or viscosity, not both")

    def joint(self, name: str, journal, journal_frame: str, bearing,
              bearing_frame: str) -> ClearanceJoint:
        """The clearance joint ``name`` between ``journal`` (the pin at ``journal_frame``) and
        ``bearing`` (the bore at ``bearing_frame``)."""
        return ClearanceJoint(
            name=name, journal=journal, journal_frame=journal_frame, bearing=bearing,
            bearing_frame=bearing_frame, clearance=self.clearance,
            journal_radius=self.journal_radius, law=self.normal, friction=self.friction,
            v_impact_min=self.v_impact_min, clearance_major=self.clearance_major,
            wear_angle=self.wear_angle, viscosity=self.viscosity,
            bearing_length=self.bearing_length or 0.0, film_model=self.film_model)


@dataclass
class ClearanceJoint:
    """A revolute joint with radial clearance.

    Parameters
    ----------
    name : str
        Joint name (outputs).
    journal, journal_frame : body, str
        The body carrying the pin and the frame at the pin centre.
    bearing, bearing_frame : body, str
        The body carrying the bore and the frame at the bore centre.
    clearance : float
        Radial clearance ``c = R_bearing - R_journal``, m.
    journal_radius : float
        m (lever arm of friction).
    law : NormalLaw
        Normal force law, an object of :mod:`..laws.objects` (``Impact(...)``,
        ``make_law(name, params)``). Deprecated: its name with ``law_params``.
    law_params : dict, optional
        Deprecated: the parameters of a law given by name (None after construction).
    friction : FrictionLaw
        Friction law, an object of :mod:`..laws.objects` (default: none). Deprecated: its name
        with ``friction_params``.
    friction_params : dict, optional
        Deprecated: ``mu_static, mu_dynamic, v_static, v_dynamic`` (m/s) of a law given by name
        (None after construction).
    v_impact_min : float
        Floor of the impact velocity used by restitution laws, m/s: a contact that starts at
        (almost) zero approach speed would otherwise get unbounded damping.
    clearance_major : float or None
        Radial clearance along the major axis of a worn (elliptical) bore, m (>= clearance,
        which is then the minor-axis clearance); None for a round bore.
    wear_angle : float
        Direction of the major axis in the bearing body's frame, rad.
    viscosity : float or None
        Lubricant dynamic viscosity, Pa s: adds the short-bearing film force of
        :mod:`.lubrication` (round bores only); None for a dry joint.
    bearing_length : float
        Bearing length for the film force, m.
    film_model : str
        ``"short"``: short-bearing (Ocvirk) pi film of :mod:`.lubrication`; ``"finite"``:
        finite-length Reynolds film with Reynolds cavitation, tabulated per ``L/D`` by
        :mod:`.reynolds` (the first use of an ``L/D`` costs a few seconds).
    eps_max : float
        Eccentricity ratio at which the film force stops growing (the dry contact law takes
        over at ``eps = 1``); keeps the film's ``(1 - eps^2)^-5/2`` finite.
    """

    name: str
    journal: object
    journal_frame: str
    bearing: object
    bearing_frame: str
    clearance: float
    journal_radius: float
    law: laws.NormalLaw = None
    law_params: dict | None = field(default=None, repr=False)
    friction: laws.FrictionLaw = field(default_factory=laws.NoFriction)
    friction_params: dict | None = field(default=None, repr=False)
    v_impact_min: float = 1e-3
    clearance_major: float | None = None
    wear_angle: float = 0.0
    viscosity: float | None = None
    bearing_length: float = 0.0
    film_model: str = "short"
    eps_max: float = 0.95
    # impact velocity of the current contact (restitution laws) for callers that do not pass
    # one: the integrator keeps its own (simulate.integrate) and passes it to forces
    v_impact: float = 1e-3

    @property
    def normal(self) -> laws.NormalLaw:
        """The normal force law (:attr:`law`)."""
        return self.law

    @property
    def friction_law(self) -> laws.FrictionLaw:
        """The friction law (:attr:`friction`)."""
        return self.friction

    @property
    def needs_memory(self) -> bool:
        return self.law.needs_impact_velocity

    def kinematics(self, sysm, q, qd):
        """Eccentricity, penetration, penetration rate, slip velocity, and the frame data."""
        pj, Jj, _ = sysm.frame(self.journal, self.journal_frame, q, qd)
        pb, Jb, _ = sysm.frame(self.bearing, self.bearing_frame, q, qd)
        vj = sysm.frame_velocity(self.journal, Jj, qd)
        vb = sysm.frame_velocity(self.bearing, Jb, qd)
        e = pj[:2] - pb[:2]
        d = float(np.hypot(e[0], e[1]))
        # direction is irrelevant inside the clearance; avoid 0/0 at the exact centre
        n = e / d if d > 1e-300 else np.array([1.0, 0.0])
        t = np.array([-n[1], n[0]])
        vrel = vj[:2] - vb[:2]
        c, dc = self.bore_clearance(np.arctan2(n[1], n[0]) - pb[2])
        delta = d - c
        grad = n - (dc / d) * t if (dc != 0.0 and d > 1e-300) else n  # d delta / d e
        delta_dot = float(grad @ vrel + dc * vb[2])
        r_b = self.journal_radius + c
        v_slip = float(t @ vrel + self.journal_radius * vj[2] - r_b * vb[2])
        return {"e": e, "n": n, "t": t, "grad": grad, "dtheta": dc, "delta": delta,
                "delta_dot": delta_dot, "v_slip": v_slip, "Jj": Jj, "Jb": Jb, "r_b": r_b, "d": d,
                "vrel": vrel, "omega_sum": float(vj[2] + vb[2])}

    def bore_clearance(self, phi):
        """Radial clearance (m) of the bore in direction ``phi`` (bearing frame) and its derivative.

        Round bore: ``(c, 0)``. Worn bore: polar radius of the ellipse minus the journal radius.
        """
        if self.clearance_major is None:
            return self.clearance, 0.0
        return worn_bore_clearance(float(phi), float(self.journal_radius), float(self.clearance),
                                   float(self.clearance_major), float(self.wear_angle))

    def __post_init__(self):
        from ... import arguments as arg

        for name, rule in RULES.items():  # the rules ClearanceSpec and the scene keys share
            value = getattr(self, name)
            if name == "bearing_length" and not value:  # 0: no film
                continue
            setattr(self, name, arg.check(name, value, rule,
                                          optional=rule.default is not REQUIRED))
        if self.law is None:
            raise ParameterError("law", "is required: a NormalLaw (e.g. Impact(...), or "
                                 "make_law(name, params))")
        if not (isinstance(self.law, laws.NormalLaw) and isinstance(self.friction,
                                                                      laws.FrictionLaw)
                and self.law_params is None and self.friction_params is None):
            self.law, self.friction = laws.legacy_laws(self.law, self.law_params, self.friction,
                                                       self.friction_params, stacklevel=4)
            self.law_params = self.friction_params = None

    def film_force(self, k) -> np.ndarray:
        """Film force on the journal (global x, y), N (``film_model``: short or finite)."""
        c = self.clearance
        n, t = k["n"], k["t"]
        eps, wedge, eps_dot = film_arguments(k["d"], float(n @ k["vrel"]), float(t @ k["vrel"]),
                                             k["omega_sum"], c, self.eps_max)
        if self.film_model == "finite":
            from ..laws.reynolds import finite_bearing_film as law
        else:
            law = short_film
        fr, ftan = law(eps, wedge, eps_dot, self.viscosity, self.journal_radius,
                       self.bearing_length, c)
        return float(fr) * n + float(ftan) * t

    def gap(self, sysm, q) -> float:
        """Penetration ``|e| - c`` from positions only, m (event function)."""
        pj = sysm.frame_pose_only(self.journal, self.journal_frame, q)
        pb = sysm.frame_pose_only(self.bearing, self.bearing_frame, q)
        ex, ey = pj[0] - pb[0], pj[1] - pb[1]
        c, _ = self.bore_clearance(np.arctan2(ey, ex) - pb[2])
        return float(np.hypot(ex, ey)) - c

    def forces(self, sysm, t, q, qd, Q, v_impact=None):
        """Add the contact forces to ``Q``; return the diagnostics and dissipated powers.

        ``v_impact``: impact velocity of the contact in progress, m/s (restitution laws; floored
        at ``v_impact_min``); None reads :attr:`v_impact`.
        """
        k = self.kinematics(sysm, q, qd)
        delta, ddot = k["delta"], k["delta_dot"]
        if delta > 0.0:
            law = self.law
            v = self.v_impact if v_impact is None else v_impact
            fn = float(law.force(delta, ddot, max(v, self.v_impact_min)))
            fel = float(law.elastic_force(delta))
            mu = float(self.friction.coefficient(k["v_slip"]))
        else:
            fn = fel = mu = 0.0
        ft = -mu * fn
        g, tt = k["grad"], k["t"]
        f = -fn * g + ft * tt  # force on the journal, N
        p_film = 0.0
        f_film = np.zeros(2)
        if self.viscosity is not None:
            f_film = self.film_force(k)
            p_film = float(f_film @ k["vrel"])
            f = f + f_film
        if fn != 0.0 or p_film != 0.0:
            sysm.add_frame_force(Q, self.journal, k["Jj"],
                                 np.array([f[0], f[1], self.journal_radius * ft]))
            sysm.add_frame_force(Q, self.bearing, k["Jb"],
                                 np.array([-f[0], -f[1], -k["r_b"] * ft - fn * k["dtheta"]]))
        k.update(fn=fn, ft=ft, force=f, film=float(np.hypot(*f_film)),
                 p_damp=(fn - fel) * ddot - p_film, p_fric=-ft * k["v_slip"],
                 v_elastic=float(self.law.elastic_energy(delta)))
        return k


@njit(cache=True)
def worn_bore_clearance(phi, journal_radius, clearance, clearance_major, wear_angle):
    """Radial clearance of a worn (elliptical) bore in direction ``phi`` and its derivative.

    The bore is an ellipse of semi-axes ``a = r + c_major`` along ``wear_angle`` and
    ``b = r + c`` (``r`` the journal radius); its polar radius from the centre is
    ``rho = a b / sqrt((b cos u)^2 + (a sin u)^2)``, ``u = phi - wear_angle``.

    Parameters
    ----------
    phi : float
        Direction from the bore centre, rad, in the bearing body's frame.
    journal_radius, clearance, clearance_major : float
        ``r``, the minor- and the major-axis radial clearance, m.
    wear_angle : float
        Direction of the major axis in the bearing body's frame, rad.

    Returns
    -------
    c, dc_dphi : float
        ``rho - r``, m, and ``d rho / d phi``, m/rad.
    """
    a = journal_radius + clearance_major
    b = journal_radius + clearance
    ph = phi - wear_angle
    cs, sn = np.cos(ph), np.sin(ph)
    s2 = (b * cs) ** 2 + (a * sn) ** 2
    rho = a * b / np.sqrt(s2)
    drho = -a * b * (a * a - b * b) * sn * cs / s2**1.5
    return rho - journal_radius, drho
