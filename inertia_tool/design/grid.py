"""Voxel grid of a closed mesh: which cell centres are inside, and how far they are from the surface.

Inside/outside is the **winding number along vertical rays**: for every column of cell centres a ray is cast
upwards; each triangle it crosses adds the sign of the triangle's normal z component (+1 leaving an outward-wound
solid, −1 entering).  The winding number of a centre is the sum over the crossings above it: 1 inside a body,
0 outside, 0 again inside a cavity (its shell is wound inward).  The grid is shifted by an irrational fraction of
a cell so that no ray runs through an edge or vertex of a mesh whose coordinates are round numbers.

The distance to the surface is the Euclidean distance transform of the inside mask (scipy.ndimage): the
distance from a centre to the nearest centre of the other class, signed (positive inside).  It is an
approximation (within about a cell of the true distance), good enough to place a cavity; the wall of the final
part is then measured exactly (:func:`surface_distance`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import UsageError

__all__ = ["InteriorGrid", "interior_grid", "surface_distance"]

#: Fraction of a cell by which the grid is shifted off the mesh's round coordinates (irrational ratios).
_SHIFT = np.array([0.1234567 * np.sqrt(2.0), 0.0765432 * np.sqrt(3.0), 0.0])

#: Most (column, triangle) pairs examined at once while casting rays (bounds the memory of one batch).
_PAIR_BATCH = 2_000_000


@dataclass(frozen=True)
class InteriorGrid:
    """A regular grid of cubic cells over a closed mesh.

    Attributes
    ----------
    origin : (3,) float
        Centre of cell (0, 0, 0), m, mesh axes.
    spacing : float
        Cell edge ``h``, m.
    inside : (nx, ny, nz) bool
        Cell centre inside the solid (winding number ≥ 1).
    signed_distance : (nx, ny, nz) float
        Approximate distance from the cell centre to the surface, m, positive inside (distance transform).
    """

    origin: np.ndarray
    spacing: float
    inside: np.ndarray
    signed_distance: np.ndarray

    @property
    def shape(self) -> tuple:
        """``(nx, ny, nz)``."""
        return self.inside.shape

    def centers(self, index) -> np.ndarray:
        """Centres of the cells ``index`` (a tuple of index arrays, as from ``np.nonzero``), (n, 3) m."""
        return self.origin + self.spacing * np.column_stack(index).astype(np.float64)


def _winding_columns(vertices, faces, origin, spacing, shape) -> np.ndarray:
    """Winding number of every cell centre by vertical rays (module docstring); (nx, ny, nz) int."""
    nx, ny, nz = shape
    tri = vertices[faces]                                  # (m, 3, 3)
    p = (tri[:, :, :2] - origin[:2]) / spacing             # column coordinates of the corners
    lo = np.ceil(p.min(axis=1)).astype(np.int64)
    hi = np.floor(p.max(axis=1)).astype(np.int64)
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, [nx - 1, ny - 1])
    counts = np.maximum(hi[:, 0] - lo[:, 0] + 1, 0) * np.maximum(hi[:, 1] - lo[:, 1] + 1, 0)
    delta = np.zeros((nx, ny, nz + 1), dtype=np.int32)
    order = np.nonzero(counts)[0]
    start = 0
    while start < len(order):
        # a batch of triangles whose pairs stay under _PAIR_BATCH (at least one triangle)
        cum = np.cumsum(counts[order[start:]])
        stop = start + max(1, int(np.searchsorted(cum, _PAIR_BATCH, side="right")))
        ids = order[start:stop]
        start = stop
        c = counts[ids]
        tri_of_pair = np.repeat(ids, c)
        local = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
        width = np.repeat(hi[ids, 0] - lo[ids, 0] + 1, c)
        ci = lo[tri_of_pair, 0] + local % width
        cj = lo[tri_of_pair, 1] + local // width
        a, b, d = p[tri_of_pair, 0], p[tri_of_pair, 1], p[tri_of_pair, 2]
        q = np.column_stack([ci, cj]).astype(np.float64)
        # signed areas: q inside the projected triangle iff all three have the sign of the triangle's area
        w0 = (b[:, 0] - q[:, 0]) * (d[:, 1] - q[:, 1]) - (b[:, 1] - q[:, 1]) * (d[:, 0] - q[:, 0])
        w1 = (d[:, 0] - q[:, 0]) * (a[:, 1] - q[:, 1]) - (d[:, 1] - q[:, 1]) * (a[:, 0] - q[:, 0])
        w2 = (a[:, 0] - q[:, 0]) * (b[:, 1] - q[:, 1]) - (a[:, 1] - q[:, 1]) * (b[:, 0] - q[:, 0])
        area = w0 + w1 + w2
        hit = np.where(area > 0, (w0 > 0) & (w1 > 0) & (w2 > 0), (w0 < 0) & (w1 < 0) & (w2 < 0)) & (area != 0)
        if not np.any(hit):
            continue
        w0, w1, w2, area = w0[hit], w1[hit], w2[hit], area[hit]
        z = tri[tri_of_pair[hit], :, 2]
        z_cross = (w0 * z[:, 0] + w1 * z[:, 1] + w2 * z[:, 2]) / area
        sign = np.where(area > 0, 1, -1).astype(np.int32)   # projected area > 0 ⇔ normal z > 0
        # cells strictly below the crossing: k < k_cross
        k_cross = np.clip(np.ceil((z_cross - origin[2]) / spacing).astype(np.int64), 0, nz)
        np.add.at(delta, (ci[hit], cj[hit], k_cross), sign)
    # winding(k) = Σ of crossings with k_cross > k
    winding = np.cumsum(delta[:, :, ::-1], axis=2)[:, :, ::-1]
    return winding[:, :, 1:]


def interior_grid(vertices, faces, *, spacing: float, padding: int = 2) -> InteriorGrid:
    """Voxelise a closed, outward-wound mesh on cubic cells of edge ``spacing``.

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        Outward-wound triangles of a closed surface.
    spacing : float
        Cell edge, m, > 0.
    padding : int
        Cells of outside margin around the bounding box.

    Returns
    -------
    InteriorGrid
    """
    from scipy.ndimage import distance_transform_edt

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if not (np.isfinite(spacing) and spacing > 0):
        raise UsageError(f"Expected a positive cell `spacing`, got {spacing!r}")
    lo, hi = v.min(axis=0), v.max(axis=0)
    shape = tuple(int(n) for n in np.ceil((hi - lo) / spacing).astype(int) + 2 * padding)
    origin = lo - (padding - 0.5) * spacing + _SHIFT * spacing
    inside = _winding_columns(v, f, origin, spacing, shape) >= 1
    signed = (distance_transform_edt(inside, sampling=spacing)
              - distance_transform_edt(~inside, sampling=spacing))
    return InteriorGrid(origin=origin, spacing=float(spacing), inside=inside, signed_distance=signed)


def _closest_on_triangles(p, a, b, c):
    """Squared distance from points ``p`` to triangles ``abc`` (all (k, 3)), Ericson's region tests."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v = np.where(denom != 0, vb / denom, 0.0)
        w = np.where(denom != 0, vc / denom, 0.0)
        closest = a + ab * v[:, None] + ac * w[:, None]                    # interior of the face
        # edges
        t_ab = np.where(d1 - d3 != 0, d1 / (d1 - d3), 0.0)
        t_ac = np.where(d2 - d6 != 0, d2 / (d2 - d6), 0.0)
        t_bc = np.where((d4 - d3) + (d5 - d6) != 0, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 0.0)
    on_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    on_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    on_bc = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)
    closest = np.where(on_bc[:, None], b + (c - b) * t_bc[:, None], closest)
    closest = np.where(on_ac[:, None], a + ac * t_ac[:, None], closest)
    closest = np.where(on_ab[:, None], a + ab * t_ab[:, None], closest)
    closest = np.where(((d6 >= 0) & (d5 <= d6))[:, None], c, closest)
    closest = np.where(((d3 >= 0) & (d4 <= d3))[:, None], b, closest)
    closest = np.where(((d1 <= 0) & (d2 <= 0))[:, None], a, closest)
    diff = p - closest
    return np.einsum("ij,ij->i", diff, diff)


def _expand_ranges(begin: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For ranges ``[begin, begin + count)``: (range number, position) of every element, concatenated."""
    owner = np.repeat(np.arange(len(count)), count)
    offset = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    return owner, np.repeat(begin, count) + offset


def surface_distance(points, vertices, faces, *, cutoff: float, max_pairs: int = 2_000_000) -> np.ndarray:
    """Exact distance from each point to the nearest triangle, clipped at ``cutoff`` (m).

    Points are binned on cubic cells of edge ``cutoff``; each triangle is paired with the points of the cells
    its bounding box, grown by ``cutoff``, touches (every point closer than ``cutoff`` is among them, and each
    pair occurs once).  Pairs are then culled by the distance to the triangle's bounding box and plane before
    the exact point-triangle distance (Ericson, *Real-Time Collision Detection*, §5.1.5).

    Parameters
    ----------
    points : (k, 3) float
        m.
    vertices, faces
        The surface.
    cutoff : float
        Distances at or beyond it are returned as ``cutoff`` (m), > 0.
    max_pairs : int
        Most (cell, triangle) or (point, triangle) pairs held at once (memory bound).

    Returns
    -------
    (k,) float
    """
    pts = np.asarray(points, dtype=np.float64)
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    result = np.full(len(pts), float(cutoff))
    if len(pts) == 0 or len(tri) == 0:
        return result
    if not (np.isfinite(cutoff) and cutoff > 0):
        raise UsageError(f"Expected a positive `cutoff`, got {cutoff!r}")
    base = pts.min(axis=0)
    n_cells = np.floor((pts.max(axis=0) - base) / cutoff).astype(np.int64) + 1
    stride = np.array([n_cells[1] * n_cells[2], n_cells[2], 1], dtype=np.int64)
    pcell = np.floor((pts - base) / cutoff).astype(np.int64) @ stride
    order = np.argsort(pcell, kind="stable")
    sorted_cells = pcell[order]
    box_lo, box_hi = tri.min(axis=1), tri.max(axis=1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    unit_normal = normal / np.where(length > 0, length, 1.0)[:, None]   # degenerate: 0, no plane bound
    tlo = np.clip(np.floor((box_lo - cutoff - base) / cutoff).astype(np.int64), 0, n_cells - 1)
    thi = np.floor((box_hi + cutoff - base) / cutoff).astype(np.int64)
    outside = np.any(thi < 0, axis=1) | np.any(tlo > n_cells - 1, axis=1) | np.any(
        (box_lo - cutoff - base) > (n_cells * cutoff), axis=1)
    thi = np.clip(thi, 0, n_cells - 1)
    span = np.where(outside[:, None], 0, thi - tlo + 1)
    count = span.prod(axis=1)
    best = np.full(len(pts), float(cutoff) ** 2)
    tri_ids = np.nonzero(count)[0]
    cum = np.cumsum(count[tri_ids])
    first = 0
    while first < len(tri_ids):
        done = cum[first - 1] if first else 0
        last = max(first + 1, int(np.searchsorted(cum, done + max_pairs, side="right")))
        ids = tri_ids[first:last]
        first = last
        owner, local = _expand_ranges(np.zeros(len(ids), dtype=np.int64), count[ids])
        sy, sz = span[ids[owner], 1], span[ids[owner], 2]
        cells = (tlo[ids[owner]] + np.column_stack([local // (sy * sz), (local // sz) % sy, local % sz])) @ stride
        begin = np.searchsorted(sorted_cells, cells, side="left")
        end = np.searchsorted(sorted_cells, cells, side="right")
        has = end > begin
        cell_tri = ids[owner[has]]
        begin, n = begin[has], (end - begin)[has]
        for s in range(0, len(n), max(1, max_pairs // max(1, int(n.max(initial=1))))):
            which, pos = _expand_ranges(begin[s:s + max_pairs], n[s:s + max_pairs])
            pair_point = order[pos]
            pair_tri = cell_tri[s:s + max_pairs][which]
            p = pts[pair_point]
            gap = np.maximum(np.maximum(box_lo[pair_tri] - p, p - box_hi[pair_tri]), 0.0)
            keep = np.einsum("ij,ij->i", gap, gap) < best[pair_point]
            plane = np.einsum("ij,ij->i", p - tri[pair_tri, 0], unit_normal[pair_tri])
            keep &= plane * plane < best[pair_point]
            if not np.any(keep):
                continue
            pair_point, pair_tri = pair_point[keep], pair_tri[keep]
            t = tri[pair_tri]
            d2 = _closest_on_triangles(pts[pair_point], t[:, 0], t[:, 1], t[:, 2])
            np.minimum.at(best, pair_point, d2)
    return np.sqrt(best)
