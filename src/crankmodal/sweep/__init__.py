"""Parameter sweeps and searches over scenes, run on Dask (``crankmodal sweep``).

A sweep file names a base scene, axes of ``--set`` keys, and the results.json paths to collect;
every point is one scene run in its own folder. Modules, one concept each:

``spec``      reading and checking a SWEEP.toml;
``axes``      axis values and point generation (grid, zip, random, latin hypercube);
``execute``   one point: the scene run, in-process in a Dask worker, turned into a record;
``store``     the records, one JSON line per finished point (resumption);
``table``     output paths in results.json and the collected CSV table;
``driver``    the Dask cluster or client and the loop over points;
``search``    coarse grid then refinement around the best point.

Dask is imported only by ``driver`` (inside :func:`run_sweep`), so ``crankmodal run`` never
loads it.
"""

from .driver import run_sweep
from .spec import SweepSpec, load_sweep, parse_sweep

__all__ = ["SweepSpec", "load_sweep", "parse_sweep", "run_sweep"]
