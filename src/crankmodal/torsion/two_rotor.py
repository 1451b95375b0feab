"""Two-rotor system: closed-form frequency and node, and the reduction of a chain to two rotors.

Two rotors ``I_a``, ``I_b`` on a massless shaft of stiffness ``k`` (length ``L``) twist against
each other at::

    omega^2 = k (I_a + I_b) / (I_a I_b)

with the node at ``L I_b / (I_a + I_b)`` from rotor ``a`` (the heavier rotor sits nearer the
node). Seed 004 writes this as ``omega = sqrt(G J / (N_2 I_2))`` with ``N_2`` the node distance
from the flywheel ``I_2``; both are the same.

Reduction of a longer free-free chain (the seed's way, generalised): rotor ``a`` is the flywheel,
an end rotor (by default the heavier end); all other rotors are lumped into rotor ``b`` with
their summed inertia, placed at their inertia-weighted mean position along the shaft, measured
in compliance ``sum 1/k`` (which is length for a shaft of one equivalent diameter). The two-rotor
spring is the shaft between the flywheel and that position. For a two-rotor chain this is the
closed form itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .chain import TorsionalChain


@dataclass
class TwoRotorResult:
    """Frequency and node of a two-rotor system.

    Attributes
    ----------
    frequency_hz : float
        Hz.
    inertia_flywheel, inertia_lumped : float
        ``I_a`` (flywheel) and ``I_b`` (lumped rest), kg m^2.
    stiffness : float
        N m/rad.
    node_fraction_from_flywheel : float
        Node position as a fraction of the shaft from the flywheel, ``I_b / (I_a + I_b)``.
    length : float or None
        Equivalent shaft length between the two rotors, m.
    flywheel_index : int or None
        Chain index of the flywheel rotor, when reduced from a chain.
    """

    frequency_hz: float
    inertia_flywheel: float
    inertia_lumped: float
    stiffness: float
    node_fraction_from_flywheel: float
    length: float | None = None
    flywheel_index: int | None = None

    @property
    def node_from_flywheel_m(self) -> float | None:
        """Node distance from the flywheel along the equivalent shaft, m."""
        return None if self.length is None else self.node_fraction_from_flywheel * self.length

    def to_dict(self) -> dict:
        return {
            "frequency_hz": self.frequency_hz,
            "inertia_flywheel_kgm2": self.inertia_flywheel,
            "inertia_lumped_kgm2": self.inertia_lumped,
            "stiffness_Nm_per_rad": self.stiffness,
            "node_fraction_from_flywheel": self.node_fraction_from_flywheel,
            "length_m": self.length,
            "node_from_flywheel_m": self.node_from_flywheel_m,
            "flywheel_index": self.flywheel_index,
        }


def two_rotor(
    inertia_flywheel: float, inertia_other: float, stiffness: float, length: float | None = None
) -> TwoRotorResult:
    """Closed-form natural frequency and node of two rotors on a shaft.

    Parameters
    ----------
    inertia_flywheel, inertia_other : float
        kg m^2.
    stiffness : float
        N m/rad (``G J / L``).
    length : float, optional
        Shaft length, m, to give the node position in m.

    Returns
    -------
    TwoRotorResult
        ``frequency_hz`` (Hz) and the node's position from the flywheel (fraction, and m when
        ``length`` is given).

    Raises
    ------
    ParameterError
        Naming an inertia or the stiffness not finite and > 0, or ``length`` not > 0.

    Examples
    --------
    Seed 004's two-rotor model (its flywheel, throw, ``G J / L_eq`` and ``L_eq``) gives its
    printed 306.8 Hz and the node 129.66 mm from the flywheel:

    >>> import crankmodal as cm
    >>> r = cm.two_rotor(2.04661, 0.36172, 1.14223e6, length=0.86326)
    >>> print(f"{r.frequency_hz:.1f} Hz, node {1e3 * r.node_from_flywheel_m:.2f} mm")
    306.8 Hz, node 129.66 mm
    """
    from .. import arguments as arg

    ia = arg.number("inertia_flywheel", inertia_flywheel, gt=0.0)
    ib = arg.number("inertia_other", inertia_other, gt=0.0)
    stiffness = arg.number("stiffness", stiffness, gt=0.0)
    length = arg.number("length", length, gt=0.0, optional=True)
    omega = np.sqrt(stiffness * (ia + ib) / (ia * ib))
    return TwoRotorResult(
        frequency_hz=float(omega / (2.0 * np.pi)),
        inertia_flywheel=ia,
        inertia_lumped=ib,
        stiffness=float(stiffness),
        node_fraction_from_flywheel=ib / (ia + ib),
        length=None if length is None else float(length),
    )


def reduce_to_two_rotors(chain: TorsionalChain, flywheel: str = "auto") -> TwoRotorResult | None:
    """The seed's two-rotor reduction of a free-free chain (see the module docstring).

    Parameters
    ----------
    chain : TorsionalChain
    flywheel : {"auto", "first", "last"}
        Which end rotor is the flywheel; ``auto`` takes the heavier end (the first on a tie).

    Returns
    -------
    TwoRotorResult or None
        None for a chain with a fixed end (no two-rotor equivalent).

    Raises
    ------
    ParameterError
        Naming ``flywheel`` when it is not ``auto``, ``first`` or ``last`` (the ``[torsion]``
        stage reads it from ``torsion.two_rotor_flywheel``).
    """
    if chain.fixed_end:
        return None
    inertias = chain.inertias
    if flywheel == "auto":
        a = 0 if inertias[0] >= inertias[-1] else len(inertias) - 1
    elif flywheel in ("first", "last"):
        a = 0 if flywheel == "first" else len(inertias) - 1
    else:
        raise ParameterError("flywheel", f"must be auto, first or last; got {flywheel!r}")
    compliance = np.concatenate([[0.0], np.cumsum(1.0 / chain.stiffnesses)])
    rest = np.arange(len(inertias)) != a
    i_b = inertias[rest].sum()
    c_b = (inertias[rest] * compliance[rest]).sum() / i_b
    stiffness = 1.0 / abs(c_b - compliance[a])
    length = None
    pos = chain.rotor_positions()
    if pos is not None:
        length = abs((inertias[rest] * pos[rest]).sum() / i_b - pos[a])
    res = two_rotor(inertias[a], i_b, stiffness, length)
    res.flywheel_index = int(a)
    return res
