"""Bounding a hole that reaches round an edge of the part, under the user's ``faceted-holes``: the pieces of the
planes' polytope beyond the cone.

:func:`~.hole_facets.faceted_doubt` reads a hole under ``faceted-holes`` as a graph over the plane square to the
rim's vector area ``d``.  A hole that reaches round an edge of a faceted part (across a cylinder's cap and side, a
cone's base and side, two faces of an octahedron) is often no such graph: its cone folds over ``d``, or a face
across its rim faces away from ``d``.  For those the same statement is read without the graph
(:data:`~.hole_assumptions.FACETED_HOLES`).

**Assumption.**  The faces with a corner on the rim (the *ring*) give planes ``n_j · x = c_j`` (``n_j`` outward,
unit); every rim vertex lies inside every one of them (*convex* surroundings, checked), so their intersection
``K`` is convex and holds the rim, its hull and the cone over it (apex ``a``, the rim's centroid).  The missing
surface ``M`` lies in ``K`` on the far side of the cone from the part: in the region ``R`` between the cone and
``∂K`` (the planes continued until they meet).

**The region, exactly.**  Seen from a point ``o`` strictly inside ``K`` from which every fan triangle
``T_i = (e1, e0, a)`` (wound outward) faces away (``n_i · (a − o) > 0``: the cone is a radial graph over ``o``), and
whose central projection of the fan turns once round ``a``'s (the fan's projected triangles tile the rim's
projection), the solid cones ``C_i`` from ``o`` over the ``T_i`` partition the directions over the rim, and ``R`` is
the union of the convex polytopes ``Z_i = K ∩ C_i ∩ {n_i · x ≥ n_i · a}`` (a ray from ``o`` over ``T_i`` leaves the
cone at ``T_i`` and ``K`` at ``∂K``).  ``R`` is a closed ball (a radial region over a disc of directions), so every
point outside it is joined to infinity outside it; the cycle "cone − M" lies in ``R``, its winding number vanishes
outside ``R``, and the patched and the true solid differ by at most ``vol R = Σ_i vol Z_i``, each computed as a
convex polytope (:class:`scipy.spatial.HalfspaceIntersection`, its hull's volume; ``K``'s planes and the ``T_i``'s
moved out by the tolerance ``τ`` of "on a plane"), summed and rounded up.  Every ``Z_i`` must be bounded (the
planes close ``R``: a ring of walls alone leaves it open).  ``o`` is tried at ``a + t w`` for ``t`` = 1, ½, 2, ¼,
4 times the rim's ball radius, ``w`` the direction every fan triangle faces away from most (a small LP; ``−d``,
``d`` the cone's vector area, where every fan triangle faces ``d``); where none qualifies the reading is not made.

**The fill** (:func:`wrapped_fill`): the cone's fan pushed along the rays from ``o`` out to ``∂K``, ``R``'s far
side (the planes continued, one plane per point); it lies in ``R``, so the bound stands.

**The file's evidence against it** (the reading withdrawn, the hole keeps its other bound): a vertex of the file,
other than the rim's, in ``R`` farther than ``τ`` beyond the cone (on ``∂K`` too: the file's own surface lies
where the assumption puts only the lost one), surroundings that are not convex, a pinched rim, a rim or fan that
is no radial graph from any ``o`` tried.
"""

from __future__ import annotations

import numpy as np

from ..rounding import round_up
from ..values import frozen_value
from .hole_bounds import FLAT_RIM_RTOL, _round_off, normals_surround_origin
from .hole_fills import PLANE_FILL_LEVELS, CurvedFill, PlaneFill, _sector_grid
from .hole_graphs import _walk

__all__ = ["WrappedRegion", "wrapped_doubt", "wrapped_reading", "wrapped_fill", "WRAP_DECLINED", "in_wrapped",
           "fill_excess", "WRAP_MAX_PLANES", "WRAP_MAX_RIM"]

#: Most distinct ring planes :func:`wrapped_doubt` intersects (a cost limit: each rim corner's piece is a hull of that
#: many half-spaces).  64 until cover19: a cone whose apex is a rim corner has every side facet in its ring
#: (``meshes/cone.stl``, 65–130 planes), and under the user's ``faceted-holes`` those planes close the hole.
WRAP_MAX_PLANES = 256
#: Most rim corners of a hole :func:`wrapped_doubt` bounds (one small polytope per corner).
WRAP_MAX_RIM = 512
#: The viewpoints ``o = a − t d`` tried, ``t`` in units of the rim's ball radius.
_VIEW_STEPS = (1.0, 0.5, 2.0, 0.25, 4.0)


@frozen_value
class WrappedRegion:
    """One hole's region in doubt under ``faceted-holes`` where it reaches round an edge (:func:`wrapped_doubt`).

    Attributes
    ----------
    doubt : float
        ``vol R``, the ring planes' polytope beyond the cone, m³ (an upper bound, rounded up).
    reach : float
        Every point of ``R`` lies within ``reach`` of one rim corner, m (an upper bound).
    planes : int
        The distinct ring planes bounding ``R``.
    frame : tuple of arrays
        What :func:`in_wrapped` reads: the viewpoint ``o`` (3,), the apex (3,), the rim edges' ends ``e0``, ``e1``
        (r, 3), the fan's unit normals (r, 3), the ring planes' unit normals (p, 3) and offsets (p,), and the
        tolerance ``τ`` (1,), m.
    """

    doubt: float
    reach: float
    planes: int
    frame: tuple[np.ndarray, ...] = ()


def in_wrapped(region: WrappedRegion, points: np.ndarray) -> bool:
    """Whether every point lies in ``region``'s ``R`` (within its tolerance): in ``K``, over a fan triangle as seen
    from its viewpoint and not short of that triangle's plane (a fill there keeps the bound, as the cone does)."""
    view, top, e0, e1, fan_unit, unit, offset, tol_array = region.frame
    tol = float(tol_array[0])
    x = np.asarray(points, dtype=np.float64)
    if bool(((x @ unit.T - offset[None, :]).max(axis=1) > tol).any()):
        return False
    basis = np.stack([e1 - view, e0 - view, np.broadcast_to(top - view, e0.shape)], axis=2)
    stu = np.einsum("rij,qj->qri", np.linalg.inv(basis), x - view)                        # (q, r, 3)
    over = (stu >= -1e-9).all(axis=2)
    level = np.einsum("ij,ij->i", fan_unit, np.broadcast_to(top, e0.shape))
    beyond = x @ fan_unit.T - level[None, :] >= -tol
    return bool((over & beyond).any(axis=1).all())


def _ring_planes(v: np.ndarray, f: np.ndarray, on_rim: np.ndarray, outward: float, radius: float,
                 rtol: float) -> tuple[np.ndarray, np.ndarray]:
    """The distinct planes (unit outward normals (p, 3), offsets (p,)) of the faces with a corner on the rim."""
    ring = np.flatnonzero(on_rim[f].any(axis=1))
    a0 = v[f[ring, 0]]
    normal = outward * np.cross(v[f[ring, 1]] - a0, v[f[ring, 2]] - a0)
    length = np.linalg.norm(normal, axis=1)
    keep = length > 0
    unit = normal[keep] / length[keep, None]
    offset = np.einsum("ij,ij->i", unit, a0[keep])
    key = np.round(np.column_stack([unit, offset / max(radius, 1e-300)]) / rtol)
    _, first = np.unique(key, axis=0, return_index=True)
    return unit[np.sort(first)], offset[np.sort(first)]


def _polytope(normals: np.ndarray, bounds: np.ndarray, scale: float) -> tuple[float, np.ndarray] | None:
    """Volume and corners of ``{x : normals x ≤ bounds}``: (0, no corners) where it has no inside, None where it is
    unbounded (the normals do not surround the origin) or reaches past ``1e6 · scale``."""
    from scipy.optimize import linprog
    from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError

    if not normals_surround_origin(normals):
        return None                                   # open along some ray: never given a volume
    norms = np.linalg.norm(normals, axis=1)
    res = linprog(np.r_[0.0, 0.0, 0.0, -1.0], A_ub=np.column_stack([normals, norms]), b_ub=bounds,
                  bounds=[(None, None)] * 3 + [(0.0, None)], method="highs")
    if res.status == 2:
        return 0.0, np.zeros((0, 3))                  # empty
    if res.status != 0:
        return None                                   # unbounded inradius: the polytope is open
    if not res.x[3] > 1e-12 * scale:
        return 0.0, np.zeros((0, 3))                  # flat: no volume
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            region = HalfspaceIntersection(np.column_stack([normals, -bounds]), np.asarray(res.x[:3]))
        corners = region.intersections
        if not np.all(np.isfinite(corners)) or float(np.abs(corners).max()) > 1e6 * scale:
            return None
        return float(ConvexHull(corners).volume), corners
    except (QhullError, ValueError):
        return None


def wrapped_doubt(vertices: np.ndarray, faces: np.ndarray, rim_edges: np.ndarray, radius: float, *,
                  outward: float = 1.0, rtol: float = FLAT_RIM_RTOL, max_planes: int = WRAP_MAX_PLANES,
                  max_rim: int = WRAP_MAX_RIM) -> WrappedRegion | None:
    """The region in doubt of one hole reaching round an edge, under ``faceted-holes`` (module docstring), or
    ``None`` where the reading does not apply or the file contradicts it (:func:`wrapped_reading` says which).
    Parameters as :func:`wrapped_reading`."""
    reading = wrapped_reading(vertices, faces, rim_edges, radius, outward=outward, rtol=rtol, max_planes=max_planes,
                              max_rim=max_rim)
    return reading if isinstance(reading, WrappedRegion) else None


#: Why :func:`wrapped_reading` does not read a hole, one name per check (in the order they are made).
WRAP_DECLINED = {
    "rim": "a pinched rim, several loops, fewer than 3 or more than WRAP_MAX_RIM corners",
    "planes": "no ring plane, or more than WRAP_MAX_PLANES (a tessellated curved surface)",
    "not convex": "a rim corner outside a ring plane: the surroundings are not convex",
    "flat fan": "the cone over the rim has no area, or a fan triangle has none",
    "no viewpoint": "no point inside K from which the fan is a radial graph turning once round the apex",
    "open": "the ring planes do not close the region beyond the cone (K open over some fan triangle)",
    "file inside": "a vertex of the file lies in the region beyond the cone (the file contradicts the reading)",
}


def wrapped_reading(vertices: np.ndarray, faces: np.ndarray, rim_edges: np.ndarray, radius: float, *,
                    outward: float = 1.0, rtol: float = FLAT_RIM_RTOL, max_planes: int = WRAP_MAX_PLANES,
                    max_rim: int = WRAP_MAX_RIM) -> WrappedRegion | str:
    """The region in doubt of one hole reaching round an edge, under ``faceted-holes`` (module docstring), or the
    key in :data:`WRAP_DECLINED` of the first check that declines the reading.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        The surface with the hole, wound as ``outward`` says.
    rim_edges : (r, 2) int
        The hole's boundary edges ``a → b`` (each the edge of one face in that direction).
    radius : float
        The radius of the ball over the rim, m (sets the tolerance ``τ = rtol · radius`` + round-off).
    outward : float
        +1 where the faces are wound outward, −1 where inward.
    rtol, max_planes, max_rim
        :data:`~.hole_bounds.FLAT_RIM_RTOL`, :data:`WRAP_MAX_PLANES`, :data:`WRAP_MAX_RIM`.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e = np.asarray(rim_edges, dtype=np.int64)
    rim = np.unique(e)
    if len(e) < 3 or len(rim) != len(e) or len(rim) > max_rim or _walk(e) is None:
        return "rim"                                  # a pinch, several loops, or too long
    on_rim = np.zeros(len(v), dtype=bool)
    on_rim[rim] = True
    unit, offset = _ring_planes(v, f, on_rim, outward, float(radius), rtol)
    if not len(unit) or len(unit) > max_planes:
        return "planes"
    tol = rtol * float(radius) + _round_off(v)
    if float((v[rim] @ unit.T - offset[None, :]).max()) > tol:
        return "not convex"                           # not convex surroundings: K misses the rim
    e0, e1 = v[e[:, 0]], v[e[:, 1]]
    top = v[rim].mean(axis=0)
    fan = outward * 0.5 * np.cross(e0 - e1, top - e1)              # the fan triangles (e1, e0, apex), outward
    d = fan.sum(axis=0)
    size = float(np.linalg.norm(d))
    fan_size = np.linalg.norm(fan, axis=1)
    if not size > 0 or not bool((fan_size > 0).all()):
        return "flat fan"
    d = d / size
    fan_unit = fan / fan_size[:, None]
    view = _viewpoint(top, d, float(radius), unit, offset, tol, fan_unit, e0, e1)
    if view is None:
        return "no viewpoint"
    scale = max(float(np.abs(v[rim]).max()), float(radius), 1e-300)
    total, far = 0.0, []
    for i in range(len(e)):                           # bounded by max_rim
        # Z_i: K (moved out by tol), beyond T_i's plane (moved in by tol), inside the solid cone from o over T_i
        corners3 = np.stack([e1[i], e0[i], top])
        sides = []
        for j in range(3):                            # the plane through o and each edge of T_i, facing out of C_i
            n = np.cross(corners3[j] - view, corners3[(j + 1) % 3] - view)
            if float(n @ (corners3[(j + 2) % 3] - view)) > 0:
                n = -n
            sides.append(n / max(float(np.linalg.norm(n)), 1e-300))
        normals = np.vstack([unit, -fan_unit[i][None, :], np.array(sides)])
        bounds = np.r_[offset + tol, -(float(fan_unit[i] @ top) - tol), np.array(sides) @ view]
        piece = _polytope(normals, bounds, scale)
        if piece is None:
            return "open"                             # R is open there: the planes do not close it
        total += piece[0]
        if len(piece[1]):
            far.append(piece[1])
    if _file_inside(v, f, on_rim, view, top, e0, e1, fan_unit, unit, offset, tol):
        return "file inside"
    corners = np.vstack([v[rim], *far])
    reach = float(np.min(np.max(np.linalg.norm(corners[None, :, :] - v[rim][:, None, :], axis=2), axis=1)))
    return WrappedRegion(doubt=round_up(total * (1.0 + 1e-9) + 1e-15 * scale ** 3),
                         reach=round_up(reach * (1.0 + 1e-12)), planes=int(len(unit)),
                         frame=(view, top, e0, e1, fan_unit, unit, offset, np.array([tol])))


def _viewpoint(top: np.ndarray, d: np.ndarray, radius: float, unit: np.ndarray, offset: np.ndarray, tol: float,
               fan_unit: np.ndarray, e0: np.ndarray, e1: np.ndarray) -> np.ndarray | None:
    """A point ``o = a + t w`` strictly inside ``K`` (by more than ``tol``) from which every fan triangle faces away
    and whose central projection of the fan turns exactly once round the apex's, or None."""
    from scipy.optimize import linprog

    # the direction ``w`` every fan triangle faces away from most (n_i · w ≤ −s, s largest, |w|∞ ≤ 1): the cone is
    # a radial graph from every point a + t w, t > 0; −d where that already serves
    if bool((fan_unit @ d > 0).all()):
        w = -d
    else:
        res = linprog(np.r_[0.0, 0.0, 0.0, -1.0], A_ub=np.column_stack([fan_unit, np.ones(len(fan_unit))]),
                      b_ub=np.zeros(len(fan_unit)), bounds=[(-1.0, 1.0)] * 3 + [(None, 1.0)], method="highs")
        if res.status != 0 or not res.x[3] > 1e-6:
            return None                               # the fan's normals fill more than a hemisphere
        w = np.asarray(res.x[:3], dtype=np.float64)
        w /= float(np.linalg.norm(w))
    for step in _VIEW_STEPS:                          # a fixed, short list
        o = top + step * radius * w
        if not float((unit @ o - offset).max()) < -tol:
            continue
        if not bool((fan_unit @ top - fan_unit @ o > tol).all()):
            continue
        # the turn of the rim's directions from o round the apex's (each fan triangle's angle at the apex seen
        # from o: the angle between the rim corners' components square to a − o), once round for a tiling
        axis = (top - o) / float(np.linalg.norm(top - o))
        q0, q1 = e0 - o, e1 - o
        p0 = q0 - (q0 @ axis)[:, None] * axis
        p1 = q1 - (q1 @ axis)[:, None] * axis
        turn = float(np.sum(np.arctan2(np.cross(p1, p0) @ axis, np.einsum("ij,ij->i", p0, p1))))
        if abs(abs(turn) - 2.0 * np.pi) < 1e-6:
            return o
    return None


#: Most (vertex, fan triangle) pairs :func:`_file_inside` checks at once.
_INSIDE_CHUNK = 2_000_000


def _file_inside(v: np.ndarray, f: np.ndarray, on_rim: np.ndarray, view: np.ndarray, top: np.ndarray,
                 e0: np.ndarray, e1: np.ndarray, fan_unit: np.ndarray, unit: np.ndarray, offset: np.ndarray,
                 tol: float) -> bool:
    """Whether a vertex of the file's faces, off the rim, lies in ``R`` (within ``tol`` of ``K``) farther than
    ``tol`` beyond the cone: over some fan triangle as seen from ``view`` (its coordinates ``(s, t, u)`` in the
    frame ``o + s (e1 − o) + t (e0 − o) + u (a − o)`` all ≥ 0) and beyond that triangle's plane."""
    used = np.zeros(len(v), dtype=bool)
    used[f.reshape(-1)] = True
    cand = np.flatnonzero(used & ~on_rim)
    if not len(cand):
        return False
    cand = cand[(v[cand] @ unit.T - offset[None, :]).max(axis=1) <= tol]
    if not len(cand):
        return False
    basis = np.stack([e1 - view, e0 - view, np.broadcast_to(top - view, e0.shape)], axis=2)   # (r, 3, 3) columns
    inverse = np.linalg.inv(basis)
    level = np.einsum("ij,ij->i", fan_unit, np.broadcast_to(top, e0.shape))
    step = max(1, _INSIDE_CHUNK // max(len(e0), 1))
    for lo in range(0, len(cand), step):
        x = v[cand[lo:lo + step]]
        stu = np.einsum("rij,qj->qri", inverse, x - view)                                   # (q, r, 3)
        over = (stu >= -1e-12).all(axis=2)
        beyond = x @ fan_unit.T - level[None, :] > tol                                       # (q, r)
        if bool((over & beyond).any()):
            return True
    return False


def wrapped_fill(vertices: np.ndarray, region: WrappedRegion, rim_edges: np.ndarray, loop: int, *,
                 levels: int = PLANE_FILL_LEVELS) -> PlaneFill | None:
    """A hole read round an edge (:func:`wrapped_doubt`) filled on ``R``'s far side: the cone's fan, split into
    ``levels`` rows (:func:`~.hole_fills._sector_grid`), pushed point by point along the ray from the reading's
    viewpoint ``o`` out to ``∂K``, or None where a ray does not leave ``K`` (R open: not expected of a region read).

    The planes round the rim continued until they meet (the assumption's reading of the lost surface) are ``∂K``
    over the hole, so this is the fill of :func:`~.hole_fills.plane_fills` with one plane chosen per point along
    its ray from ``o`` instead of along one direction ``d``: it goes on across an edge the hole reaches round (a
    cylinder's cap and side, a cone's base and side).  A point ``p`` of fan triangle ``T_i`` lies in ``K`` (the
    cone does), so its ray leaves ``K`` at ``o + s (p − o)``, ``s = min_j (c_j − n_j·o) / (n_j·(p − o))`` over the
    planes it moves towards, ``s ≥ 1``: beyond ``T_i``'s plane (``T_i`` faces away from ``o``), inside ``K``'s
    closure and over ``T_i`` as seen from ``o``, so in ``R``.  The fill and the missing surface both lie in ``R``;
    the bound (``vol R``) is unchanged.  The rim stays (the rim corners lie on ``∂K`` within the tolerance).  The
    fill is a radial graph over the directions of the fan, so it does not cross itself.

    Parameters
    ----------
    vertices : (n, 3) float
    region : WrappedRegion
        The hole's region (its ``frame``).
    rim_edges : (r, 2) int
        The hole's boundary edges, as given to :func:`wrapped_doubt`.
    loop : int
        The hole's loop (its apex is numbered ``n + loop`` in the fill's ``caps``).
    levels : int
        Rows of each fan triangle (:data:`~.hole_fills.PLANE_FILL_LEVELS`).
    """
    v = np.asarray(vertices, dtype=np.float64)
    e = np.asarray(rim_edges, dtype=np.int64)
    view, top, _, _, _, unit, offset, _ = region.frame
    rim = np.unique(e)
    slot = np.searchsorted(rim, e)
    caps, weights = _sector_grid(e, slot, levels)
    sa, sb = weights[:, 2:3], weights[:, 3:4]
    flat = np.vstack([top[None, :], top + sa * (v[rim[weights[:, 0].astype(np.int64)]] - top)
                      + sb * (v[rim[weights[:, 1].astype(np.int64)]] - top)])
    ray = flat - view                                                     # (p + 1, 3)
    towards = ray @ unit.T                                                # (p + 1, planes)
    room = offset[None, :] - (unit @ view)[None, :]                      # > 0: o strictly inside K
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = np.where(towards > 0, room / towards, np.inf)
    scale = reach.min(axis=1)
    if not bool(np.isfinite(scale).all()):
        return None
    scale = np.maximum(scale, 1.0)                                        # never short of the cone (round-off)
    moved = view + scale[:, None] * ray
    n = len(v)
    caps = caps.copy()
    caps[caps == -1] = n + loop
    inner = caps < -1
    caps[inner] = -1 - (-2 - caps[inner])                                 # inner point i as −1 − i
    lift = (scale - 1.0) * np.linalg.norm(ray, axis=1)
    return PlaneFill(loop=int(loop), apex=moved[0], points=moved[1:], caps=caps, lift=lift,
                     planes=int(len(unit)), convex=True)


def fill_excess(vertices: np.ndarray, fill: PlaneFill | CurvedFill, apex: np.ndarray) -> tuple[float, float]:
    """What a fill (a plane fill outside a hole's wrapped region, a quadric fill kept under ``faceted-holes``) adds to
    its doubt: ``(Σ_T |det(T − a)| / 6`` over the fill's
    triangles ``T`` (m³, rounded up), the farthest the fill's points lie from their nearest rim corner (m)).

    The patched and the true solid differ by the winding number of "fill − M" = ("fill − cone") + ("cone − M"); the
    second is bounded by the region (:func:`wrapped_doubt`), the first by the sum of the unsigned volumes of the
    tetrahedra from the cone's apex ``a`` over the cycle's triangles (the cone's own triangles hold ``a``: zero).
    """
    v = np.asarray(vertices, dtype=np.float64)
    n = len(v)
    caps = np.asarray(fill.caps, dtype=np.int64)
    corners = np.where((caps < 0)[..., None], fill.points[np.maximum(-1 - caps, 0)],
                       np.where((caps >= n)[..., None], fill.apex, v[np.clip(caps, 0, n - 1)]))     # (q, 3, 3)
    rel = corners - np.asarray(apex, dtype=np.float64)
    volume = float(np.sum(np.abs(np.einsum("ij,ij->i", rel[:, 0], np.cross(rel[:, 1], rel[:, 2]))))) / 6.0
    rim = np.unique(caps[(caps >= 0) & (caps < n)])
    points = np.vstack([fill.apex[None, :], fill.points])
    reach = float(np.max(np.min(np.linalg.norm(points[:, None, :] - v[rim][None, :, :], axis=2), axis=1))) \
        if len(rim) else float("inf")
    return round_up(volume * (1.0 + 1e-9)), round_up(reach * (1.0 + 1e-12))
