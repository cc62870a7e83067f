"""Seal the seams an export split: cracks and T-junctions, with a bound on what sealing may have changed.

A surface whose boundary edges come in near pairs (a crack: the two lips of a seam a hair apart) or end on
the middle of another boundary edge (a T-junction: a fine side meeting a coarse one) is geometrically
closed, or nearly: only the bookkeeping of its vertices is broken.  :func:`seal_seams` repairs that
bookkeeping within a stated gap ``g`` and nothing else, in bounded rounds of two steps:

1. *Weld the lips*: boundary vertices within ``g`` of another boundary vertex are merged (a k-d tree,
   exact distances), each cluster into its lowest-numbered vertex; faces that collapse are dropped.
2. *Split at T-junctions*: a boundary vertex ``m`` within ``g`` of the interior of a boundary edge
   ``a→b`` (and farther than ``g`` from both ends) splits the face holding ``a→b`` into a fan through the
   points on that edge, in order along it.

The stated assumption: **the true surface is the sealed surface with each corner of a face that sealing
touched moved by at most that face's slack** ``d`` (the distance a welded corner travelled, or the distance
of a T-vertex from the edge it was put on).  A point of a triangle whose corners move by at most ``d`` moves
by at most ``d`` (it is a convex combination of them), so the solid can change only inside the parallel body
of radius ``d`` around the touched faces, whose volume for a triangle of area ``A`` and perimeter ``P`` is
Steiner's ``2Ad + (π/2)Pd² + (4/3)πd³`` (a dropped, collapsed face counts as a segment, ``A = 0``).  The
sum over touched faces is the volume in doubt.  When nothing moved (a T-vertex exactly on its edge, lips
bit-identical) every slack is zero and the sealed surface is exact.
"""

from __future__ import annotations

import numpy as np

from ..values import frozen_value
from .edges import edge_keys

__all__ = ["Seal", "seal_seams", "parallel_body_volume"]

#: Rounds of (weld, split): a T-vertex revealed by a weld, or a weld revealed by a split, is found next round.
MAX_SEAL_ROUNDS = 4


@frozen_value
class Seal:
    """A surface with its seams sealed, and what that may have changed.

    Attributes
    ----------
    faces : (m, 3) int
        The sealed faces (indices into the unchanged vertex array).
    slack : (m,) float
        m: how far each face may lie from the true surface (0 for faces sealing did not touch).
    dropped_doubt : float
        m³: the parallel bodies of faces that collapsed in a weld and were dropped.
    welded : int
        Boundary vertices merged into another.
    split : int
        T-junction vertices inserted into an edge.
    """

    faces: np.ndarray
    slack: np.ndarray
    dropped_doubt: float
    welded: int
    split: int

    def doubt(self, vertices: np.ndarray) -> float:
        """Volume (m³) within which the sealed solid may differ from the true one (module docstring)."""
        touched = self.slack > 0
        return self.dropped_doubt + float(np.sum(parallel_body_volume(vertices, self.faces[touched],
                                                                      self.slack[touched])))


def parallel_body_volume(vertices: np.ndarray, faces: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Volume of the set of points within ``radius`` of each triangle, (k,) m³.

    Steiner's formula for a flat convex set: ``2·A·d + (π/2)·P·d² + (4/3)·π·d³`` with area ``A`` and
    perimeter ``P`` (a degenerate triangle gives the capsule around its longest segment, over-counted by its
    doubled perimeter, which keeps the bound a bound).
    """
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    perimeter = (np.linalg.norm(b - a, axis=1) + np.linalg.norm(c - b, axis=1) + np.linalg.norm(a - c, axis=1))
    d = np.asarray(radius, dtype=np.float64)
    volume: np.ndarray = 2.0 * area * d + 0.5 * np.pi * perimeter * d ** 2 + 4.0 / 3.0 * np.pi * d ** 3
    return volume


def _boundary_vertices(faces: np.ndarray, n: int) -> np.ndarray:
    from .estimate import boundary_edges

    edges = boundary_edges(faces, n)
    return np.unique(edges) if len(edges) else np.zeros(0, dtype=np.int64)


def _weld_lips(v: np.ndarray, f: np.ndarray, slack: np.ndarray, vertex_slack: np.ndarray,
               gap: float) -> tuple[np.ndarray, np.ndarray, float, int]:
    """Step 1: merge boundary vertices within ``gap``; returns faces, face slack, dropped doubt, merged count."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    bv = _boundary_vertices(f, len(v))
    if len(bv) < 2:
        return f, slack, 0.0, 0
    pairs = cKDTree(v[bv]).query_pairs(gap, output_type="ndarray")
    if not len(pairs):
        return f, slack, 0.0, 0
    k = len(bv)
    graph = coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
    _, label = connected_components(graph, directed=False)
    rep_local = np.full(label.max() + 1, k, dtype=np.int64)
    np.minimum.at(rep_local, label, np.arange(k))           # lowest local index = lowest vertex (bv is sorted)
    rep = bv[rep_local[label]]
    move = np.linalg.norm(v[bv] - v[rep], axis=1) + vertex_slack[bv]
    np.maximum.at(vertex_slack, rep, move)
    remap = np.arange(len(v))
    remap[bv] = rep
    merged = int(np.count_nonzero(rep != bv))
    g = remap[f]
    collapsed = (g[:, 0] == g[:, 1]) | (g[:, 1] == g[:, 2]) | (g[:, 2] == g[:, 0])
    d = np.maximum(slack, vertex_slack[g].max(axis=1))
    dropped = float(np.sum(parallel_body_volume(v, f[collapsed], d[collapsed]))) if collapsed.any() else 0.0
    return g[~collapsed], d[~collapsed], dropped, merged


def _split_t_junctions(v: np.ndarray, f: np.ndarray, slack: np.ndarray,
                       gap: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Step 2: split faces at boundary vertices lying on the interior of a boundary edge; returns faces,
    slack and the number of vertices inserted."""
    from scipy.spatial import cKDTree
    from .estimate import boundary_edges

    edges = boundary_edges(f, len(v))
    if not len(edges):
        return f, slack, 0
    edges = np.unique(edges, axis=0)
    bv = np.unique(edges)
    a, b = v[edges[:, 0]], v[edges[:, 1]]
    ab = b - a
    length = np.linalg.norm(ab, axis=1)
    near = cKDTree(v[bv]).query_ball_point(0.5 * (a + b), 0.5 * length + gap)
    counts = np.fromiter((len(x) for x in near), dtype=np.int64, count=len(near))
    if not counts.sum():
        return f, slack, 0
    e = np.repeat(np.arange(len(edges)), counts)
    m = bv[np.concatenate([np.asarray(x, dtype=np.int64) for x in near if len(x)])]
    keep = (m != edges[e, 0]) & (m != edges[e, 1])
    e, m = e[keep], m[keep]
    t = np.einsum("ij,ij->i", v[m] - a[e], ab[e]) / np.maximum(length[e] ** 2, np.finfo(float).tiny)
    foot = a[e] + t[:, None] * ab[e]
    dist = np.linalg.norm(v[m] - foot, axis=1)
    ok = ((dist <= gap) & (t > 0) & (t < 1) & (np.linalg.norm(v[m] - a[e], axis=1) > gap)
          & (np.linalg.norm(v[m] - b[e], axis=1) > gap))
    e, m, t, dist = e[ok], m[ok], t[ok], dist[ok]
    if not len(e):
        return f, slack, 0
    # the face holding each directed edge a→b, and which of its edges it is
    undirected, forward = edge_keys(f, len(v))            # edge slot j of face i: f[i, j] → f[i, j+1]
    key = 2 * undirected + forward
    order = np.argsort(key, kind="stable")
    start, end = edges[e, 0].astype(np.int64), edges[e, 1].astype(np.int64)
    want = 2 * edge_keys(np.stack([start, end, end], axis=1), len(v))[0][0::3] + (start > end)
    pos = np.searchsorted(key[order], want)
    found = (pos < len(key)) & (key[order][np.minimum(pos, len(key) - 1)] == want)
    e, m, t, dist, pos = e[found], m[found], t[found], dist[found], pos[found]
    slot = order[pos]
    face, corner = slot // 3, slot % 3
    # one edge per face per round: keep the points of the first edge listed for each face
    first_slot = np.full(len(f), -1, dtype=np.int64)
    np.maximum.at(first_slot, face, slot)
    sel = slot == first_slot[face]
    face, corner, m, t, dist = face[sel], corner[sel], m[sel], t[sel], dist[sel]
    _, unique_m = np.unique(np.stack([face, m], axis=1), axis=0, return_index=True)
    face, corner, m, t, dist = face[unique_m], corner[unique_m], m[unique_m], t[unique_m], dist[unique_m]
    by = np.lexsort((t, face))
    face, corner, m, dist = face[by], corner[by], m[by], dist[by]
    split_faces = np.unique(face)
    new_faces: list[np.ndarray] = []
    new_slack: list[np.ndarray] = []
    starts = np.searchsorted(face, split_faces)
    ends = np.r_[starts[1:], len(face)]
    for s, stop in zip(starts.tolist(), ends.tolist()):    # one short fan per split face (bounded by the faces)
        i, j = int(face[s]), int(corner[s])
        p, q, c = f[i, j], f[i, (j + 1) % 3], f[i, (j + 2) % 3]
        chain = np.r_[p, m[s:stop], q]
        fan = np.stack([chain[:-1], chain[1:], np.full(len(chain) - 1, c)], axis=1)
        new_faces.append(fan)
        new_slack.append(np.full(len(fan), max(float(slack[i]), float(dist[s:stop].max()))))
    keep_face = np.ones(len(f), dtype=bool)
    keep_face[split_faces] = False
    return (np.vstack([f[keep_face], *new_faces]), np.concatenate([slack[keep_face], *new_slack]),
            int(len(m)))


def seal_seams(vertices: np.ndarray, faces: np.ndarray, gap: float) -> Seal:
    """Weld crack lips and split T-junctions within ``gap`` m (module docstring: steps and bound).

    Parameters
    ----------
    vertices : (n, 3) float
        m (not changed: welds re-index, splits reuse the T-vertex).
    faces : (m, 3) int
    gap : float
        m; 0 leaves the surface as it is.

    Returns
    -------
    Seal
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    slack = np.zeros(len(f))
    vertex_slack = np.zeros(len(v))
    dropped, welded, split = 0.0, 0, 0
    if not gap > 0:
        return Seal(f, slack, 0.0, 0, 0)
    for _ in range(MAX_SEAL_ROUNDS):
        f, slack, lost, merged = _weld_lips(v, f, slack, vertex_slack, gap)
        f, slack, inserted = _split_t_junctions(v, f, slack, gap)
        dropped += lost
        welded += merged
        split += inserted
        if not (merged or inserted):
            break
    slack = np.maximum(slack, vertex_slack[f].max(axis=1)) if len(f) else slack
    return Seal(f, slack, dropped, welded, split)
