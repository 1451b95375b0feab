"""One call from an assembled model to a :class:`~crankmodal.reduction.flexbody.FlexibleBody`.

interfaces → Craig–Bampton basis → orthonormalisation → invariants (→ mesh, mode shapes and
stress modes, when the mesh is given).
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import ParameterError
from .craig_bampton import craig_bampton
from .flexbody import FlexibleBody, flexible_body
from .interfaces import Interface, interface_rigid_fields
from .orthonormal import orthonormalise


def reduce_body(model, interfaces: list[Interface], fixed_interface_modes: int | None = None,
                cutoff_hz: float | None = None, backend: str = "auto", mesh=None,
                stress_dtype=np.float32, name: str = "body",
                info: dict | None = None, stress: bool = True,
                shape_dtype=np.float32, *, n_modes: int | None = None
                ) -> tuple[FlexibleBody, object]:
    """Reduce an FE model to a flexible body.

    Parameters
    ----------
    model : crankmodal.fem.assembly.FEModel
    interfaces : list of Interface
    fixed_interface_modes, cutoff_hz : int or float
        Fixed-interface (Craig-Bampton) modes: a number, or all up to a frequency (Hz).
        Exactly one.
    backend : str
        ``auto``, ``pardiso`` or ``superlu``.
    mesh : meshio.Mesh, optional
        The part's mesh; when given, the body carries the mesh and the shapes of every
        orthonormal mode on its nodes (``body.mode_shapes``), and (with ``stress``) their
        stress modes.
    stress_dtype : numpy dtype
        Storage type of the stress modes.
    name : str
    info : dict, optional
        Provenance stored with the body.
    stress : bool
        Compute the stress modes when the mesh is given.
    shape_dtype : numpy dtype
        Storage type of the mode shapes.
    n_modes : int, optional
        Deprecated name of ``fixed_interface_modes`` (a DeprecationWarning).

    Returns
    -------
    body : FlexibleBody
        ``body.info["timings_s"]`` holds the wall time per phase.
    cb : CraigBamptonBasis
        With the full-size basis ``cb.V`` (for checks and visualisation).
    """
    if n_modes is not None:
        import warnings

        if fixed_interface_modes is not None:
            raise ParameterError("n_modes", "is the deprecated name of fixed_interface_modes; "
                                 "give one of them")
        warnings.warn("reduce_body(n_modes=...) is deprecated: use fixed_interface_modes=",
                      DeprecationWarning, stacklevel=2)
        fixed_interface_modes = n_modes
    try:
        cb = craig_bampton(model, interfaces, n_modes=fixed_interface_modes,
                           cutoff_hz=cutoff_hz, backend=backend)
    except ParameterError as exc:  # this function's name for craig_bampton's n_modes
        if exc.argument != "n_modes":
            raise
        raise ParameterError("fixed_interface_modes", exc.text) from None
    from ..progress import PhaseTimings

    if hasattr(cb.timings, "close"):
        cb.timings.close()
    timings = PhaseTimings("reduction: body", 3 if mesh is not None and stress else 2, cb.timings)
    t0 = time.perf_counter()
    Ra = np.vstack([interface_rigid_fields(interfaces), np.zeros((cb.n_fixed_modes, 6))])
    ortho = orthonormalise(cb.K, cb.M, Ra)
    timings["orthonormalise_s"] = time.perf_counter() - t0
    smodes = None
    if mesh is not None and stress:
        from .stress_modes import stress_modes, stress_recovery

        t0 = time.perf_counter()
        rec = stress_recovery(model, mesh)
        smodes = stress_modes(rec, cb.V @ ortho.W, dtype=stress_dtype)
        timings["stress_modes_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    body = flexible_body(model, cb, ortho, name=name, stress_modes=smodes,
                         info={**(info or {}), "backend": cb.backend,
                               "eigen_residual": cb.residual,
                               "rigid_defect": ortho.rigid_defect},
                         mode_shapes=mesh is not None, shape_dtype=shape_dtype)
    timings["invariants_s"] = time.perf_counter() - t0
    timings.close()
    body.info["timings_s"] = dict(timings)
    return body, cb
