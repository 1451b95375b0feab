"""Multi-phase work shows a progress bar that advances per phase, and books plain timings."""

import pickle

from crankmodal import progress
from crankmodal.progress import PhaseTimings


def test_phase_timings_book_like_a_dict_and_advance_a_bar(monkeypatch):
    monkeypatch.setattr(progress, "enabled", lambda: True)  # as at a terminal
    t = PhaseTimings("reduction", 3)
    assert t._bar is not None and not t._bar.disable
    t["partition_s"] = 0.1
    assert t._bar.n == 1 and "partition" in t._bar.postfix
    t["factorize_s"] = 0.2
    t["modes_s"] = 0.3
    assert t._bar is None  # closed when every phase is booked
    assert t == {"partition_s": 0.1, "factorize_s": 0.2, "modes_s": 0.3}
    assert type(pickle.loads(pickle.dumps(t))) is dict


def test_quiet_phase_timings_draw_nothing():
    progress.set_quiet(True)
    try:
        t = PhaseTimings("reduction", 2)
        assert t._bar.disable
        t["a_s"] = 1.0
    finally:
        progress.set_quiet(False)
