"""Interface nodes: exact bore centres, RBE3 averaging and ovalisation, RBE2 rigidity."""

import numpy as np
import pytest

from crankmodal.errors import ParameterError, SceneError
from crankmodal.fem.assembly import assemble, rigid_body_modes
from crankmodal.fem.materials import Material
from crankmodal.fem.testparts import bar, tube
from crankmodal.part import Region
from crankmodal.reduction.craig_bampton import craig_bampton
from crankmodal.reduction.interfaces import (
    distributing_rows,
    make_interfaces,
    rigid_map,
    split_region,
)

STEEL = Material("steel", 2.1e11, 0.3, 7850.0)
A_IN, A_OUT, LEN = 0.05, 0.1, 0.1


@pytest.fixture(scope="module")
def ring():
    part = tube(A_IN, A_OUT, LEN, divisions=(3, 32, 3), order=2)
    return part, assemble(part, STEEL)


def test_interface_node_sits_at_the_exact_bore_centre_or_a_fitted_one(ring):
    part, _ = ring
    itf = make_interfaces(part, [{"region": "bore", "kind": "distributing"}])[0]
    assert itf.centre_source == "cylinder"
    assert np.allclose(itf.centre, [0, 0, LEN / 2], atol=1e-15)
    # the same surface without its Cylinder: least-squares fit, close to the exact one
    r = part.regions["bore"]
    bare = Region("bore_nocyl", r.facets, r.nodes, None)
    fitted = make_interfaces(part, [{"region": "x", "region_object": bare}])[0]
    assert fitted.centre_source == "fit"
    assert np.allclose(fitted.centre, [0, 0, LEN / 2], atol=1e-6 * A_IN)
    # a planar end face: its area centroid
    face = make_interfaces(part, [{"region": "end_z1"}])[0]
    assert face.centre_source == "centroid"
    assert np.allclose(face.centre, [0, 0, LEN], atol=1e-4 * A_OUT)


def test_distributing_node_moves_with_the_area_mean_of_the_bore(ring):
    """q = G u: rigid fields are reproduced exactly, and the translation of a smooth field is
    its mean over the exact cylinder (∫ u dA / A, closed form) to the P2 surface accuracy."""
    part, model = ring
    itf = make_interfaces(part, [{"region": "bore", "kind": "distributing"}])
    _, G = distributing_rows(model.points, model.cells, itf)
    c = itf[0].centre
    R = rigid_body_modes(model.points, c)
    assert np.allclose(G @ R, np.eye(6), atol=1e-12)
    x, y, z = (model.points - c).T
    u = np.column_stack([x ** 2, 1e-3 + y * y * z, z ** 2]).ravel()
    q = G @ u
    # closed form over r = a, θ ∈ [0, 2π), z ∈ [-L/2, L/2]: mean x² = a²/2, mean z² = L²/12
    assert q[0] == pytest.approx(A_IN ** 2 / 2, rel=2e-3)
    assert q[1] == pytest.approx(1e-3, rel=1e-6)  # mean of y² z is 0 by symmetry
    assert q[2] == pytest.approx(LEN ** 2 / 12, rel=2e-3)


@pytest.mark.parametrize("kind", ["rigid", "distributing"])
def test_loaded_bore_ovalises_only_with_a_distributing_coupling(ring, kind):
    """A radial force on the bore's interface node, the outer surface held rigidly: with RBE3
    the bore deforms (ovalises) and the node moves with the surface mean; with RBE2 the bore
    moves as a rigid body."""
    part, model = ring
    itf = make_interfaces(part, [{"region": "outer", "kind": "rigid"},
                                 {"region": "bore", "kind": kind}])
    cb = craig_bampton(model, itf, n_modes=0)
    F = np.array([1e5, 0, 0, 0, 0, 0])
    q = np.linalg.solve(cb.K[6:12, 6:12], F)  # outer interface clamped
    u = cb.V[:, 6:12] @ q
    nodes = itf[1].nodes
    Rl = rigid_body_modes(model.points[nodes], itf[1].centre)
    us = u.reshape(-1, 3)[nodes].ravel()
    fit = np.linalg.lstsq(Rl, us, rcond=None)[0]
    deform = np.linalg.norm(us - Rl @ fit) / np.linalg.norm(us)
    if kind == "rigid":
        assert deform < 1e-10
        assert np.allclose(fit, q, atol=1e-10 * np.abs(q).max())
    else:
        assert deform > 0.05
        _, G = distributing_rows(model.points, model.cells, itf)
        assert np.allclose(G @ u, q, atol=1e-10 * np.abs(q).max())


def test_distributing_coupling_lets_a_pinched_bore_ovalise(ring):
    """Interface node held (q = G u = 0), the ring pinched across x at its outer surface: the
    bore closes along x and opens along y (an oval), while its mean motion stays zero. Solved
    as a full saddle-point system [K Gᵀ; G 0] with SuperLU, independently of the reduction."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    part, model = ring
    itf = make_interfaces(part, [{"region": "bore", "kind": "distributing"}])
    _, G = distributing_rows(model.points, model.cells, itf)
    used = np.flatnonzero(np.repeat(model.used, 3))
    K = model.K.tocsr()[used][:, used]
    Gu = G[:, used]
    A = sp.bmat([[K, Gu.T], [Gu, None]], format="csc")
    p = model.points
    outer = part.regions["outer"].nodes
    th = np.arctan2(p[outer, 1], p[outer, 0])
    f = np.zeros(model.K.shape[0])
    for ang, sign in ((0.0, -1.0), (np.pi, 1.0)):
        sel = outer[np.abs(np.angle(np.exp(1j * (th - ang)))) < 1e-6]
        f[3 * sel] = sign * 1e4 / len(sel)
    x = spla.spsolve(A, np.r_[f[used], np.zeros(6)])
    u = np.zeros(model.K.shape[0])
    u[used] = x[:len(used)]
    assert np.abs(G @ u).max() < 1e-10 * np.abs(u).max()
    bore = part.regions["bore"].nodes
    tb = np.arctan2(p[bore, 1], p[bore, 0])
    U = u.reshape(-1, 3)

    def at(ang, comp):
        return U[bore[np.abs(np.angle(np.exp(1j * (tb - ang)))) < 1e-6], comp].mean()

    dx = at(0.0, 0) - at(np.pi, 0)  # change of the bore diameter along x
    dy = at(np.pi / 2, 1) - at(-np.pi / 2, 1)
    assert dx < 0 < dy
    assert dy > 0.3 * abs(dx)


def test_rigid_map_moves_the_surface_rigidly(ring):
    part, model = ring
    itf = make_interfaces(part, [{"region": "bore", "kind": "rigid"}])
    dofs, R = rigid_map(model.points, itf)
    assert len(dofs) == 3 * len(part.regions["bore"].nodes)
    q = np.array([1e-3, -2e-3, 5e-4, 0.01, -0.02, 0.03])
    u = np.zeros(model.K.shape[0])
    u[dofs] = R @ q
    full = rigid_body_modes(model.points, itf[0].centre) @ q
    assert np.allclose(u[dofs], full[dofs], atol=1e-16)


def test_split_region_makes_disjoint_bands_with_their_own_centres(ring):
    part, model = ring
    bands = split_region(part.regions["bore"], model.points, 2, model.cells)
    assert [b.name for b in bands] == ["bore_seg1", "bore_seg2"]
    assert np.allclose([b.cylinder.centre[2] for b in bands], [LEN / 4, 3 * LEN / 4])
    assert not set(bands[0].nodes) & set(bands[1].nodes)
    assert set(bands[0].nodes) | set(bands[1].nodes) == set(part.regions["bore"].nodes)


def test_bad_interfaces_name_the_argument():
    """make_interfaces names its argument (interfaces[i].region/kind), not a scene key (issue
    20; the [reduction] stage's key: test_reduction_stress_io_stage). Before: SceneError
    'reduction.interfaces[0].region: ...' from the core."""
    part = bar(0.2, 0.02, 0.02, (4, 1, 1), order=1)
    with pytest.raises(ParameterError) as info:
        make_interfaces(part, [{"region": "nope"}])
    assert not isinstance(info.value, SceneError) and info.value.argument == "interfaces[0].region"
    assert str(info.value).startswith("interfaces[0].region: no region 'nope' in part")
    with pytest.raises(ParameterError) as info:
        make_interfaces(part, [{"region": "end_x0"}, {"region": "end_x1", "kind": "glued"}])
    assert str(info.value) == "interfaces[1].kind: must be one of rigid, distributing; got 'glued'"
    with pytest.raises(ParameterError, match=r"^interfaces\[1\]\.region: 'end_x0' lies inside "
                                             r"interface 'end_x0'; interfaces must not overlap$"):
        make_interfaces(part, [{"region": "end_x0"}, {"region": "end_x0"}])


def test_mixed_bands_sharing_a_cut_line_keep_the_distributing_constraint_exact(ring):
    """Bore cut in two bands, the first rigid, the second distributing: the cut-line nodes are
    eliminated by the rigid band yet weighted by the distributing one. Every basis vector
    still satisfies G u = q exactly (constraint modes: unit q; fixed-interface modes: q = 0)."""
    part, model = ring
    bands = split_region(part.regions["bore"], model.points, 2, model.cells)
    itf = make_interfaces(part, [
        {"region": bands[0].name, "kind": "rigid", "region_object": bands[0]},
        {"region": bands[1].name, "kind": "distributing", "region_object": bands[1]},
        {"region": "outer", "kind": "distributing"}])
    cb = craig_bampton(model, itf, n_modes=5)
    rows, G = distributing_rows(model.points, model.cells, itf)
    GV = G @ cb.V
    target = np.zeros_like(GV)
    target[np.arange(len(rows)), rows] = 1.0
    assert np.abs(GV - target).max() < 1e-10
    shared = np.intersect1d(itf[0].nodes, np.unique(itf[1].facets))
    assert len(shared) > 0 and abs(G[:6][:, 3 * shared]).max() > 0  # the path is exercised
