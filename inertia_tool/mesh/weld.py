"""Welding triangle corners into shared vertices.

STL stores every triangle with its own three corners; topology checks need to know which corners are the
same vertex.  ``weld_exact`` merges corners whose coordinates are bit-identical (what every exporter writes
for a shared corner); ``weld_tolerance`` merges vertices closer than a tolerance on a grid, for meshes whose
exporter rounded shared corners differently.  Welding never moves a coordinate that the integrals use:
``weld_exact`` keeps the exact values, ``weld_tolerance`` moves corners by less than its tolerance.

Vertices are numbered in order of first appearance in the corner stream, whichever path welds them.

Three implementations give identical results: the C extension's ``Welder`` (an open-addressing hash table on
the exact 12 or 24 bytes of a point, fed chunk by chunk in one pass, about 12 bytes per triangle beyond
the output; see ``inertia_tool._native``); its ``PartWelder`` for large float32 streams (binary STL), which
partitions the points by hash into buckets as they stream in and welds each bucket in a table that fits in
a core's cache, on several threads (16 bytes per corner that reaches a bucket, at most 48 per triangle,
given back chunk by chunk while the vertices are written); and
the numpy reference below, which reads the corners in chunks (twice) and holds only 64-bit keys and 32-bit
indices, about 72 bytes per triangle at its peak.  Either way a 5M-face binary STL never exists as a
float64 soup.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from types import ModuleType

import numpy as np

from .._native import accel, threads

__all__ = ["weld_exact", "weld_exact_stream", "weld_tolerance"]

_CHUNK = 1 << 21
#: Points from which a float32 stream is welded by the C extension's radix partition (``PartWelder``, on
#: :func:`inertia_tool._native.threads` threads) rather than its one hash table (``Welder``): 2**22 corners,
#: about 1.4M triangles.  At 3M corners (1M-face torus) both took the same CPU time (the table still largely
#: in the cache) and the partition 2 % more peak memory; at 15.7M and 30M corners the partition took 0.79x
#: and 0.54x the CPU time (docs/performance.md, "The weld by radix partition").
PARTITION_MIN_POINTS = 1 << 22
_MIX = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x165667B19E3779F9))


def _hash_rows(rows: np.ndarray) -> np.ndarray:
    """64-bit key of each row's exact bit pattern, (k,) uint64.  Collisions are checked by the caller.

    float32 rows: the x and y bit patterns fill the key exactly and z is mixed in, so only points that
    differ in z *and* collide in the mix share a key; float64 rows: a multiply-xor mix of the three.
    """
    if rows.dtype == np.float32 and rows.ndim == 2 and rows.shape[1] == 4 and rows.flags.c_contiguous:
        # padded layout (x, y, z, 0): the (x, y) pair is one uint64 word and z the other
        bits = rows.view(np.uint32)
        bits[bits == 0x80000000] = 0     # -0.0 -> +0.0 in place (the chunk is the caller's scratch buffer)
        words = bits.view(np.uint64)
        with np.errstate(over="ignore"):
            h: np.ndarray = words[:, 1] * _MIX[0]
        h ^= words[:, 0]
        return h
    rows = rows + rows.dtype.type(0)  # -0.0 -> +0.0 so that equal values hash equally
    with np.errstate(over="ignore"):
        if rows.dtype == np.float32:
            bits = rows.view(np.uint32)
            h32: np.ndarray = (bits[:, 0].astype(np.uint64) << np.uint64(32)) | bits[:, 1]
            h32 ^= bits[:, 2].astype(np.uint64) * _MIX[0]
            return h32
        bits = rows.astype(np.float64, copy=False).view(np.uint64)
        h64: np.ndarray = bits[:, 0] * _MIX[0]
        h64 ^= h64 >> np.uint64(29)
        h64 += bits[:, 1] * _MIX[1]
        h64 ^= h64 >> np.uint64(31)
        h64 += bits[:, 2] * _MIX[2]
        h64 ^= h64 >> np.uint64(32)
        return h64


def _index_dtype(n: int) -> type[np.int32] | type[np.int64]:
    return np.int32 if n < 2**31 - 1 else np.int64


def _renumber_by_first_appearance(inverse: np.ndarray, first: np.ndarray) -> None:
    """Renumber group ids in place so that they increase with each group's first position.

    ``inverse`` (k,) holds each point's group, ``first`` (g,) each group's first position in ``inverse``.
    """
    mark = np.zeros(len(inverse), dtype=bool)
    mark[first] = True
    firsts = np.flatnonzero(mark)          # first positions in increasing order
    del mark
    new_id = np.empty(len(first), dtype=inverse.dtype)
    new_id[inverse[firsts]] = np.arange(len(first), dtype=inverse.dtype)
    del firsts
    for s in range(0, len(inverse), _CHUNK):
        inverse[s:s + _CHUNK] = new_id[inverse[s:s + _CHUNK]]


def _weld_partitioned(lib: ModuleType, stream: Iterable[np.ndarray], n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """``weld_exact_stream`` of float32 points on the C extension's radix partition (``PartWelder``).

    The points are partitioned by hash into buckets as they stream in, each bucket is welded in a table that
    fits in a core's cache, and the vertices are numbered by first appearance: the same vertices and faces as
    the one-table ``Welder``, on :func:`inertia_tool._native.threads` threads.  The corner ids and the
    vertices are written into the extension's ``Scratch`` buffers (uninitialised, like ``numpy.empty``):
    pages an earlier weld or census in the process faulted in and left behind, when there are any, so that a
    second large file does not pay the kernel's page faults again.
    """
    index = _scratch(lib, n_points, np.int32)
    welder = lib.PartWelder(index, threads())
    s = 0
    for c in stream:
        c = np.asarray(c)
        if c.ndim == 2 and c.shape[1] == 4:
            c = c[:, :3]                       # the padded (x, y, z, 0) layout of the numpy path
        if c.dtype != np.float32 or not c.dtype.isnative:
            if c.dtype.kind != "f" or c.dtype.itemsize != 4:
                raise ValueError(f"Expected every chunk as float32 like the first one, got {c.dtype}")
            c = c.astype(np.float32)
        k = c.size // 3
        if s + k > n_points:
            raise ValueError(f"expected {n_points} points from the stream, got more")
        welder.feed(c)
        s += k
    if s != n_points:
        raise ValueError(f"expected {n_points} points from the stream, got {s}")
    vertices = _scratch(lib, 3 * welder.finish(), np.float64).reshape(-1, 3)
    welder.output(vertices)
    return vertices, index.reshape(-1, 3)


def _scratch(lib: ModuleType, n: int, dtype: type[np.int32] | type[np.float64]) -> np.ndarray:
    """An uninitialised writable (n,) array on a ``Scratch`` buffer of the C extension (its memory goes back
    to the extension's kept mappings when the array is freed)."""
    out: np.ndarray = np.frombuffer(lib.Scratch(n * np.dtype(dtype).itemsize), dtype=dtype)
    return out


def _chain(first: np.ndarray, rest: Iterator[np.ndarray]) -> Iterator[np.ndarray]:
    yield first
    yield from rest


def _weld_stream_c(lib: ModuleType, chunks: Callable[[], Iterable[np.ndarray]],
                   n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """``weld_exact_stream`` on the C extension: a float32 stream of at least ``PARTITION_MIN_POINTS`` points
    by radix partition on several threads, any other in one hash table (one pass, no keys array, no sort)."""
    if n_points >= PARTITION_MIN_POINTS:
        it = iter(chunks())
        first = next(it, None)
        if first is not None and np.asarray(first).dtype == np.float32:
            return _weld_partitioned(lib, _chain(first, it), n_points)
        chunks = _restart(first, it)
    index = np.empty(n_points, dtype=np.int32)
    welder = None
    wide = False
    s = 0
    for c in chunks():
        c = np.asarray(c)
        if c.ndim == 2 and c.shape[1] == 4:
            c = c[:, :3]                       # the padded (x, y, z, 0) layout of the numpy path
        if welder is None:
            wide = c.dtype != np.float32
            welder = lib.Welder("float64" if wide else "float32", n_points // 6)
        if c.dtype != (np.float64 if wide else np.float32) or not c.dtype.isnative:
            if not wide and c.dtype != np.float32:
                raise ValueError(f"Expected every chunk as float32 like the first one, got {c.dtype}")
            c = c.astype(np.float64 if wide else np.float32)
        k = c.size // 3
        if s + k > n_points:
            raise ValueError(f"expected {n_points} points from the stream, got more")
        welder.feed(c, index[s:s + k])
        s += k
    if s != n_points:
        raise ValueError(f"expected {n_points} points from the stream, got {s}")
    vertices = np.empty((welder.count if welder is not None else 0, 3), dtype=np.float64)
    if welder is not None:
        welder.vertices_into(vertices)
    return vertices, index.reshape(-1, 3)


def _restart(first: np.ndarray | None, rest: Iterator[np.ndarray]) -> Callable[[], Iterator[np.ndarray]]:
    """A one-shot chunk factory over a stream whose first chunk was already taken."""
    def chunks() -> Iterator[np.ndarray]:
        if first is not None:
            yield first
        yield from rest
    return chunks


def weld_exact_stream(chunks: Callable[[], Iterable[np.ndarray]], n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Weld a stream of points (triangle corners in order) by exact equality.

    Parameters
    ----------
    chunks : callable
        Returns a fresh iterator over float arrays whose last axis is (x, y, z) — ``(k, 3)``, or ``(k, j, 3)``
        with any strides (the C path welds a view into the file's records), or ``(k, 4)`` C-contiguous
        float32 scratch arrays with a zero last column (a faster layout for the numpy path, which modifies
        them) — whose concatenation is the ``n_points`` corners, three per triangle.  The C path calls it
        once; the numpy path twice (keys; coordinates with the collision check), and once more only if a
        key collision forces the exact fallback.
    n_points : int
        Total number of points (a multiple of 3).

    Returns
    -------
    vertices : (n, 3) float64
        Distinct positions, exact values of the input (-0.0 and +0.0 are one point), numbered in order of
        first appearance.
    faces : (n_points // 3, 3) int32 or int64
    """
    lib = accel()
    if lib is not None and n_points < 2**31 - 1:
        return _weld_stream_c(lib, chunks, n_points)
    keys = np.empty(n_points, dtype=np.uint64)
    s = 0
    for c in chunks():
        keys[s:s + len(c)] = _hash_rows(c)
        s += len(c)
    if s != n_points:
        raise ValueError(f"expected {n_points} points from the stream, got {s}")
    order = np.argsort(keys)
    ordered = keys[order]
    del keys
    step = np.empty(n_points, dtype=bool)
    step[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=step[1:])
    del ordered
    first = np.minimum.reduceat(order, np.flatnonzero(step))   # each group's first point
    step[0] = False
    n_unique = len(first)
    idx_t = _index_dtype(n_unique)
    group = np.cumsum(step, dtype=idx_t)
    del step
    inverse = np.empty(n_points, dtype=idx_t)
    inverse[order] = group
    del order, group
    _renumber_by_first_appearance(inverse, first)
    del first
    # fill the vertices; the first point written to a slot owns it, and every point is compared with its
    # slot's owner, so a key collision (two different points, one key) cannot go unnoticed
    vertices = np.empty((n_unique, 3), dtype=np.float64)
    written = np.zeros(n_unique, dtype=bool)
    s = 0
    for c in chunks():
        c = c[:, :3]
        inv = inverse[s:s + len(c)]
        fresh = ~written[inv]
        vertices[inv[fresh]] = c[fresh].astype(np.float64) + 0.0    # -0.0 -> +0.0, as the C extension writes it
        written[inv] = True
        if not np.array_equal(vertices[inv], c.astype(np.float64) + 0.0):
            pts = np.concatenate([x[:, :3].astype(np.float64) + 0.0 for x in chunks()])
            uniq, first, inv_all = np.unique(pts, axis=0, return_index=True, return_inverse=True)
            inv_all = inv_all.reshape(-1).astype(_index_dtype(len(uniq)))
            _renumber_by_first_appearance(inv_all, first)
            return uniq[np.argsort(first)], inv_all.reshape(-1, 3)
        s += len(c)
    return vertices, inverse.reshape(-1, 3)


def weld_exact(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge bit-identical triangle corners of an in-memory soup.

    Parameters
    ----------
    corners : (m, 3, 3) float32 or float64
        Triangle corners.

    Returns
    -------
    vertices : (n, 3) float64
    faces : (m, 3) int32 or int64
    """
    flat = np.asarray(corners).reshape(-1, 3)

    def chunks() -> Iterator[np.ndarray]:
        for s in range(0, len(flat), _CHUNK):
            yield flat[s:s + _CHUNK]
    return weld_exact_stream(chunks, len(flat))


def weld_tolerance(vertices: np.ndarray, faces: np.ndarray, tolerance: float) -> np.ndarray:
    """Merge vertices that fall in the same cell of a grid of spacing ``tolerance`` (m).

    Two vertices closer than ``tolerance`` usually share a cell (they can straddle a cell boundary, so this
    is a heuristic for rounding noise, not a distance query).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int
    tolerance : float
        Grid spacing in the units of ``vertices``; must be positive.

    Returns
    -------
    faces : (m, 3) int
        Faces re-indexed onto one representative vertex per cell (indices into the same ``vertices``).
    """
    if not tolerance > 0:
        raise ValueError(f"Expected a positive tolerance, got {tolerance}")
    lo = vertices.min(axis=0)
    cells = np.floor((vertices - lo) / tolerance + 0.5)
    if cells.max() < 2**20:
        c = cells.astype(np.int64)
        key = (c[:, 0] << 42) | (c[:, 1] << 21) | c[:, 2]
        _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    else:
        _, first, inverse = np.unique(cells, axis=0, return_index=True, return_inverse=True)
    representative = first[inverse.reshape(-1)]
    welded: np.ndarray = representative[faces].astype(faces.dtype)
    return welded
