"""Time histories of a run: motion, joint forces, contact, drive and the energy balance.

Everything is re-evaluated from the integrated states with the same equations the integrator
used, so accelerations and multipliers at the output times are those of the model, not finite
differences of the output.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.joints import AngleDrive, Revolute
from ..model.system import AUX_NAMES, N_AUX
from .torsional import torsion_histories


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
        work_constraints, dissipated_contact, dissipated_friction, residual; with flexible
        bodies also strain; dissipated_modal (modal damping, integrated with the run).
    constraint_drift : (K,) max ``|Phi|``, m or rad.
    onsets : dict joint -> [(t, v_impact)] contact onsets (s, m/s), every zero crossing.
    separations : dict joint -> [t] contact separations, s.
    angular_acceleration : dict body name -> (K,) rad/s^2 (e.g. the loom's rocker and sley; a
        flexible body's: of its frame, the mean axes).
    peaks : dict joint -> dict of arrays at the deepest penetration of each contact (located as
        events, not sampled): ``t`` (s), ``fn`` (N), ``penetration`` (m), ``main_bearing_force``
        (magnitude, N) and ``piston_acceleration`` (n, P) (m/s^2) at that instant.
    modal : dict body name -> (K, k) the flexible bodies' modal coordinates (elastic, then
        tilts), m kg^½ (tilts in rad).
    torsion : dict name -> (K,) torsional histories of a crank train with a motor or a
        flexible crank (:func:`.torsional.torsion_histories`: ``motor_angle`` rad,
        ``motor_speed`` rad/s, ``coupling_twist`` rad, ``coupling_torque`` N m,
        ``twist_<frame>``, ``twist_free_end`` rad).
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
    peaks: dict = field(default_factory=dict)
    nfev: int = 0
    wall_time: float = 0.0
    modal: dict = field(default_factory=dict)
    torsion: dict = field(default_factory=dict)

    def energy_error(self) -> float:
        """Largest ``|residual|`` of the energy balance relative to the energy exchanged in the run
        (:meth:`energy_scale`), not to the largest energy term: a flywheel's kinetic energy or a
        potential energy with an arbitrary zero would hide a drift of the energy that moves."""
        scale = self.energy_scale()
        res = float(np.max(np.abs(self.energy["residual"]), initial=0.0))
        if scale == 0.0:
            return 0.0 if res == 0.0 else float("inf")
        return res / scale

    def energy_scale(self) -> float:
        """Energy exchanged during the run, J.

        The largest excursions of the kinetic, potential and contact elastic energies from their
        initial values plus the cumulative |work| of the drive, the loads and the ideal
        constraints and the energy dissipated by contact damping and friction (each work term's
        total variation over the output samples: a lower bound of its integral of |power|).
        """
        e = self.energy
        scale = 0.0
        for k in ("kinetic", "potential", "contact_elastic", "strain"):
            if k in e and e[k].size:
                scale += float(np.max(np.abs(e[k] - e[k][0])))
        for k in AUX_NAMES:
            if k in e and e[k].size > 1:
                scale += float(np.sum(np.abs(np.diff(e[k]))))
        return scale

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
        for name, pk in self.peaks.items():
            for k, v in pk.items():
                out[f"peaks_{name}_{k}"] = v
        for name, v in self.modal.items():
            out[f"modal_{name}"] = v
        for name, v in self.torsion.items():
            out[f"torsion_{name}"] = v
        return out

    def peak(self, key: str, sampled, name: str | None = None, since: float | None = None,
             until: float | None = None):
        """Largest magnitude of a sampled quantity and of its values at the contacts' deepest
        points (``key`` of :attr:`peaks`; every joint's, or joint ``name``'s; the events from
        time ``since`` on and up to ``until``, s, if given — the samples are the caller's to
        select).

        ``sampled`` of shape (K,) gives a float; of shape (K, P), one peak per column.
        """
        sampled = np.abs(np.asarray(sampled, float))
        parts = [sampled]
        for j, pk in self.peaks.items():
            if name is None or j == name:
                tk = np.asarray(pk["t"], float)
                keep = np.ones(tk.size, bool)
                if since is not None:
                    keep &= tk >= since
                if until is not None:
                    keep &= tk <= until
                parts.append(np.abs(pk[key]).reshape((len(pk["t"]),) + sampled.shape[1:])[keep])
        out = np.max(np.concatenate(parts), axis=0, initial=0.0)
        return float(out) if out.ndim == 0 else out


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
    # every body's frame (a flexible body's mean axes, e.g. the four-bar's flexible rocker)
    alpha = {b.name: np.zeros(K) for b in sysm.bodies}
    elastic = bool(getattr(sysm, "_elastic", ()))
    if elastic:
        energy["strain"] = np.zeros(K)
    for k in range(K):
        q, qd = integ.y[:n, k], integ.y[n:2 * n, k]
        out = _solve_at(sysm, integ, integ.t[k], q, qd)
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
        if elastic:
            energy["strain"][k] = sysm.strain_energy(q)
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
    if elastic:
        # modal damping work: a running integral of the ODE (AUX_NAMES), not of the samples
        e_mech = e_mech + energy["strain"] + energy["dissipated_modal"]
    energy["residual"] = (e_mech - e_mech[0]) - (energy["work_drive"] + energy["work_loads"]
                                                + energy["work_constraints"]
                                                - energy["dissipated_contact"]
                                                - energy["dissipated_friction"])
    # the force of the crank on the housing: the sum over its main journals
    main = np.zeros((K, 2))
    for name in _main_joints(mech):
        main = main + forces.get(name, 0.0)
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
                                for i, cj in enumerate(sysm.clearances)},
                   peaks=_record_peaks(mech, sysm, integ, pins),
                   modal={b.name: integ.y[sysm.slices[id(b)].start + 3: sysm.slices[id(b)].stop].T
                          .copy() for b in getattr(sysm, "_elastic", ())},
                   torsion=torsion_histories(mech, sysm, integ))


def _main_joints(mech) -> list:
    """The joints between the crank and the housing (one per main journal)."""
    return getattr(mech, "main_joints", None) or [mech.main_joint]


def _solve_at(sysm, integ, t, q, qd) -> dict:
    """``sysm.solve`` at one state, with each clearance joint's contact in progress (the
    impact velocities passed in, as the integrator does; no state left in the joints)."""
    v = np.array([_impact_velocity(ons, t, cj)
                  for cj, ons in zip(sysm.clearances, integ.onsets)], float)
    return sysm.solve(t, q, qd, v_impact=v if len(v) else None)


def _record_peaks(mech, sysm, integ, pins) -> dict:
    """Contact force, main-bearing force and piston accelerations at each contact's deepest
    penetration (the integrator's ``peak`` events)."""
    n = sysm.n
    rows = {c.name: r for c, r in pins}
    names = [cj.name for cj in sysm.clearances]
    piston_sl = [sysm.slices[id(p)] for p in mech.pistons]
    out = {}
    for j, cj in enumerate(sysm.clearances):
        ev = integ.peaks[j] if j < len(integ.peaks) else []
        d = {"t": np.zeros(len(ev)), "fn": np.zeros(len(ev)), "penetration": np.zeros(len(ev)),
             "main_bearing_force": np.zeros(len(ev)),
             "piston_acceleration": np.zeros((len(ev), len(piston_sl)))}
        for k, (t, y) in enumerate(ev):
            s = _solve_at(sysm, integ, t, y[:n], y[n:2 * n])
            ck = s["contacts"][j]
            d["t"][k], d["fn"][k], d["penetration"][k] = t, ck["fn"], ck["delta"]
            f = np.zeros(2)
            for name in _main_joints(mech):
                if name in rows:
                    f = f + s["lam"][rows[name]]
                elif name in names:
                    f = f + s["contacts"][names.index(name)]["force"]
            d["main_bearing_force"][k] = float(np.hypot(f[0], f[1]))
            for i, sl in enumerate(piston_sl):
                d["piston_acceleration"][k, i] = mech.axes[i] @ s["qdd"][sl][:2]
        out[cj.name] = d
    return out


def _impact_velocity(onsets, t, cj) -> float:
    """Impact velocity of the contact in progress at ``t`` (last onset at or before ``t``)."""
    v = cj.v_impact_min
    for te, ve in onsets:
        if te <= t:
            v = ve
        else:
            break
    return max(v, cj.v_impact_min)
