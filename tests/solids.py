"""Solids for the certificate tests: boxes, spheres, tori and swept tubes, and ways to combine them.

Each builder returns ``(vertices, faces)`` (float64 m, int64, outward-wound, closed, manifold).  The
hypothesis strategies of ``tests/test_mesh_certificate.py`` compose them under random rigid motions; the
truths they are checked against come from independent code (manifold3d booleans in float64, closed forms).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


def box(extents=(1.0, 1.0, 1.0), center=(0.0, 0.0, 0.0)):
    """Axis-aligned box, 8 vertices, 12 outward faces."""
    e = np.asarray(extents, dtype=np.float64) / 2
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64) * e
    v += np.asarray(center, dtype=np.float64)
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.int64)
    return v, f


def uv_sphere(radius=1.0, center=(0.0, 0.0, 0.0), segments=24, rings=12):
    """Latitude–longitude sphere with single pole vertices (outward)."""
    verts = [[0.0, 0.0, radius]]
    for i in range(1, rings):
        th = np.pi * i / rings
        for j in range(segments):
            ph = 2 * np.pi * j / segments
            verts.append([radius * np.sin(th) * np.cos(ph), radius * np.sin(th) * np.sin(ph), radius * np.cos(th)])
    verts.append([0.0, 0.0, -radius])
    v = np.asarray(verts) + np.asarray(center, dtype=np.float64)
    faces = []
    south = len(verts) - 1

    def ring(i, j):
        return 1 + (i - 1) * segments + j % segments

    for j in range(segments):
        faces.append([0, ring(1, j), ring(1, j + 1)])
        faces.append([south, ring(rings - 1, j + 1), ring(rings - 1, j)])
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces.append([a, c, d])
            faces.append([a, d, b])
    return v, np.asarray(faces, dtype=np.int64)


def tube(curve, radius, sections=12):
    """A closed tube swept along a closed curve ``curve`` ((k, 3), no repeated end point), outward."""
    c = np.asarray(curve, dtype=np.float64)
    k = len(c)
    tangent = np.roll(c, -1, axis=0) - np.roll(c, 1, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    ref = np.array([0.0, 0.0, 1.0])
    normal = ref - (tangent @ ref)[:, None] * tangent
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    binormal = np.cross(tangent, normal)
    ang = 2 * np.pi * np.arange(sections) / sections
    v = (c[:, None, :] + radius * (np.cos(ang)[None, :, None] * normal[:, None, :]
                                   + np.sin(ang)[None, :, None] * binormal[:, None, :])).reshape(-1, 3)
    faces = []
    for i in range(k):
        for j in range(sections):
            a, b = i * sections + j, i * sections + (j + 1) % sections
            c2, d = ((i + 1) % k) * sections + j, ((i + 1) % k) * sections + (j + 1) % sections
            faces.append([a, c2, d])
            faces.append([a, d, b])
    f = np.asarray(faces, dtype=np.int64)
    if _signed_volume(v, f) < 0:
        f = f[:, ::-1]
    return v, f


def torus(major=1.0, minor=0.3, steps=32, sections=12):
    t = 2 * np.pi * np.arange(steps) / steps
    return tube(np.c_[major * np.cos(t), major * np.sin(t), np.zeros(steps)], minor, sections)


def figure_eight(steps=64, radius=0.2, sections=12):
    """A tube along the planar figure-eight (sin 2t, 2 sin t, 0): it passes through itself at the origin."""
    t = 2 * np.pi * np.arange(steps) / steps + np.pi / steps      # no sample exactly at the crossing
    return tube(np.c_[np.sin(2 * t), 2 * np.sin(t), np.zeros(steps)], radius, sections)


def _signed_volume(v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def rotation(axis, angle):
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def icosahedron():
    """The regular icosahedron on the unit sphere, outward: ((12, 3) float64 corners, (20, 3) int64 faces).

    The corners are the cyclic permutations of (0, ±1, ±φ), φ the golden ratio, scaled to unit length; the one
    table of it (``tests/adversary_solids.py`` and ``benchmarks/_shapes.py`` subdivide it into icospheres)."""
    t = (1 + 5 ** 0.5) / 2
    v = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=np.float64)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v, f


class ConvexSolid(NamedTuple):
    """A convex polyhedron: outward ``vertices`` (n, 3) and ``faces`` (m, 3), its hull's plane ``equations``
    (k, 4: ``a · x + b ≤ 0`` inside, scipy's ``ConvexHull.equations``) and ``centre``, the mean of its corners
    (inside)."""

    vertices: np.ndarray
    faces: np.ndarray
    equations: np.ndarray
    centre: np.ndarray


def random_convex(seed, n=14):
    """The convex hull of ``n`` random points (a random solid, not tuned on), wound outward."""
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(n, 3)) * rng.uniform(0.5, 2.0, size=3) + rng.uniform(-5, 5, size=3)
    hull = ConvexHull(pts)
    f = hull.simplices.copy()
    centre = pts[hull.vertices].mean(axis=0)
    normal = np.cross(pts[f[:, 1]] - pts[f[:, 0]], pts[f[:, 2]] - pts[f[:, 0]])
    inward = np.einsum("ij,ij->i", normal, pts[f[:, 0]] - centre) < 0
    f[inward] = f[inward][:, ::-1]
    used, f = np.unique(f, return_inverse=True)
    return ConvexSolid(pts[used], f.reshape(-1, 3), hull.equations, centre)


def stack(*parts):
    """Concatenate meshes (vertex indices offset), ``(vertices, faces)``."""
    vs, fs, offset = [], [], 0
    for v, f in parts:
        vs.append(v)
        fs.append(f + offset)
        offset += len(v)
    return np.vstack(vs), np.vstack(fs)


def union_volume(*parts):
    """Independent truth: the manifold3d float64 union of closed outward parts, m³."""
    import manifold3d as m3

    solids = [m3.Manifold(m3.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                                    tri_verts=np.ascontiguousarray(f, dtype=np.uint64))) for v, f in parts]
    out = solids[0]
    for s in solids[1:]:
        out = out + s
    return float(out.volume())
