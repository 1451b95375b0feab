"""Meshing time and counts of the seed 000 crankshaft (four-star compressor), by hand:

    .venv/bin/python benchmarks/geometry_bench.py [--repeat 3] [--fidelity full] [--order 2]
    .venv/bin/python benchmarks/geometry_bench.py --render docs/img   # README pictures

For each target size the part is built from scratch (geometry, regions, mesh, P2, mass check;
no cache) ``--repeat`` times; the median wall time is printed with element, node and P2 DOF
counts (3 per node) and the minimum quality.
"""

from __future__ import annotations

import argparse
import statistics
import time

from crankmodal.geometry import MeshSettings, build_part, params_from_dict
from crankmodal.resources import load_machine


def render(folder: str, size: float = 0.006) -> None:
    """Off-screen PNG of each fidelity of the seed 000 crank, journals and pin rows coloured."""
    from pathlib import Path

    import numpy as np
    import pyvista as pv

    from crankmodal.geometry.importers import boundary_facets

    pv.OFF_SCREEN = True
    params = params_from_dict("crankshaft", load_machine("four_star_compressor")["crankshaft"])
    Path(folder).mkdir(parents=True, exist_ok=True)
    for fidelity in ("full", "dechamfered", "simplified"):
        part = build_part(params, fidelity, MeshSettings(size, 1))
        faces = boundary_facets(part.mesh.cells[0].data)
        row = {tuple(sorted(f)): i for i, f in enumerate(faces)}
        colour = np.zeros(len(faces))
        for name, region in part.regions.items():
            value = 1.0 if name.startswith("main_journal") else 2.0 if name.endswith("row_1") else 3.0
            if name.startswith(("main_journal", "crankpin")):
                for f in region.facets:
                    colour[row[tuple(sorted(f))]] = value
        surf = pv.PolyData(part.mesh.points, np.column_stack([np.full(len(faces), 3), faces]).ravel())
        surf.cell_data["region"] = colour
        pl = pv.Plotter(off_screen=True, window_size=(1000, 700))
        pl.add_mesh(surf, scalars="region", cmap=["lightsteelblue", "seagreen", "orange", "gold"], clim=[0, 3],
                    show_edges=True, edge_color="dimgray", line_width=0.2, show_scalar_bar=False)
        pl.view_vector((1.0, -1.2, 0.5), viewup=(0, 0, 1))
        pl.reset_camera()
        pl.add_text(f"seed 000 crankshaft, {fidelity}: {part.n_elements} P1 tetrahedra at {size * 1e3:g} mm\n"
                    "green: main journals; orange / gold: crankpin rows 1 / 2", font_size=10)
        pl.screenshot(str(Path(folder) / f"crankshaft_{fidelity}.png"))
        pl.close()
        print(f"{fidelity}: {part.n_elements} elements -> {folder}/crankshaft_{fidelity}.png")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--fidelity", default="full")
    ap.add_argument("--order", type=int, default=2)
    ap.add_argument("--sizes", type=float, nargs="+", default=[0.012, 0.009, 0.0070])
    ap.add_argument("--render", metavar="FOLDER", help="write PNG pictures of the three fidelities instead")
    args = ap.parse_args()
    if args.render:
        render(args.render)
        return
    params = params_from_dict("crankshaft", load_machine("four_star_compressor")["crankshaft"])
    print(f"seed 000 crankshaft, fidelity {args.fidelity}, P{args.order}, median of {args.repeat}")
    print(f"{'size_mm':>8} {'elements':>9} {'nodes':>8} {'dofs':>8} {'min_sicn':>8} {'time_s':>7}")
    for h in args.sizes:
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            part = build_part(params, args.fidelity, MeshSettings(h, args.order))
            times.append(time.perf_counter() - t0)
        print(f"{h * 1e3:8.1f} {part.n_elements:9d} {part.n_nodes:8d} {3 * part.n_nodes:8d} "
              f"{part.quality['min']:8.3f} {statistics.median(times):7.2f}")


if __name__ == "__main__":
    main()
