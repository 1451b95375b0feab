"""The result of a dynamics run (ROSS-style): histories, statistics, spectra, validity, energy
and flexible-body outputs, with ``to_dict``, ``save``/``load`` and ``plot_*``.

The file is the stage's ``dynamics.npz`` (compressed, no pickle): every time history under the
names the guide documents (``t``, ``main_bearing_force``, ``contact_<joint>_fn``, ``ideal_*``,
``rigid_*``, ``spectrum_*``, ...), plus ``separations_<joint>`` (contact separation times, s),
``format`` (``"crankmodal-dynamics"``), ``version`` (1) and ``meta_json``: the results.json
entry of the run and the layout of the arrays (which joints, contact keys, energy terms, bodies).
:meth:`DynamicsResult.load` checks every member (kind, shape, finiteness, monotonic times)
before building the result, so a damaged or hostile file is refused naming the file and member.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .history import History
from .signals import Spectrum

FORMAT = "crankmodal-dynamics"
VERSION = 1
#: the prefixes of the histories in the file (in the order written): the run with clearance,
#: its twins
PREFIXES = {"history": "", "rigid": "rigid_", "ideal": "ideal_"}


@dataclass(frozen=True)
class MachineInfo:
    """What the figures need to know of the mechanism, as plain data (kept in the file).

    Attributes
    ----------
    kind : str
        ``slider_crank``, ``four_star`` or ``four_bar``.
    revolution_hz : float
        Crank revolution frequency, Hz.
    main_joints : tuple of str
        The joints between the crank and the housing (one per main journal).
    n_pistons : int
        Pistons (columns of the piston arrays).
    clearances : dict
        Clearance joint name -> radial clearance, m.
    flexible : dict
        Flexible body name -> frequencies of its kept elastic modes, Hz (bodies with at least
        one elastic mode, in the system's order).
    """

    kind: str
    revolution_hz: float
    main_joints: tuple = ()
    n_pistons: int = 0
    clearances: dict = field(default_factory=dict)
    flexible: dict = field(default_factory=dict)

    @classmethod
    def of(cls, mech) -> MachineInfo:
        """The description of a built :class:`~crankmodal.dynamics.model.mechanisms.Mechanism`."""
        mains = getattr(mech, "main_joints", None) or [mech.main_joint]
        flex = {b.name: [float(f) for f in b.frequencies_hz[:b.n_elastic]]
                for b in mech.system.bodies if getattr(b, "n_elastic", 0) > 0}
        return cls(kind=str(mech.kind), revolution_hz=float(mech.revolution_hz),
                   main_joints=tuple(mains), n_pistons=len(mech.pistons),
                   clearances={cj.name: float(cj.clearance) for cj in mech.system.clearances},
                   flexible=flex)

    def to_dict(self) -> dict:
        """JSON-ready dict (the file's ``machine``)."""
        return {"kind": self.kind, "revolution_hz": self.revolution_hz,
                "main_joints": list(self.main_joints), "n_pistons": self.n_pistons,
                "clearances": dict(self.clearances), "flexible": dict(self.flexible)}


@dataclass
class DynamicsResult:
    """Everything a ``[dynamics]`` run gives, SI units.

    Attributes
    ----------
    history : History
        The run with clearance joints (or the only run).
    machine : MachineInfo
        The mechanism as the figures need it.
    window_s : tuple of float
        First and last output time of the results window (whole revolutions after the
        start-up), s: every peak, spectrum and statistic is taken over it.
    summary : dict
        The run's entry in results.json (``dynamics``): peaks, order amplitudes, energy,
        ``clearance_joints``, ``statistics``, ``ensemble``, ``headline``, ``ideal``,
        ``flexible``, ``tolerance_study``, ``warnings``, ``summary``, ...
    ideal : History or None
        The ideal-joint twin (``run_ideal``).
    rigid : History or None
        The rigid twin of a run with flexible bodies (``run_rigid``).
    spectrum : Spectrum or None
        Main-bearing force spectrum over the window (amplitude (F, 2), N); None when the window
        holds no whole revolution.
    ideal_force_direction : dict
        Clearance joint name -> ``(beta, rate)``: direction of the force the ideal pin carries
        there (rad) and its rate (rad/s), over the ideal twin's output times.

    Examples
    --------
    A run's output folder read back and a figure redrawn (the stage saved ``dynamics.npz``)::

        import crankmodal as cm

        cm.run_scene(cm.load_scene(cm.scene_path("slider_crank_dynamics")), "out")
        result = cm.DynamicsResult.load("out/dynamics.npz")
        peak = result.statistics["main_bearing_force"]["per_rev_peak"]  # N: mean, sem, ...
        sel = result.window_mask()
        force = result.history.main_bearing_force[sel]  # (K, 2) N, the results window
        result.plot_orbits("orbit.png")
    """

    history: History
    machine: MachineInfo
    window_s: tuple
    summary: dict
    ideal: History | None = None
    rigid: History | None = None
    spectrum: Spectrum | None = None
    ideal_force_direction: dict = field(default_factory=dict)

    # ---- views -----------------------------------------------------------------------------
    @property
    def statistics(self) -> dict:
        """Per-revolution statistics (``summary["statistics"]``; empty if absent)."""
        return self.summary.get("statistics", {})

    @property
    def warnings(self) -> list:
        """The validity and accuracy warnings of the run (texts)."""
        return self.summary.get("warnings", [])

    @property
    def energy(self) -> dict:
        """Energy terms of the run with clearance over time, J (``history.energy``)."""
        return self.history.energy

    @property
    def energy_balance_error(self) -> float:
        """Largest energy-balance residual over the energy exchanged in the run."""
        return self.history.energy_error()

    def window_mask(self, hist: History | None = None) -> np.ndarray:
        """Boolean mask of the output times of ``hist`` (default: :attr:`history`) in the
        results window (1e-12 s of slack for the round-off of the stored times)."""
        t = (self.history if hist is None else hist).t
        return (t >= self.window_s[0] - 1e-12) & (t <= self.window_s[1] + 1e-12)

    def ideal_spectrum(self) -> Spectrum | None:
        """Main-bearing force spectrum of the ideal twin over the window (None without it)."""
        from .signals import amplitude_spectrum

        if self.ideal is None:
            return None
        sel = self.window_mask(self.ideal)
        return amplitude_spectrum(self.ideal.t[sel], self.ideal.main_bearing_force[sel],
                                  self.machine.revolution_hz)

    def to_dict(self) -> dict:
        """The JSON-ready summary (results.json's ``dynamics``; no time histories)."""
        from ...results import to_jsonable

        return to_jsonable(self.summary)

    # ---- files -----------------------------------------------------------------------------
    def arrays(self) -> dict:
        """Flat ``{name: ndarray}`` of every time history, spectrum and force direction (the
        members of ``dynamics.npz`` besides ``format``, ``version`` and ``meta_json``)."""
        out = {}
        for attr, prefix in PREFIXES.items():
            h = getattr(self, attr)
            if h is not None:
                out.update({prefix + k: v for k, v in _history_arrays(h).items()})
        for name, (beta, rate) in self.ideal_force_direction.items():
            out[f"ideal_force_direction_{name}"] = beta
            out[f"ideal_force_direction_rate_{name}"] = rate
        if self.spectrum is not None:
            out["spectrum_frequency_hz"] = self.spectrum.frequency_hz
            out["spectrum_order"] = self.spectrum.order
            out["spectrum_main_bearing_amplitude"] = self.spectrum.amplitude
        return out

    def save(self, path) -> Path:
        """Write the result to ``path`` (``.npz``, compressed, atomically); returns the path.

        Raises
        ------
        ParameterError
            ``path`` is not a path.
        OutputError
            The file cannot be written (names the path).
        NumericalError
            The summary holds a NaN or infinite value (names its key).
        """
        from ...arguments import path as path_argument
        from ...results import atomic_path, to_jsonable

        path_argument("path", path)
        path = Path(path)
        meta = {"machine": self.machine.to_dict(), "window_s": [float(x) for x in self.window_s],
                "layout": {a: _layout(getattr(self, a)) for a in PREFIXES
                           if getattr(self, a) is not None},
                "force_direction": list(self.ideal_force_direction),
                "spectrum": self.spectrum is not None,
                "summary": to_jsonable(self.summary, "dynamics")}
        data = self.arrays()
        data.update(format=np.array(FORMAT), version=np.array(VERSION),
                    meta_json=np.array(json.dumps(meta, allow_nan=False)))
        with atomic_path(path) as tmp:
            np.savez_compressed(tmp, **data)
        return path

    @classmethod
    def load(cls, path) -> DynamicsResult:
        """Read a result written by :meth:`save` (a run's ``dynamics.npz``), checking every
        member.

        Raises
        ------
        ParameterError
            ``path`` is not a path.
        InputFileError
            The file is missing, or naming the file and the member that is missing, damaged,
            of the wrong kind or shape, or not finite.
        """
        from ...arguments import path as path_argument

        path_argument("path", path)
        from .result_file import read

        return read(Path(path))

    # ---- figures ---------------------------------------------------------------------------
    def plot_forces(self, path) -> Path:
        """Main-bearing force against time (ideal twin dashed) and its spectrum over the window
        (:func:`.plots.plot_bearing_force`)."""
        from . import plots
        from .signals import amplitude_spectrum

        h, sel = self.history, self.window_mask()
        spec = self.spectrum
        if spec is None:
            spec = amplitude_spectrum(h.t[sel], h.main_bearing_force[sel],
                                      self.machine.revolution_hz)
        return plots.plot_bearing_force(h, spec, Path(path), self.ideal_spectrum(), self.ideal,
                                        tuple(self.window_s))

    def plot_piston(self, path, piston: int = 0) -> Path:
        """Piston acceleration over time, crank angle and as a phase diagram
        (:func:`.plots.plot_piston`)."""
        from . import plots

        return plots.plot_piston(self.history, self.ideal, Path(path), piston,
                                 window=tuple(self.window_s))

    def plot_orbits(self, path) -> Path:
        """Journal-centre orbits in units of the clearance (:func:`.plots.plot_orbit`)."""
        from . import plots

        return plots.plot_orbit(self.history, self.machine.clearances, Path(path))

    def plot_contact(self, path) -> Path:
        """Contact forces, impacts and penetrations (:func:`.plots.plot_contact`)."""
        from . import plots

        return plots.plot_contact(self.history, Path(path), self.ideal, tuple(self.window_s))

    def plot_drive(self, path) -> Path:
        """Drive torque and power (:func:`.plots.plot_drive`)."""
        from . import plots

        return plots.plot_drive(self.history, self.ideal, Path(path), tuple(self.window_s))

    def plot_energy(self, path) -> Path:
        """Energy terms and the balance residual (:func:`.plots.plot_energy`)."""
        from . import plots

        return plots.plot_energy(self.history, Path(path), self.ideal, tuple(self.window_s))

    def plot_tolerance_study(self, path) -> Path:
        """Error against wall time over the tolerance study (:func:`.plots.plot_study`)."""
        from ...errors import ParameterError
        from . import plots

        if "tolerance_study" not in self.summary:
            raise ParameterError("path", "this run has no tolerance study (solver.study_rtols)")
        return plots.plot_study(self.summary["tolerance_study"], Path(path))

    def plot_flexible(self, path) -> Path:
        """Joint forces flexible against the rigid twin and their orders
        (:func:`.flexplots.plot_main_bearing`)."""
        from .flexplots import plot_main_bearing

        return plot_main_bearing(self.history, self.rigid, self.machine, self.window_mask(),
                                 Path(path))

    def plot_modes(self, path) -> Path:
        """Modal coordinates of the flexible bodies (:func:`.flexplots.plot_modal`)."""
        from .flexplots import plot_modal

        return plot_modal(self.history, self.machine, Path(path))

    def figures(self, out_dir) -> tuple[list, list]:
        """Write the stage's PNG figures into ``out_dir``; returns the file names written and,
        of them, the flexible bodies' (empty for a rigid run)."""
        out = Path(out_dir)
        figs = [self.plot_forces(out / "dynamics_main_bearing.png")]
        if self.history.piston_acceleration.shape[1]:
            figs.append(self.plot_piston(out / "dynamics_piston.png"))
        if self.machine.clearances:
            figs.append(self.plot_orbits(out / "dynamics_orbit.png"))
            figs.append(self.plot_contact(out / "dynamics_contact.png"))
        figs.append(self.plot_drive(out / "dynamics_drive.png"))
        figs.append(self.plot_energy(out / "dynamics_energy.png"))
        if "tolerance_study" in self.summary:
            figs.append(self.plot_tolerance_study(out / "dynamics_tolerance_study.png"))
        flex = []
        if "flexible" in self.summary:
            flex = [self.plot_flexible(out / "dynamics_flexible_main_bearing.png"),
                    self.plot_modes(out / "dynamics_flexible_modes.png")]
        return [f.name for f in figs + flex], [f.name for f in flex]


def _history_arrays(h: History) -> dict:
    """``History.arrays()`` and the contact separations (``separations_<joint>``, s)."""
    out = h.arrays()
    for name, sep in h.separations.items():
        out[f"separations_{name}"] = np.asarray(sep, float).reshape(-1)
    return out


def _layout(h: History | None) -> dict | None:
    """The names needed to read a history's flat arrays back (names may hold underscores)."""
    if h is None:
        return None
    return {"joint_forces": list(h.joint_forces),
            "contact": {n: list(d) for n, d in h.contact.items()},
            "energy": list(h.energy), "angular_acceleration": list(h.angular_acceleration),
            "onsets": list(h.onsets), "separations": list(h.separations),
            "peaks": {n: list(d) for n, d in h.peaks.items()}, "modal": list(h.modal),
            "nfev": int(h.nfev), "wall_time": float(h.wall_time),
            # a crank train with a motor or a flexible crank (History.torsion)
            **({"torsion": list(h.torsion)} if getattr(h, "torsion", None) else {})}
