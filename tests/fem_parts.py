"""Test parts for the FE tests: structured bars/tubes (no gmsh) and a gmsh P2 cylinder."""

import numpy as np

from crankmodal.fem import testparts
from crankmodal.part import CylindricalSurface, Part

bar = testparts.bar
tube = testparts.tube


def gmsh_rod(length=0.6, radius=0.02, size=0.012, order=2, tmp_path=None) -> Part:
    """A solid circular rod along x meshed by gmsh (OCC), read back through a .msh file.

    Goes through meshio so the tetra10 node order is gmsh's → meshio's (VTK), the path a
    real part takes. Regions ``end_x0``/``end_x1`` (flat ends) and ``surface`` (the cylinder).
    """
    import gmsh
    import meshio

    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("rod")
        gmsh.model.occ.addCylinder(0, 0, 0, length, 0, 0, radius)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", size)
        gmsh.option.setNumber("Mesh.ElementOrder", order)
        gmsh.option.setNumber("Mesh.HighOrderOptimize", 0)
        gmsh.model.addPhysicalGroup(3, [1], name="solid")
        gmsh.model.mesh.generate(3)
        path = str(tmp_path / "rod.msh")
        gmsh.write(path)
    finally:
        gmsh.finalize()
    m = meshio.read(path)
    kind = "tetra10" if order == 2 else "tetra"
    cells = np.vstack([c.data for c in m.cells if c.type == kind])
    used = np.unique(cells)
    remap = -np.ones(len(m.points), np.int64)
    remap[used] = np.arange(len(used))
    mesh = meshio.Mesh(m.points[used], [(kind, remap[cells])])
    pts, cells = mesh.points, mesh.cells[0].data
    fac = testparts.boundary_facets(cells)
    tol = 1e-6 * length
    regions = {
        "end_x0": testparts.region("end_x0", pts, cells, fac, lambda c: c[:, 0] < tol),
        "end_x1": testparts.region("end_x1", pts, cells, fac, lambda c: c[:, 0] > length - tol),
        "surface": testparts.region(
            "surface", pts, cells, fac, lambda c: (c[:, 0] > tol) & (c[:, 0] < length - tol),
            cylinder=CylindricalSurface(np.array([length / 2, 0, 0]), np.array([1.0, 0, 0]), radius, length)),
    }
    return Part(name="rod", mesh=mesh, regions=regions, fidelity="full")
