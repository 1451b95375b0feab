"""The Holzer method: residual over a frequency sweep, bracketed roots, the Holzer table.

For a trial frequency ``omega`` the first rotor is given a unit twist and the twist is carried
along the chain: rotor ``i`` adds the inertia torque ``I_i omega^2 theta_i`` to the shaft torque
``T``, which twists the next spring by ``T / k_i``. A free-free chain vibrates freely where the
torque left after the last rotor (the *residual torque*) is zero. With a fixed end the sweep
starts at the free end and the residual is the twist left at the wall.

Roots are bracketed by sign changes of the residual on a grid (linear and geometric spacing
together) up to a Gershgorin bound of the highest natural frequency, refined with :func:`scipy.optimize.brentq` to a relative tolerance of
about 1e-15, and counted: an unbranched chain has exactly as many distinct natural frequencies
as it has rotors (one fewer when free-free), so a missed root is detected and the grid refined.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import NumericalError
from .chain import TorsionalChain, node_positions, normalise_shape


def _propagate(chain: TorsionalChain, omega):
    """Twist angles (n, m) and residual (m,) at the frequencies ``omega`` (m,), rad/s."""
    omega = np.atleast_1d(np.asarray(omega, float))
    w2 = omega**2
    inertias = chain.inertias
    springs = chain.inner_springs()
    if chain.fixed_end:  # start at the free end, run towards the wall
        inertias, springs = inertias[::-1], springs[::-1]
    n = len(inertias)
    theta = np.empty((n, len(omega)))
    theta[0] = 1.0
    torque = np.zeros(len(omega))
    for i in range(n):
        torque = torque + inertias[i] * w2 * theta[i]
        if i < n - 1:
            theta[i + 1] = theta[i] - torque / springs[i]
    if chain.fixed_end:
        residual = theta[-1] - torque / chain.stiffnesses[0]
        theta = theta[::-1]
    else:
        residual = torque
    return theta, residual


def holzer_residual(chain: TorsionalChain, omega) -> np.ndarray:
    """Residual at ``omega`` (rad/s): torque after the last rotor for a unit twist of the first
    (N m/rad, free-free), or the twist at the wall (rad/rad, fixed end)."""
    return _propagate(chain, omega)[1]


def omega_upper_bound(chain: TorsionalChain) -> float:
    """Gershgorin bound on the highest natural frequency, rad/s."""
    K = chain.stiffness_matrix()
    return float(np.sqrt(np.max(np.abs(K).sum(axis=1) / chain.inertias)))


def holzer_table(chain: TorsionalChain, omega: float) -> list[dict]:
    """The Holzer table at one trial frequency, one row per rotor (like seed 004 Fig. 2).

    Row keys: ``rotor``, ``inertia_kgm2``, ``omega2`` (rad^2/s^2), ``theta_rad``,
    ``inertia_torque_Nm`` (``I omega^2 theta``), ``shaft_torque_Nm`` (cumulative sum),
    ``stiffness_Nm_per_rad`` and ``twist_rad`` (of the spring after the rotor; None after the
    last). With a fixed end the rows run from the free end to the wall.
    """
    theta, _ = _propagate(chain, [omega])
    theta = theta[:, 0]
    order = np.arange(chain.n_rotors)
    springs = list(chain.inner_springs())
    if chain.fixed_end:
        order = order[::-1]
        springs = springs[::-1] + [chain.stiffnesses[0]]
    else:
        springs = springs + [None]
    rows, torque = [], 0.0
    for j, i in enumerate(order):
        t_i = chain.inertias[i] * omega**2 * theta[i]
        torque += t_i
        k = springs[j]
        rows.append({
            "rotor": chain.labels[i],
            "inertia_kgm2": float(chain.inertias[i]),
            "omega2": float(omega**2),
            "theta_rad": float(theta[i]),
            "inertia_torque_Nm": float(t_i),
            "shaft_torque_Nm": float(torque),
            "stiffness_Nm_per_rad": None if k is None else float(k),
            "twist_rad": None if k is None else float(torque / k),
        })
    return rows


@dataclass
class HolzerResult:
    """Holzer roots with their mode shapes, nodes and tables, and the sweep that found them.

    Attributes
    ----------
    frequencies_hz : ndarray
        Roots, ascending, Hz (the zero root of a free-free chain left out).
    shapes : ndarray, shape (n_roots, n_rotors)
        Twist per rotor at each root, max ``|theta|`` = 1.
    nodes : list
        :func:`~crankmodal.torsion.chain.node_positions` per root.
    tables : list of list of dict
        :func:`holzer_table` at each root.
    sweep_omega : ndarray
        Frequencies of the sweep, rad/s.
    sweep_residual : ndarray
        Residual at each sweep frequency.
    residual_kind : str
        ``"torque_Nm"`` (free-free) or ``"wall_twist_rad"`` (fixed end).
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    nodes: list
    tables: list
    sweep_omega: np.ndarray
    sweep_residual: np.ndarray
    residual_kind: str

    def to_dict(self) -> dict:
        return {
            "frequencies_hz": self.frequencies_hz,
            "mode_shapes": self.shapes,
            "nodes": self.nodes,
            "tables": self.tables,
            "residual_kind": self.residual_kind,
            "n_sweep_points": len(self.sweep_omega),
        }

    def table_text(self, mode: int = 0) -> str:
        """The Holzer table at root ``mode`` as fixed-width text."""
        head = (f"{'rotor':>10} {'I kg m2':>12} {'theta rad':>12} {'I w2 theta':>13} "
                f"{'sum N m':>13} {'k N m/rad':>12} {'twist rad':>12}")
        title = (f"Holzer table at f = {self.frequencies_hz[mode]:.6g} Hz "
                 f"(omega^2 = {self.tables[mode][0]['omega2']:.6g} rad^2/s^2)")
        lines = [title, head]
        for r in self.tables[mode]:
            k = "" if r["stiffness_Nm_per_rad"] is None else f"{r['stiffness_Nm_per_rad']:.6g}"
            tw = "" if r["twist_rad"] is None else f"{r['twist_rad']:.6g}"
            lines.append(f"{r['rotor']:>10} {r['inertia_kgm2']:>12.6g} {r['theta_rad']:>12.6g} "
                         f"{r['inertia_torque_Nm']:>13.6g} {r['shaft_torque_Nm']:>13.6g} "
                         f"{k:>12} {tw:>12}")
        return "\n".join(lines)


def _brackets(chain: TorsionalChain, omega: np.ndarray):
    res = holzer_residual(chain, omega)
    s = np.sign(res)
    exact = np.flatnonzero(s[1:-1] == 0) + 1
    change = np.flatnonzero(s[:-1] * s[1:] < 0)
    return res, [(omega[i], omega[i + 1]) for i in change], omega[exact]


def holzer(chain: TorsionalChain, points_per_rotor: int = 400, max_refinements: int = 6) -> HolzerResult:
    """All natural frequencies of the chain by the Holzer method.

    Parameters
    ----------
    chain : TorsionalChain
    points_per_rotor : int
        Initial sweep density (the grid has about ``2 max(2000, points_per_rotor * n)`` points).
        The cost grows as ``n^2``: a few seconds for 150 rotors; use :func:`exact_modes` for long
        discretised shafts.
    max_refinements : int
        Times the grid is made 4x finer when fewer roots than expected were bracketed.

    Raises
    ------
    ParameterError
        Naming ``chain`` (not a TorsionalChain), ``points_per_rotor`` (an integer in
        [1, 1e5], and at most 1e8 grid points) or ``max_refinements`` (an integer in [0, 10]).
    NumericalError
        If the expected number of roots is not bracketed after the refinements.

    Examples
    --------
    The roots of the Holzer residual are the chain's eigenvalues (:func:`exact_modes`):

    >>> import crankmodal as cm
    >>> chain = cm.TorsionalChain([0.8, 3.1], [2.5e5])
    >>> print(f"{cm.holzer(chain).frequencies_hz[0]:.3f} Hz")
    99.792 Hz
    """
    from scipy.optimize import brentq

    from .. import arguments as arg

    arg.instance("chain", chain, TorsionalChain, "a TorsionalChain")
    points_per_rotor = arg.integer("points_per_rotor", points_per_rotor, ge=1, le=100_000)
    max_refinements = arg.integer("max_refinements", max_refinements, ge=0, le=10)
    if 2 * points_per_rotor * chain.n_rotors > 1e8:
        from ..errors import ParameterError

        raise ParameterError("points_per_rotor", f"{points_per_rotor} for {chain.n_rotors} "
                             f"rotors is a sweep of {2 * points_per_rotor * chain.n_rotors:.3g} "
                             f"points (8 bytes each, x4 per refinement); keep it <= 1e8, or use "
                             "exact_modes")
    expected = chain.n_rotors - chain.n_rigid
    w_max = 1.02 * omega_upper_bound(chain)
    n_grid = max(2000, points_per_rotor * chain.n_rotors)
    for _ in range(max_refinements + 1):
        # linear spacing for the bulk, geometric spacing so low roots far below w_max are bracketed
        omega = np.union1d(np.linspace(w_max * 1e-6, w_max, n_grid), np.geomspace(w_max * 1e-6, w_max, n_grid))
        res, brackets, exact = _brackets(chain, omega)
        if len(brackets) + len(exact) == expected:
            break
        n_grid *= 4
    else:
        raise NumericalError(
            f"Holzer: bracketed {len(brackets) + len(exact)} of {expected} roots on a "
            f"{n_grid // 4}-point sweep; the chain's frequencies are too close together or the "
            "input spans too many decades: rescale or merge nearly rigid springs"
        )
    def f(w):
        return holzer_residual(chain, w)[0]

    roots = [brentq(f, a, b, xtol=1e-14 * a, rtol=4 * np.finfo(float).eps, maxiter=500) for a, b in brackets]
    roots = np.sort(np.concatenate([roots, exact]))
    theta, _ = _propagate(chain, roots)
    shapes = np.array([normalise_shape(t) for t in theta.T]).reshape(len(roots), chain.n_rotors)
    return HolzerResult(
        frequencies_hz=roots / (2.0 * np.pi),
        shapes=shapes,
        nodes=[node_positions(chain, s) for s in shapes],
        tables=[holzer_table(chain, w) for w in roots],
        sweep_omega=omega,
        sweep_residual=res,
        residual_kind="wall_twist_rad" if chain.fixed_end else "torque_Nm",
    )
