"""The C kernels' threads: every kernel must give the same result whatever its thread count.

The edge census splits start vertices; the tetrahedron sums and the face measures add a fixed number of lanes
in lane order; the bounds split rows; the face-pair check takes node pairs by ticket (same set of pairs).
Each is compared here, on meshes above the kernels' thresholds for using threads, with its own one-thread
result (bit for bit) and with the numpy reference.  The radix-partition welder takes buckets by ticket and
numbers vertices by first appearance: the one-table Welder's result whatever the thread count.  The one-table
welder and the shell labels run on one thread; they are checked on the same mesh.
"""

import os

import numpy as np
import pytest
import trimesh

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from inertia_tool.integrals import bounding_box
from inertia_tool.mesh.checks import edge_topology, shell_labels

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")

THREADS = (2, 3, 5)

#: Set by scripts/tsan.sh, which runs this file against a ThreadSanitizer build to look for data races: there the
#: kernels run on several threads only (a one-thread run has no race to find, and under the sanitizer it costs as
#: much as the others); every result is still compared with the same reference.  The ordinary run adds one thread.
#: Under the sanitizer the costly kernels run on 2 and 5 threads (a race needs two threads; five give the most
#: interleavings): 3 threads' uneven parts are checked for their results in the ordinary run.
UNDER_TSAN = os.environ.get("INERTIA_TOOL_TSAN", "") not in ("", "0")
RUNS = (2, 5) if UNDER_TSAN else (1,) + THREADS


@pytest.fixture(scope="module")
def lib():
    return _native.accel()


@pytest.fixture(scope="module")
def damaged():
    """Faces and vertices of 5 shells (icospheres of 81,920 faces, one of them with 40 faces flipped, 30
    removed and 20 duplicated), 409,590 faces in all: above every kernel's threshold for threads."""
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=1.0)
    v0, f0 = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    rng = np.random.default_rng(7)
    vs, fs, off = [], [], 0
    for k in range(5):
        f = f0.copy()
        if k == 2:
            flip = rng.choice(len(f), 40, replace=False)
            f[flip] = f[flip][:, ::-1]
            f = np.delete(f, rng.choice(len(f), 30, replace=False), axis=0)
            f = np.concatenate([f, f[rng.choice(len(f), 20, replace=False)]])
        vs.append(v0 * (1.0 + 0.1 * k) + [3.0 * k, 0.0, 0.0])
        fs.append(f + off)
        off += len(v0)
    order = rng.permutation(sum(len(f) for f in fs))
    return np.concatenate(vs), np.concatenate(fs)[order].astype(np.int32)


@pytest.mark.one_thread
def test_welder_on_a_large_stream_matches_first_appearance(lib, damaged):
    """The recent-point cache in front of the table must not change the numbering: 1.2M corners (most found in
    the cache), some -0.0, ids in order of first appearance and the right coordinates, in chunks of any size."""
    v, f = damaged
    corners = v.astype(np.float32)[f].reshape(-1, 3)
    corners[::97] *= -0.0
    for chunk in (1 << 21, 50_000, 4_000):
        w = lib.Welder("float32", len(corners) // 6)
        ids = np.empty(len(corners), dtype=np.int32)
        for s in range(0, len(corners), chunk):
            w.feed(corners[s:s + chunk], ids[s:s + chunk])
        out = np.empty((w.count, 3))
        w.vertices_into(out)
        first = np.full(len(out), -1)
        first[ids[::-1]] = np.arange(len(ids))[::-1]
        assert np.all(np.diff(first) > 0)
        np.testing.assert_array_equal(out[ids], np.where(corners == 0, 0.0, corners))
        assert w.count == len(np.unique(np.where(corners == 0, 0.0, corners), axis=0))


def test_partition_welder_is_independent_of_threads(lib, damaged):
    """PartWelder on 1.2M corners (some -0.0) with 1, 2, 3 and 5 threads, in the reader's chunk size: the
    one-table Welder's vertices and ids, bit for bit (ThreadSanitizer runs this via scripts/tsan.sh)."""
    v, f = damaged
    corners = v.astype(np.float32)[f].reshape(-1, 3)
    corners[::97] *= -0.0
    ref_ids = np.empty(len(corners), dtype=np.int32)
    w = lib.Welder("float32", len(corners) // 6)
    w.feed(corners, ref_ids)
    ref = np.empty((w.count, 3))
    w.vertices_into(ref)
    for threads in RUNS:
        ids = np.empty(len(corners), dtype=np.int32)
        p = lib.PartWelder(ids, threads)
        for s in range(0, len(corners), 3 << 17):
            p.feed(corners[s:s + (3 << 17)])
        out = np.empty((p.finish(), 3))
        p.output(out)
        np.testing.assert_array_equal(ids, ref_ids)
        np.testing.assert_array_equal(out.view(np.uint64), ref.view(np.uint64))


def test_edge_census_is_independent_of_threads(lib, damaged):
    v, f = damaged
    ref = lib.edge_census(f, len(v), 1)
    assert ref[1] > 0 and ref[2] > 0 and ref[3] > 0      # holes, duplicated faces, flips are all seen
    for threads in THREADS:
        assert lib.edge_census(f, len(v), threads) == ref


def test_edge_census_threads_match_numpy(monkeypatch, damaged):
    v, f = damaged
    monkeypatch.setenv(_native.THREADS_ENV, "3")
    c = edge_topology(f, len(v), v)
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    ref = edge_topology(f, len(v), v)
    assert (c.edges, c.boundary_edges, c.nonmanifold_edges, c.misoriented_edges) == \
        (ref.edges, ref.boundary_edges, ref.nonmanifold_edges, ref.misoriented_edges)
    np.testing.assert_array_equal(c.sample, ref.sample)


@pytest.mark.one_thread
def test_shell_labels_match_numpy_on_a_large_mesh(lib, monkeypatch, damaged):
    v, f = damaged
    ref = np.empty(len(f), dtype=np.int64)
    assert lib.shell_labels(f, len(v), ref) == 5
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    labels, count = shell_labels(f, len(v))
    assert count == 5
    np.testing.assert_array_equal(labels, ref)


@pytest.mark.one_thread
def test_shell_labels_many_small_shells(lib):
    """100,000 separate triangles in shuffled order, numbered by the smallest vertex of each."""
    rng = np.random.default_rng(3)
    f = rng.permutation(300_000).reshape(-1, 3).astype(np.int32)
    ref = np.empty(len(f), dtype=np.int64)
    assert lib.shell_labels(f, 300_000, ref) == 100_000
    np.testing.assert_array_equal(np.argsort(np.argsort(f.min(axis=1))), ref)


def _separate_kernels(lib, f, n):
    """The census and the shells as the separate one-thread kernels give them (sections 3, 4 and 4b), with
    checks.shell_labels' choice of numbering."""
    census = lib.edge_census(f, n, 1)
    by_vertex = np.empty(len(f), np.int64)
    k_vertex = lib.shell_labels(f, n, by_vertex)
    by_edge = np.empty(len(f), np.int64)
    k_edge = lib.edge_shell_labels(f, n, by_edge)
    return census, (by_vertex, k_vertex) if k_vertex == k_edge else (by_edge, k_edge)


def test_census_shells_are_independent_of_threads(lib, damaged):
    """The one-adjacency census and shells on 409,590 shuffled faces (most united pairs across the threads'
    parts of the faces), and the same with two shells joined at one vertex (numbered by first face then):
    the separate kernels' census and labels, bit for bit, on 1, 2, 3 and 5 threads (ThreadSanitizer runs
    this via scripts/tsan.sh)."""
    v, f = damaged
    bowtie = f.copy()
    bowtie[bowtie == int(f[-1, 0])] = int(f[0, 0])       # the last face's shell meets the first's at a vertex
    separate = []
    for faces in (f, bowtie):
        census, (labels, count) = _separate_kernels(lib, faces, len(v))
        separate.append(labels)
        for threads in RUNS:
            out = np.empty(len(faces), np.int64)
            got = lib.census_shells(faces, len(v), out, threads)
            assert got == census + (count,)
            np.testing.assert_array_equal(out, labels)
    assert count == 5 and not np.array_equal(separate[1], separate[0])


def test_census_shells_many_small_shells(lib):
    """100,000 separate triangles in shuffled order over 300,000 vertices, every one of them a boundary
    triangle: numbered by the smallest vertex of each, on 1 to 5 threads."""
    rng = np.random.default_rng(3)
    f = rng.permutation(300_000).reshape(-1, 3).astype(np.int32)
    for threads in RUNS:
        out = np.empty(len(f), np.int32)
        got = lib.census_shells(f, 300_000, out, threads)
        assert got[:4] == (300_000, 300_000, 0, 0) and got[7] == 100_000
        np.testing.assert_array_equal(np.argsort(np.argsort(f.min(axis=1))), out)


def _sums(lib, v, f, labels, n_labels, threads):
    sums = np.empty((n_labels, 11))
    zero = np.empty(n_labels, dtype=np.int64)
    lib.tetra_sums(v, f, (0.1, -0.2, 0.3), 1e-30, labels, sums, zero, threads)
    return sums, zero


def test_tetra_sums_are_bitwise_independent_of_threads(lib, damaged):
    v, f = damaged
    labels = np.empty(len(f), dtype=np.int64)
    n = lib.shell_labels(f, len(v), labels)
    for lab, n_labels in ((None, 1), (labels, n)):
        ref = _sums(lib, v, f, lab, n_labels, 1)
        for threads in THREADS:
            got = _sums(lib, v, f, lab, n_labels, threads)
            np.testing.assert_array_equal(got[0], ref[0])
            np.testing.assert_array_equal(got[1], ref[1])


def test_face_measures_are_bitwise_independent_of_threads(lib, damaged):
    v, f = damaged
    ref = lib.face_measures(v, f, 1)
    for threads in THREADS:
        assert lib.face_measures(v, f, threads) == ref


def test_contact_scan_pairs_are_independent_of_threads(lib, damaged):
    """The face-pair check's tasks are taken by ticket, so the pairs come in another order: the same set,
    counts and per-face outputs (the damaged shell's duplicated faces are found on every thread count)."""
    v, f = damaged
    ref = lib.contact_scan(v, f, -1, 1)
    ref_pairs = set(zip(np.frombuffer(ref[0], np.int64), np.frombuffer(ref[1], np.int64), ref[2]))
    assert ref_pairs and ref[3] > len(f)
    for threads in (3,) if UNDER_TSAN else (2, 3):
        got = lib.contact_scan(v, f, -1, threads)
        assert set(zip(np.frombuffer(got[0], np.int64), np.frombuffer(got[1], np.int64), got[2])) == ref_pairs
        assert got[3:7] == ref[3:7] and got[7:] == ref[7:]


def test_contact_scan_with_stars_patches_and_twin_rounds_is_independent_of_threads(lib, monkeypatch):
    """The same with star certificates and patches (the faces across each edge built in rounds over ranges of
    vertices, ct_twins; the traversal reading each leaf's corner indices into its own cache): every output on
    3 threads and 3 rounds is that of one thread and one round, on two tori of 120,000 faces each crossing the
    other (check7; ThreadSanitizer runs this)."""
    t = trimesh.creation.torus(50.0, 20.0, major_sections=400, minor_sections=150)
    tv, tf = np.asarray(t.vertices), np.asarray(t.faces)
    v = np.concatenate([tv, tv + [135.0, 0.5, 0.25]])
    f = np.concatenate([tf, tf + len(tv)]).astype(np.int32)
    monkeypatch.setenv("INERTIA_TOOL_CT_TWIN_ROUNDS", "1")
    ref = lib.contact_scan(v, f, -1, 1, 8, True)
    ref_pairs = set(zip(np.frombuffer(ref[0], np.int64), np.frombuffer(ref[1], np.int64), ref[2]))
    assert ref_pairs
    for threads, rounds in ((3, "3"),):
        monkeypatch.setenv("INERTIA_TOOL_CT_TWIN_ROUNDS", rounds)
        got = lib.contact_scan(v, f, -1, threads, 8, True)
        assert set(zip(np.frombuffer(got[0], np.int64), np.frombuffer(got[1], np.int64), got[2])) == ref_pairs
        assert got[3:7] == ref[3:7] and got[7:] == ref[7:]


def test_tetra_sums_lanes_match_an_exact_sum(lib):
    """The lane sums against math.fsum of the per-face volume terms (correctly rounded): within 2 ulps."""
    import math
    m = trimesh.creation.icosphere(subdivisions=6, radius=1.0)
    v = np.asarray(m.vertices) + [1e3, -2e3, 5e2]
    f = np.asarray(m.faces, dtype=np.int64)
    o = np.array([0.1, -0.2, 0.3])
    a, b, c = v[f[:, 0]] - o, v[f[:, 1]] - o, v[f[:, 2]] - o
    v6 = np.einsum("ij,ij->i", a, np.cross(b - a, c - a))
    exact = math.fsum(v6 / 6.0)
    sums, _ = _sums(lib, v, f, None, 1, 4)
    assert abs(sums[0, 0] - exact) <= 2 * np.spacing(abs(exact))


def test_tetra_sums_bad_label_reports_the_first(lib, damaged):
    v, f = damaged
    labels = np.zeros(len(f), dtype=np.int64)
    labels[[300_000, 123_456]] = 9
    with pytest.raises(ValueError, match="position 123456"):
        _sums(lib, v, f, labels, 2, 3)


def test_bounds_kernel(lib, damaged):
    v, _ = damaged
    v = np.ascontiguousarray(v)
    for threads in (1, 3):
        lo, hi, finite = lib.bounds(v, threads)
        np.testing.assert_array_equal(lo, v.min(axis=0))
        np.testing.assert_array_equal(hi, v.max(axis=0))
        assert finite is True
    w = v.copy()
    w[200_000, 1] = np.nan
    w[5, 2] = np.inf
    lo, hi, finite = lib.bounds(w, 2)
    assert np.isnan(lo[1]) and np.isnan(hi[1]) and hi[2] == np.inf and finite is False
    np.testing.assert_array_equal(np.array(lo)[[0, 2]], w.min(axis=0)[[0, 2]])
    lo_hi = bounding_box(w)
    np.testing.assert_array_equal(lo_hi[0], w.min(axis=0))
    np.testing.assert_array_equal(lo_hi[1], w.max(axis=0))
    with pytest.raises(ValueError, match="float64"):
        lib.bounds(v.astype(np.float32))
    with pytest.raises(ValueError, match="n >= 1"):
        lib.bounds(np.zeros((0, 3)))


@pytest.mark.one_thread
@pytest.mark.parametrize("raw, expected", [("3", 3), ("1", 1), ("99", 16), ("0", None), ("abc", None), ("", None),
                                           ("-2", None)])
def test_threads_setting(monkeypatch, raw, expected):
    monkeypatch.setenv(_native.THREADS_ENV, raw)
    got = _native.threads()
    if expected is None:
        monkeypatch.delenv(_native.THREADS_ENV)
        assert got == _native.threads() and 1 <= got <= 16
    else:
        assert got == expected


def test_welder_refuses_feed_while_vertices_into_runs(lib):
    """vertices_into releases the GIL while it copies the keys: a feed() from another Python thread meanwhile
    must be refused (it may grow and move the keys being read, or raise the count the copy loop reads).
    Thread B wakes as A enters vertices_into and feeds one new point (no growth, so the unfixed kernel does
    not crash); B's call succeeding entirely within A's call is the race.  An attempt in which B fed before
    A started (A then refuses the stale `out`) proves nothing and is repeated."""
    import threading
    import time
    n = 1_000_000
    conclusive = 0
    for _ in range(5):
        w = lib.Welder("float32", n)
        w.feed(np.arange(3 * n, dtype=np.float32).reshape(-1, 3), np.empty(n, dtype=np.int32))
        out = np.empty((w.count, 3))
        go = threading.Event()
        state = {}

        def feed_one():
            go.wait()
            b0 = time.perf_counter()
            try:
                w.feed(np.array([[-1.0, -2.0, -3.0]], dtype=np.float32), np.empty(1, dtype=np.int32))
                state["b"] = "fed"
            except RuntimeError:
                state["b"] = "refused"
            state["b_time"] = (b0, time.perf_counter())

        other = threading.Thread(target=feed_one)
        other.start()
        go.set()
        t0 = time.perf_counter()
        try:
            w.vertices_into(out)
        except (RuntimeError, ValueError):      # B's feed came first: the count no longer matches `out`
            other.join()
            continue
        t1 = time.perf_counter()
        other.join()
        b0, b1 = state["b_time"]
        assert not (state["b"] == "fed" and t0 < b0 and b1 < t1), "feed() ran while vertices_into() was copying"
        np.testing.assert_array_equal(out[:3], [[0, 1, 2], [3, 4, 5], [6, 7, 8]])
        conclusive += 1
        break
    assert conclusive == 1


@pytest.mark.one_thread
def test_threads_setting_non_ascii_digits(monkeypatch):
    """str.isdigit() accepts '²' but int() does not: a malformed value must count as unset, not raise."""
    monkeypatch.setenv(_native.THREADS_ENV, "²")
    got = _native.threads()
    monkeypatch.delenv(_native.THREADS_ENV)
    assert got == _native.threads()


def test_census_shells_unite_across_threads_on_a_torus_in_file_order(lib):
    """A 240,000-face torus welded from the benchmark's file order (every quad's two triangles in opposite
    halves of the faces, so every face pair to unite spans the threads' parts; the threads unite them
    concurrently by compare-and-swap), plus a second torus far away in shuffled vertex numbers: the separate
    kernels' census and labels on 1, 2, 3 and 5 threads."""
    from test_weld_partition import _torus_soup

    from inertia_tool.mesh.weld import weld_exact

    v, f = weld_exact(_torus_soup(400, 300).reshape(-1, 3, 3))
    perm = np.random.default_rng(5).permutation(len(v))
    faces = np.concatenate([f, perm[f] + len(v)]).astype(np.int32)
    n = 2 * len(v)
    census, (labels, count) = _separate_kernels(lib, faces, n)
    assert count == 2
    for threads in RUNS:
        out = np.empty(len(faces), np.int64)
        assert lib.census_shells(faces, n, out, threads) == census + (count,)
        np.testing.assert_array_equal(out, labels)
