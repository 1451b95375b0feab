"""Planar crank-linkage dynamics with ideal and clearance joints.

Bodies expose interface frames; joints (ideal pins, sliders, the crank drive) and clearance
joints see only those frames, so a flexible body can later replace a rigid one. Modules:
``contact`` (force and friction laws), ``lubrication`` (short-bearing film force), ``bodies``,
``joints``, ``clearance``, ``loads``, ``system`` (the DAE), ``fastpath`` (vectorised rigid
constraints), ``simulate`` (integration with contact events), ``history`` (sampled outputs and
energy balance), ``signals`` (spectra, impacts, contact loss), ``mechanisms`` (slider-crank
trains, four-star, four-bar), ``analysis`` (checked runs, tolerance study), ``scene_keys``,
``build``, ``bridge`` (machines of :mod:`crankmodal.mechanism`), ``plots``, ``stage``,
``flexible`` (planar floating-frame body from a reduced ``.npz``), ``flexbuild`` (crank, rod and
four-bar link bodies from reduced files), ``initial`` (the quasi-static start of flexible bodies).
"""

from .analysis import simulate, tolerance_study
from .flexbuild import crank_body, link_body, rod_body
from .flexible import FlexibleBody, load_flexible_body
from .initial import quasi_static_start
from .mechanisms import Cylinder, Mechanism, crank_train, four_bar
from .simulate import SolverSettings, auto_method

__all__ = ["Cylinder", "FlexibleBody", "Mechanism", "SolverSettings", "auto_method",
           "crank_body", "crank_train", "four_bar", "link_body", "load_flexible_body",
           "quasi_static_start", "rod_body", "simulate", "tolerance_study"]
