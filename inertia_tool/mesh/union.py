"""Overlapping bodies: a sound test for crossing surfaces, and the union by a robust boolean (manifold3d).

When closed shells overlap (two bodies modelled through each other, or one surface passing through itself
at non-manifold edges), the summed divergence-theorem integral counts the shared volume twice: the winding
number there is 2.  The physical solid is the union ``{w ≥ 1}``.

* :func:`crossing_shells` finds the shells whose surface touches or crosses another shell's surface, by
  exact-in-spirit triangle–triangle tests (an edge of one triangle passing through the other, with
  non-strict signs so that touching counts too) on the pairs that a k-d tree of face centres proposes.  It is
  conservative: it never misses a crossing between faces that share no vertex, and it may report touching
  surfaces; :func:`union_surface` is the arbiter (the union's volume equals the summed volume when nothing
  overlaps).
* :func:`closed_groups` splits a balanced surface into closed, manifold pieces: the patches of faces joined
  through manifold edges, with unclosed patches merged across the edges they share.
* :func:`union_surface` builds one manifold3d ``Manifold`` per piece (float64 ``Mesh64``), takes the union of
  the outward pieces minus the union of the inward ones (cavities) and returns the result as a triangle
  surface, which the caller integrates exactly like any other.

manifold3d (Elalish et al., "Manifold", github.com/elalish/manifold; PyPI ``manifold3d``) guarantees a
manifold output for manifold inputs, with symbolic perturbation for coplanar and touching cases.
"""

from __future__ import annotations

import numpy as np

from ..values import frozen_value

__all__ = ["crossing_shells", "closed_groups", "union_surface", "UnionSurface", "UnionError"]


class UnionError(RuntimeError):
    """The boolean union could not be formed (manifold3d missing, or a piece it rejects)."""


# -- sound crossing test -----------------------------------------------------------------------------------

def _orient(a, b, c, d):
    """6 × signed volume of the tetrahedron (a, b, c, d), rows of (k, 3) arrays."""
    return np.einsum("ij,ij->i", a - d, np.cross(b - d, c - d))


def _segment_meets_triangle(p, q, a, b, c, eps):
    """Non-strict: the closed segment pq touches or crosses the closed triangle abc (k,) bool."""
    sp, sq = _orient(a, b, c, p), _orient(a, b, c, q)
    straddle = ~(((sp > eps) & (sq > eps)) | ((sp < -eps) & (sq < -eps)))
    u, v, w = _orient(p, q, a, b), _orient(p, q, b, c), _orient(p, q, c, a)
    same = ~(((u > eps) | (v > eps) | (w > eps)) & ((u < -eps) | (v < -eps) | (w < -eps)))
    return straddle & same


def triangles_meet(t1: np.ndarray, t2: np.ndarray, eps: float = 0.0) -> np.ndarray:
    """Whether triangle pairs touch or cross (conservative), (k,) bool.

    Two triangles in general position intersect iff an edge of one passes through the other; coplanar or
    touching configurations make some orientation zero (within ``eps``) and count as meeting.

    Parameters
    ----------
    t1, t2 : (k, 3, 3) float
        Corner coordinates.
    eps : float
        Orientation values (6 × tetrahedron volumes) with magnitude at most ``eps`` count as zero.
    """
    hit = np.zeros(len(t1), dtype=bool)
    for s, t in ((t1, t2), (t2, t1)):
        for i, j in ((0, 1), (1, 2), (2, 0)):
            hit |= _segment_meets_triangle(s[:, i], s[:, j], t[:, 0], t[:, 1], t[:, 2], eps)
    return hit


def _near_query(lo, hi, query, origin, size, coarse=64):
    """Indices of the non-query faces whose box may overlap a query face's box.

    A coarse occupancy grid (``coarse`` cells a side) marks the cells the query boxes reach; a face inside one
    coarse cell is kept when that cell is marked, a face spanning several is kept regardless (conservative).
    """
    h = size / coarse if size > 0 else 1.0
    c0 = np.clip(np.floor((lo - origin) / h).astype(np.int64), 0, coarse - 1)
    c1 = np.clip(np.floor((hi - origin) / h).astype(np.int64), 0, coarse - 1)
    marked = np.zeros((coarse, coarse, coarse), dtype=bool)
    q = np.flatnonzero(query)
    one = (c0[q, 0] == c1[q, 0]) & (c0[q, 1] == c1[q, 1]) & (c0[q, 2] == c1[q, 2])
    marked[c0[q[one], 0], c0[q[one], 1], c0[q[one], 2]] = True
    for f in q[~one]:           # faces spanning several coarse cells: few (cells are 1/64 of the part)
        marked[c0[f, 0]:c1[f, 0] + 1, c0[f, 1]:c1[f, 1] + 1, c0[f, 2]:c1[f, 2] + 1] = True
    other = np.flatnonzero(~query)
    d0, d1 = c0[other], c1[other]
    single = (d0[:, 0] == d1[:, 0]) & (d0[:, 1] == d1[:, 1]) & (d0[:, 2] == d1[:, 2])
    keep = ~single
    cell = c0[other[single]]
    keep[single] = marked[cell[:, 0], cell[:, 1], cell[:, 2]]
    return other[keep]


def _cells(faces, lo, hi, origin, h, dims):
    """Grid entries (face, cell key) of ``faces`` on cells of side ``h`` covering their boxes."""
    i0 = np.floor((lo[faces] - origin) / h).astype(np.int64)
    i1 = np.floor((hi[faces] - origin) / h).astype(np.int64)
    span = i1 - i0 + 1
    count = span[:, 0] * span[:, 1] * span[:, 2]
    which = np.repeat(np.arange(len(faces)), count)
    k = np.arange(len(which)) - np.repeat(np.cumsum(count) - count, count)
    sy, sz = span[which, 1], span[which, 2]
    key = ((i0[which, 0] + k // (sy * sz)) * dims[1] + i0[which, 1] + (k // sz) % sy) * dims[2] + i0[which, 2] + k % sz
    return faces[which], key


def _home(a, b, lo, origin, h, dims):
    """Cell key (side ``h``) of the low corner of the intersection of the boxes of faces a and b."""
    c = np.floor((np.maximum(lo[a], lo[b]) - origin) / h).astype(np.int64)
    return (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]


def _grid_pairs(lo, hi, query, max_pairs, pad):
    """Face pairs whose padded bounding boxes overlap, at least one face in ``query``: (a, b) or None.

    A hierarchical grid: faces are sorted into levels by size (level ``L`` holds boxes at most ``h·2^L``
    across, ``h`` the median), each level has its own grid of cells ``h·2^L`` (a box spans at most 2 cells
    a side there), and every face is paired with the faces of its own level sharing a cell and with the
    larger levels' faces through their grids.  A pair is reported only in the cell holding the low corner of
    the two boxes' intersection, so it comes out once.  Faces far from every query face are dropped first
    (coarse occupancy grid).  Returns None beyond ``max_pairs`` candidate pairs (the caller then lets the
    boolean decide).
    """
    lo, hi = lo - pad, hi + pad
    origin = lo.min(axis=0)
    size = float(np.max(hi.max(axis=0) - origin))
    d = hi - lo
    extent = np.maximum(np.maximum(d[:, 0], d[:, 1]), d[:, 2])
    h0 = max(float(np.median(extent)), size / 4096, pad)
    level = np.ceil(np.log2(np.maximum(extent, h0) / h0)).astype(np.int64)
    keep = np.zeros(len(lo), dtype=bool)
    keep[np.flatnonzero(query)] = True
    keep[_near_query(lo, hi, query, origin, size)] = True
    out_a, out_b, total = [], [], 0
    for top in np.unique(level[keep]):
        h = h0 * 2.0 ** top
        dims = np.full(3, int(np.floor(size / h)) + 2, dtype=np.int64)
        members = np.flatnonzero(keep & (level == top))
        fb, kb = _cells(members, lo, hi, origin, h, dims)
        order = np.argsort(kb, kind="stable")
        fb, kb = fb[order], kb[order]
        # the same level: pairs within each cell
        starts = np.flatnonzero(np.r_[True, kb[1:] != kb[:-1]]) if len(kb) else np.zeros(0, dtype=np.int64)
        size_of = np.diff(np.r_[starts, len(kb)])
        later = np.repeat(starts + size_of, size_of) - np.arange(len(kb)) - 1
        n_same = int(later.sum())
        # smaller levels through this level's grid (only their query faces when this level has none)
        smaller = keep & (level < top)
        if not query[members].any():
            smaller &= query
        fa, ka = _cells(np.flatnonzero(smaller), lo, hi, origin, h, dims)
        left = np.searchsorted(kb, ka, side="left")
        run = np.searchsorted(kb, ka, side="right") - left
        n_cross = int(run.sum())
        total += n_same + n_cross
        if total > max_pairs:
            return None
        first = np.repeat(np.arange(len(kb)), later)
        offset = np.arange(n_same) - np.repeat(np.cumsum(later) - later, later)
        partner = np.repeat(left, run) + (np.arange(n_cross) - np.repeat(np.cumsum(run) - run, run))
        a = np.r_[fb[first], np.repeat(fa, run)]
        b = np.r_[fb[first + 1 + offset], fb[partner]]
        cell = np.r_[kb[first], kb[partner]]
        ok = (query[a] | query[b]) & (a != b)
        ok &= np.all(lo[a] <= hi[b], axis=1) & np.all(lo[b] <= hi[a], axis=1)
        a, b, cell = a[ok], b[ok], cell[ok]
        once = _home(a, b, lo, origin, h, dims) == cell
        out_a.append(a[once])
        out_b.append(b[once])
    if not out_a:
        e = np.zeros(0, dtype=np.int64)
        return e, e
    return np.concatenate(out_a), np.concatenate(out_b)


def crossing_shells(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, query: np.ndarray, *,
                    eps_rtol: float = 1e-12, max_pairs: int = 20_000_000) -> np.ndarray | None:
    """Shells whose surface touches or crosses another shell's surface or its own (non-adjacent) faces.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    labels : (m,) int
        Shell of each face.
    query : (m,) bool
        Faces to test against all faces (e.g. every face of the smaller shells of each overlapping pair).
    eps_rtol : float
        Orientation values below ``eps_rtol · L³`` (``L`` the bounding-box diagonal) count as zero.
    max_pairs : int
        Work bound on candidate pairs; beyond it the test gives up and returns None (the caller then lets
        the boolean union decide).

    Returns
    -------
    (s,) bool or None
        Per shell (``s = labels.max() + 1``): some face of it meets a face of another shell, or a face of its
        own shell that shares no vertex with it.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n_shells = int(labels.max()) + 1 if len(labels) else 0
    found = np.zeros(n_shells, dtype=bool)
    if not np.any(query):
        return found
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    v = v - centre
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    lo = np.minimum(np.minimum(p0, p1), p2)
    hi = np.maximum(np.maximum(p0, p1), p2)
    del p0, p1, p2
    pairs = _grid_pairs(lo, hi, np.asarray(query, dtype=bool), max_pairs, 1e-9 * diag)
    if pairs is None:
        return None
    a, b = pairs
    shared = np.zeros(len(a), dtype=bool)
    for i in range(3):
        for j in range(3):
            shared |= f[a, i] == f[b, j]
    a, b = a[~shared], b[~shared]
    eps = eps_rtol * diag ** 3
    step = 1 << 20
    for s in range(0, len(a), step):
        aa, bb = a[s:s + step], b[s:s + step]
        meet = triangles_meet(v[f[aa]], v[f[bb]], eps)
        found[labels[aa[meet]]] = True
        found[labels[bb[meet]]] = True
    return found


# -- closed pieces and their union ------------------------------------------------------------------------

def closed_groups(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """Split a balanced surface into pieces each closed and balanced on its own.

    Patches are the components of the faces joined through manifold edges (exactly two faces); a patch
    that is not closed on its own (its boundary runs along non-manifold edges) is merged with the unclosed
    patches it shares such edges with.

    Returns
    -------
    labels : (m,) int
        Piece of each face, ``0..count-1``.
    count : int
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .orient import _directed_keys

    f = np.asarray(faces)
    m = len(f)
    key, forward = _directed_keys(f, n_vertices)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    starts = np.flatnonzero(np.r_[True, skey[1:] != skey[:-1]])
    count = np.diff(np.r_[starts, len(skey)])
    pair = starts[count == 2]
    f1, f2 = order[pair] // 3, order[pair + 1] // 3
    n_patch, patch = connected_components(coo_matrix((np.ones(len(f1), dtype=np.int8), (f1, f2)), shape=(m, m)),
                                          directed=False)
    # patches unbalanced on their own: join those meeting at a non-manifold edge
    keyed_patch = patch[order // 3]
    edge_of = np.repeat(np.arange(len(starts)), count)
    sign = np.where(forward[order], 1, -1)
    patch_edge = keyed_patch.astype(np.int64) * len(starts) + edge_of
    unique, inverse = np.unique(patch_edge, return_inverse=True)
    net = np.bincount(inverse.reshape(-1), weights=sign)      # net direction count of each (patch, edge)
    unbalanced = np.zeros(n_patch, dtype=bool)
    unbalanced[(unique[net != 0] // len(starts)).astype(np.int64)] = True
    big = starts[count > 2]
    rows, cols = [], []
    for s, c in zip(big, count[count > 2]):
        members = np.unique(keyed_patch[s:s + c])
        members = members[unbalanced[members]]
        if len(members) > 1:
            rows.append(members[:-1])
            cols.append(members[1:])
    if rows:
        r, c = np.concatenate(rows), np.concatenate(cols)
        _, group = connected_components(coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)),
                                                   shape=(n_patch, n_patch)), directed=False)
    else:
        group = np.arange(n_patch)
    _, labels = np.unique(group[patch], return_inverse=True)
    return labels.reshape(-1).astype(np.intp), int(labels.max()) + 1 if m else 0


@frozen_value
class UnionSurface:
    """The boundary of the union, as produced by manifold3d.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes.
    faces : (k, 3) int64
        Outward-wound, closed, manifold.
    volume : float
        manifold3d's own volume of the result, m³ (a cross-check of the exact integral).
    """

    vertices: np.ndarray
    faces: np.ndarray
    volume: float


def _manifold(m3, vertices, faces):
    used, inverse = np.unique(faces, return_inverse=True)
    mesh = m3.Mesh64(vert_properties=np.ascontiguousarray(vertices[used], dtype=np.float64),
                     tri_verts=np.ascontiguousarray(inverse.reshape(-1, 3), dtype=np.uint64))
    solid = m3.Manifold(mesh)
    status = str(solid.status())
    if not status.endswith("NoError"):
        raise UnionError(f"a closed piece of {len(faces):,} faces is not accepted by the boolean ({status})")
    return solid


def union_surface(vertices: np.ndarray, faces: np.ndarray, groups: np.ndarray, n_groups: int,
                  outward: np.ndarray, body: np.ndarray | None = None) -> UnionSurface:
    """The solid of overlapping pieces: per body, its outward pieces united minus its inward ones; all united.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    groups : (m,) int
        Closed piece of each face (see :func:`closed_groups`).
    n_groups : int
    outward : (n_groups,) bool
        Whether each piece is wound outward (material); inward pieces are cavities.
    body : (n_groups,) int, optional
        The body each piece belongs to (a cavity belongs to the body around it); cavities are subtracted
        from their own body only, so a part sitting inside another part's void stays.  Default: one body.

    Returns
    -------
    UnionSurface

    Raises
    ------
    UnionError
    """
    try:
        import manifold3d as m3
    except ImportError as exc:  # pragma: no cover - a runtime dependency
        raise UnionError("the union of overlapping bodies needs the manifold3d package") from exc
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    body = np.zeros(n_groups, dtype=np.int64) if body is None else np.asarray(body)
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))   # the boolean works near the origin
    local = v - centre
    order = np.argsort(groups, kind="stable")
    starts = np.searchsorted(groups[order], np.arange(n_groups + 1))
    solids = []
    for b in np.unique(body):
        material: list = []
        voids: list = []
        for g in np.flatnonzero(body == b):
            piece = f[order[starts[g]:starts[g + 1]]]
            if len(piece):
                oriented = piece if outward[g] else piece[:, ::-1]
                (material if outward[g] else voids).append(_manifold(m3, local, oriented))
        if not material:
            continue
        solid = m3.Manifold.batch_boolean(material, m3.OpType.Add) if len(material) > 1 else material[0]
        if voids:
            solid = solid - (m3.Manifold.batch_boolean(voids, m3.OpType.Add) if len(voids) > 1 else voids[0])
        solids.append(solid)
    if not solids:
        raise UnionError("no outward-wound piece to unite")
    solid = m3.Manifold.batch_boolean(solids, m3.OpType.Add) if len(solids) > 1 else solids[0]
    out = solid.to_mesh64()
    verts = np.asarray(out.vert_properties, dtype=np.float64)[:, :3] + centre
    tris = np.asarray(out.tri_verts, dtype=np.int64).reshape(-1, 3)
    return UnionSurface(vertices=verts, faces=tris, volume=float(solid.volume()))
