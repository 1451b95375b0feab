"""Topology of tetrahedral meshes (meshio node order): boundary facets and their nodes.

One home for what the geometry importers, the FE loads and the test parts all need: the corner
triangles on a mesh's boundary, the mid-edge nodes of such triangles on a ``tetra10`` mesh, and
every node of a set of facets.
"""

from __future__ import annotations

import numpy as np

from .errors import GeometryError

#: The four corner faces of a tetrahedron, outward for a positively oriented element.
TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
#: tetra10 edges in meshio's (VTK) node order, nodes 4..9.
TET10_EDGES = np.array([[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]])


#: The corner of a tetrahedron opposite each face of :data:`TET_FACES`.
TET_FACE_OPPOSITE = np.array([3, 2, 1, 0])


def boundary_facets(cells: np.ndarray, opposite: bool = False):
    """Corner triangles (n, 3) on the boundary of a tetra/tetra10 mesh (faces used once).

    Each keeps the node order of its element's face: outward for positively oriented elements.
    With ``opposite``, also the element's fourth corner behind each triangle (n,), which orients
    the triangle whatever the element's orientation.
    """
    c = np.asarray(cells)[:, :4]
    faces = c[:, TET_FACES].transpose(1, 0, 2).reshape(-1, 3)
    _, first, counts = np.unique(np.sort(faces, axis=1), axis=0, return_index=True,
                                 return_counts=True)
    sel = first[counts == 1]
    if opposite:
        return faces[sel], c[:, TET_FACE_OPPOSITE].T.ravel()[sel]
    return faces[sel]


def facet_midnodes(facets: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Mid-side nodes of corner triangles of a ``tetra10`` mesh, shape (n_facets, 3).

    Column k is the node on edge (k, k+1 mod 3) of each triangle. Raises GeometryError if an
    edge is not an element edge.
    """
    n = int(cells.max()) + 1
    e = np.sort(cells[:, TET10_EDGES], axis=2).reshape(-1, 2)
    keys = e[:, 0].astype(np.int64) * n + e[:, 1]
    mids = cells[:, 4:].ravel()
    order = np.argsort(keys, kind="stable")
    keys, mids = keys[order], mids[order]
    fe = np.sort(facets[:, [[0, 1], [1, 2], [2, 0]]], axis=2).reshape(-1, 2)
    fk = fe[:, 0].astype(np.int64) * n + fe[:, 1]
    pos = np.minimum(np.searchsorted(keys, fk), len(keys) - 1)
    if not np.array_equal(keys[pos], fk):
        raise GeometryError("region facets are not faces of the mesh's tetra10 elements")
    return mids[pos].reshape(-1, 3)


def facet_nodes(facets: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """All nodes (corners and, for tetra10, mid-edge nodes) of corner triangles, ascending."""
    nodes = [np.asarray(facets).ravel()]
    if cells.shape[1] == 10 and len(facets):
        nodes.append(facet_midnodes(facets, cells).ravel())
    return np.unique(np.concatenate(nodes)).astype(np.int64)
