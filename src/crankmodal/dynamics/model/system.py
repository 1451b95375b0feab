"""Assembly of bodies, constraints, clearance joints and loads into an index-1 DAE.

Equations of motion in body coordinates ``q`` with Lagrange multipliers ``lam``::

    [ M    Phi_q^T ] [ qdd ]   [ Q                                   ]
    [ Phi_q   0    ] [ lam ] = [ gamma - 2 a Phidot - b**2 Phi        ]

(Baumgarte stabilisation with ``a = b = baumgarte`` in 1/s). The ODE state is
``y = [q, qd, W_drive, W_loads, W_constraints, D_contact, D_friction, D_modal]``: the last six
are the running integrals (J) of the drive power, the power of applied loads, the power of the
ideal constraint forces (zero up to drift), and the power dissipated by contact damping, by
friction and by the flexible bodies' modal damping.
"""

from __future__ import annotations

import numpy as np

from ...errors import NumericalError
from .bodies import Ground, RigidBody
from .joints import AngleDrive

N_AUX = 6
_NO_JACOBIAN = np.zeros((3, 0))
AUX_NAMES = ("work_drive", "work_loads", "work_constraints", "dissipated_contact",
             "dissipated_friction", "dissipated_modal")


class Multibody:
    """A planar multibody system.

    Parameters
    ----------
    bodies : list
        Bodies with coordinates (a :class:`~.bodies.Ground` is referenced by joints, not listed).
    constraints : list
        Ideal joints and drives (objects with ``n_eq`` and ``blocks``).
    clearances : list of ClearanceJoint
    loads : list
        Objects with ``forces(sysm, t, q, qd, Q) -> power``.
    gravity : (2,) array
        m/s^2.
    baumgarte : float
        Stabilisation rate, 1/s.
    compiled : bool
        Evaluate :meth:`solve` and :meth:`rhs` with the Numba-compiled kernel of
        :mod:`.compiled` when every part of the system has a compiled form (all-rigid bodies,
        pins, sliders, drives, clearance joints without a finite-length film, piston loads,
        crank torques); the
        generic Python path otherwise. The system must not be changed after its first
        evaluation on the compiled path.
    """

    def __init__(self, bodies, constraints, clearances=(), loads=(), gravity=(0.0, 0.0),
                 baumgarte=100.0, compiled=True):
        self.bodies = list(bodies)
        self.constraints = list(constraints)
        self.clearances = list(clearances)
        self.loads = list(loads)
        self.gravity = np.asarray(gravity, float)
        self.baumgarte = float(baumgarte)
        self.slices = {}
        i = 0
        for b in self.bodies:
            self.slices[id(b)] = slice(i, i + b.ndof)
            i += b.ndof
        self.n = i
        self.rows = []
        j = 0
        for c in self.constraints:
            self.rows.append(slice(j, j + c.n_eq))
            j += c.n_eq
        self.m = j
        self._kkt = np.zeros((self.n + self.m, self.n + self.m))
        # constant mass matrix only for rigid bodies (a flexible one has M(q)): decided by type,
        # not by duck-typing an attribute a flexible body might also carry
        self._rigid = all(isinstance(b, RigidBody) for b in self.bodies)
        # bodies with elastic coordinates (FlexibleBody): internal forces and strain energy
        self._elastic = [b for b in self.bodies if hasattr(b, "internal_forces")]
        if self._rigid:
            self._kkt[: self.n, : self.n] = self.mass_matrix(np.zeros(self.n))
        self.nfev = 0
        self.max_nfev = None
        self._drive_rows = np.zeros(self.m, bool)
        for c, r in zip(self.constraints, self.rows):
            self._drive_rows[r] = isinstance(c, AngleDrive)
        self.compiled = compiled
        self._kernel = None  # the compiled form, built at the first evaluation

    def kernel(self):
        """The :class:`~.compiled.CompiledSystem` of this system, or None (generic path)."""
        if not self.compiled:
            return None
        if self._kernel is None:
            from ..kernel import compiled

            self._kernel = compiled.CompiledSystem(self) if compiled.applicable(self) else False
        return self._kernel or None

    def gap(self, j, q) -> float:
        """Penetration of clearance joint ``j`` from positions only, m (event function)."""
        k = self.kernel()
        if k is None:
            return self.clearances[j].gap(self, q)
        return float(k.penetration(j, q)[0])

    def penetration_rate(self, j, q, qd) -> float:
        """Rate of penetration of clearance joint ``j``, m/s (event function)."""
        k = self.kernel()
        if k is None:
            return self.clearances[j].kinematics(self, q, qd)["delta_dot"]
        return float(k.penetration(j, q, qd)[1])

    # ----------------------------------------------------------------- body access
    def frame(self, body, frame, q, qd):
        """Pose, Jacobian (3, ndof_body) and ``Jdot qdot`` of an interface frame."""
        if isinstance(body, Ground):
            return body.frame_pose(None, frame), _NO_JACOBIAN, np.zeros(3)
        s = self.slices[id(body)]
        return (body.frame_pose(q[s], frame), body.frame_jacobian(q[s], frame),
                body.frame_bias(q[s], qd[s], frame))

    def frame_pose_only(self, body, frame, q):
        if isinstance(body, Ground):
            return body.frame_pose(None, frame)
        return body.frame_pose(q[self.slices[id(body)]], frame)

    def frame_velocity(self, body, J, qd):
        """Frame velocity ``(vx, vy, omega)`` from its Jacobian."""
        if J is _NO_JACOBIAN:
            return np.zeros(3)
        return J @ qd[self.slices[id(body)]]

    def add_frame_force(self, Q, body, J, f):
        """Add a force/moment ``(fx, fy, mz)`` acting at an interface frame to ``Q``."""
        if J is not _NO_JACOBIAN:
            Q[self.slices[id(body)]] += J.T @ f

    # ----------------------------------------------------------------- global quantities
    def mass_matrix(self, q):
        M = np.zeros((self.n, self.n))
        for b in self.bodies:
            s = self.slices[id(b)]
            M[s, s] = b.mass_matrix(q[s])
        return M

    def constraint_terms(self, t, q, qd):
        """``Phi``, ``Phi_q`` (m, n), ``nu = -Phi_t`` and ``gamma``, joint by joint (any body
        type)."""
        phi = np.empty(self.m)
        Cq = np.zeros((self.m, self.n))
        nu = np.empty(self.m)
        gamma = np.empty(self.m)
        for c, r in zip(self.constraints, self.rows):
            ph, blocks, nn, gg = c.blocks(self, t, q, qd)
            phi[r], nu[r], gamma[r] = ph, nn, gg
            for body, J in blocks:
                if not isinstance(body, Ground):
                    Cq[r, self.slices[id(body)]] += J
        return phi, Cq, nu, gamma

    def energy(self, q, qd):
        """Kinetic and gravitational potential energy, J."""
        ke = pe = 0.0
        for b in self.bodies:
            s = self.slices[id(b)]
            ke += b.kinetic_energy(q[s], qd[s])
            pe += b.potential_energy(q[s], self.gravity)
        return ke, pe

    def strain_energy(self, q):
        """Elastic strain energy of the flexible bodies, J."""
        return sum(b.strain_energy(q[self.slices[id(b)]]) for b in self._elastic)

    def damping_power(self, qd):
        """Power dissipated by the flexible bodies' modal damping, W."""
        return sum(b.damping_power(qd[self.slices[id(b)]]) for b in self._elastic)

    def solve(self, t, q, qd, v_impact=None):
        """Accelerations, multipliers and per-element diagnostics at one state.

        ``v_impact``: per clearance joint the impact velocity of its contact in progress, m/s
        (restitution laws; the integrator's state); None reads each joint's ``v_impact``.
        """
        k = self.kernel()
        if k is not None:
            return k.solve(t, q, qd, v_impact)
        n = self.n
        Q = np.zeros(n)
        for b in self.bodies:
            s = self.slices[id(b)]
            Q[s] += b.gravity_force(q[s], self.gravity) + b.velocity_forces(q[s], qd[s])
        for b in self._elastic:
            s = self.slices[id(b)]
            Q[s] -= b.internal_forces(q[s], qd[s])
        contacts = [cj.forces(self, t, q, qd, Q, None if v_impact is None else v_impact[j])
                    for j, cj in enumerate(self.clearances)]
        p_loads = sum(ld.forces(self, t, q, qd, Q) for ld in self.loads)
        phi, Cq, nu, gamma = self.constraint_terms(t, q, qd)
        a = self.baumgarte
        phidot = Cq @ qd - nu
        rhs = np.concatenate([Q, gamma - 2.0 * a * phidot - a * a * phi])
        K = self._kkt
        if not self._rigid:
            K[:n, :n] = self.mass_matrix(q)
        K[:n, n:] = Cq.T
        K[n:, :n] = Cq
        sol = np.linalg.solve(K, rhs)
        qdd, lam = sol[:n], sol[n:]
        return {"qdd": qdd, "lam": lam, "phi": phi, "Cq": Cq, "nu": nu, "contacts": contacts,
                "p_loads": p_loads}

    def drive_power(self, lam, Cq, qd):
        """Power of the rheonomic (drive) constraints and of the ideal joints, W."""
        p = -lam * (Cq @ qd)
        p_drive = float(p[self._drive_rows].sum())
        return p_drive, float(p.sum()) - p_drive

    def rhs(self, t, y, v_impact=None):
        """Right-hand side of the first-order ODE in ``y`` (``v_impact``: see :meth:`solve`)."""
        self.nfev += 1
        if self.max_nfev is not None and self.nfev > self.max_nfev:
            raise BudgetExceeded(t)
        k = self.kernel()
        if k is not None:
            dy = k.rhs(t, y, v_impact)
            if dy is None:
                raise NonFinite(t)
            return dy
        n = self.n
        q, qd = y[:n], y[n: 2 * n]
        out = self.solve(t, q, qd, v_impact)
        p_drive, p_ideal = self.drive_power(out["lam"], out["Cq"], qd)
        p_damp = sum(c["p_damp"] for c in out["contacts"])
        p_fric = sum(c["p_fric"] for c in out["contacts"])
        p_modal = self.damping_power(qd) if self._elastic else 0.0
        dy = np.concatenate([qd, out["qdd"], [p_drive, out["p_loads"], p_ideal, p_damp, p_fric,
                                              p_modal]])
        if not np.all(np.isfinite(dy)):
            raise NonFinite(t)
        return dy

    # ----------------------------------------------------------------- initial state
    def assemble(self, t, q0, qd0, tol=1e-12, max_iter=30, hold=(), rcond=None):
        """Consistent positions and velocities close to ``q0``, ``qd0`` (least-change Newton);
        the coordinates in ``hold`` (indices) keep their positions and velocities. ``rcond``:
        the velocity step's cut-off of small singular values relative to the largest (NumPy's
        ``lstsq``; default machine precision): a free direction left by the held coordinates
        (a torque-driven crank's rotation with its modes held) must not be "corrected"."""
        q = np.array(q0, float)
        free = np.setdiff1d(np.arange(self.n), np.asarray(hold, int))
        for _ in range(max_iter):
            phi, Cq, nu, _ = self.constraint_terms(t, q, np.zeros(self.n))
            if np.max(np.abs(phi), initial=0.0) < tol:
                break
            q[free] -= np.linalg.lstsq(Cq[:, free], phi, rcond=None)[0]
        else:
            raise NumericalError(
                f"dynamics: the mechanism cannot be assembled at t = {t} s (constraint residual "
                f"{np.max(np.abs(phi)):.1e} after {max_iter} Newton steps); check that the link "
                f"lengths close (a four-bar must satisfy the triangle inequalities at every crank "
                f"angle) and the assembly branch")
        _, Cq, nu, _ = self.constraint_terms(t, q, np.zeros(self.n))
        qd = np.array(qd0, float)
        if self.m:
            qd[free] -= np.linalg.lstsq(Cq[:, free], Cq @ qd - nu, rcond=rcond)[0]
        return q, qd


class BudgetExceeded(Exception):
    """The right-hand side was evaluated more often than allowed."""

    def __init__(self, t):
        super().__init__(t)
        self.t = t


class NonFinite(Exception):
    """The right-hand side produced NaN or inf."""

    def __init__(self, t):
        super().__init__(t)
        self.t = t
