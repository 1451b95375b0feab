"""Mode shapes and static fields to VTU (ParaView) through meshio."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def mode_array_names(frequencies_hz) -> list[str]:
    """``mode_01_263.5Hz``-style names, one per mode."""
    return [f"mode_{i + 1:02d}_{f:.1f}Hz" for i, f in enumerate(frequencies_hz)]


def write_modes(path: str | Path, mesh, frequencies_hz, shapes: np.ndarray,
                extra_point_data: dict | None = None) -> Path:
    """Write the volume mesh with one displacement point array per mode.

    Parameters
    ----------
    path : str or Path
        ``.vtu`` file to write.
    mesh : meshio.Mesh
        The part's mesh (its tetra/tetra10 block is written).
    frequencies_hz : array_like, shape (n,)
    shapes : ndarray, shape (3 n_points, n)
        Mode shapes, node-interleaved; each is scaled to a unit maximum nodal displacement
        (the array names carry the frequency).
    extra_point_data : dict, optional
        Further point arrays (e.g. von Mises stress).
    """
    n = len(mesh.points)
    data = {}
    for name, col in zip(mode_array_names(frequencies_hz), np.asarray(shapes).T):
        u = col.reshape(n, 3)
        peak = np.linalg.norm(u, axis=1).max()
        data[name] = u / peak if peak > 0 else u
    data.update(extra_point_data or {})
    return write_point_data(path, mesh, data)


def write_point_data(path: str | Path, mesh, point_data: dict) -> Path:
    """Write the volume mesh (its tetra/tetra10 block) with the given point arrays."""
    import meshio

    from ..results import atomic_path

    block = next(c for c in mesh.cells if c.type in ("tetra", "tetra10"))
    path = Path(path)
    with atomic_path(path) as tmp:  # a killed run leaves no truncated .vtu
        meshio.write(tmp, meshio.Mesh(np.asarray(mesh.points, float), [(block.type, block.data)],
                                      point_data=point_data), binary=True)
    return path
