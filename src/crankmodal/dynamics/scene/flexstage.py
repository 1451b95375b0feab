"""The ``[dynamics.flexible]`` part of the stage: flexible bodies in, flexible-vs-rigid results out.

:func:`make_bodies` turns the validated tables into body objects (:mod:`.flexbuild`), and
:func:`rigid_twins` their rigid twins (same mass properties and frames, modes frozen).
:func:`flexible_results` compares a flexible run with its rigid twin: the main-bearing force
(sum and per journal: peak, RMS, order amplitudes, the RMS of the difference), the modal
coordinates, the interfaces' elastic deflections and the dynamic stress of each flexible body
from its stress modes (largest von Mises over the run: where and when). For the four-bar
(:func:`make_links`: crank, coupler, rocker from a file or a bar reduced here) the "main bearing"
is the crank's ground joint A, and the joints B, C, D are compared as well.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import SceneError, scene_keys
from ..results.validity import dynamic_stress, flexible_bodies_of


def train_geometry(p, mechanism_params):
    """Crank radius (m), rod lengths (m) and row positions (m) of the crank train."""
    if p["from_mechanism"]:
        from ..model.bridge import cylinders_from_mechanism

        src = cylinders_from_mechanism(mechanism_params, p["ring_friction_n"])
        cyl = src["cylinders"]
        return src["crank_radius"], [c.rod_length for c in cyl], [c.z for c in cyl]
    from .keys import cylinder_angles

    ct = p["crank_train"]
    n = len(cylinder_angles(p))
    return ct["crank_radius"], [ct["rod_length"]] * n, list(ct["row_z"] or [0.0] * n)


def _machine_throws(p, mechanism_params):
    """Per cylinder its 1-based throw when a ``[mechanism]`` machine has several throws (the
    arrangement of :func:`~.trains.machine_cylinders`), else None."""
    if not p["from_mechanism"]:
        return None
    from .trains import machine_cylinders

    arrangement = machine_cylinders(p, mechanism_params)["arrangement"]
    if len({round(float(a), 9) for a in arrangement.throw_angles}) <= 1:
        return None
    return [t + 1 for t in arrangement.cylinder_throws]


def _file(spec, machine, part, n_rods, key):
    from ..flexible.build import reduced_part

    if spec["file"] is not None:
        return Path(spec["file"])
    if not machine:
        raise SceneError(f"dynamics.flexible.{key}.file: give a crankmodal-flexbody .npz, or "
                         "dynamics.machine so that the machine's part is reduced here")
    return reduced_part(machine, part, spec, n_rods=n_rods)


#: the body builders' arguments (:mod:`..flexible.build`, :func:`..flexible.body.planar_body`)
#: -> their ``[dynamics.flexible.<body>]`` keys
BODY_KEYS = {"source": "file", **{f"spec.{k}": k for k in (
    "n_modes", "cutoff_hz", "damping_ratio", "interfaces")}}


def body_keys(key: str):
    """The builders' errors (:mod:`..flexible.build`: ``ParameterError`` naming ``source``,
    ``interfaces``, ``spec.n_modes``, ...; :func:`..flexible.body.planar_body`'s ``n_modes``,
    ...) re-raised under ``dynamics.flexible.<key>`` (``source`` is its ``file``)."""
    return scene_keys(f"dynamics.flexible.{key}", BODY_KEYS)


def link_length(p, role: str) -> float:
    """The four-bar's length of link ``role`` (crank, coupler, rocker), m."""
    from .keys import FOUR_BAR_LINKS

    return float(p["four_bar"]["lengths"][FOUR_BAR_LINKS.index(role)])


def make_links(p) -> dict:
    """Four-bar: ``{"crank": None, "rods": None, "links": {role: body}, "files": {role: path}}``
    from the validated ``[dynamics.flexible]`` link tables (a file, or a bar reduced here)."""
    from ...errors import InputFileError
    from ..flexible.build import link_body, reduced_bar
    from .keys import FOUR_BAR_LINKS

    out = {"crank": None, "rods": None, "links": {}, "files": {}}
    for role in FOUR_BAR_LINKS:
        spec = p["flexible"][role]
        if spec is None:
            continue
        key = f"dynamics.flexible.{role}"
        length = link_length(p, role)
        try:
            path = Path(spec["file"]) if spec["file"] is not None else \
                reduced_bar(length, spec["bar"], spec, key)
            with body_keys(role):
                out["links"][role] = link_body(path, spec, length, role)
        except (SceneError, InputFileError) as exc:
            if str(exc).startswith("dynamics."):
                raise
            raise type(exc)(f"{key}: {exc}") from None
        out["files"][role] = str(path)
    return out


def truncation_warnings(p, bodies: dict | None) -> list[str]:
    """Warnings for a flexible rocker that carries the sley (``four_bar.extra_rocker_inertia``)
    with fewer than all its stored in-plane modes: a rotary inertia on one interface needs that
    interface's static deformation shapes, which the lowest free modes lack (measured on the
    test rocker bar, the sley's swing with C and D pinned: 68.0 / 62.0 / 52.9 / 48.51 Hz with
    1 / 3 / 4 / all 6 modes, full FE 48.26 Hz)."""
    rocker = ((bodies or {}).get("links") or {}).get("rocker")
    extra = p["four_bar"]["extra_rocker_inertia"] if p["mechanism"] == "four_bar" else 0.0
    if rocker is None or not extra:
        return []
    stored = len(rocker.left_out().get("offered_hz", []))
    if rocker.n_elastic >= stored:
        return []
    text = (f"dynamics.flexible.rocker.n_modes: keeps {rocker.n_elastic} of the {stored} stored "
            f"in-plane modes of a rocker carrying the sley (four_bar.extra_rocker_inertia = "
            f"{extra:g} kg m^2): a rotary inertia on one interface needs that interface's static "
            f"deformation shapes, which the lowest modes lack (a test rocker's sley swing: "
            f"68.0 Hz with 1 mode, 48.5 Hz with all 6, FE 48.3 Hz); keep all stored modes")
    return [text]


def make_bodies(p, mechanism_params=None) -> dict | None:
    """Flexible bodies of validated ``[dynamics]`` parameters, or None when all are rigid.

    Returns ``{"crank": (body, roles) or None, "rods": [body per cylinder] or None,
    "files": {name: path}}``; for the four-bar :func:`make_links`.
    """
    from ..flexible.build import crank_body, read, rod_body
    from .keys import flexible_keys

    flex = p["flexible"]
    if not flexible_keys(p):
        return None
    if p["mechanism"] == "four_bar":
        return make_links(p)
    from ...errors import InputFileError

    radius, lengths, rows = train_geometry(p, mechanism_params)
    machine = p.get("machine")
    out = {"crank": None, "rods": None, "files": {}}
    key = "crank"
    try:
        if flex["crank"] is not None:
            path = _file(flex["crank"], machine, "crankshaft", len(rows), "crank")
            throws = _machine_throws(p, mechanism_params)
            with body_keys("crank"):
                if throws is None:
                    out["crank"] = crank_body(path, flex["crank"], rows, radius)
                else:  # multi-throw: each rod on its throw's band (.trains, issue 29)
                    out["crank"] = crank_body(path, flex["crank"], None, radius, throws=throws)
            out["files"]["crank"] = str(path)
        key = "rods"
        if flex["rods"] is not None:
            path = _file(flex["rods"], machine, "rod", 1, "rods")
            rod = read(path)[0]  # one reading, a planar body per cylinder
            rod.info["file"] = str(path)
            with body_keys("rods"):
                out["rods"] = [rod_body(rod, flex["rods"], L, f"rod_{i}", z=z)
                               for i, (L, z) in enumerate(zip(lengths, rows), start=1)]
            out["files"]["rods"] = str(path)
    except (SceneError, InputFileError) as exc:
        if str(exc).startswith("dynamics."):
            raise
        raise type(exc)(f"dynamics.flexible.{key}: {exc}") from None
    return out


def rigid_twins(bodies: dict) -> dict:
    """The same bodies with their modes frozen (:func:`.flexbuild.rigid_twin`)."""
    from ..flexible.build import rigid_twin

    out = {"crank": None, "rods": None}
    if bodies.get("links"):
        out["links"] = {role: rigid_twin(b) for role, b in bodies["links"].items()}
    if bodies.get("crank") is not None:
        body, roles = bodies["crank"]
        out["crank"] = (rigid_twin(body), roles)
    if bodies.get("rods") is not None:
        out["rods"] = [rigid_twin(b) for b in bodies["rods"]]
    return out


def flexible_key(body_name: str) -> str:
    """The ``[dynamics.flexible]`` table of a flexible body (``rod_2`` -> ``rods``)."""
    return "dynamics.flexible." + ("rods" if body_name.startswith("rod_") else body_name)


def _rms(x):
    return float(np.sqrt(np.mean(np.asarray(x) ** 2)))


def force_comparison(t, f_flex, f_rigid, rev_hz, orders) -> dict:
    """Peak, RMS and order amplitudes of a force (K, 2) flexible vs rigid, and their difference."""
    from ..results.signals import order_amplitudes

    mf, mr = np.hypot(*f_flex.T), np.hypot(*f_rigid.T)
    diff = np.hypot(*(f_flex - f_rigid).T)
    out = {"peak_n": float(mf.max()), "rigid_peak_n": float(mr.max()),
           "rms_n": _rms(mf), "rigid_rms_n": _rms(mr),
           "difference_rms_n": _rms(diff), "difference_peak_n": float(diff.max()),
           "relative_difference_rms": _rms(diff) / max(_rms(mr), 1e-300)}
    n_rev = (t[-1] - t[0]) * rev_hz
    if n_rev >= 1.0 - 1e-9:
        a = order_amplitudes(t, f_flex, rev_hz, orders)
        b = order_amplitudes(t, f_rigid, rev_hz, orders)
        out["orders"] = list(orders)
        out["order_amplitude_n"] = np.hypot(a[:, 0], a[:, 1]).tolist()
        out["rigid_order_amplitude_n"] = np.hypot(b[:, 0], b[:, 1]).tolist()
    return out


def interface_deflections(body, modal) -> dict:
    """Largest elastic in-plane displacement of each interface in the body frame, m."""
    k = body.n_elastic
    out = {}
    for name in body.info["interface_centres"]:  # the file's interfaces, not their aliases
        D = body.frames[name][1]
        u = modal[:, :k] @ D[:, :k].T
        out[name] = float(np.hypot(u[:, 0], u[:, 1]).max())
    return out


def flexible_results(mech, hist, rigid_hist, sel, rev_hz, bodies, warnings=None) -> dict:
    """The ``dynamics.flexible`` results block (see the module docstring).

    Per body also ``validity`` (its elastic deflection against its size and its dynamic stress
    against its material's yield strength, :func:`.validity.flexible_validity`; the warnings
    go to ``warnings``, a list, as :func:`crankmodal.errors.warn` does) and
    ``effective_damping`` (its lowest mode with its joints pinned, :mod:`.modal_damping`).
    """
    from ...errors import warn
    from ..flexible.modal_damping import effective_damping
    from ..results.validity import elastic_deflection, flexible_validity

    t = hist.t[sel]
    orders = list(range(13))
    res = {"bodies": {}, "files": bodies.get("files", {})}
    for b in flexible_bodies_of(mech):
        modal = hist.modal[b.name]
        d = {"n_modes": int(b.n_elastic), "frequencies_hz": b.frequencies_hz[:b.n_elastic].tolist(),
             "damping_ratio": b.zeta[:b.n_elastic].tolist(), "tilts": int(b.n_tilt),
             "mass_kg": b.mass, "inertia_kgm2": b.j0, "file": b.info.get("file"),
             "modal_amplitude_max": np.abs(modal[sel]).max(axis=0).tolist(),
             "interface_deflection_max_m": interface_deflections(b, modal[sel])}
        lo = b.left_out()
        d["not_offered_hz"] = [m["hz"] for m in lo.get("not_offered", [])]
        if "roles" in b.info:
            d["interfaces"] = b.info["roles"]
        if "extra_inertia_kgm2" in b.info:  # the four-bar's sley on a flexible rocker
            d["extra_inertia_kgm2"] = b.info["extra_inertia_kgm2"]
            for key in ("extra_inertia_frame", "extra_inertia_interface"):  # where it sits
                if key in b.info:
                    d[key] = b.info[key]
        stress = dynamic_stress(b, modal[sel], t, hist.crank_angle[sel])
        if stress is not None:
            d["dynamic_stress"] = stress
        d["validity"], texts = flexible_validity(b, elastic_deflection(b, modal[sel], t),
                                                 stress, flexible_key(b.name))
        for text in texts:
            warn(text, into=warnings)
        d["effective_damping"] = effective_damping(b)
        res["bodies"][b.name] = d
    if rigid_hist is not None:
        cmp = {"main_bearing": force_comparison(t, hist.main_bearing_force[sel],
                                                rigid_hist.main_bearing_force[sel], rev_hz,
                                                orders)}
        for name in mech.main_joints:
            if name in hist.joint_forces and len(mech.main_joints) > 1:
                cmp[name] = force_comparison(t, hist.joint_forces[name][sel],
                                             rigid_hist.joint_forces[name][sel], rev_hz, orders)
        for name in hist.joint_forces:
            if mech.kind == "four_bar" and name != mech.main_joint \
                    and name in rigid_hist.joint_forces:  # joints B, C, D besides A
                cmp[name] = force_comparison(t, hist.joint_forces[name][sel],
                                             rigid_hist.joint_forces[name][sel], rev_hz, orders)
            if name.startswith("big_end_") and name in rigid_hist.joint_forces:
                cmp[name] = force_comparison(t, hist.joint_forces[name][sel],
                                             rigid_hist.joint_forces[name][sel], rev_hz, orders)
        res["rigid"] = cmp
    return res


__all__ = ["body_keys", "dynamic_stress", "flexible_key", "flexible_results", "force_comparison",
           "interface_deflections", "link_length", "make_bodies", "make_links", "rigid_twins",
           "train_geometry", "truncation_warnings"]
