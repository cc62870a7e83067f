"""The scratch mappings the radix-partition weld (``PartWelder``) and the one-adjacency census
(``census_shells``) keep for the next call in the process (``_accel.c`` section 2b, ``pool_take`` /
``pool_give``): a kept mapping holds the previous call's entries, vertices, counts and words, so every
result here is computed on dirty memory and compared with an independent reference (a Python dict on the
bit patterns for the weld, the separate one-thread kernels for the census and shells).

The floor below which mappings are not kept is lowered to one byte.  Scratch below 1 MB comes from the heap
instead of a mapping (issue 25: a 12-face census made 16 system calls), so the small hypothesis streams run on
heap blocks the junk weld and census have just freed (dirty as well), and the larger cases on kept mappings.
"""

import os
import re
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from test_native_threads import _separate_kernels
from test_weld_partition import _NAN_A, _NAN_B, _SPECIAL, _dict_weld, _part_welder, _same, _torus_soup

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


@pytest.fixture(scope="module")
def lib():
    """The extension with every scratch mapping kept (floor 1 byte); the default floor and an empty pool
    are restored afterwards."""
    lib = _native.accel()
    previous = lib.set_pool_floor(1)
    yield lib
    lib.set_pool_floor(previous)
    lib.release_buffers()


def _dirty(lib, n: int, seed: int) -> None:
    """Fill the pool with mappings written by a weld and a census of unrelated data of about ``n`` points."""
    rng = np.random.default_rng(seed)
    junk = rng.integers(0, 2**31, size=(max(n, 3), 3)).astype(np.uint32).view(np.float32)
    _part_welder(lib, junk, threads=3, bits=4)
    faces = rng.integers(0, max(n // 2, 3), size=(max(n // 3, 1), 3)).astype(np.int32)
    lib.census_shells(faces, max(n // 2, 3), np.empty(len(faces), np.int32), 2, 1)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(0, 2500), alphabet=st.integers(1, 30), seed=st.integers(0, 2**32 - 1),
       threads=st.integers(1, 5), bits=st.integers(0, 8), feeds=st.integers(1, 5))
def test_partition_on_kept_mappings_matches_dict(lib, n, alphabet, seed, threads, bits, feeds):
    """Streams with -0.0, subnormals, infinities, two NaN payloads and many repeats, welded on 1-5 threads
    right after a weld and a census of junk of a similar size: the dict's vertices and ids, bit for bit."""
    _dirty(lib, n + 50, seed)
    rng = np.random.default_rng(seed)
    coords = np.concatenate([_SPECIAL, [_NAN_A, _NAN_B], rng.normal(size=6).astype(np.float32)])
    pts = rng.choice(coords, size=(alphabet, 3)).astype(np.float32)[rng.integers(0, alphabet, n)]
    cuts = np.unique(np.r_[0, rng.integers(0, n + 1, size=feeds - 1), n])
    _same(_part_welder(lib, pts, threads, bits, list(cuts)), _dict_weld(pts))


@settings(max_examples=40, deadline=None)
@given(n_vertices=st.integers(3, 400), n_faces=st.integers(1, 600), seed=st.integers(0, 2**32 - 1),
       threads=st.integers(1, 5))
def test_census_shells_on_kept_mappings_match_separate_kernels(lib, n_vertices, n_faces, seed, threads):
    """Random faces (duplicates, flips, shells joined at a vertex) on 1-5 threads after a census of junk: the
    separate one-thread kernels' census and labels (their memory is never kept)."""
    _dirty(lib, 3 * n_faces + 30, seed)
    rng = np.random.default_rng(seed)
    f = rng.integers(0, n_vertices, size=(n_faces, 3)).astype(np.int32)
    census, (labels, count) = _separate_kernels(lib, f, n_vertices)
    out = np.empty(n_faces, np.int64)
    assert lib.census_shells(f, n_vertices, out, threads, 1) == census + (count,)
    np.testing.assert_array_equal(out, labels)


def test_large_weld_keeps_and_releases_its_mappings(lib):
    """A 240,000-face torus welded twice in a row (the second on the first's mappings) gives the same result
    as the dict; release_buffers empties the pool."""
    pts = _torus_soup(400, 300)
    lib.release_buffers()
    first = _part_welder(lib, pts, 2)
    kept = lib.kept_buffers()
    assert kept >= 16 * 120_000              # at least the entries of the partitioned points
    second = _part_welder(lib, pts[::-1].copy(), 2)
    _same(first, _dict_weld(pts))
    _same(second, _dict_weld(pts[::-1]))
    lib.release_buffers()
    assert lib.kept_buffers() == 0


def test_pool_floor_refuses_nonsense(lib):
    with pytest.raises(ValueError, match="positive number of bytes"):
        lib.set_pool_floor(0)


def test_scratch_buffer_is_a_writable_array_whose_memory_goes_back(lib):
    """Scratch(n): a writable n-byte buffer (numpy.frombuffer gives a writable array over it); freeing the
    array gives its mapping back to the pool, and the next Scratch of that size reuses it, dirty."""
    lib.release_buffers()
    n = (1 << 18) + 1000                     # 1 MB and more: a mapping (below, a heap block, never kept)
    a = np.frombuffer(lib.Scratch(4 * n), dtype=np.int32)
    assert a.flags.writeable and a.shape == (n,)
    a[:] = np.arange(n)
    assert lib.kept_buffers() == 0
    del a
    kept = lib.kept_buffers()
    assert kept >= 4 * n
    b = np.frombuffer(lib.Scratch(4 * n), dtype=np.int32)
    assert lib.kept_buffers() == 0 and b.flags.writeable             # the one kept mapping, taken again
    small = np.frombuffer(lib.Scratch(4000), dtype=np.int32)
    small[:] = np.arange(1000)
    del small
    assert lib.kept_buffers() == 0                                   # a heap block, freed
    assert np.frombuffer(lib.Scratch(0), dtype=np.int32).shape == (0,)
    with pytest.raises(ValueError, match="number of bytes >= 0"):
        lib.Scratch(-1)


def _resident_bytes(address: int, length: int) -> int:
    """Resident bytes of the pages in [address, address + length) (mincore; page-aligned address)."""
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    page = os.sysconf("SC_PAGE_SIZE")
    pages = (length + page - 1) // page
    vec = (ctypes.c_ubyte * pages)()
    if libc.mincore(ctypes.c_void_p(address), ctypes.c_size_t(length), vec) != 0:
        raise OSError(ctypes.get_errno(), "mincore")
    return sum(v & 1 for v in vec) * page


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="mincore and MADV_DONTNEED: Linux")
def test_pool_takes_the_mapping_whose_written_pages_cover_the_request(lib):
    """Of two kept mappings large enough, the one written over the request is taken, not the smaller one
    written only at its start (a census that took the weld's 240 MB vertex list, 40 MB of it written, for its
    240 MB of words faulted in 200 MB of fresh pages: 1,018 MB peak against 703 at 10M faces); and pages a
    small user does not need are given back to the kernel when it takes a large mapping."""
    mb = 1 << 20
    lib.release_buffers()
    big = np.frombuffer(lib.Scratch(64 * mb), dtype=np.uint8)
    big[:] = 1                                             # 64 MB mapped, all of it written
    big_address = big.ctypes.data
    mid = np.frombuffer(lib.Scratch(48 * mb), dtype=np.uint8)
    mid[:] = 2
    mid_address = mid.ctypes.data
    del mid
    small = np.frombuffer(lib.Scratch(4 * mb), dtype=np.uint8)   # takes the 48 MB mapping (the only one kept)
    assert small.ctypes.data == mid_address
    resident = _resident_bytes(mid_address, 48 * mb)
    assert 4 * mb <= resident <= 8 * mb                          # the 44 MB it does not need went back
    small[:] = 3
    del small, big                                          # kept: 48 MB mapped / 4 written, 64 / 64
    taken = np.frombuffer(lib.Scratch(40 * mb), dtype=np.uint8)
    assert taken.ctypes.data == big_address                 # not the smaller, mostly unwritten one
    del taken
    lib.release_buffers()


def test_weld_outputs_live_on_scratch_and_match_numpy(lib, monkeypatch):
    """weld_exact_stream on the partition writes its faces and vertices into Scratch buffers: the numpy
    reference's arrays, writable, and still right after the pool has been dirtied by other welds."""
    from inertia_tool.mesh import weld as weld_mod

    monkeypatch.setattr(weld_mod, "PARTITION_MIN_POINTS", 1)
    pts = _torus_soup(40, 30)
    pts[::5] *= -0.0
    for seed in range(3):
        _dirty(lib, len(pts), seed)
        vertices, faces = weld_mod.weld_exact(pts.reshape(-1, 3, 3))
        assert isinstance(faces.base.base, lib.Scratch) and isinstance(vertices.base.base, lib.Scratch)
        assert faces.flags.writeable and vertices.flags.writeable
        ref_v, ref_ids = _dict_weld(pts)
        np.testing.assert_array_equal(vertices.view(np.uint64), ref_v.view(np.uint64))
        np.testing.assert_array_equal(faces.reshape(-1), ref_ids)


def test_kept_mappings_are_unmapped_before_the_check_maps_fresh_ones(lib, capfd, monkeypatch):
    """The face-pair check takes its large blocks from its own earlier phases, and maps fresh ones only after
    unmapping the mappings the weld kept (arena_alloc's pool_drain), so kept pages never sit beside fresh ones and
    keeping them never raises the peak of an analysis (the check sets it).  At the end its blocks go to the pool
    for the next call: what is kept after the scan is at most what the scan itself mapped (check6 changed the end
    from "nothing kept" to this; arrays below 1 MB come from the heap, so the torus is large enough for the
    mapped path)."""
    monkeypatch.setenv("INERTIA_TOOL_CT_PROFILE", "1")
    pts = _torus_soup(400, 300)
    vertices, ids = _part_welder(lib, pts, 2)
    before = lib.kept_buffers()
    assert before > 0
    capfd.readouterr()
    lib.contact_scan(vertices, ids.reshape(-1, 3), -1)
    err = capfd.readouterr().err
    found = re.search(r"MB mapped ([0-9.]+) reused ([0-9.]+)", err)
    assert found, err
    mapped = float(found.group(1)) * 1e6
    after = lib.kept_buffers()
    assert mapped > 0                                            # the mapped path ran, so the pool was drained
    assert after <= mapped + 0.1e6                               # the scan's own blocks only (printed to 0.1 MB)
    assert after < before + mapped                               # the weld's kept mappings are gone
    lib.release_buffers()
    assert lib.kept_buffers() == 0


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_forked_child_welds_on_inherited_mappings(lib):
    """A child forked while the pool holds mappings (a batch worker started by fork) welds on them and gets
    the dict's result; the lock is free in the child (pthread_atfork)."""
    pts = _torus_soup(150, 80)                   # 72,000 points: entries above 1 MB, a kept mapping
    _part_welder(lib, pts, 2)
    assert lib.kept_buffers() > 0
    pid = os.fork()
    if pid == 0:                                 # the child: exit status 0 when the weld is right
        ok = False
        try:
            got = _part_welder(lib, pts[::-1].copy(), 2)
            ok = bool(np.array_equal(got[1], _dict_weld(pts[::-1])[1]))
        except BaseException:
            pass
        os._exit(0 if ok else 1)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0


def test_binary_stl_from_bytes_is_fed_in_chunks_and_matches_the_file(tmp_path, monkeypatch):
    """load_mesh(path, data=the file's bytes) (the batch's read-once path) feeds the partition weld the same
    chunks as reading the file does (so its output gathers on several threads), with the same result."""
    from inertia_tool.mesh import read as read_mod
    from inertia_tool.mesh import read_stl
    from inertia_tool.mesh import weld as weld_mod

    pts = _torus_soup(40, 30)
    rec = np.zeros(len(pts) // 3, dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = pts.reshape(-1, 3, 3)
    path = tmp_path / "torus.stl"
    path.write_bytes(b"x" * 80 + np.uint32(len(rec)).tobytes() + rec.tobytes())
    monkeypatch.setattr(weld_mod, "PARTITION_MIN_POINTS", 1)
    monkeypatch.setattr(read_stl, "_CHUNK_FACES", 500)
    sizes = []
    real = _native.accel().PartWelder

    class Spy:
        def __init__(self, index, *args):
            self.w = real(index, *args)

        def feed(self, c):
            sizes.append(len(c))
            return self.w.feed(c)

        def __getattr__(self, name):
            return getattr(self.w, name)
    monkeypatch.setattr(_native.accel(), "PartWelder", Spy)
    from_file = read_mod.load_mesh(str(path))
    file_sizes, sizes[:] = list(sizes), []
    from_bytes = read_mod.load_mesh(str(path), data=path.read_bytes())
    assert sizes == file_sizes == [500] * 4 + [400]
    np.testing.assert_array_equal(from_file.vertices, from_bytes.vertices)
    np.testing.assert_array_equal(from_file.faces, from_bytes.faces)


def test_small_weld_and_census_use_no_mappings(lib):
    """Issue 25: below 1 MB the scratch is a heap block (a 12-face part's census made 4 mmap, 4 munmap and
    8 madvise calls): after a small weld and census nothing is kept, whatever the floor, and the results are
    the references'."""
    lib.release_buffers()
    pts = _torus_soup(6, 4)
    got = _part_welder(lib, pts, 2)
    _same(got, _dict_weld(pts))
    f = got[1].reshape(-1, 3).astype(np.int32)
    census, (labels, count) = _separate_kernels(lib, f, len(got[0]))
    out = np.empty(len(f), np.int64)
    assert lib.census_shells(f, len(got[0]), out, 2, 1) == census + (count,)
    np.testing.assert_array_equal(out, labels)
    assert lib.kept_buffers() == 0
