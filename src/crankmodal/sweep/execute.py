"""One sweep point: a scene run in its own folder, turned into a record.

This runs inside a Dask worker, in-process: the worker has crankmodal and its stages imported
once, so a point costs its computation plus milliseconds. A user error (exit 2) or a failed
numerical check (exit 3) becomes the record's status and one-line error, never an exception:
one bad point must not stop a sweep. With a per-point timeout the run happens in a forked child
of the worker (it inherits the imported modules, so the fork costs milliseconds), which is
killed when the time is up - a thread cannot be stopped, a process can.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
import tomllib
from pathlib import Path

from ..errors import CrankmodalError


def toml_value(v) -> str:
    """A Python value in the TOML syntax ``--set`` parses (:func:`crankmodal.scene.parse_value`)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"cannot write {v!r} as a TOML value")


def overrides_of(point: dict, fixed: list[str] = ()) -> list[str]:
    """The ``--set`` assignments of a point: the sweep's fixed ones, then the axes'."""
    return [*fixed, *(f"{k}={toml_value(v)}" for k, v in point.items())]


def point_key(base_digest: str, overrides: list[str]) -> str:
    """The identity of a point: a hash of the base scene's content and its overrides. A re-run
    skips a key already recorded; an edited base scene or axis value gives new keys."""
    h = hashlib.sha256(base_digest.encode())
    for s in overrides:
        h.update(b"\0" + s.encode())
    return h.hexdigest()[:16]


def build_scene(base_text: str, base_path: str, overrides: list[str]):
    """The point's scene: the base scene's text with the overrides (relative files resolve
    against the base scene's folder, which remote workers must see at the same path)."""
    from ..scene import scene_from_dict

    path = Path(base_path)
    return scene_from_dict(tomllib.loads(base_text), name=path.stem,
                           base_dir=path.resolve().parent, overrides=overrides, path=path)


def lookup(results: dict, path: str):
    """The value at a dotted results.json path (a numeric element indexes a list); KeyError
    when the path does not exist."""
    node = results
    for part in path.split("."):
        if isinstance(node, dict) and part in node:
            node = node[part]
        elif isinstance(node, list) and part.lstrip("-").isdigit() and \
                -len(node) <= int(part) < len(node):
            node = node[int(part)]
        else:
            raise KeyError(path)
    return node


def collect(results: dict, outputs: list[str]) -> dict:
    """``{path: value}`` of the wanted outputs; a path the run did not produce is None."""
    out = {}
    for p in outputs:
        try:
            out[p] = lookup(results, p)
        except KeyError:
            out[p] = None
    return out


def _guarded(fn, outputs) -> dict:
    """``fn()`` and its record fields (status, exit code, error line); ``fn`` returns the
    outputs. An error is recorded, never raised: one bad point must not stop a sweep."""
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a point's model warnings are in its results.json
            out = fn()
    except CrankmodalError as exc:
        return {"status": "error", "exit_code": exc.exit_code, "error": str(exc).splitlines()[0]
                if str(exc) else type(exc).__name__, "outputs": dict.fromkeys(outputs)}
    except Exception as exc:  # noqa: BLE001 (a bug, not the user's: recorded, the sweep goes on)
        return {"status": "error", "exit_code": 1, "error": f"{type(exc).__name__}: {exc}"
                .splitlines()[0], "outputs": dict.fromkeys(outputs)}
    return {"status": "ok", "exit_code": 0, "error": None, "outputs": out}


def _run(base_text, base_path, overrides, out_dir, outputs, figures) -> dict:
    """The scene run and its record fields (status, exit code, error line, outputs)."""

    def scene_run():
        from ..results import to_jsonable
        from ..runner import run

        results = run(build_scene(base_text, base_path, overrides), out_dir, figures=figures)
        return collect(to_jsonable(results), outputs)  # as results.json has them (lists)

    return _guarded(scene_run, outputs)


def _call(target: str, kwargs: dict, out_dir: str, outputs) -> dict:
    """A function point: ``target`` ("package.module:function") called as
    ``function(out_dir=..., **kwargs)``; the dict it returns (JSON-able) is the outputs.
    Studies that are not one scene run per point (the mesh-simplification study's models) run
    on the same driver, store and resumption this way."""

    def call():
        import importlib

        module, _, name = target.partition(":")
        return getattr(importlib.import_module(module), name)(out_dir=out_dir, **kwargs)

    return _guarded(call, outputs)


def _run_in_child(fn, args, timeout_s: float, outputs) -> dict:
    """:func:`_run` in a forked child, killed after ``timeout_s``.

    ``os.fork`` itself, not :mod:`multiprocessing`: Dask's worker processes are daemonic, and
    multiprocessing refuses children to those.
    """
    import os
    import pickle
    import select
    import signal

    rfd, wfd = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: run, send the record, leave without any cleanup of the parent's
        code = 0
        try:
            os.close(rfd)
            data = pickle.dumps(fn(*args))
            with os.fdopen(wfd, "wb") as fh:
                fh.write(data)
        except BaseException:  # noqa: BLE001 (the child must reach os._exit)
            code = 1
        finally:
            os._exit(code)
    os.close(wfd)
    chunks, deadline, timed_out = [], time.monotonic() + timeout_s, False
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([rfd], [], [], left)[0]:
                timed_out = True
                break
            chunk = os.read(rfd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
    finally:
        os.close(rfd)
        if timed_out:
            os.kill(pid, signal.SIGKILL)
        _, status = os.waitpid(pid, 0)
    if timed_out:
        return {"status": "timeout", "exit_code": None, "outputs": dict.fromkeys(outputs),
                "error": f"the point ran past timeout_s = {timeout_s:g} s"}
    try:
        return pickle.loads(b"".join(chunks))
    except Exception:  # noqa: BLE001 (no complete record came back)
        return {"status": "error", "exit_code": None, "outputs": dict.fromkeys(outputs),
                "error": f"the point's process died (wait status {status})"}


def execute_point(task: dict) -> dict:
    """Run one point and return its record.

    Parameters
    ----------
    task : dict
        ``index``, ``key``, ``parameters`` ({key: value}), ``overrides`` (list of str),
        ``base_text``, ``base_path``, ``dir`` (the point's output folder), ``outputs``,
        ``timeout_s`` (or None), ``figures``, ``round`` (search round). A function point has
        ``call`` ("module:function") and ``kwargs`` instead of the scene's keys (see
        :func:`_call`).

    Returns
    -------
    dict
        The record: ``point``, ``key``, ``parameters``, ``status`` ("ok", "error",
        "timeout"), ``exit_code`` (0, 2, 3; 1 for an unexpected exception; None for a timeout),
        ``error`` (one line or None), ``outputs``, ``wall_time_s``, ``dir``, ``round``.
    """
    t0 = time.perf_counter()
    if task.get("call"):
        fn, args = _call, (task["call"], task["kwargs"], task["dir"], task["outputs"])
    else:
        fn, args = _run, (task["base_text"], task["base_path"], task["overrides"], task["dir"],
                          task["outputs"], task["figures"])
    if task.get("timeout_s"):
        res = _run_in_child(fn, args, task["timeout_s"], task["outputs"])
    else:
        res = fn(*args)
    return {"point": task["index"], "key": task["key"], "round": task.get("round", 0),
            "parameters": task["parameters"], **res,
            "wall_time_s": time.perf_counter() - t0, "dir": task["dir"]}
