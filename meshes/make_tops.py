"""Write the two spinning-body sample meshes of ``meshes/``: a T-handle and a spinning top.

Regenerate (from the repository root)::

    python meshes/make_tops.py

Both are binary STL in **millimetres** (pass ``--units mm``), each a single closed, consistently wound,
2-manifold solid built vertex by vertex (no boolean operations):

* ``t_handle.stl`` — the "Dzhanibekov nut": a T-shaped outline (crossbar 60 × 10 mm on a 10 × 40 mm stem)
  extruded 10 mm along y.  Its three principal moments differ, so spin about the intermediate axis flips.
* ``spinning_top.stl`` — a solid of revolution about z with its tip at the origin (the pivot): a cone
  from the tip to a disc of radius 30 mm (z = 12 … 18 mm), then a stem of radius 4 mm up to z = 45 mm.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

#: T outline in the xz-plane (mm), counter-clockwise seen from −y, and the extrusion depth along y.
T_OUTLINE = [(-5, 0), (5, 0), (5, 40), (30, 40), (30, 50), (-30, 50), (-30, 40), (-5, 40)]
T_CAP_TRIANGLES = [(0, 1, 2), (0, 2, 7), (6, 7, 5), (7, 2, 4), (7, 4, 5), (2, 3, 4)]
T_DEPTH = 10.0

#: Profile (r, z) in mm of the top, from the tip on the axis to the top of the stem on the axis.
TOP_PROFILE = [(0.0, 0.0), (30.0, 12.0), (30.0, 18.0), (4.0, 18.0), (4.0, 45.0), (0.0, 45.0)]
TOP_SEGMENTS = 96


def t_handle() -> tuple[np.ndarray, np.ndarray]:
    """Vertices (mm) and outward-wound faces of the extruded T."""
    outline = np.array(T_OUTLINE, dtype=float)
    n = len(outline)
    front = np.column_stack([outline[:, 0], np.full(n, -T_DEPTH / 2), outline[:, 1]])
    back = front + [0.0, T_DEPTH, 0.0]
    vertices = np.vstack([front, back])
    faces = []
    for a, b, c in T_CAP_TRIANGLES:
        faces.append((a, b, c))                 # front cap (y = −d/2)
        faces.append((n + a, n + c, n + b))     # back cap, reversed
    for i in range(n):
        j = (i + 1) % n
        faces.append((i, n + i, n + j))
        faces.append((i, n + j, j))
    faces = np.array(faces)
    if _signed_volume(vertices, faces) < 0:
        faces = faces[:, ::-1]
    return vertices, faces


def spinning_top() -> tuple[np.ndarray, np.ndarray]:
    """Vertices (mm) and outward-wound faces of the revolved profile (two pole vertices, rings between)."""
    profile = TOP_PROFILE
    rings = profile[1:-1]
    m = TOP_SEGMENTS
    angles = 2 * math.pi * np.arange(m) / m
    vertices = [(0.0, 0.0, profile[0][1])]
    for r, z in rings:
        vertices += [(r * math.cos(a), r * math.sin(a), z) for a in angles]
    vertices.append((0.0, 0.0, profile[-1][1]))
    vertices = np.array(vertices)
    bottom, top = 0, len(vertices) - 1

    def ring(k, i):
        return 1 + k * m + (i % m)

    faces = []
    for i in range(m):
        faces.append((bottom, ring(0, i + 1), ring(0, i)))
        for k in range(len(rings) - 1):
            faces.append((ring(k, i), ring(k, i + 1), ring(k + 1, i + 1)))
            faces.append((ring(k, i), ring(k + 1, i + 1), ring(k + 1, i)))
        faces.append((top, ring(len(rings) - 1, i), ring(len(rings) - 1, i + 1)))
    faces = np.array(faces)
    if _signed_volume(vertices, faces) < 0:
        faces = faces[:, ::-1]
    return vertices, faces


def _signed_volume(vertices, faces) -> float:
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def write_stl(path: Path, vertices: np.ndarray, faces: np.ndarray, name: str) -> None:
    """Binary STL, float32 coordinates as given (mm)."""
    tri = vertices[faces].astype(np.float32)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    record = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    record["n"] = normals
    record["v"] = tri
    with open(path, "wb") as fh:
        fh.write(name.encode("ascii")[:80].ljust(80, b" "))
        fh.write(struct.pack("<I", len(faces)))
        fh.write(record.tobytes())


def main() -> None:
    write_stl(HERE / "t_handle.stl", *t_handle(), "inertia_tool T-handle (mm)")
    write_stl(HERE / "spinning_top.stl", *spinning_top(), "inertia_tool spinning top (mm), tip at origin")


if __name__ == "__main__":
    main()
