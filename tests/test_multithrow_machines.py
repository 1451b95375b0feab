"""Issue 29's machines from their scenes, and what the planar crank leaves out, measured.

- The inline-6 with its six-throw crank flexible on seven main journals
  (``scenes/inline6_flexible_dynamics.toml``, slow): Newton's law for the crank at the
  quasi-static start (the sum of the seven journal forces against the rods' forces on the crank
  plus its own inertia ``m R̈``: an identity independent of how the journals share), and the
  shares against the rigid lever-rule split of ``scenes/inline6_dynamics.toml`` (all on the two
  end journals).
- The rotation coupling of seed 004's crank, held on its three journals, from the reduced 3-D
  body (mass-orthonormal modes, 3-D shapes): the gyroscopic matrix ``2 Ω G``
  (``G_ab = ∫ρ (u_a × u_b)_z``) moves its frequencies at 1494.6 rpm by the bounds stated in
  ``docs/guide/crank_bodies.md`` ("What the model leaves out, measured"); a second formulation
  (the closed form of two coupled modes) checks the split of the lowest pair; the mean-axis
  modes need no net axial force (``∫ρ φ_z = 0``).
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

SCENES = Path(__file__).resolve().parents[1] / "scenes"
SPEC004 = {"fidelity": "simplified", "mesh_size": 0.04, "element_order": 2,
           "material": "SG 700/2", "fixed_interface_modes": 12}
RPM004 = 1494.6  # seed 004's speed, rpm


def _skew(s):
    return np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])


def rotating_matrices(fb):
    """Mass, stiffness and spin coupling ``G`` (skew) of a reduced 3-D body, and the
    translations of its interface nodes, in the coordinates (t, θ, ξ): rigid translation (m),
    rigid rotation about the centre of mass (rad), elastic orthonormal modes (m kg^½).

    ``G_ab = ∫ρ (u_a × u_b)_z`` from the mass properties (rigid block: ``m`` between x and y
    translations, ``(J (e_i × e_j))_z`` between rotations with ``J = ∫ρ s sᵀ``), Shabana's
    invariants (rotation-mode block ``∫ρ s_z φ_a,i − δ_iz ∫ρ s·φ_a`` from ``I8``, mode-mode
    block ``I5[2]``); translation-mode and translation-rotation blocks vanish (mean axes).
    """
    inv = fb.invariants
    el = ~np.asarray(fb.rigid, bool)
    n = int(el.sum())
    m = float(fb.mass_kg)
    inertia = np.asarray(fb.inertia, float)
    J = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    I8 = np.asarray(inv["I8"], float)
    X = 0.5 * np.einsum("iia->a", I8)                 # ∫ρ x·φ_a
    P = np.einsum("ij,a->ija", np.eye(3), X) - I8     # P[i, j, a] = ∫ρ φ_a,i x_j
    N = 6 + n
    G = np.zeros((N, N))
    G[0, 1], G[1, 0] = m, -m
    e = np.eye(3)
    for i in range(3):
        for j in range(3):
            G[3 + i, 3 + j] = (J @ np.cross(e[i], e[j]))[2]
        G[3 + i, 6:] = P[i, 2] - (X if i == 2 else 0.0)
        G[6:, 3 + i] = -G[3 + i, 6:]
    G[6:, 6:] = np.asarray(inv["I5"], float)[2]
    M = np.zeros((N, N))
    M[:3, :3] = m * np.eye(3)
    M[3:6, 3:6] = inertia
    M[6:, 6:] = np.eye(n)
    K = np.zeros((N, N))
    K[6:, 6:] = np.diag((2 * np.pi * np.asarray(fb.frequencies_hz)[el]) ** 2)
    T = {}
    for r, name in enumerate(fb.interface_names):
        s = np.asarray(fb.interface_centres[r], float) - np.asarray(fb.centre_of_mass, float)
        A = np.zeros((3, N))
        A[:, :3] = np.eye(3)
        A[:, 3:6] = -_skew(s)
        A[:, 6:] = np.asarray(fb.interface_map[r], float)[:3][:, el]
        T[name] = A
    return M, K, G, T


def held_system(fb):
    """``M, K, G`` of the body held in the plane at every main journal and axially at the
    first (a thrust bearing), on the constraints' null space."""
    from scipy.linalg import null_space

    M, K, G, T = rotating_matrices(fb)
    mains = sorted(k for k in T if k.startswith("main_journal"))
    C = np.vstack([T[k][:2] for k in mains] + [T[mains[0]][2:3]])
    N = null_space(C)
    return N.T @ M @ N, N.T @ K @ N, N.T @ G @ N


def spinning_frequencies(M, K, G, omega):
    """Natural frequencies (Hz, ascending, the spin's zero left out) of
    ``M q̈ + 2 Ω G q̇ + K q = 0``."""
    k = len(M)
    A = np.zeros((2 * k, 2 * k))
    A[:k, k:] = np.eye(k)
    Mi = np.linalg.inv(M)
    A[k:, :k] = -Mi @ K
    A[k:, k:] = -2.0 * omega * Mi @ G
    lam = np.linalg.eigvals(A)
    f = np.sort(lam.imag[lam.imag > 0]) / (2 * np.pi)
    return f[f > 1.0]


@pytest.fixture(scope="module")
def crank004():
    from crankmodal.dynamics.flexible.build import reduced_part
    from crankmodal.reduction.io import load_flexbody

    return load_flexbody(reduced_part("multi_bearing_compressor", "crankshaft", SPEC004, n_rods=2))


def test_spin_coupling_moves_seed004_crank_frequencies_within_stated_bounds(crank004):
    """At 1494.6 rpm the gyroscopic coupling splits the lowest pair (the flywheel rocking in x
    and y, 220.7 / 227.1 Hz held) by -5.1 / +5.2 % and moves the next six by at most 0.2 %
    (docs/guide/crank_bodies.md). The split of the pair is checked against a second
    formulation: the closed-form roots of the two modes alone coupled by their ``2 Ω g``,
    ``ω⁴ − (ω1² + ω2² + (2Ωg)²) ω² + ω1² ω2² = 0`` (the other modes shift it by < 1 %)."""
    from scipy.linalg import eigh

    M, K, G = held_system(crank004)
    omega = RPM004 * 2 * np.pi / 60
    f0 = spinning_frequencies(M, K, G, 0.0)
    f1 = spinning_frequencies(M, K, G, omega)
    shift = (f1[:8] - f0[:8]) / f0[:8]
    assert abs(shift[0]) <= 0.06 and abs(shift[1]) <= 0.06
    assert abs(shift[0]) >= 0.03 and abs(shift[1]) >= 0.03  # the pair does split
    assert np.abs(shift[2:8]).max() <= 0.005
    # second formulation: the pair alone
    w2, V = eigh(K, M)
    keep = w2 > (2 * np.pi) ** 2  # the spin's zero out
    w2, V = w2[keep], V[:, keep]
    g = 2 * omega * (V[:, 0] @ G @ V[:, 1])
    b = w2[0] + w2[1] + g * g
    roots = np.sqrt(np.array([b - np.sqrt(b * b - 4 * w2[0] * w2[1]),
                              b + np.sqrt(b * b - 4 * w2[0] * w2[1])]) / 2) / (2 * np.pi)
    assert np.allclose(f1[:2], roots, rtol=0.01)


def test_seed004_crank_modes_need_no_net_axial_force(crank004):
    """Mean axes: ``∫ρ φ_z = 0`` for every elastic mode, so an in-plane load that excites them
    needs no axial reaction at a thrust bearing (the modes' axial kinetic energy is local,
    webs against journals). Bound 1e-9 of ``sqrt(m)`` (FE round-off of the orthonormalisation;
    measured 1e-13 kg^½)."""
    I3z = np.asarray(crank004.invariants["I3"], float)[2]
    assert np.abs(I3z).max() <= 1e-9 * np.sqrt(crank004.mass_kg)
    axial = 1.0 - np.einsum("aa->a", np.asarray(crank004.invariants["I9"], float)[2, 2])
    assert np.all((axial > -1e-9) & (axial < 1.0 + 1e-9))  # a share of the unit modal mass


def _run(scene, out):
    code = "import sys; from crankmodal.cli import main; sys.exit(main())"
    return subprocess.run([sys.executable, "-c", code, "run", str(scene), "--out", str(out),
                           "--no-figures"], capture_output=True, text=True, timeout=900,
                          check=False)


@pytest.mark.slow
def test_inline6_flexible_scene_journal_forces_balance_the_crank_and_differ_from_lever_rule(
        tmp_path):
    """The scene runs; at the quasi-static start (elastic velocities and accelerations zero)
    the seven journal forces on the housing equal minus the rods' forces on the crank minus its
    inertia ``m R̈`` (the mean-axis origin held by journal 1: ``R = −A(θ) D₁ ξ``), within 1e-6
    of the total main-bearing peak (measured 2e-14; 7e-5 without ``m R̈``); and the shares
    differ from the rigid scene's lever rule on its end journals (0.5 on journals 1 and 7,
    nothing between): the five inner journals carry half the mean load."""
    from crankmodal.dynamics.flexible.build import crank_body

    out = tmp_path / "out"
    proc = _run(SCENES / "inline6_flexible_dynamics.toml", out)
    assert proc.returncode == 0, proc.stderr[-2000:]
    res = json.loads((out / "results.json").read_text())["dynamics"]
    assert res["flexible"]["start"]["state"] == "quasi_static"
    d = np.load(out / "dynamics.npz")
    journals = [d[f"joint_force_main_{j}"] for j in range(1, 8)]
    rods = sum(d[f"joint_force_big_end_{i}"] for i in range(1, 7))
    total = sum(journals)
    peak = np.hypot(*total.T).max()
    body, _ = crank_body(res["flexible"]["bodies"]["crank"]["file"], {"n_modes": 24}, None,
                         0.078, throws=[1, 2, 3, 4, 5, 6])
    s0, D, _ = body.frames["main_journal_1"]
    q, th = d["modal_crank"][0], d["crank_angle"][0]
    w, al = d["crank_speed"][0], d["angular_acceleration_crank"][0]
    c, s = np.cos(th), np.sin(th)
    dA, ddA = np.array([[-s, -c], [c, -s]]), -np.array([[c, -s], [s, c]])
    Rdd = -(al * dA + w * w * ddA) @ (s0 + D @ q)
    assert np.abs(total[0] + rods[0] + body.mass * Rdd).max() <= 1e-6 * peak
    mj = res["main_journals"]
    shares = np.array([mj[f"main_{j}"]["share_mean"] for j in range(1, 8)])
    assert shares.sum() == pytest.approx(1.0, abs=1e-9)
    assert shares[1:6].sum() >= 0.3  # the lever rule on the end journals gives 0


@pytest.mark.slow
def test_flexible_crank_figures_when_the_whole_cycle_window_ends_before_the_run(tmp_path):
    """0.2 s at 1800 rpm from 0.0667 s holds 1.99 working cycles: the results window is one
    cycle (to 0.1667 s) and the run's last revolution lies outside it. The main-bearing figure
    plots the window's last revolution (it raised IndexError on an empty selection, exit 1
    with a traceback)."""
    code = "import sys; from crankmodal.cli import main; sys.exit(main())"
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-c", code, "run", str(SCENES / "inline6_flexible_dynamics.toml"),
         "--out", str(out), "--set", "dynamics.end_time=0.2",
         "--set", "dynamics.spectrum_start=0.0666667"],
        capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    window = json.loads((out / "results.json").read_text())["dynamics"]["peak_window_s"]
    assert window[1] < 0.19  # the case: the window ends a revolution before the run
    assert (out / "dynamics_flexible_main_bearing.png").stat().st_size > 0
