"""Merging vertices closer than a distance: a tolerance weld that is a distance query, not a grid.

Exporters that write each triangle's corners separately sometimes round the copies of one vertex
differently (float noise ~1e-7 of the part).  :func:`merge_close_vertices` finds every pair of vertices
closer than ``tolerance`` (exact distances; a C kernel on cells sorted by their Morton code when the extension
is built, else a grid and a k-d tree of scipy: the same pairs) and merges the connected groups of such pairs,
each onto its lowest-numbered vertex.  Unlike a rounding grid, two copies closer
than the tolerance are always merged (a grid splits them when they straddle a cell boundary).  A chain of
close pairs merges as a group, so a vertex can move farther than ``tolerance``; the largest move is
returned so the caller can state it.
"""

from __future__ import annotations

import numpy as np

from .._native import accel
from ..values import frozen_value

__all__ = ["Merge", "merge_close_vertices", "lowest_in_group"]


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
    representative : (n,) int or None
        The vertex each vertex was merged onto (itself when it did not move); None when nothing merged.  The
        certificate bounds what the moves changed from it (:func:`~.precision.weld_sweep`).
    """

    faces: np.ndarray
    merged_vertices: int
    largest_move: float
    representative: np.ndarray | None = None


def merge_close_vertices(vertices: np.ndarray, faces: np.ndarray, tolerance: float, *,
                         among: np.ndarray | None = None) -> Merge:
    """Merge the vertices that lie within ``tolerance`` of each other (transitively).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    tolerance : float
        Distance, in the units of ``vertices``; must be positive.
    among : (k,) int, optional
        Only these vertices may merge (default: every vertex a face uses).  The repair passes the vertices of
        unbalanced edges: merging two vertices whose edges are all balanced cannot balance anything.

    Returns
    -------
    Merge
    """
    if not tolerance > 0:
        raise ValueError(f"Expected a positive tolerance, got {tolerance}")
    v = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    if among is None:                           # only vertices that faces use can matter
        used = np.flatnonzero(np.bincount(faces.reshape(-1), minlength=len(v)))
    else:
        used = np.flatnonzero(np.bincount(np.asarray(among, dtype=np.int64).reshape(-1), minlength=len(v)))
    points = np.take(v, used, axis=0)         # (the rows v[used]: numpy's take gathers them ~3x faster)
    lowest = lowest_in_group(points, tolerance)
    if lowest is None:
        return Merge(faces=faces, merged_vertices=0, largest_move=0.0)
    representative = np.arange(len(v), dtype=np.int64)
    representative[used] = used[lowest]
    moved = np.flatnonzero(lowest != np.arange(len(used)))          # only vertices of `used` move
    return Merge(faces=representative[faces].astype(faces.dtype, copy=False), merged_vertices=len(moved),
                 largest_move=_largest_move(points, lowest, moved), representative=representative)


def _largest_move(points: np.ndarray, lowest: np.ndarray, moved: np.ndarray) -> float:
    """``max |points[i] − points[lowest[i]]|`` over ``moved``, as ``numpy.linalg.norm(·, axis=1)`` forms each
    distance (``sqrt((dx² + dy²) + dz²)``), bit for bit: one column per axis, and the root of the largest square
    (the correctly rounded root is monotone, so it is the largest root; issue 25, soup18: 0.3 → 0.1 s for a soup's
    3.2M moves).  A NaN anywhere gives NaN, as the maximum of the norms did."""
    columns = [np.ascontiguousarray(points[:, axis]) for axis in range(3)]
    largest = 0.0
    for start in range(0, len(moved), _MOVE_BLOCK):    # in blocks: a soup moves 3.2M points (300 MB at once)
        block = moved[start:start + _MOVE_BLOCK]
        onto = lowest[block]
        square = np.zeros(len(block))
        for column in columns:
            step = column[block] - column[onto]
            step *= step
            square += step
        largest = float(np.max((largest, np.sqrt(np.max(square)))))
    return largest


def lowest_in_group(points: np.ndarray, tolerance: float) -> np.ndarray | None:
    """For each point, the lowest index in its group (points within ``tolerance``, transitively), (k,) int, or None
    when no two points are that close.

    The C kernel (``_accel.close_groups``, section 9b: cells of side ``tolerance/2`` sorted by their Morton code,
    a union-find over the cells) when it is built and the grid fits its 21 bits per axis; else :func:`_groups`
    (numpy and scipy).  Both find the components of the same graph, ``|p − q|² <= tolerance²`` with the square
    summed as ``(dx² + dy²) + dz²``; the 1.3M-face soup (3.9M points) spent 2–3 s in :func:`_groups`.
    """
    k = len(points)
    if k < 2:
        return None
    lib = accel()
    if lib is not None and np.isfinite(points).all():
        got = lib.close_groups(np.ascontiguousarray(points, dtype=np.float64), float(tolerance))
        if got is not None:
            lowest = np.frombuffer(got, dtype=np.int64)
            if bool(np.all(lowest == np.arange(k))):
                return None
            return lowest
    group = _groups(points, tolerance)
    if group is None:
        return None
    first = np.full(group.max() + 1, k, dtype=np.int64)
    np.minimum.at(first, group, np.arange(k))
    found: np.ndarray = first[group]
    return found


#: Moved points whose distance to their representative is measured at a time (bounds the temporaries).
_MOVE_BLOCK = 1 << 18

#: Cells per axis up to which the grid of :func:`_groups` packs a cell into one 63-bit key.
_GRID_AXIS_LIMIT = 1 << 21

#: Point pairs checked per block when two neighbouring cells are compared.
_PAIR_BLOCK = 1 << 20


def _groups(points: np.ndarray, tolerance: float) -> np.ndarray | None:
    """Connected components of the graph "closer than ``tolerance``", (k,) int, or None when no pair is close.

    Points sharing a cell of side ``tolerance/√3`` are within ``tolerance`` of each other, so a cell is one
    group at once; only cells whose boxes come within ``tolerance`` of each other (a k-d tree over the cell
    centres with radius ``tolerance + cell diagonal``) have their points compared, pair by pair, exactly.  For a
    soup (every vertex copied per triangle, the copies a hair apart) this handles a few points per cell
    instead of every close pair.  Falls back to a k-d tree over the points when the grid would not fit 63-bit
    keys (a tolerance below 2⁻²¹ of the extent).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    k = len(points)
    if k < 2:
        return None
    side = tolerance / np.sqrt(3.0) * (1.0 - 1e-9)      # two points in one cell: |Δ| < side·√3 < tolerance
    lo = points.min(axis=0)
    cells = np.floor((points - lo) / side)
    if not float(cells.max()) < _GRID_AXIS_LIMIT:
        pairs = cKDTree(points, balanced_tree=False, compact_nodes=False).query_pairs(tolerance, output_type="ndarray")
        if not len(pairs):
            return None
        graph = coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
        labels: np.ndarray = connected_components(graph, directed=False)[1]
        return labels
    c = cells.astype(np.int64)
    key = (c[:, 0] << 42) | (c[:, 1] << 21) | c[:, 2]
    order = np.argsort(key, kind="stable")
    sk = key[order]
    new = np.r_[True, sk[1:] != sk[:-1]]
    cell_of = np.empty(k, dtype=np.int64)
    cell_of[order] = np.cumsum(new) - 1                  # cell index of each point, cells in key order
    starts = np.flatnonzero(new)
    n_cells = len(starts)
    counts = np.diff(np.r_[starts, k])
    corner = c[order[starts]]
    centre = (corner + 0.5) * side
    reach = tolerance + side * np.sqrt(3.0)              # two points' distance ≥ centres' distance − diagonal
    near = cKDTree(centre, balanced_tree=False, compact_nodes=False).query_pairs(reach, output_type="ndarray")
    links = [np.zeros((0, 2), dtype=np.int64)]
    if len(near):
        # every point of cell a against every point of cell b, in blocks of bounded size
        cum = np.cumsum(counts[near[:, 0]] * counts[near[:, 1]])
        begin = 0
        while begin < len(near):                         # each block advances by at least one cell pair
            done = int(cum[begin - 1]) if begin else 0
            end = max(begin + 1, int(np.searchsorted(cum, done + _PAIR_BLOCK, side="right")))
            block = near[begin:end]
            begin = end
            na, nb = counts[block[:, 0]], counts[block[:, 1]]
            m = na * nb
            pair = np.repeat(np.arange(len(block)), m)
            within = np.arange(int(m.sum())) - np.repeat(np.cumsum(m) - m, m)
            ia = order[starts[block[:, 0]][pair] + within // nb[pair]]
            ib = order[starts[block[:, 1]][pair] + within % nb[pair]]
            d = points[ia] - points[ib]
            close = np.einsum("ij,ij->i", d, d) <= tolerance * tolerance
            links.append(block[np.bincount(pair[close], minlength=len(block)) > 0])
    link = np.concatenate(links)
    if not len(link) and n_cells == k:
        return None
    graph = coo_matrix((np.ones(len(link), dtype=np.int8), (link[:, 0], link[:, 1])), shape=(n_cells, n_cells))
    _, cell_group = connected_components(graph, directed=False)
    group: np.ndarray = cell_group[cell_of]
    return group
