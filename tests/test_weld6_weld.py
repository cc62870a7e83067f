"""The radix-partition weld after issue 25's sixth pass (``_accel.c`` section 2b): each chunk's entries are
contiguous across the threads' parts (a stage pass, then a scatter at offsets summed over the parts), and the
gather gives the entries' pages back to the kernel chunk by chunk once they pass 32 MiB, so that the entries
and the vertices never peak together and do not stay resident into the census.

Compared with the one-table ``Welder`` (another algorithm: one hash table, no buckets, no recent-point cache
per part) bit for bit, and the process's resident memory is read from ``/proc/self/status``."""

import sys

import numpy as np
import pytest

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from test_weld_partition import _part_welder, _same, _torus_soup, _welder

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


@pytest.fixture(scope="module")
def lib():
    return _native.accel()


def _resident() -> int:
    """RssAnon of this process, bytes (anonymous pages: the weld's arrays, not the file cache)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("RssAnon:"):
                return int(line.split()[1]) * 1024
    raise OSError("no RssAnon in /proc/self/status")


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_parts_packed_back_to_back_give_the_welders_ids(lib, threads):
    """The far-apart repeats of the benchmark torus (half the corners reach a bucket), fed in uneven chunks
    split over 1-3 parts each: the one-table Welder's vertices and ids."""
    pts = _torus_soup(120, 70)
    cuts = [0, 1, 7_000, 7_003, 30_000, 50_001, len(pts)]
    for bits in (0, 3, 8):
        _same(_part_welder(lib, pts, threads, bits, cuts), _welder(lib, pts))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RssAnon and MADV_DONTNEED: Linux")
def test_entries_are_not_resident_after_a_large_weld(lib):
    """2.2M distinct points (every one reaches a bucket: 35 MB of entries, above the 32 MiB from which they are
    dropped): after output the process holds the ids and the vertices it asked for, not the entries as well;
    the ids are 0, 1, 2, ... and the vertices the points, exactly (all distinct: first appearance is order)."""
    n = 2_200_000
    bits = np.empty((n, 3), np.uint32)
    bits[:, 0] = 0x3F800000 + np.arange(n, dtype=np.uint32)          # 1.0 and the floats after it
    bits[:, 1] = 0x40000000 + (np.arange(n, dtype=np.uint32) * 7919) % n
    bits[:, 2] = 0x3F000000
    pts = bits.view(np.float32)
    lib.release_buffers()
    ids = np.empty(n, np.int32)
    ids[:] = -1                                  # faulted in before the baseline: only the weld's own memory counts
    vertices = np.empty((n, 3))
    vertices[:] = 0.0
    before = _resident()
    w = lib.PartWelder(ids, 2)
    for a in range(0, n, 1 << 17):
        w.feed(pts[a:a + (1 << 17)])
    assert w.finish() == n and w.partitioned == n
    w.output(vertices)
    grown = _resident() - before
    del w
    np.testing.assert_array_equal(ids, np.arange(n, dtype=np.int32))
    np.testing.assert_array_equal(vertices, pts.astype(np.float64))
    entries = 16 * n                             # 35.2 MB of (key, corner) entries
    assert grown < entries // 2, f"{grown / 2**20:.1f} MiB still resident after the weld"
    lib.release_buffers()
