"""Bodies whose faces overlap in a common plane: the solid {winding number ≥ 1} by a planar overlay.

Two bodies welded along an edge of a plane they both stand on (two L-shaped prisms on one grid, their bottoms
in one plane facing the same way) make one closed surface whose faces overlap there, coplanar.  Which faces
close which body is undefined at such an edge (rule R1b of :mod:`~.policy`), but the winding number ``w`` of
the whole surface is not, and the solid meant is ``{w ≥ 1}`` (Rigid Body Motion, Ch. 4: the volume integrals
as surface sums hold for a region bounded once).  The mesh arrangement of :mod:`~.arrange` cannot form it:
it cuts faces along *transversal* intersection segments (edge–face piercing points, computed as the meeting
point of an edge and a plane) and refuses a coplanar pair, since an edge lying in the other face's plane has
no piercing point, the two faces meet in a polygon rather than a segment, and the winding number jumps by the
*net* number of faces covering each part of that polygon (2 where two faces face the same way, 0 where they
face each other), not by one as its labels assume.  :func:`arrange_coplanar` builds the boundary instead:

1. *Planes.*  The faces that overlap a coplanar face beyond what they share (same or opposite orientation,
   from :func:`~.intersect.surface_contacts`, and faces repeated with the same corners) are grouped by their
   exact plane (integer normal and offset, reduced).
2. *Overlay.*  In each plane every edge of the group is split at the group's corners lying on it and at its
   proper crossings with the group's other edges (exact orientation signs on integer coordinates; crossing
   points rational, rounded once to float64).  Each face is triangulated in its plane with the overlay's points
   in it and the overlay's segments through it as constraints (the constrained triangulation of
   :mod:`~.arrange`), so that every small triangle lies in one cell of the overlay.
3. *Net cover.*  A cell covered by faces ``g`` with orientations ``s_g = ±1`` is a sheet of multiplicity
   ``c = Σ s_g``; it is written once (by the covering face of smallest index), wound by the sign of ``c``, and
   left out where ``c = 0`` (faces face to face).  Across it ``w`` changes by ``|c|``.
4. *Labels.*  Pieces joined through edges used by exactly two pieces form patches with ``w`` constant on each
   side.  At a point ``p`` of a patch the winding number of every face outside the piece's plane, ``W(p)``
   (solid-angle sum with a rounding bound, :func:`~.arrange._winding_except`), gives ``w_front = W − c/2`` and
   ``w_back = w_front + c``; accepted only when the bound keeps the integer unique.
5. *Kept.*  The pieces with ``w_front ≤ 0 < w_back`` bound ``{w ≥ 1}``, wound outward.  Checks: the split
   surface balances every edge with multiplicity, the kept one is closed (every directed edge matched by its
   reverse), and the face-pair check finds no two of its faces crossing or overlapping.

Scope: a surface whose faces meet beyond what they share only in coplanar overlaps (and touches within one
plane).  A transversal crossing, or an edge or corner of one face lying on a face of another plane, is refused
with that reason (:class:`~inertia_tool.errors.ArrangementError`), never guessed.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction
from math import gcd

import numpy as np

from ..errors import ArrangementError
from ..values import frozen_value
from .arrange import (_U, WINDING_MARGIN, _compact, _Exact, _FaceTriangulation, _Hom, _inside_face, _orient2d,
                      _patches, _projection, _winding_terms, _winding_total, rounded_points_bounds)
from .edges import edge_keys, unique_rows
from .intersect import SurfaceContacts, orient3d_sign, surface_contacts
from .multiplicity import cancel_opposite, signed_multiplicity
from .precision import RoundedRegion, rounded_region

__all__ = ["CoplanarArrangement", "arrange_coplanar", "MAX_GROUP_EDGES"]

#: Work bound: edges of one plane's group of overlapping faces (their pairs are tested for crossings, in time
#: growing with the square); a larger group is refused with the count.
MAX_GROUP_EDGES = 4000

#: Work bound: points of the overlay in one face (each face is triangulated on its own).
MAX_POINTS_PER_FACE = 1000

#: Pieces tried per patch (largest first) before the patch is refused as too close to other surfaces.
_TRIES = 12


@frozen_value
class CoplanarArrangement:
    """The boundary of ``{w ≥ 1}`` of a surface whose faces overlap in common planes.

    Attributes
    ----------
    vertices : (n, 3) float64
        m; the input's used vertices, then the overlay's crossing points (each rounded once from its exact value).
    faces : (k, 3) int64
        Closed (every directed edge matched by its reverse), wound outward.
    coplanar_pairs : int
        Face pairs of the input overlapping in a common plane (same or opposite orientation, repeated faces).
    planes : int
        Planes in which faces overlap.
    split_faces : int
        Input faces triangulated along the overlay.
    new_vertices : int
        Crossing points of the overlay added.
    patches : int
        Patches of constant winding (each labelled by one certified winding-number evaluation).
    max_winding : int
        Largest winding number met (2 where two bodies overlap).
    crossings_left : int
        Face pairs of the output that cross or overlap (new points rounded to float64); 0 certifies it.
    cancelled_faces : int
        Faces taken out before the overlay as zero chains (:func:`_zero_chains`): a face with its reverse, and
        coplanar patches whose boundaries are each other's reverse.
    rounding : (float, float, float)
        What rounding the overlay's new points to float64 may change in the result (volume relative, centroid m,
        inertia relative; :func:`~.arrange.rounded_points_bounds`, refused above half of ``ROUNDOFF_RTOL``); zeros
        when the result uses no new point.
    region : RoundedRegion or None
        The same figure in absolute units, for R7 to judge against the final solid
        (:class:`~.precision.RoundedRegion`); None when the result uses no new point.
    """

    vertices: np.ndarray
    faces: np.ndarray
    coplanar_pairs: int
    planes: int
    split_faces: int
    new_vertices: int
    patches: int
    max_winding: int
    crossings_left: int = 0
    cancelled_faces: int = 0
    rounding: tuple[float, float, float] = (0.0, 0.0, 0.0)
    region: RoundedRegion | None = None


def _normal_key(exact: _Exact, faces: np.ndarray, face: int) -> tuple[tuple[int, int, int, int], int]:
    """The reduced plane ``(n, d)`` of a face with the first nonzero normal component positive, and ``±1``: the
    face's own orientation relative to it."""
    (nx, ny, nz), d = exact.plane(faces, face)
    g = gcd(gcd(gcd(abs(nx), abs(ny)), abs(nz)), abs(d)) or 1
    key = (nx // g, ny // g, nz // g, d // g)
    first = next(x for x in key[:3] if x != 0)
    if first < 0:
        return (-key[0], -key[1], -key[2], -key[3]), -1
    return key, 1


def _reduced(p: _Hom) -> _Hom:
    g = gcd(gcd(gcd(abs(p[0]), abs(p[1])), abs(p[2])), abs(p[3])) or 1
    return (p[0] // g, p[1] // g, p[2] // g, p[3] // g)


def _coplanar_pairs(v: np.ndarray, f: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(k,) bool: the pairs whose second face has all three corners in the first face's plane (exact)."""
    if not len(pairs):
        return np.zeros(0, dtype=bool)
    a, b = f[pairs[:, 0]], f[pairs[:, 1]]
    sides = [orient3d_sign(v[a[:, 0]], v[a[:, 1]], v[a[:, 2]], v[b[:, j]]) for j in range(3)]
    return np.asarray(np.all(np.stack(sides, axis=1) == 0, axis=1))


def _repeated_pairs(f: np.ndarray) -> np.ndarray:
    """(k, 2) int: pairs of faces with the same three corners (either orientation); the face-pair check does
    not report them (they share everything by index)."""
    canon = np.sort(f, axis=1)
    _, inverse, counts = unique_rows(canon, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    many = np.flatnonzero(counts[inverse] > 1)
    rows: list[tuple[int, int]] = []
    groups: dict[int, list[int]] = {}
    for i in many.tolist():
        groups.setdefault(int(inverse[i]), []).append(i)
    for members in groups.values():
        rows += [(a, b) for k, a in enumerate(members) for b in members[k + 1:]]
    return np.asarray(rows, dtype=np.int64).reshape(-1, 2)


def _along(exact_hom: dict[int, _Hom], a: int, b: int, p: _Hom) -> Fraction:
    """Position of ``p`` (on the line a→b) along it, as a fraction of the edge on its longest axis."""
    pa, pb = exact_hom[a], exact_hom[b]
    k = max(range(3), key=lambda i: abs(pb[i] - pa[i]))
    return (Fraction(p[k], p[3]) - pa[k]) / (pb[k] - pa[k])


class _Overlay:
    """The overlay of one plane's faces: points keyed by exact coordinates, each edge's chain of points."""

    def __init__(self, exact: _Exact, faces: np.ndarray, hom: dict[int, _Hom], ids: dict[_Hom, int],
                 on_edge: dict[tuple[int, int], dict[int, Fraction]], new_point: Callable[[_Hom], int]) -> None:
        self.exact, self.faces, self.hom, self.ids, self.on_edge = exact, faces, hom, ids, on_edge
        self.new_point = new_point

    def add(self, members: list[int], normal: tuple[int, int, int]) -> set[int]:
        """Put the group's corners on the edges they lie on and the edges' crossing points on both edges;
        return the group's points."""
        f = self.faces
        i, j = _projection(normal)
        corners = sorted({int(x) for g in members for x in f[g]})
        edges = sorted({(min(int(f[g][e]), int(f[g][(e + 1) % 3])), max(int(f[g][e]), int(f[g][(e + 1) % 3])))
                        for g in members for e in range(3)})
        if len(edges) > MAX_GROUP_EDGES:
            raise ArrangementError(f"{len(edges):,} edges of faces overlapping in one plane, more than the "
                                   f"overlay's work bound of {MAX_GROUP_EDGES:,}")

        def xy(vid: int) -> tuple[int, int, int]:
            p = self.hom[vid]
            return (p[i], p[j], p[3])

        box = {e: (min(xy(e[0])[0], xy(e[1])[0]), max(xy(e[0])[0], xy(e[1])[0]),
                   min(xy(e[0])[1], xy(e[1])[1]), max(xy(e[0])[1], xy(e[1])[1])) for e in edges}
        points = set(corners)
        for a, b in edges:                           # corners lying inside an edge
            xa, xb = xy(a), xy(b)
            lo_x, hi_x, lo_y, hi_y = box[(a, b)]
            for c in corners:
                if c in (a, b):
                    continue
                xc = xy(c)
                if not (lo_x <= xc[0] <= hi_x and lo_y <= xc[1] <= hi_y) or _orient2d(xa, xb, xc) != 0:
                    continue
                t = _along(self.hom, a, b, self.hom[c])
                if 0 < t < 1:
                    self.on_edge.setdefault((a, b), {})[c] = t
        for n1, (a, b) in enumerate(edges):           # proper crossings of two edges
            xa, xb = xy(a), xy(b)
            b1 = box[(a, b)]
            for c, d in edges[n1 + 1:]:
                if len({a, b, c, d}) < 4:
                    continue
                b2 = box[(c, d)]
                if b1[1] < b2[0] or b2[1] < b1[0] or b1[3] < b2[2] or b2[3] < b1[2]:
                    continue
                xc, xd = xy(c), xy(d)
                oa, ob = _orient2d(xc, xd, xa), _orient2d(xc, xd, xb)
                if oa * ob >= 0 or _orient2d(xa, xb, xc) * _orient2d(xa, xb, xd) >= 0:
                    continue
                # the crossing in 3-D: (oa·B − ob·A)/(oa − ob) with the signed areas of the projection
                sa, sb = self._signed_area(xc, xd, xa), self._signed_area(xc, xd, xb)
                pa, pb = self.hom[a], self.hom[b]
                w = sa - sb
                x = tuple(sa * pb[k] - sb * pa[k] for k in range(3))
                hom = _reduced((x[0], x[1], x[2], w) if w > 0 else (-x[0], -x[1], -x[2], -w))
                vid = self.ids.get(hom)
                if vid is None:
                    vid = self.new_point(hom)
                points.add(vid)
                for e in ((a, b), (c, d)):
                    if vid not in e:
                        self.on_edge.setdefault(e, {})[vid] = _along(self.hom, e[0], e[1], hom)
        return points

    @staticmethod
    def _signed_area(p: tuple[int, int, int], q: tuple[int, int, int], r: tuple[int, int, int]) -> int:
        """orient2d of three integer points (w = 1), with its value."""
        return (p[0] - r[0]) * (q[1] - r[1]) - (p[1] - r[1]) * (q[0] - r[0])


def _chain(on_edge: dict[tuple[int, int], dict[int, Fraction]], a: int, b: int) -> list[int]:
    """The points on edge a→b from a to b (ends included)."""
    pts = on_edge.get((min(a, b), max(a, b)), {})
    inner = [vid for vid, _ in sorted(pts.items(), key=lambda kv: kv[1])]
    return [a, *(inner if a < b else inner[::-1]), b]


def _centroid(h: list[_Hom]) -> _Hom:
    (x1, y1, z1, w1), (x2, y2, z2, w2), (x3, y3, z3, w3) = h
    return _reduced((x1 * w2 * w3 + x2 * w1 * w3 + x3 * w1 * w2, y1 * w2 * w3 + y2 * w1 * w3 + y3 * w1 * w2,
                     z1 * w2 * w3 + z2 * w1 * w3 + z3 * w1 * w2, 3 * w1 * w2 * w3))


def arrange_coplanar(vertices: np.ndarray, faces: np.ndarray) -> CoplanarArrangement:
    """The boundary of ``{w ≥ 1}`` of a closed surface whose faces overlap only in common planes (module docs).

    Parameters
    ----------
    vertices : (n, 3) float
        m (any unit).
    faces : (m, 3) int
        A closed surface (every directed edge matched by its reverse, non-manifold edges allowed), wound so that
        its inside has a positive winding number.

    Returns
    -------
    CoplanarArrangement

    Raises
    ------
    ArrangementError
        Faces that also cross transversally or touch a face of another plane, a work bound, a patch whose winding
        number cannot be certified, or an output that fails its checks; the message says which.
    """
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    n = len(v)
    keep = cancel_opposite(f)                  # a face with its reverse: the zero chain (R0's count with sign)
    f = f[keep]
    cancelled = int(len(keep) - np.count_nonzero(keep))
    found = surface_contacts(v, f)
    if not found.complete:
        raise ArrangementError("the face-intersection check did not finish")
    zero = _zero_chains(_Exact(v, np.unique(f)), f, _overlapping(found, f))
    if zero.any():                             # coplanar patches that cancel: taken out before any point is made
        f = f[~zero]
        cancelled += int(np.count_nonzero(zero))
        found = surface_contacts(v, f)
        if not found.complete:
            raise ArrangementError("the face-intersection check did not finish")
    if not len(_overlapping(found, f)) and not len(found.crossing):
        return _as_it_stands(v, f, cancelled)
    crossing = np.asarray(found.crossing, dtype=np.int64).reshape(-1, 2)
    flat = _coplanar_pairs(v, f, crossing)
    if not flat.all():
        raise ArrangementError(f"{int(np.count_nonzero(~flat)):,} face pairs cross transversally as well (the "
                               "coplanar overlay handles faces overlapping in a common plane only)")
    contact = np.asarray(found.contact, dtype=np.int64).reshape(-1, 2)
    touching = _coplanar_pairs(v, f, contact)
    exact = _Exact(v, np.unique(f))
    tri3 = v[f]
    area = np.linalg.norm(np.cross(tri3[:, 1] - tri3[:, 0], tri3[:, 2] - tri3[:, 0]), axis=1)
    tiny = np.flatnonzero(area <= 1e-8 * max(float(np.max(np.abs(tri3))), 1e-300) ** 2)
    if any(exact.plane(f, int(k))[0] == (0, 0, 0) for k in tiny.tolist()):
        raise ArrangementError("a face has zero area (three collinear corners): it has no plane to overlay in")
    across = contact[~touching]
    inside_touches = [(int(g), int(h)) for g, h in across.tolist()
                      if _touches_inside(exact, f, g, h) or _touches_inside(exact, f, h, g)]
    if inside_touches:
        raise ArrangementError(f"{len(inside_touches):,} face pairs touch across planes inside a face (a corner or "
                               "edge of a face on the interior of a face of another plane): not handled by the "
                               "coplanar overlay")
    overlapping = np.concatenate([crossing, np.asarray(found.coplanar_opposite, dtype=np.int64).reshape(-1, 2),
                                  _repeated_pairs(f)])
    involved = np.unique(np.concatenate([overlapping.reshape(-1), contact[touching].reshape(-1)]))
    hom: dict[int, _Hom] = {vid: (p[0], p[1], p[2], 1) for vid, p in exact.point.items()}
    ids: dict[_Hom, int] = {}
    for vid in np.unique(f[involved]).tolist():
        if ids.setdefault(hom[vid], vid) != vid:
            raise ArrangementError("two vertices of faces overlapping in a plane have the same coordinates (the "
                                   "surface is not welded there)")
    new_xyz: list[tuple[float, float, float]] = []

    def new_point(point: _Hom) -> int:
        vid = n + len(new_xyz)
        hom[vid], ids[point] = point, vid
        new_xyz.append(exact.to_float(point))
        return vid

    # 1. planes
    groups: dict[tuple[int, int, int, int], list[int]] = {}
    sign: dict[int, int] = {}
    for face in involved.tolist():
        plane_key, s = _normal_key(exact, f, face)
        groups.setdefault(plane_key, []).append(face)
        sign[face] = s
    # 2. the overlay of each plane
    on_edge: dict[tuple[int, int], dict[int, Fraction]] = {}
    overlay = _Overlay(exact, f, hom, ids, on_edge, new_point)
    group_points = {k: overlay.add(members, (k[0], k[1], k[2])) for k, members in groups.items()}
    group_of = {face: k for k, members in groups.items() for face in members}
    split = set(involved.tolist())
    if on_edge:                            # faces of other planes whose edges carry overlay points: split too
        keys, _ = edge_keys(f, n)
        carried = np.fromiter(((lo * n + hi) for (lo, hi), pts in on_edge.items() if pts), dtype=np.int64)
        split |= set((np.flatnonzero(np.isin(keys, carried)) // 3).tolist())
    pieces: list[list[int]] = []
    cover: list[int] = []              # multiplicity of each piece
    source: list[int] = []
    for face in sorted(split):
        corners = [int(x) for x in f[face]]
        normal, _ = exact.plane(f, face)
        i, j = _projection(normal)
        plane = group_of.get(face)
        members = groups[plane] if plane is not None else [face]
        verts = set(corners)
        for e in range(3):
            verts |= set(_chain(on_edge, corners[e], corners[(e + 1) % 3]))
        boundary = set(verts)
        segments: list[tuple[int, int]] = []
        if plane is not None:
            inner = [p for p in group_points[plane] | {q for (lo, hi) in _group_edges(f, members)
                                                     for q in on_edge.get((lo, hi), {})}
                     if p not in boundary and _inside_face(exact, f, face, hom[p]) > 0]
            verts |= set(inner)
            inside = verts
            for lo, hi in _group_edges(f, members):
                chain = _chain(on_edge, lo, hi)
                for p, q in zip(chain[:-1], chain[1:]):
                    if p in inside and q in inside and not _along_boundary(exact, f, face, hom[p], hom[q]):
                        segments.append((p, q))
        else:
            inner = []
        if len(verts) > MAX_POINTS_PER_FACE:
            raise ArrangementError(f"a face holds {len(verts):,} points of the overlay, more than the work bound "
                                   f"of {MAX_POINTS_PER_FACE:,} per face")
        xy = {vid: (hom[vid][i], hom[vid][j], hom[vid][3]) for vid in verts}
        tri = _FaceTriangulation(corners, xy)
        fixed: set[tuple[int, int]] = set()
        for e in range(3):
            chain = _chain(on_edge, corners[e], corners[(e + 1) % 3])
            prev = chain[0]
            for q in chain[1:-1]:
                tri.split_boundary(prev, chain[-1], q)
                prev = q
            fixed |= {(min(p, q), max(p, q)) for p, q in zip(chain[:-1], chain[1:])}
        for q in sorted(inner):
            tri.insert(q)
        for p, q in segments:
            tri.constrain(p, q)
        fixed |= {(min(p, q), max(p, q)) for p, q in segments}
        tri.improve(fixed)
        for t in tri.tris:
            if plane is None:
                pieces.append(t)
                cover.append(1)
                source.append(face)
                continue
            c = _centroid([hom[k] for k in t])
            covering = [g for g in members if _inside_face(exact, f, g, c) > 0]
            if face not in covering:
                raise ArrangementError("internal: a piece of a face does not lie in it")
            if min(covering) != face:
                continue                     # the cell is written by the covering face of smallest index
            net = sum(sign[g] for g in covering) * sign[face]
            if net == 0:
                continue
            pieces.append(t if net > 0 else t[::-1])
            cover.append(abs(net))
            source.append(face)
    # 3. the split surface: every face not split, then the pieces
    whole = np.setdiff1d(np.arange(len(f)), np.fromiter(split, dtype=np.int64, count=len(split)))
    out_faces = np.vstack([f[whole], np.asarray(pieces, dtype=np.int64).reshape(-1, 3)])
    mult = np.r_[np.ones(len(whole), dtype=np.int64), np.asarray(cover, dtype=np.int64)]
    out_source = np.r_[whole, np.asarray(source, dtype=np.int64)]
    out_v = np.vstack([v, np.asarray(new_xyz, dtype=np.float64).reshape(-1, 3)])
    n_all = len(out_v)
    _check_balanced(out_faces, n_all, mult, "the overlay of the coplanar faces does not balance every edge (internal)")
    # 4. labels
    patch, n_patches = _patches(out_faces, n_all, set())
    front = _label(out_v, out_faces, out_source, mult, patch, n_patches, v, f, exact, hom)
    w_front = front[patch]
    keep = (w_front <= 0) & (w_front + mult >= 1)
    kept = out_faces[keep]
    if not len(kept):
        raise ArrangementError("no face bounds the region of winding number ≥ 1 (the surface is wound inward)")
    # 5. checks
    result_v, result_f = _compact(out_v, kept)
    if len(_repeated_pairs(result_f)):
        raise ArrangementError("the surface of winding number ≥ 1 repeats a face (internal)")
    _check_balanced(result_f, len(result_v), np.ones(len(result_f), dtype=np.int64),
                    "the surface of winding number ≥ 1 is not closed (its edges do not balance)")
    after = surface_contacts(result_v, result_f)
    if not after.complete:
        raise ArrangementError("the face-intersection check of the surface of winding number ≥ 1 did not finish")
    left = len(after.crossing) + len(after.coplanar_opposite)
    used = np.unique(kept)
    new_used = out_v[used[used >= n]]
    delta = 0.5 * float(np.max(np.spacing(np.abs(new_used)))) if len(new_used) else 0.0
    at_new = (used >= n)[result_f].any(axis=1)        # faces at a new point (result_v is used, in order)
    rounding = rounded_points_bounds(result_v, result_f, [(at_new, delta)])   # refused above ROUNDOFF_RTOL/2
    region = rounded_region(result_v, result_f, [(at_new, delta)])
    return CoplanarArrangement(vertices=result_v, faces=result_f, coplanar_pairs=len(overlapping),
                               planes=len(groups), split_faces=len(split), new_vertices=len(new_xyz),
                               patches=n_patches, max_winding=int((w_front + mult).max()),
                               crossings_left=left, cancelled_faces=cancelled, rounding=rounding, region=region)


def _overlapping(found: SurfaceContacts, faces: np.ndarray) -> np.ndarray:
    """(k,) int: the faces in a pair that overlaps in a common plane (either way round, or repeated)."""
    pairs = np.concatenate([np.asarray(found.crossing, dtype=np.int64).reshape(-1, 2),
                            np.asarray(found.coplanar_opposite, dtype=np.int64).reshape(-1, 2),
                            _repeated_pairs(faces)])
    return np.unique(pairs.reshape(-1))


def _zero_chains(exact: _Exact, faces: np.ndarray, involved: np.ndarray) -> np.ndarray:
    """(m,) bool: copies of coplanar patches taken out in pairs whose boundaries are each other's reverse.

    The faces of ``involved`` are grouped by their exact plane and the side they face; on one side, faces on the
    same three vertices are copies of one face, and the distinct faces joined through edges used once each way
    among them form a patch (a polygon as triangulated).  A patch facing one way whose boundary (its directed edges
    not matched inside it) is exactly the reverse of a patch facing the other way in the same plane cancels it:
    the two together are a 2-chain in one plane with no boundary, which is zero (its cover is constant off the
    edges and 0 far away), so every surface integral and the winding number at every point off the plane stay as
    they are (Rigid Body Motion, Ch. 4: the divergence-theorem sums are sums over faces), and the directed edges
    left out balance, so what stays is as closed as before.  ``k`` copies one way and ``j`` the other leave
    ``|k − j|`` (the ones listed first).  Two triangulations of one polygon cancel so without the overlay's
    crossing points (review 12's R8: a side quad and its reverse split along the other diagonal, 1.5e8 m out,
    2.3e-7 off).  A side on which two distinct faces use one directed edge is left to the overlay."""
    drop = np.zeros(len(faces), dtype=bool)
    if len(involved) < 2:
        return drop
    cls, _ = signed_multiplicity(faces)
    sides: dict[tuple[tuple[int, int, int, int], int], dict[int, list[int]]] = {}
    for face in involved.tolist():
        if cls[face] < 0 or exact.plane(faces, face)[0] == (0, 0, 0):
            continue                             # no triangle: no plane, no side
        key, side = _normal_key(exact, faces, face)
        sides.setdefault((key, side), {}).setdefault(int(cls[face]), []).append(face)
    patches: dict[tuple[int, int, int, int], list[tuple[int, frozenset[tuple[int, int]], list[list[int]]]]] = {}
    for (key, side), copies in sides.items():
        for members, boundary in _patches_of(faces, list(copies.values())):
            patches.setdefault(key, []).append((side, boundary, members))
    for found in patches.values():
        used = [False] * len(found)
        for a, (side_a, edges_a, members_a) in enumerate(found):
            if used[a] or side_a < 0:
                continue
            reverse = frozenset((q, p) for p, q in edges_a)
            b = next((b for b, (side_b, edges_b, _) in enumerate(found)
                      if not used[b] and side_b < 0 and edges_b == reverse), None)
            if b is None:
                continue
            used[a] = used[b] = True
            members_b = found[b][2]
            k = min(len(members_a[0]), len(members_b[0]))
            for group in members_a + members_b:
                drop[group[len(group) - k:]] = True
    return drop


def _patches_of(faces: np.ndarray, copies: list[list[int]]) -> list[tuple[list[list[int]], frozenset[tuple[int, int]]]]:
    """The patches of one side of a plane (:func:`_zero_chains`): ``(copies of each face, boundary)`` for each
    set of distinct faces joined through edges used once each way, all listed the same number of times."""
    owner: dict[tuple[int, int], int] = {}
    bad: set[int] = set()
    for d, group in enumerate(copies):
        a, b, c = (int(x) for x in faces[group[0]])
        for edge in ((a, b), (b, c), (c, a)):
            if edge in owner:
                bad |= {d, owner[edge]}
            owner[edge] = d
    parent = list(range(len(copies)))

    def root(d: int) -> int:
        while parent[d] != d:               # bounded: each step moves to a smaller index
            parent[d] = parent[parent[d]]
            d = parent[d]
        return d

    for (p, q), d in owner.items():
        e = owner.get((q, p))
        if e is not None:
            ra, rb = root(d), root(e)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    comps: dict[int, list[int]] = {}
    for d in range(len(copies)):
        comps.setdefault(root(d), []).append(d)
    out = []
    for members in comps.values():
        if bad & set(members) or len({len(copies[d]) for d in members}) != 1:
            continue
        inside = set(members)
        edges = {e for e, d in owner.items() if d in inside}
        boundary = frozenset(e for e in edges if (e[1], e[0]) not in edges)
        if boundary:
            out.append(([copies[d] for d in members], boundary))
    return out


def _as_it_stands(v: np.ndarray, f: np.ndarray, cancelled: int) -> CoplanarArrangement:
    """The surface left once the zero chains are out, when no two of its faces overlap any more: closed (checked)
    and integrated as it stands, no point made."""
    result_v, result_f = _compact(v, f)
    if not len(result_f):
        raise ArrangementError("no face is left once the faces written with their reverse are taken out")
    _check_balanced(result_f, len(result_v), np.ones(len(result_f), dtype=np.int64),
                    "the surface left once the faces written with their reverse are taken out is not closed")
    return CoplanarArrangement(vertices=result_v, faces=result_f, coplanar_pairs=0, planes=0, split_faces=0,
                               new_vertices=0, patches=0, max_winding=1, cancelled_faces=cancelled)


def _touches_inside(exact: _Exact, faces: np.ndarray, g: int, h: int) -> bool:
    """A corner of face ``g`` lies in the relative interior of face ``h``, or an edge of ``g`` lying in ``h``'s
    plane meets its interior (exact).  Contacts only on the boundaries of both faces (a corner on an edge, edges
    along each other) are split by the overlay where they lie in a plane of overlapping faces, and change no
    winding number elsewhere; a contact inside a face would cut a patch (different winding numbers on its side)."""
    n, d = exact.plane(faces, h)
    i, j = _projection(n)
    hc = [exact.point[int(k)] for k in faces[h]]
    h2 = [(c[i], c[j], 1) for c in hc]
    own = {int(k) for k in faces[h]}
    corners = [int(k) for k in faces[g]]
    flat = {k: sum(n[a] * exact.point[k][a] for a in range(3)) == d for k in corners}
    for k in corners:
        if k in own or not flat[k]:
            continue
        q = (exact.point[k][i], exact.point[k][j], 1)
        if min(_orient2d(h2[e], h2[(e + 1) % 3], q) for e in range(3)) > 0:
            return True
    for e in range(3):
        a, b = corners[e], corners[(e + 1) % 3]
        if not (flat[a] and flat[b]):
            continue
        pa, pb = (exact.point[a][i], exact.point[a][j], 1), (exact.point[b][i], exact.point[b][j], 1)
        # separated when both ends lie on or outside one edge line of h, or h lies on one closed side of a–b
        if any(_orient2d(h2[x], h2[(x + 1) % 3], pa) <= 0 and _orient2d(h2[x], h2[(x + 1) % 3], pb) <= 0
               for x in range(3)):
            continue
        sides = [_orient2d(pa, pb, c) for c in h2]
        if min(sides) >= 0 or max(sides) <= 0:
            continue
        return True
    return False


def _group_edges(f: np.ndarray, members: list[int]) -> set[tuple[int, int]]:
    return {(min(int(f[g][e]), int(f[g][(e + 1) % 3])), max(int(f[g][e]), int(f[g][(e + 1) % 3])))
            for g in members for e in range(3)}


def _along_boundary(exact: _Exact, faces: np.ndarray, face: int, p: _Hom, q: _Hom) -> bool:
    """Both points lie on one edge (line) of ``face``: the segment between them runs along its boundary."""
    n, _ = exact.plane(faces, face)
    i, j = _projection(n)
    c = [exact.point[int(k)] for k in faces[face]]
    c2 = [(x[i], x[j], 1) for x in c]
    p2, q2 = (p[i], p[j], p[3]), (q[i], q[j], q[3])
    return any(_orient2d(c2[e], c2[(e + 1) % 3], p2) == 0 and _orient2d(c2[e], c2[(e + 1) % 3], q2) == 0
               for e in range(3))


def _check_balanced(faces: np.ndarray, n_vertices: int, mult: np.ndarray, message: str) -> None:
    """Raise ArrangementError unless every undirected edge is used as often (with multiplicity) both ways."""
    key, forward = edge_keys(faces, n_vertices)
    _, inverse = np.unique(key, return_inverse=True)
    net = np.bincount(inverse.reshape(-1), weights=np.where(forward, 1, -1) * np.repeat(mult, 3))
    if np.any(net != 0):
        raise ArrangementError(message)


#: Barycentric weights of the points tried on a piece (its centroid can lie exactly on an edge of a face that is
#: coplanar with it only to rounding: the diagonals of a square split both ways).
_WEIGHTS = ((1, 1, 1), (2, 1, 1), (1, 2, 1), (1, 1, 2), (4, 3, 1), (1, 4, 3), (3, 1, 4))


def _point_on(hom: dict[int, _Hom], tri: np.ndarray, weights: tuple[int, int, int]) -> _Hom:
    """The exact point ``Σ wᵢ pᵢ / Σ wᵢ`` of a triangle of homogeneous points."""
    (x1, y1, z1, w1), (x2, y2, z2, w2), (x3, y3, z3, w3) = (hom[int(k)] for k in tri)
    u1, u2, u3 = weights[0] * w2 * w3, weights[1] * w1 * w3, weights[2] * w1 * w2
    return _reduced((u1 * x1 + u2 * x2 + u3 * x3, u1 * y1 + u2 * y2 + u3 * y3, u1 * z1 + u2 * z2 + u3 * z3,
                     sum(weights) * w1 * w2 * w3))


def _near_faces(point: _Hom, p: np.ndarray, exact: _Exact, v: np.ndarray, f: np.ndarray, unsure: np.ndarray,
                theta: np.ndarray, error: np.ndarray) -> bool:
    """Settle the faces whose float solid angle at ``p`` has no useful bound (``p`` lies within rounding of their
    plane): on which side of its plane the exact ``point`` lies is an exact sign, and the face's half solid angle
    is then within ``π·δ/r`` of ``±π`` over the face (``δ`` the distance from its plane, ``r`` the distance of the
    foot from its edges: a disk of radius ``r`` at height ``δ`` subtends at least ``2π(1 − δ/r)``) and within
    ``π·δ/|r|`` of 0 beside it (the face lies outside that disk).  Updates ``theta`` and ``error`` in place;
    False when ``p`` is too close to a face's edge as well (try another point)."""
    scale = float(np.max(np.abs(v))) if len(v) else 1.0
    slop = 16 * _U * scale
    g = np.flatnonzero(unsure)
    a, b, c = v[f[g, 0]], v[f[g, 1]], v[f[g, 2]]
    normal = np.cross(b - a, c - a)
    length = np.linalg.norm(normal, axis=1)
    if np.any(length == 0.0):
        return False
    unit = normal / length[:, None]
    height = np.einsum("ij,ij->i", p - a, unit)
    delta = np.abs(height) + slop
    foot = p - height[:, None] * unit
    inside = np.full(len(g), np.inf)
    for q, r in ((a, b), (b, c), (c, a)):                  # signed distance of the foot inside each edge
        inward = np.cross(unit, r - q)
        inside = np.minimum(inside, np.einsum("ij,ij->i", foot - q, inward)
                            / np.maximum(np.linalg.norm(inward, axis=1), 1e-300))
    over, beside = inside > 4 * delta, inside < -4 * delta
    if not np.all(over | beside):
        return False
    for k in np.flatnonzero(over).tolist():
        (nx, ny, nz), d = exact.plane(f, int(g[k]))
        side = d * point[3] - (nx * point[0] + ny * point[1] + nz * point[2])     # (a − P)·n, times W > 0
        if side == 0:
            return False
        theta[g[k]] = np.pi if side > 0 else -np.pi
    error[g[over]] = np.pi * delta[over] / (inside[over] - delta[over])
    theta[g[beside]] = 0.0
    error[g[beside]] = np.pi * delta[beside] / (-inside[beside] - delta[beside])
    return True


def _edge_distance(point: np.ndarray, corners: list[np.ndarray]) -> np.ndarray:
    """(m,) float: distance from ``point`` to the boundary (three edges) of each face (float64; the bound it enters
    is a first-order term far below the margin unless the distance is tiny, where the face is settled exactly)."""
    best = np.full(len(corners[0]), np.inf)
    for j in range(3):
        a, b = corners[j], corners[(j + 1) % 3]
        d = b - a
        t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(point - (a + t[:, None] * d), axis=1))
    return best


def _label(out_v: np.ndarray, out_faces: np.ndarray, out_source: np.ndarray, mult: np.ndarray, patch: np.ndarray,
           n_patches: int, v: np.ndarray, f: np.ndarray, exact: _Exact, hom: dict[int, _Hom]) -> np.ndarray:
    """(p,) int: the winding number in front of each patch: ``W − c/2`` at a point of a piece, ``W`` over every
    input face outside the piece's plane (faces within rounding of it settled by :func:`_near_faces`), certified
    by its rounding bound."""
    p0, p1, p2 = out_v[out_faces[:, 0]], out_v[out_faces[:, 1]], out_v[out_faces[:, 2]]
    area2 = np.einsum("ij,ij->i", np.cross(p1 - p0, p2 - p0), np.cross(p1 - p0, p2 - p0))
    order = np.lexsort((-area2, patch))
    starts = np.searchsorted(patch[order], np.arange(n_patches + 1))
    front = np.zeros(n_patches, dtype=np.int64)
    corners = [v[f[:, j]] for j in range(3)]
    normals = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    lengths = np.linalg.norm(normals, axis=1)
    units = normals / np.maximum(lengths, 1e-300)[:, None]
    # the float point is the exact point rounded (≤ u·|x| per coordinate): a face whose plane passes within a few
    # such roundings of it may have the float point on its other side, so its side is taken exactly
    scale = float(np.max(np.abs(v))) if len(v) else 1.0
    close = 64 * _U * scale
    shift = 4 * _U * scale             # |float point − exact point| (each coordinate rounded once: ≤ √3·u·scale)
    perimeter = sum(np.linalg.norm(corners[(j + 1) % 3] - corners[j], axis=1) for j in range(3))
    planes: dict[int, np.ndarray] = {}                 # faces exactly in the plane of a source face
    for p in range(n_patches):
        members = order[starts[p]:starts[p + 1]]
        tries = [(k, w) for k in members[:_TRIES].tolist() for w in _WEIGHTS][:_TRIES * 2]
        for k, weights in tries:
            src = int(out_source[k])
            same_plane = planes.get(src)
            if same_plane is None:
                a, b, c = (np.tile(v[f[src, j]], (len(f), 1)) for j in range(3))
                same_plane = np.all(np.stack([orient3d_sign(a, b, c, x) for x in corners], axis=1) == 0, axis=1)
                planes[src] = same_plane
            point = _point_on(hom, out_faces[k], weights)
            at = np.array(exact.to_float(point))
            theta, error = _winding_terms(at, v, f)
            # the float point is not the exact one: a face's half solid angle moves by at most shift·L/(2(ρ − shift)²)
            # between them (|∇Ω| ≤ ∮|dl|/r² over its boundary, ρ the distance from the boundary), unless ρ ≤ shift
            rho = _edge_distance(at, corners)
            with np.errstate(divide="ignore"):
                error += np.where(rho > 2 * shift, shift * perimeter / (2 * np.maximum(rho - shift, 1e-300) ** 2),
                                  np.inf)
            theta[same_plane] = error[same_plane] = 0.0
            unsure = (error > 1e-3) | ((np.abs(np.einsum("ij,ij->i", at - corners[0], units)) <= close)
                                       & (lengths > 0) & ~same_plane)
            if unsure.any() and not _near_faces(point, at, exact, v, f, unsure, theta, error):
                continue
            total, bound = _winding_total(theta, error)
            x = total - mult[k] / 2
            nearest = np.round(x)
            if bound + abs(x - nearest) < WINDING_MARGIN:
                front[p] = int(nearest)
                break
        else:
            raise ArrangementError(f"the winding number of a patch of {len(members):,} faces could not be certified "
                                   "(every point tried is too close to another surface for float64)")
    return front


def arrange_coplanar_shells(vertices: np.ndarray, faces: np.ndarray,
                            chosen: np.ndarray) -> tuple[np.ndarray, np.ndarray, CoplanarArrangement]:
    """Replace the faces marked ``chosen`` (closed shells welded where coplanar faces overlap, rule R1b) by the
    boundary of their ``{w ≥ 1}`` (:func:`arrange_coplanar`); the other faces are kept as given.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    chosen : (m,) bool
        Faces of the shells to arrange (closed together).

    Returns
    -------
    vertices : (n', 3) float64
        The used vertices of the input, then the overlay's new points.
    faces : (m', 3) int64
        The faces not chosen, then the arranged ones.
    arrangement : CoplanarArrangement
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    chosen = np.asarray(chosen, dtype=bool)
    used, inverse = np.unique(f[chosen], return_inverse=True)
    done = arrange_coplanar(v[used], inverse.reshape(-1, 3).astype(np.int64))
    out_v, out_f = _compact(np.vstack([v, done.vertices]), np.vstack([f[~chosen], done.faces + len(v)]))
    return out_v, out_f, done
