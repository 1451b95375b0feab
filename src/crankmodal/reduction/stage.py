"""The ``[reduction]`` scene section: Craig–Bampton reduction of the part to a flexible body.

Keys are declared in :data:`SCHEMA` (interface tables in :data:`INTERFACE_SCHEMA`). Results:
sizes, interfaces, fixed-interface and reduced free-free frequencies, the full model's
free-free frequencies and the relative differences, mass properties, timings per phase, peak
memory; the body (with its mesh and mode shapes) is written to ``out_dir/<file>`` (format:
:mod:`crankmodal.reduction.io`), its elastic modes to ``out_dir/<file stem>_modes.vtu`` (one point
vector per mode, :func:`crankmodal.reduction.export.write_modes_vtu`), and the body is handed on
as ``ctx.products["reduction"]``.
"""

from __future__ import annotations

import os
import time

from ..errors import SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table

SECTION = "reduction"
REQUIRES = ("geometry", "material")

KINDS = ("rigid", "distributing")

INTERFACE_SCHEMA: dict[str, Field] = {
    "region": Field("str", doc="named region of the part (a bearing bore or journal)"),
    "kind": Field("str", None, "rigid (RBE2-like) or distributing (RBE3-like); default: coupling",
                  choices=KINDS),
    "segments": Field("int", 1, "cut a cylindrical region into this many axial bands, one "
                      "interface each (e.g. 2 rods on one crankpin)", ge=1, le=16),
}


def _file_check(v):
    return None if v.endswith(".npz") and "/" not in v else f"must be a file name ending in .npz, got {v!r}"


SCHEMA: dict[str, Field] = {
    "interfaces": Field("tables", [], "interface nodes {region = name, kind = 'rigid'|'distributing', "
                        "segments = 1}; empty: every cylindrical region of the part"),
    "coupling": Field("str", "rigid", "default interface kind: rigid | distributing", choices=KINDS),
    "n_modes": Field("int", None, "fixed-interface normal modes to keep (default 20 if no cutoff_hz)",
                     ge=0, le=400),
    "cutoff_hz": Field("float", None, "keep every fixed-interface mode up to this frequency, Hz",
                       gt=0.0),
    "backend": Field("str", "auto", "factorisation: auto (PARDISO if installed), pardiso, superlu",
                     choices=("auto", "pardiso", "superlu")),
    "file": Field("str", "flexbody.npz", "output file in the output folder (.npz)", check=_file_check),
    "stress_modes": Field("bool", True, "store nodal stress modes (float32) in the file"),
    "compare_full": Field("bool", True, "also solve the full model free-free and compare frequencies"),
    "n_compare": Field("int", 10, "elastic modes compared with the full model", ge=1, le=200),
}


def validate(raw: dict, scene) -> dict:
    p = validate_table(SECTION, raw, SCHEMA)
    if p["n_modes"] is not None and p["cutoff_hz"] is not None:
        raise SceneError("reduction.cutoff_hz: give either n_modes or cutoff_hz, not both")
    if p["n_modes"] is None and p["cutoff_hz"] is None:
        p["n_modes"] = 20
    specs = []
    for i, t in enumerate(p["interfaces"]):
        s = validate_table(f"{SECTION}.interfaces[{i}]", t, INTERFACE_SCHEMA)
        s["kind"] = s["kind"] or p["coupling"]
        specs.append(s)
    p["interfaces"] = specs
    return p


def interface_specs(part, p: dict) -> list[dict]:
    """Interface specs of validated parameters on a part (regions split into segments)."""
    import numpy as np

    from .interfaces import split_region

    specs = p["interfaces"] or [{"region": n, "kind": p["coupling"], "segments": 1}
                                for n, r in part.regions.items() if r.cylinder is not None]
    if not specs:
        raise SceneError(f"reduction.interfaces: part {part.name!r} has no cylindrical region; "
                         f"name the interface regions (regions: {', '.join(part.regions) or 'none'})")
    out = []
    cells = np.asarray(part.mesh.cells[0].data)
    points = np.asarray(part.mesh.points, float)[:, :3]
    for i, s in enumerate(specs):
        if s["region"] not in part.regions:
            known = ", ".join(sorted(part.regions)) or "none"
            raise SceneError(f"reduction.interfaces[{i}].region: no region {s['region']!r} in part "
                             f"{part.name!r}; regions: {known}")
        if s.get("segments", 1) > 1:
            try:
                pieces = split_region(part.regions[s["region"]], points, s["segments"], cells)
            except ValueError as exc:
                raise SceneError(f"reduction.interfaces[{i}].segments: region {s['region']!r} "
                                 f"is not cylindrical ({exc})") from None
            out += [{"region": r.name, "kind": s["kind"], "region_object": r} for r in pieces]
        else:
            out.append({"region": s["region"], "kind": s["kind"]})
    return out


def interface_keys(p: dict) -> dict:
    """Scene keys of :func:`make_interfaces`' arguments for the specs of :func:`interface_specs`.

    A region split into ``segments`` bands gives that many specs, so the ``i``-th spec is not
    always the scene's ``interfaces[i]``: ``{"interfaces[j].region": "interfaces[i].region"}``.
    """
    keys, j = {}, 0
    for i, s in enumerate(p["interfaces"]):
        for _ in range(s.get("segments", 1)):
            for name in ("region", "kind"):
                keys[f"interfaces[{j}].{name}"] = f"interfaces[{i}].{name}"
            j += 1
    return keys


def run(p: dict, ctx) -> dict:
    import numpy as np

    from ..fem.memory import PeakMemory
    from ..fem.stage_common import part_and_material, timed_fe_model
    from .export import write_modes_vtu
    from .interfaces import make_interfaces
    from .io import save_flexbody
    from .reduce import reduce_body

    part, mat = part_and_material(ctx, SECTION)
    with PeakMemory() as mem:
        model, t_asm = timed_fe_model(ctx, part, mat)
        with scene_keys(SECTION, interface_keys(p)):
            itf = make_interfaces(part, interface_specs(part, p))
        with scene_keys(SECTION, {"fixed_interface_modes": "n_modes"}):
            body, cb = reduce_body(model, itf, fixed_interface_modes=p["n_modes"],
                                   cutoff_hz=p["cutoff_hz"],
                                   backend=p["backend"], mesh=part.mesh, stress=p["stress_modes"],
                                   name=part.name, info={"part": part.name, "material": mat.name})
        timings = {"assembly_s": t_asm, **body.info["timings_s"]}
        full = None
        if p["compare_full"]:
            from ..fem.modal import solve_modes

            t0 = time.perf_counter()
            with scene_keys(SECTION, {"n_modes": "n_compare"}):
                full = solve_modes(model, p["n_compare"], backend=p["backend"])
            timings["full_modal_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    path = save_flexbody(ctx.out_dir / p["file"], body)
    vtu = write_modes_vtu(path.with_name(f"{path.stem}_modes.vtu"), body)
    timings["write_s"] = time.perf_counter() - t0
    ctx.products[SECTION] = body
    fr = body.elastic_frequencies_hz
    basis_s = sum(body.info["timings_s"][k] for k in ("partition_s", "factorize_s",
                                                        "constraint_modes_s",
                                                        "fixed_interface_modes_s",
                                                        "reduced_matrices_s", "orthonormalise_s"))
    res = {
        "n_full_dofs": body.n_full_dofs,
        "n_interior_dofs": cb.n_interior,
        "n_boundary_dofs": cb.n_boundary,
        "n_fixed_interface_modes": cb.n_fixed_modes,
        "n_reduced": body.n_modes,
        "interfaces": [i.to_dict() for i in itf],
        "fixed_interface_frequencies_hz": cb.fixed_interface_hz,
        "frequencies_hz": fr,
        "rigid_body_modes": int(body.rigid.sum()),
        "mass_kg": body.mass_kg,
        "centre_of_mass_m": body.centre_of_mass,
        "inertia_kgm2": body.inertia,
        "m_orthonormality": body.info["m_orthonormality"],
        "eigen_residual": body.info["eigen_residual"],
        "backend": body.info["backend"],
        "basis_time_s": basis_s,
        "timings_s": timings,
        "peak_memory_bytes": mem.peak,
        "file": str(path),
        "modes_vtu": str(vtu),
        # relative to the output folder (file, modes_vtu: the full paths)
        "files": [os.path.relpath(path, ctx.out_dir), os.path.relpath(vtu, ctx.out_dir)],
    }
    cmp = ""
    if full is not None:
        k = min(len(full.frequencies_hz), len(fr))
        ff = full.frequencies_hz[:k]
        rel = fr[:k] / ff - 1.0
        res["full_frequencies_hz"] = full.frequencies_hz
        res["relative_difference"] = rel
        cmp = f"; vs full FE max {np.abs(rel).max() * 100:.2f} % over {k} modes"
    kinds = sorted({i.kind for i in itf})
    from ..report.quantity import quantity_range

    band = f"elastic {quantity_range(fr[0], fr[-1], 'Hz', 5)}" if len(fr) else "no elastic mode"
    res["summary"] = (f"{len(itf)} {'/'.join(kinds)} interfaces, {cb.n_fixed_modes} fixed-interface "
                      f"modes -> {body.n_modes} coordinates; {band}{cmp}; basis {basis_s:.1f} s, "
                      f"{body.n_full_dofs} DOF")
    return res
