"""Command line: ``crankmodal run | check | demo | study | sweep | machines``.

User errors (:class:`~crankmodal.errors.CrankmodalError`) print one line on stderr and exit with
status 2 (3 for a failed numerical check), without a traceback unless ``--debug`` is given; so do
output files that cannot be written (:class:`~crankmodal.errors.OutputError`).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

from . import __version__
from .errors import CrankmodalError

DEMO_SCENE = "four_star_compressor"


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's usage errors: one line, exit 2
        raise CrankmodalError(f"usage: {message} (see crankmodal --help)")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="crankmodal", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"crankmodal {__version__}")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    # --debug is also accepted after the command; SUPPRESS keeps a subcommand that was not given
    # it from overwriting the top-level value.
    debug = argparse.ArgumentParser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help="show tracebacks of errors")
    debug.add_argument("--quiet", action="store_true", default=argparse.SUPPRESS,
                       help="no progress bars")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def scene_args(sp, scene_required=True):
        if scene_required:
            sp.add_argument("scene", help="scene TOML file")
        sp.add_argument(
            "--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
            help="override a scene value (TOML syntax; repeatable)",
        )

    r = sub.add_parser("run", parents=[debug],
                       help="run a scene, write DIR/results.json and figures")
    scene_args(r)
    r.add_argument("--out", type=Path, help="output folder (default out/<scene name>)")
    r.add_argument("--no-figures", action="store_true", help="skip PNG plots")

    c = sub.add_parser("check", parents=[debug], help="validate a scene without running it")
    scene_args(c)

    d = sub.add_parser("demo", parents=[debug],
                       help="run the main job: the four-star compressor study")
    scene_args(d, scene_required=False)
    d.add_argument("--out", type=Path, help="output folder (default out/four_star_compressor)")
    d.add_argument("--no-figures", action="store_true", help="skip PNG plots")

    st = sub.add_parser("study", parents=[debug], help="run a study of a scene's part (see README)")
    st.add_argument("kind", choices=("simplification",),
                    help="simplification: fidelities x mesh sizes x element orders")
    scene_args(st)
    st.add_argument("--out", type=Path, help="output folder (default out/<scene name>_study)")
    st.add_argument("--no-figures", action="store_true", help="skip PNG plots")
    st.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                    help="solve the models on this Dask scheduler instead of a local cluster")
    st.add_argument("--workers", type=int, metavar="N",
                    help="worker processes of the local cluster (default: the CPU count)")

    sw = sub.add_parser("sweep", parents=[debug],
                        help="run a parameter sweep or search of a scene on Dask (see README)")
    sw.add_argument("sweep", type=Path, help="sweep TOML file (base scene, axes, outputs)")
    sw.add_argument("--out", type=Path, help="sweep folder (default out/<sweep file stem>_sweep)")
    sw.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                    help="run on this Dask scheduler instead of a local cluster")
    sw.add_argument("--workers", type=int, metavar="N",
                    help="worker processes of the local cluster (default: the CPU count)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="run again the recorded points that failed")
    sw.add_argument("--no-figures", action="store_true", help="skip the sweep_<output>.png maps")
    sw.add_argument("--max-failed", type=float, metavar="SHARE",
                    help="share of failed points (0-1) above which the sweep exits with status 4 "
                         "(default: the sweep file's max_failed, else 0.1)")
    sw.add_argument("--dry-run", action="store_true",
                    help="check every point and count those recorded and to run; run nothing")

    sub.add_parser("machines", parents=[debug], help="list the machine parameter files")
    return p


def _summary(results: dict) -> str:
    """A few lines a person reads after a run: per stage, its headline numbers."""
    lines = [f"crankmodal {results['crankmodal_version']}  scene {results['scene']}"]
    for section, res in results.items():
        if not isinstance(res, dict):
            continue
        head = res.get("summary")
        t = res.get("wall_time_s", 0.0)
        lines.append(f"  [{section}] {t:.2f} s" + (f"  {head}" if head else ""))
    return "\n".join(lines)


def _run(scene_file: Path, overrides, out: Path | None, figures: bool) -> int:
    from .runner import run
    from .scene import load_scene

    scene = load_scene(scene_file, overrides)
    out_dir = out if out is not None else _default_out("run", scene.name)
    results = run(scene, out_dir, figures=figures, log=lambda s: print(s, file=sys.stderr))
    print(_summary(results))
    print(f"results: {out_dir / 'results.json'}")
    return 0


def _sweep(args) -> int:
    from .sweep import run_sweep

    if args.workers is not None and args.workers < 1:
        raise CrankmodalError(f"--workers: must be >= 1, got {args.workers}")
    out_dir = args.out if args.out is not None else Path("out") / (args.sweep.stem + "_sweep")
    if args.max_failed is not None:
        from .sweep.spec import check_max_failed

        check_max_failed("--max-failed", args.max_failed)
    if args.dry_run:
        from .sweep.driver import plan_sweep

        plan = plan_sweep(args.sweep, out_dir)
        print(f"sweep {plan['name']}: {plan['n_points']} points checked, {plan['recorded']} "
              f"recorded in {out_dir}, {plan['to_run']} to run"
              + (" (and the search's rounds)" if plan["search"] else "")
              + (f"; {plan['bad_record_lines']} bad record line(s) would be skipped"
                 if plan["bad_record_lines"] else "") + "; nothing run (--dry-run)")
        return 0
    from .sweep.driver import FAILED_EXIT, SweepInterrupted

    try:
        res = run_sweep(args.sweep, out_dir, scheduler=args.scheduler, workers=args.workers,
                        retry_failed=args.retry_failed, figures=not args.no_figures,
                        max_failed=args.max_failed, log=lambda m: print(m, file=sys.stderr))
    except SweepInterrupted as exc:
        how = "terminated" if isinstance(exc.original, _Terminated) else "interrupted"
        print(f"crankmodal: {how}: {exc.recorded} of {exc.total} points recorded; resume with: "
              f"crankmodal sweep {args.sweep} --out {out_dir}", file=sys.stderr)
        return 143 if how == "terminated" else 130
    print(f"sweep {res['name']}: {res['n_points']} points, {res['n_ok']} ok, "
          f"{res['n_failed']} failed ({res['ran']} run now, {res['skipped']} already recorded) "
          f"in {res['wall_time_s']:.1f} s")
    if "search" in res:
        s = res["search"]
        print(f"search: {s['sense']} {s['objective']} = {s['best_value']!r} at "
              f"{s['best_parameters']} (point {s['best_point']})" if s["best_point"] is not None
              else f"search: no best {s['objective']}: every point failed")
    print(f"sweep: {out_dir / 'sweep.json'}")
    print(res["failures"]["line"], file=sys.stderr if res["failures"]["exceeded"] else sys.stdout)
    return FAILED_EXIT if res["failures"]["exceeded"] else 0


#: command -> (the summary file it writes, suffix of its default folder ``out/<scene name>``)
SUMMARY_FILES = {"run": ("results.json", ""), "demo": ("results.json", ""),
                 "study": ("study.json", "_study")}


def _default_out(command: str, name: str) -> Path:
    """The output folder of ``command`` when no ``--out`` is given: ``out/<scene name><suffix>``."""
    return Path("out") / (name + SUMMARY_FILES[command][1])


def _remove_stale_summary(args) -> None:
    """After a failed ``run``/``demo``/``study``, delete the summary file (``results.json``,
    ``study.json``) that an earlier run left in the output folder, so that no old result looks
    like the answer to this run. Nothing else is deleted, and no folder is created."""
    if args.command not in SUMMARY_FILES:
        return
    filename = SUMMARY_FILES[args.command][0]
    out_dir = args.out
    if out_dir is None:
        from .resources import load_toml, scene_path

        demo = args.command == "demo"
        stem = DEMO_SCENE if demo else Path(args.scene).stem
        try:
            name = load_toml(scene_path(DEMO_SCENE) if demo else args.scene).get("name")
        except CrankmodalError:
            # A missing or unparsable file: its stem, the name of a scene without a `name`
            # key, is the best guess.
            name = None
        out_dir = _default_out(args.command, name if isinstance(name, str) else stem)
    try:
        (Path(out_dir) / filename).unlink(missing_ok=True)
    except OSError:  # e.g. DIR is a file: there is no stale summary to remove
        pass


def _show_model_warnings():
    """Print crankmodal's own model warnings as one plain line each (``crankmodal: warning:``);
    other warnings keep Python's format, which names their source."""
    import warnings

    python_format = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if category.__name__ == "ModelWarning":
            print(f"crankmodal: warning: {message}", file=sys.stderr)
        else:
            python_format(message, category, filename, lineno, file, line)

    warnings.showwarning = show


class _Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, a batch system's time limit), raised where Python runs, so that the
    output being written is cleaned up as for Ctrl-C instead of the process just ending."""


def _on_sigterm(signum, frame):
    raise _Terminated()


@contextlib.contextmanager
def _sigterm_interrupts():
    """Turn SIGTERM into :class:`_Terminated` inside the block (main thread only: elsewhere a
    handler cannot be set, e.g. ``main`` called from a worker thread)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``crankmodal`` console script; returns the exit status."""
    with _sigterm_interrupts():
        return _main(argv)


def _main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    debug = "--debug" in argv  # until the arguments have parsed
    args = None
    _show_model_warnings()
    try:
        args = _parser().parse_args(argv)
        debug = args.debug
        if args.quiet:
            from .progress import set_quiet

            set_quiet()
        if args.command == "run":
            return _run(args.scene, args.overrides, args.out, not args.no_figures)
        if args.command == "demo":
            from .resources import scene_path

            return _run(scene_path(DEMO_SCENE), args.overrides, args.out, not args.no_figures)
        if args.command == "check":
            from .runner import check
            from .scene import load_scene

            scene = load_scene(args.scene, args.overrides)
            sections = check(scene)
            print(f"{args.scene}: ok ({', '.join(sections)})")
            return 0
        if args.command == "study":
            from .report.study_scene import simplification_study
            from .scene import load_scene

            scene = load_scene(args.scene, args.overrides)
            out_dir = args.out if args.out is not None else _default_out("study", scene.name)
            res = simplification_study(scene, out_dir, figures=not args.no_figures,
                                       log=lambda m: print(m, file=sys.stderr),
                                       scheduler=args.scheduler, workers=args.workers)
            print(res["summary"])
            print(f"study: {out_dir}")
            return 0
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "machines":
            from .resources import list_machines

            print("\n".join(list_machines()))
            return 0
    except (CrankmodalError, OSError) as exc:
        if args is not None:
            _remove_stale_summary(args)
        if debug:
            raise
        if isinstance(exc, OSError):  # an I/O failure no stage turned into an OutputError
            from .results import output_error

            exc = output_error(exc)
        print(f"crankmodal: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:
        # every output file is written atomically: an interrupted writer leaves no partial file
        # (results.json of this run was removed when it started)
        if isinstance(exc, _Terminated):
            print("crankmodal: terminated", file=sys.stderr)
            return 143  # 128 + SIGTERM, as a shell reports a process it ended
        print("crankmodal: interrupted", file=sys.stderr)
        return 130
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
