"""The small-part arithmetic of ``integrals`` on Python floats against the array forms it stands in for, bit for
bit (issue 25 item 6, batch12): ``_finish`` (a shell's centroid and central second moment from its raw sums) and
``_box_area_floor`` (the zero-area threshold of a bounding box), on adversarial floats: magnitudes from 1e-150 to
1e150 with either sign, subnormal-adjacent and cancelling values, an asymmetric second moment."""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from inertia_tool.integrals import _box_area_floor, _finish

_MAGNITUDES = st.floats(-150, 150).map(lambda e: 10.0 ** e)
_VALUES = st.one_of(st.just(0.0), st.tuples(_MAGNITUDES, st.sampled_from((1.0, -1.0))).map(lambda p: p[0] * p[1]),
                    st.floats(-10.0, 10.0))                  # of one magnitude: sums that round


def _vector(n):
    return st.lists(_VALUES, min_size=n, max_size=n).map(lambda xs: np.array(xs, dtype=np.float64))


def _reference(vol, first, second, origin):
    """The array form of ``_finish``: d = first / vol, C = second − vol (d ⊗ d), symmetrised, origin + d."""
    d = first / vol
    c = second - vol * np.outer(d, d)
    return origin + d, 0.5 * (c + c.T)


@settings(max_examples=300, deadline=None)
@given(_VALUES.filter(lambda x: x != 0.0), _vector(3), _vector(9).map(lambda x: x.reshape(3, 3)), _vector(3))
@example(1.0, np.array([1.0, 1e-300, -1.0]), np.array([[1.0, 2.0, 3.0], [2.0 + 2 ** -52, 5.0, 6.0],
                                                        [3.0, 6.0, 9.0]]), np.array([1e8, -1e8, 0.0]))
def test_finish_is_the_array_form_bit_for_bit(vol, first, second, origin):
    with np.errstate(all="ignore"):
        centroid, central = _reference(vol, first, second, origin)
        got = _finish(vol, first, second, 2.5, origin, 3)
    assert got.centroid.tobytes() == centroid.tobytes()
    assert got.second_moment.tobytes() == central.tobytes()
    assert (got.volume, got.area, got.zero_area_faces) == (vol, 2.5, 3)


def test_finish_of_no_volume_keeps_the_raw_second_moment():
    second = np.arange(9.0).reshape(3, 3)
    got = _finish(0.0, np.ones(3), second, 1.0, np.zeros(3))
    assert np.isnan(got.centroid).all() and got.second_moment.tobytes() == second.tobytes()


@settings(max_examples=300, deadline=None)
@given(_vector(3), _vector(3), _MAGNITUDES)
@example(np.array([0.1, 0.2, 0.3]), np.array([0.7, 1e-9, -3.0]), 1e-14)
def test_box_area_floor_is_numpys_sum_bit_for_bit(lo, hi, rtol):
    with np.errstate(all="ignore"):
        expected = rtol * float(np.sum((hi - lo) ** 2))
        got = _box_area_floor(lo, hi, rtol)
    assert np.array(got).tobytes() == np.array(expected).tobytes()
