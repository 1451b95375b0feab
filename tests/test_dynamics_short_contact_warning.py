"""The short-contact warning (contacts under two output steps) asks the contact law whether its
stiffness is a Hertz constant comparable with a steel journal's (``NormalLaw.hertz_stiffness``)
instead of reading law names and parameter keys."""

import numpy as np
import pytest

from crankmodal.dynamics.laws import contact
from crankmodal.dynamics.laws.objects import LAWS
from crankmodal.dynamics.model.clearance import ClearanceJoint
from crankmodal.dynamics.scene.stage import short_contact_warning

R, C = 0.02, 1e-4  # journal radius, radial clearance, m
#: the scene's law parameters (build.contact_arguments passes every law all of them)
SCENE = {"exponent": 1.5, "damping": 1e3, "penetration": 1e-5, "restitution": 0.5,
         "radial_clearance": C}


def _joint(law, K, **kw):
    return ClearanceJoint("big_end_1", None, "a", None, "b", C, R, law=law,
                          law_params=dict(SCENE, stiffness=K, **kw))


def _fitted_exponent(law):
    """The exponent of the elastic force K delta**n from two penetrations (None: not a power
    law K delta**n with the law's own K)."""
    d = np.array([1e-6, 1e-5])
    f = np.asarray(law.elastic_force(d), float)
    n = np.log(f[1] / f[0]) / np.log(d[1] / d[0])
    return float(n) if np.allclose(f, law.stiffness * d**n, rtol=1e-9) else None


@pytest.mark.parametrize("name", list(LAWS))
def test_hertz_stiffness_is_k_exactly_for_the_power_three_halves_laws(name):
    law = _joint(name, 1e12).normal
    n = _fitted_exponent(law)
    is_hertz = n is not None and abs(n - 1.5) < 1e-9
    assert law.hertz_stiffness == (1e12 if is_hertz else None)
    # kelvin_voigt is linear (a scene's exponent key does not apply), johnson_cylinder a line contact
    assert is_hertz == (name not in ("kelvin_voigt", "johnson_cylinder"))
    assert _joint(name, 1e12, exponent=1.2).normal.hertz_stiffness is None


@pytest.mark.parametrize("name", list(LAWS))
def test_warning_compares_with_steel_only_a_hertz_constant(name):
    k_steel = float(contact.cylinder_stiffness(R, R + C, 2.1e11, 0.3, 2.1e11, 0.3))
    base = short_contact_warning(_joint(name, 1e9), 2e-5, 1e-4)
    assert "'big_end_1'" in base and "below 5e-06 s" in base and "steel" not in base
    text = short_contact_warning(_joint(name, 1e3 * k_steel), 2e-5, 1e-4)
    if name in ("kelvin_voigt", "johnson_cylinder"):  # N/m: no comparison with N/m^1.5
        assert text == base
    else:
        assert text.startswith(base)
        assert f"contact.stiffness = {1e3 * k_steel:.3g} N/m^1.5: 1e+03 times a steel" in text
    # another exponent: not comparable either
    assert short_contact_warning(_joint(name, 1e3 * k_steel, exponent=1.2), 2e-5, 1e-4) == base
