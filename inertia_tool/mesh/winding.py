"""Generalized winding number of a triangle soup at many points.

``w(p) = Σ_f Ω_f(p) / 4π``, the signed solid angles of the triangles seen from ``p`` (Van Oosterom &
Strackee, IEEE Trans. Biomed. Eng. 30 (1983) 125).  For a closed outward surface it is 1 inside and 0
outside; for an open or broken one it varies smoothly and stays near 1 deep inside and near 0 far outside,
which makes ``w > 1/2`` a robust inside test for meshes with holes, cracks, duplicated faces and stray
pieces (Jacobson, Kavan & Sorkine-Hornung, "Robust inside-outside segmentation using generalized winding
numbers", ACM TOG 32(4) 33, SIGGRAPH 2013).

Evaluation: libigl's hierarchical ``fast_winding_number`` (Barill et al., "Fast winding numbers for soups
and clouds", ACM TOG 37(4) 43, SIGGRAPH 2018) when the optional ``libigl`` package is installed; otherwise
the exact direct sum, vectorised in blocks (``points × faces`` work; the caller bounds it).
"""

from __future__ import annotations

import numpy as np

__all__ = ["winding_numbers", "fast_available"]

_BLOCK = 1 << 22     # point-triangle pairs per vectorised block of the direct sum


def fast_available() -> bool:
    """Whether libigl's hierarchical evaluation can be used."""
    try:
        import igl  # noqa: F401
    except ImportError:
        return False
    return hasattr(igl, "fast_winding_number")


def _direct(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a0, b0, c0 = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    out = np.zeros(len(points))
    per = max(1, _BLOCK // max(len(faces), 1))
    for s in range(0, len(points), per):
        p = points[s:s + per, None, :]
        a, b, c = a0[None] - p, b0[None] - p, c0[None] - p
        la, lb, lc = (np.sqrt(np.einsum("...i,...i", x, x)) for x in (a, b, c))
        num = np.einsum("...i,...i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("...i,...i", a, b) * lc + np.einsum("...i,...i", a, c) * lb
               + np.einsum("...i,...i", b, c) * la)
        out[s:s + per] = np.arctan2(num, den).sum(axis=1) / (2 * np.pi)
    return out


def winding_numbers(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, *,
                    fast: bool | None = None) -> np.ndarray:
    """Generalized winding number at each point, (p,) float.

    Parameters
    ----------
    points : (p, 3) float
    vertices : (n, 3) float
    faces : (m, 3) int
    fast : bool, optional
        Use libigl's approximation (relative error ~1e-3 of a full turn far from the surface) — the default
        when libigl is installed — or force the exact direct sum (``False``).
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    if len(points) == 0 or len(faces) == 0:
        return np.zeros(len(points))
    if fast is None:
        fast = fast_available()
    if fast:
        import igl
        centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
        return np.asarray(igl.fast_winding_number(vertices - centre, faces, points - centre), dtype=np.float64)
    return _direct(points, vertices, faces)
