"""The radix-partition weld's bucket tables hold entry numbers compared in place with the bucket's entries
(``_accel.c`` section 2b, issue 25 fifth pass: no per-thread copy of the vertices).  What that changes: the
table's growth re-inserts the entry numbers it holds (not a vertex list), and a repeated point takes its first
corner from the first entry of its key.  Checked against the one-table ``Welder`` and a Python dict on the bit
patterns, with the keys that equality must not confuse (-0.0 and +0.0 one point, NaN payloads distinct)."""

import numpy as np
import pytest

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from test_weld_partition import _NAN_A, _NAN_B, _dict_weld, _part_welder, _same, _welder

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


@pytest.fixture(scope="module")
def lib():
    return _native.accel()


def test_growing_table_keeps_first_corners_of_nan_and_signed_zero_keys(lib):
    """One bucket of 1.1M points (past 2**20: its table starts at half its points and doubles twice while
    welding); a handful of special keys (NaN payloads, -0.0 / +0.0) recur every 997 points, before, during and
    after each growth, each keeping the id of its first corner."""
    k = 1_100_000
    pts = np.arange(3 * k, dtype=np.float32).reshape(-1, 3)
    special = np.array([[_NAN_A, 1, 2], [_NAN_B, 1, 2], [0.0, -0.0, 5], [-0.0, 0.0, 5], [1, 2, _NAN_A]],
                       dtype=np.float32)
    at = np.arange(3, k, 997)
    pts[at] = special[np.arange(len(at)) % len(special)]
    got = _part_welder(lib, pts, 2, 0, [0, 300_001, 700_000, k])
    _same(got, _welder(lib, pts))
    vertices, ids = got
    # the four distinct special keys ((0, -0, 5) and (-0, 0, 5) are one point) keep their first ids
    first = {i: int(ids[at[i]]) for i in range(len(special))}
    assert first[2] == first[3] and len({first[0], first[1], first[2], first[4]}) == 4
    for i in range(len(special)):
        assert np.all(ids[at[i::len(special)]] == first[i])
    assert len(vertices) == k - len(at) + 4
    assert not np.signbit(vertices[first[2]]).any()


@pytest.mark.parametrize("threads", [1, 2, 5])
@pytest.mark.parametrize("bits", [0, 3, 9])
def test_repeats_across_buckets_chunks_and_threads_match_the_dict(lib, threads, bits):
    """60,000 points drawn from 700 keys (every key in many chunks and threads' parts, past the recent-point
    cache by construction: drawn at random), a tenth of them NaN payloads or signed zeros."""
    rng = np.random.default_rng(25)
    keys = rng.integers(-4, 5, size=(700, 3)).astype(np.float32)
    keys[::10, 0] = np.where(np.arange(70) % 2, _NAN_A, _NAN_B)
    keys[5::10] = -keys[5::10] * 0.0                          # -0.0 and +0.0 by the sign of the key
    pts = keys[rng.integers(0, len(keys), size=60_000)]
    got = _part_welder(lib, pts, threads, bits, [0, 7, 20_000, 20_001, 59_999, 60_000])
    _same(got, _dict_weld(pts))
