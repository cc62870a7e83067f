"""Patching holes: a bounded estimate of the solid behind a surface with holes.

:func:`patched_estimate` closes every boundary loop by a cone (a fan of triangles) to the centroid of the
loop's vertices and integrates the closed result exactly.  The boundary of a triangle 2-chain is a 1-cycle, so
the cones always close it.  **Assumption: the missing surface of each hole lies within the ball enclosing the
hole's rim** (:func:`~.rims.enclosing_balls`, close to the smallest such ball; for a round hole in a smooth part
this is the ball whose great circle is the rim, which holds any cap up to a hemisphere).  The cone lies in the
rim's convex hull, inside the same ball, so the closed cycle "cone minus missing surface" lies in the ball and
its winding number — the difference between the patched solid and the true one — vanishes outside it.  The
same assumption, for a long thin rim: **the missing surface also lies within the capsule round the rim's
principal axis that holds the rim** (:func:`~.rims.enclosing_capsules`: no farther from the axis than the rim
is; round a circle the capsule is the ball).  The capsule is convex and holds the cone too, so the region in
doubt lies in it as well, and each hole's doubt is the smaller of the two volumes (a strip of facets taken
along a cylinder has a ball as long as the strip, larger than the part, and a capsule as thin as the strip).
**Second assumption: the missing surface strays from the plane of a face beside the hole no farther than the
rim does** (:func:`hole_doubt_volumes`); the cone does too, so each ball is cut to that slab, and the volume in
doubt is the total volume of the cut balls.  The convex hull of the rim is *not* enough (a planar rim has a hull
of volume 0, yet a spherical cap over it is far from flat), and no hole gets a bound of 0.  **Third assumption,
for a hole across one crease of a faceted part: the missing surface lies in the two planes that hold its rim**
(:func:`crease_fills`): each plane's part of the rim is filled in that plane instead of by the cone, and the
ball is cut to both slabs.  Seams sealed first (cracks, T-junctions; :mod:`~.seal`) add the volume of the
parallel bodies of the faces sealing touched.  The bounds follow from the volume in doubt as
:mod:`~.uncertainty` states.

**No bound follows from the file alone**: the missing surface of a hole can be anything with the rim as its
boundary (a boss of any height, a housing that leaves the convex hull of what remains), so every bound here is
conditional on the assumptions above.  What the file *can* do is contradict them, and then the narrower
assumption is dropped (:func:`rim_evidence`).  On a surface tessellated with vertices only on the loops of its
flat faces (as CAD exporters do), a rim vertex whose remaining faces all lie in one plane (*bare*) lay on a loop
of that face, so the hole took a surface that met the face there: the slab is withdrawn (the ball stays), a
crease fill is not made, and a hole that is an island of a flat face with a bare rim — the footprint of a
feature taken whole — is refused (:attr:`~.uncertainty.Estimate.unbounded`), since nothing bounds its height.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..rounding import round_up
from ..values import frozen_value
from .edges import edge_keys
from .rims import boundary_edges, boundary_loops, capsule_volumes, enclosing_balls, enclosing_capsules
from .seal import Seal
from .uncertainty import Estimate, uncertainty_from

__all__ = ["patched_estimate", "hole_doubt_volumes", "ball_slab_volume", "crease_fills", "CreaseFill", "rim_evidence",
           "curved_fills", "CurvedFill",
           "RimEvidence", "bare_vertices", "slab_contradicted",
           "convex_hole_bound"]


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
    nv = np.int64(max(n, 1))
    key, _ = edge_keys(faces, n)
    rim_key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * nv + np.maximum(edges[:, 0], edges[:, 1])
    order = np.argsort(rim_key, kind="stable")
    sorted_rim = rim_key[order]
    pos = np.searchsorted(sorted_rim, key)
    hit = (pos < len(sorted_rim)) & (sorted_rim[np.minimum(pos, len(sorted_rim) - 1)] == key)
    slot = np.flatnonzero(hit)
    if not len(slot):
        return ball
    ring_face = slot // 3
    ring_loop = label[order[pos[slot]]]
    # one (face, loop) pair per ring face of each loop
    pair = np.unique(np.stack([ring_face, ring_loop], axis=1), axis=0)
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
    scale = float(np.max(np.abs(v))) if n else 0.0
    margin = 16.0 * np.finfo(np.float64).eps * max(scale, 1e-300)
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


@frozen_value
class CreaseFill:
    """A hole across one crease of a faceted part, filled in the two planes that hold its rim.

    Attributes
    ----------
    loop : int
        The boundary loop.
    apexes : (2, 3) float
        The centroid of each planar part of the rim (with the two ends of the crease segment), m.
    caps : (k, 3) int
        The fill's triangles: each rim edge with the apex of its plane (index ``n_vertices + 0`` or ``+ 1`` of
        the caller's numbering, shifted by the caller), and the two triangles over the crease segment.
    doubt : float
        Volume in doubt, m³: the ball over the rim cut to the slab of each plane, summed.
    narrow : bool
        The surface is tessellated the CAD way (no vertex inside a flat face anywhere off the rims), so the
        check can see a contradiction, and the faces left at the rim show none (no rim vertex off the crease
        keeps faces in its plane only: :func:`crease_fills`): ``doubt`` bounds the hole; else the whole ball.
    """

    loop: int
    apexes: np.ndarray
    caps: np.ndarray
    doubt: float
    narrow: bool = False


#: A rim "lies in a plane" when every rim vertex and every face left at the rim is within this share of the
#: ball's radius of the plane of a ring face (far above round-off and quantisation to 1e-4 of a diagonal, far
#: below any boss or pocket a designer draws).
FLAT_RIM_RTOL = 1e-3
#: A vertex is *flat* when every face at it is within acos(FLAT_VERTEX_COSINE) ≈ 1.1° of their mean plane.
FLAT_VERTEX_COSINE = 1.0 - 2e-4
#: Most distinct planes of the faces beside one rim tried in pairs by :func:`crease_fills`.
CREASE_MAX_PLANES = 8
#: Most loops :func:`crease_fills` examines (one at a time, ~0.1 ms each).
CREASE_MAX_LOOPS = 5000


def crease_fills(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                 centre: np.ndarray, radius: np.ndarray, *, bare: np.ndarray | None = None,
                 flat_rtol: float = FLAT_RIM_RTOL, flat_cosine: float = FLAT_VERTEX_COSINE) -> list[CreaseFill]:
    """Holes across one crease, each filled by two planar fans instead of one cone (the third assumption).

    A hole that took triangles from two flat faces of a faceted part meeting at a crease (a box's edge, a
    cylinder's cap rim) has a rim that no one plane holds, so one slab cannot cut its ball.  It qualifies here
    when two planes of faces beside it (the ring) hold the rim this way: each holds three rim vertices not on
    a line (a two-dimensional part of the rim, not an edge: the octahedron's faces hold only an edge each),
    every rim edge lies in one of them and none in both, and walking the rim the plane changes exactly twice,
    at two vertices ``a`` and ``b`` lying on both (on the crease).  **Assumption: the missing surface lies in
    those two planes** (the hole is a piece of the two faces it crosses), as far from each as the rim part it
    holds (``e₁``, ``e₂``, plus 16 ulp of the coordinates).  Each planar part of the rim, closed by the crease
    segment ``a–b``, is filled by a fan to the centroid of its vertices; the two fans share ``a–b`` with
    opposite windings, so the fill has exactly the rim as boundary.  A 2-chain in a plane is fixed by its
    boundary, so where the assumption holds exactly the fill *is* the missing surface; in general the cycle
    "fill − missing surface" lies in the ball over the rim (assumption 1; the fans lie in the rim's convex hull)
    cut to the union of the two slabs, whose complement is connected (each piece of the ball between the slabs
    reaches its sphere), so the winding number of the cycle vanishes outside it: the volume in doubt is at most
    the sum of the ball's two slab volumes (:func:`ball_slab_volume`).  Loops of at least four edges are tried,
    at most ``CREASE_MAX_LOOPS`` of them (beyond, every hole keeps its cone).

    Returns
    -------
    list of CreaseFill
        The loops that qualify (others keep their cone).
    """
    from itertools import combinations

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    scale = float(np.max(np.abs(v))) if n else 0.0
    margin = 16.0 * np.finfo(np.float64).eps * max(scale, 1e-300)
    on_tol = 4.0 * margin                        # a rim vertex "on" a plane: within round-off of it
    candidates = np.flatnonzero(np.bincount(label, minlength=n_loops) >= 4).tolist()
    if not candidates or len(candidates) > CREASE_MAX_LOOPS:
        return []
    nv = np.int64(max(n, 1))
    rim_key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * nv + np.maximum(edges[:, 0], edges[:, 1])
    ring_pairs, ring_start = _ring_faces(f, n, rim_key, label, candidates, n_loops)
    maybe = _may_hold_two_planes(v, f, edges, label, n_loops, candidates, ring_pairs, ring_start, 2.0 * on_tol)
    # read only where a fill is about to be made (issue 25: both read every face, ~0.5 s at 1.3M faces)
    interior: np.ndarray | None = None
    corner_order = corner_start = np.zeros(0, dtype=np.int64)

    def vertex_faces(x: int) -> np.ndarray:
        faces_at: np.ndarray = corner_order[corner_start[x]:corner_start[x + 1]] // 3
        return faces_at

    by_loop = np.argsort(label, kind="stable")          # each loop's edges in their order in ``edges``
    loop_start = np.searchsorted(label[by_loop], np.arange(n_loops + 1))
    out = []
    for k in candidates:
        if not maybe[k]:
            continue                              # fewer than two ring faces whose planes hold three rim vertices
        raw = edges[by_loop[loop_start[k]:loop_start[k + 1]]]
        succ = dict(zip(raw[:, 0].tolist(), raw[:, 1].tolist()))
        if len(succ) != len(raw) or len(raw) < 4:
            continue                              # a vertex met twice (a pinch), or too short to cross a crease
        walk = [int(raw[0, 0])]                   # the rim in its own order (one cycle, else skipped)
        while len(walk) <= len(raw) and succ.get(walk[-1], walk[0]) != walk[0]:
            walk.append(succ[walk[-1]])
        if len(walk) != len(raw):
            continue
        loop_edges = np.array([[x, succ[x]] for x in walk], dtype=np.int64)
        ring = ring_pairs[ring_start[k]:ring_start[k + 1], 1]
        if not len(ring):
            continue
        a0 = v[f[ring, 0]]
        normal = np.cross(v[f[ring, 1]] - a0, v[f[ring, 2]] - a0)
        length = np.linalg.norm(normal, axis=1)
        keep = length > 0
        if not keep.any():
            continue
        unit, a0 = normal[keep] / length[keep, None], a0[keep]
        offset = np.einsum("ij,ij->i", unit, a0)
        rim = np.array(list(succ), dtype=np.int64)
        dist = np.abs(v[rim] @ unit.T - offset[None, :])          # (rim vertex, ring face)
        on = dist <= on_tol
        # distinct planes: ring faces holding the same rim vertices within round-off of one plane
        _, first = np.unique(on.T, axis=0, return_index=True)
        planes = [int(p) for p in first if np.count_nonzero(on[:, p]) >= 3]
        if len(planes) < 2 or len(planes) > CREASE_MAX_PLANES:
            continue
        index = {int(x): i for i, x in enumerate(rim.tolist())}
        found = None
        for p, q in combinations(planes, 2):
            if abs(float(unit[p] @ unit[q])) > 1.0 - 1e-9:
                continue                          # parallel planes meet in no crease
            in_p, in_q = on[:, p], on[:, q]
            if not (in_p | in_q).all():
                continue
            if any(np.linalg.matrix_rank(v[rim[m]][1:] - v[rim[m]][0], tol=on_tol) < 2 for m in (in_p, in_q)):
                continue
            side: list[int] = []
            for start, end in loop_edges.tolist():
                ep = in_p[index[start]] and in_p[index[end]]
                eq = in_q[index[start]] and in_q[index[end]]
                if ep == eq:
                    side = []
                    break                         # an edge in neither plane, or along the crease itself
                side.append(0 if ep else 1)
            if side and sum(side[i] != side[i - 1] for i in range(len(side))) == 2:
                found = (p, q, side)
                break
        if found is None:
            continue
        p, q, side = found
        order = loop_edges.tolist()
        switch = [i for i in range(len(side)) if side[i] != side[i - 1]]
        # the vertex where plane p's chain ends and q's begins (a), and where q's ends and p's begins (b)
        a = next(order[i][0] for i in switch if side[i] == 1)
        b = next(order[i][0] for i in switch if side[i] == 0)
        if bare is not None and any(bare[x] for x in rim.tolist() if x not in (a, b)):
            continue                              # the hole took a third surface meeting a plane at a bare vertex
        parts = []
        for which in (0, 1):
            ids = sorted({x for (s0, s1), sd in zip(order, side) if sd == which for x in (s0, s1)})
            parts.append(v[ids].mean(axis=0))
        apexes = np.array(parts)
        caps = [[e1, e0, n + sd] for (e0, e1), sd in zip(order, side)]
        # p's chain runs b → … → a and closes along a → b; q's runs a → … → b and closes along b → a
        caps += [[b, a, n + 0], [a, b, n + 1]]
        if interior is None:
            interior = _flat_off_rim_nearby(v, f, edges, flat_cosine=flat_cosine)
            corner_order = np.argsort(f.reshape(-1), kind="stable")
            corner_start = np.searchsorted(f.reshape(-1)[corner_order], np.arange(n + 1))
        narrow = not interior.any() and not _crease_rim_contradicts(
            v, f, loop_edges, side, (a, b), unit[[p, q]], offset[[p, q]], flat_rtol * float(radius[k]) + margin,
            vertex_faces, interior)
        doubt = 0.0
        for which, plane in ((0, p), (1, q)):
            chain = [index[x] for (s0, s1), sd in zip(order, side) if sd == which for x in (s0, s1)]
            half = float(dist[chain, plane].max()) + margin
            centre_offset = float(centre[k] @ unit[plane] - offset[plane])
            doubt += float(ball_slab_volume(np.array([radius[k]]), np.array([centre_offset]),
                                            np.array([half]))[0])
        out.append(CreaseFill(loop=int(k), apexes=apexes, caps=np.array(caps, dtype=np.int64), doubt=doubt,
                              narrow=narrow))
    return out


def _ring_faces(f: np.ndarray, n: int, rim_key: np.ndarray, label: np.ndarray, candidates: list[int],
                n_loops: int) -> tuple[np.ndarray, np.ndarray]:
    """The faces with an edge on the rim of each candidate loop of :func:`crease_fills` (the ring): ``(pairs,
    start)``, the (loop, face) pairs sorted, loop ``k``'s faces ascending in ``pairs[start[k]:start[k + 1], 1]``.
    A face edge counts for the loop of the *last* rim edge with its key (the rim edges listed in
    ``edges`` order), and only keys of candidate loops' rim edges are looked up.  Sorting only the face edges
    whose two ends lie on a candidate rim keeps this to the rims' size (issue 25: every face edge was, ~0.4 s
    at 1.3M faces, and a Python loop ran over the ring)."""
    wanted = np.zeros(n_loops, dtype=bool)
    wanted[candidates] = True
    nv = np.int64(max(n, 1))
    sel = wanted[label]
    rim_vertex = np.zeros(int(nv), dtype=bool)
    rim_vertex[rim_key[sel] // nv] = True
    rim_vertex[rim_key[sel] % nv] = True
    a, b = f.reshape(-1), f[:, [1, 2, 0]].reshape(-1)
    slot = np.flatnonzero(rim_vertex[a] & rim_vertex[b])
    key = np.minimum(a[slot], b[slot]) * nv + np.maximum(a[slot], b[slot])
    slot = slot[np.isin(key, rim_key[sel])]
    key = np.minimum(a[slot], b[slot]) * nv + np.maximum(a[slot], b[slot])
    # the loop of the last rim edge with each key
    unique_key, last = np.unique(rim_key[::-1], return_index=True)
    loop_of_key = label[::-1][last]
    loop = loop_of_key[np.searchsorted(unique_key, key)]
    pairs = np.unique(np.stack([loop, slot // 3], axis=1), axis=0) if len(slot) else np.zeros((0, 2), np.int64)
    start = np.searchsorted(pairs[:, 0], np.arange(n_loops + 1))
    return pairs, start


#: Most (ring face, rim vertex) pairs :func:`_may_hold_two_planes` measures over all loops (~80 bytes each at
#: once, so ~80 MB); loops beyond it are examined one by one as before.
CREASE_SCREEN_PAIRS = 1_000_000


def _may_hold_two_planes(v: np.ndarray, f: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                         candidates: list[int], ring_pairs: np.ndarray, ring_start: np.ndarray, loose: float
                         ) -> np.ndarray:
    """Loops that may still qualify for :func:`crease_fills`, (n_loops,) bool: a necessary condition measured on
    all candidate loops at once, so that the loop over them skips the rest without a step of their own
    (issue 25: thousands of small holes, ~0.1 ms each).

    A loop qualifies only if two ring faces have planes each holding at least three of its rim vertices within
    ``on_tol``.  Here the distances are measured another way (one product per (face, vertex) pair rather than a
    matrix product), which may differ from the loop's by a few ulp of the coordinates, so a vertex counts when
    within ``loose`` (twice ``on_tol``, 64 ulp more than any such difference): every loop the loop would keep is
    kept.  Loops whose pairs would pass ``CREASE_SCREEN_PAIRS`` in total are kept unmeasured."""
    maybe = np.ones(n_loops, dtype=bool)
    cand = np.zeros(n_loops, dtype=bool)
    cand[candidates] = True
    nv = np.int64(max(len(v), 1))
    # the distinct (loop, vertex) pairs of the candidate loops' rims, by loop
    sel = cand[label]
    rim = np.unique(label[sel].astype(np.int64) * nv + edges[sel, 0])
    rim_loop, rim_vertex = rim // nv, rim % nv
    rim_start = np.searchsorted(rim_loop, np.arange(n_loops + 1))
    rim_count = np.diff(rim_start)
    ring_count = np.diff(ring_start)
    work = rim_count * ring_count
    order = np.argsort(work, kind="stable")
    measured = np.zeros(n_loops, dtype=bool)
    measured[order[np.cumsum(work[order]) <= CREASE_SCREEN_PAIRS]] = True
    measured &= cand
    loops = np.flatnonzero(measured)
    if not len(loops):
        return maybe
    maybe[loops] = False
    # every (ring face, rim vertex) pair of each measured loop
    faces_per = ring_count[loops]
    face_row = np.repeat(ring_start[loops], faces_per) + (np.arange(int(faces_per.sum()))
                                                          - np.repeat(np.cumsum(faces_per) - faces_per, faces_per))
    face = ring_pairs[face_row, 1]
    loop_of_face = np.repeat(loops, faces_per)
    a0 = v[f[face, 0]]
    normal = np.cross(v[f[face, 1]] - a0, v[f[face, 2]] - a0)
    length = np.linalg.norm(normal, axis=1)
    good = length > 0
    unit = normal / np.where(good, length, 1.0)[:, None]
    offset = np.einsum("ij,ij->i", unit, a0)
    per = rim_count[loop_of_face]
    owner = np.repeat(np.arange(len(face)), per)
    vertex = rim_vertex[np.repeat(rim_start[loop_of_face], per) + (np.arange(int(per.sum()))
                                                                  - np.repeat(np.cumsum(per) - per, per))]
    dist = np.abs(np.einsum("ij,ij->i", v[vertex], unit[owner]) - offset[owner])
    held = np.bincount(owner, weights=dist <= loose, minlength=len(face))
    planes = np.bincount(loop_of_face, weights=good & (held >= 3), minlength=n_loops)
    maybe[loops] = planes[loops] >= 2
    return maybe


def _crease_rim_contradicts(v: np.ndarray, f: np.ndarray, loop_edges: np.ndarray, side: list[int],
                            crease: tuple[int, int], plane_unit: np.ndarray, plane_offset: np.ndarray,
                            tol: float, vertex_faces: Callable[[int], np.ndarray], interior: np.ndarray) -> bool:
    """Whether the faces left at a crease fill's rim contradict the third assumption (the missing surface lies
    in the two planes), read as :func:`slab_contradicted` reads one plane: a rim vertex off the crease (not
    ``a`` or ``b``, so in one plane only) whose every remaining face lies in its plane (each corner within
    ``tol``), on a surface with no vertex inside its flat faces there (``interior`` false).  Another face of the
    part met the plane at that vertex and is gone, and it is not the other plane (the vertex is not on it), so
    the missing surface leaves both planes there (a featured box that lost half its faces: the fill closed the
    boss alone, 80-98 % low inside the two slabs)."""
    plane_of: dict[int, set[int]] = {}
    for (e0, e1), sd in zip(loop_edges.tolist(), side):
        plane_of.setdefault(e0, set()).add(sd)
        plane_of.setdefault(e1, set()).add(sd)
    for x, sides in plane_of.items():
        if x in crease or len(sides) != 1 or interior[x]:
            continue
        sd = next(iter(sides))
        faces_at = vertex_faces(x)
        if not len(faces_at):
            continue
        off = np.abs(v[f[faces_at]] @ plane_unit[sd] - plane_offset[sd])
        if float(off.max()) <= tol:
            return True
    return False


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
    # the face holding each rim edge a→b in that direction (the ring face)
    nv = np.int64(max(n, 1))
    directed = f.reshape(-1) * nv + f[:, [1, 2, 0]].reshape(-1)
    order = np.argsort(directed, kind="stable")
    query = edges[:, 0].astype(np.int64) * nv + edges[:, 1]
    pos = np.minimum(np.searchsorted(directed[order], query), len(order) - 1)
    found = directed[order[pos]] == query
    face = order[pos] // 3
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
        rim_pairs = np.unique(np.stack([np.r_[edges[:, 0], edges[:, 1]], np.r_[label, label]], axis=1), axis=0)
        loop_at = np.full(n, -1, dtype=np.int64)
        loop_at[rim_pairs[:, 0]] = rim_pairs[:, 1]     # a vertex on two rims (a pinch) keeps one: excluded below
        on_two = np.bincount(rim_pairs[:, 0], minlength=n) > 1
        fi, ci = np.nonzero(loop_at[f] >= 0)
        loop = loop_at[f[fi, ci]]
        dist = np.abs(np.einsum("ijk,ik->ij", v[f[fi]] - origin[loop][:, None, :], unit[loop])).max(axis=1)
        worst = np.zeros(n_loops)
        np.maximum.at(worst, loop, dist)
        pinched = np.zeros(n_loops, dtype=bool)
        pinched[rim_pairs[on_two[rim_pairs[:, 0]], 1]] = True
        scale = float(np.max(np.abs(v)))
        margin = 16.0 * np.finfo(np.float64).eps * max(scale, 1e-300)
        flat = has & ~pinched & (worst <= flat_rtol * radius + margin)
    if bare is None:
        bare = bare_vertices(v, f, edges, flat_cosine=flat_cosine)
    rim = np.unique(np.stack([edges[:, 0], label], axis=1), axis=0)
    count = np.bincount(rim[:, 1], weights=bare[rim[:, 0]], minlength=n_loops).astype(np.int64)
    return RimEvidence(flat_all_round=flat, bare=count)


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
    key, _ = edge_keys(g, n)
    order = np.argsort(key, kind="stable")
    key = key[order]
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
                      flat_rtol: float = FLAT_RIM_RTOL, flat_cosine: float = FLAT_VERTEX_COSINE
                      ) -> np.ndarray:
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
    pairs = np.unique(np.stack([e.reshape(-1), np.repeat(label, 2)], axis=1), axis=0)
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
    out[pairs[~off_p, 1]] = True
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


def _crease_contradicted(pv: np.ndarray, pf: np.ndarray, n_given: int, creases: list[CreaseFill], n_loops: int,
                         n_vertices: int) -> list[int]:
    """Loops whose crease fill meets a face of the file other than along shared edges and corners (the face-pair
    check, exact): a fill lying over, or through, surface the file has is not where the surface is missing, so
    the third assumption is contradicted there (a box with a boss, half its faces gone: the fill of the top
    face's plane closed the boss alone, 98 % low at a stated ±1e-12)."""
    from .intersect import surface_contacts
    contacts = surface_contacts(pv, pf)
    pairs = np.concatenate([np.asarray(p, dtype=np.int64).reshape(-1, 2)
                            for p in (contacts.crossing, contacts.coplanar_opposite, contacts.contact)])
    if not contacts.complete:
        return sorted({fill.loop for fill in creases})
    if not len(pairs):
        return []
    # the caps follow the given faces: the cones' first, then each fill's in order
    sizes = [len(fill.caps) for fill in creases]
    first_fill = len(pf) - sum(sizes)
    owner = np.full(len(pf), -1, dtype=np.int64)
    at = first_fill
    for fill, size in zip(creases, sizes):
        owner[at:at + size] = fill.loop
        at += size
    out = set()
    for a, b in pairs.tolist():
        if owner[a] >= 0 and b < n_given:
            out.add(int(owner[a]))
        elif owner[b] >= 0 and a < n_given:
            out.add(int(owner[b]))
    return sorted(out)


#: A hole's neighbourhood "is" a quadric when every point of it lies within this share of the ball's radius of
#: the fitted surface (first-order distance ``|Q|/|∇Q|``): far above round-off, below the sagitta of any facet
#: a curved fill could improve on.
QUADRIC_FIT_RTOL = 1e-3
#: Levels of the curved fill between rim and apex (each cone triangle becomes ``2 · levels − 1`` triangles).
CURVED_FILL_LEVELS = 6
#: Most holes given a curved fill (those with the most doubt first; the rest keep their cone).
CURVED_MAX_LOOPS = 64


@frozen_value
class CurvedFill:
    """A hole filled by a fan bent onto the quadric its surroundings lie on (:func:`curved_fills`).

    Attributes
    ----------
    loop : int
        The boundary loop.
    apex : (3,) float
        Where the cone's apex moved to (onto the quadric), m.
    points : (p, 3) float
        The fill's inner vertices, m.
    caps : (q, 3) int
        Its triangles: rim vertices by their index, the apex as ``n_vertices + loop`` (the cone's), the inner
        vertices as ``−1 − i`` (the caller numbers them).
    """

    loop: int
    apex: np.ndarray
    points: np.ndarray
    caps: np.ndarray


def curved_fills(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                 apex: np.ndarray, centre: np.ndarray, radius: np.ndarray, capsule: tuple[np.ndarray, ...],
                 slab: tuple[np.ndarray, np.ndarray, np.ndarray], order: np.ndarray, *,
                 fit_rtol: float = QUADRIC_FIT_RTOL, levels: int = CURVED_FILL_LEVELS,
                 max_loops: int = CURVED_MAX_LOOPS) -> list[CurvedFill]:
    """Holes whose surroundings lie on one quadric, filled on it instead of by the flat cone (a better estimate,
    the same bound).

    The vertices of the faces within two rings of the rim are fitted by the quadric ``Q(x) = 0`` (ten
    coefficients, the right singular vector of the smallest singular value of ``[x², y², z², xy, yz, zx, x, y,
    z, 1]``, in coordinates centred on the ball and scaled by its radius).  It is used when it is unique (the
    next singular value is not round-off: a planar neighbourhood fits many quadrics, and keeps its cone) and
    every fitted point lies within ``fit_rtol`` of the radius of it (``|Q|/|∇Q|``): spheres, cylinders, cones
    and their facets' vertices fit exactly, a torus or a feature does not.  The cone's fan is split into
    ``levels`` rings (points ``apex + s (rim − apex)``, ``s = sin(π/2 · (levels − L)/levels)`` at ring ``L``:
    even in angle over a hemisphere), and each inner point and the apex are moved along the
    normal of the rim's mean plane onto the quadric (the root of ``Q(p + λ d) = 0`` nearest ``λ = 0``).

    The bound does not change: the region in doubt lies where the cycle "fill − missing surface" winds, and
    both lie in the ball, the capsule and (where it applies) the slab over the rim — convex sets, so a fill
    whose every vertex lies in all three does too (*checked*; a fill with a vertex outside keeps its cone).
    ``order`` lists the loops by decreasing doubt; at most ``max_loops`` of them are tried, one at a time.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    start, end, thick = capsule
    normal, origin, half = slab
    out: list[CurvedFill] = []
    tried = 0
    for k in order.tolist():
        if tried >= max_loops:
            break
        rim_edges = edges[label == k]
        rim = np.unique(rim_edges)
        if len(rim) < 5 or len(rim_edges) != len(rim):
            continue                               # too short to be curved, or a pinch
        tried += 1
        near = np.zeros(n, dtype=bool)
        near[rim] = True
        for _ in range(2):
            near[f[near[f].any(axis=1)].reshape(-1)] = True
        x = (v[near] - centre[k]) / radius[k]
        if len(x) < 12:
            continue
        design = np.column_stack([x * x, x[:, 0] * x[:, 1], x[:, 1] * x[:, 2], x[:, 2] * x[:, 0], x,
                                  np.ones(len(x))])
        try:
            _, sv, vt = np.linalg.svd(design, full_matrices=False)
        except np.linalg.LinAlgError:
            continue
        if not sv[-2] > 1e-6 * sv[0]:
            continue                               # many quadrics fit (a plane): the cone stays
        q = vt[-1]
        a = np.array([[q[0], q[3] / 2, q[5] / 2], [q[3] / 2, q[1], q[4] / 2], [q[5] / 2, q[4] / 2, q[2]]])
        b = q[6:9]
        grad = 2 * x @ a + b
        size = np.linalg.norm(grad, axis=1)
        if not (size > 0).all() or float(np.max(np.abs(_quadric(x, a, b, q[9])) / size)) > fit_rtol:
            continue                               # the surroundings are not one quadric
        rim_x = (v[rim] - centre[k]) / radius[k]
        _, _, axes = np.linalg.svd(rim_x - rim_x.mean(axis=0), full_matrices=False)
        d = axes[2]
        top = (apex[k] - centre[k]) / radius[k]
        # inner rings, outermost first, at s = sin(π/2 · (levels − L)/levels): evenly spaced in angle on a
        # hemisphere over the rim (a steep cap is not left one long chord from the rim to the first ring)
        steps = np.sin(0.5 * np.pi * np.arange(levels - 1, 0, -1) / levels)
        spoke = top + steps[None, :, None] * (rim_x[:, None, :] - top)        # (rim vertex, level, 3)
        flat = np.vstack([top[None, :], spoke.reshape(-1, 3)])
        alpha = float(d @ a @ d)
        beta = 2 * flat @ a @ d + float(b @ d)
        gamma = _quadric(flat, a, b, q[9])
        if abs(alpha) > 1e-12:
            disc = beta * beta - 4 * alpha * gamma
            if (disc < 0).any():
                continue
            root = np.sqrt(disc)
            one, two = (-beta + root) / (2 * alpha), (-beta - root) / (2 * alpha)
            lam = np.where(np.abs(one) <= np.abs(two), one, two)
        elif (np.abs(beta) > 0).all():
            lam = -gamma / beta
        else:
            continue
        moved = centre[k] + radius[k] * (flat + lam[:, None] * d)
        if not np.isfinite(moved).all():
            continue
        # the fill must lie where the bound looks: in the ball, the capsule and the slab over the rim
        seg = end[k] - start[k]
        t = np.clip((moved - start[k]) @ seg / max(float(seg @ seg), 1e-300), 0.0, 1.0)
        inside = ((np.linalg.norm(moved - centre[k], axis=1) <= radius[k])
                  & (np.linalg.norm(moved - (start[k] + t[:, None] * seg), axis=1) <= thick[k]))
        if np.isfinite(half[k]):
            inside &= np.abs((moved - origin[k]) @ normal[k]) <= half[k]
        if not inside.all():
            continue
        # spoke points: level 0 is the rim vertex, ``levels`` the apex (n + k), between them inner point
        # −1 − (slot · (levels − 1) + level − 1), ``slot`` the vertex's place in ``rim``
        slot = np.searchsorted(rim, rim_edges)
        index = np.empty((len(rim_edges), 2, levels + 1), dtype=np.int64)
        index[:, :, 0] = rim_edges
        index[:, :, levels] = n + k
        for level in range(1, levels):
            index[:, :, level] = -1 - (slot * (levels - 1) + level - 1)
        first, second = index[:, 0], index[:, 1]          # e0's spoke, e1's spoke
        outer = np.arange(levels)
        # the cone's (e1, e0, apex), split between the rings
        caps = [np.stack([second[:, outer], first[:, outer], first[:, outer + 1]], axis=2).reshape(-1, 3),
                np.stack([second[:, outer[:-1]], first[:, outer[:-1] + 1], second[:, outer[:-1] + 1]],
                         axis=2).reshape(-1, 3)]
        # the moved spoke points are ordered (rim vertex, level), as the inner indices count them
        out.append(CurvedFill(loop=int(k), apex=moved[0], points=moved[1:], caps=np.vstack(caps)))
    return out


def _engulfing(v: np.ndarray, f: np.ndarray, centre: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Holes whose ball holds every vertex of the surface left, (n_loops,) bool.

    Then nothing says which side of the rim is the hole: what remains may be the small part (a sphere less all
    but a cap at its pole, the ring nearly in the rim's plane), and the slab and the capsule, which read the
    hole as the rim's own small disc, stated ±40 % for a solid 1,000 times larger (found by the generated
    spherical-cap test of ``tests/test_hole_footprints.py``, height −0.969).  Such a hole keeps its whole ball.
    """
    used = v[np.unique(f)] if len(f) else v[:0]
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
    for lo in range(0, n, chunk):
        gap = np.linalg.norm(centre[lo:lo + chunk, None, :] - centre[None, :, :], axis=2)
        meet = gap <= radius[lo:lo + chunk, None] + radius[None, :]
        meet[np.arange(len(meet)), lo + np.arange(len(meet))] = False
        out[lo:lo + chunk] = ~meet.any(axis=1)
    return out


def _quadric(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: float) -> np.ndarray:
    """``Q(p) = pᵀ A p + b·p + c`` at each row of ``p`` (k, 3)."""
    value: np.ndarray = np.einsum("ij,jk,ik->i", p, a, p) + p @ b + c
    return value


def patched_estimate(vertices: np.ndarray, faces: np.ndarray, moments: Callable[..., Any], *,
                     seal: Seal | None = None) -> Estimate:
    """Close each boundary loop by a cone to its centroid and integrate; bound by the balls over the rims.

    Assumption (stated in the module docstring): the missing surface of each boundary component lies in the
    ball enclosing its rim (:func:`enclosing_balls`) and in the capsule enclosing it
    (:func:`~.rims.enclosing_capsules`); the cone lies there too, so the patched solid and the true one differ
    only inside both (each hole's doubt is at most the smaller volume, and its reach from the centroid the
    nearer of the two regions' far points); with the second assumption (the missing surface strays from the
    plane of a face beside the hole no farther than the rim does) only inside each ball's slab around that
    plane (:func:`hole_doubt_volumes`), whose total volume is the volume in doubt.  A hole with a bare rim vertex
    keeps its whole ball, and a footprint of a feature taken whole sets ``unbounded`` (:func:`rim_evidence`;
    the caller refuses).  With ``seal``, the seams it sealed add their own doubt (:mod:`~.seal`).  Limits: a
    hole whose missing piece joins two rims (a band round a handle) or reaches far outside its rim's ball (a
    feature swallowed whole on a surface that shows no bare rim vertex) is not covered.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        Consistently oriented where possible (see ``orient.py``); the sign of the total decides outward.
    moments : callable
        ``moments(vertices, faces) -> VolumeMoments`` (the exact integrator, ``volume.volume_moments``).
    seal : Seal, optional
        How ``faces`` were sealed from the input (their slack enters the bound).

    Returns
    -------
    Estimate
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    edges = seal.boundary if seal is not None else boundary_edges(f, len(v))
    label, n_loops = boundary_loops(edges, len(v), f, v) if len(edges) else (np.zeros(0, dtype=np.int64), 0)
    # the distinct vertices of each loop, grouped: (loop, vertex) pairs sorted by loop
    pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0) if n_loops \
        else np.zeros((0, 2), dtype=np.int64)
    loop_of, vertex_of = pairs[:, 0], pairs[:, 1]
    size = np.bincount(loop_of, minlength=n_loops)
    apex = np.zeros((n_loops, 3))
    for i in range(3):
        apex[:, i] = np.bincount(loop_of, weights=v[vertex_of, i], minlength=n_loops) / np.maximum(size, 1)
    creases: list[CreaseFill] = []
    if n_loops:
        centre, radius = enclosing_balls(v[vertex_of], loop_of, n_loops)
        slabs: dict[str, np.ndarray] = {}
        hole_doubt = hole_doubt_volumes(v, f, edges, label, n_loops, centre, radius, vertex_of, loop_of,
                                        slabs=slabs)
        bare = bare_vertices(v, f, edges)
        evidence = rim_evidence(v, f, edges, label, n_loops, radius, bare=bare)
        # a bare rim vertex: the hole took a surface that met the face beside it there, which need not stay
        # near that face's plane; a flat rim whose faces say the missing surface leaves its plane
        # (slab_contradicted): the slab is withdrawn, the ball (first assumption) bounds the hole
        withdrawn = evidence.bare > 0
        if slabs:
            withdrawn |= slab_contradicted(v, f, edges, label, n_loops, slabs, radius)
        engulfed = _engulfing(v, f, centre, radius)
        withdrawn |= engulfed
        taken = bool(withdrawn.any())      # a feature may have gone with a hole: no convex bound either
        hole_doubt[withdrawn] = 4.0 / 3.0 * np.pi * radius[withdrawn] ** 3
        creases = crease_fills(v, f, edges, label, n_loops, centre, radius, bare=bare)
        unbounded = _contradicted(evidence, radius, size)
    else:
        centre, radius, hole_doubt = np.zeros((0, 3)), np.zeros(0), np.zeros(0)
        engulfed = np.zeros(0, dtype=bool)
        unbounded = ""
        taken = False
    cone_doubt = hole_doubt.copy()
    curved: list[CurvedFill] = []

    def build(creases: list[CreaseFill], curved: list[CurvedFill]
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, Any, np.ndarray]:
        cap = np.stack([edges[:, 1], edges[:, 0], len(v) + label], axis=1) if n_loops else np.zeros((0, 3), np.int64)
        extra = np.zeros((0, 3))
        tops = apex.copy()
        if curved:            # holes on a quadric: the fan bent onto it (same bound: curved_fills)
            bent = np.zeros(n_loops, dtype=bool)
            base = len(v) + n_loops + 2 * len(creases)
            fills, at = [], 0
            for bend in curved:
                bent[bend.loop] = True
                tops[bend.loop] = bend.apex
                shifted = bend.caps.copy()
                shifted[shifted < 0] = base + at + (-1 - shifted[shifted < 0])
                fills.append(shifted)
                at += len(bend.points)
            cap = np.vstack([cap[~bent[label]], *fills])
            label_of = np.r_[label[~bent[label]], np.full(len(cap) - int(np.count_nonzero(~bent[label])), -1)]
        else:
            label_of = label
        doubts = cone_doubt.copy()
        if creases:           # holes across one crease: two planar fans instead of the cone (third assumption)
            crossed = np.zeros(n_loops, dtype=bool)
            fills = []
            for j, fill in enumerate(creases):
                crossed[fill.loop] = True
                # the two slabs bound the fill where the faces at its rim do not contradict the third
                # assumption (CreaseFill.narrow); else the whole ball (generated featured boxes that lost half
                # their faces showed fills 80-98 % low inside the two slabs)
                ball = 4.0 / 3.0 * np.pi * radius[fill.loop] ** 3
                doubts[fill.loop] = min(fill.doubt, ball) if fill.narrow else max(fill.doubt, ball)
                shifted = fill.caps.copy()
                shifted[shifted >= len(v)] += n_loops + 2 * j       # apexes after the cones' (kept for numbering)
                fills.append(shifted)
            # the cones (and bent fills: label −1) kept, the crease fills last (_crease_contradicted counts on it)
            cap = np.vstack([cap[(label_of < 0) | ~crossed[np.maximum(label_of, 0)]], *fills])
            extra = np.vstack([fill.apexes for fill in creases])
        pv = np.vstack([v, tops, extra, *[bend.points for bend in curved]])
        pf = np.vstack([f, cap])
        closed = moments(pv, pf)
        if closed.volume < 0:
            pf = pf[:, ::-1]
            closed = moments(pv, pf)
        return pv, pf, cap, closed, doubts

    pv, pf, cap, closed, hole_doubt = build(creases, curved)
    contradicted = _crease_contradicted(pv, pf, len(f), creases, n_loops, len(v)) if creases else []
    if contradicted:          # a crease fill lying over faces the file has: the two planes do not hold the hole
        cone_doubt[contradicted] = 4.0 / 3.0 * np.pi * radius[contradicted] ** 3
        creases = [fill for fill in creases if fill.loop not in set(contradicted)]
        pv, pf, cap, closed, hole_doubt = build(creases, curved)
    # the capsule over each rim (first assumption, for long thin rims): the region in doubt lies in it too
    start, end, thick = enclosing_capsules(v[vertex_of], loop_of, n_loops) if n_loops else (centre, centre, radius)

    def reach_of(point: np.ndarray) -> np.ndarray:
        """Per hole, the farthest a point of its region in doubt (ball ∩ capsule) can be from ``point``, m."""
        ball_reach = np.linalg.norm(centre - point, axis=1) + radius
        capsule_reach = np.maximum(np.linalg.norm(start - point, axis=1), np.linalg.norm(end - point, axis=1)) + thick
        nearer: np.ndarray = np.where(alone, np.minimum(ball_reach, capsule_reach), ball_reach)
        return nearer

    alone = np.zeros(n_loops, dtype=bool)

    if n_loops:
        in_slab = slabs["has"] & ~withdrawn if slabs else np.zeros(n_loops, dtype=bool)
        slab = ((slabs["normal"], slabs["origin"], np.where(in_slab, slabs["half_width"], np.inf)) if slabs else
                (np.zeros((n_loops, 3)), np.zeros((n_loops, 3)), np.full(n_loops, np.inf)))
        crossed = np.zeros(n_loops, dtype=bool)
        crossed[[fill.loop for fill in creases]] = True
        order = np.argsort(-np.where(crossed, -1.0, hole_doubt), kind="stable")
        order = order[~crossed[order]]
        curved = curved_fills(v, f, edges, label, n_loops, apex, centre, radius, (start, end, thick), slab, order)
        if curved:
            pv, pf, cap, closed, hole_doubt = build(creases, curved)
        # the capsule reads the hole as its rim's own thin disc: only where the ball over the rim is no larger
        # than the solid patched (where it is larger, what remains may be the small side: a box with a slot
        # that lost 17 of its 28 faces kept the slot's walls, and the capsule stated ±37 % for a truth 40 times
        # the estimate; found by tests/test_hole_capsules.py, hypothesis seed 202)
        alone = _alone(centre, radius) & ~engulfed & (4.0 / 3.0 * np.pi * radius ** 3 <= abs(float(closed.volume)))
        hole_doubt = np.where(alone, np.minimum(hole_doubt, capsule_volumes(start, end, thick)), hole_doubt)
    doubt = float(np.sum(hole_doubt))
    # the surface as given: the closed surface's area less the cones' (no second pass over every face)
    ca, cb, cc = pv[cap[:, 0]], pv[cap[:, 1]], pv[cap[:, 2]]
    area = float(closed.area) - float(0.5 * np.linalg.norm(np.cross(cb - ca, cc - ca), axis=1).sum())
    far = float(np.max(reach_of(closed.centroid))) if n_loops else 0.0
    convex = False
    if n_loops and doubt > 0 and not taken:
        # fourth assumption, where what remains is convex: the complete part is too (convex_hole_bound)
        outward = pf[:len(f)]
        bound = convex_hole_bound(pv, outward, float(closed.volume)) if not curved else None
        if curved:
            # where what remains is convex the cones stay: the convex bound needs the patch inside the part, as
            # the cones are (in the rims' hulls) and a bent fill need not be
            cones = build(creases, [])
            bound = convex_hole_bound(cones[0], cones[1][:len(f)], float(cones[3].volume))
            if bound is not None:
                curved = []
                pv, pf, cap, closed, _ = cones
                far = float(np.max(reach_of(closed.centroid)))
        if bound is not None and bound[0] < doubt:
            doubt, corners = bound
            far = float(np.max(np.linalg.norm(corners - closed.centroid, axis=1)))
            convex = True
    sealed = ""
    if seal is not None and (seal.welded or seal.split):
        doubt += seal.doubt(v)
        touched = seal.slack > 0
        if touched.any():
            corners = v[f[touched]]
            reach = np.linalg.norm(corners - closed.centroid, axis=2).max(axis=1) + seal.slack[touched]
            far = max(far, float(reach.max()))
        moved = round_up(float(seal.slack.max(initial=0.0)))
        sealed = (f"seams sealed ({seal.welded:,} crack vertices welded, {seal.split:,} T-junction vertices "
                  f"put on their edges, every corner within {moved:.3g} m of where it was); ")
    unc = uncertainty_from(closed.volume, closed.centroid, closed.second_moment, doubt, far)
    if n_loops:
        detail = (f"{sealed}{n_loops} boundary loop{'s' if n_loops != 1 else ''} ({len(edges):,} edges) "
                  "closed by cones to their centroids; bounded by the balls enclosing their rims, each cut to the "
                  "slab around the plane of the face beside it that the rim strays least from "
                  f"(largest radius {float(radius.max()):.3g} m)")
        if convex:
            detail += ("; what remains is convex, so the part is taken to be convex too and the holes bounded "
                       "instead by the polytope its faces' planes enclose")
        if creases:
            detail += (f"; {len(creases)} of them across a crease, filled instead in the two planes that hold "
                       "the rim and bounded by the ball cut to both planes' slabs")
    else:
        detail = f"{sealed}no hole left" if sealed else "no hole"
    return Estimate(volume=closed.volume, centroid=closed.centroid, second_moment=closed.second_moment, area=area,
                    uncertainty=unc, method="patched", detail=detail, vertices=pv, faces=pf, far=far,
                    unbounded=unbounded)


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
    planes = np.unique(np.round(np.column_stack([unit, offset]), 12), axis=0)
    used = np.unique(f)
    try:
        hull = ConvexHull(v[used])
    except (QhullError, ValueError):
        return None
    corners = v[used][hull.vertices]
    if len(planes) * len(corners) > CONVEX_WORK_LIMIT:
        return None
    tol = CONVEX_ROUND_OFF * _round_off(v)
    excess = np.full(len(planes), -np.inf)
    for lo in range(0, len(corners), 4096):
        chunk = corners[lo:lo + 4096]
        excess = np.maximum(excess, (chunk @ planes[:, :3].T - planes[:, 3]).max(axis=0))
    if float(excess.max()) > tol:
        return None                      # what remains is not convex
    shift = max(float(excess.max()), 0.0) + _round_off(v)
    inside = v[used].mean(axis=0)
    slack = planes[:, 3] + shift - planes[:, :3] @ inside
    if float(slack.min()) <= 10 * shift:
        return None
    halfspaces = np.column_stack([planes[:, :3], -(planes[:, 3] + shift)])
    try:
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


def _contradicted(evidence: RimEvidence, radius: np.ndarray, size: np.ndarray) -> str:
    """Why the faces left at some hole's rim contradict the bound's assumption (empty when none does).

    The bound assumes the missing surface of each hole stays near its rim (the ball, cut to the slab).  A hole
    that is an island in a flat face *and* has a bare rim vertex (:class:`RimEvidence`) contradicts it: on a
    surface with no vertex inside its flat faces the rim was a loop of the face, the footprint of something
    standing on it or sunk into it (a boss, a pocket, a connector housing) that the hole took whole, whose
    height nothing in the file bounds.
    """
    found = np.flatnonzero(evidence.flat_all_round & (evidence.bare > 0))
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
