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
in C, each sum compensated (TwoSum); the numpy path below (the reference) sums each shell's column by a tree of
TwoSums whose rounding errors are kept and added back (:func:`_label_sums`, whole-array operations whatever the
number of shells), so the two agree to round-off and share one round-off bound.

Everything here is pure: SI numpy arrays in, numpy arrays out.  See ``docs/conventions.md``.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from .values import frozen_value
from ._native import accel, faces_for_c, labels_for_c, threads
from .tolerances import ROUNDOFF_RTOL

__all__ = ["VolumeMoments", "volume_moments", "body_volume_moments", "second_moment_to_inertia", "bounding_box",
           "roundoff_bounds", "exact_volume_moments", "RoundoffBound", "accurate_shells", "total_roundoff",
           "total_roundoff_parts",
           "one_shell_moments"]

_DEFAULT_CHUNK = 1 << 15

#: The labels of a single shell's faces as the C round-off sums take them (none: every face is the shell's).
_NO_LABELS = np.zeros(0, dtype=np.int64)

#: Most terms a row that the numpy path sums by ``math.fsum`` rather than by a tree of TwoSums (the tree's ~10 numpy
#: calls a level cost more below about this; measured in session 17).
_FSUM_MAX_TERMS = 256

#: Largest shell (faces) :func:`accurate_shells` integrates in exact integer arithmetic (about 10 µs a face).
EXACT_MAX_FACES = 4096


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

#: Columns of the C kernel's sums (4..9: xx yy zz xy xz yz) that fill a second-moment matrix row by row.
_SECOND_COLUMNS = np.array([4, 7, 8, 7, 5, 9, 8, 9, 6])

if TYPE_CHECKING:     # annotations only: numpy.typing is not loaded at run time
    from typing import TypeAlias

    from numpy.typing import NDArray

    #: Per-label raw sums: volume (L,), first moment (L, 3), second moment (L, 3, 3), area (L,), zero-area faces
    #: (L,).
    _Sums: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                             NDArray[np.int64]]


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
    # each face's 11 terms in the C kernel's columns and operations (v6/6, v6·s/24, v6·(…)/120 for xx yy zz xy
    # xz yz, area); each label's column summed without error by a tree of TwoSums per chunk and the chunks'
    # (sum, error) pairs by TwoSum again (_label_sums, _add_pairs): within the compensated bound
    # (2 + m²u)·u·Σ|x| that roundoff_bounds charges both paths (issue 21: the plain sequential sum's m·u·Σ|x|
    # made the numpy path call a needle of aspect 1e7 flat that the C path, by its tighter bound, answered)
    coords = np.ascontiguousarray((vertices - origin).T)      # (3, n): component arrays gather faster
    # terms that overflow give inf and NaN silently, as on C (tidy17 saw numpy's RuntimeWarnings for a box at
    # 1e100 m): the sums' NaN is the signal, and the pipeline refuses a part whose integrals are not finite
    with np.errstate(over="ignore", invalid="ignore"):
        return _tetra_sums_numpy(coords, faces, chunk_size, labels, n_labels, area_floor)


def _tetra_sums_numpy(coords: np.ndarray, faces: np.ndarray, chunk_size: int, labels: np.ndarray | None,
                      n_labels: int, area_floor: float) -> _Sums:
    """:func:`_tetra_sums` on numpy: ``coords`` (3, n) the corners relative to the origin; same return values."""
    hi = np.zeros((n_labels, 11))
    lo = np.zeros((n_labels, 11))
    zero = np.zeros(n_labels, dtype=np.int64)
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
        terms = np.empty((11, len(f)))
        terms[10] = 0.5 * np.sqrt(np.einsum("ij,ij->j", nrm, nrm))     # area
        tiny = terms[10] <= 0.5 * area_floor
        sm = a + b + c
        terms[0] = v6 / 6.0
        for i in range(3):
            terms[1 + i] = v6 * sm[i] / 24.0
        for col, (i, j) in enumerate(_PAIRS, start=4):
            terms[col] = v6 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + sm[i] * sm[j]) / 120.0
        if labels is None:
            zero[0] += int(np.count_nonzero(tiny))
            ids = np.zeros(1, dtype=np.intp)
            part_hi, part_lo = _label_sums(terms, np.array([len(f)]))
        else:
            lab = np.asarray(labels[start:start + chunk_size])
            counts = np.bincount(lab, minlength=n_labels)      # a negative label: numpy's ValueError
            if len(counts) > n_labels:                         # as the C kernel refuses it
                raise ValueError(f"Expected labels in 0..{n_labels - 1}, got {int(lab.max())}")
            zero += np.bincount(lab[tiny], minlength=n_labels)
            order = np.argsort(lab, kind="stable")
            ids = np.flatnonzero(counts)
            part_hi, part_lo = _label_sums(terms[:, order], counts[ids])
        if start == 0:
            hi[ids], lo[ids] = part_hi.T, part_lo.T
        else:
            hi[ids], lo[ids] = _add_pairs(hi[ids], lo[ids], part_hi.T, part_lo.T)
    sums = hi + lo                        # one rounding (NaN where a term or a sum is not finite, as on C)
    second = sums[:, _SECOND_COLUMNS].reshape(n_labels, 3, 3)
    return sums[:, 0].copy(), sums[:, 1:4].copy(), second, sums[:, 10].copy(), zero


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(s, e)`` with ``s = fl(a + b)`` and ``a + b = s + e`` exactly (Knuth's TwoSum, six operations, no branch;
    Ogita, Rump and Oishi 2005, Algorithm 3.1), elementwise; ``e`` is NaN where ``s`` is not finite."""
    s = a + b
    b_virtual = s - a
    return s, (a - (s - b_virtual)) + (b - b_virtual)


def _add_pairs(hi: np.ndarray, lo: np.ndarray, more_hi: np.ndarray, more_lo: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Two unevaluated sums ``hi + Σ(errors)`` added: the high parts by TwoSum (exact), the low parts plainly."""
    s, e = _two_sum(hi, more_hi)
    return s, lo + (e + more_lo)


def _label_sums(x: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each segment's sum of the columns of ``x`` as an unevaluated pair ``hi + lo``, by a tree of TwoSums.

    Parameters
    ----------
    x : (k, n) float
        ``k`` rows of terms; the columns of a segment are contiguous, segments in order.
    counts : (g,) int
        The columns of each segment, each at least 1, summing to ``n``.

    Returns
    -------
    hi, lo : (k, g) float
        Per segment and row: ``hi`` the root of a pairwise tree of float additions, ``lo`` the float sum of every
        addition's rounding error (TwoSum, exact).  ``hi + (the exact sum of the errors)`` is the segment's exact
        sum, so for a segment of ``m`` terms ``|hi + lo − Σx| ≤ N·u·Σ|e|`` with ``Σ|e| ≤ L·u·Σ|x|`` (each level
        of the tree errs by at most ``u`` times its partial sums, which add up to ``Σ|x|`` to first order),
        ``L = ⌈log₂ m⌉`` levels and ``N ≤ m + L`` error terms.  A single segment of at most ``_FSUM_MAX_TERMS``
        finite terms is summed by ``math.fsum`` instead: ``hi`` correctly rounded, ``lo`` zero.

    Notes
    -----
    A level pairs neighbours within each segment: a segment of odd length gets a zero at its end (adding zero is
    exact), a segment of one column is finished.  Every level is a few whole-array operations, so ``L`` levels cost
    about twice the first; the same numbers whatever the number of segments (no loop over segments).
    """
    k, n = x.shape
    g = len(counts)
    hi = np.zeros((k, g))
    lo = np.zeros((k, g))
    cnt = np.asarray(counts, dtype=np.intp)
    where = np.arange(g)                        # the output column of each open segment
    if g == 1:                                  # one segment (one shell): no gathers, the odd column carried
        return _one_segment_sum(x, hi, lo)
    for _ in range(n.bit_length() + 1):         # ⌈log₂ n⌉ levels at most: each halves the longest segment
        done = cnt == 1
        if done.any():
            first = np.cumsum(cnt) - cnt
            hi[:, where[done]] = x[:, first[done]]
            if done.all():
                break
            x = x[:, np.repeat(~done, cnt)]
            where, cnt = where[~done], cnt[~done]
        odd = cnt & 1
        if odd.any():                           # a zero at the end of each odd segment
            shift = np.repeat(np.cumsum(odd) - odd, cnt)
            padded = np.zeros((k, x.shape[1] + int(odd.sum())))
            padded[:, np.arange(x.shape[1]) + shift] = x
            x, cnt = padded, cnt + odd
        s, e = _two_sum(x[:, 0::2], x[:, 1::2])
        cnt = cnt >> 1
        lo[:, where] += np.add.reduceat(e, np.cumsum(cnt) - cnt, axis=1)
        x = s
    return hi, lo


def _one_segment_sum(x: np.ndarray, hi: np.ndarray, lo: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_label_sums` of a single segment (``hi``, ``lo`` its (k, 1) outputs, zero): the same tree, an odd
    level's last column added to the level's first sum by one more TwoSum; up to ``_FSUM_MAX_TERMS`` finite terms
    a row (a small part), each row's ``math.fsum`` instead (correctly rounded, Shewchuk 1997; ``lo`` zero), which
    costs less than the tree's numpy calls there."""
    if x.shape[1] <= _FSUM_MAX_TERMS and bool(np.isfinite(x).all()):
        try:
            hi[:, 0] = [math.fsum(row) for row in x.tolist()]
            return hi, lo
        except OverflowError:                       # finite terms whose sum overflows: the tree's NaN, as on C
            pass
    carry_lo = np.zeros(x.shape[0])
    for _ in range(x.shape[1].bit_length() + 1):    # ⌈log₂ n⌉ levels at most
        n = x.shape[1]
        if n <= 1:
            break
        s, e = _two_sum(x[:, 0:n - 1:2], x[:, 1:n:2])
        carry_lo += e.sum(axis=1)
        if n & 1:
            s[:, 0], e_last = _two_sum(s[:, 0], x[:, n - 1])
            carry_lo += e_last
        x = s
    if x.shape[1]:
        hi[:, 0] = x[:, 0]
    lo[:, 0] = carry_lo
    return hi, lo


def _tetra_sums_c(lib: ModuleType, vertices: np.ndarray, faces: np.ndarray, origin: np.ndarray,
                  labels: np.ndarray | None, n_labels: int, area_floor: float) -> _Sums:
    """``_tetra_sums`` on the C extension: the same sums in one pass, compensated; same return values."""
    sums = np.empty((n_labels, 11))
    zero = np.empty(n_labels, dtype=np.int64)
    lib.tetra_sums(np.ascontiguousarray(vertices, dtype=np.float64), faces_for_c(faces),
                   tuple(float(x) for x in origin), float(area_floor),
                   None if labels is None else labels_for_c(labels), sums, zero, threads())
    second = sums[:, _SECOND_COLUMNS].reshape(n_labels, 3, 3)     # one gather instead of twelve assignments
    return sums[:, 0].copy(), sums[:, 1:4].copy(), second, sums[:, 10].copy(), zero


def _finish(vol: float, first: np.ndarray, second: np.ndarray, area: float, origin: np.ndarray,
            zero: int = 0) -> VolumeMoments:
    if vol != 0.0:
        # on Python floats (a small part's shell: numpy's per-call cost was ~4 times the arithmetic), the same
        # operations in the same order as the array form: d = first / vol (the centroid relative to origin),
        # C - vol (d ⊗ d), symmetrised, origin + d
        # written out, not as nested comprehensions (each a function call: a third of this function's time)
        v = float(vol)
        f0, f1, f2 = first.tolist()
        d0, d1, d2 = f0 / v, f1 / v, f2 / v
        (s00, s01, s02), (s10, s11, s12), (s20, s21, s22) = second.tolist()
        c00, c01, c02 = s00 - v * (d0 * d0), s01 - v * (d0 * d1), s02 - v * (d0 * d2)
        c10, c11, c12 = s10 - v * (d1 * d0), s11 - v * (d1 * d1), s12 - v * (d1 * d2)
        c20, c21, c22 = s20 - v * (d2 * d0), s21 - v * (d2 * d1), s22 - v * (d2 * d2)
        central = np.array([[0.5 * (c00 + c00), 0.5 * (c01 + c10), 0.5 * (c02 + c20)],
                            [0.5 * (c10 + c01), 0.5 * (c11 + c11), 0.5 * (c12 + c21)],
                            [0.5 * (c20 + c02), 0.5 * (c21 + c12), 0.5 * (c22 + c22)]])
        o0, o1, o2 = np.asarray(origin, dtype=np.float64).tolist()
        centroid = np.array([o0 + d0, o1 + d1, o2 + d2])
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
    return _box_area_floor(*bounding_box(vertices), area_rtol)


def _box_area_floor(lo: np.ndarray, hi: np.ndarray, area_rtol: float) -> float:
    """``area_rtol · Σ (hi − lo)²`` of a bounding box's corners (3,): the doubled area at or below which a face
    counts as zero-area.  On Python floats, with the operations of ``area_rtol * np.sum((hi - lo) ** 2)`` in its
    order (a product per square; numpy adds three terms left to right), the same bits at a tenth of the calls'
    cost (``tests/test_batch12_small_floats.py``)."""
    extent: list[float] = (hi - lo).tolist()
    e0, e1, e2 = extent
    return area_rtol * ((e0 * e0 + e1 * e1) + e2 * e2)


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
                                                 labels=labels_for_c(labels), n_labels=n_labels,
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


# -- round-off: a derived bound, and exact integer arithmetic where the bound is too wide ----------------------

#: Unit round-off of float64 (2⁻⁵³).
_U = float(np.finfo(np.float64).eps) / 2


@frozen_value
class RoundoffBound:
    """Bounds on the float64 round-off of each shell's moments as :func:`body_volume_moments` computes them.

    Attributes
    ----------
    volume : (s,) float
        m³, on the volume.
    centroid : (s,) float
        m, on the centroid (Euclidean).
    second_moment : (s,) float
        m⁵, on the central second moment (Frobenius).
    """

    volume: np.ndarray
    centroid: np.ndarray
    second_moment: np.ndarray


def _dot_abs_cross(a: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``Σᵢ aᵢ (x ⊠ y)ᵢ`` for non-negative (3, k) arrays, ``⊠`` the cross product with both products added."""
    return np.asarray(a[0] * (x[1] * y[2] + x[2] * y[1]) + a[1] * (x[2] * y[0] + x[0] * y[2])
                      + a[2] * (x[0] * y[1] + x[1] * y[0]))


def roundoff_bounds(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, shells: list[VolumeMoments],
                    origin: np.ndarray, *, chunk_size: int = _DEFAULT_CHUNK) -> RoundoffBound:
    """A bound on the float64 round-off of every shell's moments about ``origin`` (first order in u = 2⁻⁵³).

    By the standard model ``fl(x ∘ y) = (x ∘ y)(1 + δ)``, ``|δ| ≤ u`` (Higham, *Accuracy and Stability of
    Numerical Algorithms*, §2.2, §3.1), each face's ``6v = a·(e₁ × e₂)``, ``e₁ = b − a``, ``e₂ = c − a`` (``a, b,
    c`` the corners less ``origin``) errs by at most ``u·P`` with

    ``P = 8·|a|·(|e₁| ⊠ |e₂|) + 2·|a|·((|a| + |b|) ⊠ |e₂| + |e₁| ⊠ (|a| + |c|))``

    (``⊠`` the cross product with both products of a component added, all entries non-negative): the rounding
    of ``a`` (1), of each difference (1) and of the cross (2) and dot (3) products give the 8; the roundings of
    the corners inside the differences the second term (1, doubled for slack and the u² terms), so a part far
    from ``origin`` is charged for its distance once.  The first-moment term ``6v·s/24`` adds the roundings of
    ``s = a + b + c`` and of two products (bound ``2u·P·‖s‖``), the second-moment term
    ``6v·(Σ pₖpₖᵀ + ssᵀ)/120`` those of ``Q`` (``3u·P·tr|Q|``).  Sums over a shell's m faces add
    ``(2 + m²u)·u·Σ P``: the C path's compensated sums (Ogita, Rump and Oishi 2005, Sum2) and the numpy path's
    TwoSum trees (:func:`_label_sums`: at most ``(1 + 3m(L + C)u)·u·Σ P`` with ``L ≤ 16`` levels per chunk and
    ``C`` chunks of the default size, under ``1.02·u·Σ P`` up to 10⁹ faces) both meet it, so both paths draw the
    same line (issue 21).  The central moment ``C − f fᵀ/V`` carries the errors of its parts to
    first order plus ``4u·(‖C‖ + ‖f‖²/|V|)`` of its own.  Terms of order u² are left out.

    The per-face terms and their sums run in one C pass when the extension is built (``_accel.roundoff_sums``:
    the numpy loop's operations in its order, so the same bits), and a single shell's tail on Python floats.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    labels : (m,) int
        Shell of each face.
    shells : list of VolumeMoments
        As computed about ``origin``.
    origin : (3,) float
        The reference point the moments were computed about.
    """
    n = len(shells)
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    lab = np.asarray(labels)
    origin = np.asarray(origin, dtype=np.float64)
    lib = accel()
    if lib is not None:
        sums = _roundoff_sums_c(lib, v, f, lab, n, origin, chunk_size)
    else:
        sums = _roundoff_sums(v, f, lab, n, origin, chunk_size)
    if n == 1:
        return _one_shell_bound(sums[0], len(f), shells[0], origin)
    return _shells_bound(sums, np.bincount(lab, minlength=n), shells, origin)


def _shells_bound(sums: np.ndarray, counts: np.ndarray, shells: list[VolumeMoments],
                  origin: np.ndarray) -> RoundoffBound:
    """The tail of :func:`roundoff_bounds`: each shell's bounds from its sums (:func:`_roundoff_sums`) and its
    face count ``counts`` (s,); the sums over a shell's m faces are charged ``(2 + m²u)·u`` of their size
    (compensated or correctly rounded, on either engine path)."""
    sp, sps, spq = sums.T
    counts = np.asarray(counts).astype(np.float64)
    summing = (2 + counts * counts * _U) * _U
    e_volume = (_U + summing) * sp / 6
    e_first = (2 * _U + summing) * sps / 24
    e_second = (3 * _U + summing) * spq / 120
    vol = np.array([abs(sh.volume) for sh in shells])
    d = np.array([np.linalg.norm(sh.centroid - origin) if sh.volume != 0 else 0.0 for sh in shells])
    first = vol * d
    about_origin = np.array([np.linalg.norm(sh.second_moment) for sh in shells]) + vol * d * d
    with np.errstate(divide="ignore", invalid="ignore"):
        e_centroid = np.where(vol > 0, (e_first + d * e_volume) / vol, np.inf)
        e_central = e_second + np.where(vol > 0, (2 * first * e_first + d * d * vol * e_volume) / vol, np.inf) \
            + 4 * _U * (about_origin + first * d)
    return RoundoffBound(volume=e_volume, centroid=e_centroid, second_moment=e_central)


def _roundoff_sums(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n: int, origin: np.ndarray,
                   chunk_size: int) -> np.ndarray:
    """(n, 3) per-shell sums ``Σ P``, ``Σ P·√(3 Σ‖pₖ‖²)``, ``Σ P·4 Σ‖pₖ‖²`` of :func:`roundoff_bounds` (the
    numpy reference: sequential sums per chunk of faces, the chunks added in order)."""
    coords = np.ascontiguousarray((vertices - origin).T)
    sp, sps, spq = (np.zeros(n) for _ in range(3))
    # sums that overflow are inf silently, as on C (an infinite bound refuses the answer; no RuntimeWarning)
    with np.errstate(over="ignore", invalid="ignore"):
        for start in range(0, len(faces), chunk_size):
            f = faces[start:start + chunk_size]
            lab = labels[start:start + chunk_size]
            a, b, c = (coords[:, f[:, k]] for k in range(3))
            e1, e2 = np.abs(b - a), np.abs(c - a)
            a, b, c = np.abs(a), np.abs(b), np.abs(c)
            # |a|·(|e1| ⊠ |e2|) carries the roundings of the cross and dot products and of a itself; the terms with
            # |a| + |b| (|a| + |c|) carry the roundings of the corners and of the differences b − a (c − a)
            p = 8 * _dot_abs_cross(a, e1, e2) + 2 * (_dot_abs_cross(a, a + b, e2) + _dot_abs_cross(a, e1, a + c))
            # Σ‖pₖ‖², each square norm summed x, y, z in that order (einsum's order depends on the array's shape; a
            # fixed one is what the C kernel repeats bit for bit)
            n2 = (_norm2(a) + _norm2(b)) + _norm2(c)
            s_norm = np.sqrt(3 * n2)                      # ‖|a| + |b| + |c|‖ ≤ √(3 Σ‖pₖ‖²)
            q = 4 * n2                                    # tr|Q| = Σ‖pₖ‖² + ‖|a| + |b| + |c|‖² ≤ 4 Σ‖pₖ‖²
            sp += np.bincount(lab, weights=p, minlength=n)
            sps += np.bincount(lab, weights=p * s_norm, minlength=n)
            spq += np.bincount(lab, weights=p * q, minlength=n)
    return np.stack([sp, sps, spq], axis=1)


def _norm2(x: np.ndarray) -> np.ndarray:
    """``(x₀² + x₁²) + x₂²`` of a (3, k) array, in that order."""
    return np.asarray((x[0] * x[0] + x[1] * x[1]) + x[2] * x[2])


def _roundoff_sums_c(lib: ModuleType, vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n: int,
                     origin: np.ndarray, chunk_size: int) -> np.ndarray:
    """:func:`_roundoff_sums` on the C extension, bit for bit the same (the same operations in the same order)."""
    if n == 0:                                  # no shells (the kernel wants an output row): no sums, as numpy's
        return np.zeros((0, 3))
    out = np.empty((n, 3))
    lib.roundoff_sums(np.ascontiguousarray(vertices), faces_for_c(faces), (float(origin[0]), float(origin[1]),
                      float(origin[2])), None if n == 1 else labels_for_c(labels), out,
                      max(1, int(chunk_size)))
    return out


def _norm(x: np.ndarray) -> float:
    """``np.linalg.norm(x)`` of a float64 vector or matrix, the same bits: ``√(x·x)`` over the flattened entries."""
    flat = x.ravel(order="K")
    return math.sqrt(float(flat.dot(flat)))


def _one_shell_bound(sums: np.ndarray, m: int, shell: VolumeMoments, origin: np.ndarray) -> RoundoffBound:
    """The tail of :func:`roundoff_bounds` for one shell of ``m`` faces on Python floats: the same operations
    in the same order as its array form :func:`_shells_bound` (the same bits: ``tests/test_integrals_small.py``),
    without its dozens of numpy calls on arrays of one element (a small part makes this call once or twice)."""
    sp, sps, spq = (float(x) for x in sums)
    count = float(m)
    summing = (2 + count * count * _U) * _U
    e_volume = (_U + summing) * sp / 6
    e_first = (2 * _U + summing) * sps / 24
    e_second = (3 * _U + summing) * spq / 120
    vol = abs(shell.volume)
    d = _norm(shell.centroid - origin) if shell.volume != 0 else 0.0
    first = vol * d
    about_origin = _norm(shell.second_moment) + vol * d * d
    # numpy.where's choice: a shell of no (or NaN) volume has no bounded centroid
    spread = (2 * first * e_first + d * d * vol * e_volume) / vol if vol > 0 else math.inf
    e_centroid = (e_first + d * e_volume) / vol if vol > 0 else math.inf
    e_central = e_second + spread + 4 * _U * (about_origin + first * d)
    return RoundoffBound(volume=np.array([e_volume]), centroid=np.array([e_centroid]),
                         second_moment=np.array([e_central]))


def exact_volume_moments(vertices: np.ndarray, faces: np.ndarray, *, area: float = 0.0,
                         zero_area_faces: int = 0) -> VolumeMoments:
    """The moments of one closed surface in exact integer arithmetic, rounded to float64 once at the end.

    Every float64 coordinate is an integer multiple of a common power of two ``2⁻ᵏ``, so the signed-tetrahedron
    sums (volume ``det/6``, first moment ``det·s/24``, second moment ``det·(Σ pₖpₖᵀ + ssᵀ)/120``: Tonon 2004, as
    in :func:`volume_moments`) are integers times known powers of two; the centroid and the central moment are
    formed as fractions and rounded.  The answer is the polyhedron's to the last bit (one rounding each), at
    about 10 µs a face: for small shells whose float64 bound (:func:`roundoff_bounds`) is too wide.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    area, zero_area_faces
        Carried over to the result (not recomputed).
    """
    from fractions import Fraction

    f = np.asarray(faces, dtype=np.int64)
    used, local = np.unique(f, return_inverse=True)
    pts = np.asarray(vertices, dtype=np.float64)[used]
    ref = pts[0].copy()
    # the differences to one corner (exact as fractions: pts - ref in float64 would round)
    exact = [[Fraction(x) - Fraction(r) for x, r in zip(row, ref.tolist())] for row in pts.tolist()]
    scale = max((q.denominator for row in exact for q in row), default=1)
    ints = [[int(q * scale) for q in row] for row in exact]
    tri = local.reshape(-1, 3)
    vol6 = 0
    first24 = [0, 0, 0]
    second120 = [[0] * 3 for _ in range(3)]
    for i0, i1, i2 in tri.tolist():
        a, b, c = ints[i0], ints[i1], ints[i2]
        det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
               + a[2] * (b[0] * c[1] - b[1] * c[0]))
        if det == 0:
            continue
        s = [a[k] + b[k] + c[k] for k in range(3)]
        vol6 += det
        for k in range(3):
            first24[k] += det * s[k]
        for r in range(3):
            for q in range(r, 3):
                second120[r][q] += det * (a[r] * a[q] + b[r] * b[q] + c[r] * c[q] + s[r] * s[q])
    if vol6 == 0:
        return VolumeMoments(volume=0.0, centroid=np.full(3, np.nan), second_moment=np.zeros((3, 3)), area=area,
                             zero_area_faces=zero_area_faces)
    volume = Fraction(vol6, 6 * scale ** 3)
    first = [Fraction(x, 24 * scale ** 4) for x in first24]
    centre = [x / volume for x in first]
    central = np.zeros((3, 3))
    for r in range(3):
        for q in range(r, 3):
            central[r, q] = central[q, r] = float(Fraction(second120[r][q], 120 * scale ** 5)
                                                  - volume * centre[r] * centre[q])
    centroid = np.array([float(Fraction(x) + cx) for x, cx in zip(ref.tolist(), centre)])
    return VolumeMoments(volume=float(volume), centroid=centroid, second_moment=central, area=area,
                         zero_area_faces=zero_area_faces)


def accurate_shells(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, shells: list[VolumeMoments],
                    origin: np.ndarray | None = None, *, rtol: float = ROUNDOFF_RTOL,
                    exact_max_faces: int = EXACT_MAX_FACES,
                    integrated: np.ndarray | None = None) -> tuple[list[VolumeMoments], int, RoundoffBound]:
    """Shell moments whose combined round-off is provably within ``rtol`` where that can be reached.

    The bound of :func:`roundoff_bounds` is turned into each shell's share of the error of the total volume
    and of the total inertia about the total centroid (``3·(E_C + d²·E_V + 2|V|·d·E_c)`` for a shell at
    distance ``d`` from it; ``‖ΔI‖ ≤ 3‖ΔC‖`` since ``I = tr(C)𝟙 − C``).  Shells are taken from the largest share
    down until what is left sums to at most half of ``rtol``; each of those is integrated again about its own
    bounding-box centre (a part far from the rest keeps its digits), and, when its bound is still above its
    part of the other half and it has at most ``exact_max_faces`` faces, in exact integer arithmetic
    (:func:`exact_volume_moments`).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    labels : (m,) int
        Shell of each face, ``0..len(shells)-1``.
    shells : list of VolumeMoments
        As computed about ``origin`` (default: the vertices' bounding-box centre, as :func:`body_volume_moments`).
    rtol : float
        Target relative bound (``tolerances.ROUNDOFF_RTOL``).
    exact_max_faces : int
        Largest shell integrated in exact arithmetic (about 10 µs a face).
    integrated : (m, 3) int, optional
        The faces as they were wound when ``shells`` were integrated (a shell turned inside out afterwards has
        its moments negated, not recomputed): the bound is of that computation.  Default ``faces``.

    Returns
    -------
    shells : list of VolumeMoments
    refined : int
        Shells integrated again.
    bounds : RoundoffBound
        Each shell's bound after refinement (:func:`total_roundoff` turns them into the total's).

    Notes
    -----
    Which shells to refine is decided against the magnitudes ``Σ|V|`` and ``Σ (‖C‖ + |V| d²)``, which do not
    depend on how the shells are wound (this runs before they are oriented); the bound of the final answer is
    :func:`total_roundoff` of the oriented shells.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    lab = np.asarray(labels)      # read as it is (one shell: a broadcast zero); the C kernels take labels_for_c
    o = reference_point(v) if origin is None else np.asarray(origin, dtype=np.float64)
    shells = list(shells)
    if not shells:                             # nothing to bound or refine
        empty = np.zeros(0)
        return shells, 0, RoundoffBound(volume=empty, centroid=empty.copy(), second_moment=empty.copy())
    b = roundoff_bounds(v, f if integrated is None else np.asarray(integrated), lab, shells, o)
    e_vol, e_cen, e_sec = b.volume.copy(), b.centroid.copy(), b.second_moment.copy()
    share_v, share_i, total_v, total_i = _shares(shells, e_vol, e_cen, e_sec, magnitude=True)
    if not np.isfinite(total_v) or total_v == 0 or total_i == 0:
        return shells, 0, RoundoffBound(volume=e_vol, centroid=e_cen, second_moment=e_sec)
    budget = 0.5 * rtol
    if len(shells) == 1:                       # one shell (most parts): the ordering below is that shell alone
        one_v, one_i = float(share_v[0]), float(share_i[0])
        if one_v <= budget * total_v and one_i <= budget * total_i and math.isfinite(one_v) and math.isfinite(one_i):
            return shells, 0, RoundoffBound(volume=e_vol, centroid=e_cen, second_moment=e_sec)
    worst = np.argsort(-np.maximum(share_v / (rtol * total_v), share_i / (rtol * total_i)), kind="stable")
    rest_v, rest_i = np.cumsum(share_v[worst][::-1])[::-1], np.cumsum(share_i[worst][::-1])[::-1]
    over = (rest_v > budget * total_v) | (rest_i > budget * total_i) | ~np.isfinite(rest_v) | ~np.isfinite(rest_i)
    redo = worst[over]
    refined = 0
    for k in redo.tolist():                    # the shells carrying the error, largest first (bounded by s)
        mine = lab == k
        fk = f[mine]
        own = reference_point(v[np.unique(fk)])
        s = shells[k]
        again = volume_moments(v, fk, origin=own)
        shells[k] = VolumeMoments(again.volume, again.centroid, again.second_moment, s.area, s.zero_area_faces)
        bk = roundoff_bounds(v, fk, np.zeros(len(fk), dtype=np.intp), [shells[k]], own)
        e_vol[k], e_cen[k], e_sec[k] = bk.volume[0], bk.centroid[0], bk.second_moment[0]
        refined += 1
        sv, si, _, _ = _shares(shells, e_vol, e_cen, e_sec, only=k, magnitude=True)
        if (sv > budget * total_v / len(redo) or si > budget * total_i / len(redo)) and len(fk) <= exact_max_faces:
            shells[k] = exact_volume_moments(v, fk, area=s.area, zero_area_faces=s.zero_area_faces)
            e_vol[k], e_cen[k], e_sec[k] = _exact_rounding(shells[k])
    return shells, refined, RoundoffBound(volume=e_vol, centroid=e_cen, second_moment=e_sec)


def total_roundoff(shells: list[VolumeMoments], bounds: RoundoffBound) -> float:
    """The bound on the relative round-off of the total of oriented ``shells`` (cavities negative): the larger
    of the volume's (relative to ``|Σ V|``) and the inertia's about the total centroid (relative to its Frobenius
    norm), from each shell's bounds (:func:`accurate_shells`); inf when the total is zero."""
    share_v, share_i, total_v, total_i = _shares(shells, bounds.volume, bounds.centroid, bounds.second_moment)
    if not (total_v > 0 and total_i > 0):
        return float("inf")
    return float(max(share_v.sum() / total_v, share_i.sum() / total_i))


def total_roundoff_parts(shells: list[VolumeMoments], bounds: RoundoffBound) -> tuple[float, float, float]:
    """The round-off of the total of oriented ``shells`` as an estimate's bounds are stated
    (:class:`~inertia_tool.mesh.uncertainty.Uncertainty`): ``(volume relative, centroid m, inertia relative)``.

    The volume and inertia terms are those of :func:`total_roundoff` (the same shares).  The total centroid
    ``c = Σ Vᵢcᵢ / V`` moves, to first order, by ``Σ (δVᵢ (cᵢ − c) + Vᵢ δcᵢ) / V``, so its error is at most
    ``Σ (e_Vᵢ dᵢ + |Vᵢ| e_cᵢ) / (|V| − Σ e_Vᵢ)`` (``dᵢ = ‖cᵢ − c‖``; Higham, *Accuracy and Stability of Numerical
    Algorithms*, §3.1, first order in u as :func:`roundoff_bounds`).  All three are inf when the total is zero."""
    share_v, share_i, total_v, total_i = _shares(shells, bounds.volume, bounds.centroid, bounds.second_moment)
    if not (total_v > 0 and total_i > 0):
        return float("inf"), float("inf"), float("inf")
    vol = np.array([s.volume for s in shells], dtype=np.float64)
    cen = np.array([s.centroid if s.volume else np.zeros(3) for s in shells], dtype=np.float64).reshape(-1, 3)
    c = (vol @ cen) / float(vol.sum())
    d = np.linalg.norm(cen - c, axis=1)
    e_vol = np.asarray(bounds.volume, dtype=np.float64)
    spare = total_v - float(e_vol.sum())
    centroid = float(np.sum(e_vol * d + np.abs(vol) * np.asarray(bounds.centroid, dtype=np.float64))) / spare \
        if spare > 0 else float("inf")
    return float(share_v.sum() / total_v), centroid, float(share_i.sum() / total_i)


def _exact_rounding(s: VolumeMoments) -> tuple[float, float, float]:
    """The bounds of an exactly integrated shell: one rounding of each rounded value."""
    return (_U * abs(s.volume), _U * float(np.linalg.norm(s.centroid)) if s.volume else 0.0,
            2 * _U * float(np.linalg.norm(s.second_moment)))


def _shares(shells: list[VolumeMoments], e_vol: np.ndarray, e_cen: np.ndarray, e_sec: np.ndarray,
            only: int | None = None, magnitude: bool = False) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Each shell's bound on the total volume and on the total central inertia (Frobenius), and the totals'
    sizes ``|V|`` and ``‖I‖`` (with ``magnitude``, ``Σ|V|`` and ``Σ ‖I‖`` of the shells taken positive; with
    ``only``, that shell's two shares, ``|V|``, and, with more than one shell, NaN for ``‖I‖``, which is not
    computed)."""
    if len(shells) == 1:
        return _one_shell_shares(shells[0], e_vol, e_cen, e_sec, only, magnitude)
    return _many_shares(shells, e_vol, e_cen, e_sec, only, magnitude)


def _many_shares(shells: list[VolumeMoments], e_vol: np.ndarray, e_cen: np.ndarray, e_sec: np.ndarray,
                 only: int | None, magnitude: bool) -> tuple[np.ndarray, np.ndarray, float, float]:
    """:func:`_shares` on arrays, for any number of shells."""
    vol = np.array([s.volume for s in shells])
    weight = np.abs(vol) if magnitude else vol
    total = float(np.sum(weight))
    cen = np.array([s.centroid if s.volume else np.zeros(3) for s in shells])
    c = (weight @ cen) / total if total else np.zeros(3)
    d = np.linalg.norm(cen - c, axis=1)
    if only is not None and len(shells) > 1:
        # not asked for: one shell's shares, once per refined shell (issue 25, unique19: the sum over every shell
        # for each refined one was quadratic, 130k matrix norms on the Menagerie's 45 slowest meshes)
        inertia = float("nan")
    elif magnitude:
        inertia = float(sum(_norm(s.second_moment) + abs(s.volume) * dd * dd
                            for s, dd in zip(shells, d) if s.volume))
    else:
        second = sum((s.second_moment + s.volume * np.outer(cc - c, cc - c) for s, cc in zip(shells, cen)),
                     np.zeros((3, 3)))
        inertia = float(np.linalg.norm(np.trace(second) * np.eye(3) - second))
    # the parallel-axis shifts cᵢ − c are taken from absolute centroids, each stored rounded (to half an ulp of
    # its size) and subtracted once more: far from the origin that rounding, not the integration's, bounds the
    # shift (review 12's R5: two 0.8 mm boxes 2.1e7 m out, inertia 2.1e-6 off, labelled exact)
    # (one shell has no shift: its share stays that of _one_shell_shares, bit for bit)
    e_shift = e_cen + _U * (np.linalg.norm(cen, axis=1) + float(np.linalg.norm(c)) + d) if len(shells) > 1 else e_cen
    share_i = 3 * (e_sec + d * d * e_vol + 2 * np.abs(vol) * d * e_shift)
    if only is not None:
        return np.array(e_vol[only]), np.array(share_i[only]), abs(total), inertia
    return e_vol, share_i, abs(total), inertia


def _one_shell_shares(s: VolumeMoments, e_vol: np.ndarray, e_cen: np.ndarray, e_sec: np.ndarray, only: int | None,
                      magnitude: bool) -> tuple[np.ndarray, np.ndarray, float, float]:
    """:func:`_shares` of a single shell on Python floats: the same operations in the same order (the same bits;
    ``tests/test_integrals_small.py`` compares them), a tenth of the time on a small part."""
    volume = float(s.volume)
    weight = abs(volume) if magnitude else volume
    cen = [float(x) for x in s.centroid] if volume else [0.0, 0.0, 0.0]
    c = [(weight * x) / weight for x in cen] if weight else [0.0, 0.0, 0.0]
    delta = [x - y for x, y in zip(cen, c)]
    d = math.sqrt((delta[0] * delta[0] + delta[1] * delta[1]) + delta[2] * delta[2])
    if magnitude:
        inertia = _norm(s.second_moment) + abs(volume) * d * d if volume else 0.0
    else:
        m = s.second_moment.tolist()
        second = [[0.0 + (m[i][j] + volume * (delta[i] * delta[j])) for j in range(3)] for i in range(3)]
        trace = (second[0][0] + second[1][1]) + second[2][2]
        flat = np.array([trace * (1.0 if i == j else 0.0) - second[i][j] for i in range(3) for j in range(3)])
        inertia = math.sqrt(float(flat.dot(flat)))
    share_i = 3 * (e_sec + d * d * e_vol + 2 * abs(volume) * d * e_cen)
    if only is not None:
        return np.array(e_vol[only]), np.array(share_i[only]), abs(weight), inertia
    return e_vol, share_i, abs(weight), inertia


def one_shell_moments(vertices: np.ndarray, faces: np.ndarray, origin: np.ndarray, box: tuple[np.ndarray, np.ndarray],
                      *, rtol: float = ROUNDOFF_RTOL, area_rtol: float = 1e-14,
                      margin: float = 1e-6) -> tuple[VolumeMoments, bool] | None:
    """One closed shell's moments about ``origin``, as ``body_volume_moments`` (one label) gives them, bit for bit,
    and whether their round-off is certainly within ``rtol``: the clean-part fast path of
    :mod:`~inertia_tool.mesh.clean_part`, in one call on the C extension.

    The moments come from the same kernel and the same :func:`_finish` as :func:`volume_moments` (same area floor
    from ``box``).  The round-off bound is :func:`roundoff_bounds`'s one-shell formula and the shares of
    :func:`accurate_shells` and :func:`total_roundoff`, evaluated on Python floats; since only decisions are taken
    from them (never a number of the result), each is taken with a ``margin``: a shell within it of
    ``accurate_shells``' budget (half of ``rtol``) gives None, and one within it of ``rtol`` says False, so that a
    difference of summation order (a few units of round-off in the bound itself) can never make this call accept a
    shell that the general path would treat otherwise.

    Parameters
    ----------
    vertices : (n, 3) float64, C-contiguous
        m.
    faces : (m, 3) int
        One shell (every face is integrated).
    origin : (3,) float
        The reference point (the bounding-box centre, as :func:`body_volume_moments` takes by default).
    box : ((3,) float, (3,) float)
        ``bounding_box(vertices)``, already computed (the area floor of ``area_rtol`` is taken from it).
    rtol, area_rtol
        As for :func:`accurate_shells` and :func:`volume_moments`.
    margin : float
        Relative margin of the decisions (above).

    Returns
    -------
    (VolumeMoments, bool) or None
        The moments, and True when :func:`total_roundoff` of them is within ``rtol`` (by the margin; the general
        path decides a shell that gets False); None without the C extension, or when :func:`accurate_shells` could
        integrate the shell again (a sliver), so that the caller takes the general path.
    """
    lib = accel()
    if lib is None:
        return None
    lo, hi = box
    o = np.asarray(origin, dtype=np.float64)
    vol, first, second, area, zero = _tetra_sums_c(lib, vertices, faces, o, None, 1, _box_area_floor(lo, hi, area_rtol))
    shell = _finish(vol[0], first[0], second[0], area[0], o, zero[0])
    sp, sps, spq = _roundoff_sums_c(lib, vertices, faces, _NO_LABELS, 1, o, _DEFAULT_CHUNK)[0].tolist()
    # roundoff_bounds' one-shell tail (_one_shell_bound), on floats
    count = float(len(faces))
    summing = (2 + count * count * _U) * _U
    e_volume = (_U + summing) * sp / 6
    e_first = (2 * _U + summing) * sps / 24
    e_second = (3 * _U + summing) * spq / 120
    volume = shell.volume
    vol_abs = abs(volume)
    centroid = shell.centroid.tolist()
    moment = shell.second_moment.tolist()
    d = math.sqrt(sum((c - x) ** 2 for c, x in zip(centroid, o.tolist()))) if volume != 0 else 0.0
    norm_c = math.sqrt(sum(x * x for row in moment for x in row))
    if not (vol_abs > 0 and math.isfinite(vol_abs) and math.isfinite(norm_c) and norm_c > 0):
        return None                                    # no volume or no spread: the general path decides
    first_m = vol_abs * d
    about_origin = norm_c + vol_abs * d * d
    e_centroid = (e_first + d * e_volume) / vol_abs
    e_central = e_second + (2 * first_m * e_first + d * d * vol_abs * e_volume) / vol_abs + \
        4 * _U * (about_origin + first_m * d)
    keep = 1 - margin

    def shares(weight: float) -> tuple[float, float, list[float]]:
        """_one_shell_shares on floats: the shares of the volume and of the inertia, and the shell's offset from
        the total's centroid (``(w·x)/w``: zero but for rounding)."""
        delta = [x - (weight * x) / weight for x in centroid]
        dd = math.sqrt((delta[0] * delta[0] + delta[1] * delta[1]) + delta[2] * delta[2])
        return e_volume, 3 * (e_central + dd * dd * e_volume + 2 * vol_abs * dd * e_centroid), delta

    share_v, share_i, delta = shares(vol_abs)          # accurate_shells: magnitudes (Σ|V|, Σ‖C‖ + |V| d²)
    total_i = norm_c + vol_abs * sum(x * x for x in delta)
    if not (share_v <= keep * 0.5 * rtol * vol_abs and share_i <= keep * 0.5 * rtol * total_i
            and math.isfinite(share_v) and math.isfinite(share_i)):
        return None                                    # accurate_shells would integrate it again
    share_v, share_i, delta = shares(volume)           # total_roundoff: |Σ V| and ‖tr(C') 1 - C'‖
    about = [[moment[i][j] + volume * (delta[i] * delta[j]) for j in range(3)] for i in range(3)]
    trace = (about[0][0] + about[1][1]) + about[2][2]
    norm_i = math.sqrt(sum((trace * (i == j) - about[i][j]) ** 2 for i in range(3) for j in range(3)))
    within = norm_i > 0 and max(share_v / vol_abs, share_i / norm_i) <= keep * rtol
    return shell, bool(within)
