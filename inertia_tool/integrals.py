"""Volume integrals of a closed triangle mesh by signed tetrahedra.

Each triangle ``(a, b, c)`` (counter-clockwise seen from outside) and a reference point ``o`` span a
tetrahedron of signed volume ``v = (a−o)·((b−o)×(c−o))/6``.  For a tetrahedron with one vertex at the
origin and the others at ``p1, p2, p3`` the moments of a unit density are exact polynomials of the
vertices (Tonon, F., "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of its vertex
coordinates", J. Math. Stat. 1 (2004) 8–11; the same identity is the covariance form of Blow & Binstock):

* ``∫ 1 dV = v``
* ``∫ x_i dV = v (p1 + p2 + p3)_i / 4``
* ``∫ x_i x_j dV = v/20 · [ Σ_k p_k,i p_k,j + s_i s_j ]`` with ``s = p1 + p2 + p3``

Summing over the faces gives the integrals over the polyhedron exactly (the contributions outside the
solid cancel in pairs), which is Eq. (4.13) of the chapter made discrete.  The inertia tensor follows as
``I = tr(C) 𝟙 − C`` from the second-moment matrix ``C_ij = ∫ x_i x_j dV`` (Eq. 4.11).

Precision: the reference point is chosen near the body (the mean of the vertex bounding box) and the
coordinates are made relative to it before any product is formed, so a part far from the origin keeps
all its digits (a unit cube at 1e8 keeps its central tensor to ~1e-16 relative).

Memory: faces are processed in chunks of ``chunk_size`` so temporaries stay bounded.

Speed: when the C extension is built (``inertia_tool._native``) the sums run in one pass over the faces
in C, each sum compensated (TwoSum), so they agree with the numpy path below (the reference) to round-off
and are, if anything, more accurate.

Everything here is pure: SI numpy arrays in, numpy arrays out.  See ``docs/conventions.md``.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np
from numpy.typing import NDArray

from .values import frozen_value
from ._native import accel, faces_for_c, threads

__all__ = ["VolumeMoments", "volume_moments", "body_volume_moments", "second_moment_to_inertia", "bounding_box"]

_DEFAULT_CHUNK = 1 << 15


@frozen_value
class VolumeMoments:
    """Zeroth, first and second volume moments of a solid (unit density).

    Attributes
    ----------
    volume : float
        ``∫ dV`` in m³ (signed: negative for an inside-out surface).
    centroid : (3,) float
        ``∫ x dV / V`` in m, mesh axes (NaN when the volume is zero).
    second_moment : (3, 3) float
        ``C_ij = ∫ (x−c)_i (x−c)_j dV`` in m⁵ about the centroid ``c``, mesh axes.
    area : float
        Surface area in m² (sum of triangle areas).
    zero_area_faces : int
        Triangles whose doubled area is at most ``area_rtol · L²`` (``L`` the bounding-box diagonal).
    """

    volume: float
    centroid: np.ndarray
    second_moment: np.ndarray
    area: float
    zero_area_faces: int = 0


_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))

#: Per-label raw sums: volume (L,), first moment (L, 3), second moment (L, 3, 3), area (L,), zero-area faces (L,).
_Sums = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]


def _tetra_sums(vertices: np.ndarray, faces: np.ndarray, origin: np.ndarray, chunk_size: int,
                labels: np.ndarray | None = None, n_labels: int = 1, area_floor: float = 0.0) -> _Sums:
    """Accumulate per-label raw sums about ``origin``.

    Returns arrays ``vol (L,)``, ``first (L, 3)``, ``second (L, 3, 3)``, ``area (L,)``, ``zero (L,)`` where
    the sums are ``Σ v``, ``Σ v s / 4`` and ``Σ v/20 (Σ_k p_k p_kᵀ + s sᵀ)`` over the faces of each label,
    with ``p_k`` the corners relative to ``origin``, ``s = p1 + p2 + p3`` and
    ``6 v = p1 · ((p2 − p1) × (p3 − p1)) = p1 · (p2 × p3)`` (one cross product serves volume and area).
    """
    lib = accel()
    if lib is not None:
        return _tetra_sums_c(lib, vertices, faces, origin, labels, n_labels, area_floor)
    vol = np.zeros(n_labels)
    first = np.zeros((n_labels, 3))
    second = np.zeros((n_labels, 3, 3))
    area = np.zeros(n_labels)
    zero = np.zeros(n_labels, dtype=np.int64)
    coords = np.ascontiguousarray((vertices - origin).T)      # (3, n): component arrays gather faster
    n_faces = len(faces)
    for start in range(0, n_faces, chunk_size):
        f = faces[start:start + chunk_size]
        a = coords[:, f[:, 0]]
        b = coords[:, f[:, 1]]
        c = coords[:, f[:, 2]]
        e1 = b - a
        e2 = c - a
        nrm = np.empty_like(a)
        nrm[0] = e1[1] * e2[2] - e1[2] * e2[1]
        nrm[1] = e1[2] * e2[0] - e1[0] * e2[2]
        nrm[2] = e1[0] * e2[1] - e1[1] * e2[0]
        v6 = np.einsum("ij,ij->j", a, nrm)                      # 6 × signed volume
        tri_area = 0.5 * np.sqrt(np.einsum("ij,ij->j", nrm, nrm))
        tiny = tri_area <= 0.5 * area_floor
        s = a + b + c
        # rows (a_x, b_x, c_x, s_x, a_y, ..., s_z): Σ_f v6 Q Qᵀ holds every Σ v6 (Σ_k p_ki p_kj + s_i s_j)
        q = np.concatenate([np.stack([a[i], b[i], c[i], s[i]]) for i in range(3)])
        if labels is None:
            zero[0] += int(np.count_nonzero(tiny))
            vol[0] += v6.sum() / 6.0
            first[0] += s @ v6 / 24.0
            g = (q * v6) @ q.T
            second[0] += np.array([[np.trace(g[4 * i:4 * i + 4, 4 * j:4 * j + 4]) for j in range(3)]
                                   for i in range(3)]) / 120.0
            area[0] += tri_area.sum()
        else:
            lab = labels[start:start + chunk_size]
            zero += np.bincount(lab[tiny], minlength=n_labels)
            vol += np.bincount(lab, weights=v6, minlength=n_labels) / 6.0
            area += np.bincount(lab, weights=tri_area, minlength=n_labels)
            for i in range(3):
                first[:, i] += np.bincount(lab, weights=v6 * s[i], minlength=n_labels) / 24.0
            for i, j in _PAIRS:
                w = v6 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j])
                second[:, i, j] += np.bincount(lab, weights=w, minlength=n_labels) / 120.0
                if i != j:
                    second[:, j, i] = second[:, i, j]
    return vol, first, second, area, zero


def _tetra_sums_c(lib: ModuleType, vertices: np.ndarray, faces: np.ndarray, origin: np.ndarray,
                  labels: np.ndarray | None, n_labels: int, area_floor: float) -> _Sums:
    """``_tetra_sums`` on the C extension: the same sums in one pass, compensated; same return values."""
    sums = np.empty((n_labels, 11))
    zero = np.empty(n_labels, dtype=np.int64)
    lib.tetra_sums(np.ascontiguousarray(vertices, dtype=np.float64), faces_for_c(faces),
                   tuple(float(x) for x in origin), float(area_floor),
                   None if labels is None else np.ascontiguousarray(labels, dtype=np.int64), sums, zero, threads())
    second = np.empty((n_labels, 3, 3))
    for k, (i, j) in enumerate(_PAIRS):   # columns 4..9 hold xx yy zz xy xz yz
        second[:, i, j] = second[:, j, i] = sums[:, 4 + k]
    return sums[:, 0].copy(), sums[:, 1:4].copy(), second, sums[:, 10].copy(), zero


def _finish(vol: float, first: np.ndarray, second: np.ndarray, area: float, origin: np.ndarray,
            zero: int = 0) -> VolumeMoments:
    if vol != 0.0:
        d = first / vol                       # centroid relative to origin
        central = second - vol * np.outer(d, d)
        central = 0.5 * (central + central.T)
        centroid = origin + d
    else:
        centroid = np.full(3, np.nan)
        central = second.copy()
    return VolumeMoments(volume=float(vol), centroid=centroid, second_moment=central, area=float(area),
                         zero_area_faces=int(zero))


def bounding_box(vertices: np.ndarray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Corners ``(lo, hi)`` of the axis-aligned bounding box of (n, 3) vertices, each (3,), same unit.

    The values of ``vertices.min(axis=0)`` and ``.max(axis=0)`` (NaN propagates; a zero may come out as +0.0
    where numpy gives -0.0), in one pass over the rows on the C extension, else column by column (several times
    faster on millions of vertices than numpy's reduction over the short axis).
    """
    v = np.asarray(vertices)
    lib = accel()
    if lib is not None and len(v) and v.dtype == np.float64 and v.ndim == 2 and v.flags.c_contiguous:
        lo3, hi3, _ = lib.bounds(v, threads())      # one pass over the rows, NaN propagating like min/max
        return np.array(lo3), np.array(hi3)
    lo = np.array([v[:, i].min() for i in range(3)], dtype=np.float64)
    hi = np.array([v[:, i].max() for i in range(3)], dtype=np.float64)
    return lo, hi


def reference_point(vertices: np.ndarray) -> np.ndarray:
    """A point near the body: the centre of the vertex bounding box, (3,) m."""
    if len(vertices) == 0:
        return np.zeros(3)
    lo, hi = bounding_box(vertices)
    return 0.5 * (lo + hi)


def _area_floor(vertices: np.ndarray, area_rtol: float) -> float:
    if len(vertices) == 0:
        return 0.0
    lo, hi = bounding_box(vertices)
    return area_rtol * float(np.sum((hi - lo) ** 2))


def volume_moments(vertices: np.ndarray, faces: np.ndarray, *, origin: np.ndarray | None = None,
                   chunk_size: int = _DEFAULT_CHUNK, area_rtol: float = 1e-14) -> VolumeMoments:
    """Exact volume, centroid and central second moment of the polyhedron bounded by ``faces``.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex coordinates in m.
    faces : (m, 3) int
        Triangles, counter-clockwise seen from outside (outward normals).
    origin : (3,) float, optional
        Reference point of the tetrahedra; defaults to the bounding-box centre, which keeps precision for
        parts far from the origin.  Any point gives the same result up to round-off.
    chunk_size : int
        Faces processed per vectorised step (bounds temporary memory at about 400 bytes per face).
    area_rtol : float
        Triangles with doubled area at most ``area_rtol · L²`` (``L`` the bounding-box diagonal) are counted
        in ``zero_area_faces`` (they contribute nothing either way).

    Returns
    -------
    VolumeMoments
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    o = reference_point(vertices) if origin is None else np.asarray(origin, dtype=np.float64)
    vol, first, second, area, zero = _tetra_sums(vertices, faces, o, max(1, int(chunk_size)),
                                                 area_floor=_area_floor(vertices, area_rtol))
    return _finish(vol[0], first[0], second[0], area[0], o, zero[0])


def body_volume_moments(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n_labels: int, *,
                        origin: np.ndarray | None = None, chunk_size: int = _DEFAULT_CHUNK,
                        area_rtol: float = 1e-14) -> list[VolumeMoments]:
    """Like :func:`volume_moments` but separately for each group of faces (``labels[i]`` in ``[0, n_labels)``).

    Used for meshes with several shells (bodies and cavities); one pass over the faces.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    o = reference_point(vertices) if origin is None else np.asarray(origin, dtype=np.float64)
    if n_labels == 1:
        return [volume_moments(vertices, faces, origin=o, chunk_size=chunk_size, area_rtol=area_rtol)]
    vol, first, second, area, zero = _tetra_sums(vertices, np.asarray(faces), o, max(1, int(chunk_size)),
                                                 labels=np.asarray(labels, dtype=np.intp), n_labels=n_labels,
                                                 area_floor=_area_floor(vertices, area_rtol))
    return [_finish(vol[k], first[k], second[k], area[k], o, zero[k]) for k in range(n_labels)]


def second_moment_to_inertia(second_moment: np.ndarray, density: float = 1.0) -> np.ndarray:
    """Inertia tensor ``I = ρ (tr(C) 𝟙 − C)`` from the second-moment matrix ``C`` (Eq. 4.11/4.13).

    Parameters
    ----------
    second_moment : (3, 3) float
        ``C_ij = ∫ x_i x_j dV`` in m⁵ about some point.
    density : float
        kg/m³.

    Returns
    -------
    (3, 3) float
        kg·m² about the same point; off-diagonals are −∫xy dm (tensor convention).
    """
    c = np.asarray(second_moment, dtype=np.float64)
    inertia: NDArray[np.float64] = density * (np.trace(c) * np.eye(3) - c)
    return inertia
