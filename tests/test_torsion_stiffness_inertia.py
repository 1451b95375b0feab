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
