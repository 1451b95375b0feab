"""Holzer-style tables at the resonances of a forced train, with the energy-balance estimate.

At each critical speed ``n_c = 60 f_m / q`` inside the speed range the train is solved for that
order alone; the table lists, per rotor, the vibratory angle, the inertia torque
``I omega^2 theta`` and the torque in the following shaft section, as a Holzer table does for a
free mode but with the forced amplitudes. Beside it, the amplitude the energy balance predicts
(:func:`~.forced.energy_balance_amplitude` with the mode shape) — for light damping the two
differ by the off-resonant modes, which move in quadrature with the resonant one, so by
``O((2 zeta)^2)`` relative.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from .forced import energy_balance_amplitude, harmonic_response


def resonance_tables(train, response, natural_hz, shapes, excitation, speeds, max_tables: int = 12):
    """Tables at the strongest resonances inside the speed range.

    Parameters
    ----------
    train : DampedTrain
    response : ForcedResponse
    natural_hz, shapes : ndarray
        Undamped natural frequencies and mode shapes of the train.
    excitation : RotorExcitation
    speeds : ndarray
        The speed grid (rpm); resonances outside it are skipped.
    max_tables : int
        The strongest ones (by the largest section torque) are kept.

    Returns
    -------
    list of dict
        ``mode``, ``order``, ``speed_rpm``, ``natural_hz``, ``rows`` (per DOF), ``energy_balance_rad``
        and ``full_response_rad`` at the largest-amplitude rotor, ``max_section_torque_nm``, ``text``.
    """
    out = []
    B = train.section_matrix() * train.section_stiffness[:, None]
    for m, f in enumerate(natural_hz):
        for j, q in enumerate(excitation.orders):
            n_c = 60.0 * f / q
            if not speeds[0] <= n_c <= speeds[-1]:
                continue
            Omega = n_c * math.pi / 30.0
            w = q * Omega
            F = excitation.at([Omega])[0, j]
            if not np.any(F):
                continue
            X = harmonic_response(train, [w], F[None])[0]
            T = B @ X
            try:
                eb = energy_balance_amplitude(train, shapes[m], w, F)
            except ParameterError:  # an undamped mode (e.g. a node at the only damper): no estimate
                eb = None
            ref = int(np.argmax(np.abs(shapes[m])))
            rows = []
            for i in range(train.n_dofs):
                sec = [s for s, (a, _) in enumerate(train.section_pairs) if a == i]
                rows.append({"dof": train.labels[i], "inertia_kgm2": float(train.M[i, i]),
                             "angle_rad": float(abs(X[i])),
                             "inertia_torque_nm": float(train.M[i, i] * w**2 * abs(X[i])),
                             "section_torque_nm": float(abs(T[sec[0]])) if sec else None})
            out.append({"mode": m + 1, "order": float(q), "speed_rpm": float(n_c), "natural_hz": float(f),
                        "rows": rows, "reference": train.labels[ref],
                        "energy_balance_rad": None if eb is None else float(eb[ref]),
                        "full_response_rad": float(abs(X[ref])),
                        "max_section_torque_nm": float(np.abs(T).max())})
    out.sort(key=lambda t: -t["max_section_torque_nm"])
    out = out[:max_tables]
    for t in out:
        t["text"] = _text(t)
    return out


def _text(t: dict) -> str:
    head = (f"Resonance: mode {t['mode']} ({t['natural_hz']:.5g} Hz) x order {t['order']:g} at "
            f"{t['speed_rpm']:.5g} rpm; {t['reference']}: full response {t['full_response_rad']:.4e} rad, "
            + ("no energy-balance estimate (the mode dissipates nothing)" if t["energy_balance_rad"] is None
               else f"energy balance {t['energy_balance_rad']:.4e} rad"))
    lines = [head, f"{'DOF':<34}{'I kg m2':>12}{'angle rad':>14}{'I w2 th N m':>14}{'section N m':>14}"]
    for r in t["rows"]:
        sec = "" if r["section_torque_nm"] is None else f"{r['section_torque_nm']:14.5g}"
        lines.append(f"{r['dof'][:33]:<34}{r['inertia_kgm2']:12.5g}{r['angle_rad']:14.5e}"
                     f"{r['inertia_torque_nm']:14.5g}{sec}")
    return "\n".join(lines)
