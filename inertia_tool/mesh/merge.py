"""Merging vertices closer than a distance: a tolerance weld that is a distance query, not a grid.

Exporters that write each triangle's corners separately sometimes round the copies of one vertex
differently (float noise ~1e-7 of the part).  :func:`merge_close_vertices` finds every pair of vertices
closer than ``tolerance`` with a k-d tree (scipy ``cKDTree.query_pairs``, exact distances) and merges the
connected groups of such pairs, each onto its lowest-numbered vertex.  Unlike a grid, two copies closer
than the tolerance are always merged (a grid splits them when they straddle a cell boundary).  A chain of
close pairs merges as a group, so a vertex can move farther than ``tolerance``; the largest move is
returned so the caller can state it.
"""

from __future__ import annotations

import numpy as np

from ..values import frozen_value

__all__ = ["Merge", "merge_close_vertices"]


@frozen_value
class Merge:
    """Result of :func:`merge_close_vertices`.

    Attributes
    ----------
    faces : (m, 3) int
        Faces re-indexed onto one representative per group (indices into the same vertex array).
    merged_vertices : int
        Vertices replaced by a representative.
    largest_move : float
        Largest distance between a vertex and its representative, in the units of the vertices.
    """

    faces: np.ndarray
    merged_vertices: int
    largest_move: float


def merge_close_vertices(vertices: np.ndarray, faces: np.ndarray, tolerance: float) -> Merge:
    """Merge the vertices that lie within ``tolerance`` of each other (transitively).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    tolerance : float
        Distance, in the units of ``vertices``; must be positive.

    Returns
    -------
    Merge
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    if not tolerance > 0:
        raise ValueError(f"Expected a positive tolerance, got {tolerance}")
    v = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    used = np.unique(faces)                     # only vertices that faces use can matter
    pairs = cKDTree(v[used]).query_pairs(tolerance, output_type="ndarray")
    if len(pairs) == 0:
        return Merge(faces=faces, merged_vertices=0, largest_move=0.0)
    k = len(used)
    graph = coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
    _, group = connected_components(graph, directed=False)
    first = np.full(group.max() + 1, k, dtype=np.int64)
    np.minimum.at(first, group, np.arange(k))
    representative = np.arange(len(v), dtype=np.int64)
    representative[used] = used[first[group]]
    moved = representative != np.arange(len(v))
    largest = float(np.max(np.linalg.norm(v[moved] - v[representative[moved]], axis=1))) if moved.any() else 0.0
    return Merge(faces=representative[faces].astype(faces.dtype), merged_vertices=int(np.count_nonzero(moved)),
                 largest_move=largest)
