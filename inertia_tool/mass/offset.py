"""Moments of the inward offset (the *core*) of a closed solid, with a bracket that holds.

The core of a solid ``X`` at depth ``t`` is ``X_t = {p ∈ X : dist(p, ∂X) ≥ t}``, the morphological erosion of
``X`` by a ball of radius ``t``: what a printed part's infill fills when its skin is ``t`` thick.  For a convex
solid it has a closed form (a box ``a × b × c``: ``(a − 2t)(b − 2t)(c − 2t)``; a sphere of radius ``r``: the
sphere of radius ``r − t``; a cylinder: radius ``r − t``, height ``h − 2t``); for a general polyhedron it is
bounded by offset planes, and by cylinders and spheres about concave edges and vertices, trimmed where they
meet: this module integrates it numerically with a bound.

Method (``core_moments``).  The signed distance ``d(p)`` to the surface (positive inside) is evaluated exactly
(libigl's AABB tree; the sign from the angle-weighted pseudo-normal, exact for a closed, consistently oriented
surface).  ``d`` is 1-Lipschitz, so a cube cell of half-diagonal ``r`` centred at ``c`` lies wholly in the core
when ``d(c) − t ≥ r`` and wholly outside it when ``d(c) − t ≤ −r``; the cells in between (the *band*) are
split into eight down to the finest size.  In a finest band cell the core is taken as the half-space of the
linearised distance ``d(c) + ∇d·(p − c) ≥ t`` (exact volume of a cube cut by a plane), which is exact where
the core surface is a plane across the cell.

The bracket.  In a band cell, the ball of radius ``d(c) − t`` about ``c`` is certainly in the core, and the
ball of radius ``t − d(c)`` certainly outside it (Lipschitz); the cube inscribed in that ball bounds the
cell's unknown part.  Summing over the band gives a volume interval that holds for any closed, oriented
polyhedron (no assumption on its shape); the first and second moments are bounded through the largest
distance of a band cell from the reference point.  The interval shrinks as the band cells shrink (the band's
volume is about ``1.7 A_t h`` for a core surface of area ``A_t`` and cells of size ``h``) and is reported with
the result; the estimate is much closer than the interval (second order in ``h`` where the core surface is
flat or smooth).
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import UsageError
from ..values import frozen_value

__all__ = ["CoreMoments", "core_moments", "vertical_skin_moments", "DEFAULT_BAND_CELLS"]

#: Finest band cells (distance queries) ``core_moments`` aims at by default: about 1–3 s on one core.
DEFAULT_BAND_CELLS = 100_000

#: Cells of the first grid over the box the core can occupy.
_FIRST_GRID_CELLS = 32_768

#: Refinement levels at most (the loop bound; 2⁻¹² of the first cell is far below any useful size).
_MAX_LEVELS = 12

#: Smallest normal component in the cube–half-space volume formula (a tilt of 1e-4 rad moves a cell's volume
#: by at most ~1e-4 of the cell, and keeps the formula's divisions well conditioned).
_MIN_NORMAL_COMPONENT = 1e-4

_CORNERS = np.array(list(itertools.product((0.0, 1.0), repeat=3)))
_CORNER_SIGNS = (-1.0) ** _CORNERS.sum(axis=1)


@frozen_value
class CoreMoments:
    """Volume moments of the core ``{p ∈ X : dist(p, ∂X) ≥ t}``, unit density, about a reference point.

    Attributes
    ----------
    depth : float
        ``t``, m.
    origin : (3,) float
        The reference point of ``first_moment`` and ``second_moment``, m, mesh axes.
    volume : float
        Estimate of the core volume, m³.
    volume_bounds : (2,) float
        ``[lower, upper]``, m³: the core volume certainly lies in this interval.
    first_moment : (3,) float
        Estimate of ``∫ (x − o) dV`` over the core, m⁴.
    first_moment_bound : float
        ``|Δ ∫ (x − o) dV| ≤`` this, m⁴ (Euclidean norm of the error).
    second_moment : (3, 3) float
        Estimate of ``∫ (x − o)(x − o)ᵀ dV`` over the core, m⁵, mesh axes.
    second_moment_bound : float
        Spectral norm of the error of ``second_moment`` is at most this, m⁵.
    cell_size : float
        Edge of the finest cells, m.
    band_cells : int
        Finest cells that straddle the core surface.
    """

    depth: float
    origin: np.ndarray
    volume: float
    volume_bounds: np.ndarray
    first_moment: np.ndarray
    first_moment_bound: float
    second_moment: np.ndarray
    second_moment_bound: float
    cell_size: float
    band_cells: int


def _signed_distance(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                     reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed distance (positive inside), unit gradient and closest surface point at ``points``.

    Points farther than ``reach`` are asked again without the search bound (libigl answers NaN past it).
    """
    import igl
    kind = igl.SignedDistanceType.SIGNED_DISTANCE_TYPE_PSEUDONORMAL
    p = np.ascontiguousarray(points, dtype=np.float64)
    s, face, closest, _ = igl.signed_distance(p, vertices, faces, kind, -reach, reach)
    far = ~np.isfinite(s)
    if np.any(far):
        s2, face2, closest2, _ = igl.signed_distance(np.ascontiguousarray(p[far]), vertices, faces, kind)
        s[far], face[far], closest[far] = s2, face2, closest2
    d = -s                                          # libigl: negative inside an outward-wound surface
    away = p - closest
    length = np.linalg.norm(away, axis=1)
    e1 = vertices[faces[face, 1]] - vertices[faces[face, 0]]
    e2 = vertices[faces[face, 2]] - vertices[faces[face, 0]]
    normal = np.cross(e1, e2)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), np.finfo(float).tiny)[:, None]
    tiny = length <= 1e-12 * max(reach, np.finfo(float).tiny)
    grad = np.where(tiny[:, None], -normal, np.sign(d)[:, None] * away / np.where(tiny, 1.0, length)[:, None])
    return d, grad, closest


def _cube_cut_fraction(normal: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Fraction of the unit cube ``[−½, ½]³`` where ``n · x ≤ δ``, for unit normals ``n`` (k, 3) and ``δ`` (k,).

    ``vol{u ∈ [0,1]³ : a·u ≤ s} = Σ_v (−1)^|v| max(0, s − a·v)³ / (6 a₁a₂a₃)`` over the cube's corners ``v``
    (the box-spline formula), with ``a = |n|`` (reflecting the cube) and ``s = δ + Σa/2``.
    """
    a = np.maximum(np.abs(normal), _MIN_NORMAL_COMPONENT)
    s = delta + 0.5 * a.sum(axis=1)
    w = np.maximum(s[:, None] - a @ _CORNERS.T, 0.0)
    total = (w ** 3) @ _CORNER_SIGNS
    fraction: np.ndarray = np.clip(total / (6.0 * np.prod(a, axis=1)), 0.0, 1.0)
    return fraction


_SUB = 4
_SUB_OFFSETS = (np.array(list(itertools.product(range(_SUB), repeat=3))) + 0.5) / _SUB - 0.5
_SUB_OUTER = (_SUB_OFFSETS[:, :, None] * _SUB_OFFSETS[:, None, :]).reshape(-1, 9)
_CORNER_OFFSETS = _CORNERS - 0.5


def _certain_parts(centres: np.ndarray, size: float, depth: float, points: np.ndarray, margins: np.ndarray,
                   closest: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which sub-cells of each cell are certainly in the core and which certainly outside it, (k, 64) bool each.

    Each cell is cut into ``4³`` sub-cells (centres ``y``, half-diagonal ``ρ``).  With samples ``x_j`` (the
    cell's centre and corners), their margins ``m_j = d(x_j) − t`` and closest surface points ``q_j``, a
    sub-cell is

    * in the core when ``m_j − |y − x_j| ≥ ρ`` for some ``j`` (``d`` is 1-Lipschitz);
    * outside it when ``−m_j − |y − x_j| ≥ ρ`` for some ``j`` (likewise), or ``|y − q_j| + ρ ≤ t``
      (``q_j`` lies on the surface, so ``d(p) ≤ |p − q_j| < t`` on the whole sub-cell).
    """
    rho = 0.5 * np.sqrt(3.0) * size / _SUB
    offsets = np.concatenate([np.zeros((1, 3)), _CORNER_OFFSETS])                  # the samples, in cell units
    gap = size * np.linalg.norm(_SUB_OFFSETS[:, None, :] - offsets[None, :, :], axis=-1)     # (64, 9), the same
    sub = size * _SUB_OFFSETS                                                       # for every cell
    core = np.zeros((len(centres), _SUB ** 3), dtype=bool)
    empty = np.zeros_like(core)
    limit = max(depth - rho, 0.0) ** 2
    from .._native import accel
    lib = accel()
    if lib is not None:
        # the same tests in C (_accel.c section 12), a sub-cell at a time with an early exit once it is in the core
        lib.certain_parts(np.ascontiguousarray(centres, dtype=np.float64),
                          np.ascontiguousarray(margins, dtype=np.float64),
                          np.ascontiguousarray(closest, dtype=np.float64), np.ascontiguousarray(gap),
                          np.ascontiguousarray(sub), float(rho), float(limit), bool(depth > rho),
                          core.view(np.uint8), empty.view(np.uint8))
        return core, empty
    step = 4096
    sub_norm2 = np.einsum("sx,sx->s", sub, sub)[None, :]
    # one sample at a time: (k, 64) arrays, and the cross term a matrix product (the (k, 64, 9) arrays and
    # einsum of the vectorised form cost about 5 s of the 7 s a 12-face box took)
    for a in range(0, len(centres), step):
        m = margins[a:a + step]                                                     # (k, 9)
        away = centres[a:a + step, None, :] - closest[a:a + step]                   # (k, 9, 3): c − q_j
        core_k = np.zeros((len(m), _SUB ** 3), dtype=bool)
        out = np.zeros_like(core_k)
        for j in range(m.shape[1]):
            mj = m[:, j:j + 1]
            core_k |= mj - gap[None, :, j] >= rho
            out |= -mj - gap[None, :, j] >= rho
            if depth > rho:
                # |y − q_j|² = |c − q_j|² + 2 (y − c)·(c − q_j) + |y − c|²
                aj = away[:, j, :]
                reach2 = (np.einsum("kx,kx->k", aj, aj)[:, None] + 2.0 * (aj @ sub.T)) + sub_norm2
                out |= reach2 <= limit
        core[a:a + step] = core_k
        empty[a:a + step] = out
    return core, empty & ~core


def core_moments(vertices: ArrayLike, faces: ArrayLike, depth: float, *, origin: ArrayLike,
                 band_cells: int = DEFAULT_BAND_CELLS) -> CoreMoments:
    """Volume moments of the core of a closed solid at ``depth`` (its inward offset), with bounds.

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        A closed, consistently outward-wound surface (as ``prepare_mesh`` leaves it; cavities wound inward).
    depth : float
        ``t > 0``, m: the skin thickness.
    origin : (3,) float
        Reference point of the moments, m (the solid's centroid keeps them well conditioned).
    band_cells : int
        About how many finest cells may straddle the core surface (each one distance query); more cells give a
        tighter bracket (its width falls as ``1/√band_cells``).

    Returns
    -------
    CoreMoments

    Raises
    ------
    UsageError
        For a depth that is not positive and finite, or a band budget below 1000.
    """
    t = float(depth)
    if not (np.isfinite(t) and t > 0):
        raise UsageError(f"Expected `depth` to be a positive finite length in m, got {depth}")
    if int(band_cells) < 1000:
        raise UsageError(f"Expected `band_cells` of at least 1000, got {band_cells}")
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    o = np.asarray(origin, dtype=np.float64)
    lo, hi = v.min(axis=0) + t, v.max(axis=0) - t        # a core point's ball of radius t lies in the box
    empty = CoreMoments(depth=t, origin=o, volume=0.0, volume_bounds=np.zeros(2), first_moment=np.zeros(3),
                        first_moment_bound=0.0, second_moment=np.zeros((3, 3)), second_moment_bound=0.0,
                        cell_size=0.0, band_cells=0)
    if np.any(hi <= lo):
        return empty
    extent = hi - lo
    h = float(np.prod(extent) / _FIRST_GRID_CELLS) ** (1.0 / 3.0)
    h = max(h, float(extent.max()) / 256.0)
    counts = np.maximum(np.ceil(extent / h).astype(np.int64), 1)
    start = lo + 0.5 * (extent - counts * h)             # the grid centred on the box
    axes = [start[k] + h * (np.arange(counts[k]) + 0.5) for k in range(3)]
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    e1 = v[f[:, 1]] - v[f[:, 0]]
    area = 0.5 * float(np.linalg.norm(np.cross(e1, v[f[:, 2]] - v[f[:, 0]]), axis=1).sum())
    finest = np.sqrt(np.sqrt(3.0) * area / int(band_cells))   # band ≈ √3 A / h² cells at size h
    volume = 0.0
    first = np.zeros(3)
    second = np.zeros((3, 3))
    low = high = 0.0
    first_bound = second_bound = 0.0
    reach = np.inf
    n_band = 0

    grid_origin = start.copy()

    def add_full(c: np.ndarray, size: float, weight: np.ndarray | None = None) -> None:
        nonlocal volume, first, second
        x = c - o
        cell = size ** 3
        w = np.full(len(c), cell) if weight is None else cell * weight
        volume += float(w.sum())
        first = first + w @ x
        second = second + (x * w[:, None]).T @ x + float(w.sum()) * size * size / 12.0 * np.eye(3)

    for level in range(_MAX_LEVELS + 1):
        r = 0.5 * np.sqrt(3.0) * h
        d, grad, near = _signed_distance(centres, v, f, reach)
        margin = d - t
        inside = margin >= r
        add_full(centres[inside], h)
        band = np.abs(margin) < r
        last = h <= finest or level == _MAX_LEVELS or 8 * np.count_nonzero(band) > 16 * int(band_cells)
        if not last:
            kids = (np.array(list(itertools.product((-0.25, 0.25), repeat=3))) * h)
            centres = (centres[band][:, None, :] + kids[None, :, :]).reshape(-1, 3)
            reach = t + 2.0 * r
            h *= 0.5
            continue
        c, m, g, qc = centres[band], margin[band], grad[band], near[band]
        n_band = len(c)
        # the cells' corners lie on the lattice grid_origin + h·j; each distinct corner is asked once
        keys = np.rint((c - grid_origin) / h - 0.5).astype(np.int64)[:, None, :] + _CORNERS.astype(np.int64)
        span = keys.reshape(-1, 3).max(axis=0) + 1
        flat = (keys[..., 0] * span[1] + keys[..., 1]) * span[2] + keys[..., 2]
        unique, back = np.unique(flat.reshape(-1), return_inverse=True)
        lattice = np.stack([unique // (span[1] * span[2]), (unique // span[2]) % span[1], unique % span[2]], axis=1)
        dk, _, qk = _signed_distance(grid_origin + h * lattice, v, f, t + 3.0 * r)
        back = back.reshape(len(c), 8)
        points = np.concatenate([c[:, None, :], c[:, None, :] + h * _CORNER_OFFSETS[None, :, :]], axis=1)
        margins = np.concatenate([m[:, None], dk[back] - t], axis=1)
        closest = np.concatenate([qc[:, None, :], qk[back]], axis=1)
        cell = h ** 3
        sub = cell / _SUB ** 3
        core, outside = _certain_parts(c, h, t, points, margins, closest)
        unknown = ~(core | outside)
        lower = sub * np.count_nonzero(core, axis=1)
        upper = cell - sub * np.count_nonzero(outside, axis=1)
        est = np.clip(_cube_cut_fraction(-g, m / h) * cell, lower, upper)
        # the estimate's volume spread evenly over the undecided sub-cells (weight w): its moments are then
        # wrong by at most max(w, 1 − w) of each undecided sub-cell's
        n_unknown = np.count_nonzero(unknown, axis=1)
        w = np.where(n_unknown > 0, (est - lower) / np.maximum(n_unknown * sub, np.finfo(float).tiny), 0.0)
        weights = np.where(core, 1.0, 0.0) + np.where(unknown, w[:, None], 0.0)       # (k, 64)
        slack = np.where(unknown, np.maximum(w, 1.0 - w)[:, None], 0.0)
        # Σ_s w_s y_s y_sᵀ over sub-cells y_s = c + h o_s: W c cᵀ + h (c Pᵀ + P cᵀ) + h² Q per cell
        x = c - o
        wsum = sub * weights.sum(axis=1)                                                # (k,)
        moment = sub * h * (weights @ _SUB_OFFSETS)                                     # (k, 3)
        spread = sub * h * h * (weights @ _SUB_OUTER).reshape(-1, 3, 3).sum(axis=0)
        volume += float(wsum.sum())
        first = first + wsum @ x + moment.sum(axis=0)
        cross = x.T @ moment
        second = (second + (x * wsum[:, None]).T @ x + cross + cross.T + spread
                  + float(wsum.sum()) * (h / _SUB) ** 2 / 12.0 * np.eye(3))
        reach_o = np.linalg.norm(x, axis=1) + r                                         # any point of the cell
        undecided = sub * slack.sum(axis=1)
        first_bound = float(undecided @ reach_o)
        second_bound = float(undecided @ (reach_o * reach_o))         # ‖x xᵀ‖ = ‖|x|² 1 − x xᵀ‖ = |x|²
        low = volume - float((est - lower).sum())
        high = volume + float((upper - est).sum())
        break
    return CoreMoments(depth=t, origin=o, volume=volume, volume_bounds=np.array([max(low, 0.0), high]),
                       first_moment=first, first_moment_bound=first_bound, second_moment=0.5 * (second + second.T),
                       second_moment_bound=second_bound, cell_size=h, band_cells=n_band)


#: Points per cell at which ``_column_fraction`` samples the cell's height.
_COLUMN_SAMPLES = 16


def _column_fraction(column: np.ndarray, j_lo: int, h: float, depth: float, top: float, bottom: float) -> np.ndarray:
    """Estimated fraction of each cell in ``D`` (see ``vertical_skin_moments``), along its centre's vertical line.

    ``column[:, k]`` is the signed distance at ``c + (j_lo + k) h e_z``; between samples it is taken linear.  At
    ``_COLUMN_SAMPLES`` heights ``z`` in the cell: in the core when ``d(z) ≥ t``; the surface crossings of the
    line are where the linear ``d`` changes sign; ``z`` is in ``D`` when the nearest crossing above is closer than
    ``top`` or the nearest below closer than ``bottom``.  Exact where the distance is linear along the line
    (below horizontal faces), an estimate elsewhere; the bracket does not depend on it."""
    n, m = column.shape
    z = (np.arange(m) + j_lo) * h                                              # sample heights, cell centre 0
    d0, d1 = column[:, :-1], column[:, 1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        crossing = z[:-1] + h * d0 / (d0 - d1)                                 # where the linear d is 0
    exits = np.where((d0 > 0) & (d1 <= 0), crossing, np.inf)                   # leaving X going up
    enters = np.where((d0 <= 0) & (d1 > 0), crossing, -np.inf)                 # entering X going up
    samples = ((np.arange(_COLUMN_SAMPLES) + 0.5) / _COLUMN_SAMPLES - 0.5) * h
    k0 = -j_lo
    fraction = np.zeros(n)
    for zs in samples:
        below = k0 - 1 if zs < 0 else k0
        w = (zs - z[below]) / h
        d = column[:, below] * (1.0 - w) + column[:, below + 1] * w
        up = np.where(exits > zs, exits, np.inf).min(axis=1)
        down = np.where(enters < zs, enters, -np.inf).max(axis=1)
        fraction += (d >= depth) & ((up - zs < top) | (zs - down < bottom))
    return fraction / _COLUMN_SAMPLES


def _crosses_surface(tree: Any, v: np.ndarray, f: np.ndarray, centres: np.ndarray, size: float, top: float,
                     bottom: float) -> np.ndarray:
    """Whether every vertical segment ``[q − bottom, q + top]`` from every point ``q`` of each cell certainly leaves
    the solid: the face first hit by the vertical ray from the cell's centre (up, then down) covers the cell's
    whole footprint in projection, faces the way of travel (its outward normal's z has the ray's sign, so the
    line passes from inside to outside there), and lies over the footprint above the cell's top and within
    ``top`` of its bottom (below: within ``bottom``).  Exact predicates are not needed: the margins are a cell."""
    out = np.zeros(len(centres), dtype=bool)
    half = 0.5 * size
    corners = np.array([[-1.0, -1.0], [1.0, -1.0], [-1.0, 1.0], [1.0, 1.0]]) * half
    for sign, reach in ((1.0, top), (-1.0, bottom)):
        direction = np.tile([0.0, 0.0, sign], (len(centres), 1))
        face, _, _ = tree.intersect_ray_first(v, f, np.ascontiguousarray(centres), direction)
        hit = face >= 0
        tri = v[f[np.where(hit, face, 0)]]                                          # (k, 3, 3)
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        facing = hit & (sign * normal[:, 2] > 0)
        ok = facing.copy()
        a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
        area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        for dx, dy in corners:
            px, py = centres[:, 0] + dx, centres[:, 1] + dy
            w0 = (b[:, 0] - px) * (c[:, 1] - py) - (b[:, 1] - py) * (c[:, 0] - px)
            w1 = (c[:, 0] - px) * (a[:, 1] - py) - (c[:, 1] - py) * (a[:, 0] - px)
            w2 = area - w0 - w1
            inside = np.where(area > 0, (w0 >= 0) & (w1 >= 0) & (w2 >= 0), (w0 <= 0) & (w1 <= 0) & (w2 <= 0))
            with np.errstate(divide="ignore", invalid="ignore"):
                z = (w0 * a[:, 2] + w1 * b[:, 2] + w2 * c[:, 2]) / area                # the face over the corner
            rise = sign * (z - centres[:, 2])                                          # along the travel
            ok &= inside & (area != 0) & (rise > half) & (rise <= reach - half)
        out |= ok
    return out


def _add_weighted(c: np.ndarray, size: float, weight: np.ndarray,
                  origin: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, first and second moments (about ``origin``) of cubes at ``c`` filled to ``weight``."""
    x = c - origin
    w = size ** 3 * weight
    return (float(w.sum()), w @ x, (x * w[:, None]).T @ x + float(w.sum()) * size * size / 12.0 * np.eye(3))


#: Distance queries per refinement level of ``vertical_skin_moments`` at most (its loop's memory bound).
_VERTICAL_QUERY_BATCH = 1 << 18


def vertical_skin_moments(vertices: ArrayLike, faces: ArrayLike, depth: float, *, top: float, bottom: float,
                          origin: ArrayLike, band_cells: int = DEFAULT_BAND_CELLS) -> CoreMoments:
    """Volume moments of the part of the core that a slicer's top and bottom layers make solid, with bounds.

    A slicer fills solid every point within ``top`` (measured vertically) below an up-facing surface and within
    ``bottom`` above a down-facing one.  With ``S = [−bottom, top] e_z``, the point ``p`` stays infill only when
    the vertical segment ``p + S`` lies in the solid ``X`` (the erosion ``X ⊖ S``).  This function integrates
    ``D = X_t \\ (X ⊖ S)``: the points of the core ``X_t`` (``core_moments``) the top/bottom layers take.  The
    infill is then ``X_t − D``.

    Method: an octree over the box of the core.  With the exact signed distance ``d`` (1-Lipschitz) and a cell
    ``Q`` of centre ``c``, half-diagonal ``r`` and edge ``h``:

    * ``Q ⊂ X_t`` when ``d(c) − t ≥ r``; ``Q ∩ X_t = ∅`` when ``d(c) − t ≤ −r``;
    * ``Q ∩ D = ∅`` when the cubes ``Q + j h e_z`` that cover ``Q + S`` all lie in ``X`` (``d ≥ r`` at their
      centres): every segment from ``Q`` stays in the solid;
    * ``Q ⊂ D`` (given ``Q ⊂ X_t``) when one cube ``Q + j h e_z`` lying within ``q + S`` for every ``q ∈ Q``
      lies wholly outside ``X`` (``d ≤ −r``): every vertical segment from ``Q`` passes through it.

    Undecided cells are split into eight, down to the size that leaves about ``band_cells`` of them; at the
    finest level each undecided cell counts by its centre (in ``X_t`` and its segment, sampled every cell and
    at its two ends, leaving ``X``).  The bracket ``[certain, certain + undecided]`` holds for any closed,
    consistently oriented mesh (the assumption of the signed distance's sign), as in ``core_moments``.

    Parameters
    ----------
    vertices, faces
        The closed, outward-wound surface, m.
    depth : float
        ``t > 0``, m: the wall (the core is the inward offset by ``t``).
    top, bottom : float
        m, ≥ 0: the vertical thickness of the top and bottom skins.
    origin : (3,) float
        Reference point of the moments, m.
    band_cells : int
        About how many finest cells may stay undecided (each costs a column of distance queries).

    Returns
    -------
    CoreMoments
        Of ``D``; its ``volume_bounds`` and moment bounds bracket the truth.
    """
    t = float(depth)
    top, bottom = float(top), float(bottom)
    if not (np.isfinite(t) and t > 0):
        raise UsageError(f"Expected `depth` to be a positive finite length in m, got {depth}")
    if not (np.isfinite(top) and np.isfinite(bottom) and top >= 0 and bottom >= 0):
        raise UsageError(f"Expected `top` and `bottom` to be finite lengths ≥ 0 in m, got {top}, {bottom}")
    if int(band_cells) < 1000:
        raise UsageError(f"Expected `band_cells` of at least 1000, got {band_cells}")
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    o = np.asarray(origin, dtype=np.float64)
    lo, hi = v.min(axis=0) + t, v.max(axis=0) - t
    empty = CoreMoments(depth=t, origin=o, volume=0.0, volume_bounds=np.zeros(2), first_moment=np.zeros(3),
                        first_moment_bound=0.0, second_moment=np.zeros((3, 3)), second_moment_bound=0.0,
                        cell_size=0.0, band_cells=0)
    if np.any(hi <= lo) or max(top, bottom) <= t:       # a ball of radius t in X holds the segment: D is empty
        return empty
    extent = hi - lo
    h = float(np.prod(extent) / _FIRST_GRID_CELLS) ** (1.0 / 3.0)
    h = max(h, float(extent.max()) / 256.0)
    counts = np.maximum(np.ceil(extent / h).astype(np.int64), 1)
    start = lo + 0.5 * (extent - counts * h)
    axes = [start[k] + h * (np.arange(counts[k]) + 0.5) for k in range(3)]
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    # refined while the next level's undecided cells stay within the budget (the zone is often a thin slab,
    # far smaller than the surface's area suggests)
    finest = 0.0

    import igl
    tree = igl.AABB()
    tree.init(v, f)

    def distance(points: np.ndarray) -> np.ndarray:
        out = np.empty(len(points))
        for a in range(0, len(points), _VERTICAL_QUERY_BATCH):
            out[a:a + _VERTICAL_QUERY_BATCH] = _signed_distance(points[a:a + _VERTICAL_QUERY_BATCH], v, f,
                                                                np.inf)[0]
        return out

    volume, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    undecided_volume = first_bound = second_bound = 0.0
    n_band = 0

    def add(c: np.ndarray, size: float) -> tuple[float, np.ndarray, np.ndarray]:
        x = c - o
        cell = size ** 3
        return (cell * len(c), cell * x.sum(axis=0),
                cell * (x.T @ x) + cell * len(c) * size * size / 12.0 * np.eye(3))

    for level in range(_MAX_LEVELS + 1):
        r = 0.5 * np.sqrt(3.0) * h
        d_c = distance(centres)
        in_core = d_c - t >= r
        maybe = d_c - t > -r
        centres, d_c, in_core = centres[maybe], d_c[maybe], in_core[maybe]
        j_lo, j_hi = -int(np.ceil(bottom / h)) - 1, int(np.ceil(top / h)) + 1
        # the cubes Q + j h e_z cover Q + S (one more each way, for the column estimate below); those with
        # (1 − bottom/h) ≤ j ≤ (top/h − 1) lie in q + S for every q in Q
        column = np.empty((len(centres), j_hi - j_lo + 1))
        stays = np.ones(len(centres), dtype=bool)
        leaves = np.zeros(len(centres), dtype=bool)
        for j in range(j_lo, j_hi + 1):
            d_j = d_c if j == 0 else distance(centres + [0.0, 0.0, j * h])
            column[:, j - j_lo] = d_j
            if -bottom / h - 1.0 <= j <= top / h + 1.0 and j_lo < j < j_hi:
                stays &= d_j >= r
            if 1.0 - bottom / h <= j <= top / h - 1.0:
                leaves |= d_j <= -r
        candidates = np.nonzero(in_core & ~leaves & ~stays)[0]
        if len(candidates):
            leaves[candidates] = _crosses_surface(tree, v, f, centres[candidates], h, top, bottom)
        certain = in_core & leaves
        undecided = ~certain & ~stays
        dv, ds, dj = add(centres[certain], h)
        volume, first, second = volume + dv, first + ds, second + dj
        n_undecided = int(np.count_nonzero(undecided))
        last = h <= finest or level == _MAX_LEVELS or 8 * n_undecided > int(band_cells)
        if not last:
            kids = np.array(list(itertools.product((-0.25, 0.25), repeat=3))) * h
            centres = (centres[undecided][:, None, :] + kids[None, :, :]).reshape(-1, 3)
            h *= 0.5
            continue
        c = centres[undecided]
        n_band = len(c)
        certain_volume = volume
        fraction = _column_fraction(column[undecided], j_lo, h, t, top, bottom)
        dv, ds, dj = _add_weighted(c, h, fraction, o)
        volume, first, second = volume + dv, first + ds, second + dj
        cell = h ** 3
        reach_o = np.linalg.norm(c - o, axis=1) + r
        undecided_volume = cell * n_band
        first_bound = float(cell * reach_o.sum())
        second_bound = float(cell * (reach_o * reach_o).sum())
        break
    else:                                        # pragma: no cover - the loop always ends at its last level
        certain_volume = volume
    return CoreMoments(depth=t, origin=o, volume=volume,
                       volume_bounds=np.array([certain_volume, certain_volume + undecided_volume]),
                       first_moment=first, first_moment_bound=first_bound, second_moment=0.5 * (second + second.T),
                       second_moment_bound=second_bound, cell_size=h, band_cells=n_band)
