"""Crankshaft fatigue verdict (issue 29 item 3): stress over a steady cycle from stress modes,
mean and alternating stress, Goodman/Gerber against the material's fatigue strength with
Marin-type factors, the safety factor per point and per location (fillets, oil-hole exits).

- :mod:`.factors` -- :class:`FatigueFactors` and Shigley's Marin factor estimates;
- :mod:`.cycle` -- ``σ(t) = σ_0 + Σ σ_k ξ_k(t)`` per point, in memory-bounded chunks;
- :mod:`.criterion` -- mean/amplitude tensors, equivalent stresses, Goodman and Gerber;
- :mod:`.locations` -- a crank's fillets and oil-hole exits from its parameters;
- :mod:`.verdict` -- :func:`fatigue_verdict`, the whole check on plain arrays;
- :mod:`.result` -- :class:`FatigueResult` (summary, ``save``/``load``, plots);
- :mod:`.plots` -- the bar/Haigh figure and the crank coloured by safety factor.

Only numpy is imported here; matplotlib and pyvista inside the plotting functions.
"""

from .criterion import equivalent_alternating, equivalent_mean, mean_and_amplitude, safety_factor
from .cycle import CycleExtremes, cycle_extremes
from .factors import FatigueFactors, reliability_factor, size_factor, surface_factor
from .locations import CrankLocations, crank_locations, surface_nodes
from .result import FatigueFileError, FatigueResult
from .verdict import fatigue_verdict

__all__ = ["CrankLocations", "CycleExtremes", "FatigueFactors", "FatigueFileError",
           "FatigueResult", "crank_locations", "cycle_extremes", "equivalent_alternating",
           "equivalent_mean", "fatigue_verdict", "mean_and_amplitude", "reliability_factor",
           "safety_factor", "size_factor", "surface_factor", "surface_nodes"]
