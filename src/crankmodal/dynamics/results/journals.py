"""Main-bearing forces per journal of a crank train, their statistics and their shares.

* A crank on several main journals (a flexible crank body, joints ``main_1..N``): each
  journal's force is its joint's (ideal pin multiplier or clearance-joint contact and film
  force), the crank's force on the housing.
* A rigid crank on two journals (``crank_train(journals_z=[z1, z2])``): statically determinate.
  The planar model gives the crank's total force on the housing; each load on the crank is
  carried to the two journals by the lever rule ``w1(z) = (z2 - z) / (z2 - z1)``,
  ``w2 = 1 - w1``: the rods' forces on the crank at their rows ``z_i`` (minus the big-end
  forces) and the rest (the crank's own inertia and weight) at the crank's ``z``.
* One journal: ``main``.
"""

from __future__ import annotations

import numpy as np

from .signals import order_amplitudes
from .stats import per_revolution_peaks, revolution_blocks, summarise


def lever_weights(z, journals_z) -> tuple[float, float]:
    """Shares of a load at axial position ``z`` carried by two journals at ``journals_z``
    (simply supported shaft; outside the span one share is negative)."""
    z1, z2 = journals_z
    w1 = (z2 - z) / (z2 - z1)
    return float(w1), float(1.0 - w1)


def journal_forces(mech, hist) -> dict:
    """``{journal: (K, 2)}`` force of the crank on each main journal's housing, N."""
    mains = list(getattr(mech, "main_joints", None) or [mech.main_joint])
    if len(mains) > 1:
        return {name: np.asarray(hist.joint_forces[name], float) for name in mains}
    total = np.asarray(hist.main_bearing_force, float)
    jz = getattr(mech, "journals_z", None)
    if not jz or len(jz) != 2:
        return {mains[0]: total}
    out = {"main_1": np.zeros_like(total), "main_2": np.zeros_like(total)}
    rest = total.copy()
    for name, z in mech.rows_z.items():
        f = -np.asarray(hist.joint_forces[name], float)  # the rod's force on the crank
        rest -= f
        w1, w2 = lever_weights(z, jz)
        out["main_1"] += w1 * f
        out["main_2"] += w2 * f
    w1, w2 = lever_weights(mech.crank.z, jz)
    out["main_1"] += w1 * rest
    out["main_2"] += w2 * rest
    return out


def journal_statistics(mech, hist, t_start: float, orders=tuple(range(13))) -> dict:
    """Per journal: peak, mean, per-revolution peaks, orders and shares, from ``t_start``.

    Returns
    -------
    dict
        Per journal ``peak_n`` (largest |F|, N), ``mean_n`` (mean |F|), ``x_peak_n``,
        ``y_peak_n`` (largest |F_x|, |F_y|), ``per_revolution_peak_n`` (mean, standard
        deviation, ... of the revolutions' peaks: :func:`~.stats.summarise`), ``orders`` and
        ``order_amplitude_n`` (the magnitude of the order's force vector amplitudes,
        ``hypot(|X_k|, |Y_k|)``, over the whole revolutions of the window), ``share_mean``
        and ``share_peak`` (its mean and its peak over the journals' sum); and ``journals``,
        the names in order.
    """
    forces = journal_forces(mech, hist)
    t = np.asarray(hist.t, float)
    rev_hz = mech.revolution_hz
    sel = t >= t_start - 1e-12
    block, n = revolution_blocks(t[sel], t_start, rev_hz)
    out = {"journals": list(forces)}
    per = {}
    for name, f in forces.items():
        fs = f[sel]
        mag = np.hypot(fs[:, 0], fs[:, 1])
        d = {"peak_n": float(mag.max()), "mean_n": float(mag.mean()),
             "x_peak_n": float(np.abs(fs[:, 0]).max()), "y_peak_n": float(np.abs(fs[:, 1]).max())}
        if n >= 1:
            d["per_revolution_peak_n"] = summarise(per_revolution_peaks(mag, block, n))
            ts = t[sel]
            whole = ts <= ts[0] + n / rev_hz + 1e-9 / rev_hz
            ax = order_amplitudes(ts[whole], fs[whole, 0], rev_hz, list(orders))
            ay = order_amplitudes(ts[whole], fs[whole, 1], rev_hz, list(orders))
            d["orders"] = [int(k) for k in orders]
            d["order_amplitude_n"] = np.hypot(ax, ay).tolist()
        per[name] = d
    mean_sum = sum(d["mean_n"] for d in per.values())
    peak_sum = sum(d["peak_n"] for d in per.values())
    for d in per.values():
        d["share_mean"] = d["mean_n"] / mean_sum if mean_sum > 0 else 0.0
        d["share_peak"] = d["peak_n"] / peak_sum if peak_sum > 0 else 0.0
    out.update(per)
    return out


def train_results(mech, hist, t_start: float) -> dict:
    """The crank-train block of a run's results (empty for a train on one journal without a
    motor or a flexible crank, so older scenes' results are unchanged).

    Returns
    -------
    dict
        ``main_journals`` (:func:`journal_statistics`) when the crank runs on several journals
        (or a rigid crank's two ``journals_z``); ``torsion`` (per torsional history of
        :attr:`~.history.History.torsion`: amplitudes by order over whole working cycles,
        ``orders`` in steps of 1/2 for a four-stroke arrangement, else 1, up to 12, and
        ``half_peak_to_peak``) when there is a motor or a flexible crank; ``arrangement``
        (:meth:`~crankmodal.mechanism.arrangement.Arrangement.to_dict`) when given.
    """
    from .torsional import torsional_orders

    out = {}
    if len(journal_forces(mech, hist)) > 1:
        out["main_journals"] = journal_statistics(mech, hist, t_start)
    arrangement = getattr(mech, "arrangement", None)
    cycle = 1 if arrangement is None else arrangement.cycle_revolutions
    if hist.torsion:
        step = 1.0 / cycle
        orders = list(np.arange(0.0, 12.0 + 1e-9, step))
        rev_hz = mech.revolution_hz
        span = (hist.t[-1] - t_start) * rev_hz
        if span >= cycle - 1e-9:
            keep = {k: v for k, v in hist.torsion.items() if k != "motor_angle"}
            out["torsion"] = torsional_orders(hist.t, keep, rev_hz / cycle,
                                              [o * cycle for o in orders], t_start)
            out["torsion"]["orders"] = orders
    if arrangement is not None:
        d = arrangement.to_dict()
        out["arrangement"] = {k: (np.asarray(v).tolist() if v is not None else None)
                              for k, v in d.items()}
    return out
