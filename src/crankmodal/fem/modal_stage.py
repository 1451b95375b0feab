"""The ``[modal]`` scene section: free-free or supported natural frequencies and mode shapes.

Fixed keys (../shared/SCENES.md): ``n_modes``, ``supports``. Own keys: ``band``, ``backend``,
``eigensolver``, ``tol``, ``axis``, ``vtu``. Results: ``frequencies_hz`` (elastic, ascending, ``n_modes``),
``rigid_body_modes``, ``n_dofs``, ``n_elements``, mode ``classes``, effective masses, residual
and orthogonality checks, timings per phase, peak memory; mode shapes to ``modes.vtu``.
"""

from __future__ import annotations

from ..schema import Field
from ..schema import validate as validate_table
from .stage_common import BACKEND_FIELD, part_and_material, timed_fe_model

SECTION = "modal"
REQUIRES = ("geometry", "material")


def _band_check(v):
    return None if 0 <= v[0] < v[1] else f"must be [f_min, f_max] Hz with 0 <= f_min < f_max, got {v}"


SCHEMA: dict[str, Field] = {
    "n_modes": Field("int", 12, "number of elastic (non-rigid) modes wanted", ge=1, le=500),
    "supports": Field("tables", [], "supports {box = [xmin, xmax, ymin, ymax, zmin, zmax], fix = 'xyz'} "
                      "or {region = name, fix = 'x'|'xy'|...|'radial'}; empty: free-free"),
    "band": Field("floats", None, "analysis band [f_min, f_max], Hz (flags the modes inside; "
                  "warns when the modes computed stop below f_max)",
                  length=2, check=_band_check),
    "backend": BACKEND_FIELD,
    "eigensolver": Field("str", "auto", "auto (dense for small models or many modes), lanczos "
                         "(sparse shift-invert) or dense (LAPACK, then one refinement step)",
                         choices=("auto", "lanczos", "dense")),
    "tol": Field("float", 1e-6, "largest admissible eigen-residual and M-orthogonality defect",
                 gt=0.0, lt=1.0),
    "axis": Field("floats", None, "long axis for naming modes (default: principal axis)", length=3),
    "vtu": Field("bool", True, "write the mode shapes to modes.vtu"),
}


def validate(raw: dict, scene) -> dict:
    from .supports import validate_specs

    p = validate_table(SECTION, raw, SCHEMA)
    p["supports"] = validate_specs(p["supports"], SECTION)
    return p


def run(p: dict, ctx) -> dict:
    from ..errors import scene_keys
    from .classify import classify
    from .memory import PeakMemory
    from .modal import solve_modes
    from .supports import select
    from .vtu import write_modes

    part, mat = part_and_material(ctx, SECTION)
    with PeakMemory() as mem:
        model, t_asm = timed_fe_model(ctx, part, mat)
        sup = select(part, p["supports"], SECTION)
        with scene_keys(SECTION):  # the core names its arguments: n_modes, eigensolver
            modes = solve_modes(model, p["n_modes"], sup, backend=p["backend"],
                                band=p["band"], tol=p["tol"], eigensolver=p["eigensolver"])
        classes = classify(model.points[model.used], modes.shapes.reshape(-1, 3, modes.shapes.shape[1])
                           [model.used].reshape(-1, modes.shapes.shape[1]), axis=p["axis"])
    ctx.products[SECTION] = modes
    res = modes.to_dict()
    res.update({
        "n_elements": model.n_elements,
        "element_order": model.order,
        "classes": [c["label"] for c in classes],
        "class_fractions": [{k: float(v) for k, v in c.items() if k != "label"} for c in classes],
        "supports": [{"label": s.label, "fix": s.fix, "n_nodes": len(s.nodes)} for s in sup],
        "mass_kg": modes.total_mass,
        "timings_s": {**model.timings, "assembly_total_s": t_asm, **modes.timings},
        "peak_memory_bytes": mem.peak,
        "warnings": list(model.warnings),
    })
    if p["band"] is not None and not modes.band_complete:
        from ..errors import warn

        f_top = modes.frequencies_hz[-1]
        text = (f"modal.band: the {len(modes.frequencies_hz)} modes computed reach {f_top:.1f} Hz, "
                f"below the band's {p['band'][1]:g} Hz: modes between them were not computed; "
                f"raise modal.n_modes")
        warn(text, into=res["warnings"])
    if part.cad_mass is not None:
        cad = part.cad_mass.mass(mat.rho)
        res["mass_vs_cad"] = modes.total_mass / cad - 1.0
    if p["vtu"]:
        res["vtu"] = str(write_modes(ctx.out_dir / "modes.vtu", part.mesh,
                                     modes.frequencies_hz, modes.shapes))
        res["files"] = ["modes.vtu"]  # relative to the output folder (vtu: the full path)
    from ..report.quantity import quantity_range

    f = modes.frequencies_hz
    kind = "free-free" if not sup else f"{len(sup)} supports"
    res["summary"] = (f"{len(f)} elastic modes ({kind}, {modes.rigid_body_modes} rigid), "
                      f"{quantity_range(f[0], f[-1], 'Hz', 5)}; {modes.n_dofs} DOF, "
                      f"{sum(res['timings_s'].get(k, 0.0) for k in ('assembly_total_s', 'reduce_s', 'factorize_s', 'lanczos_s', 'dense_s')):.1f} s"
                      + (" (dense eigensolver)" if modes.eigensolver == "dense" else ""))
    return res
