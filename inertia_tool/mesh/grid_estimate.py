"""A bounded estimate of the solid behind a soup or a surface that passes through itself, on a grid.

:func:`winding_estimate` — for soups (no surface with holes to patch): the generalized winding number ``w``
(:mod:`~.winding`) on a regular grid of cells.  **Assumption: the solid is the set where ``w > 1/2``**
(Jacobson et al.'s definition for soups); cells with ``w > 1/2`` are material and integrated exactly as cubes.
Cells that the surface passes through count as half material, half of their volume in doubt (their true share
lies between 0 and 1; ``w`` is not evaluated there); cells whose ``w`` is ambiguous (between ``w_low`` and
``w_high``, or whose evaluation error bound could cross 1/2) could go either way; their volume bounds the
discretization error.  With libigl, ``w`` is evaluated only at cells near a hole: elsewhere it is the integer
winding number of the surface closed by cones over its holes, constant on each region of cells no surface
crosses, less the cones' share, which a distance bound keeps below the margin of every threshold
(:func:`_closed_part_numbers`), so those cells are decided as the exact ``w`` would be.
:func:`closed_surface_estimate` refines the grid of a closed surface until the bound is useful.  The bounds
follow from the volume in doubt as :mod:`~.uncertainty` states.
"""

from __future__ import annotations

import numpy as np

from .rims import boundary_edges, enclosing_balls
from .uncertainty import Estimate, Uncertainty, uncertainty_from

__all__ = ["winding_estimate", "closed_surface_estimate"]


#: Grid resolution of the winding estimate without libigl: the numpy treecode costs a few hundred exact
#: solid angles per cell whatever the face count, so 24 cells along the longest side (~17k cells) keeps a
#: repair under a few seconds on two cores; the bounds are about 2.5 times wider than at libigl's 64.
TREECODE_RESOLUTION = 24


def _cube_moments(centres: np.ndarray, h: float,
                  weight: np.ndarray | None = None) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centroid and central second moment of disjoint cubes of side h, each counted ``weight`` times
    (1 when omitted; a cube counted half is half its material)."""
    wt = np.ones(len(centres)) if weight is None else np.asarray(weight, dtype=np.float64)
    vol = float(wt.sum()) * h ** 3
    c = (wt[:, None] * centres).sum(axis=0) / wt.sum()
    d = centres - c
    second = h ** 3 * ((wt[:, None] * d).T @ d) + vol * h ** 2 / 12.0 * np.eye(3)
    return vol, c, second


def _surface_cells(vertices: np.ndarray, faces: np.ndarray, lo: np.ndarray, h: float, dims: tuple[int, ...],
                   spacing: float = 0.5) -> np.ndarray:
    """(cells,) bool: every cell the surface passes through (and a thin margin around it).

    Each triangle is sampled on a barycentric grid whose sub-triangles have edges of at most
    ``δ = spacing · h``, so every point of the surface lies within ``δ`` of a sample; a cell the surface
    crosses therefore meets the cube of half-side ``δ`` around some sample, and the cells those cubes touch
    are marked (a cube no larger than a cell touches exactly the cells holding its 8 corners).
    """
    v = vertices
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    delta = spacing * h
    if 2 * delta > h:
        raise ValueError(f"expected a sample spacing of at most half a cell, got {spacing}")
    longest = np.max(np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                               np.linalg.norm(a - c, axis=1)]), axis=0)
    steps = np.maximum(1, np.ceil(longest / delta).astype(np.int64))
    limit = np.array(dims) - 1
    # the cell of each cube's lowest corner; the cube (side 2δ ≤ h) reaches at most one cell further along
    # each axis, so marking those cells and then each marked cell's 7 upper neighbours covers every cell
    # the cube touches (a superset only where a cube ends exactly on a cell face)
    low = np.zeros(int(np.prod(dims)), dtype=bool)
    from .._native import accel
    lib = accel()
    if lib is not None and int(steps.max(initial=1)) <= 1 << 20:
        # the same samples and cells in C (_accel.c section 10), without the (triangles, samples, 3) blocks
        origin = lo + delta
        lib.sample_cells(np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(faces, dtype=np.int64),
                         np.ascontiguousarray(steps, dtype=np.int64), tuple(float(x) for x in origin), float(h),
                         tuple(int(d) for d in dims), low.view(np.uint8))
        steps = steps[:0]                   # done: the numpy loop below (the fallback) has no faces left
    for n in np.unique(steps):
        sel = np.flatnonzero(steps == n)
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        s, t = (i[keep] / n), (j[keep] / n)
        per = max(1, (1 << 20) // len(s))
        for k in range(0, len(sel), per):
            ids = sel[k:k + per]
            pts = (a[ids, None] * (1 - s - t)[None, :, None] + b[ids, None] * s[None, :, None]
                   + c[ids, None] * t[None, :, None]).reshape(-1, 3)
            idx = np.minimum(np.maximum(np.floor((pts - (lo + delta)) / h).astype(np.int64), 0), limit)
            low[(idx[:, 0] * dims[1] + idx[:, 1]) * dims[2] + idx[:, 2]] = True
    grid = low.reshape(dims)
    for axis in range(3):
        ahead = [slice(None)] * 3
        behind = [slice(None)] * 3
        ahead[axis], behind[axis] = slice(1, None), slice(None, -1)
        grid[tuple(ahead)] |= grid[tuple(behind)]
    marked: np.ndarray = grid.reshape(-1)
    return marked


#: Largest cone cap (triangles) for which :func:`_closed_part_numbers` is tried; beyond it (a soup whose
#: boundary is most of its edges) every free cell is evaluated.
CAP_FACES_LIMIT = 20000
#: Most boundary components for which the cells' distances to every cap are bounded.
CAP_LOOPS_LIMIT = 512
#: Most (cell, cap) pairs bounded one by one; cells beyond it are evaluated instead.
CAP_BOUND_WORK = 20_000_000
#: Most regions whose one winding number each is taken from the bounded treecode (a proven error bound, about
#: 1 ms per point at 8k faces) rather than from libigl's approximation (no proven bound).
BOUNDED_REGION_POINTS = 4096


def _cap_bound(points: np.ndarray, reach: float, ball_centre: np.ndarray, ball_radius: np.ndarray,
               cap_area: np.ndarray) -> np.ndarray:
    """(p,) bound on ``|w_C|`` at every point within ``reach`` m of each of ``points``: Σ over the cones of
    ``A / (4π s²)``, ``s`` the distance from the point to the cone's ball less ``reach`` (∞ where s ≤ 0)."""
    bound = np.zeros(len(points))
    per = max(1, (1 << 22) // max(len(points), 1))
    for k in range(0, len(ball_radius), per):
        delta = points[:, None, :] - ball_centre[None, k:k + per, :]
        gap = np.sqrt(np.einsum("pki,pki->pk", delta, delta)) - ball_radius[None, k:k + per] - reach
        with np.errstate(divide="ignore"):
            share = np.where(gap > 0, cap_area[None, k:k + per] / (4 * np.pi * np.maximum(gap, 1e-300) ** 2),
                             np.inf)
        bound += share.sum(axis=1)
    return bound


def _closed_part_numbers(vertices: np.ndarray, faces: np.ndarray, centres: np.ndarray, crossed: np.ndarray,
                         lo: np.ndarray, h: float, dims: tuple[int, ...], *, fast: bool, margin: float
                         ) -> tuple[np.ndarray, np.ndarray] | None:
    """Winding numbers of the cells far from the surface's holes without evaluating them one by one.

    Close the surface ``S`` by a cone ``C`` over each component of its boundary (apex at the centroid of the
    component's vertices; a component of the net boundary is balanced at every vertex, so the cone over it
    has exactly that boundary, reversed).  ``S + C`` is a cycle, so its winding number is an integer,
    constant on each connected region of space it does not meet, and ``w_S = w_{S+C} − w_C``.  Cells that
    neither ``S`` nor ``C`` crosses are grouped into face-connected regions (two such neighbouring cubes
    form a box that meets neither surface); ``w_{S+C}`` is found once per region, at one cell, from
    ``w_S + w_C`` rounded (refused, returning None, when that is more than 1/4 from an integer, counting the
    error bound of :func:`~.winding.winding_numbers_bounded`, used for ``w_S`` when libigl would be and there
    are at most ``BOUNDED_REGION_POINTS`` regions; ``w_C`` is the exact direct sum).  A triangle
    of area ``a`` at distance at least ``s`` subtends a solid angle of at most ``a/s²``; each cone lies in the
    ball enclosing its rim (:func:`enclosing_balls`: the apex is in the rim's convex hull), so at a cell at
    distance ``s`` from the ball ``|w_C| ≤ A_C / (4π s²)``.  Where the sum of these bounds over the cones is
    below ``margin`` (= ``min(w_low, 1 − w_high)``), the cell's ``w`` lies within ``margin`` of the region's
    integer and every threshold of :func:`winding_estimate` decides it as the exact value would: it is
    *settled* with that integer.  Every other free cell is left to the caller to evaluate.

    Returns
    -------
    settled : (cells,) bool
        Cells given a value here.
    value : (cells,) float
        The integer of each settled cell's region (0 elsewhere).
    None
        When the caps are too large to help or a region's integer is uncertain.
    """
    from scipy import ndimage
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .winding import winding_numbers, winding_numbers_bounded

    v, f = vertices, faces
    edges = boundary_edges(f, len(v))
    if len(edges) > CAP_FACES_LIMIT:
        return None
    if len(edges):
        n = len(v)
        graph = coo_matrix((np.ones(len(edges), dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n))
        _, vertex_label = connected_components(graph, directed=False)
        _, label = np.unique(vertex_label[edges[:, 0]], return_inverse=True)
        label = label.reshape(-1)
        n_loops = int(label.max()) + 1
        if n_loops > CAP_LOOPS_LIMIT:
            return None
        pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
        size = np.bincount(pairs[:, 0], minlength=n_loops)
        apex = np.stack([np.bincount(pairs[:, 0], weights=v[pairs[:, 1], i], minlength=n_loops)
                         for i in range(3)], axis=1) / size[:, None]
        ball_centre, ball_radius = enclosing_balls(v[pairs[:, 1]], pairs[:, 0], n_loops)
        cap_v = np.vstack([v, apex])
        cap_f = np.stack([edges[:, 1], edges[:, 0], n + label], axis=1)
        ca, cb, cc = cap_v[cap_f[:, 0]], cap_v[cap_f[:, 1]], cap_v[cap_f[:, 2]]
        cap_area = np.bincount(label, weights=0.5 * np.linalg.norm(np.cross(cb - ca, cc - ca), axis=1),
                               minlength=n_loops)
        on_cap = _surface_cells(cap_v, cap_f, lo, h, dims)
    else:
        n_loops, on_cap = 0, np.zeros(len(centres), dtype=bool)
    open_cells = ~crossed & ~on_cap
    region, n_regions = ndimage.label(open_cells.reshape(dims))
    region = region.reshape(-1)
    value = np.zeros(len(centres))
    settled = np.zeros(len(centres), dtype=bool)
    if n_regions == 0:
        return settled, value
    _, first = np.unique(region, return_index=True)
    first = first[1:] if region[first[0]] == 0 else first           # one cell of each region (0 = none)
    if fast and len(first) <= BOUNDED_REGION_POINTS:
        # one point per region: the treecode's proven error bound instead of libigl's unbounded approximation
        w_s, w_err = winding_numbers_bounded(centres[first], v, f)
    else:
        w_s, w_err = winding_numbers(centres[first], v, f, fast=fast), np.zeros(len(first))
    w_c = winding_numbers(centres[first], cap_v, cap_f, fast=False) if n_loops else np.zeros(len(first))
    total = w_s + w_c
    whole = np.round(total)
    if np.any(np.abs(total - whole) + w_err > 0.25):
        return None
    cells = np.flatnonzero(open_cells)
    if n_loops:
        # first per block of 4×4×4 cells (every centre within 1.5·√3·h of the block's), then cell by cell
        # where the block's bound is not enough and the work stays within CAP_BOUND_WORK
        nb = tuple(-(-d // 4) for d in dims)
        blocks = np.stack(np.meshgrid(*[np.arange(m) for m in nb], indexing="ij"), axis=-1).reshape(-1, 3)
        block_bound = _cap_bound(lo + h * (4 * blocks + 2), 1.5 * np.sqrt(3) * h, ball_centre, ball_radius,
                                 cap_area)
        i, j, k = np.unravel_index(cells, dims)
        fine = block_bound[((i // 4) * nb[1] + j // 4) * nb[2] + k // 4] < margin
        rest = np.flatnonzero(~fine)
        if len(rest) * n_loops <= CAP_BOUND_WORK:
            fine[rest] = _cap_bound(centres[cells[rest]], 0.0, ball_centre, ball_radius, cap_area) < margin
        ok = cells[fine]
    else:
        ok = cells
    value[ok] = whole[region[ok] - 1]
    settled[ok] = True
    return settled, value


def winding_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64, w_low: float = 0.1,
                     w_high: float = 0.9, fast: bool | None = None, tolerance: float = 2e-3) -> Estimate:
    """Material where the generalized winding number exceeds 1/2, on a grid, with the doubtful cells as bounds.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    resolution : int
        Cells along the longest side of the bounding box (the grid is padded by one cell); at most
        :data:`TREECODE_RESOLUTION` without libigl.
    w_low, w_high : float
        Cells with ``w_low < w < w_high`` are doubtful, as are cells the surface passes through.
    fast : bool, optional
        libigl's evaluation (default when installed) or, with ``False`` or without libigl, the numpy
        treecode (:func:`~.winding.winding_numbers_bounded`), whose error bound per cell is honoured: a cell
        whose bound could carry its ``w`` across 1/2 from outside the doubtful band is doubtful too.
    tolerance : float
        Error allowed per cluster of the treecode (the per-cell bound is the sum over the clusters used).

    Returns
    -------
    Estimate
    """
    from .winding import fast_available, winding_numbers, winding_numbers_bounded

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    use_igl = fast_available() if fast is None else (fast and fast_available())
    n = int(resolution) if use_igl else min(int(resolution), TREECODE_RESOLUTION)
    h = float(np.max(hi - lo)) / n
    lo = lo - h
    dims = tuple(int(x) for x in np.ceil((hi + h - lo) / h).astype(np.int64))
    axes = [lo[i] + h * (np.arange(dims[i]) + 0.5) for i in range(3)]
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    crossed = _surface_cells(v, f, lo, h, dims)
    w = np.full(len(centres), 0.5)                  # cells the surface crosses: half material, half in doubt
    err = np.zeros(len(centres))
    free = np.flatnonzero(~crossed)
    known = _closed_part_numbers(v, f, centres, crossed, lo, h, dims, fast=use_igl,
                                 margin=min(w_low, 1.0 - w_high)) if use_igl else None
    if known is not None:
        # cells far from every cap take the integer of their component; the others are evaluated
        settled, value = known
        w[free] = value[free]
        ask = free[~settled[free]]
        w[ask] = winding_numbers(centres[ask], v, f, fast=True)
    elif use_igl:
        w[free] = winding_numbers(centres[free], v, f, fast=True)
    else:
        w[free], err[free] = winding_numbers_bounded(centres[free], v, f, tolerance=tolerance)
    if np.sum(w[w > 0.5]) < np.sum(-w[w < -0.5]):
        w = -w                                      # the surface is inside out as a whole
    material = np.where(crossed, 0.5, (w > 0.5).astype(np.float64))
    doubtful = np.where(crossed, 0.5, (((w > w_low) & (w < w_high))
                                       | (err >= min(0.5 - w_low, w_high - 0.5))).astype(np.float64))
    area = float(0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum())
    if not np.any(material[~crossed]):
        zero = np.zeros(3)
        return Estimate(0.0, zero, np.zeros((3, 3)), area, Uncertainty(np.inf, np.inf, np.inf, 0.0), "winding",
                        "no grid cell has a winding number above 1/2", v, f)
    vol, c, second = _cube_moments(centres[material > 0], h, material[material > 0])
    doubt = float(np.sum(doubtful)) * h ** 3
    # each doubtful cell's points lie within its centre's distance + half its diagonal of the centroid; the
    # difference between true and estimated material there is at most its weight (1/2 crossed, 1 ambiguous)
    reach = np.linalg.norm(centres[doubtful > 0] - c, axis=1) + h * np.sqrt(3) / 2
    far = float(np.max(reach)) if doubtful.any() else 0.0
    cell_doubt = doubtful[doubtful > 0] * h ** 3
    unc = uncertainty_from(vol, c, second, doubt, far, first_doubt=float(np.sum(cell_doubt * reach)),
                           second_doubt=float(np.sum(cell_doubt * reach ** 2)))
    how = "libigl fast winding numbers" if use_igl else "winding numbers by a treecode with an error bound"
    detail = (f"winding number > 1/2 on a {dims[0]}×{dims[1]}×{dims[2]} grid of {h:.3g} m cells ({how}); "
              f"{int(np.count_nonzero(crossed)):,} cells crossed by the surface counted half, "
              f"{int(np.count_nonzero(doubtful[~crossed])):,} more undecided")
    return Estimate(volume=vol, centroid=c, second_moment=second, area=area, uncertainty=unc, method="winding",
                    detail=detail, vertices=v, faces=f, far=far)


#: Closed-surface estimate (:func:`closed_surface_estimate`): the mass bound it refines towards, relative.
CLOSED_TARGET_MASS_RTOL = 0.05
#: Finest grid of the closed-surface estimate, cells along the longest side (one refinement pass at most): the
#: dense grid's arrays dominate the cost, ~6 s of CPU for a near-cubic part at 224 (qb_move: 9.7 s at 256).
CLOSED_MAX_RESOLUTION = 224


def closed_surface_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                            target: float = CLOSED_TARGET_MASS_RTOL,
                            max_resolution: int = CLOSED_MAX_RESOLUTION) -> Estimate:
    """The solid ``{w ≥ 1}`` of a closed, edge-balanced surface that passes through itself, on a grid, with an
    assumption-free bound.

    For a surface whose every directed edge is matched by its reverse (a 2-cycle), the winding number ``w``
    is an integer at every point off the surface, constant on each connected region of space the surface
    does not meet.  On a grid of cubes, a cell the surface crosses is *undecided*
    (:func:`_surface_cells` marks a superset of them); the other cells form face-connected regions, each
    given the integer of one of its cells (:func:`_closed_part_numbers`: evaluated there and rounded,
    refused when more than 1/4 from an integer — then every free cell is evaluated and thresholded with
    the margins of :func:`winding_estimate`).  With ``D`` the decided cells with ``w ≥ 1`` and ``U`` the
    undecided ones, the true solid ``S`` satisfies ``D ⊆ S ⊆ D ∪ U`` **with no assumption** on the
    surface.  The estimate is ``D`` plus half of ``U`` (each undecided cell counted half), so its volume is
    within ``|U|/2`` of the truth, and the mass, centre-of-mass and inertia bounds of
    :func:`uncertainty_from` follow from ``δV = |U|/2`` lying within ``far`` of the centroid (the
    difference between truth and estimate is a signed density of at most 1/2 on ``U``).

    The grid has ``resolution`` cells along the longest side; when the mass bound exceeds ``target``, it is
    built once more at ``resolution · bound / target`` cells (the undecided volume of a surface shrinks as
    the cell size), at most ``max_resolution`` (exactly that when no cell was decided inside, a part thinner
    than the cells), and that second grid is the answer (chosen by this rule, not by which bound is smaller).

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        Edge-balanced (closed) surface; the caller checks.
    resolution, target, max_resolution
        As above.

    Returns
    -------
    Estimate
        ``method`` ``"winding"``.
    """
    first = winding_estimate(vertices, faces, resolution=resolution)
    bound = first.uncertainty.mass
    if resolution >= max_resolution or (np.isfinite(bound) and bound <= target):
        return first
    # no cell decided inside (a part thinner than the cells) or no finite bound: the finest grid
    finer = max_resolution if not (np.isfinite(bound) and first.volume > 0) else \
        int(min(max_resolution, np.ceil(resolution * bound / target)))
    if finer <= resolution:
        return first
    second = winding_estimate(vertices, faces, resolution=finer)
    return second if second.detail != first.detail else first
