"""Flexible bodies outside the linear floating-frame model are warned (issue 25, item 11).

Oracle: the slender coupler of ``scenes/seed001_flexible_slender_coupler.toml`` (a steel bar
75 x 16 x 8 mm, bending in its 16 mm direction) pinned at its two end faces under a uniform
transverse body load ``q = rho A a`` balanced by the pin reactions ``q L / 2``. Its modal state
is the static one, ``xi_a = Q_a / omega_a^2`` with ``Q_a = -(q L / 2)(D_0,a + D_1,a)`` (the
body load itself has no modal force: mean axes, ``int rho phi = 0``). Closed forms: the
midspan deflection from the chord, Timoshenko's ``5 q L^4 / (384 E I) + q L^2 / (8 kappa G A)``
(Cowper's kappa = 10 (1 + nu) / (12 + 11 nu); shear adds 11 % at L/h = 4.7), and the bending
stress at the midspan surface ``(q L^2 / 8)(h / 2) / I``. Measured: deflection 0.54 % and
stress 0.07 % above them.
"""

import re

import numpy as np
import pytest

from crankmodal.dynamics.results.validity import (
    DEFLECTION_FRACTION,
    elastic_deflection,
    flexible_validity,
)
from crankmodal.dynamics.scene.flexstage import dynamic_stress

L, H, T = 0.075, 0.016, 0.008
E, NU, RHO = 2.1e11, 0.3, 7850.0
YIELD = 355e6  # the library's "steel"
A, I = H * T, T * H**3 / 12
KAPPA = 10 * (1 + NU) / (12 + 11 * NU)
G = E / (2 * (1 + NU))


@pytest.fixture(scope="module")
def coupler():
    from crankmodal.dynamics.flexible.build import link_body, reduced_bar

    spec = {"bar": [H, T], "material": "steel", "mesh_size": 0.004, "element_order": 2,
            "fixed_interface_modes": 12, "n_modes": None, "cutoff_hz": None,
            "damping_ratio": 0.02}
    path = reduced_bar(L, spec["bar"], spec, "dynamics.flexible.coupler")
    return link_body(path, spec, L, "coupler")


def _static_state(body, a):
    """Modal coordinates (two samples: rest, then loaded) of the pinned bar under ``q = rho A a``
    (``a`` in m/s^2, transverse, in the plane)."""
    k = body.n_elastic
    q = RHO * A * a
    D0, D1 = (body.frames[n][1][1, :k] for n in ("end_x0", "end_x1"))
    xi = -(q * L / 2) * (D0 + D1) / body.K[:k]
    return np.vstack([np.zeros(k), xi]), q


def _closed_forms(q):
    deflection = 5 * q * L**4 / (384 * E * I) + q * L**2 / (8 * KAPPA * G * A)
    stress = q * L**2 / 8 * (H / 2) / I
    return deflection, stress


PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9, "m": 1e-3, "µ": 1e-6}


def _number(pattern, text):
    return float(re.search(pattern, text).group(1))


def _si(pattern, text):
    """A quantity the text prints with an engineering prefix (``23.72 mm``), in SI units."""
    value, prefix = re.search(pattern, text).groups()
    return float(value) * PREFIX[prefix]


def test_a_bent_coupler_beyond_2_percent_and_yield_is_warned_with_the_closed_form_numbers(coupler):
    a = 3e6  # m/s^2: deflection 3.2 % of the span, bending stress 6.2 GPa
    modal, q = _static_state(coupler, a)
    t = np.array([0.0, 1e-3])
    d = elastic_deflection(coupler, modal, t)
    s = dynamic_stress(coupler, modal, t, np.zeros(2))
    d_ref, s_ref = _closed_forms(q)
    assert d["where"] == "mesh nodes, relative to the interfaces"
    assert d["max_m"] == pytest.approx(d_ref, rel=0.02)
    assert d["time_s"] == 1e-3
    assert s["max_von_mises_pa"] == pytest.approx(s_ref, rel=0.02)
    block, texts = flexible_validity(coupler, d, s, "dynamics.flexible.coupler")
    assert block["size_m"] == pytest.approx(L, rel=1e-12) and block["size_of"] == "interface span"
    assert block["deflection_fraction"] == pytest.approx(d_ref / L, rel=0.02)
    assert block["yield_strength_pa"] == YIELD and block["material"] == "steel"
    assert block["inside"] is False
    assert len(texts) == 2
    bend, stress = texts
    assert bend.startswith("dynamics.flexible.coupler: coupler deflects")
    # the numbers the warnings quote, against the closed forms
    assert _si(r"deflects ([\d.]+) (\w?)m elastically", bend) == pytest.approx(d_ref, rel=0.02)
    assert _number(r", ([\d.]+) % of its 75 mm interface span", bend) == \
        pytest.approx(100 * d_ref / L, rel=0.02)
    assert f"warning above {100 * DEFLECTION_FRACTION:g} %" in bend
    assert _si(r"reaches ([\d.]+) (\w?)Pa", stress) == pytest.approx(s_ref, rel=0.02)
    assert _number(r"Pa \(von Mises, from its stress modes\), ([\d.]+) times", stress) == \
        pytest.approx(s_ref / YIELD, rel=0.02)
    assert "yield strength 355 MPa of steel" in stress
    assert "e+" not in bend + stress                                  # issue 25 #15


def test_a_coupler_well_inside_its_limits_is_not_warned(coupler):
    modal, q = _static_state(coupler, 1e3)  # 0.8 um, 2 MPa
    t = np.array([0.0, 1e-3])
    d = elastic_deflection(coupler, modal, t)
    s = dynamic_stress(coupler, modal, t, np.zeros(2))
    d_ref, _ = _closed_forms(q)
    assert d["max_m"] == pytest.approx(d_ref, rel=0.02)
    block, texts = flexible_validity(coupler, d, s, "dynamics.flexible.coupler")
    assert texts == [] and block["inside"] is True and block["stress_checked"] is True


def test_a_material_without_yield_strength_is_said_so(coupler, monkeypatch):
    modal, _ = _static_state(coupler, 1e3)
    t = np.array([0.0, 1e-3])
    s = dynamic_stress(coupler, modal, t, np.zeros(2))
    monkeypatch.setitem(coupler.source.info, "material", "unobtainium")
    block, texts = flexible_validity(coupler, elastic_deflection(coupler, modal, t), s,
                                     "dynamics.flexible.coupler")
    assert block["stress_checked"] is False and block["yield_strength_pa"] is None
    assert len(texts) == 1 and "not checked against a yield strength" in texts[0]
    assert "no yield strength for 'unobtainium'" in texts[0]
    assert block["inside"] is True            # a missing check is said, not counted as outside


@pytest.mark.slow
def test_the_slender_coupler_at_20000_rpm_is_warned_and_at_450_rpm_not(tmp_path):
    """The tester's case (issue 25, 11): the scene's coupler at 20 000 rpm reports stress far
    beyond yield and a deflection of a third of its length; the warnings and the summary say
    so. At the scene's 450 rpm the same coupler stays inside (nothing warned)."""
    from crankmodal.runner import run
    from crankmodal.scene import load_scene

    scene = "scenes/seed001_flexible_slender_coupler.toml"
    fast = run(load_scene(scene, ["dynamics.speed_rpm=20000", "dynamics.end_time=0.012",
                                  "dynamics.run_rigid=false"]), tmp_path / "fast",
               figures=False)["dynamics"]
    v = fast["flexible"]["bodies"]["coupler"]["validity"]
    assert v["deflection_fraction"] > DEFLECTION_FRACTION and v["max_von_mises_pa"] > YIELD
    texts = [w for w in fast["warnings"] if w.startswith("dynamics.flexible.coupler")]
    assert len(texts) == 2
    assert "OUTSIDE THE LINEAR FLEXIBLE MODEL'S VALIDITY: coupler deflects" in fast["summary"]
    slow = run(load_scene(scene, ["dynamics.end_time=0.27", "dynamics.run_rigid=false"]),
               tmp_path / "slow", figures=False)["dynamics"]
    v = slow["flexible"]["bodies"]["coupler"]["validity"]
    assert v["inside"] is True and v["deflection_fraction"] < DEFLECTION_FRACTION
    assert not [w for w in slow["warnings"] if w.startswith("dynamics.flexible.coupler")]
    assert "OUTSIDE" not in slow["summary"]
    # item 13: the coupler's lowest mode held at its joints, stated in results and summary
    e = slow["flexible"]["bodies"]["coupler"]["effective_damping"]
    assert e["pinned"] == ["end_x0", "end_x1"] and e["given_ratio"] == 0.02
    from crankmodal.report.quantity import number, quantity

    assert f"coupler {quantity(e['frequency_hz'], 'Hz')} held at end_x0, end_x1, effective " \
           f"damping {number(e['damping_ratio'], 2)} (0.02 given on its free-free modes)" \
        in slow["summary"]


def test_an_api_run_is_checked_the_same_way(coupler):
    """check_flexible_bodies: a History-like record (times, modal coordinates, crank angle) of
    the loaded coupler is warned with a ModelWarning naming the scene table, and the same block
    as flexible_validity's."""
    from types import SimpleNamespace

    from crankmodal.dynamics.results.validity import check_flexible_bodies
    from crankmodal.errors import ModelWarning

    modal, q = _static_state(coupler, 3e6)
    hist = SimpleNamespace(t=np.array([0.0, 1e-3]), modal={"coupler": modal},
                           crank_angle=np.zeros(2))
    coupler.name = "coupler"
    mech = SimpleNamespace(system=SimpleNamespace(bodies=[coupler]))
    kept = []
    with pytest.warns(ModelWarning, match="flexible body 'coupler': coupler deflects"):
        blocks = check_flexible_bodies(mech, hist, warnings=kept)
    d_ref, _ = _closed_forms(q)
    assert blocks["coupler"]["deflection_max_m"] == pytest.approx(d_ref, rel=0.02)
    assert len(kept) == 2 and blocks["coupler"]["inside"] is False
