"""Temporary stand-in for :mod:`inertia_tool.mesh.intersect` (being written; same interface).

Face pairs whose boxes overlap come from :func:`~.union._grid_pairs`; pairs sharing a vertex are not tested
(a crossing beyond a shared vertex is missed here — the real module handles it); the rest are classified in
float64 with a distance tolerance of ``1e-10 ×`` the bounding-box diagonal:

* non-coplanar: *crossing* when each triangle has corners strictly on both sides of the other's plane and
  the two segments they cut from the planes' common line overlap with positive length, else *contact*;
* coplanar: the interiors overlap unless an edge line of one separates them; overlapping interiors with the
  same normal are *crossing*, with opposite normals *coplanar_opposite*; otherwise *contact*.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .union import _grid_pairs, triangles_meet

__all__ = ["SurfaceContacts", "surface_contacts"]

#: Beyond this many faces the stand-in does not try (it is slow there) and reports an incomplete check.
_MAX_FACES = 200_000


@dataclass(frozen=True)
class SurfaceContacts:
    crossing: np.ndarray
    coplanar_opposite: np.ndarray
    contact: np.ndarray
    complete: bool


def _interval(t, d, direction):
    """Interval (lo, hi) of ``direction · x`` over the cut of triangles ``t`` by the plane with distances d."""
    lo = np.full(len(t), np.inf)
    hi = np.full(len(t), -np.inf)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        di, dj = d[:, i], d[:, j]
        cut = di * dj < 0
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.where(cut, di / (di - dj), 0.0)
        p = t[:, i] + s[:, None] * (t[:, j] - t[:, i])
        x = np.einsum("ij,ij->i", p, direction)
        lo = np.where(cut, np.minimum(lo, x), lo)
        hi = np.where(cut, np.maximum(hi, x), hi)
        on = di == 0
        x = np.einsum("ij,ij->i", t[:, i], direction)
        lo = np.where(on, np.minimum(lo, x), lo)
        hi = np.where(on, np.maximum(hi, x), hi)
    return lo, hi


def _classify(t1, t2, tol):
    """(crossing, coplanar_opposite) (k,) bool for triangle pairs that meet."""
    n1 = np.cross(t1[:, 1] - t1[:, 0], t1[:, 2] - t1[:, 0])
    n2 = np.cross(t2[:, 1] - t2[:, 0], t2[:, 2] - t2[:, 0])
    u1 = n1 / np.linalg.norm(n1, axis=1)[:, None]
    u2 = n2 / np.linalg.norm(n2, axis=1)[:, None]
    d1 = np.einsum("ikj,ij->ik", t1 - t2[:, :1], u2)          # corners of t1 from t2's plane
    d2 = np.einsum("ikj,ij->ik", t2 - t1[:, :1], u1)
    d1 = np.where(np.abs(d1) <= tol, 0.0, d1)
    d2 = np.where(np.abs(d2) <= tol, 0.0, d2)
    coplanar = np.all(d1 == 0, axis=1) & np.all(d2 == 0, axis=1)
    straddle1 = np.any(d1 > 0, axis=1) & np.any(d1 < 0, axis=1)
    straddle2 = np.any(d2 > 0, axis=1) & np.any(d2 < 0, axis=1)
    line = np.cross(u1, u2)
    norm = np.linalg.norm(line, axis=1)
    line = line / np.where(norm > 0, norm, 1.0)[:, None]
    lo1, hi1 = _interval(t1, d1, line)
    lo2, hi2 = _interval(t2, d2, line)
    crossing = ~coplanar & straddle1 & straddle2 & (np.minimum(hi1, hi2) - np.maximum(lo1, lo2) > tol)
    # coplanar: separating edge lines (in the plane) mean disjoint interiors
    separated = np.zeros(len(t1), dtype=bool)
    for a, b in ((t1, t2), (t2, t1)):
        for i, j in ((0, 1), (1, 2), (2, 0)):
            axis = np.cross(u1, a[:, j] - a[:, i])
            axis /= np.maximum(np.linalg.norm(axis, axis=1), 1e-300)[:, None]
            pa = np.einsum("ikj,ij->ik", a, axis)
            pb = np.einsum("ikj,ij->ik", b, axis)
            separated |= (pa.max(axis=1) <= pb.min(axis=1) + tol) | (pb.max(axis=1) <= pa.min(axis=1) + tol)
    overlap = coplanar & ~separated
    same = np.einsum("ij,ij->i", u1, u2) > 0
    return crossing | (overlap & same), overlap & ~same


def surface_contacts(vertices, faces, *, max_pairs=None) -> SurfaceContacts:
    """Face pairs that cross, overlap coplanar with opposite normals, or touch (see the module docstring)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    empty = np.zeros((0, 2), dtype=np.int64)
    if len(f) < 2:
        return SurfaceContacts(empty, empty, empty, True)
    if len(f) > _MAX_FACES:
        return SurfaceContacts(empty, empty, empty, False)
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    v = v - centre
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    tri = v[f]
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    limit = int(max_pairs) if max_pairs is not None else max(64 * len(f), 1 << 20)
    pairs = _grid_pairs(lo, hi, np.ones(len(f), dtype=bool), limit, 1e-9 * diag)
    if pairs is None:
        return SurfaceContacts(empty, empty, empty, False)
    a, b = pairs
    shared = np.zeros(len(a), dtype=bool)
    for i in range(3):
        for j in range(3):
            shared |= f[a, i] == f[b, j]
    a, b = a[~shared], b[~shared]
    tol = 1e-10 * diag
    out: tuple[list, list, list] = ([], [], [])
    step = 1 << 18
    for s in range(0, len(a), step):
        aa, bb = a[s:s + step], b[s:s + step]
        meet = triangles_meet(tri[aa], tri[bb], 1e-12 * diag ** 3)
        aa, bb = aa[meet], bb[meet]
        cross, opposite = _classify(tri[aa], tri[bb], tol)
        out[0].append(np.c_[aa[cross], bb[cross]])
        out[1].append(np.c_[aa[opposite], bb[opposite]])
        rest = ~cross & ~opposite
        out[2].append(np.c_[aa[rest], bb[rest]])

    def cat(xs):
        return np.vstack(xs).astype(np.int64) if xs else empty

    return SurfaceContacts(cat(out[0]), cat(out[1]), cat(out[2]), True)
