"""Whether a run's contacts stayed inside their law's validity: the penetration against the
clearance and against the elastic approach of the journal in its bore.

A penalty law (``K delta**n``) stands for the elastic approach of two bodies; a penetration that
is a large part of the clearance, or many times what the elastic journal and bore would
actually approach under the same force, means the stiffness is far too low for the loads and
the orbit, impacts and peaks are those of a much softer joint. The approach of conformal
cylinders is Johnson's line-contact formula (:func:`.contact.johnson_cylinder_approach`,
``delta = F / (pi L E*) (ln(4 pi L E* dR / F) - 1)``).
"""

from __future__ import annotations

import numpy as np

from . import contact

#: a penetration above this fraction of the radial clearance gives a warning
CLEARANCE_FRACTION = 0.25
#: a penetration above this multiple of the elastic approach under the peak force gives a warning
APPROACH_FACTOR = 5.0


def elastic_approach(cj, force: float, E: float, nu: float) -> tuple[float, float]:
    """Elastic approach (m) of the joint's journal in its bore under ``force`` N, and the length
    used (m): the joint's ``bearing_length`` if given, else one journal diameter (L/D = 1).

    Journal and bore of the same material (``E`` in Pa, ``nu``), radial clearance ``dR``.
    """
    L = cj.bearing_length if cj.bearing_length and cj.bearing_length > 0.0 else 2.0 * cj.journal_radius
    K = np.pi * L * contact.effective_modulus(E, nu, E, nu)
    return float(contact.johnson_cylinder_approach(force, K, cj.clearance)), L


def penetration_warning(cj, depth: float, force: float, E: float = 2.1e11,
                        nu: float = 0.3) -> str | None:
    """The warning for a joint whose largest penetration ``depth`` (m), under its peak contact
    force ``force`` (N), exceeds :data:`CLEARANCE_FRACTION` of the clearance or
    :data:`APPROACH_FACTOR` times the elastic approach; None when it stays inside both."""
    if not depth > 0.0:
        return None
    approach, L = elastic_approach(cj, force, E, nu)
    of_clearance = depth / cj.clearance
    ratio = depth / approach if approach > 0.0 else 0.0  # no force: the clearance alone
    if of_clearance <= CLEARANCE_FRACTION and ratio <= APPROACH_FACTOR:
        return None
    K = cj.law_params.get("stiffness", float("nan"))
    return (f"dynamics: joint {cj.name!r} penetrates {depth:.3g} m, {100 * of_clearance:.0f} % "
            f"of its {cj.clearance:.3g} m clearance (warning above "
            f"{100 * CLEARANCE_FRACTION:.0f} %) and {ratio:.2g} times the elastic approach of "
            f"journal and bore under its peak contact force {force:.3g} N ({approach:.2g} m, "
            f"Johnson's conformal cylinders, L = {L:.3g} m; warning above "
            f"{APPROACH_FACTOR:g} times): the contact law ({cj.law}) is far outside its "
            f"validity; raise dynamics.contact.stiffness (now {K:.3g}) or use "
            f"dynamics.contact.law = 'johnson_cylinder'")
