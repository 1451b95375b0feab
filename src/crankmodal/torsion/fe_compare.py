"""Putting the lumped-chain numbers beside an FE modal analysis of the same crank.

Pure functions on plain arrays, so they can be fed by ``crankmodal.fem`` modal results (node
coordinates and mode shapes) without importing any FE package here:

- :func:`torsional_participation` -- how much of a mode shape is rigid twist of the shaft's
  cross-sections about its axis;
- :func:`classify_modes` -- ``"torsion"`` or ``"other"`` per mode from that measure;
- :func:`compare_with_fe` -- the first FE torsional mode beside the two-rotor, Holzer and exact
  chain frequencies.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np


def torsional_participation(
    points, shape, axis_point=(0.0, 0.0, 0.0), axis_direction=(1.0, 0.0, 0.0),
    n_slices: int = 20, weights=None,
) -> float:
    """Fraction of a mode shape that is rigid twist of cross-sections about the shaft axis.

    The nodes are cut into ``n_slices`` slices along the axis. In each slice the displacement is
    projected (weighted least squares) on the rigid rotation field ``e x r``; the captured part,
    summed over the slices, is divided by the whole. Pure twist gives 1; bending (a lateral
    translation of each section) and axial motion give about 0 on an axisymmetric shaft; a crank
    throw's offset masses mix the classes a little.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Node coordinates, m.
    shape : array_like, shape (n, 3)
        Nodal displacements of the mode.
    axis_point, axis_direction : array_like, shape (3,)
        The shaft axis.
    n_slices : int
        Axial slices.
    weights : array_like, shape (n,), optional
        Nodal masses (default equal).

    Returns
    -------
    float
        In [0, 1].
    """
    p = np.asarray(points, float)
    u = np.asarray(shape, float)
    w = np.ones(len(p)) if weights is None else np.asarray(weights, float)
    e = np.asarray(axis_direction, float)
    e = e / np.linalg.norm(e)
    r = p - np.asarray(axis_point, float)
    s = r @ e
    rot = np.cross(e, r - np.outer(s, e))  # rigid twist field, |rot| = distance from axis
    total = float(np.sum(w * np.einsum("ij,ij->i", u, u)))
    if total <= 0.0:
        return 0.0
    edges = np.linspace(s.min(), s.max(), n_slices + 1)
    which = np.clip(np.searchsorted(edges, s, side="right") - 1, 0, n_slices - 1)
    captured = 0.0
    for k in range(n_slices):
        m = which == k
        denom = np.sum(w[m] * np.einsum("ij,ij->i", rot[m], rot[m]))
        if denom > 0.0:
            captured += np.sum(w[m] * np.einsum("ij,ij->i", rot[m], u[m])) ** 2 / denom
    return float(min(1.0, captured / total))


def classify_modes(
    points, shapes, axis_point=(0.0, 0.0, 0.0), axis_direction=(1.0, 0.0, 0.0),
    threshold: float = 0.6, n_slices: int = 20, weights=None,
) -> list[str]:
    """``"torsion"`` where :func:`torsional_participation` exceeds ``threshold``, else ``"other"``.

    ``shapes`` has shape (n_modes, n_nodes, 3).
    """
    return [
        "torsion"
        if torsional_participation(points, s, axis_point, axis_direction, n_slices, weights) > threshold
        else "other"
        for s in shapes
    ]


def compare_with_fe(
    chain_result: Mapping, fe_frequencies_hz: Sequence[float], fe_mode_classes: Sequence[str]
) -> dict:
    """The first FE torsional mode beside the lumped-chain frequencies.

    Parameters
    ----------
    chain_result : mapping
        The ``torsion`` results (``two_rotor_hz``, ``holzer_hz``, ``exact_hz``).
    fe_frequencies_hz : sequence of float
        FE elastic frequencies, ascending, Hz.
    fe_mode_classes : sequence of str
        One class per FE mode (``"torsion"`` marks torsional modes), e.g. from
        :func:`classify_modes`.

    Returns
    -------
    dict
        ``fe_mode`` (1-based index of the first torsional FE mode, None if there is none),
        ``fe_hz`` and ``rows``: per method its first frequency ``hz``,
        ``difference_of_fe`` = (hz - fe) / fe and ``difference_of_method`` = (hz - fe) / hz
        (seed 004 quotes the latter: 7.6 %).
    """
    if len(fe_frequencies_hz) != len(fe_mode_classes):
        raise ValueError(
            f"fe_mode_classes: need one class per FE frequency, got {len(fe_mode_classes)} "
            f"for {len(fe_frequencies_hz)}"
        )
    idx = next((i for i, c in enumerate(fe_mode_classes) if c == "torsion"), None)
    fe = None if idx is None else float(fe_frequencies_hz[idx])
    rows = []
    for method, key in (("two-rotor", "two_rotor_hz"), ("Holzer", "holzer_hz"), ("exact chain", "exact_hz")):
        v = chain_result.get(key)
        if v is None:
            continue
        hz = float(v if np.isscalar(v) else v[0])
        row = {"method": method, "hz": hz}
        if fe is not None:
            row["difference_of_fe"] = (hz - fe) / fe
            row["difference_of_method"] = (hz - fe) / hz
        rows.append(row)
    return {"fe_mode": None if idx is None else idx + 1, "fe_hz": fe, "rows": rows}
