"""What the FE stages share: the Part and Material from earlier stages, one assembled model."""

from __future__ import annotations

import time

from ..errors import SceneError
from ..schema import Field

BACKEND_FIELD = Field("str", "auto", "factorisation: auto (PARDISO if installed), pardiso, superlu",
                      choices=("auto", "pardiso", "superlu"))


def part_and_material(ctx, section: str):
    """The Part of ``[geometry]`` and the Material of ``[material]``."""
    from ..part import Part

    part = ctx.products.get("geometry")
    if isinstance(part, dict):  # a geometry stage may hand over several parts
        part = part.get("part", next(iter(part.values()), None))
    if not isinstance(part, Part):
        raise SceneError(f"[{section}] needs a part from [geometry]; got {type(part).__name__}")
    mat = ctx.products.get("material")
    if mat is None:
        raise SceneError(f"[{section}] needs a [material] section")
    return part, mat


def fe_model(ctx, part, mat):
    """Assemble K and M once per (part, material) and keep them for later stages."""
    from .assembly import assemble

    cache = ctx.products.setdefault("fe_model", {})
    key = (id(part), id(mat))
    if key not in cache:
        cache.clear()
        cache[key] = assemble(part, mat)
    return cache[key]


def timed_fe_model(ctx, part, mat):
    """:func:`fe_model` and the wall time it took, s (about 0 when an earlier stage assembled it)."""
    t0 = time.perf_counter()
    model = fe_model(ctx, part, mat)
    return model, time.perf_counter() - t0
