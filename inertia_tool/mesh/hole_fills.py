"""Filling holes: the surfaces that close each boundary loop other than the plain cone to its centroid.

A hole across one crease of a faceted part is filled in the two planes that hold its rim (:func:`crease_fills`,
the third assumption of :mod:`~.holes`), and withdrawn where the file contradicts it (:func:`_crease_contradicted`);
a hole whose surroundings lie on one quadric is filled on it (:func:`curved_fills`); a hole on a faceted part is
filled on the planes of the faces round its rim, continued across it (:func:`plane_fills`).  The bounds they keep
are in :mod:`~.hole_bounds`; :func:`~.holes.patched_estimate` puts the two together.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..values import frozen_value
from .edges import unique_rows
from .hole_bounds import (BEND_MAX_DEGREES, FLAT_RIM_RTOL, FLAT_VERTEX_COSINE, _flat_off_rim_nearby, _round_off,
                          ball_slab_volume)


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
    margin = _round_off(v)
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
    pairs = unique_rows(np.stack([loop, slot // 3], axis=1)) if len(slot) else np.zeros((0, 2), np.int64)
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


def region_check(centre: np.ndarray, radius: np.ndarray, capsule: tuple[np.ndarray, np.ndarray, np.ndarray],
                  alone: np.ndarray, slab: tuple[np.ndarray, np.ndarray, np.ndarray]
                  ) -> Callable[[int, np.ndarray], bool]:
    """``inside(loop, points)``: whether every point lies in the region a hole's bound states — its ball, the
    capsule where the hole is read alone (``alone``), and the slab where it is cut to one (finite half-width) —
    so that a fill made of them leaves the bound as it is (:func:`plane_fills`; :func:`curved_fills`, with the
    capsule everywhere)."""
    start, end, thick = capsule
    normal, origin, half = slab

    def inside(k: int, points: np.ndarray) -> bool:
        if not bool((np.linalg.norm(points - centre[k], axis=1) <= radius[k]).all()):
            return False
        if alone[k]:
            seg = end[k] - start[k]
            t = np.clip((points - start[k]) @ seg / max(float(seg @ seg), 1e-300), 0.0, 1.0)
            if not bool((np.linalg.norm(points - (start[k] + t[:, None] * seg), axis=1) <= thick[k]).all()):
                return False
        if np.isfinite(half[k]):
            return bool((np.abs((points - origin[k]) @ normal[k]) <= half[k]).all())
        return True
    return inside


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
    # the fill must lie where the bound looks: in the ball, the capsule and the slab over the rim
    inside = region_check(centre, radius, (capsule[0], capsule[1], capsule[2]), np.ones(n_loops, dtype=bool), slab)
    out: list[CurvedFill] = []
    # the loops tried: the first ``max_loops`` in ``order`` long enough to be curved and not a pinch (decided
    # before any fit, so known up front: their neighbourhoods are grown over the faces near them alone)
    tried: list[tuple[int, np.ndarray, np.ndarray]] = []
    if max_loops > 0:
        by_loop = np.argsort(label, kind="stable")
        cuts = np.searchsorted(label[by_loop], np.arange(n_loops + 1))
        for k in order.tolist():
            rim_edges = edges[by_loop[cuts[k]:cuts[k + 1]]]
            rim = np.unique(rim_edges)
            if len(rim) < 5 or len(rim_edges) != len(rim):
                continue                               # too short to be curved, or a pinch
            tried.append((int(k), rim_edges, rim))
            if len(tried) >= max_loops:
                break
    near_faces = _faces_near(f, n, [rim for _, _, rim in tried])
    for k, rim_edges, rim in tried:
        near = _two_rings(near_faces, n, rim)
        fit = _fitted_quadric((v[near] - centre[k]) / radius[k], fit_rtol)
        if fit is None:
            continue                               # a plane (many quadrics fit) or no quadric: the cone stays
        a, b, q9 = fit
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
        gamma = _quadric(flat, a, b, q9)
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
        if not inside(k, moved):
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


def _fitted_quadric(x: np.ndarray, fit_rtol: float) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The one quadric ``Q(x) = xᵀ A x + b·x + c = 0`` through the points ``x`` (p, 3), scaled to about unit size,
    as ``(A, b, c)``; ``None`` when fewer than 12 points, when several quadrics fit (the next singular value is
    round-off: points on a plane or on two planes) or when some point lies farther than ``fit_rtol`` from it
    (``|Q|/|∇Q|``).  Ten coefficients: the right singular vector of the smallest singular value of
    ``[x², y², z², xy, yz, zx, x, y, z, 1]``."""
    if len(x) < 12:
        return None
    design = np.column_stack([x * x, x[:, 0] * x[:, 1], x[:, 1] * x[:, 2], x[:, 2] * x[:, 0], x, np.ones(len(x))])
    try:
        _, sv, vt = np.linalg.svd(design, full_matrices=False)
    except np.linalg.LinAlgError:
        return None
    if not sv[-2] > 1e-6 * sv[0]:
        return None
    q = vt[-1]
    a = np.array([[q[0], q[3] / 2, q[5] / 2], [q[3] / 2, q[1], q[4] / 2], [q[5] / 2, q[4] / 2, q[2]]])
    b = q[6:9]
    size = np.linalg.norm(2 * x @ a + b, axis=1)
    if not (size > 0).all() or float(np.max(np.abs(_quadric(x, a, b, q[9])) / size)) > fit_rtol:
        return None
    return a, b, float(q[9])


#: Least number of points for :func:`curved_surroundings` to read a fit as evidence: twice the quadric's ten
#: coefficients (12 points of a box-like part fit some ellipsoid to 1e-3 by chance: Stretch ``link_lift_2.obj``).
CURVED_MIN_POINTS = 20

#: The quadric's 4×4 form is read as curved when its third singular value exceeds this share of the first (a
#: plane pair has rank 2; a cylinder or cone rank 3, a sphere rank 4).
CURVED_MIN_RANK_RTOL = 1e-3


def curved_surroundings(vertices: np.ndarray, faces: np.ndarray, rims: list[np.ndarray], centre: np.ndarray,
                        radius: np.ndarray, *, fit_rtol: float = QUADRIC_FIT_RTOL) -> np.ndarray:
    """Per rim, whether the vertices of the faces within two rings of it lie on one curved quadric, (k,) bool.

    The same fit as :func:`curved_fills` (:func:`_fitted_quadric`, in coordinates centred on the ball over the
    rim and scaled by its radius), read as evidence only from :data:`CURVED_MIN_POINTS` points up and only for a
    quadric of rank 3 or more (:data:`CURVED_MIN_RANK_RTOL`): a sphere, cylinder or cone round the rim fits one;
    a plane, two planes (a prism's wall and the face at its other end) or a faceted part with features does not.
    The planar-rim reading (:func:`~.hole_bounds.planar_rim_doubt`) is withdrawn where this holds: a sphere cut
    by a plane leaves a planar rim whose surface continues round over the hole.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    rims : list of (r,) int arrays
        The vertices of each rim.
    centre, radius : (k, 3), (k,) float
        The ball over each rim.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    out = np.zeros(len(rims), dtype=bool)
    near_faces = _faces_near(f, len(v), rims)
    for k, rim in enumerate(rims):
        near = _two_rings(near_faces, len(v), rim)
        x = (v[near] - centre[k]) / radius[k]
        fit = _fitted_quadric(x, fit_rtol) if len(x) >= CURVED_MIN_POINTS else None
        if fit is None:
            continue
        a, b, c = fit
        form = np.block([[a, b[:, None] / 2], [b[None, :] / 2, np.array([[c]])]])
        sv = np.linalg.svd(form, compute_uv=False)
        out[k] = bool(sv[2] > CURVED_MIN_RANK_RTOL * sv[0])      # rank ≥ 3: not a plane or a pair of planes
    return out


def _faces_near(faces: np.ndarray, n_vertices: int, rims: list[np.ndarray]) -> np.ndarray:
    """The faces with a vertex within one ring of some rim's vertices, (q, 3) int: all the faces that
    :func:`_two_rings` of any of ``rims`` can reach, so that growing a rim over them marks the same vertices as
    growing it over every face, at the cost of the neighbourhood instead of the mesh (two passes over all faces
    once, instead of two per rim).

    Parameters
    ----------
    faces : (m, 3) int
    n_vertices : int
    rims : list of (r,) int arrays
        Vertex indices of each rim.
    """
    near = np.zeros(n_vertices, dtype=bool)
    for rim in rims:
        near[rim] = True
    near[faces[near[faces].any(axis=1)].reshape(-1)] = True     # the first ring of every rim
    subset: np.ndarray = faces[near[faces].any(axis=1)]
    return subset


def _two_rings(faces: np.ndarray, n_vertices: int, rim: np.ndarray) -> np.ndarray:
    """The vertices of the faces within two rings of ``rim``, (n_vertices,) bool: the rim's vertices, those of
    every face holding one, then those of every face holding one of those.  ``faces`` may be
    :func:`_faces_near` of a list of rims holding ``rim`` (the same mask)."""
    near = np.zeros(n_vertices, dtype=bool)
    near[rim] = True
    for _ in range(2):
        near[faces[near[faces].any(axis=1)].reshape(-1)] = True
    return near


def _quadric(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: float) -> np.ndarray:
    """``Q(p) = pᵀ A p + b·p + c`` at each row of ``p`` (k, 3)."""
    value: np.ndarray = np.einsum("ij,jk,ik->i", p, a, p) + p @ b + c
    return value


#: Levels of the plane-continuation fill between the cone's apex and the rim (:func:`plane_fills`): each cone
#: triangle becomes about ``PLANE_FILL_LEVELS²`` triangles, so a crease of the continued planes that crosses it is
#: followed to a share of about ``1 / PLANE_FILL_LEVELS²`` of the volume the crease lifts.
PLANE_FILL_LEVELS = 12
#: Most holes given a plane-continuation fill (those with the most doubt first; the rest keep their fill).
PLANE_MAX_LOOPS = 32
#: Most rim corners of a hole given a plane-continuation fill (each adds ``PLANE_FILL_LEVELS²`` points).
PLANE_MAX_RIM = 256
#: Most distinct planes of the faces at a rim read as a faceted surface: more are a tessellated curved surface,
#: whose facets' planes continued overshoot it as far as the cone falls short (and a quadric fill is the one for it).
PLANE_MAX_PLANES = 24


@frozen_value
class PlaneFill:
    """A hole filled on the planes of the faces round its rim, continued across it (:func:`plane_fills`).

    Attributes
    ----------
    loop : int
        The boundary loop.
    apex : (3,) float
        Where the cone's apex moved to (onto the continued planes), m.
    points : (p, 3) float
        The fill's inner points, m.
    caps : (q, 3) int
        Its triangles: rim vertices by their index, the apex as ``n_vertices + loop`` (the cone's), the inner
        points as ``−1 − i`` (the caller numbers them).
    lift : (p + 1,) float
        How far the apex and each inner point moved from the cone along the hole's outward direction, m
        (≥ 0 everywhere where the fill lies outside the cone).
    planes : int
        The distinct planes continued.
    convex : bool
        True where the surroundings are convex (the solid is the intersection of the planes' half-spaces, the
        fill their lower envelope), False where concave (their union, the upper envelope).
    """

    loop: int
    apex: np.ndarray
    points: np.ndarray
    caps: np.ndarray
    lift: np.ndarray
    planes: int
    convex: bool


def _sector_grid(rim_edges: np.ndarray, slot: np.ndarray, levels: int) -> tuple[np.ndarray, np.ndarray]:
    """The cone's fan over a rim, split into ``levels`` rows between the apex and the rim.

    Row ``l = 1 … levels − 1`` of the triangle over rim edge ``i`` (``e0 → e1``, ``slot`` (k, 2) the places of
    its corners in the sorted rim) holds ``l + 1`` points ``apex + (l / levels) ((1 − t) (e0 − apex) + t (e1 −
    apex))``, ``t = j / l``; row 0 is the apex and the rim row holds ``e0`` and ``e1`` alone, so the fill's
    boundary is exactly the rim.  The points on a spoke ``apex → e`` are shared by the two triangles at ``e``.

    Returns
    -------
    caps : (q, 3) int
        The triangles, wound as the cone's ``(e1, e0, apex)``: rim corners by their index, the apex as ``−1``,
        inner point ``i`` as ``−2 − i``.
    weights : (p, 4) float
        Inner point ``i`` as ``[slot a, slot b, s_a, s_b]``: at ``apex + s_a (rim[a] − apex) + s_b (rim[b] −
        apex)``.
    """
    n_edges = len(rim_edges)
    n_slots = int(slot.max()) + 1 if len(slot) else 0
    inner = levels - 1                                   # spoke points per rim vertex (rows 1 … levels − 1)
    weights: list[list[float]] = []
    for s in range(n_slots):                             # spoke points: slot s, row l at −2 − (s · inner + l − 1)
        for level in range(1, levels):
            weights.append([s, s, level / levels, 0.0])

    def spoke(s: int, level: int) -> int:
        return -1 if level == 0 else -2 - (s * inner + level - 1)

    caps: list[list[int]] = []
    for i in range(n_edges):
        a, b = int(slot[i, 0]), int(slot[i, 1])
        rows: list[list[int]] = [[-1]]
        for level in range(1, levels):
            row = [spoke(a, level)]
            for j in range(1, level):
                t = j / level
                weights.append([a, b, level / levels * (1.0 - t), level / levels * t])
                row.append(-2 - (len(weights) - 1))
            row.append(spoke(b, level))
            rows.append(row)
        for level in range(levels - 1):
            upper, lower = rows[level], rows[level + 1]
            for j in range(len(upper)):
                caps.append([upper[j], lower[j + 1], lower[j]])
                if j + 1 < len(upper):
                    caps.append([upper[j], upper[j + 1], lower[j + 1]])
        last = rows[levels - 1]
        e0, e1 = int(rim_edges[i, 0]), int(rim_edges[i, 1])
        half = (len(last) - 1) // 2
        for j in range(len(last) - 1):
            caps.append([last[j], last[j + 1], e0 if j < half else e1])
        caps.append([last[half], e1, e0])
    return np.array(caps, dtype=np.int64), np.array(weights, dtype=np.float64).reshape(-1, 4)


def _continues_at_rim(v: np.ndarray, f: np.ndarray, rim: np.ndarray, corner_order: np.ndarray,
                      corner_start: np.ndarray, unit: np.ndarray, offset: float, tol: float) -> bool:
    """Whether some rim vertex has every face at it within ``tol`` of the plane ``unit · x = offset`` (the flat face
    goes on across the rim there: the vertex lies inside it, not on its border)."""
    for x in rim.tolist():
        at = corner_order[corner_start[x]:corner_start[x + 1]] // 3
        if len(at) and float(np.abs(v[f[at]] @ unit - offset).max()) <= tol:
            return True
    return False


def plane_fills(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, loops: np.ndarray,
                apex: np.ndarray, radius: np.ndarray, inside: Callable[[int, np.ndarray], bool], *,
                outward: float = 1.0, rtol: float = FLAT_RIM_RTOL, levels: int = PLANE_FILL_LEVELS,
                max_loops: int = PLANE_MAX_LOOPS, max_rim: int = PLANE_MAX_RIM,
                max_planes: int = PLANE_MAX_PLANES,
                wall_cosine: float = float(np.cos(np.radians(BEND_MAX_DEGREES)))) -> list[PlaneFill]:
    """Holes filled on the planes of the faces round their rims, continued across them (a better estimate on a
    faceted part, the same bound).

    On a faceted part the surface a hole took lies, most often, on the planes of the faces still there round
    it: a box's side, a cone's facets meeting at its apex, three planes at a corner.  The faces with a corner on
    the rim (the ring) give planes ``n_j · x = c_j`` (``n_j`` outward, unit).  Where every rim vertex lies inside
    every one of them (within ``rtol`` of the ball's radius: the surroundings are *convex*) the solid there is
    their half-spaces' intersection, and its surface over a point ``p`` of the cone, along the hole's outward
    direction ``d`` (the cone's vector area), is at ``p + λ d``, ``λ = min_j (c_j − n_j·p) / (n_j·d)`` over the
    planes facing ``d`` (the planes' lower envelope); where every rim vertex lies outside or on every plane
    (*concave*: a pocket's corner) the union's, ``λ = max_j``, every plane facing ``d``.  Mixed surroundings, a
    single plane (the cone already lies in it), more than ``max_planes`` distinct planes (a tessellated curved
    surface, whose facet planes overshoot it) or a pinched rim keep their fill.  The cone's fan, split into
    ``levels`` rows (:func:`_sector_grid`), is lifted point by point onto that envelope; the rim stays.

    **The bound does not change**: the region in doubt lies where the cycle "fill − missing surface" winds, and
    both lie in the convex region the hole's bound states (the ball over the rim, with the capsule and the slab
    where taken) when every point of the fill does: ``inside(loop, points)`` is asked of the apex and the inner
    points, and a fill with a point outside keeps the cone.  So the planes must *close* the hole inside that
    region; where they diverge (a face lost with its plane, the octahedron's) the fill leaves it and is not made.
    ``loops`` lists the loops by decreasing doubt; at most ``max_loops`` are tried, one at a time.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    edges : (k, 2) int
        Boundary edges ``a → b`` (each the edge of one face in that direction), ``label`` (k,) their loop.
    loops : (j,) int
    apex : (n_loops, 3) float
        The cone's apex of each loop, m.
    radius : (n_loops,) float
        The ball's radius over each rim, m (sets the tolerance ``rtol · radius``).
    inside : callable
        ``inside(loop, points (p, 3)) -> bool``: whether every point lies in the region the hole's bound states.
    outward : float
        +1 where the faces are wound outward, −1 where inward (the patched solid's volume sign).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    margin = _round_off(v)
    corner_order = np.argsort(f.reshape(-1), kind="stable")
    corner_start = np.searchsorted(f.reshape(-1)[corner_order], np.arange(n + 1))
    out: list[PlaneFill] = []
    for k in np.asarray(loops, dtype=np.int64)[:max_loops].tolist():
        rim_edges = edges[label == k]
        rim = np.unique(rim_edges)
        if len(rim_edges) < 3 or len(rim) != len(rim_edges) or len(rim) > max_rim:
            continue                                   # a pinch, or too long to fill point by point
        ring = np.unique(np.concatenate([corner_order[corner_start[x]:corner_start[x + 1]] // 3
                                         for x in rim.tolist()]))
        a0 = v[f[ring, 0]]
        normal = outward * np.cross(v[f[ring, 1]] - a0, v[f[ring, 2]] - a0)
        length = np.linalg.norm(normal, axis=1)
        keep = length > 0
        if not keep.any():
            continue
        unit = normal[keep] / length[keep, None]
        offset = np.einsum("ij,ij->i", unit, a0[keep])
        tol = rtol * float(radius[k]) + margin
        spread = v[rim] - v[rim].mean(axis=0)
        planar = float(np.abs(spread @ np.linalg.svd(spread, full_matrices=False)[2][-1]).max()) <= tol
        distinct = np.unique(np.round(np.column_stack([unit, offset / max(float(radius[k]), 1e-300)]) / rtol),
                             axis=0)
        if len(distinct) < 2 or len(distinct) > max_planes:
            continue
        top = apex[k]
        e0, e1 = v[rim_edges[:, 0]], v[rim_edges[:, 1]]
        d = outward * 0.5 * np.cross(e0 - e1, top - e1).sum(axis=0)
        size = float(np.linalg.norm(d))
        if not size > 0:
            continue
        d = d / size
        facing = unit @ d
        carries = facing > wall_cosine                # planes the fill can lie on; the others are walls
        # each plane's side of the rim: every rim vertex inside it (within tol), or every one outside or on it
        excess = v[rim] @ unit.T - offset[None, :]
        slot = np.searchsorted(rim, rim_edges)
        on = (np.abs(excess) <= tol) & carries[None, :]
        if not carries.any() or not bool((on[slot[:, 0]] & on[slot[:, 1]]).any(axis=1).all()):
            continue                                   # a rim edge on walls alone: a graph over d cannot go on them
        inner, outer = excess.max(axis=0) <= tol, excess.min(axis=0) >= -tol
        if not (inner | outer).all():
            continue                                   # the rim lies on both sides of a plane: no envelope
        convex = bool(inner[carries].all())
        if not convex and not bool(outer[carries].all()):
            continue                                   # mixed: neither the planes' intersection nor their union
        caps, weights = _sector_grid(rim_edges, slot, levels)
        sa, sb = weights[:, 2:3], weights[:, 3:4]
        flat = np.vstack([top[None, :], top + sa * (v[rim[weights[:, 0].astype(np.int64)]] - top)
                          + sb * (v[rim[weights[:, 1].astype(np.int64)]] - top)])
        heights = (offset[carries][None, :] - flat @ unit[carries].T) / facing[carries][None, :]
        lift = heights.min(axis=1) if convex else heights.max(axis=1)
        if planar:
            # a planar rim is also what a lost flat face leaves (the octahedron less a face: the cone is exact, the
            # planes round it make a pyramid): the planes are continued only where the file shows each plane the
            # fill lies on going on across the rim, at a rim vertex whose every face lies in that plane
            used = np.flatnonzero(carries)[np.unique(heights.argmin(axis=1) if convex else heights.argmax(axis=1))]
            if not all(_continues_at_rim(v, f, rim, corner_order, corner_start, unit[j], offset[j], tol)
                       for j in used.tolist()):
                continue
        moved = flat + lift[:, None] * d
        if not np.isfinite(moved).all():
            continue
        # the fill keeps every plane's side the rim keeps (a wall's too): else the planes do not close the hole
        side = moved @ unit.T - offset[None, :]
        keeps_inside = (inner & ~outer) | (inner & outer & convex)
        wrong = np.where(keeps_inside, side > tol, side < -tol)
        if wrong.any():
            continue
        if not inside(k, moved):
            continue                                   # the planes do not close the hole in the bound's region
        caps = caps.copy()
        caps[caps == -1] = n + k
        inner_ids = caps < -1
        caps[inner_ids] = -1 - (-2 - caps[inner_ids])   # inner point i as −1 − i
        out.append(PlaneFill(loop=int(k), apex=moved[0], points=moved[1:], caps=caps, lift=lift,
                             planes=int(len(distinct)), convex=convex))
    return out
