"""The damping a flexible body's lowest mode actually has in the assembled mechanism.

``damping_ratio`` is given on the body's *free-free* modes: the internal force is
``C ξ̇`` with ``C = diag(2 ζ_a ω_a)`` in the file's orthonormal free-free modal coordinates
(:mod:`.flexible`). In the mechanism the joints hold the interfaces, and the body vibrates in
*constrained* modes (a coupler between two pins: pinned-pinned bending), each a mix of free-free
elastic modes and of rigid motion. The rigid part carries no damping, and the free-free modes
in the mix have other frequencies than the constrained one, so the constrained mode's damping
ratio is not the ζ given: a slender pinned-pinned coupler with ζ = 0.02 on its free-free modes
has about 0.0087 in its first pinned-pinned mode.

:func:`effective_damping` linearises the body about its undeformed state at rest with the
translations of its joined interfaces held (pins: the rotation stays free), and solves the
damped eigenproblem ``(s² M + s C + K) v = 0`` on the constraints' null space; the effective
ratio of a mode is ``ζ_eff = −Re(s) / |s|``. The rest of the mechanism is taken as rigid ground
at the pins (exact for a link between two much stiffer and heavier neighbours; otherwise the
neighbours' compliance and inertia lower the frequency somewhat), the rotation speed's
centrifugal stiffening is left out and the rigid tilts of a crank are dropped.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def pinned_interfaces(body) -> list[str]:
    """The interfaces held for a body's constrained modes: a crank's main journals (its joints
    to the ground; the crankpins carry the light rods and stay free), a four-bar link's joints
    (``roles``), or, without roles, every interface of its file (a rod's two eyes)."""
    roles = body.info.get("roles")
    names = []
    if roles and "mains" in roles:
        names = list(roles["mains"])
    elif roles:
        for role, v in roles.items():
            if role == "drive":  # where the drive acts: a journal already, or a free flange
                continue
            names += list(v) if isinstance(v, (list, tuple)) else [v]
    else:
        names = list(body.info["interface_centres"])
    return list(dict.fromkeys(n for n in names if n in body.frames))


def constrained_matrices(body, pinned=None):
    """Mass, damping and stiffness of the body (frame x, y, θ and its elastic modes; tilts
    dropped) on the null space of its pinned interfaces' translations, at rest and undeformed.

    Returns
    -------
    M, C, K : (r, r) arrays
        kg-, (N s/m)-, (N/m)-like generalised matrices of the ``r`` free coordinates.
    N : (3 + k, r) array
        The null-space basis: body coordinates = ``N`` × free coordinates.
    """
    k = body.n_elastic
    n = 3 + k
    q0 = np.zeros(body.ndof)
    M = body.mass_matrix(q0)[:n, :n]
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    K[3:, 3:] = np.diag(body.K[:k])
    C[3:, 3:] = np.diag(body.C[:k])
    pinned = pinned_interfaces(body) if pinned is None else pinned
    if pinned:
        A = np.vstack([body.frame_jacobian(q0, f)[:2, :n] for f in pinned])
        N = sla.null_space(A)
    else:
        N = np.eye(n)
    return N.T @ M @ N, N.T @ C @ N, N.T @ K @ N, N


def damped_modes(M, C, K) -> tuple[np.ndarray, np.ndarray]:
    """Undamped natural frequencies (``|s|``, rad/s) and damping ratios (``−Re s / |s|``) of the
    oscillating eigenvalues of ``s² M + s C + K`` (one per conjugate pair), lowest first.
    Zero roots (free rigid motion) and overdamped real roots are left out."""
    r = len(M)
    if r == 0:  # the constraints hold every coordinate
        return np.zeros(0), np.zeros(0)
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((r, r)), np.eye(r)], [-Minv @ K, -Minv @ C]])
    s = np.linalg.eigvals(A)
    scale = np.sqrt(max(np.max(np.abs(np.diag(Minv @ K))), 1e-300))
    keep = (s.imag > 1e-9 * scale) & (np.abs(s) > 1e-6 * scale)
    s = s[keep]
    s = s[np.argsort(np.abs(s))]
    return np.abs(s), -s.real / np.abs(s)


def effective_damping(body, pinned=None) -> dict | None:
    """The lowest constrained mode of a flexible body with its joined interfaces pinned:
    frequency and effective damping ratio, beside the ratio given on its free-free modes.

    Returns
    -------
    dict or None
        ``frequency_hz`` (Hz), ``damping_ratio`` (effective, of that mode), ``given_ratio``
        (on the lowest free-free mode), ``free_free_hz``, ``pinned`` (interface names); None
        for a body without elastic modes or without an oscillating constrained mode (the
        pins hold every coordinate).
    """
    if body.n_elastic == 0:
        return None
    pinned = pinned_interfaces(body) if pinned is None else list(pinned)
    M, C, K, _ = constrained_matrices(body, pinned)
    w, z = damped_modes(M, C, K)
    if w.size == 0:
        return None
    return {"frequency_hz": float(w[0] / (2 * np.pi)), "damping_ratio": float(z[0]),
            "given_ratio": float(body.zeta[0]), "free_free_hz": float(body.frequencies_hz[0]),
            "pinned": pinned,
            "model": "body alone, joined interfaces pinned (translations held), at rest"}


__all__ = ["constrained_matrices", "damped_modes", "effective_damping", "pinned_interfaces"]
