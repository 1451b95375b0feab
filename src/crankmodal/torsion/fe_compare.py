"""Putting the lumped-chain numbers beside an FE modal analysis of the same crank.

:func:`compare_with_fe` puts the first FE torsional mode beside the two-rotor, Holzer and exact
chain frequencies. It works on plain frequencies and class labels (the FE stage's own
classifier, :func:`crankmodal.fem.classify.classify`, names the modes), so no FE package is
imported here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np


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
        One class per FE mode (``"torsion"`` marks torsional modes), e.g. the FE modal
        classes mapped to ``"torsion"``/``"other"`` (see ``stage.beside_cad_and_fe``).

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
