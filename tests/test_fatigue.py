"""Fatigue criterion against closed forms and hand values; Marin factors against Shigley's
worked examples; bad input and damaged files refused naming the argument, file and member."""

import math
import zipfile

import numpy as np
import pytest

from crankmodal.errors import InputFileError, ParameterError
from crankmodal.fatigue import (
    FatigueFactors,
    FatigueFileError,
    FatigueResult,
    cycle_extremes,
    fatigue_verdict,
    reliability_factor,
    safety_factor,
    size_factor,
    surface_factor,
)
from crankmodal.fem.materials import Material, material

STEEL = Material("test steel", 2.1e11, 0.3, 7850.0, yield_strength=600e6,
                 ultimate_strength=700e6, fatigue_strength=280e6)
CYCLE = np.linspace(0.0, 2 * np.pi, 361)  # one cycle, both ends included


def _voigt(**components):
    s = np.zeros(6)
    for k, v in components.items():
        s[["xx", "yy", "zz", "yz", "xz", "xy"].index(k)] = v
    return s


def _one_mode(voigt):
    """Stress modes of one point and one mode: the stress per unit coordinate."""
    return np.asarray(voigt, float).reshape(1, 6, 1)


def test_marin_factors_match_shigley_worked_examples(oracle):
    # Shigley, Mechanical Engineering Design 9th ed., Ex. 6-3: machined, Sut 520 MPa -> 0.860;
    # Ex. 6-4: a 32 mm rotating bar -> k_b = 0.858; Table 6-5: 99 % reliability -> 0.814
    ka = oracle(stage="fem", quantity="Marin surface factor, machined, S_ut 520 MPa",
                reference="Shigley 9th ed. Example 6-3", tolerance="5e-4 absolute",
                measured=surface_factor(520e6, "machined"), expected=0.860)
    kb = oracle(stage="fem", quantity="Marin size factor, 32 mm bar in bending",
                reference="Shigley 9th ed. Example 6-4", tolerance="5e-4 absolute",
                measured=size_factor(0.032), expected=0.858)
    assert ka == pytest.approx(0.860, abs=5e-4)
    assert kb == pytest.approx(0.858, abs=5e-4)
    assert reliability_factor(0.99) == 0.814
    assert size_factor(0.1) == pytest.approx(1.51 * 100 ** -0.157, rel=1e-12)


def test_pure_alternating_shear_gives_the_closed_form_torsional_safety_factor(oracle):
    """A round shaft under T sin(wt), no mean: tau = 16 T / (pi d^3) at its surface. With the
    stated factors the verdict is k_a k_b k_e S_f / (sqrt(3) K_f tau): von Mises' torsional
    fatigue strength S_f / sqrt(3) over the shear amplitude."""
    T, d = 1500.0, 0.04
    tau = 16.0 * T / (math.pi * d ** 3)
    f = FatigueFactors(surface=surface_factor(STEEL.ultimate_strength, "machined"),
                       size=size_factor(d), reliability=reliability_factor(0.99), notch=1.3)
    # the surface point (0, d/2, 0) of a shaft along x: shear xz... any shear plane will do
    S = _one_mode(_voigt(xy=tau / T))  # Pa per N m
    xi = T * np.sin(CYCLE)[None, :]
    res = fatigue_verdict(S, xi, STEEL, np.zeros((1, 3)), factors=f)
    expected = f.surface * f.size * f.reliability * STEEL.torsional_fatigue_strength / (1.3 * tau)
    oracle(stage="fem", quantity="fatigue safety factor, round shaft in alternating torsion "
           "(closed-form stress state)", reference="tau = 16 T / (pi d^3), tau_f = S_f / sqrt(3)",
           tolerance="1e-9 relative", measured=res.min_safety_factor, expected=expected)
    # independent arithmetic on both sides (shear route vs. von Mises of a tensor): round-off only
    assert res.min_safety_factor == pytest.approx(expected, rel=1e-9)
    assert res.mean[0] == pytest.approx(0.0, abs=1e-6)


def test_goodman_and_gerber_with_a_mean_stress_match_the_hand_values(oracle):
    """Uniaxial 100 MPa mean + 150 MPa amplitude, S_f 280 MPa, k_a = 0.9, S_u 700 MPa:
    S_e = 252 MPa; Goodman 1 / (150/252 + 100/700) = 1.354839 (by hand);
    Gerber 1/2 (700/100)^2 (150/252) [-1 + sqrt(1 + (2 100 252 / (700 150))^2)] = 1.592995."""
    S = np.stack([_one_mode(_voigt(xx=100e6)), _one_mode(_voigt(xx=150e6))], axis=2)[:, :, :, 0]
    xi = np.vstack([np.ones_like(CYCLE), np.sin(CYCLE)])
    f = FatigueFactors(surface=0.9)
    good = fatigue_verdict(S, xi, STEEL, np.zeros((1, 3)), factors=f)
    gerb = fatigue_verdict(S, xi, STEEL, np.zeros((1, 3)), factors=f, rule="gerber")
    oracle(stage="fem", quantity="Goodman safety factor, 100 MPa mean + 150 MPa alternating",
           reference="hand calculation", tolerance="1e-6 relative",
           measured=good.min_safety_factor, expected=1.354839)
    assert good.min_safety_factor == pytest.approx(1.354839, rel=1e-6)
    assert gerb.min_safety_factor == pytest.approx(1.592995, rel=1e-6)
    # a compressive mean earns no credit: S_e / sigma_a
    comp = fatigue_verdict(S, np.vstack([-np.ones_like(CYCLE), np.sin(CYCLE)]), STEEL,
                           np.zeros((1, 3)), factors=f)
    assert comp.min_safety_factor == pytest.approx(252.0 / 150.0, rel=1e-9)


def test_sines_mean_ignores_mean_shear_and_signed_von_mises_does_not():
    """Alternating bending 150 MPa on a steady shear 100 MPa: Sines' mean (first invariant) is
    zero, n = S_e / 150 MPa; signed von Mises takes sqrt(3) 100 MPa as the mean."""
    S = np.zeros((1, 6, 2))
    S[0, 5, 0], S[0, 0, 1] = 100e6, 150e6
    xi = np.vstack([np.ones_like(CYCLE), np.sin(CYCLE)])
    sines = fatigue_verdict(S, xi, STEEL, np.zeros((1, 3)))
    vm = fatigue_verdict(S, xi, STEEL, np.zeros((1, 3)), mean_stress="signed_von_mises")
    assert sines.min_safety_factor == pytest.approx(280.0 / 150.0, rel=1e-9)
    assert vm.min_safety_factor == pytest.approx(
        1.0 / (150.0 / 280.0 + math.sqrt(3.0) * 100.0 / 700.0), rel=1e-9)


def test_safety_factor_limits_zero_mean_and_zero_amplitude():
    n = safety_factor([100e6, 0.0, 0.0], [0.0, 350e6, 0.0], 200e6, 700e6, "gerber")
    assert n[0] == pytest.approx(2.0, rel=1e-12) and n[1] == pytest.approx(2.0, rel=1e-12)
    assert math.isinf(n[2])


def test_chunked_cycle_equals_one_block_and_a_direct_superposition():
    rng = np.random.default_rng(3)
    S = rng.normal(size=(500, 6, 7)) * 1e6
    xi = rng.normal(size=(7, 50))
    s0 = rng.normal(size=(500, 6)) * 1e6
    small = cycle_extremes(S, xi, s0, memory_bytes=1.0)  # one point per chunk
    direct = np.einsum("pik,kt->pit", S, xi) + s0[:, :, None]  # second formulation
    # different summation orders: equal to round-off (1e-12 relative of the largest stress)
    scale = np.abs(direct).max()
    np.testing.assert_allclose(small.stress_max, direct.max(axis=2), rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(small.stress_min, direct.min(axis=2), rtol=0, atol=1e-12 * scale)
    vm = np.sqrt(0.5 * ((direct[:, 0] - direct[:, 1]) ** 2 + (direct[:, 1] - direct[:, 2]) ** 2
                        + (direct[:, 2] - direct[:, 0]) ** 2)
                 + 3 * (direct[:, 3] ** 2 + direct[:, 4] ** 2 + direct[:, 5] ** 2))
    np.testing.assert_allclose(small.max_von_mises, vm.max(axis=1), rtol=1e-12)


def test_yield_passed_is_warned_and_a_material_without_fatigue_data_is_refused():
    S = _one_mode(_voigt(xx=700e6))
    xi = np.sin(CYCLE)[None, :]
    notes = []
    with pytest.warns(UserWarning, match="passes the yield strength"):
        res = fatigue_verdict(S, xi, STEEL, np.zeros((1, 3)), warnings=notes)
    assert res.yield_safety_factor[0] == pytest.approx(600.0 / 700.0, rel=1e-9)
    assert notes and "yield" in notes[0]
    with pytest.raises(ParameterError) as exc:
        fatigue_verdict(S, xi, material("steel"), np.zeros((1, 3)))
    assert exc.value.argument == "fatigue_strength"


@pytest.mark.parametrize("change, argument", [
    (lambda a: {**a, "modal_coordinates": a["modal_coordinates"][:1]}, "modal_coordinates"),
    (lambda a: {**a, "modal_coordinates": np.where(a["modal_coordinates"] > 0.5, np.nan,
                                                   a["modal_coordinates"])}, "modal_coordinates"),
    (lambda a: {**a, "stress_modes": np.where(a["stress_modes"] > 0, np.inf, 0.0)}, "stress_modes"),
    (lambda a: {**a, "stress_modes": a["stress_modes"][:, :5]}, "stress_modes"),
    (lambda a: {**a, "static_stress": np.zeros((4, 6))}, "static_stress"),
    (lambda a: {**a, "static_stress": np.full((3, 6), np.nan)}, "static_stress"),
    (lambda a: {**a, "points": np.zeros((2, 3))}, "points"),
    (lambda a: {**a, "nodes": np.array([0, 3])}, "nodes"),
    (lambda a: {**a, "nodes": np.array([0.0, 1.0])}, "nodes"),
    (lambda a: {**a, "factors": FatigueFactors}, "factors"),
    (lambda a: {**a, "rule": "soderberg"}, "rule"),
    (lambda a: {**a, "mean_stress": "tresca"}, "mean_stress"),
    (lambda a: {**a, "material": "SG 700/2"}, "material"),
])
def test_bad_input_is_refused_naming_the_argument(change, argument):
    good = {"stress_modes": np.ones((3, 6, 2)), "modal_coordinates": np.vstack(
        [np.sin(CYCLE), np.cos(CYCLE)]), "material": STEEL, "points": np.zeros((3, 3))}
    kw = change(good)
    with pytest.raises(ParameterError) as exc:
        fatigue_verdict(**kw)
    assert exc.value.argument == argument


@pytest.mark.parametrize("name, value", [("surface", 1.2), ("notch", 0.8), ("size", float("nan")),
                                         ("reliability", True)])
def test_bad_factors_are_refused_naming_the_factor(name, value):
    with pytest.raises(ParameterError) as exc:
        FatigueFactors(**{name: value})
    assert exc.value.argument == name


def _saved(tmp_path):
    S = np.stack([np.eye(6)[:, 0] * 1e8, np.eye(6)[:, 5] * 5e7, np.zeros(6)])[:, :, None]
    res = fatigue_verdict(S, np.sin(CYCLE)[None, :], STEEL, np.arange(9.0).reshape(3, 3))
    return res, res.save(tmp_path / "fatigue.npz")


def test_save_and_load_round_trip(tmp_path):
    res, path = _saved(tmp_path)
    back = FatigueResult.load(path)
    np.testing.assert_array_equal(back.safety_factor, res.safety_factor)  # stored, not computed
    assert back.to_dict() == res.to_dict()


def _rewrite(path, **members):
    with np.load(path) as z:
        data = {k: z[k] for k in z.files}
    data.update(members)
    with open(path, "wb") as fh:
        np.savez(fh, **data)


@pytest.mark.parametrize("member, value", [
    ("safety_factor", np.array([np.nan, 1.0, 1.0])),
    ("points", np.zeros((2, 3))),
    ("label", np.array([0, 5, -1])),
    ("format", np.array("something-else")),
    ("meta_json", np.array("{not json")),
    ("nodes", np.array([object()], dtype=object)),
])
def test_a_damaged_saved_result_names_the_file_and_member(tmp_path, member, value):
    _, path = _saved(tmp_path)
    _rewrite(path, **{member: value})
    with pytest.raises(FatigueFileError) as exc:
        FatigueResult.load(path)
    assert exc.value.member == member and str(path) in str(exc.value)


def test_a_truncated_or_missing_file_is_refused_naming_it(tmp_path):
    _, path = _saved(tmp_path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(FatigueFileError, match="fatigue.npz"):
        FatigueResult.load(path)
    with zipfile.ZipFile(tmp_path / "other.npz", "w") as z:
        z.writestr("x.npy", b"")
    with pytest.raises(FatigueFileError) as exc:
        FatigueResult.load(tmp_path / "other.npz")
    assert exc.value.member == "format"
    with pytest.raises(InputFileError, match="not found"):
        FatigueResult.load(tmp_path / "absent.npz")


def test_library_fatigue_strengths_lie_in_the_handbook_fatigue_ratio_band():
    """Fully reversed fatigue strength of steels and nodular irons: 0.3-0.6 of the ultimate
    (Shigley Fig. 6-17; EN 1563's GJS grades 0.4-0.5); the three crank materials have it."""
    from crankmodal.fem.materials import library

    have = [n for n in library() if material(n).fatigue_strength is not None]
    assert {"42CrMo", "crank_steel_seed000", "SG 700/2"} <= set(have)
    for name in have:
        m = material(name)
        assert 0.3 <= m.fatigue_strength / m.ultimate_strength <= 0.6, name
        assert m.torsional_fatigue_strength == pytest.approx(m.fatigue_strength / math.sqrt(3))
    assert material("SG 700/2").to_dict()["fatigue_strength_pa"] == 280e6


def test_out_of_phase_bending_and_torsion_is_flagged_non_proportional(oracle):
    """sigma_xx = s sin t, tau_xy = (s / sqrt 3) cos t: the von Mises stress of sigma(t) stays
    s all cycle, while the component-wise amplitude's is sqrt(2) s: proportionality 1/sqrt(2)
    (closed form), warned at the worst point; in phase it is 1."""
    s = 150e6
    S = np.zeros((1, 6, 2))
    S[0, 0, 0], S[0, 5, 1] = s, s / math.sqrt(3.0)
    out = np.vstack([np.sin(CYCLE), np.cos(CYCLE)])
    notes = []
    with pytest.warns(UserWarning, match="non-proportional"):
        res = fatigue_verdict(S, out, STEEL, np.zeros((1, 3)), warnings=notes)
    oracle(stage="fem", quantity="proportionality of bending and torsion 90 deg out of phase",
           reference="closed form 1/sqrt(2)", tolerance="1e-6 relative (360 steps)",
           measured=res.proportionality[0], expected=1 / math.sqrt(2.0))
    assert res.proportionality[0] == pytest.approx(1 / math.sqrt(2.0), rel=1e-6)
    assert res.alternating[0] == pytest.approx(math.sqrt(2.0) * s, rel=1e-6)
    inphase = fatigue_verdict(S, np.vstack([np.sin(CYCLE), np.sin(CYCLE)]), STEEL,
                              np.zeros((1, 3)))
    assert inphase.proportionality[0] == pytest.approx(1.0, rel=1e-12)
    assert not inphase.warnings


def test_material_scene_keys_carry_fatigue_data_and_refuse_bad_values():
    from pathlib import Path

    from crankmodal.errors import SceneError
    from crankmodal.fem import material_stage
    from crankmodal.scene import Scene

    scene = Scene(name="t", base_dir=Path("."))
    p = material_stage.validate({"name": "steel", "fatigue_strength": 250e6}, scene)
    m = material_stage.make_material(p)
    assert m.fatigue_strength == 250e6 and m.torsional_fatigue_strength == pytest.approx(
        250e6 / math.sqrt(3))
    with pytest.raises(SceneError, match=r"^material\.fatigue_strength: "):
        material_stage.validate({"name": "steel", "fatigue_strength": -1.0}, scene)
    custom = material_stage.make_material(material_stage.validate(
        {"E": 2e11, "nu": 0.3, "rho": 7800.0, "ultimate_strength": 6e8}, scene))
    with pytest.raises(ParameterError) as exc:  # the verdict names the missing key
        fatigue_verdict(np.ones((1, 6, 1)), np.sin(CYCLE)[None, :], custom, np.zeros((1, 3)))
    assert exc.value.argument == "fatigue_strength"
