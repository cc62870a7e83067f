"""Surface and curve integrals of triangle meshes and polylines: the thin-walled analogue of ``volume``.

A thin wall of thickness ``t`` and density ``ρ`` carries the areal density ``ρ t`` on its mid-surface.
For a triangle ``(p1, p2, p3)`` of area ``A`` the surface moments are exact polynomials of the corners
(the surface analogue of the tetrahedron identity used in ``volume``; both follow from integrating a
quadratic over a simplex with barycentric coordinates, ``∫ λ_a λ_b dA = A (1 + δ_ab) / 12``):

* ``∫ dA = A``
* ``∫ x_i dA = A (p1 + p2 + p3)_i / 3``
* ``∫ x_i x_j dA = A/12 · [ Σ_k p_k,i p_k,j + s_i s_j ]`` with ``s = p1 + p2 + p3``

A straight segment ``(p, q)`` of length ``L`` (a wire) gives in the same way

* ``∫ ds = L``, ``∫ x_i ds = L (p + q)_i / 2``
* ``∫ x_i x_j ds = L/6 · [ p_i p_j + q_i q_j + (p + q)_i (p + q)_j ]``

A flat triangular plate of thickness ``t`` centred on its triangle (a prism) adds the through-thickness
term ``t²/12 · A n nᵀ`` to the second moment (``n`` the unit normal), exactly.  The inertia tensor then
follows from the second moment ``C`` as ``I = ρ t (tr C 𝟙 − C)``, Eqs. (4.11)/(4.13) of the chapter with the
volume element ``t dA``.  Summing over the faces is exact for the union of the flat plates.  Where two faces
meet at an angle the plates leave a thin wedge open on the convex side and overlap by the same wedge on
the concave side: the volume stays right to order ``t²``, but material moves from the outer to the inner
side, so a curved wall (or a bend) of radius ``R`` is off by a relative ``O((t/R)²)`` (for a sphere the
moments are low by ``(t/R)²/3``; see tests/test_surface.py).

Unlike the volume integral, none of this needs a closed or consistently wound surface: an open sheet
(sheet metal, a bracket) is as valid as the surface of a hollow part, and the winding does not matter.

Pure functions on SI numpy arrays.  See ``docs/conventions.md``.
"""

from __future__ import annotations



import numpy as np
from numpy.typing import ArrayLike

from ..values import frozen_value
from ..errors import UsageError
from ..integrals import reference_point, second_moment_to_inertia

__all__ = ["SurfaceMoments", "CurveMoments", "surface_moments", "curve_moments", "shell_second_moment",
           "shell_inertia", "wire_inertia", "inward_offset_coefficient"]

_DEFAULT_CHUNK = 1 << 18
_IU = (np.array([0, 1, 2, 0, 0, 1]), np.array([0, 1, 2, 1, 2, 2]))


@frozen_value
class SurfaceMoments:
    """Zeroth, first and second moments of a surface (unit areal density).

    Attributes
    ----------
    area : float
        ``∫ dA`` in m².
    centroid : (3,) float
        ``∫ x dA / A`` in m, mesh axes.
    second_moment : (3, 3) float
        ``∫ (x−c)_i (x−c)_j dA`` in m⁴ about the centroid ``c``, mesh axes.
    normal_moment : (3, 3) float
        ``Σ_faces A_f n_f n_fᵀ`` in m² (``n_f`` the unit normal; sign-free): multiplied by ``t³/12`` it is
        the through-thickness second moment of plates of thickness ``t``.
    zero_area_faces : int
        Triangles whose area is below ``area_rtol`` times the squared bounding-box diagonal (they add nothing).
    """

    area: float
    centroid: np.ndarray
    second_moment: np.ndarray
    normal_moment: np.ndarray
    zero_area_faces: int = 0


@frozen_value
class CurveMoments:
    """Zeroth, first and second moments of a polyline (unit linear density).

    Attributes
    ----------
    length : float
        ``∫ ds`` in m.
    centroid : (3,) float
        ``∫ x ds / L`` in m, mesh axes.
    second_moment : (3, 3) float
        ``∫ (x−c)_i (x−c)_j ds`` in m³ about the centroid ``c``, mesh axes.
    """

    length: float
    centroid: np.ndarray
    second_moment: np.ndarray


def _symmetric(six: np.ndarray) -> np.ndarray:
    full = np.empty((3, 3))
    for col, (i, j) in enumerate(zip(*_IU)):
        full[i, j] = full[j, i] = six[col]
    return full


def _central(total: float, first: np.ndarray, second: np.ndarray,
             origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centroid and central second moment from raw sums about ``origin`` (parallel-axis shift)."""
    if not total > 0:
        raise UsageError(f"Expected a surface or curve of positive extent, got a total of {total}")
    d = first / total
    central = second - total * np.outer(d, d)
    return origin + d, 0.5 * (central + central.T)


def surface_moments(vertices: ArrayLike, faces: ArrayLike, *, origin: ArrayLike | None = None,
                    chunk_size: int = _DEFAULT_CHUNK, area_rtol: float = 1e-14) -> SurfaceMoments:
    """Exact area, centroid, central second moment and normal moment of a triangulated surface.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex coordinates in m.
    faces : (m, 3) int
        Triangles (any winding; open surfaces allowed).
    origin : (3,) float, optional
        Point the products are formed about; defaults to the bounding-box centre (keeps precision far from
        the origin).  Any point gives the same result up to round-off.
    chunk_size : int
        Faces processed per vectorised step (bounds temporary memory).
    area_rtol : float
        A triangle counts as zero-area (reported, contributes nothing) when twice its area is below
        ``area_rtol · L²`` with ``L`` the bounding-box diagonal.

    Returns
    -------
    SurfaceMoments

    Raises
    ------
    UsageError
        When the total area is zero.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    o = reference_point(v) if origin is None else np.asarray(origin, dtype=np.float64)
    area = 0.0
    first = np.zeros(3)
    second = np.zeros(6)
    normal = np.zeros(6)
    zero = 0
    diag2 = float(np.sum((v.max(axis=0) - v.min(axis=0)) ** 2)) if len(v) else 0.0
    step = max(1, int(chunk_size))
    for start in range(0, len(f), step):
        fc = f[start:start + step]
        p1, p2, p3 = v[fc[:, 0]] - o, v[fc[:, 1]] - o, v[fc[:, 2]] - o
        cross = np.cross(p2 - p1, p3 - p1)
        a = 0.5 * np.linalg.norm(cross, axis=1)
        zero += int(np.count_nonzero(2.0 * a <= area_rtol * diag2))
        s = p1 + p2 + p3
        area += a.sum()
        first += a @ s / 3.0
        # A n nᵀ = (cross cross^T) / (2 |cross|) = cross crossᵀ / (4 A)
        safe = np.where(a > 0, a, 1.0)
        for col, (i, j) in enumerate(zip(*_IU)):
            quad = p1[:, i] * p1[:, j] + p2[:, i] * p2[:, j] + p3[:, i] * p3[:, j] + s[:, i] * s[:, j]
            second[col] += a @ quad / 12.0
            normal[col] += np.sum(np.where(a > 0, cross[:, i] * cross[:, j] / (4.0 * safe), 0.0))
    centroid, central = _central(float(area), first, _symmetric(second), o)
    return SurfaceMoments(area=float(area), centroid=centroid, second_moment=central,
                          normal_moment=_symmetric(normal), zero_area_faces=zero)


def curve_moments(points: ArrayLike, segments: ArrayLike, *, origin: ArrayLike | None = None) -> CurveMoments:
    """Exact length, centroid and central second moment of a polyline (a wire of straight segments).

    Parameters
    ----------
    points : (n, 3) float
        m.
    segments : (k, 2) int
        Index pairs of the segment end points.
    origin : (3,) float, optional
        As in :func:`surface_moments`.

    Returns
    -------
    CurveMoments
    """
    v = np.asarray(points, dtype=np.float64)
    seg = np.asarray(segments)
    if v.ndim != 2 or v.shape[1] != 3:
        raise UsageError(f"Expected `points` to have shape (n, 3), got {v.shape}")
    if seg.ndim != 2 or seg.shape[1] != 2:
        raise UsageError(f"Expected `segments` to have shape (k, 2), got {seg.shape}")
    o = reference_point(v) if origin is None else np.asarray(origin, dtype=np.float64)
    p, q = v[seg[:, 0]] - o, v[seg[:, 1]] - o
    length = np.linalg.norm(q - p, axis=1)
    s = p + q
    second = np.array([length @ (p[:, i] * p[:, j] + q[:, i] * q[:, j] + s[:, i] * s[:, j]) / 6.0
                       for i, j in zip(*_IU)])
    total = float(length.sum())
    centroid, central = _central(total, length @ s / 2.0, _symmetric(second), o)
    return CurveMoments(length=total, centroid=centroid, second_moment=central)


def shell_second_moment(moments: SurfaceMoments, thickness: float) -> np.ndarray:
    """Second moment per unit density of a wall of ``thickness`` centred on the surface, (3, 3) m⁵.

    ``t · (C + t²/12 · N)`` with ``C = moments.second_moment`` and ``N = moments.normal_moment``: exact for
    each flat triangular plate (prism), about the centroid, mesh axes.
    """
    t = float(thickness)
    if not (np.isfinite(t) and t > 0):
        raise UsageError(f"Expected a positive finite thickness in m, got {thickness}")
    return t * (moments.second_moment + t * t / 12.0 * moments.normal_moment)


def shell_inertia(moments: SurfaceMoments, thickness: float, density: float) -> np.ndarray:
    """Inertia tensor of a thin wall about the surface centroid, (3, 3) kg·m², mesh axes, tensor convention.

    ``I = ρ (tr C' 𝟙 − C')`` with ``C' = t (C + t²/12 N)`` (Eqs. 4.11/4.13 with ``dV = t dA``).  Mass is
    ``ρ t A``.
    """
    return second_moment_to_inertia(shell_second_moment(moments, thickness), density)


def wire_inertia(moments: CurveMoments, linear_density: float) -> np.ndarray:
    """Inertia tensor of a thin wire about its centroid, (3, 3) kg·m², tensor convention: ``λ (tr C 𝟙 − C)``.

    ``linear_density`` λ in kg/m (ρ times the cross-section area); the wire's own cross-section inertia
    is neglected (relative error of order (radius / length)²).
    """
    return second_moment_to_inertia(moments.second_moment, linear_density)


def inward_offset_coefficient(vertices: ArrayLike, faces: ArrayLike) -> float:
    """Second-order coefficient ``K`` of the volume between a closed surface and its inward offset.

    Moving every face of a closed, outward-wound polyhedron inward by ``s`` along its normal removes the
    volume ``A s − K s² + O(s³)`` with

    ``K = Σ_edges ℓ_e cot(α_e / 2) = Σ_edges ℓ_e σ_e tan(φ_e / 2)``

    where ``α_e`` is the interior dihedral angle at the edge, ``φ_e = |π − α_e|`` the angle between the two
    face normals and ``σ_e = +1`` on a convex edge, −1 on a concave one: near each edge the two face slabs
    of the first-order term ``A s`` overlap (convex) or leave a gap (concave) of cross-section
    ``s² cot(α/2)``.  Flat edges contribute nothing; for a polyhedron with an inscribed sphere of radius
    ``r`` touching every face, ``K = A / r`` (the inward offset is the scaled copy).

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        Closed, consistently outward-wound surface (every edge shared by exactly two faces).

    Returns
    -------
    float
        ``K`` in m.

    Raises
    ------
    UsageError
        When an edge is not shared by exactly two faces.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    norm = np.linalg.norm(cross, axis=1)
    normal = cross / np.where(norm > 0, norm, 1.0)[:, None]
    n = np.int64(max(len(v), 1))
    m = len(f)
    a = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    b = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    opposite = np.concatenate([f[:, 2], f[:, 0], f[:, 1]])
    face = np.tile(np.arange(m), 3)
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    key = key[order]
    if len(key) % 2 or not np.all(key[0::2] == key[1::2]) or (len(key) > 2 and np.any(key[2::2] == key[1:-1:2])):
        raise UsageError("Expected a closed surface with every edge shared by exactly two faces")
    first, second = order[0::2], order[1::2]
    n1, n2 = normal[face[first]], normal[face[second]]
    phi = np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1), np.einsum("ij,ij->i", n1, n2))
    height = np.einsum("ij,ij->i", n1, v[opposite[second]] - v[a[first]])
    sign = np.where(height > 0, -1.0, 1.0)
    length = np.linalg.norm(v[b[first]] - v[a[first]], axis=1)
    return float(np.sum(length * sign * np.tan(0.5 * phi)))
