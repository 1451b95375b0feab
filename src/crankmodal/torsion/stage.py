"""The ``[torsion]`` scene section: a lumped torsional chain, its checks and critical speeds.

Three ways to give the chain (exactly one):

- ``inertias`` (kg m^2) + ``stiffnesses`` (N m/rad): the fixed keys of the scene contract;
- ``inertias`` + ``segments``: shaft segments ``{diameter, length, G, bore}`` between rotors;
- a crank geometry: ``machine = "..."`` (whose ``[torsion]`` table supplies the rest) or the
  ``throw``/``flywheel`` tables and ``G``/``density`` given in the scene.

Results: ``exact_hz``, ``holzer_hz``, ``two_rotor_hz`` (fixed names), node positions, mode shapes,
the Holzer tables and the critical-speed check. Only numpy/scipy are imported (matplotlib for
figures, inside the plotting functions).
"""

from __future__ import annotations

import numpy as np

from ..errors import NumericalError, SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table
from .critical_speeds import MAX_ORDER, ORDER_TYPES
from .equivalent_length import THROW_FORMS
from .inertias import SEED_RECIPROCATING_FACTOR

SECTION = "torsion"
REQUIRES = ()


def _range_check(v):
    return None if v[0] < v[1] else f"must be [min, max] with min < max, got {v}"


SCHEMA: dict[str, Field] = {
    "machine": Field("str", None, "machine file whose [torsion] table gives the crank geometry"),
    "inertias": Field("floats", None, "rotor inertias in order along the shaft, kg m^2", gt=0.0),
    "stiffnesses": Field("floats", None, "shaft stiffness between consecutive rotors, N m/rad", gt=0.0),
    "segments": Field("tables", None, "shaft segments between rotors: {diameter, length, G, bore} (m, Pa)"),
    "fixed_end": Field("bool", False, "true: the end before rotor 1 is fixed (first spring to the wall)"),
    "labels": Field("strs", None, "rotor names"),
    "G": Field("float", None, "shear modulus of the crank (geometry) or default of segments, Pa", gt=0.0),
    "density": Field("float", None, "density of the crank and flywheel, kg/m^3", gt=0.0),
    "n_throws": Field("int", 1, "identical throws before the flywheel", ge=1, le=64),
    "equivalent_length_form": Field("str", "seed004", "throw formula coefficients", choices=tuple(THROW_FORMS)),
    "reference_diameter": Field("float", None, "diameter the equivalent length refers to, m (default journal)", gt=0.0),
    "throw": Field("table", None, "crank throw dimensions and masses (see [torsion.throw] keys)"),
    "flywheel": Field("table", None, "flywheel disc: diameter, thickness, bore (m)"),
    "two_rotor_flywheel": Field("str", "auto", "end rotor kept as the flywheel in the two-rotor reduction",
                                choices=("auto", "first", "last")),
    "order_type": Field("str", "compressor", "integer orders (compressor, two_stroke) or half orders (four_stroke)",
                        choices=ORDER_TYPES),
    "max_order": Field("float", 12.0, "highest excitation order", gt=0.0, le=MAX_ORDER),
    "speed_range_rpm": Field("floats", None, "running-speed range [min, max], rpm (default [0, 1.25 x operating])",
                             ge=0.0, length=2, check=_range_check),
    "operating_speed_rpm": Field("float", None, "operating speed, rpm", gt=0.0),
    "required_margin": Field("float", 0.10, "separation wanted between critical and operating speed (fraction)",
                             ge=0.0, lt=1.0),
    "forced": Field("table", None, "steady-state forced response of the chain (see forced_stage.SCHEMA)"),
}

THROW_SCHEMA: dict[str, Field] = {
    "journal_diameter": Field("float", doc="d_j, m", gt=0.0),
    "journal_length": Field("float", doc="B, journal length each side of the throw (eq. 1 counts 2B), m", ge=0.0),
    "journal_bore": Field("float", 0.0, "m", ge=0.0),
    "crankpin_diameter": Field("float", doc="d_p, m", gt=0.0),
    "crankpin_length": Field("float", doc="l_p, m", gt=0.0),
    "crankpin_bore": Field("float", 0.0, "m", ge=0.0),
    "crank_radius": Field("float", doc="R, m", gt=0.0),
    "web_thickness": Field("float", doc="T, each web, m", gt=0.0),
    "web_width": Field("float", doc="W, m", gt=0.0),
    "web_below_axis": Field("float", doc="web outline extent from the shaft axis away from the pin, m", ge=0.0),
    "web_beyond_axis": Field("float", doc="web outline extent from the shaft axis towards and past the pin, m", gt=0.0),
    "reciprocating_mass": Field("float", doc="piston, crosshead, nuts, 1/3 of the rod, kg", ge=0.0),
    "reciprocating_factor": Field("float", SEED_RECIPROCATING_FACTOR, "seed 004 eq. 2 factor", gt=0.0, le=1.0),
    "big_end_mass": Field("float", doc="rotating 2/3 of the rod, kg", ge=0.0),
}

FLYWHEEL_SCHEMA: dict[str, Field] = {
    "diameter": Field("float", doc="m", gt=0.0),
    "thickness": Field("float", doc="m", gt=0.0),
    "bore": Field("float", 0.0, "m", ge=0.0),
}

SEGMENT_SCHEMA: dict[str, Field] = {
    "diameter": Field("float", doc="m", gt=0.0),
    "length": Field("float", doc="m", gt=0.0),
    "G": Field("float", None, "Pa (default: torsion.G)", gt=0.0),
    "bore": Field("float", 0.0, "m", ge=0.0),
}


def _bore_check(key: str, table: dict, outer: str, inner: str) -> None:
    if not table[inner] < table[outer]:
        raise SceneError(f"{key}.{inner}: must be < {outer} ({table[outer]:g} m), got {table[inner]:g}")


def _mode(p: dict) -> str:
    geometry = p["throw"] is not None or p["flywheel"] is not None
    if geometry:
        if p["inertias"] is not None or p["stiffnesses"] is not None or p["segments"] is not None:
            raise SceneError(
                "torsion.inertias: give either a chain (inertias + stiffnesses or segments) or a crank "
                "geometry (machine, or throw + flywheel), not both"
            )
        for k in ("throw", "flywheel", "G", "density"):
            if p[k] is None:
                raise SceneError(f"torsion.{k}: is required for a crank geometry (or name a machine)")
        for k in ("fixed_end", "labels"):
            if p[k]:
                raise SceneError(f"torsion.{k}: applies to a chain given by inertias, not to a crank geometry")
        return "geometry"
    if p["inertias"] is None:
        raise SceneError(
            "torsion.inertias: is required (kg m^2, with stiffnesses or segments), "
            "or name a machine with a [torsion] table"
        )
    if (p["stiffnesses"] is None) == (p["segments"] is None):
        raise SceneError("torsion.stiffnesses: give exactly one of stiffnesses (N m/rad) or segments")
    return "segments" if p["segments"] is not None else "chain"


def build(p: dict):
    """The chain (and crank model, for a geometry) from validated parameters."""
    from .chain import TorsionalChain
    from .crank_model import crank_model
    from .equivalent_length import segments_stiffness

    mode = p["mode"]
    if mode == "geometry":
        with scene_keys(SECTION):  # the chain's own check of the computed inertias/stiffnesses
            model = crank_model(p["throw"], p["flywheel"], p["G"], p["density"], p["n_throws"],
                                p["equivalent_length_form"], p["reference_diameter"])
        return model.chain, model
    lengths = None
    if mode == "segments":
        stiff = segments_stiffness(p["segments"])
        lengths = [s["length"] for s in p["segments"]]
        n_need = len(p["inertias"]) - (0 if p["fixed_end"] else 1)
        if len(stiff) != n_need:
            raise SceneError(
                f"torsion.segments: needs {n_need} segments for {len(p['inertias'])} inertias, got {len(stiff)}"
            )
    else:
        stiff = p["stiffnesses"]
    labels = p["labels"] or []
    if labels and len(labels) != len(p["inertias"]):
        raise SceneError(f"torsion.labels: needs one name per rotor of inertias ({len(p['inertias'])}), "
                         f"got {len(labels)}")
    with scene_keys(SECTION):
        chain = TorsionalChain(p["inertias"], stiff, fixed_end=p["fixed_end"], lengths=lengths,
                               labels=list(labels))
    return chain, None


def validate(raw: dict, scene) -> dict:
    """Check the ``[torsion]`` table; the chain is built once here so every error shows at check time."""
    p = validate_table(SECTION, raw, SCHEMA)
    p["mode"] = _mode(p)
    if p["mode"] == "geometry":
        p["throw"] = validate_table("torsion.throw", p["throw"], THROW_SCHEMA)
        p["flywheel"] = validate_table("torsion.flywheel", p["flywheel"], FLYWHEEL_SCHEMA)
        _bore_check("torsion.throw", p["throw"], "journal_diameter", "journal_bore")
        _bore_check("torsion.throw", p["throw"], "crankpin_diameter", "crankpin_bore")
        _bore_check("torsion.flywheel", p["flywheel"], "diameter", "bore")
        if not p["throw"]["web_beyond_axis"] > p["throw"]["crank_radius"]:
            raise SceneError("torsion.throw.web_beyond_axis: must be > crank_radius (the web carries the pin)")
    elif p["mode"] == "segments":
        segs = []
        for i, s in enumerate(p["segments"]):
            s = validate_table(f"torsion.segments[{i}]", s, SEGMENT_SCHEMA)
            if s["G"] is None:
                if p["G"] is None:
                    raise SceneError(f"torsion.segments[{i}].G: is required (Pa) when torsion.G is not given")
                s["G"] = p["G"]
            _bore_check(f"torsion.segments[{i}]", s, "diameter", "bore")
            segs.append(s)
        p["segments"] = segs
    if p["speed_range_rpm"] is None and p["operating_speed_rpm"] is not None:
        p["speed_range_rpm"] = [0.0, 1.25 * p["operating_speed_rpm"]]
    from .critical_speeds import excitation_orders

    with scene_keys(SECTION):
        excitation_orders(p["order_type"], p["max_order"])
    chain, model = build(p)
    if p["forced"] is not None:
        from .forced_stage import validate as validate_forced

        p["forced"] = validate_forced(p, scene, chain, model)
    return p


def run(p: dict, ctx) -> dict:
    """Solve the chain three ways, check the critical speeds, write tables and figures."""
    from ..results import write_atomic
    from .chain import exact_modes
    from .critical_speeds import critical_speeds
    from .holzer import holzer
    from .two_rotor import reduce_to_two_rotors

    chain, model = build(p)
    exact = exact_modes(chain)
    hz = holzer(chain)
    rel = np.abs(hz.frequencies_hz - exact.frequencies_hz) / exact.frequencies_hz
    if len(rel) and rel.max() > 1e-6:
        raise NumericalError(
            f"torsion: Holzer and eigen solution differ by {rel.max():.1e} (relative); the chain's "
            "inertias/stiffnesses span too many decades"
        )
    with scene_keys(SECTION, {"flywheel": "two_rotor_flywheel"}):
        two = reduce_to_two_rotors(chain, p["two_rotor_flywheel"])
    crit = None
    if p["speed_range_rpm"] is not None:
        with scene_keys(SECTION, {"operating_rpm": "operating_speed_rpm"}):
            crit = critical_speeds(exact.frequencies_hz, p["order_type"], p["max_order"],
                                   p["speed_range_rpm"], p["operating_speed_rpm"],
                                   p["required_margin"])

    out = ctx.out_dir
    text = "\n\n".join(hz.table_text(m) for m in range(len(hz.frequencies_hz)))
    write_atomic(out / "torsion_holzer_tables.txt", text + "\n")
    figures = []
    if ctx.figures:
        from .plots import plot_campbell, plot_holzer_residual, plot_mode_shapes

        figures.append(plot_holzer_residual(hz, out / "torsion_holzer_residual.png").name)
        figures.append(plot_mode_shapes(chain, exact, out / "torsion_mode_shapes.png").name)
        if crit is not None:
            figures.append(plot_campbell(crit, out / "torsion_campbell.png").name)
    ctx.products[SECTION] = {"chain": chain, "modes": exact, "holzer": hz, "two_rotor": two,
                             "critical_speeds": crit, "crank_model": model}

    res = {
        "exact_hz": exact.frequencies_hz,
        "holzer_hz": hz.frequencies_hz,
        "two_rotor_hz": None if two is None else two.frequency_hz,
        "input": p["mode"],
        "boundary": "fixed-free" if chain.fixed_end else "free-free",
        "rigid_body_modes": exact.n_rigid,
        "holzer_vs_exact_max_rel": float(rel.max()) if len(rel) else 0.0,
        "mode_shapes": exact.shapes,
        "nodes": exact.nodes,
        "holzer_nodes": hz.nodes,
        "holzer_tables": hz.tables[:3],  # first three modes; all in torsion_holzer_tables.txt
        "two_rotor": None if two is None else two.to_dict(),
        "chain": chain.to_dict(),
        "critical_speeds": None if crit is None else crit.to_dict(),
        "files": ["torsion_holzer_tables.txt", *figures],
    }
    if model is not None:
        res["crank_model"] = model.to_dict()
    if p["forced"] is not None:
        from .forced_stage import run as run_forced

        res["forced"] = run_forced(p["forced"], ctx, chain)
        res["files"] += res["forced"]["files"]
        if res["forced"]["warnings"]:
            res.setdefault("warnings", []).extend(res["forced"]["warnings"])
    beside = beside_cad_and_fe(res, ctx, p["n_throws"])
    if beside:
        res.update(beside)
    res["summary"] = _summary(res, crit)
    return res


def beside_cad_and_fe(res: dict, ctx, n_throws: int = 1) -> dict:
    """The CAD polar inertia and the first FE torsional mode of the scene's own crank, if any.

    When the scene also has ``[geometry]`` (a crankshaft, axis z) and ``[material]``, the polar
    inertia of the CAD solid about the shaft axis is put beside the lumped model's solid parts
    (crankpins, webs, flywheel; the reciprocating and rod equivalents are not in the CAD), in
    total and per rotor (the mesh cut at the flywheel's crank-side face). When it
    has ``[modal]``, the first mode the FE classifier calls torsion is put beside the two-rotor,
    Holzer and exact-chain frequencies.
    """
    from .fe_compare import compare_with_fe
    from .inertias import inertia_about_axis

    out = {}
    part, mat = ctx.products.get("geometry"), ctx.products.get("material")
    if getattr(part, "cad_mass", None) is not None and hasattr(mat, "rho"):
        cad = {"cad_polar_inertia_kgm2": inertia_about_axis(part.cad_mass, mat.rho, (0, 0, 0),
                                                            (0, 0, 1)),
               "part": part.name}
        model = res.get("crank_model")
        if model:
            t = model["throw_inertias_kgm2"]
            throws = n_throws * (t["crankpin"] + t["webs"])
            lumped = throws + model["flywheel_inertia_kgm2"]
            cad["lumped_solid_inertia_kgm2"] = lumped
            cad["lumped_vs_cad"] = lumped / cad["cad_polar_inertia_kgm2"] - 1.0
            fw = part.regions.get("flywheel_face")
            if fw is not None:  # per rotor: cut the meshed solid at the flywheel's crank-side face
                from .mesh_inertias import slab_axial_inertias

                pts = part.mesh.points
                z_cut = float(pts[fw.nodes, 2].mean())
                slabs = slab_axial_inertias(pts, part.mesh.cells[0].data, mat.rho, [z_cut],
                                            (0, 0, 0), (0, 0, 1))
                cad["rotors"] = [
                    {"rotor": "throws (with journals and stubs)", "cut_z_m": z_cut,
                     "cad_kgm2": float(slabs[0]),
                     "lumped_kgm2": throws},
                    {"rotor": "flywheel", "cut_z_m": z_cut, "cad_kgm2": float(slabs[1]),
                     "lumped_kgm2": model["flywheel_inertia_kgm2"]},
                ]
        out["cad_inertia"] = cad
    modal = ctx.results.get("modal")
    if modal and modal.get("classes"):
        classes = ["torsion" if c.startswith("torsion") else "other" for c in modal["classes"]]
        out["fe_comparison"] = compare_with_fe(res, modal["frequencies_hz"], classes)
    return out


def _summary(res: dict, crit) -> str:
    s = (f"{len(res['chain']['inertias_kgm2'])} rotors {res['boundary']}: first mode exact "
         f"{res['exact_hz'][0]:.4g} Hz, Holzer {res['holzer_hz'][0]:.4g} Hz")
    if res["two_rotor_hz"] is not None:
        s += f", two-rotor {res['two_rotor_hz']:.4g} Hz"
    near = crit.nearest() if crit is not None else None
    if res.get("forced"):
        s += "; forced: " + res["forced"]["summary"]
    if near is not None:
        s += (f"; nearest critical {near['speed_rpm']:.5g} rpm (mode {near['mode']}, order {near['order']:g}, "
              f"{100 * near['margin']:+.1f} % of operating)")
    return s
