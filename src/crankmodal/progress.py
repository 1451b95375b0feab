"""Progress bars for long work (tqdm), for the person at the terminal only.

A bar is drawn on stderr when stderr is a terminal and the run is not quiet (``--quiet`` on the
command line, :func:`set_quiet` from Python, or ``CRANKMODAL_QUIET=1``); otherwise every call
here is a no-op. Progress never enters results.
"""

from __future__ import annotations

import os
import sys

_quiet = False


def set_quiet(quiet: bool = True) -> None:
    """Switch progress bars off (``True``) or back on for this process."""
    global _quiet
    _quiet = bool(quiet)


def enabled() -> bool:
    """Whether a bar would be drawn now."""
    if _quiet or os.environ.get("CRANKMODAL_QUIET", "") not in ("", "0"):
        return False
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # a closed or replaced stderr
        return False


def bar(total=None, desc: str = "", unit: str = "it", **kwargs):
    """A ``tqdm`` bar on stderr, disabled when :func:`enabled` is false.

    Parameters
    ----------
    total : float or None
        Amount of work (e.g. simulated seconds, steps, models); None for an open count.
    desc : str
        Label, e.g. ``"dynamics"``.
    unit : str
        Unit of ``total``.
    **kwargs
        Passed to ``tqdm`` (``unit_scale``, ``bar_format``, ...).

    Returns
    -------
    tqdm.tqdm
        Use as a context manager; ``update(n)`` advances it. A disabled bar costs nothing.
    """
    from tqdm import tqdm

    kwargs.setdefault("leave", False)
    kwargs.setdefault("dynamic_ncols", True)
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=not enabled(),
                **kwargs)


class PhaseTimings(dict):
    """A ``{phase_s: seconds}`` timings dict that also advances a progress bar, one step per
    phase recorded (the phase's name shown): long multi-phase work (a Craig–Bampton reduction)
    shows where it is without changing how it books its timings."""

    def __init__(self, desc: str, phases: int, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._bar = bar(total=phases, desc=desc, unit="phase")

    def __setitem__(self, key, value):
        super().__setitem__(key, value)
        if self._bar is not None:
            self._bar.set_postfix_str(str(key).removesuffix("_s"), refresh=False)
            self._bar.update(1)
            if self._bar.n >= (self._bar.total or 0):
                self.close()

    def close(self) -> None:
        """Remove the bar (a no-op once closed)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __reduce__(self):  # pickled or copied as the plain dict it books
        return (dict, (dict(self),))
