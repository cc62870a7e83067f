"""The tolerance weld's measures read column by column (issue 25, soup18) give what the row readings gave, bit for bit.

``precision._swept_faces`` sums Steiner's bound ``3 Σ (2 δ A + (π/2) δ² P + (4/3) π δ³)`` over the faces a weld
moved and boxes their corners.  It now gathers one (k,) column per corner and axis and forms every product and
sum in the order of ``numpy.cross`` and ``numpy.linalg.norm(·, axis=1)``; the reference below is the code it
replaced, kept verbatim.  ``merge.merge_close_vertices`` gathers its points with ``numpy.take`` and measures the
largest move one column at a time (the root of the largest square): the same faces, representatives and largest
move as the loop of ``numpy.linalg.norm`` it replaced (kept below).  Inputs: random soups and shared-vertex
meshes with coordinates over many binades, reach zero at some corners (faces left out), none at all, and more
faces than one chunk (the chunks' partial sums are added in the same order).  No timings here:
``benchmarks/bench_repair.py`` and ``docs/performance.md``.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import merge, precision


def _reference(vertices, faces, reach, chunk):
    """``_swept_faces`` before soup18 (``numpy.linalg.norm`` of (k, 3) rows of a (k, 3, 3) gather)."""
    total = 0.0
    lo = hi = None
    for start in range(0, len(faces), chunk):
        f = faces[start:start + chunk]
        r = reach[f]
        d = np.maximum(np.maximum(r[:, 0], r[:, 1]), r[:, 2])
        hit = d > 0
        if not hit.any():
            continue
        f, d = f[hit], d[hit]
        tri = vertices[f]
        ab, ac, bc = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], tri[:, 2] - tri[:, 1]
        normal = np.empty_like(ab)
        for axis, (p, q) in enumerate(((1, 2), (2, 0), (0, 1))):
            np.multiply(ab[:, p], ac[:, q], out=normal[:, axis])
            normal[:, axis] -= ab[:, q] * ac[:, p]
        area = 0.5 * np.linalg.norm(normal, axis=1)
        perimeter = np.linalg.norm(ab, axis=1) + np.linalg.norm(ac, axis=1) + np.linalg.norm(bc, axis=1)
        total += 3.0 * float(np.sum(2.0 * d * area + 0.5 * math.pi * d * d * perimeter
                                    + 4.0 / 3.0 * math.pi * d ** 3))
        corners = tri.reshape(-1, 3)
        a, b = corners.min(axis=0), corners.max(axis=0)
        lo = a if lo is None else np.minimum(lo, a)
        hi = b if hi is None else np.maximum(hi, b)
    return total, (None if lo is None or hi is None else (lo, hi))


def _case(seed: int, n_faces: int, soup: bool, scale_exp: int, zero_share: float):
    rng = np.random.default_rng([seed, 18])
    if soup:        # every face its own corners, jittered copies of a few points
        base = rng.standard_normal((max(3, n_faces // 4), 3)) * 10.0 ** scale_exp
        v = base[rng.integers(0, len(base), 3 * n_faces)]
        v = v + rng.standard_normal(v.shape) * 10.0 ** (scale_exp - 7)
        f = np.arange(3 * n_faces, dtype=np.int64).reshape(-1, 3)
    else:           # shared corners, indices in any order, far off the origin
        v = rng.standard_normal((max(3, n_faces), 3)) * 10.0 ** scale_exp + rng.uniform(-1e3, 1e3, 3)
        f = rng.integers(0, len(v), (n_faces, 3)).astype(np.int64)
    reach = rng.uniform(0, 1, len(v)) * 10.0 ** (scale_exp - rng.integers(3, 9))
    reach[rng.random(len(v)) < zero_share] = 0.0
    return v, f, reach


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 400), st.booleans(), st.integers(-6, 6),
       st.sampled_from([0.0, 0.3, 0.9, 1.0]), st.sampled_from([7, 64, 1 << 20]))
def test_swept_faces_are_the_row_readings_bit_for_bit(seed, n_faces, soup, scale_exp, zero_share, chunk):
    v, f, reach = _case(seed, n_faces, soup, scale_exp, zero_share)
    old_chunk = precision._CHUNK
    try:
        precision._CHUNK = chunk                     # several chunks even on small cases
        got = precision._swept_faces(v, f, reach)
    finally:
        precision._CHUNK = old_chunk
    want = _reference(v, f, reach, chunk)
    assert got[0].hex() == want[0].hex()
    if want[1] is None:
        assert got[1] is None
    else:
        assert got[1] is not None
        assert got[1][0].tobytes() == want[1][0].tobytes() and got[1][1].tobytes() == want[1][1].tobytes()


def test_swept_faces_of_one_triangle_is_steiners_formula():
    # the right triangle (0,0,0), (3,0,0), (0,4,0): A = 6, P = 12; δ = 0.5 at one corner
    v = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]])
    reach = np.array([0.0, 0.5, 0.0])
    total, box = precision._swept_faces(v, np.array([[0, 1, 2]]), reach)
    delta = 0.5
    assert total == 3.0 * (2 * delta * 6.0 + math.pi / 2 * delta ** 2 * 12.0 + 4 / 3 * math.pi * delta ** 3)
    assert box is not None and box[0].tolist() == [0, 0, 0] and box[1].tolist() == [3, 4, 0]
    assert precision._swept_faces(v, np.array([[0, 1, 2]]), np.zeros(3)) == (0.0, None)


def _merge_reference(vertices, faces, tolerance, among):
    """``merge_close_vertices`` before soup18 (row gathers, ``numpy.linalg.norm`` in blocks)."""
    v = np.asarray(vertices, dtype=np.float64)
    used = np.flatnonzero(np.bincount(np.asarray(among, dtype=np.int64).reshape(-1), minlength=len(v)))
    points = v[used]
    lowest = merge.lowest_in_group(points, tolerance)
    if lowest is None:
        return faces, 0, 0.0, None
    representative = np.arange(len(v), dtype=np.int64)
    representative[used] = used[lowest]
    moved = np.flatnonzero(lowest != np.arange(len(used)))
    largest = 0.0
    for start in range(0, len(moved), merge._MOVE_BLOCK):
        block = moved[start:start + merge._MOVE_BLOCK]
        largest = float(np.max((largest, np.max(np.linalg.norm(points[block] - points[lowest[block]], axis=1)))))
    return representative[faces].astype(faces.dtype), len(moved), largest, representative


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 300), st.integers(-6, 6), st.sampled_from([1e-9, 1e-7, 1e-5]),
       st.sampled_from([5, 1 << 18]), st.booleans(), st.sampled_from(["int32", "int64"]))
def test_merge_close_vertices_is_the_row_reading_bit_for_bit(seed, n_faces, scale_exp, jitter, block, some, dtype):
    rng = np.random.default_rng([seed, 181])
    v, f, _ = _case(seed, n_faces, True, scale_exp, 0.0)            # a soup: copies 1e-7 of the scale apart
    v = v + rng.standard_normal(v.shape) * jitter * 10.0 ** scale_exp
    f = f.astype(dtype)
    among = rng.choice(len(v), int(rng.integers(1, len(v) + 1)), replace=False) if some else np.arange(len(v))
    tolerance = float(rng.choice([1e-8, 1e-6, 1e-4])) * 10.0 ** scale_exp
    old_block = merge._MOVE_BLOCK
    try:
        merge._MOVE_BLOCK = block
        got = merge.merge_close_vertices(v, f, tolerance, among=among)
        want = _merge_reference(v, f, tolerance, among)
    finally:
        merge._MOVE_BLOCK = old_block
    assert got.merged_vertices == want[1]
    assert got.largest_move.hex() == want[2].hex()
    assert got.faces.dtype == want[0].dtype and got.faces.tobytes() == want[0].tobytes()
    if want[3] is None:
        assert got.representative is None
    else:
        assert got.representative.tobytes() == want[3].tobytes()
    if want[1]:     # the largest move is a distance between two of the points, within the chains' reach
        assert 0 < got.largest_move <= tolerance * (len(v) - 1) * (1 + 1e-12)


def _sweep_reference(v, faces, welded_faces, rep, tolerance):
    """``weld_sweep`` before soup18 (moves by ``einsum`` of (k, 3) steps; the faces by :func:`_reference`)."""
    moved = np.flatnonzero(rep != np.arange(len(rep)))
    if not len(moved):
        return None
    move = np.zeros(len(v))
    step = v[moved] - v[rep[moved]]
    move[moved] = np.sqrt(np.einsum("ij,ij->i", step, step))
    move *= 1.0 + 1e-12
    largest = float(move.max())
    if not largest > 0:
        return None
    group = np.zeros(len(v))
    np.maximum.at(group, rep[moved], move[moved])
    written, box_a = _reference(v, faces, move, precision._CHUNK)
    joined, box_b = _reference(v, welded_faces, group, precision._CHUNK)
    boxes = [b for b in (box_a, box_b) if b is not None]
    if not boxes:
        return None
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    return max(written, joined) * (1.0 + 1e-9), largest, len(moved), lo, hi


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 300), st.integers(-6, 6), st.sampled_from([7, 1 << 20]))
def test_weld_sweep_is_the_einsum_reading_bit_for_bit(seed, n_faces, scale_exp, chunk):
    v, f, _ = _case(seed, n_faces, True, scale_exp, 0.0)
    welded = merge.merge_close_vertices(v, f, 1e-6 * 10.0 ** scale_exp, among=np.arange(len(v)))
    rep = welded.representative if welded.representative is not None else np.arange(len(v))
    kept = welded.faces[(welded.faces[:, 0] != welded.faces[:, 1]) & (welded.faces[:, 1] != welded.faces[:, 2])
                        & (welded.faces[:, 0] != welded.faces[:, 2])]
    old_chunk = precision._CHUNK
    try:
        precision._CHUNK = chunk
        got = precision.weld_sweep(v, f, kept, rep, 1.0)
        want = _sweep_reference(v, f, kept, rep, 1.0)
    finally:
        precision._CHUNK = old_chunk
    if want is None:
        assert got is None
        return
    assert got is not None
    assert got.volume.hex() == want[0].hex() and got.largest_move.hex() == want[1].hex()
    assert got.merged == want[2] and got.lo.tobytes() == want[3].tobytes() and got.hi.tobytes() == want[4].tobytes()
    assert got.volume > 0 and got.largest_move > 0
