"""Whether a run's contacts stayed inside their law's validity: the penetration against the
clearance and against the elastic approach of the journal in its bore.

A penalty law (``K delta**n``) stands for the elastic approach of two bodies; a penetration that
is a large part of the clearance, or many times what the elastic journal and bore would
actually approach under the same force, means the stiffness is far too low for the loads and
the orbit, impacts and peaks are those of a much softer joint. The approach of conformal
cylinders is Johnson's line-contact formula (:func:`.contact.johnson_cylinder_approach`,
``delta = F / (pi L E*) (ln(4 pi L E* dR / F) - 1)``).
"""

from __future__ import annotations

import numpy as np

from ..laws import contact

#: a penetration above this fraction of the radial clearance gives a warning
CLEARANCE_FRACTION = 0.25
#: a penetration above this multiple of the elastic approach under the peak force gives a warning
APPROACH_FACTOR = 5.0


def elastic_approach(cj, force: float, E: float, nu: float) -> tuple[float, float]:
    """Elastic approach (m) of the joint's journal in its bore under ``force`` N, and the length
    used (m): the joint's ``bearing_length`` if given, else one journal diameter (L/D = 1).

    Journal and bore of the same material (``E`` in Pa, ``nu``), radial clearance ``dR``.
    """
    L = cj.bearing_length if cj.bearing_length and cj.bearing_length > 0.0 else 2.0 * cj.journal_radius
    K = np.pi * L * contact.effective_modulus(E, nu, E, nu)
    return float(contact.johnson_cylinder_approach(force, K, cj.clearance)), L


#: how :func:`penetration_warning` names what to change: the law's own arguments (Python API);
#: a stage passes its scene keys instead (:data:`..scene.build.CONTACT_WORDS`)
LAW_WORDS = {"stiffness": "law.stiffness", "johnson_cylinder": "law = JohnsonCylinder(...)"}


def penetration_warning(cj, depth: float, force: float, E: float = 2.1e11,
                        nu: float = 0.3, words: dict | None = None) -> str | None:
    """The warning for a joint whose largest penetration ``depth`` (m), under its peak contact
    force ``force`` (N), exceeds :data:`CLEARANCE_FRACTION` of the clearance or
    :data:`APPROACH_FACTOR` times the elastic approach; None when it stays inside both.

    ``E`` (Pa) and ``nu`` are the journal's and bore's elastic constants; ``words`` names what
    to change (:data:`LAW_WORDS`, the default: the law's arguments; a stage passes its keys)."""
    words = LAW_WORDS | (words or {})
    if not depth > 0.0:
        return None
    approach, L = elastic_approach(cj, force, E, nu)
    of_clearance = depth / cj.clearance
    ratio = depth / approach if approach > 0.0 else 0.0  # no force: the clearance alone
    if of_clearance <= CLEARANCE_FRACTION and ratio <= APPROACH_FACTOR:
        return None
    from ...report.quantity import number, quantity  # 92.3 µm, not 9.23e-05 m (issue 25 #15)

    K = getattr(cj.law, "stiffness", float("nan"))  # echoed as a scene value is typed
    return (f"dynamics: joint {cj.name!r} penetrates {quantity(depth, 'm', 3)}, "
            f"{100 * of_clearance:.0f} % of its {quantity(cj.clearance, 'm', 3)} clearance "
            f"(warning above {100 * CLEARANCE_FRACTION:.0f} %) and {number(ratio, 2)} times the "
            f"elastic approach of journal and bore under its peak contact force "
            f"{quantity(force, 'N', 3)} ({quantity(approach, 'm', 2)}, Johnson's conformal "
            f"cylinders, L = {quantity(L, 'm', 3)}; warning above "
            f"{APPROACH_FACTOR:g} times): the contact law ({cj.law.name}) is far outside its "
            f"validity; raise {words['stiffness']} (now {K:.3g}) or use "
            f"{words['johnson_cylinder']}")


# ------------------------------------------------------------------ flexible bodies
#: an elastic deflection above this fraction of the body's size gives a warning: the linear
#: floating-frame model (small deformation about the undeformed shape, no geometric stiffening
#: by the axial load, linear modes) no longer holds. At 2 % a pinned beam's end slope is about
#: pi x 2 % = 0.06 rad and its chord shortens by ~0.1 % of the length (pi^2/4 (d/L)^2 L); both
#: grow with the square of the deflection.
DEFLECTION_FRACTION = 0.02


def body_size(body) -> tuple[float, str]:
    """The size a body's deflection is compared with, m, and what it is.

    The largest in-plane distance between two of its interfaces (the span the joints hold),
    or with fewer than two interfaces the in-plane diagonal of the mesh's bounding box."""
    centres = [np.asarray(c, float)[:2] for c in body.info["interface_centres"].values()]
    if len(centres) >= 2:
        c = np.array(centres)
        d = np.sqrt(((c[:, None, :] - c[None, :, :]) ** 2).sum(-1)).max()
        if d > 0.0:
            return float(d), "interface span"
    fb = body.source
    pts = None if fb is None else getattr(fb, "mesh_points", None)
    if pts is not None:
        p = np.asarray(pts, float)[:, :2]
        return float(np.hypot(*(p.max(axis=0) - p.min(axis=0)))), "bounding-box diagonal"
    return float("nan"), "unknown size"


def interface_rigid_fit(body) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The small rigid motion that best fits (least squares) the elastic displacements of the
    body's interfaces, as linear maps of the elastic coordinates ξ (body axes).

    Returns ``s_bar`` (2,), the interfaces' centroid (m, from the centre of mass), ``T`` (2, k),
    the translation per ξ (m), and ``W`` (k,), the rotation per ξ (rad): the fitted rigid
    displacement of a point ``p`` is ``(T + ẑ × (p − s_bar) W) ξ``. Needs two interfaces."""
    k = body.n_elastic
    names = list(body.info["interface_centres"])
    s = np.array([body.frames[n][0] for n in names], float)          # (m, 2)
    D = np.array([body.frames[n][1][:, :k] for n in names], float)   # (m, 2, k)
    s_bar = s.mean(axis=0)
    T = D.mean(axis=0)
    r = s - s_bar
    # rotation: sum of r x (u - T) over sum |r|^2 (the least-squares small rotation)
    W = np.einsum("m,mk->k", r[:, 0], D[:, 1] - T[1]) - np.einsum("m,mk->k", r[:, 1],
                                                                    D[:, 0] - T[0])
    return s_bar, T, W / float(np.sum(r ** 2))


def elastic_deflection(body, modal, t=None, chunk: int = 256) -> dict | None:
    """Largest in-plane elastic deflection of a flexible body over a run, m.

    With the mode shapes at the mesh nodes (a file with its mesh) and two interfaces or more,
    the deflection is each node's elastic displacement less the small rigid motion that best
    fits the interfaces' (least squares, :func:`interface_rigid_fit`): the bending the joints
    see (a pinned-pinned beam's deflection from its chord). With one interface, the
    displacement in the body's mean axes. Without mode shapes, the interfaces' displacements in
    the mean axes (a lower bound). Returns None for a body without elastic modes.

    Parameters
    ----------
    body : FlexibleBody
    modal : (K, n_modes) array
        Modal coordinates over the run (m kg^½).
    t : (K,) array, optional
        s, for ``time_s``.
    chunk : int
        Mesh nodes superposed at once (:func:`.peak_stress.peak_seminorm`).

    Returns
    -------
    dict
        ``max_m``, ``where`` (``mesh nodes, relative to the interfaces`` / ``mesh nodes, mean
        axes`` / ``interfaces, mean axes``), ``location_m`` (part coordinates) and ``time_s``.
    """
    k = body.n_elastic
    if k == 0:
        return None
    xi = np.asarray(modal, float)[:, :k]
    fb = body.source
    shapes = None if fb is None else getattr(fb, "mode_shapes", None)
    pts = None if fb is None else getattr(fb, "mesh_points", None)
    names = list(body.info["interface_centres"])
    co, so = np.cos(-body.orientation), np.sin(-body.orientation)
    R = np.array([[co, -so], [so, co]])                  # part x-y axes -> body axes
    if shapes is None or pts is None:
        best, where, loc, when = 0.0, "interfaces, mean axes", None, 0
        for n in names:
            u = xi @ body.frames[n][1][:, :k].T
            a = np.hypot(u[:, 0], u[:, 1])
            i = int(np.argmax(a))
            if a[i] > best:
                best, loc, when = float(a[i]), body.info["interface_centres"][n], i
    else:
        cols = np.asarray(body.info["mode_columns"], int)
        B = np.einsum("ij,pjk->pik", R, np.asarray(shapes, float)[:, :2, cols])  # (P, 2, k)
        if len(names) >= 2:
            s_bar, T, W = interface_rigid_fit(body)
            p = (np.asarray(pts, float)[:, :2] - body.centre) @ R.T - s_bar
            B = B - T[None] - np.stack([-p[:, 1], p[:, 0]], axis=1)[:, :, None] * W
            where = "mesh nodes, relative to the interfaces"
        else:
            where = "mesh nodes, mean axes"
        from .peak_stress import peak_seminorm  # bounds skip the nodes that cannot lead

        best, j, when, _ = peak_seminorm(B, xi, lambda u: np.hypot(u[:, 0], u[:, 1]), chunk)
        loc = np.asarray(pts)[j].tolist()
    return {"max_m": best, "where": where, "location_m": loc,
            "time_s": None if t is None else float(t[when])}


def yield_strength(body) -> tuple[float | None, str | None]:
    """The yield strength (Pa) of the body's material and the material's name, from the
    flexbody file's provenance (``info["material"]``, a name of the material library);
    ``(None, name or None)`` when the file names no material or the library has no yield for it."""
    fb = body.source
    name = None if fb is None else (getattr(fb, "info", None) or {}).get("material")
    if not name:
        return None, None
    from ...errors import ParameterError
    from ...fem.materials import material

    try:
        return material(str(name)).yield_strength, str(name)
    except ParameterError:
        return None, str(name)


def flexible_bodies_of(mech) -> list:
    """The mechanism's bodies with elastic coordinates."""
    return [b for b in mech.system.bodies if getattr(b, "n_elastic", 0) > 0]


def dynamic_stress(body, modal, t, crank_angle, material_strength=None) -> dict | None:
    """Largest von Mises stress of a flexible body over a run, from its stress modes.

    ``σ(t) = Σ_a σ_a ξ_a(t)`` over the kept elastic modes (Pa per unit ξ, stored by the
    reduction at the mesh nodes); the rigid tilts carry no stress. Returns None when the file
    holds no stress modes.
    """
    from ...reduction.io import load_flexbody
    from .peak_stress import peak_von_mises

    fb = body.source if body.source is not None else load_flexbody(body.info["file"])
    modes = getattr(fb, "stress_modes", None)
    if modes is None or body.n_elastic == 0:
        return None
    cols = np.asarray(body.info["mode_columns"], int)
    S = np.asarray(modes[:, :, cols], float)  # (p, 6, k)
    # the points whose seminorm bound can exceed the largest found only (.peak_stress)
    best, p, k, _ = peak_von_mises(S, modal[:, :body.n_elastic])
    out = {"max_von_mises_pa": best,
           "location_m": np.asarray(fb.stress_points)[p].tolist(),
           "time_s": float(t[k]),
           "crank_angle_deg": float(np.rad2deg(crank_angle[k]) % 360.0),
           "n_points": int(S.shape[0]), "n_modes": int(S.shape[2])}
    if material_strength:
        out["safety_factor"] = float(material_strength / best) if best > 0 else None
    return out


def flexible_validity(body, deflection: dict | None, stress: dict | None, key: str,
                      fraction: float = DEFLECTION_FRACTION) -> tuple[dict, list[str]]:
    """Whether a flexible body stayed inside the linear floating-frame model: its elastic
    deflection against ``fraction`` of its size (:func:`body_size`) and its dynamic stress
    (von Mises, from the stress modes) against its material's yield strength.

    Parameters
    ----------
    body : FlexibleBody
    deflection : dict or None
        :func:`elastic_deflection`.
    stress : dict or None
        :func:`dynamic_stress` (``max_von_mises_pa``), None without stress modes.
    key : str
        The body's scene table (``dynamics.flexible.coupler``), named in the warnings.

    Returns
    -------
    block : dict
        ``size_m``, ``size_of``, ``deflection_max_m``, ``deflection_fraction``,
        ``deflection_limit_fraction``, ``deflection_where``, ``max_von_mises_pa``,
        ``material``, ``yield_strength_pa``, ``stress_checked`` and ``inside`` (bool).
    warnings : list of str
    """
    size, size_of = body_size(body)
    d = None if deflection is None else deflection["max_m"]
    frac = d / size if (d is not None and size > 0) else None
    sy, mat = yield_strength(body)
    sv = None if stress is None else stress["max_von_mises_pa"]
    block = {"size_m": size, "size_of": size_of, "deflection_max_m": d,
             "deflection_fraction": frac, "deflection_limit_fraction": fraction,
             "deflection_where": None if deflection is None else deflection["where"],
             "deflection_time_s": None if deflection is None else deflection["time_s"],
             "max_von_mises_pa": sv, "material": mat, "yield_strength_pa": sy,
             "stress_checked": sv is not None and sy is not None}
    from ...report.quantity import number, quantity  # engineering prefixes, never e+NN

    out = []
    name = body.name
    if frac is not None and frac > fraction:
        out.append(f"{key}: {name} deflects {quantity(d, 'm')} elastically "
                   f"({deflection['where']}), {number(100 * frac, 3)} % of its "
                   f"{quantity(size, 'm')} {size_of} (warning above {100 * fraction:g} %): the "
                   f"linear floating-frame model (small deformation, no geometric stiffening) no "
                   f"longer holds and its forces, deflections and stresses are outside the "
                   f"model's validity")
    if sv is not None and sy is not None and sv > sy:
        out.append(f"{key}: {name}'s dynamic stress reaches {quantity(sv, 'Pa')} (von Mises, "
                   f"from its stress modes), {number(sv / sy, 3)} times the yield strength "
                   f"{quantity(sy, 'Pa')} of {mat}: a linear-elastic body would have yielded, "
                   f"the model does not hold")
    elif sv is not None and sy is None:
        why = (f"the material library has no yield strength for {mat!r}" if mat
               else "its file names no material")
        out.append(f"{key}: {name}'s dynamic stress ({quantity(sv, 'Pa')} von Mises) is not "
                   f"checked against a yield strength: {why}")
    block["inside"] = not any(w for w in out if "not checked" not in w)
    return block, out


def validity_summary(bodies: dict) -> str:
    """The summary's words on flexible bodies: each one's lowest mode with its joints held
    (:func:`.modal_damping.effective_damping`) and its effective damping, and the bodies outside
    the model's validity.

    ``bodies``: results ``dynamics.flexible.bodies`` (``validity``, ``effective_damping``)."""
    from ...report.quantity import number, quantity  # never e+NN in a summary

    parts, bad = [], []
    for name, d in bodies.items():
        e = d.get("effective_damping")
        if e:
            parts.append(f"{name} {quantity(e['frequency_hz'], 'Hz')} held at "
                         f"{', '.join(e['pinned'])}, effective damping "
                         f"{number(e['damping_ratio'], 2)} ({number(e['given_ratio'], 3)} "
                         f"given on its free-free modes)")
        v = d.get("validity") or {}
        why = []
        if v.get("deflection_fraction") is not None and \
                v["deflection_fraction"] > v["deflection_limit_fraction"]:
            why.append(f"deflects {number(100 * v['deflection_fraction'], 3)} % of its "
                       f"{v['size_of']}")
        if v.get("stress_checked") and v["max_von_mises_pa"] > v["yield_strength_pa"]:
            why.append(f"stress {quantity(v['max_von_mises_pa'], 'Pa')} > yield "
                       f"{quantity(v['yield_strength_pa'], 'Pa')}")
        if why:
            bad.append(f"{name} " + " and ".join(why))
    out = "; lowest modes: " + ", ".join(parts) if parts else ""
    if bad:
        out += ("; OUTSIDE THE LINEAR FLEXIBLE MODEL'S VALIDITY: " + "; ".join(bad)
                + " (results warnings)")
    return out


def check_flexible_bodies(mech, hist, t_start: float = 0.0, warnings: list | None = None) -> dict:
    """The flexible-body checks of a run made with the Python API (:func:`.analysis.simulate`),
    as a scene run makes them: each flexible body's :func:`flexible_validity` block over the
    samples from ``t_start`` (s) on, its warnings (naming the body: ``flexible body
    'coupler': ...``) issued as :class:`~crankmodal.errors.ModelWarning` (and appended to
    ``warnings`` if given).

    Returns
    -------
    dict
        Body name -> validity block (:func:`flexible_validity`).
    """
    from ...errors import warn

    sel = np.asarray(hist.t) >= t_start
    t = np.asarray(hist.t)[sel]
    out = {}
    for b in flexible_bodies_of(mech):
        modal = np.asarray(hist.modal[b.name])[sel]
        stress = dynamic_stress(b, modal, t, np.asarray(hist.crank_angle)[sel])
        out[b.name], texts = flexible_validity(b, elastic_deflection(b, modal, t), stress,
                                               f"flexible body {b.name!r}")
        for text in texts:
            warn(text, into=warnings)
    return out
