"""The lumped torsional chain and its exact eigen solution.

Rotors ``I_1 .. I_n`` (kg m^2) in a row, joined by shaft springs (N m/rad). Free at both ends,
the chain has ``n - 1`` springs and one rigid (zero-frequency) mode, which is left out. With
``fixed_end`` the first spring ties rotor 1 to a fixed wall, so there are ``n`` springs and no
rigid mode. The eigenproblem ``K theta = omega^2 M theta`` is solved by
:func:`scipy.linalg.eigh`; it is the reference the Holzer method is checked against.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import NumericalError, ParameterError


@dataclass
class TorsionalChain:
    """A lumped torsional chain.

    Attributes
    ----------
    inertias : ndarray, shape (n,)
        Rotor mass moments of inertia in order along the shaft, kg m^2.
    stiffnesses : ndarray, shape (n - 1,) or (n,)
        Shaft stiffnesses between consecutive rotors, N m/rad; with ``fixed_end`` the first
        one joins the fixed wall to rotor 1.
    fixed_end : bool
        ``False``: free at both ends; ``True``: the end before rotor 1 is fixed.
    lengths : ndarray or None
        Equivalent length of each spring, m (same shape as ``stiffnesses``), when known; node
        positions are then given in m from the start of the chain.
    labels : list of str
        Rotor names (``"rotor 1"``... by default).

    Raises
    ------
    ParameterError
        Naming the argument (``inertias``, ``inertias[i]``, ``stiffnesses``, ``stiffnesses[i]``,
        ``lengths``): too few rotors, an entry not > 0 and finite, the wrong number of springs or
        lengths. The ``[torsion]`` stage re-raises it under its scene key (``torsion.inertias[1]``).

    Examples
    --------
    Two rotors on a shaft, against the closed form ``sqrt(k (I1 + I2) / (I1 I2)) / 2 pi``:

    >>> import math
    >>> import crankmodal as cm
    >>> chain = cm.TorsionalChain(inertias=[0.8, 3.1], stiffnesses=[2.5e5])
    >>> f = cm.exact_modes(chain).frequencies_hz[0]
    >>> closed = math.sqrt(2.5e5 * (0.8 + 3.1) / (0.8 * 3.1)) / (2 * math.pi)
    >>> print(f"{f:.3f} Hz, closed form {closed:.3f} Hz")
    99.792 Hz, closed form 99.792 Hz
    """

    inertias: np.ndarray
    stiffnesses: np.ndarray
    fixed_end: bool = False
    lengths: np.ndarray | None = None
    labels: list = field(default_factory=list)

    def __post_init__(self):
        self.inertias = np.atleast_1d(np.asarray(self.inertias, float))
        self.stiffnesses = np.atleast_1d(np.asarray(self.stiffnesses, float))
        n = len(self.inertias)
        need = n if self.fixed_end else n - 1
        if n < (1 if self.fixed_end else 2):
            raise ParameterError(
                "inertias", f"a {'fixed-free' if self.fixed_end else 'free-free'} chain "
                f"needs at least {1 if self.fixed_end else 2} rotors, got {n}"
            )
        for name, arr in (("inertias", self.inertias), ("stiffnesses", self.stiffnesses)):
            for i, v in enumerate(arr):
                if not (np.isfinite(v) and v > 0.0):
                    raise ParameterError(f"{name}[{i}]", f"must be > 0 and finite, got {float(v)!r}")
        if len(self.stiffnesses) != need:
            raise ParameterError(
                "stiffnesses", f"needs {need} entries for {n} inertias "
                f"({'fixed end: wall spring first' if self.fixed_end else 'free at both ends'}), "
                f"got {len(self.stiffnesses)}"
            )
        if self.lengths is not None:
            self.lengths = np.asarray(self.lengths, float)
            if self.lengths.shape != self.stiffnesses.shape or np.any(self.lengths <= 0):
                raise ParameterError("lengths", f"need {need} positive lengths")
        if not self.labels:
            self.labels = [f"rotor {i + 1}" for i in range(n)]

    @property
    def n_rotors(self) -> int:
        return len(self.inertias)

    @property
    def n_rigid(self) -> int:
        """Number of zero-frequency modes (1 free-free, 0 with a fixed end)."""
        return 0 if self.fixed_end else 1

    def inner_springs(self) -> np.ndarray:
        """The springs between rotors (the wall spring left out), N m/rad."""
        return self.stiffnesses[1:] if self.fixed_end else self.stiffnesses

    def stiffness_matrix(self) -> np.ndarray:
        """Tridiagonal stiffness matrix, N m/rad, shape (n, n)."""
        n = self.n_rotors
        k = self.inner_springs()
        K = np.zeros((n, n))
        i = np.arange(n - 1)
        K[i, i] += k
        K[i + 1, i + 1] += k
        K[i, i + 1] -= k
        K[i + 1, i] -= k
        if self.fixed_end:
            K[0, 0] += self.stiffnesses[0]
        return K

    def rotor_positions(self) -> np.ndarray | None:
        """Rotor positions along the equivalent shaft from the start of the chain, m (or None)."""
        if self.lengths is None:
            return None
        inner = self.lengths[1:] if self.fixed_end else self.lengths
        start = self.lengths[0] if self.fixed_end else 0.0
        return start + np.concatenate([[0.0], np.cumsum(inner)])

    def to_dict(self) -> dict:
        out = {
            "inertias_kgm2": self.inertias,
            "stiffnesses_Nm_per_rad": self.stiffnesses,
            "fixed_end": self.fixed_end,
            "labels": list(self.labels),
        }
        if self.lengths is not None:
            out["lengths_m"] = self.lengths
            out["rotor_positions_m"] = self.rotor_positions()
        return out


def normalise_shape(theta: np.ndarray) -> np.ndarray:
    """Scale a mode shape to max ``|theta|`` = 1 with its first non-negligible entry positive."""
    theta = np.asarray(theta, float)
    theta = theta / np.max(np.abs(theta))
    first = theta[np.argmax(np.abs(theta) > 1e-9)]
    return theta if first > 0 else -theta


def node_positions(chain: TorsionalChain, theta: np.ndarray) -> list[dict]:
    """Nodes (zero twist) of a mode shape between rotors, by linear interpolation.

    Along a uniform shaft segment the twist angle varies linearly, so a sign change between
    rotors ``i`` and ``i + 1`` puts a node at the fraction ``theta_i / (theta_i - theta_{i+1})``
    of that segment. A fixed wall is a boundary, not listed as a node.

    Returns
    -------
    list of dict
        ``{"between": [i, i+1]`` (0-based rotor indices), ``"fraction"`` (0..1 from rotor i),
        ``"position_m"`` (from the start of the chain, when lengths are known)``}``.
    """
    theta = np.asarray(theta, float)
    scale = np.max(np.abs(theta))
    pos = chain.rotor_positions()
    nodes = []
    for i in range(len(theta) - 1):
        a, b = theta[i], theta[i + 1]
        if abs(a) <= 1e-12 * scale:
            frac = 0.0
        elif a * b < 0.0:
            frac = a / (a - b)
        else:
            continue
        node = {"between": [i, i + 1], "fraction": float(frac)}
        if pos is not None:
            node["position_m"] = float(pos[i] + frac * (pos[i + 1] - pos[i]))
        nodes.append(node)
    if abs(theta[-1]) <= 1e-12 * scale:
        node = {"between": [len(theta) - 1, len(theta) - 1], "fraction": 0.0}
        if pos is not None:
            node["position_m"] = float(pos[-1])
        nodes.append(node)
    return nodes


@dataclass
class ChainModes:
    """Exact natural frequencies and mode shapes of a chain (rigid mode left out).

    Attributes
    ----------
    frequencies_hz : ndarray
        Ascending, Hz.
    shapes : ndarray, shape (n_modes, n_rotors)
        Rotor twist angles, max ``|theta|`` = 1.
    nodes : list of list of dict
        :func:`node_positions` per mode.
    n_rigid : int
        Zero-frequency modes found and left out.
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    nodes: list
    n_rigid: int

    def to_dict(self) -> dict:
        return {
            "frequencies_hz": self.frequencies_hz,
            "mode_shapes": self.shapes,
            "nodes": self.nodes,
            "rigid_body_modes": self.n_rigid,
        }


def exact_modes(chain: TorsionalChain) -> ChainModes:
    """Eigen solution of the lumped chain with :func:`scipy.linalg.eigh`.

    Parameters
    ----------
    chain : TorsionalChain

    Returns
    -------
    ChainModes
        Elastic natural frequencies (Hz), mode shapes (max ``|theta|`` = 1), nodes, and the
        number of rigid modes left out (1 for a free-free chain).

    Examples
    --------
    >>> import crankmodal as cm
    >>> modes = cm.exact_modes(cm.TorsionalChain([0.8, 3.1], [2.5e5]))
    >>> modes.n_rigid, modes.frequencies_hz.round(2).tolist()
    (1, [99.79])

    Raises
    ------
    ParameterError
        ``chain`` is not a TorsionalChain.
    NumericalError
        If a free-free chain's lowest eigenvalue is not zero to round-off.
    """
    from scipy.linalg import eigh

    from .. import arguments as arg

    arg.instance("chain", chain, TorsionalChain, "a TorsionalChain")

    K = chain.stiffness_matrix()
    w2, vecs = eigh(K, np.diag(chain.inertias))
    n_rigid = chain.n_rigid
    if n_rigid:
        scale = np.max(np.abs(w2))
        if abs(w2[0]) > 1e-8 * scale:
            raise NumericalError(
                f"free-free chain: rigid mode eigenvalue {w2[0]:.3e} is not zero to round-off "
                f"(largest {scale:.3e}); the inertias/stiffnesses span too many decades"
            )
    w2 = w2[n_rigid:]
    vecs = vecs[:, n_rigid:]
    if np.any(w2 <= 0.0):
        raise NumericalError("chain: a non-positive elastic eigenvalue; check the input scaling")
    shapes = np.array([normalise_shape(v) for v in vecs.T]).reshape(len(w2), chain.n_rotors)
    return ChainModes(
        frequencies_hz=np.sqrt(w2) / (2.0 * np.pi),
        shapes=shapes,
        nodes=[node_positions(chain, s) for s in shapes],
        n_rigid=n_rigid,
    )
