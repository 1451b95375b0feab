"""results.json is written atomically and never carries non-finite numbers."""

import json

import numpy as np
import pytest

from crankmodal.errors import NumericalError
from crankmodal.results import to_jsonable, write_atomic, write_json_atomic


def test_numpy_values_become_plain_json(tmp_path):
    p = write_json_atomic(tmp_path / "r.json", {"a": np.arange(3), "b": np.float64(2.5), "c": (1, 2)})
    assert json.loads(p.read_text()) == {"a": [0, 1, 2], "b": 2.5, "c": [1, 2]}


def test_nan_is_refused_with_its_key_path_and_nothing_is_written(tmp_path):
    target = tmp_path / "results.json"
    with pytest.raises(NumericalError, match=r"modal\.frequencies_hz\[1\] is nan"):
        write_json_atomic(target, {"modal": {"frequencies_hz": np.array([1.0, np.nan])}})
    assert not target.exists()


def test_failed_write_leaves_old_file_intact_and_no_temp_files(tmp_path):
    target = tmp_path / "results.json"
    target.write_text("old")

    with pytest.raises(TypeError):
        write_atomic(target, object())  # the temporary file is open when the write fails
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]


def test_to_jsonable_uses_to_dict():
    class R:
        def to_dict(self):
            return {"x": np.float32(1.5)}

    assert to_jsonable({"r": R()}) == {"r": {"x": 1.5}}


def test_atomic_write_gives_an_ordinary_readable_file(tmp_path):
    import os
    import stat

    p = write_atomic(tmp_path / "r.txt", "x")
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~mask
