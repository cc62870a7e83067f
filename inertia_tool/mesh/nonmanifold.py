"""R1b's machinery (:mod:`~.policy`): the faces around each non-manifold edge paired, and each shell split into the
bodies welded along their crossing.

Where closed surfaces cross exactly along edges of both tessellations and the file shares those edges' vertices,
each crossing edge is used by four faces, two of each body; :func:`welded_bodies` pairs the faces around every such
edge first in, first out (:func:`_crossing_pairs_at_edges`) and splits a shell into the pieces so joined when every
piece is closed and balanced on its own.  The rule and its reason are stated in :mod:`~.policy` (R1b); the stage
that applies it is :func:`~.welded.settle_welded`.
"""

from __future__ import annotations

import numpy as np

from .._native import label_dtype
from ..values import frozen_value
from .edges import edge_keys, unique_rows

__all__ = ["WeldedBodies", "welded_bodies"]


@frozen_value
class WeldedBodies:
    """R1b: shells split at their non-manifold edges into the bodies welded there.

    Attributes
    ----------
    labels : (m,) int
        Shell of each face after the split, ``0..n_shells-1``.
    n_shells : int
    split : int
        Shells that were split (0: the labels are the ones given).
    ambiguous : int
        Shells with non-manifold edges that could not be split into closed bodies (kept whole).
    contact : (c, 2) int
        Face pairs of different shells that share a non-manifold edge by index (R4 tests their points).
    ambiguous_shells : (s,) bool
        The given shells counted by ``ambiguous`` (their faces go to the coplanar overlay, :mod:`~.coplanar`).
    """

    labels: np.ndarray
    n_shells: int
    split: int
    ambiguous: int
    contact: np.ndarray
    ambiguous_shells: np.ndarray | None = None


def _crossing_pairs_at_edges(vertices: np.ndarray, faces: np.ndarray, at: np.ndarray, edge_faces: np.ndarray,
                             lo: np.ndarray, hi: np.ndarray,
                             forward: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R1b: at each non-manifold edge, the faces that continue one body's surface through the others.

    Around the edge ``lo → hi`` the faces are sorted by angle; crossing a face wound along the edge (``forward``)
    counter-clockwise leaves a solid (the winding number drops by one), crossing one wound against it enters one.
    Read from a sector of the smallest winding number, the faces form a sequence of entries and exits, and the
    first solid entered is the first left: entries and exits are paired first in, first out, so that bodies whose
    surfaces pass through each other stay whole (paired last in, first out they would read as the boundary of the
    union around the boundary of the common part, a body inside a body).  Where the winding number around the
    edge never differs by more than one (bodies only touching there) both readings pair each entry with the next
    exit.  Two faces at the same angle (within their angles' rounding errors) facing opposite ways (bodies face to
    face) are read leaving one before entering the other; facing the same way (coplanar faces of two bodies
    overlapping) the order is undefined and the edge gives no pairs.

    Parameters
    ----------
    at : (k,) int
        Edge of each slot (a face at a non-manifold edge), slots grouped by edge.
    edge_faces, lo, hi, forward : (k,) arrays
        The slot's face, the edge's end points (``lo < hi``) and whether the face runs ``lo → hi`` (its outward
        normal then turns counter-clockwise about ``hi − lo`` from the face, so its solid lies clockwise).

    Returns
    -------
    pairs : (p, 2) int
        Faces paired.
    crossing : (k,) bool
        Slots at an edge where surfaces cross (the winding number around it spans two or more).
    undefined : (k,) bool
        Slots at an edge whose order is undefined.
    """
    v = vertices
    k = len(at)
    starts = np.flatnonzero(np.r_[True, at[1:] != at[:-1]])
    size = np.diff(np.r_[starts, k])
    group = np.repeat(np.arange(len(starts)), size)
    a, b = v[lo], v[hi]
    d = b - a
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    third = faces[edge_faces].sum(axis=1) - lo - hi
    w = v[third] - a
    w -= np.einsum("ij,ij->i", w, d)[:, None] * d
    height = np.linalg.norm(w, axis=1)
    u = w[starts] / np.maximum(height[starts], 1e-300)[:, None]
    u = u[group]
    angle = np.arctan2(np.einsum("ij,ij->i", w, np.cross(d, u)), np.einsum("ij,ij->i", w, u)) % (2 * np.pi)
    # each angle's float64 error is a few units of rounding of the coordinates over the face's height from the edge
    scale = np.max(np.abs(np.concatenate([a, b, v[third]], axis=1)), axis=1)
    error = 64 * 2.0 ** -53 * scale / np.maximum(height, 1e-300) + 1e-12
    order = np.lexsort((~forward, angle, at))          # by edge, by angle, at one angle a face leaving first
    ang, err, fw = angle[order], error[order], forward[order]
    nxt = np.arange(k) + 1
    last = starts + size - 1
    nxt[last] = starts                                  # the next slot around the edge, cyclically
    gap = np.where(np.isin(np.arange(k), last), ang[nxt] + 2 * np.pi - ang, ang[nxt] - ang)
    undefined_slot = (gap <= err + err[nxt]) & (fw == fw[nxt]) & (nxt != np.arange(k))
    undefined_edge = np.bincount(group, weights=undefined_slot, minlength=len(starts)) > 0
    step = np.where(fw, -1, 1)
    level = np.cumsum(step)
    level -= np.repeat(level[starts] - step[starts], size)     # within each edge, from its first slot
    low = np.minimum.reduceat(level, starts)
    high = np.maximum.reduceat(level, starts)
    crossing_edge = (high - low >= 2) & ~undefined_edge
    # start just after the first sector of the smallest winding number, each edge's sequence rotated there
    is_low = level == low[group]
    first_low = np.minimum.reduceat(np.where(is_low, np.arange(k), k), starts)
    start = first_low + 1 - starts                      # offset within the edge
    pos = (np.arange(k) - starts[group] - start[group]) % size[group]
    rotated = np.empty(k, dtype=np.int64)
    rotated[starts[group] + pos] = np.arange(k)         # rotated[starts + j] = the j-th slot read
    pairs = []
    simple = ~crossing_edge & ~undefined_edge
    if simple.any():                                    # enter, leave, enter, leave: consecutive slots pair
        first = starts[group] + pos
        take = simple[group] & (pos % 2 == 0)
        entry = order[np.arange(k)[take]]
        exit_ = order[rotated[first[take] + 1]]
        pairs.append(np.stack([edge_faces[entry], edge_faces[exit_]], axis=1))
    for e in np.flatnonzero(crossing_edge):             # surfaces crossing: first in, first out (rare; bounded)
        seq = order[rotated[starts[e]:starts[e] + size[e]]]
        entered: list[int] = []
        for slot in seq.tolist():
            if not forward[slot]:
                entered.append(slot)
            elif entered:
                pairs.append(np.array([[edge_faces[entered.pop(0)], edge_faces[slot]]]))
    out = np.concatenate(pairs).astype(np.int64) if pairs else np.zeros((0, 2), dtype=np.int64)
    return out, crossing_edge[group], undefined_edge[group]


def welded_bodies(faces: np.ndarray, n_vertices: int, labels: np.ndarray, n_shells: int,
                  vertices: np.ndarray) -> WeldedBodies:
    """R1b: split each shell at its non-manifold edges into the bodies welded there.

    The faces joined through manifold edges (used by exactly two faces) form pieces; at each non-manifold edge the
    pieces are joined as :func:`_crossing_pairs_at_edges` pairs the faces (bodies passing through each other stay
    whole).  A shell is split when every group of pieces so joined is closed and balanced on its own; otherwise it
    stays one shell (``ambiguous`` counts it).

    Parameters
    ----------
    faces : (m, 3) int
        A balanced surface (every directed edge matched by its reverse).
    n_vertices : int
    labels : (m,) int
        Edge-connected shells (:func:`~.checks.shell_labels`).
    n_shells : int
    vertices : (n, 3) float
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components


    f = np.asarray(faces, dtype=np.int64)
    labels = np.asarray(labels, dtype=np.int64)
    m = len(f)
    none = WeldedBodies(labels=labels, n_shells=n_shells, split=0, ambiguous=0,
                        contact=np.zeros((0, 2), dtype=np.int64))
    if m < 8:                                     # two closed surfaces need at least eight faces
        return none
    key, forward = edge_keys(f, n_vertices)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    starts = np.flatnonzero(np.r_[True, skey[1:] != skey[:-1]])
    count = np.diff(np.r_[starts, len(skey)])
    many = np.flatnonzero(count > 2)
    if not len(many):
        return none
    two = starts[count == 2]
    rows, cols = order[two] // 3, order[two + 1] // 3
    # the faces around each non-manifold edge, paired so that crossing bodies stay whole
    at = np.repeat(many, count[many])
    slots = order[np.concatenate([np.arange(starts[k], starts[k] + count[k]) for k in many])]
    nv = np.int64(max(int(n_vertices), 1))
    ekey = key[slots]
    paired, crossing_slot, undefined_slot = _crossing_pairs_at_edges(
        np.asarray(vertices, dtype=np.float64), f, at, slots // 3, ekey // nv, ekey % nv, ~forward[slots])
    rows, cols = np.r_[rows, paired[:, 0]], np.r_[cols, paired[:, 1]]
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(m, m))
    n_pieces, piece = connected_components(graph, directed=False)
    # each group balanced on its own: the net direction of every (group, edge) is zero
    owner = piece[np.arange(3 * m) // 3].astype(np.int64)
    _, inverse = unique_rows(np.stack([owner, key], axis=1), return_inverse=True)
    inverse = inverse.reshape(-1)
    net = np.bincount(inverse, weights=np.where(forward, 1.0, -1.0))
    first = np.zeros(len(net), dtype=np.int64)
    first[inverse] = owner
    unbalanced = np.zeros(n_pieces, dtype=bool)
    unbalanced[first[net != 0]] = True
    shell_of_piece = np.zeros(n_pieces, dtype=np.int64)
    shell_of_piece[piece] = labels
    bad_shell = np.zeros(n_shells, dtype=bool)
    bad_shell[shell_of_piece[unbalanced]] = True
    pieces_per_shell = np.bincount(shell_of_piece, minlength=n_shells)
    # only shells where surfaces cross at a welded edge need splitting (bodies that only touch sum exactly)
    crossed = np.zeros(n_shells, dtype=bool)
    crossed[labels[(slots // 3)[crossing_slot | undefined_slot]]] = True
    splits = (pieces_per_shell > 1) & ~bad_shell & crossed
    ambiguous = int(np.count_nonzero(crossed & bad_shell))
    if splits.any():
        sub = np.where(splits[labels], piece, -1)
        _, new = unique_rows(np.stack([labels, sub + 1], axis=1), return_inverse=True)   # (-1 → 0: same order)
        new = new.reshape(-1)
        _, first_face = np.unique(new, return_index=True)          # numbered in order of each shell's first face
        rank = np.empty(len(first_face), dtype=np.int64)
        rank[np.argsort(first_face, kind="stable")] = np.arange(len(first_face))
        new, count_new = rank[new], len(first_face)
    else:                      # already apart (split before): the contacts at their shared edges are still wanted
        new, count_new = labels, n_shells
    # face pairs of different new shells around each non-manifold edge: contacts for R4
    fa = slots // 3
    groups = np.flatnonzero(np.r_[True, at[1:] != at[:-1]])
    mixed = np.minimum.reduceat(new[fa], groups) != np.maximum.reduceat(new[fa], groups)
    pairs = []
    for g0, g1 in zip(groups[mixed], np.r_[groups[1:], len(at)][mixed]):     # edges between shells; bounded
        fs = fa[g0:g1]
        i, j = np.triu_indices(len(fs), 1)
        keep = new[fs[i]] != new[fs[j]]
        pairs.append(np.stack([fs[i][keep], fs[j][keep]], axis=1))
    contact = unique_rows(np.sort(np.concatenate(pairs), axis=1)) if pairs else np.zeros((0, 2), np.int64)
    new = new.astype(label_dtype(len(new)), copy=False)
    return WeldedBodies(labels=new, n_shells=count_new, split=int(np.count_nonzero(splits)),
                        ambiguous=ambiguous, contact=contact.astype(np.int64), ambiguous_shells=crossed & bad_shell)
