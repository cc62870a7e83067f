"""Bounding a hole under the user's ``faceted-holes`` assumption: between the cone and the continued planes.

On a faceted part (a CAD box, an octahedron, a cone's facets, a cylinder's flat cap meeting its side) the surface
a hole took lies, most often, on the planes of the faces still there round it, continued across the hole until
they meet (a box's lost corner), or on the flat lid the rim spans (an octahedron's lost face).  Neither reading is
in the file: a boss or pocket taken whole leaves the same rim.  So this reading is never taken by default; the user
states it (:data:`~.hole_assumptions.FACETED_HOLES`, ``--assume faceted-holes``) and the estimate names it.

**Assumption.**  The faces with a corner on the rim (the *ring*) give planes ``n_j · x = c_j`` (``n_j`` outward,
unit).  Where every rim vertex lies inside every one of them (*convex* surroundings) the part near the hole is
taken to lie inside them too; where every rim vertex lies outside or on every plane facing the hole's outward
direction ``d`` (*concave*: a pocket's corner) the part is taken to hold their union there.  Either way the
missing surface ``M`` lies in the region ``S`` swept from the cone over the rim (the fill of :mod:`~.holes`, its
apex the rim's centroid) along ``d`` up to the planes' envelope: ``S = {p + t d : p on the cone, t between 0 and
λ(p)}``, ``λ(p) = min_j (c_j − n_j·p)/(n_j·d)`` (convex; ``max_j`` concave) over the planes facing ``d`` (``n_j·d
> cos 80°``; the others are walls, and leaving them out only widens ``S``).  Both readings above lie in ``S``: the
planes met (``M`` is the envelope, ``S``'s far side) and a lost flat lid (``M`` is the cone, its near side).
Part of the assumption, as of every graph reading here: ``M`` is a graph over the plane ``⟂ d`` (it does not fold
back over the hole: a hole across a cone's base and side whose lost base facet faces away from ``d`` is not one),
and every face round the rim faces ``d`` (checked: the file's own evidence that its surroundings do not fold).

**The bound follows from it.**  The cone is checked to be a graph over the plane ``⟂ d`` (every fan triangle
facing ``d``, and their angles at the projected apex summing to one turn), so ``S`` lies between two graphs over
the projected rim, and every point outside ``S`` is joined to infinity outside it (along ``±d`` or sideways).  The
fill (the cone, or the plane fill on the envelope, :func:`~.hole_fills.plane_fills`) and ``M`` both lie in ``S``,
so the winding number of the cycle "fill − M" vanishes outside ``S``, and the patched and the true solid differ by
at most ``|S| = ∫_cone |λ| (d·n̂) dA``.  ``|λ|`` is the smallest of affine functions on each fan triangle (concave),
so over each of the ``levels²`` sub-triangles ``T`` of a fan triangle it is at most ``|λ|`` at ``T``'s centroid
times its area (Jensen's inequality) where ``λ`` keeps its sign on ``T``, and at most the largest of its corner
values of the smallest affine function otherwise; the bound is the sum, rounded up, plus round-off.  The region
reaches no farther than ``max |λ|`` from the cone (``reach``).

**The file's evidence against it** (the reading withdrawn, the hole keeps its other bound): a vertex of the file,
other than the rim's, inside ``S`` (the surface the file has passes where the assumption puts only the lost one);
surroundings neither convex nor concave; a face round the rim facing away from ``d``; a pinched rim; a cone that
folds over ``d``.
"""

from __future__ import annotations

import numpy as np

from ..rounding import round_up
from ..values import frozen_value
from .hole_bounds import BEND_MAX_DEGREES, FLAT_RIM_RTOL, _round_off

__all__ = ["FacetedRegion", "faceted_doubt", "FACETED_LEVELS", "FACETED_MAX_RIM", "FACETED_WORK", "FACETED_MAX_LOOPS"]

#: Most holes of one surface bounded under ``faceted-holes`` (those with the most doubt first; each costs a pass
#: over the surface's faces and vertices).
FACETED_MAX_LOOPS = 64

#: Sub-triangle rows of each fan triangle for :func:`faceted_doubt` (the bound tightens as ``1 / levels`` where
#: the envelope creases across a fan triangle; exact where it does not).
FACETED_LEVELS = 12
#: Most rim corners of a hole :func:`faceted_doubt` bounds (longer rims keep their other bound).
FACETED_MAX_RIM = 4096
#: Most (sub-triangle corner, plane) values evaluated per hole (40 MB): ``levels`` is lowered to stay within it.
FACETED_WORK = 5_000_000


@frozen_value
class FacetedRegion:
    """One hole's region in doubt under ``faceted-holes`` (:func:`faceted_doubt`).

    Attributes
    ----------
    doubt : float
        ``|S|``, the volume between the cone and the planes' envelope, m³ (an upper bound, rounded up).
    reach : float
        ``max |λ|``: how far ``S`` reaches from the cone along ``d``, m (an upper bound).
    convex : bool
        True for convex surroundings (the envelope outside the cone), False for concave.
    planes : int
        The planes facing ``d`` that bound ``S``.
    """

    doubt: float
    reach: float
    convex: bool
    planes: int


def _grid(levels: int) -> tuple[np.ndarray, np.ndarray]:
    """Barycentric weights ``(s, t)`` of the points ``apex + s (e0 − apex) + t (e1 − apex)``, ``s + t ≤ 1``, on
    a grid of ``levels`` rows, (q, 2), and the ``levels²`` sub-triangles as triples of point indices, (levels², 3)."""
    index: dict[tuple[int, int], int] = {}
    weights: list[tuple[float, float]] = []
    for i in range(levels + 1):
        for j in range(levels + 1 - i):
            index[(i, j)] = len(weights)
            weights.append((i / levels, j / levels))
    tris = []
    for i in range(levels):
        for j in range(levels - i):
            tris.append((index[(i, j)], index[(i + 1, j)], index[(i, j + 1)]))
            if i + j <= levels - 2:
                tris.append((index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]))
    return np.array(weights, dtype=np.float64), np.array(tris, dtype=np.int64)


def faceted_doubt(vertices: np.ndarray, faces: np.ndarray, rim_edges: np.ndarray, apex: np.ndarray,
                  radius: float, *, outward: float = 1.0, rtol: float = FLAT_RIM_RTOL,
                  levels: int = FACETED_LEVELS, max_rim: int = FACETED_MAX_RIM, work: int = FACETED_WORK,
                  wall_cosine: float = float(np.cos(np.radians(BEND_MAX_DEGREES)))) -> FacetedRegion | None:
    """The region in doubt of one hole under ``faceted-holes`` (module docstring), or ``None`` where the
    assumption cannot be read there or the file contradicts it.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        The surface with the hole, wound as ``outward`` says.
    rim_edges : (r, 2) int
        The hole's boundary edges ``a → b`` (each the edge of one face in that direction).
    apex : (3,) float
        The cone's apex (the rim's centroid), m.
    radius : float
        The radius of the ball over the rim, m (sets the tolerance ``rtol · radius`` of "on a plane").
    outward : float
        +1 where the faces are wound outward, −1 where inward.
    rtol, levels, max_rim, work, wall_cosine
        :data:`~.hole_bounds.FLAT_RIM_RTOL`, :data:`FACETED_LEVELS`, :data:`FACETED_MAX_RIM`,
        :data:`FACETED_WORK`, the cosine of :data:`~.hole_bounds.BEND_MAX_DEGREES`.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e = np.asarray(rim_edges, dtype=np.int64)
    top = np.asarray(apex, dtype=np.float64)
    rim = np.unique(e)
    if len(e) < 3 or len(rim) != len(e) or len(rim) > max_rim:
        return None                                   # a pinch, or too long
    on_rim = np.zeros(len(v), dtype=bool)
    on_rim[rim] = True
    ring = np.flatnonzero(on_rim[f].any(axis=1))
    a0 = v[f[ring, 0]]
    normal = outward * np.cross(v[f[ring, 1]] - a0, v[f[ring, 2]] - a0)
    length = np.linalg.norm(normal, axis=1)
    keep = length > 0
    if not keep.any():
        return None
    unit = normal[keep] / length[keep, None]
    offset = np.einsum("ij,ij->i", unit, a0[keep])
    margin = _round_off(v)
    tol = rtol * float(radius) + margin
    # distinct planes (to the tolerance): a tessellation's repeated planes count once
    key = np.round(np.column_stack([unit, offset / max(float(radius), 1e-300)]) / rtol)
    _, first = np.unique(key, axis=0, return_index=True)
    unit, offset = unit[np.sort(first)], offset[np.sort(first)]
    e0, e1 = v[e[:, 0]], v[e[:, 1]]
    area = outward * 0.5 * np.cross(e0 - e1, top - e1)            # the cone's fan triangles (e1, e0, apex)
    d = area.sum(axis=0)
    size = float(np.linalg.norm(d))
    if not size > 0:
        return None
    d = d / size
    if not bool((area @ d > 0).all()):
        return None                                   # the cone folds over d: S is no region between two graphs
    b1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(d, b1)
    p0 = np.column_stack([(e0 - top) @ b1, (e0 - top) @ b2])
    p1 = np.column_stack([(e1 - top) @ b1, (e1 - top) @ b2])
    turn = float(np.sum(np.abs(np.arctan2(p0[:, 0] * p1[:, 1] - p0[:, 1] * p1[:, 0],
                                          np.einsum("ij,ij->i", p0, p1)))))
    if abs(turn - 2.0 * np.pi) > 1e-6:
        return None                                   # the projected fan covers its polygon more than once
    # the faces across the rim's edges face d (else the surroundings fold over d there: M need not be a graph)
    rim_key = set(zip(np.minimum(e[:, 0], e[:, 1]).tolist(), np.maximum(e[:, 0], e[:, 1]).tolist()))
    tri = f[ring]
    pairs = np.sort(np.stack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]], axis=1), axis=2)   # (k, 3, 2)
    across = np.array([any((int(x), int(y)) in rim_key for x, y in row) for row in pairs.tolist()], dtype=bool)
    if not bool((normal[across & keep] @ d > 0).all()):
        return None
    facing = unit @ d
    carries = facing > wall_cosine
    if not carries.any():
        return None
    excess = v[rim] @ unit.T - offset[None, :]
    inner, outer = excess.max(axis=0) <= tol, excess.min(axis=0) >= -tol
    if bool(inner.all()):
        convex = True
    elif bool(outer[carries].all()) and bool((inner | outer).all()):
        convex = False
    else:
        return None                                   # mixed surroundings: neither the intersection nor the union
    nc, cc, fc = unit[carries], offset[carries], facing[carries]
    sign = 1.0 if convex else -1.0
    weights, tris = _grid(levels)
    while levels > 1 and 3 * len(e) * len(tris) * len(nc) > work:
        levels = max(1, levels // 2)
        weights, tris = _grid(levels)
    if 3 * len(e) * len(tris) * len(nc) > work:
        return None
    # the grid points of every fan triangle: apex + s (e0 − apex) + t (e1 − apex), (r, q, 3)
    pts = top + weights[None, :, 0:1] * (e0 - top)[:, None, :] + weights[None, :, 1:2] * (e1 - top)[:, None, :]
    # sign · λ_j at each point: (r, q, planes); g = min_j is |λ| where λ keeps the side the surroundings take
    g_j = sign * (cc[None, None, :] - pts @ nc.T) / fc[None, None, :]
    corner = g_j[:, tris, :]                                       # (r, levels², 3, planes)
    upper = corner.max(axis=2).min(axis=2)                         # ≥ max of g over the sub-triangle
    g = g_j.min(axis=2)
    lower = g[:, tris].min(axis=2)                                 # = min of g (concave) over the sub-triangle
    centroid = corner.mean(axis=2).min(axis=2)                     # g at the sub-triangle's centroid
    per = np.where(lower >= 0, centroid, np.maximum(np.maximum(upper, 0.0), -lower))
    sub_area = (area @ d)[:, None] / levels ** 2                   # every sub-triangle has 1 / levels² of its fan's
    doubt = float(np.sum(sub_area * per))
    reach = float(np.max(np.maximum(np.maximum(upper, 0.0), -lower)))
    if not (np.isfinite(doubt) and np.isfinite(reach)):
        return None
    total_area = float(np.sum(area @ d))
    doubt += total_area * 4.0 * margin / float(np.min(fc))         # round-off of the planes and the points
    reach += 4.0 * margin / float(np.min(fc))
    if _file_inside(v, f, on_rim, top, e0, e1, d, nc, cc, fc, sign, reach, tol):
        return None
    return FacetedRegion(doubt=round_up(doubt), reach=round_up(reach), convex=convex, planes=int(len(nc)))


#: Most (vertex, fan triangle) pairs :func:`_file_inside` checks at once.
_INSIDE_CHUNK = 2_000_000


def _file_inside(v: np.ndarray, f: np.ndarray, on_rim: np.ndarray, top: np.ndarray, e0: np.ndarray,
                 e1: np.ndarray, d: np.ndarray, nc: np.ndarray, cc: np.ndarray, fc: np.ndarray, sign: float,
                 reach: float, tol: float) -> bool:
    """Whether a vertex of the file's faces, off the rim, lies inside ``S`` by more than ``tol`` (the evidence
    against ``faceted-holes``): its coordinates ``(s, t, h)`` in each fan triangle's frame ``apex + s (e0 − apex) +
    t (e1 − apex) + h d`` put it over the fan triangle (``s, t ≥ 0``, ``s + t ≤ 1``) and between the cone
    (``h = 0``) and the envelope (``h = sign · g(p)``)."""
    used = np.zeros(len(v), dtype=bool)
    used[f.reshape(-1)] = True
    far = float(np.max(np.linalg.norm(np.vstack([e0, e1]) - top, axis=1))) + reach
    near = np.flatnonzero(used & ~on_rim & (np.linalg.norm(v - top, axis=1) <= far + tol))
    if not len(near):
        return False
    basis = np.stack([e0 - top, e1 - top, np.broadcast_to(d, e0.shape)], axis=2)     # (r, 3, 3) columns
    det = np.linalg.det(basis)
    ok = np.abs(det) > 0
    if not ok.all():
        basis, e0, e1 = basis[ok], e0[ok], e1[ok]
    inverse = np.linalg.inv(basis)
    step = max(1, _INSIDE_CHUNK // max(len(e0), 1))
    for lo in range(0, len(near), step):
        rel = v[near[lo:lo + step]] - top                                            # (q, 3)
        stw = np.einsum("rij,qj->qri", inverse, rel)                                 # (q, r, 3)
        s, t, h = stw[..., 0], stw[..., 1], stw[..., 2]
        over = (s >= 0) & (t >= 0) & (s + t <= 1)
        q_idx, r_idx = np.nonzero(over & (sign * h > tol))
        if not len(q_idx):
            continue
        p = top + s[q_idx, r_idx, None] * (e0[r_idx] - top) + t[q_idx, r_idx, None] * (e1[r_idx] - top)
        g = (sign * (cc[None, :] - p @ nc.T) / fc[None, :]).min(axis=1)
        if bool((sign * h[q_idx, r_idx] < g - tol).any()):
            return True
    return False
