"""A pytest plugin giving the ``assert_frequencies`` fixture.

Installing crankmodal registers it with pytest (entry point ``pytest11``), so any test suite can
ask for the fixture without further setup::

    def test_rod_modes(assert_frequencies, results):
        assert_frequencies(results, [780.0, 1115.0, 1687.0], rtol=0.12)

The function itself lives in :mod:`crankmodal.report.testing` and can be imported directly.
"""

from __future__ import annotations

import pytest


@pytest.fixture
def assert_frequencies():
    """The :func:`crankmodal.report.testing.assert_frequencies` function."""
    from .testing import assert_frequencies as check

    return check
