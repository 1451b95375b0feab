"""Progress bars: drawn only for a person at a terminal, never with --quiet."""

import io

from crankmodal import progress


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_bar_draws_on_a_terminal_and_not_when_quiet(monkeypatch):
    monkeypatch.delenv("CRANKMODAL_QUIET", raising=False)
    tty = _Tty()
    monkeypatch.setattr("sys.stderr", tty)
    progress.set_quiet(False)
    with progress.bar(total=10, desc="work") as b:
        b.update(10)
    assert "work" in tty.getvalue()
    tty2 = _Tty()
    monkeypatch.setattr("sys.stderr", tty2)
    progress.set_quiet(True)
    try:
        with progress.bar(total=10, desc="work") as b:
            b.update(10)
    finally:
        progress.set_quiet(False)
    assert tty2.getvalue() == ""


def test_bar_is_silent_when_stderr_is_not_a_terminal(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr("sys.stderr", buf)
    with progress.bar(total=3, desc="work") as b:
        b.update(3)
    assert buf.getvalue() == ""


def test_environment_quiets_bars(monkeypatch):
    monkeypatch.setattr("sys.stderr", _Tty())
    monkeypatch.setenv("CRANKMODAL_QUIET", "1")
    assert not progress.enabled()
