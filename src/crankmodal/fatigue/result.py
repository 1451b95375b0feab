"""The fatigue verdict's result: per-point arrays, per-location summary, save/load, plots.

The ``.npz`` file (format ``crankmodal-fatigue``, version 1) holds plain arrays and one JSON
text; :meth:`FatigueResult.load` checks every member (kind, shape, finiteness, index ranges)
before building the result, so a damaged or hostile file is refused with the file and member
named, never a traceback or a pickle.
"""

from __future__ import annotations

import json
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FileMemberError, InputFileError

FORMAT = "crankmodal-fatigue"
VERSION = 1
#: per-point float arrays of the file; the NaN-allowed one (no yield strength) separately
_PER_POINT = ("safety_factor", "alternating", "mean", "max_von_mises", "proportionality")


class FatigueFileError(FileMemberError):
    """A saved fatigue result that cannot be trusted; the message names the file and member.

    Attributes
    ----------
    path, member, text : str
    """


@dataclass
class FatigueResult:
    """Fatigue safety factors of the points assessed, SI units.

    Attributes
    ----------
    nodes : ndarray of int, shape (n,)
        The points assessed (indices into the stress modes' points).
    points : ndarray, shape (n, 3)
        Their coordinates, m.
    safety_factor : ndarray, shape (n,)
        Fatigue safety factor (``inf`` where the stress does not vary and has no mean).
    alternating, mean : ndarray, shape (n,)
        Equivalent alternating and mean stress, notch factor applied, Pa.
    max_von_mises : ndarray, shape (n,)
        Largest von Mises stress over the cycle, Pa.
    yield_safety_factor : ndarray, shape (n,)
        ``yield_strength / max_von_mises`` (NaN without a yield strength).
    proportionality : ndarray, shape (n,)
        Largest von Mises stress of ``σ(t) − σ_m`` over that of the component-wise amplitude,
        in (0, 1]: 1 for proportional loading; below it the component-wise amplitude
        over-estimates the stress range (the verdict is conservative by up to its inverse).
    location_names, location_kinds : list of str
        The named locations (fillets, oil-hole exits) and their kinds.
    label : ndarray of int, shape (n,)
        Location of each point (index into ``location_names``; -1: elsewhere).
    fatigue_strength : float
        Corrected fatigue strength ``S_e``, Pa.
    specimen_fatigue_strength, ultimate_strength, yield_strength : float
        The material's, Pa (``yield_strength`` NaN when absent).
    factors : dict
        :class:`~crankmodal.fatigue.factors.FatigueFactors` as a dict.
    rule, mean_stress, material : str
    warnings : list of str
    """

    nodes: np.ndarray
    points: np.ndarray
    safety_factor: np.ndarray
    alternating: np.ndarray
    mean: np.ndarray
    max_von_mises: np.ndarray
    yield_safety_factor: np.ndarray
    proportionality: np.ndarray
    location_names: list
    location_kinds: list
    label: np.ndarray
    fatigue_strength: float
    specimen_fatigue_strength: float
    ultimate_strength: float
    yield_strength: float
    factors: dict
    rule: str
    mean_stress: str
    material: str
    warnings: list = field(default_factory=list)

    # ---- summary ---------------------------------------------------------------------------
    @property
    def min_safety_factor(self) -> float:
        """Smallest fatigue safety factor over every point assessed."""
        return float(np.min(self.safety_factor))

    def _worst(self, mask) -> dict | None:
        if not np.any(mask):
            return None
        i = np.flatnonzero(mask)[int(np.argmin(self.safety_factor[mask]))]
        return {"safety_factor": float(self.safety_factor[i]), "node": int(self.nodes[i]),
                "point_m": self.points[i].tolist(), "alternating_pa": float(self.alternating[i]),
                "mean_pa": float(self.mean[i]), "max_von_mises_pa": float(self.max_von_mises[i]),
                "yield_safety_factor": float(self.yield_safety_factor[i]),
                "proportionality": float(self.proportionality[i]), "n_points": int(np.sum(mask))}

    def locations(self) -> dict:
        """Per named location (and ``elsewhere``: the other points assessed) its worst point:
        safety factor, node, point (m), stresses (Pa), yield safety factor, point count."""
        out = {}
        for k, name in enumerate(self.location_names):
            w = self._worst(self.label == k)
            if w is not None:
                out[name] = {"kind": self.location_kinds[k], **w}
        w = self._worst(self.label < 0)
        if w is not None:
            out["elsewhere"] = {"kind": "surface", **w}
        return out

    @property
    def worst_location(self) -> str | None:
        """The named location with the smallest safety factor (None: no location named)."""
        named = {k: v for k, v in self.locations().items() if k != "elsewhere"}
        return min(named, key=lambda k: named[k]["safety_factor"]) if named else None

    def to_dict(self) -> dict:
        """JSON-ready summary (no per-point arrays)."""
        locs = self.locations()
        worst = self.worst_location
        return {
            "criterion": {"rule": self.rule, "mean_stress": self.mean_stress,
                          "equivalent_alternating": "von Mises of the amplitude tensor"},
            "material": self.material,
            "fatigue_strength_pa": self.fatigue_strength,
            "specimen_fatigue_strength_pa": self.specimen_fatigue_strength,
            "ultimate_strength_pa": self.ultimate_strength,
            "yield_strength_pa": None if np.isnan(self.yield_strength) else self.yield_strength,
            "factors": dict(self.factors),
            "n_points": len(self.nodes),
            "min_safety_factor": self.min_safety_factor,
            "worst_location": worst,
            "worst_location_safety_factor": locs[worst]["safety_factor"] if worst else None,
            "min_yield_safety_factor": float(np.nanmin(self.yield_safety_factor))
            if np.any(np.isfinite(self.yield_safety_factor)) else None,
            "locations": locs,
            "warnings": list(self.warnings),
        }

    # ---- files -----------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write the result to ``path`` (``.npz``, atomically); returns the path."""
        from ..arguments import path as path_argument
        from ..results import atomic_path

        path_argument("path", path)
        path = Path(path)
        meta = {"location_names": list(self.location_names),
                "location_kinds": list(self.location_kinds), "factors": dict(self.factors),
                "rule": self.rule, "mean_stress": self.mean_stress, "material": self.material,
                "warnings": list(self.warnings)}
        data = {k: np.asarray(getattr(self, k), float) for k in _PER_POINT}
        data.update(format=np.array(FORMAT), version=np.array(VERSION),
                    nodes=np.asarray(self.nodes, np.int64), points=np.asarray(self.points, float),
                    yield_safety_factor=np.asarray(self.yield_safety_factor, float),
                    label=np.asarray(self.label, np.int64),
                    strengths=np.array([self.fatigue_strength, self.specimen_fatigue_strength,
                                        self.ultimate_strength, self.yield_strength]),
                    meta_json=np.array(json.dumps(meta)))
        with atomic_path(path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, **data)
        return path

    @classmethod
    def load(cls, path) -> FatigueResult:
        """Read a result written by :meth:`save`, checking every member.

        Raises
        ------
        InputFileError
            The file is missing.
        FatigueFileError
            Naming the file and the member that is missing, damaged or of the wrong kind.
        """
        from ..arguments import path as path_argument

        path_argument("path", path)
        return _read(Path(path))

    # ---- figures ---------------------------------------------------------------------------
    def plot_safety(self, path=None, required: float | None = None):
        """Bar chart of the safety factor per location and the Haigh diagram of their worst
        points (see :func:`crankmodal.fatigue.plots.plot_safety`)."""
        from .plots import plot_safety

        return plot_safety(self, path, required)

    def plot_crank(self, mesh_points, cells, path, title: str | None = None) -> Path:
        """PNG of the part's surface coloured by safety factor, off-screen (see
        :func:`crankmodal.fatigue.plots.plot_crank`)."""
        from .plots import plot_crank

        return plot_crank(self, mesh_points, cells, path, title)


def _fail(path, member, text):
    return FatigueFileError(path, member, text)


def _read(path: Path) -> FatigueResult:
    if not path.is_file():
        raise InputFileError(f"fatigue result file not found: {path}")
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head[:2] != b"PK":
        raise _fail(path, "", "not a readable .npz file (not a zip archive)")
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
        raise _fail(path, "", f"not a readable .npz file ({exc})") from None
    with z:
        def raw(name):
            if name not in z.files:
                raise _fail(path, name, f"missing (every {FORMAT} file has it)")
            try:
                return z[name]
            except ValueError as exc:
                raise _fail(path, name, f"unreadable ({'pickled objects are never loaded' if 'pickle' in str(exc) else exc})") from None
            except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
                raise _fail(path, name, f"unreadable, the file is damaged ({exc})") from None
            except MemoryError:
                raise _fail(path, name, "declares an array larger than the memory available") from None

        def text(name):
            a = raw(name)
            if a.ndim != 0 or a.dtype.kind != "U":
                raise _fail(path, name, f"must be a text, got {a.dtype} of shape {a.shape}")
            return str(a)

        def numbers(name, shape, kinds="f", nan_ok=False, inf_ok=False):
            a = raw(name)
            if a.dtype.kind not in kinds or a.shape != shape:
                raise _fail(path, name, f"must be numbers of shape {shape}, got {a.dtype} of "
                                        f"shape {a.shape}")
            bad = np.isnan(a) if a.dtype.kind == "f" and not nan_ok else np.zeros(a.shape, bool)
            if a.dtype.kind == "f" and not inf_ok:
                bad |= np.isinf(a)
            if np.any(bad):
                raise _fail(path, name, f"holds {int(bad.sum())} non-finite value(s)")
            return a

        if text("format") != FORMAT:
            raise _fail(path, "format", f"must be {FORMAT!r}, got {text('format')!r}")
        v = raw("version")
        if v.ndim != 0 or v.dtype.kind not in "iu" or int(v) != VERSION:
            raise _fail(path, "version", f"must be {VERSION}, got {v!r}")
        try:
            meta = json.loads(text("meta_json"))
            names, kinds = list(meta["location_names"]), list(meta["location_kinds"])
            factors, rule = dict(meta["factors"]), str(meta["rule"])
            mean_stress, material = str(meta["mean_stress"]), str(meta["material"])
            warns = [str(w) for w in meta["warnings"]]
            if len(kinds) != len(names) or not all(isinstance(s, str) for s in names + kinds):
                raise ValueError("location names and kinds do not match")
        except (ValueError, KeyError, TypeError) as exc:
            raise _fail(path, "meta_json", f"not the expected JSON ({exc})") from None
        nodes = raw("nodes")
        n = nodes.shape[0] if nodes.ndim == 1 else -1
        nodes = numbers("nodes", (n,), "iu")
        if n <= 0 or nodes.min() < 0:
            raise _fail(path, "nodes", "must be one or more point indices >= 0")
        arrays = {k: numbers(k, (n,), inf_ok=(k == "safety_factor")) for k in _PER_POINT}
        for name, ok in (("safety_factor", arrays["safety_factor"] > 0),
                         ("alternating", arrays["alternating"] >= 0),
                         ("max_von_mises", arrays["max_von_mises"] >= 0),
                         ("proportionality", (arrays["proportionality"] >= 0)
                          & (arrays["proportionality"] <= 1))):
            if not np.all(ok):
                raise _fail(path, name, f"holds {int((~ok).sum())} value(s) out of range "
                                        f"(safety factor > 0, stresses >= 0, proportionality "
                                        f"in [0, 1])")
        ny = numbers("yield_safety_factor", (n,), nan_ok=True, inf_ok=True)
        label = numbers("label", (n,), "iu")
        if np.any((label < -1) | (label >= len(names))):
            raise _fail(path, "label", f"must be -1 or a location index below {len(names)}")
        s = numbers("strengths", (4,), nan_ok=True)
        if not (s[0] > 0 and s[1] > 0 and s[2] > 0):
            raise _fail(path, "strengths", "the fatigue and ultimate strengths must be > 0 Pa")
        return FatigueResult(
            nodes=nodes.astype(np.int64), points=numbers("points", (n, 3)), **arrays,
            yield_safety_factor=ny, location_names=names, location_kinds=kinds,
            label=label.astype(np.int64), fatigue_strength=float(s[0]),
            specimen_fatigue_strength=float(s[1]), ultimate_strength=float(s[2]),
            yield_strength=float(s[3]), factors=factors, rule=rule, mean_stress=mean_stress,
            material=material, warnings=warns)
