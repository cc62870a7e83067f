"""The grid under the estimates of :mod:`~.grid_estimate` and :mod:`~.grid_corrected`: the cells a surface meets,
exactly (:func:`_surface_cells`), the face-connected regions of the cells it leaves free (:func:`_label_regions`,
:func:`_first_cells`), the cells' centres and the moments of weighted cells.

A grid is its lowest corner ``lo`` (m), its cell size ``h`` (m) and its shape ``dims`` (cells along x, y, z); a
cell is its flat index in C order.  Both estimates read the surface on such a grid; neither module is imported by
the other's stages here, so this one holds what they share.
"""

from __future__ import annotations

import numpy as np


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


#: Most regions whose one winding number each is taken from the bounded treecode (a proven error bound, about
#: 1 ms per point at 8k faces) rather than from libigl's approximation (no proven bound).
BOUNDED_REGION_POINTS = 4096


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
