"""Which shells lie inside which: exact ray-crossing counts against a sorted index of the faces.

For a closed, balanced surface the winding number at a point ``p`` equals the signed number of crossings of
any ray from ``p``: ``w(p) = Σ sign(n_x)`` over the triangles that the ray ``p + t·x̂, t > 0`` passes through
(``n`` the triangle's normal; an outward-wound surface is left with ``n_x > 0``).  Unlike the solid-angle
sum, this needs only the triangles whose (y, z) shadow holds ``p``: the probe points are sorted by y, each
triangle finds the probes in its y-range by binary search, and only those pairs are tested.  A scanned
skin of a million faces with hundreds of pores costs about one pass over the faces.

Robustness: the three edge tests of a triangle are evaluated with each edge's end points in a canonical
order (smaller vertex index first) and the sign applied afterwards, so the two triangles sharing an edge
see exactly opposite values and a ray through an edge is never counted twice or missed.  A ray that passes
exactly through an edge or vertex (an edge test is exactly 0) is cast again in a rotated frame; a probe
that lies on another shell's surface (two shells touching) is replaced by the centre of another face.
Probes left undecided after ``tries`` attempts are reported, never guessed.
"""

from __future__ import annotations

import numpy as np

from ..values import frozen_value

__all__ = ["Nesting", "shell_nesting", "ray_winding", "PointSides", "touching_sides", "TOUCH_SAMPLE"]

#: Fixed generic rotations (unit quaternions, scalar first) for recasting rays that hit an edge exactly.
_FRAMES = ((1.0, 0.0, 0.0, 0.0), (0.8660254, 0.2886751, 0.2886751, 0.2886751),
           (0.7071068, 0.1, 0.6928203, 0.0707107), (0.5, -0.5, 0.5, 0.5))

#: Candidate pairs (triangle, probe) tested per vectorised step (bounds memory at ~100 bytes each).
_PAIR_STEP = 1 << 21


def _rotation(q: tuple[float, float, float, float]) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _edge_test(pi: np.ndarray, pj: np.ndarray, i: np.ndarray, j: np.ndarray, py: np.ndarray,
               pz: np.ndarray) -> np.ndarray:
    """orient2d of (p_i, p_j, p) in the (y, z) plane with the end points in canonical (index) order."""
    swap = i > j
    lo = np.where(swap[:, None], pj, pi)
    hi = np.where(swap[:, None], pi, pj)
    d = (hi[:, 1] - lo[:, 1]) * (pz - lo[:, 2]) - (hi[:, 2] - lo[:, 2]) * (py - lo[:, 1])
    signed: np.ndarray = np.where(swap, -d, d)
    return signed


def ray_winding(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, groups: np.ndarray,
                n_groups: int, *, exclude: np.ndarray | None = None,
                on_surface: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Signed ray-crossing count of every group of faces at every point, along +x.

    Parameters
    ----------
    points : (p, 3) float
    vertices : (n, 3) float
    faces : (m, 3) int
    groups : (m,) int
        Group (shell) of each face, in ``[0, n_groups)``.
    n_groups : int
    exclude : (p,) int, optional
        A group to skip for each point (the shell the point lies on).
    on_surface : float
        A crossing closer than this to the point (along the ray) makes the point undecided (it lies on
        that surface).

    Returns
    -------
    point, group, winding : (k,) int arrays
        The nonzero crossing sums: ``winding`` of group ``group`` at point ``point``.
    degenerate : (p,) bool
        Points whose ray passed exactly through an edge or vertex, or that lie on a surface: their counts are
        not valid and must be recomputed (another frame, another point).
    """
    points = np.asarray(points, dtype=np.float64)
    n_points = len(points)
    degenerate = np.zeros(n_points, dtype=bool)
    if n_points == 0 or len(faces) == 0:
        e = np.zeros(0, dtype=np.int64)
        return e, e, e, degenerate
    order = np.argsort(points[:, 1], kind="stable")
    sorted_y = points[order, 1]
    f = np.asarray(faces, dtype=np.int64)
    y = vertices[:, 1]
    y0, y1, y2 = y[f[:, 0]], y[f[:, 1]], y[f[:, 2]]
    lo = np.searchsorted(sorted_y, np.minimum(np.minimum(y0, y1), y2), side="left")
    hi = np.searchsorted(sorted_y, np.maximum(np.maximum(y0, y1), y2), side="right")
    del y0, y1, y2
    z_of_face = vertices[:, 2][f]
    z_lo, z_hi = z_of_face.min(axis=1), z_of_face.max(axis=1)      # once per face, not once per pair
    del z_of_face
    counts = hi - lo
    candidates = np.flatnonzero(counts)
    keys: list[np.ndarray] = []
    signs: list[np.ndarray] = []
    cum = np.cumsum(counts[candidates])
    start = 0
    while start < len(candidates):
        base = cum[start - 1] if start else 0
        stop = int(np.searchsorted(cum, base + _PAIR_STEP, side="right"))
        stop = max(stop, start + 1)
        fc = candidates[start:stop]
        c = counts[fc]
        face = np.repeat(fc, c)
        offset = np.arange(len(face)) - np.repeat(np.cumsum(c) - c, c)
        point = order[lo[face] + offset]
        pz = points[point, 2]
        inside_z = (z_lo[face] <= pz) & (pz <= z_hi[face])
        if exclude is not None:
            inside_z &= groups[face] != exclude[point]
        face, point = face[inside_z], point[inside_z]
        p = points[point]
        ia, ib, ic = f[face, 0], f[face, 1], f[face, 2]
        a, b, cc = vertices[ia], vertices[ib], vertices[ic]
        d_ab = _edge_test(a, b, ia, ib, p[:, 1], p[:, 2])
        d_bc = _edge_test(b, cc, ib, ic, p[:, 1], p[:, 2])
        d_ca = _edge_test(cc, a, ic, ia, p[:, 1], p[:, 2])
        pos = (d_ab >= 0) & (d_bc >= 0) & (d_ca >= 0)
        neg = (d_ab <= 0) & (d_bc <= 0) & (d_ca <= 0)
        total = d_ab + d_bc + d_ca
        hit = (pos | neg) & (total != 0)                 # shadow holds p; edge-on triangles hold nothing
        edge = hit & ((d_ab == 0) | (d_bc == 0) | (d_ca == 0))
        degenerate[point[edge]] = True
        hit &= ~edge
        with np.errstate(invalid="ignore", divide="ignore"):
            x = (d_bc * a[:, 0] + d_ca * b[:, 0] + d_ab * cc[:, 0]) / total
        gap = x - p[:, 0]
        touching = hit & (np.abs(gap) <= on_surface)
        degenerate[point[touching]] = True
        crossing = hit & ~touching & (gap > 0)
        keys.append(point[crossing] * np.int64(n_groups) + groups[face[crossing]])
        signs.append(np.where(total[crossing] > 0, 1, -1))
        start = stop
    key = np.concatenate(keys) if keys else np.zeros(0, dtype=np.int64)
    sign = np.concatenate(signs) if signs else np.zeros(0, dtype=np.int64)
    unique, inverse = np.unique(key, return_inverse=True)
    winding = np.bincount(inverse.reshape(-1), weights=sign, minlength=len(unique)).astype(np.int64)
    keep = winding != 0
    return unique[keep] // n_groups, unique[keep] % n_groups, winding[keep], degenerate


@frozen_value
class Nesting:
    """Winding numbers of the shells at one point of each shell.

    Attributes
    ----------
    shell, other, winding : (k,) int
        Shell ``other`` has winding number ``winding`` (≠ 0) at the probe point of shell ``shell``
        (``other ≠ shell``), with the faces as given (an outward shell counts +1 inside, an inward one −1).
    probes : (s, 3) float
        The probe point used for each shell (a face centre), m.
    undecided : (s,) bool
        Shells for which no probe gave a clean answer within the tries (every probe on another surface).
    """

    shell: np.ndarray
    other: np.ndarray
    winding: np.ndarray
    probes: np.ndarray
    undecided: np.ndarray


def _probe_faces(faces: np.ndarray, vertices: np.ndarray, labels: np.ndarray, n_shells: int,
                 rank: int) -> np.ndarray:
    """Index of the face of each shell with the ``rank``-th largest area (the last one when fewer), (s,)."""
    v = vertices
    e1 = v[faces[:, 1]] - v[faces[:, 0]]
    e2 = v[faces[:, 2]] - v[faces[:, 0]]
    area = ((e1[:, 1] * e2[:, 2] - e1[:, 2] * e2[:, 1]) ** 2 + (e1[:, 2] * e2[:, 0] - e1[:, 0] * e2[:, 2]) ** 2
            + (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) ** 2)          # squared doubled area: same order
    del e1, e2
    if rank == 0:
        order = np.argsort(labels, kind="stable")             # labels come grouped: nearly linear
        starts = np.searchsorted(labels[order], np.arange(n_shells))
        best = np.maximum.reduceat(area[order], starts)
        is_best = area[order] == np.repeat(best, np.diff(np.r_[starts, len(order)]))
        first = np.flatnonzero(is_best)
        picked: np.ndarray = order[first[np.searchsorted(first, starts)]]
        return picked
    order = np.lexsort((-area, labels))
    starts = np.searchsorted(labels[order], np.arange(n_shells))
    ends = np.r_[starts[1:], len(faces)]
    picked = order[np.minimum(starts + rank, ends - 1)]
    return picked


def shell_nesting(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n_shells: int, *,
                  on_surface_rtol: float = 1e-9, tries: int = 8) -> Nesting:
    """Winding number of every shell at a point of every other shell, by exact ray crossings.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        Closed, balanced shells (each shell's winding number is an integer off its surface).
    labels : (m,) int
        Shell of each face, ``0..n_shells-1``, every shell non-empty.
    n_shells : int
    on_surface_rtol : float
        A probe within this fraction of the bounding-box diagonal of another shell's surface (along its ray)
        counts as lying on it and is replaced.
    tries : int
        Probe points (face centres, largest faces first) and ray frames tried per shell.

    Returns
    -------
    Nesting
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    labels = np.asarray(labels, dtype=np.int64)
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    diag = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    local = vertices - centre
    result_shell: list[np.ndarray] = []
    result_other: list[np.ndarray] = []
    result_w: list[np.ndarray] = []
    probes = np.zeros((n_shells, 3))
    pending = np.arange(n_shells)
    for attempt in range(max(1, int(tries))):
        if not len(pending):
            break
        pick = _probe_faces(faces, local, labels, n_shells, attempt)[pending]
        p = local[faces[pick]].mean(axis=1)
        probes[pending] = p + centre
        frame = _rotation(_FRAMES[attempt % len(_FRAMES)])
        point, other, w, bad = ray_winding(p @ frame, local @ frame, faces, labels, n_shells,
                                           exclude=pending, on_surface=on_surface_rtol * diag)
        own = pending[point]
        keep = ~bad[point]
        result_shell.append(own[keep])
        result_other.append(other[keep])
        result_w.append(w[keep])
        pending = pending[bad]
    def cat(xs: list[np.ndarray]) -> np.ndarray:
        return np.concatenate(xs) if xs else np.zeros(0, dtype=np.int64)
    undecided = np.zeros(n_shells, dtype=bool)
    undecided[pending] = True
    return Nesting(shell=cat(result_shell), other=cat(result_other), winding=cat(result_w), probes=probes,
                   undecided=undecided)


#: Vertices of a shell tested against a shell it touches, at most, besides those of the faces in contact.
TOUCH_SAMPLE = 4096

#: Frames for the points of touching shells: no ray along a mesh axis, so a point on a face parallel to an axis
#: (rounded off it by 1e-16) meets that face at a generic angle, within the on-surface margin, and stays undecided
#: instead of being counted by its rounding.
_GENERIC_FRAMES = ((0.8660254, 0.2886751, 0.2886751, 0.2886751), (0.7071068, 0.1, 0.6928203, 0.0707107),
                   (0.3, 0.4, -0.5, 0.7), (0.6, -0.2, 0.3, 0.71))

#: Barycentric weights of the points tested inside each face in contact: its centroid and the midpoints between
#: the centroid and each corner (two bodies crossing like beams have every vertex of both on the other surface).
_INNER_WEIGHTS = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])


@frozen_value
class PointSides:
    """Where the points of one shell lie relative to another shell that it touches (R4).

    Attributes
    ----------
    pairs : (k, 2) int
        ``(shell, other)``: the vertices of ``shell`` were tested against the surface of ``other``.
    inside, outside : (k,) int
        Tested points (vertices, and points inside the faces in contact) where ``other``'s winding number is
        nonzero / zero (exact ray counts).
    on_surface : (k,) int
        Tested points left undecided: on ``other``'s surface (within ``on_surface_rtol`` of the diagonal along
        every ray tried) or with every ray through an edge.
    """

    pairs: np.ndarray
    inside: np.ndarray
    outside: np.ndarray
    on_surface: np.ndarray


def _touch_points(faces: np.ndarray, shell_faces: np.ndarray, contact_faces: np.ndarray, shared: np.ndarray,
                  sample: int) -> np.ndarray:
    """Vertex indices of one shell to test: every corner of its faces in contact with the other shell, and a
    strided sample of at most ``sample`` of the others; corners shared by index with the other shell left out."""
    everyone = np.unique(faces[shell_faces])
    near = np.unique(faces[contact_faces])
    rest = np.setdiff1d(everyone, near, assume_unique=True)
    if len(rest) > sample:
        rest = rest[np.linspace(0, len(rest) - 1, sample).astype(np.int64)]
    points = np.union1d(near, rest)
    return np.setdiff1d(points, shared, assume_unique=True)


def touching_sides(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, pairs: np.ndarray,
                   contact_pairs: np.ndarray, *, on_surface_rtol: float = 1e-9,
                   sample: int = TOUCH_SAMPLE) -> PointSides:
    """For each pair of shells that touch, the sides of each shell's vertices relative to the other shell.

    Two surfaces can cross exactly along edges and vertices of both meshes (CAD tessellations sharing their
    intersection curve): then no face pair crosses transversally, every pair there is only a contact, and one
    probe point cannot tell nesting from overlap.  Points of A decide instead: those not on B's surface lie
    inside B (winding number ≠ 0), outside it, or both (the surfaces cross).  Tested are every corner of A's
    faces in contact with B and four points inside each of those faces (a face whose corners all lie on B's
    surface can still lie inside B: two boxes crossing like beams), and a strided sample of A's other vertices.
    Without a transversal crossing, the faces of A next to where the surfaces cross are in contact with B and
    lie on both sides of it, so these points see the crossing.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        Closed, balanced shells.
    labels : (m,) int
        Shell of each face.
    pairs : (k, 2) int
        Shell pairs that touch (a contact or coplanar-opposite face pair between them).
    contact_pairs : (c, 2) int
        The touching face pairs (faces of different shells): their corners and inner points are always tested.
    on_surface_rtol : float
        A vertex within this fraction of the bounding-box diagonal of the other surface (along its ray) lies on it.
    sample : int
        Other vertices of each shell tested, at most (evenly strided over the vertex indices).

    Returns
    -------
    PointSides
        Both directions of every pair, ``(a, b)`` then ``(b, a)``.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    labels = np.asarray(labels, dtype=np.int64)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    contact_pairs = np.asarray(contact_pairs, dtype=np.int64).reshape(-1, 2)
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    margin = on_surface_rtol * float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    local = vertices - centre
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], np.arange(int(labels.max()) + 2))
    directed = np.concatenate([pairs, pairs[:, ::-1]]) if len(pairs) else pairs
    inside = np.zeros(len(directed), dtype=np.int64)
    outside = np.zeros(len(directed), dtype=np.int64)
    undecided = np.zeros(len(directed), dtype=np.int64)
    ca, cb = labels[contact_pairs[:, 0]], labels[contact_pairs[:, 1]]
    for k, (a, b) in enumerate(directed.tolist()):                # bounded by the pairs given
        own = order[starts[a]:starts[a + 1]]
        other = order[starts[b]:starts[b + 1]]
        touching = np.concatenate([contact_pairs[(ca == a) & (cb == b), 0], contact_pairs[(ca == b) & (cb == a), 1]])
        corners = local[_touch_points(faces, own, touching, np.unique(faces[other]), sample)]
        tri = local[faces[np.unique(touching)]]                  # (t, 3, 3)
        inner = np.einsum("pk,tkd->tpd", _INNER_WEIGHTS, tri).reshape(-1, 3)
        points = np.concatenate([corners, inner])
        pending = np.arange(len(points))
        winding = np.zeros(len(points), dtype=np.int64)
        for frame_q in _GENERIC_FRAMES:                           # recast rays through an edge; bounded
            if not len(pending):
                break
            frame = _rotation(frame_q)
            point, _, w, bad = ray_winding(points[pending] @ frame, local @ frame, faces[other],
                                           np.zeros(len(other), dtype=np.int64), 1, on_surface=margin)
            winding[pending] = 0
            winding[pending[point]] = w
            pending = pending[bad]
        decided = np.ones(len(points), dtype=bool)
        decided[pending] = False
        inside[k] = int(np.count_nonzero(decided & (winding != 0)))
        outside[k] = int(np.count_nonzero(decided & (winding == 0)))
        undecided[k] = len(pending)
    return PointSides(pairs=directed, inside=inside, outside=outside, on_surface=undecided)
