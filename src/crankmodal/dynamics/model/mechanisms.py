"""Mechanisms from parameters: slider-crank trains (single, offset, four-star) and the four-bar.

A builder returns a :class:`Mechanism`: the multibody system with the requested clearance
joints, its ideal-joint twin (same bodies, every clearance joint replaced by a pin) and a
consistent initial state in which every journal sits at its bearing centre.

Angles: the crank angle ``theta`` is measured from the global x axis; cylinder ``i`` has its axis
at ``psi_i`` (unit vector from the crank towards the head) and is at top dead centre when
``theta = psi_i`` (zero offset).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError
from .bodies import Ground, RigidBody
from .clearance import ClearanceSpec
from .joints import AngleDrive, Prismatic, Revolute, SpeedProfile
from .layout import body_reference_angle, single_pin_layout, throw_layout
from .loads import CrankTorque, PistonLoads, TorsionalCoupling
from .system import Multibody


@dataclass
class Cylinder:
    """One cylinder of a crank train (SI units, angles in rad).

    The multibody form of a machine's cylinder (:class:`crankmodal.mechanism.machine.Cylinder`,
    from which :meth:`from_machine` builds it): the axis at ``axis_angle`` from +x
    counter-clockwise, with the rod it drives and its gas force as a function. Not a geometric
    surface (:class:`crankmodal.part.CylindricalSurface`).

    ``rod_com`` is the distance of the rod's centre of mass from the big-end centre; ``offset``
    the piston-pin offset across the cylinder axis (positive towards +90 deg from the axis);
    ``z`` the axial position of the cylinder's plane (its rod row) along the crank axis, m (for
    3D moments and, with ``journals_z``, the split between a rigid crank's two journals). Its
    throw is not a field: a multi-throw train's throws are its ``arrangement``'s
    (:func:`crank_train`).

    Attributes
    ----------
    axis_angle : float
        The cylinder axis from +x, counter-clockwise, rad.
    rod_length : float
        Big-end to small-end centre, m.
    rod_mass, piston_mass : float
        kg (the piston with its pin and rings).
    rod_inertia : float
        The rod's polar moment of inertia about its centre of mass, kg m².
    rod_com : float
        m, from the big-end centre.
    offset, z : float
        m.
    gas_force : callable or None
        ``gas_force(angle)``: the gas force on the piston (N) against the crank angle from this
        cylinder's top dead centre (rad).
    ring_friction : float
        Piston-ring friction force, N (>= 0).
    """

    axis_angle: float
    rod_length: float
    rod_mass: float
    rod_inertia: float
    rod_com: float
    piston_mass: float
    offset: float = 0.0
    z: float = 0.0
    gas_force: object = None
    ring_friction: float = 0.0

    def __post_init__(self):
        """Check every field by the ``[dynamics.crank_train]`` keys' rules (ParameterError
        naming the field): lengths and masses > 0, ``rod_com >= 0``; ``rod_inertia >= 0``
        (0 only with a rod body given to :func:`crank_train`, which brings its own inertia);
        angles and offsets finite; ``gas_force`` None or callable; ``ring_friction >= 0``."""
        from ... import arguments as arg
        from ..scene.keys import CRANK_TRAIN, SCHEMA

        self.axis_angle = arg.number("axis_angle", self.axis_angle)
        for name in ("rod_length", "rod_mass", "rod_com", "piston_mass", "offset"):
            setattr(self, name, arg.check(name, getattr(self, name), CRANK_TRAIN[name]))
        self.rod_inertia = arg.number("rod_inertia", self.rod_inertia, ge=0.0)
        self.z = arg.number("z", self.z)
        self.ring_friction = arg.check("ring_friction", self.ring_friction,
                                       SCHEMA["ring_friction_n"])
        if self.gas_force is not None and not callable(self.gas_force):
            raise ParameterError("gas_force", "must be None or a function of the crank angle "
                                 f"from top dead centre (rad) giving N, got {self.gas_force!r:.60}")

    @classmethod
    def from_machine(cls, machine, cylinder, gas_force=None,
                     ring_friction: float = 0.0) -> Cylinder:
        """The crank-train cylinder of one cylinder line of a machine.

        :mod:`crankmodal.mechanism` measures a bank angle ``phi`` from +y towards +x; the
        dynamics plane measures axes from +x counter-clockwise, so the axis angle is
        ``pi/2 - phi`` (and the crank turns with ``direction = -1``). The rod is the machine's,
        the row position its axial offset.

        Parameters
        ----------
        machine : crankmodal.mechanism.machine.Machine
            Gives the rod (length m, mass kg, inertia kg m², centre of mass from the big end m).
        cylinder : crankmodal.mechanism.machine.Cylinder
            One of ``machine.cylinders``. Its throw angle is not kept here: the throws are
            the arrangement's (:func:`crank_train`'s ``arrangement``,
            :func:`~crankmodal.mechanism.arrangement.arrangement_of_machine`).
        gas_force : callable, optional
            Gas force on the piston against crank angle (see :mod:`crankmodal.dynamics.model.loads`).
        ring_friction : float
            Coulomb ring friction force, N.

        Raises
        ------
        ParameterError
            ``machine`` or ``cylinder`` of the wrong kind.
        """
        for name, value, attrs in (("machine", machine, ("rod",)),
                                   ("cylinder", cylinder, ("throw_angle", "bank_angle",
                                                           "piston_mass", "axial_offset"))):
            if not all(hasattr(value, a) for a in attrs):
                raise ParameterError(name, f"must be a crankmodal.mechanism.machine "
                                     f"{'Machine' if name == 'machine' else 'Cylinder'} "
                                     f"(with {', '.join(attrs)}), got {value!r:.60}")
        rod = machine.rod
        return cls(axis_angle=np.pi / 2 - cylinder.bank_angle, rod_length=rod.length,
                   rod_mass=rod.mass, rod_inertia=rod.inertia, rod_com=rod.cg_from_big_end,
                   piston_mass=cylinder.piston_mass, z=cylinder.axial_offset,
                   gas_force=gas_force, ring_friction=ring_friction)


@dataclass
class Mechanism:
    """A built mechanism: systems, initial state and what the outputs need to know.

    Made by :func:`crank_train` or :func:`four_bar`; :func:`simulate` integrates it.

    Attributes
    ----------
    kind : str
        The ``kind`` given to :func:`crank_train` (``slider_crank``, ``four_star``), or
        ``four_bar``.
    system, ideal : Multibody
        The mechanism, and its twin with every clearance joint an ideal pin.
    q0, qd0 : ndarray
        The initial coordinates and velocities (m, rad; m/s, rad/s).
    crank : body
        The crank.
    pistons, axes : list
        The pistons and their cylinder axes.
    revolution_hz : float
        Crank revolutions per second.
    main_joint, main_joints, rows_z
        The main bearing's joint name(s) and the rows' axial positions (m).
    start, start_info
        How the initial state was found (``quasi_static`` or ``undeformed``) and its record.
    arrangement, layout
        The crank train's :class:`~crankmodal.mechanism.arrangement.Arrangement` (None: one
        crankpin) and its :class:`~.layout.ThrowLayout` (throws, pin angles, top dead centres).
    reference_angle : float
        Angle of the reference throw in the crank's body axes, rad (0 for a rigid crank): the
        reference crank angle is the crank's body angle plus it.
    journals_z : list or None
        A rigid crank's two main journals' axial positions, m (the lever-rule split).
    motor : RigidBody or None
        The motor rotor of a :class:`~.drive.MotorDrive`.
    pin_frames : list of str
        The crank frame carrying each cylinder's rod.
    drive_frame : str
        The crank frame the drive (or the motor's coupling) acts on.
    """

    kind: str
    system: Multibody
    ideal: Multibody
    q0: np.ndarray
    qd0: np.ndarray
    crank: RigidBody
    pistons: list = field(default_factory=list)
    axes: list = field(default_factory=list)
    revolution_hz: float = 1.0
    main_joint: str = "main"
    rows_z: dict = field(default_factory=dict)
    main_joints: list = field(default_factory=list)
    start: str = "quasi_static"
    start_info: dict | None = None
    arrangement: object = None
    layout: object = None
    reference_angle: float = 0.0
    journals_z: list | None = None
    motor: RigidBody | None = None
    pin_frames: list = field(default_factory=list)
    drive_frame: str = "main"

    def __post_init__(self):
        if not self.main_joints:
            self.main_joints = [self.main_joint]
        self._built = (np.array(self.q0, float), np.array(self.qd0, float))

    def as_built(self) -> bool:
        """Whether ``q0`` and ``qd0`` are still the state the mechanism was made with (not set
        by the caller since): only such a state gets :func:`~.analysis.simulate`'s default
        quasi-static start; a state you set is run as given."""
        q, qd = self._built
        return bool(np.array_equal(self.q0, q) and np.array_equal(self.qd0, qd))

    def start_quasi_static(self) -> dict:
        """Deform the flexible bodies to rest under the loads at ``t = 0``, as scenes start.

        Replaces ``q0`` and ``qd0`` by :func:`~.initial.quasi_static_start`'s state (solved on
        the ideal-joint twin: across a clearance the Newton steps found spurious states balanced
        by the contact or film force past the wall: the loom's coupler pin C at 165 % of its
        clearance) and keeps its ``{"iterations", "residual"}`` in ``start_info``. :func:`~.analysis.simulate` calls it before the first
        run unless told ``start="undeformed"``. Without elastic modes nothing changes.
        """
        from ..flexible.initial import quasi_static_start

        self.q0, self.qd0, self.start_info = quasi_static_start(self.ideal, self.q0, self.qd0)
        return self.start_info


class RedundantJoints(ParameterError):
    """The joints hold more than the bodies' coordinates can give (a singular system); a
    :class:`~crankmodal.errors.ParameterError` naming the body argument that brought them."""


def _check_rank(sysm, q, what: str, argument: str = "bodies") -> None:
    """Refuse redundant constraints at the assembled state (the KKT matrix would be singular)."""
    if not sysm.m:
        return
    _, Cq, _, _ = sysm.constraint_terms(0.0, q, np.zeros_like(q))
    sv = np.linalg.svd(Cq, compute_uv=False)
    rank = int(np.sum(sv > 1e-9 * sv[0]))
    if rank < sysm.m:
        raise RedundantJoints(argument, f"{what}: {sysm.m - rank} of its {sysm.m} joint "
                              f"equations are redundant (rank {rank})")


def _unit(angle):
    return np.array([np.cos(angle), np.sin(angle)])


def _split(pins, clearances, contact_kw):
    """Ideal pins and clearance joints from the pin list and ``{name: ClearanceSpec}`` (or the
    deprecated dict form, converted by :func:`clearance_specs`)."""
    from ... import arguments as arg

    specs = clearances or {}
    if not hasattr(specs, "values"):
        raise ParameterError("clearances", f"must be a mapping {{joint: ClearanceSpec}}, got "
                             f"{specs!r:.60}")
    specs = arg.table("clearances", specs, {p.name for p in pins})  # the names first
    if contact_kw or any(not isinstance(v, ClearanceSpec) for v in specs.values()):
        specs = clearance_specs(specs, contact_kw, stacklevel=5)
    ideal_pins, clear = [], []
    for p in pins:
        spec = specs.get(p.name)
        if spec is None:
            ideal_pins.append(p)
            continue
        clear.append(spec.joint(p.name, p.a, p.frame_a, p.b, p.frame_b))
    return ideal_pins, clear


def clearance_specs(clearances, contact_kw=None, stacklevel: int = 2) -> dict:
    """``{joint: ClearanceSpec}`` from the deprecated dict form of ``clearances``.

    The one edge where the dictionaries of the old Python API (``clearances = {joint: {
    "clearance", "journal_radius", "contact": {...}}}`` with shared ``contact_kw = {"law",
    "law_params", "friction", "friction_params", "v_impact_min"}``) become typed
    :class:`~.clearance.ClearanceSpec` objects; it issues one :class:`DeprecationWarning`.
    Entries that are ClearanceSpecs already pass unchanged.

    Raises
    ------
    ParameterError
        Naming ``clearances.<joint>.<key>`` or ``contact_kw`` (and, for a missing contact
        stiffness, the scenes' default for steel on steel).
    """
    import warnings

    from ... import arguments as arg
    from ..laws.objects import legacy_laws

    clearances = arg.table("clearances", clearances or {}, set(clearances or {}))
    contact_kw = arg.table("contact_kw", contact_kw or {}, CONTACT_KW)
    out = {}
    for name, spec in clearances.items():
        if isinstance(spec, ClearanceSpec):
            out[name] = spec
            continue
        spec = _clearance_spec(f"clearances.{name}", spec)
        kw = dict(contact_kw)
        kw.update(spec.get("contact") or {})  # per-joint overrides (a stiffness from the radii)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DeprecationWarning)
                normal, friction = legacy_laws(kw.get("law", "impact"), kw.get("law_params"),
                                               kw.get("friction"), kw.get("friction_params"))
        except (ValueError, TypeError) as exc:  # the law objects' own checks (ParameterError)
            where = f"clearances.{name}.contact" if spec.get("contact") else "contact_kw"
            raise ParameterError(where, f"joint {name!r}: {exc}"
                                 + _stiffness_hint(kw, spec)) from None
        try:
            out[name] = ClearanceSpec(
                clearance=spec["clearance"], journal_radius=spec["journal_radius"],
                normal=normal, friction=friction,
                v_impact_min=kw.get("v_impact_min", 1e-3),
                clearance_major=spec.get("clearance_major"),
                wear_angle=spec.get("wear_angle", 0.0), viscosity=spec.get("viscosity"),
                bearing_length=spec.get("bearing_length") or None,
                film_model=spec.get("film_model", "short"))
        except ParameterError as exc:
            where = "contact_kw.v_impact_min" if exc.argument == "v_impact_min" \
                else f"clearances.{name}.{exc.argument}"
            raise ParameterError(where, exc.text) from None
    if any(not isinstance(v, ClearanceSpec) for v in clearances.values()) or contact_kw:
        warnings.warn("clearances as dicts with contact_kw are deprecated: pass {joint: "
                      "ClearanceSpec(clearance, journal_radius, normal=<NormalLaw>, "
                      "friction=<FrictionLaw>, ...)}", DeprecationWarning,
                      stacklevel=stacklevel)
    return out


#: keys of ``contact_kw`` (the clearance joints' shared law settings)
CONTACT_KW = ("law", "law_params", "friction", "friction_params", "v_impact_min")


def _clearance_spec(name: str, spec) -> dict:
    """One ``clearances`` entry checked by the ``[[dynamics.clearances]]`` keys' rules."""
    from ... import arguments as arg
    from ..scene.keys import CLEARANCE

    keys = ("clearance", "journal_radius", "clearance_major", "wear_angle", "viscosity",
            "bearing_length", "film_model", "contact")
    spec = arg.table(name, spec, keys, required=("clearance", "journal_radius"))
    if spec.get("bearing_length") == 0.0:  # no film: the length is not used
        spec["bearing_length"] = None
    for key in ("clearance", "journal_radius", "clearance_major", "viscosity", "bearing_length",
                "film_model"):
        if key in spec:
            spec[key] = arg.check(f"{name}.{key}", spec[key], CLEARANCE[key],
                                  optional=key not in ("clearance", "journal_radius"))
    if "wear_angle" in spec:
        spec["wear_angle"] = arg.number(f"{name}.wear_angle", spec["wear_angle"])
    major = spec.get("clearance_major")
    if major is not None and major < spec["clearance"]:
        raise ParameterError(f"{name}.clearance_major", f"must be >= clearance "
                             f"({spec['clearance']:g} m), got {major:g}")
    if spec.get("viscosity") is not None and not spec.get("bearing_length"):
        raise ParameterError(f"{name}.bearing_length", "is required with viscosity (bearing "
                             "length, m, > 0)")
    if spec.get("contact") is not None:
        spec["contact"] = arg.table(f"{name}.contact", spec["contact"], CONTACT_KW)
    return spec


def _stiffness_hint(kw: dict, spec: dict) -> str:
    """A start for a missing contact stiffness: the scene's default for steel on steel."""
    if "stiffness" in (kw.get("law_params") or {}) or not isinstance(kw.get("law", "impact"), str):
        return ""
    from ..laws.contact import cylinder_stiffness

    rj = spec["journal_radius"]
    K = cylinder_stiffness(rj, rj + spec["clearance"], 2.1e11, 0.3, 2.1e11, 0.3)
    return (f"; for steel on steel the scenes' default is law_params['stiffness'] = {K:.3g} "
            f"N/m^1.5 (from the radii), with 'damping' 300 N s/m and 'penetration' 1e-4 m")


def _finish(kind, bodies, pins, others, loads, clearance_specs, contact_kw, q0, qd0, crank,
            drive, gravity, baumgarte, body_argument="bodies", **meta):
    ideal_pins, clear = _split(pins, clearance_specs, contact_kw)
    assembly = Multibody(bodies, pins + others, [], loads, gravity, baumgarte)
    q, qd = assembly.assemble(0.0, q0, qd0)
    extra = []
    if not any(c is drive for c in others):
        # free speed: assembled at omega0, then torque-driven; or a motor's drive
        others = [c for c in others if not isinstance(c, AngleDrive)]
        if isinstance(drive, AngleDrive):
            others.append(drive)
        else:
            extra = [drive]
    ideal = Multibody(bodies, pins + others, [], loads + extra, gravity, baumgarte)
    _check_rank(ideal, q, f"{kind} with {len(bodies)} bodies", body_argument)
    system = Multibody(bodies, ideal_pins + others, clear, loads + extra, gravity, baumgarte)
    return Mechanism(kind=kind, system=system, ideal=ideal, q0=q, qd0=qd, crank=crank, **meta)


def _check_common(speed_rpm, theta0, ramp_time, drive_torque, gravity, baumgarte,
                  direction) -> dict:
    """The arguments crank trains and the four-bar share, by the ``[dynamics]`` keys' rules."""
    from ... import arguments as arg
    from ..scene.keys import SCHEMA, SOLVER

    # as dynamics.speed_rpm, but 0 (the crank held by its drive) is a state the API runs
    out = {"speed_rpm": arg.number("speed_rpm", speed_rpm, ge=0.0, le=SCHEMA["speed_rpm"].le),
           "theta0": arg.number("theta0", theta0),
           "ramp_time": arg.check("ramp_time", ramp_time, SCHEMA["ramp_time"]),
           "drive_torque": arg.check("drive_torque", drive_torque, SCHEMA["drive_torque"],
                                     optional=True),
           "gravity": tuple(arg.check("gravity", gravity, SCHEMA["gravity"])),
           "baumgarte": arg.check("baumgarte", baumgarte, SOLVER["baumgarte"], optional=True),
           "direction": arg.one_of("direction", direction, (1, -1))}
    if out["drive_torque"] is not None and out["ramp_time"] > 0.0:
        raise ParameterError("ramp_time", "must be 0 with drive_torque (the torque drives), "
                             f"got {out['ramp_time']:g}")
    return out


def _default_roles(body, n_cylinders: int) -> dict:
    """The roles of a crank body's frames when ``crank_roles`` is not given: the frames
    :func:`~.flexbuild.crank_body` names (``main_1``, ``main_2``…, ``pin_1``…, ``drive``), or
    those of a plain crank (``main``, ``pin``)."""
    import re

    frames = list(body.frames)
    mains = sorted((f for f in frames if re.fullmatch(r"main_\d+", f)), key=lambda f: int(f[5:]))
    mains = mains or (["main"] if "main" in frames else [])
    pins = [f"pin_{i}" for i in range(1, n_cylinders + 1)]
    if not all(p in frames for p in pins):
        pins = ["pin"] * n_cylinders if "pin" in frames else []
    drive = "drive" if "drive" in frames else (mains[0] if mains else None)
    if not mains or not pins:
        raise ParameterError("crank_roles", "not given, and the crank body's frames "
                             f"({', '.join(frames) or 'none'}) are not those of crank_body() "
                             "(main_1.., pin_1.., drive) or of a plain crank (main, pin): give "
                             "crank_roles = {'mains': [...], 'pins': [one per cylinder], "
                             "'drive': ...}")
    return {"mains": mains, "pins": pins, "drive": drive}


def _check_roles(body, roles, n_cylinders: int) -> dict:
    """``crank_roles`` (given, or the default of the body's frames) checked against the body."""
    from ... import arguments as arg

    if roles is None:
        return _default_roles(body, n_cylinders)
    roles = arg.table("crank_roles", roles, ("mains", "pins", "drive"),
                      required=("mains", "pins", "drive"))
    mains = roles["mains"] = list(roles["mains"]) if not isinstance(roles["mains"], str) \
        else [roles["mains"]]
    pins = roles["pins"] = list(roles["pins"])
    if not mains:
        raise ParameterError("crank_roles.mains", "needs at least one main journal frame")
    if len(pins) != n_cylinders:
        raise ParameterError("crank_roles.pins", f"needs one frame per cylinder "
                             f"({n_cylinders}), got {len(pins)}")
    for key, names in (("mains", mains), ("pins", pins), ("drive", [roles["drive"]])):
        for i, frame in enumerate(names):
            if frame not in body.frames:
                where = "crank_roles.drive" if key == "drive" else f"crank_roles.{key}[{i}]"
                raise ParameterError(where, f"the crank body has no frame {frame!r}; frames: "
                                     f"{', '.join(body.frames)}")
    return roles


def _is_body(value) -> bool:
    return all(hasattr(value, a) for a in ("frames", "ndof", "local", "frame_pose"))


def _drive(crank, omega, theta0, ramp_time, drive_torque, crank_frame="main"):
    """The angle drive used for assembly, and the drive of the run (same, or a torque)."""
    omega_start = 0.0 if ramp_time > 0.0 else omega
    angle = AngleDrive("drive", crank, crank_frame,
                       SpeedProfile(omega, theta0, ramp_time, omega_start))
    if drive_torque is None:
        return angle, angle
    return angle, CrankTorque(crank, crank_frame, drive_torque)


def crank_train(crank_radius, cylinders, speed_rpm, crank_mass=0.0, crank_inertia=0.0,
                crank_com=0.0, theta0=0.0, ramp_time=0.0, drive_torque=None, clearances=None,
                contact_kw=None, gravity=(0.0, 0.0), baumgarte=None, kind="slider_crank",
                direction=1, crank_body=None, crank_roles=None, rod_bodies=None,
                arrangement=None, journals_z=None, motor=None):
    """Crank train: one crank, ``len(cylinders)`` rods on its crankpins, pistons.

    Without ``arrangement`` every rod sits on one crankpin (slider-crank, V, four-star). With
    one (:class:`~crankmodal.mechanism.arrangement.Arrangement`, the machine description the
    forced torsion reads too), each cylinder works on its throw at the throw's phase, and a
    four-stroke gas cycle is phased by the firing order (:mod:`.layout`).

    The crank and the rods are rigid bodies made from the parameters, or the body objects given
    (e.g. flexible ones, :mod:`~.flexbuild`): ``crank_body`` with ``crank_roles`` naming its
    frames (``mains``: one per main journal, each pinned to the ground as joint ``main``, or
    ``main_1``, ``main_2``… when there are several; ``pins``: the frame carrying each rod;
    ``drive``: the frame the speed or torque drives), and ``rod_bodies`` (one per cylinder, or
    None for a rigid one) with frames ``big`` and ``small`` and body x from big to small end.

    Parameters
    ----------
    crank_radius : float
        m.
    cylinders : list of Cylinder
    speed_rpm : float
        Crank speed (prescribed, or initial when ``drive_torque`` is given), rpm, in
        ``[0, 20000]`` (0: the crank held).
    crank_mass, crank_inertia, crank_com : float
        kg, kg m^2 about its centre of mass, and the distance of that centre from the crank axis
        along the crank (negative: counterweight side), m.
    theta0 : float
        Initial crank angle, rad.
    ramp_time : float
        Speed ramp from rest (ADAMS STEP), s; 0 starts at full speed.
    drive_torque : float or None
        None: prescribed speed. A number: constant torque (N m) with the speed free (put the
        flywheel into ``crank_inertia``).
    clearances : dict, optional
        ``{joint_name: ClearanceSpec}`` (:class:`~.clearance.ClearanceSpec`: the bore, the
        journal, the law objects, the film); joints are ``main`` (or ``main_1``… of a crank body
        on several journals), ``big_end_<i>``, ``small_end_<i>`` (i from 1). Deprecated, still
        accepted with one DeprecationWarning (:func:`clearance_specs`): ``{joint_name:
        {"clearance": m, "journal_radius": m, "contact": {overrides}, ...}}`` with
        ``contact_kw``.
    contact_kw : dict, optional
        Deprecated: ``law, law_params, friction, friction_params, v_impact_min`` of the dict
        form of ``clearances``.
    gravity : (2,)
        m/s^2.
    baumgarte : float, optional
        Stabilisation rate, 1/s (default: 2 crank speeds, at least 50).
    direction : {1, -1}
        Sense of rotation: 1 counter-clockwise (angles grow), -1 clockwise. A cylinder's angle
        from its top dead centre is ``direction * (theta - psi_i)``.
    crank_body : body, optional
        The crank as a body object (e.g. :func:`~.flexbuild.crank_body`'s), replacing the rigid
        crank made from ``crank_mass``, ``crank_inertia`` and ``crank_com``. The speed is then
        prescribed (``drive_torque`` None: the part carries no flywheel, as in scenes).
    crank_roles : dict, optional
        ``mains``, ``pins``, ``drive`` frame names of ``crank_body`` (see above); default: the
        frames :func:`~.flexbuild.crank_body` makes (``main_1``…, ``pin_1``…, ``drive``).
    rod_bodies : list, optional
        One body (or None: rigid) per cylinder, frames ``big`` and ``small``.
    arrangement : Arrangement, optional
        Throws (phases ahead of the reference crank in the sense of rotation), each cylinder's
        throw and bank angle (its ``axis_angle`` must be ``90 deg - bank``), and the firing
        order of a four-stroke cycle (each cylinder's ``gas_force`` is then read from its
        firing top dead centre, over 720 deg). A rigid crank gets one pin frame per throw
        (``pin_1``…); a ``crank_body``'s pin frames must lie at their throws' phases.
    journals_z : sequence of float, optional
        Rigid crank only: the axial positions of its main journals, m (the cylinders' ``z`` in
        the same axis). Two journals: the main-bearing force is split between them by the
        lever rule (statically determinate; outputs ``main_1``, ``main_2``); more than two
        are statically indeterminate and refused: give a flexible ``crank_body``.
    motor : MotorDrive, optional
        A motor rotor coupled to the crank's drive frame through a torsional coupling
        (:mod:`.drive`): the prescribed speed (or ``drive_torque``) then acts on the motor,
        and the train's torsional modes appear. A rigid crank then needs ``crank_inertia > 0``.

    Raises
    ------
    ParameterError
        An argument out of its range, naming it (``crank_radius``, ``cylinders[0].rod_length``,
        ``clearances.main.clearance``, ``crank_roles``, ``arrangement.cylinder_throws``,
        ``journals_z``, ``motor``…); the bounds are those of the ``[dynamics]`` scene keys.
    """
    from ... import arguments as arg
    from ..scene.keys import CRANK_TRAIN

    common = _check_common(speed_rpm, theta0, ramp_time, drive_torque, gravity, baumgarte,
                           direction)
    speed_rpm, theta0, ramp_time = common["speed_rpm"], common["theta0"], common["ramp_time"]
    drive_torque, gravity, baumgarte = (common["drive_torque"], common["gravity"],
                                        common["baumgarte"])
    crank_radius = arg.check("crank_radius", crank_radius, CRANK_TRAIN["crank_radius"])
    crank_mass = arg.check("crank_mass", crank_mass, CRANK_TRAIN["crank_mass"])
    crank_inertia = arg.check("crank_inertia", crank_inertia, CRANK_TRAIN["crank_inertia"])
    crank_com = arg.check("crank_com", crank_com, CRANK_TRAIN["crank_com"])
    if isinstance(cylinders, (str, bytes)) or not hasattr(cylinders, "__len__") or not cylinders:
        raise ParameterError("cylinders", f"must be a non-empty list of Cylinder, got "
                             f"{cylinders!r:.60}")
    cylinders = list(cylinders)
    for i, cyl in enumerate(cylinders):
        arg.instance(f"cylinders[{i}]", cyl, Cylinder, "a Cylinder")
    if rod_bodies is not None:
        if isinstance(rod_bodies, (str, bytes)) or len(rod_bodies) != len(cylinders):
            raise ParameterError("rod_bodies", f"needs one entry (a body, or None for a rigid "
                                 f"rod) per cylinder ({len(cylinders)})")
        for i, rod in enumerate(rod_bodies):
            if rod is None:
                continue
            if not _is_body(rod):
                raise ParameterError(f"rod_bodies[{i}]", f"must be a body (RigidBody, "
                                     f"FlexibleBody) or None, got {rod!r:.60}")
            missing = [f for f in ("big", "small") if f not in rod.frames]
            if missing:
                raise ParameterError(f"rod_bodies[{i}]", f"needs frames 'big' and 'small' "
                                     f"(rod_body() makes them); it has {', '.join(rod.frames)}")
    for i, cyl in enumerate(cylinders):
        given = rod_bodies is not None and rod_bodies[i] is not None
        if not given and cyl.rod_length <= crank_radius + abs(cyl.offset):
            raise ParameterError(f"cylinders[{i}].rod_length", f"must exceed crank_radius + "
                                 f"|offset| = {crank_radius + abs(cyl.offset):g} m, got "
                                 f"{cyl.rod_length:g}")
        if not given and cyl.rod_inertia <= 0.0:
            raise ParameterError(f"cylinders[{i}].rod_inertia", "must be > 0 kg m^2 for a rigid "
                                 "rod made from the parameters (0 only with a rod body given)")
    if crank_body is not None:
        if not _is_body(crank_body):
            raise ParameterError("crank_body", f"must be a body (RigidBody, FlexibleBody, e.g. "
                                 f"from crank_body()), got {crank_body!r:.60}")
        if isinstance(crank_body, tuple):
            raise ParameterError("crank_body", "got a tuple: crank_body() returns (body, roles)")
        crank_roles = _check_roles(crank_body, crank_roles, len(cylinders))
        if drive_torque is not None and not isinstance(crank_body, RigidBody) and motor is None:
            raise ParameterError("drive_torque", "with a flexible crank the speed is "
                                 "prescribed (the part carries no flywheel); give None")
    elif crank_roles is not None:
        raise ParameterError("crank_roles", "given without crank_body")
    if drive_torque is not None and crank_body is None and crank_inertia <= 0.0:
        raise ParameterError("crank_inertia", "must be > 0 (crank and flywheel, kg m^2) when "
                             "drive_torque sets the speed free")
    if motor is not None:
        from .drive import MotorDrive

        arg.instance("motor", motor, MotorDrive, "a MotorDrive(inertia, coupling_stiffness, "
                     "coupling_damping)")
        if crank_body is None and crank_inertia <= 0.0:
            raise ParameterError("crank_inertia", "must be > 0 (crank and flywheel, kg m^2) "
                                 "with a motor: the crank turns on the coupling")
    if arrangement is None:
        layout = single_pin_layout([c.axis_angle for c in cylinders])
    else:
        layout = throw_layout(arrangement, [c.axis_angle for c in cylinders], direction)
    if journals_z is not None:
        journals_z = arg.numbers("journals_z", journals_z)
        if crank_body is not None:
            raise ParameterError("journals_z", "is for a rigid crank made from the parameters; "
                                 "a crank body's main journals are its frames (crank_roles)")
        if len(journals_z) > 2:
            raise RedundantJoints("journals_z", f"a rigid crank on {len(journals_z)} main "
                                  "journals is statically indeterminate (only the crank's "
                                  "flexibility shares the load): give a flexible crank_body")
        if len(journals_z) == 2 and journals_z[0] == journals_z[1]:
            raise ParameterError("journals_z", "the two journals must be at different axial "
                                 f"positions, got {journals_z}")
    omega = direction * speed_rpm * 2.0 * np.pi / 60.0
    baumgarte = max(50.0, 2.0 * abs(omega)) if baumgarte is None else baumgarte
    ground = Ground(frames={"main": (0.0, 0.0)})
    r, b = crank_radius, crank_com
    rw = omega if ramp_time <= 0.0 else 0.0
    reference = 0.0  # angle of the reference throw in the crank's body axes
    if crank_body is None:
        frames = {"main": (-b, 0.0)}
        if all(a == 0.0 for a in layout.pin_angles):  # one crankpin, as ever
            frames["pin"] = (r - b, 0.0)
            throw_frames = ["pin"] * layout.n_throws
        else:
            throw_frames = [f"pin_{t}" for t in range(1, layout.n_throws + 1)]
            for name, a in zip(throw_frames, layout.pin_angles):
                frames[name] = (r * np.cos(a) - b, r * np.sin(a))
        z_crank = 0.0 if not journals_z else float(np.mean(journals_z))
        crank = RigidBody("crank", max(crank_mass, 0.0), max(crank_inertia, 1e-12), frames,
                          z=z_crank)
        mains, drive_frame = ["main"], "main"
        pin_frames = [throw_frames[t] for t in layout.throws]
        c0, s0 = np.cos(theta0), np.sin(theta0)
        q_crank = np.array([b * c0, b * s0, theta0])
    else:
        crank = crank_body
        mains, pin_frames = list(crank_roles["mains"]), list(crank_roles["pins"])
        drive_frame = crank_roles["drive"]
        if arrangement is not None:
            reference = body_reference_angle(crank, mains[0], pin_frames, layout)
        th = theta0 - reference
        A0 = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        s_main = crank.local(mains[0])[0]  # undeformed, body axes
        q_crank = np.concatenate([-A0 @ s_main, [th], np.zeros(crank.ndof - 3)])
    # rigid rotation about the axis at rw: v = rw e_z x (position of the frame origin)
    qd_crank = np.zeros(crank.ndof)
    qd_crank[:3] = [-q_crank[1] * rw, q_crank[0] * rw, rw]
    bodies, q0, qd0 = [crank], list(q_crank), list(qd_crank)
    main_names = ["main"] if len(mains) == 1 else [f"main_{j}" for j in range(1, len(mains) + 1)]
    pins = [Revolute(nm, crank, fr, ground, "main") for nm, fr in zip(main_names, mains)]
    others, loads, pistons, axes, rows_z = [], [], [], [], {}
    angle_drive, drive = _drive(crank, omega, theta0 - reference, ramp_time, drive_torque,
                                drive_frame)
    others.append(angle_drive)
    motor_body = None
    if motor is not None:
        motor_body, drive = _motor(motor, crank, drive_frame, q_crank, omega, ramp_time,
                                   drive_torque)
        bodies.append(motor_body)
        q0 += [0.0, 0.0, float(crank.frame_pose(q_crank, drive_frame)[2])]
        qd0 += [0.0, 0.0, rw]
        pins.append(Revolute("motor_bearing", motor_body, "shaft", ground, "main"))
        loads.append(TorsionalCoupling(motor_body, "shaft", crank, drive_frame,
                                       motor.coupling_stiffness, motor.coupling_damping))
    for i, cyl in enumerate(cylinders, start=1):
        u = _unit(cyl.axis_angle)
        nrm = np.array([-u[1], u[0]])
        P = crank.frame_pose(q_crank, pin_frames[i - 1])[:2]
        rod = rod_bodies[i - 1] if rod_bodies and rod_bodies[i - 1] is not None else None
        given_rod = None if rod is None else rod
        if rod is None:
            a, L = cyl.rod_com, cyl.rod_length
            rod = RigidBody(f"rod_{i}", cyl.rod_mass, cyl.rod_inertia,
                            {"big": (-a, 0.0), "small": (L - a, 0.0)}, z=cyl.z)
        else:
            rod.z = cyl.z
        s_big = rod.local("big")[0]
        L = float(np.hypot(*(rod.local("small")[0] - s_big)))
        piston = RigidBody(f"piston_{i}", cyl.piston_mass, 1.0e-6, {"pin": (0.0, 0.0)}, z=cyl.z)
        h = P @ nrm - cyl.offset
        if abs(h) >= L:
            where = f"rod_bodies[{i - 1}]" if given_rod is not None else f"cylinders[{i - 1}]"
            raise ParameterError(where, f"the rod ({L:.5g} m) cannot reach the crankpin")
        s = P @ u + np.sqrt(L * L - h * h)
        X = s * u + cyl.offset * nrm
        d = X - P
        phi = np.arctan2(d[1], d[0])
        A = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
        G = P - A @ s_big
        q0 += [G[0], G[1], phi] + [0.0] * (rod.ndof - 3) + [X[0], X[1], cyl.axis_angle]
        qd0 += [0.0] * (rod.ndof + 3)
        bodies += [rod, piston]
        pins += [Revolute(f"big_end_{i}", crank, pin_frames[i - 1], rod, "big"),
                 Revolute(f"small_end_{i}", piston, "pin", rod, "small")]
        others.append(Prismatic(f"slider_{i}", piston, "pin", cyl.offset * nrm, u, cyl.axis_angle))
        # the crank angle is read at the first main journal: its body angle (reference less
        # the reference throw's angle in the body axes)
        tdc = layout.firing_tdc_angles[i - 1] - reference
        loads.append(PistonLoads(piston, "pin", u, tdc, crank, mains[0],
                                 cyl.gas_force, cyl.ring_friction, sense=direction))
        pistons.append(piston)
        axes.append(u)
        rows_z[f"big_end_{i}"] = cyl.z
    return _finish(kind, bodies, pins, others, loads, clearances or {}, contact_kw or {},
                   np.array(q0), np.array(qd0), crank, drive, gravity, baumgarte,
                   pistons=pistons, axes=axes, revolution_hz=speed_rpm / 60.0, rows_z=rows_z,
                   main_joint=main_names[0], main_joints=main_names,
                   body_argument="crank_body" if crank_body is not None else "cylinders",
                   arrangement=arrangement, layout=layout, reference_angle=reference,
                   journals_z=None if journals_z is None else list(journals_z),
                   motor=motor_body, pin_frames=pin_frames, drive_frame=drive_frame)


def _motor(motor, crank, drive_frame, q_crank, omega, ramp_time, drive_torque):
    """The motor rotor (a rigid body on the crank axis, its coupling relaxed at the start) and
    the drive of the run acting on it: its prescribed angle, or ``drive_torque``."""
    rotor = RigidBody("motor", 0.0, motor.inertia, {"shaft": (0.0, 0.0)})
    start = float(crank.frame_pose(q_crank, drive_frame)[2])
    omega_start = 0.0 if ramp_time > 0.0 else omega
    if drive_torque is not None:
        return rotor, CrankTorque(rotor, "shaft", drive_torque)
    # the motor's angle runs from the crank drive frame's: the coupling starts relaxed
    profile = SpeedProfile(omega, start, ramp_time, omega_start)
    return rotor, AngleDrive("drive", rotor, "shaft", profile)


#: relative tolerance on the distance between a link body's two joint frames and its length
LINK_TOLERANCE = 0.01

#: the two joint frames of each four-bar link (body x axis from the first to the second)
FOUR_BAR_JOINTS = {"crank": ("A", "B"), "coupler": ("B", "C"), "rocker": ("D", "C")}


def _link_length(body, role: str, length: float) -> float:
    """Distance between a given link body's two joint frames (undeformed), m, checked against
    the link's ``length`` (±:data:`LINK_TOLERANCE`)."""
    f0, f1 = FOUR_BAR_JOINTS[role]
    missing = [f for f in (f0, f1) if f not in body.frames]
    if missing:
        raise ParameterError(f"{role}_body", f"needs frames {f0!r} and {f1!r} (the joints it "
                             f"carries); it has {', '.join(body.frames) or 'none'}")
    d = float(np.hypot(*(body.local(f1)[0] - body.local(f0)[0])))
    if not abs(d / length - 1.0) <= LINK_TOLERANCE:
        raise ParameterError(f"{role}_body", f"its frames {f0!r} and {f1!r} are {d:.5g} m apart, "
                             f"the {role} length is {length:.5g} m (tolerance "
                             f"{LINK_TOLERANCE:.0%})")
    return d


def _with_extra_inertia(body, extra: float, frame: str = "D"):
    """A copy of ``body`` carrying ``extra`` (kg m²) at its ``frame``: a rigid body's
    ``inertia`` plus ``extra``; a flexible body's rotary inertia attached to that interface
    (:meth:`~.flexible.FlexibleBody.attach_inertia`: it turns with the interface, ``θ + r_zᵀξ``,
    not with the mean axes), recorded in its ``info`` (``extra_inertia_kgm2``,
    ``extra_inertia_frame``, ``extra_inertia_interface``)."""
    import copy

    if extra == 0.0:
        return body
    twin = copy.copy(body)
    if isinstance(body, RigidBody):
        twin.inertia = body.inertia + extra
        return twin
    for cache in ("_stacked", "_geo", "_bias"):
        twin.__dict__.pop(cache, None)
    twin.attach_inertia(frame, extra)
    twin.info = dict(body.info, extra_inertia_kgm2=extra, extra_inertia_frame=frame)
    interface = body.info.get("roles", {}).get(frame)
    if interface is not None:
        twin.info["extra_inertia_interface"] = interface
    return twin


def _place(body, f0, f1, X0, X1):
    """Coordinates of a body whose (undeformed) frames ``f0`` and ``f1`` lie on the line from
    ``X0`` towards ``X1`` with ``f0`` at ``X0``: ``(x, y, phi, 0 …)``."""
    s0, s1 = body.local(f0)[0], body.local(f1)[0]
    ds, dX = s1 - s0, np.asarray(X1) - np.asarray(X0)
    phi = float(np.arctan2(dX[1], dX[0]) - np.arctan2(ds[1], ds[0]))
    A = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    R = np.asarray(X0) - A @ s0
    return np.concatenate([R, [phi], np.zeros(body.ndof - 3)])


def four_bar(crank_length, coupler_length, rocker_length, rocker_pivot, masses, inertias,
             speed_rpm, com_fractions=(0.0, 0.5, 0.5), extra_rocker_inertia=0.0, theta0=0.0,
             ramp_time=0.0, drive_torque=None, branch=1, clearances=None, contact_kw=None,
             gravity=(0.0, 0.0), baumgarte=None, direction=1, crank_body=None,
             coupler_body=None, rocker_body=None):
    """Four-bar crank-rocker: crank A-B, coupler B-C, rocker D-C; joints ``A, B, C, D``.

    Each link is a rigid body made from the parameters, or the body object given (rigid or
    flexible, e.g. :func:`~.flexbuild.link_body`) with frames named for the joints it carries:
    ``crank_body`` frames ``A`` and ``B``, ``coupler_body`` ``B`` and ``C``, ``rocker_body``
    ``D`` and ``C``. A given body's frames must be its link's length apart (±1 %, undeformed;
    the kinematics then use the body's own distance), and its own mass properties replace
    ``masses``, ``inertias`` and ``com_fractions`` for that link. The crank is driven at its
    ``A`` frame.

    Parameters
    ----------
    crank_length, coupler_length, rocker_length : float
        m.
    rocker_pivot : (2,)
        Position of D, m (A at the origin).
    masses, inertias : 3 floats each
        Crank, coupler, rocker: kg and kg m^2 about the centre of mass.
    com_fractions : 3 floats
        Centre of mass of each link as a fraction of its length from A, B, D respectively.
    extra_rocker_inertia : float
        Inertia rigidly attached to the rocker about D (e.g. sley and sword), kg m^2. It is
        added to the rocker's moment about its centre of mass (its mass taken as centred on the
        fixed pivot D, so only its inertia acts); on a flexible rocker it is a rotary inertia
        attached to the ``D`` interface (kinetic energy ``½ J_s (θ̇ + r_zᵀξ̇)²``: it turns with
        the shaft, so its inertia torque enters the rocker there), recorded in the rocker's
        ``info`` (``extra_inertia_kgm2``, ``extra_inertia_frame``).
    branch : {1, -1}
        Assembly mode (which side of BD the joint C lies on).
    direction : {1, -1}
        Sense of rotation of the crank (1 counter-clockwise).
    crank_body, coupler_body, rocker_body : body, optional
        The link as a given body (see above).

    Raises
    ------
    ParameterError
        An argument out of its range, naming it (the ``[dynamics.four_bar]`` keys' rules:
        lengths and masses > 0, inertias >= 0, three entries each; ``branch`` 1 or -1); a
        given body lacks its joint frames, or they are not its link's length apart; the links
        cannot be assembled at ``theta0`` (naming ``rocker_pivot``).
    """
    from ... import arguments as arg
    from ..scene.keys import FOUR_BAR

    common = _check_common(speed_rpm, theta0, ramp_time, drive_torque, gravity, baumgarte,
                           direction)
    speed_rpm, theta0, ramp_time = common["speed_rpm"], common["theta0"], common["ramp_time"]
    drive_torque, gravity, baumgarte = (common["drive_torque"], common["gravity"],
                                        common["baumgarte"])
    length_rule = FOUR_BAR["lengths"]
    crank_length, coupler_length, rocker_length = (
        arg.number(name, value, gt=length_rule.gt) for name, value in
        (("crank_length", crank_length), ("coupler_length", coupler_length),
         ("rocker_length", rocker_length)))
    rocker_pivot = arg.check("rocker_pivot", rocker_pivot, FOUR_BAR["rocker_pivot"])
    masses = arg.check("masses", masses, FOUR_BAR["masses"])
    inertias = arg.check("inertias", inertias, FOUR_BAR["inertias"])
    com_fractions = arg.check("com_fractions", com_fractions, FOUR_BAR["com_fractions"])
    extra_rocker_inertia = arg.check("extra_rocker_inertia", extra_rocker_inertia,
                                     FOUR_BAR["extra_rocker_inertia"])
    branch = arg.check("branch", branch, FOUR_BAR["branch"])
    for role, body in (("crank", crank_body), ("coupler", coupler_body),
                       ("rocker", rocker_body)):
        if body is not None and not _is_body(body):
            raise ParameterError(f"{role}_body", f"must be a body (RigidBody, FlexibleBody, "
                                 f"e.g. from link_body()), got {body!r:.60}")
    if drive_torque is not None and crank_body is None and masses[0] > 0 \
            and inertias[0] + masses[0] * (com_fractions[0] * crank_length) ** 2 <= 0.0:
        raise ParameterError("inertias", "the crank's inertia must be > 0 when drive_torque "
                             "sets the speed free")
    omega = direction * speed_rpm * 2.0 * np.pi / 60.0
    baumgarte = max(50.0, 2.0 * abs(omega)) if baumgarte is None else baumgarte
    D = np.asarray(rocker_pivot, float)
    ground = Ground(frames={"A": (0.0, 0.0), "D": (D[0], D[1])})
    lengths = {"crank": crank_length, "coupler": coupler_length, "rocker": rocker_length}
    given = {"crank": crank_body, "coupler": coupler_body, "rocker": rocker_body}
    for role, body in given.items():
        if body is not None:
            lengths[role] = _link_length(body, role, lengths[role])
    l1, l2, l3 = lengths["crank"], lengths["coupler"], lengths["rocker"]
    f1, f2, f3 = com_fractions
    crank, coupler = crank_body, coupler_body
    if crank is None:
        crank = RigidBody("crank", masses[0], max(inertias[0], 1e-12),
                          {"A": (-f1 * l1, 0.0), "B": ((1 - f1) * l1, 0.0)})
    if coupler is None:
        coupler = RigidBody("coupler", masses[1], inertias[1],
                            {"B": (-f2 * l2, 0.0), "C": ((1 - f2) * l2, 0.0)})
    if rocker_body is None:
        rocker = RigidBody("rocker", masses[2], inertias[2] + extra_rocker_inertia,
                           {"D": (-f3 * l3, 0.0), "C": ((1 - f3) * l3, 0.0)})
    else:
        rocker = _with_extra_inertia(rocker_body, extra_rocker_inertia)
    B = l1 * _unit(theta0)
    BD = D - B
    dist = np.hypot(*BD)
    if not abs(l2 - l3) < dist < l2 + l3:
        raise ParameterError("rocker_pivot", f"the four-bar cannot be assembled at theta0 = "
                             f"{theta0:g} rad: B is {dist:.5g} m from the pivot D, the coupler "
                             f"and rocker ({l2:.5g} + {l3:.5g} m) reach only "
                             f"{abs(l2 - l3):.5g} to {l2 + l3:.5g} m")
    x = (dist**2 + l2**2 - l3**2) / (2 * dist)
    y = branch * np.sqrt(l2**2 - x**2)
    ebd = BD / dist
    C = B + x * ebd + y * np.array([-ebd[1], ebd[0]])
    A0 = np.zeros(2)
    qs = [_place(crank, "A", "B", A0, B), _place(coupler, "B", "C", B, C),
          _place(rocker, "D", "C", D, C)]
    if crank_body is not None:
        turn = float(crank.frame_pose(qs[0], "A")[2] - theta0)
        if abs(np.angle(np.exp(1j * turn))) > 1e-9:
            raise ParameterError("crank_body", "its A frame's angle must be the crank angle "
                                 "(body x axis from A towards B, no angle offset at A); it is "
                                 f"{np.rad2deg(turn):.4g} deg off")
    q0 = np.concatenate(qs)
    rw = omega if ramp_time <= 0.0 else 0.0
    qd0 = np.zeros(len(q0))
    # rigid rotation of the crank about A at rw: v = rw e_z x (position of its frame origin)
    qd0[:3] = [-qs[0][1] * rw, qs[0][0] * rw, rw]
    pins = [Revolute("A", crank, "A", ground, "A"), Revolute("B", crank, "B", coupler, "B"),
            Revolute("C", rocker, "C", coupler, "C"), Revolute("D", rocker, "D", ground, "D")]
    angle_drive, drive = _drive(crank, omega, theta0, ramp_time, drive_torque, "A")
    return _finish("four_bar", [crank, coupler, rocker], pins, [angle_drive], [],
                   clearances or {}, contact_kw or {}, q0, qd0, crank, drive, gravity,
                   baumgarte, revolution_hz=speed_rpm / 60.0, main_joint="A",
                   body_argument=next((f"{r}_body" for r, b in (("crank", crank_body),
                                       ("coupler", coupler_body), ("rocker", rocker_body))
                                       if b is not None), "bodies"))
