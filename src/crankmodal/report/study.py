"""Mesh-simplification study: fidelities × mesh sizes × element orders, error against run time.

Seed 000 (Table 3) computes the free modes of the crankshaft as the 1:1 model, without holes and
chamfers, and with its peripheral details simplified, and compares them with the experiment.
Here one part is built and solved for every (fidelity, mesh size, element order); each model's
frequencies are compared, mode by mode in ascending order, with a reference:

- the measured frequencies, for the modes they cover, when given;
- otherwise the Richardson extrapolation (h → 0, :func:`crankmodal.fem.convergence.richardson`)
  of the ``full`` model at its highest element order over its two finest mesh sizes (three sizes
  let the observed rate be used); with one size, the finest ``full`` model itself.

Modes are paired with the reference model's (the finest ``full`` model at the highest order)
by their MAC on a common cloud of surface points (the first model's boundary nodes, each model
sampled at its nearest node), so a mode that moves past another in a simplified model is still
compared with its own counterpart; a pair needs MAC >= ``MIN_PAIR_MAC``, otherwise the mode of
the same rank is used and the cell is flagged. Without shapes, modes are compared by rank, as
seed 000 does.

A model's *estimated error* is the largest relative difference over the compared modes. Its
*cost* is the wall time to mesh it and solve it. The Pareto front holds the models no other
model beats in both; the recommendation is the cheapest model whose error is within the user's
tolerance.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .quantity import percent, quantity

#: Smallest MAC accepted to pair a model's mode with a reference mode.
MIN_PAIR_MAC = 0.6

#: Surface points at most in the common cloud on which models' mode shapes are compared.
MAX_PROBES = 3000


def pareto_front(cost, error) -> np.ndarray:
    """Indices of the non-dominated points, by increasing cost.

    A point is dominated when another has cost <= and error <= with at least one strictly less.
    """
    c = np.asarray(cost, float)
    e = np.asarray(error, float)
    order = np.lexsort((e, c))  # by cost, ties by error
    front, best = [], np.inf
    for i in order:
        if e[i] < best:
            front.append(int(i))
            best = e[i]
    return np.array(front, dtype=int)


def recommend(cost, error, tolerance: float) -> int | None:
    """Index of the cheapest point with ``error <= tolerance`` (None if there is none).

    Ties in cost go to the smaller error. The answer always lies on the Pareto front.
    """
    c = np.asarray(cost, float)
    e = np.asarray(error, float)
    ok = np.flatnonzero(e <= tolerance)
    if not len(ok):
        return None
    return int(ok[np.lexsort((e[ok], c[ok]))[0]])


def reference_frequencies(runs: list[dict], n_modes: int, measured_hz=None):
    """Reference frequency per mode and where it comes from.

    Parameters
    ----------
    runs : list of dict
        With ``fidelity``, ``order``, ``mesh_size`` (m) and ``frequencies_hz``.
    n_modes : int
    measured_hz : sequence of float, optional
        Measured frequencies of the first modes, Hz (they take precedence).

    Returns
    -------
    ref : ndarray, shape (n_modes,)
        Hz (NaN where no reference exists).
    source : list of str
        ``measured``, ``Richardson (full, P2, h → 0)`` or ``finest full (P2, h = … mm)``.
    computed : ndarray, shape (n_modes,)
        The computed reference alone (Richardson or finest full), Hz.
    """
    from ..fem.convergence import richardson

    full = [r for r in runs if r["fidelity"] == "full"] or runs
    order = max(r["order"] for r in full)
    rows = sorted((r for r in full if r["order"] == order), key=lambda r: -r["mesh_size"])
    F = np.array([r["frequencies_hz"][:n_modes] for r in rows], float)
    fid = rows[0]["fidelity"]
    if len(rows) >= 2:
        computed, _ = richardson(np.array([r["mesh_size"] for r in rows]), F, order)
        what = f"Richardson ({fid}, P{order}, h → 0)"
    else:
        computed = F[-1]
        what = f"finest {fid} (P{order}, h = {1e3 * rows[-1]['mesh_size']:.3g} mm)"
    ref = np.array(computed, float)
    source = [what] * n_modes
    for k, f in enumerate(measured_hz or ()):
        if k < n_modes and f is not None:
            ref[k] = f
            source[k] = "measured"
    return ref, source, np.asarray(computed, float)


@dataclass
class SimplificationStudy:
    """Result of a simplification study.

    Attributes
    ----------
    runs : list of dict
        Per model: ``fidelity``, ``mesh_size`` (m), ``order``, ``n_elements``, ``n_nodes``,
        ``n_dofs``, ``mesh_time_s``, ``solve_time_s``, ``wall_time_s``, ``frequencies_hz``
        (by rank), ``mode_of`` (its mode paired with each reference mode), ``pair_mac`` (their
        MAC, None when compared by rank), ``matched_hz`` (frequency paired with each reference
        mode), ``rel_diff`` ((f − f_ref)/f_ref per reference mode), ``error`` (max |rel_diff|
        over the compared modes).
    reference_hz : list
        Hz per mode.
    reference_source : list of str
    computed_reference_hz : list
        Richardson (or finest full) frequencies, Hz, even where measured values exist.
    compared_modes : int
        Modes entering ``error``.
    tolerance : float
        Admissible relative error for the recommendation.
    pareto : list of int
        Indices into ``runs``, by increasing cost.
    recommended : int or None
        Index into ``runs``.
    """

    runs: list
    reference_hz: list
    reference_source: list
    computed_reference_hz: list
    compared_modes: int
    tolerance: float
    pareto: list = field(default_factory=list)
    recommended: int | None = None

    @staticmethod
    def label(run: dict) -> str:
        return f"{run['fidelity']} P{run['order']} h={1e3 * run['mesh_size']:.3g} mm"

    def recommendation_text(self) -> str:
        if self.recommended is None:
            best = int(np.argmin([r["error"] for r in self.runs]))
            return (f"no model is within the tolerance of {percent(self.tolerance)}; the most "
                    f"accurate is {self.label(self.runs[best])} "
                    f"({percent(self.runs[best]['error'])})")
        r = self.runs[self.recommended]
        return (f"{self.label(r)}: estimated error {percent(r['error'])} <= "
                f"{percent(self.tolerance)} in {quantity(r['wall_time_s'], 's', 3)} "
                f"({r['n_elements']} elements, {r['n_dofs']} DOF)")

    def to_dict(self) -> dict:
        return {"runs": self.runs, "reference_hz": self.reference_hz,
                "reference_source": self.reference_source,
                "computed_reference_hz": self.computed_reference_hz,
                "compared_modes": self.compared_modes, "tolerance": self.tolerance,
                "pareto": self.pareto, "recommended": self.recommended,
                "recommendation": self.recommendation_text()}

    def table(self, measured_hz=None, recommended: str = "(recommended)") -> tuple[list, list]:
        """Seed 000 Table 3 style: frequency per mode per model (% difference), element counts.

        Returns the header and the rows (None for an empty cell): the experiment (when
        ``measured_hz`` is given), the computed reference, then one row per model, its label
        followed by ``recommended`` or ``(Pareto)`` where it applies.
        """
        n = len(self.reference_hz)
        head = ["model", "elements", "DOF", "time, s"] + [f"mode {k + 1}, Hz" for k in range(n)] \
            + ["error"]
        rows = []
        if measured_hz:
            cells = [f"{f:.0f}" if f is not None else "/" for f in measured_hz[:n]]
            rows.append(["experiment", None, None, None] + cells + ["/"] * (n - len(cells)) + [None])
        src = self.reference_source[-1] if self.reference_source else ""
        rows.append([f"reference: {src}", None, None, None]
                    + [f"{f:.0f}" for f in self.computed_reference_hz] + [None])
        for i, r in enumerate(self.runs):
            mark = f" {recommended}" if i == self.recommended else (
                " (Pareto)" if i in self.pareto else "")
            rows.append([f"{self.label(r)}{mark}", r["n_elements"], r["n_dofs"],
                         f"{r['wall_time_s']:.3g}"] + [cell(r, k) for k in range(n)]
                        + [percent(r["error"], 2)])
        return head, rows

    def table_markdown(self, measured_hz=None) -> str:
        """:meth:`table` as Markdown, the recommended model in bold."""
        head, rows = self.table(measured_hz, recommended="**(recommended)**")
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["|" + "|".join(" " if c is None else f" {c} " for c in row) + "|" for row in rows]
        return "\n".join(lines)


def cell(run: dict, k: int) -> str:
    """``1336 (-1.5 %)`` for reference mode k; ``†`` marks a mode paired out of rank order,
    ``?`` one paired by rank because no mode had MAC >= MIN_PAIR_MAC."""
    mark = ""
    if run.get("pair_mac") is not None and run["pair_mac"][k] is None:
        mark = "?"
    elif run.get("mode_of") is not None and run["mode_of"][k] != k:
        mark = f"† (mode {run['mode_of'][k] + 1})"
    return f"{run['matched_hz'][k]:.0f} ({100 * run['rel_diff'][k]:+.1f} %){mark}"


def evaluate(runs: list[dict], n_modes: int, measured_hz=None, tolerance: float = 0.05,
             compared_modes: int | None = None) -> SimplificationStudy:
    """Reference, errors, Pareto front and recommendation of finished runs.

    Parameters
    ----------
    runs : list of dict
        Each with ``fidelity``, ``order``, ``mesh_size``, ``frequencies_hz``, ``wall_time_s``
        (and any counts); ``rel_diff`` and ``error`` are added.
    n_modes : int
        Modes tabulated.
    measured_hz : sequence, optional
    tolerance : float
        Relative.
    compared_modes : int, optional
        Modes entering the error (default: the measured ones if given, else all).
    """
    ref, source, computed = reference_frequencies(runs, n_modes, measured_hz)
    if compared_modes is None:
        compared_modes = len(measured_hz) if measured_hz else n_modes
    compared_modes = max(1, min(compared_modes, n_modes))
    match_modes(runs, n_modes)
    for r in runs:
        f = np.asarray(r["matched_hz"], float)
        d = (f - ref) / ref
        r["rel_diff"] = d.tolist()
        r["error"] = float(np.max(np.abs(d[:compared_modes])))
    cost = [r["wall_time_s"] for r in runs]
    err = [r["error"] for r in runs]
    front = pareto_front(cost, err)
    return SimplificationStudy(runs=runs, reference_hz=ref.tolist(), reference_source=source,
                               computed_reference_hz=computed.tolist(),
                               compared_modes=compared_modes, tolerance=float(tolerance),
                               pareto=front.tolist(), recommended=recommend(cost, err, tolerance))


def reference_run(runs: list[dict]) -> int:
    """Index of the finest ``full`` run at the highest order (any fidelity if none is full)."""
    full = [i for i, r in enumerate(runs) if r["fidelity"] == "full"] or list(range(len(runs)))
    return max(full, key=lambda i: (runs[i]["order"], -runs[i]["mesh_size"]))


def finest_per_fidelity(runs: list[dict]) -> dict:
    """Index of the finest run at the highest order of each fidelity -> fidelity name."""
    best = {}
    for i, r in enumerate(runs):
        key = (r["order"], -r["mesh_size"])
        if r["fidelity"] not in best or key > best[r["fidelity"]][0]:
            best[r["fidelity"]] = (key, i)
    return {i: fid for fid, (_, i) in best.items()}


def match_modes(runs: list[dict], n_modes: int) -> None:
    """Pair every run's modes with the reference run's by MAC; add ``matched_hz``, ``mode_of``.

    ``mode_of[k]`` is the run's mode (0-based) paired with reference mode k, ``pair_mac[k]`` its
    MAC (None when compared by rank). Runs without ``probe_shapes`` are compared by rank. The
    probe shapes are removed from the runs (they are large and not JSON).
    """
    from .mac import mac_matrix, pair_modes

    shapes = [r.pop("probe_shapes", None) for r in runs]
    k0 = reference_run(runs)
    ref_shapes = shapes[k0]
    for r, sh in zip(runs, shapes):
        f = np.asarray(r["frequencies_hz"], float)
        mode_of = list(range(n_modes))
        macs = [None] * n_modes
        if sh is not None and ref_shapes is not None:
            mac = mac_matrix(sh, ref_shapes[:, :n_modes])
            r["mac_to_reference"] = mac.tolist()
            for i, j, v in pair_modes(mac):
                if v >= MIN_PAIR_MAC:
                    mode_of[j], macs[j] = i, v
        r["mode_of"] = mode_of
        r["pair_mac"] = macs if sh is not None and ref_shapes is not None else None
        r["matched_hz"] = [float(f[i]) if i < len(f) else float("nan") for i in mode_of]
        if not np.all(np.isfinite(r["matched_hz"])):
            from ..errors import NumericalError

            raise NumericalError(f"study: {SimplificationStudy.label(r)} has fewer than "
                                 f"{n_modes} modes; ask for more modes")


def run_models(build, solve, fidelities, sizes, orders, log=None) -> list[dict]:
    """Build and solve every (fidelity, size, order); time both phases.

    Parameters
    ----------
    build : callable
        ``build(fidelity, mesh_size, order) -> Part``.
    solve : callable
        ``solve(part) -> Modes``.

    Returns
    -------
    list of dict
        One per model (see :class:`SimplificationStudy`), each with ``probe_shapes``: its mode
        shapes at the first model's surface points, for :func:`match_modes`.
    """
    from .mac import sample_at
    from .render import boundary_surface

    runs, probes = [], None
    for fid in fidelities:
        for order in orders:
            for h in sorted(sizes, reverse=True):
                t0 = time.perf_counter()
                part = build(fid, h, order)
                t1 = time.perf_counter()
                modes = solve(part)
                t2 = time.perf_counter()
                cells = part.mesh.cells[0].data
                if probes is None:  # the first model's surface nodes, thinned out
                    surf = boundary_surface(part.mesh.points, cells).points
                    probes = surf[::max(1, len(surf) // MAX_PROBES)]
                sampled, _ = sample_at(part.mesh.points, modes.shapes, probes)
                runs.append({"fidelity": fid, "mesh_size": float(h), "order": int(order),
                             "n_elements": part.n_elements, "n_nodes": part.n_nodes,
                             "n_dofs": int(modes.n_dofs), "mesh_time_s": t1 - t0,
                             "solve_time_s": t2 - t1, "wall_time_s": t2 - t0,
                             "frequencies_hz": np.asarray(modes.frequencies_hz, float).tolist(),
                             "probe_shapes": sampled})
                if log:
                    log(f"  {SimplificationStudy.label(runs[-1])}: {part.n_elements} elements, "
                        f"{t2 - t0:.1f} s, f1 = {modes.frequencies_hz[0]:.1f} Hz")
    return runs


def write_study(study: SimplificationStudy, out_dir, measured_hz=None, title="",
                figures: bool = True) -> dict:
    """Write ``study.md``, ``study.csv`` and the error-vs-time / convergence plots.

    Returns
    -------
    dict
        Paths written.
    """
    import csv

    from ..results import atomic_path, make_out_dir, write_atomic
    from . import plots

    out_dir = make_out_dir(out_dir)
    paths = {}
    n = len(study.reference_hz)
    csv_path = out_dir / "study.csv"
    with atomic_path(csv_path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["fidelity", "order", "mesh_size_m", "n_elements", "n_nodes", "n_dofs",
                    "mesh_time_s", "solve_time_s", "wall_time_s", "error", "pareto",
                    "recommended"] + [f"f{k + 1}_hz" for k in range(n)]
                   + [f"rel_diff_{k + 1}" for k in range(n)])
        for i, r in enumerate(study.runs):
            w.writerow([r["fidelity"], r["order"], r["mesh_size"], r["n_elements"], r["n_nodes"],
                        r["n_dofs"], f"{r['mesh_time_s']:.4g}", f"{r['solve_time_s']:.4g}",
                        f"{r['wall_time_s']:.4g}", f"{r['error']:.6g}", int(i in study.pareto),
                        int(i == study.recommended)] + [f"{f:.6g}" for f in r["matched_hz"][:n]]
                       + [f"{d:.6g}" for d in r["rel_diff"]])
    paths["csv"] = csv_path
    if figures:
        paths["error_vs_time"] = plots.plot_error_vs_time(study, out_dir / "error_vs_time.png")
        paths["convergence"] = plots.plot_convergence(study.runs, out_dir / "convergence.png",
                                                      reference_hz=study.computed_reference_hz)
        k0 = reference_run(study.runs)
        ref = study.runs[k0]
        for k, name in finest_per_fidelity(study.runs).items():
            r = study.runs[k]
            if k == k0 or "mac_to_reference" not in r:
                continue
            paths[f"mac_{name}"] = plots.plot_mac(
                r["mac_to_reference"], out_dir / f"mac_{name}.png",
                [f"{i + 1}: {f:.0f} Hz" for i, f in enumerate(r["frequencies_hz"])],
                [f"{j + 1}: {f:.0f} Hz" for j, f in enumerate(ref["frequencies_hz"][:n])],
                title=f"MAC: {study.label(r)}\nagainst {study.label(ref)}",
                xlabel="reference modes", ylabel=f"{name} modes")
    sources = ", ".join(sorted(set(study.reference_source)))
    md = [f"# {title or 'Mesh-simplification study'}", "",
          (f"Reference per mode: {sources}. Error = largest |f − f_ref| / f_ref over the first "
           f"{study.compared_modes} modes; cost = wall time to mesh and solve. Modes are paired "
           f"with the reference model's by MAC (†: paired out of rank order)."), "",
          study.table_markdown(measured_hz), "",
          (f"**Recommendation** (tolerance ±{percent(study.tolerance)}): "
           f"{study.recommendation_text()}."), ""]
    if figures:
        md += ["![error against run time](error_vs_time.png)", "",
               "![frequency against DOF](convergence.png)", ""]
        md += [f"![{k.replace('_', ' ')}]({paths[k].name})" + "\n" for k in paths
               if k.startswith("mac_")]
    paths["markdown"] = write_atomic(out_dir / "study.md", "\n".join(md))
    return paths
