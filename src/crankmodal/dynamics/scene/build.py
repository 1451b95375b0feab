"""From validated ``[dynamics]`` parameters to a :class:`~.mechanisms.Mechanism` and solver settings."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError, SceneError, scene_keys
from ..laws import contact
from ..laws.objects import FrictionLaw, NormalLaw, make_friction, make_law
from ..model.clearance import ClearanceSpec
from ..model.loads import tabulated_gas_force
from ..model.mechanisms import Cylinder, crank_train, four_bar
from ..run.integrate import SolverSettings, auto_method
from .keys import cylinder_angles

#: law parameter (argument of :mod:`..laws.objects`) -> its ``[dynamics.contact]`` key
NORMAL_LAW_KEYS = {"stiffness": "stiffness", "exponent": "exponent", "damping": "damping",
                   "penetration": "penetration", "restitution": "restitution",
                   "radial_clearance": "stiffness", "law": "law"}
#: what the core's advice names (the law's and the solver settings' arguments, simulate's
#: t_end) -> the key under ``[dynamics]`` a scene's user changes (:func:`scene_words`)
ADVICE_KEYS = {"law.stiffness": "contact.stiffness", "law.damping": "contact.damping",
               "settings.rtol": "solver.rtol", "settings.atol": "solver.atol",
               "settings.max_step": "solver.max_step_deg", "settings.method": "solver.method",
               "settings.max_rhs_evals": "solver.max_rhs_evals", "t_end": "end_time"}
#: :func:`..results.validity.penetration_warning`'s words in a scene
CONTACT_WORDS = {"stiffness": "dynamics.contact.stiffness",
                 "johnson_cylinder": "dynamics.contact.law = 'johnson_cylinder'"}


def relabel(text: str, keys: dict = ADVICE_KEYS) -> str:
    """``text`` with each argument named in ``keys`` (whole words) replaced by its scene key."""
    import re

    for argument, key in keys.items():
        text = re.sub(rf"(?<![\w.]){re.escape(argument)}(?![\w])", key, text)
    return text


class scene_words:
    """Re-raise a :class:`~crankmodal.errors.NumericalError` or
    :class:`~crankmodal.errors.SceneError` of the block with the arguments its advice names
    replaced by their scene keys (:data:`ADVICE_KEYS`; a SceneError's leading key kept)."""

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        from ...errors import NumericalError, SceneError

        if isinstance(exc, NumericalError):
            text = relabel(str(exc))
            if text != str(exc):
                raise NumericalError(text) from None
        elif isinstance(exc, SceneError):
            key, sep, text = str(exc).partition(": ")
            if relabel(text) != text:
                raise SceneError(key + sep + relabel(text)) from None
        return False


#: :class:`ClearanceSpec` field -> its ``[[dynamics.clearances]]`` key
CLEARANCE_KEYS = {"wear_angle": "wear_angle_deg", "normal": "law", "friction": "law",
                  "v_impact_min": "v_impact_min"}


def friction_law(p) -> FrictionLaw:
    """The ``[dynamics.friction]`` law object (law errors relabelled with its keys)."""
    f = p["friction"]
    with scene_keys("dynamics.friction", {"name": "law"}):
        return make_friction(f["law"], {k: f[k] for k in ("mu_static", "mu_dynamic",
                                                          "v_static", "v_dynamic")})


def normal_law(p, clearance: dict) -> NormalLaw:
    """The ``[dynamics.contact]`` law object of one ``[[dynamics.clearances]]`` entry: its
    stiffness, when not given, from E, nu and the radii (Hertz constant, N/m^1.5) or, for
    ``johnson_cylinder``, pi L E* (N/m) with the joint's clearance as ``radial_clearance``."""
    c = p["contact"]
    params = {"exponent": c["exponent"], "damping": c["damping"],
              "penetration": c["penetration"], "restitution": c["restitution"],
              "stiffness": c["stiffness"]}
    if c["law"] == "johnson_cylinder":  # a line contact: its own stiffness pi L E*, and dR
        if params["stiffness"] is None:
            params["stiffness"] = float(np.pi * clearance["bearing_length"] * contact.
                                        effective_modulus(c["E"], c["nu"], c["E"], c["nu"]))
        params["radial_clearance"] = clearance["clearance"]
    elif params["stiffness"] is None:
        rj = clearance["journal_radius"]
        if not rj + clearance["clearance"] > rj:  # the bore's radius rounds to the journal's
            raise ParameterError("clearance", f"{clearance['clearance']:.3g} m is lost in the "
                                 f"round-off of the journal radius {rj:.3g} m: the bore cannot "
                                 "be told from the journal")
        params["stiffness"] = float(contact.cylinder_stiffness(
            rj, rj + clearance["clearance"], c["E"], c["nu"], c["E"], c["nu"]))
    with scene_keys("dynamics.contact", NORMAL_LAW_KEYS | {"name": "law"}):
        return make_law(c["law"], params)


def clearance_specs(p) -> dict[str, ClearanceSpec]:
    """``{joint: ClearanceSpec}`` of the ``[[dynamics.clearances]]`` entries: the typed
    description the mechanism builders take, made once here (errors name the scene keys)."""
    friction = friction_law(p)
    specs = {}
    for i, cl in enumerate(p["clearances"]):
        with scene_keys(f"dynamics.clearances[{i}]", CLEARANCE_KEYS):
            specs[cl["joint"]] = ClearanceSpec(
                clearance=cl["clearance"], journal_radius=cl["journal_radius"],
                normal=normal_law(p, cl), friction=friction,
                v_impact_min=p["contact"]["v_impact_min"],
                clearance_major=cl["clearance_major"],
                wear_angle=float(np.deg2rad(cl["wear_angle_deg"])), viscosity=cl["viscosity"],
                bearing_length=cl["bearing_length"], film_model=cl["film_model"])
    return specs


@dataclass(frozen=True)
class Drive:
    """How the crank is driven, as the builders take it.

    Parameters
    ----------
    speed_rpm : float
        Prescribed (or, with ``drive_torque``, initial) crank speed, rpm.
    theta0 : float
        Initial crank angle, rad.
    ramp_time : float
        Speed ramp from rest, s (0: full speed at once).
    drive_torque : float or None
        Constant driving torque, N m (the speed free), or None (speed prescribed).
    direction : int
        1 counter-clockwise, -1 clockwise.
    """

    speed_rpm: float
    theta0: float
    ramp_time: float
    drive_torque: float | None
    direction: int

    def arguments(self) -> dict:
        """The keyword arguments of :func:`~..model.mechanisms.crank_train` and ``four_bar``."""
        return {"speed_rpm": self.speed_rpm, "theta0": self.theta0,
                "ramp_time": self.ramp_time, "drive_torque": self.drive_torque,
                "direction": self.direction}


#: shortest admissible time constant m v_f / F of a piston's smoothed ring friction, s: below it
#: the friction is a damper so stiff that the explicit integrator crawls through every step
MIN_FRICTION_TIME = 1e-7


def check_ring_friction(force: float, cylinders) -> None:
    """Refuse a ring friction that would make each piston a near-rigid damper (SceneError)."""
    from ..model.loads import PistonLoads

    if force <= 0.0:
        return
    v_f = PistonLoads.friction_velocity
    m = min(c.piston_mass for c in cylinders)
    if m * v_f / force < MIN_FRICTION_TIME:
        raise SceneError(
            f"dynamics.ring_friction_n: {force:.3g} N, smoothed over {v_f:g} m/s, damps the "
            f"{m:.3g} kg piston with a time constant of {m * v_f / force:.2g} s, which no "
            f"integrator step can follow; must be <= {m * v_f / MIN_FRICTION_TIME:.3g} N")


def build_mechanism(p, mechanism_params=None, bodies=None):
    """The mechanism described by validated parameters ``p``.

    ``mechanism_params`` are the validated ``[mechanism]`` parameters, used when
    ``p["from_mechanism"]`` is set. ``bodies`` (crank trains): ``{"crank": (body, roles) or
    None, "rods": [body or None per cylinder] or None}`` replacing the rigid crank and rods
    made from the parameters (:mod:`.flexbuild`); four-bar: ``{"links": {role: body}}``
    (roles crank, coupler, rocker).
    """
    bodies = bodies or {}
    crank, roles = bodies.get("crank") or (None, None)
    body_kw = {"crank_body": crank, "crank_roles": roles, "rod_bodies": bodies.get("rods")}
    specs = clearance_specs(p)
    gas = None
    if p["gas_force_deg"] is not None:
        gas = tabulated_gas_force(p["gas_force_deg"], p["gas_force_n"], p["gas_cycle_deg"])
    direction = -1 if p["rotation"] == "cw" else 1
    ct = p["crank_train"]
    from .trains import machine_cylinders, train_arguments

    body_kw.update(train_arguments(p, crank is not None))
    if p["from_mechanism"]:
        src = machine_cylinders(p, mechanism_params)  # each cylinder on its throw
        body_kw["arrangement"] = src["arrangement"]
        check_ring_friction(p["ring_friction_n"], src["cylinders"])
        speed = p["speed_rpm"] or src["speed_rpm"]
        common = _common(p, speed, specs, src["direction"])
        # the mechanism's unbalance at the pin, less a counterweight opposite it (both kg m)
        mr = src["crank_unbalance"] - ct["counterweight_mass_radius"]
        com = mr / ct["crank_mass"] if ct["crank_mass"] > 0 else 0.0
        return crank_train(src["crank_radius"], src["cylinders"], crank_mass=ct["crank_mass"],
                           crank_inertia=ct["crank_inertia"], crank_com=com, kind=p["mechanism"],
                           **common, **body_kw)
    common = _common(p, p["speed_rpm"], specs, direction)
    if p["mechanism"] == "four_bar":
        fb = p["four_bar"]
        return four_bar(*fb["lengths"], rocker_pivot=fb["rocker_pivot"], masses=fb["masses"],
                        inertias=fb["inertias"], com_fractions=fb["com_fractions"],
                        extra_rocker_inertia=fb["extra_rocker_inertia"], branch=fb["branch"],
                        **common, **{f"{role}_body": b
                                     for role, b in (bodies.get("links") or {}).items()})
    L = ct["rod_length"]
    angles = cylinder_angles(p)
    z = ct["row_z"] or [0.0] * len(angles)
    cyls = [Cylinder(axis_angle=np.deg2rad(a), rod_length=L, rod_mass=ct["rod_mass"],
                     rod_inertia=ct["rod_inertia"] or 0.175 * ct["rod_mass"] * L * L,
                     rod_com=0.3 * L if ct["rod_com"] is None else ct["rod_com"],
                     piston_mass=ct["piston_mass"], offset=ct["offset"], z=zi, gas_force=gas,
                     ring_friction=p["ring_friction_n"])
            for a, zi in zip(angles, z)]
    check_ring_friction(p["ring_friction_n"], cyls)
    return crank_train(ct["crank_radius"], cyls, crank_mass=ct["crank_mass"],
                       crank_inertia=ct["crank_inertia"],
                       crank_com=ct["crank_com"] - (ct["counterweight_mass_radius"] / ct["crank_mass"]
                                                    if ct["crank_mass"] > 0 else 0.0),
                       kind=p["mechanism"], **common, **body_kw)


def _common(p, speed_rpm, specs, direction):
    drive = Drive(speed_rpm=speed_rpm, theta0=float(np.deg2rad(p["initial_angle_deg"])),
                  ramp_time=p["ramp_time"], drive_torque=p["drive_torque"], direction=direction)
    return {**drive.arguments(), "clearances": specs,
            "gravity": tuple(p["gravity"]), "baumgarte": p["solver"]["baumgarte"]}


def solver_settings(p, speed_rpm, flexible: bool = False) -> SolverSettings:
    """Integrator settings; tolerances scale with the smallest clearance. ``flexible``: the
    mechanism has flexible bodies (their modes take part in the choice of ``method = auto``)."""
    s = p["solver"]
    cmin = min((c["clearance"] for c in p["clearances"]), default=1e-3)
    atol = s["atol"] if s["atol"] is not None else min(1e-9, cmin * 1e-4)
    omega = speed_rpm * 2 * np.pi / 60
    method = s["method"]
    if method == "auto":  # the API's simulate decides with the same function
        fr = friction_law(p)
        method = auto_method([(c["journal_radius"], fr.name, float(getattr(fr, "v_dynamic", 0.0)),
                               c["viscosity"] is not None) for c in p["clearances"]],
                             omega, flexible)
    return SolverSettings(method=method, rtol=s["rtol"], atol=atol,
                          velocity_scale=max(1000.0, 10 * omega),
                          max_step=np.deg2rad(s["max_step_deg"]) / omega,
                          max_rhs_evals=s["max_rhs_evals"])
