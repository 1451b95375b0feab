"""The sweep driver: validate every point, run them on Dask, store, tabulate, search.

Dask (``dask.distributed``) is the engine: a :class:`~dask.distributed.LocalCluster` of worker
processes on this machine's cores by default (one thread each, with MKL/OpenMP/OpenBLAS held to
one thread so PARDISO and BLAS do not oversubscribe the cores), or any cluster through its
scheduler address or a :class:`~dask.distributed.Client`. The driver keeps a bounded number of
points in flight (twice the workers' threads), so a sweep of thousands of points keeps the
client's memory flat; records go to disk as they arrive.

Ctrl-C (or SIGTERM) is the client's alone: the local cluster's worker processes are started
with SIGINT ignored (a terminal sends it to the whole process group, and each worker would print
its own traceback), so the driver cancels the points in flight, closes the cluster and raises
:class:`SweepInterrupted` saying how far the sweep got.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from pathlib import Path

from ..errors import CrankmodalError, ParameterError
from ..results import make_out_dir, write_json_atomic
from .execute import build_scene, execute_point, overrides_of, point_key
from .spec import SweepSpec, check_max_failed, load_sweep
from .store import RecordStore, as_stored, folder_lock
from .table import missing_outputs, refresh_outputs, suggestion, summarise, write_csv

#: The workers' environment: one BLAS/OpenMP thread per worker process.
THREAD_ENV = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
#: Dask settings of the local cluster's workers. A point is a long pure-Python computation; the
#: worker's event loop, waking every 20 ms to time itself (tick), every 10 ms to sample the running
#: task's stack (profile, for the dashboard's profile page) and every 0.5 s for the system monitor,
#: takes the GIL from it each time: one seed 003 dynamics point took 20.7 s in a worker against
#: 16.2 s in-process, 15.4 s with these settings (17.1 s with the tick alone).
WORKER_CONFIG = {"distributed.admin.tick.interval": "1s",
                 "distributed.worker.profile.enabled": False,
                 "distributed.admin.system-monitor.interval": "2s"}
#: Seconds to wait for a scheduler given by address.
CONNECT_TIMEOUT_S = 3


#: Exit status of ``crankmodal sweep`` when more than ``max_failed`` of the points failed: the
#: table and summary are written (unlike exit 2, bad input, where neither is), but a script
#: must not take them for a complete sweep.
FAILED_EXIT = 4


class SchedulerError(CrankmodalError):
    """The Dask scheduler given by address cannot be reached."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) stopped a sweep; raised once its cluster is closed.

    Attributes
    ----------
    recorded, total : int
        Points of the sweep with a record (kept: a re-run skips them) and points planned.
    out_dir : Path
        The sweep's folder.
    original : KeyboardInterrupt
        The interrupt as raised (the CLI's SIGTERM is a subclass).
    """

    def __init__(self, recorded: int, total: int, out_dir: Path, original: BaseException):
        self.recorded, self.total, self.out_dir, self.original = recorded, total, out_dir, original
        super().__init__(f"{recorded} of {total} points recorded")


@contextlib.contextmanager
def _children_ignore_sigint():
    """Processes started inside the block ignore SIGINT: an ignored signal stays ignored through
    fork and exec (Python and asyncio then install no handler of their own), so Dask's worker
    processes never see the terminal's Ctrl-C and the client shuts them down. The price: a
    Ctrl-C in the second or two the local cluster takes to start is ignored here too (blocking
    it instead would not do: the BLAS threads that exist already would take and drop it)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, handler)


def _ignore_sigint() -> None:
    """A second Ctrl-C while the cluster shuts down would break the shutdown halfway."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def _sigint_handler_kept():
    """Restore the SIGINT handler on leaving (after :func:`_ignore_sigint`)."""
    main = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGINT) if main else None
    try:
        yield
    finally:
        if main and previous is not None:
            signal.signal(signal.SIGINT, previous)


def plan_tasks(spec: SweepSpec, points: list[dict], out_dir: Path, first_index: int = 0,
               round_no: int = 0) -> list[dict]:
    """Every point's task, each point's scene validated (:func:`crankmodal.runner.check`).

    Raises
    ------
    CrankmodalError
        Of the first invalid point: ``point N (key=value, ...): <the scene's error>``.
    """
    from ..runner import check

    tasks = []
    for i, p in enumerate(points, start=first_index):
        ov = overrides_of(p, spec.fixed)
        try:
            check(build_scene(spec.base_text, str(spec.base), ov))
        except CrankmodalError as exc:
            absent = _absent_sections(spec)
            if absent:  # the override made the section up: that, not its value, is the problem
                raise type(exc)(absent[0]) from None
            where = ", ".join(f"{k}={v!r}" for k, v in p.items())
            raise type(exc)(f"point {i} ({where}): {exc}") from None
        key = point_key(spec.base_digest, ov)
        tasks.append({"index": i, "key": key, "parameters": p, "overrides": ov,
                      "base_text": spec.base_text, "base_path": str(spec.base.resolve()),
                      "dir": str(out_dir / "points" / key), "outputs": spec.outputs,
                      "timeout_s": spec.timeout_s, "figures": spec.figures, "round": round_no})
    return tasks


def _absent_sections(spec: SweepSpec) -> list[str]:
    """One message per axis or ``set`` key whose section the base scene lacks. An override
    does not add a section's other keys (nor its machine's defaults), so such a point fails its
    check on whatever the lone key makes of the section; this names the actual cause."""
    try:
        scene = build_scene(spec.base_text, str(spec.base), [])
    except CrankmodalError:
        return []  # the base scene's own error is the one to show
    have = set(scene.sections)
    out = []
    for where, key in [*((f"axes.{a.key}", a.key) for a in spec.axes),
                       *((f"set: {s.partition('=')[0].strip()}", s.partition("=")[0].strip())
                         for s in spec.fixed)]:
        section = key.split(".")[0]
        if section not in have:
            out.append(f"{where}: the base scene {spec.base.name} has no [{section}] section "
                       f"(it has {', '.join(f'[{s}]' for s in scene.sections) or 'none'}); a "
                       f"sweep only varies keys of its base scene: add [{section}] to it or "
                       f"take a base scene that has one")
    return out


def check_output_sections(spec: SweepSpec, task: dict) -> None:
    """An output whose first element is no section of the scene (nor a top-level key) is
    refused before anything runs."""
    scene = build_scene(spec.base_text, str(spec.base), task["overrides"])
    top = {*scene.sections, "crankmodal_version", "scene"}
    for o in spec.outputs:
        if o.split(".")[0] not in top:
            raise CrankmodalError(f"outputs: {o!r}: the scene has no [{o.split('.')[0]}] "
                                  f"section, so no point produces it; sections: "
                                  f"{', '.join(scene.sections)}")


@contextlib.contextmanager
def dask_client(client=None, scheduler: str | None = None, workers: int | None = None, log=None):
    """The Dask client to run on: ``client`` as given, a client of ``scheduler``, or a new
    local cluster of ``workers`` processes (default: the CPU count), closed on exit."""
    if client is not None:
        yield client
        return
    import logging

    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise CrankmodalError("crankmodal sweep runs on Dask, which is not installed: "
                              "pip install 'crankmodal[sweep]' (or 'dask[distributed]')") from None
    if scheduler:
        try:
            c = Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
        except Exception as exc:  # noqa: BLE001 (OSError, TimeoutError, ValueError: all one line)
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise SchedulerError(f"--scheduler {scheduler}: cannot reach the Dask scheduler "
                                 f"({reason})") from None
        try:
            yield c
        finally:
            c.close()
        return
    n = workers or os.cpu_count() or 1
    # a free port: the scheduler's HTTP server runs with or without bokeh, and on the default
    # 8787 a second cluster on the machine warned "Port 8787 is already in use" (5 lines)
    dashboard = ":0"
    import dask

    cluster = None
    try:
        # each Nanny hands its config to its worker process; the workers ignore SIGINT
        with dask.config.set(WORKER_CONFIG), _children_ignore_sigint():
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   env=THREAD_ENV, dashboard_address=dashboard,
                                   silence_logs=logging.ERROR)
        with Client(cluster) as c:
            yield c
    finally:
        if cluster is not None:
            cluster.close()


class LazyClient:
    """The Dask client, connected (or its local cluster started) on first use: a re-run whose
    points are all recorded starts no cluster."""

    def __init__(self, stack: contextlib.ExitStack, client=None, scheduler=None, workers=None,
                 log=None):
        self.stack, self.args, self.log = stack, (client, scheduler, workers, log), log
        self.client, self.info = None, {}

    def get(self):
        if self.client is None:
            c = self.client = self.stack.enter_context(dask_client(*self.args))
            self.info = {"scheduler": c.scheduler.address, "workers": len(c.nthreads()),
                         "threads": sum(c.nthreads().values()), "dashboard": _dashboard(c)}
            if self.log:
                _, scheduler, workers, _ = self.args
                if scheduler and workers:
                    self.log(f"--workers {workers} ignored: the cluster at {scheduler} has its own")
                board = self.info["dashboard"]
                self.log(f"dask: {self.info['workers']} workers at {self.info['scheduler']}, "
                         + (f"dashboard {board}" if board else
                            "no dashboard (it needs bokeh: pip install 'bokeh>=3.1')"))
        return self.client


def run_tasks(client, tasks: list[dict], store: RecordStore, done: dict, log=None) -> dict:
    """Run the tasks whose key is not in ``done`` (updated in place with the new records) on
    ``client`` (a Dask client or a :class:`LazyClient`).

    Returns
    -------
    dict
        ``ran``, ``skipped``, ``failed`` counts.
    """
    from ..progress import bar

    _drop_mismatched(done, tasks, store, log)
    todo = list({t["key"]: t for t in tasks if t["key"] not in done}.values())  # a key once
    skipped = sum(t["key"] in done for t in tasks)
    if not todo:
        return {"ran": 0, "skipped": skipped, "failed": 0}
    if isinstance(client, LazyClient):
        client = client.get()
    from dask.distributed import as_completed
    threads = sum(client.nthreads().values()) or 1
    window = 2 * threads
    it = iter(todo)
    inflight: dict = {}
    ac = as_completed()

    def submit(task):
        fut = client.submit(execute_point, task, pure=False, key=f"point-{task['key']}-"
                            f"{time.monotonic_ns()}")
        inflight[fut.key] = (fut, task)
        ac.add(fut)

    for task in (next(it) for _ in range(min(window, len(todo)))):
        submit(task)
    failed = 0
    try:
        with bar(total=len(todo), desc="sweep", unit="pt") as pb:
            for fut in ac:
                task = inflight.pop(fut.key)[1]
                try:
                    rec = fut.result()
                except Exception as exc:  # noqa: BLE001 (the worker died, KilledWorker): recorded
                    rec = {"point": task["index"], "key": task["key"],
                           "round": task["round"], "parameters": task["parameters"],
                           "status": "error", "exit_code": None,
                           "error": f"{type(exc).__name__}: {exc}".splitlines()[0],
                           "outputs": dict.fromkeys(task["outputs"]), "wall_time_s": None,
                           "dir": task["dir"]}
                fut.release()
                rec["dir"] = str(Path(rec["dir"]).relative_to(store.path.parent))
                store.append(rec)
                done[rec["key"]] = rec
                failed += rec["status"] != "ok"
                pb.update(1)
                pb.set_postfix(failed=failed, refresh=False)
                if log and rec["status"] != "ok":
                    pb.clear()  # the line above the bar, not through it
                    log(f"point {rec['point']}: {rec['status']}: {rec['error']}")
                    pb.refresh()
                nxt = next(it, None)
                if nxt is not None:
                    submit(nxt)
    except BaseException:
        # an interrupt: the points in flight are lost, the recorded ones are kept
        client.cancel([f for f, _ in inflight.values()])
        raise
    return {"ran": len(todo), "skipped": skipped, "failed": failed}


def run_tasks_in_process(tasks: list[dict], store: RecordStore, done: dict, log=None) -> dict:
    """:func:`run_tasks` one after another in this process, without Dask: the same records,
    store and resumption, for callers that must not start a cluster (a study inside
    ``crankmodal run``, which may itself be a sweep's point in a daemonic Dask worker) or
    where Dask is not installed."""
    from ..progress import bar
    from .execute import execute_point

    _drop_mismatched(done, tasks, store, log)
    todo = list({t["key"]: t for t in tasks if t["key"] not in done}.values())  # a key once
    skipped = sum(t["key"] in done for t in tasks)
    failed = 0
    with bar(total=len(todo), desc="models", unit="pt") as pb:
        for task in todo:
            rec = execute_point(task)
            rec["dir"] = str(Path(rec["dir"]).relative_to(store.path.parent))
            store.append(rec)
            done[rec["key"]] = rec
            failed += rec["status"] != "ok"
            pb.update(1)
            if log and rec["status"] != "ok":
                pb.clear()
                log(f"point {rec['point']}: {rec['status']}: {rec['error']}")
                pb.refresh()
    return {"ran": len(todo), "skipped": skipped, "failed": failed}


def run_sweep(spec, out_dir, client=None, *, scheduler: str | None = None,
              workers: int | None = None, retry_failed: bool = False, figures: bool = True,
              max_failed: float | None = None, log=None) -> dict:
    """Run a sweep (and its search) and write its records, table and ``sweep.json``.

    Parameters
    ----------
    spec : SweepSpec or str or Path
        The sweep, or its SWEEP.toml.
    out_dir : str or Path
        The sweep's folder: ``records.jsonl``, ``sweep.csv``, ``sweep.json``, ``points/<key>/``.
        A re-run into the same folder skips the points already recorded.
    client : dask.distributed.Client, optional
        Run on this client's cluster (not closed here).
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:port``) when no client is given.
    workers : int, optional
        Worker processes of the local cluster (default: the CPU count).
    retry_failed : bool
        Run again the recorded points that failed (error, timeout).
    figures : bool
        Write ``sweep_<output>.png`` maps (:mod:`crankmodal.sweep.figures`).
    max_failed : float, optional
        Share of the points (0 to 1) that may fail (error, timeout) before the sweep counts as
        failed (``failures.exceeded`` in the result; the CLI then exits with
        :data:`FAILED_EXIT`). Default: the sweep file's ``max_failed`` (itself
        :data:`.spec.MAX_FAILED`, 0.1, when absent).
    log : callable, optional
        ``log(str)`` for progress lines, the skipped bad record lines and the failures line.
        Without it, bad record lines are a :class:`UserWarning`.

    Returns
    -------
    dict
        What ``sweep.json`` holds; ``failures`` (``n``, ``share``, ``max_failed``,
        ``exceeded``, ``line``) says how many points failed and where their errors are.

    Raises
    ------
    CrankmodalError
        Bad sweep or point (before anything runs), unreachable scheduler (SchedulerError), an
        output no successful point produced (after the run; the records are kept, so fixing
        ``outputs`` and re-running recomputes nothing).
    SweepInterrupted
        Ctrl-C or SIGTERM: the cluster is closed, the finished points' records are kept.
    """
    t0 = time.perf_counter()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ParameterError("workers", f"must be an integer >= 1, got {workers!r}")
    spec = spec if isinstance(spec, SweepSpec) else load_sweep(spec)
    share = spec.max_failed if max_failed is None else check_max_failed("max_failed", max_failed)
    out_dir = Path(out_dir)
    tasks = plan_tasks(spec, spec.points(), out_dir.resolve())  # every point checked first
    check_output_sections(spec, tasks[0])
    out_dir = make_out_dir(out_dir)
    with folder_lock(out_dir):
        return _run_locked(spec, out_dir, tasks, client, scheduler, workers, retry_failed,
                           figures, share, log, t0)


def plan_sweep(spec, out_dir) -> dict:
    """Check a sweep and count what a run would do, running nothing (``--dry-run``).

    Every point's scene is checked as :func:`run_sweep` does; nothing is written.

    Returns
    -------
    dict
        ``n_points`` (of the grid or samples; a search adds its rounds' points when run),
        ``recorded`` (of those, recorded in ``out_dir/records.jsonl``: a run skips them),
        ``to_run``, ``bad_record_lines`` (lines of the records file a run would skip).
    """
    spec = spec if isinstance(spec, SweepSpec) else load_sweep(spec)
    out_dir = Path(out_dir)
    tasks = plan_tasks(spec, spec.points(), out_dir.resolve())
    check_output_sections(spec, tasks[0])
    store = RecordStore(out_dir / "records.jsonl")
    done = store.read()
    keys = dict.fromkeys(t["key"] for t in tasks)
    recorded = sum(k in done for k in keys)
    return {"name": spec.name, "n_points": len(keys), "recorded": recorded,
            "to_run": len(keys) - recorded, "bad_record_lines": len(store.skipped),
            "search": bool(spec.search)}


def failures(records: list[dict], max_failed: float, out_dir: Path) -> dict:
    """How many points failed, whether that is more than ``max_failed`` of them, and the one
    line that says so and where their errors are."""
    bad = [r for r in records if r["status"] != "ok"]
    n = len(records)
    share = len(bad) / n if n else 0.0
    exceeded = share > max_failed
    line = f"failed: {len(bad)} of {n} points ({100 * share:.3g} %"
    line += (f", more than max_failed = {100 * max_failed:.3g} %)" if exceeded else
             f"; max_failed = {100 * max_failed:.3g} %)")
    if bad:
        first = bad[0]
        line += (f"; errors: {out_dir / 'sweep.csv'} (column error) and "
                 f"{out_dir / 'records.jsonl'}; first: point {first['point']}: {first['status']}: "
                 f"{first['error']}")
    return {"n": len(bad), "share": share, "max_failed": max_failed, "exceeded": exceeded,
            "line": line}


def _run_locked(spec, out_dir, tasks, client, scheduler, workers, retry_failed, figures,
                max_failed, log, t0) -> dict:
    """:func:`run_sweep` once the folder is made and locked."""
    for stale in ("sweep.json", "sweep.csv", *(p.name for p in out_dir.glob("sweep_*.png"))):
        # a failed re-run must not leave an old table or map looking like its answer
        (out_dir / stale).unlink(missing_ok=True)
    store = RecordStore(out_dir.resolve() / "records.jsonl")  # point dirs are absolute
    done = store.read()
    if store.skipped:
        _warn(store.skipped_line(), log)
    if retry_failed:
        done = {k: r for k, r in done.items() if r.get("status") == "ok"}
    before = dict(done)  # recorded by earlier runs: "already recorded", not "run now"
    stats = {"ran": 0, "skipped": 0, "failed": 0}
    rounds = []
    keys = [t["key"] for t in tasks]
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(_sigint_handler_kept())  # restored after the cluster closed
            lazy = LazyClient(stack, client, scheduler, workers, log)
            try:
                _add(stats, run_tasks(lazy, tasks, store, done, log))
                if spec.search:
                    rounds, more = _search(spec, lazy, tasks, store, done, out_dir.resolve(),
                                           log, stats)
                    keys += more
            except KeyboardInterrupt:
                _ignore_sigint()  # until the cluster is closed (the stack's unwinding)
                raise
            info = lazy.info
    except KeyboardInterrupt as exc:
        planned = dict.fromkeys(keys)
        # what the store holds is what a resume skips: the interrupt can land between a
        # record's append and its entry in ``done`` (the count was one short then)
        recorded = store.read()
        raise SweepInterrupted(sum(k in recorded for k in planned), len(planned), out_dir,
                               exc) from None
    records = [refresh_outputs(done[k], spec.outputs, out_dir) for k in dict.fromkeys(keys)]
    records.sort(key=lambda r: (r.get("round", 0), r["point"]))
    missing = missing_outputs(records, spec.outputs)
    if missing:
        ok = next(r for r in records if r["status"] == "ok")
        raise CrankmodalError(
            f"outputs: {missing[0]!r} is in no successful point's results.json"
            f"{suggestion(ok, out_dir, missing[0])}; fix outputs and re-run (finished points "
            "are kept and not recomputed)")
    axis_keys = [a.key for a in spec.axes]
    write_csv(out_dir / "sweep.csv", records, axis_keys, spec.outputs)
    fails = failures(records, max_failed, out_dir)
    by_status: dict = {}
    for r in records:
        by_status[r["status"]] = by_status.get(r["status"], 0) + 1
    summary = {
        "name": spec.name, "base": str(spec.base), "mode": spec.mode,
        "axes": [{"key": a.key, "values": list(a.values), "start": a.start, "stop": a.stop,
                  "log": a.log} for a in spec.axes],
        "set": spec.fixed, "outputs": spec.outputs, "timeout_s": spec.timeout_s,
        "n_points": len(records), "status_counts": by_status,
        "n_ok": by_status.get("ok", 0), "n_failed": len(records) - by_status.get("ok", 0),
        "ran": stats["ran"],
        "skipped": sum(k in before and done[k] is before[k] for k in dict.fromkeys(keys)),
        "failures": fails,
        "wall_time_s": time.perf_counter() - t0, "dask": info,
        "files": {"records": "records.jsonl", "table": "sweep.csv", "points": "points/"},
        "output_ranges": summarise(records, spec.outputs),
    }
    if spec.search:
        summary["search"] = _search_result(spec, records, rounds)
    if figures:
        from .figures import sweep_maps

        summary["files"]["figures"] = sweep_maps(
            records, axis_keys, spec.outputs, out_dir, {a.key for a in spec.axes if a.log},
            summary.get("search", {}).get("best_point"),
            spec.search["sense"] if spec.search else "max")
    write_json_atomic(out_dir / "sweep.json", summary)
    return summary


def _drop_mismatched(done: dict, tasks: list[dict], store: RecordStore, log=None) -> None:
    """Remove from ``done`` the records of these tasks' keys whose ``parameters`` are not the
    task's, with one warning line: a hand-edited file (a genuine record's key is the hash of its
    parameters). The search refines around a record's parameters, so they must be the point's;
    the points run again."""
    bad = list(dict.fromkeys(t["key"] for t in tasks if t["key"] in done
                             and done[t["key"]]["parameters"] != as_stored(t["parameters"])))
    for k in bad:
        del done[k]
    if bad:
        _warn(f"{store.path}: {len(bad)} record(s) whose parameters are not their point's "
              "skipped; their points run again", log)


def _warn(text: str, log=None) -> None:
    """A warning line through ``log`` (the CLI's stderr), else a :class:`UserWarning`."""
    if log:
        log(f"warning: {text}")
    else:
        import warnings

        warnings.warn(text, UserWarning, stacklevel=3)


def _add(total: dict, part: dict) -> None:
    for k in total:
        total[k] += part[k]


def _dashboard(client) -> str | None:
    try:
        import bokeh  # noqa: F401
    except ImportError:
        return None
    return getattr(client, "dashboard_link", None)


def _search(spec, client, tasks, store, done, out_dir, log, stats):
    """Refinement rounds of the search; returns the per-round summary and the new keys."""
    from .search import best, initial_steps, refine

    s = spec.search
    steps = initial_steps(spec.axes)
    current = [done[t["key"]] for t in tasks]
    keys, rounds = [], []
    n_next = len(tasks)
    top = best(current, s["objective"], s["sense"])
    rounds.append({"round": 0, "points": len(tasks), "best_point": top and top["point"],
                   "best_value": top and top["outputs"][s["objective"]]})
    if s["method"] != "grid" and top is not None:
        return _optimise(spec, client, store, done, out_dir, log, stats, top, rounds, n_next)
    for r in range(1, s["rounds"] + 1):
        if top is None:
            break
        pts, steps = refine(spec.axes, top["parameters"], steps, s["num"])
        new = plan_tasks(spec, pts, out_dir, n_next, r)
        n_next += len(new)
        _add(stats, run_tasks(client, new, store, done, log))
        keys += [t["key"] for t in new]
        current += [done[t["key"]] for t in new]
        top = best(current, s["objective"], s["sense"])
        rounds.append({"round": r, "points": len(new), "best_point": top and top["point"],
                       "best_value": top and top["outputs"][s["objective"]],
                       "step": dict(steps)})
        if log:
            log(f"search round {r}: best {s['objective']} = {rounds[-1]['best_value']!r} at "
                f"{top['parameters']}")
    return rounds, keys


def _optimise(spec, client, store, done, out_dir, log, stats, top, rounds, n_next):
    """The scipy search from the coarse best point: each evaluation is one point run on the
    cluster (one at a time: these optimisers are sequential)."""
    from .search import objective_value, optimise

    s = spec.search
    keys: list[str] = []
    count = {"n": n_next}

    def evaluate(point):
        task = plan_tasks(spec, [point], out_dir, count["n"], 1)[0]
        if task["key"] not in done:
            count["n"] += 1
        _add(stats, run_tasks(client, [task], store, done, None))
        keys.append(task["key"])
        return objective_value(done[task["key"]], s["objective"])

    calls = optimise(spec.axes, top["parameters"], evaluate, s["sense"], s["method"],
                     s["max_points"], s["xtol"])
    from .search import best

    top = best([done[k] for k in keys] + [top], s["objective"], s["sense"])
    rounds.append({"round": 1, "method": s["method"], "evaluations": calls,
                   "points": len(set(keys)), "best_point": top["point"],
                   "best_value": top["outputs"][s["objective"]]})
    if log:
        log(f"search ({s['method']}, {calls} evaluations): best {s['objective']} = "
            f"{top['outputs'][s['objective']]!r} at {top['parameters']}")
    return rounds, keys


def _search_result(spec, records, rounds) -> dict:
    from .search import best

    s = spec.search
    top = best(records, s["objective"], s["sense"])
    if top is None and all(r["status"] != "ok" for r in records):
        # every point failed: no best, and the failures line (exit 4) says where the errors are
        return {"objective": s["objective"], "sense": s["sense"], "best_point": None,
                "best_parameters": None, "best_value": None, "rounds": rounds}
    if top is None:
        raise CrankmodalError(f"search: no point produced a number for {s['objective']!r}")
    return {"objective": s["objective"], "sense": s["sense"], "best_point": top["point"],
            "best_parameters": top["parameters"], "best_value": top["outputs"][s["objective"]],
            "rounds": rounds}
