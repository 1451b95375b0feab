"""Reference mode shapes for the MAC matrix, read from an untrusted file and checked whole.

:func:`load_reference` reads another crankmodal run's ``modes.vtu`` or an ``.npz`` of test modes
and refuses anything it cannot use — a file numpy cannot read without unpickling, a missing
member, shapes that do not match the points, NaN or infinite values — with a
:class:`~crankmodal.errors.ParameterError` naming the member. The ``[report]`` stage calls it
while validating the scene, so a bad reference stops the run before any mesh is built or solved.
"""

from __future__ import annotations

import re
import zipfile
from pathlib import Path

import numpy as np

from ..errors import ParameterError

#: the argument every error names (the stage relabels it ``report.reference``)
ARGUMENT = "path"

#: point arrays of a crankmodal ``modes.vtu``: ``mode_03_1995.3Hz``
VTU_MODE = re.compile(r"mode_(\d+)_([0-9.eE+-]+)Hz")


def _fail(path: Path, text: str):
    raise ParameterError(ARGUMENT, f"{path.name}: {text}")


def _real(path: Path, name: str, value) -> np.ndarray:
    """``value`` as a float array, refused unless real numbers, all finite."""
    a = np.asarray(value)
    if a.dtype.kind not in "iuf":
        _fail(path, f"member '{name}' must hold real numbers, got dtype {a.dtype}")
    a = a.astype(float)
    bad = int(np.count_nonzero(~np.isfinite(a)))
    if bad:
        _fail(path, f"member '{name}' has {bad} NaN or infinite value{'s' * (bad > 1)} "
                    f"(of {a.size}); a reference must be finite everywhere")
    return a


def _npz_member(path: Path, data, name: str):
    try:
        return data[name]
    except ValueError:  # an object array: reading it would unpickle
        _fail(path, f"member '{name}' is a Python object array (pickled); it must be numbers")


def _check(path: Path, points, shapes, freqs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shapes of the three arrays against each other; returns shapes as (3 p, k)."""
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 1:
        _fail(path, f"member 'points' must have shape (p, 3), got {points.shape}")
    p = len(points)
    if shapes.ndim == 3 and shapes.shape[:2] == (p, 3):
        shapes = shapes.reshape(3 * p, -1)
    elif shapes.ndim == 1 and shapes.shape[0] == 3 * p:
        shapes = shapes.reshape(3 * p, 1)
    if shapes.ndim != 2 or shapes.shape[0] != 3 * p or shapes.shape[1] < 1:
        _fail(path, f"member 'shapes' must have shape (3 p, k) or (p, 3, k) with p = {p} "
                    f"points, got {shapes.shape}")
    k = shapes.shape[1]
    if not np.any(np.linalg.norm(shapes, axis=0) > 0):
        _fail(path, "member 'shapes' is zero everywhere: no mode to compare with")
    if freqs is None:
        return points, shapes, np.full(k, np.nan)
    if freqs.shape != (k,):
        _fail(path, f"member 'frequencies_hz' must have one value per mode, shape ({k},), got "
                    f"{freqs.shape}")
    if np.any(freqs < 0):
        _fail(path, "member 'frequencies_hz' must be >= 0 Hz")
    return points, shapes, freqs


def _load_npz(path: Path):
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        _fail(path, f"not an .npz archive numpy can read without unpickling ({exc})")
    if not isinstance(data, np.lib.npyio.NpzFile):  # a single .npy array named .npz
        _fail(path, "not an .npz archive (a single array); save it with numpy.savez(points=..., "
                    "shapes=..., frequencies_hz=...)")
    with data:
        for name in ("points", "shapes"):
            if name not in data.files:
                _fail(path, f"member '{name}' is missing (has: {', '.join(data.files) or 'none'}); "
                            f"needs 'points' (p, 3) in m and 'shapes' (3 p, k)")
        try:
            pts = _real(path, "points", _npz_member(path, data, "points"))
            sh = _real(path, "shapes", _npz_member(path, data, "shapes"))
            f = (_real(path, "frequencies_hz", _npz_member(path, data, "frequencies_hz"))
                 if "frequencies_hz" in data.files else None)
        except (OSError, EOFError, zipfile.BadZipFile) as exc:  # a truncated member
            _fail(path, f"a member cannot be read ({exc})")
    return _check(path, pts, sh, f)


def _load_vtu(path: Path):
    import meshio

    try:
        m = meshio.read(path)
    except Exception as exc:  # noqa: BLE001 - meshio raises many types on bad input
        _fail(path, f"cannot read it ({exc})")
    found = sorted((int(g.group(1)), float(g.group(2)), k) for k in m.point_data
                   if (g := VTU_MODE.fullmatch(k)))
    if not found:
        _fail(path, "has no point arrays named mode_NN_<f>Hz")
    pts = _real(path, "points", m.points)
    cols = []
    for _, _, k in found:
        a = _real(path, k, m.point_data[k])
        if a.size != 3 * len(pts):
            _fail(path, f"member '{k}' must have 3 values per point ({3 * len(pts)}), "
                        f"got {a.size}")
        cols.append(a.reshape(-1))
    return _check(path, pts, np.column_stack(cols), np.array([f for _, f, _ in found]))


def load_reference(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reference modes from a file: another crankmodal run's ``modes.vtu``, or an ``.npz``.

    The ``.npz`` holds ``points`` (p, 3) in m, ``shapes`` (3 p, k) node-interleaved or
    (p, 3, k), and optionally ``frequencies_hz`` (k,) — e.g. test modes at measurement points.
    It is read with ``allow_pickle=False``. In a ``.vtu`` every point array named
    ``mode_NN_<f>Hz`` (as crankmodal writes them) is one mode.

    Parameters
    ----------
    path : str or Path
        The file (``.npz`` or ``.vtu``).

    Returns
    -------
    points : ndarray, shape (p, 3)
        m.
    shapes : ndarray, shape (3 p, k)
    frequencies_hz : ndarray, shape (k,)
        Hz (NaN where unknown).

    Raises
    ------
    ParameterError
        Naming ``path`` and, where it applies, the member: missing file, unreadable or pickled
        content, a missing member, mismatched shapes, NaN or infinite values.
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError(ARGUMENT, f"file not found: {path}")
    suffix = path.suffix.lower()
    if suffix == ".npz":
        return _load_npz(path)
    if suffix == ".vtu":
        return _load_vtu(path)
    raise ParameterError(ARGUMENT, f"must be a .vtu or .npz file, got {path.name}")
