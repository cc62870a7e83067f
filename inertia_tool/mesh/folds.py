"""Folds that enclose (next to) nothing: sliver fans and internal walls taken out of a closed surface (rule R3a).

A closed, edge-balanced triangle surface ``S`` is a 2-chain: its faces with their orientations, a face and its
reverse cancelling.  Its winding number at a point ``x`` off the faces is the sum of the faces' signed solid angles
over 4π, and the divergence-theorem integrals (Rigid Body Motion, Ch. 4, the volume integrals written as sums over
the faces) are ``∫ w_S (1, x, x xᵀ) dV``.  Both are additive: when ``S = S′ + Z`` as chains, with ``Z`` closed
(every edge of ``Z`` used equally often in both directions, by vertex index), then ``w_S = w_S′ + w_Z`` off the
faces.  If ``w_Z`` vanishes except on a set ``D`` of bounded volume, the solids ``{w_S ≥ 1}`` and ``{w_S′ ≥ 1}``
differ only inside ``D``, by at most ``∫|w_Z| dV`` of volume; and when ``S′`` passes the face-pair check with no
crossing (:mod:`~.intersect`, exact), ``S′`` bounds its solid exactly.  Two kinds of ``Z`` are found here.

Sliver fans
-----------
A vertex ``m`` in exactly three faces whose other corners form one cycle ``a → b → c → a`` (the faces
``(a, b, m), (b, c, m), (c, a, m)``) is the face ``(a, b, c)`` split at ``m``: the fan minus ``(a, b, c)`` is
closed (the edges at ``m`` cancel, the link edges are those of ``(a, b, c)``) and is the boundary of the
tetrahedron ``(a, b, c, m)``, so ``w_Z = ±1`` inside it and 0 outside, ``∫|w_Z| = |det(a − m, b − m, c − m)|/6``.
A point put on an edge makes such a fan: a face split at a point of one of its edges into a zero-area sliver
``(a, b, m)`` and two triangles, or a T-vertex on a face's edge closed by a sliver.  When ``m`` lies exactly on
the edge the tetrahedron is flat (``w_Z = 0`` almost everywhere: the replacement is exact).  When ``m`` was rounded
off the edge the sliver folds by that rounding, the check rightly finds the folds crossing, and the tetrahedron is
as thin as ``m``'s distance from the edge.  A face of exactly zero area (three collinear corners) subtends no solid
angle from any point off it, so it cannot change the winding number and cannot make a crossing that matters: the
face-pair check skips it.  Fans are replaced one at a time (a vertex left with three faces by a replacement is
tried next, so a chain of points on one edge unwinds), and only thin ones: a tetrahedron of at most
``tolerances.WALL_PLANE_RTOL`` times the cube of its longest edge (a corner of the part that has three faces is
no sliver).

Internal walls
--------------
Two sheets of a wall cover one region of a plane with opposite orientation: two halves of a part written face to
face, each half's cut face triangulated on its own (their corners computed on the cut plane, so off it by
rounding), or two bodies touching face to face.  The slab lemma: a closed chain ``Z`` whose corners all lie within
``δ`` of a plane ``P`` has ``w_Z(x) = 0`` for ``x`` farther than ``δ`` from ``P`` (the ray from ``x`` along the
normal away from ``P`` meets no face of ``Z``); within the slab that ray meets at most ``N(x)`` faces, the number of
faces of ``Z`` whose projection on ``P`` contains that of ``x``, so ``∫|w_Z| ≤ 2δ·Σ area``, and ``w_Z ≠ 0`` only
within ``2δ`` of the hull of its corners.  When every corner lies exactly in one plane (exact ``orient3d``) the
sheets cancel exactly: the density ``Σ ±1_T`` of the projected faces jumps across an edge by that edge's net use
in ``Z``, which is zero, so it is zero everywhere (their signed areas cancel over every region of the plane) and
``w_Z = 0`` off ``P``.

A wall ``W`` is grown from the faces of crossing or coplanar-opposite pairs, and of pairs facing each other at an
edge of four or more faces (sheets coplanar only to rounding can meet there without crossing), connected through
those pairs whose faces lie in one plane (where the rim runs along a flat side of the part, a wall face crosses
that side's faces by rounding: a group of two planes would be no wall), then through shared edges to every face
within ``tolerances.WALL_PLANE_RTOL`` of the same plane; it is taken for a wall only when its faces' vector areas
nearly cancel (two sheets of opposite orientation; a closed surface's vector area is zero), and walls must not
share a corner.  In the plane of a wall found, the other faces joined through shared edges whose vector areas
cancel are a wall too (a piece of the cut apart from the rest, which no flagged pair reached).
``W`` need not be closed by index: where one sheet's rim has a corner
the other's lacks (T-vertices along the rim, common when the halves were cut apart), ``S − W`` is left with open
loops.  Each loop ``a → b → w₁ → … → w_k → a`` (one simple cycle, its longest edge ``a → b`` in a face
``F = (a, b, x)`` of ``S − W``) is closed by splitting ``F`` along the rest of the loop into the fan
``(a, w_k, x) … (w₁, b, x)`` (``X = fan − F``).  With ``Q`` the cone from ``a`` over the loop, ``S − S* = W − X
= (W + Q) − (X + Q)`` for the closed surface ``S* = S − W + X``: ``W + Q`` is closed with every corner near ``P``
(the slab lemma: ``2δ·(area W + area Q)``), and ``X + Q`` is the boundary of the pyramid with apex ``x`` over the
loop (``Σ |tet(x, a, wᵢ, wᵢ₊₁)|``: zero when the loop's corners are collinear with ``a`` and ``b``, or when
``F`` lies in the plane of the loop).  Where the rim turns round a corner of the part that both sheets' rims share,
and they differ on both sides of it, the open edges form two loops through that corner: each edge arriving there
is followed by the leaving edge that turns back most sharply.  Any pairing gives closed loops whose sum is the rim,
which is all the bound needs; this one gives loops that run out along one side and back.

The bound
---------
``D = Σ ∫|w_Z|`` over the fans, walls and pyramids (the bounds above, added: the pieces' chains add).  The result
stands for the file's solid (R7) when ``D`` is within ``budget`` (``tolerances.ROUNDOFF_RTOL``) of the remaining
surface's volume, and ``D·R²`` (``R`` the largest distance of a corner of a removed or split piece from the
remaining surface's centroid, plus ``2δ``) within ``budget`` of its second moment's norm: the same test as R0's
copies up to rounding.  Otherwise, or when the remaining surface still has a crossing face pair (the face-pair
check runs again on ``S*`` whenever faces were split or replaced), nothing is taken out and the surface goes on to
R3 as it stands.  Crossings between faces outside every wall (a sliver of overlap along a rim on a flat face of
the part) are not explained by this rule: unless the splits undo them, the surface stays on the normal path (the
boolean union, R6 up to rounding).
"""

from __future__ import annotations

import dataclasses
from collections import deque

import numpy as np

from ..integrals import volume_moments
from ..tolerances import ROUNDOFF_RTOL, WALL_PLANE_RTOL
from ..values import frozen_value
from .edges import edge_keys
from .intersect import O3D_BOUND, SurfaceContacts, orient2d_sign, orient3d_sign, surface_contacts

__all__ = ["Folds", "Wall", "settle_folds", "sliver_fans", "internal_walls"]

_U = 2.0 ** -53
#: Work bound: groups of flagged faces examined as walls (each may grow through the surface); the rest stay
#: on the normal path.
MAX_WALL_GROUPS = 256
#: Work bound: planes of walls found in which unflagged walls are looked for (:func:`_unflagged_walls`; each
#: plane tests every vertex).
MAX_WALL_PLANES = 32
#: Work bound: faces at one edge whose pairs seed the wall search (:func:`_facing_at_folded_edges`; the pairs grow
#: with the square); edges of more faces seed nothing.
MAX_FOLD_VALENCE = 8
#: Open edges leaving one corner of the rims that are paired into loops (:func:`_rim_loops`); more are left to the
#: normal path.
MAX_RIM_VALENCE = 4
_PLANE = np.array([[1, 2], [2, 0], [0, 1]])       # coordinates kept when dropping an axis (orientation-preserving)


@frozen_value
class Folds:
    """A closed surface with its zero-volume folds taken out (R3a).

    Attributes
    ----------
    faces : (k, 3) int64
        The remaining surface (sliver fans replaced by the face they split, wall faces left out).
    contacts : SurfaceContacts
        The face-pair check of ``faces`` (no crossing pair).
    fans : int
        Sliver fans replaced.
    wall_faces : int
        Faces of internal walls left out.
    walls : int
        Internal walls (closed coplanar groups) left out.
    exact_walls : int
        Walls whose corners lie exactly in one plane (their sheets cancel exactly).
    volume_bound : float
        m³: bound on the volume in which the file's winding number differs from that of ``faces`` (``D`` of the
        module docstring); 0 when every fan and wall is exactly flat.
    """

    faces: np.ndarray
    contacts: SurfaceContacts
    fans: int
    wall_faces: int
    walls: int
    exact_walls: int
    volume_bound: float

    def describe(self) -> str:
        """One line for the report's notes."""
        parts = []
        if self.fans:
            parts.append(f"{self.fans:,} sliver fan{'s' if self.fans > 1 else ''} (a vertex of three faces splitting "
                         "the face of its neighbours, folded by rounding) replaced by the face they split")
        if self.walls:
            exact = f", {self.exact_walls} exactly coplanar" if self.exact_walls else ""
            parts.append(f"{self.walls:,} internal wall{'s' if self.walls > 1 else ''} ({self.wall_faces:,} faces: two "
                         f"sheets of opposite orientation whose edges cancel{exact}) left out")
        return ("zero-volume folds: " + "; ".join(parts) + f"; the winding number they add is nonzero in at most "
                f"{self.volume_bound:.3g} m³, within the round-off bound of an exact result")


@frozen_value
class Wall:
    """One internal wall (module docstring): faces near one plane, found together.

    Attributes
    ----------
    faces : (k,) int64
        Indices of its faces.
    distance : float
        m, upper bound on the distance of its corners from its plane; 0 when they are exactly coplanar.
    area : float
        m², summed area of its faces (rounded up).
    exact : bool
        Every corner lies exactly in one plane.
    """

    faces: np.ndarray
    distance: float
    area: float
    exact: bool


# -- sliver fans ----------------------------------------------------------------------------------------------

def sliver_fans(vertices: np.ndarray, faces: np.ndarray, *, volume_cap: float,
                thin: float = WALL_PLANE_RTOL) -> tuple[np.ndarray, int, float, np.ndarray]:
    """Replace the sliver fans (module docstring) by the face they split.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    volume_cap : float
        m³: a fan whose tetrahedron may hold more than this is left alone.
    thin : float
        Only fans whose tetrahedron holds at most ``thin`` times the cube of its longest edge are replaced (a
        point on an edge, rounded off it: the tetrahedron is as thin as the rounding); a corner of the part that
        happens to have three faces is not.

    Returns
    -------
    faces : (k, 3) int64
        The surface with the fans replaced (a face and its fan's three faces: two fewer per fan).
    fans : int
    volume : float
        m³, upper bound on the summed volumes of the fans' tetrahedra.
    corners : (c,) int
        The vertices of the fans replaced (for the moment bound).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n, m = len(v), len(f)
    valence = np.bincount(f.reshape(-1), minlength=n)
    order = np.argsort(f.reshape(-1), kind="stable")
    start = np.r_[0, np.cumsum(valence)]
    rows = [tuple(r) for r in f.tolist()]
    alive = [True] * m
    added: dict[int, list[int]] = {}
    queue = deque(_thin_fan_vertices(v, f, valence, order, start, thin).tolist())
    fans, volume, corners = 0, 0.0, []
    for _ in range(m):                                   # each replacement removes two faces: bounded by m
        if not queue:
            break
        c0 = queue.popleft()
        around = [g for g in (order[start[c0]:start[c0 + 1]] // 3).tolist() + added.get(c0, []) if alive[g]]
        if len(around) != 3:
            continue
        link: dict[int, int] = {}
        for g in around:
            tri = rows[g]
            i = tri.index(c0)
            link[tri[(i + 1) % 3]] = tri[(i + 2) % 3]
        if len(link) != 3 or set(link) != set(link.values()) or c0 in link or any(x == y for x, y in link.items()):
            continue                                     # not one cycle of three distinct corners
        a = next(iter(link))
        b = link[a]
        c = link[b]
        tet = _tetra_volume_bound(v[a], v[b], v[c], v[c0])
        corners4 = v[[a, b, c, c0]]
        longest = float(np.max(np.linalg.norm(corners4[:, None] - corners4[None], axis=2)))
        if tet > volume_cap or tet > thin * longest ** 3:
            continue
        for g in around:
            alive[g] = False
        rows.append((a, b, c))
        alive.append(True)
        new = len(rows) - 1
        for x in (a, b, c):
            added.setdefault(x, []).append(new)
            valence[x] -= 1
            if valence[x] == 3:
                queue.append(x)
        valence[c0] = 0
        fans += 1
        volume += tet
        corners += [a, b, c, c0]
    if not fans:
        return f, 0, 0.0, np.zeros(0, dtype=np.int64)
    keep = np.flatnonzero(np.array(alive))
    return (np.array([rows[g] for g in keep.tolist()], dtype=np.int64).reshape(-1, 3), fans, volume,
            np.unique(np.array(corners, dtype=np.int64)))


def _thin_fan_vertices(v: np.ndarray, f: np.ndarray, valence: np.ndarray, order: np.ndarray, start: np.ndarray,
                       thin: float) -> np.ndarray:
    """The vertices of exactly three faces whose tetrahedron (the vertex and the corners following it in its
    faces) is thin by the test of :func:`sliver_fans` (up to a factor 2 of slack: this only picks the vertices
    tried; each is tested again exactly as it stands when tried)."""
    c = np.flatnonzero(valence == 3)
    if not len(c):
        return c
    around = order[start[c][:, None] + np.arange(3)] // 3              # (k, 3) the three faces
    tri = f[around]                                                     # (k, 3, 3)
    at = np.argmax(tri == c[:, None, None], axis=2)                     # the vertex's corner in each face
    nxt = np.take_along_axis(tri, ((at + 1) % 3)[:, :, None], axis=2)[:, :, 0]     # (k, 3) corners after it
    p = v[nxt] - v[c][:, None, :]
    det = np.abs(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])))
    q = np.concatenate([p, np.zeros_like(p[:, :1])], axis=1)
    longest = np.max(np.linalg.norm(q[:, :, None] - q[:, None], axis=3), axis=(1, 2))
    return np.asarray(c[det / 6 <= 2 * thin * longest ** 3 + 1e-300])


def _tetra_volume_bound(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> float:
    """m³, an upper bound on ``|det(a − d, b − d, c − d)|/6`` (the float value plus orient3d's static error bound,
    :data:`~.intersect.O3D_BOUND`, and the rounding of the last steps)."""
    ad, bd, cd = a - d, b - d, c - d
    det = float(np.dot(ad, np.cross(bd, cd)))
    perm = float(np.dot(np.abs(ad), np.abs(bd)[[1, 2, 0]] * np.abs(cd)[[2, 0, 1]]
                        + np.abs(bd)[[2, 0, 1]] * np.abs(cd)[[1, 2, 0]]))
    return (abs(det) + O3D_BOUND * perm) / 6 * (1 + 8 * _U)


# -- internal walls -------------------------------------------------------------------------------------------

def internal_walls(vertices: np.ndarray, faces: np.ndarray, pairs: np.ndarray, *,
                   plane_rtol: float = WALL_PLANE_RTOL) -> list[Wall]:
    """The internal walls (module docstring) among the faces of ``pairs``.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    pairs : (k, 2) int
        Face pairs the check flagged (crossing, or coplanar and facing opposite ways within one shell).
    plane_rtol : float
        A wall's corners lie within ``plane_rtol`` times the largest |coordinate| of its plane.

    Returns
    -------
    list of Wall
        Disjoint groups of faces, each near one plane (what they leave open by index is closed by
        :func:`_close_rims`).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    m = len(f)
    wall = np.zeros(m, dtype=bool)
    found: list[Wall] = []
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if not len(p):
        return found
    flagged = np.unique(p.reshape(-1))
    key, forward = edge_keys(f, len(v))
    key_order = np.argsort(key, kind="stable")
    sorted_keys = key[key_order]
    # flagged faces sharing an edge and lying in one plane (normals parallel within 1e-6 of the cosine) belong to
    # one group too (a sheet is edge-connected; a face of the part beside its rim is not in its plane)
    is_flagged = np.zeros(m, dtype=bool)
    is_flagged[flagged] = True
    same = np.flatnonzero(sorted_keys[1:] == sorted_keys[:-1])
    fa, fb = key_order[same] // 3, key_order[same + 1] // 3
    both = is_flagged[fa] & is_flagged[fb]
    if both.any():
        normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        size = np.maximum(np.linalg.norm(normal, axis=1), 1e-300)
        cos = np.einsum("ij,ij->i", normal[fa[both]], normal[fb[both]]) / (size[fa[both]] * size[fb[both]])
        both[np.flatnonzero(both)[np.abs(cos) < 1 - 1e-6]] = False
    tolerance = plane_rtol * float(np.abs(v).max())
    # a flagged pair joins its faces into one group only when they lie in one plane: where the rim runs along a
    # flat side of the part, a wall's face crosses that side's faces by rounding, and a group spanning both
    # planes would be no wall (its faces stay flagged, each a group of its own, grown through its plane below)
    p = p[_in_one_plane(v, f, p, tolerance)]
    rows = np.r_[p[:, 0], fa[both]]
    cols = np.r_[p[:, 1], fb[both]]
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(m, m))
    _, comp = connected_components(graph, directed=False)
    groups = comp[flagged]
    order = np.argsort(groups, kind="stable")
    bounds = np.flatnonzero(np.r_[True, groups[order][1:] != groups[order][:-1], True])
    spans = sorted(zip(bounds[:-1].tolist(), bounds[1:].tolist()), key=lambda b: b[0] - b[1])    # largest first
    for s0, s1 in spans[:MAX_WALL_GROUPS]:               # one group per connected set of flagged faces
        # the group's faces in increasing order (f[ids] is f[members]); a group is mostly left at the plane
        # test, before its (m,) mask is built (issue 25, corpus15: ~11k groups a Menagerie corpus run)
        ids = np.sort(flagged[order[s0:s1]])
        if wall[ids].any():
            continue
        plane = _plane(v, f[ids])
        if plane is None or _distance_bound(v, f[ids], *plane) > tolerance:
            continue
        members = np.zeros(m, dtype=bool)
        members[ids] = True
        if not _closed(key, forward, members):           # the flagged faces alone leave part of the wall out
            grown = _grow(v, f, members, plane, tolerance, key, sorted_keys, key_order)
            if grown is not None:
                members = grown & ~wall
        if not _sheets_cancel(v, f[members]):
            continue                                    # one sheet (a flat face of the part): no wall
        exact = _exactly_coplanar(v, f[members])
        wall |= members
        found.append(Wall(faces=np.flatnonzero(members),
                          distance=0.0 if exact else _distance_bound(v, f[members], *plane),
                          area=_area_bound(v, f[members]), exact=exact))
    return found + _unflagged_walls(v, f, found, wall, tolerance, key)


def _unflagged_walls(v: np.ndarray, f: np.ndarray, found: list[Wall], wall: np.ndarray, tolerance: float,
                     key: np.ndarray) -> list[Wall]:
    """Walls in the plane of a wall found, that no flagged pair reached: a small piece of the cut apart from the
    rest of it (where the cut clips a corner of the part) whose two sheets meet only at shared corners and edges.
    Left in, its sheets are a flat fold of the surface (edges used by four faces) that the later stages read as
    bodies welded along an edge.  The faces within ``tolerance`` of that plane outside every wall, joined through
    shared edges, are a wall when their vector areas cancel (:func:`_sheets_cancel`)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    out: list[Wall] = []
    planes: list[tuple[np.ndarray, float]] = []
    for w in found:
        if len(planes) >= MAX_WALL_PLANES:
            break
        plane = _plane(v, f[w.faces])
        if plane is None or any(abs(float(plane[0] @ u)) > 1 - 1e-12 and abs(plane[1] - o) <= tolerance
                                for u, o in planes):
            continue
        planes.append(plane)
        unit, offset = plane
        near = np.all((np.abs(v @ unit - offset) <= tolerance)[f], axis=1) & ~wall
        if not near.any():
            continue
        slots = (3 * np.flatnonzero(near)[:, None] + np.arange(3)).reshape(-1)
        _, edge = np.unique(key[slots], return_inverse=True)      # faces and their edges: a bipartite graph (an
        m = len(f)                                                 # edge of four faces joins all four)
        graph = coo_matrix((np.ones(len(slots), dtype=np.int8), (slots // 3, m + edge.reshape(-1))),
                           shape=(m + len(slots), m + len(slots)))
        _, comp = connected_components(graph, directed=False)
        comp = comp[:m]
        for c in np.unique(comp[near]).tolist():
            members = near & (comp == c)
            if np.count_nonzero(members) < 2 or not _sheets_cancel(v, f[members]):
                continue
            exact = _exactly_coplanar(v, f[members])
            wall |= members
            out.append(Wall(faces=np.flatnonzero(members),
                            distance=0.0 if exact else _distance_bound(v, f[members], unit, offset),
                            area=_area_bound(v, f[members]), exact=exact))
    return out


def _close_rims(v: np.ndarray, rest: np.ndarray) -> tuple[np.ndarray, float, float, np.ndarray] | None:
    """Close by index what the walls left open in ``rest`` (the surface without them): module docstring,
    "Internal walls".  Each loop of unmatched edges must be one simple cycle that runs out along a line and back
    (two chains, monotone in the position along the line between its two farthest corners: the two sheets' rims
    with their T-vertices).  Every open edge ``p → q`` lies in one face ``(p, q, x)``, split at the loop's
    corners lying strictly between ``p`` and ``q`` into the fan ``(p, s₁, x) … (s_k, q, x)``, so that both chains
    end up with every corner.  Returns the new surface, the bound on the pyramids' volumes ``Σ |tet(x, p, sⱼ,
    sⱼ₊₁)|`` (m³), the area of the cones from ``p`` over each split edge's polygon (m²) and the corners of the faces
    split; None when a loop is not of that form."""
    key, forward = edge_keys(rest, len(v))
    _, inverse = np.unique(key, return_inverse=True)
    inverse = inverse.reshape(-1)
    net = np.bincount(inverse, weights=np.where(forward, -1.0, 1.0)).astype(np.int64)     # lo→hi minus hi→lo
    open_slot = np.flatnonzero(net[inverse] != 0)
    if not len(open_slot):
        return rest, 0.0, 0.0, np.zeros(0, dtype=np.int64)
    if np.any(np.abs(net) > 1) or len(np.unique(inverse[open_slot])) != len(open_slot):
        return None                                     # an edge left open twice: not one simple cycle
    a = rest.reshape(-1)[open_slot].tolist()
    b = rest[:, [1, 2, 0]].reshape(-1)[open_slot].tolist()
    loops = _rim_loops(v, a, b)
    if loops is None:
        return None
    face_of = {(x, y): int(s) // 3 for x, y, s in zip(a, b, open_slot.tolist())}
    keep = np.ones(len(rest), dtype=bool)
    added: list[list[int]] = []
    pyramids, cone_area = 0.0, 0.0
    for loop in loops:
        if len(loop) < 3:
            return None
        pts = v[loop]
        gap = np.linalg.norm(pts[:, None] - pts[None], axis=2)
        i, j = np.unravel_index(int(np.argmax(gap)), gap.shape)
        along = (pts - pts[i]) @ (pts[j] - pts[i])       # position along the line of the two farthest corners
        if len(np.unique(along)) != len(loop):
            return None
        k = len(loop)
        rises = np.diff(along[np.r_[np.arange(k), 0]]) > 0
        turns = int(np.count_nonzero(rises != np.roll(rises, 1)))
        if turns != 2:
            return None                                 # not out along the line and back
        order = np.argsort(along)
        rank = np.empty(k, dtype=np.int64)
        rank[order] = np.arange(k)
        for e in range(k):
            p, q = loop[e], loop[(e + 1) % k]
            lo, hi = sorted((int(rank[e]), int(rank[(e + 1) % k])))
            inner = order[lo + 1:hi]
            if not len(inner):
                continue
            if rank[e] > rank[(e + 1) % k]:
                inner = inner[::-1]
            g = face_of[(p, q)]
            if not keep[g]:
                return None                             # a face on two open edges: left to the normal path
            tri = rest[g].tolist()
            x = tri[(tri.index(p) + 2) % 3]
            keep[g] = False
            chain = [p, *[loop[t] for t in inner.tolist()], q]
            for s0, s1 in zip(chain[:-1], chain[1:]):
                added.append([s0, s1, x])
                if s0 != p:
                    pyramids += _tetra_volume_bound(v[x], v[p], v[s0], v[s1])
                    cone_area += 0.5 * float(np.linalg.norm(np.cross(v[s0] - v[p], v[s1] - v[p])))
    split = np.array(added, dtype=np.int64).reshape(-1, 3)
    return np.vstack([rest[keep], split]), pyramids, cone_area * (1 + 1e-12), np.unique(split)


def _in_one_plane(v: np.ndarray, f: np.ndarray, pairs: np.ndarray, tolerance: float) -> np.ndarray:
    """(k,) bool: whether the corners of the smaller face of each pair lie within ``tolerance`` (m) of the plane of
    the larger (a sliver's own normal says nothing of its plane; the larger face's does)."""
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    size = np.linalg.norm(normal, axis=1)
    big = np.where(size[pairs[:, 0]] >= size[pairs[:, 1]], pairs[:, 0], pairs[:, 1])
    small = np.where(big == pairs[:, 0], pairs[:, 1], pairs[:, 0])
    unit = normal[big] / np.maximum(size[big], 1e-300)[:, None]
    reach = np.abs(np.einsum("kij,kj->ki", v[f[small]] - v[f[big, 0]][:, None, :], unit))
    return np.asarray(np.all(reach <= tolerance, axis=1) & (size[big] > 0))


def _rim_loops(v: np.ndarray, a: list[int], b: list[int]) -> list[list[int]] | None:
    """The open edges ``a[i] → b[i]`` (each used once) as simple cycles of corners, or None.

    Where a corner lies on two loops (the two sheets' rims share a corner of the part, where the rim turns round
    it, and differ on both sides of it), each edge arriving there is followed by the leaving edge that turns back
    most sharply (the largest cosine between the directions to the two other ends): the loop along one side of
    the part runs out and back along that side, so its chains leave the shared corner in nearly the same
    direction.  Any pairing gives closed loops whose sum is the rim (what the bound of the module docstring
    needs); this one gives the loops :func:`_close_rims` can split."""
    outs: dict[int, list[int]] = {}
    ins: dict[int, list[int]] = {}
    for e, (x, y) in enumerate(zip(a, b)):
        outs.setdefault(x, []).append(e)
        ins.setdefault(y, []).append(e)
    if any(len(ins.get(x, ())) != len(es) for x, es in outs.items()) or set(ins) != set(outs):
        return None                                     # not a union of cycles
    follow = [-1] * len(a)
    for x, leaving in outs.items():
        arriving = ins[x]
        if len(leaving) == 1:
            follow[arriving[0]] = leaving[0]
            continue
        if len(leaving) > MAX_RIM_VALENCE:
            return None
        back = v[[a[e] for e in arriving]] - v[x]      # from the corner to where each arriving edge came from
        ahead = v[[b[e] for e in leaving]] - v[x]
        back /= np.maximum(np.linalg.norm(back, axis=1), 1e-300)[:, None]
        ahead /= np.maximum(np.linalg.norm(ahead, axis=1), 1e-300)[:, None]
        cos = back @ ahead.T
        used_in, used_out = set(), set()
        for flat in np.argsort(-cos, axis=None, kind="stable").tolist():
            i, j = divmod(flat, len(leaving))
            if i in used_in or j in used_out:
                continue
            follow[arriving[i]] = leaving[j]
            used_in.add(i)
            used_out.add(j)
    loops: list[list[int]] = []
    seen = [False] * len(a)
    for e0 in range(len(a)):
        if seen[e0]:
            continue
        loop, e = [], e0
        for _ in range(len(a)):                         # bounded: each edge once
            seen[e] = True
            loop.append(a[e])
            e = follow[e]
            if e == e0:
                break
        else:
            return None
        if len(set(loop)) != len(loop) or len(loop) < 3:
            return None                                 # a corner twice on one loop
        loops.append(loop)
    return loops


def _closed(key: np.ndarray, forward: np.ndarray, members: np.ndarray) -> bool:
    """Whether the faces ``members`` (m,) bool use every edge equally often in both directions (by index)."""
    at = np.repeat(members, 3)
    _, inverse = np.unique(key[at], return_inverse=True)
    net = np.bincount(inverse.reshape(-1), weights=np.where(forward[at], 1.0, -1.0))
    return bool(len(net) and np.all(net == 0))


def _sheets_cancel(v: np.ndarray, f: np.ndarray, rtol: float = 1e-6) -> bool:
    """Whether the faces' vector areas nearly cancel (``|Σ Aᵢnᵢ| ≤ rtol·Σ Aᵢ``), as those of two sheets of
    opposite orientation over one region do (a closed surface's vector area is zero).  Only a filter: a flat face
    of the part next to a seam is not taken for a wall; what makes the result exact is the volume bound."""
    normal = 0.5 * _face_normals(v, f)
    total = float(np.sum(np.linalg.norm(normal, axis=1)))
    return bool(total > 0 and float(np.linalg.norm(normal.sum(axis=0))) <= rtol * total)


def _face_normals(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """(k, 3): ``np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])``, the same floats (each component
    ``a_i b_j − a_j b_i``, two products and a difference, as ``np.cross`` rounds them), without its set-up per
    call (the fold search calls it on a few faces thousands of times)."""
    a = v[f[:, 1]] - v[f[:, 0]]
    b = v[f[:, 2]] - v[f[:, 0]]
    out = np.empty_like(a)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return np.asarray(out)


def _median(x: np.ndarray) -> float:
    """``np.median`` of a 1-D float array, the same value: the middle of the sorted values, or the two middle ones'
    sum halved (``np.median`` takes their mean); NaN when one is NaN (sorted last)."""
    if not len(x):
        return float(np.median(x))
    ordered = np.sort(x)
    half = len(ordered) // 2
    if np.isnan(ordered[-1]):
        return float("nan")
    if len(ordered) % 2:
        return float(ordered[half])
    return float((ordered[half - 1] + ordered[half]) / 2)


def _plane(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Unit normal and offset of the plane of faces nearly in one plane (normals aligned to the largest face's,
    area-weighted), or None when they have no area."""
    normal = _face_normals(v, f)
    size = np.linalg.norm(normal, axis=1)
    if not len(size) or not size.max() > 0:
        return None
    ref = normal[int(np.argmax(size))]
    total = np.sum(np.where((normal @ ref >= 0)[:, None], normal, -normal), axis=0)
    norm = float(np.linalg.norm(total))
    if not norm > 0:
        return None
    unit = total / norm
    offset = _median(v[np.unique(f.reshape(-1))] @ unit)
    return unit, offset


def _distance_bound(v: np.ndarray, f: np.ndarray, unit: np.ndarray, offset: float) -> float:
    """m, an upper bound on the distance of the corners of ``f`` from the plane ``unit·x = offset``: the float
    value plus the rounding of the dot products and the difference, over ``|unit|`` (which is 1 within 4u)."""
    p = v[np.unique(f.reshape(-1))]
    dist = np.abs(p @ unit - offset)
    scale = np.abs(p) @ np.abs(unit) + abs(offset)
    return float(np.max(dist + 8 * _U * scale)) / (float(np.linalg.norm(unit)) * (1 - 8 * _U))


def _area_bound(v: np.ndarray, f: np.ndarray) -> float:
    """m², the faces' summed area, rounded up."""
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    return float(np.sum(area)) * (1 + 1e-12)


def _grow(v: np.ndarray, f: np.ndarray, members: np.ndarray, plane: tuple[np.ndarray, float], tolerance: float,
          key: np.ndarray, sorted_keys: np.ndarray, key_order: np.ndarray) -> np.ndarray | None:
    """``members`` grown through shared edges by the faces within ``tolerance`` of ``plane`` (a wall's faces that
    overlap no face of the other sheet but only touch it); None when nothing is added."""
    unit, offset = plane
    grown = members.copy()
    near_vertex = np.abs(v @ unit - offset) <= tolerance
    # a face is near when its three corners are; judged only for the faces the frontier touches (issue 25: the
    # test of every face on each call was ~4 s of CPU over the ~14k calls of a Menagerie corpus run)
    frontier_keys = np.unique(key[(3 * np.flatnonzero(grown)[:, None] + np.arange(3)).reshape(-1)])
    for _ in range(len(f)):                               # each pass adds at least one face
        lo = np.searchsorted(sorted_keys, frontier_keys, side="left")
        hi = np.searchsorted(sorted_keys, frontier_keys, side="right")
        count = hi - lo
        slots = np.repeat(lo, count) + (np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count))
        touched = np.unique(key_order[slots] // 3)
        new = touched[np.all(near_vertex[f[touched]], axis=1) & ~grown[touched]]
        if not len(new):
            break
        grown[new] = True
        frontier_keys = np.unique(key[(3 * new[:, None] + np.arange(3)).reshape(-1)])
    return grown if np.count_nonzero(grown) > np.count_nonzero(members) else None


def _exactly_coplanar(v: np.ndarray, f: np.ndarray) -> bool:
    """Whether every corner of ``f`` lies exactly in the plane of its largest face (exact orient3d), that face
    having nonzero area exactly (exact orient2d on its best projection)."""
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal = np.cross(p1 - p0, p2 - p0)
    big = int(np.argmax(np.linalg.norm(normal, axis=1)))
    keep = _PLANE[int(np.argmax(np.abs(normal[big])))]
    if int(orient2d_sign(p0[big, keep], p1[big, keep], p2[big, keep])[0]) == 0:
        return False
    corners = v[np.unique(f.reshape(-1))]
    k = len(corners)
    signs = orient3d_sign(np.repeat(p0[big][None], k, 0), np.repeat(p1[big][None], k, 0),
                          np.repeat(p2[big][None], k, 0), corners)
    return bool(np.all(signs == 0))


# -- the rule -------------------------------------------------------------------------------------------------

def _merged(v: np.ndarray, f: np.ndarray, walls: list[Wall], plane_rtol: float) -> list[Wall] | None:
    """The walls with those sharing a corner joined into one (near one plane, or None)."""
    if len(walls) < 2:
        return walls
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    corner_wall = np.concatenate([np.full(3 * len(w.faces), i) for i, w in enumerate(walls)])
    corner = np.concatenate([f[w.faces].reshape(-1) for w in walls])
    graph = coo_matrix((np.ones(len(corner), dtype=np.int8), (corner_wall, corner)),
                       shape=(len(walls), int(corner.max()) + 1))
    n, joined = connected_components(graph @ graph.T, directed=False)
    if n == len(walls):
        return walls
    out = []
    for k in range(n):
        members = [walls[i] for i in np.flatnonzero(joined == k).tolist()]
        if len(members) == 1:
            out.append(members[0])
            continue
        faces = np.concatenate([w.faces for w in members])
        plane = _plane(v, f[faces])
        if plane is None:
            return None
        delta = _distance_bound(v, f[faces], *plane)
        if delta > plane_rtol * float(np.abs(v).max()):
            return None
        exact = _exactly_coplanar(v, f[faces])
        out.append(Wall(faces=faces, distance=0.0 if exact else delta, area=_area_bound(v, f[faces]), exact=exact))
    return out


def _flagged_pairs(contacts: SurfaceContacts, labels: np.ndarray, v: np.ndarray | None = None,
                   f: np.ndarray | None = None) -> np.ndarray:
    """Crossing pairs, coplanar-opposite pairs within one shell, and (given ``v`` and ``f``) the facing pairs at
    edges of four or more faces (:func:`_facing_at_folded_edges`) (k, 2)."""
    cross = np.asarray(contacts.crossing, dtype=np.int64).reshape(-1, 2)
    opp = np.asarray(contacts.coplanar_opposite, dtype=np.int64).reshape(-1, 2)
    opp = opp[labels[opp[:, 0]] == labels[opp[:, 1]]]
    if v is None or f is None:
        return np.concatenate([cross, opp])
    return np.concatenate([cross, opp, _facing_at_folded_edges(v, f)])


def _facing_at_folded_edges(v: np.ndarray, f: np.ndarray, cos_max: float = -1 + 1e-6) -> np.ndarray:
    """(k, 2) pairs of faces on one edge of four or more faces that use it in opposite directions and face
    opposite ways (cosine of their normals at most ``cos_max``): the two sheets of a wall at an edge both have.
    Where the sheets' corners are coplanar only to rounding they can meet without crossing or overlapping
    (the face-pair check calls them touching), so nothing else flags such a wall; the pairs only seed the
    search (:func:`internal_walls`), which decides."""
    key, forward = edge_keys(f, len(v))
    order = np.argsort(key, kind="stable")
    k = key[order]
    starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
    counts = np.diff(np.r_[starts, len(k)])
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    unit = normal / np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    out = []
    top = min(int(counts.max(initial=0)), MAX_FOLD_VALENCE)
    for i in range(top):
        for j in range(i + 1, top):
            at = starts[(counts > j) & (counts <= MAX_FOLD_VALENCE)]
            a, b = order[at + i], order[at + j]
            ga, gb = a // 3, b // 3
            keep = ((forward[a] != forward[b]) & (ga != gb)
                    & (np.einsum("ij,ij->i", unit[ga], unit[gb]) <= cos_max))
            out.append(np.stack([ga[keep], gb[keep]], axis=1))
    return np.concatenate(out) if out else np.zeros((0, 2), dtype=np.int64)


def settle_folds(vertices: np.ndarray, faces: np.ndarray, contacts: SurfaceContacts,
                 labels: np.ndarray | None = None, *,
                 budget: float = ROUNDOFF_RTOL, plane_rtol: float = WALL_PLANE_RTOL) -> Folds | None:
    """R3a (:func:`_settle_folds`): the wall search seeded by the flagged pairs and the facing pairs at edges of
    four or more faces; when that settles nothing, seeded by the flagged pairs alone.  More seeds can join a
    found wall's faces to faces of another plane (two touching copies' contact faces with the faces facing
    them round its rim), and then no wall passes; either search's result passes the same checks."""
    found = _settle_folds(vertices, faces, contacts, labels, budget=budget, plane_rtol=plane_rtol, facing=True)
    if found is None:
        found = _settle_folds(vertices, faces, contacts, labels, budget=budget, plane_rtol=plane_rtol,
                              facing=False)
    return found


def _settle_folds(vertices: np.ndarray, faces: np.ndarray, contacts: SurfaceContacts,
                  labels: np.ndarray | None = None, *,
                  budget: float = ROUNDOFF_RTOL, plane_rtol: float = WALL_PLANE_RTOL,
                  facing: bool = True) -> Folds | None:
    """R3a: the surface with its sliver fans and internal walls taken out, when what they change is within
    ``budget`` and the rest has no crossing face pair (module docstring); else None.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        A closed, edge-balanced surface.
    contacts : SurfaceContacts
        Its face-pair check.
    labels : (m,) int, optional
        Shell of each face; default the edge-connected shells (R1), so that the two sheets of a wall between
        bodies welded along its rim (which R1b may have split apart) count as one shell's.
    budget : float
        Relative bound on what the folds may change (``tolerances.ROUNDOFF_RTOL``: what "exact" allows).
    plane_rtol : float
        A wall's corners lie within this times the largest |coordinate| of its plane.
    """
    from .checks import shell_labels

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if labels is None:
        labels, _ = shell_labels(f, len(v))
    labels = np.asarray(labels, dtype=np.int64)
    if not contacts.complete:
        return None
    pairs = _flagged_pairs(contacts, labels, v, f) if facing else _flagged_pairs(contacts, labels)
    if not len(pairs):
        return None
    whole = volume_moments(v, f)
    cap = budget * abs(whole.volume)
    if len(contacts.crossing):                           # folded slivers cross; without a crossing R3 has no work
        g, fans, fan_volume, fan_corners = sliver_fans(v, f, volume_cap=cap, thin=plane_rtol)
    else:
        g, fans, fan_volume, fan_corners = f, 0, 0.0, np.zeros(0, dtype=np.int64)
    if fans:
        if fan_volume > cap:
            return None
        contacts = surface_contacts(v, g)
        if not contacts.complete:
            return None
        labels, _ = shell_labels(g, len(v))
        pairs = _flagged_pairs(contacts, labels, v, g) if facing else _flagged_pairs(contacts, labels)
    found = internal_walls(v, g, pairs, plane_rtol=plane_rtol)
    wall = np.zeros(len(g), dtype=bool)
    for w in found:
        wall[w.faces] = True
    cross = np.asarray(contacts.crossing, dtype=np.int64).reshape(-1, 2)
    uncovered = bool(np.any(~wall[cross[:, 0]] & ~wall[cross[:, 1]]))    # only a split at a rim can undo them
    if not fans and not wall.any():
        return None
    merged = _merged(v, g, found, plane_rtol)            # walls sharing a corner are one (their rims would mix)
    if merged is None:
        return None
    found = merged
    keep = ~wall
    closed = _close_rims(v, g[keep])
    if closed is None:
        return None
    h, pyramids, cone_area, split_corners = closed
    if not len(h):
        return None                                       # nothing but walls: R2 says what that is
    delta = max((w.distance for w in found), default=0.0)
    volume = fan_volume + pyramids + 2 * delta * (sum(w.area for w in found) + cone_area)
    rest = volume_moments(v, h)
    corners = np.unique(np.concatenate([fan_corners, g[wall].reshape(-1), split_corners]))
    reach = float(np.sqrt(np.max(np.sum((v[corners] - rest.centroid) ** 2, axis=1)))) if len(corners) else 0.0
    reach += 2 * delta                                    # the slab: within 2δ of the hull of the corners
    if not (volume <= budget * abs(rest.volume)
            and volume * reach ** 2 <= budget * float(np.linalg.norm(rest.second_moment))):
        return None
    if len(h) != int(np.count_nonzero(keep)) or uncovered:     # faces split at the rims: checked like any others
        left = surface_contacts(v, h)
        if len(left.crossing) or not left.complete:
            return None
    else:
        index = np.cumsum(keep) - 1                       # old face -> new face
        left = dataclasses.replace(contacts, crossing=np.zeros((0, 2), dtype=np.intp),
                                   coplanar_opposite=_kept_pairs(contacts.coplanar_opposite, keep, index),
                                   contact=_kept_pairs(contacts.contact, keep, index))
    return Folds(faces=h, contacts=left, fans=fans, wall_faces=int(np.count_nonzero(wall)), walls=len(found),
                 exact_walls=sum(1 for w in found if w.exact), volume_bound=float(volume))


def _kept_pairs(pairs: np.ndarray, keep: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Face pairs with both faces kept, renumbered (k, 2) intp."""
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    p = p[keep[p[:, 0]] & keep[p[:, 1]]]
    return np.asarray(index[p].astype(np.intp).reshape(-1, 2))
