"""Vectorised constraint terms for rigid bodies, pins, sliders and drives.

The generic path asks every joint for its blocks (a Python call and several small arrays per
joint); for all-rigid mechanisms the same numbers come from a few gathers over a table of all
interface frames. :class:`RigidConstraintTable` is built once per system; its ``terms`` returns
exactly what :meth:`Multibody.constraint_terms` returns on the generic path.
"""

from __future__ import annotations

import numpy as np

from .bodies import Ground, RigidBody
from .joints import AngleDrive, Prismatic, Revolute


def applicable(sysm) -> bool:
    """True when every body is rigid and every constraint a pin, slider or angle drive."""
    rigid = all(isinstance(b, RigidBody) for b in sysm.bodies)
    kinds = all(isinstance(c, (Revolute, Prismatic, AngleDrive)) for c in sysm.constraints)
    return rigid and kinds


class RigidConstraintTable:
    """Index tables of the constraints of an all-rigid system."""

    def __init__(self, sysm):
        self.n, self.m = sysm.n, sysm.m
        # frame table: the rigid frames of the cache, then ground frames (fixed, no Jacobian)
        ground = {}
        for c in sysm.constraints:
            for body, frame in frames_of(c):
                if isinstance(body, Ground) and (id(body), frame) not in ground:
                    ground[(id(body), frame)] = body.frame_pose(None, frame)
        k_rigid = len(sysm._fi)
        self.index = dict(sysm._frame_index)
        for i, key in enumerate(ground):
            self.index[key] = k_rigid + i
        self.ground_pose = np.array(list(ground.values()), float).reshape(-1, 3)
        Cq0 = np.zeros((self.m, self.n))
        rev_rows, rev_a, rev_b = [], [], []
        side_rows, side_k, side_col, side_sign = [], [], [], []
        pri_rows, pri_k, pri_n, pri_o, pri_ang, pri_col = [], [], [], [], [], []
        self.drives = []
        for c, r in zip(sysm.constraints, sysm.rows):
            r0 = r.start
            if isinstance(c, Revolute):
                ka = self.index[(id(c.a), c.frame_a)]
                kb = self.index[(id(c.b), c.frame_b)]
                rev_rows.append(r0)
                rev_a.append(ka)
                rev_b.append(kb)
                for body, k, s in ((c.a, ka, 1.0), (c.b, kb, -1.0)):
                    if isinstance(body, Ground):
                        continue
                    col = sysm.slices[id(body)].start
                    Cq0[r0, col] = s
                    Cq0[r0 + 1, col + 1] = s
                    side_rows.append(r0)
                    side_k.append(k)
                    side_col.append(col + 2)
                    side_sign.append(s)
            elif isinstance(c, Prismatic):
                k = self.index[(id(c.a), c.frame_a)]
                col = sysm.slices[id(c.a)].start
                nrm = np.array([-c.axis[1], c.axis[0]])
                Cq0[r0, col], Cq0[r0, col + 1] = nrm
                Cq0[r0 + 1, col + 2] = 1.0
                pri_rows.append(r0)
                pri_k.append(k)
                pri_n.append(nrm)
                pri_o.append(np.asarray(c.origin, float))
                pri_ang.append(c.angle)
                pri_col.append(col + 2)
            else:  # AngleDrive
                k = self.index[(id(c.a), c.frame_a)]
                Cq0[r0, sysm.slices[id(c.a)].start + 2] = 1.0
                self.drives.append((r0, k, c.profile))
        self.Cq0 = Cq0
        self.rev_rows = np.array(rev_rows, int)
        self.rev_a = np.array(rev_a, int)
        self.rev_b = np.array(rev_b, int)
        self.side_rows = np.array(side_rows, int)
        self.side_k = np.array(side_k, int)
        self.side_col = np.array(side_col, int)
        self.side_sign = np.array(side_sign, float)
        self.pri_rows = np.array(pri_rows, int)
        self.pri_k = np.array(pri_k, int)
        self.pri_n = np.array(pri_n, float).reshape(-1, 2)
        self.pri_o = np.array(pri_o, float).reshape(-1, 2)
        self.pri_ang = np.array(pri_ang, float)
        self.pri_col = np.array(pri_col, int)

    def terms(self, t, pose, arm, bias):
        """``Phi, Phi_q, nu, gamma`` from the frame table.

        ``pose``, ``bias``: (K, 3) rigid frames; ``arm``: (K, 2) the rotated frame offsets
        ``A s`` (whose perpendicular is the theta column of the frame Jacobian).
        """
        P = np.vstack([pose, self.ground_pose]) if self.ground_pose.size else pose
        Bi = np.vstack([bias, np.zeros_like(self.ground_pose)]) if self.ground_pose.size else bias
        phi = np.empty(self.m)
        nu = np.zeros(self.m)
        gamma = np.zeros(self.m)
        Cq = self.Cq0.copy()
        r, a, b = self.rev_rows, self.rev_a, self.rev_b
        phi[r] = P[a, 0] - P[b, 0]
        phi[r + 1] = P[a, 1] - P[b, 1]
        gamma[r] = -(Bi[a, 0] - Bi[b, 0])
        gamma[r + 1] = -(Bi[a, 1] - Bi[b, 1])
        k, s = self.side_k, self.side_sign
        Cq[self.side_rows, self.side_col] = -s * arm[k, 1]
        Cq[self.side_rows + 1, self.side_col] = s * arm[k, 0]
        if self.pri_rows.size:
            r, k, nrm = self.pri_rows, self.pri_k, self.pri_n
            phi[r] = np.sum(nrm * (P[k, :2] - self.pri_o), axis=1)
            phi[r + 1] = P[k, 2] - self.pri_ang
            Cq[r, self.pri_col] = -nrm[:, 0] * arm[k, 1] + nrm[:, 1] * arm[k, 0]
            gamma[r] = -np.sum(nrm * Bi[k, :2], axis=1)
        for r0, k, prof in self.drives:
            phi[r0] = P[k, 2] - prof.angle(t)
            nu[r0] = prof.speed(t)
            gamma[r0] = prof.acceleration(t)
        return phi, Cq, nu, gamma


def frames_of(c):
    """The (body, frame) pairs a pin, slider or drive constrains."""
    if isinstance(c, Revolute):
        return [(c.a, c.frame_a), (c.b, c.frame_b)]
    return [(c.a, c.frame_a)]
