"""The edges of a triangle mesh, keyed once for every stage that counts, pairs or looks them up.

Edge ``k`` of face ``i`` runs from corner ``k`` to corner ``k + 1 (mod 3)``: ``(0,1), (1,2), (2,0)``.  Its
undirected key is ``min(a, b)·n + max(a, b)`` (``n`` the number of vertices, so the key is unique and fits in
int64 for any mesh below 3·10⁹ vertices) and its direction bit is ``a > b``.  The edge census
(:mod:`~.checks`), consistent orientation (:mod:`~.orient`), the boundary of an open surface
(:mod:`~.rims`), sealing (:mod:`~.seal`) and closed groups (:mod:`~.union`) all use this one key.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["edge_keys", "stable_key_order", "unique_rows"]


def edge_keys(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """Undirected keys and direction bits of the 3m edges, face-major.

    Parameters
    ----------
    faces : (m, 3) int
        Vertex indices.
    n_vertices : int
        Number of vertices (the key's radix; values below 1 are taken as 1).

    Returns
    -------
    key : (3m,) int64
        ``min(a, b)·n + max(a, b)`` of edge ``k`` of face ``i`` at entry ``3i + k``.
    forward : (3m,) bool
        ``a > b``: the edge runs from the larger index to the smaller.
    """
    f = np.asarray(faces)
    # int32 faces, as the readers give them, are not copied: the ufuncs below widen them to int64 as they go
    # (uint64 would promote to float64 against int64, so it is converted, as anything not an integer)
    if f.dtype.kind not in "iu" or (f.dtype.kind == "u" and f.dtype.itemsize >= 8):
        f = f.astype(np.int64)
    a = f.reshape(-1)
    # the next corners, then their larger ends in place: two fresh (3m,) arrays fewer than the expression
    # min(a, b)·n + max(a, b) (each a 31 MB page-faulted allocation for a 1.3M-face soup)
    nxt = np.empty(f.shape, dtype=np.int64)
    nxt[:, :2] = f[:, 1:]
    nxt[:, 2] = f[:, 0]
    b: np.ndarray = nxt.reshape(-1)
    forward = a > b
    key = np.minimum(a, b)
    np.maximum(a, b, out=b)
    key *= np.int64(max(int(n_vertices), 1))
    key += b
    return key, forward


def stable_key_order(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``key`` (k,) non-negative int64 sorted and the stable order that sorts it: ``(key[order], order)`` with
    ``order = numpy.argsort(key, kind="stable")``, bit for bit.  Each key packed with its position into one int64
    (``key · k + i``: distinct, so any sort gives the stable order) and sorted by value (issue 25, soup17: the
    3.6M edge slots of the scattered-holes sphere, 0.45 → 0.12 s CPU).  For the stages that pair the
    uses of each key (a key of :func:`edge_keys`, below ``n²``); the stable argsort where the packed key
    would not fit 63 bits.

    Parameters
    ----------
    key : (k,) int64
        Non-negative keys (a negative one: the stable argsort).

    Returns
    -------
    sorted_key : (k,) int64
        ``key[order]``.
    order : (k,) int64
        ``numpy.argsort(key, kind="stable")``.
    """
    k = len(key)
    if not k or (int(key.max()) + 1) * k > np.iinfo(np.int64).max or int(key.min()) < 0:
        order = np.argsort(key, kind="stable")
        return key[order], order
    slots = np.int64(k)
    packed = key * slots
    packed += np.arange(k, dtype=np.int64)
    packed.sort()
    return packed // slots, packed % slots


def unique_rows(rows: np.ndarray, *, return_index: bool = False, return_inverse: bool = False,
                return_counts: bool = False) -> Any:
    """``numpy.unique(rows, axis=0, ...)`` of non-negative integer rows, bit for bit, by one int64 key per row.

    The columns are packed into one key, ``((r₀·R₁ + r₁)·R₂ + r₂)…`` with ``Rⱼ`` one more than column ``j``'s
    largest value, which orders rows as ``numpy.unique`` does (lexicographically), so the unique rows, the first
    indices (both sorts stable), the inverse and the counts are the same; the packed keys are sorted as plain
    integers instead of as the structured rows numpy compares field by field (issue 25, corpus19: ~35× less CPU
    on 210,000 (owner, edge key) pairs of ``nonmanifold.welded_bodies``).  Rows with a negative value, an
    unsigned 64-bit column, or a key that would not fit 63 bits go to ``numpy.unique`` itself.

    Parameters
    ----------
    rows : (k, c) int
        The rows.
    return_index, return_inverse, return_counts : bool
        As ``numpy.unique``.

    Returns
    -------
    unique : (u, c) int
        The distinct rows in lexicographic order, ``rows``' dtype; followed, as asked, by ``index`` (u,) int64
        (first occurrence of each), ``inverse`` (k,) int64 (the row of ``unique`` each row is) and ``counts``
        (u,) int64.
    """
    a = np.asarray(rows)
    packable = (a.ndim == 2 and len(a) > 0 and a.shape[1] > 0 and
                (a.dtype.kind == "i" or (a.dtype.kind == "u" and a.dtype.itemsize < 8)))
    if packable:
        wide = a.astype(np.int64, copy=False)
        low, high = wide.min(axis=0), wide.max(axis=0)
        radix = [int(h) + 1 for h in high]
        total = 1
        for r in radix:
            total *= r
        packable = int(low.min()) >= 0 and total <= np.iinfo(np.int64).max
    if not packable:
        numpy_unique: Any = np.unique              # (its overloads want the flags as literals)
        return numpy_unique(a, axis=0, return_index=return_index, return_inverse=return_inverse,
                            return_counts=return_counts)
    key = wide[:, 0].copy()
    for j in range(1, a.shape[1]):
        key *= np.int64(radix[j])
        key += wide[:, j]
    _, index, inverse, counts = np.unique(key, return_index=True, return_inverse=True, return_counts=True)
    out = [a[index]]
    if return_index:
        out.append(index)
    if return_inverse:
        out.append(inverse.reshape(-1))
    if return_counts:
        out.append(counts)
    return out[0] if len(out) == 1 else tuple(out)
