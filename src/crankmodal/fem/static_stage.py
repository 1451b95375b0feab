"""The ``[static]`` scene section: linear static strength of the part.

Keys: ``supports`` (as in ``[modal]``; they must hold the part), ``loads`` — a list of
``{region = "...", pressure = Pa}`` (positive pushes into the surface),
``{region = "...", force = [Fx, Fy, Fz]}`` (N, spread as a uniform traction) or
``{region = "...", remote_force = [Fx, Fy, Fz], point = [x, y, z], moment = [Mx, My, Mz]}``
(N, m, N m, carried to the region by a distributing coupling) — plus ``backend`` and ``vtu``.
Results: max von Mises stress and where, max displacement, safety factors against the
material's yield and ultimate strength.
"""

from __future__ import annotations

import numpy as np

from ..errors import SceneError, scene_keys
from ..schema import Field
from ..schema import validate as validate_table
from .stage_common import BACKEND_FIELD, fe_model, part_and_material

SECTION = "static"
REQUIRES = ("geometry", "material")

SCHEMA: dict[str, Field] = {
    "supports": Field("tables", None, "supports as in [modal]; must remove every rigid-body mode"),
    "loads": Field("tables", None, "{region, pressure (Pa)} | {region, force [N]} | "
                   "{region, remote_force [N], point [m], moment [N m]} | "
                   "{region, bearing_force [N]} (a pin on a cylindrical bore, cos-distributed)"),
    "backend": BACKEND_FIELD,
    "vtu": Field("bool", True, "write displacement and stresses to static.vtu"),
}

_KINDS = ("pressure", "force", "remote_force", "bearing_force")


def validate_loads(loads, section: str = SECTION) -> list[dict]:
    """Check load tables; one line naming ``<section>.loads[i].<key>`` on error."""
    if not loads:
        raise SceneError(f"{section}.loads: is required (a list of load tables)")
    out = []
    for i, ld in enumerate(loads):
        key = f"{section}.loads[{i}]"
        allowed = {"region", "point", "moment", *_KINDS}
        unknown = set(ld) - allowed
        if unknown:
            raise SceneError(f"{key}.{min(unknown)}: unknown key; allowed: "
                             f"{', '.join(sorted(allowed))}")
        if not isinstance(ld.get("region"), str):
            raise SceneError(f"{key}.region: is required (a region name)")
        kinds = [k for k in _KINDS if k in ld]
        if len(kinds) != 1:
            raise SceneError(f"{key}: give exactly one of {', '.join(_KINDS)}")
        kind = kinds[0]
        if kind == "pressure":
            v = ld["pressure"]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
                raise SceneError(f"{key}.pressure: must be a number (Pa), got {v!r}")
        for vec in ("force", "remote_force", "bearing_force", "point", "moment"):
            if vec in ld:
                v = ld[vec]
                if (not isinstance(v, (list, tuple)) or len(v) != 3 or not all(
                        isinstance(c, (int, float)) and not isinstance(c, bool) and np.isfinite(c)
                        for c in v)):
                    raise SceneError(f"{key}.{vec}: must be 3 numbers, got {v!r}")
        if kind != "remote_force" and ({"point", "moment"} & set(ld)):
            raise SceneError(f"{key}: point/moment only go with remote_force")
        out.append({**ld, "kind": kind})
    return out


def validate(raw: dict, scene) -> dict:
    from .supports import validate_specs

    p = validate_table(SECTION, raw, SCHEMA)
    p["supports"] = validate_specs(p["supports"], SECTION)
    if not p["supports"]:
        raise SceneError(f"{SECTION}.supports: is required; a static solve needs the part held")
    p["loads"] = validate_loads(p["loads"])
    return p


def scene_loads(part, loads) -> list:
    """A :class:`~crankmodal.fem.loads.Load` per (validated) load table, labelled by its key.

    Raises
    ------
    SceneError
        Naming ``static.loads[i].<key>`` (an unknown region; a bearing force on a region that is
        not cylindrical or along its axis).
    """
    from .loads import Load
    from .supports import part_region

    out = []
    for i, ld in enumerate(loads):
        key = f"loads[{i}]"
        kind = ld["kind"]
        with scene_keys(SECTION, {"region": f"{key}.region"}):
            part_region(part, ld["region"])
        # the value's own key: a bearing load's region that is no bore is its bearing_force's fault
        keys = {"force": f"{key}.{kind}", "region": f"{key}.{kind}", "pressure": f"{key}.pressure",
                "point": f"{key}.point", "moment": f"{key}.moment"}
        with scene_keys(SECTION, keys):
            if kind == "pressure":
                load = Load.pressure(part, ld["region"], float(ld["pressure"]))
            elif kind == "force":
                load = Load.traction(part, ld["region"], ld["force"])
            elif kind == "bearing_force":
                load = Load.bearing(part, ld["region"], ld["bearing_force"])
            else:
                load = Load.remote(part, ld["region"], ld["remote_force"], ld.get("point"),
                                   ld.get("moment"))
        load.label = f"{SECTION}.{key} ({load.label})"
        out.append(load)
    return out


def load_vector(part, model, loads) -> np.ndarray:
    """Sum of the nodal forces of every load table, N, shape (3 n_points,)."""
    from .loads import as_vector

    return as_vector(scene_loads(part, loads), len(model.points))


def run(p: dict, ctx) -> dict:
    from .static import solve_static
    from .supports import select

    part, mat = part_and_material(ctx, SECTION)
    model = fe_model(ctx, part, mat)
    sup = select(part, p["supports"], SECTION)
    loads = scene_loads(part, p["loads"])
    with scene_keys(SECTION):
        res = solve_static(model, part.mesh, loads, sup, backend=p["backend"])
    f = sum(ld.vector for ld in loads)
    ctx.products[SECTION] = res
    out = res.to_dict()
    out["applied_force_n"] = f.reshape(-1, 3).sum(axis=0)
    out["material"] = mat.name
    out["warnings"] = list(model.warnings)
    if p["vtu"]:
        from .vtu import write_point_data

        data = {"displacement": res.displacement, "von_mises": res.von_mises,
                "principal": res.principal}
        out["vtu"] = str(write_point_data(ctx.out_dir / "static.vtu", part.mesh, data))
        out["files"] = ["static.vtu"]  # relative to the output folder (vtu: the full path)
    sfu = res.safety_factor_ultimate
    out["summary"] = (f"max von Mises {res.max_von_mises / 1e6:.4g} MPa at "
                      f"{np.array2string(res.max_location, precision=4)} m, max displacement "
                      f"{res.max_displacement * 1e3:.4g} mm"
                      + (f", safety factor {sfu:.3g} (ultimate)" if sfu else ""))
    return out
