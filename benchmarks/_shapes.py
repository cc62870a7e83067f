"""Meshes the benchmarks build in memory: closed tori, fan-capped cylinders, and a real-ish CAD part subdivided;
and the binary STL writer the benchmarks share.

Shared by ``bench_intersect.py`` and any benchmark that needs the same surfaces (vertices (n, 3) float64, faces
(m, 3) int64, outward winding):

* :func:`torus`, :func:`cylinder`, :func:`wheel` (``bench_intersect.py``);
* :func:`ring_torus` — a ring of ``2·nu·nv`` triangles, each grid quad's two triangles next to each other in the
  face list (an exporter's patch-by-patch order), in mm (``bench_repair.py``, ``bench_scaling.py`` and so
  ``bench_peers.py``);
* :func:`icosphere` — a subdivided icosahedron on the sphere, ``20·4^s`` triangles (``bench_repair.py``);
* :func:`write_binary_stl` — float32 corners, zero normals, written to a temporary file and renamed (a run cut
  short leaves no half-written file for the next run to reuse).
"""

from __future__ import annotations

import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, os.pardir, "tests"))       # one icosahedron and cylinder: tests/solids.py
from solids import fan_capped_cylinder, icosahedron  # noqa: E402


def _torus_grid(nu: int, nv: int, major: float, minor: float, phase: float = 0.0):
    """Points of a torus grid (``nu`` round the ring, ``nv`` round the tube, the tube angle starting at
    ``phase``) and the corners a, b, c, d of each grid quad, outward when split into (a, b, c), (a, c, d)."""
    u = 2 * np.pi * np.arange(nu) / nu
    w = 2 * np.pi * np.arange(nv) / nv + phase
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = major + minor * np.cos(ww)
    pts = np.stack([r * np.cos(uu), r * np.sin(uu), minor * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = i * nv + j
    b = ((i + 1) % nu) * nv + j
    c = ((i + 1) % nu) * nv + (j + 1) % nv
    d = i * nv + (j + 1) % nv
    return pts, (a, b, c, d)


def torus(n_faces: float, major: float = 1.0, minor: float = 0.35) -> tuple[np.ndarray, np.ndarray]:
    """A closed torus grid of about ``n_faces`` triangles (n around the axis, n/2 around the tube); its quads
    are exactly planar isosceles trapezoids, so each quad's diagonal joins two coplanar faces."""
    n = max(8, int(round(np.sqrt(n_faces))))
    k = max(4, n // 2)
    # the tube angle starts off the coordinate planes: no accidental symmetry
    v, (a, b, c, d) = _torus_grid(n, k, major, minor, phase=0.1234)
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    return v, f


def cylinder(n_faces: float, radius: float = 1.0, height: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder of about ``n_faces`` triangles (``n_faces/4`` sections), fan caps round a centre."""
    return fan_capped_cylinder(max(8, int(round(n_faces / 4))), radius, height)


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

STL_RECORD = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])


def ring_torus(nu: int, nv: int, major: float = 40.0, minor: float = 10.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed outward torus: ((nu·nv, 3) float64 vertices, (2·nu·nv, 3) int64 faces).

    ``nu`` points round the ring (major radius ``major``), ``nv`` round the tube (minor radius ``minor``);
    grid quad (i, j) becomes the faces (a, b, c) and (a, c, d), written one after the other.
    """
    pts, (a, b, c, d) = _torus_grid(nu, nv, major, minor)
    faces = np.stack([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], axis=2).reshape(-1, 3)
    return pts, faces.astype(np.int64)


def icosphere(subdivisions: int, radius: float = 50.0) -> tuple[np.ndarray, np.ndarray]:
    """A subdivided icosahedron projected on the sphere of ``radius``: 20·4^s faces, outward
    ((n, 3) float64 vertices, (m, 3) int64 faces)."""
    v, f = icosahedron()
    for _ in range(subdivisions):
        n = len(v)
        v, f = subdivide(v, f)
        v[n:] /= np.linalg.norm(v[n:], axis=1, keepdims=True)          # the new midpoints pushed to the sphere
    return v * radius, f


def write_binary_stl(path: str, vertices: np.ndarray, faces: np.ndarray | None = None,
                     header: bytes = b"inertia_tool benchmark", chunk: int = 1 << 20) -> None:
    """Write triangles as binary STL: ``vertices`` (k, 3, 3) triangles, or (n, 3) vertices with (k, 3) ``faces``
    (gathered ``chunk`` faces at a time, so a 10M-face part needs no second copy in float64)."""
    count = len(vertices) if faces is None else len(faces)
    rec = np.zeros(count, dtype=STL_RECORD)
    if faces is None:
        rec["v"] = np.asarray(vertices, dtype=np.float32)
    else:
        flat = np.asarray(vertices, dtype=np.float32)
        for s in range(0, count, chunk):
            rec["v"][s:s + chunk] = flat[faces[s:s + chunk]]
    tmp = path + ".tmp"
    with open(tmp, "wb") as fh:
        fh.write(header.ljust(80, b" ")[:80])
        fh.write(np.uint32(count).tobytes())
        rec.tofile(fh)
    os.replace(tmp, path)
