"""The face-pair check's radix sort of its Morton codes (``_accel.c`` section 8, ``ct_radix_sort``), which gives
the hierarchy its order: a stable sort by the top 33 bits of each word, compared bit for bit with numpy's stable
argsort on hypothesis-drawn words (issue 25: the sort is one of the check's larger stages, and a faster one must
keep its order)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


@pytest.fixture(scope="module")
def lib():
    return _native.accel()


@st.composite
def _code_words(draw):
    """Words ``code << 31 | tag`` as the check sorts them, adversarial for an LSD radix sort: the codes from one
    or a few distinct values (long runs of one digit, ties kept in order) to all 2^33 (every digit), or with one
    of the three 11-bit digits varying; as drawn, sorted, reversed or in runs; the tags (the face indices in the
    check) any 31-bit values, so that a tie broken by the tag, or a word moved out of its tie's order, shows."""
    m = draw(st.sampled_from([0, 1, 63, 64, 65, 65_535, 65_536, 65_537, 100_003, 262_144]))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    spread = draw(st.sampled_from(["one", "few", "digit", "all"]))
    if spread == "one":
        code = np.full(m, rng.integers(0, 2**33), dtype=np.uint64)
    elif spread == "few":
        code = rng.choice(rng.integers(0, 2**33, 5, dtype=np.uint64), m)
    elif spread == "digit":             # only one of the three 11-bit digits varies
        code = rng.integers(0, 2048, m, dtype=np.uint64) << np.uint64(11 * draw(st.integers(0, 2)))
    else:
        code = rng.integers(0, 2**33, m, dtype=np.uint64)
    layout = draw(st.sampled_from(["as drawn", "sorted", "reversed", "runs"]))
    if layout == "sorted":
        code = np.sort(code)
    elif layout == "reversed":
        code = np.sort(code)[::-1].copy()
    elif layout == "runs" and m:
        code = np.repeat(code[: max(1, m // 997)], 997)[:m]
        code = np.concatenate([code, np.zeros(m - len(code), dtype=np.uint64)])
    tag = rng.integers(0, 2**31, m, dtype=np.uint64)
    return (code << np.uint64(31)) | tag


@settings(max_examples=40, deadline=None)
@given(words=_code_words())
def test_check_radix_sort_is_a_stable_sort(lib, words):
    """The face-pair check's radix sort (`sort_codes`, its ct_radix_sort, the hierarchy's order) orders the
    words by their top 33 bits and keeps ties in their order: numpy's stable argsort of the codes, bit for bit."""
    want = words[np.argsort(words >> np.uint64(31), kind="stable")]
    got = words.copy()
    lib.sort_codes(got)
    np.testing.assert_array_equal(got, want)


def test_check_radix_sort_refuses_other_arrays(lib):
    """Only a writable contiguous uint64 vector is sorted: anything else is refused, not reinterpreted."""
    for bad in (np.zeros(4, np.int64), np.zeros(4, np.uint32), np.zeros((2, 2), np.uint64)):
        with pytest.raises(ValueError, match="uint64"):
            lib.sort_codes(bad)
    frozen = np.zeros(4, np.uint64)
    frozen.flags.writeable = False
    with pytest.raises((ValueError, BufferError)):
        lib.sort_codes(frozen)
