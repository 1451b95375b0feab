"""Per-revolution statistics of a run: numbers that converge, with their uncertainty.

The largest value of one trajectory of an impacting system is one event: it moves by a factor
of two when the tolerance changes (the four-star's main-bearing peak read 19.2 / 17.7 / 21.7 /
45.5 / 14.7 kN at rtol 1e-5 ... 1e-9). A statistic over many revolutions converges instead: the
record after the start-up is cut into whole revolutions (blocks), each block gives one value
(its peak, RMS, order amplitudes, band levels, impact count) and the mean over the blocks is
reported with its standard error ``std / sqrt(n)`` (blocks taken as independent samples).
"""

from __future__ import annotations

import numpy as np

BAND_EDGES_HZ = (0.0, 100.0, 300.0, 1000.0, 3000.0, np.inf)
REL_TOL = 0.01  # a change under 1 % is converged whatever the standard error says
ORDERS = (1, 2, 3, 4)
_BOOTSTRAP = 200


def revolution_blocks(t, t_start: float, revolution_hz: float) -> tuple[np.ndarray, int]:
    """Index of the revolution each time falls in, counted from ``t_start`` (-1: outside).

    Parameters
    ----------
    t : (K,) s.
    t_start : float
        s, start of the first block.
    revolution_hz : float
        Hz; a block is one revolution, ``1 / revolution_hz`` s.

    Returns
    -------
    block : (K,) int
        0 .. n-1, or -1 before ``t_start`` or past the last whole revolution.
    n : int
        Number of whole revolutions.
    """
    t = np.asarray(t, float)
    span = (t[-1] - t_start) if t.size else 0.0
    n = max(int(np.floor(span * revolution_hz + 1e-9)), 0)
    return block_of(t, t_start, revolution_hz, n), n


def results_window(t, ramp_time: float, spectrum_start: float | None,
                   revolution_hz: float) -> tuple[float, float, int, bool]:
    """The results (statistics) window of a run: whole revolutions after the start-up.

    By default the window opens one revolution after the speed ramp (``ramp_time``), the
    start-up transient left out, and holds every whole revolution that fits before the last
    output time; ``spectrum_start`` (s) opens it there instead. A run too short for one whole
    revolution after that settling revolution opens the window at the ramp's end instead
    (the start-up included: the caller warns). "Fits" has a round-off slack of 1e-9 revolution:
    a run of exactly ``ramp_time`` + 2 revolutions has one whole revolution after the settling
    one, whatever the last bit of its output times.

    Parameters
    ----------
    t : (K,) output times, s, increasing.
    ramp_time : float
        s, end of the speed ramp.
    spectrum_start : float or None
        s, explicit start of the window.
    revolution_hz : float
        Hz.

    Returns
    -------
    start_s, end_s : float
        s; ``end_s`` is ``start_s`` + ``n_revolutions`` revolutions (the last output time when
        no whole revolution fits).
    n_revolutions : int
        Whole revolutions in the window (0 when none fits).
    includes_start_up : bool
        The default window had to open at the ramp's end, before the settling revolution.
    """
    t = np.asarray(t, float)
    t_last = float(t[-1]) if t.size else 0.0

    def whole(t0):
        return max(int(np.floor((t_last - t0) * revolution_hz + 1e-9)), 0)

    start_up = False
    if spectrum_start is not None:
        t0 = float(spectrum_start)
    else:
        t0 = float(ramp_time) + 1.0 / revolution_hz
        if whole(t0) < 1:
            t0, start_up = float(ramp_time), True
    n = whole(t0)
    t1 = t0 + n / revolution_hz if n >= 1 else t_last
    return t0, t1, n, start_up


def block_of(times, t_start: float, revolution_hz: float, n: int) -> np.ndarray:
    """Revolution index (0 .. n-1, else -1) of arbitrary times, s (e.g. events)."""
    b = np.floor((np.asarray(times, float) - t_start) * revolution_hz + 1e-9).astype(int)
    b[(b < 0) | (b >= n)] = -1
    return b


def summarise(values) -> dict:
    """Mean, standard deviation (ddof 1), standard error of the mean, median, min, max and
    count of per-block values (unit of the values; NaN-free; ``None`` for an empty set)."""
    v = np.asarray(values, float)
    n = int(v.size)
    if n == 0:
        return {"mean": None, "std": None, "sem": None, "median": None, "min": None,
                "max": None, "n": 0}
    std = float(np.std(v, ddof=1)) if n > 1 else 0.0
    return {"mean": float(v.mean()), "std": std, "sem": std / np.sqrt(n),
            "median": float(np.median(v)), "min": float(v.min()), "max": float(v.max()), "n": n}


def per_cycle(values, revolutions_per_cycle: int, how: str = "max") -> np.ndarray:
    """Per-revolution values grouped into working cycles of ``revolutions_per_cycle``
    consecutive revolutions (a four-stroke engine: 2), each cycle's ``max`` or ``sum``; a
    trailing incomplete cycle is left out."""
    v = np.asarray(values, float)
    k = int(revolutions_per_cycle)
    m = v.size // k
    blocks = v[: m * k].reshape(m, k)
    return blocks.max(axis=1) if how == "max" else blocks.sum(axis=1)


def per_revolution_peaks(x, block, n, event_block=(), event_x=()) -> np.ndarray:
    """Largest ``|x|`` in each revolution, samples and events (e.g. a contact's deepest point).

    Parameters
    ----------
    x : (K,) sampled signal.
    block, n : from :func:`revolution_blocks` on the sample times.
    event_block, event_x : (E,) revolution index (:func:`block_of`) and value of events
        between the samples.
    """
    peaks = np.zeros(n)
    for b, v in ((block, x), (np.asarray(event_block, int), event_x)):
        ok = b >= 0
        if np.any(ok):
            np.maximum.at(peaks, b[ok], np.abs(np.asarray(v, float))[ok])
    return peaks


def per_revolution_rms(x, block, n) -> np.ndarray:
    """RMS of ``x`` in each revolution (samples; unit of ``x``)."""
    x = np.asarray(x, float)
    ok = block >= 0
    s = np.bincount(block[ok], weights=x[ok] ** 2, minlength=n)
    c = np.bincount(block[ok], minlength=n)
    return np.sqrt(s / np.maximum(c, 1))


def per_revolution_spectra(x, block, n, revolution_hz, orders=ORDERS, edges=BAND_EDGES_HZ):
    """Order amplitudes and band RMS levels of each revolution.

    Each block is one period of the revolution, so its DFT bins fall on integer orders: bin
    ``k`` is order ``k``, ``k * revolution_hz`` Hz. Band levels are the RMS of the block's
    fluctuating part (mean removed) carried by the bins in ``[lo, hi)`` Hz (Parseval).

    Returns
    -------
    orders : (n, len(orders)) amplitudes (unit of ``x``).
    bands : (n, len(edges) - 1) RMS levels (unit of ``x``).
    """
    x = np.asarray(x, float)
    amps = np.zeros((n, len(orders)))
    bands = np.zeros((n, len(edges) - 1))
    for i in range(n):
        xi = x[block == i]
        m = xi.size
        if m < 2:
            continue
        X = np.fft.rfft(xi - xi.mean()) / m
        for j, k in enumerate(orders):
            amps[i, j] = 2.0 * np.abs(X[k]) if 0 < k < X.size else 0.0
        f = np.arange(X.size) * revolution_hz
        # one-sided power: bins other than 0 and (even m) Nyquist count twice
        p = 2.0 * np.abs(X) ** 2
        p[0] = 0.0
        if m % 2 == 0:
            p[-1] /= 2.0
        for j in range(len(edges) - 1):
            bands[i, j] = np.sqrt(np.sum(p[(f >= edges[j]) & (f < edges[j + 1])]))
    return amps, bands


def signal_statistics(x, block, n, revolution_hz, event_block=(), event_x=(),
                      spectra=True, revolutions_per_cycle: int = 1) -> dict:
    """Per-revolution peak, RMS and (``spectra``) order amplitudes and band levels of a signal.

    Returns
    -------
    dict
        ``per_rev_peak`` and ``rms`` (:func:`summarise` of the per-revolution values), and with
        ``spectra`` ``order_amplitude`` (``orders``, ``mean``, ``sem`` lists) and ``band_rms``
        (``edges_hz``, ``mean``, ``sem``), all in the unit of ``x``; with
        ``revolutions_per_cycle`` > 1 (a four-stroke engine) also ``per_cycle_peak``, the
        summary of each working cycle's largest ``|x|``.
    """
    peaks = per_revolution_peaks(x, block, n, event_block, event_x)
    out = {"per_rev_peak": summarise(peaks), "rms": summarise(per_revolution_rms(x, block, n))}
    if revolutions_per_cycle > 1:
        out["per_cycle_peak"] = summarise(per_cycle(peaks, revolutions_per_cycle))
    if spectra:
        amps, bands = per_revolution_spectra(x, block, n, revolution_hz)
        out["order_amplitude"] = _columns(amps, {"orders": list(ORDERS)})
        out["band_rms"] = _columns(bands, {"edges_hz": [float(e) if np.isfinite(e) else None
                                                        for e in BAND_EDGES_HZ]})
    return out


def _columns(a, head: dict) -> dict:
    n = a.shape[0]
    head["mean"] = a.mean(axis=0).tolist() if n else []
    head["sem"] = (a.std(axis=0, ddof=1) / np.sqrt(n)).tolist() if n > 1 else [0.0] * a.shape[1]
    return head


def impact_velocity_statistics(onsets, t_start, revolution_hz, n, v_min=0.0, seed=0,
                               revolutions_per_cycle: int = 1) -> dict:
    """Impact-velocity distribution of one clearance joint over ``n`` revolutions from
    ``t_start``.

    Quantiles pool the impacts (onsets with approach velocity at least ``v_min``, m/s) of all
    revolutions; their standard errors come from a bootstrap over revolutions (fixed ``seed``:
    the numbers repeat).

    Returns
    -------
    dict
        ``p50``, ``p90``, ``max`` (m/s) with ``p50_sem``, ``p90_sem``; ``count_per_rev`` and
        ``max_per_rev`` (:func:`summarise` of the per-revolution count and largest velocity);
        with ``revolutions_per_cycle`` > 1 also ``count_per_cycle`` and ``max_per_cycle`` (per
        working cycle: a four-stroke engine knocks in its firing revolution and rests in the
        other, an alternation the per-revolution standard error counts as scatter).
    """
    ons = np.asarray(onsets, float).reshape(-1, 2)
    b = np.floor((ons[:, 0] - t_start) * revolution_hz + 1e-9).astype(int)
    keep = (b >= 0) & (b < n) & (ons[:, 1] >= v_min)
    b, v = b[keep], ons[keep, 1]
    counts = np.bincount(b, minlength=n)[:n].astype(float)
    vmax = np.zeros(n)
    np.maximum.at(vmax, b, v)
    out = {"p50": None, "p90": None, "max": None, "p50_sem": None, "p90_sem": None}
    if v.size:
        out.update(p50=float(np.quantile(v, 0.5)), p90=float(np.quantile(v, 0.9)),
                   max=float(v.max()))
        if n > 1:
            rng = np.random.default_rng(seed)
            qs = []
            for _ in range(_BOOTSTRAP):
                pick = rng.integers(0, n, n)
                vv = np.concatenate([v[b == i] for i in pick])
                if vv.size:
                    qs.append(np.quantile(vv, [0.5, 0.9]))
            qs = np.array(qs)
            out["p50_sem"], out["p90_sem"] = (float(s) for s in qs.std(axis=0, ddof=1))
    out["count_per_rev"] = summarise(counts)
    out["max_per_rev"] = summarise(vmax)
    if revolutions_per_cycle > 1:
        out["count_per_cycle"] = summarise(per_cycle(counts, revolutions_per_cycle, "sum"))
        out["max_per_cycle"] = summarise(per_cycle(vmax, revolutions_per_cycle))
    return out


def statistics(hist, revolution_hz: float, t_start: float, v_min: dict | None = None,
               revolutions_per_cycle: int = 1) -> dict:
    """The ``statistics`` block of a run's results.

    Parameters
    ----------
    hist : History
    revolution_hz : float
        Hz.
    t_start : float
        s, start of the first whole revolution counted (after the start-up).
    v_min : dict, optional
        Joint name -> impact velocity floor, m/s (onsets below it are grazing, not impacts).
    revolutions_per_cycle : int
        Revolutions of one working cycle (2 for a four-stroke engine): adds the per-cycle
        statistics (``per_cycle_peak``, ``count_per_cycle``, ``max_per_cycle``) and the
        window's ``revolutions_per_cycle`` and ``n_cycles``.

    Returns
    -------
    dict
        ``window`` (``start_s``, ``end_s``, ``n_revolutions``), ``main_bearing_force`` (of the
        magnitude: per-revolution peak, RMS; of the x and y components: order amplitudes and
        band levels), ``piston_acceleration`` (list per piston), ``clearance_joints`` (contact
        force and impact velocities per joint). Units: N, m/s^2, m/s.
    """
    v_min = v_min or {}
    t = hist.t
    block, n = revolution_blocks(t, t_start, revolution_hz)
    ev_b = block_of(np.concatenate([pk["t"] for pk in hist.peaks.values()] or [np.zeros(0)]),
                    t_start, revolution_hz, n)
    f = hist.main_bearing_force
    mag = np.hypot(f[:, 0], f[:, 1])
    ev_f = np.concatenate([pk["main_bearing_force"] for pk in hist.peaks.values()]
                          or [np.zeros(0)])
    rpc = int(revolutions_per_cycle)
    main = signal_statistics(mag, block, n, revolution_hz, ev_b, ev_f, spectra=False,
                             revolutions_per_cycle=rpc)
    for c, name in enumerate(("x", "y")):
        s = signal_statistics(f[:, c], block, n, revolution_hz)
        main[f"order_amplitude_{name}"] = s["order_amplitude"]
        main[f"band_rms_{name}"] = s["band_rms"]
    pistons = []
    for i in range(hist.piston_acceleration.shape[1]):
        ev_a = np.concatenate([pk["piston_acceleration"][:, i] for pk in hist.peaks.values()]
                              or [np.zeros(0)])
        pistons.append(signal_statistics(hist.piston_acceleration[:, i], block, n,
                                         revolution_hz, ev_b, ev_a, revolutions_per_cycle=rpc))
    joints = {}
    for name, d in hist.contact.items():
        pk = hist.peaks.get(name, {"t": np.zeros(0), "fn": np.zeros(0)})
        joints[name] = {
            "contact_force": signal_statistics(
                d["fn"], block, n, revolution_hz, block_of(pk["t"], t_start, revolution_hz, n),
                pk["fn"], spectra=False, revolutions_per_cycle=rpc),
            "impact_velocity": impact_velocity_statistics(hist.onsets.get(name, []), t_start,
                                                          revolution_hz, n, v_min.get(name, 0.0),
                                                          revolutions_per_cycle=rpc),
        }
    window = {"start_s": float(t_start), "end_s": float(t_start + n / revolution_hz),
              "n_revolutions": n}
    if rpc > 1:
        window.update(revolutions_per_cycle=rpc, n_cycles=n // rpc)
    return {"window": window,
            "main_bearing_force": main, "piston_acceleration": pistons,
            "clearance_joints": joints}


def headline(stats: dict) -> dict:
    """Flat ``{name: (value, standard error)}`` of the statistics a tolerance study compares."""
    out = {}
    mb = stats["main_bearing_force"]
    out["main_bearing_per_rev_peak"] = (mb["per_rev_peak"]["mean"], mb["per_rev_peak"]["sem"])
    out["main_bearing_rms"] = (mb["rms"]["mean"], mb["rms"]["sem"])
    for j, k in enumerate(mb["order_amplitude_x"]["orders"]):
        ax, ay = mb["order_amplitude_x"], mb["order_amplitude_y"]
        if ax["mean"]:
            out[f"main_bearing_order_{k}"] = (float(np.hypot(ax["mean"][j], ay["mean"][j])),
                                              float(np.hypot(ax["sem"][j], ay["sem"][j])))
    bx, by = mb["band_rms_x"], mb["band_rms_y"]
    for j in range(len(bx["mean"])):
        lo, hi = bx["edges_hz"][j], bx["edges_hz"][j + 1]
        label = f"{lo:g}_{hi:g}hz" if hi is not None else f"above_{lo:g}hz"
        out[f"main_bearing_band_{label}"] = (float(np.hypot(bx["mean"][j], by["mean"][j])),
                                             float(np.hypot(bx["sem"][j], by["sem"][j])))
    for i, p in enumerate(stats["piston_acceleration"]):
        out[f"piston_{i + 1}_acceleration_per_rev_peak"] = (p["per_rev_peak"]["mean"],
                                                            p["per_rev_peak"]["sem"])
        out[f"piston_{i + 1}_acceleration_rms"] = (p["rms"]["mean"], p["rms"]["sem"])
    for name, j in stats["clearance_joints"].items():
        c, v = j["contact_force"], j["impact_velocity"]
        out[f"{name}_contact_force_per_rev_peak"] = (c["per_rev_peak"]["mean"],
                                                     c["per_rev_peak"]["sem"])
        out[f"{name}_contact_force_rms"] = (c["rms"]["mean"], c["rms"]["sem"])
        out[f"{name}_impacts_per_rev"] = (v["count_per_rev"]["mean"], v["count_per_rev"]["sem"])
        out[f"{name}_impact_velocity_p50"] = (v["p50"], v["p50_sem"])
        out[f"{name}_impact_velocity_p90"] = (v["p90"], v["p90_sem"])
    return {k: v for k, v in out.items() if v[0] is not None}


def _fmt(value: float, sem: float, unit: str) -> str:
    """``18.3 ± 0.9 kN``: value and standard error with a k prefix above 1e4."""
    from ...report.quantity import number  # no 6.3e+02 beside 4863 (issue 25 #15)

    k = 1e3 if abs(value) >= 1e4 else 1.0
    return f"{number(value / k)} ± {number(sem / k, 2)} {'k' if k > 1 else ''}{unit}"


def converged_summary(stats: dict, study: dict | None = None, rtol: float | None = None,
                      n_trajectories: int | None = None) -> str:
    """The headline numbers of a clearance run for the summary line: per-revolution means with
    their standard errors and, with a tolerance ``study``, whether each converged (from the
    run's own ``rtol`` if the study has it, else the second tightest, to the tightest, and
    across an ensemble of ``n_trajectories`` if one ran: :func:`.analysis.statistics_convergence`),
    how many statistics did and by how much the worst did not."""
    n = stats["window"]["n_revolutions"]
    conv = (study or {}).get("statistics", {})
    at = -2
    if conv and rtol is not None:
        hit = [i for i, r in enumerate(study["rtol"][:-1]) if np.isclose(r, rtol, rtol=1e-9)]
        at = hit[0] if hit else -2

    def tag(name):
        from ..run.simulate import convergence_tag

        return convergence_tag(conv.get(name), at, study.get("rel_tol", REL_TOL)) if conv else ""

    mb = stats["main_bearing_force"]["per_rev_peak"]
    parts = [f"main-bearing per-rev peak {_fmt(mb['mean'], mb['sem'], 'N')}"
             + tag("main_bearing_per_rev_peak")]
    pist = stats["piston_acceleration"]
    if pist:
        i = int(np.argmax([p["per_rev_peak"]["mean"] for p in pist]))
        p = pist[i]["per_rev_peak"]
        parts.append(f"piston {i + 1} accel per-rev peak {_fmt(p['mean'], p['sem'], 'm/s^2')}"
                     f"{tag(f'piston_{i + 1}_acceleration_per_rev_peak')}")
    for name, j in stats["clearance_joints"].items():
        c = j["impact_velocity"]["count_per_rev"]
        text = f"{name} {c['mean']:.3g} ± {c['sem']:.2g} impacts/rev{tag(f'{name}_impacts_per_rev')}"
        if j["impact_velocity"]["p90"] is not None:
            text += (f", impact v p90 {j['impact_velocity']['p90']:.3g} m/s"
                     f"{tag(f'{name}_impact_velocity_p90')}")
        parts.append(text)
    out = ", ".join(parts) + f" (mean ± standard error over {n} revs)"
    if conv and len(study["rtol"]) >= 2:
        from ..run.simulate import convergence_line

        out += "; " + convergence_line(study, at, n_trajectories)
    return out
