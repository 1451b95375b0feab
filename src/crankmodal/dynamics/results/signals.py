"""Signal post-processing: windowed spectra in Hz and engine orders, impacts, contact loss."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Spectrum:
    """One-sided amplitude spectrum.

    Attributes
    ----------
    frequency_hz : (F,) Hz.
    order : (F,) frequency over the crank revolution frequency.
    amplitude : (F,) or (F, C) amplitude of each harmonic, in the signal's unit (e.g. N).
    """

    frequency_hz: np.ndarray
    order: np.ndarray
    amplitude: np.ndarray


def amplitude_spectrum(t, x, revolution_hz, window="hann") -> Spectrum:
    """Windowed FFT of a uniformly sampled signal.

    Parameters
    ----------
    t : (K,) s, uniform spacing.
    x : (K,) or (K, C) signal.
    revolution_hz : float
        Crank revolution frequency, Hz (for the order axis).
    window : {"hann", "rect"}
        The Hann window is amplitude-corrected (coherent gain): a sinusoid that falls on a bin
        reads its amplitude; use an integer number of revolutions for exact order lines.
    """
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    K = t.size
    dt = (t[-1] - t[0]) / (K - 1)
    w = np.hanning(K) if window == "hann" else np.ones(K)
    w = w.reshape((K,) + (1,) * (x.ndim - 1))
    X = np.fft.rfft((x - x.mean(axis=0)) * w, axis=0)
    amp = 2.0 * np.abs(X) / w.sum()
    amp[0] = np.abs(x.mean(axis=0))
    f = np.fft.rfftfreq(K, dt)
    return Spectrum(frequency_hz=f, order=f / revolution_hz, amplitude=amp)


def order_amplitudes(t, x, revolution_hz, orders) -> np.ndarray:
    """Exact Fourier amplitudes at integer orders from a whole number of revolutions.

    ``t`` must span an integer number of revolutions (uniform, endpoint excluded or included:
    the last sample is dropped if it closes the period).
    """
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    period = 1.0 / revolution_hz
    span = t[-1] - t[0]
    if abs(span / period - round(span / period)) < 1e-6 and round(span / period) >= 1:
        t, x = t[:-1], x[:-1]
    phase = 2.0 * np.pi * revolution_hz * (t - t[0])
    out = []
    for k in orders:
        c = np.exp(-1j * k * phase)
        c = c.reshape((-1,) + (1,) * (x.ndim - 1))
        out.append(2.0 * np.abs((x * c).mean(axis=0)) if k else np.abs(x.mean(axis=0)))
    return np.array(out)


def whirl_components(t, fx, fy, revolution_hz, order):
    """Forward and backward whirl amplitudes of a planar force at one order, N.

    ``fx + i fy = A_f exp(i k w t) + A_b exp(-i k w t) + ...``; a force of constant magnitude
    rotating with the crank has ``A_b = 0``.
    """
    z = np.asarray(fx) + 1j * np.asarray(fy)
    t = np.asarray(t, float)
    period = 1.0 / revolution_hz
    if abs((t[-1] - t[0]) / period - round((t[-1] - t[0]) / period)) < 1e-6:
        t, z = t[:-1], z[:-1]
    ph = 2.0 * np.pi * revolution_hz * (t - t[0])
    return (abs(np.mean(z * np.exp(-1j * order * ph))),
            abs(np.mean(z * np.exp(1j * order * ph))))


def contact_durations(onsets, separations) -> np.ndarray:
    """Duration of each contact of one clearance joint: from an onset to the first separation
    after it, s (a contact still closed at the end is left out).

    Parameters
    ----------
    onsets : list of (t, v)
        Contact onsets (s) and approach velocities (m/s).
    separations : list of float
        Contact separations, s.
    """
    t_on = np.asarray(onsets, float).reshape(-1, 2)[:, 0]
    sep = np.sort(np.asarray(separations, float))
    k = np.searchsorted(sep, t_on, side="right")
    ok = k < sep.size
    return sep[k[ok]] - t_on[ok]


def impact_statistics(onsets, separations=None, v_min=0.0, min_flight=0.0) -> dict:
    """Count and velocities of the impacts of one clearance joint.

    An impact is a contact onset (zero crossing of the penetration) whose approach velocity is
    at least ``v_min`` and, with ``separations``, that follows a free flight of at least
    ``min_flight`` since the previous separation (the first onset counts as after free flight).
    ``v_min`` drops grazing onsets of a journal sliding along the wall; ``min_flight`` merges a
    rattle (bounces separated by short flights) into one collision event, which is what a
    time trace shows as one spike.

    Parameters
    ----------
    onsets : list of (t, v)
        Contact onsets (s) and approach velocities (m/s).
    separations : list of float, optional
        Contact separations, s.
    v_min : float
        m/s.
    min_flight : float
        s.

    Returns
    -------
    dict
        ``impact_count``, ``onset_count`` (every zero crossing), ``impact_velocity_max``,
        ``_mean`` and ``_rms`` (m/s) over the counted impacts.
    """
    ons = np.asarray(onsets, float).reshape(-1, 2)
    keep = ons[:, 1] >= v_min
    if separations is not None and min_flight > 0.0 and ons.shape[0]:
        sep = np.sort(np.asarray(separations, float))
        k = np.searchsorted(sep, ons[:, 0]) - 1          # last separation before each onset
        flight = np.where(k >= 0, ons[:, 0] - sep[np.maximum(k, 0)], np.inf)
        keep &= flight >= min_flight
    v = ons[keep, 1]
    return {
        "impact_count": int(v.size),
        "onset_count": int(ons.shape[0]),
        "impact_velocity_max": float(v.max()) if v.size else 0.0,
        "impact_velocity_mean": float(v.mean()) if v.size else 0.0,
        "impact_velocity_rms": float(np.sqrt(np.mean(v**2))) if v.size else 0.0,
    }


def force_direction(t, f) -> tuple[np.ndarray, np.ndarray]:
    """Direction angle (rad, unwrapped) of a planar force and its rate (rad/s)."""
    beta = np.unwrap(np.arctan2(f[:, 1], f[:, 0]))
    return beta, np.gradient(beta, t)


def contact_loss_indicator(t, f_ideal, crank_angle=None) -> dict:
    """Seed 001's empirical criterion from the zero-clearance bearing force.

    Contact is expected to be kept while the rate of change of the force direction (rad/s) over
    the smallest force magnitude (N) stays below one: ``max|d beta/dt| / min|F| < 1``.
    Returns the ratio (None if the force vanishes), where the direction changes fastest, and the
    minimum force; with ``crank_angle`` (rad) also the crank angles (deg, 0..360) of both.
    """
    _, rate = force_direction(t, f_ideal)
    mag = np.hypot(f_ideal[:, 0], f_ideal[:, 1])
    k = int(np.argmax(np.abs(rate)))
    fmin = float(mag.min())
    ratio = float(np.abs(rate).max() / fmin) if fmin > 0.0 else None
    kmin = int(np.argmin(mag))
    out = {"ratio": ratio, "max_direction_rate": float(np.abs(rate[k])),
           "time_of_max_rate": float(t[k]), "min_force": fmin, "time_of_min_force": float(t[kmin]),
           "contact_kept": ratio is not None and ratio < 1.0}
    if crank_angle is not None:
        out["crank_angle_of_max_rate_deg"] = float(np.degrees(crank_angle[k]) % 360.0)
        out["crank_angle_of_min_force_deg"] = float(np.degrees(crank_angle[kmin]) % 360.0)
    return out


def window_peaks(t, x, window) -> dict:
    """Peaks of ``|x|`` over consecutive windows of equal length: the typical and the largest.

    The largest value of a rattling signal is one event; the median of the per-window peaks
    is what every window reaches, the robust "amplitude" to compare runs at different speeds
    over equally long, equally sampled records.

    Parameters
    ----------
    t : (K,) s, increasing.
    x : (K,) signal.
    window : float
        Window length, s; the record is cut into ``floor(span / window)`` windows from ``t[0]``
        (a remainder shorter than one window is dropped).

    Returns
    -------
    dict
        ``n_windows``, ``max``, ``median`` and ``min`` of the per-window peaks of ``|x|``.
    """
    t = np.asarray(t, float)
    a = np.abs(np.asarray(x, float))
    n = int(np.floor((t[-1] - t[0]) / window + 1e-9))
    if n < 1:
        raise ValueError(f"window {window} s is longer than the record ({t[-1] - t[0]} s)")
    k = ((t - t[0]) / window + 1e-9).astype(int)            # samples past n windows: dropped
    peaks = np.array([a[k == i].max() for i in range(n)])
    return {"n_windows": n, "max": float(peaks.max()), "median": float(np.median(peaks)),
            "min": float(peaks.min())}
