"""Filling a hole as a graph over the plane most face-on to the faces round it (issue 21 item 3, fill13).

The bend bound of :func:`~.hole_bounds.bend_doubt_volumes` reads a hole as a graph over its rim's *mean* plane and
fills it by the cone to the rim's centroid; a large hole that wraps round the curvature or a crease is not a graph
over that plane (its projected fan is not star-shaped, or a face at the rim stands steeper than 80° to it), and
kept the ball, far too wide to answer.  Here the plane is chosen from the faces instead: the direction ``d``
most face-on to every face touching the rim (the one that maximises the least cosine ``n·d`` over their unit
normals ``n``, a small linear programme), and the fill is a triangulation of the region ``Ω`` the rim bounds in
the plane ``Π ⟂ d``, lifted to a height over it (:func:`graph_fills`).

**Assumption** (:data:`~.hole_assumptions.GRAPH`): the missing surface ``M`` of the hole is the graph of a height
``g`` over ``Ω`` along ``d`` and slopes against ``Π`` no more steeply than the steepest face touching the rim,
``|∇g| ≤ L = tan θ``, ``θ`` the largest angle between such a face's normal and ``d``.  It is the bend assumption
(``bend``) with the plane taken from the faces rather than from the rim, so that a hole over a crease or round a
cylinder's edge, whose faces all face one side, is a graph.  It fails for a feature taken whole whose walls are
steeper than the faces round its rim (a boss, a pocket) and for a surface folding back over the hole (the faces
round it face more than a half-space: then no ``d`` has every cosine above ``cos 80°`` and nothing is filled).

**The fill.** The rim, projected onto ``Π``, must be a simple polygon (no two edges meet but neighbours at their
shared corner), running clockwise about ``d`` (the faces at the rim lie outside ``Ω``, as the graph's orientation
asks). Points of a square grid inside ``Ω`` (at least half a grid step and half the longest rim edge from the rim)
and the rim's corners are triangulated by Delaunay's rule and the triangles inside ``Ω`` kept; the triangulation is
*checked* to tile ``Ω`` exactly once with the rim edges on its border (each rim edge in one triangle, every other
edge in two, areas summing to the polygon's). Where the Delaunay cut loses a rim edge (a rim that is not convex),
the polygon is ear-clipped instead and split twice (each triangle fanned from its centroid to its corners and to the
middles of its edges off the rim), checked the same way; else the loop keeps its other fill. Each inner point ``q``
is lifted to the height of the quadric the two rings round the rim lie on where one fits
(:func:`~.hole_fills._fitted_quadric`, the root along ``d`` nearest the rim's height at the nearest rim point
``r``), else to the least-squares quadratic height over ``Π`` of those points, and clamped into ``[h(r) − L|q − r|,
h(r) + L|q − r|]``, where the assumption puts ``g(q)`` (``h(r)`` the rim's height at ``r``; the segment ``qr`` lies
in ``Ω``'s closure, ``r`` being the nearest point of its border).

**The bound** (follows from the assumption; no factor is tuned).  ``M`` and the fill ``F`` are graphs over ``Ω``
with the rim as common boundary, so the patched and the true solid differ by ``∫_Ω |g − F| dA``.  On a fill
triangle ``T`` with corners ``q_i`` at heights ``z_i`` (``F`` linear, ``F(p) = Σ λ_i z_i``):
``|g(p) − F(p)| ≤ Σ λ_i (|g(p) − g(q_i)| + |g(q_i) − z_i|) ≤ Σ λ_i (L |p − q_i| + e_i)``, with ``e_i = 0`` at a rim
corner and ``e_i = |z_i − h(r_i)| + L |q_i − r_i|`` at an inner one.  ``Σ λ_i |p − q_i| ≤ max_i |p − q_i|``, a
convex function of ``p``, whose mean over ``T`` is at most the mean of its values at the corners (Jensen), so
``∫_T |g − F| ≤ A_T (L · mean_i max_j |q_i − q_j| + mean_i e_i)`` (``A_T`` the projected area); the sum over the
fill, plus 16 ulp of the coordinates times the area, is the hole's volume in doubt.  Every point of the region
lies within ``height = max |h − h̄| + L √(A/π)`` (``A`` the area of ``Ω``: no point of ``Ω`` is farther from its
border) of the rim's mean height ``h̄`` (the caller's reach).
"""

from __future__ import annotations

import numpy as np

from ..values import frozen_value
from .hole_bounds import BEND_MAX_DEGREES, _round_off
from .hole_fills import QUADRIC_FIT_RTOL, _faces_near, _fitted_quadric, _quadric
from .polygons import ear_clip_2d

__all__ = ["GraphFill", "graph_fills", "face_on_direction", "GRAPH_MAX_LOOPS", "GRAPH_MAX_RIM", "GRAPH_GRID"]

#: Most holes given a graph fill (those with the most doubt first).
GRAPH_MAX_LOOPS = 16
#: Most rim corners of a hole given a graph fill (the polygon's simplicity check is quadratic in them).
GRAPH_MAX_RIM = 2000
#: Grid steps across the square root of the projected area: about ``GRAPH_GRID²`` inner points.
GRAPH_GRID = 14


@frozen_value
class GraphFill:
    """A hole filled as a graph over the plane most face-on to the faces round it (:func:`graph_fills`).

    Attributes
    ----------
    loop : int
        The boundary loop.
    apex : (3,) float
        The cone's apex, unchanged (not used by the fill's triangles), m.
    points : (p, 3) float
        The fill's inner points, m.
    caps : (q, 3) int
        Its triangles: rim vertices by their index, the inner points as ``−1 − i`` (the caller numbers them).
    doubt : float
        Volume in doubt under the ``graph`` assumption, m³ (rounded up).
    height : float
        How far the region in doubt reaches from the rim's mean height along ``direction``, m.
    direction : (3,) float
        The unit direction ``d`` the fill is a graph along.
    slope : float
        ``L``, the tangent of the largest angle between ``d`` and a face touching the rim.
    """

    loop: int
    apex: np.ndarray
    points: np.ndarray
    caps: np.ndarray
    doubt: float
    height: float
    direction: np.ndarray
    slope: float


def face_on_direction(normals: np.ndarray) -> tuple[np.ndarray, float]:
    """The unit direction ``d`` most face-on to the unit ``normals`` (k, 3), and its least cosine ``min n·d``.

    Maximises ``t`` subject to ``n_i·x ≥ t`` and ``|x_j| ≤ 1`` (a linear programme, scipy's HiGHS); ``x/|x|`` is
    compared with the normals' normalised mean and the better of the two kept (the programme's box is not the
    unit ball, so neither is optimal in general; any ``d`` serves the bound, which uses the cosine it measures).
    """
    from scipy.optimize import linprog

    n = np.asarray(normals, dtype=np.float64)
    best = np.zeros(3)
    best_cos = -np.inf
    mean = n.sum(axis=0)
    candidates = [mean / np.linalg.norm(mean)] if np.linalg.norm(mean) > 0 else []
    res = linprog(np.r_[0.0, 0.0, 0.0, -1.0], A_ub=np.column_stack([-n, np.ones(len(n))]), b_ub=np.zeros(len(n)),
                  bounds=[(-1.0, 1.0)] * 3 + [(None, None)], method="highs")
    if res.status == 0 and np.linalg.norm(res.x[:3]) > 0:
        candidates.append(res.x[:3] / np.linalg.norm(res.x[:3]))
    for d in candidates:
        c = float(np.min(n @ d))
        if c > best_cos:
            best, best_cos = d, c
    return best, best_cos


def _walk(raw: np.ndarray) -> list[int] | None:
    """The rim's corners in the order of its edges ``a → b`` (one simple cycle), or None (a pinch, or several)."""
    succ = dict(zip(raw[:, 0].tolist(), raw[:, 1].tolist()))
    if len(succ) != len(raw):
        return None
    walk = [int(raw[0, 0])]
    while len(walk) <= len(raw) and succ.get(walk[-1], walk[0]) != walk[0]:
        walk.append(succ[walk[-1]])
    return walk if len(walk) == len(raw) else None


def _segments_cross(p: np.ndarray) -> bool:
    """Whether the closed polygon ``p`` (k, 2) is *not* simple: two edges that are not neighbours meet (touching
    counts), or two corners coincide.  Exact orientation signs in float64 (a pair within round-off counts as
    meeting)."""
    k = len(p)
    if len(np.unique(p, axis=0)) != k:
        return True
    a, b = p, np.roll(p, -1, axis=0)
    lo, hi = np.minimum(a, b), np.maximum(a, b)

    def orient(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        value: np.ndarray = (y[..., 0] - x[..., 0]) * (z[..., 1] - x[..., 1]) - (y[..., 1] - x[..., 1]) * (
            z[..., 0] - x[..., 0])
        return value

    idx = np.arange(k)
    for start in range(0, k, 256):                       # bounded by k / 256 + 1 blocks
        i = idx[start:start + 256, None]
        j = idx[None, :]
        # non-neighbouring pairs i < j only
        pair = (j > i) & (j != i + 1) & ~((i == 0) & (j == k - 1))
        boxes = ((lo[i, 0] <= hi[j, 0]) & (lo[j, 0] <= hi[i, 0]) & (lo[i, 1] <= hi[j, 1]) & (lo[j, 1] <= hi[i, 1]))
        ii, jj = np.nonzero(pair & boxes)
        if not len(ii):
            continue
        ii = ii + start
        o1 = np.sign(orient(a[ii], b[ii], a[jj]))
        o2 = np.sign(orient(a[ii], b[ii], b[jj]))
        o3 = np.sign(orient(a[jj], b[jj], a[ii]))
        o4 = np.sign(orient(a[jj], b[jj], b[ii]))
        if np.any((o1 * o2 <= 0) & (o3 * o4 <= 0)):
            return True
    return False


def _inside(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Crossing-number test of ``points`` (m, 2) against the closed polygon ``poly`` (k, 2)."""
    inside = np.zeros(len(points), dtype=bool)
    a, b = poly, np.roll(poly, -1, axis=0)
    for s in range(len(poly)):                           # bounded by the rim's corners
        ya, yb = a[s, 1], b[s, 1]
        straddles = (ya > points[:, 1]) != (yb > points[:, 1])
        if not straddles.any():
            continue
        with np.errstate(divide="ignore", invalid="ignore"):
            cut = (b[s, 0] - a[s, 0]) * (points[:, 1] - ya) / (yb - ya) + a[s, 0]
        inside ^= straddles & (points[:, 0] < cut)
    return inside


def _nearest_on_rim(points: np.ndarray, poly: np.ndarray, heights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each point (m, 2), its distance to the closed polygon's border and the rim's height there (linear
    along each rim edge between its corners' ``heights``)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    ha, hb = heights, np.roll(heights, -1)
    best = np.full(len(points), np.inf)
    at = np.zeros(len(points))
    for lo in range(0, len(poly), 512):                  # bounded by len(poly) / 512 + 1 blocks
        sa, sb = a[lo:lo + 512], b[lo:lo + 512]
        e = sb - sa
        ee = np.maximum(np.einsum("ij,ij->i", e, e), 1e-300)
        t = np.clip(((points[:, None, :] - sa[None]) * e[None]).sum(axis=2) / ee[None], 0.0, 1.0)
        dist = np.linalg.norm(points[:, None, :] - (sa[None] + t[..., None] * e[None]), axis=2)
        which = np.argmin(dist, axis=1)
        d = dist[np.arange(len(points)), which]
        h = ha[lo:lo + 512][which] + t[np.arange(len(points)), which] * (hb[lo:lo + 512][which]
                                                                          - ha[lo:lo + 512][which])
        closer = d < best
        best = np.where(closer, d, best)
        at = np.where(closer, h, at)
    return best, at


def _tiling(tri: np.ndarray, points: np.ndarray, k: int, area: float) -> bool:
    """Whether the triangles ``tri`` (t, 3) over ``points`` (the polygon's ``k`` corners first, counter-clockwise)
    tile the polygon once: every triangle counter-clockwise (or flat to 1e-12 of the area), each polygon edge
    ``i → i+1`` in exactly one triangle in that direction and in none reversed, every other edge in two triangles
    in opposite directions, and the areas summing to the polygon's ``area`` (to 1e-9)."""
    if not len(tri):
        return False
    p = points[tri]
    signed = 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                    - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))
    # a sliver along collinear rim corners may come out at ±round-off: 1e-12 of the area, no volume to speak of
    if not (signed > -1e-12 * area).all() or abs(float(signed.sum()) - area) > 1e-9 * area:
        return False
    directed = tri[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    n = np.int64(len(points))
    key = directed[:, 0] * n + directed[:, 1]
    if len(np.unique(key)) != len(key):
        return False
    present = set(key.tolist())
    for x, y in directed.tolist():
        boundary = y == (x + 1) % k and x < k and y < k
        if boundary:
            if y * int(n) + x in present:
                return False
        elif y * int(n) + x not in present:
            return False
    return all((i * int(n) + (i + 1) % k) in present for i in range(k))


#: Most rim corners ear-clipped by :func:`_ear_clip` (quadratic passes in Python).
GRAPH_MAX_CLIPPED = 600
#: Times :func:`_refined` splits an ear-clipped fill (each level: a point at every triangle's centroid and at the
#: middle of every edge off the rim).
GRAPH_LEVELS = 2


def _ear_clip(poly: np.ndarray) -> np.ndarray | None:
    """Triangles (t, 3) of the simple counter-clockwise polygon ``poly`` (k, 2) by ear clipping: an ear is a corner
    turning left whose triangle holds no other remaining corner (on its border counts as held); None when no ear
    is found (not simple in float64) or more than :data:`GRAPH_MAX_CLIPPED` corners."""
    k = len(poly)
    if k > GRAPH_MAX_CLIPPED:
        return None
    triangles = ear_clip_2d(poly[:, 0], poly[:, 1], rotate=True)
    return None if triangles is None else np.array(triangles, dtype=np.int64)


def _refined(tri: np.ndarray, points: np.ndarray, k: int, levels: int) -> tuple[np.ndarray, np.ndarray]:
    """The triangulation ``tri`` over ``points`` (the polygon's ``k`` corners first) split ``levels`` times: each
    triangle into the fan from its centroid to its corners and to the middles of its edges that are not polygon
    edges (``i → i+1``, kept whole so that the fill's border stays the rim).  A middle is shared by the two
    triangles of its edge, so the result is again a triangulation of the polygon, counter-clockwise."""
    pts = [points]
    count = len(points)
    for _ in range(levels):                       # bounded by ``levels``
        pts_now = np.vstack(pts)
        middle: dict[tuple[int, int], int] = {}
        extra: list[np.ndarray] = []
        out: list[tuple[int, int, int]] = []
        for a, b, c in tri.tolist():
            g = count
            count += 1
            extra.append(pts_now[[a, b, c]].mean(axis=0))
            for x, y in ((a, b), (b, c), (c, a)):
                if x < k and y < k and y == (x + 1) % k:
                    out.append((x, y, g))
                    continue
                key = (min(x, y), max(x, y))
                if key not in middle:
                    middle[key] = count
                    count += 1
                    extra.append(0.5 * (pts_now[x] + pts_now[y]))
                mid = middle[key]
                out += [(x, mid, g), (mid, y, g)]
        pts.append(np.array(extra))
        tri = np.array(out, dtype=np.int64)
    return tri, np.vstack(pts)


def graph_fills(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, loops: np.ndarray,
                apex: np.ndarray, *, max_degrees: float = BEND_MAX_DEGREES, fit_rtol: float = QUADRIC_FIT_RTOL,
                max_loops: int = GRAPH_MAX_LOOPS, max_rim: int = GRAPH_MAX_RIM, grid: int = GRAPH_GRID
                ) -> list[GraphFill]:
    """Holes filled as graphs over the plane most face-on to the faces touching their rims (module docstring).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    edges : (k, 2) int
        Boundary edges ``a → b`` (each the edge of one face in that direction), ``label`` (k,) their loop.
    loops : (j,) int
        The loops to try, most doubt first; at most ``max_loops`` are tried.
    apex : (n_loops, 3) float
        The cone's apex of each loop (kept in the fill's record, unused by its triangles), m.
    max_degrees : float
        The steepest a face touching the rim may stand to ``d`` (``BEND_MAX_DEGREES``).
    fit_rtol : float
        The quadric fit's tolerance (``QUADRIC_FIT_RTOL``).
    max_loops, max_rim, grid : int
        ``GRAPH_MAX_LOOPS``, ``GRAPH_MAX_RIM``, ``GRAPH_GRID``.

    Returns
    -------
    list of GraphFill
        The loops that qualify (others keep their fill).
    """
    from scipy.spatial import Delaunay, QhullError

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    margin = _round_off(v)
    cos_max = float(np.cos(np.radians(max_degrees)))
    out: list[GraphFill] = []
    tried = np.asarray(loops, dtype=np.int64)[:max_loops]
    # only the faces within two rings of a rim tried are read (issue 25: a 1.3M-face part made three passes over
    # every face for each of up to 16 loops): every face touching a rim, and every face holding a vertex of one,
    # lies in ``f_near``, which keeps the faces' order, so ``touching`` and ``near`` below are what the whole
    # surface gives, bit for bit
    sizes = np.bincount(label, minlength=int(tried.max(initial=-1)) + 1)
    kept = tried[(sizes[tried] >= 4) & (sizes[tried] <= max_rim)] if len(tried) else tried
    f_near = _faces_near(f, len(v), [edges[np.isin(label, kept)].reshape(-1)]) if len(kept) else f[:0]
    for k in tried.tolist():
        raw = edges[label == k]
        if len(raw) < 4 or len(raw) > max_rim:
            continue
        walk = _walk(raw)
        if walk is None:
            continue
        rim = np.array(walk, dtype=np.int64)
        on_rim = np.zeros(len(v), dtype=bool)
        on_rim[rim] = True
        touching = f_near[on_rim[f_near].any(axis=1)]
        normal = np.cross(v[touching[:, 1]] - v[touching[:, 0]], v[touching[:, 2]] - v[touching[:, 0]])
        size = np.linalg.norm(normal, axis=1)
        if not (size > 0).any():
            continue
        unit = normal[size > 0] / size[size > 0, None]
        d, least = face_on_direction(unit)
        if not least >= cos_max:
            continue                                   # a face at the rim steeper than max_degrees to every d
        slope = float(np.sqrt(max(1.0 - least * least, 0.0)) / least)
        e1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        ref = v[rim].mean(axis=0)
        rel = v[rim] - ref
        poly = np.column_stack([rel @ e1, rel @ e2])
        h = rel @ d
        signed = 0.5 * float(np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1]))
        if not signed < 0:
            continue                                   # the rim runs the wrong way round d: not this graph
        if _segments_cross(poly):
            continue                                   # the projected rim is not a simple polygon
        # counter-clockwise: the rim reversed (rim edge a → b becomes b → a, as the fill's triangles hold it)
        ccw = poly[::-1]
        ccw_h = h[::-1]
        ccw_rim = rim[::-1]
        area = -signed
        step = np.sqrt(area) / grid
        lo, hi = ccw.min(axis=0), ccw.max(axis=0)
        gu = np.arange(lo[0] + 0.5 * step, hi[0], step)
        gw = np.arange(lo[1] + 0.5 * step, hi[1], step)
        cand = np.stack(np.meshgrid(gu, gw), axis=-1).reshape(-1, 2)
        cand = cand[_inside(cand, ccw)] if len(cand) else cand
        if len(cand):
            # half a step, and half the longest rim edge, from the border: then no grid point lies in a rim edge's
            # diametral disc, so the rim edges stay edges of the Delaunay cut (where no rim corner lies there)
            dist, _ = _nearest_on_rim(cand, ccw, ccw_h)
            longest = float(np.max(np.linalg.norm(ccw - np.roll(ccw, -1, axis=0), axis=1)))
            cand = cand[dist >= max(0.5 * step, 0.55 * longest)]
        tri = None
        for inner in (cand, cand[::4], cand[:0]):       # fewer inner points where the first cut fails
            pts = np.vstack([ccw, inner])
            try:
                dt = Delaunay(pts)
            except (QhullError, ValueError):
                continue
            simplices = dt.simplices.astype(np.int64)
            centroid = pts[simplices].mean(axis=1)
            kept = simplices[_inside(centroid, ccw)]
            p = pts[kept]
            turn = ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                    - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))
            kept = np.where((turn < 0)[:, None], kept[:, [0, 2, 1]], kept)
            if _tiling(kept, pts, len(ccw), area):
                tri, cand = kept, inner
                break
        if tri is None:                                 # the Delaunay cut lost a rim edge: ear clipping, split
            clipped = _ear_clip(ccw)
            if clipped is not None:
                tri, pts = _refined(clipped, ccw, len(ccw), GRAPH_LEVELS)
                if _tiling(tri, pts, len(ccw), area):
                    cand = pts[len(ccw):]
                else:
                    tri = None
        if tri is None:
            continue
        # inner heights: the quadric round the rim where one fits, else the least-squares quadratic height
        z = np.zeros(len(cand))
        dist, h_at = _nearest_on_rim(cand, ccw, ccw_h) if len(cand) else (np.zeros(0), np.zeros(0))
        if len(cand):
            near = on_rim.copy()
            for _ in range(2):
                near[f_near[near[f_near].any(axis=1)].reshape(-1)] = True
            radius = float(np.max(np.linalg.norm(rel, axis=1)))
            x = (v[near] - ref) / radius
            fit = _fitted_quadric(x, fit_rtol)
            q3 = (cand[:, :1] * e1 + cand[:, 1:] * e2 + h_at[:, None] * d) / radius
            lifted = None
            if fit is not None:
                qa, qb, qc = fit
                alpha = float(d @ qa @ d)
                beta = 2.0 * q3 @ qa @ d + float(qb @ d)
                gamma = _quadric(q3, qa, qb, qc)
                if abs(alpha) > 1e-12:
                    disc = beta * beta - 4.0 * alpha * gamma
                    if (disc >= 0).all():
                        root = np.sqrt(disc)
                        one, two = (-beta + root) / (2 * alpha), (-beta - root) / (2 * alpha)
                        lifted = h_at + radius * np.where(np.abs(one) <= np.abs(two), one, two)
                elif (np.abs(beta) > 0).all():
                    lifted = h_at + radius * (-gamma / beta)
            if lifted is None or not np.isfinite(lifted).all():
                xn = v[near] - ref
                u, w, hh = xn @ e1, xn @ e2, xn @ d
                design = np.column_stack([np.ones(len(u)), u, w, u * u, u * w, w * w])
                coef, *_ = np.linalg.lstsq(design, hh, rcond=None)
                cu, cw = cand[:, 0], cand[:, 1]
                lifted = np.column_stack([np.ones(len(cu)), cu, cw, cu * cu, cu * cw, cw * cw]) @ coef
            z = np.clip(lifted, h_at - slope * dist, h_at + slope * dist)
        heights = np.r_[ccw_h, z]
        err = np.r_[np.zeros(len(ccw)), np.abs(z - h_at) + slope * dist]
        pts = np.vstack([ccw, cand])
        p = pts[tri]
        tri_area = 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                          - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))
        edge = np.linalg.norm(p - np.roll(p, -1, axis=1), axis=2)         # (t, 3): |q0q1|, |q1q2|, |q2q0|
        far = np.maximum(edge, np.roll(edge, 1, axis=1)).mean(axis=1)     # mean over corners of max_j |q_i − q_j|
        doubt = float(np.sum(tri_area * (slope * far + err[tri].mean(axis=1) + 2.0 * margin)))
        doubt = float(np.nextafter(doubt * (1.0 + 1e-9), np.inf))
        mean_h = float(h.mean())
        # no point of Ω is farther from its border than sqrt(area / π) (the disc round it inside Ω)
        height = float(np.max(np.abs(heights - mean_h))) + slope * float(np.sqrt(area / np.pi)) + 2.0 * margin
        # numbering: corner i < len(ccw) is rim vertex ccw_rim[i]; inner point j is −1 − j
        index = np.r_[ccw_rim, -1 - np.arange(len(cand))]
        caps = index[tri]
        points = ref + cand[:, :1] * e1 + cand[:, 1:] * e2 + z[:, None] * d if len(cand) else np.zeros((0, 3))
        out.append(GraphFill(loop=int(k), apex=apex[k].copy(), points=points, caps=caps, doubt=doubt,
                             height=height, direction=d, slope=slope))
    return out
