"""A planar floating-frame flexible body built from a ``crankmodal-flexbody`` .npz.

Coordinates ``q = (x, y, θ, ξ_1 … ξ_k)``: the position (m) and angle (rad) of the body frame and
the amplitudes of k elastic orthonormal modes (unit 3D modal mass, so ``ξ`` is in m·kg^½).

Reference conditions: mean axes (Tisserand) at the centre of mass. The body frame's origin is
the undeformed part's centre of mass, its axes are the part's x–y axes (the plane of motion:
"the rod lies in the x-y plane with the big-end bore on the z axis"). The orthonormal elastic
modes of the .npz are mass-orthogonal to its six rigid ones, so ``I3 = ∫ρΦ = 0`` and
``I4 = ∫ρ x̃Φ = 0``: the elastic deformation moves neither the centre of mass nor the mean
orientation, the frame follows the mean motion of the body and the translation–elastic and the
linear rotation–elastic inertia couplings vanish exactly. This is seed 000's choice; it needs no
extra constraint and keeps the rigid part of ``M`` constant.

Plane restriction: a material point moves as ``r = R + A(θ)(u₀ + Φ_xy ξ)``, with ``Φ_xy`` the
x and y rows of the mode shapes; the z displacement of the modes and their rotations about x
and y are dropped. From the invariants (``[2, …]`` is the z component)::

    G  = I9[2, 2]            ∫ρ Φ_xyᵀ Φ_xy           in-plane modal mass (k, k)
    b  = I8[2, 2]            ∫ρ u₀·φ_a (in-plane)     (k,)
    S  = I5[2]               S[a, b] = ∫ρ (φ_a × φ_b)_z, antisymmetric (k, k)
    J₀ = inertia[2, 2]       polar moment about the centre of mass, kg m²

    M(ξ) = [[m I₂, 0,                 0          ],
            [0,    J₀ + 2bᵀξ + ξᵀGξ,  (c + Sᵀξ)ᵀ ],
            [0,    c + Sᵀξ,           G          ]]

(``c = I4[2]``, zero for mean axes, kept as stored.)

Point rotary inertias attached to interfaces (:meth:`FlexibleBody.attach_inertia`; the loom's
sley on the rocker's shaft): a rotor of polar moment ``J_s`` (kg m², its mass on the interface
node, or on a fixed pivot) turns with the interface, whose angle is ``φ = θ + r_zᵀξ``, so its
kinetic energy is ``T_s = ½ J_s (θ̇ + r_zᵀξ̇)² = ½ q̇ᵀ H q̇`` with the constant matrix ::

    H[θ, θ] = J_s,   H[θ, ξ] = H[ξ, θ]ᵀ = J_s r_zᵀ,   H[ξ, ξ] = J_s r_z r_zᵀ

added to ``M(ξ)``. ``r_z`` is constant and ``T_s`` does not depend on ``q``, so ``∂T_s/∂q = 0``
and ``Ṁ_s = 0``: the rotor adds no centrifugal or Coriolis force (its mass at the interface node
would: the node's velocity depends on ``θ`` and ``ξ``; it is left out, as it is at a pin on the
ground). Frozen (0 modes), ``H`` is ``J_s`` on ``θ``: a rigid body's inertia plus ``J_s``.

Only modes whose in-plane mass share ``G_aa`` is at least ``min_in_plane`` are offered (an
out-of-plane bending or a torsion mode would keep its 3D stiffness with almost no planar mass);
:meth:`FlexibleBody.left_out` reports, per kept mode, the modal mass and interface motion the
plane drops, and which stored modes were not offered.

Internal forces: ``K ξ + C ξ̇`` with ``K = diag(ω²)`` and ``C = diag(2 ζ_a ω_a)`` (ζ a ratio per
mode, default :data:`DEFAULT_DAMPING`, of the unit 3D modal mass); strain energy ``½ ξᵀKξ``.
Interfaces are the .npz's interface nodes, named as their regions; a frame's pose is that of the
interface node: position ``R + A(s₀ + D ξ)``, angle ``θ + r_zᵀ ξ`` (``D`` the x, y translation
rows and ``r_z`` the z rotation row of ``interface_map``; the out-of-plane rows are dropped).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import ParameterError

DEFAULT_DAMPING = 0.02
"""Modal damping ratio of every kept mode when none is given (2 %, a common value for steel
parts bolted into an assembly; not measured here)."""

MIN_IN_PLANE = 0.5
_OMEGA = np.array([[0.0, -1.0], [1.0, 0.0]])


class FlexibleBody:
    """A planar floating-frame body with modal coordinates (SI units).

    Parameters
    ----------
    name : str
    mass : float
        kg.
    j0 : float
        Polar moment of inertia about the centre of mass, kg m².
    centre : (2,) array
        Centre of mass in part coordinates, m.
    frequencies_hz : (k,) array
        Of the kept elastic modes.
    G, b, S : arrays (k, k), (k,), (k, k)
        In-plane invariants (see the module docstring).
    interfaces : dict str -> (centre (3,), map (6, k))
        Interface node position (part coordinates, m) and its rows of ``interface_map``.
    damping_ratio : float or (k,) array
    z : float
        Axial position of the body's plane, m (3D moments only, as :class:`RigidBody`).
    info : dict
        Provenance and what the plane leaves out (:meth:`left_out`).

    Attributes
    ----------
    n_coordinates : int
        Modal coordinates of the body, ``k``: its kept elastic modes (``n_elastic``, what
        ``[dynamics.flexible] n_modes`` counts) plus ``n_tilt`` tilt coordinates (0 or 2).
        ``n_modes`` is its deprecated former name.
    n_elastic, n_tilt : int
        Kept elastic modes; tilt coordinates.
    ndof : int
        ``3 + n_coordinates``.
    """

    @property
    def n_modes(self) -> int:
        """Deprecated name of :attr:`n_coordinates` (elastic modes and tilts)."""
        import warnings

        warnings.warn("FlexibleBody.n_modes is deprecated: use n_coordinates (elastic modes "
                      "plus tilts; n_elastic counts the kept elastic modes)", DeprecationWarning,
                      stacklevel=2)
        return self.n_coordinates

    def __init__(self, name, mass, j0, centre, frequencies_hz, G, b, S, interfaces,
                 damping_ratio=DEFAULT_DAMPING, z=0.0, info=None, c=None, n_tilt=0,
                 orientation=0.0, source=None, Gz=None):
        self.name = name
        self.mass = float(mass)
        self.j0 = float(j0)
        self.centre = np.asarray(centre, float)[:2]
        self.frequencies_hz = np.asarray(frequencies_hz, float)
        k = len(self.frequencies_hz)
        self.n_coordinates = k
        self.n_tilt = int(n_tilt)
        self.n_elastic = k - self.n_tilt
        self.ndof = 3 + k
        w = 2 * np.pi * self.frequencies_hz
        self.zeta = np.broadcast_to(np.asarray(damping_ratio, float), (k,)).copy()
        self.K = w ** 2
        self.C = 2.0 * self.zeta * w
        self.G = np.asarray(G, float).reshape(k, k)
        self.b = np.asarray(b, float).reshape(k)
        self.S = np.asarray(S, float).reshape(k, k)
        self.c = np.zeros(k) if c is None else np.asarray(c, float).reshape(k)
        #: axial (z) modal mass of the modes and tilts, constant (:func:`axial_mass`; zero
        #: unless the body was made with ``axial_inertia``), added with the attached inertias
        self.Gz = np.zeros((k, k)) if Gz is None else np.asarray(Gz, float).reshape(k, k)
        self.orientation = float(orientation)
        co, so = np.cos(-self.orientation), np.sin(-self.orientation)
        R = np.array([[co, -so], [so, co]])  # part x-y axes -> body axes
        self.frames = {}
        for nm, (cen, mp) in interfaces.items():
            mp = np.asarray(mp, float).reshape(6, k)
            # s0: the interface node relative to the centre of mass; D: its in-plane translation
            # per ξ; rz: its rotation about z per ξ (all in body axes)
            self.frames[nm] = (R @ (np.asarray(cen, float)[:2] - self.centre), R @ mp[:2],
                               mp[5].copy())
        self.z = float(z)
        self.info = dict(info or {})
        self.source = source  # the reduced body it was made from (stress modes, mesh), or None
        #: point rotary inertias attached to interfaces: ((frame, J_s in kg m²), …), a tuple so
        #: that a copy (:meth:`frozen`, a mechanism's twin) never shares later attachments
        self.attached = ()

    def attach_inertia(self, frame: str, inertia: float) -> None:
        """Attach a point rotary inertia ``inertia`` (kg m², ≥ 0) to interface ``frame``: it turns
        with the interface (angle ``θ + r_zᵀξ``), adding ``½ J_s (θ̇ + r_zᵀξ̇)²`` to the kinetic
        energy (the module docstring). Several attachments add up.

        Raises
        ------
        ValueError
            No such frame, or ``inertia`` negative or not finite.
        """
        if frame not in self.frames:
            raise ValueError(f"{self.name}: no frame {frame!r} to attach an inertia to; frames: "
                             f"{', '.join(self.frames) or 'none'}")
        J = float(inertia)
        if not (np.isfinite(J) and J >= 0.0):
            raise ValueError(f"{self.name}: attached inertia = {inertia!r}: must be >= 0 kg m^2")
        self.attached = self.attached + ((frame, J),)

    @property
    def attached_inertia(self) -> float:
        """Sum of the attached rotary inertias, kg m² (what a frozen twin adds to ``J₀``)."""
        return float(sum(J for _, J in self.attached))

    def attached_terms(self) -> tuple[float, np.ndarray, np.ndarray]:
        """The attached inertias' constant mass terms: ``Σ J_s`` (θ, θ), ``Σ J_s r_z`` (θ, ξ;
        shape (k,)) and ``Σ J_s r_z r_zᵀ`` (ξ, ξ; shape (k, k)), kg m², kg m² per ξ, …; the
        (ξ, ξ) block also holds the constant axial modal mass ``Gz`` (:func:`axial_mass`)."""
        k = self.n_coordinates
        h, H = np.zeros(k), self.Gz.copy()  # the axial modal mass: constant as well
        for frame, J in self.attached:
            rz = self.frames[frame][2]
            h += J * rz
            H += J * np.outer(rz, rz)
        return self.attached_inertia, h, H

    def alias(self, name: str, frame: str) -> None:
        """Name interface ``frame`` also ``name`` (a mechanism's frame names: ``main``, ``pin``…)."""
        self.frames[name] = self.frames[frame]

    def frozen(self) -> FlexibleBody:
        """The same body with its elastic modes frozen: only the tilts (if any) stay as
        coordinates (a rigid crank on its journals, each journal's force still defined)."""
        import copy

        keep = np.arange(self.n_elastic, self.n_coordinates)
        twin = copy.copy(self)
        for cache in ("_stacked", "_geo", "_bias"):
            twin.__dict__.pop(cache, None)
        twin.frequencies_hz = self.frequencies_hz[keep]
        twin.n_coordinates, twin.n_elastic, twin.ndof = len(keep), 0, 3 + len(keep)
        for a in ("zeta", "K", "C", "b", "c"):
            setattr(twin, a, getattr(self, a)[keep])
        twin.G, twin.S = self.G[np.ix_(keep, keep)], self.S[np.ix_(keep, keep)]
        twin.Gz = self.Gz[np.ix_(keep, keep)]
        twin.frames = {n: (s0, D[:, keep], rz[keep]) for n, (s0, D, rz) in self.frames.items()}
        twin.info = dict(self.info, rigid_twin=True)
        return twin

    def local(self, frame: str) -> tuple[np.ndarray, float]:
        """Undeformed position of an interface in the body frame (m) and its angle offset (0)."""
        return np.array(self.frames[frame][0], float), 0.0

    # ----------------------------------------------------------------- inertia
    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """``M(ξ)``, shape (3 + k, 3 + k), kg, kg m, kg m²."""
        xi = q[3:]
        M = np.zeros((self.ndof, self.ndof))
        M[0, 0] = M[1, 1] = self.mass
        M[2, 2] = self.j0 + 2.0 * self.b @ xi + xi @ self.G @ xi
        h = self.c + self.S.T @ xi
        M[2, 3:] = h
        M[3:, 2] = h
        M[3:, 3:] = self.G
        if self.attached or self.Gz.any():
            Js, h, H = self.attached_terms()
            M[2, 2] += Js
            M[2, 3:] += h
            M[3:, 2] += h
            M[3:, 3:] += H
        return M

    def velocity_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Quadratic velocity forces ``∂T/∂q − Ṁ q̇`` (centrifugal and Coriolis), N, N m
        (attached rotary inertias add none: their mass terms are constant)."""
        xi, w, xid = q[3:], qd[2], qd[3:]
        c = self.b + self.G @ xi
        out = np.zeros(self.ndof)
        out[2] = -2.0 * w * (c @ xid)
        out[3:] = w * w * c + 2.0 * w * (self.S @ xid)
        return out

    def internal_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Elastic and modal damping forces ``[0, 0, 0, Kξ + Cξ̇]`` (moved to the left side)."""
        out = np.zeros(self.ndof)
        out[3:] = self.K * q[3:] + self.C * qd[3:]
        return out

    def damping_power(self, qd: np.ndarray) -> float:
        """Power dissipated by modal damping, W (≥ 0)."""
        return float(self.C @ (qd[3:] ** 2))

    def gravity_force(self, q: np.ndarray, g: np.ndarray) -> np.ndarray:
        """Generalised weight: the centre of mass is the frame origin (``I3 = 0``)."""
        out = np.zeros(self.ndof)
        out[0], out[1] = self.mass * g[0], self.mass * g[1]
        return out

    def potential_energy(self, q: np.ndarray, g: np.ndarray) -> float:
        """Gravitational potential energy, J (zero at the origin)."""
        return -self.mass * float(g[0] * q[0] + g[1] * q[1])

    def strain_energy(self, q: np.ndarray) -> float:
        """``½ ξᵀKξ``, J."""
        return 0.5 * float(self.K @ (q[3:] ** 2))

    def kinetic_energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """``½ q̇ᵀ M(ξ) q̇`` (attached inertias included), J."""
        return 0.5 * float(qd @ self.mass_matrix(q) @ qd)

    # ----------------------------------------------------------------- interface frames
    def _stack(self):
        """The frames' ``s0``, ``D`` and ``r_z`` stacked (rebuilt when a frame is added)."""
        names = tuple(self.frames)
        if getattr(self, "_stacked", (None,))[0] != names:
            idx = {n: i for i, n in enumerate(names)}
            F, k = len(names), self.n_coordinates
            S0 = np.array([self.frames[n][0] for n in names], float).reshape(F, 2)
            D = np.array([self.frames[n][1] for n in names], float).reshape(F, 2, k)
            RZ = np.array([self.frames[n][2] for n in names], float).reshape(F, k)
            self._stacked = (names, idx, S0, D, RZ)
            self._geo = self._bias = (None, None)
        return self._stacked

    def _geometry(self, q):
        """Poses (F, 3), Jacobians (F, 3, ndof) and ``A s`` and ``A D`` of every frame at ``q``,
        computed once per configuration (every joint asks for its frames at the same ``q``)."""
        _, idx, S0, D, RZ = self._stack()
        key = q.tobytes()
        if self._geo[0] == key:
            return self._geo[1]
        xi = q[3:]
        c, sn = np.cos(q[2]), np.sin(q[2])
        A = np.array([[c, -sn], [sn, c]])
        As = (S0 + D @ xi) @ A.T
        AD = np.einsum("ij,fjk->fik", A, D)
        F = len(S0)
        pose = np.empty((F, 3))
        pose[:, :2] = q[:2] + As
        pose[:, 2] = q[2] + RZ @ xi
        J = np.zeros((F, 3, self.ndof))
        J[:, 0, 0] = J[:, 1, 1] = J[:, 2, 2] = 1.0
        J[:, 0, 2], J[:, 1, 2] = -As[:, 1], As[:, 0]
        J[:, :2, 3:] = AD
        J[:, 2, 3:] = RZ
        out = (idx, pose, J, As, AD)
        self._geo = (key, out)
        return out

    def frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Pose ``(x, y, phi)`` of an interface node in the global plane, m and rad."""
        idx, pose, *_ = self._geometry(q)
        return pose[idx[frame]].copy()

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """d(pose)/dq, shape (3, 3 + k)."""
        idx, _, J, *_ = self._geometry(q)
        return J[idx[frame]].copy()

    def frame_bias(self, q: np.ndarray, qd: np.ndarray, frame: str) -> np.ndarray:
        """``Jdot qdot``: centripetal ``−θ̇² A s`` and Coriolis ``2 θ̇ Ω A D ξ̇``, m/s²."""
        idx, _, _, As, AD = self._geometry(q)
        key = q.tobytes() + qd.tobytes()
        if self._bias[0] != key:
            w = qd[2]
            v = AD @ qd[3:]  # (F, 2)
            a = np.zeros((len(As), 3))
            a[:, 0] = -w * w * As[:, 0] - 2.0 * w * v[:, 1]
            a[:, 1] = -w * w * As[:, 1] + 2.0 * w * v[:, 0]
            self._bias = (key, a)
        return self._bias[1][idx[frame]].copy()

    def left_out(self) -> dict:
        """What the plane drops: per kept mode the out-of-plane share of its modal mass
        (``1 − G_aa``) and of its interface translations and rotations (squared norms), and
        the stored elastic modes not offered (frequency, in-plane share)."""
        return self.info.get("left_out", {})


def _fail(argument, path, text):
    raise ParameterError(argument, f"{path}: {text}")


def load_flexible_body(path, name: str, **kwargs) -> FlexibleBody:
    """Read a ``crankmodal-flexbody`` .npz as a planar :class:`FlexibleBody`
    (:func:`planar_body`'s keywords).

    Parameters
    ----------
    path : str or Path
        The ``.npz`` the ``[reduction]`` stage or :func:`crankmodal.save_flexbody` wrote.
    name : str
        The body's name in the mechanism.
    **kwargs
        :func:`planar_body`'s keywords: ``n_modes`` or ``cutoff_hz`` (Hz), ``damping_ratio``,
        ``interfaces``, ``z`` (m), ``tilt``, ``orientation`` (rad).

    Returns
    -------
    FlexibleBody
        The in-plane floating-frame body (mean axes at the centre of mass), frames named after
        the file's interfaces.

    Raises
    ------
    InputFileError
        Not a readable crankmodal-flexbody file of version 1.
    ParameterError
        As :func:`planar_body`.
    """
    from ...reduction.io import load_flexbody

    return planar_body(load_flexbody(path), name, path=path, **kwargs)


def planar_body(fb, name: str, n_modes: int | None = None,
                       cutoff_hz: float | None = None,
                       damping_ratio=DEFAULT_DAMPING, interfaces=None,
                       min_in_plane: float = MIN_IN_PLANE, z: float = 0.0, tilt: bool = False,
                       orientation: float = 0.0, path=None,
                       axial_inertia: bool = False) -> FlexibleBody:
    """A planar :class:`FlexibleBody` from a reduced body (:func:`crankmodal.reduction.io.load_flexbody`).

    Several planar bodies (four rods) can be made from one reading of the file.

    Parameters
    ----------
    fb : crankmodal.reduction.flexbody.FlexibleBody
    name : str
        Body name.
    n_modes : int, optional
        In-plane elastic modes to keep, lowest first (0: frozen, a rigid body).
    cutoff_hz : float, optional
        Keep the in-plane elastic modes up to this frequency, Hz. Neither given: all of them.
    damping_ratio : float or sequence
        Modal damping ratio per kept mode (≥ 0).
    interfaces : sequence of str, optional
        Interface names the caller needs (each must be in the file).
    min_in_plane : float
        Smallest in-plane share of a mode's modal mass for it to be offered.
    z : float
        Axial position of the body's plane, m.
    tilt : bool
        Append the two small rigid tilts about the part's x and y axes through the centre of
        mass as coordinates without stiffness (see :func:`tilt_terms`): a shaft held in the
        plane at two or more journals at different z needs them, or the journals would also
        hold its mean axis straight.
    orientation : float
        Angle of the body frame's x axis from the part's x axis, rad (e.g. the crank's pin
        direction, so that the frame angle is the crank angle).
    path : str or Path, optional
        The file it was read from (error messages and provenance).
    axial_inertia : bool
        Also count the kinetic energy of the modes' and tilts' axial (z) motion
        (:func:`axial_mass`): exact for a body turning about z, it gives the linearised planar
        body the 3D body's frequencies (a crank's flywheel rocking, torsion with web axial
        motion). Default False (the plane restriction of the module docstring).

    Raises
    ------
    ParameterError
        Naming the argument (``n_modes``, ``cutoff_hz``, ``damping_ratio``, ``interfaces``),
        the file in its text: more modes than stored, both or a bad selection, negative
        damping, a missing interface.
    """
    path = Path(path) if path is not None else Path(fb.name)
    el = ~np.asarray(fb.rigid, bool)
    f_el = fb.frequencies_hz[el]
    inv = fb.invariants
    G_all = np.asarray(inv["I9"])[2, 2]
    share = np.diag(G_all)
    offered = np.flatnonzero(share >= min_in_plane)
    if n_modes is not None and cutoff_hz is not None:
        _fail("cutoff_hz", path, "give either n_modes or cutoff_hz, not both")
    if n_modes is not None:
        if int(n_modes) != n_modes or n_modes < 0:
            _fail("n_modes", path, f"must be an integer >= 0, got {n_modes!r}")
        if n_modes > len(offered):
            _fail("n_modes", path, f"{n_modes} asked, but the file stores {len(offered)} "
                  f"in-plane elastic modes (of {int(el.sum())} elastic, in-plane share >= "
                  f"{min_in_plane})")
        keep = offered[:int(n_modes)]
    elif cutoff_hz is not None:
        if not cutoff_hz > 0:
            _fail("cutoff_hz", path, f"must be > 0 Hz, got {cutoff_hz!r}")
        keep = offered[f_el[offered] <= cutoff_hz]
    else:
        keep = offered
    k = len(keep)
    zeta = np.asarray(damping_ratio, float)
    k = len(keep)
    if zeta.ndim > 1 or (zeta.ndim == 1 and len(zeta) != k):
        _fail("damping_ratio", path, f"give one ratio or {k} (one per kept mode), got "
              f"{zeta.size}")
    if not np.all(np.isfinite(zeta)) or np.any(zeta < 0):
        _fail("damping_ratio", path, f"must be >= 0, got {damping_ratio!r}")
    names = list(fb.interface_names)
    for itf in interfaces or ():
        if itf not in names:
            _fail("interfaces", path, f"no interface {itf!r}; interfaces: "
                  f"{', '.join(names) or 'none'}")
    cols = np.flatnonzero(el)[keep]  # columns of the elastic modes among all n
    imap = np.asarray(fb.interface_map)[:, :, cols]
    G = G_all[np.ix_(keep, keep)]
    b = np.asarray(inv["I8"])[2, 2][keep]
    S = np.asarray(inv["I5"])[2][np.ix_(keep, keep)]
    tr = np.sum(imap[:, :3] ** 2, axis=(0, 1))
    rot = np.sum(imap[:, 3:] ** 2, axis=(0, 1))
    tiny = 1e-300
    left = {
        "kept_hz": f_el[keep].tolist(),
        "out_of_plane_mass_share": (1.0 - np.diag(G)).tolist(),
        "out_of_plane_interface_translation_share":
            (np.sum(imap[:, 2] ** 2, axis=0) / np.maximum(tr, tiny)).tolist(),
        "out_of_plane_interface_rotation_share":
            (np.sum(imap[:, 3:5] ** 2, axis=(0, 1)) / np.maximum(rot, tiny)).tolist(),
        "not_offered": [{"hz": float(f_el[i]), "in_plane_share": float(share[i])}
                        for i in range(len(f_el)) if share[i] < min_in_plane],
        "offered_hz": f_el[offered].tolist(),
        "translation_coupling_I3": float(np.abs(np.asarray(inv["I3"])).max(initial=0.0)),
        "rotation_coupling_I4z": float(np.abs(np.asarray(inv["I4"])[2]).max(initial=0.0)),
    }
    c = np.asarray(inv["I4"])[2][keep]  # ∫ρ (u0 × φ_a)_z: 0 for mean axes, kept as stored
    freq = f_el[keep]
    centres = np.asarray(fb.interface_centres, float)
    zeta = np.broadcast_to(zeta, (k,)) if zeta.ndim else np.full(k, float(zeta))
    n_tilt = 0
    Gz = axial_mass(inv, keep, np.asarray(fb.inertia, float), tilt) if axial_inertia else None
    if tilt:
        I8 = np.asarray(inv["I8"])[:, :, keep]
        G, b, S, c, imap = tilt_terms(G, b, S, c, imap, I8, np.asarray(fb.inertia, float),
                                      np.asarray(fb.centre_of_mass, float), centres)
        freq = np.concatenate([freq, [0.0, 0.0]])
        zeta = np.concatenate([zeta, [0.0, 0.0]])
        n_tilt = 2
    return FlexibleBody(
        name=name, mass=fb.mass_kg, j0=float(np.asarray(fb.inertia)[2, 2]),
        centre=fb.centre_of_mass, frequencies_hz=freq, G=G, b=b, S=S, c=c,
        interfaces={n: (centres[i], imap[i]) for i, n in enumerate(names)},
        damping_ratio=zeta, z=z, n_tilt=n_tilt, orientation=orientation,
        source=fb, Gz=Gz,
        info={"file": str(path), "part": fb.name, "left_out": left,
              "mode_columns": cols.tolist(),
              "interface_centres": {n: centres[i].tolist() for i, n in enumerate(names)}})


def axial_mass(inv, keep, inertia, tilt: bool) -> np.ndarray:
    """The axial (z) modal mass of the kept modes (and of the two tilts, with ``tilt``).

    A body turning about z moves a point axially by ``w = Φ_z ξ (+ α_x ȳ − α_y x̄)``, in body
    axes; rotation about z leaves the axial velocity ``ẇ`` unchanged, so its kinetic energy is
    ``½ q̇ᵀ Gz q̇`` with a constant ``Gz`` and no centrifugal or Coriolis term (as an attached
    inertia's). From the invariants of :mod:`crankmodal.reduction.flexbody` and the inertia
    tensor ``I`` about the centre of mass (``∫ρ x_j φ_a,i = δ_ij ∫ρ x·φ_a − I8[i, j, a]``)::

        Gz[a, b] = I6[a, b] − I9[2, 2, a, b]        (∫ρ φ_a,z φ_b,z)
        Gz[tx, tx] = ∫ρ ȳ² = (I_xx + I_zz − I_yy) / 2,  Gz[ty, ty] = (I_yy + I_zz − I_xx) / 2,
        Gz[tx, ty] = −∫ρ x̄ȳ = I_xy,  Gz[tx, a] = −I8[2, 1, a],  Gz[ty, a] = I8[2, 0, a]

    Returns an array (k, k), or (k + 2, k + 2) with the tilts last (x, y) as :func:`tilt_terms`.
    """
    I6 = np.asarray(inv["I6"])[np.ix_(keep, keep)]
    Gz = I6 - np.asarray(inv["I9"])[2, 2][np.ix_(keep, keep)]
    if not tilt:
        return Gz
    k = len(keep)
    I8 = np.asarray(inv["I8"])[:, :, keep]
    out = np.zeros((k + 2, k + 2))
    out[:k, :k] = Gz
    out[k, k] = 0.5 * (inertia[0, 0] + inertia[2, 2] - inertia[1, 1])
    out[k + 1, k + 1] = 0.5 * (inertia[1, 1] + inertia[2, 2] - inertia[0, 0])
    out[k, k + 1] = out[k + 1, k] = inertia[0, 1]
    out[k, :k] = out[:k, k] = -I8[2, 1]
    out[k + 1, :k] = out[:k, k + 1] = I8[2, 0]
    return out


def tilt_terms(G, b, S, c, imap, I8, inertia, com, centres):
    """Planar invariants and interface rows extended by the two rigid tilts.

    A tilt by a small angle α about the part's x axis through the centre of mass moves a point
    in the plane by ``(0, −α z̄)``, one about y by ``(α z̄, 0)`` (``z̄ = z − z_c``; their z
    displacements are out of the plane and dropped like the modes'). They are rigid motions:
    no stiffness, no damping. Their planar invariants follow from the inertia tensor ``I``
    about the centre of mass and ``I8`` of the elastic modes (:mod:`crankmodal.reduction.flexbody`;
    ``∫ρ z φ_a,i = −I8[i, 2, a]``, the mean-axis condition ``∫ρ φ = 0`` making the origin
    irrelevant)::

        G[tx, tx] = G[ty, ty] = Z = ∫ρ z̄² = (I_xx + I_yy − I_zz) / 2,   G[tx, a] = I8[1, 2, a],
        G[ty, a] = −I8[0, 2, a];   b = (I_yz, −I_xz) (tensor entries);   c = (I_xz, I_yz);
        S[tx, ty] = Z,  S[tx, a] = −I8[0, 2, a],  S[ty, a] = −I8[1, 2, a]  (S antisymmetric).

    Returns ``G, b, S, c, imap`` with the two tilt columns appended (in that order: x, y).
    """
    k = len(b)
    Z = 0.5 * (inertia[0, 0] + inertia[1, 1] - inertia[2, 2])
    gx, gy = I8[1, 2], -I8[0, 2]
    G2 = np.zeros((k + 2, k + 2))
    G2[:k, :k] = G
    G2[k, :k] = G2[:k, k] = gx
    G2[k + 1, :k] = G2[:k, k + 1] = gy
    G2[k, k] = G2[k + 1, k + 1] = Z
    S2 = np.zeros((k + 2, k + 2))
    S2[:k, :k] = S
    S2[k, :k], S2[k + 1, :k] = -I8[0, 2], -I8[1, 2]
    S2[:k, k], S2[:k, k + 1] = I8[0, 2], I8[1, 2]
    S2[k, k + 1], S2[k + 1, k] = Z, -Z
    b2 = np.concatenate([b, [inertia[1, 2], -inertia[0, 2]]])
    c2 = np.concatenate([c, [inertia[0, 2], inertia[1, 2]]])
    m = len(centres)
    im2 = np.zeros((m, 6, k + 2))
    im2[:, :, :k] = imap
    zb = centres[:, 2] - com[2]
    im2[:, 1, k] = -zb            # tilt about x: y translation −z̄, rotation about x 1
    im2[:, 3, k] = 1.0
    im2[:, 0, k + 1] = zb         # tilt about y: x translation z̄, rotation about y 1
    im2[:, 4, k + 1] = 1.0
    return G2, b2, S2, c2, im2


__all__ = ["DEFAULT_DAMPING", "FlexibleBody", "axial_mass", "load_flexible_body", "planar_body",
           "tilt_terms"]
