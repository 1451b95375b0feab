"""Damping of a torsional train, and dampers as chain elements.

Four sources, added into one viscous matrix ``C`` (N m s/rad) and one hysteretic matrix
``D`` (N m/rad, the imaginary part of a complex stiffness ``K + i D``):

- absolute damping per rotor ``c_i`` (oil churning, bearings, the driven machine): ``C_ii += c_i``;
- relative damping per shaft section ``c_s`` (material hysteresis as a dashpot across the
  section): like a stiffness between its two rotors;
- modal damping ratio ``zeta`` of every elastic mode of the undamped train:
  ``C += M Phi diag(2 zeta omega_r) Phi^T M`` with mass-normalised shapes ``Phi`` (adds to the
  rest). Default 0.02: a resonant amplification ``Q = 1 / (2 zeta) = 25``, inside the 10-50 range
  measured at resonance on reciprocating machines (issue 28; Wilson, *Practical Solution of
  Torsional Vibration Problems*, vol. 4, gives Q of 20-60 for undamped crankshafts);
- dampers, each a seismic ring of inertia ``J_d`` on a rotor: a viscous (Houdaille) damper couples
  the ring by a dashpot ``c_d`` only; a tuned rubber damper by a spring ``k_d`` with loss factor
  ``eta`` (complex stiffness ``k_d (1 + i eta)``, frequency-independent).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

#: default modal damping ratio of every elastic mode (see the module docstring for the source)
DEFAULT_MODAL_DAMPING = 0.02


@dataclass(frozen=True)
class Damper:
    """A torsional damper: a seismic ring on a rotor.

    Attributes
    ----------
    rotor : int
        0-based chain rotor carrying the damper hub (the hub inertia belongs to that rotor).
    inertia : float
        Ring (seismic mass) inertia, kg m^2.
    damping : float
        Viscous coefficient between hub and ring, N m s/rad.
    stiffness : float
        Spring between hub and ring, N m/rad (0: viscous damper).
    loss_factor : float
        Hysteretic loss factor of the spring (rubber), dimensionless.
    """

    rotor: int
    inertia: float
    damping: float = 0.0
    stiffness: float = 0.0
    loss_factor: float = 0.0

    def __post_init__(self):
        if not (np.isfinite(self.inertia) and self.inertia > 0):
            raise ParameterError("inertia", f"must be > 0, got {self.inertia!r}")
        for name in ("damping", "stiffness", "loss_factor"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ParameterError(name, f"must be >= 0 and finite, got {v!r}")
        if self.damping == 0 and self.stiffness * self.loss_factor == 0:
            raise ParameterError("damping", "a damper needs damping > 0 (viscous) or stiffness and "
                                 "loss_factor > 0 (tuned rubber)")

    @property
    def kind(self) -> str:
        return "viscous" if self.stiffness == 0 else "tuned_rubber"

    def to_dict(self) -> dict:
        return {"rotor": self.rotor + 1, "kind": self.kind, "inertia_kgm2": self.inertia,
                "damping_Nms_per_rad": self.damping, "stiffness_Nm_per_rad": self.stiffness,
                "loss_factor": self.loss_factor}


def _check_nonnegative(name: str, values, n: int) -> np.ndarray:
    if values is None:
        return np.zeros(n)
    v = np.atleast_1d(np.asarray(values, float))
    if v.shape != (n,):
        raise ParameterError(name, f"needs {n} entries, got {v.size}")
    for i, x in enumerate(v):
        if not (np.isfinite(x) and x >= 0):
            raise ParameterError(f"{name}[{i}]", f"must be >= 0 (N m s/rad), got {float(x)!r}")
    return v


def spring_matrix(pairs: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Assemble elements between DOF pairs (``-1`` = the fixed wall) into an (n, n) matrix."""
    A = np.zeros((n, n))
    for (i, j), v in zip(pairs, values):
        if i >= 0:
            A[i, i] += v
        if j >= 0:
            A[j, j] += v
        if i >= 0 and j >= 0:
            A[i, j] -= v
            A[j, i] -= v
    return A


def modal_damping_matrix(M: np.ndarray, K: np.ndarray, zeta: float) -> np.ndarray:
    """``M Phi diag(2 zeta omega_r) Phi^T M`` over the elastic modes of (K, M), N m s/rad.

    Zero-frequency (rigid, or a viscous damper's free ring) modes get no modal damping.
    """
    from scipy.linalg import eigh

    if not (np.isfinite(zeta) and zeta >= 0):
        raise ParameterError("modal_damping", f"must be >= 0, got {zeta!r}")
    if zeta == 0:
        return np.zeros_like(M)
    w2, phi = eigh(K, M)  # mass-normalised: phi^T M phi = I
    elastic = w2 > 1e-9 * max(np.max(np.abs(w2)), 1e-300)
    w = np.sqrt(w2[elastic])
    Mp = M @ phi[:, elastic]
    return (Mp * (2.0 * zeta * w)) @ Mp.T
