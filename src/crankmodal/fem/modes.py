"""The result of a modal analysis (:class:`Modes`) and its conventions: eigenpairs ascending and
mass-normalised (:func:`sort_and_normalise`), rigid-body modes told apart by frequency
(:func:`rigid_mask`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: A computed mode is rigid when its frequency is below this fraction of a reference: the
#: highest computed one, or with many modes the (rigid + :data:`RIGID_REF_MODES`)-th lowest
#: (the 50th mode of a clamped 0.3 m bar is 1000x its first, 34 Hz, which counted as rigid).
RIGID_RATIO = 1e-3

#: Elastic modes above the rigid ones whose highest sets the reference of :data:`RIGID_RATIO`.
RIGID_REF_MODES = 12


def rigid_mask(f: np.ndarray, n_rigid: int = 6) -> np.ndarray:
    """Which frequencies (any unit) are rigid-body ones: below :data:`RIGID_RATIO` of the
    ``n_rigid + RIGID_REF_MODES``-th lowest (the highest when there are fewer)."""
    f = np.abs(np.asarray(f, float))
    if not len(f):
        return np.zeros(0, bool)
    ref = np.sort(f)[min(len(f), n_rigid + RIGID_REF_MODES) - 1]
    return f < RIGID_RATIO * ref


@dataclass
class Modes:
    """Result of a modal analysis.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (n,)
        Elastic natural frequencies, ascending, Hz.
    shapes : ndarray, shape (3 n_points, n)
        Mass-normalised elastic mode shapes (ΦᵀMΦ = I), node-interleaved, m/√kg.
    rigid_body_modes : int
        Zero-frequency modes found and left out.
    rigid_frequencies_hz : ndarray
        Their computed frequencies (numerically ~0), Hz.
    residuals : ndarray, shape (n,)
        ‖Kφ − λMφ‖ / ‖Kφ‖ of each elastic pair.
    orthogonality : float
        max ``|ΦᵀMΦ − I|`` over every returned pair (rigid ones included).
    effective_mass : ndarray, shape (n, 6)
        Effective modal masses for translations x, y, z (kg) and rotations about axes through
        the centre of mass (kg m²).
    total_mass : float
        kg, from M.
    rigid_mass : ndarray, shape (6,) or None
        What the six rigid-body fields carry (the totals the effective masses add up to over
        every mode): mass along x, y, z (kg) and moments of inertia about the axes through the
        centre of mass (kg m²).
    n_dofs : int
        Unconstrained degrees of freedom solved for.
    backend : str
        The sparse factorisation of the Lanczos run (``pardiso``, ``superlu``), or ``dense``
        when the pencil was solved dense (:func:`~crankmodal.fem.dense_eigen.use_dense`).
    eigensolver : str
        ``lanczos`` (shift-invert, sparse) or ``dense`` (LAPACK,
        :func:`~crankmodal.fem.dense_eigen.dense_pairs`).
    timings : dict
        Wall time per phase, s.
    n_solves, solve_time : int, float
        Factorisation solves of the Lanczos phase and their wall time, s (the rest of
        ``timings["lanczos_s"]`` is the loop's own work).
    memory : dict
        Peak resident memory, bytes.
    in_band : ndarray of bool or None
        Which elastic modes lie in the requested band.
    band_complete : bool or None
        Whether every mode of the band was computed: the highest computed mode reaches the
        band's top (the modes are the lowest ``n_modes``; above the highest there may be more).
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    rigid_body_modes: int
    rigid_frequencies_hz: np.ndarray
    residuals: np.ndarray
    orthogonality: float
    effective_mass: np.ndarray
    total_mass: float
    n_dofs: int
    backend: str
    timings: dict = field(default_factory=dict)
    memory: dict = field(default_factory=dict)
    in_band: np.ndarray | None = None
    band: tuple | None = None
    n_solves: int = 0
    solve_time: float = 0.0
    rigid_mass: np.ndarray | None = None
    eigensolver: str = "lanczos"

    @property
    def band_complete(self) -> bool | None:
        if self.band is None:
            return None
        return bool(len(self.frequencies_hz)) and bool(self.frequencies_hz[-1] >= self.band[1])

    def to_dict(self) -> dict:
        out = {
            "frequencies_hz": self.frequencies_hz,
            "rigid_body_modes": self.rigid_body_modes,
            "rigid_frequencies_hz": self.rigid_frequencies_hz,
            "n_dofs": self.n_dofs,
            "residual_max": float(self.residuals.max()) if len(self.residuals) else 0.0,
            "residuals": self.residuals,
            "m_orthogonality_max": self.orthogonality,
            "effective_mass": {
                k: self.effective_mass[:, i] for i, k in enumerate(
                    ("x_kg", "y_kg", "z_kg", "rx_kgm2", "ry_kgm2", "rz_kgm2"))},
            "total_mass_kg": self.total_mass,
            "backend": self.backend,
            "eigensolver": self.eigensolver,
            "n_solves": self.n_solves,
            "solve_time_s": self.solve_time,
            "timings_s": self.timings,
            "peak_memory_bytes": self.memory.get("peak_rss_bytes"),
        }
        if self.rigid_mass is not None:  # cumulative share of the total, as modes are added
            tot = np.where(self.rigid_mass > 0, self.rigid_mass, 1.0)
            cum = np.cumsum(self.effective_mass, axis=0) / tot
            out["effective_mass_cumulative_fraction"] = {
                k: cum[:, i] for i, k in enumerate(("x", "y", "z", "rx", "ry", "rz"))}
        if self.band is not None:
            out["band_hz"] = list(self.band)
            out["frequencies_in_band_hz"] = self.frequencies_hz[self.in_band]
            out["band_complete"] = self.band_complete
        return out


def sort_and_normalise(lam: np.ndarray, X: np.ndarray, M, chunk: int = 8):
    """Eigenpairs in ascending order with ``xᵀMx = 1``, normalised in place.

    Columns are scaled a few at a time, so no second n × k array is made (that copy was the
    memory peak of a 274k-DOF Craig–Bampton reduction).
    """
    if np.any(np.diff(lam) < 0):
        order = np.argsort(lam)
        lam, X = lam[order], X[:, order]
    for j in range(0, X.shape[1], chunk):
        Xj = X[:, j:j + chunk]
        Xj /= np.sqrt(np.einsum("ij,ij->j", Xj, M @ Xj))
    return lam, X
