"""A gmsh session that is always closed, prints nothing, and turns failures into GeometryError."""

from __future__ import annotations

import contextlib
import itertools
import os
import sys

from ..errors import CrankmodalError, GeometryError

_counter = itertools.count()


@contextlib.contextmanager
def gmsh_session(what: str, params: dict | None = None, threads: int = 1):
    """Run a block with a fresh gmsh model.

    gmsh is initialised (and finalised afterwards) unless a caller already holds it, in which
    case a new model is added and removed, leaving the caller's models alone. Any exception
    raised by gmsh inside the block becomes a :class:`GeometryError` naming ``what`` and the
    parameters.

    Parameters
    ----------
    what : str
        The part being made, for messages.
    params : dict, optional
        Parameters quoted in a failure message.
    threads : int
        gmsh threads; 1 keeps meshes reproducible.
    """
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(interruptible=False)
    previous = None if owner else gmsh.model.getCurrent()
    name = f"crankmodal_{next(_counter)}"
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("General.NumThreads", threads)
        gmsh.model.add(name)
        try:
            yield gmsh
        except CrankmodalError:
            raise
        except Exception as exc:  # noqa: BLE001 - gmsh raises plain Exception with its last error
            text = str(exc).strip().splitlines()[-1] if str(exc).strip() else type(exc).__name__
            raise GeometryError(
                f"{what}: the geometry kernel failed ({text}); parameters: {params or {}}"
            ) from None
    finally:
        if owner:
            gmsh.finalize()
        else:
            with contextlib.suppress(Exception):
                gmsh.model.setCurrent(name)
                gmsh.model.remove()
            if previous:
                with contextlib.suppress(Exception):
                    gmsh.model.setCurrent(previous)


@contextlib.contextmanager
def quiet_stdout():
    """Silence C-level writes to stdout (OpenCASCADE's STEP translator prints to fd 1)."""
    sys.stdout.flush()
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # captured streams without a descriptor
        fd = 1
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
            yield
    finally:
        _flush_c_stdio()
        os.dup2(saved, fd)
        os.close(saved)


def _flush_c_stdio() -> None:
    import ctypes

    with contextlib.suppress(Exception):
        ctypes.CDLL(None).fflush(None)
