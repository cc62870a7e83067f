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


def fan_capped_cylinder(n, radius=1.0, height=2.0):
    """A closed cylinder of ``n`` sections with fan caps round a centre vertex at each end (as CAD exports
    tessellate one), outward: ``2n + 2`` vertices, ``4n`` faces (bottom fan, top fan, then the sides)."""
    t = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
    v = np.concatenate([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    i = np.arange(n)
    j = (i + 1) % n
    bottom, top = np.full(n, 2 * n), np.full(n, 2 * n + 1)
    f = np.concatenate([np.stack([bottom, j, i], 1), np.stack([top, n + i, n + j], 1),
                        np.stack([i, j, n + j], 1), np.stack([i, n + j, n + i], 1)])
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


# ------------------------------------------------------------------------------------ stacked trimesh boxes

def crossing_boxes_inside(size, subdivide_outer=False):
    """A 4 m cube centred at the origin and, inside it, two cubes of side ``size`` crossing each other (the second
    moved by (0.5, 0.4, 0.3)), all wound outward: three ``(vertices, faces)`` parts to :func:`stack`.  trimesh's
    boxes (its triangulation, the one the nesting tests were written on); ``subdivide_outer``: the outer cube's
    faces split in four (trimesh ``subdivide``)."""
    import trimesh

    outer = trimesh.creation.box(extents=(4.0, 4.0, 4.0))
    if subdivide_outer:
        outer = outer.subdivide()
    a = trimesh.creation.box(extents=(size,) * 3)
    b = a.copy()
    b.apply_translation((0.5, 0.4, 0.3))
    return [(np.asarray(p.vertices), np.asarray(p.faces)) for p in (outer, a, b)]


# ------------------------------------------------------------------------ featured boxes and hole cutters

def featured_box(extents, place, size, height):
    """A box with a rectangular boss (``height`` > 0) or pocket (< 0) on its top face, made by manifold3d,
    whose flat faces are triangulated with vertices on their loops only (as CAD exporters do).

    Returns the vertices, faces, the feature's faces (walls and top or floor) and its top or floor faces."""
    import manifold3d as m3d

    w, d, h = extents
    fw, fd = size[0] * w, size[1] * d
    x0, y0 = place[0] * (w - fw), place[1] * (d - fd)
    body = m3d.Manifold.cube([w, d, h])
    if height > 0:
        body = body + m3d.Manifold.cube([fw, fd, height]).translate([x0, y0, h])
    else:
        body = body - m3d.Manifold.cube([fw, fd, 1.0 - height]).translate([x0, y0, h + height])
    mesh = body.to_mesh()
    v = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(mesh.tri_verts, dtype=np.int64)
    corners = v[f]
    tol = 1e-5 * max(extents)
    inside = np.all((corners[:, :, 0] >= x0 - tol) & (corners[:, :, 0] <= x0 + fw + tol)
                    & (corners[:, :, 1] >= y0 - tol) & (corners[:, :, 1] <= y0 + fd + tol), axis=1)
    feature = inside & np.any(np.abs(corners[:, :, 2] - h) > tol, axis=1)
    end = np.all(np.abs(corners[:, :, 2] - (h + height)) <= tol, axis=1)
    return v, f, np.flatnonzero(feature), np.flatnonzero(end)


def manifold_neighbours(v, f):
    """Each face's neighbours across its manifold edges (trimesh's ``face_adjacency``, in its order)."""
    import trimesh

    mesh = trimesh.Trimesh(v, f, process=False)
    neighbours = [[] for _ in range(len(f))]
    for a, b in mesh.face_adjacency.tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    return neighbours


def edge_neighbours(f):
    """Each face's neighbours across every edge it shares by index (non-manifold edges too: every other face on
    the edge), in the order of the faces' edges."""
    f = np.asarray(f)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(len(f)), 3)
    by_edge: dict[tuple[int, int], list[int]] = {}
    for (a, b), o in zip(edges.tolist(), owner.tolist()):
        by_edge.setdefault((a, b), []).append(o)
    neighbours: list[list[int]] = [[] for _ in range(len(f))]
    for faces in by_edge.values():
        for x in faces:
            neighbours[x].extend(y for y in faces if y != x)
    return neighbours


def grown_patch(neighbours, start, count):
    """Up to ``count`` faces grown breadth-first from face ``start`` through ``neighbours`` (lists per face, e.g.
    :func:`manifold_neighbours`), sorted: the faces a hole cutter takes out."""
    seen, queue = {start}, [start]
    for face in queue:                                # grows to at most len(neighbours)
        if len(seen) >= count:
            break
        for other in neighbours[face]:
            if other not in seen and len(seen) < count:
                seen.add(other)
                queue.append(other)
    return np.array(sorted(seen), dtype=np.int64)


# --------------------------------------------------------------------------------------- T-vertices on edges

def split_at_edge_points(faces, inner):
    """Every face holding a directed edge ``(a, b)`` of ``inner`` (or its reverse) fanned through the points
    ``inner[(a, b)]`` (vertex indices, in order from ``a`` to ``b``) from its opposite corner, so that a surface
    with points put on its edges stays closed by index.  A face is split at one edge at most (the last of its
    edges found in ``inner``).

    Returns
    -------
    rows : list of list of int
        The faces, split ones replaced by their fans in place.
    source : list of int
        The face of ``faces`` each row came from.
    """
    rows, source = [], []
    for i, tri in enumerate(np.asarray(faces).tolist()):
        hit = None
        for k in range(3):
            a, b = tri[k], tri[(k + 1) % 3]
            if (a, b) in inner:
                hit = (k, inner[(a, b)])
            elif (b, a) in inner:
                hit = (k, inner[(b, a)][::-1])
        if hit is None:
            rows.append(tri)
            source.append(i)
            continue
        k, mids = hit
        a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
        chain = [a, *mids, b]
        rows.extend([s, t, c] for s, t in zip(chain[:-1], chain[1:]))
        source.extend([i] * (len(chain) - 1))
    return rows, source


def halves_by_plane(v, f, normal, offset):
    """The closed pieces of the solid ``(v, f)`` on either side of the plane ``x·normal = offset``, by manifold3d's
    ``split_by_plane``: a list of ``(vertices, faces)``."""
    import manifold3d as m3d

    solid = m3d.Manifold(m3d.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                                    tri_verts=np.ascontiguousarray(f, dtype=np.uint64)))
    out = []
    for half in solid.split_by_plane(tuple(float(x) for x in normal), float(offset)):
        mesh = half.to_mesh64()
        out.append((np.array(mesh.vert_properties, dtype=np.float64)[:, :3].copy(),
                    np.array(mesh.tri_verts, dtype=np.int64)))
    return out
