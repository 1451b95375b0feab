"""Critical speeds: excitation orders x running speed against the natural frequencies.

The gas and inertia torques of a reciprocating machine repeat every working cycle, so they excite
at whole multiples (orders) of the cycle frequency: integer orders of the shaft speed for
compressors and two-stroke engines, half orders for four-stroke engines (the cycle takes two
revolutions). Order ``q`` at shaft speed ``n`` (rpm) forces at ``q n / 60`` Hz; a natural
frequency ``f`` is excited at the critical speed ``n_c = 60 f / q``. The margin of a critical
speed from the operating speed ``n_op`` is ``(n_c - n_op) / n_op``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

#: Order families by machine type.
ORDER_TYPES = ("compressor", "two_stroke", "four_stroke")
#: highest excitation order (the ``torsion.max_order`` key's bound)
MAX_ORDER = 100.0


def excitation_orders(order_type: str, max_order: float) -> np.ndarray:
    """Orders up to ``max_order``: integers, or halves for ``four_stroke``.

    Raises
    ------
    ParameterError
        Naming ``order_type`` (not one of :data:`ORDER_TYPES`) or ``max_order`` (below the
        first order).
    """
    if order_type not in ORDER_TYPES:
        raise ParameterError("order_type", f"must be one of {', '.join(ORDER_TYPES)}; got {order_type!r}")
    step = 0.5 if order_type == "four_stroke" else 1.0
    if not max_order >= step:
        raise ParameterError("max_order", f"must be >= {step:g} for {order_type}, got {max_order!r}")
    return np.arange(1, int(np.floor(max_order / step)) + 1) * step


@dataclass
class CriticalSpeeds:
    """Interference of excitation orders with natural frequencies.

    Attributes
    ----------
    natural_hz : ndarray
        Natural frequencies checked, Hz.
    orders : ndarray
        Excitation orders.
    speed_range_rpm : (float, float)
        Running-speed range, rpm.
    operating_rpm : float or None
        Operating speed, rpm.
    required_margin : float
        Separation asked for between any critical speed and the operating speed (fraction).
    """

    natural_hz: np.ndarray
    orders: np.ndarray
    speed_range_rpm: tuple
    operating_rpm: float | None = None
    required_margin: float = 0.10

    def all_criticals(self) -> list[dict]:
        """Every (mode, order) critical speed, ascending in speed."""
        rows = [
            {"mode": int(m + 1), "natural_hz": float(f), "order": float(q),
             "speed_rpm": float(60.0 * f / q)}
            for m, f in enumerate(self.natural_hz) for q in self.orders
        ]
        return sorted(rows, key=lambda r: r["speed_rpm"])

    def in_range(self) -> list[dict]:
        """Critical speeds inside the running-speed range (bounds inclusive)."""
        lo, hi = self.speed_range_rpm
        return [r for r in self.all_criticals() if lo <= r["speed_rpm"] <= hi]

    def nearest(self) -> dict | None:
        """The critical speed nearest the operating speed, with its margin (fraction)."""
        if self.operating_rpm is None or not len(self.natural_hz):
            return None
        best = min(self.all_criticals(), key=lambda r: abs(r["speed_rpm"] - self.operating_rpm))
        return {**best, "margin": (best["speed_rpm"] - self.operating_rpm) / self.operating_rpm}

    def too_close(self) -> list[dict]:
        """Critical speeds within ``required_margin`` of the operating speed."""
        if self.operating_rpm is None:
            return []
        n0 = self.operating_rpm
        return [{**r, "margin": (r["speed_rpm"] - n0) / n0} for r in self.all_criticals()
                if abs(r["speed_rpm"] - n0) <= self.required_margin * n0]

    def first_order_check(self) -> dict | None:
        """Seed 004's check: lowest-order forcing at the operating speed vs the first mode."""
        if self.operating_rpm is None or not len(self.natural_hz):
            return None
        forcing = self.orders[0] * self.operating_rpm / 60.0
        return {"order": float(self.orders[0]), "forcing_hz": float(forcing),
                "first_natural_hz": float(self.natural_hz[0]),
                "ratio": float(self.natural_hz[0] / forcing)}

    def to_dict(self) -> dict:
        return {
            "orders": self.orders,
            "speed_range_rpm": list(self.speed_range_rpm),
            "operating_speed_rpm": self.operating_rpm,
            "required_margin": self.required_margin,
            "critical_speeds_in_range": self.in_range(),
            "nearest_to_operating": self.nearest(),
            "within_required_margin": self.too_close(),
            "first_order_check": self.first_order_check(),
        }


def critical_speeds(
    natural_hz,
    order_type: str = "compressor",
    max_order: float = 12,
    speed_range_rpm=(0.0, 3000.0),
    operating_rpm: float | None = None,
    required_margin: float = 0.10,
) -> CriticalSpeeds:
    """Build the interference check.

    Parameters
    ----------
    natural_hz : array_like
        Natural frequencies, Hz.
    order_type : {"compressor", "two_stroke", "four_stroke"}
    max_order : float
        Highest order considered.
    speed_range_rpm : (float, float)
        ``min < max``, rpm, ``min >= 0``.
    operating_rpm : float, optional
        Operating speed, rpm (> 0).
    required_margin : float
        Fraction, >= 0.

    Raises
    ------
    ParameterError
        Naming ``speed_range_rpm`` (empty), ``operating_rpm`` (not > 0), ``order_type`` or
        ``max_order``; the ``[torsion]`` stage re-raises it under its scene key
        (``torsion.operating_speed_rpm``).
    """
    from .. import arguments as arg

    natural_hz = arg.numbers("natural_hz", np.atleast_1d(np.asarray(natural_hz, dtype=object)),
                             ge=0.0)
    max_order = arg.number("max_order", max_order, gt=0.0, le=MAX_ORDER)
    required_margin = arg.number("required_margin", required_margin, ge=0.0)
    operating_rpm = arg.number("operating_rpm", operating_rpm, optional=True)
    lo, hi = arg.numbers("speed_range_rpm", speed_range_rpm, length=2)
    if not (0.0 <= lo < hi):
        raise ParameterError("speed_range_rpm", f"need 0 <= min < max, got [{lo:g}, {hi:g}]")
    if operating_rpm is not None and not operating_rpm > 0.0:
        raise ParameterError("operating_rpm", f"must be > 0, got {operating_rpm!r}")
    return CriticalSpeeds(
        natural_hz=np.sort(np.asarray(natural_hz, float)),
        orders=excitation_orders(order_type, max_order),
        speed_range_rpm=(lo, hi),
        operating_rpm=None if operating_rpm is None else float(operating_rpm),
        required_margin=float(required_margin),
    )
