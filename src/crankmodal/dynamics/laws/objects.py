"""Normal contact and friction laws as objects: one class per law, its parameters as fields.

Each normal law is a frozen dataclass whose constructor validates its parameters (``ValueError``
naming the parameter) and whose methods call the pure functions of :mod:`.contact`:

``force(delta, delta_dot, v_impact)``
    Normal force, N (compressive positive, 0 outside contact; conventions of :mod:`.contact`).
``elastic_force(delta)``, ``elastic_energy(delta)``
    The conservative part of the law, N, and its potential, J.

For the contact time scales of :mod:`.timescales` a normal law answers under a representative
load ``F`` (N): ``static_penetration(F)`` (m), ``tangent_stiffness(F)`` (N/m), ``dashpot(F)``
(its own damping coefficient there, N s/m; 0 for none), ``dashpot_setting`` (the damping
parameter as set, or None) and ``stiffness_for_tangent(k_target, k_lin)`` (the stiffness
parameter that would give the tangent stiffness ``k_target`` at the same load).
``hertz_stiffness`` is ``K`` in N/m**1.5 when the law's elastic force is ``K delta**1.5`` (a
constant comparable with a steel pair's Hertz stiffness), else None.

Laws whose damping depends on the impact velocity have ``needs_impact_velocity = True``. A
friction law has ``coefficient(v)``: the signed coefficient at slip velocity ``v`` (m/s), the
friction force being ``-mu F_n``.

Each law also carries ``code`` and ``vector()``: an integer and a float vector that the compiled
right-hand side of :mod:`.compiled` evaluates (the same arithmetic, in machine code).

Registries: :data:`LAWS` and :data:`FRICTION` (name -> class); :func:`make_law` and
:func:`make_friction` build a law from a name and a parameter mapping (the ``law_params`` /
``friction_params`` dictionaries of the scene dialect; keys a law does not use are ignored) and
``law.params()`` gives such a dictionary back.
"""

from __future__ import annotations

import math
from dataclasses import MISSING, asdict, dataclass, fields
from typing import ClassVar

import numpy as np

from . import contact


def _number(name: str, value) -> float:
    from ...errors import ParameterError

    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, f"must be a number; got {value!r}") from None


def _positive(name: str, value) -> float:
    from ...errors import ParameterError

    v = _number(name, value)
    if not (math.isfinite(v) and v > 0.0):
        raise ParameterError(name, f"must be a finite number > 0; got {value!r}")
    return v


def _non_negative(name: str, value) -> float:
    from ...errors import ParameterError

    v = _number(name, value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ParameterError(name, f"must be a finite number >= 0; got {value!r}")
    return v


def _restitution(value) -> float:
    from ...errors import ParameterError

    v = _number("restitution", value)
    if not (0.0 < v <= 1.0):
        raise ParameterError("restitution", f"must be in (0, 1]; got {value!r}")
    return v


# ---------------------------------------------------------------------------------- normal laws
@dataclass(frozen=True)
class NormalLaw:
    """Base of the normal force laws (see the module docstring).

    A law is a frozen dataclass of its parameters (SI: stiffness in N/m^exponent, damping in
    N s/m, lengths in m) that answers for itself: ``force(delta, delta_dot, v_impact)`` (N) for
    a penetration ``delta`` (m) and its rate (m/s), ``elastic_force(delta)``, its time scales
    and its Hertz stiffness. Build one by name with :func:`make_law`.

    Attributes
    ----------
    name : str
        The law's scene name (``contact.law``).
    code : int
        Its number in the compiled kernel.
    needs_impact_velocity : bool
        Whether the force depends on the velocity at the contact's onset (restitution laws).
    """

    name: ClassVar[str] = ""
    code: ClassVar[int] = -1
    needs_impact_velocity: ClassVar[bool] = False

    def params(self) -> dict:
        """The parameters as a ``law_params`` dictionary."""
        return asdict(self)

    def force(self, delta, delta_dot, v_impact=1.0):
        raise NotImplementedError

    def elastic_force(self, delta):
        """``K delta**n`` (``n = 1`` for kelvin_voigt), N."""
        return self.stiffness * contact._pos(delta) ** self.elastic_exponent

    def elastic_energy(self, delta):
        """``K delta**(n+1) / (n+1)``, J."""
        n = self.elastic_exponent
        return self.stiffness * contact._pos(delta) ** (n + 1.0) / (n + 1.0)

    @property
    def elastic_exponent(self) -> float:
        return self.exponent

    def vector(self) -> np.ndarray:
        """Parameters for the compiled kernel: ``[K, n, c, d_or_e, dR]`` (unused entries 0)."""
        raise NotImplementedError

    # --- contact time scales (:mod:`.timescales`) -------------------------------------------
    #: whether :meth:`dashpot` depends on the penetration a run reaches (then an estimate only)
    dashpot_varies: ClassVar[bool] = False
    #: whether :meth:`stiffness_for_tangent` is exact (False: up to a logarithm)
    tangent_scales_exactly: ClassVar[bool] = True

    def static_penetration(self, load):
        """Penetration at which the elastic force carries ``load`` N: ``(F / K)**(1/n)``, m."""
        return (load / self.stiffness) ** (1.0 / self.elastic_exponent)

    def tangent_stiffness(self, load):
        """``dF/d delta`` of the elastic force at :meth:`static_penetration` of ``load`` N:
        ``n F / delta``, N/m."""
        return self.elastic_exponent * load / self.static_penetration(load)

    def dashpot(self, load):
        """The law's own damping coefficient at the static penetration of ``load`` N, N s/m;
        0 for a law without a dashpot (the hysteresis laws damp through the restitution)."""
        return 0.0

    @property
    def dashpot_setting(self) -> float | None:
        """The damping parameter as set (N s/m), or None for a law without a dashpot."""
        return None

    @property
    def hertz_stiffness(self) -> float | None:
        """``stiffness`` when the elastic force is ``K delta**1.5``: a Hertz-type constant in
        N/m**1.5, comparable with a steel pair's :func:`.contact.cylinder_stiffness`; None for
        another exponent, a linear law or a line contact."""
        return self.stiffness if self.elastic_exponent == 1.5 else None

    def stiffness_for_tangent(self, k_target: float, k_lin: float) -> float:
        """The stiffness parameter whose tangent stiffness at the same load would be
        ``k_target`` N/m, given ``k_lin`` at the present one: ``K_lin`` goes as ``K**(1/n)``
        (``n F / delta`` with ``delta = (F/K)**(1/n)``), so ``K (k_target / k_lin)**n``."""
        return self.stiffness * (k_target / k_lin) ** self.elastic_exponent


@dataclass(frozen=True)
class Hertz(NormalLaw):
    """``K delta**n``, no dissipation. ``stiffness`` K in N/m**n, ``exponent`` n."""

    stiffness: float
    exponent: float = 1.5
    name: ClassVar[str] = "hertz"
    code: ClassVar[int] = 0

    def __post_init__(self):
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "exponent", _positive("exponent", self.exponent))

    def force(self, delta, delta_dot=0.0, v_impact=1.0):
        return contact.hertz(delta, self.stiffness, self.exponent)

    def vector(self):
        return np.array([self.stiffness, self.exponent, 0.0, 0.0, 0.0])


@dataclass(frozen=True)
class KelvinVoigt(NormalLaw):
    """Linear spring-dashpot ``K delta + c delta_dot``: ``stiffness`` N/m, ``damping`` N s/m."""

    stiffness: float
    damping: float
    name: ClassVar[str] = "kelvin_voigt"
    code: ClassVar[int] = 1

    def __post_init__(self):
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "damping", _non_negative("damping", self.damping))

    elastic_exponent: ClassVar[float] = 1.0

    def force(self, delta, delta_dot, v_impact=1.0):
        return contact.kelvin_voigt(delta, delta_dot, self.stiffness, self.damping)

    def vector(self):
        return np.array([self.stiffness, 1.0, self.damping, 0.0, 0.0])

    def static_penetration(self, load):
        """``F / K``, m."""
        return load / self.stiffness

    def tangent_stiffness(self, load):
        """``K`` at every load, N/m."""
        return self.stiffness

    def dashpot(self, load):
        """``damping`` at every load, N s/m."""
        return self.damping

    @property
    def dashpot_setting(self):
        return self.damping

    def stiffness_for_tangent(self, k_target, k_lin):
        """``k_target`` itself (the tangent stiffness is ``K``)."""
        return k_target


@dataclass(frozen=True)
class PowerDamped(NormalLaw):
    """``K delta**n + c delta_dot``: ``stiffness`` N/m**n, ``exponent``, ``damping`` N s/m."""

    stiffness: float
    damping: float
    exponent: float = 1.5
    name: ClassVar[str] = "power_damped"
    code: ClassVar[int] = 2

    def __post_init__(self):
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "exponent", _positive("exponent", self.exponent))
        object.__setattr__(self, "damping", _non_negative("damping", self.damping))

    def force(self, delta, delta_dot, v_impact=1.0):
        return contact.power_damped(delta, delta_dot, self.stiffness, self.exponent, self.damping)

    def vector(self):
        return np.array([self.stiffness, self.exponent, self.damping, 0.0, 0.0])

    def dashpot(self, load):
        """``damping`` at every load, N s/m."""
        return self.damping

    @property
    def dashpot_setting(self):
        return self.damping


@dataclass(frozen=True)
class Impact(NormalLaw):
    """ADAMS IMPACT ``K delta**n + STEP(delta, 0, 0, d_max, c_max) delta_dot``.

    ``stiffness`` N/m**n, ``exponent``, ``damping`` c_max in N s/m, ``penetration`` d_max in m.
    """

    stiffness: float
    damping: float
    penetration: float
    exponent: float = 1.5
    name: ClassVar[str] = "impact"
    code: ClassVar[int] = 3

    def __post_init__(self):
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "exponent", _positive("exponent", self.exponent))
        object.__setattr__(self, "damping", _non_negative("damping", self.damping))
        object.__setattr__(self, "penetration", _positive("penetration", self.penetration))

    def force(self, delta, delta_dot, v_impact=1.0):
        return contact.impact(delta, delta_dot, self.stiffness, self.exponent, self.damping,
                              self.penetration)

    def vector(self):
        return np.array([self.stiffness, self.exponent, self.damping, self.penetration, 0.0])

    dashpot_varies: ClassVar[bool] = True

    def dashpot(self, load):
        """``STEP(delta, 0, 0, penetration, damping)`` at the static penetration of ``load``,
        N s/m: an estimate only (the penetration of a run wanders around it)."""
        d = self.static_penetration(load)
        return float(contact.step(d, 0.0, 0.0, self.penetration, self.damping))

    @property
    def dashpot_setting(self):
        """``damping``: the full damping ``c_max`` the STEP ramp reaches, N s/m."""
        return self.damping


@dataclass(frozen=True)
class _Hysteresis(NormalLaw):
    """``K delta**n (1 + chi(e, v_impact) delta_dot)``: ``stiffness``, ``exponent``,
    ``restitution`` e in (0, 1]."""

    stiffness: float
    restitution: float
    exponent: float = 1.5
    needs_impact_velocity: ClassVar[bool] = True

    def __post_init__(self):
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "exponent", _positive("exponent", self.exponent))
        object.__setattr__(self, "restitution", _restitution(self.restitution))

    def hysteresis_factor(self, v_impact):
        """``chi`` in s/m at impact velocity ``v_impact`` (m/s)."""
        return contact.hysteresis_factor(self.name, self.restitution, v_impact)

    def force(self, delta, delta_dot, v_impact=1.0):
        return contact.hysteresis(delta, delta_dot, self.stiffness, self.exponent,
                                  self.hysteresis_factor(v_impact))

    def vector(self):
        return np.array([self.stiffness, self.exponent, 0.0, self.restitution, 0.0])


@dataclass(frozen=True)
class HuntCrossley(_Hysteresis):
    """Hunt & Crossley (1975): ``chi = 3 (1 - e) / (2 v)``."""

    name: ClassVar[str] = "hunt_crossley"
    code: ClassVar[int] = 4


@dataclass(frozen=True)
class LankaraniNikravesh(_Hysteresis):
    """Lankarani & Nikravesh (1990): ``chi = 3 (1 - e**2) / (4 v)``."""

    name: ClassVar[str] = "lankarani_nikravesh"
    code: ClassVar[int] = 5


@dataclass(frozen=True)
class Flores(_Hysteresis):
    """Flores et al. (2011): ``chi = 8 (1 - e) / (5 e v)``."""

    name: ClassVar[str] = "flores"
    code: ClassVar[int] = 6


@dataclass(frozen=True)
class JohnsonCylinder(NormalLaw):
    """Johnson's conformal-cylinder force with Lankarani-Nikravesh damping.

    ``stiffness`` pi L E* in N/m, ``radial_clearance`` dR in m, ``restitution`` e in (0, 1]
    (see :func:`.contact.johnson_cylinder_force`).
    """

    stiffness: float
    radial_clearance: float
    restitution: float
    name: ClassVar[str] = "johnson_cylinder"
    code: ClassVar[int] = 7
    needs_impact_velocity: ClassVar[bool] = True

    def __post_init__(self):
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "radial_clearance",
                           _positive("radial_clearance", self.radial_clearance))
        object.__setattr__(self, "restitution", _restitution(self.restitution))

    def force(self, delta, delta_dot, v_impact=1.0):
        chi = contact.hysteresis_factor(self.name, self.restitution, v_impact)
        f = contact.johnson_cylinder_force(delta, self.stiffness, self.radial_clearance)
        return np.where(np.asarray(delta, float) > 0.0,
                        np.maximum(f * (1.0 + chi * np.asarray(delta_dot, float)), 0.0), 0.0)

    def elastic_force(self, delta):
        return contact.johnson_cylinder_force(delta, self.stiffness, self.radial_clearance)

    def elastic_energy(self, delta):
        return contact.johnson_cylinder_energy(delta, self.stiffness, self.radial_clearance)

    def vector(self):
        return np.array([self.stiffness, 1.0, 0.0, self.restitution, self.radial_clearance])

    #: ``K_lin`` goes as ``K`` up to a logarithm
    tangent_scales_exactly: ClassVar[bool] = False

    @property
    def hertz_stiffness(self):
        """None: ``stiffness`` is pi L E* of a line contact (N/m), not a Hertz constant."""
        return None

    def static_penetration(self, load):
        """Johnson's approach under ``load`` N (:func:`.contact.johnson_cylinder_approach`), m."""
        return float(contact.johnson_cylinder_approach(load, self.stiffness,
                                                       self.radial_clearance))

    def tangent_stiffness(self, load):
        """:func:`.contact.johnson_cylinder_stiffness` at the static penetration, N/m."""
        return float(contact.johnson_cylinder_stiffness(self.static_penetration(load),
                                                        self.stiffness, self.radial_clearance))

    def stiffness_for_tangent(self, k_target, k_lin):
        """``K k_target / k_lin`` (``K_lin`` is ``K`` over a logarithm of the load), N/m."""
        return self.stiffness * k_target / k_lin


#: normal force laws by name
LAWS: dict[str, type[NormalLaw]] = {c.name: c for c in (
    Hertz, KelvinVoigt, PowerDamped, Impact, HuntCrossley, LankaraniNikravesh, Flores,
    JohnsonCylinder)}


def _build(registry, kind, name, params):
    from ...errors import ParameterError

    try:
        cls = registry[name]
    except (KeyError, TypeError):
        raise ParameterError("name", f"unknown {kind} law {name!r}; known: "
                             f"{', '.join(registry)}") from None
    params = dict(params or {})
    kw = {}
    for f in fields(cls):
        if f.name in params and params[f.name] is not None:
            kw[f.name] = params[f.name]
    missing = [f.name for f in fields(cls) if f.name not in kw and f.default is MISSING]
    if missing:
        raise ParameterError(missing[0], f"{kind} law {name!r} needs parameter {missing[0]!r}")
    return cls(**kw)


def make_law(name: str, params=None) -> NormalLaw:
    """A normal law from its name and a ``law_params`` mapping (unused keys ignored).

    Parameters
    ----------
    name : str
        The law's scene name (``hertz``, ``hunt_crossley``, ``lankarani_nikravesh``, ``flores``,
        ``kelvin_voigt``, ``johnson_cylinder``, ...).
    params : mapping, optional
        Its parameters (``stiffness`` in N/m**exponent, ``exponent``, ``restitution``, ...).

    Returns
    -------
    NormalLaw

    Examples
    --------
    Hertz's law, ``F = K delta**1.5``: 1 um into a 1e10 N/m**1.5 contact is 10 N.

    >>> import crankmodal as cm
    >>> law = cm.make_law("hertz", {"stiffness": 1e10, "exponent": 1.5})
    >>> print(f"{law.force(1e-6, 0.0, 0.0):.6f} N")
    10.000000 N

    Raises
    ------
    ParameterError
        A ValueError naming ``name`` (unknown law), a missing parameter, or the parameter
        whose value is invalid.
    """
    return _build(LAWS, "normal force", name, params)


# ---------------------------------------------------------------------------------- friction
@dataclass(frozen=True)
class FrictionLaw:
    """Base of the friction laws: ``coefficient(v)`` signed like the slip velocity ``v``.

    A law is a frozen dataclass of its parameters (coefficients, and transition velocities in
    m/s); ``coefficient(v)`` is the friction coefficient at slip velocity ``v`` (m/s). Build one
    by name with :func:`make_friction`.

    Attributes
    ----------
    name : str
        The law's scene name (``contact.friction``).
    code : int
        Its number in the compiled kernel.
    """

    name: ClassVar[str] = ""
    code: ClassVar[int] = -1

    def params(self) -> dict:
        return asdict(self)

    def coefficient(self, v):
        raise NotImplementedError

    def vector(self) -> np.ndarray:
        """``[mu_s, mu_d, v_s, v_d]`` for the compiled kernel (unused entries 0)."""
        raise NotImplementedError


def _transition(law) -> None:
    """Check (and set as floats) ``v_static < v_dynamic``, both > 0 (m/s)."""
    from ...errors import ParameterError

    for k in ("v_static", "v_dynamic"):
        object.__setattr__(law, k, _positive(k, getattr(law, k)))
    if law.v_dynamic <= law.v_static:
        raise ParameterError("v_dynamic", f"must be > v_static ({law.v_static:g} m/s), got "
                             f"{law.v_dynamic:g}")


@dataclass(frozen=True)
class NoFriction(FrictionLaw):
    """Frictionless contact."""

    name: ClassVar[str] = "none"
    code: ClassVar[int] = 0

    def coefficient(self, v):
        return np.zeros_like(np.asarray(v, float))

    def vector(self):
        return np.zeros(4)


@dataclass(frozen=True)
class Coulomb(FrictionLaw):
    """Coulomb friction with a static/dynamic transition (ADAMS style).

    ``mu_static``, ``mu_dynamic``; ``v_static`` and ``v_dynamic`` (m/s): see :func:`.contact.coulomb_coefficient`.
    """

    mu_static: float
    mu_dynamic: float
    v_static: float
    v_dynamic: float
    name: ClassVar[str] = "coulomb"
    code: ClassVar[int] = 1

    def __post_init__(self):
        for k in ("mu_static", "mu_dynamic"):
            object.__setattr__(self, k, _non_negative(k, getattr(self, k)))
        _transition(self)

    def coefficient(self, v):
        return contact.coulomb_coefficient(v, self.mu_static, self.mu_dynamic, self.v_static,
                                           self.v_dynamic)

    def vector(self):
        return np.array([self.mu_static, self.mu_dynamic, self.v_static, self.v_dynamic])


@dataclass(frozen=True)
class Ambrosio(FrictionLaw):
    """Ambrosio's modified Coulomb law ``mu_dynamic c_d(v)``, ``c_d`` linear from 0 at
    ``v_static`` to 1 at ``v_dynamic`` (m/s)."""

    mu_dynamic: float
    v_static: float
    v_dynamic: float
    name: ClassVar[str] = "ambrosio"
    code: ClassVar[int] = 2

    def __post_init__(self):
        object.__setattr__(self, "mu_dynamic", _non_negative("mu_dynamic", self.mu_dynamic))
        _transition(self)

    def coefficient(self, v):
        return contact.ambrosio_coefficient(v, self.mu_dynamic, self.v_static, self.v_dynamic)

    def vector(self):
        return np.array([0.0, self.mu_dynamic, self.v_static, self.v_dynamic])


#: friction laws by name
FRICTION: dict[str, type[FrictionLaw]] = {c.name: c for c in (NoFriction, Coulomb, Ambrosio)}


def make_friction(name: str, params=None) -> FrictionLaw:
    """A friction law from its name and a ``friction_params`` mapping (unused keys ignored).

    Parameters
    ----------
    name : str
        ``none``, ``coulomb`` (static/dynamic transition) or ``ambrosio``.
    params : mapping, optional
        Its parameters: ``mu_static``, ``mu_dynamic`` (-), ``v_static``, ``v_dynamic`` (m/s), ...

    Returns
    -------
    FrictionLaw
        ``coefficient(v)`` is the signed coefficient at slip velocity ``v`` (m/s).

    Raises
    ------
    ParameterError
        A ValueError naming ``name`` (unknown law), a missing parameter, or the parameter
        whose value is invalid.

    Examples
    --------
    Past the transition velocity Coulomb friction is the dynamic coefficient:

    >>> import crankmodal as cm
    >>> law = cm.make_friction("coulomb", {"mu_static": 0.2, "mu_dynamic": 0.1,
    ...                                    "v_static": 1e-4, "v_dynamic": 1e-2})
    >>> float(law.coefficient(1.0))
    0.1
    """
    return _build(FRICTION, "friction", name, params)


def legacy_laws(law, law_params=None, friction=None, friction_params=None,
                stacklevel: int = 3) -> tuple[NormalLaw, FrictionLaw]:
    """The law objects of the deprecated name form ``law="impact", law_params={...}``.

    The one place where law names and parameter dictionaries of the Python API become objects
    (a scene's are made by its stage). Law objects pass through unchanged; a name or a
    parameter dictionary issues a :class:`DeprecationWarning` (pass ``make_law(name, params)``
    or the law's class instead).

    Parameters
    ----------
    law : NormalLaw or str
        The normal law, or its name (with ``law_params``).
    law_params : mapping or None
        Parameters of a normal law given by name (SI: ``stiffness`` N/m**exponent, ...).
    friction : FrictionLaw, str or None
        The friction law, or its name (with ``friction_params``); None: no friction.
    friction_params : mapping or None
        ``mu_static``, ``mu_dynamic`` (-), ``v_static``, ``v_dynamic`` (m/s) of a friction law
        given by name.
    stacklevel : int
        Of the warning (2 points at the caller of this function).

    Returns
    -------
    (NormalLaw, FrictionLaw)

    Raises
    ------
    ParameterError
        Naming ``law`` (neither a law nor a name), the unknown name's argument, or the law
        parameter that is missing or invalid (``stiffness``, ``restitution``, ...).
    """
    import warnings

    from ...errors import ParameterError

    named = []
    if isinstance(law, str):
        named.append(f"law={law!r}, law_params={{...}}")
        try:
            law = make_law(law, law_params)
        except ParameterError as exc:
            raise ParameterError("law" if exc.argument == "name" else exc.argument,
                                 exc.text) from None
    elif law_params:
        raise ParameterError("law_params", "goes with a law given by name; a law object "
                             "carries its own parameters")
    if not isinstance(law, NormalLaw):
        raise ParameterError("law", f"must be a NormalLaw (e.g. Impact(...), or make_law(name, "
                             f"params)), got {type(law).__name__} {law!r:.60}")
    if friction is None:
        friction = "none" if friction_params else NoFriction()
    if isinstance(friction, str):
        named.append(f"friction={friction!r}, friction_params={{...}}")
        try:
            friction = make_friction(friction, friction_params)
        except ParameterError as exc:
            raise ParameterError("friction" if exc.argument == "name" else exc.argument,
                                 exc.text) from None
    elif friction_params:
        raise ParameterError("friction_params", "goes with a friction law given by name; a "
                             "law object carries its own parameters")
    if not isinstance(friction, FrictionLaw):
        raise ParameterError("friction", f"must be a FrictionLaw (e.g. Coulomb(...), "
                             f"NoFriction(), or make_friction(name, params)), got "
                             f"{type(friction).__name__} {friction!r:.60}")
    if named:
        warnings.warn(f"{' and '.join(named)} is deprecated: pass the law objects "
                      f"(law={type(law).__name__}(...), make_law(name, params))",
                      DeprecationWarning, stacklevel=stacklevel)
    return law, friction

