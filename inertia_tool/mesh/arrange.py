"""A closed surface that passes through itself: the solid {winding number ≥ 1} by a mesh arrangement.

A shell that crosses itself (a tube swept along a figure-eight, two boxes written as one shell) bounds a region
where its winding number is 2: the summed divergence-theorem integral (Rigid Body Motion, Ch. 4, the volume
integrals as surface sums) counts that region twice.  The solid meant is ``{w ≥ 1}``; its boundary is made of
pieces of the input faces, cut along the curves where the surface meets itself.  :func:`arrange_crossings`
builds it:

1. *Intersection points.*  For every crossing face pair (from :func:`~.intersect.surface_contacts`), each edge
   of one face that pierces the interior of the other gives a point, keyed by (edge, face) so that the faces
   sharing that edge share the point.  Every decision (which side of a plane a corner lies on, whether an
   edge passes through a triangle) is an exact orientation sign (:func:`~.intersect.orient3d_sign`).  Three
   faces that meet at one point (a triple point) give a point keyed by the three faces.  The coordinates are
   computed exactly (rational, from integer coordinates at one power-of-two scale) and rounded once to float64.
2. *Splitting.*  Each crossed face is triangulated in its own plane (exact orientation tests on the rational
   points, projected on the two axes of the largest normal component): the face is split at the points on its
   edges, the interior points are inserted, and every intersection segment (cut at its triple points) is made
   an edge by flips (Sloan, "A fast algorithm for generating constrained Delaunay triangulations", Computers &
   Structures 47, 1993), then the other edges flipped towards the constrained Delaunay triangulation (Lawson's
   flips), so that no cap sliver is left for the rounding of the new points to turn over.
3. *Labels.*  The split surface is grouped into patches (pieces joined through edges that are not on an
   intersection curve); the winding number is constant on each side of a patch.  At a point ``c`` of a patch
   lying on its face ``f``, the generalized winding number of every face but ``f`` is ``w_front + ½``
   (``w_back = w_front + 1`` for a face wound outward), evaluated by the solid-angle sum (Van Oosterom and
   Strackee, IEEE Trans. Biomed. Eng. 30, 1983) with a rounding bound: accepted only when the bound keeps the
   nearest half-integer unique.  A patch none of whose points tried can be certified so (every one lies within
   rounding of another face: a pleat of nearly coplanar faces crossing at a tiny angle) is labelled exactly at the
   exact centroid of one of its pieces (from the pieces' exact corners, so it lies in the piece's cell of its
   face's plane), by counting the signed crossings of a ray from there into the face's front with exact integer
   orientation signs (:func:`_ray_front`).  When the labels then fail the check of step 4 (a certified float
   evaluation is one at the *rounded* centroid of a piece, which rounding can put across a face lying within an
   ulp of it), every patch is labelled again by exact rays and checked again (work bound
   ``MAX_EXACT_RAY_WORK``).
4. *Kept faces.*  The faces with ``w_back ≥ 1`` and ``w_front ≤ 0`` (``w_front = 0``) bound ``{w ≥ 1}`` and are
   wound outward.  Checks: the winding numbers change by exactly one across every intersection curve, the kept
   surface is closed and consistently wound, and no two of its faces cross (:func:`~.intersect.surface_contacts`
   again, exact).

Before step 1, a face written together with its reverse (the same three vertices, opposite cyclic order) is taken
out as a pair (:func:`~.multiplicity.cancel_opposite`, R0's count with sign, written once for R0 and both arrangements):
the two are one triangle with opposite orientations, so their contributions cancel exactly in every surface integral
and in the winding number at every point off that triangle, and ``{w ≥ 1}`` changes by a set of measure zero; every
directed edge stays matched by its reverse. Left in, the pair would be a patch every point of which lies on the
other face of the pair, where no winding number can be certified (issue 23: Barkour v0's ``upper_right_2.stl``, four
such pairs).

Degenerate crossings (a corner in the plane of a face it crosses, an edge through another edge or a corner,
coplanar overlapping faces, two crossing curves meeting on an edge) are refused with the reason
(:class:`~inertia_tool.errors.ArrangementError`), never guessed.
"""

from __future__ import annotations

from fractions import Fraction
from collections.abc import Callable
from itertools import combinations
from typing import NamedTuple, TypeVar

import numpy as np

from ..errors import ArrangementError
from ..tolerances import ARRANGE_MERGE_RTOL, ROUNDOFF_RTOL
from ..values import frozen_value
from .checks import edge_topology
from .edges import edge_keys, unique_rows
from .intersect import _integers, orient3d_sign, surface_contacts
from .multiplicity import cancel_opposite
from .precision import RoundedRegion, combined_regions, rounded_region

__all__ = ["Arrangement", "ArrangedShells", "arrange_crossings", "arrange_shells", "WINDING_MARGIN",
           "MAX_EXACT_RAY_WORK"]

#: A patch's winding number is accepted when the rounding bound of its solid-angle sum plus the distance of
#: the sum from the nearest half-integer stays below this (half a turn would make the rounding ambiguous).
WINDING_MARGIN = 0.25

#: Work bound: intersection points in one face (each face is triangulated on its own, in time growing with
#: the square of its points); a face crossed more often is refused with the count.
MAX_POINTS_PER_FACE = 1000

#: Patch points tried (largest faces first) before a patch is refused as too close to other surfaces.
_TRIES = 12

_U = 2.0 ** -53

_Hom = tuple[int, int, int, int]        # homogeneous exact point (X, Y, Z, W), W > 0

#: The generic rotation (unit quaternion, scalar first) under which a degenerate crossing is arranged again.
_TURN = (0.9689124217106447, 0.1530182, 0.0990312, 0.1620987)


class _Degenerate(ArrangementError):
    """A crossing in special position (a corner in a plane, an edge through an edge, coplanar faces)."""


@frozen_value
class Arrangement:
    """The boundary of ``{w ≥ 1}`` of a surface that passes through itself.

    Attributes
    ----------
    vertices : (n, 3) float64
        The input's vertices that are used, then the new intersection points (each rounded once from its
        exact rational value), m.
    faces : (k, 3) int64
        Closed, consistently wound outward, no two crossing.
    crossing_pairs : int
        Face pairs of the input that cross.
    split_faces : int
        Input faces cut along intersection curves.
    new_vertices : int
        Intersection points added (edge-face points and triple points).
    patches : int
        Patches of constant winding (each labelled by one certified winding-number evaluation).
    max_winding : int
        Largest winding number met (2 where a region was counted twice).
    crossings_left : int
        Face pairs of the output that still cross: new points rounded to float64 within an ulp of an edge
        (near-degenerate input); 0 is what certifies the output.
    turned : bool
        The crossing was degenerate and was arranged on the mesh turned by a generic rotation (the input's
        vertices keep their coordinates; the new points moved back carry the rotation's rounding).
    merged_points : int
        Intersection points merged into a neighbour within ``tolerances.ARRANGE_MERGE_RTOL`` of the diagonal
        because, rounded, they left faces crossing (see :func:`_merge_close_points`).
    cancelled_faces : int
        Input faces taken out as pairs of a face and its reverse before arranging
        (:func:`~.multiplicity.cancel_opposite`).
    rounding : (float, float, float)
        What rounding the new points (and merging them) may change in the result (:func:`rounded_points_bounds`),
        relative to this shell; the arrangement is refused above half of ``ROUNDOFF_RTOL``.
    region : RoundedRegion or None
        The same figure in absolute units (:class:`~.precision.RoundedRegion`), for R7 to judge against the final
        solid (a cavity cut later makes it a larger share); None when no point was rounded.
    """

    vertices: np.ndarray
    faces: np.ndarray
    crossing_pairs: int
    split_faces: int
    new_vertices: int
    patches: int
    max_winding: int
    crossings_left: int = 0
    turned: bool = False
    merged_points: int = 0
    cancelled_faces: int = 0
    rounding: tuple[float, float, float] = (0.0, 0.0, 0.0)
    region: RoundedRegion | None = None


# -- exact helpers ---------------------------------------------------------------------------------------------

# Exact 3-vectors: integers (scaled coordinates) or fractions (points found on a face), never mixed in one call.
_N = TypeVar("_N", int, Fraction)


def _cross(a: tuple[_N, ...], b: tuple[_N, ...]) -> tuple[_N, _N, _N]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _sub(a: tuple[_N, ...], b: tuple[_N, ...]) -> tuple[_N, _N, _N]:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a: tuple[_N, ...], b: tuple[_N, ...]) -> _N:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _sign(x: int | Fraction) -> int:
    return (x > 0) - (x < 0)


class _Exact:
    """Exact integer coordinates (one power-of-two scale) of the vertices involved, and the face planes."""

    def __init__(self, vertices: np.ndarray, used: np.ndarray) -> None:
        (ints,) = _integers(vertices[used])
        self.point = {int(k): (int(x), int(y), int(z)) for k, (x, y, z) in zip(used.tolist(), ints.tolist())}
        self.planes: dict[int, tuple[tuple[int, int, int], int]] = {}
        flat = vertices[used].reshape(-1)
        nonzero = np.flatnonzero(flat)
        #: integer coordinate = float coordinate × scale (a power of two)
        self.scale = Fraction(int(ints.reshape(-1)[nonzero[0]])) / Fraction(float(flat[nonzero[0]])) \
            if len(nonzero) else Fraction(1)

    def to_float(self, p: _Hom) -> tuple[float, float, float]:
        """The float64 nearest to each coordinate of an exact point (rounded once)."""
        den = self.scale * p[3]
        return (float(p[0] / den), float(p[1] / den), float(p[2] / den))

    def plane(self, faces: np.ndarray, f: int) -> tuple[tuple[int, int, int], int]:
        """Normal ``n = (b − a)×(c − a)`` and offset ``n·a`` of face ``f``."""
        got = self.planes.get(f)
        if got is None:
            a, b, c = (self.point[int(i)] for i in faces[f])
            n = _cross(_sub(b, a), _sub(c, a))
            got = (n, _dot(n, a))
            self.planes[f] = got
        return got

    def edge_point(self, faces: np.ndarray, a: int, b: int, g: int) -> _Hom:
        """Where the segment from vertex ``a`` to ``b`` meets the plane of face ``g`` (they are on opposite sides)."""
        n, d = self.plane(faces, g)
        pa, pb = self.point[a], self.point[b]
        oa, ob = _dot(n, pa) - d, _dot(n, pb) - d
        w = oa - ob
        x = tuple(oa * pb[i] - ob * pa[i] for i in range(3))
        if w < 0:
            return (-x[0], -x[1], -x[2], -w)
        return (x[0], x[1], x[2], w)

    def edge_parameter(self, faces: np.ndarray, a: int, b: int, g: int) -> Fraction:
        """Position ``t ∈ (0, 1)`` of that point along ``a → b``."""
        n, d = self.plane(faces, g)
        oa, ob = _dot(n, self.point[a]) - d, _dot(n, self.point[b]) - d
        return Fraction(oa, oa - ob)

    def triple_point(self, faces: np.ndarray, f: int, g: int, h: int) -> _Hom | None:
        """The common point of the planes of three faces (Cramer's rule), or None when they share no single point."""
        (nf, df), (ng, dg), (nh, dh) = (self.plane(faces, k) for k in (f, g, h))
        gh, hf, fg = _cross(ng, nh), _cross(nh, nf), _cross(nf, ng)
        det = _dot(nf, gh)
        if det == 0:
            return None
        x = tuple(df * gh[i] + dg * hf[i] + dh * fg[i] for i in range(3))
        if det < 0:
            return (-x[0], -x[1], -x[2], -det)
        return (x[0], x[1], x[2], det)


def _projection(normal: tuple[int, int, int]) -> tuple[int, int]:
    """Two axes on which a face of this normal projects counter-clockwise (drop the largest normal component)."""
    k = max(range(3), key=lambda i: abs(normal[i]))
    i, j = (k + 1) % 3, (k + 2) % 3
    return (i, j) if normal[k] > 0 else (j, i)


def _orient2d(p: tuple[int, int, int], q: tuple[int, int, int], r: tuple[int, int, int]) -> int:
    """Sign of orient2d of three homogeneous 2-D points (x, y, w), w > 0: +1 counter-clockwise."""
    return _sign(p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0])
                 + p[2] * (q[0] * r[1] - q[1] * r[0]))


def _inside_face(exact: _Exact, faces: np.ndarray, f: int, p: _Hom) -> int:
    """+1 when ``p`` (in the plane of ``f``) lies strictly inside face ``f``, 0 on its boundary, −1 outside."""
    n, _ = exact.plane(faces, f)
    i, j = _projection(n)
    q = (p[i], p[j], p[3])
    corners = [exact.point[int(k)] for k in faces[f]]
    c2 = [(c[i], c[j], 1) for c in corners]
    s = [_orient2d(c2[e], c2[(e + 1) % 3], q) for e in range(3)]
    if min(s) < 0:
        return -1
    return 1 if min(s) > 0 else 0


# -- step 1: intersection points and segments ----------------------------------------------------------------

def _crossing_points(v: np.ndarray, faces: np.ndarray, pairs: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each crossing pair, the two ends of its intersection segment: (edge, face) piercings, or the corner
    the two faces share.

    Returns ``edge_a, edge_b`` (k, 2) vertex ids of the piercing edges and ``face`` (k, 2) the pierced faces;
    an end at a shared corner ``s`` is ``(s, -1, -1)``.  Raises ArrangementError on a degenerate contact.
    """
    F, G = faces[pairs[:, 0]], faces[pairs[:, 1]]
    k = len(pairs)
    side_f = np.stack([orient3d_sign(v[G[:, 0]], v[G[:, 1]], v[G[:, 2]], v[F[:, j]]) for j in range(3)], axis=1)
    side_g = np.stack([orient3d_sign(v[F[:, 0]], v[F[:, 1]], v[F[:, 2]], v[G[:, j]]) for j in range(3)], axis=1)
    coplanar = np.all(side_g == 0, axis=1)
    if np.any(coplanar):
        raise _Degenerate(f"{int(np.count_nonzero(coplanar))} face pairs overlap in one plane facing the same "
                          "way (a coplanar crossing)")
    shared_f = np.any(F[:, :, None] == G[:, None, :], axis=2)          # corner j of F is a corner of G
    shared_g = np.any(G[:, :, None] == F[:, None, :], axis=2)
    n_shared = shared_f.sum(axis=1)
    if np.any(n_shared > 1) or np.any((side_f == 0) & ~shared_f) or np.any((side_g == 0) & ~shared_g):
        raise _Degenerate("a corner of a face lies exactly in the plane of a face it crosses (a degenerate "
                          "crossing)")
    rows, ea, eb, pierced = [], [], [], []
    for own, other, side, target in ((F, G, side_f, pairs[:, 1]), (G, F, side_g, pairs[:, 0])):
        for j in range(3):
            r = np.flatnonzero(side[:, j] * side[:, (j + 1) % 3] < 0)
            if not len(r):
                continue
            p, q = own[r, j], own[r, (j + 1) % 3]
            s = np.stack([orient3d_sign(v[p], v[q], v[other[r, e]], v[other[r, (e + 1) % 3]]) for e in range(3)],
                         axis=1)
            inside = np.all(s > 0, axis=1) | np.all(s < 0, axis=1)
            outside = np.any(s > 0, axis=1) & np.any(s < 0, axis=1)
            if np.any(~inside & ~outside):
                raise _Degenerate("an edge passes exactly through an edge or corner of a face it crosses (a "
                                  "degenerate crossing)")
            hit = r[inside]
            rows.append(hit)
            ea.append(p[inside])
            eb.append(q[inside])
            pierced.append(target[hit])
    one = np.flatnonzero(n_shared == 1)                 # the shared corner ends the segment
    rows.append(one)
    ea.append(F[one, np.argmax(shared_f[one], axis=1)])
    eb.append(np.full(len(one), -1, dtype=np.int64))
    pierced.append(np.full(len(one), -1, dtype=np.int64))
    row = np.concatenate(rows)
    count = np.bincount(row, minlength=k)
    if np.any(count != 2):
        raise _Degenerate(f"{int(np.count_nonzero(count != 2))} crossing face pairs do not meet in a segment "
                          "between two edge crossings (a degenerate crossing)")
    order = np.argsort(row, kind="stable")
    edge_a = np.concatenate(ea)[order].reshape(k, 2)
    edge_b = np.concatenate(eb)[order].reshape(k, 2)
    face = np.concatenate(pierced)[order].reshape(k, 2)
    return edge_a, edge_b, face


# -- step 2: the triangulation of one face ---------------------------------------------------------------------

class _FaceTriangulation:
    """A triangulation of one face in its own plane, on exact homogeneous 2-D points."""

    def __init__(self, corners: list[int], xy: dict[int, tuple[int, int, int]]) -> None:
        self.xy = xy
        self.tris: list[list[int]] = [list(corners)]

    def orient(self, a: int, b: int, c: int) -> int:
        return _orient2d(self.xy[a], self.xy[b], self.xy[c])

    def _find_edge(self, a: int, b: int) -> tuple[int, int]:
        """Triangle holding the directed edge a→b and the index of a in it; (-1, -1) if none."""
        for t, tri in enumerate(self.tris):
            for e in range(3):
                if tri[e] == a and tri[(e + 1) % 3] == b:
                    return t, e
        return -1, -1

    def split_boundary(self, a: int, b: int, p: int) -> None:
        """Insert ``p`` on the boundary edge a→b (p lies on it exactly, by construction)."""
        t, e = self._find_edge(a, b)
        if t < 0:
            raise ArrangementError("internal: a boundary edge was lost while splitting a face")
        c = self.tris[t][(e + 2) % 3]
        self.tris[t] = [a, p, c]
        self.tris.append([p, b, c])

    def insert(self, p: int) -> None:
        """Insert an interior point: split the triangle holding it (or the two sharing the edge it lies on)."""
        xy, q = self.xy, self.xy[p]
        for t, tri in enumerate(self.tris):
            # the three signs, each triangle left at its first negative one (the same triangle is found)
            s0 = _orient2d(xy[tri[0]], xy[tri[1]], q)
            if s0 < 0:
                continue
            s1 = _orient2d(xy[tri[1]], xy[tri[2]], q)
            if s1 < 0:
                continue
            s2 = _orient2d(xy[tri[2]], xy[tri[0]], q)
            if s2 < 0:
                continue
            s = [s0, s1, s2]
            zeros = s.count(0)
            if zeros == 0:
                a, b, c = tri
                self.tris[t] = [a, b, p]
                self.tris += [[b, c, p], [c, a, p]]
                return
            if zeros > 1:
                raise _Degenerate("two intersection points coincide in a face (a degenerate crossing)")
            e = s.index(0)
            a, b, c = tri[e], tri[(e + 1) % 3], tri[(e + 2) % 3]
            u, k = self._find_edge(b, a)
            if u < 0:
                raise _Degenerate("an intersection point lies exactly on the edge of a face "
                                       "(a degenerate crossing)")
            d = self.tris[u][(k + 2) % 3]
            self.tris[t] = [a, p, c]
            self.tris.append([p, b, c])
            self.tris[u] = [b, p, d]
            self.tris.append([p, a, d])
            return
        raise ArrangementError("an intersection point lies outside the face it was computed in (internal)")

    def _crosses(self, u: int, v: int, x: int, y: int) -> bool:
        """Segment x–y crosses segment u–v at a point interior to both."""
        return (self.orient(u, v, x) * self.orient(u, v, y) < 0) and (self.orient(x, y, u) * self.orient(x, y, v) < 0)

    def constrain(self, u: int, v: int) -> None:
        """Make u–v an edge by flipping the edges that cross it (Sloan 1993)."""
        # the same set, built in the same order as with min/max per edge (its order is the queue's below)
        edges = {(a, b) if a < b else (b, a)
                 for t in self.tris for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
        if ((u, v) if u < v else (v, u)) in edges:
            return
        xy = self.xy
        pu, pv = xy[u], xy[v]
        side: dict[int, int] = {}           # orient(u, v, x) of every other point, computed once for the queue
        for x in {i for t in self.tris for i in t} - {u, v}:
            side[x] = sx = _orient2d(pu, pv, xy[x])
            if sx == 0 and self._between(u, v, x):
                raise _Degenerate("an intersection segment passes exactly through another point of its face "
                                       "(a degenerate crossing)")
        # _crosses(u, v, x, y), its first factor taken from `side`
        queue = [e for e in edges if u not in e and v not in e and side[e[0]] * side[e[1]] < 0
                 and _orient2d(xy[e[0]], xy[e[1]], pu) * _orient2d(xy[e[0]], xy[e[1]], pv) < 0]
        limit = 20 * (len(queue) + 2) ** 2 + 100
        for _ in range(limit):
            if not queue:
                return
            x, y = queue.pop(0)
            t1, e1 = self._find_edge(x, y)
            t2, e2 = self._find_edge(y, x)
            if t1 < 0 or t2 < 0:
                raise ArrangementError("internal: a crossing edge has no two triangles")
            z = self.tris[t1][(e1 + 2) % 3]
            w = self.tris[t2][(e2 + 2) % 3]
            if self.orient(x, w, z) <= 0 or self.orient(w, y, z) <= 0:
                queue.append((x, y))           # not convex: come back to it once others have moved
                continue
            self.tris[t1] = [x, w, z]
            self.tris[t2] = [w, y, z]
            if z not in (u, v) and w not in (u, v) and self._crosses(u, v, z, w):
                queue.append((z, w))
        raise ArrangementError("an intersection segment could not be made an edge of its face within the flip bound")

    def _in_circle(self, a: int, b: int, c: int, d: int) -> bool:
        """d lies inside the circle through the counter-clockwise a, b, c, in float64: only the quality of the
        triangulation depends on it, never its validity (each flip is checked exactly)."""
        def xy(i: int) -> tuple[float, float]:
            p = self.xy[i]
            return p[0] / p[2], p[1] / p[2]
        dx, dy = xy(d)
        rows = []
        for i in (a, b, c):
            x, y = xy(i)
            rows.append((x - dx, y - dy, (x - dx) ** 2 + (y - dy) ** 2))
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = rows
        return ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx) > 0

    def improve(self, fixed: set[tuple[int, int]]) -> None:
        """Lawson flips of the edges not in ``fixed`` (constraints and the face's boundary) towards the
        constrained Delaunay triangulation: no thin slivers where a better diagonal exists, so that rounding the
        new points cannot turn a sliver over (bounded by a fixed number of passes)."""
        for _ in range(2 * len(self.tris) + 8):
            where = {(t[e], t[(e + 1) % 3]): (k, e) for k, t in enumerate(self.tris) for e in range(3)}
            touched: set[int] = set()
            for (x, y), (t1, e1) in where.items():
                if x > y or (x, y) in fixed or t1 in touched:
                    continue
                other = where.get((y, x))
                if other is None or other[0] in touched:
                    continue
                t2, e2 = other
                z = self.tris[t1][(e1 + 2) % 3]
                w = self.tris[t2][(e2 + 2) % 3]
                if not self._in_circle(x, y, z, w):
                    continue
                if self.orient(x, w, z) <= 0 or self.orient(w, y, z) <= 0:
                    continue
                self.tris[t1] = [x, w, z]
                self.tris[t2] = [w, y, z]
                touched |= {t1, t2}
            if not touched:
                return

    def _between(self, u: int, v: int, x: int) -> bool:
        """x (collinear with u, v) lies strictly between them."""
        pu, pv, px = (self.xy[i] for i in (u, v, x))
        du = [Fraction(pu[i], pu[2]) for i in range(2)]
        dv = [Fraction(pv[i], pv[2]) for i in range(2)]
        dx = [Fraction(px[i], px[2]) for i in range(2)]
        s = sum((dx[i] - du[i]) * (dv[i] - du[i]) for i in range(2))
        length = sum((dv[i] - du[i]) ** 2 for i in range(2))
        return bool(0 < s < length)


# -- step 3: winding numbers of patches ------------------------------------------------------------------------

def _winding_terms(point: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Half solid angle ``θ = Ω/2`` of every face seen from ``point`` (radians, so the face adds ``θ/2π`` to the
    generalized winding number) and a bound on its float64 error (infinite where it cannot be bounded).

    Each face contributes ``Ω/4π`` with ``tan(Ω/2) = det/den`` (Van Oosterom and Strackee 1983), ``det = A·(B×C)``,
    ``den = |A||B||C| + (A·B)|C| + (A·C)|B| + (B·C)|A|`` for ``A = a − p`` etc.  In float64 ``|Δdet| ≤ 12u·P``
    (``P`` the permanent of the absolute values, as in the orient3d filter) and ``|Δden| ≤ 100u·|A||B||C|``;
    the angle of ``(den, det)`` then moves by at most ``asin(h/r) ≤ (π/2)·h/r`` with ``h`` the perturbation and
    ``r`` its length (when ``h < r``), and atan2 adds a few ulps; where the perturbation reaches atan2's cut
    (``den < 0``, ``det = 0``: the point lies in a face's plane over it) the angle may jump by 2π, and the bound
    is infinite.
    """
    f = faces
    ax, ay, az = (vertices[f[:, 0], k] - point[k] for k in range(3))
    bx, by, bz = (vertices[f[:, 1], k] - point[k] for k in range(3))
    cx, cy, cz = (vertices[f[:, 2], k] - point[k] for k in range(3))
    la = np.sqrt(ax * ax + ay * ay + az * az)
    lb = np.sqrt(bx * bx + by * by + bz * bz)
    lc = np.sqrt(cx * cx + cy * cy + cz * cz)
    det = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)
    den = la * lb * lc + (ax * bx + ay * by + az * bz) * lc + (ax * cx + ay * cy + az * cz) * lb \
        + (bx * cx + by * cy + bz * cz) * la
    aax, aay, aaz, abx, aby, abz = np.abs(ax), np.abs(ay), np.abs(az), np.abs(bx), np.abs(by), np.abs(bz)
    acx, acy, acz = np.abs(cx), np.abs(cy), np.abs(cz)
    perm = (aax * (aby * acz + abz * acy) + aay * (abz * acx + abx * acz) + aaz * (abx * acy + aby * acx))
    h = 12 * _U * perm + 100 * _U * la * lb * lc
    r = np.hypot(det, den) - h
    with np.errstate(divide="ignore", invalid="ignore"):
        angle_error = np.where(r > h, (np.pi / 2) * h / np.maximum(r, 1e-300), np.inf)
    # atan2 jumps by 2π across den < 0, det = 0 (a point in the plane of a face, over it): unbounded there
    angle_error[(np.abs(det) <= h) & (den <= h)] = np.inf
    return np.arctan2(det, den), angle_error


def _winding_total(theta: np.ndarray, angle_error: np.ndarray) -> tuple[float, float]:
    """The winding number ``Σθ/2π`` of :func:`_winding_terms` and the bound on its rounding error."""
    total = float(np.sum(theta)) / (2 * np.pi)
    bound = float(np.sum(angle_error + 4 * _U * np.abs(theta))) / (2 * np.pi) + len(theta) * 4 * _U
    return total, bound


def _winding_except(point: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                    skip: int | np.ndarray) -> tuple[float, float]:
    """Generalized winding number at ``point`` of every face but ``skip`` (an index, or a boolean mask of the
    faces left out), and a bound on its rounding error (:func:`_winding_terms`)."""
    theta, angle_error = _winding_terms(point, vertices, faces)
    theta[skip] = angle_error[skip] = 0.0
    return _winding_total(theta, angle_error)


def _patches(faces: np.ndarray, n_vertices: int, cut: set[int]) -> tuple[np.ndarray, int]:
    """Patches: faces joined through edges used by exactly two faces in opposite directions and not in ``cut``
    (the undirected keys of intersection edges)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    key, forward = edge_keys(faces, n_vertices)
    order = np.argsort(key, kind="stable")
    sk = key[order]
    starts = np.flatnonzero(np.r_[True, sk[1:] != sk[:-1]])
    count = np.diff(np.r_[starts, len(sk)])
    pair = starts[count == 2]
    ok = forward[order[pair]] != forward[order[pair + 1]]
    if cut:
        ok &= ~np.isin(sk[pair], np.fromiter(cut, dtype=np.int64, count=len(cut)))
    pair = pair[ok]
    a, b = order[pair] // 3, order[pair + 1] // 3
    m = len(faces)
    n, labels = connected_components(coo_matrix((np.ones(len(a), dtype=np.int8), (a, b)), shape=(m, m)),
                                     directed=False)
    return labels, int(n)


# -- entry point -----------------------------------------------------------------------------------------------

def arrange_crossings(vertices: np.ndarray, faces: np.ndarray, crossing: np.ndarray | None = None, *,
                      turn: bool = True) -> Arrangement:
    """The boundary of ``{w ≥ 1}`` of a closed surface that passes through itself (see the module docstring).

    Parameters
    ----------
    vertices : (n, 3) float
        m (any unit).
    faces : (m, 3) int
        A closed, consistently oriented surface (one or several shells), wound so that its inside has a
        positive winding number.
    crossing : (k, 2) int, optional
        The face pairs that cross (``surface_contacts(vertices, faces).crossing``); computed when not given.
    turn : bool
        When the crossing is degenerate (symmetric meshes: a corner exactly in the plane of a face it crosses),
        arrange the surface again turned by a fixed generic rotation about its centre; the input's vertices keep
        their coordinates, the new points are turned back (rounded), and ``turned`` says so.

    Returns
    -------
    Arrangement

    Raises
    ------
    ArrangementError
        A degenerate crossing (coplanar overlapping faces, an edge through an edge or a corner), a patch whose
        winding number cannot be certified, or an output that fails its checks; the message says which.
    """
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    keep = cancel_opposite(f)
    cancelled = int(len(f) - np.count_nonzero(keep))
    if cancelled:
        remap = np.cumsum(keep) - 1
        if crossing is not None:
            pairs = np.asarray(crossing, dtype=np.int64).reshape(-1, 2)
            crossing = remap[pairs[keep[pairs].all(axis=1)]]
        f = f[keep]
        if crossing is None or not len(crossing):
            found = surface_contacts(v, f)
            if not found.complete:
                raise ArrangementError("the face-intersection check did not finish")
            crossing = found.crossing
        if not len(crossing):                  # the pairs were all that crossed: nothing left to arrange
            result_v, result_f = _compact(v, f)
            if not edge_topology(result_f, len(result_v)).oriented:
                raise ArrangementError("the surface left after taking out the faces written with their reverse "
                                       "is not closed")
            return Arrangement(vertices=result_v, faces=result_f, crossing_pairs=0, split_faces=0, new_vertices=0,
                               patches=0, max_winding=1, cancelled_faces=cancelled)
    try:
        out_v, kept, stats = _arrange(v, f, crossing)
        turned = False
    except _Degenerate as exc:
        if not turn:
            raise
        from .nesting import _rotation
        rot = _rotation(_TURN)
        centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
        try:
            out_v, kept, stats = _arrange((v - centre) @ rot.T + centre, f, None)
        except _Degenerate as again:
            raise _Degenerate(f"{exc} (and again on the mesh turned: {again})") from None
        out_v[len(v):] = (out_v[len(v):] - centre) @ rot + centre
        out_v[:len(v)] = v
        turned = True
    result_v, result_f = _compact(out_v, kept)
    moved = np.unique(kept) >= len(v)                 # the result's vertices that are new points (rounded)
    merged_faces, merged_shift = np.zeros(len(result_f), dtype=bool), 0.0
    topo = edge_topology(result_f, len(result_v))
    if not topo.oriented:
        raise ArrangementError(f"the surface of winding number ≥ 1 is not closed ({topo.boundary_edges} open, "
                               f"{topo.nonmanifold_edges} non-manifold, {topo.misoriented_edges} misoriented edges)")
    after = surface_contacts(result_v, result_f)
    if not after.complete:
        raise ArrangementError("the face-intersection check of the surface of winding number ≥ 1 did not finish")
    merged = 0
    if len(after.crossing):
        merged_v, merged_f, merged, took = _merge_close_points(out_v, kept, len(v))
        if merged and edge_topology(merged_f, len(merged_v)).oriented:
            rechecked = surface_contacts(merged_v, merged_f)
            if rechecked.complete and len(rechecked.crossing) < len(after.crossing):
                result_v, result_f, after = merged_v, merged_f, rechecked
                moved, merged_faces, merged_shift = took.new, took.faces, took.shift
            else:
                merged = 0
        else:
            merged = 0
    new = out_v[len(v):]
    delta = 0.5 * float(np.max(np.spacing(np.abs(new)))) if len(new) else 0.0
    if turned and len(new):                           # turned there and back: a few roundings of |x − centre| each
        delta += 8 * 2.0 ** -53 * float(np.max(np.abs(new - centre)))
    tiers = [(moved[result_f].any(axis=1), delta)]
    if merged:                                        # faces that had a merged point: moved by the merge too
        tiers.append((merged_faces, merged_shift + delta))
    rounding = rounded_points_bounds(result_v, result_f, tiers)
    return Arrangement(vertices=result_v, faces=result_f, crossings_left=len(after.crossing), turned=turned,
                       merged_points=merged, cancelled_faces=cancelled, rounding=rounding,
                       region=rounded_region(result_v, result_f, tiers), **stats)


def rounded_points_bounds(vertices: np.ndarray, faces: np.ndarray,
                          tiers: list[tuple[np.ndarray, float]]) -> tuple[float, float, float]:
    """What the rounding of an arrangement's new points may change in its result: ``(volume relative, centroid m,
    inertia relative)``, the sum over ``tiers`` of :func:`~.precision.conversion_bounds` over the tier's faces (the
    others are the input's own), every moved corner within the tier's ``delta`` of its exact position; refused
    (:class:`~inertia_tool.errors.ArrangementError`) above half of ``ROUNDOFF_RTOL`` of the result, the other half
    left to the integrals' round-off (R7), so that ``united`` keeps what "exact" means (review 12's R8: the coplanar
    overlay's points 1.5e8 m out, uncounted, left a union 2.3e-7 off).  The share is relative to this result; R7
    judges the same region again against the final solid (:class:`~.precision.RoundedRegion`, carried as
    ``Arrangement.region``), which a cavity cut later makes smaller.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        The result, closed.
    tiers : list of ((m,) bool, float)
        Faces moved (at a rounded new point; that had a point merged away) and ``delta``, m, the largest distance
        of their moved corners from their exact positions, per coordinate.
    """
    total = [0.0, 0.0, 0.0]
    whole = None
    n_moved = 0
    for at, delta in tiers:
        at = np.asarray(at, dtype=bool)
        if not (at.any() and delta > 0):
            continue
        from ..integrals import volume_moments
        from .precision import conversion_bounds
        whole = whole if whole is not None else volume_moments(vertices, faces)
        part = conversion_bounds(vertices, faces[at], delta, whole.volume, whole.centroid, whole.second_moment)
        total = [a + b for a, b in zip(total, part)]
        n_moved += int(np.count_nonzero(at))
    worst = max(total[0], total[2])
    if not worst <= 0.5 * ROUNDOFF_RTOL:
        raise ArrangementError(f"its new points, rounded to float64 ({n_moved:,} faces at them; by up to "
                               f"{max(d for _, d in tiers):.2g} m a coordinate), may change the result by "
                               f"{worst:.2g} of it, above the {0.5 * ROUNDOFF_RTOL:g} a certified union allows (a "
                               "part small against its distance from the origin)")
    return total[0], total[1], total[2]


class _Merged(NamedTuple):
    """What :func:`_merge_close_points` moved: ``new`` (n,) bool, the output's vertices that are new points;
    ``faces`` (m,) bool, the output's faces that had a point merged away; ``shift`` m, the largest coordinate
    difference of a merged point and the one it went into."""

    new: np.ndarray
    faces: np.ndarray
    shift: float


def _merge_close_points(vertices: np.ndarray, faces: np.ndarray,
                        n_input: int) -> tuple[np.ndarray, np.ndarray, int, _Merged]:
    """Merge intersection points (ids ≥ ``n_input``) lying within ``ARRANGE_MERGE_RTOL`` of the diagonal of
    another point of the surface (into the input's vertex when there is one), drop the faces that collapse and
    pairs of faces left as one face and its reverse (:func:`~.multiplicity.cancel_opposite`); return the compacted
    surface, the count merged, and what moved (:class:`_Merged`, for :func:`rounded_points_bounds`)."""
    lo, hi = vertices[faces.reshape(-1)].min(axis=0), vertices[faces.reshape(-1)].max(axis=0)
    limit = ARRANGE_MERGE_RTOL * float(np.linalg.norm(hi - lo))
    from scipy.spatial import cKDTree
    used = np.unique(faces)
    new = used[used >= n_input]
    if not len(new):
        return vertices, faces, 0, _Merged(np.zeros(0, dtype=bool), np.zeros(0, dtype=bool), 0.0)
    near = cKDTree(vertices[used]).query_ball_point(vertices[new], r=limit)
    a = np.repeat(new, [len(n) for n in near])
    b = used[np.concatenate([np.asarray(n, dtype=np.int64) for n in near])] if len(a) else a
    short = a != b
    target = np.arange(len(vertices))

    def root(i: int) -> int:
        while target[i] != i:
            target[i] = target[target[i]]
            i = int(target[i])
        return i

    merged = 0
    for x, y in zip(a[short].tolist(), b[short].tolist()):
        rx, ry = root(x), root(y)
        if rx != ry:
            keep, drop = (rx, ry) if rx < ry else (ry, rx)      # input vertices have the smaller ids
            target[drop] = keep
            merged += 1
    if not merged:
        return vertices, faces, 0, _Merged(np.zeros(0, dtype=bool), np.zeros(0, dtype=bool), 0.0)
    final = np.array([root(i) for i in range(len(vertices))])
    gone = final != np.arange(len(vertices))
    shift = float(np.max(np.abs(vertices[gone] - vertices[final[gone]])))
    f = final[faces]
    had = gone[faces].any(axis=1)                           # a face that had a point merged away has moved
    alive = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    f, had = f[alive], had[alive]
    stay = cancel_opposite(f)                               # a face and its reverse: the zero chain
    f, had = f[stay], had[stay]
    out_v, out_f = _compact(vertices, f)
    return out_v, out_f, merged, _Merged(np.unique(f) >= n_input, had, shift)


def _arrange(v: np.ndarray, f: np.ndarray, crossing: np.ndarray | None) -> tuple[np.ndarray, np.ndarray,
                                                                                dict[str, int]]:
    """The split surface's vertices, the kept faces (w_front = 0) and the counts for :class:`Arrangement`."""
    n = len(v)
    if crossing is None:
        found = surface_contacts(v, f)
        if not found.complete:
            raise ArrangementError("the face-intersection check did not finish")
        crossing = found.crossing
    pairs = unique_rows(np.sort(np.asarray(crossing, dtype=np.int64).reshape(-1, 2), axis=1))
    if not len(pairs):
        raise ArrangementError("no crossing face pairs to arrange")
    edge_a, edge_b, pierced = _crossing_points(v, f, pairs)
    split = np.unique(pairs)
    exact = _Exact(v, np.unique(f[split]))

    # 1. points: (edge, face) piercings, then triple points
    point_id: dict[tuple[int, int], int] = {}
    hom: dict[int, _Hom] = {}
    for vid, p in exact.point.items():
        hom[vid] = (p[0], p[1], p[2], 1)
    new_xyz: list[tuple[float, float, float]] = []
    on_edge: dict[tuple[int, int], list[tuple[Fraction, int]]] = {}

    def add_point(h: _Hom) -> int:
        vid = n + len(new_xyz)
        hom[vid] = h
        new_xyz.append(exact.to_float(h))
        return vid

    segment_ends = np.zeros((len(pairs), 2), dtype=np.int64)
    for r in range(len(pairs)):
        for s in range(2):
            a, b, g = int(edge_a[r, s]), int(edge_b[r, s]), int(pierced[r, s])
            if g < 0:                       # the corner both faces share
                segment_ends[r, s] = a
                continue
            lo, hi = min(a, b), max(a, b)
            key = (lo * n + hi, g)
            got = point_id.get(key)
            if got is None:
                got = add_point(exact.edge_point(f, lo, hi, g))
                point_id[key] = got
                on_edge.setdefault((lo, hi), []).append((exact.edge_parameter(f, lo, hi, g), got))
            segment_ends[r, s] = got
    pair_row = {(int(a), int(b)): r for r, (a, b) in enumerate(pairs.tolist())}
    partners: dict[int, list[int]] = {}
    for a, b in pairs.tolist():
        partners.setdefault(a, []).append(b)
        partners.setdefault(b, []).append(a)
    on_segment: dict[int, list[int]] = {}
    interior: dict[int, list[int]] = {}
    seen: set[tuple[int, int, int]] = set()
    for a in sorted(partners):
        for g, h in combinations(sorted(partners[a]), 2):
            trio = tuple(sorted((a, g, h)))
            if (g, h) not in pair_row or trio in seen:
                continue
            seen.add(trio)  # type: ignore[arg-type]
            if set(f[trio[0]].tolist()) & set(f[trio[1]].tolist()) & set(f[trio[2]].tolist()):
                continue                    # three faces around one corner meet there, not at a new point
            meet = exact.triple_point(f, *trio)
            inside = [_inside_face(exact, f, k, meet) for k in trio] if meet is not None else [-1]
            if meet is None and _common_line(exact, f, trio):
                raise _Degenerate("three faces cross along one common line (a degenerate crossing)")
            if min(inside) < 0:
                continue
            if min(inside) == 0:
                raise _Degenerate("two intersection curves meet exactly on an edge (a degenerate crossing)")
            if meet is None:
                continue
            triple = add_point(meet)
            for x, y in ((trio[0], trio[1]), (trio[0], trio[2]), (trio[1], trio[2])):
                on_segment.setdefault(pair_row[(x, y)], []).append(triple)
            for k in trio:
                interior.setdefault(k, []).append(triple)
    # points of each crossed edge in order, shared by the faces around it
    for pts in on_edge.values():
        pts.sort()
        if any(pts[i][0] == pts[i + 1][0] for i in range(len(pts) - 1)):
            raise _Degenerate("two faces cross one edge at the same point (a degenerate crossing)")
    # pieces of each intersection segment, cut at its triple points
    cut_edges: list[tuple[int, int, int]] = []          # (pair row, u, v)
    for r in range(len(pairs)):
        e0, e1 = int(segment_ends[r, 0]), int(segment_ends[r, 1])
        chain = [e0, e1]
        mids = on_segment.get(r, [])
        if mids:
            p0, p1 = hom[e0], hom[e1]
            d = [Fraction(p1[i], p1[3]) - Fraction(p0[i], p0[3]) for i in range(3)]

            def along(vid: int, p0: _Hom = p0, d: list[Fraction] = d) -> Fraction:
                q = hom[vid]
                return sum((Fraction(q[i], q[3]) - Fraction(p0[i], p0[3])) * d[i] for i in range(3)) or Fraction(0)

            ordered = sorted(mids, key=along)
            keys = [along(x) for x in ordered]
            if any(keys[i] == keys[i + 1] for i in range(len(keys) - 1)):
                raise _Degenerate("two triple points coincide (four faces through one point)")
            chain = [e0, *ordered, e1]
        cut_edges += [(r, chain[i], chain[i + 1]) for i in range(len(chain) - 1)]
    # interior piercing points of each face: an edge of another face through it
    for r in range(len(pairs)):
        for s in range(2):
            if pierced[r, s] >= 0:
                interior.setdefault(int(pierced[r, s]), []).append(int(segment_ends[r, s]))
    constraints: dict[int, list[tuple[int, int]]] = {}
    for r, a, b in cut_edges:
        for k in pairs[r]:
            constraints.setdefault(int(k), []).append((a, b))

    # 2. every crossed face triangulated in its plane
    edges_with_points = set(on_edge)
    pieces: list[list[int]] = []
    source: list[int] = []
    for face in split.tolist():
        corners = [int(x) for x in f[face]]
        normal, _ = exact.plane(f, face)
        i, j = _projection(normal)
        verts = set(corners) | set(interior.get(face, []))
        for e in range(3):
            a, b = corners[e], corners[(e + 1) % 3]
            verts |= {vid for _, vid in on_edge.get((min(a, b), max(a, b)), [])}
        if len(verts) > MAX_POINTS_PER_FACE:
            raise ArrangementError(f"a face is crossed at {len(verts) - 3:,} points, more than the arrangement's "
                                   f"work bound of {MAX_POINTS_PER_FACE:,} per face")
        xy = {vid: (hom[vid][i], hom[vid][j], hom[vid][3]) for vid in verts}
        tri = _FaceTriangulation(corners, xy)
        for e in range(3):
            a, b = corners[e], corners[(e + 1) % 3]
            along_edge = [vid for _, vid in on_edge.get((min(a, b), max(a, b)), [])]
            if a > b:
                along_edge = along_edge[::-1]
            prev = a
            for q in along_edge:
                tri.split_boundary(prev, b, q)
                prev = q
            edges_with_points.discard((min(a, b), max(a, b)))
        for q in sorted(set(interior.get(face, []))):
            tri.insert(q)
        for a, b in constraints.get(face, []):
            tri.constrain(a, b)
        fixed = {(min(a, b), max(a, b)) for a, b in constraints.get(face, [])}
        for e in range(3):                    # the face's boundary, split at its points
            a, b = corners[e], corners[(e + 1) % 3]
            chain = [a, *[vid for _, vid in on_edge.get((min(a, b), max(a, b)), [])][::(1 if a < b else -1)], b]
            fixed |= {(min(p, q), max(p, q)) for p, q in zip(chain[:-1], chain[1:])}
        tri.improve(fixed)
        pieces += tri.tris
        source += [face] * len(tri.tris)
    if edges_with_points:
        raise ArrangementError("an edge crossed by a face belongs to a face that crosses nothing (internal)")

    # 3. labels
    is_split = np.zeros(len(f), dtype=bool)
    is_split[split] = True
    whole = np.flatnonzero(~is_split)
    out_faces = np.vstack([f[whole], np.asarray(pieces, dtype=np.int64).reshape(-1, 3)])
    out_source = np.r_[whole, np.asarray(source, dtype=np.int64)]
    out_v = np.vstack([v, np.asarray(new_xyz, dtype=np.float64).reshape(-1, 3)])
    n_all = len(out_v)
    cut = {min(a, b) * n_all + max(a, b) for _, a, b in cut_edges}
    patch, n_patches = _patches(out_faces, n_all, cut)

    def exact_point(vid: int) -> tuple[Fraction, Fraction, Fraction]:
        h = hom.get(vid)
        if h is None:
            return (Fraction(float(out_v[vid, 0])), Fraction(float(out_v[vid, 1])), Fraction(float(out_v[vid, 2])))
        den = exact.scale * h[3]
        return (h[0] / den, h[1] / den, h[2] / den)

    front = _label_patches(out_v, out_faces, out_source, patch, n_patches, v, f, exact_point)
    w_front = front[patch]
    first_piece = len(whole)                  # cut edges border pieces only
    try:
        _check_curves(out_faces[first_piece:], n_all, cut, out_source[first_piece:], w_front[first_piece:])
    except ArrangementError as exc:
        # a float evaluation is certified at the rounded centroid of a piece, which rounding may put on the other
        # side of a face lying within an ulp of the piece (a pleat): every patch labelled again by exact rays
        if n_patches * len(f) > MAX_EXACT_RAY_WORK:
            raise ArrangementError(f"{exc}; labelling the {n_patches:,} patches by exact rays through "
                                   f"{len(f):,} faces is past the work bound of {MAX_EXACT_RAY_WORK:,}") from None
        front = _exact_labels(out_faces, out_source, patch, n_patches, v, f, exact_point)
        w_front = front[patch]
        _check_curves(out_faces[first_piece:], n_all, cut, out_source[first_piece:], w_front[first_piece:])

    # 4. the faces bounding {w ≥ 1}, compacted
    kept = out_faces[w_front == 0]
    if not len(kept):
        raise ArrangementError("no face bounds the region of winding number ≥ 1 (the surface is wound inward)")
    return out_v, kept, dict(crossing_pairs=len(pairs), split_faces=len(split), new_vertices=len(new_xyz),
                             patches=n_patches, max_winding=int(front.max()) + 1)


def _arrange_shell(v: np.ndarray, f: np.ndarray, crossing: np.ndarray) -> Arrangement:
    """One self-crossing shell: by :func:`arrange_crossings`, or, when every crossing pair lies in one plane
    (faces overlapping coplanar, facing the same way: no crossing segment to cut along), by the coplanar overlay
    (:func:`~.coplanar.arrange_coplanar`), which forms the same ``{w ≥ 1}``."""
    a, b = f[crossing[:, 0]], f[crossing[:, 1]]
    flat = np.all(np.stack([orient3d_sign(v[a[:, 0]], v[a[:, 1]], v[a[:, 2]], v[b[:, j]]) for j in range(3)],
                           axis=1) == 0, axis=1)
    if not len(crossing) or not flat.all():
        return arrange_crossings(v, f, crossing)
    from .coplanar import arrange_coplanar      # imported on use: coplanar self-overlaps are rare
    done = arrange_coplanar(v, f)
    return Arrangement(vertices=done.vertices, faces=done.faces, crossing_pairs=len(crossing),
                       split_faces=done.split_faces, new_vertices=done.new_vertices, patches=done.patches,
                       max_winding=done.max_winding, crossings_left=done.crossings_left,
                       cancelled_faces=done.cancelled_faces, rounding=done.rounding, region=done.region)


def _compact(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The used vertices (in order) and the faces renumbered onto them (linear time)."""
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.reshape(-1)] = True
    remap = np.cumsum(used) - 1
    return vertices[used], remap[faces].astype(np.int64)


def _common_line(exact: _Exact, faces: np.ndarray, trio: tuple[int, ...]) -> bool:
    """Whether the three faces' planes share a common line (their normals are coplanar and the planes meet)."""
    (n1, d1), (n2, d2), (n3, d3) = (exact.plane(faces, k) for k in trio)
    # planes through one line: the 3x4 matrix [n | d] has rank 2
    m = [list(n1) + [d1], list(n2) + [d2], list(n3) + [d3]]
    minors = []
    for cols in combinations(range(4), 3):
        a = [[m[r][c] for c in cols] for r in range(3)]
        minors.append(a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                      - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                      + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    return all(x == 0 for x in minors)


def _label_patches(out_v: np.ndarray, out_faces: np.ndarray, out_source: np.ndarray, patch: np.ndarray,
                   n_patches: int, v: np.ndarray, f: np.ndarray,
                   exact_point: Callable[[int], tuple[Fraction, Fraction, Fraction]] | None = None) -> np.ndarray:
    """(p,) int: the winding number in front of each patch, from one certified evaluation at a face of it
    (``exact_point``: a vertex id of the split surface → its exact coordinates, for the exact ray when no float
    evaluation can be certified; without it the input's float coordinates, which are exact for input vertices)."""
    p0, p1, p2 = out_v[out_faces[:, 0]], out_v[out_faces[:, 1]], out_v[out_faces[:, 2]]
    u, w = p1 - p0, p2 - p0
    area2 = ((u[:, 1] * w[:, 2] - u[:, 2] * w[:, 1]) ** 2 + (u[:, 2] * w[:, 0] - u[:, 0] * w[:, 2]) ** 2
             + (u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]) ** 2)
    del p0, p1, p2, u, w
    order = np.lexsort((-area2, patch))
    starts = np.searchsorted(patch[order], np.arange(n_patches + 1))
    front = np.zeros(n_patches, dtype=np.int64)
    for p in range(n_patches):
        members = order[starts[p]:starts[p + 1]]
        for k in members[:_TRIES].tolist():
            total, bound = _winding_except(out_v[out_faces[k]].mean(axis=0), v, f, int(out_source[k]))
            nearest = np.floor(total) + 0.5
            if bound + abs(total - nearest) < WINDING_MARGIN:
                front[p] = int(np.floor(total))
                break
        else:
            got = _exact_front(out_faces, out_source, members[:_TRIES], v, f, exact_point)
            if got is None:
                raise ArrangementError(f"the winding number of a patch of {len(members):,} faces could not be "
                                       "certified (every point tried is too close to another surface for float64, "
                                       "and no exact ray from a piece of it was free of degeneracy)")
            front[p] = got
    return front


#: Work bound of labelling every patch by exact rays (:func:`_exact_labels`): patches × faces of the shell.
MAX_EXACT_RAY_WORK = 2_000_000


def _exact_labels(out_faces: np.ndarray, out_source: np.ndarray, patch: np.ndarray, n_patches: int, v: np.ndarray,
                  f: np.ndarray, exact_point: Callable[[int], tuple[Fraction, Fraction, Fraction]]) -> np.ndarray:
    """(p,) int: the winding number in front of each patch, every one from an exact ray (:func:`_exact_front`)."""
    order = np.argsort(patch, kind="stable")
    starts = np.searchsorted(patch[order], np.arange(n_patches + 1))
    front = np.zeros(n_patches, dtype=np.int64)
    for p in range(n_patches):
        got = _exact_front(out_faces, out_source, order[starts[p]:starts[p + 1]][:_TRIES], v, f, exact_point)
        if got is None:
            raise ArrangementError(f"the winding number of a patch of {starts[p + 1] - starts[p]:,} faces could not "
                                   "be decided by an exact ray (every ray tried was degenerate)")
        front[p] = got
    return front


#: Ray directions tried by :func:`_ray_front` (added to the face's normal scaled up), before giving up.
_RAY_TILTS = ((0, 0, 0), (3, -5, 7), (-11, 2, 5), (7, 13, -3), (-2, -9, -13))


def _exact_front(out_faces: np.ndarray, out_source: np.ndarray, members: np.ndarray, v: np.ndarray,
                 f: np.ndarray, exact_point: Callable[[int], tuple[Fraction, Fraction, Fraction]] | None
                 ) -> int | None:
    """The winding number in front of a patch from an exact ray (:func:`_ray_front`) at the exact centroid of one
    of its pieces, or None when none gives an answer (a piece with a new point and no ``exact_point``, or every
    ray degenerate)."""
    n = len(v)
    for k in members.tolist():
        corners = out_faces[k].tolist()
        if exact_point is None and max(corners) >= n:
            continue
        pts = [exact_point(c) if exact_point is not None else tuple(Fraction(float(x)) for x in v[c])
               for c in corners]
        x, y, z = ((pts[0][i] + pts[1][i] + pts[2][i]) / 3 for i in range(3))
        got = _ray_front(v, f, int(out_source[k]), (x, y, z))
        if got is not None:
            return got
    return None



def _ray_front(v: np.ndarray, f: np.ndarray, face: int,
               point: tuple[Fraction, Fraction, Fraction] | None = None) -> int | None:
    """Winding number, exactly, of the closed surface ``(v, f)`` just in front of ``point`` on ``face`` (exact
    coordinates, m; its centroid when None).

    A ray from ``p`` into the front of ``face`` (direction ``d`` with ``d·n > 0``) leaves ``face`` at ``p`` and
    crosses every other face it meets once; ``w(x) = Σ ±1`` over those crossings (+1 where the ray leaves a face
    through its back, from behind to in front, the surface wound outward), since ``w = 0`` far away.  The ray is
    the segment to ``q = p + L d`` beyond every vertex.  A float filter keeps the faces whose projection along
    ``d`` comes within a margin (1e-9 of the mesh's reach from ``p``, far above the filter's rounding) of ``p`` and
    that reach in front of ``p``; only those can be crossed.  For them every test is an exact sign on rationals:
    the sides of ``p`` and ``q`` for the face's plane, and the sides of the face's three edges seen along the line
    ``pq``.  A ray through an edge or a corner, or ``p`` lying on another face, is degenerate: the next direction
    of ``_RAY_TILTS`` is tried; None when all are.  ``p`` is assumed to lie on ``face`` (exactly in its plane; only
    the other faces are counted).
    """
    corners_f = v[f]
    if point is None:
        a, b, c = corners_f[face]
        x, y, z = ((Fraction(float(a[i])) + Fraction(float(b[i])) + Fraction(float(c[i]))) / 3 for i in range(3))
        point = (x, y, z)
    p = point
    pf = np.array([float(t) for t in p])

    def exact(row: np.ndarray) -> tuple[Fraction, Fraction, Fraction]:
        return (Fraction(float(row[0])), Fraction(float(row[1])), Fraction(float(row[2])))

    a0, b0, c0 = (exact(r) for r in corners_f[face])
    normal = _cross(_sub(b0, a0), _sub(c0, a0))
    nf = np.array([float(t) for t in normal])
    if not np.any(nf):
        return None
    nf = nf / np.linalg.norm(nf)
    rel = corners_f - pf
    reach = float(np.max(np.abs(rel))) * 2.0 + 1e-300
    margin = 1e-9 * reach
    for tilt in _RAY_TILTS:
        df = nf + 0.05 * np.asarray(tilt, dtype=np.float64) / 16.0
        d = (Fraction(float(df[0])), Fraction(float(df[1])), Fraction(float(df[2])))
        if _dot(d, normal) <= 0:
            continue
        unit = df / np.linalg.norm(df)
        u = np.cross(unit, [1.0, 0.0, 0.0] if abs(unit[0]) < 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        w = np.cross(unit, u)
        along, cu, cw = rel @ unit, rel @ u, rel @ w
        near = ((cu.min(axis=1) <= margin) & (cu.max(axis=1) >= -margin) & (cw.min(axis=1) <= margin)
                & (cw.max(axis=1) >= -margin) & (along.max(axis=1) >= -margin))
        near[face] = False
        length = Fraction(2.0 ** (int(np.ceil(np.log2(2 * reach / float(np.linalg.norm(df))))) + 1))
        q = (p[0] + length * d[0], p[1] + length * d[1], p[2] + length * d[2])
        ray = _sub(q, p)
        total, degenerate = 0, False
        for g in np.flatnonzero(near).tolist():
            a, b, c = (exact(r) for r in corners_f[g])
            n = _cross(_sub(b, a), _sub(c, a))
            sp, sq = _sign(_dot(n, _sub(p, a))), _sign(_dot(n, _sub(q, a)))
            if sp == sq and sp != 0:
                continue
            if sq == 0:
                degenerate = True
                break
            e = [_sign(_dot(ray, _cross(_sub(x, p), _sub(y, p)))) for x, y in ((a, b), (b, c), (c, a))]
            if 0 in e:
                if (1 in e and -1 in e) or (sp != 0 and e.count(0) == 3):
                    continue                        # the line passes beside the triangle (or ray parallel)
                degenerate = True
                break
            if not (e[0] == e[1] == e[2]):
                continue
            if sp == 0:                             # p lies on this face: no winding number there
                degenerate = True
                break
            total += 1 if sp < 0 else -1
        if not degenerate:
            return total
    return None


def _check_curves(faces: np.ndarray, n_vertices: int, cut: set[int], source: np.ndarray, w_front: np.ndarray) -> None:
    """Across every intersection edge, the two pieces of one input face differ by exactly one turn (the other
    face's sheet lies between them); raise ArrangementError otherwise."""
    if not cut:
        return
    key, _ = edge_keys(faces, n_vertices)
    on_cut = np.isin(key, np.fromiter(cut, dtype=np.int64, count=len(cut)))
    idx = np.flatnonzero(on_cut)
    face = idx // 3
    group = key[idx]
    order = np.lexsort((source[face], group))
    g, s, w = group[order], source[face][order], w_front[face][order]
    starts = np.flatnonzero(np.r_[True, (g[1:] != g[:-1]) | (s[1:] != s[:-1])])
    lengths = np.diff(np.r_[starts, len(g)])
    if np.any(lengths != 2):
        raise ArrangementError("an intersection edge is not bordered by two pieces of each face (internal)")
    if np.any(np.abs(w[starts] - w[starts + 1]) != 1):
        raise ArrangementError("the winding numbers of the patches do not change by one across an intersection "
                               "curve (inconsistent labels)")


@frozen_value
class ArrangedShells:
    """A surface whose self-crossing shells were each replaced by the boundary of their ``{w ≥ 1}``.

    Attributes
    ----------
    vertices : (n, 3) float64
        m; the used vertices of the input, then the new intersection points.
    faces : (k, 3) int64
        The shells that did not cross themselves, as given, then the arranged ones (wound outward).
    arrangements : tuple of Arrangement
        One per self-crossing shell, in shell order.
    inside_out : int
        Self-crossing shells wound inward as a whole (negative signed volume), turned before arranging.
    """

    vertices: np.ndarray
    faces: np.ndarray
    arrangements: tuple[Arrangement, ...]
    inside_out: int

    @property
    def crossings_left(self) -> int:
        """Face pairs of the arranged shells still crossing by rounding (0 certifies them)."""
        return sum(a.crossings_left for a in self.arrangements)

    @property
    def region(self) -> RoundedRegion | None:
        """Where the rounding of every arrangement's new points may change the result (m³, m; None: nowhere)."""
        return combined_regions(*(a.region for a in self.arrangements))


def arrange_shells(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray,
                   crossing: np.ndarray) -> ArrangedShells:
    """Replace each shell that passes through itself by the boundary of its own ``{w ≥ 1}`` (rule R3).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        A closed, consistently oriented surface.
    labels : (m,) int
        Shell of each face.
    crossing : (k, 2) int
        Crossing face pairs of the whole surface (those within one shell are arranged).

    Raises
    ------
    ArrangementError
        When a shell's arrangement fails (see :func:`arrange_crossings`).
    """
    from ..integrals import volume_moments

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    labels = np.asarray(labels)
    pairs = np.asarray(crossing, dtype=np.int64).reshape(-1, 2)
    pairs = pairs[labels[pairs[:, 0]] == labels[pairs[:, 1]]]
    shells = np.unique(labels[pairs[:, 0]])
    position = np.full(len(f), -1, dtype=np.int64)
    parts_v, parts_f, done = [v], [f[~np.isin(labels, shells)]], []
    offset, inside_out = len(v), 0
    for s in shells.tolist():
        idx = np.flatnonzero(labels == s)
        position[idx] = np.arange(len(idx))
        used, inverse = np.unique(f[idx], return_inverse=True)
        sv, sf = v[used], inverse.reshape(-1, 3).astype(np.int64)
        if volume_moments(sv, sf).volume < 0:        # wound inward as a whole: {w ≥ 1} of the turned shell
            sf = sf[:, ::-1].copy()
            inside_out += 1
        mine = position[pairs[labels[pairs[:, 0]] == s]]
        arranged = _arrange_shell(sv, sf, mine)
        done.append(arranged)
        parts_v.append(arranged.vertices)
        parts_f.append(arranged.faces + offset)
        offset += len(arranged.vertices)
    out_v, out_f = _compact(np.vstack(parts_v), np.vstack(parts_f))
    return ArrangedShells(vertices=out_v, faces=out_f, arrangements=tuple(done), inside_out=inside_out)
