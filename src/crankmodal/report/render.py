"""Off-screen pyvista renders: mode shapes over an undeformed ghost, stress fields, GIFs.

Only the outer surface of the tetrahedral mesh is drawn. It is extracted once per part
(:func:`boundary_surface`: the corner triangles that belong to a single tetrahedron, oriented
outwards), so a P2 mesh is drawn through its corner nodes — its mid-side nodes only bend the
facets, which a render at this scale does not show. Every render of a part uses the same
camera (:func:`part_camera`), so mode shapes can be compared picture by picture.

pyvista (VTK) is imported inside the functions; nothing needs a display (``off_screen``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..results import atomic_path, make_out_dir

#: Largest drawn displacement as a fraction of the part's bounding-box diagonal.
DEFORMATION_FRACTION = 0.08

#: Default picture size (width, height), pixels.
WINDOW_SIZE = (1024, 768)


@dataclass
class Surface:
    """Outer surface of a tetrahedral mesh.

    Attributes
    ----------
    node_ids : ndarray of int, shape (n,)
        Mesh point index of each surface point.
    points : ndarray, shape (n, 3)
        Their coordinates, m.
    faces : ndarray of int, shape (m, 3)
        Triangles into ``points``, counter-clockwise seen from outside.
    """

    node_ids: np.ndarray
    points: np.ndarray
    faces: np.ndarray

    def displacement(self, field: np.ndarray) -> np.ndarray:
        """The surface points' rows of a node-interleaved field (3 n_mesh_points,) → (n, 3)."""
        return np.asarray(field, float).reshape(-1, 3)[self.node_ids]

    def to_pyvista(self, points: np.ndarray | None = None):
        import pyvista as pv

        cells = np.hstack([np.full((len(self.faces), 1), 3), self.faces]).ravel()
        return pv.PolyData(np.asarray(self.points if points is None else points, float), cells)


def boundary_surface(points: np.ndarray, cells: np.ndarray) -> Surface:
    """Outward-oriented boundary triangles (corner nodes only) of a tet4/tet10 mesh.

    Parameters
    ----------
    points : ndarray, shape (n_points, 3)
    cells : ndarray of int, shape (n_elements, 4 or 10)
        meshio node order (corners first).
    """
    from ..topology import boundary_facets

    faces, opposite = boundary_facets(cells, opposite=True)
    p = np.asarray(points, float)
    n = np.cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]])
    inward = np.einsum("ij,ij->i", n, p[opposite] - p[faces[:, 0]]) > 0
    faces[inward] = faces[inward][:, ::-1]
    node_ids, local = np.unique(faces, return_inverse=True)
    return Surface(node_ids=node_ids, points=p[node_ids], faces=local.reshape(-1, 3))


def part_camera(points: np.ndarray, axis=None) -> dict:
    """A three-quarter view of a part, the same for every render of it.

    The view looks across the part's long axis (default: principal axis of the points), from
    above and a little along the axis, with the global axis most perpendicular to it as "up".

    Returns
    -------
    dict
        ``position``, ``focal_point``, ``view_up`` (m) and ``diagonal`` (bounding-box diagonal).
    """
    p = np.asarray(points, float)
    c = 0.5 * (p.min(axis=0) + p.max(axis=0))
    if axis is None:
        x = p - p.mean(axis=0)
        a = np.linalg.eigh(x.T @ x)[1][:, -1]
    else:
        a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    up = np.eye(3)[int(np.argmin(np.abs(a)))] if abs(a[2]) > 0.9 else np.array([0.0, 0.0, 1.0])
    up = up - a * (up @ a)
    up /= np.linalg.norm(up)
    side = np.cross(up, a)
    view = 0.95 * side + 0.55 * up + 0.35 * a
    view /= np.linalg.norm(view)
    diag = float(np.linalg.norm(np.ptp(p, axis=0)))
    up_cam = up - view * (up @ view)
    return {"position": (c + 1.75 * diag * view).tolist(), "focal_point": c.tolist(),
            "view_up": (up_cam / np.linalg.norm(up_cam)).tolist(), "diagonal": diag}


def _headless_egl() -> None:
    """On Linux without a display, let VTK open its EGL window straight away.

    VTK's default tries X first, prints "bad X server connection" and only then falls back to
    EGL (0.25 s more per plotter). A user's choice (``VTK_DEFAULT_OPENGL_WINDOW``) is kept, and
    nothing changes where libEGL is missing or a display is there.
    """
    import ctypes.util
    import os
    import sys

    if (sys.platform.startswith("linux") and not os.environ.get("DISPLAY")
            and not os.environ.get("WAYLAND_DISPLAY") and ctypes.util.find_library("EGL")):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def _plotter(window_size):
    _headless_egl()
    import pyvista as pv

    pv.OFF_SCREEN = True
    pl = pv.Plotter(off_screen=True, window_size=list(window_size))
    pl.set_background("white")
    return pl


def _add_triad(pl):
    """The x/y/z axis triad in the lower-left corner (above the scale note), so a class such as
    "bending about y" can be matched to the picture."""
    pl.add_axes(color="black", line_width=3, labels_off=False, viewport=(0.0, 0.04, 0.17, 0.3))


def _finish(pl, camera, path) -> None:
    """The axis triad, the camera, and the picture written to ``path`` (atomically)."""
    _add_triad(pl)
    _place_camera(pl, camera)
    with atomic_path(path) as tmp:
        pl.screenshot(str(tmp))


def _place_camera(pl, camera):
    pl.camera_position = [camera["position"], camera["focal_point"], camera["view_up"]]
    pl.camera.view_angle = 30.0


def _deformed(surface: Surface, u: np.ndarray, camera: dict, fraction: float):
    """(scale, |u| normalised to 1 at the maximum) for a displacement (n, 3) on the surface."""
    mag = np.linalg.norm(u, axis=1)
    peak = float(mag.max())
    if not np.isfinite(peak) or peak <= 0:
        raise ValueError("render: the mode shape is zero on the surface")
    return fraction * camera["diagonal"] / peak, mag / peak


def _add_mode_actors(pl, surface, u, camera, fraction, ghost):
    scale, mag = _deformed(surface, u, camera, fraction)
    if ghost:
        pl.add_mesh(surface.to_pyvista(), color="#9a9a9a", opacity=0.22, smooth_shading=False)
    mesh = surface.to_pyvista(surface.points + scale * u)
    mesh.point_data["|u| / max"] = mag
    pl.add_mesh(mesh, scalars="|u| / max", cmap="turbo", clim=(0.0, 1.0), smooth_shading=True,
                split_sharp_edges=True, show_edges=False,
                scalar_bar_args={"title": "displacement / max", "color": "black", "n_labels": 5,
                                 "fmt": "%.1f", "vertical": True, "position_x": 0.87,
                                 "position_y": 0.15, "height": 0.7, "width": 0.06})
    return mesh, scale


def render_mode(surface: Surface, shape: np.ndarray, path, title: str, camera: dict,
                window_size=WINDOW_SIZE, fraction: float = DEFORMATION_FRACTION,
                ghost: bool = True) -> Path:
    """PNG of one mode shape: deformed surface coloured by |u| over the undeformed ghost.

    Parameters
    ----------
    surface : Surface
    shape : ndarray, shape (3 n_mesh_points,)
        Node-interleaved mode shape (any scale; drawn so its peak is ``fraction`` of the part's
        diagonal).
    path : str or Path
        PNG to write.
    title : str
        e.g. ``"Mode 1: 1336.2 Hz, bending about y"``.
    camera : dict
        From :func:`part_camera`.
    """
    pl = _plotter(window_size)
    try:
        _add_mode_actors(pl, surface, surface.displacement(shape), camera, fraction, ghost)
        pl.add_text(title, position="upper_edge", font_size=14, color="black")
        pl.add_text(f"deformation scaled to {100 * fraction:.0f} % of the part's size",
                    position="lower_left", font_size=9, color="#555555")
        _finish(pl, camera, path)
    finally:
        pl.close()
    return Path(path)


def animate_mode(surface: Surface, shape: np.ndarray, path, title: str, camera: dict,
                 n_frames: int = 16, window_size=(640, 480),
                 fraction: float = DEFORMATION_FRACTION) -> Path:
    """Animated GIF of one mode (one period, ``n_frames`` frames), written with Pillow.

    Each frame is drawn as the still is (:data:`WINDOW_SIZE`, the same title and colour bar
    fonts) and scaled down to ``window_size``: drawn directly at the small size the title and the
    colour bar's label ran off the picture."""
    from PIL import Image

    u = surface.displacement(shape)
    pl = _plotter(WINDOW_SIZE)
    frames = []
    try:
        mesh, scale = _add_mode_actors(pl, surface, u, camera, fraction, ghost=True)
        pl.add_text(title, position="upper_edge", font_size=14, color="black")
        _add_triad(pl)
        _place_camera(pl, camera)
        for k in range(n_frames):
            s = np.sin(2 * np.pi * k / n_frames)
            mesh.points = surface.points + s * scale * u
            pl.render()
            img = Image.fromarray(np.asarray(pl.screenshot(None, return_img=True)))
            img = img.resize(tuple(window_size), Image.LANCZOS)
            frames.append(img.convert("P", palette=Image.ADAPTIVE))
    finally:
        pl.close()
    with atomic_path(path) as tmp:
        frames[0].save(tmp, save_all=True, append_images=frames[1:], duration=80, loop=0)
    return Path(path)


def undrawn_peak_note(values: np.ndarray, drawn: np.ndarray, rtol: float = 0.01) -> str | None:
    """A note when the field's maximum lies at a node the surface does not draw (a P2 mid-side
    node or an interior node), so the colour bar stops below the maximum a title states; None
    when the drawn nodes reach it within ``rtol``. Both arrays in the colour bar's units."""
    top, seen = float(np.max(values)), float(np.max(drawn))
    if top <= 0 or seen >= (1.0 - rtol) * top:
        return None
    return (f"colours: the drawn (surface corner) nodes, up to {seen:.3g}; the maximum "
            f"{top:.3g} lies at a node not drawn (mid-side or interior)")


def render_scalar(surface: Surface, values: np.ndarray, path, title: str, camera: dict,
                  label: str = "von Mises stress, MPa", scale: float = 1e-6,
                  displacement: np.ndarray | None = None, window_size=WINDOW_SIZE) -> Path:
    """PNG of a nodal scalar field (e.g. von Mises stress in Pa) on the outer surface.

    Parameters
    ----------
    values : ndarray, shape (n_mesh_points,)
        SI values; multiplied by ``scale`` for the colour bar (Pa → MPa by default).
    displacement : ndarray, shape (n_mesh_points, 3), optional
        Static displacement, m; drawn exaggerated over a ghost when given.
    """
    v = np.asarray(values, float)[surface.node_ids] * scale
    note = undrawn_peak_note(np.asarray(values, float) * scale, v)
    pl = _plotter(window_size)
    try:
        pts = surface.points
        if displacement is not None:
            u = np.asarray(displacement, float).reshape(-1, 3)[surface.node_ids]
            peak = np.linalg.norm(u, axis=1).max()
            if peak > 0:
                pts = pts + 0.5 * DEFORMATION_FRACTION * camera["diagonal"] / peak * u
                pl.add_mesh(surface.to_pyvista(), color="#9a9a9a", opacity=0.22)
        mesh = surface.to_pyvista(pts)
        mesh.point_data[label] = v
        pl.add_mesh(mesh, scalars=label, cmap="jet", smooth_shading=True, split_sharp_edges=True,
                    scalar_bar_args={"title": label, "color": "black", "vertical": True,
                                     "position_x": 0.87, "position_y": 0.15, "height": 0.7,
                                     "width": 0.06, "fmt": "%.3g"})
        pl.add_text(title, position="upper_edge", font_size=14, color="black")
        if note:
            pl.add_text(note, position="lower_left", font_size=9, color="#555555")
        _finish(pl, camera, path)
    finally:
        pl.close()
    return Path(path)


def contact_sheet(paths, path, columns: int = 3, thumb_width: int = 512) -> Path:
    """Tile PNGs into one picture (row by row), each scaled to ``thumb_width`` pixels."""
    from PIL import Image

    imgs = [Image.open(p).convert("RGB") for p in paths]
    if not imgs:
        raise ValueError("contact_sheet: no pictures")
    w = thumb_width
    h = round(imgs[0].height * w / imgs[0].width)
    rows = -(-len(imgs) // columns)
    sheet = Image.new("RGB", (columns * w, rows * h), "white")
    for k, im in enumerate(imgs):
        sheet.paste(im.resize((w, h), Image.LANCZOS), ((k % columns) * w, (k // columns) * h))
    with atomic_path(path) as tmp:
        sheet.save(tmp)
    return Path(path)


def mode_title(k: int, frequency_hz: float, label: str | None = None) -> str:
    """``Mode 3: 1108.2 Hz, bending about y``."""
    return f"Mode {k}: {frequency_hz:.1f} Hz" + (f", {label}" if label else "")


def render_modes(points, cells, frequencies_hz, shapes, out_dir, labels=None, prefix="mode",
                 gif: bool = False, sheet: bool = True, axis=None,
                 window_size=WINDOW_SIZE) -> dict:
    """Render every mode of a part with one camera; optional GIFs and a contact sheet.

    Parameters
    ----------
    points, cells : ndarray
        The part's mesh (meshio order).
    frequencies_hz : array_like, shape (n,)
    shapes : ndarray, shape (3 n_points, n)
    out_dir : Path
    labels : list of str, optional
        Mode classes for the titles.

    Returns
    -------
    dict
        ``modes`` (PNG paths), ``gifs`` (paths, possibly empty), ``sheet`` (path or None),
        ``camera``, ``surface`` (the :class:`Surface`, for further renders of the part).
    """
    out_dir = make_out_dir(out_dir)
    surf = boundary_surface(points, cells)
    cam = part_camera(surf.points, axis)
    shapes = np.asarray(shapes)
    pngs, gifs = [], []
    for k, f in enumerate(np.asarray(frequencies_hz, float)):
        title = mode_title(k + 1, f, labels[k] if labels else None)
        pngs.append(render_mode(surf, shapes[:, k], out_dir / f"{prefix}_{k + 1:02d}.png", title,
                                cam, window_size=window_size))
        if gif:
            gifs.append(animate_mode(surf, shapes[:, k], out_dir / f"{prefix}_{k + 1:02d}.gif",
                                     title, cam))
    sheet_path = None
    if sheet and len(pngs) > 1:
        sheet_path = contact_sheet(pngs, out_dir / f"{prefix}_sheet.png",
                                   columns=3 if len(pngs) > 4 else 2)
    return {"modes": pngs, "gifs": gifs, "sheet": sheet_path, "camera": cam, "surface": surf}
