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

import math
from dataclasses import dataclass

import numpy as np

from ..errors import UsageError

__all__ = ["InteriorGrid", "SurfaceTree", "interior_grid", "surface_distance"]

#: Fraction of a cell by which the grid is shifted off the mesh's round coordinates (irrational ratios).
_SHIFT = np.array([0.1234567 * np.sqrt(2.0), 0.0765432 * np.sqrt(3.0), 0.0])

#: Most (column, triangle) pairs examined at once while casting rays (bounds the memory of one batch).
_PAIR_BATCH = 200_000


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
    signed_distance : (nx, ny, nz) float32
        Approximate distance from the cell centre to the surface, m, positive inside (distance transform).
    depth_cap : float
        m: distances beyond it read as ``±depth_cap`` (``inf``: none; see :func:`interior_grid`).
    """

    origin: np.ndarray
    spacing: float
    inside: np.ndarray
    signed_distance: np.ndarray
    depth_cap: float = math.inf

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
    # winding(k) = Σ of crossings with k_cross > k (in place: int32, no second grid)
    np.cumsum(delta[:, :, ::-1], axis=2, out=delta[:, :, ::-1])
    return delta[:, :, 1:]


def _capped_squared_distance(target: np.ndarray, reach: int) -> np.ndarray:
    """Squared distance, in cells, from every cell centre to the nearest ``target`` cell centre: exact up to
    ``reach`` cells, and above ``reach²`` (not necessarily exact) beyond.  float32, (nx, ny, nz).

    Separable (Saito and Toriwaki's decomposition): the distance along x by two scans, then
    ``d²(x, y, z) = min over |dy|, |dz| ≤ reach of g_x(x, y + dy, z + dz)² + dy² + dz²``, one axis at a time.  A
    nearest target within ``reach`` lies within ``reach`` along every axis, so it is among the candidates.
    Memory: three float32 grids (the distance, a scratch grid, the 1-D pass), whatever ``reach``.
    """
    far = np.float32(4.0 * (reach + 1) ** 2)
    g = np.where(target, np.float32(0.0), far).astype(np.float32)
    for i in range(1, g.shape[0]):                               # distance along x: forward, then backward
        np.minimum(g[i], g[i - 1] + 1.0, out=g[i])
    for i in range(g.shape[0] - 2, -1, -1):
        np.minimum(g[i], g[i + 1] + 1.0, out=g[i])
    np.minimum(g, far, out=g)
    np.multiply(g, g, out=g)
    scratch = np.empty_like(g)
    for axis in (1, 2):
        out = g.copy()
        n = g.shape[axis]
        for step in range(1, min(reach, n - 1) + 1):
            lo = [slice(None)] * 3
            hi = [slice(None)] * 3
            lo[axis], hi[axis] = slice(0, n - step), slice(step, n)
            lo_t, hi_t = tuple(lo), tuple(hi)
            np.add(g[lo_t], np.float32(step * step), out=scratch[lo_t])
            np.minimum(out[hi_t], scratch[lo_t], out=out[hi_t])          # a target `step` cells below
            np.add(g[hi_t], np.float32(step * step), out=scratch[hi_t])
            np.minimum(out[lo_t], scratch[hi_t], out=out[lo_t])          # … and above
        g = out
    return g


def interior_grid(vertices, faces, *, spacing: float, padding: int = 2,
                  depth_cap: float | None = None) -> InteriorGrid:
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
    depth_cap : float, optional
        m: distances are needed only up to here; deeper cells read as ``depth_cap`` (or more).  The capped
        transform holds three float32 grids instead of scipy's exact transform's ~70 bytes a cell.  ``None``:
        the exact transform everywhere.

    Returns
    -------
    InteriorGrid
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if not (np.isfinite(spacing) and spacing > 0):
        raise UsageError(f"Expected a positive cell `spacing`, got {spacing!r}")
    lo, hi = v.min(axis=0), v.max(axis=0)
    shape = tuple(int(n) for n in np.ceil((hi - lo) / spacing).astype(int) + 2 * padding)
    origin = lo - (padding - 0.5) * spacing + _SHIFT * spacing
    inside = _winding_columns(v, f, origin, spacing, shape) >= 1
    # float32 (a cell's depth to 1e-7 relative: the wall is measured exactly afterwards), one grid at a time
    if depth_cap is not None and depth_cap / spacing <= _MAX_REACH:
        reach = int(np.ceil(depth_cap / spacing))
        signed = _capped_squared_distance(~inside, reach)
        np.sqrt(signed, out=signed)
        outside = _capped_squared_distance(inside, reach)
        np.sqrt(outside, out=outside)
        signed -= outside
        del outside
        signed *= np.float32(spacing)
        cap = float(depth_cap)
        np.clip(signed, -cap, cap, out=signed)
    else:
        from scipy.ndimage import distance_transform_edt
        signed = distance_transform_edt(inside, sampling=spacing).astype(np.float32)
        signed -= distance_transform_edt(~inside, sampling=spacing).astype(np.float32)
        cap = math.inf
    return InteriorGrid(origin=origin, spacing=float(spacing), inside=inside, signed_distance=signed,
                        depth_cap=cap)


#: Cells of reach above which ``interior_grid`` uses scipy's exact transform (the capped one costs a pass of the
#: grid per cell of reach and axis).
_MAX_REACH = 40


class SurfaceTree:
    """The outer surface in libigl's AABB tree, built once and queried for exact point-surface distances.

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
    """

    def __init__(self, vertices, faces):
        import igl

        self.vertices = np.ascontiguousarray(vertices, dtype=np.float64)
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        self._tree = igl.AABB()
        self._tree.init(self.vertices, self.faces)

    def squared_distance(self, points) -> np.ndarray:
        """Squared distance from each point (k, 3) m to the nearest triangle, m², (k,)."""
        pts = np.asarray(points, dtype=np.float64)
        out = np.empty(len(pts))
        for start in range(0, len(pts), _QUERY_BATCH):          # bounds the (k, 3) closest points libigl returns
            chunk = np.ascontiguousarray(pts[start:start + _QUERY_BATCH])
            out[start:start + len(chunk)] = self._tree.squared_distance(self.vertices, self.faces, chunk)[0]
        return out


#: Points per libigl query (its closest-point output is 24 bytes a point).
_QUERY_BATCH = 1 << 18


def surface_distance(points, vertices, faces, *, cutoff: float, tree: SurfaceTree | None = None) -> np.ndarray:
    """Distance from each point to the nearest triangle, clipped at ``cutoff`` (m).

    The nearest triangle is found in libigl's AABB tree and the point-triangle distance evaluated in floating
    point (the closest point by the region tests of Ericson, *Real-Time Collision Detection*, §5.1.5): exact up
    to the rounding of a few dozen operations on the coordinates.

    Parameters
    ----------
    points : (k, 3) float
        m.
    vertices, faces
        The surface.
    cutoff : float
        Distances at or beyond it are returned as ``cutoff`` (m), > 0.
    tree : SurfaceTree, optional
        The same surface already in a tree (reused across calls).

    Returns
    -------
    (k,) float
    """
    pts = np.asarray(points, dtype=np.float64)
    result = np.full(len(pts), float(cutoff))
    if len(pts) == 0 or len(faces) == 0:
        return result
    if not (np.isfinite(cutoff) and cutoff > 0):
        raise UsageError(f"Expected a positive `cutoff`, got {cutoff!r}")
    if tree is None:
        tree = SurfaceTree(vertices, faces)
    return np.minimum(np.sqrt(tree.squared_distance(pts)), float(cutoff))
