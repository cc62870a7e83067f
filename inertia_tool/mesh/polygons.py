"""Polygons of an OBJ file cut into triangles as MuJoCo's loader cuts them (a stage of the reader).

Quads are split along the shorter diagonal (float32, a tie takes ``bd``); polygons of more than four corners are
ear-clipped in MuJoCo's order, the rest fanned where its clipping stops so that the surface stays closed.  A
planar polygon encloses the same solid however it is cut; for non-planar ones the reader warns
(:class:`~inertia_tool.errors.NonPlanarPolygonWarning`) with the volume the other reading (trimesh's
first-corner fan) could change, rounded up.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import NonPlanarPolygonWarning
from ..rounding import round_up

__all__ = ["split_quads_along_shorter_diagonal", "ear_clip_2d", "clip_polygon_as_mujoco", "clip_polygons",
           "warn_warped_quads", "warn_clipped_polygons", "MAX_CLIPPED_CORNERS"]


def split_quads_along_shorter_diagonal(vertices: np.ndarray, faces: np.ndarray,
                                        first: np.ndarray) -> tuple[int, float]:
    """Re-split in place the quads whose two triangles start at rows ``first`` of ``faces`` (read as
    ``abc, acd``) into ``abd, bcd`` unless the diagonal ``ac`` is strictly shorter than ``bd`` (in float32, as
    MuJoCo compares them: a tie takes ``bd``).

    Returns the number of quads whose corners are not coplanar and six times the volume between the two
    splits of all of them (the tetrahedron ``abcd`` of each quad: the other split adds or removes it)."""
    a, b, c = faces[first, 0], faces[first, 1], faces[first, 2]
    d = faces[first + 1, 2]
    six = np.abs(np.einsum("ij,ij->i", vertices[b] - vertices[a],
                           np.cross(vertices[c] - vertices[a], vertices[d] - vertices[a])))
    warped = int(np.count_nonzero(six))
    # MuJoCo's loader compares the squared diagonals in float32, summed x, y, z in that order, and keeps ac
    # only when it is strictly shorter (a tie, as in a symmetric saddle, takes bd)
    single = vertices.astype(np.float32)
    e_ac, e_bd = single[c] - single[a], single[d] - single[b]
    ac = e_ac[:, 0] * e_ac[:, 0] + e_ac[:, 1] * e_ac[:, 1] + e_ac[:, 2] * e_ac[:, 2]
    bd = e_bd[:, 0] * e_bd[:, 0] + e_bd[:, 1] * e_bd[:, 1] + e_bd[:, 2] * e_bd[:, 2]
    swap = ~(ac < bd)
    rows = first[swap]
    faces[rows] = np.column_stack([a[swap], b[swap], d[swap]])
    faces[rows + 1] = np.column_stack([b[swap], c[swap], d[swap]])
    return warped, float(six.sum())


#: Polygons with more corners than this are fanned from their first corner instead of ear-clipped (the
#: clipping below costs up to k² vectorised steps; no mesh exporter writes such polygons for a solid).
MAX_CLIPPED_CORNERS = 1024


def _inside_triangle(x: np.ndarray, y: np.ndarray, tx: np.ndarray, ty: np.ndarray) -> np.ndarray:
    """Crossing-number test of the points ``(tx, ty)`` (arrays) against the triangle ``(x, y)`` (3 each), in
    the arithmetic of the arrays (float32 here); True inside (W. R. Franklin's even-odd rule, points on an
    edge fall on either side as the rounding decides)."""
    inside = np.zeros(tx.shape, dtype=bool)
    j = 2
    for i in range(3):
        straddles = (y[i] > ty) != (y[j] > ty)
        with np.errstate(divide="ignore", invalid="ignore"):
            cut = (x[j] - x[i]) * (ty - y[i]) / (y[j] - y[i]) + x[i]
        inside ^= straddles & (tx < cut)
        j = i
    return inside


def clip_polygon_as_mujoco(corners: np.ndarray) -> tuple[list[tuple[int, int, int]], int]:
    """Triangles of one polygon of k > 4 corners in the order and shape MuJoCo's OBJ loader makes them.

    MuJoCo (its ``obj_decoder`` on tinyobjloader's built-in triangulation) works in float32 on two coordinate
    axes: those of the plane most face-on to the first corner triple (a, b, c) whose cross product has a
    component above float32's epsilon (x dominant: y, z; otherwise x and y if z dominates, else x and z).
    From corner ``g`` = 0 of the remaining polygon it takes the triangle of corners g, g+1, g+2; it skips
    it (g += 1) when the turn ``cross`` at g+1 has the sign opposite to ``(x_g y_{g+1} − y_g x_{g+1}) / 2``,
    or when another remaining corner lies inside it (crossing-number test); else it emits it and removes
    corner g+1.  After as many skips as corners remain without a removal it stops, and MuJoCo drops what
    is left.  This reader fans what is left from its first corner instead, so that the surface stays closed;
    on a planar polygon every such sequence gives the same solid, and on a non-planar one this is the solid
    MuJoCo integrates whenever it drops nothing.

    Parameters
    ----------
    corners : (k, 3) float
        The polygon's corners in file order.

    Returns
    -------
    triangles : list of (int, int, int)
        ``k − 2`` triangles, indices into ``corners``.
    dropped : int
        How many of them MuJoCo's loader leaves out.
    """
    k = len(corners)
    single = corners.astype(np.float32)
    eps = np.finfo(np.float32).eps
    axes = (1, 2)
    for i in range(k):
        e0 = single[(i + 1) % k] - single[i]
        e1 = single[(i + 2) % k] - single[(i + 1) % k]
        cx = abs(e0[1] * e1[2] - e0[2] * e1[1])
        cy = abs(e0[2] * e1[0] - e0[0] * e1[2])
        cz = abs(e0[0] * e1[1] - e0[1] * e1[0])
        if cx > eps or cy > eps or cz > eps:
            if not (cx > cy and cx > cz):
                axes = (0, 1) if (cz > cx and cz > cy) else (0, 2)
            break
    u, w = single[:, axes[0]], single[:, axes[1]]
    remaining = list(range(k))
    triangles: list[tuple[int, int, int]] = []
    guess, tries, previous = 0, k, k
    half = np.float32(0.5)
    while len(remaining) > 3 and tries > 0:          # at most k skips between removals: bounded by k²
        m = len(remaining)
        if guess >= m:
            guess -= m
        if previous != m:
            previous, tries = m, m
        else:
            tries -= 1
        tri = [remaining[(guess + j) % m] for j in range(3)]
        x, y = u[tri], w[tri]
        cross = (x[1] - x[0]) * (y[2] - y[1]) - (y[1] - y[0]) * (x[2] - x[1])
        area = (x[0] * y[1] - y[0] * x[1]) * half
        if cross * area < 0:
            guess += 1
            continue
        others = np.array([remaining[(guess + j) % m] for j in range(3, m)], dtype=np.int64)
        if others.size and _inside_triangle(x, y, u[others], w[others]).any():
            guess += 1
            continue
        triangles.append((tri[0], tri[1], tri[2]))
        del remaining[(guess + 1) % m]
    dropped = len(remaining) - 2 if len(remaining) > 3 else 0
    triangles.extend((remaining[0], remaining[j], remaining[j + 1]) for j in range(1, len(remaining) - 1))
    return triangles, dropped


def clip_polygons(vertices: np.ndarray, faces: np.ndarray, polygons: list[tuple[int, list[int]]]
                   ) -> tuple[int, int, float, int]:
    """Replace in place the first-corner fans of ``polygons`` ((first row in ``faces``, corner indices) each,
    k > 4 corners) by :func:`clip_polygon_as_mujoco`'s triangles.

    Returns the number of polygons whose solid differs from the first-corner fan's, the number whose corners
    are not coplanar, six times the sum over polygons of the absolute volume between the two triangulations
    (the closed surface of one and the other reversed, integrated about the polygon's first corner) and the
    number of triangles MuJoCo's loader drops."""
    differs = warped = dropped = 0
    six_between = 0.0
    for row, idx in polygons:
        corners = vertices[idx]
        k = len(idx)
        fan = [(0, j, j + 1) for j in range(1, k - 1)]
        clipped, lost = ([], 0) if k > MAX_CLIPPED_CORNERS else clip_polygon_as_mujoco(corners)
        relative = corners - corners[0]
        normal = np.cross(relative[1:-1], relative[2:]).sum(axis=0)
        if np.any(np.abs(relative @ normal) > 0):
            warped += 1
        elif clipped and _overlapping(relative, clipped, normal):
            clipped, lost = _clipped_near_the_origin(relative, clipped, lost, normal)
        dropped += lost
        if not clipped or clipped == fan:
            continue
        signed = 0.0
        for tris, sign in ((clipped, 1.0), (fan, -1.0)):
            p = relative[np.array(tris)]
            signed += sign * float(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum())
        if signed != 0.0:
            differs += 1
            six_between += abs(signed)
        faces[row:row + k - 2] = np.asarray(idx, dtype=faces.dtype)[np.array(clipped)]
    return differs, warped, six_between, dropped


def _overlapping(relative: np.ndarray, triangles: list[tuple[int, int, int]], normal: np.ndarray) -> bool:
    """Whether some of ``triangles`` (indices into the planar polygon ``relative``, (k, 3) m about its first
    corner) face against the polygon's ``normal`` (Newell's sum): then they overlap in its plane."""
    p = relative[np.array(triangles)]
    return bool(np.any(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) @ normal < 0))


#: Most corners of a planar polygon cut again by :func:`_ear_clip` (k³/6 point tests at most).
MAX_EAR_CLIPPED_CORNERS = 256


def ear_clip_2d(u: np.ndarray, w: np.ndarray, *, rotate: bool = False) -> list[tuple[int, int, int]] | None:
    """Triangles of the simple counter-clockwise polygon with corners ``(u[i], w[i])`` by ear clipping in float64:
    an ear is a corner turning left whose triangle holds no other remaining corner (on its border counts as held).
    ``rotate`` starts each pass's search after the last ear cut (ears spread round the polygon instead of fanning
    from its first corners).  None when no ear is found (the polygon is not simple in float64), or when the last
    three corners left turn right: the signed areas of the triangles sum to the polygon's (shoelace), and
    every ear turns left, so a clockwise polygon always ends there and is refused instead of cut into triangles
    of both orientations (a clockwise dart has one left-turning corner, an ear of the wrong side; found by
    ``tests/test_hole_graphs.py``, hypothesis seed 3689).  Quadratic passes in Python: callers bound the corner
    count."""
    remaining = list(range(len(u)))
    triangles: list[tuple[int, int, int]] = []
    start = 0
    while len(remaining) > 3:                     # one corner removed per pass: at most k − 3 passes
        m = len(remaining)
        for step in range(m):
            g = (start + step) % m
            a, b, c = remaining[g - 1], remaining[g], remaining[(g + 1) % m]
            turn = (u[b] - u[a]) * (w[c] - w[a]) - (w[b] - w[a]) * (u[c] - u[a])
            if not turn > 0:
                continue
            others = np.array([i for i in remaining if i not in (a, b, c)], dtype=np.int64)
            pu, pw = u[others], w[others]
            s0 = (u[b] - u[a]) * (pw - w[a]) - (w[b] - w[a]) * (pu - u[a])
            s1 = (u[c] - u[b]) * (pw - w[b]) - (w[c] - w[b]) * (pu - u[b])
            s2 = (u[a] - u[c]) * (pw - w[c]) - (w[a] - w[c]) * (pu - u[c])
            if np.any((s0 >= 0) & (s1 >= 0) & (s2 >= 0)):
                continue
            triangles.append((a, b, c))
            del remaining[g]
            if rotate:
                start = g % (m - 1)
            break
        else:
            return None
    a, b, c = remaining
    if (u[b] - u[a]) * (w[c] - w[a]) - (w[b] - w[a]) * (u[c] - u[a]) < 0:
        return None                               # clockwise (a flat last triangle, area 0, is kept as before)
    triangles.append((a, b, c))
    return triangles


def _ear_clip(relative: np.ndarray, normal: np.ndarray) -> list[tuple[int, int, int]] | None:
    """Triangles of a simple planar polygon (corners ``relative`` (k, 3) about the first one, counter-clockwise
    about ``normal``) by ear clipping in float64 on the plane most face-on to it: an ear is a corner turning
    left whose triangle holds no other remaining corner (on its boundary counts as held).  None when no ear is
    found (the polygon is not simple in float64) or it has more than :data:`MAX_EAR_CLIPPED_CORNERS` corners."""
    k = len(relative)
    if k > MAX_EAR_CLIPPED_CORNERS:
        return None
    drop = int(np.argmax(np.abs(normal)))
    # (u, w, dropped axis) in cyclic order, so that a polygon counter-clockwise about +drop runs counter-clockwise
    # in (u, w); (x, z) about +y would run it clockwise and no ear would be found (count15: a prism's cap in y = 0)
    axes = ((1, 2), (2, 0), (0, 1))[drop]
    if normal[drop] < 0:
        axes = axes[::-1]                         # so that the polygon runs counter-clockwise in (u, w)
    return ear_clip_2d(relative[:, axes[0]], relative[:, axes[1]])


def _clipped_near_the_origin(relative: np.ndarray, clipped: list[tuple[int, int, int]], lost: int,
                             normal: np.ndarray) -> tuple[list[tuple[int, int, int]], int]:
    """A planar polygon cut again by :func:`_ear_clip` in float64, when MuJoCo's clip (float32, on the file's
    coordinates) overlapped itself: far from the origin float32 cannot tell the corners apart (9e8 m out they lie
    on a 64 m grid), and the overlapping triangles would read as a surface passing through itself.  A planar
    polygon bounds the same solid however it is cut, so this changes no integral, only which triangles carry
    it; the first cut is kept when the second cannot be made or overlaps too."""
    again = _ear_clip(relative, normal)
    if again is None or _overlapping(relative, again, normal):
        return clipped, lost
    return again, lost          # what MuJoCo's own clip drops, still reported


def _percent_of_volume(vertices: np.ndarray, faces: np.ndarray, six_between: float) -> float | None:
    """``six_between`` (six times a volume between two triangulations) as a percentage of the volume ``faces``
    enclose, rounded up to two digits (so the printed figure is still a bound); None below 1e-9 of the volume
    (round-off of a planar export) or when the faces enclose nothing (unit-free: the reader does not know the
    file's unit)."""
    p = vertices[faces]
    six_volume = abs(float(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum()))
    if not six_volume > 0 or six_between <= 1e-9 * six_volume:
        return None
    return round_up(100 * six_between / six_volume, 2)


def warn_warped_quads(name: str, vertices: np.ndarray, faces: np.ndarray, warped: int, quads: int,
                      six_between: float) -> None:
    """Say that non-planar quads were split by rule, with the volume the other split could change, as a
    fraction of the enclosed volume (unit-free: the reader does not know the file's unit); nothing below
    1e-9 of it (round-off of a planar export)."""
    percent = _percent_of_volume(vertices, faces, six_between)
    if percent is None:
        return
    warnings.warn(NonPlanarPolygonWarning(
        f"{name}: {warped:,} of {quads:,} quadrilaterals are not planar; each was split along its "
        f"shorter diagonal (as MuJoCo reads OBJ; trimesh splits from the first corner): the other split would "
        f"change the volume by up to {percent:.2g} % of the whole"),
        stacklevel=4)


def warn_clipped_polygons(name: str, vertices: np.ndarray, faces: np.ndarray, differs: int, polygons: int,
                          six_between: float, dropped: int) -> None:
    """Say that polygons of more than four corners were ear-clipped as MuJoCo does, with the volume the
    first-corner fan (trimesh's reading) would change, as a fraction of the enclosed volume rounded up; and
    how many triangles MuJoCo's own loader leaves out of them.  Nothing below 1e-9 of the volume (round-off
    of a planar export)."""
    percent = _percent_of_volume(vertices, faces, six_between)
    if percent is None:
        return
    lost = (f"; MuJoCo's loader leaves {dropped:,} of their triangles out (its clipping stops; they are fanned "
            "here, so that the surface stays closed)") if dropped else ""
    warnings.warn(NonPlanarPolygonWarning(
        f"{name}: {differs:,} of {polygons:,} polygons with more than four corners are not planar; "
        f"each was ear-clipped as MuJoCo reads OBJ (trimesh fans from the first corner): the fan would change "
        f"the volume by up to {percent:.2g} % of the whole{lost}"),
        stacklevel=4)
