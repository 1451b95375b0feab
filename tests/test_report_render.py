"""Off-screen renders: outward boundary surface (divergence theorem), non-trivial PNGs, GIF, sheet."""

import numpy as np
import pytest

from crankmodal.fem import testparts
from crankmodal.report.render import boundary_surface, part_camera

pytest.importorskip("pyvista")


def _image(path):
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"))


def _surface_integrals(surf):
    p = surf.points[surf.faces]
    n = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])  # area-weighted normals
    area = np.linalg.norm(n, axis=1).sum()
    volume = np.einsum("ij,ij->", p.mean(axis=1), n) / 3.0  # ∮ x·n dA / 3
    return area, volume


@pytest.mark.parametrize("order", [1, 2])
def test_bar_surface_has_exact_area_and_encloses_exact_volume_so_faces_point_outwards(order):
    L, b, h = 0.3, 0.04, 0.02
    part = testparts.bar(L, b, h, divisions=(6, 2, 1), order=order)
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    area, volume = _surface_integrals(surf)
    assert area == pytest.approx(2 * (L * b + L * h + b * h), rel=1e-12)
    assert volume == pytest.approx(L * b * h, rel=1e-12)  # negative if any face were inverted
    assert surf.points.shape[0] == 7 * 3 * 2  # one element thick: every grid node is on it


def test_p2_tube_is_drawn_through_corner_nodes_only():
    part = testparts.tube(0.05, 0.1, 0.1, divisions=(2, 16, 2), order=2)
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    corners = np.unique(part.mesh.cells[0].data[:, :4])
    assert set(surf.node_ids) <= set(corners)
    _, volume = _surface_integrals(surf)
    # a 16-gon tube: the polygon areas, not the circle's (exact for flat corner facets)
    poly = 0.5 * 16 * np.sin(2 * np.pi / 16)
    assert volume == pytest.approx(poly * (0.1 ** 2 - 0.05 ** 2) * 0.1, rel=1e-12)


@pytest.fixture(scope="module")
def bar_modes():
    from crankmodal.fem.assembly import assemble
    from crankmodal.fem.materials import material
    from crankmodal.fem.modal import solve_modes

    part = testparts.bar(0.3, 0.03, 0.02, divisions=(16, 2, 2), order=2)
    return part, solve_modes(assemble(part, material("steel")), 3)


def test_mode_render_is_a_non_blank_png_of_the_asked_size_with_a_colour_ramp(tmp_path, bar_modes):
    from crankmodal.report.render import render_modes

    part, modes = bar_modes
    out = render_modes(part.mesh.points, part.mesh.cells[0].data, modes.frequencies_hz[:2],
                       modes.shapes[:, :2], tmp_path, labels=["bending about y", "bending about z"],
                       window_size=(400, 300))
    img = _image(out["modes"][0])
    assert img.shape == (300, 400, 3)
    not_white = np.any(img < 235, axis=2).mean()
    assert 0.05 < not_white < 0.9  # the part fills a real share of the picture, not all of it
    colours = np.unique(img.reshape(-1, 3) // 16, axis=0)
    assert len(colours) > 40  # a colour map, shading and text, not a flat fill
    # turbo: both ends of the ramp appear (a bending mode has nodes ~0 and ends at the max)
    reds = np.sum((img[..., 0] > 150) & (img[..., 1] < 90) & (img[..., 2] < 90))
    blues = np.sum((img[..., 2] > 120) & (img[..., 0] < 90))
    assert reds > 50 and blues > 50
    sheet = _image(out["sheet"])
    assert sheet.shape[1] == 2 * 512  # two modes side by side


def test_the_same_part_gets_the_same_camera_whatever_the_mode():
    part = testparts.bar(0.3, 0.03, 0.02, divisions=(4, 1, 1), order=1)
    a = part_camera(part.mesh.points)
    b = part_camera(part.mesh.points.copy())
    assert a == b
    view = np.subtract(a["position"], a["focal_point"])
    assert abs(view @ np.array(a["view_up"])) < 1e-12 * np.linalg.norm(view)


def test_gif_has_one_frame_per_step_and_the_shape_swings_both_ways(tmp_path, bar_modes):
    from PIL import Image

    from crankmodal.report.render import animate_mode

    part, modes = bar_modes
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    path = animate_mode(surf, modes.shapes[:, 0], tmp_path / "m.gif", "mode 1",
                        part_camera(surf.points), n_frames=4, window_size=(200, 150))
    im = Image.open(path)
    assert im.n_frames == 4
    frames = []
    for k in range(4):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB"), int))
    assert np.abs(frames[1] - frames[3]).sum() > 0  # +max and -max differ


def test_von_mises_render_of_a_linear_field_shows_the_whole_jet_ramp(tmp_path):
    from crankmodal.report.render import render_scalar

    part = testparts.bar(0.3, 0.03, 0.02, divisions=(10, 2, 2), order=1)
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    stress = 1e8 * part.mesh.points[:, 0] / 0.3  # 0 .. 100 MPa along the bar
    path = render_scalar(surf, stress, tmp_path / "vm.png", "von Mises", part_camera(surf.points),
                         window_size=(400, 300))
    img = _image(path).astype(int)
    reds = np.sum((img[..., 0] > 180) & (img[..., 1] < 80) & (img[..., 2] < 80))
    blues = np.sum((img[..., 2] > 150) & (img[..., 0] < 60) & (img[..., 1] < 80))
    assert reds > 100 and blues > 100


def test_every_render_carries_the_xyz_axis_triad_in_its_lower_left_corner(tmp_path, bar_modes):
    """Issue 20: a class such as "bending about y" must be matchable to the picture. The triad's
    three axes (x tomato red, y sea green, z blue) are drawn in the lower-left viewport of the
    mode PNGs and of the stress render, where the part (centred by the camera) never is."""
    from crankmodal.report.render import render_modes, render_scalar

    part, modes = bar_modes
    out = render_modes(part.mesh.points, part.mesh.cells[0].data, modes.frequencies_hz[:1],
                       modes.shapes[:, :1], tmp_path, labels=["bending about y"],
                       window_size=(400, 300))
    vm = render_scalar(out["surface"], part.mesh.points[:, 0], tmp_path / "vm.png", "x",
                       out["camera"], window_size=(400, 300))
    for path in (out["modes"][0], vm):
        img = _image(path).astype(int)
        h, w, _ = img.shape
        box = img[int(0.7 * h):int(0.96 * h), :int(0.17 * w)]
        r, g, b = box[..., 0], box[..., 1], box[..., 2]
        assert np.sum((g > r + 40) & (g > b + 20)) > 10, path  # y axis
        assert np.sum((r > g + 80) & (r > b + 80)) > 10, path  # x axis
        assert np.sum((b > r + 80) & (b > g + 80)) > 10, path  # z axis


def test_a_stress_peak_at_an_undrawn_node_is_said_under_the_render():
    """The seed 000 rod's von Mises render said "max 25.5 MPa" in its title while its colour bar
    stopped at 19.8 MPa: the peak sits at a P2 mid-side node, which the surface does not draw."""
    from crankmodal.report.render import undrawn_peak_note

    part = testparts.bar(0.3, 0.03, 0.02, divisions=(4, 1, 1), order=2)
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    corners = np.unique(part.mesh.cells[0].data[:, :4])
    mid = np.setdiff1d(np.arange(len(part.mesh.points)), corners)[0]
    v = np.ones(len(part.mesh.points))
    v[mid] = 25.5
    note = undrawn_peak_note(v, v[surf.node_ids])
    assert note is not None and "up to 1;" in note and "25.5" in note
    v[corners[0]] = 25.5  # the maximum on a drawn node too: nothing to say
    assert undrawn_peak_note(v, v[surf.node_ids]) is None


def test_a_gif_frame_keeps_the_whole_title_and_colour_bar_label_inside_the_picture(tmp_path,
                                                                                    bar_modes):
    """Issue 25 #15 (the crank report's GIFs read 'lode 1: 1192.3 Hz, bending about' and
    'displacement /'): the title band and the colour bar's label stay clear of the picture's
    left and right edges."""
    from PIL import Image

    from crankmodal.report.render import animate_mode

    part, modes = bar_modes
    surf = boundary_surface(part.mesh.points, part.mesh.cells[0].data)
    path = animate_mode(surf, modes.shapes[:, 0], tmp_path / "m.gif",
                        "Mode 1: 1192.3 Hz, bending about y", part_camera(surf.points),
                        n_frames=2)
    img = np.asarray(Image.open(path).convert("L"), int)
    h, w = img.shape
    band = img[: int(0.2 * h)]  # title and the colour bar's label
    ink = np.flatnonzero((band < 128).any(axis=0))
    assert ink.size, "no title drawn"
    margin = int(0.01 * w)
    assert ink.min() > margin and ink.max() < w - 1 - margin, (ink.min(), ink.max(), w)
