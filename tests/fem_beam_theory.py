"""Independent oracles for the FE tests: Timoshenko beam frequencies (transfer matrix), Lamé."""

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq


def rectangle_shear_coefficient(nu):
    """Cowper's shear coefficient of a rectangular section."""
    return 10 * (1 + nu) / (12 + 11 * nu)


def _transfer(omega, L, E, nu, rho, A, I, kappa):
    """State [w, ψ, V, M] along x for harmonic motion of a Timoshenko beam: y' = B y."""
    G = E / (2 * (1 + nu))
    B = np.array([
        [0.0, 1.0, 1.0 / (kappa * G * A), 0.0],
        [0.0, 0.0, 0.0, 1.0 / (E * I)],
        [-rho * A * omega**2, 0.0, 0.0, 0.0],
        [0.0, -rho * I * omega**2, -1.0, 0.0],
    ])
    return expm(B * L)


def timoshenko_frequencies(n, L, E, nu, rho, A, I, kappa, ends="free-free", f_max=None):
    """The first ``n`` bending frequencies (Hz) of a uniform Timoshenko beam.

    ``ends``: ``free-free`` (M = V = 0 at both ends) or ``clamped-free`` (w = ψ = 0 at x = 0).
    Roots of the 2×2 boundary determinant of the transfer matrix, bracketed on a fine grid.
    """
    def det(f):
        T = _transfer(2 * np.pi * f, L, E, nu, rho, A, I, kappa)
        if ends == "free-free":
            sub = T[np.ix_([2, 3], [0, 1])]
        else:
            sub = T[np.ix_([2, 3], [2, 3])]
        return np.linalg.det(sub)

    c = np.sqrt(E * I / (rho * A))
    f_hi = f_max or (n + 2) ** 2 * np.pi * c / L**2
    grid = np.linspace(f_hi * 1e-4, f_hi, 1200)
    vals = np.array([det(f) for f in grid])
    roots = []
    for a, b, va, vb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if np.sign(va) != np.sign(vb):
            roots.append(brentq(det, a, b, xtol=1e-12 * b))
        if len(roots) == n:
            break
    return np.array(roots)


def lame_thick_cylinder(r, a, b, p, E, nu):
    """Internal pressure p on a tube a < r < b, plane strain: (u_r, σ_r, σ_θ, σ_z)."""
    A = p * a * a / (b * b - a * a)
    B = p * a * a * b * b / (b * b - a * a)
    sr = A - B / r**2
    st = A + B / r**2
    sz = 2 * nu * A
    u = (1 + nu) / E * ((1 - 2 * nu) * A * r + B / r)
    return u, sr, st, sz
