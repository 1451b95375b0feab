"""Peak resident memory of a block of code, sampled from ``/proc/self/statm``.

``tracemalloc`` misses what MKL, SuperLU and ARPACK allocate in C, and ``ru_maxrss`` never goes
down, so a sampling thread records the largest resident set size seen during the block.
"""

from __future__ import annotations

import contextlib
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


def _read_int(path: str) -> int | None:
    try:
        with open(path) as fh:
            text = fh.read().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def _cgroup_room() -> int | None:
    """What this process's memory cgroup (a container's limit) still allows, bytes, or None."""
    try:
        with open("/proc/self/cgroup") as fh:
            lines = fh.read().splitlines()
    except OSError:
        return None
    for line in lines:
        _, controllers, path = line.split(":", 2)
        if controllers == "":  # cgroup v2
            pairs = [(f"/sys/fs/cgroup{path}/memory.max", f"/sys/fs/cgroup{path}/memory.current"),
                     ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current")]
        elif "memory" in controllers.split(","):  # cgroup v1
            root = "/sys/fs/cgroup/memory"
            pairs = [(f"{root}{path}/memory.limit_in_bytes", f"{root}{path}/memory.usage_in_bytes"),
                     (f"{root}/memory.limit_in_bytes", f"{root}/memory.usage_in_bytes")]
        else:
            continue
        for limit_file, usage_file in pairs:
            limit, usage = _read_int(limit_file), _read_int(usage_file)
            if limit is not None and usage is not None and limit < 1 << 60:  # v1: "no limit"
                return max(limit - usage, 0)
    return None


def available_bytes() -> int | None:
    """Memory this process can still take, bytes; None where the system does not say.

    ``CRANKMODAL_MEMORY_LIMIT`` (GB) if set; else the smaller of the kernel's ``MemAvailable``
    and the room left under a container's memory limit (cgroup v1 or v2).
    """
    env = os.environ.get("CRANKMODAL_MEMORY_LIMIT", "").strip()
    if env:
        try:
            return int(float(env) * 1e9)
        except ValueError:
            from ..errors import SceneError

            raise SceneError(f"CRANKMODAL_MEMORY_LIMIT: must be a number of GB, got {env!r}") from None
    avail = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except OSError:
        pass
    room = _cgroup_room()
    if room is not None:
        avail = room if avail is None else min(avail, room)
    return avail


@contextlib.contextmanager
def address_space_limit(extra: int | None):
    """Let the process map at most ``extra`` bytes more than it has mapped now (Linux).

    Inside, an allocation beyond that fails with ``MemoryError`` instead of the kernel's
    out-of-memory killer ending the process. Memory the process has mapped but freed (glibc's
    heap) can be used on top: a safety net, not an exact bound. ``None``, or a system without
    ``/proc/self/status``: no limit.
    """
    try:
        with open("/proc/self/status") as fh:
            vm = next(int(line.split()[1]) * 1024 for line in fh if line.startswith("VmSize:"))
    except (OSError, StopIteration, ValueError):
        vm = None
    if extra is None or vm is None:
        yield
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    limit = vm + int(extra)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    if soft != resource.RLIM_INFINITY:
        limit = min(limit, soft)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


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
