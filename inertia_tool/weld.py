"""Welding triangle corners into shared vertices.

STL stores every triangle with its own three corners; topology checks need to know which corners are the
same vertex.  ``weld_exact`` merges corners whose coordinates are bit-identical (what every exporter writes
for a shared corner), in bounded memory; ``weld_tolerance`` merges vertices closer than a tolerance on a
grid, for meshes whose exporter rounded shared corners differently.  Welding never moves a coordinate that
the integrals use: ``weld_exact`` keeps the exact values, ``weld_tolerance`` only changes connectivity.
"""

from __future__ import annotations

import numpy as np

__all__ = ["weld_exact", "weld_tolerance"]

_CHUNK = 1 << 21
_MIX = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x165667B19E3779F9))


def _hash_rows(rows: np.ndarray) -> np.ndarray:
    """64-bit hash of each row's exact bit pattern, (k,) uint64.  Collisions are checked by the caller."""
    rows = rows + rows.dtype.type(0)  # -0.0 -> +0.0 so that equal values hash equally
    if rows.dtype == np.float32:
        bits = rows.view(np.uint32).astype(np.uint64)
    elif rows.dtype == np.float64:
        bits = rows.view(np.uint64)
    else:
        bits = rows.astype(np.int64).view(np.uint64)
    with np.errstate(over="ignore"):
        h = bits[:, 0] * _MIX[0]
        h ^= (h >> np.uint64(29))
        h += bits[:, 1] * _MIX[1]
        h ^= (h >> np.uint64(31))
        h += bits[:, 2] * _MIX[2]
        h ^= (h >> np.uint64(32))
    return h


def _index_dtype(n: int):
    return np.int32 if n < 2**31 - 1 else np.int64


def _unique_rows_fallback(points: np.ndarray):
    uniq, inverse = np.unique(points, axis=0, return_inverse=True)
    return uniq.astype(np.float64), inverse.reshape(-1)


def weld_exact(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge bit-identical triangle corners.

    Parameters
    ----------
    corners : (m, 3, 3) float32 or float64
        Triangle corners (a triangle soup).

    Returns
    -------
    vertices : (n, 3) float64
        Distinct corner positions (exact values of the input).
    faces : (m, 3) int32 or int64
        Indices into ``vertices``.
    """
    m = len(corners)
    flat = corners.reshape(-1, 3)
    k = len(flat)
    keys = np.empty(k, dtype=np.uint64)
    for s in range(0, k, _CHUNK):
        keys[s:s + _CHUNK] = _hash_rows(flat[s:s + _CHUNK])
    ordered = np.sort(keys)
    first = np.empty(k, dtype=bool)
    first[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    uniq = ordered[first]
    del ordered, first
    idx_t = _index_dtype(len(uniq))
    inverse = np.empty(k, dtype=idx_t)
    for s in range(0, k, _CHUNK):
        inverse[s:s + _CHUNK] = np.searchsorted(uniq, keys[s:s + _CHUNK])
    del keys
    vertices = np.empty((len(uniq), 3), dtype=np.float64)
    for s in range(0, k, _CHUNK):
        vertices[inverse[s:s + _CHUNK]] = flat[s:s + _CHUNK]
    # a hash collision would map two different points to one vertex: verify, fall back if so
    for s in range(0, k, _CHUNK):
        if not np.array_equal(vertices[inverse[s:s + _CHUNK]], flat[s:s + _CHUNK].astype(np.float64) + 0.0):
            uniq_pts, inv = _unique_rows_fallback(flat.astype(np.float64) + 0.0)
            return uniq_pts, inv.astype(_index_dtype(len(uniq_pts))).reshape(m, 3)
    return vertices, inverse.reshape(m, 3)


def weld_tolerance(vertices: np.ndarray, faces: np.ndarray, tolerance: float) -> np.ndarray:
    """Merge vertices that fall in the same cell of a grid of spacing ``tolerance`` (m).

    Two vertices closer than ``tolerance`` usually share a cell (they can straddle a cell boundary, so this
    is a heuristic for rounding noise, not a distance query).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int
    tolerance : float
        Grid spacing in the units of ``vertices``; must be positive.

    Returns
    -------
    faces : (m, 3) int
        Faces re-indexed onto one representative vertex per cell (indices into the same ``vertices``).
    """
    if not tolerance > 0:
        raise ValueError(f"Expected a positive tolerance, got {tolerance}")
    lo = vertices.min(axis=0)
    cells = np.floor((vertices - lo) / tolerance + 0.5)
    if cells.max() < 2**20:
        c = cells.astype(np.int64)
        key = (c[:, 0] << 42) | (c[:, 1] << 21) | c[:, 2]
        _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    else:
        _, first, inverse = np.unique(cells, axis=0, return_index=True, return_inverse=True)
    representative = first[inverse.reshape(-1)]
    return representative[faces].astype(faces.dtype)
