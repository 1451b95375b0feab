"""Reading a saved :class:`~.result.DynamicsResult` (``dynamics.npz``): an untrusted file.

Every member is checked before the result is built: the format and version, the JSON metadata
(no NaN, the expected structure), and each array's kind (floating point), shape (against the
history's output times, the pistons and the layout) and finiteness; output times must increase.
A file that fails is refused with :class:`DynamicsFileError` naming the file and the member —
never a traceback, never a pickle.
"""

from __future__ import annotations

import json
import math
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ...errors import FileMemberError, InputFileError
from .history import History
from .result import FORMAT, PREFIXES, VERSION, DynamicsResult, MachineInfo
from .signals import Spectrum

#: a history's arrays of shape (K,), (K, pistons) and (K, 2)
_SERIES = ("crank_angle", "crank_speed", "drive_torque", "drive_power", "constraint_drift")
_PISTON = ("piston_position", "piston_velocity", "piston_acceleration")
_PLANAR = ("main_bearing_force", "main_bearing_moment")

#: keys every clearance joint's contact record and contact-peak record holds
CONTACT_KEYS = ("fn", "ft", "penetration", "penetration_rate", "ex", "ey", "ex_bearing",
                "ey_bearing", "film_force")
PEAK_KEYS = ("t", "fn", "penetration", "main_bearing_force", "piston_acceleration")


class DynamicsFileError(FileMemberError):
    """A saved dynamics result that cannot be trusted; the message names the file and member.

    Attributes
    ----------
    path, member, text : str
    """


class _Members:
    """The members of an open ``.npz``, each checked as it is read."""

    def __init__(self, path: Path, z):
        self.path, self.z = path, z

    def fail(self, member: str, text: str) -> DynamicsFileError:
        return DynamicsFileError(self.path, member, text)

    def raw(self, name: str) -> np.ndarray:
        if name not in self.z.files:
            raise self.fail(name, f"missing (every {FORMAT} file has it)")
        try:
            return self.z[name]
        except ValueError as exc:
            why = "pickled objects are never loaded" if "pickle" in str(exc) else exc
            raise self.fail(name, f"unreadable ({why})") from None
        except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
            raise self.fail(name, f"unreadable, the file is damaged ({exc})") from None
        except MemoryError:
            raise self.fail(name, "declares an array larger than the memory available") from None

    def text(self, name: str) -> str:
        a = self.raw(name)
        if a.ndim != 0 or a.dtype.kind != "U":
            raise self.fail(name, f"must be a text, got {a.dtype} of shape {a.shape}")
        return str(a)

    def floats(self, name: str, shape: tuple) -> np.ndarray:
        """A finite float array of ``shape`` (``None`` in it: any length along that axis)."""
        a = self.raw(name)
        ok = a.dtype.kind == "f" and a.ndim == len(shape) and all(
            s is None or s == n for s, n in zip(shape, a.shape))
        if not ok:
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + \
                   ("," if len(shape) == 1 else "") + ")"
            raise self.fail(name, f"must be floating-point numbers of shape {want}, got "
                                  f"{a.dtype} of shape {a.shape}")
        bad = ~np.isfinite(a)
        if np.any(bad):
            raise self.fail(name, f"holds {int(bad.sum())} non-finite value(s) (NaN or inf)")
        return a


def read(path: Path) -> DynamicsResult:
    """The result saved in ``path``, every member checked (see the module's docstring)."""
    if not path.is_file():
        raise InputFileError(f"dynamics result file not found: {path}")
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head[:2] != b"PK":
        raise DynamicsFileError(path, "", "not a readable .npz file (not a zip archive)")
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
        raise DynamicsFileError(path, "", f"not a readable .npz file ({exc})") from None
    with z:
        m = _Members(path, z)
        if "meta_json" not in z.files and "t" in z.files:
            raise m.fail("meta_json", "missing: a dynamics.npz written before crankmodal kept "
                                      "its layout (run the scene again to read it here)")
        fmt = m.text("format")
        if fmt != FORMAT:
            raise m.fail("format", f"must be {FORMAT!r}, got {fmt!r}")
        v = m.raw("version")
        if v.ndim != 0 or v.dtype.kind not in "iu" or int(v) != VERSION:
            raise m.fail("version", f"must be {VERSION}, got {v!r}")
        meta = _meta(m)
        machine = _machine(m, meta.get("machine"))
        layout = _dict(m, meta, "layout")
        if "history" not in layout:
            raise m.fail("meta_json", "layout: has no 'history' (the run with clearance)")
        hist = {a: _history(m, PREFIXES[a], layout[a], machine.n_pistons) if a in layout else None
                for a in PREFIXES}
        _consistent(m, hist["history"], machine)
        window = _window(m, meta.get("window_s"), hist["history"].t)
        summary = _dict(m, meta, "summary")
        return DynamicsResult(history=hist["history"], machine=machine, window_s=window,
                              summary=summary, ideal=hist["ideal"], rigid=hist["rigid"],
                              spectrum=_spectrum(m, meta.get("spectrum")),
                              ideal_force_direction=_directions(m, meta, hist["ideal"]))


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a number a result may hold")


def _meta(m: _Members) -> dict:
    try:
        meta = json.loads(m.text("meta_json"), parse_constant=_refuse_constant)
    except (ValueError, RecursionError) as exc:
        raise m.fail("meta_json", f"not the expected JSON ({exc})") from None
    if not isinstance(meta, dict):
        raise m.fail("meta_json", f"must be a JSON object, got {type(meta).__name__}")
    return meta


def _dict(m: _Members, parent: dict, key: str) -> dict:
    v = parent.get(key)
    if not isinstance(v, dict):
        raise m.fail("meta_json", f"{key}: must be a JSON object, got {type(v).__name__}")
    return v


def _names(m: _Members, value, where: str) -> list:
    if not isinstance(value, list) or not all(isinstance(s, str) and s for s in value) \
            or len(set(value)) != len(value):
        raise m.fail("meta_json", f"{where}: must be a list of distinct names")
    return value


def _number(m: _Members, value, where: str, low: float = 0.0, strict: bool = True) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) \
        and (value > low if strict else value >= low)
    if not ok:
        raise m.fail("meta_json", f"{where}: must be a number {'>' if strict else '>='} {low:g}, "
                                  f"got {value!r:.40}")
    return float(value)


def _machine(m: _Members, d) -> MachineInfo:
    if not isinstance(d, dict):
        raise m.fail("meta_json", "machine: must be a JSON object")
    if not isinstance(d.get("kind"), str):
        raise m.fail("meta_json", "machine.kind: must be a text")
    n = d.get("n_pistons")
    if not isinstance(n, int) or isinstance(n, bool) or n < 0:
        raise m.fail("meta_json", f"machine.n_pistons: must be an integer >= 0, got {n!r:.40}")
    cl, flex = d.get("clearances"), d.get("flexible")
    if not isinstance(cl, dict) or not isinstance(flex, dict):
        raise m.fail("meta_json", "machine.clearances and machine.flexible: must be JSON objects")
    for name, f in flex.items():
        if not isinstance(f, list) or not f:
            raise m.fail("meta_json", f"machine.flexible.{name}: must be a list of frequencies")
    return MachineInfo(
        kind=d["kind"], revolution_hz=_number(m, d.get("revolution_hz"), "machine.revolution_hz"),
        main_joints=tuple(_names(m, d.get("main_joints"), "machine.main_joints")), n_pistons=n,
        clearances={k: _number(m, c, f"machine.clearances.{k}") for k, c in cl.items()},
        flexible={k: [_number(m, x, f"machine.flexible.{k}") for x in f]
                  for k, f in flex.items()})


def _history(m: _Members, prefix: str, lay, P: int) -> History:
    """One history (``prefix``: ``""``, ``ideal_`` or ``rigid_``) from its arrays and layout."""
    where = f"layout.{prefix.rstrip('_') or 'history'}"
    if not isinstance(lay, dict):
        raise m.fail("meta_json", f"{where}: must be a JSON object")
    t = m.floats(prefix + "t", (None,))
    if t.size < 2 or np.any(np.diff(t) <= 0.0):
        raise m.fail(prefix + "t", "must be two or more increasing output times, s")
    K = t.size

    def series(name, shape=(K,)):
        return m.floats(prefix + name, shape)

    def table(key, keys_required):
        d = lay.get(key)
        if not isinstance(d, dict):
            raise m.fail("meta_json", f"{where}.{key}: must be a JSON object")
        for name, keys in d.items():
            _names(m, keys, f"{where}.{key}.{name}")
            missing = [k for k in keys_required if k not in keys]
            if missing:
                raise m.fail("meta_json", f"{where}.{key}.{name}: lacks {', '.join(missing)}")
        return d

    contact = {name: {k: series(f"contact_{name}_{k}") for k in keys}
               for name, keys in table("contact", CONTACT_KEYS).items()}
    energy = {k: series(f"energy_{k}") for k in _names(m, lay.get("energy"), f"{where}.energy")}
    if "residual" not in energy:
        raise m.fail("meta_json", f"{where}.energy: lacks residual")
    peaks = {}
    for name, keys in table("peaks", PEAK_KEYS).items():
        n = m.floats(f"{prefix}peaks_{name}_t", (None,)).shape[0]
        peaks[name] = {k: m.floats(f"{prefix}peaks_{name}_{k}",
                                   (n, P) if k == "piston_acceleration" else (n,)) for k in keys}
    extra = {}
    if "torsion" in lay:  # a crank train with a motor or a flexible crank
        extra["torsion"] = {n: series(f"torsion_{n}")
                            for n in _names(m, lay["torsion"], f"{where}.torsion")}
    nfev, wall = lay.get("nfev"), lay.get("wall_time")
    if not isinstance(nfev, int) or isinstance(nfev, bool) or nfev < 0:
        raise m.fail("meta_json", f"{where}.nfev: must be an integer >= 0")
    return History(
        t=t, **{k: series(k) for k in _SERIES}, **{k: series(k, (K, P)) for k in _PISTON},
        **{k: series(k, (K, 2)) for k in _PLANAR},
        joint_forces={n: series(f"joint_force_{n}", (K, 2))
                      for n in _names(m, lay.get("joint_forces"), f"{where}.joint_forces")},
        contact=contact, energy=energy,
        onsets={n: [(float(a), float(b)) for a, b in m.floats(f"{prefix}impacts_{n}", (None, 2))]
                for n in _names(m, lay.get("onsets"), f"{where}.onsets")},
        separations={n: [float(a) for a in m.floats(f"{prefix}separations_{n}", (None,))]
                     for n in _names(m, lay.get("separations"), f"{where}.separations")},
        angular_acceleration={n: series(f"angular_acceleration_{n}") for n in _names(
            m, lay.get("angular_acceleration"), f"{where}.angular_acceleration")},
        peaks=peaks, nfev=nfev, wall_time=_number(m, wall, f"{where}.wall_time", strict=False),
        modal={n: series(f"modal_{n}", (K, None))
               for n in _names(m, lay.get("modal"), f"{where}.modal")}, **extra)


def _consistent(m: _Members, h: History, machine: MachineInfo) -> None:
    """The machine's joints, clearances and flexible bodies are those the history records."""
    for j in machine.main_joints:
        if j not in h.joint_forces:
            raise m.fail("meta_json", f"machine.main_joints: {j!r} has no joint_force_{j}")
    if set(machine.clearances) != set(h.contact):
        raise m.fail("meta_json", "machine.clearances: must name the joints of layout.history."
                                  "contact")
    for name, freqs in machine.flexible.items():
        if name not in h.modal or h.modal[name].shape[1] < len(freqs):
            raise m.fail(f"modal_{name}", f"must hold the {len(freqs)} elastic modes of "
                                          f"machine.flexible.{name}")


def _window(m: _Members, w, t: np.ndarray) -> tuple:
    if not isinstance(w, list) or len(w) != 2:
        raise m.fail("meta_json", "window_s: must be [start, end] in s")
    a, b = (_number(m, x, "window_s", low=-math.inf) for x in w)
    if not (a <= b and np.any((t >= a - 1e-12) & (t <= b + 1e-12))):
        raise m.fail("meta_json", f"window_s: [{a:g}, {b:g}] s holds no output time")
    return (a, b)


def _spectrum(m: _Members, present) -> Spectrum | None:
    if not isinstance(present, bool):
        raise m.fail("meta_json", "spectrum: must be true or false")
    if not present:
        return None
    f = m.floats("spectrum_frequency_hz", (None,))
    return Spectrum(frequency_hz=f, order=m.floats("spectrum_order", f.shape),
                    amplitude=m.floats("spectrum_main_bearing_amplitude", (f.size, 2)))


def _directions(m: _Members, meta: dict, ideal: History | None) -> dict:
    names = _names(m, meta.get("force_direction"), "force_direction")
    if names and ideal is None:
        raise m.fail("meta_json", "force_direction: needs the ideal twin (layout.ideal)")
    K = None if ideal is None else ideal.t.size
    return {n: (m.floats(f"ideal_force_direction_{n}", (K,)),
                m.floats(f"ideal_force_direction_rate_{n}", (K,))) for n in names}


__all__ = ["CONTACT_KEYS", "PEAK_KEYS", "DynamicsFileError", "read"]
