"""Planar crank-linkage dynamics with ideal and clearance joints.

Bodies expose interface frames; joints (ideal pins, sliders, the crank drive) and clearance
joints see only those frames, so a flexible body can later replace a rigid one. Modules:
``contact`` (force and friction laws), ``lubrication`` (short-bearing film force), ``bodies``,
``joints``, ``clearance``, ``loads``, ``system`` (the DAE), ``fastpath`` (vectorised rigid
constraints), ``simulate`` (integration with contact events), ``history`` (sampled outputs and
energy balance), ``signals`` (spectra, impacts, contact loss), ``mechanisms`` (slider-crank
trains, four-star, four-bar), ``analysis`` (checked runs, tolerance study), ``scene_keys``,
``build``, ``bridge`` (machines of :mod:`crankmodal.mechanism`), ``plots``, ``stage``,
``flexible`` (planar floating-frame body from a reduced ``.npz``; core only, not in scenes yet).
"""

from .analysis import simulate, tolerance_study
from .flexible import FlexibleBody, load_flexible_body
from .mechanisms import Cylinder, Mechanism, crank_train, four_bar
from .simulate import SolverSettings

__all__ = ["Cylinder", "FlexibleBody", "Mechanism", "SolverSettings", "crank_train", "four_bar",
           "load_flexible_body", "simulate", "tolerance_study"]
