"""Bounding holes: what the surface left at each rim says, and how far the missing surface can stray.

The volume in doubt of each hole under the assumptions of :mod:`~.holes` (the ball over the rim cut to the slab
of a face beside it, :func:`hole_doubt_volumes`; the convex polytope where what remains is convex,
:func:`convex_hole_bound`), and the evidence in the file that withdraws a narrower assumption or refuses:
bare rim vertices (:func:`bare_vertices`), a flat rim whose faces leave its plane (:func:`slab_contradicted`),
the footprint of a feature taken whole (:func:`rim_evidence`, :func:`_contradicted`), a ball holding the whole
surface (:func:`_engulfing`) and balls that meet (:func:`_alone`).  The fills these bound are in
:mod:`~.hole_fills`; :func:`~.holes.patched_estimate` puts the two together.
"""

from __future__ import annotations

import numpy as np

from ..rounding import round_up
from ..values import frozen_value
from .edges import edge_keys, stable_key_order


def ball_slab_volume(radius: np.ndarray, offset: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """Volume of the part of a ball that lies in a slab, (k,) m³.

    The ball has radius ``r``; the slab is the set of points whose signed distance from a plane lies in
    ``[−t, t]`` (``t = half_width``), and the ball's centre is at signed distance ``s = offset`` from that plane.
    In the ball's own axial coordinate ``z`` the slab is ``[−t − s, t − s]``; clipped to ``[−r, r]`` it is
    ``[a, b]``, and the volume is ``π ∫_a^b (r² − z²) dz = π [r² z − z³/3]_a^b`` (slices of a ball are discs).
    """
    r = np.asarray(radius, dtype=np.float64)
    lo = np.clip(-np.asarray(half_width) - np.asarray(offset), -r, r)
    hi = np.clip(np.asarray(half_width) - np.asarray(offset), -r, r)
    volume: np.ndarray = np.maximum(np.pi * ((r ** 2 * hi - hi ** 3 / 3.0) - (r ** 2 * lo - lo ** 3 / 3.0)), 0.0)
    return volume


def hole_doubt_volumes(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray,
                       n_loops: int, centre: np.ndarray, radius: np.ndarray, vertex_of: np.ndarray,
                       loop_of: np.ndarray, slabs: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """Volume in doubt of each hole (boundary loop), (n_loops,) m³: the ball over its rim, cut to a slab.

    Two assumptions, both about the missing surface ``M`` of the hole (the surface the file lost):

    1. ``M`` lies in the ball enclosing the rim (module docstring), and
    2. ``M`` strays from the plane of a face beside the hole no farther than the rim itself does: of the faces
       sharing an edge with the rim (the *ring*), take the one whose plane the rim is closest to; if every rim
       vertex is within ``e`` of that plane, so is ``M``.  A hole inside a flat face of a part (a missing
       triangle of a CAD face) has ``e`` ≈ 0; a hole in a curved surface has ``e`` of the order of its sagitta
       (for a spherical cap of half-angle α the ring plane is tilted by about α and the rim's far side lies
       ``2r sin α`` from it, more than the cap's height ``r tan(α/2)`` above the rim's own plane); a hole
       across a crease has ``e`` up to its width, and the ball decides.  It fails for a hole that swallowed a
       whole boss or dimple standing on a flat face (the ring is flat, the missing part is not); on a CAD
       tessellation the bare rim vertices that leaves show it (:func:`rim_evidence`), and the caller withdraws
       the slab or refuses; on a surface with vertices inside its flat faces nothing shows it: the stated limit.

    The cone that patches the hole has its apex at the centroid of the rim vertices, so it lies in the rim's
    convex hull, inside both the ball and the slab of half-width ``e`` around the plane (a convex set holding
    every rim vertex).  The patched and the true solid therefore differ only where the cycle "cone minus
    ``M``" winds, which is inside ball ∩ slab: its volume (:func:`ball_slab_volume`) is the hole's volume in
    doubt.  ``e`` carries a round-off margin of 16 ulp of the coordinates, so an exactly flat hole still
    states a (tiny) positive bound.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        The surface with the holes (sealed where seams were sealed).
    edges : (k, 2) int
        Its boundary edges; ``label`` (k,) the loop of each.
    centre, radius : (n_loops, 3), (n_loops,) float
        The ball enclosing each loop's rim (:func:`enclosing_balls`).
    vertex_of, loop_of : (p,) int
        The distinct (vertex, loop) pairs of the rims.
    slabs : dict, optional
        Filled with each loop's slab when given: ``has`` (n_loops,) bool (a ring face was found), ``normal`` and
        ``origin`` (n_loops, 3) (its plane), ``half_width`` (n_loops,) m (``inf`` where none: the whole ball).
    """
    v = np.asarray(vertices, dtype=np.float64)
    ball: np.ndarray = 4.0 / 3.0 * np.pi * np.asarray(radius, dtype=np.float64) ** 3
    n = len(v)
    slot, rim_edge = _rim_edge_slots(np.asarray(faces), n, edges)
    if not len(slot):
        return ball
    ring_face = slot // 3
    ring_loop = label[rim_edge]
    # one (face, loop) pair per ring face of each loop
    pair = _sorted_pairs(ring_face, ring_loop, n_loops)      # (numpy.unique(axis=0)'s rows, by one int64 key)
    ring_face, ring_loop = pair[:, 0], pair[:, 1]
    a, b, c = (v[faces[ring_face, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    length = np.linalg.norm(normal, axis=1)
    usable = length > 0
    ring_face, ring_loop, a, normal = ring_face[usable], ring_loop[usable], a[usable], normal[usable]
    if not len(ring_face):
        return ball
    unit = normal / length[usable, None]
    # the farthest rim vertex of each loop from each of its ring faces' planes; (ring face, rim vertex)
    # pairs are formed loop by loop (rims are short next to the surface, so this stays small)
    rim_order = np.argsort(loop_of, kind="stable")
    rim_loop, rim_vertex = loop_of[rim_order], vertex_of[rim_order]
    rim_start = np.searchsorted(rim_loop, np.arange(n_loops))
    rim_count = np.diff(np.r_[rim_start, len(rim_loop)])
    per_face = rim_count[ring_loop]
    if int(per_face.sum()) > RING_WORK_LIMIT:
        return ball
    e_face = np.zeros(len(ring_face))
    ends = np.cumsum(per_face)
    lo = 0
    while lo < len(ring_face):          # ring faces in chunks of about RING_CHUNK (face, vertex) pairs
        hi = max(lo + 1, int(np.searchsorted(ends, ends[lo] - per_face[lo] + RING_CHUNK, side="right")))
        hi = min(hi, len(ring_face))
        count = per_face[lo:hi]
        which = lo + np.repeat(np.arange(hi - lo), count)
        offset_in = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        pts = v[rim_vertex[rim_start[ring_loop[which]] + offset_in]]
        dist = np.abs(np.einsum("ij,ij->i", pts - a[which], unit[which]))
        e_face[lo:hi] = np.maximum.reduceat(dist, np.r_[0, np.cumsum(count)[:-1]])
        lo = hi
    best = np.full(n_loops, np.inf)
    np.minimum.at(best, ring_loop, e_face)
    choice = np.full(n_loops, -1, dtype=np.int64)
    is_best = e_face <= best[ring_loop]
    choice[ring_loop[is_best]] = np.flatnonzero(is_best)
    has = choice >= 0
    margin = _round_off(v)
    doubt: np.ndarray = ball.copy()
    k = choice[has]
    offset = np.einsum("ij,ij->i", centre[has] - a[k], unit[k])
    doubt[has] = np.minimum(ball[has], ball_slab_volume(radius[has], offset, best[has] + margin))
    if slabs is not None:          # the slab of each loop, for a caller that checks the assumption
        slabs["has"] = has
        slabs["normal"] = np.zeros((n_loops, 3))
        slabs["normal"][has] = unit[k]
        slabs["origin"] = np.zeros((n_loops, 3))
        slabs["origin"][has] = a[k]
        slabs["half_width"] = np.where(has, best + margin, np.inf)
    return doubt


#: A rim "lies in a plane" when every rim vertex and every face left at the rim is within this share of the
#: ball's radius of the plane of a ring face (far above round-off and quantisation to 1e-4 of a diagonal, far
#: below any boss or pocket a designer draws).
FLAT_RIM_RTOL = 1e-3
#: A vertex is *flat* when every face at it is within acos(FLAT_VERTEX_COSINE) ≈ 1.1° of their mean plane.
FLAT_VERTEX_COSINE = 1.0 - 2e-4
#: A ring is *level* (:func:`level_rings`, the rule of :func:`flat_islands`) when every face touching the rim lies
#: within acos(LEVEL_RING_COSINE) ≈ 1.1° of the rim's mean plane: the flatness of a flat vertex, a slope of 0.02.
LEVEL_RING_COSINE = FLAT_VERTEX_COSINE


@frozen_value
class RimEvidence:
    """What the surface left at each hole's rim says about the missing surface (:func:`rim_evidence`).

    Attributes
    ----------
    flat_all_round : (n_loops,) bool
        The rim lies in one plane (within ``FLAT_RIM_RTOL`` of its ball's radius) and so does every face left at
        a rim vertex: the hole is an island in the middle of a flat face.
    bare : (n_loops,) int
        Rim vertices left *bare*: every face left at them lies within about 1° of one plane (a flat face of the
        part), and no neighbour of theirs off the rims is flat that way.  A surface tessellated with vertices
        only on the loops of its flat faces (as CAD exporters do: no vertex inside a flat face) has no flat
        vertex, so a bare rim vertex lay on a loop of its face, and the hole took every face of the other surface
        that met the face there.
    """

    flat_all_round: np.ndarray
    bare: np.ndarray




def rim_evidence(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                 radius: np.ndarray, *, flat_rtol: float = FLAT_RIM_RTOL,
                 flat_cosine: float = FLAT_VERTEX_COSINE, bare: np.ndarray | None = None) -> RimEvidence:
    """Read, for each boundary loop, what the faces left at its rim say (see :class:`RimEvidence`).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    edges : (k, 2) int
        The boundary edges ``a→b`` (each the edge of one face in that direction); ``label`` (k,) their loop.
    radius : (n_loops,) float
        The radius of the ball over each rim (:func:`~.rims.enclosing_balls`), m.
    flat_rtol, flat_cosine : float
        ``FLAT_RIM_RTOL``, ``FLAT_VERTEX_COSINE``.
    bare : (n,) bool, optional
        :func:`bare_vertices` when the caller has it.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    flat = np.zeros(n_loops, dtype=bool)
    if not n_loops or not len(edges) or not len(f):
        return RimEvidence(flat_all_round=flat, bare=np.zeros(n_loops, dtype=np.int64))
    face, found = _ring_face_of_edges(f, n, edges)
    a, b, c = (v[f[face, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1)
    # the plane of each loop's largest ring face; every face at a rim vertex within the tolerance of it
    score = np.where(found & (area > 0), area, -1.0)
    top = np.full(n_loops, -1.0)
    np.maximum.at(top, label, score)
    pick = np.flatnonzero((score >= top[label]) & (score > 0))
    best = np.full(n_loops, -1, dtype=np.int64)
    best[label[pick]] = pick
    has = best >= 0
    if has.any():
        unit = np.zeros((n_loops, 3))
        unit[has] = normal[best[has]] / area[best[has], None]
        origin = np.zeros((n_loops, 3))
        origin[has] = a[best[has]]
        del a, b, c, normal                   # (the scattered holes' peak: temporaries freed on the way)
        rim_pairs = _sorted_pairs(np.r_[edges[:, 0], edges[:, 1]], np.r_[label, label], n_loops)
        loop_at = np.full(n, -1, dtype=np.int64)
        loop_at[rim_pairs[:, 0]] = rim_pairs[:, 1]     # a vertex on two rims (a pinch) keeps one: excluded below
        on_two = np.bincount(rim_pairs[:, 0], minlength=n) > 1
        worst = _worst_rim_distance(v, f, loop_at, origin, unit, n_loops)
        pinched = np.zeros(n_loops, dtype=bool)
        pinched[rim_pairs[on_two[rim_pairs[:, 0]], 1]] = True
        margin = _round_off(v)
        flat = has & ~pinched & (worst <= flat_rtol * radius + margin)
    if bare is None:
        bare = bare_vertices(v, f, edges, flat_cosine=flat_cosine)
    rim = _sorted_pairs(edges[:, 0], label, n_loops)
    count = np.bincount(rim[:, 1], weights=bare[rim[:, 0]], minlength=n_loops).astype(np.int64)
    return RimEvidence(flat_all_round=flat, bare=count)


def _rim_edge_slots(f: np.ndarray, n: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The face edge slots (slot ``3i + j``: ``f[i, j] → f[i, j+1]``, either direction) that are a rim edge of
    ``edges`` (k, 2), ascending, and for each the first rim edge (in a stable sort of the rim's keys) with its
    key: ``(slot, rim_edge)``, int.

    Only the slots with both ends on a rim can match: those alone are keyed and looked up (issue 25, soup17: all
    3m were, by :func:`~.edges.edge_keys`), in slot order, so the slots found and their rim edges are the ones a
    lookup of every slot finds."""
    nv = np.int64(max(n, 1))
    e = np.asarray(edges, dtype=np.int64)
    rim_key = np.minimum(e[:, 0], e[:, 1]) * nv + np.maximum(e[:, 0], e[:, 1])
    order = np.argsort(rim_key, kind="stable")
    sorted_rim = rim_key[order]
    on_rim = np.zeros(n, dtype=bool)
    on_rim[e.reshape(-1)] = True
    start, end = f.reshape(-1), f[:, [1, 2, 0]].reshape(-1)
    candidate = np.flatnonzero(on_rim[start] & on_rim[end])
    a_end, b_end = start[candidate].astype(np.int64), end[candidate].astype(np.int64)
    key = np.minimum(a_end, b_end) * nv + np.maximum(a_end, b_end)      # edge_keys' key of each slot
    pos = np.searchsorted(sorted_rim, key)
    hit = np.flatnonzero((pos < len(sorted_rim)) & (sorted_rim[np.minimum(pos, len(sorted_rim) - 1)] == key))
    found: np.ndarray = order[pos[hit]]
    return candidate[hit], found


def _ring_face_of_edges(f: np.ndarray, n: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each directed edge ``a→b`` of ``edges``, the lowest-numbered face of ``f`` holding it in that direction
    and whether there is one: ``(face, found)``, (k,) int and bool (face 0 where none).

    Only the face edges whose two ends are rim vertices can match, and only those are sorted (issue 25: every
    face edge was, 0.12 s of the scattered sphere's 1.0 s); the stable sort keeps each key's edges in face order,
    so the first match is the lowest face, as with all of them."""
    nv = np.int64(max(n, 1))
    e = np.asarray(edges, dtype=np.int64)
    query = e[:, 0] * nv + e[:, 1]
    on_rim = np.zeros(n, dtype=bool)
    on_rim[e.reshape(-1)] = True
    start, end = f.reshape(-1), f[:, [1, 2, 0]].reshape(-1)        # slot 3i + j: f[i, j] → f[i, j+1]
    slot = np.flatnonzero(on_rim[start] & on_rim[end])
    directed = start[slot] * nv + end[slot]
    if not len(slot):
        return np.zeros(len(e), dtype=np.int64), np.zeros(len(e), dtype=bool)
    ranked, order = stable_key_order(directed)
    pos = np.minimum(np.searchsorted(ranked, query), len(order) - 1)
    found = ranked[pos] == query
    face = np.where(found, slot[order[pos]] // 3, 0)
    return face, found


def _sorted_pairs(vertex: np.ndarray, loop: np.ndarray, n_loops: int) -> np.ndarray:
    """The distinct rows (vertex, loop) in lexicographic order, (k, 2) int64, as ``numpy.unique(axis=0)`` gives
    them (by a sort of one int64 key per row: sorting the rows as a void dtype was 0.34 s of the scattered sphere's
    1.0 s).  Any pair of non-negative int columns whose second is below ``n_loops`` (the key's width): also the
    (face, loop) and (loop, vertex) rows of the hole bounds (issue 25, soup17)."""
    width = np.int64(max(n_loops, 1))
    key = np.sort(np.asarray(vertex, dtype=np.int64) * width + np.asarray(loop, dtype=np.int64))
    key = key[np.r_[True, key[1:] != key[:-1]]] if len(key) else key    # (numpy's hash-based unique: 0.14 s)
    rows: np.ndarray = np.stack([key // width, key % width], axis=1)
    return rows


#: (face, rim corner) rows measured at a time by :func:`_worst_rim_distance` (~170 bytes each).
_RIM_ROWS = 1 << 17


def _worst_rim_distance(v: np.ndarray, f: np.ndarray, loop_at: np.ndarray, origin: np.ndarray, unit: np.ndarray,
                        n_loops: int) -> np.ndarray:
    """For each loop, the largest distance from the plane ``(origin, unit)`` of a corner of a face at one of its
    rim vertices (``loop_at``: the loop of each rim vertex, −1 elsewhere), (n_loops,); a face counts once per rim
    corner, for that corner's loop.  Measured a block of rows at a time (the maximum does not depend on the
    order): with holes everywhere the (rows, 3, 3) corners at once set the hole stages' peak."""
    worst = np.zeros(n_loops)
    fi, ci = np.nonzero((loop_at >= 0)[f])
    for lo in range(0, len(fi), _RIM_ROWS):            # bounded by len(fi) / _RIM_ROWS + 1
        rows, corner = fi[lo:lo + _RIM_ROWS], ci[lo:lo + _RIM_ROWS]
        loop = loop_at[f[rows, corner]]
        dist = np.abs(np.einsum("ijk,ik->ij", v[f[rows]] - origin[loop][:, None, :], unit[loop])).max(axis=1)
        np.maximum.at(worst, loop, dist)
    return worst


def bare_vertices(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, *,
                  flat_cosine: float = FLAT_VERTEX_COSINE) -> np.ndarray:
    """Rim vertices left bare, (n,) bool (:class:`RimEvidence`): every face left at the vertex lies within
    ``acos(flat_cosine)`` of their mean plane, and one of them shares an edge with a face in that plane (they
    belong to a flat face of the part, not a lone facet of a curved surface), and no neighbour of it off the
    rims is flat that way (else the surface has vertices inside its flat faces there, and a flat rim vertex
    proves nothing)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    on_rim = np.zeros(n, dtype=bool)
    on_rim[np.asarray(edges, dtype=np.int64).reshape(-1)] = True
    # Only the faces near the rims are read (issue 25: the whole surface was, 0.8 s at 1.3M faces for one
    # hole); the answer is the same bit for bit.  A rim vertex's answer depends on ``flat`` at the vertices
    # sharing a face with it (``near``), which depends on the faces at them (``at_near``) and on the faces
    # sharing an edge with those, all among the faces with two corners at a vertex of ``at_near``
    # (``local``).  Every face at a vertex of ``near`` and every face across an edge of ``at_near`` is in
    # ``local``, which keeps the faces' order, so the sums, minima and edge pairs below see the same faces in
    # the same order at every vertex and edge that decides a rim vertex.
    at_rim = on_rim[f].any(axis=1)
    near = np.zeros(n, dtype=bool)
    near[f[at_rim].reshape(-1)] = True
    at_near = near[f].any(axis=1)
    reached = np.zeros(n, dtype=bool)
    reached[f[at_near].reshape(-1)] = True
    local = np.count_nonzero(reached[f], axis=1) >= 2
    f = f[local] if not local.all() else f
    g, unit, least, size = _vertex_flatness(v, f)
    # a face of a flat *face of the part*: it shares an edge with a face in its plane (a lone triangle of a
    # curved surface is flat trivially and proves nothing)
    key, order = stable_key_order(edge_keys(g, n)[0])
    same = key[1:] == key[:-1]
    del key                                       # (the peak of a hole's bounds: temporaries freed on the way)
    first, second = order[:-1][same] // 3, order[1:][same] // 3
    del order, same
    coplanar = np.einsum("ij,ij->i", unit[first], unit[second]) >= flat_cosine
    in_flat_face = np.zeros(len(g), dtype=bool)
    in_flat_face[first[coplanar]] = True
    in_flat_face[second[coplanar]] = True
    on_flat_face = np.zeros(n, dtype=bool)
    for k in range(3):
        on_flat_face[g[in_flat_face, k]] = True
    flat = (least >= flat_cosine) & (size > 0) & on_flat_face       # exact at the vertices of ``near``
    # rim vertices with a flat neighbour off the rims: the surface has vertices inside its flat faces here
    off = flat & ~on_rim
    near_flat = np.zeros(n, dtype=bool)
    ring = np.asarray(faces, dtype=np.int64)[at_rim]                  # every face at a rim vertex
    for k in range(3):
        for j in range(3):
            if j != k:
                near_flat[ring[off[ring[:, j]], k]] = True
    bare: np.ndarray = flat & on_rim & ~near_flat
    return bare


def slab_contradicted(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray,
                      n_loops: int, slabs: dict[str, np.ndarray], radius: np.ndarray, *,
                      flat_rtol: float = FLAT_RIM_RTOL, flat_cosine: float = FLAT_VERTEX_COSINE,
                      excused: np.ndarray | None = None) -> np.ndarray:
    """Loops whose flat slab the faces left at the rim contradict, (n_loops,) bool.

    Only rims that are flat (within ``flat_rtol`` of the ball's radius of their slab plane ``P``: a hole in a
    flat face of the part) are examined; the second assumption then says the missing surface ``M`` *is* the
    planar region the rim bounds in ``P``.  The file contradicts it, or cannot confirm it, at **a rim vertex
    whose every remaining face lies in ``P``** (each corner within ``flat_rtol`` of the radius of it).  On a
    surface with no vertex inside its flat faces (a CAD tessellation) every vertex lies on a loop of its flat
    face, where another face of the part meets ``P``; that face is gone with the hole, so ``M`` leaves ``P`` at
    the vertex, by an amount nothing in the file bounds.  On a surface with vertices inside its flat faces (a
    grid, Steiner points) such a vertex may be an inner point of the face or a corner of a feature taken whole
    (a pocket of a grid-meshed box taken with its walls and floor was stated within 1e-15 and 2 % off: review6),
    and nothing in the file tells which, so the slab is withdrawn there too (``flat_cosine`` is kept for the
    signature).  Found by
    the generated featured-box test: a box that
    lost most of its faces keeps a boss and two top triangles, whose outer corners keep nothing else (the patch
    closed the boss alone, 94 % low at ±1e-13); half a top face gone with the pocket in it, the rim touching
    the pocket's footprint at one corner (0.7 % high at ±2e-14).  :func:`bare_vertices` asks the same of
    vertices whose faces form a flat face of the part by themselves; here one face in ``P`` suffices, since
    ``P`` is the plane the whole rim lies in, not just that face's own.

    ``slabs`` is what :func:`hole_doubt_volumes` fills (``has``, ``normal``, ``origin``, ``half_width``).
    ``excused`` (n,) bool, optional: rim vertices that do not count (the convex reading's vertices inside a flat
    face, :func:`inner_face_vertices`).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    out = np.zeros(n_loops, dtype=bool)
    if not n_loops or not len(edges) or not len(f):
        return out
    margin = _round_off(v)
    tol = flat_rtol * np.asarray(radius, dtype=np.float64) + margin
    flat = slabs["has"] & (slabs["half_width"] <= tol)
    if not flat.any():
        return out
    e = np.asarray(edges, dtype=np.int64)
    # (rim vertex, loop) pairs of the flat rims, sorted by vertex; each face at such a vertex, once per pair
    pairs = _sorted_pairs(e.reshape(-1), np.repeat(label, 2), n_loops)
    pairs = pairs[flat[pairs[:, 1]]]
    first = np.searchsorted(pairs[:, 0], np.arange(n))
    count = np.bincount(pairs[:, 0], minlength=n)
    fi, ci = np.nonzero(count[f] > 0)
    reps = count[f[fi, ci]]
    pair = np.repeat(first[f[fi, ci]], reps) + (np.arange(int(reps.sum())) - np.repeat(np.cumsum(reps) - reps, reps))
    face, loop = np.repeat(fi, reps), pairs[pair, 1]
    corners = v[f[face]] - slabs["origin"][loop][:, None, :]
    off = np.abs(np.einsum("ijk,ik->ij", corners, slabs["normal"][loop])).max(axis=1)
    off_p = np.bincount(pair, weights=off > tol[loop], minlength=len(pairs)) > 0
    if excused is not None:
        off_p |= np.asarray(excused, dtype=bool)[pairs[:, 0]]
    out[pairs[~off_p, 1]] = True
    return out


#: A bare rim vertex is read as inside its flat face (:func:`inner_face_vertices`) when the faces left at it turn
#: round it by more than π plus this margin, rad (about 0.6°: far above round-off and quantisation of the corner
#: angles, far below a fan's missing wedge of one triangle on the coarsest cap the benchmarks hold, 7.5°).
INNER_TURN_MARGIN = 0.01


def inner_face_vertices(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, bare: np.ndarray, *,
                        margin: float = INNER_TURN_MARGIN) -> np.ndarray:
    """Bare rim vertices that the convex reading puts inside their flat face, (n,) bool.

    A bare rim vertex ``x`` (:func:`bare_vertices`: every face left at it lies in one plane ``P``) is read two
    ways.  On a surface with no vertex inside its flat faces (a CAD tessellation) ``x`` lay on a loop of its flat
    face, where another surface met it (a feature's footprint), and the hole took that surface.  Under
    :data:`~.hole_assumptions.CONVEX` (the part ``K`` is convex), ``F = K ∩ P`` is a convex face holding the faces
    left at ``x``; when those faces turn round ``x`` by more than π, their directions at ``x`` span more than a
    half-plane, so every direction in ``P`` is a positive combination of two of them, and ``F`` (convex) holds a
    disc round ``x``: ``x`` is *inside* ``F``, the part's surface near ``x`` is ``F`` itself, and the hole there
    is a piece of ``F`` (as on a cap triangulated as a fan, whose centre a hole takes a wedge from).  So, with
    ``K`` convex, such a vertex cannot be a loop vertex of its face, and the two readings contradict each other:
    **the file cannot tell a convex part with a vertex inside a flat face from a part with a pocket taken whole
    whose footprint corner kept more than π of the face round it.**  The rule taken here: a bare vertex turning by
    more than π is read as inside its face (the convex reading, named as ``convex``'s limit) *unless* one of its
    two rim neighbours is such a vertex too (a run of them along the rim is a footprint's side, as a pocket taken
    whole with the faces round it leaves: two corners of one footprint edge; a fan's centre has one).  A bare
    vertex turning by π or less keeps withdrawing the convex bound (a corner of its face, where another face met
    it: the footprint of a feature, or an edge of the part whose other face the hole took; the file cannot tell).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    edges : (k, 2) int
        The boundary edges.
    bare : (n,) bool
        :func:`bare_vertices`.
    margin : float
        ``INNER_TURN_MARGIN``, rad.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e = np.asarray(edges, dtype=np.int64)
    n = len(v)
    out = np.zeros(n, dtype=bool)
    candidate = np.asarray(bare, dtype=bool)
    if not candidate.any() or not len(f) or not len(e):
        return out
    at = np.flatnonzero(candidate[f].any(axis=1))
    turn = np.zeros(n)
    for k in range(3):              # the corner angle at corner k of each face at a bare vertex, summed per vertex
        corner = f[at, k]
        keep = candidate[corner]
        p = v[corner[keep]]
        a = v[f[at[keep], (k + 1) % 3]] - p
        b = v[f[at[keep], (k + 2) % 3]] - p
        angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
        turn += np.bincount(corner[keep], weights=angle, minlength=n)
    wide = candidate & (turn > np.pi + margin)
    # a wide vertex with a wide rim neighbour: a run along the rim (a footprint's side), not a face's inside
    paired = np.zeros(n, dtype=bool)
    both = wide[e[:, 0]] & wide[e[:, 1]]
    paired[e[both].reshape(-1)] = True
    out = wide & ~paired
    return out


def _round_off(v: np.ndarray) -> float:
    """16 ulp of the largest coordinate: the margin every plane distance here carries."""
    scale = float(np.max(np.abs(v))) if len(v) else 0.0
    return 16.0 * float(np.finfo(np.float64).eps) * max(scale, 1e-300)


def _vertex_flatness(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per vertex, how flat its faces lie: ``(g, unit, least, size)``, the faces of nonzero area and their unit
    normals, and for each vertex the least cosine between one of its faces' normals and their area-weighted mean
    (1 where all lie in one plane) and that mean's length (0: no face, or normals cancelling)."""
    n = len(v)
    # the cross product as numpy.cross forms it (each product, then the difference), bit for bit, without its
    # axis shuffling (0.19 -> 0.12 s at 1.3M faces)
    a = v[f[:, 0]]
    u = v[f[:, 1]] - a
    w = np.subtract(v[f[:, 2]], a, out=a)
    normal = np.empty_like(u)
    for axis, (p, q) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.multiply(u[:, p], w[:, q], out=normal[:, axis])
        normal[:, axis] -= u[:, q] * w[:, p]
    del a, u, w                                   # the peak of a hole's bounds is here: free before the sums
    area = np.linalg.norm(normal, axis=1)
    good = area > 0
    if not good.all():
        normal, area = normal[good], area[good]
    g, unit = f[good], normal / area[:, None]
    # the sum of the normals at each vertex, added in the order corner 0 of every face, corner 1, corner 2
    # (bincount adds its weights in index order, as np.add.at does, at a tenth of the time: issue 25)
    corner_vertex = g.T.reshape(-1)
    mean = np.empty((n, 3))
    for axis in range(3):
        mean[:, axis] = np.bincount(corner_vertex, weights=np.tile(normal[:, axis], 3), minlength=n)
    del corner_vertex, normal, area
    size = np.linalg.norm(mean, axis=1)
    mean_unit = mean / np.where(size > 0, size, 1.0)[:, None]
    least = np.ones(n)
    for k in range(3):
        np.minimum.at(least, g[:, k], np.einsum("ij,ij->i", unit, mean_unit[g[:, k]]))
    return g, unit, least, size


def _flat_off_rim_nearby(v: np.ndarray, f: np.ndarray, edges: np.ndarray, *,
                         flat_cosine: float = FLAT_VERTEX_COSINE) -> np.ndarray:
    """Where a flat rim vertex proves nothing, (n,) bool: everywhere when some vertex off the rims has all its
    faces within ``acos(flat_cosine)`` of one plane (the surface has vertices inside its flat faces, so it is
    not tessellated the CAD way, and a rim vertex may be one of them: robot parts with Steiner points inside
    flat faces lost their exact flat answers to the local reading), else nowhere."""
    n = len(v)
    g, unit, least, size = _vertex_flatness(v, f)
    on_rim = np.zeros(n, dtype=bool)
    on_rim[np.asarray(edges, dtype=np.int64).reshape(-1)] = True
    off = (least >= flat_cosine) & (size > 0) & ~on_rim
    anywhere: np.ndarray = np.full(n, bool(off.any()))
    return anywhere


#: Most (ring face, rim vertex) pairs measured by :func:`hole_doubt_volumes` (a few seconds); beyond it every
#: hole keeps its whole ball (a bound that needs no ring).
RING_WORK_LIMIT = 200_000_000
#: (ring face, rim vertex) pairs measured at once (bounds the memory: ~100 MB).
RING_CHUNK = 2_000_000


def _engulfing(v: np.ndarray, f: np.ndarray, centre: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Holes whose ball holds every vertex of the surface left, (n_loops,) bool.

    Then nothing says which side of the rim is the hole: what remains may be the small part (a sphere less all
    but a cap at its pole, the ring nearly in the rim's plane), and the slab and the capsule, which read the
    hole as the rim's own small disc, stated ±40 % for a solid 1,000 times larger (found by the generated
    spherical-cap test of ``tests/test_hole_footprints.py``, height −0.969).  Such a hole keeps its whole ball.
    """
    used = v[np.flatnonzero(np.bincount(f.ravel(), minlength=len(v)))] if len(f) else v[:0]   # np.unique's, sorted
    out = np.zeros(len(radius), dtype=bool)
    if not len(used):
        return out
    lo, hi = used.min(axis=0), used.max(axis=0)
    # a ball holding every vertex has a radius of at least half the box's longest side: check only those
    for k in np.flatnonzero(radius >= 0.5 * float(np.max(hi - lo)) * (1 - 1e-12)).tolist():
        out[k] = float(np.max(np.linalg.norm(used - centre[k], axis=1))) <= radius[k]
    return out


def _alone(centre: np.ndarray, radius: np.ndarray, *, chunk: int = 512) -> np.ndarray:
    """Holes whose ball meets no other hole's ball, (n,) bool: only those get the capsule.

    A band round a handle (a washer's sector taken top, walls and bottom) leaves two rims joined by the missing
    surface, which the bound does not cover (each rim is assumed to close over its own disc).  Where the two
    balls are disjoint the band must leave both, so the ball assumption is false there too and nothing is lost;
    where they meet (the band 25° of a washer, its rims 18 × 4 across: balls of radius 9.2, 13 apart) the balls
    happened to hold it, and a capsule as thin as the rims would not (benchmark case 25-15-crack_hole: 7.0 %
    off at a stated ±6.5 %)."""
    n = len(radius)
    out = np.ones(n, dtype=bool)
    if n > chunk and np.isfinite(centre).all() and np.isfinite(radius).all() and (radius >= 0).all():
        pairs = _meeting_candidates(centre, radius)
        if pairs is not None:                 # the same test as the tree's candidates get below
            i, j = pairs
            gap = np.linalg.norm(centre[i] - centre[j], axis=1)
            meet = gap <= radius[i] + radius[j]
            out[i[meet]] = False
            out[j[meet]] = False
            return out
        # Candidates from a k-d tree (scattered holes: 60,000 balls, all pairs 170 s and 744 MB): each meeting
        # pair (gap <= r_i + r_j) lies within 2 max(r_i, r_j) of the larger ball's centre, so querying every
        # centre within twice its own radius (widened by 1e-9 for the tree's own rounding) finds it from that
        # side; the same test as below then decides each candidate, in the same arithmetic.
        from scipy.spatial import cKDTree
        tree = cKDTree(centre)
        near = tree.query_ball_point(centre, 2.0 * radius * (1.0 + 1e-9) + 1e-300, return_sorted=False)
        counts = np.fromiter((len(x) for x in near), dtype=np.int64, count=n)
        i = np.repeat(np.arange(n), counts)
        j = np.fromiter((k for x in near for k in x), dtype=np.int64, count=int(counts.sum()))
        keep = i != j
        i, j = i[keep], j[keep]
        gap = np.linalg.norm(centre[i] - centre[j], axis=1)
        meet = gap <= radius[i] + radius[j]
        out[i[meet]] = False
        out[j[meet]] = False
        return out
    for lo in range(0, n, chunk):
        gap = np.linalg.norm(centre[lo:lo + chunk, None, :] - centre[None, :, :], axis=2)
        meet = gap <= radius[lo:lo + chunk, None] + radius[None, :]
        meet[np.arange(len(meet)), lo + np.arange(len(meet))] = False
        out[lo:lo + chunk] = ~meet.any(axis=1)
    return out


#: Balls :func:`_meeting_candidates` pairs with every centre one at a time (the largest; the rest share a grid).
MEETING_LARGEST = 64
#: Most candidate pairs per ball :func:`_meeting_candidates` lists before leaving the balls to the k-d tree.
MEETING_PAIRS_PER_BALL = 64


def _meeting_candidates(centre: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Pairs ``(i, j)``, ``i ≠ j``, among which are all balls that meet (``|c_i − c_j| ≤ r_i + r_j``), as two
    (p,) int64 arrays; None where the grid would be too fine or list too many pairs (the caller's k-d tree
    then), so that :func:`_alone` needs no scipy (its import was ~0.8 s of CPU of a scattered-holes repair).

    The :data:`MEETING_LARGEST` largest balls are paired with every centre their box can reach (``|Δx| ≤ r_i +
    r_j`` per axis, widened by 1e-6: every meeting pair passes).  The others, of radius at most ``R``, lie in
    cubic cells of side ``h = 2R (1 + 1e-6)``: two of them that meet are within ``2R`` per axis, so their cells
    differ by at most one per axis (the margin covers the rounding of ``(c − lo) / h`` below 2^20 cells per
    axis); each is paired with the balls of its own cell and of the 13 neighbours after it in (x, y, z) order,
    so each pair of neighbouring cells is read from its lower one.  Duplicates are harmless (the caller only
    marks balls).  Centres and radii finite, radii ≥ 0 (the caller's condition).
    """
    n = len(radius)
    large = np.argsort(radius, kind="stable")[max(n - MEETING_LARGEST, 0):]
    small = np.ones(n, dtype=bool)
    small[large] = False
    rest = np.flatnonzero(small)
    limit = MEETING_PAIRS_PER_BALL * n
    firsts: list[np.ndarray] = []
    seconds: list[np.ndarray] = []
    by_x = np.argsort(centre[:, 0], kind="stable")
    sorted_x = centre[by_x, 0]
    widest = float(radius.max())
    for k in large.tolist():                        # bounded by MEETING_LARGEST
        # the centres within r_k + max r in x first (a sorted axis), then the box of each pair
        span = (radius[k] + widest) * (1.0 + 1e-6)
        near = by_x[np.searchsorted(sorted_x, centre[k, 0] - span, side="left"):
                    np.searchsorted(sorted_x, centre[k, 0] + span, side="right")]
        reach = (radius[k] + radius[near]) * (1.0 + 1e-6)
        hit = near[(np.abs(centre[near] - centre[k]) <= reach[:, None]).all(axis=1)]
        hit = hit[hit != k]
        firsts.append(np.full(len(hit), k, dtype=np.int64))
        seconds.append(hit.astype(np.int64))
    if len(rest):
        big = float(radius[rest].max())
        lo = centre[rest].min(axis=0)
        extent = float(np.max(centre[rest].max(axis=0) - lo))
        h = 2.0 * big * (1.0 + 1e-6)
        if not h > 0 or extent / h >= 2.0 ** 20:
            if h > 0:
                return None                         # cells too fine for 21 bits per axis: the tree
            h = max(extent, 1.0)                    # every small ball a point: equal centres only, one cell
        cell = np.floor((centre[rest] - lo) / h).astype(np.int64) + 1        # 1 .. 2^20: neighbours in range
        side = np.int64(2 ** 21)
        key = (cell[:, 0] * side + cell[:, 1]) * side + cell[:, 2]
        order = np.argsort(key, kind="stable")
        sorted_key = key[order]
        total = sum(len(x) for x in seconds)
        # the cell itself and the 13 neighbours after it in (x, y, z) order: each pair of neighbouring cells
        # once, from its lower cell (the caller marks both balls of a pair)
        for dx, dy, dz in [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
                           if (dx, dy, dz) >= (0, 0, 0)]:
            want = sorted_key + (dx * side + dy) * side + dz          # sorted needles: searched in one sweep
            start = np.searchsorted(sorted_key, want, side="left")
            count = np.searchsorted(sorted_key, want, side="right") - start
            total += int(count.sum())
            if total > limit:
                return None                 # too many pairs per ball: the tree
            owner = np.repeat(order, count)
            within = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
            other = order[np.repeat(start, count) + within]
            keep = other != owner
            firsts.append(rest[owner[keep]])
            seconds.append(rest[other[keep]])
    if not firsts:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(firsts), np.concatenate(seconds)


#: Most (plane, hull vertex) pairs :func:`convex_hole_bound` checks (beyond it no convex bound is tried).
CONVEX_WORK_LIMIT = 50_000_000
#: What remains counts as convex when no vertex lies farther than this share of the largest coordinate
#: (times 16 ulp) outside the plane of a face: round-off, not quantisation or design.
CONVEX_ROUND_OFF = 1024.0


def convex_hole_bound(vertices: np.ndarray, faces: np.ndarray, patched_volume: float
                      ) -> tuple[float, np.ndarray] | None:
    """Volume in doubt of every hole at once when what remains of the surface is convex, m³, with the corners of
    the region in doubt ((k, 3) m); None where it does not apply.

    **Fourth assumption: where the faces that remain are convex, so is the complete part** ``K``.  The check:
    every vertex of the given faces lies on the inner side of the plane of every given face (within
    ``CONVEX_ROUND_OFF`` × 16 ulp of the coordinates; the planes are moved out by the largest excess found).
    Then each given face lies on ``∂K`` and its plane supports ``K``, so ``K`` lies in the polytope ``U``
    the planes enclose (their half-spaces' intersection, :class:`scipy.spatial.HalfspaceIntersection`), and
    the patched solid ``P`` in ``K`` (its surface, the given faces and the cones in the rims' convex hulls,
    lies in ``K``).  So ``vol P ≤ vol K ≤ vol U``: the volume in doubt is ``vol U − vol P``, with no ball at
    all, and the region in doubt lies in ``U`` (its corners bound the centre of mass).  ``U`` must be bounded
    (the planes left must surround the part); it is ``K`` itself when every plane of ``K`` keeps a face.  What
    the check cannot see: a dent or pocket the holes took whole (the rest is convex, the part is not); the
    bare-vertex checks see it on CAD tessellations (footprints), not on others: the stated limit, as for the
    slab.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        The given faces, wound outward (as the patched surface is).
    patched_volume : float
        ``vol P``, m³.
    """
    from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if not len(f) or not patched_volume > 0:
        return None
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    size = np.linalg.norm(normal, axis=1)
    keep = size > 0
    if not keep.any():
        return None
    unit = normal[keep] / size[keep, None]
    offset = np.einsum("ij,ij->i", unit, v[f[keep, 0]])
    tol = CONVEX_ROUND_OFF * _round_off(v)
    # a reflex edge already shows what remains is not convex: a face's vertex outside a neighbour's plane by more
    # than the tolerance plus what rounding the planes to 12 decimals below can move it (5e-13 per coefficient,
    # and a few ulp of the offset and of the products: 1e-12 + 8 ulp of the scale, times the 1-norm of a point
    # plus one) puts some vertex outside that rounded plane by more than the tolerance, where the full check
    # returns None too; so the result is the same, without the convex hull and the (planes × corners) test on a
    # part that is plainly not convex (cover11: parts whose bare rim vertices no longer skip this bound spent
    # ~0.5 s CPU here)
    scale = float(np.abs(v[f]).max())
    slack = (1e-12 + 8.0 * float(np.finfo(np.float64).eps) * max(scale, 1.0)) * (3.0 * scale + 1.0)
    if _reflex_edge_excess(v, f[keep], unit, offset) > tol + slack:
        return None
    planes = np.unique(np.round(np.column_stack([unit, offset]), 12), axis=0)
    used = np.unique(f)
    try:
        hull = ConvexHull(v[used])
    except (QhullError, ValueError):
        return None
    corners = v[used][hull.vertices]
    if len(planes) * len(corners) > CONVEX_WORK_LIMIT:
        return None
    excess = np.full(len(planes), -np.inf)
    for lo in range(0, len(corners), 4096):
        chunk = corners[lo:lo + 4096]
        excess = np.maximum(excess, (chunk @ planes[:, :3].T - planes[:, 3]).max(axis=0))
    if float(excess.max()) > tol:
        return None                      # what remains is not convex
    if _plane_unattested_at_rim(v, f, planes, tol + 1e-12 * (1.0 + float(np.abs(v[used]).max()))):
        return None                      # a hole took a flat face up to its border: a feature may have gone too
    if not normals_surround_origin(planes[:, :3]):
        return None                      # the planes left do not close the part in (an open direction)
    shift = max(float(excess.max()), 0.0) + _round_off(v)
    inside = v[used].mean(axis=0)
    slack = planes[:, 3] + shift - planes[:, :3] @ inside
    if float(slack.min()) <= 10 * shift:
        return None
    halfspaces = np.column_stack([planes[:, :3], -(planes[:, 3] + shift)])
    try:
        with np.errstate(divide="ignore", invalid="ignore"):     # unbounded regions: non-finite points, refused below
            region = HalfspaceIntersection(halfspaces, inside)
        points = region.intersections
        if not np.all(np.isfinite(points)) or float(np.abs(points).max()) > 1e6 * max(float(np.abs(v).max()), 1e-300):
            return None                  # the planes left do not close the part in
        volume = float(ConvexHull(points).volume)
    except (QhullError, ValueError):
        return None
    if not volume >= patched_volume * (1 - 1e-9):
        return None
    return round_up(max(volume - patched_volume, 0.0) + 1e-12 * volume), points


def normals_surround_origin(normals: np.ndarray) -> bool:
    """Whether ``{x : normals x ≤ b}`` is bounded for every ``b`` under which it is not empty: no direction
    ``u ≠ 0`` with ``normals u ≤ 0``, i.e. the origin strictly inside the convex hull of the unit normals
    (a margin of 1e-9).  A region open along some ray is never given a volume: ``HalfspaceIntersection``
    assumes a bounded region, and finite intersection points or a bounded inscribed ball do not show one."""
    from scipy.spatial import ConvexHull, QhullError

    n = np.asarray(normals, dtype=np.float64)
    if len(n) < 4:
        return False
    unit_normals = n / np.linalg.norm(n, axis=1)[:, None]
    try:
        return bool(float(ConvexHull(unit_normals).equations[:, 3].max()) < -1e-9)
    except (QhullError, ValueError):
        return False                          # the normals span no solid: open


def _reflex_edge_excess(v: np.ndarray, f: np.ndarray, unit: np.ndarray, offset: np.ndarray) -> float:
    """The farthest any face's vertex lies outside the plane of a face sharing an edge with it, m (−inf where no
    two faces share an edge): a lower bound of the excess :func:`convex_hole_bound` measures over every vertex and
    plane, at O(faces).  ``f`` (m, 3) the faces of nonzero area, ``unit`` and ``offset`` their planes."""
    key, _ = edge_keys(f, len(v))
    order = np.argsort(key, kind="stable")
    ranked = key[order]
    same = np.flatnonzero(ranked[1:] == ranked[:-1])
    if not len(same):
        return float("-inf")
    a, b = order[same] // 3, order[same + 1] // 3
    worst = float("-inf")
    for x, y in ((a, b), (b, a)):         # each face's corners against the other face's plane
        excess = np.einsum("ijk,ik->ij", v[f[y]], unit[x]).max(axis=1) - offset[x]
        worst = max(worst, float(excess.max()))
    return worst


#: Most (rim vertex, plane it lies on) pairs :func:`_plane_unattested_at_rim` examines (beyond: no convex bound).
CONVEX_RIM_PAIRS = 200_000


def _plane_unattested_at_rim(v: np.ndarray, f: np.ndarray, planes: np.ndarray, tol: float) -> bool:
    """Whether a rim vertex lies on the plane of a remaining face but keeps no face in that plane.

    The convex reading (:func:`convex_hole_bound`) extends the plane of every face left over the holes.  A rim
    vertex on such a plane that keeps no face in it is where the hole took every face of that flat face around
    the vertex, up to the face's border: the face is not seen there, and a feature standing on it or sunk into it
    inside the rim (a rib, a boss, a pocket) may have gone with the hole, which the planes left cannot see (a
    generated box less a rib and the faces round it: the polytope of its planes stated ±11 %, 12 % off; found by
    ``tests/test_hole_capsules.py``).  The convex bound is then not taken.  A rim vertex on a plane it keeps a
    face of (a hole inside a flat face, or across a whole face: the octahedron missing one) says nothing.

    ``planes`` (p, 4): unit normal and offset of each distinct plane; ``tol`` m: a point "on" a plane.
    """
    from .rims import boundary_edges

    rim = np.unique(boundary_edges(f, len(v)))
    if not len(rim):
        return False
    if len(rim) * len(planes) > CONVEX_WORK_LIMIT:
        return True
    rows, cols = np.nonzero(np.abs(v[rim] @ planes[:, :3].T - planes[:, 3]) <= tol)
    if len(rows) > CONVEX_RIM_PAIRS:
        return True
    corner_order = np.argsort(f.reshape(-1), kind="stable")
    corner_start = np.searchsorted(f.reshape(-1)[corner_order], rim)
    corner_end = np.searchsorted(f.reshape(-1)[corner_order], rim, side="right")
    for r, c in zip(rows.tolist(), cols.tolist()):
        at = corner_order[corner_start[r]:corner_end[r]] // 3
        off = np.abs(v[f[at]] @ planes[c, :3] - planes[c, 3]).max(axis=1)
        if not (off <= tol).any():
            return True
    return False


def _contradicted(evidence: RimEvidence, radius: np.ndarray, size: np.ndarray, *,
                  assumed: np.ndarray | None = None) -> str:
    """Why the faces left at some hole's rim contradict the bound's assumption (empty when none does).

    The bound assumes the missing surface of each hole stays near its rim (the ball, cut to the slab).  A hole
    that is an island in a flat face *and* has a bare rim vertex (:class:`RimEvidence`) contradicts it: on a
    surface with no vertex inside its flat faces the rim was a loop of the face, the footprint of something
    standing on it or sunk into it (a boss, a pocket, a connector housing) that the hole took whole, whose
    height nothing in the file bounds.  ``assumed`` (n_loops,) bool: holes the user stated lost a flat piece of
    the face (``hole_assumptions.FLAT_ISLANDS``), not refused.  The message ends by naming that option.
    """
    refused = evidence.flat_all_round & (evidence.bare > 0)
    if assumed is not None:
        refused = refused & ~assumed
    found = np.flatnonzero(refused)
    if not len(found):
        return ""
    k = int(found[np.argmax(radius[found])])
    many = len(found) != 1
    return (f"{len(found)} hole{'s' if many else ''} (the largest a rim of {int(size[k])} vertices, "
            f"{round_up(2 * float(radius[k])):.3g} m across) {'are islands' if many else 'is an island'} in a flat "
            "face whose rim kept no face off that face, on a surface with no vertex inside its flat faces: the rim "
            "is the footprint of a feature standing on the face or sunk into it (a boss, a pocket) that the hole "
            "took whole, and nothing in the file bounds its height (expected a rim that keeps a face of the "
            "surface beside it)")


def flat_islands(evidence: RimEvidence, level: np.ndarray | None = None) -> np.ndarray:
    """Holes whose only evidence of a flat missing surface is their own flatness, (n_loops,) bool: the rule that
    a slab of (near) zero width, or a (near) zero slope, is no evidence (issue 21, "no bound of 0 unless the
    answer is exact").  ``level`` (n_loops,) bool: :func:`level_rings`, when the caller has it.

    A hole that is an island in a flat face (:attr:`RimEvidence.flat_all_round`: the rim and every face left at
    a rim vertex lie within ``FLAT_RIM_RTOL`` of the ball's radius of one plane) keeps no face that leaves that
    plane, so nothing in the file tells a flat lid (a missing piece of the face) from a dome, boss, dimple or
    pocket taken whole with a flat ring round it: both leave the same rim with the same faces at it.  Every
    narrower reading of such a hole collapses to the rim's own plane: the ``flat`` slab and the ``planar`` slab
    are as wide as the rim is thick (0 plus 16 ulp), ``bend`` and ``graph`` get the slope 0 of the level faces
    round the rim, and ``capsule`` (a rib taken whole) and ``convex`` (a dimple taken whole) see no more.  A dome
    taken whole on a grid-meshed face (vertices inside its flat faces, so no bare rim vertex shows the footprint)
    was stated ±3.8e-14 of the mass while 0.40 % off, and review 13's fuzzer found 22 of 23 such estimates off
    0.1-3 % inside bounds of 1e-13..8e-4.  **The rule**: these holes keep the uncut ball over their rim
    (assumption ``ball``, which holds any dome or dimple no taller than the rim is wide), and the estimate is
    refused where that is not useful (:func:`~.uncertainty.check_useful`); where a rim vertex is also bare (a CAD
    tessellation: the footprint is proven) the hole is refused outright (:func:`_contradicted`).  A rim with a
    face beside it that leaves the plane (a crease: ``planar``'s lost flat face of a prism; a curved surface:
    ``bend``'s slope) is evidence and keeps the narrower bounds.

    **A level ring is an island too** (review 14): a hole whose every face touching the rim lies within
    acos(``LEVEL_RING_COSINE``) ≈ 1.1° of the rim's mean plane (:func:`level_rings`; the angle below which a
    vertex is flat, a slope of 0.02) shows no slope either, only at a tolerance the island test above does not
    reach: a ring curved by 4e-4 (a bowl ``c (x² + y²)`` round a dimple taken whole) fails that test, which
    measures against the plane of the largest face at the rim, and ``bend`` then bounded the dimple by the ring's
    slope of 7e-4: ±3.7e-5 of the mass while 8.7e-4 off; with ``bend`` withdrawn alone, the ``flat`` slab (as
    thin as the rim strays from a ring face's plane) missed the next one the same way.  The file cannot tell a
    gently curved surface continuing across the hole from a feature taken whole with a nearly level ring round
    it, and every narrower reading is then about the ring's slope times the hole's size, however deep the
    feature: such a hole keeps the uncut ball like an island (the user's ``flat-islands`` stays for the islands
    of the test above: a level ring need not be a flat face).  Where some face at the rim stands more than 1.1°
    off, its slope is evidence and ``bend``'s stated limit (a feature steeper than that) is the named one.
    """
    islands: np.ndarray = np.asarray(evidence.flat_all_round, dtype=bool).copy()
    if level is not None:
        islands |= np.asarray(level, dtype=bool)
    return islands


def flat_island_doubt(vertices: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                      centre: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Volume in doubt of each hole under the user's ``flat-islands`` assumption, and the slab's half-width:
    ``(doubt, half_width)``, (n_loops,) m³ and m.

    Assumption (``hole_assumptions.FLAT_ISLANDS``, stated by the user, never taken by default): a hole that is an
    island in a flat face lost a flat piece of that face, so its missing surface ``M`` lies within ``δ`` of the
    rim's least-squares plane ``P`` — the slab the ``planar`` reading uses (:func:`planar_rim_doubt`: ``P``
    through the rim's centroid ``c̄``, normal the eigenvector of the least eigenvalue of
    ``Σ (x − c̄)(x − c̄)ᵀ``; ``δ`` the rim's largest distance from ``P`` plus 16 ulp of the coordinates).  The cone
    to ``c̄`` lies in the rim's convex hull, hence in that slab, so the patched and the true solid differ only
    inside ball ∩ slab (:func:`ball_slab_volume`).  For an exactly planar rim ``M`` minus the cone is a planar
    2-cycle, which encloses nothing: the doubt is round-off.  Unlike ``planar``, no crease is asked of the faces
    beside the rim and a rim of three corners is taken (the flat face round it, not the rim, is the evidence the
    user relies on); what the assumption cannot see — a boss or pocket taken whole — is its stated limit.
    """
    v = np.asarray(vertices, dtype=np.float64)
    if not n_loops:
        return np.full(0, np.inf), np.full(0, np.inf)
    _, mean, normal, delta, _, _ = _rim_planes(v, edges, label, n_loops)
    half = delta + _round_off(v)
    offset = np.einsum("ij,ij->i", centre - mean, normal)
    doubt: np.ndarray = ball_slab_volume(radius, offset, half)
    return doubt, half


def _rim_planes(v: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each rim's least-squares plane: ``(count, mean, normal, delta, spread, d)`` — the rim's distinct vertices
    (n_loops,), their centroid ``c̄`` (n_loops, 3) m, the unit eigenvector of the least eigenvalue of
    ``Σ (x − c̄)(x − c̄)ᵀ`` (n_loops, 3), the largest distance of a rim vertex from the plane (n_loops,) m, the
    largest distance from ``c̄`` (n_loops,) m, and each (loop, vertex) pair's offset from its ``c̄``."""
    pairs = _sorted_pairs(np.repeat(label, 2), edges.reshape(-1), len(v))    # (numpy.unique(axis=0)'s rows)
    loop_of, vertex_of = pairs[:, 0], pairs[:, 1]
    count = np.bincount(loop_of, minlength=n_loops).astype(np.float64)
    mean: np.ndarray = np.stack([np.bincount(loop_of, weights=v[vertex_of, i], minlength=n_loops) for i in range(3)],
                                axis=1) / np.maximum(count, 1.0)[:, None]
    d = v[vertex_of] - mean[loop_of]
    scatter = np.zeros((n_loops, 3, 3))
    for i in range(3):
        for j in range(3):
            scatter[:, i, j] = np.bincount(loop_of, weights=d[:, i] * d[:, j], minlength=n_loops)
    _, vectors = np.linalg.eigh(scatter)
    normal = vectors[:, :, 0]
    delta = np.zeros(n_loops)
    np.maximum.at(delta, loop_of, np.abs(np.einsum("ij,ij->i", d, normal[loop_of])))
    spread = np.zeros(n_loops)
    np.maximum.at(spread, loop_of, np.linalg.norm(d, axis=1))
    return count, mean, normal, delta, spread, d


#: A face beside the rim steeper than this (its normal's angle with the rim's mean plane's normal, degrees) leaves
#: :func:`bend_doubt_volumes` no slope to bound (the missing surface may fold over itself): that hole keeps the
#: other bounds.
BEND_MAX_DEGREES = 80.0


@frozen_value
class RimFans:
    """Each rim's fan and the steepest face touching it, as :func:`level_rings` and :func:`bend_doubt_volumes`
    read them (:func:`rim_fans`: computed once for both, the same arrays either way).

    Attributes
    ----------
    apex_of_edge : (k, 3) float
        m: per boundary edge ``a → b``, its loop's apex ``c``.
    to_a, to_b : (k, 3) float
        m: ``a − c`` and ``b − c``.
    has_normal : (n_loops,) bool
        The fan's area vector ``Σ (a − c) × (b − c)`` is non-zero.
    normal : (n_loops, 3) float
        Its unit (0 where ``has_normal`` is False).
    star : (n_loops,) bool
        The fan projected onto the plane ⟂ ``normal`` is star-shaped round ``c`` (one full turn, none backward).
    least : (n_loops,) float
        The least cosine between ``normal`` and the normal of a face touching the rim at a rim vertex (``inf``
        where none; negative for a face facing against the fan).
    """

    apex_of_edge: np.ndarray
    to_a: np.ndarray
    to_b: np.ndarray
    has_normal: np.ndarray
    normal: np.ndarray
    star: np.ndarray
    least: np.ndarray


def rim_fans(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
             apex: np.ndarray) -> RimFans:
    """The :class:`RimFans` of the loops ``label`` (k,) of the boundary edges ``edges`` (k, 2) ``a → b``, apexes
    ``apex`` (n_loops, 3) m: pass it to :func:`level_rings` and :func:`bend_doubt_volumes` (``fans=``), which
    otherwise each compute it (issue 25: twice 0.5 s on a 1.3M-face sphere with 60,574 holes).

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
    edges : (k, 2) int
        Boundary edges ``a → b``.
    label : (k,) int
        The loop of each edge, below ``n_loops``.
    n_loops : int
    apex : (n_loops, 3) float
        m: each loop's cone apex.

    Returns
    -------
    RimFans
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e = np.asarray(edges, dtype=np.int64)
    return RimFans(*_fan_and_ring(v, f, e, np.asarray(label, dtype=np.int64), n_loops, np.asarray(apex)))


def _fan_and_ring(v: np.ndarray, f: np.ndarray, e: np.ndarray, label: np.ndarray, n_loops: int, apex: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each rim's fan and the steepest face touching it: ``(c, pa, pb, ok, normal, star, least)`` — per boundary
    edge ``a → b`` its loop's apex ``c`` and ``a − c``, ``b − c`` (k, 3); per loop whether the fan's area vector
    ``Σ (a − c) × (b − c)`` is non-zero, its unit ``normal`` (n_loops, 3), whether the projected fan is
    star-shaped round ``c``, and the least cosine ``least`` (n_loops,) between ``normal`` and the normal of a face
    touching the rim at any rim vertex (``inf`` where none; negative for a face facing against the fan)."""
    c = apex[label]
    pa, pb = v[e[:, 0]] - c, v[e[:, 1]] - c
    area_vec = np.cross(pa, pb)
    total = np.zeros((n_loops, 3))
    for axis in range(3):
        total[:, axis] = np.bincount(label, weights=area_vec[:, axis], minlength=n_loops)
    size = np.linalg.norm(total, axis=1)
    ok = size > 0
    normal = total / np.where(ok, size, 1.0)[:, None]
    nk = normal[label]
    ha, hb = np.einsum("ij,ij->i", pa, nk), np.einsum("ij,ij->i", pb, nk)
    ua, ub = pa - ha[:, None] * nk, pb - hb[:, None] * nk          # projections onto the plane, apex at 0
    signed = 0.5 * np.einsum("ij,ij->i", np.cross(ua, ub), nk)
    tiny = 1e-12 * np.bincount(label, weights=np.abs(signed), minlength=n_loops)
    backward = np.bincount(label, weights=signed < -tiny[label], minlength=n_loops) > 0
    turn = np.arctan2(2.0 * signed, np.einsum("ij,ij->i", ua, ub))
    turns = np.bincount(label, weights=turn, minlength=n_loops)
    star = ok & ~backward & (np.abs(turns - 2.0 * np.pi) <= 1e-6)
    # the steepest face touching each loop's rim (at any rim vertex: a face across a crease met at a rim corner
    # counts, so a hole whose rim touches a crease or a wall gets that slope), against the fan's normal
    rim = _sorted_pairs(np.r_[e[:, 0], e[:, 1]], np.r_[label, label], n_loops)      # (vertex, loop), by vertex
    first = np.searchsorted(rim[:, 0], np.arange(len(v)))
    count = np.searchsorted(rim[:, 0], np.arange(len(v)), side="right") - first
    fi, ci = np.nonzero(count[f] > 0)
    corner_vertex = f[fi, ci]
    reps = count[corner_vertex]
    face_of = np.repeat(fi, reps)
    within = np.arange(int(reps.sum())) - np.repeat(np.cumsum(reps) - reps, reps)
    which = np.repeat(first[corner_vertex], reps) + within
    loop_of_face = rim[which, 1]
    fa, fb, fc = (v[f[face_of, k]] for k in range(3))
    fn = np.cross(fb - fa, fc - fa)
    fsize = np.linalg.norm(fn, axis=1)
    good = fsize > 0
    cosine = np.where(good, -np.einsum("ij,ij->i", fn, normal[loop_of_face]) / np.where(good, fsize, 1.0), 1.0)
    least = np.full(n_loops, np.inf)
    np.minimum.at(least, loop_of_face, cosine)
    return c, pa, pb, ok, normal, star, least


def level_rings(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                apex: np.ndarray, *, level_cosine: float = LEVEL_RING_COSINE, fans: RimFans | None = None
                ) -> np.ndarray:
    """Holes whose every face touching the rim lies within ``acos(level_cosine)`` ≈ 1.1° of the rim's mean plane,
    (n_loops,) bool: a *level* ring (the rule of :func:`flat_islands`, which says why that is no evidence).

    The plane is the fan's (normal along ``Σ (a − c) × (b − c)`` over the rim edges ``a → b``, ``c`` the apex:
    the plane :func:`bend_doubt_volumes` measures slopes against), and the faces are those touching the rim at any
    rim vertex, as there.  Parameters as :func:`bend_doubt_volumes` (``fans``: :func:`rim_fans` of the same
    arguments, when the caller has it).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e = np.asarray(edges, dtype=np.int64)
    if not n_loops or not len(e) or not len(f):
        return np.zeros(n_loops, dtype=bool)
    if fans is None:
        fans = rim_fans(v, f, e, label, n_loops, apex)
    ok, least = fans.has_normal, fans.least
    level: np.ndarray = ok & np.isfinite(least) & (least >= level_cosine)
    return level


def bend_doubt_volumes(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray,
                       n_loops: int, apex: np.ndarray, *, max_degrees: float = BEND_MAX_DEGREES,
                       level_cosine: float = LEVEL_RING_COSINE, fans: RimFans | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Volume in doubt of each hole under the *bend* assumption, and how far its region reaches from the rim's
    mean plane: ``(doubt, height)``, (n_loops,) m³ and m, ``inf`` where the assumption cannot be applied.

    **Assumption** (:data:`~.hole_assumptions.BEND`): the missing surface ``M`` of a hole is the graph of a
    height ``g`` over the region ``Ω`` its rim bounds in the rim's mean plane ``Π`` (through the cone's apex
    ``c``, normal ``n``: the fan's area vector ``Σ (a − c) × (b − c)`` over the rim edges ``a → b``), and slopes
    against ``Π`` no more than the steepest face touching the rim (at a rim vertex): ``|∇g| ≤ L = tan θ``, ``θ`` the
    largest angle between such a face's normal and ``n``.  Faces at the rim's corners count, not only those across
    its edges: a hole whose rim touches a crease or a wall at a corner gets that slope (or none: past
    ``max_degrees``), which is what keeps a feature taken whole with the faces round its footprint, whose rim
    reaches the face's border, out of the bound's reach.  For a small hole on a faceted or smooth part that is
    the statement that the surface bends no more inside the hole than round it; it fails for a feature taken whole
    whose walls are steeper than the faces round its rim (a boss on a flat face), as the flat slab does.

    The bound.  Where the projected fan is star-shaped round ``c`` (every fan triangle ``T = (a, b, c)`` turns the
    same way in ``Π`` and the turns add up to one full turn, so the projected fan tiles ``Ω`` once), ``M`` and the
    cone are two graphs over ``Ω`` with the rim as common boundary, and the patched and true solids differ by
    ``∫_Ω |g − cone| dA``.  At ``p`` in the projection of ``T``, with ``r`` the nearest point of the rim edge
    ``ab`` (``g(r)`` the rim's height there, between ``h_a`` and ``h_b``), the Lipschitz bound gives
    ``|g(p) − g(r)| ≤ L |p − r|``, and the cone's height at ``p`` lies between the least and the largest of
    ``h_a, h_b, h_c``; so ``|g − cone|(p) ≤ L dist(p, ab) + s_T`` with ``s_T`` that spread.  The right side is a
    convex function of ``p``; its mean over a triangle is at most the mean of its values at the corners, which
    are ``s_T`` at ``a`` and ``b``: ``∫_T ≤ A_T (L dist(c, ab) / 3 + s_T)`` (``A_T`` the projected area).  The sum
    over the fan is the hole's volume in doubt, and every point of the region lies within
    ``max|h| + L max dist(c, ab)`` of ``Π`` (``height``).  A round-off margin of 16 ulp of the coordinates is
    added to every height.  Not applied (``inf``): a fan that is not star-shaped, a ring face steeper than
    ``max_degrees`` or facing against the fan.

    Nor to a *level* ring (every face touching the rim within ``acos(level_cosine)`` ≈ 1.1° of ``Π``,
    :func:`level_rings`): a near-zero slope is no evidence, by the rule of :func:`flat_islands` (the caller
    withdraws every narrower reading there; the check is repeated here so the bound is never stated alone).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    edges : (k, 2) int
        Boundary edges ``a → b`` (each the edge of one face in that direction), ``label`` (k,) their loop.
    apex : (n_loops, 3) float
        The cone's apex of each loop (the centroid of its rim vertices), m.
    max_degrees : float
        ``BEND_MAX_DEGREES``.
    level_cosine : float
        ``LEVEL_RING_COSINE``: a ring whose every face has at least this cosine with ``n`` is level (no bound).
    fans : RimFans, optional
        :func:`rim_fans` of the same vertices, faces, edges, labels and apexes, when the caller has it (computed
        here otherwise).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e = np.asarray(edges, dtype=np.int64)
    doubt = np.full(n_loops, np.inf)
    height = np.full(n_loops, np.inf)
    if not n_loops or not len(e) or not len(f):
        return doubt, height
    margin = _round_off(v)
    if fans is None:
        fans = rim_fans(v, f, e, label, n_loops, apex)
    pa, pb, normal, star, least = fans.to_a, fans.to_b, fans.normal, fans.star, fans.least
    nk = normal[label]
    ha, hb = np.einsum("ij,ij->i", pa, nk), np.einsum("ij,ij->i", pb, nk)
    ua, ub = pa - ha[:, None] * nk, pb - hb[:, None] * nk          # projections onto the plane, apex at 0
    signed = 0.5 * np.einsum("ij,ij->i", np.cross(ua, ub), nk)
    steep = ~(least >= np.cos(np.radians(max_degrees))) | ~(least > 0.0)     # a face at 90° bounds no graph
    level = least >= level_cosine                   # a level ring: no evidence (flat_islands)
    usable = star & ~steep & ~level
    # L = tan θ for the loops the bound applies to (cos θ ≥ cos max_degrees > 0); 0 for the others, whose doubt is
    # inf anyway (a ring face at 90° made L ~1e300 here, and L·dist·area overflowed on parts ~1 km across)
    cos_l = np.where(usable, least, 1.0)
    slope = np.sqrt(np.maximum(1.0 - cos_l ** 2, 0.0)) / cos_l
    # the apex's distance from each rim edge's segment, in the plane
    d = ub - ua
    dd = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.where(dd > 0, -np.einsum("ij,ij->i", ua, d) / np.where(dd > 0, dd, 1.0), 0.0), 0.0, 1.0)
    dist = np.linalg.norm(ua + t[:, None] * d, axis=1)
    spread = np.maximum(np.maximum(ha, hb), 0.0) - np.minimum(np.minimum(ha, hb), 0.0) + 2.0 * margin
    per_edge = np.abs(signed) * (slope[label] * dist / 3.0 + spread)
    total_doubt = np.bincount(label, weights=per_edge, minlength=n_loops)
    worst_h = np.zeros(n_loops)
    np.maximum.at(worst_h, label, np.maximum(np.abs(ha), np.abs(hb)))
    worst_d = np.zeros(n_loops)
    np.maximum.at(worst_d, label, dist)
    doubt[usable] = round_up_array(total_doubt[usable] * (1.0 + 1e-9))
    height[usable] = worst_h[usable] + slope[usable] * worst_d[usable] + 2.0 * margin
    return doubt, height


def round_up_array(values: np.ndarray) -> np.ndarray:
    """Each value moved one ulp away from zero (a sum of rounded terms, made an upper bound)."""
    out: np.ndarray = np.nextafter(values, np.inf)
    return out


#: A rim "lies in one plane" for :func:`planar_rim_doubt` when every rim vertex is within this share of the
#: ball's radius of the rim's least-squares plane (the same share as :data:`FLAT_RIM_RTOL`).
PLANAR_RIM_RTOL = FLAT_RIM_RTOL

#: The least angle, degrees, between the rim's plane and every face sharing an edge with the rim for
#: :func:`planar_rim_doubt`: the surface left meets the missing face at a crease of at least this, as the walls of
#: a prism, a box or a hull meet the face they lost (a hole in a smooth or gently curved surface meets it at the
#: tessellation's angle and keeps the other bounds).
PLANAR_MIN_CREASE_DEGREES = 30.0


@frozen_value
class PlanarRims:
    """Per hole, the planar-rim reading of :func:`planar_rim_doubt`.

    Attributes
    ----------
    applies : (n_loops,) bool
        The rim lies within ``half_width`` of one plane and meets every face beside it at a crease.
    doubt : (n_loops,) float
        m³: the volume of the ball over the rim within ``half_width`` of the plane (``inf`` where it does not
        apply).
    half_width : (n_loops,) float
        m: the rim's largest distance from its plane plus 16 ulp of the coordinates (``inf`` where none).
    normal : (n_loops, 3) float
        Unit normal of each rim's least-squares plane.
    origin : (n_loops, 3) float
        m: the centroid of each rim's vertices, on that plane.
    """

    applies: np.ndarray
    doubt: np.ndarray
    half_width: np.ndarray
    normal: np.ndarray
    origin: np.ndarray


def planar_rim_doubt(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                     centre: np.ndarray, radius: np.ndarray, *, rim_rtol: float = PLANAR_RIM_RTOL,
                     min_crease_degrees: float = PLANAR_MIN_CREASE_DEGREES) -> PlanarRims:
    """The volume in doubt of holes that are a missing flat face (assumption ``planar``), (n_loops,) m³.

    Assumption (``hole_assumptions.PLANAR``): a hole whose rim lies within ``δ`` of one plane ``P`` and whose
    faces beside the rim all meet ``P`` at a crease of at least ``min_crease_degrees`` lost a flat face: its
    missing surface ``M`` lies within ``δ`` of ``P`` (and, as every hole's, in the ball over the rim).  ``P`` is
    the least-squares plane of the rim's vertices (through their centroid ``c̄``, normal the eigenvector of the
    smallest eigenvalue of ``Σ (x − c̄)(x − c̄)ᵀ``), ``δ`` the rim's largest distance from it plus 16 ulp of the
    coordinates.  The cone to ``c̄`` lies in the rim's convex hull, hence within ``δ`` of ``P`` too, so the
    patched and the true solid differ only inside ball ∩ slab, whose volume :func:`ball_slab_volume` gives.

    Unlike the ``flat`` slab (:func:`hole_doubt_volumes`, the plane of a face *beside* the hole), ``P`` is the
    rim's own plane: a box or prism that lost a whole face, whose walls stand at 90° to the rim's plane, is
    bounded by ``±δ``.  A planar rim does *not* show that the missing surface is flat (a sphere cut by a plane
    leaves one): the crease keeps holes in smooth surfaces out, and the caller withdraws the reading where the
    surroundings lie on one curved quadric (:func:`~.hole_fills.curved_surroundings`) or where another fill than
    the cone was made.  What no evidence in the file shows (a dome or boss standing on a crease, taken whole)
    is the assumption's stated limit.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    edges : (k, 2) int
        Boundary edges; ``label`` (k,) the loop of each.
    centre, radius : (n_loops, 3), (n_loops,) float
        The ball over each rim.
    rim_rtol : float
        Largest ``δ`` as a share of the ball's radius.
    min_crease_degrees : float
        Least angle between ``P`` and each face sharing a rim edge.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    applies = np.zeros(n_loops, dtype=bool)
    doubt = np.full(n_loops, np.inf)
    half = np.full(n_loops, np.inf)
    normal = np.zeros((n_loops, 3))
    if not n_loops:
        return PlanarRims(applies=applies, doubt=doubt, half_width=half, normal=normal, origin=np.zeros((0, 3)))
    count, mean, normal, delta, spread, _ = _rim_planes(v, edges, label, n_loops)
    half = delta + _round_off(v)
    # a rim of at least 4 vertices spanning the plane (not a pinch along a line), within rim_rtol of it: three
    # points always lie in one plane, so a 3-vertex rim is no evidence of a flat face (a triangular prism that
    # lost the three faces of a corner tetrahedron was 33 % low inside ±1e-14: test_hole_footprints, CI dry run)
    candidate = (count >= 4) & (delta <= rim_rtol * radius) & (spread > 0)
    # the faces sharing a rim edge, each at a crease of at least min_crease_degrees to the rim's plane
    # (each rim edge's face, found in either direction; a rim edge without one keeps the loop out)
    forward, found = _ring_face_of_edges(f, len(v), edges)
    backward, found_back = _ring_face_of_edges(f, len(v), edges[:, ::-1])
    face_of = np.where(found, forward, backward)
    a, b, c = (v[f[face_of, k]] for k in range(3)) if len(f) else (np.zeros((len(edges), 3)),) * 3
    m = np.cross(b - a, c - a)
    size = np.linalg.norm(m, axis=1)
    lean = np.abs(np.einsum("ij,ij->i", m, normal[label])) / np.maximum(size, 1e-300)
    steep_enough = (found | found_back) & (size > 0) & (lean <= np.cos(np.radians(min_crease_degrees)))
    shallow = np.zeros(n_loops, dtype=bool)
    shallow[label[~steep_enough]] = True
    candidate &= ~shallow
    offset = np.einsum("ij,ij->i", centre - mean, normal)
    doubt = np.where(candidate, ball_slab_volume(radius, offset, np.where(candidate, half, 0.0)), np.inf)
    return PlanarRims(applies=candidate, doubt=doubt, half_width=np.where(candidate, half, np.inf), normal=normal,
                      origin=mean)


#: The user's ``smooth-holes`` assumption (:data:`~.hole_assumptions.SMOOTH_HOLES`): the missing surface lies
#: within this many times (the surroundings' largest deviation from their quartic fit, plus the largest gap between
#: their quartic and quadratic fits over the hole) of the quartic.  2: a margin over what the surroundings show,
#: fixed before the benchmark's held-out seeds were run.
SMOOTH_BAND_FACTOR = 2.0

#: Least number of sample points (corners and face centres round the rim) for the quartic fit of
#: :func:`smooth_doubt`: twice its fifteen coefficients.
SMOOTH_MIN_POINTS = 30


def _height_design(x: np.ndarray, y: np.ndarray, degree: int) -> np.ndarray:
    """Monomials ``x^i y^j`` with ``i + j <= degree``, ordered by ``(i + j, j)``, as columns, (p, terms)."""
    return np.column_stack([x ** (total - j) * y ** j for total in range(degree + 1) for j in range(total + 1)])


def _hessian_norms(coef: np.ndarray, x: np.ndarray, y: np.ndarray, degree: int) -> np.ndarray:
    """The spectral norm of the Hessian of the height ``Σ c_ij x^i y^j`` (:func:`_height_design`'s order) at each
    point, (p,)."""
    hxx = np.zeros_like(x)
    hxy = np.zeros_like(x)
    hyy = np.zeros_like(x)
    at = 0
    for total in range(degree + 1):
        for j in range(total + 1):
            i = total - j
            c = coef[at]
            at += 1
            if i >= 2:
                hxx = hxx + c * i * (i - 1) * x ** (i - 2) * y ** j
            if i >= 1 and j >= 1:
                hxy = hxy + c * i * j * x ** (i - 1) * y ** (j - 1)
            if j >= 2:
                hyy = hyy + c * j * (j - 1) * x ** i * y ** (j - 2)
    # eigenvalues of [[a, b], [b, c]]: (a + c)/2 ± sqrt(((a − c)/2)² + b²)
    half = 0.5 * (hxx + hyy)
    root = np.sqrt((0.5 * (hxx - hyy)) ** 2 + hxy ** 2)
    out: np.ndarray = np.abs(half) + root
    return out


@frozen_value
class SmoothFill:
    """One hole's fill and bound under the user's ``smooth-holes`` assumption (:func:`smooth_doubt`).

    Attributes
    ----------
    points : (p, 3) float
        The fill's inner points, lifted onto the surroundings' quartic, m.
    doubt : float
        Volume in doubt, m³ (rounded up).
    height : float
        How far the region in doubt reaches from the rim's mean height along the fill's direction, m.
    band : float
        ``t``: how far the assumption lets the missing surface stray from the quartic, m.
    """

    points: np.ndarray
    doubt: float
    height: float
    band: float


def smooth_doubt(vertices: np.ndarray, faces: np.ndarray, rim_edges: np.ndarray, points: np.ndarray,
                 caps: np.ndarray, direction: np.ndarray, *, lift: bool = True, factor: float = SMOOTH_BAND_FACTOR,
                 min_points: int = SMOOTH_MIN_POINTS) -> SmoothFill | None:
    """A hole's graph fill lifted onto its surroundings' quartic, and its volume in doubt under ``smooth-holes``;
    ``None`` where the surroundings do not allow the reading (too few points, a face round the rim facing away
    from ``direction``, a fit of deficient rank).

    Frame: ``d = direction``, heights ``h = (x − o)·d`` over the plane ``Π ⟂ d`` (``o`` the rim's centroid,
    lengths scaled by the rim's radius about it).  The surroundings are the faces within two rings of the rim;
    their corners and centres (the centres carry the facets' sag) are fitted in the least-squares sense by a
    quadratic height ``S`` and a quartic height ``Q`` over ``Π``.  With ``lift``, the fill's inner points are moved
    along ``d`` onto ``Q``; else they stay (the caller's rule: where the surroundings lie on one curved quadric,
    :func:`~.hole_fills.curved_surroundings`, the graph fill's points lie on it, a better continuation of a
    sphere or cylinder than a quartic).

    **Assumption** (:data:`~.hole_assumptions.SMOOTH_HOLES`): the missing surface ``M`` is the graph of a height
    ``g`` over the region ``Ω`` the projected rim bounds with ``|g − Q| ≤ t`` on ``Ω``, ``t = factor · (ρ + γ)``:
    ``ρ`` the surroundings' largest ``|h − Q|`` (how far they stray from the fitted continuation) and ``γ`` the
    largest ``|Q − S|`` at the fill's points (how much the continuation over the hole depends on the fit: zero on
    a paraboloid, growing with the hole where the curvature changes).

    **The bound** (follows from it; only ``factor`` is chosen).  The fill ``F`` and ``M`` are graphs over ``Ω``
    with the rim as common border (``F`` checked to tile ``Ω`` once by :func:`~.hole_graphs.graph_fills`), so the
    solids differ by ``∫_Ω |g − F| ≤ t |Ω| + ∫_Ω |F − Q|``.  On a fill triangle ``T`` (corners off ``Q`` by
    ``δ_i``: zero inside, the rim's own deviation on it), ``Q − LQ = ½ Σ λ_i λ_j (q_i − q_j)ᵀ ∇²Q (q_i − q_j)``
    up to the change of ``∇²Q`` across ``T``, so ``∫_T |F − Q| ≤ A_T (mean |δ_i| + H Σ ℓ_ij² / 24)``, ``H`` the
    largest ``‖∇²Q‖`` at the sample's and the fill's points (not a bound between them: the one step taken on
    trust, as :func:`~.hole_fills.region_check` checks a fill at its points).  Plus 16 ulp of the coordinates
    times the area.  The region in doubt lies within ``height = max |z_i − h̄| + max_T (max |δ_i| + H ℓ_T²/6) +
    t`` of the rim's mean height ``h̄``.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    rim_edges : (r, 2) int
        The rim's edges (the border of ``Ω``).
    points : (p, 3) float
        The graph fill's inner points, m.
    caps : (q, 3) int
        The fill's triangles: rim vertices by index, inner points as ``−1 − i``, tiling ``Ω`` once in projection
        along ``direction`` (:func:`~.hole_graphs.graph_fills` checks it).
    direction : (3,) float
        Unit ``d``.
    lift : bool
        Move the inner points onto ``Q`` (else keep them; their distance from ``Q`` enters the bound).
    factor, min_points
        :data:`SMOOTH_BAND_FACTOR`, :data:`SMOOTH_MIN_POINTS`.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    d = np.asarray(direction, dtype=np.float64)
    rim = np.unique(np.asarray(rim_edges, dtype=np.int64))
    e1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    origin = v[rim].mean(axis=0)
    scale = float(np.max(np.linalg.norm(v[rim] - origin, axis=1)))
    if not scale > 0:
        return None

    def frame(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        rel = (p - origin) / scale
        return rel @ e1, rel @ e2, rel @ d

    near = np.zeros(len(v), dtype=bool)
    near[rim] = True
    for _ in range(2):
        near[f[near[f].any(axis=1)].reshape(-1)] = True
    ring = f[near[f].all(axis=1)]
    if not len(ring):
        return None
    normal = np.cross(v[ring[:, 1]] - v[ring[:, 0]], v[ring[:, 2]] - v[ring[:, 0]])
    if not bool((normal @ d > 0).all()):
        return None                        # the surroundings fold over Π: not a graph there
    sample = np.vstack([v[np.unique(ring)], v[ring].mean(axis=1)])
    if len(sample) < min_points:
        return None
    sx, sy, sh = frame(sample)
    quart = _height_design(sx, sy, 4)
    if np.linalg.matrix_rank(quart) < quart.shape[1]:
        return None
    cs, *_ = np.linalg.lstsq(_height_design(sx, sy, 2), sh, rcond=None)
    cq, *_ = np.linalg.lstsq(quart, sh, rcond=None)
    inner = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    ix, iy, _ = frame(inner)
    lifted = _height_design(ix, iy, 4) @ cq if lift else frame(inner)[2]
    new_points = origin + scale * (ix[:, None] * e1 + iy[:, None] * e2 + lifted[:, None] * d)
    all_points = np.vstack([v, new_points])
    tri = np.where(caps < 0, len(v) + (-1 - caps), caps)
    px, py, ph = frame(all_points[tri.reshape(-1)])
    px, py, ph = px.reshape(-1, 3), py.reshape(-1, 3), ph.reshape(-1, 3)
    flat_x, flat_y = px.reshape(-1), py.reshape(-1)
    on_q = _height_design(flat_x, flat_y, 4) @ cq
    delta = np.abs(ph - on_q.reshape(-1, 3))
    if lift:
        delta[tri >= len(v)] = 0.0             # the inner points are on Q (their rounding is in the margin)
    stray = float(np.max(np.abs(sh - quart @ cq)))
    gap = float(np.max(np.abs(on_q - _height_design(flat_x, flat_y, 2) @ cs)))
    band = factor * (stray + gap)
    curvature = float(max(np.max(_hessian_norms(cq, sx, sy, 4)), np.max(_hessian_norms(cq, flat_x, flat_y, 4))))
    area = 0.5 * np.abs((px[:, 1] - px[:, 0]) * (py[:, 2] - py[:, 0]) - (py[:, 1] - py[:, 0]) * (px[:, 2] - px[:, 0]))
    sq = (px - np.roll(px, -1, axis=1)) ** 2 + (py - np.roll(py, -1, axis=1)) ** 2
    margin = _round_off(all_points) / scale
    doubt = float(np.sum(area * (delta.mean(axis=1) + curvature * sq.sum(axis=1) / 24.0 + band + 2.0 * margin)))
    rim_h = frame(v[rim])[2]
    height = (float(np.max(np.abs(ph - float(rim_h.mean()))))
              + float(np.max(delta.max(axis=1) + curvature * sq.max(axis=1) / 6.0)) + band + 2.0 * margin)
    if not (np.isfinite(doubt) and np.isfinite(height) and np.isfinite(new_points).all()):
        return None
    return SmoothFill(points=new_points, doubt=round_up(doubt * scale ** 3), height=round_up(height * scale),
                      band=round_up(band * scale))
