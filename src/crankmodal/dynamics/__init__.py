"""Planar crank-linkage dynamics with ideal and clearance joints.

Bodies expose interface frames; joints (ideal pins, sliders, the crank drive) and clearance
joints see only those frames, so a flexible body can replace a rigid one. Subpackages, in the
order data flows:

``model``
    bodies, ideal joints, clearance joints, loads, the assembled DAE (``system``), the builders
    of crank trains and four-bars (``mechanisms``) and of machines of :mod:`crankmodal.mechanism`
    (``bridge``).
``laws``
    contact and friction laws (``contact`` functions, ``objects`` classes), the short-bearing
    (``lubrication``) and finite-length (``reynolds``) oil films.
``flexible``
    planar floating-frame bodies from reduced files (``body``), crank, rod and link bodies
    (``build``), the quasi-static start (``initial``), modal damping and step bounds.
``kernel``
    the compiled (Numba) evaluator of a built system.
``run``
    the integrator driver (``integrate``), checked runs (``simulate``), run budgets, contact
    time scales and ensembles.
``results``
    sampled histories and energy balance, signals, per-revolution statistics, validity, figures.
``scene``
    the ``[dynamics]`` scene stage: keys, validation, building from a scene.
"""

from .flexible.body import FlexibleBody, load_flexible_body
from .flexible.build import crank_body, link_body, rod_body
from .flexible.initial import quasi_static_start
from .model.drive import MotorDrive
from .model.mechanisms import Cylinder, Mechanism, crank_train, four_bar
from .results.result import DynamicsResult
from .run.integrate import SolverSettings, auto_method
from .run.simulate import simulate, tolerance_study

__all__ = ["Cylinder", "DynamicsResult", "FlexibleBody", "Mechanism", "MotorDrive", "SolverSettings",
           "auto_method", "crank_body", "crank_train", "four_bar", "link_body", "load_flexible_body",
           "quasi_static_start", "rod_body", "simulate", "tolerance_study"]
