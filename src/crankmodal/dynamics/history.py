"""Time histories of a run: motion, joint forces, contact, drive and the energy balance.

Everything is re-evaluated from the integrated states with the same equations the integrator
used, so accelerations and multipliers at the output times are those of the model, not finite
differences of the output.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .joints import AngleDrive, Revolute
from .system import AUX_NAMES, N_AUX


@dataclass
class History:
    """Sampled results of one run (SI units; ``[k]`` indexes output times).

    Attributes
    ----------
    t : (K,) s.
    crank_angle, crank_speed : (K,) rad, rad/s.
    piston_position, piston_velocity, piston_acceleration : (K, P) along each cylinder axis
        (towards the head), m, m/s, m/s^2.
    joint_forces : dict name -> (K, 2) force of the first body on the second, N (ideal pins);
        for a clearance joint the contact force on the bearing body.
    main_bearing_force : (K, 2) force of the crank on the main bearing (housing), N.
    main_bearing_moment : (K, 2) moment about the crank centre of the big-end forces acting at
        their row positions ``z`` (M_x, M_y), N m.
    drive_torque, drive_power : (K,) N m, W.
    contact : dict joint -> dict of (K,) arrays ``fn`` (N), ``ft`` (N), ``penetration`` (m),
        ``penetration_rate`` (m/s), ``ex``, ``ey`` (eccentricity, global axes, m) and
        ``ex_bearing``, ``ey_bearing`` (the same in the bearing body's frame, m), ``film_force``
        (magnitude of the lubricant film force, N).
    energy : dict of (K,) arrays, J: kinetic, potential, contact_elastic, work_drive, work_loads,
        work_constraints, dissipated_contact, dissipated_friction, residual.
    constraint_drift : (K,) max |Phi|, m or rad.
    onsets : dict joint -> [(t, v_impact)] contact onsets (s, m/s), every zero crossing.
    separations : dict joint -> [t] contact separations, s.
    angular_acceleration : dict body name -> (K,) rad/s^2 (e.g. the loom's rocker and sley).
    """

    t: np.ndarray
    crank_angle: np.ndarray
    crank_speed: np.ndarray
    piston_position: np.ndarray
    piston_velocity: np.ndarray
    piston_acceleration: np.ndarray
    joint_forces: dict
    main_bearing_force: np.ndarray
    main_bearing_moment: np.ndarray
    drive_torque: np.ndarray
    drive_power: np.ndarray
    contact: dict
    energy: dict
    constraint_drift: np.ndarray
    onsets: dict = field(default_factory=dict)
    separations: dict = field(default_factory=dict)
    angular_acceleration: dict = field(default_factory=dict)
    nfev: int = 0
    wall_time: float = 0.0

    def energy_error(self) -> float:
        """Largest |residual| of the energy balance relative to the largest energy term."""
        terms = [v for k, v in self.energy.items() if k != "residual"]
        scale = max(float(np.max(np.abs(v), initial=0.0)) for v in terms)
        if scale == 0.0:
            return 0.0
        return float(np.max(np.abs(self.energy["residual"]), initial=0.0)) / scale

    def arrays(self) -> dict:
        """Flat ``{name: ndarray}`` for ``np.savez``."""
        out = {k: getattr(self, k) for k in ("t", "crank_angle", "crank_speed", "piston_position",
                                             "piston_velocity", "piston_acceleration",
                                             "main_bearing_force", "main_bearing_moment",
                                             "drive_torque", "drive_power", "constraint_drift")}
        for name, f in self.joint_forces.items():
            out[f"joint_force_{name}"] = f
        for name, c in self.contact.items():
            for k, v in c.items():
                out[f"contact_{name}_{k}"] = v
        for k, v in self.energy.items():
            out[f"energy_{k}"] = v
        for name, v in self.angular_acceleration.items():
            out[f"angular_acceleration_{name}"] = v
        for name, ev in self.onsets.items():
            out[f"impacts_{name}"] = np.asarray(ev, float).reshape(-1, 2)
        return out


def record(mech, sysm, integ) -> History:
    """Evaluate a :class:`History` of system ``sysm`` (``mech.system`` or ``mech.ideal``)."""
    n, K = sysm.n, integ.t.size
    P = len(mech.pistons)
    crank_sl = sysm.slices[id(mech.crank)]
    piston_sl = [sysm.slices[id(p)] for p in mech.pistons]
    xs = np.zeros((K, P))
    vs = np.zeros((K, P))
    acc = np.zeros((K, P))
    angle = integ.y[crank_sl.start + 2]
    speed = integ.y[n + crank_sl.start + 2]
    pins = [(c, r) for c, r in zip(sysm.constraints, sysm.rows) if isinstance(c, Revolute)]
    drives = [r for c, r in zip(sysm.constraints, sysm.rows) if isinstance(c, AngleDrive)]
    forces = {c.name: np.zeros((K, 2)) for c, _ in pins}
    for cj in sysm.clearances:
        forces[cj.name] = np.zeros((K, 2))
    contact = {cj.name: {k: np.zeros(K) for k in ("fn", "ft", "penetration", "penetration_rate",
                                                  "ex", "ey", "ex_bearing", "ey_bearing", "film_force")}
               for cj in sysm.clearances}
    torque = np.zeros(K)
    energy = {k: np.zeros(K) for k in ("kinetic", "potential", "contact_elastic")}
    drift = np.zeros(K)
    alpha = {b.name: np.zeros(K) for b in sysm.bodies if b.ndof == 3}
    for k in range(K):
        q, qd = integ.y[:n, k], integ.y[n:2 * n, k]
        for cj, ons in zip(sysm.clearances, integ.onsets):  # the contact in progress
            cj.v_impact = _impact_velocity(ons, integ.t[k], cj)
        out = sysm.solve(integ.t[k], q, qd)
        qdd, lam = out["qdd"], out["lam"]
        for i, sl in enumerate(piston_sl):
            u = mech.axes[i]
            xs[k, i] = u @ q[sl][:2]
            vs[k, i] = u @ qd[sl][:2]
            acc[k, i] = u @ qdd[sl][:2]
        for c, r in pins:
            forces[c.name][k] = lam[r]
        for r in drives:
            torque[k] = -lam[r][0]
        for cj, ck in zip(sysm.clearances, out["contacts"]):
            forces[cj.name][k] = -ck["force"]
            d = contact[cj.name]
            d["fn"][k], d["ft"][k] = ck["fn"], ck["ft"]
            d["penetration"][k], d["penetration_rate"][k] = ck["delta"], ck["delta_dot"]
            d["film_force"][k] = ck["film"]
            d["ex"][k], d["ey"][k] = ck["e"]
            phb = sysm.frame_pose_only(cj.bearing, cj.bearing_frame, q)[2]
            c, sn = np.cos(phb), np.sin(phb)
            d["ex_bearing"][k] = c * ck["e"][0] + sn * ck["e"][1]
            d["ey_bearing"][k] = -sn * ck["e"][0] + c * ck["e"][1]
            energy["contact_elastic"][k] += ck["v_elastic"]
        energy["kinetic"][k], energy["potential"][k] = sysm.energy(q, qd)
        drift[k] = np.max(np.abs(out["phi"]), initial=0.0)
        for b in sysm.bodies:
            if b.name in alpha:
                alpha[b.name][k] = qdd[sysm.slices[id(b)].start + 2]
    if not drives:
        for ld in sysm.loads:
            if hasattr(ld, "torque"):
                torque[:] = ld.torque
    aux = integ.y[2 * n: 2 * n + N_AUX]
    for name, row in zip(AUX_NAMES, aux):
        energy[name] = row.copy()
    e_mech = energy["kinetic"] + energy["potential"] + energy["contact_elastic"]
    energy["residual"] = (e_mech - e_mech[0]) - (energy["work_drive"] + energy["work_loads"]
                                                + energy["work_constraints"]
                                                - energy["dissipated_contact"]
                                                - energy["dissipated_friction"])
    main = forces.get(mech.main_joint, np.zeros((K, 2)))
    moment = np.zeros((K, 2))
    for name, z in mech.rows_z.items():
        f = forces.get(name)
        if f is not None and z != 0.0:
            # the crank receives -f at height z: moment z e_z x (-f) about the crank centre
            moment[:, 0] += z * f[:, 1]
            moment[:, 1] += -z * f[:, 0]
    return History(t=integ.t.copy(), crank_angle=angle, crank_speed=speed, piston_position=xs,
                   piston_velocity=vs, piston_acceleration=acc, joint_forces=forces,
                   main_bearing_force=main, main_bearing_moment=moment, drive_torque=torque,
                   drive_power=torque * speed, contact=contact, energy=energy,
                   constraint_drift=drift, angular_acceleration=alpha,
                   onsets={cj.name: integ.onsets[i] for i, cj in enumerate(sysm.clearances)},
                   separations={cj.name: integ.separations[i]
                                for i, cj in enumerate(sysm.clearances)})


def _impact_velocity(onsets, t, cj) -> float:
    """Impact velocity of the contact in progress at ``t`` (last onset at or before ``t``)."""
    v = cj.v_impact_min
    for te, ve in onsets:
        if te <= t:
            v = ve
        else:
            break
    return max(v, cj.v_impact_min)
