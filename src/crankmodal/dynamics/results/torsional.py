"""Torsional vibration of a crank train: coupling twist and torque, the flexible crank's twist.

Two sources, both from the integrated states (no finite differences):

* a :class:`~..model.drive.MotorDrive`: the motor's angle and speed, the twist across the
  coupling ``motor angle - crank drive-frame angle`` (rad) and the torque it carries to the
  crank ``k tw + c tw_dot`` (N m, the formula of :class:`~..model.loads.TorsionalCoupling`,
  evaluated by it);
* a flexible crank (:class:`~..flexible.body.FlexibleBody`): each crank frame's elastic twist
  relative to the drive frame, ``(r_z,f - r_z,drive)^T xi`` (rad), from the modal coordinates;
  ``twist_free_end`` is that of the main journal farthest from the drive in the journal order
  (the first journal when the drive is not on it, else the last).

:func:`torsional_orders` turns any of them into amplitudes by order over whole working cycles
(:func:`~.signals.order_amplitudes`), :func:`torsional_sweep` runs a list of speeds.
"""

from __future__ import annotations

import numpy as np

from .signals import order_amplitudes


def torsion_histories(mech, sysm, integ) -> dict:
    """``{name: (K,) array}`` of the torsional quantities of the run (see the module docstring);
    empty for a train with neither a motor nor a flexible crank.

    Parameters
    ----------
    mech : Mechanism
    sysm : Multibody
        The system integrated (``mech.system`` or ``mech.ideal``).
    integ : object
        The integrator's output: ``t`` (K,), ``y`` (state rows, K).
    """
    from ..model.loads import TorsionalCoupling

    out = {}
    n = sysm.n
    motor = getattr(mech, "motor", None)
    if motor is not None and id(motor) in sysm.slices:
        sl = sysm.slices[id(motor)]
        out["motor_angle"] = integ.y[sl.start + 2].copy()
        out["motor_speed"] = integ.y[n + sl.start + 2].copy()
        cp = next(ld for ld in sysm.loads if isinstance(ld, TorsionalCoupling))
        K = integ.t.size
        tw, tq = np.zeros(K), np.zeros(K)
        for k in range(K):
            q, qd = integ.y[:n, k], integ.y[n:2 * n, k]
            tq[k] = cp.coupling_torque(sysm, q, qd)[0]
            tw[k] = (sysm.frame_pose_only(cp.a, cp.frame_a, q)[2]
                     - sysm.frame_pose_only(cp.b, cp.frame_b, q)[2])
        out["coupling_twist"] = tw
        out["coupling_torque"] = tq
    crank = mech.crank
    drive = getattr(mech, "drive_frame", None) or mech.main_joint
    frames = getattr(crank, "frames", {})
    # a flexible crank of a crank train (a free flexible body has no drive frame to twist from)
    if crank.ndof > 3 and id(crank) in sysm.slices and drive in frames:
        sl = sysm.slices[id(crank)]
        xi = integ.y[sl.start + 3: sl.stop]
        rz0 = frames[drive][2]
        for frame in _crank_frames(mech):
            if frame in frames:
                out[f"twist_{frame}"] = (frames[frame][2] - rz0) @ xi
        end = free_end_frame(mech)
        if f"twist_{end}" in out:
            out["twist_free_end"] = out[f"twist_{end}"].copy()
    return out


def _crank_frames(mech) -> list:
    """The crank frames whose twist is reported: the pins (once each), then the journals."""
    names = []
    for f in list(getattr(mech, "pin_frames", [])) + list(_main_frames(mech)):
        if f not in names:
            names.append(f)
    return names


def _main_frames(mech) -> list:
    roles = mech.crank.info.get("roles", {}) if hasattr(mech.crank, "info") else {}
    mains = [f"main_{j}" for j in range(1, len(roles.get("mains", [])) + 1)]
    return [f for f in mains if f in mech.crank.frames] or ["main"]


def free_end_frame(mech) -> str:
    """The main journal frame taken as the crank's free end (see the module docstring)."""
    mains = _main_frames(mech)
    drive = getattr(mech, "drive_frame", None)
    crank = mech.crank
    if drive is not None and len(mains) > 1 \
            and np.allclose(crank.frames[drive][2], crank.frames[mains[0]][2]):
        return mains[-1]
    return mains[0]


def torsional_orders(t, signals: dict, revolution_hz: float, orders, t_start: float) -> dict:
    """Amplitudes by order of torsional signals over the whole revolutions from ``t_start``.

    Parameters
    ----------
    t : (K,) s, uniform.
    signals : dict name -> (K,) array (rad or N m).
    revolution_hz : float
        Crank revolutions per second.
    orders : sequence of float
        Orders of the crank speed (half orders for a four-stroke cycle need two revolutions
        per window: give ``t_start`` so that an even number of revolutions follows).
    t_start : float
        Start of the window, s.

    Returns
    -------
    dict
        ``orders`` (list) and per signal the list of amplitudes (its unit), and ``mean``.
    """
    t = np.asarray(t, float)
    period = 1.0 / revolution_hz
    n_rev = int(np.floor((t[-1] - t_start) / period + 1e-9))
    if n_rev < 1:
        raise ValueError(f"the window from {t_start:g} s holds no whole revolution "
                         f"({period:.4g} s) of the record ending at {t[-1]:g} s")
    sel = (t >= t_start - 1e-12) & (t <= t_start + n_rev * period + 1e-9 * period)
    out = {"orders": [float(o) for o in orders], "revolutions": n_rev}
    for name, x in signals.items():
        x = np.asarray(x, float)[sel]
        amps = _order_amplitudes(t[sel], x, revolution_hz, orders)
        out[name] = {"amplitude": amps.tolist(), "mean": float(np.mean(x[:-1])),
                     "half_peak_to_peak": float(0.5 * (x.max() - x.min()))}
    return out


def _order_amplitudes(t, x, revolution_hz, orders) -> np.ndarray:
    """:func:`~.signals.order_amplitudes` at any (also half) orders: over the cycle of the
    lowest half order, as orders of a slower fundamental."""
    orders = np.asarray(orders, float)
    if np.allclose(orders, np.round(orders)):
        return order_amplitudes(t, x, revolution_hz, [round(o) for o in orders])
    return order_amplitudes(t, x, revolution_hz / 2.0, [round(2 * o) for o in orders])


def torsional_sweep(make_mechanism, speeds_rpm, revolutions: float, settle_revolutions: float,
                    orders, signal: str = "twist_free_end", settings=None,
                    samples_per_revolution: int = 360) -> dict:
    """Steady-state torsional response at a list of speeds, one run per speed.

    Parameters
    ----------
    make_mechanism : callable
        ``make_mechanism(speed_rpm) -> Mechanism`` (a crank train with a motor or a flexible
        crank).
    speeds_rpm : sequence of float
        rpm, > 0.
    revolutions, settle_revolutions : float
        Revolutions analysed, and run before them (the start-up transient to decay), per
        speed.
    orders : sequence of float
        Orders whose amplitudes are reported.
    signal : str
        The torsional history analysed (``twist_free_end``, ``coupling_twist``,
        ``coupling_torque``, ``twist_<frame>``).
    settings : SolverSettings, optional
    samples_per_revolution : int
        Output samples per revolution.

    Returns
    -------
    dict
        ``speed_rpm``, ``orders``, ``amplitude`` (speeds x orders, the signal's unit) and
        ``half_peak_to_peak`` (per speed).
    """
    from ..run.simulate import simulate

    amps, p2p = [], []
    for n in speeds_rpm:
        mech = make_mechanism(float(n))
        rev_hz = n / 60.0
        t0 = settle_revolutions / rev_hz
        t_end = t0 + revolutions / rev_hz
        hist = simulate(mech, t_end, 1.0 / (rev_hz * samples_per_revolution), settings,
                        ideal=not mech.system.clearances)
        if signal not in hist.torsion:
            raise KeyError(f"signal {signal!r} is not among this train's torsional histories "
                           f"({', '.join(hist.torsion) or 'none'})")
        res = torsional_orders(hist.t, {signal: hist.torsion[signal]}, rev_hz, orders, t0)
        amps.append(res[signal]["amplitude"])
        p2p.append(res[signal]["half_peak_to_peak"])
    return {"speed_rpm": [float(n) for n in speeds_rpm], "orders": [float(o) for o in orders],
            "signal": signal, "amplitude": amps, "half_peak_to_peak": p2p}
