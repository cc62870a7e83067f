"""Mass properties of an extruded polygonal region (SDFormat ``<polyline>``) in closed form.

A region of the plane is given by one or more simple polygons that neither cross nor touch one another; a point
belongs to the region when an odd number of the polygons enclose it (even-odd rule, as Gazebo's extrusion of
several ``<polyline>`` elements: a polygon inside another is a hole, one inside a hole is an island again).  The
solid is the region swept from ``z = 0`` to ``z = h``.

Area moments by Green's theorem
-------------------------------
For a simple polygon wound counter-clockwise with vertices ``(x_i, y_i)`` and ``c_i = x_i y_{i+1} − x_{i+1} y_i``
(Green's theorem, ``∫ f dA = ∮ F dy`` with ``∂F/∂x = f``, integrated exactly along each straight edge; the plane
counterpart of the signed tetrahedra of a closed surface):

* ``A = ½ Σ c_i``,
* ``∫x dA = ⅙ Σ (x_i + x_{i+1}) c_i`` (and ``y`` alike),
* ``∫x² dA = (1/12) Σ (x_i² + x_i x_{i+1} + x_{i+1}²) c_i`` (and ``y`` alike),
* ``∫xy dA = (1/24) Σ (2 x_i y_i + x_i y_{i+1} + x_{i+1} y_i + 2 x_{i+1} y_{i+1}) c_i``.

Each polygon enters the region's moments with the sign ``(−1)^d``, ``d`` the number of the other polygons that
enclose it (its nesting depth).  The prism then has ``V = A h``, ``∫x dV = h ∫x dA``, ``∫z dV = A h²/2``,
``∫x² dV = h ∫x² dA``, ``∫xy dV = h ∫xy dA``, ``∫xz dV = (h²/2) ∫x dA``, ``∫z² dV = A h³/3``; the inertia
about the origin is ``ρ (tr C 𝟙 − C)`` (Chapter 4, "Rigid Body Motion", Eq. 4.11/4.13) and the parallel-axis
theorem (Eq. 4.16) moves it to the centre of mass.  The sums are taken about the polygons' bounding-box centre
so that a region far from its frame's origin keeps its precision.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidMeshError
from ..integrals import second_moment_to_inertia
from ..mesh.intersect import orient2d_sign
from .properties import MassProperties

__all__ = ["extruded_region", "polygon_region", "point_in_polygon", "MAX_POLYGON_POINTS"]

#: Most points all the polygons of one region may hold together: the crossing check compares every pair of
#: edges (about ``n²/2`` pairs, vectorised one edge at a time).
MAX_POLYGON_POINTS = 4096


def _cleaned(points: np.ndarray) -> np.ndarray:
    """The polygon without repeated consecutive points and without a closing copy of the first point."""
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(points[1:] != points[:-1], axis=1)
    points = points[keep]
    if len(points) > 1 and np.all(points[0] == points[-1]):
        points = points[:-1]
    return points


def _signed_area(points: np.ndarray) -> float:
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Exact sign of the turn a → b → c (+1 left, −1 right, 0 collinear), broadcast over the rows.

    Exact (filtered, with an exact fallback): a float determinant can call two edges that touch at a point
    disjoint, or two that miss each other touching, when the turn is within rounding of zero.
    """
    a, b, c = np.broadcast_arrays(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64),
                                  np.asarray(c, dtype=np.float64))
    shape = a.shape[:-1]
    sign = orient2d_sign(a.reshape(-1, 2), b.reshape(-1, 2), c.reshape(-1, 2))
    return np.asarray(sign, dtype=np.int64).reshape(shape)


def _on_segment(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether the collinear point ``p`` lies within the box of segment ``a b`` (rows broadcast)."""
    low, high = np.minimum(a, b), np.maximum(a, b)
    return np.asarray(np.all((low <= p) & (p <= high), axis=-1))


def _first_crossing(polygons: list[np.ndarray]) -> tuple[int, int, int, int] | None:
    """The first pair of edges that cross or touch (polygon, edge, polygon, edge), or None.

    Edges next to each other in one polygon share an end point; they count only when they fold back onto
    each other (collinear and overlapping beyond the shared point).
    """
    starts = np.concatenate(polygons)
    ends = np.concatenate([np.roll(p, -1, axis=0) for p in polygons])
    owner = np.concatenate([np.full(len(p), k) for k, p in enumerate(polygons)])
    index = np.concatenate([np.arange(len(p)) for p in polygons])
    sizes = np.array([len(p) for p in polygons])
    for i in range(len(starts) - 1):
        a, b = starts[i], ends[i]
        c, d = starts[i + 1:], ends[i + 1:]
        o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
        hit = (o1 * o2 < 0) & (o3 * o4 < 0)
        hit |= (o1 == 0) & _on_segment(a, b, c)
        hit |= (o2 == 0) & _on_segment(a, b, d)
        hit |= (o3 == 0) & _on_segment(c, d, a)
        hit |= (o4 == 0) & _on_segment(c, d, b)
        same = owner[i + 1:] == owner[i]
        n = sizes[owner[i]]
        after = same & (index[i + 1:] == (index[i] + 1) % n)       # shares b = c
        before = same & (index[i + 1:] == (index[i] - 1) % n)      # shares a = d
        direction = b - a
        fold_after = (o2 == 0) & (np.einsum("j,ij->i", direction, d - c) < 0)
        fold_before = (o1 == 0) & (np.einsum("j,ij->i", direction, d - c) < 0)
        hit = np.where(after, fold_after, np.where(before, fold_before, hit))
        if np.any(hit):
            j = i + 1 + int(np.argmax(hit))
            return int(owner[i]), int(index[i]), int(owner[j]), int(index[j])
    return None


def point_in_polygon(point: ArrayLike, polygon: ArrayLike) -> bool:
    """Even-odd test of ``point`` (2,) against ``polygon`` (n, 2), exact (a point on the boundary may go either
    way).

    A ray from the point towards +x crosses edge ``a b`` when the edge straddles the point's height (half-open,
    so a vertex at that height counts once) and the point lies on the edge's left if it runs upwards, on its
    right if it runs downwards: both decided by the exact turn of ``a → b → point``, so a point within rounding
    of an edge is still placed on its true side.
    """
    p = np.asarray(point, dtype=np.float64).reshape(1, 2)
    a = np.asarray(polygon, dtype=np.float64)
    b = np.roll(a, -1, axis=0)
    y = p[0, 1]
    up = (a[:, 1] <= y) & (y < b[:, 1])
    down = (b[:, 1] <= y) & (y < a[:, 1])
    straddle = np.flatnonzero(up | down)
    if not len(straddle):
        return False
    turn = _orient(a[straddle], b[straddle], np.broadcast_to(p, (len(straddle), 2)))
    right = np.where(up[straddle], turn > 0, turn < 0)
    return bool(np.count_nonzero(right) % 2)


def polygon_region(polygons: Iterable[ArrayLike], *,
                   flat_rtol: float = 1e-12) -> tuple[tuple[np.ndarray, ...], tuple[int, ...]]:
    """Check the polygons of a region and give each its counter-clockwise winding and even-odd sign.

    Parameters
    ----------
    polygons : sequence of (n_k, 2) float
        The polygons' vertices in m, in order, either winding; a closing copy of the first point and repeated
        consecutive points are dropped.
    flat_rtol : float
        A polygon whose points lie within ``flat_rtol · L`` of one line (the smallest singular value of its
        centred points; ``L`` its bounding-box diagonal) has no area and is refused.

    Returns
    -------
    polygons : tuple of (n_k, 2) float
        Counter-clockwise, cleaned.
    signs : tuple of int
        ``+1`` for a polygon at even nesting depth (material), ``−1`` at odd depth (a hole).

    Raises
    ------
    InvalidMeshError
        No polygon, more than :data:`MAX_POLYGON_POINTS` points, a non-finite coordinate, a polygon with
        fewer than 3 distinct points or all on one line, or edges that cross or touch (within one polygon or
        between two).
    """
    cleaned = []
    total = 0
    for k, raw in enumerate(polygons):
        points = np.asarray(raw, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 2:
            raise InvalidMeshError(f"polygon {k + 1}: expected (n, 2) points, got shape {points.shape}")
        total += len(points)
        if total > MAX_POLYGON_POINTS:
            raise InvalidMeshError(f"expected at most {MAX_POLYGON_POINTS} polygon points in all, found more "
                                   f"(polygon {k + 1} reaches {total})")
        if not np.all(np.isfinite(points)):
            raise InvalidMeshError(f"polygon {k + 1}: expected finite coordinates, found a non-finite one")
        points = _cleaned(points)
        if len(points) < 3:
            raise InvalidMeshError(f"polygon {k + 1}: expected at least 3 distinct points, found {len(points)}")
        diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
        thickness = float(np.linalg.svd(points - points.mean(axis=0), compute_uv=False)[-1])
        if thickness <= flat_rtol * diagonal:
            raise InvalidMeshError(f"polygon {k + 1}: expected a positive area, found its {len(points)} points "
                                   "on one line")
        cleaned.append(points)
    if not cleaned:
        raise InvalidMeshError("expected at least one polygon, found none")
    crossing = _first_crossing(cleaned)
    if crossing is not None:
        p, e, q, f = crossing
        where = (f"polygon {p + 1} crosses itself (edges {e + 1} and {f + 1})" if p == q
                 else f"polygons {p + 1} and {q + 1} cross or touch (edges {e + 1} and {f + 1})")
        raise InvalidMeshError(f"expected simple polygons that do not meet, but {where}")
    # simple and not flat, so the signed area is not zero: its sign is the winding
    cleaned = [p if _signed_area(p) > 0 else p[::-1].copy() for p in cleaned]
    signs = []
    for k, polygon in enumerate(cleaned):
        depth = sum(point_in_polygon(polygon[0], other) for j, other in enumerate(cleaned) if j != k)
        signs.append(-1 if depth % 2 else 1)
    return tuple(cleaned), tuple(signs)


def _area_moments(points: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Area, first moment (2,) and second moment (2, 2) of a counter-clockwise polygon (Green's theorem)."""
    x0, y0 = points[:, 0], points[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    c = x0 * y1 - x1 * y0
    area = float(np.sum(c)) / 2.0
    first = np.array([np.sum((x0 + x1) * c), np.sum((y0 + y1) * c)]) / 6.0
    sxx = float(np.sum((x0 * x0 + x0 * x1 + x1 * x1) * c)) / 12.0
    syy = float(np.sum((y0 * y0 + y0 * y1 + y1 * y1) * c)) / 12.0
    sxy = float(np.sum((2 * x0 * y0 + x0 * y1 + x1 * y0 + 2 * x1 * y1) * c)) / 24.0
    return area, first, np.array([[sxx, sxy], [sxy, syy]])


def extruded_region(polygons: Iterable[ArrayLike], height: float) -> MassProperties:
    """Unit-density mass properties of a polygonal region extruded from ``z = 0`` to ``z = height``.

    Parameters
    ----------
    polygons : sequence of (n_k, 2) float
        The region's polygons in m (checked and signed by :func:`polygon_region`: even-odd nesting).
    height : float
        m, positive.

    Returns
    -------
    MassProperties
        ``mass == volume`` (m³); centre of mass in m and inertia about it (kg·m² per kg/m³), in the polygons'
        frame; tensor convention (off-diagonals ``−∫xy dm``).

    Raises
    ------
    InvalidMeshError
        From :func:`polygon_region`, or a height that is not finite and positive.
    """
    h = float(height)
    if not (np.isfinite(h) and h > 0):
        raise InvalidMeshError(f"expected a finite positive extrusion height, got {height!r}")
    cleaned, signs = polygon_region(polygons)
    everything = np.concatenate(cleaned)
    origin = 0.5 * (everything.min(axis=0) + everything.max(axis=0))
    area, first, second = 0.0, np.zeros(2), np.zeros((2, 2))
    for polygon, sign in zip(cleaned, signs):
        a, f, s = _area_moments(polygon - origin)
        area += sign * a
        first += sign * f
        second += sign * s
    if not area > 0:
        raise InvalidMeshError(f"expected a region of positive area, found {area:.3g} m²")
    volume = area * h
    # second moment C_ij = ∫ x_i x_j dV about (origin, z = 0), then about the centroid.
    moment = np.zeros((3, 3))
    moment[:2, :2] = h * second
    moment[:2, 2] = moment[2, :2] = 0.5 * h * h * first
    moment[2, 2] = area * h ** 3 / 3.0
    centroid = np.array([first[0] * h, first[1] * h, 0.5 * area * h * h]) / volume
    central = moment - volume * np.outer(centroid, centroid)
    surface = 2.0 * abs(area) + h * sum(float(np.sum(np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)))
                                        for p in cleaned)
    return MassProperties(mass=volume, volume=volume,
                          center_of_mass=centroid + np.array([origin[0], origin[1], 0.0]),
                          inertia=second_moment_to_inertia(central), density=1.0, surface_area=surface)
