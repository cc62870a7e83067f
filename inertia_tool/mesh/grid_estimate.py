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

from typing import TYPE_CHECKING, Literal, NamedTuple, overload

import numpy as np

from ..errors import InternalInvariantError, WorkBudgetError
from ..tolerances import ESTIMATE_MAX_MASS_RTOL
from .rims import boundary_edges, enclosing_balls
from .uncertainty import Estimate, Uncertainty, uncertainty_from

if TYPE_CHECKING:
    from .winding import IntegerTree

__all__ = ["winding_estimate", "closed_surface_estimate", "open_surface_estimate", "corrected_estimate",
           "predicted_resolution", "affordable_resolution", "refusal_proven", "WINDING_EVALUATION_BUDGET",
           "TURNED_READING"]


#: Most grid cells whose winding number :func:`winding_estimate` evaluates one by one (libigl's hierarchical
#: evaluation, one call per cell): the work is counted before it is done and refused past this budget
#: (:class:`~inertia_tool.errors.WorkBudgetError`), never timed, so the answer is the same on every machine.
#: A 64-cell grid never reaches it (at most 66³ ≈ 287k cells); refinements are sized to stay within it
#: (:func:`open_surface_estimate`, :func:`closed_surface_estimate`).  At the 10–40 µs an evaluation near a
#: CAD part's surface costs (libigl, 2 cores at load 2–20), about 4–16 s of CPU; issue 23: ALOHA's
#: ``vx300s_7_gripper_prop.stl`` asked for 1,181,078 (44 s of CPU) and was then refused for its holes' doubt.
WINDING_EVALUATION_BUDGET = 400_000

#: Grid resolution of the winding estimate without libigl: the numpy treecode costs a few hundred exact
#: solid angles per cell whatever the face count, so 24 cells along the longest side (~17k cells) keeps a
#: repair under a few seconds on two cores; the bounds are about 2.5 times wider than at libigl's 64.
TREECODE_RESOLUTION = 24


def _cell_centres(cells: np.ndarray, lo: np.ndarray, h: float, dims: tuple[int, ...]) -> np.ndarray:
    """(k, 3) m: the centres of the cells with flat (C-order) indices ``cells`` of the grid ``lo``, ``h``,
    ``dims`` (the grid's centres are never stored whole: 24 bytes a cell)."""
    centres: np.ndarray = lo + h * (np.stack(np.unravel_index(np.asarray(cells, dtype=np.int64), dims), axis=1)
                                    + 0.5)
    return centres


def _grid_moments(weight: np.ndarray, lo: np.ndarray, h: float, scale: float = 1.0
                  ) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centroid and central second moment of the cubes of a grid, cube ``(i, j, k)`` counted
    ``scale · weight[i, j, k]`` times (a cube counted half is half its material), from the grid's marginal sums.

    ``weight`` is (d0, d1, d2), small integers (0, 1, 2).  With ``x_a`` the centre coordinate along axis ``a``
    (``lo_a + h (i_a + ½)``), ``Σ w x_a`` needs only the sums of ``w`` over the other two axes and
    ``Σ w x_a x_b`` only the sums over the third, so no per-cell coordinates are formed; the sums are taken
    about the centroid (centred coordinates).  A cube of side ``h`` adds ``h²/12`` times its volume to each
    diagonal second moment about its own centre (parallel-axis theorem, Eq. 4.16 of Chapter 4, "Rigid Body
    Motion").
    """
    w = weight
    plane = [w.sum(axis=2, dtype=np.float64), w.sum(axis=1, dtype=np.float64), w.sum(axis=0, dtype=np.float64)]
    line = [plane[0].sum(axis=1), plane[0].sum(axis=0), plane[1].sum(axis=0)]   # over (1, 2), (0, 2), (0, 1)
    total = float(line[0].sum())
    coords = [lo[a] + h * (np.arange(w.shape[a]) + 0.5) for a in range(3)]
    c = np.array([float(line[a] @ coords[a]) / total for a in range(3)])
    x = [coords[a] - c[a] for a in range(3)]
    second = np.empty((3, 3))
    for a in range(3):
        second[a, a] = float(line[a] @ (x[a] * x[a]))
    second[0, 1] = second[1, 0] = float(x[0] @ plane[0] @ x[1])
    second[0, 2] = second[2, 0] = float(x[0] @ plane[1] @ x[2])
    second[1, 2] = second[2, 1] = float(x[1] @ plane[2] @ x[2])
    vol = scale * total * h ** 3
    second = scale * h ** 3 * second + vol * h ** 2 / 12.0 * np.eye(3)
    return vol, c, second


def _surface_cells(vertices: np.ndarray, faces: np.ndarray, lo: np.ndarray, h: float, dims: tuple[int, ...]
                   ) -> np.ndarray:
    """(cells,) bool: every cell of the grid ``lo``, ``h``, ``dims`` (C order) whose closed box the surface meets.

    Each triangle is clipped to the slabs of cells it reaches along x, the pieces to the rows along y, and the
    cells between each row piece's least and greatest z are marked (:func:`_clipped_cells`; ``_accel.c``
    section 10 when built, the same operations in the same order).  Clipped with a margin of
    ``ε = 2⁻⁴⁰ (1 + the largest |coordinate| of the triangle in cells)``, far above the clipping's round-off, so the
    set holds every cell the triangle meets and no cell farther than ``2ε`` cells from it: a function of the
    geometry, not of a sampling density, and the work is the slabs, rows and cells the triangle crosses.  A
    surface off the grid marks the cell it would be clamped to (the first and last cell of each axis reach to
    infinity).  The marking of a set of faces is the union of its faces' markings.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not np.all(np.isfinite(v[f])):
        raise ValueError("expected finite vertices for the surface's cells, got NaN or infinity")
    marked = np.zeros(int(np.prod(dims)), dtype=bool)
    from .._native import accel
    lib = accel()
    if lib is not None:
        lib.surface_cells(np.ascontiguousarray(v), np.ascontiguousarray(f), tuple(float(x) for x in lo), float(h),
                          tuple(int(d) for d in dims), marked.view(np.uint8))
        return marked
    for start in range(0, len(f), 4096):
        tri = (v[f[start:start + 4096]] - np.asarray(lo, dtype=np.float64)) / float(h)
        if not np.all(np.isfinite(tri)):
            raise ValueError("expected finite corners in cells of the grid, got an overflow")
        _clipped_cells(tri, dims, marked)
    return marked


def _clip_polygons(poly: np.ndarray, count: np.ndarray, axis: int, bound: np.ndarray, above: bool,
                   active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sutherland–Hodgman clips of the polygons ``poly`` ((p, K, 3), the first ``count[i]`` rows of each in order)
    to ``u[axis] ≥ bound`` (``above``) or ``≤ bound``, only where ``active`` ((p,) bool; elsewhere unchanged):
    ``(polygons (p, K', 3), counts (p,))``.  Each edge ``P → Q`` gives ``P`` when inside and, when it crosses,
    ``P + t (Q − P)`` with ``t = (bound − P_a) / (Q_a − P_a)`` and that coordinate set to ``bound``: the
    operations of ``_accel.c``'s ``sc_clip`` in its order, so the vertices are the kernel's to the bit."""
    p, k = poly.shape[:2]
    slot = np.arange(k)
    valid = slot[None, :] < count[:, None]
    nxt = np.where(slot[None, :] + 1 < count[:, None], slot[None, :] + 1, 0)
    q = np.take_along_axis(poly, nxt[:, :, None], axis=1)
    b = bound[:, None]
    if above:
        in_p, in_q = poly[:, :, axis] >= b, q[:, :, axis] >= b
    else:
        in_p, in_q = poly[:, :, axis] <= b, q[:, :, axis] <= b
    cross = valid & (in_p != in_q) & active[:, None]
    keep = valid & (in_p | ~active[:, None])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(cross, (b - poly[:, :, axis]) / np.where(cross, q[:, :, axis] - poly[:, :, axis], 1.0), 0.0)
    meet = poly + t[:, :, None] * (q - poly)
    meet[:, :, axis] = np.broadcast_to(b, (p, k))
    both = np.stack([poly, meet], axis=2).reshape(p, 2 * k, 3)     # P then its crossing, edge by edge
    emit = np.stack([keep, cross], axis=2).reshape(p, 2 * k)
    new_count = emit.sum(axis=1)
    order = np.argsort(~emit, axis=1, kind="stable")               # the emitted ones first, in order
    width = max(1, int(new_count.max(initial=0)))
    out = np.take_along_axis(both, order[:, :width, None], axis=1)
    return out, new_count


def _cell_range(low: np.ndarray, high: np.ndarray, cells: int) -> tuple[np.ndarray, np.ndarray]:
    """``(first, last)`` (int64): the cells ``floor(low)`` … ``floor(high)`` clamped to ``0 … cells − 1``."""
    top = float(cells - 1)
    first = np.clip(np.floor(low), 0.0, top).astype(np.int64)
    last = np.clip(np.floor(high), 0.0, top).astype(np.int64)
    return first, last


def _clipped_cells(tri: np.ndarray, dims: tuple[int, ...], marked: np.ndarray) -> None:
    """Mark in ``marked`` ((cells,) bool, C order) every cell the triangles ``tri`` ((t, 3, 3), in grid units:
    ``(p − lo) / h``) meet, as :func:`_surface_cells` states: each triangle clipped to ``i − ε ≤ u₀ ≤ i + 1 + ε``
    for each slab ``i`` it reaches, each piece to ``j − ε ≤ u₁ ≤ j + 1 + ε`` for each row ``j``, and the cells
    ``floor(z_min − ε) … floor(z_max + ε)`` of each row piece marked (the first and last slab, row and cell
    unbounded outward).  The numpy twin of ``_accel.c`` section 10: the same operations in the same order."""
    n0, n1, n2 = (int(d) for d in dims)
    if len(tri) == 0:
        return
    eps = (1.0 + np.abs(tri).reshape(len(tri), -1).max(axis=1)) * 2.0 ** -40
    i0, i1 = _cell_range(tri[:, :, 0].min(axis=1) - eps, tri[:, :, 0].max(axis=1) + eps, n0)
    # (triangle, slab) pairs
    many = i1 - i0 + 1
    owner = np.repeat(np.arange(len(tri)), many)
    slab = np.repeat(i0, many) + (np.arange(int(many.sum())) - np.repeat(np.cumsum(many) - many, many))
    e = eps[owner]
    poly, count = tri[owner], np.full(len(owner), 3)
    poly, count = _clip_polygons(poly, count, 0, slab.astype(np.float64) - e, True, slab > 0)
    poly, count = _clip_polygons(poly, count, 0, (slab + 1).astype(np.float64) + e, False,
                                 (slab < n0 - 1) & (count > 0))
    live = count > 0
    poly, count, slab, e = poly[live], count[live], slab[live], e[live]
    width = poly.shape[1]
    filled = np.arange(width)[None, :] < count[:, None]
    j0, j1 = _cell_range(np.where(filled, poly[:, :, 1], np.inf).min(axis=1) - e,
                         np.where(filled, poly[:, :, 1], -np.inf).max(axis=1) + e, n1)
    # (slab piece, row) pairs
    many = j1 - j0 + 1
    owner = np.repeat(np.arange(len(poly)), many)
    row = np.repeat(j0, many) + (np.arange(int(many.sum())) - np.repeat(np.cumsum(many) - many, many))
    e, slab = e[owner], slab[owner]
    poly, count = poly[owner], count[owner]
    poly, count = _clip_polygons(poly, count, 1, row.astype(np.float64) - e, True, (row > 0) & (count > 0))
    poly, count = _clip_polygons(poly, count, 1, (row + 1).astype(np.float64) + e, False,
                                 (row < n1 - 1) & (count > 0))
    live = count > 0
    poly, count, slab, row, e = poly[live], count[live], slab[live], row[live], e[live]
    width = poly.shape[1]
    filled = np.arange(width)[None, :] < count[:, None]
    k0, k1 = _cell_range(np.where(filled, poly[:, :, 2], np.inf).min(axis=1) - e,
                         np.where(filled, poly[:, :, 2], -np.inf).max(axis=1) + e, n2)
    many = k1 - k0 + 1
    base = (slab * n1 + row) * n2
    cell = np.repeat(base + k0, many) + (np.arange(int(many.sum())) - np.repeat(np.cumsum(many) - many, many))
    marked[cell] = True


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
#: Most (region point, face) pairs for which the regions' winding numbers are the exact sum over every face
#: instead of the treecode (whose tree costs ~0.1 s for 40k faces; the sum ~0.035 s for three points of them).
DIRECT_REGION_WORK = 250_000


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


class _Regions(NamedTuple):
    """The settled cells of :func:`_closed_part_numbers` as their regions (``per_cell=False``): a cell's value
    is ``whole[region[cell]]`` where it is ``settled``, without a (cells,) array of values."""

    settled: np.ndarray     #: (cells,) bool: cells given their region's integer
    region: np.ndarray      #: (cells,) int: the region of each free cell off the caps, 1…; 0 elsewhere
    whole: np.ndarray       #: (regions + 1,) float64: 0, then the integer winding number of each region
    sizes: np.ndarray | None = None     #: (regions,) int64: the cells of each region, when the labels gave them


def _label_regions(cells: np.ndarray, dims: tuple[int, ...]
                   ) -> tuple[np.ndarray, int, np.ndarray | None, np.ndarray | None]:
    """The face-connected regions of the true ``cells`` ((cells,) bool, the grid ``dims`` in C order), numbered
    1… in the order of their first cells (0 off them) as ``scipy.ndimage.label`` numbers them with its default
    structure: ``(labels (cells,) int32, count, first cells (count,) int64 or None, cells of each region
    (count,) int64 or None)``.

    The C kernel (``_accel.c`` section 11, which also gives each region's first cell and size) when built;
    otherwise scipy's (the first cells are then left to :func:`_first_cells`, the sizes to a count).
    scipy.ndimage was imported for this alone on the repair's path (issue 23: ~0.15 s of CPU on top of its
    label, 0.25 s for UR5e's three grids; the kernel labels them in a sixth of scipy's time).
    """
    from .._native import accel

    lib = accel()
    if lib is not None and len(cells) < 2 ** 31 - 1:
        labels = np.empty(len(cells), dtype=np.int32)
        count, first, sizes = lib.label_cells(cells.view(np.uint8), tuple(int(d) for d in dims), labels)
        return labels, int(count), np.frombuffer(first, dtype=np.int64), np.frombuffer(sizes, dtype=np.int64)
    from scipy import ndimage

    region, n_regions = ndimage.label(cells.reshape(dims))
    flat: np.ndarray = region.reshape(-1)
    return flat, int(n_regions), None, None


def _first_cells(region: np.ndarray, n_regions: int) -> np.ndarray:
    """(n_regions,) int64: the first cell in C order of each region of ``region`` (labels 1…n_regions, 0 for
    no region).

    scipy's and the C labels number the regions in the order their first cells come (C order), so the running
    maximum of the labels first reaches ``k`` at region ``k``'s first cell; that is checked (the label found
    there must be ``k``: a cell where the maximum first reaches ``k`` or more, all before it below ``k``), and
    the regions are otherwise found by a scatter of every cell's index (the same cells, slower)."""
    if n_regions == 0:
        return np.zeros(0, dtype=np.int64)
    peak = np.maximum.accumulate(region)
    first = np.searchsorted(peak, np.arange(1, n_regions + 1, dtype=peak.dtype), side="left").astype(np.int64)
    del peak
    if np.array_equal(region[first], np.arange(1, n_regions + 1)):
        return first
    # one cell of each region by a scatter instead of numpy.unique's sort of every cell; written in reverse so
    # that, as numpy's repeated-index assignment keeps the last value written, it is the region's first cell
    first = np.empty(n_regions + 1, dtype=np.int64)
    step = 1 << 22
    for start in reversed(range(0, len(region), step)):        # in blocks, to hold no index of every cell
        labels = region[start:start + step]
        where = np.flatnonzero(labels)[::-1]
        first[labels[where]] = where + start
    scattered: np.ndarray = first[1:]
    return scattered


@overload
def _closed_part_numbers(vertices: np.ndarray, faces: np.ndarray, crossed: np.ndarray, lo: np.ndarray, h: float,
                         dims: tuple[int, ...], *, fast: bool, margin: float, per_cell: Literal[True] = ...
                         ) -> tuple[np.ndarray, np.ndarray] | None: ...


@overload
def _closed_part_numbers(vertices: np.ndarray, faces: np.ndarray, crossed: np.ndarray, lo: np.ndarray, h: float,
                         dims: tuple[int, ...], *, fast: bool, margin: float, per_cell: Literal[False]
                         ) -> _Regions | None: ...


def _closed_part_numbers(vertices: np.ndarray, faces: np.ndarray, crossed: np.ndarray,
                         lo: np.ndarray, h: float, dims: tuple[int, ...], *, fast: bool, margin: float,
                         per_cell: bool = True) -> tuple[np.ndarray, np.ndarray] | _Regions | None:
    """Winding numbers of the cells far from the surface's holes without evaluating them one by one.

    Close the surface ``S`` by a cone ``C`` over each component of its boundary (apex at the centroid of the
    component's vertices; a component of the net boundary is balanced at every vertex, so the cone over it
    has exactly that boundary, reversed).  ``S + C`` is a cycle, so its winding number is an integer,
    constant on each connected region of space it does not meet, and ``w_S = w_{S+C} − w_C``.  Cells that
    neither ``S`` nor ``C`` crosses are grouped into face-connected regions (two such neighbouring cubes
    form a box that meets neither surface); ``w_{S+C}`` is found once per region, at one cell, from
    ``w_S + w_C`` rounded (refused, returning None, when that is more than 1/4 from an integer, counting the
    error bound of :func:`~.winding.winding_numbers_bounded`, used for ``w_S`` when libigl would be and there
    are at most ``BOUNDED_REGION_POINTS`` regions, or the exact direct sum with its round-off bound when the
    regions' points times the faces are at most ``DIRECT_REGION_WORK``; ``w_C`` is the exact direct sum).  A triangle
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
    value : (cells,) float32
        The integer of each settled cell's region (0 elsewhere; small integers, exact in float32).
    _Regions
        With ``per_cell=False``: the settled cells, their regions and each region's integer instead of
        ``value`` (the caller that needs no per-cell values skips their array).
    None
        When the caps are too large to help or a region's integer is uncertain.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .winding import winding_integers, winding_numbers, winding_numbers_summed

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
        n_loops, on_cap = 0, np.zeros(len(crossed), dtype=bool)
    open_cells = ~crossed & ~on_cap
    del on_cap
    region, n_regions, first_cells, sizes = _label_regions(open_cells, dims)
    if n_regions == 0:
        if not per_cell:
            return _Regions(np.zeros(len(crossed), dtype=bool), region, np.zeros(1))
        return np.zeros(len(crossed), dtype=bool), np.zeros(len(crossed))
    # one cell of each region (any cell would do: the region's winding number is the same at all of them): the
    # first in C order
    first = _first_cells(region, n_regions) if first_cells is None else first_cells
    points = _cell_centres(first, lo, h, dims)
    w_c = winding_numbers(points, cap_v, cap_f, fast=False) if n_loops else np.zeros(len(first))
    if fast and len(first) * len(f) <= DIRECT_REGION_WORK:
        # one point per region, few enough for the exact sum over every face (its round-off bounded)
        w_s, w_err = winding_numbers_summed(points, v, f)
    elif fast and len(first) <= BOUNDED_REGION_POINTS:
        # one point per region: the treecode's proven error bound instead of libigl's unbounded approximation
        # (rounded below: a cheaper first pass where it settles the integer)
        w_s, w_err = winding_integers(points, v, f, offset=w_c)
    else:
        w_s, w_err = winding_numbers(points, v, f, fast=fast), np.zeros(len(first))
    total = w_s + w_c
    whole = np.round(total)
    if np.any(np.abs(total - whole) + w_err > 0.25):
        return None
    settled = open_cells
    if n_loops:
        # first per block of 4×4×4 cells (every centre within 1.5·√3·h of the block's), then cell by cell
        # where the block's bound is not enough and the work stays within CAP_BOUND_WORK
        nb = tuple(-(-d // 4) for d in dims)
        blocks = np.stack(np.meshgrid(*[np.arange(m) for m in nb], indexing="ij"), axis=-1).reshape(-1, 3)
        block_fine = (_cap_bound(lo + h * (4 * blocks + 2), 1.5 * np.sqrt(3) * h, ball_centre, ball_radius,
                                 cap_area) < margin).reshape(nb)
        fine = block_fine[np.ix_(*[np.arange(d) // 4 for d in dims])].reshape(-1)
        rest = np.flatnonzero(open_cells & ~fine)
        if len(rest) * n_loops <= CAP_BOUND_WORK:
            fine[rest] = _cap_bound(_cell_centres(rest, lo, h, dims), 0.0, ball_centre, ball_radius,
                                    cap_area) < margin
        settled = open_cells & fine
    if not per_cell:
        return _Regions(settled, region, np.concatenate([[0.0], whole]), sizes)
    value: np.ndarray = np.concatenate([[0.0], whole]).astype(np.float32)[region]     # small integers: exact
    value[~settled] = 0.0
    return settled, value


def winding_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64, w_low: float = 0.1,
                     w_high: float = 0.9, fast: bool | None = None, tolerance: float = 2e-3,
                     max_evaluations: int | None = None) -> Estimate:
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
    max_evaluations : int, optional
        Most cells whose winding number is evaluated one by one (default :data:`WINDING_EVALUATION_BUDGET`, read
        at the call); counted once the grid's crossed and settled cells are known, before any is evaluated.

    Returns
    -------
    Estimate

    Raises
    ------
    WorkBudgetError
        More than ``max_evaluations`` cells would be evaluated; ``details`` has ``evaluations``, ``budget`` and
        ``resolution``.
    """
    return _winding_grid(vertices, faces, resolution=resolution, w_low=w_low, w_high=w_high, fast=fast,
                         tolerance=tolerance, max_evaluations=max_evaluations).estimate


class _GridWork(NamedTuple):
    """A grid estimate and its work: ``evaluated`` cells whose winding number was evaluated one by one, and
    ``crossed`` cells the surface crosses (counted half, not evaluated; at a finer grid many become free)."""

    estimate: Estimate
    evaluated: int
    crossed: int


def _grid_shape(vertices: np.ndarray, resolution: int) -> tuple[np.ndarray, float, tuple[int, ...]]:
    """``(lo, h, dims)`` of the grid of ``resolution`` cells along the longest side of ``vertices``' box, padded
    by one cell each way (the grid of :func:`winding_estimate`)."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    h = float(np.max(hi - lo)) / int(resolution)
    lo = lo - h
    dims = tuple(int(x) for x in np.ceil((hi + h - lo) / h).astype(np.int64))
    return lo, h, dims


def _budget_refusal(evaluations: int, budget: int, resolution: int, dims: tuple[int, ...], faces: int,
                    crossed: int) -> WorkBudgetError:
    """The one-line refusal of a grid whose cells to evaluate exceed the budget."""
    return WorkBudgetError(
        f"the winding-number estimate would evaluate {evaluations:,} grid cells one by one ({dims[0]}×{dims[1]}×"
        f"{dims[2]} grid, {faces:,} triangles), more than its budget of {budget:,} evaluations; close the holes "
        "or the crossings in a mesh editor", details={"evaluations": evaluations, "budget": budget,
                                                       "resolution": resolution, "crossed": crossed})


#: What the estimate's detail (a note of the report) adds when the grid read the surface turned over as a whole
#: (:func:`_inside_out_as_a_whole`): the reading named, since ``{w ≥ 1}`` as wound is empty.
TURNED_READING = ("; the file's winding number is at least one nowhere (above 1/2 in no cell, below −1/2 in some), "
                  "so the solid {w ≥ 1} as wound is empty: the surface is read turned over as a whole (a body "
                  "written inside out), the solid {−w ≥ 1}")


def _inside_out_as_a_whole(positive: float, negative: float) -> bool:
    """Whether the grid reads the surface turned over: its winding is below −1/2 somewhere and above 1/2 nowhere
    (``positive``, ``negative``: the sums of the winding numbers above 1/2 and of minus those below −1/2).  Where
    the winding is positive in some places and negative in others no turn of the whole surface is the file's
    solid: the solid is where the winding number as wound is at least one (the issue's definition;
    turned, a box wound outward holding four crossing boxes wound inward, 0.172 m³, would read 0.261 ±11 %)."""
    return positive == 0.0 and negative > 0.0


def _cell_codes(w: np.ndarray, err: np.ndarray | None, crossed: np.ndarray, w_low: float, w_high: float
                ) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """The codes of :func:`_winding_grid` from every cell's winding number ``w`` (0.5 on crossed cells; turned
    over in place when the surface is inside out as a whole, :func:`_inside_out_as_a_whole`) and its error bound
    ``err`` (or None): twice the material (crossed 1, decided inside 2), twice the density in doubt (crossed 1,
    ambiguous 2), both (cells,) uint8, the number of free cells undecided, and whether the surface was read
    turned over (said in the estimate's detail: :data:`TURNED_READING`)."""
    turned = _inside_out_as_a_whole(float(np.sum(w[w > 0.5])), float(np.sum(-w[w < -0.5])))
    if turned:
        np.negative(w, out=w)                       # the surface is inside out as a whole
    material2 = np.where(crossed, np.uint8(1), (w > 0.5).astype(np.uint8) * np.uint8(2))
    ambiguous = (w > w_low) & (w < w_high)
    if err is not None:
        ambiguous |= err >= min(0.5 - w_low, w_high - 0.5)
    doubt2 = np.where(crossed, np.uint8(1), ambiguous.astype(np.uint8) * np.uint8(2))
    undecided = int(np.count_nonzero(ambiguous & ~crossed))
    return material2, doubt2, undecided, turned


def _region_codes(regions: _Regions, w_low: float, w_high: float) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """:func:`_cell_codes` where every free cell is settled by its region (``regions.region`` > 0 exactly on the
    free cells): each code is looked up by region, and the sums deciding whether the surface is inside out are
    each region's integer times its cell count.  They are the per-cell sums exactly (integers below 2⁵³ add
    without rounding in any order), so every code is the one :func:`_cell_codes` gives."""
    region, whole = regions.region, regions.whole.copy()
    if regions.sizes is not None:
        count = np.concatenate([[0.0], regions.sizes.astype(np.float64)])
    else:
        count = np.bincount(region, minlength=len(whole)).astype(np.float64)
    count[0] = 0.0                                  # the crossed cells: w = 1/2, in neither sum
    turned = _inside_out_as_a_whole(float(np.sum(count * np.where(whole > 0.5, whole, 0.0))),
                                    float(np.sum(count * np.where(whole < -0.5, -whole, 0.0))))
    if turned:
        np.negative(whole, out=whole)               # the surface is inside out as a whole
    material = np.where(whole > 0.5, 2, 0).astype(np.uint8)
    ambiguous = (whole > w_low) & (whole < w_high)
    doubt = np.where(ambiguous, 2, 0).astype(np.uint8)
    material[0] = doubt[0] = 1                      # label 0: the cells the surface crosses
    undecided = int(np.sum(count[ambiguous]))
    return material[region], doubt[region], undecided, turned


def _winding_grid(vertices: np.ndarray, faces: np.ndarray, *, resolution: int, w_low: float = 0.1,
                  w_high: float = 0.9, fast: bool | None = None, tolerance: float = 2e-3,
                  max_evaluations: int | None = None) -> _GridWork:
    """:func:`winding_estimate`, with the cells it evaluated one by one (the work its budget counts) and the
    cells the surface crosses."""
    budget = WINDING_EVALUATION_BUDGET if max_evaluations is None else int(max_evaluations)
    from .winding import fast_available, winding_numbers, winding_numbers_bounded

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    use_igl = fast_available() if fast is None else (fast and fast_available())
    n = int(resolution) if use_igl else min(int(resolution), TREECODE_RESOLUTION)
    lo, h, dims = _grid_shape(v, n)
    crossed = _surface_cells(v, f, lo, h, dims)
    n_crossed = int(np.count_nonzero(crossed))
    # the grid's per-cell arrays: crossed (bool), w (float64) and two uint8 codes, ~11 bytes a cell; the cell
    # centres are formed only for the cells evaluated and the cells in doubt.  When every free cell is settled
    # by its region (a closed surface: issue 23, UR5e), w is not formed: the codes come from the regions
    w = err = None
    regions = None
    known = _closed_part_numbers(v, f, crossed, lo, h, dims, fast=use_igl, margin=min(w_low, 1.0 - w_high),
                                 per_cell=False) if use_igl else None
    if known is not None:
        # cells far from every cap take the integer of their component; the others are evaluated
        free = ~crossed
        ask = np.flatnonzero(free & ~known.settled)
        evaluations = len(ask)
        if evaluations > budget:
            raise _budget_refusal(evaluations, budget, n, dims, len(f), n_crossed)
        if evaluations == 0:
            regions = known                         # every free cell is settled (so in a region, label > 0)
        else:
            w = np.full(len(crossed), 0.5)          # cells the surface crosses: half material, half in doubt
            value = known.whole.astype(np.float32)[known.region]       # small integers: exact
            value[~known.settled] = 0.0
            np.copyto(w, value, where=free)
            del value
            w[ask] = winding_numbers(_cell_centres(ask, lo, h, dims), v, f, fast=True)
        del known, free, ask
    else:
        w = np.full(len(crossed), 0.5)
        free_cells = np.flatnonzero(~crossed)
        evaluations = len(free_cells)
        if evaluations > budget:
            raise _budget_refusal(evaluations, budget, n, dims, len(f), n_crossed)
        points = _cell_centres(free_cells, lo, h, dims)
        if use_igl:
            w[free_cells] = winding_numbers(points, v, f, fast=True)
        else:
            err = np.zeros(len(crossed))
            w[free_cells], err[free_cells] = winding_numbers_bounded(points, v, f, tolerance=tolerance)
        del points, free_cells
    if regions is not None:
        material2, doubt2, undecided, turned = _region_codes(regions, w_low, w_high)
        del regions
    elif w is not None:
        material2, doubt2, undecided, turned = _cell_codes(w, err, crossed, w_low, w_high)
        del w, err
    else:                                           # every path above sets one of them
        raise InternalInvariantError("expected the winding numbers of the grid's cells or their regions, got "
                                     "neither")
    area = float(0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum())
    if not np.any(material2[~crossed]):
        zero = np.zeros(3)
        empty = Estimate(0.0, zero, np.zeros((3, 3)), area, Uncertainty(np.inf, np.inf, np.inf, 0.0), "winding",
                         "no grid cell has a winding number above 1/2" + (TURNED_READING if turned else ""), v, f)
        return _GridWork(empty, evaluations, n_crossed)
    vol, c, second = _grid_moments(material2.reshape(dims), lo, h, scale=0.5)
    del material2
    # each doubtful cell's points lie within its centre's distance + half its diagonal of the centroid; the
    # difference between true and estimated material there is at most its weight (1/2 crossed, 1 ambiguous)
    in_doubt = np.flatnonzero(doubt2)
    doubt = far = first_doubt = second_doubt = 0.0
    for start in range(0, len(in_doubt), 1 << 20):
        cells = in_doubt[start:start + (1 << 20)]
        reach = np.linalg.norm(_cell_centres(cells, lo, h, dims) - c, axis=1) + h * np.sqrt(3) / 2
        cell_doubt = 0.5 * doubt2[cells] * h ** 3
        doubt += float(cell_doubt.sum())
        far = max(far, float(reach.max()))
        first_doubt += float(np.sum(cell_doubt * reach))
        second_doubt += float(np.sum(cell_doubt * reach ** 2))
    unc = uncertainty_from(vol, c, second, doubt, far, first_doubt=first_doubt, second_doubt=second_doubt)
    how = "libigl fast winding numbers" if use_igl else "winding numbers by a treecode with an error bound"
    detail = (f"winding number > 1/2 on a {dims[0]}×{dims[1]}×{dims[2]} grid of {h:.3g} m cells ({how}); "
              f"{n_crossed:,} cells crossed by the surface counted half, "
              f"{undecided:,} more undecided" + (TURNED_READING if turned else ""))
    return _GridWork(Estimate(volume=vol, centroid=c, second_moment=second, area=area, uncertainty=unc,
                              method="winding", detail=detail, vertices=v, faces=f, far=far), evaluations, n_crossed)


#: Closed-surface estimate (:func:`closed_surface_estimate`): the mass bound it refines towards, relative.
CLOSED_TARGET_MASS_RTOL = 0.05
#: Finest grid of the closed-surface estimate, cells along the longest side (one refinement pass at most): the
#: dense grid's arrays dominate the cost, ~6 s of CPU for a near-cubic part at 224 (qb_move: 9.7 s at 256).
CLOSED_MAX_RESOLUTION = 224
#: The same budget as cells (a near-cubic part's grid at ``CLOSED_MAX_RESOLUTION``): an elongated or flat part
#: is refined further along its longest side for the same memory and time (TIAGo's gripper finger,
#: 0.033 × 0.060 × 0.165 m: 10.1M cells at 512, mass bound ±22.5 %; at 224: 0.9M cells, ±50.9 %).
CLOSED_MAX_CELLS = (CLOSED_MAX_RESOLUTION + 2) ** 3
#: :func:`closed_surface_estimate` builds a second grid only when the one at the predicted resolution misses the
#: target by more than this factor (the prediction takes the signed volume, which counts the overlap of two
#: bodies twice; on UR5e's visual meshes it lands within 1.2× of the target).
CLOSED_PREDICTION_SLACK = 1.25
#: Cell budget of :func:`open_surface_estimate`'s second grid: a quarter of the closed one, since near holes
#: each cell's winding number is evaluated one by one (TIAGo's ``gripper_link.stl``, 225 holes: 27.6 s of CPU
#: at 160 cells along its longest side under load 11, mass bound ±46.6 %; at 258, the closed budget, 128 s).
OPEN_MAX_CELLS = CLOSED_MAX_CELLS // 4


def budget_resolution(vertices: np.ndarray, max_cells: int = CLOSED_MAX_CELLS) -> int:
    """The most cells along the longest side whose padded grid (one cell each way) holds at most ``max_cells``
    cells, never fewer than 8."""
    extent = np.ptp(np.asarray(vertices, dtype=np.float64), axis=0)
    share = extent / max(float(extent.max()), np.finfo(float).tiny)
    n = max(8, int(np.cbrt(max_cells / max(float(np.prod(np.maximum(share, 1e-6))), 1e-18))))
    for _ in range(256):                     # the padding (2 cells per axis) may push it over: step down
        if n <= 8 or float(np.prod(np.ceil(share * n) + 2)) <= max_cells:
            break
        n -= max(1, n // 100)
    return max(8, min(n, 4096))


def closed_surface_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                            target: float = CLOSED_TARGET_MASS_RTOL, max_resolution: int | None = None,
                            max_evaluations: int | None = None, added_doubt: float = 0.0) -> Estimate:
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

    One grid is built, at the resolution where the bound is expected to meet ``target``
    (:func:`predicted_resolution`: from the cells the surface crosses on a grid of ``resolution`` cells along
    the longest side, and the signed volume; at most ``max_resolution``), and it is the answer (chosen by this
    rule, not by which bound is smaller); when its bound misses ``target`` by more than
    :data:`CLOSED_PREDICTION_SLACK` (the signed volume counts overlaps twice), it is built once more at
    ``resolution · bound / target`` cells; when that grid's bound is past the ±50 % at which an estimate is
    refused (:data:`~inertia_tool.tolerances.ESTIMATE_MAX_MASS_RTOL`), :func:`corrected_estimate` is built on
    the finest grid too and the narrower of the two proven bounds is the answer.  When the grid decided no
    cell inside (a part thinner than the cells, which no affordable plain grid resolves):
    :func:`corrected_estimate` (the exact signed integral, corrected only near faces where the
    winding number may leave {0, 1}) is built on the finest grid and is the answer when its mass bound meets
    ``target``;
    otherwise the plain finest grid is built too and the one with the smaller proven mass bound is the answer
    (each bound holds for its own estimate: a choice between two proven bounds, not between claims).  A thin
    part is thus found wherever its faces do not cross; where they do,
    the doubt grows with the size of the crossing faces (the cells near them).

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        Edge-balanced (closed) surface; the caller checks.
    resolution, target
        As above.
    max_resolution : int, optional
        Finest grid, cells along the longest side; by default as many as :data:`CLOSED_MAX_CELLS` cells allow
        (:func:`budget_resolution`: a flat or long part goes finer than a cubic one for the same memory).
    max_evaluations : int, optional
        Most cells a grid evaluates one by one (:func:`winding_estimate`; none where every region's integer is
        found, every free cell where one is not): a grid that would exceed it is built again at
        :func:`affordable_resolution` instead, and a refinement that would exceed it is not made (the grid
        before stands; counted before any cell is evaluated).
    added_doubt : float
        m³ the caller adds to the estimate's volume in doubt (the holes' patches of a patched surface): when the
        first grid shows that every estimate would then be refused (:func:`refusal_proven`), it is the answer and
        nothing finer is built.

    Returns
    -------
    Estimate
        ``method`` ``"winding"``.

    Raises
    ------
    WorkBudgetError
        Even a grid of 8 cells along the longest side would evaluate more than ``max_evaluations`` cells.
    """
    if max_resolution is None:
        max_resolution = budget_resolution(vertices)
    finer = predicted_resolution(vertices, faces, resolution=resolution, target=target,
                                 max_resolution=max_resolution)
    try:
        grid = winding_estimate(vertices, faces, resolution=finer, max_evaluations=max_evaluations)
    except WorkBudgetError as over:
        # a region's integer was uncertain, so every free cell would be evaluated: the grid the budget affords
        finer = min(finer - 1, affordable_resolution(vertices, finer, over.details["evaluations"],
                                                     over.details["crossed"], max_evaluations))
        if finer < 8:
            raise
        grid = winding_estimate(vertices, faces, resolution=finer, max_evaluations=max_evaluations)
    bound = grid.uncertainty.mass
    if grid.volume > 0:
        if refusal_proven(grid, added_doubt):
            return grid                         # refused with the added doubt, as any finer grid would be
        if finer < max_resolution and bound > CLOSED_PREDICTION_SLACK * target:
            # predicted too coarse (overlapping bodies count twice in the signed volume): refined once by the
            # grid's own bound; a grid over the budget of evaluations is refused before it evaluates anything
            again = int(min(max_resolution, np.ceil(finer * bound / target)))
            if again > finer:
                try:
                    grid = winding_estimate(vertices, faces, resolution=again, max_evaluations=max_evaluations)
                except WorkBudgetError:
                    pass                        # counted, not timed: the first grid stands
        if not grid.uncertainty.mass > ESTIMATE_MAX_MASS_RTOL:
            return grid
        # the plain grid's bound would be refused: the corrected estimate on the finest grid too, and the
        # narrower of the two proven bounds (as for a thin part below; before the one-grid rule a part the
        # 64-cell grid found nothing inside came here, issue 23: Barkour vb's upper_leg_left.stl, ±48.6 % this
        # way).  Only past the refusal bound: on Barkour and Piper every grid between the target and it paid for
        # a corrected estimate it did not need (358 s of CPU for four Menagerie folders)
        corrected = corrected_estimate(vertices, faces, resolution=max_resolution)
        if corrected is not None and corrected.uncertainty.mass < grid.uncertainty.mass:
            return corrected
        return grid
    # thinner than the cells: the plain grid decides nothing inside at any resolution it can afford
    corrected = corrected_estimate(vertices, faces, resolution=max_resolution)
    if corrected is not None and corrected.uncertainty.mass <= target:
        return corrected
    second = grid
    if finer < max_resolution:
        try:
            second = winding_estimate(vertices, faces, resolution=max_resolution, max_evaluations=max_evaluations)
        except WorkBudgetError:
            pass                                # counted, not timed: the grid built stands
    if corrected is not None and not corrected.uncertainty.mass >= second.uncertainty.mass:
        return corrected                # both bounds are proven: the narrower one is reported
    return second


def refusal_proven(grid: Estimate, added_doubt: float, max_mass_rtol: float = ESTIMATE_MAX_MASS_RTOL) -> bool:
    """Whether every estimate of the solid ``grid`` estimates, with ``added_doubt`` m³ more in doubt, would have a
    mass bound past ``max_mass_rtol`` (and be refused), while ``grid``'s own bound is within it.

    The grid claims that the solid ``S`` lies within its decided and doubtful cells: ``|S| ≤ V + δ`` (its volume
    and its volume in doubt; the decided cells plus the crossed and ambiguous ones).  Any estimate ``(V', δ')``
    whose bound holds has ``V' − δ' ≤ |S|``, so with ``p = added_doubt`` its relative mass bound is
    ``(p + δ')/V' ≥ (p + δ')/(|S|max + δ') ≥ min(1, p/|S|max)``: past ``max_mass_rtol`` (< 1) whenever
    ``p > max_mass_rtol · (V + δ)``, however fine its grid.  The grid itself is then refused with the added
    doubt, by the same message as a finer one; its own bound within the limit keeps the refusal that of the
    added doubt (the caller's check of the grid alone passes as before).
    """
    unc = grid.uncertainty
    most = grid.volume + unc.volume_in_doubt
    return bool(added_doubt > 0 and grid.volume > 0 and np.isfinite(most) and unc.mass <= max_mass_rtol
                and added_doubt > max_mass_rtol * most)


def predicted_resolution(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                         target: float = CLOSED_TARGET_MASS_RTOL, max_resolution: int | None = None) -> int:
    """Cells along the longest side at which :func:`winding_estimate`'s mass bound of a closed surface is
    expected to meet ``target``, from ``resolution`` to ``max_resolution``: the one grid
    :func:`closed_surface_estimate` builds.

    The bound of a closed surface is the volume of the cells its faces cross, counted half, over the volume:
    ``β(h) ≈ n(h) h³ / (2 V)``.  The crossed cells ``n(h₀)`` of the grid of ``resolution`` cells are marked
    (:func:`_surface_cells`, no winding number evaluated), and ``V`` is the signed volume of the surface
    (``∫ w dV``, exact by the divergence theorem, Eq. 4.27 of Chapter 4, "Rigid Body Motion").  The crossed
    volume of a surface shrinks as the cell size, so ``β(h) ≈ β(h₀) h / h₀``: the grid of
    ``⌈resolution · β(h₀) / target⌉`` cells (issue 23, item 6: the estimate used to build the first grid in
    full, evaluate it, and then the second; this is the same rule without the first grid).  Only the choice
    of the grid rests on this expectation; the bound reported is the grid's own.  ``max_resolution`` when
    ``V`` is not larger than the crossed volume (a part thinner than the cells, or inside out).
    """
    from ..integrals import volume_moments

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if max_resolution is None:
        max_resolution = budget_resolution(v)
    if resolution >= max_resolution:
        return int(resolution)
    lo, hi = v.min(axis=0), v.max(axis=0)
    h = float(np.max(hi - lo)) / int(resolution)
    lo = lo - h
    dims = tuple(int(x) for x in np.ceil((hi + h - lo) / h).astype(np.int64))
    doubt = 0.5 * float(np.count_nonzero(_surface_cells(v, f, lo, h, dims))) * h ** 3
    volume = abs(volume_moments(v, f).volume)
    if not volume > doubt:
        return int(max_resolution)
    bound = doubt / volume
    if bound <= target:
        return int(resolution)
    return int(min(max_resolution, np.ceil(resolution * bound / target)))


def open_surface_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                          target: float = CLOSED_TARGET_MASS_RTOL, max_resolution: int | None = None,
                          max_evaluations: int | None = None, added_doubt: float = 0.0) -> Estimate:
    """:func:`winding_estimate` of a surface that is open and passes through itself, refined once as
    :func:`closed_surface_estimate` refines: when the first grid's mass bound exceeds ``target``, the grid is
    built again at ``resolution · bound / target`` cells along the longest side, at most ``max_resolution``
    (default: :func:`budget_resolution` of :data:`OPEN_MAX_CELLS`), and exactly that when the first decided no
    cell inside (a part thinner than the cells, which the first grid reports as enclosing nothing; issue 23:
    Barkour vb's ``upper_leg_right.stl``), and at most as fine as ``max_evaluations`` allows
    (:func:`affordable_resolution`, from the cells the first grid evaluated).  The second grid is the answer (by
    this rule), unless it would still evaluate more cells than ``max_evaluations``: then the first is (decided by
    counting cells, never by time).  The assumption and the bounds are :func:`winding_estimate`'s.  With
    ``added_doubt`` (m³ the caller adds to the volume in doubt: a patched surface's holes), the first grid is the
    answer when it shows that every estimate would be refused with it (:func:`refusal_proven`; issue 23: ALOHA's
    ``vx300s_7_gripper_prop.stl`` built a 109-cell grid, 10 of its 12 s, only to be refused).

    Raises
    ------
    WorkBudgetError
        The first grid alone would evaluate more than ``max_evaluations`` cells.
    """
    if max_resolution is None:
        max_resolution = budget_resolution(vertices, OPEN_MAX_CELLS)
    first, evaluated, crossed = _winding_grid(vertices, faces, resolution=resolution, max_evaluations=max_evaluations)
    bound = first.uncertainty.mass
    if resolution >= max_resolution or (np.isfinite(bound) and bound <= target) or refusal_proven(first,
                                                                                                 added_doubt):
        return first
    finer = max_resolution if not (np.isfinite(bound) and first.volume > 0) else \
        int(min(max_resolution, np.ceil(resolution * bound / target)))
    finer = min(finer, affordable_resolution(vertices, resolution, evaluated, crossed, max_evaluations))
    if finer <= resolution:
        return first
    try:
        return winding_estimate(vertices, faces, resolution=finer, max_evaluations=max_evaluations)
    except WorkBudgetError:
        return first


def affordable_resolution(vertices: np.ndarray, resolution: int, evaluated: int, crossed: int,
                          max_evaluations: int | None = None) -> int:
    """The finest grid (cells along the longest side, 8 to 4096) expected to evaluate at most ``max_evaluations``
    cells one by one, from the grid of ``resolution`` that evaluated ``evaluated`` cells and found ``crossed``
    cells crossed by the surface.

    The cells evaluated fill a volume (near the holes; or every free cell), so their number grows with the
    grid's cell count; at a finer grid the crossed cells shrink in share and their room is free, evaluated or
    settled.  The expectation is therefore ``(evaluated + crossed) · cells(n) / cells(resolution)``, with
    ``cells(n)`` the padded grid's exact count (:func:`_grid_shape`): an over-estimate where the evaluated
    cells lie near the surface (their number grows as the area).  ALOHA's ``vx300s_7_gripper_prop.stl``:
    48,795 evaluated and 37,042 crossed at 64 cells; at 180, expected 1.72M, evaluated 1.18M.  Only the choice
    of the grid rests on this expectation; the grid built counts its own cells against the budget.
    """
    budget = WINDING_EVALUATION_BUDGET if max_evaluations is None else int(max_evaluations)
    v = np.asarray(vertices, dtype=np.float64)
    base = evaluated + crossed
    if base <= 0:
        return 4096

    def cells(n: int) -> float:
        return float(np.prod(_grid_shape(v, n)[2], dtype=np.float64))

    per_cell = base / cells(int(resolution))
    low, high = 8, 4096                         # the largest n in [8, 4096] whose expectation fits, by bisection
    if per_cell * cells(low) > budget:
        return low - 1
    for _ in range(16):                         # 2^12 > 4096 - 8: at most 12 halvings
        if high - low <= 0:
            break
        mid = (low + high + 1) // 2
        if per_cell * cells(mid) <= budget:
            low = mid
        else:
            high = mid - 1
    return low


# -- the exact signed integral, corrected on a grid only where the winding number may leave {0, 1} -------------

#: Most clean components of the surface whose front winding number is found (one probe each; beyond it the
#: corrected estimate is not built).
FRONT_PROBES_LIMIT = 4096
#: Probes closer than this (relative to the bounding-box diagonal) to another face are not trusted.
PROBE_FLOOR_RTOL = 1e-9
#: Relative round-off allowed for the signed integral of :func:`corrected_estimate` when no cell is in doubt.
SIGNED_ROUNDOFF_RTOL = 1e-12
#: Most distinct front numbers kept as classes by :func:`corrected_estimate`.
MAX_FRONT_CLASSES = 8
#: Most (doubtful cell, candidate face) pairs tested for the face counts of the doubtful cells.
FACE_COUNT_WORK = 20_000_000


def _point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(k,) distance from points ``p`` to triangles ``(a, b, c)`` (all (k, 3)), by the closest point's region
    (Ericson, "Real-Time Collision Detection", §5.1.5); a degenerate triangle gets a lower bound (distance to
    its first corner less its longest edge)."""
    ab, ac, ap = b - a, c - a, p - a
    bp, cp = p - b, p - c

    def dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        out: np.ndarray = np.einsum("ij,ij->i", x, y)
        return out

    d1, d2, d3, d4, d5, d6 = dot(ab, ap), dot(ac, ap), dot(ab, bp), dot(ac, bp), dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        denom = 1.0 / (va + vb + vc)
        inner = a + ab * (vb * denom)[:, None] + ac * (vc * denom)[:, None]
    conditions = [(d1 <= 0) & (d2 <= 0), (d3 >= 0) & (d4 <= d3), (vc <= 0) & (d1 >= 0) & (d3 <= 0),
                  (d6 >= 0) & (d5 <= d6), (vb <= 0) & (d2 >= 0) & (d6 <= 0),
                  (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)]
    choices = [a, b, a + ab * t_ab[:, None], c, a + ac * t_ac[:, None], b + (c - b) * t_bc[:, None]]
    closest = inner.copy()
    for cond, choice in zip(conditions[::-1], choices[::-1]):      # the first condition that holds wins
        closest = np.where(cond[:, None], choice, closest)
    dist = np.linalg.norm(p - closest, axis=1)
    longest = np.max(np.stack([np.linalg.norm(ab, axis=1), np.linalg.norm(ac, axis=1),
                               np.linalg.norm(c - b, axis=1)]), axis=0)
    fallback = np.linalg.norm(ap, axis=1) - longest
    out: np.ndarray = np.where(np.isfinite(dist), dist, fallback)
    return out


#: Spacing of the samples of the good faces (in cells) with which :func:`corrected_estimate` clears cells
#: without a distance query (:func:`_distance_above`; any spacing is sound, a finer one clears more for more
#: samples: on Piper's link2.stl 2, 4 and 8 cells cleared 216k, 209k and 195k of 219k for 1.5, 0.6 and 0.4 s).
SAMPLE_SPACING_CELLS = 4.0
#: Where :func:`corrected_estimate` stops the nearest-sample search of :func:`_distance_above` (cells): its first
#: use needs ``above`` only below 1.5 cells, its second only below the distance to the bad faces, which the exact
#: query it is compared with settles anyway (``inf`` beyond it clears nothing that the exact queries do not: the
#: same cells are cleared).  On Piper's link2.stl's 334,175 centres the query 1.1-1.7 → 0.9 s CPU, 0.6 % of them
#: beyond 6 cells.
DISTANCE_QUERY_CELLS = 6.0
#: Most sample points :func:`_distance_above` takes (the spacing is widened to stay within it).
MAX_SAMPLE_POINTS = 4_000_000


def _distance_above(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, spacing: float, *,
                    beyond: float = np.inf) -> np.ndarray:
    """(p,) m: an upper bound on the distance from each of ``points`` to the surface ``faces`` (``inf`` where the
    nearest sample is farther than ``beyond``: the k-d tree's search then stops early).

    Each face (corners ``a, b, c``) is sampled at ``a (1 − s − t) + b s + c t`` for ``s, t`` on the grid of
    ``1/n``, ``n = ⌈longest edge / spacing⌉`` (at least its corners; the spacing is widened until at most
    :data:`MAX_SAMPLE_POINTS` samples are made).  A sample lies on its face up to the round-off of its
    coordinates, so the distance to the surface is at most the distance ``D`` to the nearest sample plus
    ``ε = 1e-12 · max |coordinate| + 1e-9 · diagonal``, a margin far above that round-off and above that of the
    exact nearest-point query a caller would otherwise compare (libigl's).  Returns ``D + ε``; the nearest
    sample is found with a k-d tree (scipy).
    """
    from scipy.spatial import cKDTree

    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    longest = np.max(np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                               np.linalg.norm(a - c, axis=1)]), axis=0)
    steps = np.ones(len(faces), dtype=np.int64)
    for _ in range(64):                                 # widened until the samples fit (2^64 spans any mesh)
        steps = np.maximum(1, np.ceil(longest / spacing)).astype(np.int64)
        if int(((steps + 1) * (steps + 2) // 2).sum()) <= MAX_SAMPLE_POINTS:
            break
        spacing *= 2.0
    blocks = []
    for n in np.unique(steps).tolist():
        sel = steps == n
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        s, t = i[keep] / n, j[keep] / n
        blocks.append((a[sel, None] * (1 - s - t)[None, :, None] + b[sel, None] * s[None, :, None]
                       + c[sel, None] * t[None, :, None]).reshape(-1, 3))
    samples = np.concatenate(blocks)
    used = vertices[np.unique(faces)]
    margin = 1e-12 * float(np.abs(used).max()) + 1e-9 * float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    nearest, _ = cKDTree(samples).query(points, distance_upper_bound=beyond)
    above: np.ndarray = nearest + margin
    return above


def _probe_clearance(points: np.ndarray, reach: np.ndarray, own: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                     a: np.ndarray, b: np.ndarray, c: np.ndarray, *, work: int = 1 << 22) -> np.ndarray:
    """(p,) m: ``min(reach, d/4)`` for each of ``points`` ((p, 3)), ``d`` the distance to the nearest face other
    than its ``own`` whose bounding box (``lo``, ``hi``: (m, 3)) comes within ``reach`` of it (``inf`` when
    none does); faces ``(a, b, c)`` (each (m, 3)).

    The points are taken in order along x, a block at a time, against the faces whose boxes reach the block's
    slab ``[min(x − reach), max(x + reach)]`` along x: every face a point's box test can pass, so the same
    (point, face) pairs as testing every face against every point (issue 25: that test was most of
    :func:`_front_numbers`' ~1 s on Piper's link2.stl); each point's value is its own minimum over its pairs,
    in any order.  A block is halved while it would test more than ``work`` pairs (a single point is tested
    against its slab whatever its size).
    """
    out = np.array(reach, dtype=np.float64)
    along = np.argsort(points[:, 0], kind="stable")
    by_lo = np.argsort(lo[:, 0], kind="stable")
    sorted_lo = lo[by_lo, 0]
    start, per = 0, 256
    for _ in range(2 * len(along) + 16):                # a pass takes points or halves the block (doubled
        if start >= len(along):                         # after each take, so halvings ≤ takes + 12)
            break
        block = along[start:start + per]
        q, r = points[block], out[block]
        slab_lo, slab_hi = float(np.min(q[:, 0] - r)), float(np.max(q[:, 0] + r))
        within = by_lo[:int(np.searchsorted(sorted_lo, slab_hi, side="right"))]
        within = within[hi[within, 0] >= slab_lo]
        if len(block) * len(within) > work and len(block) > 1:
            per = max(1, len(block) // 2)               # a narrower slab for fewer points
            continue
        start += len(block)
        per = min(4096, 2 * per)
        gap = np.maximum(np.maximum(lo[within][None] - q[:, None], q[:, None] - hi[within][None]), 0.0)
        near = np.einsum("pki,pki->pk", gap, gap) <= (r ** 2)[:, None]
        near &= within[None, :] != own[block][:, None]
        pi, fi = np.nonzero(near)
        if len(pi):
            fi = within[fi]
            d = _point_triangle_distance(q[pi], a[fi], b[fi], c[fi])
            nearest = np.full(len(q), np.inf)
            np.minimum.at(nearest, pi, d)
            out[block] = np.minimum(r, 0.25 * nearest)
    if start < len(along):
        raise InternalInvariantError(f"expected every point's nearest face within the passes, {start} of "
                                     f"{len(along)} done")
    return out


def _front_numbers(v: np.ndarray, f: np.ndarray, clean: np.ndarray, *,
                   max_probes: int = FRONT_PROBES_LIMIT, tree: IntegerTree | None = None) -> np.ndarray | None:
    """(m,) int: the winding number just in front of each clean face (−2³¹ for faces not clean or not settled).

    Clean faces (no other face meets them beyond the vertices and edges they share by index) joined by edges
    that exactly two faces use, both clean, form components across which the region in front stays the same
    (near such an edge the two front sides meet, and no other face passes there).  One probe per component,
    at ``c + (ε/2) n̂`` in front of the centroid ``c`` of its largest face with ``ε`` a quarter of the distance
    from ``c`` to every other face, lies in that face's front region; the winding number there is an integer
    (the surface is a cycle), found by the bounded treecode and rounded (a component more than 1/4 away,
    counting the bound, is left unsettled).  Returns None beyond ``max_probes`` components.  ``tree``: the
    :func:`~.winding.integer_tree` of ``v, f`` when the caller has built it.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .winding import winding_integers

    m, n = len(f), len(v)
    out = np.full(m, np.iinfo(np.int32).min, dtype=np.int64)
    ids = np.flatnonzero(clean)
    if not len(ids):
        return out
    nv = np.int64(max(n, 1))
    e0 = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    e1 = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    key = np.minimum(e0, e1) * nv + np.maximum(e0, e1)
    owner = np.tile(np.arange(m), 3)
    order = np.argsort(key, kind="stable")
    key, owner = key[order], owner[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[starts, len(key)])
    two = starts[count == 2]
    fa, fb = owner[two], owner[two + 1]
    keep = clean[fa] & clean[fb]
    graph = coo_matrix((np.ones(int(keep.sum()), dtype=np.int8), (fa[keep], fb[keep])), shape=(m, m))
    _, comp = connected_components(graph, directed=False)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    comps = np.unique(comp[ids])
    if len(comps) > max_probes:
        return None
    # the largest clean face of each component
    sel = ids[np.lexsort((-area[ids], comp[ids]))]
    first = np.r_[True, comp[sel][1:] != comp[sel][:-1]]
    probe_face = sel[first]
    centroid = (a[probe_face] + b[probe_face] + c[probe_face]) / 3.0
    unit = normal[probe_face] / np.maximum(2 * area[probe_face], np.finfo(float).tiny)[:, None]
    lo, hi = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    # ε: a quarter of the nearest other face, found among the faces whose boxes come within the face's size
    eps = 0.25 * np.sqrt(area[probe_face])
    eps = _probe_clearance(centroid, eps, probe_face, lo, hi, a, b, c)
    ok = eps > PROBE_FLOOR_RTOL * diag
    probes = centroid + 0.5 * eps[:, None] * unit
    w, err = winding_integers(probes[ok], v, f, tree=tree)
    whole = np.round(w)
    settled = np.abs(w - whole) + err <= 0.25
    value = np.full(len(probe_face), np.iinfo(np.int32).min, dtype=np.int64)
    value[np.flatnonzero(ok)[settled]] = whole[settled].astype(np.int64)
    table = np.full(int(comp.max()) + 1, np.iinfo(np.int32).min, dtype=np.int64)
    table[comp[probe_face]] = value
    out[ids] = table[comp[ids]]
    return out


def _raw_moments(centres: np.ndarray, weight: np.ndarray, h: float, origin: np.ndarray
                 ) -> tuple[float, np.ndarray, np.ndarray]:
    """``∫ρ``, ``∫ρ(x−o)``, ``∫ρ(x−o)(x−o)ᵀ`` of cubes of side ``h`` at ``centres`` with densities ``weight``."""
    d = centres - origin
    cube = h ** 3
    m0 = float(weight.sum()) * cube
    m1 = cube * (weight[:, None] * d).sum(axis=0)
    m2 = cube * ((weight[:, None] * d).T @ d) + m0 * h ** 2 / 12.0 * np.eye(3)
    return m0, m1, m2


def _face_blocks(flo: np.ndarray, fhi: np.ndarray, lo: np.ndarray, h: float, dims: tuple[int, ...], block: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(blocks per axis, face, block)``: each face listed in every block of ``block`` cells per axis that its
    bounding box (``flo``, ``fhi``) widened by one cell reaches, so a face whose box meets a cell (within any
    slack below a cell) is listed in that cell's block whatever the rounding at the blocks' boundaries."""
    nb = np.array([-(-d // block) for d in dims])
    span = h * block
    b0 = np.clip(np.floor((flo - h - lo) / span).astype(np.int64), 0, nb - 1)
    b1 = np.clip(np.floor((fhi + h - lo) / span).astype(np.int64), 0, nb - 1)
    size = np.prod(b1 - b0 + 1, axis=1)
    face = np.repeat(np.arange(len(flo)), size)
    offset = np.arange(int(size.sum())) - np.repeat(np.cumsum(size) - size, size)
    ext = (b1 - b0 + 1)[face]
    k = offset % ext[:, 2]
    j = (offset // ext[:, 2]) % ext[:, 1]
    i = offset // (ext[:, 2] * ext[:, 1])
    blk = ((b0[face, 0] + i) * nb[1] + b0[face, 1] + j) * nb[2] + b0[face, 2] + k
    return nb, face, blk


def _face_counts(v: np.ndarray, f: np.ndarray, cells: np.ndarray, lo: np.ndarray, h: float,
                 dims: tuple[int, ...], *, block: int = 8, max_work: int = FACE_COUNT_WORK) -> np.ndarray | None:
    """(k,) for each cell index of ``cells``: how many faces' bounding boxes meet the closed cell (at least
    the faces that meet it); None past ``max_work`` (face, block) entries or (cell, face) tests on blocks of
    ``block`` cells.

    Candidates come from blocks of cells (:func:`_face_blocks`: a face's box widened by a cell, so that a face
    touching a cell at a block's boundary is a candidate: before, a face in the plane between two blocks was not
    counted for the cells of the block below it); each candidate is tested against the cell, so the counts do
    not depend on the block size, and blocks of 2 or 4 cells are used when they test fewer pairs (issue 25:
    Piper's link2.stl 1.06 s → 0.17 s of CPU at 2 cells).  The work bound is counted on ``block``."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    flo, fhi = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
    ci, cj, ck = np.unravel_index(cells, dims)

    def cell_blocks(nb: np.ndarray, size: int) -> np.ndarray:
        found: np.ndarray = ((ci // size) * nb[1] + cj // size) * nb[2] + ck // size
        return found

    def work(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int] | None:
        """(blocks, face, block, pairs) on blocks of ``size`` cells, or None past ``max_work`` entries."""
        nb = np.array([-(-d // size) for d in dims])
        b0 = np.clip(np.floor((flo - h - lo) / (h * size)).astype(np.int64), 0, nb - 1)
        b1 = np.clip(np.floor((fhi + h - lo) / (h * size)).astype(np.int64), 0, nb - 1)
        if int(np.prod(b1 - b0 + 1, axis=1).sum()) > max_work:
            return None
        nb, face, blk = _face_blocks(flo, fhi, lo, h, dims, size)
        pairs = int(np.bincount(blk, minlength=int(np.prod(nb)))[cell_blocks(nb, size)].sum())
        return nb, face, blk, pairs

    chosen = work(block)
    if chosen is None or chosen[3] > max_work:
        return None
    for finer in (2, 4):
        if finer >= block:
            break
        other = work(finer)
        if other is not None and other[3] < chosen[3]:
            chosen, block = other, finer
            break
    nb, face, blk, _ = chosen
    order = np.argsort(blk, kind="stable")
    blk, face = blk[order], face[order]
    cell_block = cell_blocks(nb, block)
    start = np.searchsorted(blk, cell_block, side="left")
    stop = np.searchsorted(blk, cell_block, side="right")
    many = stop - start
    who = np.repeat(np.arange(len(cells)), many)
    idx = np.repeat(start, many) + (np.arange(int(many.sum())) - np.repeat(np.cumsum(many) - many, many))
    cand = face[idx]
    cell_lo = lo + h * np.stack([ci, cj, ck], axis=1)[who]
    slack = 1e-9 * h
    meets = np.all((flo[cand] <= cell_lo + h + slack) & (fhi[cand] >= cell_lo - slack), axis=1)
    counts: np.ndarray = np.bincount(who[meets], minlength=len(cells))
    return counts


def corrected_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                       dilation: int = 4) -> Estimate | None:
    """The solid ``{w ≥ 1}`` of a closed (edge-balanced) surface as its exact signed integral plus a correction
    that a grid bounds only where ``w`` may leave ``{0, 1}``.

    For a 2-cycle the divergence theorem integrates the winding number: the signed volume integrals of the
    faces (:func:`~inertia_tool.integrals.volume_moments`) are ``∫ w φ dV`` for ``φ = 1, x, x xᵀ``, exactly.
    With ``g(w) = [w ≥ 1] − w`` (zero for ``w ∈ {0, 1}``), ``∫_S φ = ∫ w φ + ∫ g(w) φ``.

    * A face no other face meets (beyond what they share by index) has one region in front of it; so do
      such faces joined by two-face edges (:func:`_front_numbers`, one exact probe per component).  Where that
      front number is 0, both sides of the face are in ``{0, 1}``.
    * A grid cell that meets only such faces has ``g = 0`` throughout (every piece of the cell cut by the
      surface borders one of them).  A cell the marking counts as crossed but that meets no face lies in one
      region; the first face met from it towards the face that marked it is within ``2√3`` cells, so dilating
      the cells of every other face ("bad": crossing, touching, unsettled, or a front number ≠ 0) by
      ``dilation`` (4) cells covers every cell whose ``g`` could be nonzero.
    * Cells no surface crosses take the integer of their region (one evaluation each, as
      :func:`_closed_part_numbers`) and add ``g(k)`` exactly.
    * A crossed cell near a bad face has ``w`` within ``T`` of each face-neighbour's integer ``k`` (a segment
      in the box of two face-adjacent cells crosses each of the ``T`` faces meeting the cell at most once, and
      none in the free neighbour): ``w ∈ [max k − T, min k + T]``, so ``g`` lies in an interval whose middle is
      counted and whose half-width is the density in doubt (a cell with no free face-neighbour: not built).

    Truth minus estimate is then a signed density bounded cell by cell, which :func:`uncertainty_from` turns
    into bounds **with no assumption on the surface** beyond its being closed.  Returns None when a step's work
    bound is exceeded, the face-pair check is incomplete, or a doubtful cell has no free face-neighbour.
    """
    from scipy import ndimage

    from ..integrals import volume_moments
    from .intersect import surface_contacts
    from .winding import fast_available, integer_tree, winding_integers, winding_numbers

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    m = len(f)
    contacts = surface_contacts(v, f)
    if not contacts.complete:
        return None
    touched = np.zeros(m, dtype=bool)
    for pairs in (contacts.crossing, contacts.coplanar_opposite, contacts.contact):
        touched[np.asarray(pairs, dtype=np.int64).reshape(-1)] = True
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    twice_area = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    clean = ~touched & (twice_area > 1e-14 * diag ** 2)
    # one tree of faces for the front probes and the regions' integers (issue 25: built twice before, ~0.25 s
    # each on Piper's link2.stl; the same values to the bit)
    tree = integer_tree(v, f)
    front = _front_numbers(v, f, clean, tree=tree)
    if front is None:
        return None
    settled_front = front > np.iinfo(np.int32).min
    values = np.unique(front[settled_front])
    if len(values) > MAX_FRONT_CLASSES:                 # the rarest numbers join the unsettled faces
        common = np.argsort(-np.bincount(np.searchsorted(values, front[settled_front])))[:MAX_FRONT_CLASSES]
        values = values[np.sort(common)]
        settled_front &= np.isin(front, values)
    bad = ~settled_front
    lo, hi = v.min(axis=0), v.max(axis=0)
    h = float(np.max(hi - lo)) / int(resolution)
    lo = lo - h
    dims = tuple(int(x) for x in np.ceil((hi + h - lo) / h).astype(np.int64))
    size = 2 * dilation + 1

    def near(marked: np.ndarray) -> np.ndarray:
        grown: np.ndarray = ndimage.maximum_filter(marked, size=size, mode="constant", cval=False).reshape(-1)
        return grown
    # the cells each front class and the bad faces mark; the faces fall into exactly these classes, and the
    # marking of a set of faces is the union of its faces' (each face sampled on its own, then every marked
    # cell grown by the same shifts, which distribute over a union), so ``crossed`` is their union: the cells
    # of every face marked once instead of twice (issue 25: ~0.4 s of Piper's link2.stl at 11.2M cells)
    grown_classes = []
    crossed = np.zeros(int(np.prod(dims)), dtype=bool)
    for value in values.tolist():
        marked = _surface_cells(v, f[front == value], lo, h, dims)
        crossed |= marked
        grown_classes.append((value, near(marked.reshape(dims))))
        del marked
    marked_bad = _surface_cells(v, f[bad], lo, h, dims).reshape(dims) if bad.any() else None
    if marked_bad is not None:
        crossed |= marked_bad.reshape(-1)
    # the range of w on a crossed cell away from bad faces: from the least front number of the faces near it
    # to the greatest plus one
    class_lo = np.full(len(crossed), np.iinfo(np.int32).max, dtype=np.int64)
    class_hi = np.full(len(crossed), np.iinfo(np.int32).min, dtype=np.int64)
    for value, grown in grown_classes:
        hit = grown & crossed
        class_lo[hit] = np.minimum(class_lo[hit], value)
        class_hi[hit] = np.maximum(class_hi[hit], value + 1)
    del grown_classes
    near_bad = near(marked_bad) & crossed if marked_bad is not None else np.zeros_like(crossed)
    if near_bad.any() and fast_available():
        # tighter: a cell whose centre is nearer to some good face than to every bad one, and farther than half
        # its diagonal from the bad ones, meets no bad face, and its region (when it meets no face) borders the
        # good face nearest its centre (within the dilation): it keeps its class range.  The distance to every
        # face is measured only for the centres farther than that from the bad ones (the others are not cleared
        # whatever it is; issue 23: Piper's link2.stl measured 334,175 centres against all 71,916 faces)
        import igl
        ring = np.flatnonzero(near_bad)
        pts = lo + h * (np.stack(np.unravel_index(ring, dims), axis=1) + 0.5)
        slack = 1e-9 * float(np.linalg.norm(hi - lo)) + 1e-6 * h
        half_diagonal = h * np.sqrt(3) / 2
        clear = np.zeros(len(ring), dtype=bool)
        # most are decided without an exact query (issue 25: Piper's link2.stl, 3.3-5.4 s of the queries' CPU to
        # about 1 s), each as the queries below would decide it:
        # ``above`` ≥ the distance to the good faces (:func:`_distance_above`, from their samples).  A centre
        # whose cell is two cells or more (chessboard) from every cell the bad faces mark (a superset of the cells
        # they meet) is at least 1.5 h from them; where ``above`` is below that less twice the slack, the test
        # below (distance to the bad faces > max(h √3/2, distance to every face) + slack) holds: cleared
        # without measuring either distance
        # (the k-d tree's search bounded at DISTANCE_QUERY_CELLS cells: a centre farther from every sample is
        # not cleared by ``above`` below 1.5 h, and goes to the exact queries as one ``above`` does not clear)
        above = (_distance_above(pts, v, f[~bad], SAMPLE_SPACING_CELLS * h, beyond=DISTANCE_QUERY_CELLS * h)
                 if not bad.all() else None)
        if above is not None and marked_bad is not None:
            apart = ~ndimage.maximum_filter(marked_bad, size=3, mode="constant", cval=False).reshape(-1)[ring]
            clear = apart & (above < 1.5 * h - 2 * slack)
        rest = np.flatnonzero(~clear)
        d_bad = np.sqrt(np.asarray(igl.point_mesh_squared_distance(pts[rest], v, f[bad])[0], dtype=np.float64))
        far = d_bad > half_diagonal + slack
        away, d_away = rest[far], d_bad[far]
        # then the centres farther than half a diagonal from the bad faces and nearer to a good face's sample
        # (``above``) than to them less the slack; the others are measured against every face
        sure = above[away] < d_away - slack if above is not None else np.zeros(len(away), dtype=bool)
        ask = np.flatnonzero(~sure)
        if len(ask):
            d_all = np.sqrt(np.asarray(igl.point_mesh_squared_distance(pts[away[ask]], v, f)[0], dtype=np.float64))
            sure[ask] = d_away[ask] > np.maximum(half_diagonal, d_all) + slack
        clear[away[sure]] = True
        near_bad[ring[clear]] = False
    near_bad |= crossed & (class_lo > class_hi)           # none found (not expected): no range
    loose = crossed & ~near_bad & ((class_lo < 0) | (class_hi > 1))     # g may be nonzero there
    doubt_mask = near_bad | loose
    # the integer of each region of free cells, at one cell each
    # (the C labels with each region's first cell when built: scipy's numbering, without np.unique's sort of
    # every cell's label; issue 25: ~1 s of Piper's link2.stl)
    region, n_regions, first_cells, _ = _label_regions(~crossed, dims)
    cell_value = np.zeros(len(region), dtype=np.int64)
    if n_regions:
        first = _first_cells(region, n_regions) if first_cells is None else first_cells
        pts = lo + h * (np.stack(np.unravel_index(first, dims), axis=1) + 0.5)
        if len(first) <= BOUNDED_REGION_POINTS or not fast_available():
            w, err = winding_integers(pts, v, f, tree=tree)
        else:
            w, err = winding_numbers(pts, v, f, fast=True), np.zeros(len(pts))
        whole = np.round(w)
        if np.any(np.abs(w - whole) + err > 0.25):
            return None
        free = region > 0
        cell_value[free] = whole.astype(np.int64)[region[free] - 1]
    free = ~crossed
    origin = 0.5 * (v.min(axis=0) + v.max(axis=0))
    signed = volume_moments(v, f, origin=origin)
    m0 = signed.volume
    m1 = signed.volume * (signed.centroid - origin) if signed.volume != 0 else np.zeros(3)
    m2 = signed.second_moment + (np.outer(m1, m1) / signed.volume if signed.volume != 0 else 0.0)
    if signed.volume == 0:
        return None
    k = cell_value
    g = np.where(k >= 1, 1 - k, -k)
    off = np.flatnonzero(free & (g != 0))
    if len(off):
        centres = lo + h * (np.stack(np.unravel_index(off, dims), axis=1) + 0.5)
        d0, d1, d2 = _raw_moments(centres, g[off].astype(np.float64), h, origin)
        m0, m1, m2 = m0 + d0, m1 + d1, m2 + d2
    doubtful = np.flatnonzero(doubt_mask)
    half = np.zeros(0)
    if len(doubtful):
        counts = _face_counts(v, f[bad], doubtful, lo, h, dims) if bad.any() else np.zeros(len(doubtful), np.int64)
        if counts is None:
            return None
        # w on each cell's closure: free cells their integer, crossed cells away from bad faces {0, 1}; a
        # doubtful cell within its face count T of every neighbour's range (a segment from the shared face)
        unknown = np.iinfo(np.int32).max // 4
        range_lo = np.where(free, k, np.where(crossed, class_lo, 0)).astype(np.int64)
        range_hi = np.where(free, k, np.where(crossed, class_hi, 1)).astype(np.int64)
        range_lo[near_bad], range_hi[near_bad] = -unknown, unknown
        idx = np.stack(np.unravel_index(doubtful, dims), axis=1)
        neighbours = []
        for axis in range(3):
            for step in (-1, 1):
                nb = idx.copy()
                nb[:, axis] += step
                inside = (nb[:, axis] >= 0) & (nb[:, axis] < dims[axis])
                flat = np.full(len(doubtful), -1, dtype=np.int64)
                flat[inside] = np.ravel_multi_index(tuple(nb[inside].T), dims)
                neighbours.append(flat)
        base_lo = np.where(class_lo[doubtful] <= class_hi[doubtful], class_lo[doubtful], unknown)
        base_hi = np.where(class_lo[doubtful] <= class_hi[doubtful], class_hi[doubtful], -unknown)
        for _ in range(max(dims)):                       # each round settles at least one more layer
            new_lo = np.full(len(doubtful), -unknown, dtype=np.int64)
            new_hi = np.full(len(doubtful), unknown, dtype=np.int64)
            for flat in neighbours:
                use = flat >= 0
                known = use.copy()
                known[use] = range_hi[flat[use]] - range_lo[flat[use]] < unknown
                nb_lo = np.minimum(range_lo[flat[known]], base_lo[known])
                nb_hi = np.maximum(range_hi[flat[known]], base_hi[known])
                new_lo[known] = np.maximum(new_lo[known], nb_lo - counts[known])
                new_hi[known] = np.minimum(new_hi[known], nb_hi + counts[known])
            tighter = (new_lo > range_lo[doubtful]) | (new_hi < range_hi[doubtful])
            if not tighter.any():
                break
            range_lo[doubtful] = np.maximum(range_lo[doubtful], new_lo)
            range_hi[doubtful] = np.minimum(range_hi[doubtful], new_hi)
        w_lo = range_lo[doubtful].astype(np.float64)
        w_hi = range_hi[doubtful].astype(np.float64)
        if np.any(w_hi - w_lo >= unknown):
            return None
        w_lo, w_hi = np.ceil(w_lo), np.floor(w_hi)
        g_hi = np.maximum(0.0, -w_lo)                 # g(w) = −w for w ≤ 0
        g_lo = np.minimum(0.0, 1.0 - w_hi)            # g(w) = 1 − w for w ≥ 1
        mid, half = 0.5 * (g_lo + g_hi), 0.5 * (g_hi - g_lo)
        centres = lo + h * (idx + 0.5)
        if np.any(mid != 0):
            d0, d1, d2 = _raw_moments(centres, mid, h, origin)
            m0, m1, m2 = m0 + d0, m1 + d1, m2 + d2
    if not m0 > 0:
        return None
    shift = m1 / m0
    centroid = origin + shift
    second = m2 - m0 * np.outer(shift, shift)
    area = float(0.5 * twice_area.sum())
    if len(doubtful) and half.any():
        centres = lo + h * (np.stack(np.unravel_index(doubtful, dims), axis=1) + 0.5)
        reach = np.linalg.norm(centres - centroid, axis=1) + h * np.sqrt(3) / 2
        cell_doubt = half * h ** 3
        far = float(np.max(reach[half > 0]))
        doubt = float(cell_doubt.sum())
        unc = uncertainty_from(m0, centroid, second, doubt, far, first_doubt=float(np.sum(cell_doubt * reach)),
                               second_doubt=float(np.sum(cell_doubt * reach ** 2)))
    else:
        # nothing in doubt: the signed integral's round-off alone, as a volume within the bounding box
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        far = float(np.max(np.linalg.norm(corners - centroid, axis=1)))
        unc = uncertainty_from(m0, centroid, second, SIGNED_ROUNDOFF_RTOL * m0, far)
    n_bad = int(np.count_nonzero(bad))
    detail = (f"the exact signed integral (winding number weighted) corrected on a {dims[0]}×{dims[1]}×{dims[2]} "
              f"grid of {h:.3g} m cells where the winding number may leave {{0, 1}}: {m - n_bad:,} of {m:,} faces "
              f"proven to separate winding numbers 0 and 1, {len(doubtful):,} cells near the other "
              f"{n_bad:,} in doubt")
    return Estimate(volume=m0, centroid=centroid, second_moment=second, area=area, uncertainty=unc,
                    method="winding", detail=detail, vertices=v, faces=f, far=far)
