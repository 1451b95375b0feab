"""Peak resident memory of a block of code, sampled from ``/proc/self/statm``.

``tracemalloc`` misses what MKL, SuperLU and ARPACK allocate in C, and ``ru_maxrss`` never goes
down, so a sampling thread records the largest resident set size seen during the block.
"""

from __future__ import annotations

import os
import resource
import threading

_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


def rss_bytes() -> int:
    """Current resident set size of this process, bytes (0 where /proc is missing)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * _PAGE
    except OSError:
        return 0


def release_free_heap() -> None:
    """Hand memory that was freed but kept by glibc's allocator back to the system.

    Assembly frees many arrays of a few MB to a few tens of MB; glibc's dynamic mmap threshold
    keeps such blocks on its heap, where fragmentation holds them: 0.35 GB stayed resident after
    assembling a 274k-DOF crank and added to the peak of the factorisation that followed.
    A no-op where ``malloc_trim`` does not exist (musl, macOS, Windows).
    """
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


class PeakMemory:
    """Context manager measuring the peak RSS while it is active.

    Attributes (after exit)
    -----------------------
    peak : int
        Largest RSS sampled, bytes.
    baseline : int
        RSS on entry, bytes.
    """

    def __init__(self, interval: float = 0.01):
        self.interval = interval
        self.peak = 0
        self.baseline = 0
        self._stop = threading.Event()

    def _sample(self):
        while not self._stop.wait(self.interval):
            self.peak = max(self.peak, rss_bytes())

    def __enter__(self):
        self.baseline = self.peak = rss_bytes()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.peak = max(self.peak, rss_bytes())
        if self.peak == 0:  # no /proc: fall back to the lifetime maximum
            self.peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        return False

    def to_dict(self) -> dict:
        return {"peak_rss_bytes": int(self.peak), "baseline_rss_bytes": int(self.baseline)}
