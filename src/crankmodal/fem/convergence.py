"""Discretisation error against run time: a part at several mesh sizes and orders.

For each element order the frequencies of successive meshes are extrapolated (Richardson):
with mesh sizes h₁ > h₂ > h₃ the observed rate is ``q = ln(|f₁−f₂| / |f₂−f₃|) / ln(h₁/h₂)``
(when the size ratios are equal and the differences are monotone), else the theoretical rate
``2p`` of a conforming order-p element's eigenvalues; the extrapolated value is
``f∞ = f_fine + (f_fine − f_coarse) / ((h_coarse/h_fine)^q − 1)`` and each run's error estimate
is ``|f − f∞| / f∞``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np


@dataclass
class ConvergenceTable:
    """Rows of a convergence study.

    Attributes
    ----------
    rows : list of dict
        One per run: ``order``, ``mesh_size`` (m), ``n_dofs``, ``n_elements``, ``wall_time_s``,
        ``peak_memory_bytes``, ``frequencies_hz`` (list), ``estimated_error`` (list, relative,
        None where it cannot be estimated), ``rate`` (the rate q used).
    extrapolated_hz : dict
        Order -> extrapolated frequencies.
    """

    rows: list = field(default_factory=list)
    extrapolated_hz: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"rows": self.rows,
                "extrapolated_hz": {str(k): v for k, v in self.extrapolated_hz.items()}}


def richardson(h: np.ndarray, f: np.ndarray, order: int):
    """Extrapolate frequencies to h → 0.

    Parameters
    ----------
    h : ndarray, shape (m,)
        Mesh sizes, decreasing.
    f : ndarray, shape (m, k)
        Frequencies of k modes at each size.
    order : int
        Element order p (theoretical rate 2p).

    Returns
    -------
    f_inf : ndarray, shape (k,)
    rate : ndarray, shape (k,)
    """
    h = np.asarray(h, float)
    f = np.asarray(f, float)
    q = np.full(f.shape[1], 2.0 * order)
    if len(h) >= 3:
        r1, r2 = h[-3] / h[-2], h[-2] / h[-1]
        d1, d2 = f[-3] - f[-2], f[-2] - f[-1]
        ok = np.isclose(r1, r2, rtol=0.05) & (d1 * d2 > 0) & (np.abs(d2) < np.abs(d1))
        with np.errstate(divide="ignore", invalid="ignore"):
            q_obs = np.log(np.abs(d1) / np.abs(d2)) / np.log(r2)
        # trust the observed rate only within a sane band around the theory
        q = np.where(ok & (q_obs > 0.5) & (q_obs < 4.0 * order + 2), q_obs, q)
    r = h[-2] / h[-1]
    f_inf = f[-1] + (f[-1] - f[-2]) / (r ** q - 1.0)
    return f_inf, q


def study(build, sizes, orders=(1, 2), material=None, n_modes: int = 6, supports=(),
          backend: str = "auto") -> ConvergenceTable:
    """Run a part builder at each size and order; estimate each frequency's error.

    Parameters
    ----------
    build : callable
        ``build(mesh_size, order) -> Part``.
    sizes : sequence of float
        Mesh sizes, m (sorted coarse to fine here).
    orders : sequence of int
    material : Material
    n_modes : int
        Elastic modes compared (by rank).
    supports : list of dict
        Support tables ``{region = ..., fix = ...}`` or ``{box = [...], fix = ...}``, resolved
        on each mesh (empty: free-free); a bad one raises ParameterError naming ``supports[i]``.
    backend : str

    Returns
    -------
    ConvergenceTable
    """
    from .assembly import assemble
    from .memory import PeakMemory
    from .modal import solve_modes
    from .supports import select_supports

    sizes = sorted(sizes, reverse=True)
    table = ConvergenceTable()
    for order in orders:
        freqs, rows = [], []
        for h in sizes:
            with PeakMemory() as mem:
                t0 = time.perf_counter()
                part = build(h, order)
                model = assemble(part, material)
                modes = solve_modes(model, n_modes, select_supports(part, supports), backend=backend)
                wall = time.perf_counter() - t0
            freqs.append(modes.frequencies_hz[:n_modes])
            rows.append({"order": order, "mesh_size": float(h), "n_dofs": modes.n_dofs,
                         "n_elements": model.n_elements, "wall_time_s": wall,
                         "peak_memory_bytes": mem.peak,
                         "frequencies_hz": modes.frequencies_hz[:n_modes].tolist()})
        F = np.array(freqs)
        if len(sizes) >= 2:
            f_inf, q = richardson(np.array(sizes), F, order)
            table.extrapolated_hz[order] = f_inf.tolist()
            for row, f in zip(rows, F):
                row["estimated_error"] = (np.abs(f - f_inf) / f_inf).tolist()
                row["rate"] = q.tolist()
        else:
            for row in rows:
                row["estimated_error"] = [None] * n_modes
                row["rate"] = None
        table.rows.extend(rows)
    return table
