"""Counting with sign: the faces on the same three points, and the shells around a shell.

The machinery under the rules of :mod:`~.policy` that count before they decide (the rules and their reasons are
stated there, once):

* faces by *signed multiplicity* (:func:`signed_multiplicity`): the faces on the same three points form a class,
  each counted +1 wound one way and −1 the other, so the class's net count is what the winding number changes by
  across that triangle (Rigid Body Motion, Ch. 4: each face is one term of the divergence-theorem sums, and a face
  and its reverse are the zero chain).  R0 (:func:`coincident_surfaces`) and both arrangements
  (:func:`cancel_opposite`; :mod:`~.arrange`, :mod:`~.coplanar`) count by this one rule;
* *container windings* (:func:`container_windings`, :func:`winding_around`): the winding number, as the file
  winds them, of the shells around each shell, from the probes of :mod:`~.nesting` and the pairs placed by touching
  or by the boolean (R4's misread reading).

Pure functions on arrays; nothing here decides what a result is certified as.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..values import frozen_value
from .edges import edge_keys, unique_rows

if TYPE_CHECKING:
    from .nesting import Nesting

__all__ = ["Coincident", "coincident_surfaces", "signed_multiplicity", "cancel_opposite", "point_ids",
           "closed_components", "doubled_closed", "container_windings", "winding_around", "face_keys",
           "shell_multiplicity", "multiplicity_changes", "region_windings"]


@frozen_value
class Coincident:
    """R0: closed surfaces listed twice, and closed surfaces listed with their exact inverted copy.

    Attributes
    ----------
    drop : (m,) bool
        Faces to leave out: the later copy of each surface listed twice, and both members of each cancelling pair.
    repeated : int
        Closed surfaces that repeat another face for face (same corners, same winding): counted once.
    repeated_faces : int
    cancelled : int
        Pairs of closed surfaces each the other's exact inverse (same corners, opposite winding).
    cancelled_faces : int
        Faces of the cancelling pairs (both members).
    where : (3,) float
        A corner of the first surface left out, m (NaN when none).
    multiplicity : (m,) int
        For each face kept in place of its repeats, the net multiplicity ``|n|`` of its class (how many times the
        winding number counts it); 1 for every other face.
    """

    drop: np.ndarray
    repeated: int
    repeated_faces: int
    cancelled: int
    cancelled_faces: int
    where: np.ndarray
    multiplicity: np.ndarray


def closed_components(faces: np.ndarray, members: np.ndarray, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """Edge-connected components of the faces ``members`` (indices into ``faces``) and which of them are closed and
    balanced on their own (every directed edge matched by its reverse within the component)."""
    from .checks import shell_labels          # checks imports policy, which imports this module

    sub = faces[members]
    comp, n_comp = shell_labels(sub, n_vertices)
    key, forward = edge_keys(sub, n_vertices)
    owner = np.repeat(comp, 3).astype(np.int64)          # edge_keys lists each face's three edges in turn
    _, inverse = unique_rows(np.stack([owner, key.astype(np.int64)], axis=1), return_inverse=True)
    inverse = inverse.reshape(-1)
    net = np.bincount(inverse, weights=np.where(forward, 1.0, -1.0))
    unbalanced = np.zeros(n_comp, dtype=bool)
    first = np.zeros(len(net), dtype=np.int64)
    first[inverse] = owner
    unbalanced[first[net != 0]] = True
    return comp, ~unbalanced


def doubled_closed(faces: np.ndarray, n_vertices: int) -> bool:
    """Every edge of ``faces`` is used at least four times (a closed surface and its reverse on the same vertices;
    a flat sheet's rim edges are used twice)."""
    _, count = np.unique(edge_keys(faces, n_vertices)[0], return_counts=True)
    return bool(np.all(count >= 4))


def signed_multiplicity(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The faces on the same three points, and which way round each is: R0's count and the arrangements' (one rule).

    Parameters
    ----------
    corners : (m, 3) int
        Each face's corners as ids of distinct points (vertex ids of a welded surface, or ids of exact coordinates).

    Returns
    -------
    cls : (m,) int
        The class of each face (faces on the same three points share it), numbered from 0; −1 for a face with two
        equal corners (no triangle, no orientation).
    sign : (m,) int
        +1 or −1: the face's cyclic order is the class's own (from its smallest point, rising) or the reverse.
        The winding number changes across the triangle by the class's net multiplicity ``Σ sign`` (Rigid Body
        Motion, Ch. 4: each face is one term of the divergence-theorem sums, and a face and its reverse are the
        zero chain, their terms cancelling exactly).
    """
    g = np.asarray(corners, dtype=np.int64).reshape(-1, 3)
    cls = np.full(len(g), -1, dtype=np.int64)
    sign = np.zeros(len(g), dtype=np.int64)
    if not len(g):
        return cls, sign
    rows = np.arange(len(g))[:, None]
    start = np.argmin(g, axis=1)[:, None]
    key = g[rows, (start + np.arange(3)) % 3]                       # from the smallest point, same cycle
    ok = (key[:, 0] != key[:, 1]) & (key[:, 1] != key[:, 2]) & (key[:, 0] != key[:, 2])
    if ok.any():
        _, code = unique_rows(np.sort(key[ok], axis=1), return_inverse=True)
        cls[ok] = code.reshape(-1)
        sign[ok] = np.where(key[ok, 1] < key[ok, 2], 1, -1)
    return cls, sign


def cancel_opposite(corners: np.ndarray) -> np.ndarray:
    """(m,) bool: the faces kept once every face on the same three points as a face wound the other way is taken
    out with it, pair by pair (``k`` one way and ``j`` the other leave ``|k − j|``, the first listed; classes by
    :func:`signed_multiplicity`).

    A pair is the zero chain: its terms cancel exactly in the divergence-theorem sums and in the solid-angle sum
    of the winding number at every point off the triangle, so ``{w ≥ 1}`` is the same up to the triangle itself
    (measure zero); on a welded surface (``corners`` vertex ids) each directed edge loses one use and so does its
    reverse, so a closed surface stays closed."""
    cls, sign = signed_multiplicity(corners)
    keep = np.ones(len(cls), dtype=bool)
    members = np.flatnonzero(cls >= 0)
    if len(members) < 2:
        return keep
    order = members[np.lexsort((members, sign[members], cls[members]))]
    c, s = cls[order], sign[order]
    n_cls = int(c.max()) + 1
    plus = np.bincount(c, weights=(s > 0), minlength=n_cls).astype(np.int64)
    minus = np.bincount(c, weights=(s < 0), minlength=n_cls).astype(np.int64)
    group = c * 2 + (s > 0)
    first = np.r_[0, np.flatnonzero(group[1:] != group[:-1]) + 1]
    rank = np.arange(len(order)) - np.repeat(first, np.diff(np.r_[first, len(order)]))
    keep[order[rank < np.minimum(plus, minus)[c]]] = False
    return keep


def point_ids(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 3) int: each face's corners as ids of distinct exact coordinates (a copy with its own vertices gets the
    same ids)."""
    used, local = np.unique(faces, return_inverse=True)
    _, point = np.unique(np.asarray(vertices, dtype=np.float64)[used], axis=0, return_inverse=True)
    return np.asarray(point.reshape(-1)[local.reshape(-1)].reshape(-1, 3), dtype=np.int64)


def coincident_surfaces(vertices: np.ndarray, faces: np.ndarray, among: np.ndarray | None = None,
                        labels: np.ndarray | None = None) -> Coincident:
    """R0: closed surfaces listed more than once, each way round, combined by their windings.

    Faces are compared by the exact coordinates of their corners (bit for bit; a copy may use its own vertex
    indices or the same ones).  The faces on the same three points form a class; a face counts ``+1`` wound one
    way and ``−1`` the other, and the class's net multiplicity ``n`` is what the winding number changes by across
    that triangle (a repeat adds, a reverse cancels: :func:`signed_multiplicity`).  Every class keeps one face
    wound by the sign of ``n`` (the one in the lowest-numbered shell) and none when ``n = 0``; the rest are left
    out.  Left out with them: pairs of opposite faces (a zero chain: nothing changes in any surface integral nor
    in the winding number off the triangle) and, where ``|n| ≥ 2``, the repeats beyond one (the shell listed twice
    counted once).  Only whole closed surfaces go: the faces left out must make closed, balanced pieces (a face
    that two overlapping bodies happen to share stays), and a piece holding both members of a pair must use
    every edge at least four times (a closed surface and its reverse on the same vertices, not a flat sheet written
    both ways, which is R2's); the classes of a piece that fails are left as they are.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    among : (m,) bool, optional
        Only these faces are compared (the shells that could be copies); default all.
    labels : (m,) int, optional
        Shell of each face: of the copies of a face, the one in the lowest-numbered shell is kept, so that a
        copy with its own vertices is left out whole however the faces are ordered.
    """
    m = len(faces)
    drop = np.zeros(m, dtype=bool)
    none = Coincident(drop=drop, repeated=0, repeated_faces=0, cancelled=0, cancelled_faces=0,
                      where=np.full(3, np.nan), multiplicity=np.ones(m, dtype=np.int64))
    idx = np.flatnonzero(np.ones(m, dtype=bool) if among is None else np.asarray(among, dtype=bool))
    if len(idx) < 8:                       # a closed surface has at least 4 faces, two of them at least 8
        return none
    f = np.asarray(faces, dtype=np.int64)[idx]
    shell = np.zeros(len(f), dtype=np.int64) if labels is None else np.asarray(labels, dtype=np.int64)[idx]
    cls, sign = signed_multiplicity(point_ids(vertices, f))
    members = np.flatnonzero(cls >= 0)
    if not len(members):
        return none
    order = members[np.lexsort((members, shell[members], sign[members], cls[members]))]   # class, way, shell, face
    c, s = cls[order], sign[order]
    n_cls = int(c.max()) + 1
    plus = np.bincount(c, weights=(s > 0), minlength=n_cls).astype(np.int64)
    minus = np.bincount(c, weights=(s < 0), minlength=n_cls).astype(np.int64)
    net = plus - minus
    # rank of each face among the faces of its class wound the same way (0 for the first, in shell order)
    group = c * 2 + (s > 0)
    start = np.r_[0, np.flatnonzero(group[1:] != group[:-1]) + 1]
    rank = np.arange(len(order)) - np.repeat(start, np.diff(np.r_[start, len(order)]))
    kept = (s == np.sign(net[c])) & (rank == 0)
    pairs = np.minimum(plus, minus)[c]
    cancel = ~kept & ((s != np.sign(net[c])) | (rank <= pairs))                 # a member of an opposite pair
    candidate = ~kept & ((plus + minus)[c] >= 2)
    n_v = len(vertices)
    touchable = np.ones(n_cls, dtype=bool)
    gone = np.zeros(0, dtype=np.int64)
    comp = np.zeros(0, dtype=np.int64)
    both = np.zeros(0, dtype=bool)
    for _ in range(n_cls + 1):             # each pass leaves at least one more class as it is, or ends
        out = np.flatnonzero(candidate & touchable[c])               # positions in ``order``
        gone = order[out]
        if not len(gone):
            break
        comp, closed = closed_components(f, gone, n_v)
        # a piece holding both members of a pair (a class wound both ways in it) is a closed surface and its
        # reverse on the same vertices only when every edge is used at least four times (else a sheet, R2's)
        # (the sign shifted by +1 keeps the rows' order and makes them non-negative for ``unique_rows``)
        signs_in = unique_rows(np.stack([comp, c[out], s[out] + 1], axis=1))
        piece_class, per_class = unique_rows(signs_in[:, :2], return_counts=True)
        pieces_of = piece_class[:, 0]
        both = np.zeros(len(closed), dtype=bool)
        both[pieces_of[per_class > 1]] = True
        for k in np.flatnonzero(both & closed).tolist():            # bounded by the number of pieces
            closed[k] = doubled_closed(f[gone[comp == k]], n_v)
        bad = ~closed[comp]
        if not bad.any():
            break
        touchable[np.unique(c[out][bad])] = False
    if not len(gone):
        return none
    drop[idx[gone]] = True
    role = cancel[out]                                               # a member of an opposite pair
    repeated = int(np.count_nonzero(np.bincount(comp, weights=role.astype(np.float64)) == 0))
    paired = np.zeros(len(both), dtype=bool)
    paired[comp[role]] = True
    cancelled = int(np.count_nonzero(paired & both)) + (int(np.count_nonzero(paired & ~both)) + 1) // 2
    where = np.asarray(vertices, dtype=np.float64)[faces[np.flatnonzero(drop)[0], 0]]
    multiplicity = np.ones(m, dtype=np.int64)
    held = kept & touchable[c] & (np.abs(net[c]) > 1)          # a face standing for its repeats (R0: counted |n| times)
    multiplicity[idx[order[held]]] = np.abs(net[c[held]])
    return Coincident(drop=drop, repeated=repeated, repeated_faces=int(np.count_nonzero(~role)),
                      cancelled=cancelled, cancelled_faces=int(np.count_nonzero(role)), where=where,
                      multiplicity=multiplicity)


def container_windings(file_volumes: np.ndarray, nest: Nesting | None,
                       within: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(shell, container, winding)`` int arrays: each shell found inside another, and the container's winding
    number as the file winds it there.

    From the probes (``nest``: the winding each other shell gives a shell's probe point, kept where nonzero) and
    from the ``(shell, container)`` pairs placed by touching or by the boolean (``within``: a shell flush with its
    container, whose probe may lie on the container's surface and see nothing; counted with the sign of the
    container's own volume, +1 outward, −1 inward, and only where the probes did not already count it).  A shell
    is never its own container."""
    n = len(file_volumes)
    if nest is None:
        shell = other = winding = np.zeros(0, dtype=np.int64)
    else:
        shell, other = np.asarray(nest.shell, dtype=np.int64), np.asarray(nest.other, dtype=np.int64)
        winding = np.asarray(nest.winding, dtype=np.int64)
        keep = (winding != 0) & (shell != other)
        shell, other, winding = shell[keep], other[keep], winding[keep]
    if within is not None and len(within):
        pairs = np.asarray(within, dtype=np.int64).reshape(-1, 2)
        pairs = pairs[pairs[:, 0] != pairs[:, 1]]
        pairs = unique_rows(pairs[~np.isin(pairs[:, 0] * n + pairs[:, 1], shell * n + other)])
        shell, other = np.r_[shell, pairs[:, 0]], np.r_[other, pairs[:, 1]]
        winding = np.r_[winding, np.sign(file_volumes[pairs[:, 1]]).astype(np.int64)]
    return shell, other, winding


def winding_around(file_volumes: np.ndarray, nest: Nesting | None, within: np.ndarray | None) -> np.ndarray:
    """(s,) int: the winding number, as the file winds them, of the shells around each shell at its probe point
    (each container counted once: :func:`container_windings`)."""
    shell, _, winding = container_windings(file_volumes, nest, within)
    around = np.zeros(len(file_volumes), dtype=np.int64)
    np.add.at(around, shell, winding)
    return around



def region_windings(file_volumes: np.ndarray, nest: Nesting | None, within: np.ndarray | None,
                    multiplicity: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(inside, outside)``, (s,) int each: the file's winding number just inside and just outside each shell, the
    shells counted as wound (and ``multiplicity`` times each, R0; None: once).

    Valid where no shell crosses another: a shell ``X`` then lies in one region of the others, where their winding
    is ``Σ_C k_C w_C`` over the shells ``C`` around it (:func:`container_windings`), and crossing ``X`` inward adds
    ``k_X σ_X`` (``σ_X`` +1 wound outward, −1 inward).  Every region of space off the surfaces is just inside some
    shell or outside all of them (winding 0), so these numbers are every winding number the file gives."""
    vols = np.asarray(file_volumes, dtype=np.float64)
    k = np.ones(len(vols), dtype=np.int64) if multiplicity is None else np.asarray(multiplicity, dtype=np.int64)
    shell, other, winding = container_windings(vols, nest, within)
    outside = np.zeros(len(vols), dtype=np.int64)
    np.add.at(outside, shell, k[other] * winding)
    return outside + k * np.sign(vols).astype(np.int64), outside


def face_keys(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 9) float: each face's three corners' coordinates, the corners in lexicographic order (the same for a
    face and its reverse, and for a copy with its own vertex indices): what identifies a face listed again."""
    corners = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64).reshape(-1, 3)]
    order = np.lexsort((corners[:, :, 2], corners[:, :, 1], corners[:, :, 0]), axis=1)
    return np.take_along_axis(corners, order[:, :, None], axis=1).reshape(-1, 9)


def shell_multiplicity(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n_shells: int,
                       repeated: tuple[np.ndarray, np.ndarray] | None) -> np.ndarray | None:
    """(s,) int: how many times R0 found each shell listed, or None when every shell counts once.

    ``repeated``: ``(keys (r, 9) float, count (r,) int)``, the faces R0 kept in place of their repeats
    (:func:`face_keys`) and their net multiplicity.  A shell counts ``k`` times when every one of its faces is such
    a face with count ``k``; a stage after R0 that changed a shell's faces (an arrangement) leaves it counted once.
    When every shell counts the same ``k`` times (a part exported twice) the winding number is ``k`` times the
    winding counted once and ``{k·w ≥ 1} = {w ≥ 1}``: None."""
    if repeated is None or not len(repeated[0]) or n_shells == 0:
        return None
    keys, count = repeated
    mine = face_keys(vertices, faces)
    both = np.concatenate([np.asarray(keys, dtype=np.float64).reshape(-1, 9), mine])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    table = np.zeros(int(inverse.max()) + 1, dtype=np.int64)
    np.maximum.at(table, inverse[:len(keys)], np.asarray(count, dtype=np.int64))     # a key twice: the larger
    per_face = np.maximum(table[inverse[len(keys):]], 1)
    lab = np.asarray(labels, dtype=np.int64)
    lowest = np.full(n_shells, np.iinfo(np.int64).max, dtype=np.int64)
    highest = np.zeros(n_shells, dtype=np.int64)
    np.minimum.at(lowest, lab, per_face)
    np.maximum.at(highest, lab, per_face)
    k = np.where(lowest == highest, lowest, 1)
    k[lowest == np.iinfo(np.int64).max] = 1
    if np.all(k == k[0]):
        return None
    return k


def multiplicity_changes(multiplicity: np.ndarray, oriented: np.ndarray, shell: np.ndarray, other: np.ndarray,
                         winding: np.ndarray, crossing_with: np.ndarray) -> bool:
    """R0: may counting each shell ``multiplicity`` times give another ``{w ≥ 1}`` than counting it once?

    The two windings differ only inside shells listed more than once.  For each such shell and each shell inside
    one, ``X``: when ``X`` crosses no shell, the winding number just inside it (off the shells inside it) is
    ``σ_X + Σ_C w_C`` counted once and ``k_X σ_X + Σ_C k_C w_C`` counted with multiplicity, over the shells ``C``
    around it (``w_C`` their winding at its probe point, ``σ_X`` its own orientation); every region inside such a
    shell is just inside one ``X``, so the solids agree when those two sums agree on ``≥ 1`` for every ``X``
    (the empty region inside a shell filled by others is compared too: the answer errs toward True).  A shell in
    the count that crosses another makes the answer True (not decided here).

    Parameters
    ----------
    multiplicity : (s,) int
    oriented : (s,) int
        +1 or −1: each shell's orientation as read (outward or inward).
    shell, other, winding : (j,) int
        Each shell found inside another, and the winding number of that container at its probe point as read
        (:func:`container_windings`, turned where the container was turned).
    crossing_with : (k, 2) int
        Pairs of shells whose surfaces cross.
    """
    k = np.asarray(multiplicity, dtype=np.int64)
    if not np.any(k > 1) or np.all(k == k[0]):
        return False
    many = k > 1
    inside_many = np.zeros(len(k), dtype=bool)
    inside_many[shell[many[other]]] = True
    look = many | inside_many
    pairs = np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2)
    if len(pairs) and look[pairs.reshape(-1)].any():
        return True
    sigma = np.asarray(oriented, dtype=np.int64)
    once = sigma.copy()
    counted = k * sigma
    np.add.at(once, shell, winding)
    np.add.at(counted, shell, k[other] * winding)
    return bool(np.any((once[look] >= 1) != (counted[look] >= 1)))
