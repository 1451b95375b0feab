"""Figures of a fatigue verdict: safety per location with the Haigh diagram, and the crank
coloured by safety factor (off-screen pyvista). matplotlib and pyvista are imported inside."""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: colour scale of the crank picture: from the smallest safety factor to this multiple of it
COLOUR_SPAN = 4.0


def plot_safety(result, path=None, required: float | None = None):
    """Safety factor per location (bars, worst point of each) and the Haigh diagram.

    The Haigh diagram plots each location's worst point (equivalent mean, equivalent
    alternating stress, MPa) under the mean-stress line from ``S_e`` to ``S_u`` (Goodman's
    straight line or Gerber's parabola).

    Parameters
    ----------
    result : FatigueResult
    path : str or Path, optional
        PNG to write (atomically); without it the figure is returned.
    required : float, optional
        The required safety factor: a line on the bars, and the mean-stress line divided by it
        (dashed) on the Haigh diagram.

    Returns
    -------
    Path or matplotlib.figure.Figure
    """
    from ..plotting import pyplot
    from ..results import savefig_atomic

    locs = result.locations()
    names = list(locs)
    n = np.array([locs[k]["safety_factor"] for k in names])
    fig, (ax, hx) = pyplot().subplots(1, 2, figsize=(12, 0.3 * len(names) + 4.0),
                                      gridspec_kw={"width_ratios": [1.2, 1.0]})
    shown = np.where(np.isfinite(n), n, np.nan)
    colours = ["#c0392b" if v < 1 else "#e67e22" if v < 1.5 else "#27ae60" for v in n]
    ax.barh(range(len(names)), np.nan_to_num(shown, nan=0.0), color=colours)
    ax.set_yticks(range(len(names)), [k.replace("_", " ") for k in names], fontsize=8)
    ax.invert_yaxis()
    ax.axvline(1.0, color="black", lw=1)
    if required is not None:
        ax.axvline(required, color="#c0392b", lw=1, ls="--", label=f"required {required:.3g}")
        ax.legend(fontsize=8, loc="lower right")
    for i, v in enumerate(n):
        ax.text(v if np.isfinite(v) else 0.0, i, f" {v:.3g}", va="center", fontsize=8)
    worst = result.worst_location
    ax.set_xlabel("fatigue safety factor (worst point of each location)")
    ax.set_title(f"{result.rule.capitalize()}, {result.material}; worst: "
                 f"{worst.replace('_', ' ') if worst else '-'}", fontsize=10)
    se, su = result.fatigue_strength / 1e6, result.ultimate_strength / 1e6
    m = np.linspace(0.0, su, 200)
    line = se * (1 - m / su) if result.rule == "goodman" else se * (1 - (m / su) ** 2)
    hx.plot(m, line, color="black", lw=1.5, label=f"{result.rule} line (S_e = {se:.4g} MPa)")
    hx.plot([-su, 0.0], [se, se], color="black", lw=1.5, ls="--",
            label="compressive mean: no credit")
    if required is not None:
        hx.plot(m, line / required, color="#c0392b", lw=1.0, ls="--",
                label=f"{result.rule} line / required {required:.3g}")
    for k, name in enumerate(names):
        xy = (locs[name]["mean_pa"] / 1e6, locs[name]["alternating_pa"] / 1e6)
        hx.plot(*xy, "o", color=colours[k], ms=5)
        hx.annotate(name.replace("_", " "), xy, xytext=(4, 2 + 7 * (k % 3)),
                    textcoords="offset points", fontsize=6)
    hx.set_xlabel("equivalent mean stress, MPa")
    hx.set_ylabel("equivalent alternating stress, MPa")
    hx.set_title("Haigh diagram (K_f applied to the stresses)", fontsize=10)
    hx.set_xlim(-0.3 * su, su)
    hx.set_ylim(0.0, 1.15 * max(se, max((v["alternating_pa"] / 1e6 for v in locs.values()),
                                        default=0.0)))
    hx.legend(fontsize=8)
    fig.tight_layout()
    if path is None:
        return fig
    return savefig_atomic(fig, path, dpi=110)


def plot_crank(result, mesh_points, cells, path, title: str | None = None) -> Path:
    """PNG of the part's outer surface coloured by the fatigue safety factor (off-screen).

    Points not assessed are grey; the colour runs from the smallest safety factor (red) to
    :data:`COLOUR_SPAN` times it (green, larger values clipped). The surface is drawn through
    its corner nodes: a minimum at a P2 mid-side node colours its neighbourhood only.

    Parameters
    ----------
    result : FatigueResult
    mesh_points : ndarray, shape (n_points, 3)
        The mesh the result's nodes index, m.
    cells : ndarray of int, shape (n_elements, 4 or 10)
        Tetrahedra (meshio order).
    path : str or Path
        PNG to write.
    title : str, optional

    Returns
    -------
    Path
    """
    from ..arguments import path as path_argument
    from ..errors import ParameterError
    from ..report.render import _finish, _plotter, boundary_surface, part_camera

    path_argument("path", path)
    pts = np.asarray(mesh_points, float)
    cells = np.asarray(cells)
    if pts.ndim != 2 or pts.shape[1] != 3 or result.nodes.max() >= len(pts):
        raise ParameterError("mesh_points", f"must be the (n_points, 3) points the result's "
                                            f"nodes index (up to {int(result.nodes.max())}), "
                                            f"got {pts.shape}")
    if cells.ndim != 2 or cells.shape[1] not in (4, 10) or cells.dtype.kind not in "iu" \
            or cells.min() < 0 or cells.max() >= len(pts):
        raise ParameterError("cells", "must be tetrahedra (n, 4 or 10) indexing mesh_points")
    surface = boundary_surface(pts, cells)
    field = np.full(len(pts), np.nan)
    field[result.nodes] = result.safety_factor
    v = field[surface.node_ids]
    lo = result.min_safety_factor
    hi = COLOUR_SPAN * lo if np.isfinite(lo) and lo > 0 else 1.0
    worst = result.worst_location
    if title is None:
        title = (f"fatigue safety factor, min {lo:.3g}"
                 + (f"; worst location {worst.replace('_', ' ')}" if worst else ""))
    camera = part_camera(pts)
    pl = _plotter((1024, 768))
    try:
        mesh = surface.to_pyvista()
        label = "safety factor"
        mesh.point_data[label] = np.minimum(v, hi)
        pl.add_mesh(mesh, scalars=label, cmap="RdYlGn", clim=(lo, hi), nan_color="#bbbbbb",
                    smooth_shading=True, split_sharp_edges=True,
                    scalar_bar_args={"title": label, "color": "black", "vertical": True,
                                     "position_x": 0.87, "position_y": 0.15, "height": 0.7,
                                     "width": 0.06, "fmt": "%.3g"})
        i = int(np.argmin(result.safety_factor))
        pl.add_point_labels(result.points[i:i + 1], [f"min {lo:.3g}"], font_size=14,
                            point_color="black", point_size=12, text_color="black",
                            shape_color="white", always_visible=True)
        pl.add_text(title, position="upper_edge", font_size=13, color="black")
        pl.add_text(f"grey: not assessed; colours clipped at {hi:.3g}", position="lower_left",
                    font_size=9, color="#555555")
        _finish(pl, camera, path)
    finally:
        pl.close()
    return Path(path)
