"""The FE crank's torsional modes beside the forced train's natural frequencies.

When a scene has the FE crank (``[geometry]`` + ``[material]`` + ``[modal]``) and a forced
``[torsion]`` study, the FE modes the classifier calls torsion are put beside the train's
natural frequencies, mode by mode. The FE solid carries neither the reciprocating masses nor the
rods, so for a crank built from its dimensions (the ``[torsion]`` geometry mode) the chain is
also solved with the solid parts only (crankpins, webs, flywheel): that pair compares like with
like and isolates the Ker Wilson stiffness; the pair with the mean reciprocating and big-end
inertia shows what the running machine adds. Plain data in, plain data out.
"""

from __future__ import annotations

import numpy as np

from .chain import TorsionalChain, exact_modes

#: why the lumped chain and the FE crank differ (printed with the comparison)
NOTE = ("The FE solid has no reciprocating or rod inertia (the chain adds their mean, "
        "seed 004 eqs. 2-3), its journals are radially supported, and its webs and journals twist "
        "as a 3-D solid, while the chain lumps each throw at one point on a Ker Wilson equivalent "
        "length (empirical coefficients) and holds the flywheel rigid; above the first mode the "
        "chain has one mode per rotor, the FE crank many more (bending-torsion coupled).")


def fe_beside_train(natural_hz, fe_frequencies_hz, fe_classes, crank_model=None) -> dict:
    """FE torsional modes beside the train's natural frequencies.

    Parameters
    ----------
    natural_hz : sequence of float
        The forced train's undamped natural frequencies, Hz.
    fe_frequencies_hz, fe_classes : sequence
        FE elastic frequencies (Hz) and their classes (``"torsion..."`` marks torsion).
    crank_model : CrankModel, optional
        The crank built from its dimensions; adds the solid-only chain.

    Returns
    -------
    dict
        ``rows`` (``mode``, ``fe_mode`` (1-based among all FE modes), ``fe_hz``, ``chain_hz``,
        ``chain_vs_fe``, and with a crank model ``solid_chain_hz``, ``solid_chain_vs_fe``), ``note``.
    """
    tors = [(i, float(f)) for i, (f, c) in enumerate(zip(fe_frequencies_hz, fe_classes))
            if str(c).startswith("torsion")]
    solid = None
    if crank_model is not None:
        parts = crank_model.throw_parts
        n = crank_model.chain.n_rotors - 1
        j_solid = parts["crankpin"] + parts["webs"]
        chain = TorsionalChain([j_solid] * n + [crank_model.flywheel_inertia], crank_model.chain.stiffnesses)
        solid = exact_modes(chain).frequencies_hz
    rows = []
    for k, (i, fe) in enumerate(tors):
        row = {"mode": k + 1, "fe_mode": i + 1, "fe_hz": fe}
        if k < len(natural_hz):
            row["chain_hz"] = float(natural_hz[k])
            row["chain_vs_fe"] = float(natural_hz[k] / fe - 1.0)
        if solid is not None and k < len(solid):
            row["solid_chain_hz"] = float(solid[k])
            row["solid_chain_vs_fe"] = float(solid[k] / fe - 1.0)
        rows.append(row)
    return {"rows": rows, "note": NOTE,
            "solid_chain_hz": None if solid is None else np.asarray(solid)}
