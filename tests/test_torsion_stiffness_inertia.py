"""Equivalent lengths, shaft stiffness and inertias against independent integrals and identities."""

import math

import numpy as np
import pytest
from scipy.integrate import dblquad

from crankmodal.part import MassProperties
from crankmodal.torsion.equivalent_length import (
    equivalent_segment_length,
    polar_moment,
    series_stiffness,
    shaft_stiffness,
    throw_equivalent_length,
)
from crankmodal.torsion.inertias import (
    crankpin_inertia,
    disc_inertia,
    inertia_about_axis,
    reciprocating_factor,
    rectangular_web_polar_moment,
)

THROW = {"journal_length": 0.1735, "journal_diameter": 0.110, "crankpin_length": 0.0595,
         "crankpin_diameter": 0.095, "crank_radius": 0.060, "web_thickness": 0.0665, "web_width": 0.145}


def test_stepped_shaft_equivalent_length_gives_series_stiffness():
    # Springs in series 1/k = sum L_i / (G J_i), each from its own section (no equivalent length used)
    G = 8.0e10
    segs = [(0.06, 0.2, 0.0), (0.04, 0.15, 0.0), (0.08, 0.3, 0.05)]  # (d, L, bore)
    k_series = 1.0 / sum(L / (G * math.pi / 32 * (d**4 - b**4)) for d, L, b in segs)
    d_ref = 0.05
    l_eq = sum(equivalent_segment_length(L, d, d_ref, b) for d, L, b in segs)
    assert shaft_stiffness(G, d_ref, l_eq) == pytest.approx(k_series, rel=1e-13)
    assert series_stiffness([shaft_stiffness(G, d, L, b) for d, L, b in segs]) == pytest.approx(k_series, rel=1e-13)


def test_throw_equivalent_length_referred_to_other_diameter_keeps_stiffness():
    G = 6.86e10
    l_j = throw_equivalent_length(**THROW)
    for d_ref in (0.05, 0.095, 0.2):
        l_r = throw_equivalent_length(**THROW, reference_diameter=d_ref)
        assert l_r == pytest.approx(l_j * (d_ref / 0.110) ** 4, rel=1e-13)
        assert G * polar_moment(d_ref) / l_r == pytest.approx(G * polar_moment(0.110) / l_j, rel=1e-13)


def test_hollow_crankpin_lengthens_only_the_pin_term():
    # The pin term scales with d_p^4 / (d_p^4 - d_i^4); everything else unchanged.
    solid = throw_equivalent_length(**THROW)
    hollow = throw_equivalent_length(**THROW, crankpin_bore=0.05)
    pin_solid = 3.288 * 0.0595 * (0.110 / 0.095) ** 4
    assert hollow - solid == pytest.approx(pin_solid * (0.095**4 / (0.095**4 - 0.05**4) - 1), rel=1e-12)


def test_carter_and_seed_forms_differ_only_in_pin_and_web_coefficients():
    seed = throw_equivalent_length(**THROW, form="seed004")
    carter = throw_equivalent_length(**THROW, form="carter")
    pin = 0.0595 * (0.110 / 0.095) ** 4
    webs = 0.060 * 0.110**4 * 2 / (0.0665 * 0.145**3)
    assert seed - carter == pytest.approx((3.288 - 0.75) * pin + (1.284 - 0.75) * webs, rel=1e-12)


@pytest.mark.parametrize("bore", [0.0, 0.04])
def test_crankpin_inertia_equals_area_integral_of_r2_about_shaft_axis(bore):
    # Oracle: rho l * integral of (x^2 + y^2) over the pin section centred at (R, 0), by quadrature.
    d, l, R, rho = 0.095, 0.0595, 0.060, 7200.0
    ro, ri = d / 2, bore / 2
    val, _ = dblquad(lambda r, t: ((R + r * np.cos(t)) ** 2 + (r * np.sin(t)) ** 2) * r,
                     0, 2 * np.pi, ri, ro, epsabs=1e-14, epsrel=1e-12)
    assert crankpin_inertia(d, l, R, rho, bore) == pytest.approx(rho * l * val, rel=1e-9)


def test_rectangular_web_polar_moment_equals_area_integral():
    W, below, beyond = 0.145, 0.095, 0.155
    val, _ = dblquad(lambda y, x: x * x + y * y, -W / 2, W / 2, -below, beyond, epsabs=1e-14, epsrel=1e-12)
    assert rectangular_web_polar_moment(W, below, beyond) == pytest.approx(val, rel=1e-10)


def test_disc_inertia_is_half_m_r2():
    D, t, rho = 0.3848, 0.134, 7200.0
    m = rho * math.pi * D**2 / 4 * t
    assert disc_inertia(D, t, rho) == pytest.approx(m * D**2 / 8, rel=1e-14)


def test_cad_solid_inertia_about_shaft_axis_by_parallel_axis_matches_crankpin_formula():
    # A cylinder along x, offset R in y and z, as the CAD would report it (about the centroid).
    d, l, R, rho = 0.095, 0.0595, 0.060, 7200.0
    a = d / 2
    vol = math.pi * a**2 * l
    ic = np.diag([vol * a**2 / 2, vol * (3 * a**2 + l**2) / 12, vol * (3 * a**2 + l**2) / 12])
    off = R / math.sqrt(2)
    mp = MassProperties(volume=vol, centroid=np.array([0.3, off, off]), inertia_per_density=ic)
    assert inertia_about_axis(mp, rho, (0, 0, 0), (2.0, 0, 0)) == pytest.approx(
        crankpin_inertia(d, l, R, rho), rel=1e-13)


def test_reciprocating_factor_of_seed_0p508_means_rod_ratio_about_one_quarter():
    assert reciprocating_factor(1.0, 1.0 / math.sqrt(0.064)) == pytest.approx(0.508, rel=1e-12)


def _box_tets(lo, hi, n):
    """A box split into n^3 hexahedra, each into 6 tetrahedra (Kuhn split)."""
    g = [np.linspace(lo[k], hi[k], n + 1) for k in range(3)]
    X, Y, Z = np.meshgrid(*g, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    idx = np.arange(len(pts)).reshape(n + 1, n + 1, n + 1)
    cells = []
    perms = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    for i in range(n):
        for j in range(n):
            for k in range(n):
                for p in perms:
                    v, path = [i, j, k], [idx[i, j, k]]
                    for axis in p:
                        v[axis] += 1
                        path.append(idx[tuple(v)])
                    cells.append(path)
    return pts, np.array(cells)


def test_mesh_slab_inertias_equal_box_formula_with_parallel_axis():
    # Box 0.2 (x, along the shaft) x 0.1 x 0.06, shaft axis along x through (0, 0.05, 0):
    # each half-length slab: m (b^2 + c^2) / 12 + m d^2, d = distance of the box centre from the axis
    from crankmodal.torsion.mesh_inertias import slab_axial_inertias

    rho = 7200.0
    pts, cells = _box_tets((0.0, 0.0, 0.0), (0.2, 0.1, 0.06), 4)
    out = slab_axial_inertias(pts, cells, rho, cuts=[0.1], axis_point=(0, 0.05, 0), axis_direction=(1, 0, 0))
    m = rho * 0.1 * 0.1 * 0.06
    expect = m * (0.1**2 + 0.06**2) / 12 + m * 0.03**2
    np.testing.assert_allclose(out, [expect, expect], rtol=1e-12)


def _gmsh_p2_cylinders(R, r, lengths, size):
    """Coaxial cylinders (bore r, 0 for solid) stacked along z, meshed by gmsh at second order.

    The Part's path: OCC solids fragmented so the mesh conforms at the joints, curved P2 cells,
    converted to meshio's tetra10 node order by the geometry stage's own ``to_meshio``.
    """
    from crankmodal.geometry.mesh import MeshSettings, generate, to_meshio
    from crankmodal.geometry.session import gmsh_session

    with gmsh_session("test cylinder") as gmsh:
        occ = gmsh.model.occ
        z, vols = 0.0, []
        for length in lengths:
            vols.append((3, occ.addCylinder(0, 0, z, 0, 0, length, R)))
            z += length
        if r > 0:
            hole = occ.addCylinder(0, 0, -1.0, 0, 0, z + 2.0, r)
            vols, _ = occ.cut(vols, [(3, hole)])
        if len(vols) > 1:
            occ.fragment(vols[:1], vols[1:])
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMin", size)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        generate(gmsh, MeshSettings(size=size, order=2))
        mesh, _ = to_meshio(gmsh)
    assert mesh.cells[0].type == "tetra10"
    return mesh.points, mesh.cells[0].data


def test_mesh_slab_inertias_of_a_curved_p2_cylinder_follow_the_circle():
    # Solid cylinder R = 50 mm, L = 60 mm about its axis: rho pi L R^4 / 2. gmsh P2 at h = 10 and
    # 20 mm (R/h = 5, 2.5). Measured: curved -3.5e-6 (h = 10 mm) and -5.5e-5 (20 mm), order 3.96
    # (3.9-4.0 down to h = 2.5 mm); corner-only (straight-edged) -9.6e-3 and -3.7e-2, order 1.96.
    from crankmodal.torsion.mesh_inertias import slab_axial_inertias

    rho, R, L = 7850.0, 0.05, 0.06
    exact = rho * math.pi * L * R**4 / 2
    err = {}
    for h in (0.02, 0.01):
        pts, cells = _gmsh_p2_cylinders(R, 0.0, [L], h)
        curved = slab_axial_inertias(pts, cells, rho, [], (0, 0, 0), (0, 0, 1)).sum()
        corner = slab_axial_inertias(pts, cells[:, :4], rho, [], (0, 0, 0), (0, 0, 1)).sum()
        err[h] = (curved / exact - 1, corner / exact - 1)
    curved, corner = err[0.01]
    assert abs(curved) < 1e-5
    assert abs(curved) * 100 < abs(corner)
    # geometric convergence: at least third order for the P2 surface, second for straight edges
    assert math.log2(abs(err[0.02][0] / err[0.01][0])) > 3.0
    assert math.log2(abs(err[0.02][1] / err[0.01][1])) == pytest.approx(2.0, abs=0.3)


def test_mesh_slab_inertias_of_a_curved_p2_hollow_cylinder_per_slab():
    # Two stacked annuli R = 50 mm, bore r = 25 mm, lengths 20 and 40 mm, meshed conforming at the
    # joint and cut there: each slab rho pi L_i (R^4 - r^4) / 2. Measured at h = 10 mm: curved
    # -9.0e-8 and -1.7e-8; corner-only -7.6e-3 and -7.8e-3.
    from crankmodal.torsion.mesh_inertias import slab_axial_inertias

    rho, R, r, lengths = 7850.0, 0.05, 0.025, [0.02, 0.04]
    exact = rho * math.pi * np.array(lengths) * (R**4 - r**4) / 2
    pts, cells = _gmsh_p2_cylinders(R, r, lengths, 0.01)
    curved = slab_axial_inertias(pts, cells, rho, [lengths[0]], (0, 0, 0), (0, 0, 1))
    corner = slab_axial_inertias(pts, cells[:, :4], rho, [lengths[0]], (0, 0, 0), (0, 0, 1))
    np.testing.assert_allclose(curved, exact, rtol=1e-6)
    assert np.all(np.abs(curved / exact - 1) * 100 < np.abs(corner / exact - 1))


def test_mesh_slab_inertias_of_straight_tetra10_equal_the_corner_formula():
    # Mid-edge nodes exactly at the edge midpoints: the quadratic map is affine, so the P2 map on
    # the degree-7 rule reproduces the straight tetra (P1 map, degree-2 rule) to rounding (any
    # axis, any cut); the unsheared box is then checked against its closed form.
    from crankmodal.fem.testparts import elevate_to_p2
    from crankmodal.torsion.mesh_inertias import slab_axial_inertias

    pts, tets = _box_tets((0.0, 0.0, 0.0), (0.2, 0.1, 0.06), 3)
    pts = pts @ np.array([[1.0, 0.2, 0.1], [-0.3, 1.0, 0.4], [0.2, -0.1, 1.0]])  # sheared box
    p2, t10 = elevate_to_p2(pts, tets)
    axis = {"axis_point": (0.01, 0.05, -0.02), "axis_direction": (1.0, 0.3, -0.2)}
    four = slab_axial_inertias(pts, tets, 7200.0, [0.05, 0.12], **axis)
    ten = slab_axial_inertias(p2, t10, 7200.0, [0.05, 0.12], **axis)
    np.testing.assert_allclose(ten, four, rtol=1e-12)
    # still the box formula on the unsheared box with tetra10 cells
    pts, tets = _box_tets((0.0, 0.0, 0.0), (0.2, 0.1, 0.06), 4)
    p2, t10 = elevate_to_p2(pts, tets)
    m = 7200.0 * 0.1 * 0.1 * 0.06
    out = slab_axial_inertias(p2, t10, 7200.0, [0.1], (0, 0.05, 0), (1, 0, 0))
    np.testing.assert_allclose(out, m * (0.1**2 + 0.06**2) / 12 + m * 0.03**2, rtol=1e-12)


def test_mesh_slab_inertias_of_curved_tetra10_equal_an_independent_degree7_integration():
    # Mid-edge nodes moved at random (cells strongly curved, none folded): the P2 map makes the
    # integrand rho |r_perp|^2 det J of degree 7. Oracle: scikit-fem's own isoparametric P2 mesh
    # (read from meshio's tetra10) with a functional integrated on a collapsed Gauss rule of
    # 7^3 points (exact to degree 11). Measured 1e-15; a rule exact to degree 6 only
    # (scikit-fem's "order 7", 24 points) misses by 1.2e-9.
    import meshio
    from skfem import Basis, ElementTetP0, Functional
    from skfem.io.meshio import from_meshio

    from crankmodal.fem.testparts import elevate_to_p2
    from crankmodal.torsion.mesh_inertias import slab_axial_inertias

    pts, tets = _box_tets((0.0, 0.0, 0.0), (0.1, 0.1, 0.1), 2)
    x = pts[tets]
    negative = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0]) < 0
    tets[negative] = tets[negative][:, [0, 2, 1, 3]]
    p2, t10 = elevate_to_p2(pts, tets)
    mids = np.arange(len(pts), len(p2))
    p2[mids] += np.random.default_rng(7).uniform(-0.004, 0.004, (len(mids), 3))  # edges 50-87 mm
    a, e = np.array([0.01, 0.15, -0.02]), np.array([0.3, -0.4, 1.0])
    out = slab_axial_inertias(p2, t10, 7200.0, [], a, e)

    mesh = from_meshio(meshio.Mesh(p2, [("tetra10", t10)]))
    e = e / np.linalg.norm(e)

    @Functional
    def r_perp2(w):
        r = w.x - a[:, None, None]
        return 7200.0 * (np.sum(r * r, axis=0) - np.einsum("i,i...->...", e, r) ** 2)

    g, gw = np.polynomial.legendre.leggauss(7)
    g, gw = 0.5 * (g + 1), 0.5 * gw
    u, v, t = (c.ravel() for c in np.meshgrid(g, g, g, indexing="ij"))
    wu, wv, wt = (c.ravel() for c in np.meshgrid(gw, gw, gw, indexing="ij"))
    X = np.array([u * (1 - v) * (1 - t), v * (1 - t), t])      # Duffy map onto the unit tet
    W = wu * wv * wt * (1 - v) * (1 - t) ** 2
    expect = r_perp2.assemble(Basis(mesh, ElementTetP0(), quadrature=(X, W)))
    np.testing.assert_allclose(out, [expect], rtol=1e-12)


def test_mesh_slab_inertias_reject_a_folded_tetra10_cell():
    from crankmodal.errors import NumericalError
    from crankmodal.fem.testparts import elevate_to_p2
    from crankmodal.torsion.mesh_inertias import slab_axial_inertias

    pts, t10 = elevate_to_p2(np.vstack([np.zeros(3), np.eye(3)]), np.array([[0, 1, 2, 3]]))
    pts[t10[0, 4]] = [0.05, 0.0, 0.0]  # mid-node of edge 0-1 slid past the quarter point: det J < 0 by 0
    with pytest.raises(NumericalError, match="fold"):
        slab_axial_inertias(pts, t10, 1.0, [])
