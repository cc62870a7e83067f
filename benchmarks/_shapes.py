"""Meshes the benchmarks build in memory: closed tori, fan-capped cylinders, and a real-ish CAD part subdivided.

Shared by ``bench_intersect.py`` and any benchmark that needs the same surfaces (vertices (n, 3) float64, faces
(m, 3) int64, outward winding).
"""

from __future__ import annotations

import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def torus(n_faces: float, major: float = 1.0, minor: float = 0.35) -> tuple[np.ndarray, np.ndarray]:
    """A closed torus grid of about ``n_faces`` triangles (n around the axis, n/2 around the tube); its quads
    are exactly planar isosceles trapezoids, so each quad's diagonal joins two coplanar faces."""
    n = max(8, int(round(np.sqrt(n_faces))))
    k = max(4, n // 2)
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(k) / k + 0.1234      # off the coordinate planes: no accidental symmetry
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = major + minor * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), minor * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(k), indexing="ij")
    a = i * k + j
    b = ((i + 1) % n) * k + j
    c = ((i + 1) % n) * k + (j + 1) % k
    d = i * k + (j + 1) % k
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    return v, f


def cylinder(n_faces: float, radius: float = 1.0, height: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder of about ``n_faces`` triangles (``n_faces/4`` sections), fan caps round a centre."""
    n = max(8, int(round(n_faces / 4)))
    t = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
    v = np.concatenate([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    i = np.arange(n)
    j = (i + 1) % n
    bottom, top = np.full(n, 2 * n), np.full(n, 2 * n + 1)
    f = np.concatenate([np.stack([bottom, j, i], 1), np.stack([top, n + i, n + j], 1),
                        np.stack([i, j, n + j], 1), np.stack([i, n + j, n + i], 1)])
    return v, f


def subdivide(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One midpoint subdivision: every face split into four at its edges' midpoints (shared by the faces of an
    edge), so flat faces stay flat and the surface stays closed and consistently oriented."""
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    unique, inverse = np.unique(key, axis=0, return_inverse=True)
    mid = len(v) + inverse.reshape(3, -1).T                   # (m, 3): midpoint of edges 01, 12, 20
    v2 = np.concatenate([v, 0.5 * (v[unique[:, 0]] + v[unique[:, 1]])])
    a, b, c = f[:, 0], f[:, 1], f[:, 2]
    ab, bc, ca = mid[:, 0], mid[:, 1], mid[:, 2]
    f2 = np.concatenate([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                         np.stack([ab, bc, ca], 1)])
    return v2, f2


def wheel(n_faces: float) -> tuple[np.ndarray, np.ndarray]:
    """A real-ish CAD part: ``meshes/unbalanced_wheel.stl`` (4,332 faces: flat faces, fan-triangulated caps,
    slivers), welded and midpoint-subdivided until it has at least ``n_faces`` faces (4,332 · 4^k)."""
    from inertia_tool.mesh.read import load_mesh

    mesh = load_mesh(os.path.join(HERE, os.pardir, "meshes", "unbalanced_wheel.stl"))
    v, f = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    for _ in range(12):
        if len(f) >= n_faces:
            break
        v, f = subdivide(v, f)
    return v, f


SHAPES = {"torus": torus, "cylinder": cylinder, "wheel": wheel}
