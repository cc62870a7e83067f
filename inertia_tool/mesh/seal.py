"""Seal the seams an export split: cracks and T-junctions, with a bound on what sealing may have changed.

A surface whose boundary edges come in near pairs (a crack: the two lips of a seam a hair apart) or end on
the middle of another boundary edge (a T-junction: a fine side meeting a coarse one) is geometrically
closed, or nearly: only the bookkeeping of its vertices is broken.  :func:`seal_seams` repairs that
bookkeeping within a stated gap ``g`` and nothing else: first every T-vertex lying on its edge to round-off is
put on it (step 2 restricted to those: exact, nothing moves, so a T-vertex on a short edge is not welded to its
end), then bounded rounds of two steps:

1. *Weld the lips*: boundary vertices within ``g`` of another boundary vertex are merged (the tolerance
   weld's search, exact distances), each cluster into its lowest-numbered vertex; faces that collapse are dropped.
2. *Split at T-junctions*: a boundary vertex ``m`` within ``g`` of the interior of a boundary edge
   ``a→b`` (and farther than ``g`` from both ends, or on it to round-off: ``ON_EDGE_RTOL``) splits the face
   holding ``a→b`` into a fan through the points on that edge, in order along it (each vertex onto its nearest
   edge, never onto its own face; T-vertices on their edges to round-off first, before anything is welded).

The stated assumption: **the true surface is the sealed surface with each corner of a face that sealing
touched moved by at most that face's slack** ``d`` (the distance a welded corner travelled, or the distance
of a T-vertex from the edge it was put on).  A point of a triangle whose corners move by at most ``d`` moves
by at most ``d`` (it is a convex combination of them), so the solid can change only inside the parallel body
of radius ``d`` around the touched faces, whose volume for a triangle of area ``A`` and perimeter ``P`` is
Steiner's ``2Ad + (π/2)Pd² + (4/3)πd³`` (a dropped, collapsed face counts as a segment, ``A = 0``).  The
sum over touched faces is the volume in doubt.  When nothing moved (a T-vertex exactly on its edge, lips
bit-identical) every slack is zero and the sealed surface is exact.

Only the *frontier* is looked at: the faces with a corner on an unbalanced edge.  Every unbalanced edge has
both ends there, and every face using such an edge is a frontier face, so the frontier alone tells which edges
are unbalanced (those of its edges that touch a frontier vertex); welds merge frontier vertices into frontier
vertices and splits insert them, so that stays true round after round.  The rest of the surface is passed
through untouched, and a big part with a small hole costs what the hole costs.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .._native import accel, threads
from ..values import frozen_value
from .edges import edge_keys, stable_key_order

__all__ = ["Seal", "seal_seams", "parallel_body_volume", "drop_duplicate_faces", "on_edge_vertices"]

#: A boundary vertex whose distance from an edge is at most ``ON_EDGE_RTOL ×`` its distance from the edge's
#: nearer end lies on it (round-off of a midpoint; a jittered copy of the end is never that well aligned): it is
#: put on the edge even when it is within the gap of an end, where it would otherwise be welded.
ON_EDGE_RTOL = 1e-9

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
    boundary : (k, 2) int
        The net boundary of ``faces`` as directed edges with multiplicity (as
        :func:`~.rims.boundary_edges` gives it), found on the frontier.
    loose_faces : int
        Faces of ``faces`` sharing no edge with another face (loose triangles of a soup).
    front_start : int
        ``faces[front_start:]`` are the frontier (every face with a corner on an unbalanced edge), sealed; the
        faces before it are untouched.
    duplicates : int
        Repeated copies of a face (same corners, same winding) that sealing made and that were dropped.
    """

    faces: np.ndarray
    slack: np.ndarray
    dropped_doubt: float
    welded: int
    split: int
    boundary: np.ndarray
    loose_faces: int = 0
    duplicates: int = 0
    front_start: int = 0

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


def _frontier_boundary(faces: np.ndarray, n: int, region: np.ndarray | None) -> np.ndarray:
    """Boundary edges of the frontier ``faces`` that are boundary edges of the whole surface: those with an end
    in ``region`` (the frontier vertices; None: ``faces`` is the whole surface)."""
    from .rims import boundary_edges

    edges = boundary_edges(faces, n)
    if region is not None and len(edges):
        edges = edges[region[edges[:, 0]] | region[edges[:, 1]]]
    return edges


def _boundary_vertices(faces: np.ndarray, n: int, region: np.ndarray | None = None) -> np.ndarray:
    edges = _frontier_boundary(faces, n, region)
    return np.flatnonzero(np.bincount(edges.reshape(-1), minlength=n)) if len(edges) else np.zeros(0, np.int64)


class _Chain(NamedTuple):
    """The frontier's boundary 1-chain, kept up to date as sealing replaces faces instead of found again from all
    the frontier's faces each round (seven times on a T-split part, 1 s of its 1.7 s seal): ``key`` (k,) int64 the
    edges' undirected keys (:func:`~.edges.edge_keys`), ascending, each once; ``net`` (k,) int64, nonzero, the uses
    ``min→max`` minus ``max→min``.  Only edges with an end in the region (every other edge is balanced)."""

    key: np.ndarray
    net: np.ndarray


def _signed_keys(faces: np.ndarray, n: int, region: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    key, forward = edge_keys(faces, n)
    sign = np.where(forward, -1, 1).astype(np.int64)
    if region is not None and len(key):
        nn = np.int64(max(n, 1))
        near = region[key // nn] | region[key % nn]
        key, sign = key[near], sign[near]
    return key, sign


def _reduce(key: np.ndarray, sign: np.ndarray) -> _Chain:
    order = np.argsort(key, kind="stable")
    key, sign = key[order], sign[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]]) if len(key) else np.zeros(0, dtype=np.int64)
    net = np.add.reduceat(sign, starts) if len(key) else np.zeros(0, dtype=np.int64)
    keep = net != 0
    return _Chain(key[starts][keep], net[keep])


def _chain_of_faces(faces: np.ndarray, n: int, region: np.ndarray | None) -> _Chain:
    return _reduce(*_signed_keys(faces, n, region))


def _chain_of_edges(edges: np.ndarray, n: int) -> _Chain:
    """The chain of directed edges with multiplicity (a boundary as :func:`~.rims.boundary_edges` gives it)."""
    a, b = edges[:, 0].astype(np.int64), edges[:, 1].astype(np.int64)
    nn = np.int64(max(n, 1))
    return _reduce(np.minimum(a, b) * nn + np.maximum(a, b), np.where(a < b, 1, -1).astype(np.int64))


def _chain_update(chain: _Chain, removed: np.ndarray, added: np.ndarray, n: int,
                  region: np.ndarray | None) -> _Chain:
    """``chain`` with the faces ``removed`` taken out and ``added`` put in (chains add: the boundary of a sum of
    faces is the sum of their boundaries)."""
    k_out, s_out = _signed_keys(removed, n, region)
    k_in, s_in = _signed_keys(added, n, region)
    return _reduce(np.concatenate([chain.key, k_out, k_in]), np.concatenate([chain.net, -s_out, s_in]))


def _chain_edges(chain: _Chain, n: int) -> np.ndarray:
    """Directed edges with multiplicity, in the order of :func:`_frontier_boundary` (by key, each ``|net|``
    times in its net direction)."""
    nn = np.int64(max(n, 1))
    lo, hi = chain.key // nn, chain.key % nn
    reps = np.abs(chain.net)
    return np.stack([np.repeat(np.where(chain.net > 0, lo, hi), reps),
                     np.repeat(np.where(chain.net > 0, hi, lo), reps)], axis=1)


def _chain_vertices(chain: _Chain, n: int) -> np.ndarray:
    nn = np.int64(max(n, 1))
    ends = np.concatenate([chain.key // nn, chain.key % nn])
    return np.flatnonzero(np.bincount(ends, minlength=n)) if len(ends) else np.zeros(0, np.int64)


def drop_duplicate_faces(faces: np.ndarray) -> tuple[np.ndarray, int]:
    """Drop repeated copies of a face (same corners, same winding); a face and its reverse both stay.

    Returns the faces kept (first copies, in their order) and the number dropped.
    """
    f = np.asarray(faces)
    if len(f) < 2:
        return f, 0
    roll = np.argmin(f, axis=1)
    idx = (roll[:, None] + np.arange(3)) % 3
    canon = np.take_along_axis(f, idx, axis=1)       # rotated to start at the smallest index: keeps winding
    order = np.lexsort((canon[:, 2], canon[:, 1], canon[:, 0]))
    sc = canon[order]
    repeat = np.zeros(len(f), dtype=bool)
    repeat[order[1:]] = (sc[1:] == sc[:-1]).all(axis=1)
    if not repeat.any():
        return f, 0
    # keep the first copy in file order: within a run of equal rows lexsort is stable, so order[start] is it
    return f[~repeat], int(np.count_nonzero(repeat))


def _loose_faces(faces: np.ndarray, n: int, region: np.ndarray, boundary: np.ndarray | None = None) -> int:
    """Frontier faces none of whose edges is used by another face (an edge without an end in ``region`` is
    balanced in the whole surface, so it is shared even if its other face is not in the frontier).

    ``boundary`` (k, 2) int, optional: the frontier's boundary edges with an end in ``region`` (as
    :class:`Seal` holds them).  Then only the face edges whose two ends are ends of those are keyed (soup19: every
    face edge of the frontier was): an edge used once with an end in ``region`` is unbalanced, so it is one of
    them, and every use of an edge has the same two ends, so the uses counted are all its uses."""
    if not len(faces):
        return 0
    if boundary is None:
        slots = None
        key = edge_keys(faces, n)[0]
    else:
        ends = np.zeros(n, dtype=bool)
        ends[np.asarray(boundary, dtype=np.int64).reshape(-1)] = True
        at_ends = ends[faces]
        slots = np.flatnonzero((at_ends & np.roll(at_ends, -1, axis=1)).reshape(-1))   # slot 3i + j: j → j + 1
        key = edge_keys(faces[slots // 3], n)[0][np.arange(len(slots)) * 3 + slots % 3]
    sk, order = stable_key_order(key)
    nn = np.int64(max(n, 1))
    single = region[sk // nn] | region[sk % nn]
    same = sk[1:] == sk[:-1]
    single[1:] &= ~same
    single[:-1] &= ~same
    alone = np.zeros(3 * len(faces), dtype=bool)
    alone[order if slots is None else slots[order]] = single
    return int(np.count_nonzero(alone.reshape(-1, 3).all(axis=1)))


def _weld_lips(v: np.ndarray, f: np.ndarray, slack: np.ndarray, vertex_slack: np.ndarray,
               gap: float, region: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, float, int]:
    """Step 1: merge boundary vertices within ``gap``; returns faces, face slack, dropped doubt, merged count.

    The groups (vertices within ``gap``, transitively) are :func:`~.merge.lowest_in_group`'s, the tolerance
    weld's search (a C kernel; a k-d tree here cost the soup scipy's import, ~1 s, besides the search)."""
    return _weld(v, f, slack, vertex_slack, gap, _chain_of_faces(f, len(v), region), region)[:4]


def _weld(v: np.ndarray, f: np.ndarray, slack: np.ndarray, vertex_slack: np.ndarray, gap: float, chain: _Chain,
          region: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, float, int, _Chain]:
    """:func:`_weld_lips` on the frontier whose boundary is ``chain``; also returns the chain after it."""
    from .merge import lowest_in_group

    bv = _chain_vertices(chain, len(v))
    if len(bv) < 2:
        return f, slack, 0.0, 0, chain
    lowest = lowest_in_group(v[bv], gap)
    if lowest is None:
        return f, slack, 0.0, 0, chain
    rep = bv[lowest]                                        # lowest local index = lowest vertex (bv is sorted)
    move = np.linalg.norm(v[bv] - v[rep], axis=1) + vertex_slack[bv]
    np.maximum.at(vertex_slack, rep, move)
    remap = np.arange(len(v))
    remap[bv] = rep
    merged = int(np.count_nonzero(rep != bv))
    g = remap[f]
    collapsed = (g[:, 0] == g[:, 1]) | (g[:, 1] == g[:, 2]) | (g[:, 2] == g[:, 0])
    d = np.maximum(slack, vertex_slack[g].max(axis=1))
    dropped = float(np.sum(parallel_body_volume(v, f[collapsed], d[collapsed]))) if collapsed.any() else 0.0
    changed = (g != f).any(axis=1)
    chain = _chain_update(chain, f[changed], g[changed & ~collapsed], len(v), region)
    return g[~collapsed], d[~collapsed], dropped, merged, chain


def _split_t_junctions(v: np.ndarray, f: np.ndarray, slack: np.ndarray,
                       gap: float, region: np.ndarray | None = None, *, on_edge_only: bool = False
                       ) -> tuple[np.ndarray, np.ndarray, int]:
    """Step 2: split faces at boundary vertices lying on the interior of a boundary edge; returns faces,
    slack and the number of vertices inserted (``on_edge_only``: only vertices on the edge to round-off)."""
    return _split(v, f, slack, gap, _chain_of_faces(f, len(v), region), region, on_edge_only)[:3]


class _Pairs(NamedTuple):
    """The (edge, point) candidates of a seal's search (:func:`_edge_point_candidates`) within ``gap``, kept from
    pass to pass so that a pass with the same gap searches only the edges the one before did not (issue 25, soup19:
    the on-edge passes of a T-split 1.3M-face sphere searched the same ~69k edges three times).  ``searched`` (s,)
    int64: the keys ``a·n + b`` of the directed edges searched, ascending; ``points`` (n,) bool: the points they
    were searched against; ``edge`` (k,) int64, ascending, and ``point`` (k,) int64: every candidate pair of those
    edges and points (the pairs the search lists depend only on the edge and the point, not on which other edges
    and points are searched with them)."""

    gap: float
    searched: np.ndarray
    points: np.ndarray
    edge: np.ndarray
    point: np.ndarray


def _candidates(v: np.ndarray, edges: np.ndarray, gap: float, known: _Pairs | None
                ) -> tuple[np.ndarray, np.ndarray, _Pairs]:
    """(edge row, vertex) candidate pairs within ``gap`` of ``edges`` (distinct rows in lexicographic order, as
    :func:`_unique_rows` gives them) and their own boundary vertices, by edge, as :func:`_edge_point_candidates`
    lists them: when ``known`` (the previous pass's) was searched with the same gap, those of its pairs whose edge
    and point are still here, and a search of the edges it did not search.  Every vertex must then be one
    ``known`` searched against (a vertex cannot become a boundary vertex by a split or a weld that did not make it
    one before: else everything is searched again, which gives the same pairs).  The order of the pairs within an
    edge may differ from a search's; :func:`_split` does not depend on it (it orders what it keeps by vertex, then
    distance, then edge).  Also returns the pairs to hand to the next pass.  (Each pass lists what a search of
    its own would list, no more: a search with the weld's gap before the weld would list every near copy of an
    edge's ends on a soup the tolerance weld left alone, ~6 pairs an edge.)"""
    n = len(v)
    nn = np.int64(max(n, 1))
    key = edges[:, 0].astype(np.int64) * nn + edges[:, 1]                  # ascending: the rows' order
    points = np.zeros(n, dtype=bool)
    points[edges.reshape(-1)] = True
    if known is None or known.gap != gap or bool(np.any(points & ~known.points)):
        e, m = _edge_point_candidates(v, edges, gap)
        return e, m, _Pairs(gap, key, points, key[e], m)
    pos = np.minimum(np.searchsorted(known.searched, key), max(len(known.searched) - 1, 0))
    new_rows = np.flatnonzero(known.searched[pos] != key) if len(known.searched) else np.arange(len(key))
    at = np.minimum(np.searchsorted(key, known.edge), len(key) - 1)
    keep = (key[at] == known.edge) & points[known.point]
    e, m = at[keep], known.point[keep]
    if len(new_rows):
        new_e, new_m = _edge_point_candidates(v, edges[new_rows], gap, points=np.flatnonzero(points))
        e, m = np.concatenate([e, new_rows[new_e]]), np.concatenate([m, new_m])
        by_edge = np.argsort(e, kind="stable")
        e, m = e[by_edge], m[by_edge]
    return e, m, _Pairs(gap, key, points, key[e], m)


def _split(v: np.ndarray, f: np.ndarray, slack: np.ndarray, gap: float, chain: _Chain, region: np.ndarray | None,
           on_edge_only: bool, known: _Pairs | None = None
           ) -> tuple[np.ndarray, np.ndarray, int, _Chain, _Pairs | None]:
    """:func:`_split_t_junctions` on the frontier whose boundary is ``chain``; also returns the chain after it and
    the candidate pairs to hand to the next pass (``known``: those of the pass before, :class:`_Pairs`)."""
    if not len(chain.key):
        return f, slack, 0, chain, known
    edges = _chain_edges(chain, len(v))
    edges = _unique_rows(edges, len(v))
    e, m, known = _candidates(v, edges, 0.0 if on_edge_only else gap, known)
    if not len(e):
        return f, slack, 0, chain, known
    # the candidates' edges only (each row as numpy forms it for all edges: the same values)
    a = v[edges[e, 0]]
    b = v[edges[e, 1]]
    ab = b - a
    length = np.linalg.norm(ab, axis=1)
    t = np.einsum("ij,ij->i", v[m] - a, ab) / np.maximum(length ** 2, np.finfo(float).tiny)
    foot = a + t[:, None] * ab
    dist = np.linalg.norm(v[m] - foot, axis=1)
    to_end = np.minimum(np.linalg.norm(v[m] - a, axis=1), np.linalg.norm(v[m] - b, axis=1))
    # a vertex within the gap of an end is a crack lip to weld, unless it lies on the edge itself (to
    # round-off: a T-junction on a short edge, which welding would move by up to the gap)
    on_edge = dist <= ON_EDGE_RTOL * to_end
    ok = (dist <= gap) & (t > 0) & (t < 1) & (to_end > 0) & (on_edge if on_edge_only else (to_end > gap) | on_edge)
    e, m, t, dist = e[ok], m[ok], t[ok], dist[ok]
    if not len(e):
        return f, slack, 0, chain, known
    # each vertex onto its nearest edge only (a thin part can hold other boundary edges within the gap)
    nearest = np.lexsort((dist, m))
    first = nearest[np.r_[True, m[nearest][1:] != m[nearest][:-1]]]
    e, m, t, dist = e[first], m[first], t[first], dist[first]
    # the face holding each directed edge a→b, and which of its edges it is
    start, end = edges[e, 0].astype(np.int64), edges[e, 1].astype(np.int64)
    want = 2 * edge_keys(np.stack([start, end, end], axis=1), len(v))[0][0::3] + (start > end)
    # the lowest slot holding each wanted key: only the slots holding one are sorted (not the whole frontier's),
    # and only the slots whose two ends are ends of a wanted edge are keyed (soup19: every slot of the frontier
    # was keyed and looked up, each pass)
    ends = np.zeros(len(v), dtype=bool)
    ends[start] = True
    ends[end] = True
    at_ends = ends[f]
    # slot 3i + j: f[i, j] → f[i, j+1]
    slots = np.flatnonzero((at_ends & np.roll(at_ends, -1, axis=1)).reshape(-1))
    undirected, forward = edge_keys(f[slots // 3], len(v))
    pick = np.arange(len(slots)) * 3 + slots % 3
    key = 2 * undirected[pick] + forward[pick]
    targets = np.unique(want)
    at = np.minimum(np.searchsorted(targets, key), len(targets) - 1)
    hit = np.flatnonzero(targets[at] == key)
    by_key = hit[np.argsort(key[hit], kind="stable")]
    order = slots[by_key]                   # the slots holding a wanted key, by key (by slot within a key)
    held = key[by_key]                      # their keys, ascending
    pos = np.searchsorted(held, want)
    found = (pos < len(order)) & (held[np.minimum(pos, len(order) - 1)] == want)
    e, m, t, dist, pos = e[found], m[found], t[found], dist[found], pos[found]
    slot = order[pos]
    face, corner = slot // 3, slot % 3
    # never a face's own third corner (a sliver whose apex lies on its base edge): the fan would repeat it
    own = m != f[face, (corner + 2) % 3]
    face, corner, m, t, dist, slot = face[own], corner[own], m[own], t[own], dist[own], slot[own]
    # one edge per face per round: keep the points of the first edge listed for each face
    first_slot = np.full(len(f), -1, dtype=np.int64)
    np.maximum.at(first_slot, face, slot)
    sel = slot == first_slot[face]
    face, corner, m, t, dist = face[sel], corner[sel], m[sel], t[sel], dist[sel]
    if not len(face):
        return f, slack, 0, chain, known
    # each (face, vertex) once, in (face, vertex) order (as numpy.unique of the rows, by one int64 key)
    _, unique_m = np.unique(face.astype(np.int64) * np.int64(max(len(v), 1)) + m, return_index=True)
    face, corner, m, t, dist = face[unique_m], corner[unique_m], m[unique_m], t[unique_m], dist[unique_m]
    by = np.lexsort((t, face))
    face, corner, m, dist = face[by], corner[by], m[by], dist[by]
    split_faces = np.flatnonzero(np.bincount(face, minlength=len(f)))
    starts = np.searchsorted(face, split_faces)
    count = np.diff(np.r_[starts, len(face)])
    # one fan per split face p→q (apex c) through its points in order: (p, m0, c), (m0, m1, c), ..., (mk, q, c),
    # the fans in the order of the split faces (all at once: 26k fans of a T-split 1.3M-face mesh were a loop)
    j = corner[starts]
    p, q, c = f[split_faces, j], f[split_faces, (j + 1) % 3], f[split_faces, (j + 2) % 3]
    group = np.repeat(np.arange(len(split_faces)), count)     # the split face of each point, in order
    rows = len(face) + len(split_faces)
    first_row = starts + np.arange(len(split_faces))          # each fan's first row
    fan = np.empty((rows, 3), dtype=f.dtype)
    fan[first_row, 0] = p
    fan[np.arange(len(face)) + group + 1, 0] = m
    fan[np.arange(len(face)) + group, 1] = m
    fan[first_row + count, 1] = q
    fan[:, 2] = np.repeat(c, count + 1)
    fan_slack = np.repeat(np.maximum(slack[split_faces], np.maximum.reduceat(dist, starts)), count + 1)
    keep_face = np.ones(len(f), dtype=bool)
    keep_face[split_faces] = False
    chain = _chain_update(chain, f[split_faces], fan, len(v), region)
    return (np.vstack([f[keep_face], fan]), np.concatenate([slack[keep_face], fan_slack]), int(len(m)), chain,
            known)


def on_edge_vertices(vertices: np.ndarray, boundary: np.ndarray) -> np.ndarray:
    """Boundary vertices that lie on the interior of another boundary edge to round-off (T-junctions whose
    vertex is on its edge: ``ON_EDGE_RTOL``), sorted (k,) int.  A copy of an edge's end (the same coordinates)
    is not on its interior, however ``t`` rounds (a third of a COLLADA soup's copies were taken for T-vertices
    and kept out of the weld; issue 23).

    The weld before repair leaves these alone: merging such a vertex with a near one (a sliver's apex a hair
    from the edge) would fold the surface, while putting it on its edge (:func:`seal_seams`) changes nothing.
    """
    v = np.asarray(vertices, dtype=np.float64)
    edges = np.asarray(boundary, dtype=np.int64).reshape(-1, 2)
    if not len(edges):
        return np.zeros(0, dtype=np.int64)
    # an edge listed again only repeats work (the answer is a set): the copies of the census's boundary, one per
    # unit of net use, are consecutive, and dropping those needs no sort (0.4 s for a soup's 3.9M edges); the
    # two columns compared one at a time, and no copy when every row differs from the one before (a soup's:
    # 0.2 s as a (k, 2) comparison reduced by rows and a copy, 0.02 s so)
    new_row = np.empty(len(edges), dtype=bool)
    new_row[0] = True
    np.not_equal(edges[1:, 0], edges[:-1, 0], out=new_row[1:])
    new_row[1:] |= edges[1:, 1] != edges[:-1, 1]
    if not new_row.all():
        edges = edges[new_row]
    del new_row
    e, m = _edge_point_candidates(v, edges, 0.0)
    if not len(e):
        return np.zeros(0, dtype=np.int64)
    # the candidates' edges only (a soup's 3.9M edges as (k, 3) arrays were 300 MB at the peak for a few pairs)
    a, b = v[edges[e, 0]], v[edges[e, 1]]
    ab = b - a
    length = np.linalg.norm(ab, axis=1)
    t = np.einsum("ij,ij->i", v[m] - a, ab) / np.maximum(length ** 2, np.finfo(float).tiny)
    dist = np.linalg.norm(v[m] - (a + t[:, None] * ab), axis=1)
    to_end = np.minimum(np.linalg.norm(v[m] - a, axis=1), np.linalg.norm(v[m] - b, axis=1))
    # a copy of an end (to_end == 0) is not on the interior, whatever the last bit of t says (t = 1 - 1 ulp for
    # a copy of b when |b - a|² rounds above (b - a)·(b - a)): as the seal's split test
    on = (t > 0) & (t < 1) & (to_end > 0) & (dist <= ON_EDGE_RTOL * to_end)
    found: np.ndarray = np.flatnonzero(np.bincount(m[on], minlength=len(v)))    # sorted, each once
    return found


def _unique_rows(edges: np.ndarray, n: int) -> np.ndarray:
    """The distinct rows of (k, 2) int edges in lexicographic order, as ``numpy.unique(axis=0)`` gives them
    (by a sort of one int64 key per row, several times faster)."""
    nv = np.int64(max(n, 1))
    key = np.sort(edges[:, 0].astype(np.int64) * nv + edges[:, 1])
    key = key[np.r_[True, key[1:] != key[:-1]]]
    rows: np.ndarray = np.stack([key // nv, key % nv], axis=1)
    return rows


#: Points gathered at a time for their bounds (a soup's 3.9M boundary vertices were a 94 MB copy at the peak).
_BOUNDS_CHUNK = 1 << 18


def _bounds_of(lib: Any, v: np.ndarray, index: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """``lib.bounds(v[index])`` (lowest and highest coordinates, all finite) a chunk of points at a time, or of
    ``v`` itself when ``index`` (sorted, each once) is every row (a soup: no gathered copies)."""
    if len(index) == len(v) and v.flags.c_contiguous:
        every_lo, every_hi, every_finite = lib.bounds(v)
        return np.asarray(every_lo), np.asarray(every_hi), bool(every_finite)
    lo, hi, finite = np.full(3, np.inf), np.full(3, -np.inf), True
    for start in range(0, len(index), _BOUNDS_CHUNK):          # bounded by len(index) / _BOUNDS_CHUNK + 1
        part_lo, part_hi, part_finite = lib.bounds(np.ascontiguousarray(v[index[start:start + _BOUNDS_CHUNK]]))
        finite = finite and bool(part_finite)
        lo, hi = np.minimum(lo, part_lo), np.maximum(hi, part_hi)
    return lo, hi, finite


def _edge_point_candidates(v: np.ndarray, edges: np.ndarray, gap: float, *, points: np.ndarray | None = None
                           ) -> tuple[np.ndarray, np.ndarray]:
    """(edge row, vertex) pairs, by edge, of the edges' own vertices ``m`` (not an end of the edge) that may lie
    within ``gap`` of the edge's interior or on it to ``ON_EDGE_RTOL``: a superset of the pairs the callers'
    tests accept, which they then apply.  ``points`` (sorted, each once), optional: the vertices ``m`` to try
    instead of the edges' own.

    The C kernel (``_accel.edge_point_candidates``, section 9) visits a grid of cells along each edge and keeps
    the pairs within the distance to round-off; without it, a k-d tree lists the vertices in the ball on each
    edge widened by ``gap`` (every pair the tests accept lies in it).  Before the kernel, a soup (every vertex on
    the boundary) spent seconds in the k-d tree's Python lists: ~9 vertices per edge.
    """
    bv = np.flatnonzero(np.bincount(edges.reshape(-1), minlength=len(v))) if points is None else \
        np.asarray(points, dtype=np.int64)
    lib = accel()
    cell = np.inf
    finite = False
    if lib is not None and len(bv):
        lo, hi, finite = _bounds_of(lib, v, bv)
    if lib is not None and finite:
        extent = float(np.max(np.subtract(hi, lo)))
        # the edges' lengths on a sample (only the speed depends on the cell, so an estimate serves)
        sample = edges[:: max(1, len(edges) // 65536)]
        length = np.linalg.norm(v[sample[:, 1]] - v[sample[:, 0]], axis=1)
        typical = float(np.median(length[:: max(1, len(sample) // 4096)]))
        total = float(length.mean()) * len(edges)
        # a typical edge's length or the gap, at least 2**-20 of the extent (the kernel's grid indices have 21
        # bits), and coarse enough that the edges are cut into at most 16 pieces each on average plus 2**20 (a
        # few long edges over a finely meshed part)
        cell = max(typical, gap, extent * 2.0 ** -20, 2.0 * total / (16 * len(edges) + 2 ** 20),
                   np.finfo(float).tiny)
    if lib is not None and np.isfinite(cell):      # else (no C extension, or coordinates overflowing): the tree
        pe, pm = lib.edge_point_candidates(np.ascontiguousarray(v), np.ascontiguousarray(edges, dtype=np.int64),
                                           bv, cell, ON_EDGE_RTOL, float(gap), threads())
        return np.frombuffer(pe, dtype=np.int64), np.frombuffer(pm, dtype=np.int64)
    from scipy.spatial import cKDTree

    tried = v[bv]
    a, b = v[edges[:, 0]], v[edges[:, 1]]
    length = np.linalg.norm(b - a, axis=1)
    near = cKDTree(tried, balanced_tree=False, compact_nodes=False).query_ball_point(
        0.5 * (a + b), 0.5 * length * (1 + 1e-9) + gap)
    counts = np.fromiter((len(x) for x in near), dtype=np.int64, count=len(near))
    if not counts.sum():
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    e = np.repeat(np.arange(len(edges)), counts)
    m = bv[np.concatenate([np.asarray(x, dtype=np.int64) for x in near if len(x)])]
    keep = (m != edges[e, 0]) & (m != edges[e, 1])
    return e[keep], m[keep]


def seal_seams(vertices: np.ndarray, faces: np.ndarray, gap: float, *, drop_duplicates: bool = True,
               boundary: np.ndarray | None = None) -> Seal:
    """Weld crack lips and split T-junctions within ``gap`` m (module docstring: steps and bound).

    Parameters
    ----------
    vertices : (n, 3) float
        m (not changed: welds re-index, splits reuse the T-vertex).
    faces : (m, 3) int
    gap : float
        m; 0 leaves the surface as it is.
    drop_duplicates : bool
        Drop the repeated faces a weld or split made (same corners, same winding); the faces kept then all
        take the largest slack (a superset of what each could have been).
    boundary : (k, 2) int, optional
        The net boundary of ``faces`` when the caller has it (as :func:`~.rims.boundary_edges` gives it).

    Returns
    -------
    Seal
        Its faces are the untouched faces followed by the frontier's, sealed.
    """
    from .rims import boundary_edges

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    edges = boundary_edges(f, n) if boundary is None else np.asarray(boundary, dtype=np.int64).reshape(-1, 2)
    if not len(edges):
        return Seal(f, np.zeros(len(f)), 0.0, 0, 0, edges, 0, 0, len(f))
    region = np.zeros(n, dtype=bool)
    region[edges.reshape(-1)] = True
    at_front = region[f].any(axis=1)
    rest, front = f[~at_front], f[at_front]
    slack = np.zeros(len(front))
    vertex_slack = np.zeros(n)
    dropped, welded, split = 0.0, 0, 0
    chain = _chain_of_edges(edges, n)              # the frontier's boundary, updated as faces are replaced
    if gap > 0:
        # first the T-junctions exactly on their edges (exact splits, nothing moves), until none is left: a
        # vertex that only comes near an edge (a sliver's apex) is not put on it while the exact ones still
        # leave that edge open
        known: _Pairs | None = None        # the candidate pairs of the passes so far (searched once each)
        for _ in range(3 * MAX_SEAL_ROUNDS):
            front, slack, more, chain, known = _split(v, front, slack, gap, chain, region, True, known)
            split += more
            if not more:
                break
        for _ in range(MAX_SEAL_ROUNDS):
            front, slack, lost, merged, chain = _weld(v, front, slack, vertex_slack, gap, chain, region)
            inserted = 0
            for _ in range(3):          # a face splits one edge per pass and has three
                front, slack, more, chain, known = _split(v, front, slack, gap, chain, region, False, known)
                inserted += more
                if not more:
                    break
            dropped += lost
            welded += merged
            split += inserted
            if not (merged or inserted):
                break
        slack = np.maximum(slack, vertex_slack[front].max(axis=1)) if len(front) else slack
    duplicates = 0
    if drop_duplicates and (welded or split):
        kept, duplicates = drop_duplicate_faces(front)
        if duplicates:
            front = kept
    out = np.vstack([rest, front]) if len(rest) else front
    if duplicates:    # the duplicates' slack is kept for every face that remains (a superset bound)
        all_slack = np.full(len(out), float(slack.max(initial=0.0)))
    else:
        all_slack = np.concatenate([np.zeros(len(rest)), slack])
    if duplicates:
        boundary = _frontier_boundary(front, n, region)
    else:
        boundary = _chain_edges(chain, n) if (welded or split) else edges
    return Seal(out, all_slack, dropped, welded, split, boundary, _loose_faces(front, n, region, boundary),
                duplicates, len(rest))
