"""The ``.npz`` file of a reduced flexible body — readable with plain numpy.

Format ``crankmodal-flexbody``, version 1. Open with ``np.load(path)`` (no pickle needed). SI
units; ``n`` orthonormal modes (the six rigid ones first), ``m`` interface nodes, ``p`` mesh
points, ``e`` elements (the optional keys are present only when the reduction had the mesh, as
the ``[reduction]`` stage always has; files without them stay valid version-1 files).

=========================  ==================  ===============================================
key                        shape / dtype       meaning
=========================  ==================  ===============================================
format                     str                 ``"crankmodal-flexbody"``
version                    int                 1
name                       str                 body name
frequencies_hz             (n,)                0 for rigid modes, ascending
stiffness                  (n, n)              modal stiffness ``diag(ω²)``, 1/s²
mass                       (n, n)              modal mass (identity)
rigid                      (n,) bool           rigid-body modes
interface_names            (m,) str
interface_kinds            (m,) str            ``rigid`` or ``distributing``
interface_centres          (m, 3)              interface node positions, m
interface_axes             (m, 3)              bore axes (NaN: none)
interface_map              (m, 6, n)           ``q_r = interface_map[r] @ ξ`` (m, rad)
cb_stiffness, cb_mass      (n, n)              Craig–Bampton matrices
cb_to_modal                (n, n)              CB coordinates = ``cb_to_modal @ ξ``
n_fixed_interface_modes    int
fixed_interface_hz         (k,)
mass_kg                    float
centre_of_mass             (3,)                m
inertia                    (3, 3)              about the centre of mass, kg m²
I1 … I9                    see flexbody.py     Shabana inertia invariants of the elastic modes
n_full_dofs                int
stress_modes               (p, 6, n) optional  Pa per unit ξ, Voigt xx yy zz yz xz xy
stress_points              (p, 3) optional     m
mesh_points                (p, 3) optional     mesh points, m (part frame, undeformed)
mesh_cells                 (e, 4|10) optional  connectivity (int), meshio/VTK node order
mesh_cell_type             str optional        ``tetra`` or ``tetra10``
mode_shapes                (p, 3, n) optional  float32; nodal displacement per unit ξ, m, of
                                               every orthonormal mode (rigid first),
                                               ``u = mode_shapes @ ξ``; M-orthonormal
interface_node_counts      (m,) optional       mesh points of each interface's surface …
interface_nodes            (Σ,) optional       … concatenated (int; split by the counts)
interface_weights          (Σ,) optional       ``∫_Γ N_a dA`` of those points, m²
info_json                  str                 provenance as JSON
=========================  ==================  ===============================================
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from ..results import atomic_path
from .flexbody import FlexibleBody

FORMAT = "crankmodal-flexbody"
VERSION = 1
_ARRAYS = ("frequencies_hz", "stiffness", "mass", "rigid", "interface_centres", "interface_axes",
           "interface_map", "cb_stiffness", "cb_mass", "cb_to_modal", "fixed_interface_hz",
           "centre_of_mass", "inertia")


def save_flexbody(path, body: FlexibleBody) -> Path:
    """Write ``body`` to ``path`` (``.npz``, uncompressed); returns the path."""
    path = Path(path)
    data = {k: np.asarray(getattr(body, k)) for k in _ARRAYS}
    data.update({
        "format": np.array(FORMAT), "version": np.array(VERSION), "name": np.array(body.name),
        "interface_names": np.array(body.interface_names, dtype=str),
        "interface_kinds": np.array(body.interface_kinds, dtype=str),
        "n_fixed_interface_modes": np.array(body.n_fixed_interface_modes),
        "mass_kg": np.array(body.mass_kg), "n_full_dofs": np.array(body.n_full_dofs),
        "info_json": np.array(json.dumps(body.info, default=float)),
    })
    data.update({k: np.asarray(v) for k, v in body.invariants.items()})
    if body.stress_modes is not None:
        data["stress_modes"] = body.stress_modes
        data["stress_points"] = body.stress_points
    if getattr(body, "mode_shapes", None) is not None:
        data["mesh_points"] = np.asarray(body.mesh_points, float)
        data["mesh_cells"] = np.asarray(body.mesh_cells)
        data["mesh_cell_type"] = np.array(body.mesh_cell_type)
        data["mode_shapes"] = body.mode_shapes
        nodes = getattr(body, "interface_nodes", None)
        if nodes is not None:
            data["interface_node_counts"] = np.array([len(a) for a in nodes], int)
            data["interface_nodes"] = np.concatenate(nodes).astype(int)
            data["interface_weights"] = np.concatenate(body.interface_weights).astype(float)
    # a unique temporary name (concurrent writers do not collide); through an open file, so
    # savez appends no ".npz" to a name that lacks it
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **data)
    return path


def load_flexbody(path) -> FlexibleBody:
    """Read a body written by :func:`save_flexbody`.

    Raises
    ------
    InputFileError
        Missing file, or not a ``crankmodal-flexbody`` file of a known version.
    """
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"flexible body file not found: {path}")
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise InputFileError(f"{path}: not a readable .npz file ({exc})") from None
    with z:
        if "format" not in z.files or str(z["format"]) != FORMAT:
            raise InputFileError(f"{path}: not a {FORMAT} file")
        if int(z["version"]) != VERSION:
            raise InputFileError(f"{path}: {FORMAT} version {int(z['version'])}; "
                                 f"this crankmodal reads version {VERSION}")
        kw = {k: z[k] for k in _ARRAYS}
        return FlexibleBody(
            name=str(z["name"]), interface_names=[str(s) for s in z["interface_names"]],
            interface_kinds=[str(s) for s in z["interface_kinds"]],
            n_fixed_interface_modes=int(z["n_fixed_interface_modes"]),
            mass_kg=float(z["mass_kg"]), n_full_dofs=int(z["n_full_dofs"]),
            invariants={f"I{i}": (float(z[f"I{i}"]) if i == 1 else z[f"I{i}"])
                        for i in range(1, 10)},
            stress_modes=z["stress_modes"] if "stress_modes" in z.files else None,
            stress_points=z["stress_points"] if "stress_points" in z.files else None,
            mesh_points=z["mesh_points"] if "mode_shapes" in z.files else None,
            mesh_cells=z["mesh_cells"] if "mode_shapes" in z.files else None,
            mesh_cell_type=str(z["mesh_cell_type"]) if "mode_shapes" in z.files else None,
            mode_shapes=z["mode_shapes"] if "mode_shapes" in z.files else None,
            interface_nodes=(np.split(z["interface_nodes"], np.cumsum(z["interface_node_counts"])[:-1])
                             if "interface_nodes" in z.files else None),
            interface_weights=(np.split(z["interface_weights"],
                                        np.cumsum(z["interface_node_counts"])[:-1])
                               if "interface_weights" in z.files else None),
            info=json.loads(str(z["info_json"])), **kw)
