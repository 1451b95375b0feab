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
import zlib
from pathlib import Path

import numpy as np

from ..errors import FileMemberError, InputFileError
from ..results import atomic_path
from .flexbody import FlexibleBody

FORMAT = "crankmodal-flexbody"
VERSION = 1
_ARRAYS = ("frequencies_hz", "stiffness", "mass", "rigid", "interface_centres", "interface_axes",
           "interface_map", "cb_stiffness", "cb_mass", "cb_to_modal", "fixed_interface_hz",
           "centre_of_mass", "inertia")


def save_flexbody(path, body: FlexibleBody) -> Path:
    """Write ``body`` to ``path`` (``.npz``, uncompressed, atomically); returns the path.

    Parameters
    ----------
    path : str or Path
        File name; written as given (``np.savez`` would append ``.npz`` to a name without it).
    body : FlexibleBody
        A reduced body (:func:`~crankmodal.reduction.reduce.reduce_body` or :func:`load_flexbody`).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ParameterError
        ``path`` is no file name, or ``body`` is not a reduced body.
    """
    from ..arguments import instance
    from ..arguments import path as path_argument

    path_argument("path", path)
    instance("body", body, FlexibleBody, "a reduced body (reduce_body, load_flexbody)")
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


#: Highest natural frequency a file may hold, Hz: the highest mode of a steel tetrahedron of
#: 10 µm (the smallest length crankmodal meshes is 1 µm; wave speed / edge = 5e8 Hz) is below it,
#: so a frequency above it is a damaged file, not a part.
MAX_FREQUENCY_HZ = 1e9

#: The members every file holds (the optional ones are checked when present).
REQUIRED = ("format", "version", "name", *_ARRAYS, "interface_names", "interface_kinds",
            "n_fixed_interface_modes", "mass_kg", "n_full_dofs", "info_json",
            *(f"I{i}" for i in range(1, 10)))


class FlexbodyFileError(FileMemberError):
    """A flexbody file that cannot be trusted: unreadable, not a flexbody, or a member of the
    wrong kind, shape or value. The message names the file and the member.

    Attributes
    ----------
    path : str
        The file.
    member : str
        The offending member (``""``: the file as a whole).
    text : str
        What is wrong with it.
    """


class _Members:
    """Checked reads of the members of an open ``.npz`` (every failure a FlexbodyFileError)."""

    def __init__(self, path: Path, z):
        self.path, self.z = path, z

    def fail(self, name: str, text: str) -> FlexbodyFileError:
        return FlexbodyFileError(self.path, name, text)

    def has(self, name: str) -> bool:
        return name in self.z.files

    def raw(self, name: str) -> np.ndarray:
        if name not in self.z.files:
            raise self.fail(name, f"missing (every {FORMAT} file has it)")
        try:
            return self.z[name]
        except ValueError as exc:
            if "allow_pickle" in str(exc) or "pickled" in str(exc):
                raise self.fail(name, "holds pickled Python objects; crankmodal never unpickles "
                                "a file (numbers and text only)") from None
            raise self.fail(name, f"unreadable ({exc})") from None
        except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
            raise self.fail(name, f"unreadable, the file is damaged ({exc})") from None
        except MemoryError:  # a header declaring an absurd shape
            raise self.fail(name, "declares an array larger than the memory available") from None

    def text(self, name: str, choices=None) -> str:
        a = self.raw(name)
        if a.ndim != 0 or a.dtype.kind != "U":
            raise self.fail(name, f"must be a text, got {_kind(a)}")
        if choices is not None and str(a) not in choices:
            raise self.fail(name, f"must be one of {', '.join(choices)}, got {str(a)!r}")
        return str(a)

    def texts(self, name: str, n: int) -> list[str]:
        a = self.raw(name)
        if a.shape != (n,) or (n and a.dtype.kind != "U"):
            raise self.fail(name, f"must be {n} texts, got {_kind(a)}")
        return [str(s) for s in a]

    def integer(self, name: str, lo: int, hi: float = np.inf) -> int:
        a = self.raw(name)
        if a.ndim != 0 or a.dtype.kind not in "iu":
            raise self.fail(name, f"must be an integer, got {_kind(a)}")
        if not lo <= int(a) <= hi:
            raise self.fail(name, f"must be in [{lo}, {hi:g}], got {int(a)}")
        return int(a)

    def numbers(self, name: str, shape: tuple, nan_ok: bool = False, lo: float | None = None,
                hi: float | None = None, dtype=float) -> np.ndarray:
        """A real array of ``shape`` (None: any length), finite (NaN too with ``nan_ok``),
        within ``[lo, hi]``."""
        a = self.raw(name)
        if a.dtype.kind not in "fiu" or a.ndim != len(shape) or any(
                s is not None and s != t for s, t in zip(shape, a.shape)):
            raise self.fail(name, f"must be real numbers of shape {_shape(shape)}, got {_kind(a)}")
        bad = ~np.isfinite(a) & ~(np.isnan(a) if nan_ok else False)
        if np.any(bad):
            raise self.fail(name, f"holds a non-finite value {_at(a, bad)} ({int(bad.sum())} "
                            "such values)")
        for side, bound, out in ((">=", lo, None if lo is None else a < lo),
                                 ("<=", hi, None if hi is None else a > hi)):
            if out is not None and np.any(out):
                raise self.fail(name, f"must be {side} {bound:g}, got {_at(a, out)}")
        return a.astype(dtype, copy=False)

    def indices(self, name: str, shape: tuple, below: int) -> np.ndarray:
        a = self.raw(name)
        if a.dtype.kind not in "iu" or a.ndim != len(shape) or any(
                s is not None and s != t for s, t in zip(shape, a.shape)):
            raise self.fail(name, f"must be integers of shape {_shape(shape)}, got {_kind(a)}")
        if a.size and (a.min() < 0 or a.max() >= below):
            raise self.fail(name, f"must index 0 to {below - 1}, got {int(a.min())} to "
                            f"{int(a.max())}")
        return a


def _kind(a: np.ndarray) -> str:
    return f"{a.dtype} of shape {a.shape}"


def _shape(shape: tuple) -> str:
    return "(" + ", ".join("any" if s is None else str(s) for s in shape) + (",)" if len(shape) == 1 else ")")


def _at(a: np.ndarray, mask: np.ndarray) -> str:
    """The first value of ``a`` where ``mask``, and its index."""
    if a.ndim == 0:
        return f"{float(a):g}"
    i = np.unravel_index(int(np.argmax(mask)), a.shape)
    return f"{float(a[i]):g} at {list(map(int, i))}"


def _open(path: Path):
    """The NpzFile at ``path``, or a FlexbodyFileError saying why it is not one."""
    if not path.is_file():
        raise InputFileError(f"flexible body file not found: {path}")
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head[:2] != b"PK":  # np.load would try it as a pickle or a bare .npy
        what = "it is empty" if not head else f"not a zip archive: it starts with {head!r}"
        raise FlexbodyFileError(path, "", f"not a readable .npz file ({what})")
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
        raise FlexbodyFileError(path, "", f"not a readable .npz file ({exc})") from None
    return z


def load_flexbody(path) -> FlexibleBody:
    """Read a body written by :func:`save_flexbody`, validating every member.

    Parameters
    ----------
    path : str or Path
        A ``crankmodal-flexbody`` ``.npz`` file.

    Returns
    -------
    FlexibleBody
        The reduced body: its matrices, interfaces, invariants and stress modes (SI units).

    The file is untrusted: each member is checked for its kind (text, integer, real numbers;
    never pickled objects), its shape against the body's ``n`` modes, ``m`` interfaces and ``p``
    mesh points, finiteness (NaN only in ``interface_axes``), and its physical range: natural
    frequencies in ``[0, MAX_FREQUENCY_HZ]``, positive mass, modal masses and ``I1``, mesh and
    interface indices inside the mesh, ``info_json`` a JSON object.

    Raises
    ------
    ParameterError
        ``path`` is no file name.
    InputFileError
        Missing file.
    FlexbodyFileError
        (an InputFileError) naming the file and the member: unreadable or damaged file, not a
        ``crankmodal-flexbody`` file of a known version, or a member that is missing, of the
        wrong kind or shape, non-finite, or out of its physical range.
    """
    from ..arguments import path as path_argument

    path = Path(path_argument("path", path))
    z = _open(path)
    with z:
        r = _Members(path, z)
        if not r.has("format") or r.raw("format").dtype.kind != "U" or str(r.raw("format")) != FORMAT:
            raise FlexbodyFileError(path, "", f"not a {FORMAT} file (no member 'format' = {FORMAT!r})")
        version = r.integer("version", 0)
        if version != VERSION:
            raise FlexbodyFileError(path, "version", f"{FORMAT} version {version}; this "
                                    f"crankmodal reads version {VERSION}")
        return FlexibleBody(**_members(r))


def _members(r: _Members) -> dict:
    """The FlexibleBody keywords of a validated file."""
    f = r.numbers("frequencies_hz", (None,), lo=0.0, hi=MAX_FREQUENCY_HZ)
    n = len(f)
    if n == 0:
        raise r.fail("frequencies_hz", "holds no mode")
    rigid = r.raw("rigid")
    if rigid.dtype != bool or rigid.shape != (n,):
        raise r.fail("rigid", f"must be {n} booleans (one per mode), got {_kind(rigid)}")
    ne = int((~rigid).sum())
    raw_names = r.raw("interface_names")
    if raw_names.ndim != 1:
        raise r.fail("interface_names", f"must be a list of texts, got {_kind(raw_names)}")
    names = r.texts("interface_names", len(raw_names))
    m = len(names)
    if len(set(names)) != m:
        raise r.fail("interface_names", f"names an interface twice: {names}")
    kw = {"name": r.text("name"), "frequencies_hz": f, "rigid": rigid,
          "interface_names": names}
    kinds = r.texts("interface_kinds", m)
    bad = [k for k in kinds if k not in ("rigid", "distributing")]
    if bad:
        raise r.fail("interface_kinds", f"must be rigid or distributing, got {bad[0]!r}")
    kw["interface_kinds"] = kinds
    for name in ("stiffness", "cb_stiffness", "cb_mass", "cb_to_modal"):
        kw[name] = r.numbers(name, (n, n))
    kw["mass"] = r.numbers("mass", (n, n))
    if not np.all(np.diag(kw["mass"]) > 0):
        raise r.fail("mass", "modal masses (its diagonal) must be > 0")
    kw["interface_centres"] = r.numbers("interface_centres", (m, 3))
    kw["interface_axes"] = r.numbers("interface_axes", (m, 3), nan_ok=True)
    kw["interface_map"] = r.numbers("interface_map", (m, 6, n))
    k = r.integer("n_fixed_interface_modes", 0, n)
    kw["n_fixed_interface_modes"] = k
    kw["fixed_interface_hz"] = r.numbers("fixed_interface_hz", (k,), lo=0.0, hi=MAX_FREQUENCY_HZ)
    kw["mass_kg"] = float(r.numbers("mass_kg", ()))
    if not kw["mass_kg"] > 0:
        raise r.fail("mass_kg", f"must be > 0 kg, got {kw['mass_kg']:g}")
    kw["centre_of_mass"] = r.numbers("centre_of_mass", (3,))
    kw["inertia"] = r.numbers("inertia", (3, 3))
    kw["n_full_dofs"] = r.integer("n_full_dofs", 1)
    shapes = {"I1": (), "I2": (3,), "I3": (3, ne), "I4": (3, ne), "I5": (3, ne, ne),
              "I6": (ne, ne), "I7": (3, 3), "I8": (3, 3, ne), "I9": (3, 3, ne, ne)}
    inv = {name: r.numbers(name, shape) for name, shape in shapes.items()}
    inv["I1"] = float(inv["I1"])
    if not inv["I1"] > 0:
        raise r.fail("I1", f"the mass invariant must be > 0 kg, got {inv['I1']:g}")
    kw["invariants"] = inv
    try:
        info = json.loads(r.text("info_json"))
    except json.JSONDecodeError as exc:
        raise r.fail("info_json", f"not valid JSON ({exc})") from None
    if not isinstance(info, dict):
        raise r.fail("info_json", f"must be a JSON object, got {type(info).__name__}")
    kw["info"] = info
    kw.update(_optional_members(r, n, m))
    return kw


def _optional_members(r: _Members, n: int, m: int) -> dict:
    """The stress modes, and the mesh with its mode shapes and interface nodes, when present."""
    kw = {}
    if r.has("stress_modes") or r.has("stress_points"):
        kw["stress_points"] = r.numbers("stress_points", (None, 3))
        kw["stress_modes"] = r.numbers("stress_modes", (len(kw["stress_points"]), 6, n),
                                       dtype=r.raw("stress_modes").dtype)
    if not r.has("mode_shapes"):
        return kw
    pts = r.numbers("mesh_points", (None, 3))
    p = len(pts)
    kind = r.text("mesh_cell_type", ("tetra", "tetra10"))
    kw.update(mesh_points=pts, mesh_cell_type=kind,
              mesh_cells=r.indices("mesh_cells", (None, 4 if kind == "tetra" else 10), p),
              mode_shapes=r.numbers("mode_shapes", (p, 3, n), dtype=r.raw("mode_shapes").dtype))
    if r.has("interface_nodes"):
        counts = r.indices("interface_node_counts", (m,), p + 1)
        total = int(counts.sum())
        nodes = r.indices("interface_nodes", (total,), p)
        # not >= 0: a curved P2 triangle's corner nodes carry slightly negative areas
        weights = r.numbers("interface_weights", (total,))
        cuts = np.cumsum(counts)[:-1]
        kw.update(interface_nodes=np.split(nodes, cuts), interface_weights=np.split(weights, cuts))
    return kw
