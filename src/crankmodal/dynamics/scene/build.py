"""From validated ``[dynamics]`` parameters to a :class:`~.mechanisms.Mechanism` and solver settings."""

from __future__ import annotations

import numpy as np

from ...errors import SceneError
from ..laws import contact
from ..model.loads import tabulated_gas_force
from ..model.mechanisms import Cylinder, crank_train, four_bar
from ..run.integrate import SolverSettings, auto_method
from .keys import cylinder_angles


def contact_arguments(p) -> tuple[dict, dict]:
    """Shared clearance-joint keywords and per-joint specs from the parameters."""
    c, f = p["contact"], p["friction"]
    law_params = {"exponent": c["exponent"], "damping": c["damping"],
                  "penetration": c["penetration"], "restitution": c["restitution"]}
    if c["stiffness"] is not None:
        law_params["stiffness"] = c["stiffness"]
    kw = {"law": c["law"], "law_params": law_params, "friction": f["law"],
          "friction_params": {k: f[k] for k in ("mu_static", "mu_dynamic", "v_static",
                                                "v_dynamic")},
          "v_impact_min": c["v_impact_min"]}
    specs = {}
    for cl in p["clearances"]:
        spec = {"clearance": cl["clearance"], "journal_radius": cl["journal_radius"],
                "clearance_major": cl["clearance_major"],
                "wear_angle": float(np.deg2rad(cl["wear_angle_deg"])),
                "viscosity": cl["viscosity"], "bearing_length": cl["bearing_length"] or 0.0,
                "film_model": cl["film_model"]}
        if c["law"] == "johnson_cylinder":  # a line contact: its own stiffness pi L E*, and dR
            K = c["stiffness"]
            if K is None:
                K = np.pi * cl["bearing_length"] * contact.effective_modulus(c["E"], c["nu"],
                                                                             c["E"], c["nu"])
            spec["contact"] = {"law_params": dict(law_params, stiffness=float(K),
                                                  radial_clearance=cl["clearance"])}
        elif c["stiffness"] is None:
            rj = cl["journal_radius"]
            K = contact.cylinder_stiffness(rj, rj + cl["clearance"], c["E"], c["nu"], c["E"], c["nu"])
            spec["contact"] = {"law_params": dict(law_params, stiffness=float(K))}
        specs[cl["joint"]] = spec
    return kw, specs


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
    kw, specs = contact_arguments(p)
    gas = None
    if p["gas_force_deg"] is not None:
        gas = tabulated_gas_force(p["gas_force_deg"], p["gas_force_n"], p["gas_cycle_deg"])
    direction = -1 if p["rotation"] == "cw" else 1
    ct = p["crank_train"]
    if p["from_mechanism"]:
        from ..model.bridge import cylinders_from_mechanism

        src = cylinders_from_mechanism(mechanism_params, p["ring_friction_n"])
        check_ring_friction(p["ring_friction_n"], src["cylinders"])
        speed = p["speed_rpm"] or src["speed_rpm"]
        common = _common(p, speed, specs, kw, src["direction"])
        # the mechanism's unbalance at the pin, less a counterweight opposite it (both kg m)
        mr = src["crank_unbalance"] - ct["counterweight_mass_radius"]
        com = mr / ct["crank_mass"] if ct["crank_mass"] > 0 else 0.0
        return crank_train(src["crank_radius"], src["cylinders"], crank_mass=ct["crank_mass"],
                           crank_inertia=ct["crank_inertia"], crank_com=com, kind=p["mechanism"],
                           **common, **body_kw)
    common = _common(p, p["speed_rpm"], specs, kw, direction)
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


def _common(p, speed_rpm, specs, kw, direction):
    return {"speed_rpm": speed_rpm, "theta0": np.deg2rad(p["initial_angle_deg"]),
            "ramp_time": p["ramp_time"], "drive_torque": p["drive_torque"], "clearances": specs,
            "contact_kw": kw, "gravity": tuple(p["gravity"]),
            "baumgarte": p["solver"]["baumgarte"], "direction": direction}


def solver_settings(p, speed_rpm, flexible: bool = False) -> SolverSettings:
    """Integrator settings; tolerances scale with the smallest clearance. ``flexible``: the
    mechanism has flexible bodies (their modes take part in the choice of ``method = auto``)."""
    s = p["solver"]
    cmin = min((c["clearance"] for c in p["clearances"]), default=1e-3)
    atol = s["atol"] if s["atol"] is not None else min(1e-9, cmin * 1e-4)
    omega = speed_rpm * 2 * np.pi / 60
    method = s["method"]
    if method == "auto":  # the API's simulate decides with the same function
        fr = p["friction"]
        method = auto_method([(c["journal_radius"], fr["law"], fr["v_dynamic"],
                               c["viscosity"] is not None) for c in p["clearances"]],
                             omega, flexible)
    return SolverSettings(method=method, rtol=s["rtol"], atol=atol,
                          velocity_scale=max(1000.0, 10 * omega),
                          max_step=np.deg2rad(s["max_step_deg"]) / omega,
                          max_rhs_evals=s["max_rhs_evals"])
