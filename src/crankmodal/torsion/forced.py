"""Steady-state forced response of a damped torsional train, per order and synthesised.

The train is the lumped chain plus damper rings: ``M theta'' + C theta' + (K + i D) theta = F``.
Under the periodic torques of a running machine, ``F = sum_q Re(F_q(Omega) exp(i q Omega t))``,
each order is solved exactly in the frequency domain (``omega = q Omega``)::

    X_q = [K + i D - omega^2 M + i omega C]^-1 F_q

(the convention of openTorsion's ``Assembly.ss_response``) and the orders are added in the time
domain over one working cycle with their phases to give the vibratory angle of every rotor and
the vibratory torque ``k_s (theta_i - theta_j)`` of every shaft section; amplitudes are half the
peak-to-peak. Viscous and hysteretic terms are exact for steady state; a free-free train's rigid
mode is part of the solution (the speed fluctuation of the whole train, which a flywheel limits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import NumericalError, ParameterError
from .damping import (
    DEFAULT_MODAL_DAMPING,
    Damper,
    _check_nonnegative,
    modal_damping_matrix,
    spring_matrix,
)


@dataclass
class DampedTrain:
    """Matrices of a damped torsional train; DOFs are the chain's rotors, then damper rings.

    Attributes
    ----------
    M, K, C, D : ndarray, shape (N, N)
        Inertia (kg m^2), stiffness (N m/rad), viscous damping (N m s/rad) and hysteretic
        damping (N m/rad, imaginary part of the complex stiffness).
    n_rotors : int
        Chain rotors (the first ``n_rotors`` DOFs).
    section_pairs : ndarray, shape (n_sections, 2), int
        Rotor indices at the ends of each shaft section (``-1``: the fixed wall).
    section_stiffness : ndarray, shape (n_sections,)
        N m/rad.
    labels : list of str
        One per DOF.
    dampers : tuple of Damper
    modal_damping : float
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    D: np.ndarray
    n_rotors: int
    section_pairs: np.ndarray
    section_stiffness: np.ndarray
    labels: list
    dampers: tuple = ()
    modal_damping: float = DEFAULT_MODAL_DAMPING

    @property
    def n_dofs(self) -> int:
        return self.M.shape[0]

    @property
    def n_sections(self) -> int:
        return len(self.section_stiffness)

    def section_matrix(self) -> np.ndarray:
        """``B`` (n_sections, N): section twist = ``B @ theta``."""
        B = np.zeros((self.n_sections, self.n_dofs))
        for s, (i, j) in enumerate(self.section_pairs):
            if i >= 0:
                B[s, i] += 1.0
            if j >= 0:
                B[s, j] -= 1.0
        return B

    def natural_frequencies(self) -> tuple[np.ndarray, np.ndarray]:
        """Undamped elastic natural frequencies (Hz) and mode shapes (max |theta| = 1).

        Viscous damper rings are free in the undamped train (their zero modes are left out
        with the rigid mode); tuned rubber dampers add their own mode.
        """
        from scipy.linalg import eigh

        w2, phi = eigh(self.K, self.M)
        keep = w2 > 1e-9 * max(np.max(np.abs(w2)), 1e-300)
        shapes = phi[:, keep].T
        shapes = shapes / np.max(np.abs(shapes), axis=1, keepdims=True)
        return np.sqrt(w2[keep]) / (2 * math.pi), shapes

    def to_dict(self) -> dict:
        return {"labels": list(self.labels), "n_dofs": self.n_dofs,
                "modal_damping": self.modal_damping,
                "dampers": [d.to_dict() for d in self.dampers]}


def damped_train(chain, modal_damping: float = DEFAULT_MODAL_DAMPING, rotor_damping=None,
                 section_damping=None, dampers=()) -> DampedTrain:
    """Build the damped train of a :class:`~.chain.TorsionalChain`.

    Parameters
    ----------
    chain : TorsionalChain
    modal_damping : float
        Damping ratio of every elastic mode (adds to the other damping).
    rotor_damping : array_like, shape (n_rotors,), optional
        Absolute damping of each rotor, N m s/rad.
    section_damping : array_like, shape (n_sections,), optional
        Relative damping across each shaft section (the wall spring first with a fixed end),
        N m s/rad.
    dampers : sequence of Damper

    Raises
    ------
    ParameterError
        Naming ``modal_damping``, ``rotor_damping[i]``, ``section_damping[i]`` (negative, wrong
        length) or ``dampers[i].rotor``.
    """
    from .. import arguments as arg
    from .chain import TorsionalChain

    arg.instance("chain", chain, TorsionalChain, "a TorsionalChain")
    modal_damping = arg.number("modal_damping", modal_damping, ge=0.0, lt=1.0)
    n = chain.n_rotors
    n_sec = len(chain.stiffnesses)
    if chain.fixed_end:
        pairs = np.array([[-1, 0]] + [[i, i + 1] for i in range(n - 1)], int)
    else:
        pairs = np.array([[i, i + 1] for i in range(n - 1)], int).reshape(-1, 2)
    c_rot = _check_nonnegative("rotor_damping", rotor_damping, n)
    c_sec = _check_nonnegative("section_damping", section_damping, n_sec)
    dampers = tuple(dampers)
    for i, d in enumerate(dampers):
        if not isinstance(d, Damper):
            raise ParameterError(f"dampers[{i}]", "must be a Damper")
        if not 0 <= d.rotor < n:
            raise ParameterError(f"dampers[{i}].rotor", f"must be a rotor 1..{n}, got {d.rotor + 1}")
    N = n + len(dampers)
    M = np.diag(np.concatenate([chain.inertias, [d.inertia for d in dampers]]))
    d_pairs = np.array([[d.rotor, n + i] for i, d in enumerate(dampers)], int).reshape(-1, 2)
    K = spring_matrix(pairs, chain.stiffnesses, N)
    K += spring_matrix(d_pairs, [d.stiffness for d in dampers], N)
    D = spring_matrix(d_pairs, [d.stiffness * d.loss_factor for d in dampers], N)
    C = modal_damping_matrix(M, K, modal_damping)
    C += np.diag(np.concatenate([c_rot, np.zeros(len(dampers))]))
    C += spring_matrix(pairs, c_sec, N)
    C += spring_matrix(d_pairs, [d.damping for d in dampers], N)
    labels = list(chain.labels) + [f"damper ring {i + 1} (on {chain.labels[d.rotor]})"
                                   for i, d in enumerate(dampers)]
    return DampedTrain(M=M, K=K, C=C, D=D, n_rotors=n, section_pairs=pairs,
                       section_stiffness=np.asarray(chain.stiffnesses, float), labels=labels,
                       dampers=dampers, modal_damping=float(modal_damping))


def harmonic_response(train: DampedTrain, omega, force) -> np.ndarray:
    """Complex steady-state amplitudes under harmonic torques ``Re(F exp(i omega t))``.

    Parameters
    ----------
    train : DampedTrain
    omega : array_like, shape (m,)
        Excitation frequencies, rad/s (> 0 for a free-free train).
    force : array_like, shape (m, n) or (m, N)
        Complex torque amplitudes on the first n DOFs (N m); damper rings get none unless given.

    Returns
    -------
    ndarray, shape (m, N), complex
        Angle amplitudes, rad.
    """
    omega = np.atleast_1d(np.asarray(omega, float))
    force = np.asarray(force, complex).reshape(len(omega), -1)
    N = train.n_dofs
    F = np.zeros((len(omega), N), complex)
    F[:, : force.shape[1]] = force
    out = np.empty((len(omega), N), complex)
    Kc = train.K + 1j * train.D
    iC = 1j * train.C
    m = np.diag(train.M)
    diag = np.arange(N)
    chunk = max(1, 2_000_000 // (N * N))
    for a in range(0, len(omega), chunk):
        w = omega[a : a + chunk]
        A = iC[None] * w[:, None, None]
        A += Kc[None]
        A[:, diag, diag] -= w[:, None] ** 2 * m[None]  # M is diagonal (rotors and rings)
        try:
            out[a : a + chunk] = np.linalg.solve(A, F[a : a + chunk, :, None])[..., 0]
        except np.linalg.LinAlgError:
            raise NumericalError("harmonic_response: the dynamic stiffness is singular at an excitation "
                                 "frequency (an undamped resonance); add damping") from None
    if not np.all(np.isfinite(out)):
        raise NumericalError("harmonic_response: non-finite response (an undamped resonance or "
                             "non-finite input); add damping")
    return out


def half_peak_to_peak(coefficients: np.ndarray, harmonics: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Half the peak-to-peak of ``x(phi) = sum_k Re(X_k exp(i k phi))`` over one period.

    Sampled at 8+ points per shortest period, then the extremes are refined
    by Newton steps on ``x'(phi) = 0`` (the sampled extreme alone would be low by up to
    ``(pi / 8)^2 / 2 = 8 %`` of the highest harmonic's amplitude).

    Parameters
    ----------
    coefficients : ndarray, shape (..., n_harmonics), complex
    harmonics : ndarray of int, shape (n_harmonics,)
        Harmonic indices ``k >= 1`` over the period.

    Returns
    -------
    half_pp : ndarray, shape (...)
    phase_of_max : ndarray, shape (...)
        ``phi`` of the maximum (rad).
    """
    X = np.asarray(coefficients, complex)
    k = np.asarray(harmonics, int)
    kmax = int(k.max())
    shape = X.shape[:-1]
    n = 1 << max(6, math.ceil(math.log2(8 * kmax + 1)))
    phi = 2 * math.pi * np.arange(n) / n
    basis = np.concatenate([np.cos(np.outer(k, phi)), -np.sin(np.outer(k, phi))])
    flat = X.reshape(-1, len(k))
    x = np.concatenate([flat.real, flat.imag], axis=1) @ basis  # samples, (m, n)
    Xt = np.ascontiguousarray(flat.T)  # (n_harmonics, m): harmonic axis first, contiguous
    h = 2 * math.pi / n
    kf = k.astype(float)[:, None]
    k2 = kf**2

    def waves(p):  # exp(i k p), (n_harmonics, m), by powers of exp(i p) (cheaper than exp)
        e1 = np.exp(1j * p)
        pw = np.empty((kmax, len(p)), complex)
        pw[0] = e1
        for j in range(1, kmax):
            np.multiply(pw[j - 1], e1, out=pw[j])
        return pw if len(k) == kmax else pw[k - 1]

    rows = np.arange(x.shape[0])
    ext = []
    for sign, i in ((1.0, np.argmax(x, axis=1)), (-1.0, np.argmin(x, axis=1))):
        sampled = x[rows, i]
        p0 = phi[i]
        p = p0
        for _ in range(3):
            xe = Xt * waves(p)
            d1 = -(xe.imag * kf).sum(0)
            d2 = -(xe.real * k2).sum(0)
            ok = sign * d2 < 0
            step = np.where(ok, -d1 / np.where(ok, d2, 1.0), 0.0)
            p = np.where(np.abs(p + step - p0) <= h, p + step, p)
        val = (Xt * waves(p)).real.sum(0)
        better = sign * val >= sign * sampled
        ext.append((np.where(better, val, sampled).reshape(shape), np.where(better, p, p0).reshape(shape)))
    return 0.5 * (ext[0][0] - ext[1][0]), ext[0][1]


@dataclass
class ForcedResponse:
    """Steady-state response of a train over a speed range.

    Attributes
    ----------
    speed_rpm : ndarray, shape (n_speeds,)
    orders : ndarray, shape (n_orders,)
    cycle_revolutions : int
    angle : ndarray, shape (n_speeds, n_orders, N), complex
        Angle amplitude of each DOF per order, rad.
    section_torque : ndarray, shape (n_speeds, n_orders, n_sections), complex
        Vibratory torque of each section per order, N m.
    amplitude_rad : ndarray, shape (n_speeds, N)
        Synthesised (all orders, phased) half peak-to-peak angle, rad.
    section_torque_nm : ndarray, shape (n_speeds, n_sections)
        Synthesised half peak-to-peak section torque, N m.
    """

    speed_rpm: np.ndarray
    orders: np.ndarray
    cycle_revolutions: int
    angle: np.ndarray
    section_torque: np.ndarray
    amplitude_rad: np.ndarray
    section_torque_nm: np.ndarray
    extra: dict = field(default_factory=dict)

    def order_amplitude_rad(self) -> np.ndarray:
        """|angle| per speed, order and DOF (rad)."""
        return np.abs(self.angle)

    def order_section_torque_nm(self) -> np.ndarray:
        """|section torque| per speed, order and section (N m)."""
        return np.abs(self.section_torque)


def steady_state(train: DampedTrain, excitation, speed_rpm) -> ForcedResponse:
    """Per-order and synthesised steady-state response at every speed.

    Parameters
    ----------
    train : DampedTrain
    excitation : crankmodal.torsion.excitation.RotorExcitation
        Order coefficients on the rotors as a function of speed.
    speed_rpm : array_like
        Shaft speeds, rpm (> 0).

    Raises
    ------
    ParameterError
        ``speed_rpm`` not > 0, or an excitation sized for another number of rotors.
    """
    from .. import arguments as arg
    from .excitation import RotorExcitation

    arg.instance("train", train, DampedTrain, "a DampedTrain (damped_train(...))")
    arg.instance("excitation", excitation, RotorExcitation, "a RotorExcitation (rotor_excitation(...))")
    speed = np.asarray(arg.numbers("speed_rpm", np.atleast_1d(np.asarray(speed_rpm, dtype=object)).tolist(),
                                   gt=0.0), float)
    if not len(speed):
        raise ParameterError("speed_rpm", "needs at least one speed")
    if excitation.gas.shape[1] != train.n_rotors:
        raise ParameterError("excitation", f"has {excitation.gas.shape[1]} rotors, the train {train.n_rotors}")
    Omega = speed * math.pi / 30.0
    q = excitation.orders
    F = excitation.at(Omega)  # (s, o, n)
    ns, no = len(speed), len(q)
    w = (Omega[:, None] * q[None, :]).ravel()
    X = harmonic_response(train, w, F.reshape(ns * no, -1)).reshape(ns, no, train.n_dofs)
    B = train.section_matrix() * train.section_stiffness[:, None]
    T = X @ B.T
    k = np.rint(q * excitation.cycle_revolutions).astype(int)
    amp, _ = half_peak_to_peak(np.moveaxis(X, 1, -1), k)
    tor, _ = half_peak_to_peak(np.moveaxis(T, 1, -1), k)
    return ForcedResponse(speed_rpm=speed, orders=q, cycle_revolutions=excitation.cycle_revolutions,
                          angle=X, section_torque=T, amplitude_rad=amp, section_torque_nm=tor)


def energy_balance_amplitude(train: DampedTrain, shape, omega: float, force) -> np.ndarray:
    """Resonant amplitude of each DOF from the energy balance over one cycle.

    At resonance the train moves in its mode shape ``phi`` (e.g. the Holzer shape) with
    amplitude ``A`` at the reference (``|phi| = 1``) rotor; the work of the harmonic torques
    per cycle, ``pi A |phi . F|``, equals the work of the damping,
    ``pi A^2 (omega phi^T C phi + phi^T D phi)``, so

        A = |phi . F| / (omega phi^T C phi + phi^T D phi)

    Parameters
    ----------
    train : DampedTrain
    shape : array_like, shape (N,) or (n_rotors,)
        Real mode shape (damper rings' entries zero when shorter).
    omega : float
        Natural frequency, rad/s.
    force : array_like, shape (n_rotors,), complex
        Harmonic torque amplitudes (N m).

    Returns
    -------
    ndarray, shape (N,)
        ``A |phi|``, rad.
    """
    phi = np.zeros(train.n_dofs)
    s = np.asarray(shape, float)
    phi[: len(s)] = s
    f = np.zeros(train.n_dofs, complex)
    fv = np.asarray(force, complex)
    f[: len(fv)] = fv
    dissipation = omega * phi @ train.C @ phi + phi @ train.D @ phi
    if not dissipation > 0:
        raise ParameterError("shape", "the train does not dissipate energy in this mode")
    return abs(phi @ f) / dissipation * np.abs(phi)
