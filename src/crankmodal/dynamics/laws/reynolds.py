"""Finite-length plain journal bearing: steady Reynolds equation with cavitation.

Dimensionless Reynolds equation on the unwrapped film (``theta`` from the eccentricity
direction, positive in the sense of the surface velocity; ``zeta = 2 z / L`` in [-1, 1])::

    d/dtheta (H^3 dP/dtheta) + (D/L)^2 d/dzeta (H^3 dP/dzeta) = rhs,   H = 1 - eps cos(theta)

with ``rhs = 6 dH/dtheta`` for rotation (``P = p psi^2 / (mu omega)``, ``psi = c / R``,
``omega`` the sum of the surface angular velocities minus twice the whirl rate) and
``rhs = -12 cos(theta)`` for a pure squeeze (``P = p psi^2 / (mu eps_dot)``). ``P = 0`` at the
bearing ends; by symmetry only ``0 <= zeta <= 1`` is solved.

Cavitation, ``cavitation="reynolds"`` (Swift-Stieber): the complementarity problem ``P >= 0``,
``K P - g >= 0``, ``P (K P - g) = 0`` (``K = -div(H^3 grad)``, an M-matrix) solved by a
primal-dual active-set loop, which ends after finitely many sparse solves. By default the
pressure is held at ambient on the line of maximum film thickness (the oil inlet of
Raimondi and Boyd's full bearing); ``inlet="free"`` leaves both film boundaries free. With
``cavitation="half_sommerfeld"`` the full (Sommerfeld) pressure is solved and its negative
part discarded in the force (not a solution of the Reynolds equation: load only).

Film force on the journal ``F = mu omega R L / psi^2 * (f_r n + f_t t)`` (``n`` along the
eccentricity, ``t`` at +90 deg), with ``f = -int_0^1 int_0^2pi P (cos theta, sin theta) dtheta
dzeta``. The dimensionless load ``|f|`` equals ``F psi^2 / (mu U L)`` (``U = omega R``, seed
001 Eq. (2)); the Raimondi-Boyd Sommerfeld number is ``S = 1 / (pi |f|)``.

For dynamics, :func:`finite_bearing_force` interpolates a per-``L/D`` table of the rotation
(``omega - 2 gamma_dot``, equivalent rotation of a whirling journal) and squeeze (``eps_dot``)
sources solved together -- cavitation makes the film nonlinear, so the two are not added.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
from numba import njit

from ...errors import NumericalError

CAVITATION = ("reynolds", "half_sommerfeld")
INLETS = ("max_film", "free")


def _operator(eps, l_over_d, n_theta, n_zeta):
    """Finite-volume matrix ``K = -div(H^3 grad)`` (rows scaled by cell area), nodes, H."""
    dth = 2.0 * np.pi / n_theta
    dz = 1.0 / n_zeta
    th = np.arange(n_theta) * dth
    nz = n_zeta                                   # unknown rows j = 0..n_zeta-1 (j = n_zeta: P = 0)
    h_half = (1.0 - eps * np.cos(th + 0.5 * dth)) ** 3          # H^3 at theta_{i+1/2}
    h_node = (1.0 - eps * np.cos(th)) ** 3
    beta = 1.0 / l_over_d**2
    w = np.full(nz, dz)
    w[0] = 0.5 * dz                               # half cell at the symmetry plane
    i, j = np.meshgrid(np.arange(n_theta), np.arange(nz), indexing="ij")
    idx = i * nz + j
    ip = ((i + 1) % n_theta) * nz + j
    cth = (h_half[i] * w[j] / dth)                # theta-face conductance between i and i+1
    rows = [idx.ravel(), ip.ravel(), idx.ravel(), ip.ravel()]
    cols = [idx.ravel(), ip.ravel(), ip.ravel(), idx.ravel()]
    vals = [cth.ravel(), cth.ravel(), -cth.ravel(), -cth.ravel()]
    czeta = beta * h_node[i[:, :-1]] * dth / dz   # zeta-face conductance between j and j+1
    a, b = idx[:, :-1].ravel(), (idx[:, :-1] + 1).ravel()
    rows += [a, b, a, b]
    cols += [a, b, b, a]
    vals += [czeta.ravel(), czeta.ravel(), -czeta.ravel(), -czeta.ravel()]
    last = idx[:, -1].ravel()                     # face to the Dirichlet end zeta = 1
    rows.append(last)
    cols.append(last)
    vals.append(beta * h_node * dth / dz)
    n = n_theta * nz
    K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n))
    return K, th, w, dth


def _spd_solve(A, b):
    """``A x = b`` for the symmetric positive-definite film operator: SuperLU in its symmetric
    mode (minimum degree on A + A^T, diagonal pivots), 1.45x faster than spsolve's general
    COLAMD ordering on the 144 x 24 grid."""
    from scipy.sparse.linalg import splu

    return splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                options={"SymmetricMode": True}).solve(b)


def _solve_lcp(K, g, fixed, guess=None, max_iter=200):
    """Active-set solution of ``P >= 0, K P >= g, P (K P - g) = 0`` for an M-matrix ``K``.

    Nodes in the boolean mask ``fixed`` are held at ``P = 0`` (ambient inlet). The first
    guess of the cavitated set is ``guess`` or else where the source is negative (exact for
    a short bearing).
    """
    n = g.size
    active = fixed | ((g < 0.0) if guess is None else guess)
    diag = K.diagonal()
    P = np.zeros(n)
    for _ in range(max_iter):
        free = ~active
        P = np.zeros(n)
        P[free] = _spd_solve(K[free][:, free], g[free])
        lam = K @ P - g
        lam[free] = 0.0
        new = (lam - diag * P > 0.0) | fixed
        if np.array_equal(new, active):
            return P
        active = new
    raise NumericalError(
        f"reynolds: the cavitation active set did not settle in {max_iter} iterations; use a "
        f"finer grid (n_theta, n_zeta) or an eccentricity below 0.99")


def solve_pressure(eps, l_over_d, rotation=1.0, squeeze=0.0, n_theta=144, n_zeta=24,
                   cavitation="reynolds", inlet="max_film", guess=None, arc=None):
    """Dimensionless film pressure for a rotation and a squeeze term together.

    Parameters
    ----------
    eps : float
        Eccentricity ratio in [0, 1).
    l_over_d : float
        Bearing length over diameter, > 0.
    rotation, squeeze : float
        Weights of the rotation (``6 dH/dtheta``) and squeeze (``-12 cos theta``) right-hand
        sides; dimensional pressure is ``p = mu / psi^2 * P`` with ``rotation = omega - 2
        gamma_dot`` (rad/s) and ``squeeze = eps_dot`` (1/s).
    n_theta, n_zeta : int
        Nodes around the circumference and over the half length.
    cavitation : str
        ``"reynolds"`` or ``"half_sommerfeld"``.
    inlet : str
        ``"max_film"``: ambient pressure held on the line of maximum film thickness
        (``theta = pi``; oil fed there, the Raimondi-Boyd full-bearing assumption);
        ``"free"``: both film boundaries free (``P = dP/dn = 0``). Reynolds cavitation only.
        ``n_theta`` must be even for ``"max_film"``.
    guess : ndarray of bool (n_theta, n_zeta), optional
        First guess of the cavitated nodes (e.g. ``P[:, :-1] == 0`` of a nearby solution).
    arc : (float, float), optional
        Partial bearing: ``(centre, width)`` of the bearing arc in rad (``theta`` measured as
        above); the film outside the arc is at ambient pressure. None: full (360 deg) bearing.

    Returns
    -------
    P : ndarray (n_theta, n_zeta + 1)
        Pressure at the nodes (last column: bearing end, 0).
    theta : ndarray
        rad.
    force : ndarray (2,)
        ``(f_r, f_t)``, force on the journal per ``mu R L / psi^2``.
    """
    if not 0.0 <= eps < 1.0:
        raise ValueError(f"eps must be in [0, 1); got {eps}")
    if cavitation not in CAVITATION:
        raise ValueError(f"cavitation must be one of {CAVITATION}; got {cavitation!r}")
    K, th, w, dth = _operator(eps, l_over_d, n_theta, n_zeta)
    dH = (-eps * np.cos(th + 0.5 * dth)) - (-eps * np.cos(th - 0.5 * dth))  # H_{i+1/2} - H_{i-1/2}
    rhs = rotation * 6.0 * dH[:, None] * w[None, :] - squeeze * 12.0 * np.cos(th)[:, None] \
        * dth * w[None, :]
    g = -rhs.ravel()
    if inlet not in INLETS:
        raise ValueError(f"inlet must be one of {INLETS}; got {inlet!r}")
    if inlet == "max_film" and n_theta % 2:
        raise ValueError(f"n_theta must be even with inlet='max_film'; got {n_theta}")
    fixed = np.zeros((n_theta, n_zeta), bool)
    if arc is not None:
        outside = np.abs(np.angle(np.exp(1j * (th - arc[0])))) > 0.5 * arc[1]
        fixed[outside, :] = True
    if cavitation == "reynolds":
        if inlet == "max_film" and arc is None:
            fixed[n_theta // 2, :] = True
        P = _solve_lcp(K, g, fixed.ravel(), None if guess is None else np.ravel(guess))
    else:
        P = np.zeros(g.size)
        free = ~fixed.ravel()
        P[free] = np.maximum(_spd_solve(K[free][:, free], g[free]), 0.0)
    P = P.reshape(n_theta, n_zeta)
    load = P * w[None, :] * dth                   # integral weights (trapezoid in zeta)
    force = -np.array([np.sum(load * np.cos(th)[:, None]), np.sum(load * np.sin(th)[:, None])])
    return np.hstack([P, np.zeros((n_theta, 1))]), th, force


@dataclass
class SteadyBearing:
    """Steady performance of a plain journal bearing at one ``(eps, L/D)``.

    Attributes
    ----------
    load : float
        ``F psi^2 / (mu U L)`` (seed 001 Eq. (2), ``U = omega R``).
    attitude_deg : float
        Angle between the load and the line of centres, deg.
    sommerfeld : float
        Raimondi-Boyd ``S = (R/c)^2 mu N / P = 1 / (pi load)``.
    """

    eps: float
    l_over_d: float
    load: float
    attitude_deg: float
    sommerfeld: float

    def to_dict(self):
        return dict(self.__dict__)


def steady_bearing(eps, l_over_d, n_theta=144, n_zeta=24, cavitation="reynolds",
                   inlet="max_film", arc_deg=360.0):
    """Load, attitude angle and Sommerfeld number of a steadily loaded bearing (eps > 0).

    ``arc_deg < 360``: a partial bearing of that arc, centrally loaded (the arc centre is
    iterated onto the load line; Raimondi and Boyd's partial-bearing convention).
    """
    if arc_deg >= 360.0:
        _, _, (fr, ft) = solve_pressure(eps, l_over_d, 1.0, 0.0, n_theta, n_zeta, cavitation,
                                        inlet)
    else:
        width = np.radians(arc_deg)
        centre = 0.5 * np.pi                       # first guess: load at 90 deg to the centres
        for _ in range(200):
            _, _, (fr, ft) = solve_pressure(eps, l_over_d, 1.0, 0.0, n_theta, n_zeta,
                                            cavitation, arc=(centre, width))
            load_dir = float(np.arctan2(-ft, -fr))  # the applied load balances the film force
            if abs(load_dir - centre) < 1e-7:
                break
            centre = 0.5 * (centre + load_dir)
        else:
            raise NumericalError(
                f"reynolds: the load line of the {arc_deg:g}-degree arc did not settle for "
                f"eccentricity {eps}; use a wider arc or a finer grid")
    load = float(np.hypot(fr, ft))
    return SteadyBearing(eps, l_over_d, load, float(np.degrees(np.arctan2(ft, -fr))),
                         1.0 / (np.pi * load))


# -- table for dynamics ------------------------------------------------------------------------

EPS_TABLE = 1.0 - np.geomspace(0.995, 0.04, 30)     # 0.005 .. 0.96, clustered towards the wall
#: nodes in the source angle alpha, interpolated by cubic splines: on L/D = 2, 37 cubic nodes
#: met 0.04 deg of attitude off the nodes, where 37 linear ones gave 0.24 deg (73 linear: 0.06)
ALPHA_NODES, ALPHA_KY = 37, 3
ALPHA_TABLE = np.linspace(-0.5 * np.pi, 0.5 * np.pi, ALPHA_NODES)
#: the film of the dynamics has the boundary conditions of :func:`steady_bearing` (and of
#: Raimondi and Boyd's full bearing): ambient pressure on the line of maximum film, Reynolds
#: cavitation. (It was ``"free"`` before: 2 deg of attitude at eps = 0.5, L/D = 1.)
TABLE_INLET = "max_film"
#: the grid of :func:`steady_bearing`'s default, so that a table node is its solution
TABLE_GRID = (144, 24)


def _table_values(l_over_d: float, n_theta: int, n_zeta: int) -> np.ndarray:
    """The table's node values ``(eps, alpha, (f_r, f_t))``: solved, or read from the cache.

    The cache entry (``$CRANKMODAL_CACHE/film_tables``) is keyed by ``L/D``, the grid, the
    nodes, the inlet and this module's source; a damaged entry is removed with one warning line
    and solved again.
    """
    import hashlib
    import json
    from pathlib import Path

    from ...caches import cache_folder, discard_damaged, write_npz_atomically

    shape = (EPS_TABLE.size, ALPHA_TABLE.size, 2)
    key = hashlib.sha256(json.dumps({
        "l_over_d": repr(float(l_over_d)), "grid": [n_theta, n_zeta], "inlet": TABLE_INLET,
        "eps": EPS_TABLE.tolist(), "alpha": ALPHA_TABLE.tolist(),
        "source": hashlib.sha256(Path(__file__).read_bytes()).hexdigest()},
        sort_keys=True).encode()).hexdigest()[:32]
    path = cache_folder("film_tables") / f"{key}.npz"
    if path.is_file():
        try:
            with np.load(path, allow_pickle=False) as z:
                values = np.array(z["forces"], dtype=np.float64)
            if values.shape != shape or not np.all(np.isfinite(values)):
                raise ValueError(f"member 'forces' has shape {values.shape}, or is not finite")
            return values
        except Exception as exc:  # noqa: BLE001 - any damage: the table is solved again
            discard_damaged(path, "the cached film table", f"{type(exc).__name__}: {exc}",
                            then="solved again")
    values = np.zeros(shape)
    for k, e in enumerate(EPS_TABLE):
        s = 1.0 - e * e
        guess = None
        for m, a in enumerate(ALPHA_TABLE):       # warm start from the previous alpha
            P, _, values[k, m] = solve_pressure(e, l_over_d, np.cos(a) * s**2 / e,
                                                np.sin(a) * s**2.5, n_theta, n_zeta,
                                                inlet=TABLE_INLET, guess=guess)
            guess = P[:, :-1] <= 0.0
    try:
        write_npz_atomically(path, forces=values)
    except OSError:
        pass  # a read-only cache only costs the next run the solve
    return values


@lru_cache(maxsize=8)
def film_table(l_over_d, n_theta=TABLE_GRID[0], n_zeta=TABLE_GRID[1]):
    """Force table of the combined rotation and squeeze film for one ``L/D``.

    The Reynolds-cavitated problem is positively homogeneous in its two sources, so with
    ``r = w eps / s^2`` and ``q = eps_dot / s^(5/2)`` (``s = 1 - eps^2``,
    ``w = omega - 2 gamma_dot >= 0``) the force is ``hypot(r, q) * f(eps, alpha)``,
    ``alpha = atan2(q, r)`` in [-pi/2, pi/2]; ``f`` stays O(1) up to the wall. Returns the
    splines of ``f_r`` and ``f_t`` (cubic in ``eps``, ALPHA_KY in ``alpha``). Solved once per
    machine and ``L/D`` (cached on disk, :func:`_table_values`) and kept in memory.
    """
    from scipy.interpolate import RectBivariateSpline

    tab = _table_values(float(l_over_d), int(n_theta), int(n_zeta))
    return (RectBivariateSpline(EPS_TABLE, ALPHA_TABLE, tab[..., 0], kx=3, ky=ALPHA_KY),
            RectBivariateSpline(EPS_TABLE, ALPHA_TABLE, tab[..., 1], kx=3, ky=ALPHA_KY))


def finite_bearing_force(eps, eps_dot, gamma_dot, omega, viscosity, radius, length, clearance):
    """Finite-bearing film force on the journal, (radial, tangential) frame, N.

    Same arguments and frame as :func:`.lubrication.short_bearing_force`: rotation
    (``omega - 2 gamma_dot``, the equivalent rotation of a whirling journal) and squeeze
    (``eps_dot``) solved together with Reynolds cavitation and the inlet of
    :func:`steady_bearing` (``TABLE_INLET``), interpolated from :func:`film_table` (a reversed rotation by mirror symmetry). ``eps`` is
    clipped to the table, [0.005, 0.96].
    """
    e = float(min(max(eps, EPS_TABLE[0]), EPS_TABLE[-1]))
    wedge = e * (float(omega) - 2.0 * float(gamma_dot))
    return finite_bearing_film(eps, wedge, eps_dot, viscosity, radius, length, clearance)


@lru_cache(maxsize=8)
def film_spline(l_over_d: float) -> np.ndarray:
    """The film table of one ``L/D`` as one flat array for :func:`finite_film` (and the kernel):
    ``[n_tx, n_ty, eps_lo, eps_hi, tx..., ty..., c_r..., c_t...]`` — the knots and coefficients
    of :func:`film_table`'s two bicubic splines (FITPACK's layout, ``c[ix * (n_ty - 4) + iy]``)
    and the eccentricity range of the table."""
    f_r, f_t = film_table(round(float(l_over_d), 6))
    tx, ty, c_r = f_r.tck
    c_t = f_t.tck[2]
    if tuple(f_r.degrees) != (3, 3) or not np.array_equal(f_t.tck[0], tx):
        raise NumericalError("reynolds: the film table's splines are not bicubic on one grid")
    return np.concatenate([[tx.size, ty.size, EPS_TABLE[0], EPS_TABLE[-1]], tx, ty, c_r, c_t])


@njit(cache=True)
def _cubic_basis(t, x, out):
    """The four non-zero cubic B-splines of knots ``t`` at ``x`` into ``out``; returns the knot
    span ``i`` (``t[i] <= x < t[i + 1]``, the last span closed), so that ``out[a]`` belongs to
    coefficient ``i - 3 + a`` (de Boor's recurrence, as FITPACK's ``fpbspl``)."""
    n = t.size
    i = 3
    while i < n - 5 and x >= t[i + 1]:
        i += 1
    left = np.empty(4)
    right = np.empty(4)
    out[0] = 1.0
    for j in range(1, 4):
        left[j] = x - t[i + 1 - j]
        right[j] = t[i + j] - x
        saved = 0.0
        for r in range(j):
            temp = out[r] / (right[r + 1] + left[j - r])
            out[r] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        out[j] = saved
    return i


@njit(cache=True)
def finite_film(eps, wedge, eps_dot, viscosity, radius, length, clearance, spline):
    """Finite-bearing film force ``(f_r, f_t)`` on the journal, N, from the table ``spline``
    (:func:`film_spline`): the one evaluation of the finite film, for the Python path and the
    compiled kernel. Arguments as :func:`finite_bearing_film`."""
    ntx, nty = int(spline[0]), int(spline[1])
    e = min(max(eps, spline[2]), spline[3])
    s = 1.0 - e * e
    r = abs(wedge) / s**2
    q = eps_dot / s**2.5
    mag = np.hypot(r, q)
    if mag == 0.0:
        return 0.0, 0.0
    a = np.arctan2(q, r)
    tx = spline[4:4 + ntx]
    ty = spline[4 + ntx:4 + ntx + nty]
    ncx, ncy = ntx - 4, nty - 4
    c0 = 4 + ntx + nty
    bx = np.empty(4)
    by = np.empty(4)
    ix = _cubic_basis(tx, e, bx)
    iy = _cubic_basis(ty, a, by)
    fr = ft = 0.0
    for u in range(4):
        row = (ix - 3 + u) * ncy + iy - 3
        for v in range(4):
            w = bx[u] * by[v]
            fr += spline[c0 + row + v] * w
            ft += spline[c0 + ncx * ncy + row + v] * w
    scale = viscosity * radius * length * (radius / clearance) ** 2 * mag
    return scale * fr, (scale * ft if wedge >= 0.0 else -scale * ft)


def finite_bearing_film(eps, wedge, eps_dot, viscosity, radius, length, clearance):
    """Finite-bearing film force from the wedge ``eps (omega - 2 gamma_dot)`` (1/s), N.

    As :func:`finite_bearing_force`, with the arguments of
    :func:`.lubrication.short_bearing_film` (the wedge stays finite at the bearing centre).
    Evaluated by :func:`finite_film` (the compiled kernel's own evaluation).
    """
    spline = film_spline(float(length) / (2.0 * radius))
    return finite_film(float(eps), float(wedge), float(eps_dot), float(viscosity), float(radius),
                       float(length), float(clearance), spline)
