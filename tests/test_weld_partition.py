"""The radix-partition weld (``_accel.PartWelder``, mesh/weld.py's path for large float32 streams) against
the one-table ``Welder``, a Python dict and the numpy reference: the same vertices (bit for bit) and the
same face indices, whatever the buckets, threads and feed sizes.

The inputs are built to hit what the partition changes: points recurring far apart in the stream (another
chunk, another thread's part, past the recent-point cache), -0.0 next to +0.0, NaN payloads, one point
repeated everywhere (one bucket holds it all), every point distinct (tables grow), buckets of one point.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from inertia_tool.mesh import weld as weld_mod

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


@pytest.fixture(scope="module")
def lib():
    return _native.accel()


def _dict_weld(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ids by first appearance from a dict on the exact bit patterns (-0.0 folded onto +0.0): an independent
    reference, NaN payloads included (a float dict key would not match NaN with itself)."""
    bits = points.astype(np.float32).view(np.uint32).copy()
    bits[bits == 0x80000000] = 0
    seen: dict = {}
    ids = np.array([seen.setdefault(tuple(int(x) for x in p), len(seen)) for p in bits], np.int32)
    keys = np.array(list(seen), dtype=np.uint32).reshape(-1, 3)
    return keys.view(np.float32).astype(np.float64), ids


def _welder(lib, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    w = lib.Welder("float32", 1)
    ids = np.empty(len(points), np.int32)
    w.feed(points, ids)
    out = np.empty((w.count, 3))
    w.vertices_into(out)
    return out, ids


def _part_welder(lib, points, threads=2, bits=-1, cuts=None, records=False):
    ids = np.empty(len(points), np.int32)
    w = lib.PartWelder(ids, threads, bits)
    cuts = [0, len(points)] if cuts is None else cuts
    for a, b in zip(cuts[:-1], cuts[1:]):
        if records and (b - a) % 3 == 0:     # (k, 3, 3) views into 50-byte STL-like records
            rec = np.zeros((b - a) // 3, dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
            rec["v"] = points[a:b].reshape(-1, 3, 3)
            w.feed(rec["v"])
        else:
            w.feed(points[a:b])
    assert w.points == len(points)
    out = np.empty((w.finish(), 3))
    assert w.count <= w.partitioned <= len(points)    # every vertex's first corner reaches a bucket
    w.output(out)
    return out, ids


def _same(a, b):
    """Bit-for-bit equality of (vertices, ids): NaN payloads and the sign of zero included."""
    np.testing.assert_array_equal(a[0].view(np.uint64), b[0].view(np.uint64))
    np.testing.assert_array_equal(a[1], b[1])


_SPECIAL = np.array([0.0, -0.0, 1.0, -1.0, 2.0 ** -149, 3e38, np.inf, -np.inf], dtype=np.float32)
_NAN_A = np.frombuffer(np.uint32(0x7FC00000).tobytes(), np.float32)[0]
_NAN_B = np.frombuffer(np.uint32(0x7FC00001).tobytes(), np.float32)[0]


@settings(max_examples=120, deadline=None)
@given(n=st.integers(0, 3000), alphabet=st.integers(1, 40), seed=st.integers(0, 2**32 - 1),
       threads=st.integers(1, 4), bits=st.integers(0, 8), feeds=st.integers(1, 6), records=st.booleans(),
       far=st.booleans())
def test_partition_matches_welder_and_dict(lib, n, alphabet, seed, threads, bits, feeds, records, far):
    """Random streams over a small alphabet of points (many repeats; the sign of zero, subnormals, infinities
    and two NaN payloads among the coordinates), cut into feeds of any size, on 1-4 threads and 1-256
    buckets; ``far`` puts the second half of the stream after 5,000 distinct filler points, so repeats
    recur past the recent-point cache and in another feed's and thread's part."""
    rng = np.random.default_rng(seed)
    coords = np.concatenate([_SPECIAL, [_NAN_A, _NAN_B], rng.normal(size=8).astype(np.float32)])
    alphabet_pts = rng.choice(coords, size=(alphabet, 3)).astype(np.float32)
    pts = alphabet_pts[rng.integers(0, alphabet, n)]
    if far:
        filler = np.arange(15_000, dtype=np.float32).reshape(-1, 3) + 1e6
        pts = np.concatenate([pts, filler, pts[::-1]])
    cuts = np.unique(np.r_[0, rng.integers(0, len(pts) + 1, size=feeds - 1), len(pts)])
    got = _part_welder(lib, pts, threads, bits, list(cuts), records)
    _same(got, _welder(lib, pts))
    _same(got, _dict_weld(pts))


@pytest.mark.parametrize("case", ["one point", "all distinct", "alternating zeros"])
@pytest.mark.parametrize("bits", [0, 5, 12])
def test_partition_extremes(lib, case, bits):
    """One point repeated 200k times (one bucket holds every point); 200k distinct points (every table grows
    from its initial size, buckets of a few points at 4,096 buckets); +0.0 and -0.0 alternating."""
    k = 200_000
    if case == "one point":
        pts = np.full((k, 3), 7.5, np.float32)
    elif case == "all distinct":
        pts = np.random.default_rng(1).permutation(np.arange(3 * k, dtype=np.float32)).reshape(-1, 3)
    else:
        pts = np.zeros((k, 3), np.float32)
        pts[::2, 1] = -0.0
    got = _part_welder(lib, pts, 2, bits, [0, 1, 70_001, 150_000, k])
    _same(got, _welder(lib, pts))
    if case == "one point":
        assert len(got[0]) == 1 and not got[1].any()
    if case == "alternating zeros":
        assert len(got[0]) == 1 and not np.signbit(got[0]).any()


def test_partition_bucket_past_its_preset_table(lib):
    """One bucket (bucket_bits 0) of 1.2M points, 1.09M of them distinct: past 2**20 points a bucket's table
    starts at half its points and must grow while welding (the path every smaller bucket skips); one early
    point recurring 109,091 times keeps its id across the growth."""
    k = 1_200_000
    pts = np.arange(3 * k, dtype=np.float32).reshape(-1, 3)
    pts[::11] = pts[5]                          # 109,091 repeats of one early point, far apart
    got = _part_welder(lib, pts, 2, 0, [0, 400_000, k])
    _same(got, _welder(lib, pts))
    assert len(got[0]) == k - len(pts[::11]) + (0 if 5 % 11 else 1)


def _torus_soup(n_major: int, n_minor: int) -> np.ndarray:
    """Corners of a closed torus written as benchmarks/bench_stages.py writes them: every quad's first
    triangle in the first half of the stream and its second in the second half (repeats far apart)."""
    u = 2 * np.pi * np.arange(n_major) / n_major
    w = 2 * np.pi * np.arange(n_minor) / n_minor
    uu, ww = np.meshgrid(u, w, indexing="ij")
    ring = 50.0 + 25.0 * np.cos(ww)
    pts = np.stack([ring * np.cos(uu), ring * np.sin(uu), 25.0 * np.sin(ww)], axis=-1).astype(np.float32)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    i1, j1 = (i + 1) % n_major, (j + 1) % n_minor
    a, b, c, d = pts[i, j], pts[i1, j], pts[i1, j1], pts[i, j1]
    tri = np.concatenate([np.stack([a, b, c], axis=-2).reshape(-1, 3, 3),
                          np.stack([a, c, d], axis=-2).reshape(-1, 3, 3)])
    return tri.reshape(-1, 3)


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_partition_on_a_torus_in_benchmark_order(lib, threads):
    """A 240,000-face closed torus (120,000 vertices, each in six faces) in the benchmark's file order, fed
    in the reader's chunk size: the same as the Welder, each vertex six times, first appearances in order."""
    pts = _torus_soup(400, 300)
    cuts = list(range(0, len(pts), 3 << 17)) + [len(pts)]
    got = _part_welder(lib, pts, threads, -1, cuts, records=True)
    _same(got, _welder(lib, pts))
    vertices, ids = got
    assert len(vertices) == 400 * 300 and np.all(np.bincount(ids) == 6)
    first = np.full(len(vertices), -1)
    first[ids[::-1]] = np.arange(len(ids))[::-1]
    assert np.all(np.diff(first) > 0)
    np.testing.assert_array_equal(vertices[ids], pts.astype(np.float64))


def test_weld_exact_stream_takes_the_partition_and_matches_numpy(monkeypatch):
    """weld_exact_stream above PARTITION_MIN_POINTS (lowered here) gives what the numpy reference gives, on the
    padded (k, 4) chunks of the numpy reader's layout and on record views; float64 streams keep the Welder."""
    pts = _torus_soup(60, 40)
    pts[::7] *= -0.0
    chunks4 = [np.concatenate([pts[s:s + 999], np.zeros((len(pts[s:s + 999]), 1), np.float32)], axis=1)
               for s in range(0, len(pts), 999)]
    monkeypatch.setattr(weld_mod, "PARTITION_MIN_POINTS", 1)
    calls = []
    real = _native.accel().PartWelder

    def spy(index, *args):  # records that the partition ran
        calls.append(len(index))
        return real(index, *args)
    monkeypatch.setattr(_native.accel(), "PartWelder", spy)
    got = weld_mod.weld_exact_stream(lambda: iter(chunks4), len(pts))
    assert calls == [len(pts)]
    wide = weld_mod.weld_exact(pts.astype(np.float64).reshape(-1, 3, 3))
    assert calls == [len(pts)]                                    # float64: the one-table Welder
    monkeypatch.undo()
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    ref = weld_mod.weld_exact_stream(lambda: iter([c.copy() for c in chunks4]), len(pts))
    np.testing.assert_array_equal(got[0], ref[0])
    np.testing.assert_array_equal(got[1], ref[1])
    np.testing.assert_array_equal(wide[0], ref[0])
    np.testing.assert_array_equal(wide[1], ref[1])


def test_weld_exact_stream_partition_counts_points(monkeypatch):
    """A stream shorter or longer than announced is refused on the partition path, as on the others."""
    monkeypatch.setattr(weld_mod, "PARTITION_MIN_POINTS", 1)
    pts = np.arange(30, dtype=np.float32).reshape(-1, 3)
    with pytest.raises(ValueError, match="expected 11 points"):
        weld_mod.weld_exact_stream(lambda: iter([pts]), 11)
    with pytest.raises(ValueError, match="expected 9 points"):
        weld_mod.weld_exact_stream(lambda: iter([pts]), 9)
    with pytest.raises(ValueError, match="float32"):
        weld_mod.weld_exact_stream(lambda: iter([pts, pts.astype(np.float64)]), 20)


def test_partwelder_refuses_misuse(lib):
    """Wrong arrays and calls out of order raise; they never crash or return a partial weld."""
    with pytest.raises(ValueError):
        lib.PartWelder(np.empty(6, np.int64))
    with pytest.raises(ValueError):
        lib.PartWelder(np.empty((2, 3), np.int32))
    with pytest.raises(ValueError):
        lib.PartWelder(np.empty(6, np.int32), 2, 13)
    ids = np.empty(6, np.int32)
    w = lib.PartWelder(ids, 2)
    with pytest.raises(RuntimeError):
        w.__init__(ids)
    with pytest.raises(ValueError):
        w.feed(np.zeros((3, 3)))                                  # float64
    with pytest.raises(ValueError):
        w.feed(np.zeros((7, 3), np.float32))                      # more than announced
    with pytest.raises(RuntimeError):
        w.output(np.empty((1, 3)))                                # before finish
    w.feed(np.zeros((3, 3), np.float32))
    with pytest.raises(ValueError, match="Expected 6 points, got 3"):
        w.finish()
    w.feed(np.ones((3, 3), np.float32))
    assert w.finish() == 2
    with pytest.raises(RuntimeError):
        w.feed(np.zeros((1, 3), np.float32))                      # after finish
    with pytest.raises(ValueError):
        w.output(np.empty((3, 3)))                                # wrong count
    w.output(np.empty((2, 3)))
    assert list(ids) == [0, 0, 0, 1, 1, 1]
    with pytest.raises(RuntimeError):
        w.output(np.empty((2, 3)))                                # twice
    with pytest.raises(RuntimeError):
        lib.PartWelder.__new__(lib.PartWelder).feed(np.zeros((3, 3), np.float32))
    empty = lib.PartWelder(np.empty(0, np.int32))
    assert empty.finish() == 0
    empty.output(np.empty((0, 3)))


def test_partition_reads_any_strides(lib):
    """Reversed arrays, reversed record views and reversed coordinate order (negative strides) are welded as
    their contiguous copies are."""
    pts = np.random.default_rng(3).integers(0, 9, size=(30_000, 3)).astype(np.float32)
    rec = np.zeros(10_000, dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = pts.reshape(-1, 3, 3)
    for view in (pts[::-1], rec["v"][::-1], rec["v"][:, ::-1], pts[:, ::-1]):
        flat = np.ascontiguousarray(view).reshape(-1, 3)
        ids = np.empty(len(flat), np.int32)
        w = lib.PartWelder(ids, 2, 3)
        w.feed(view)
        got = (np.empty((w.finish(), 3)), ids)
        w.output(got[0])
        _same(got, _welder(lib, flat))
        _same(got, _dict_weld(flat))
