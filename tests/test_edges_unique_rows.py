"""``edges.unique_rows`` is ``numpy.unique(rows, axis=0, ...)`` bit for bit (issue 25, corpus19): the same unique
rows and dtype, first indices, inverse and counts, on hypothesis arrays of integer rows (repeats, one column to
four, int32 and int64, values up to 2⁶², negatives and keys too wide to pack, which take numpy's own path)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh.edges import unique_rows


@st.composite
def _rows(draw):
    columns = draw(st.integers(1, 4))
    dtype = draw(st.sampled_from([np.int64, np.int32, np.uint32, np.uint8]))
    top = {np.int64: 2 ** 62, np.int32: 2 ** 31 - 1, np.uint32: 2 ** 32 - 1, np.uint8: 255}[dtype]
    high = min(top, draw(st.sampled_from([1, 3, 1000, top])))
    low = -3 if dtype in (np.int64, np.int32) and draw(st.booleans()) else 0
    pool = draw(st.lists(st.lists(st.integers(low, high), min_size=columns, max_size=columns), min_size=1,
                         max_size=12))
    picks = draw(st.lists(st.integers(0, len(pool) - 1), min_size=0, max_size=60))
    return np.array([pool[i] for i in picks], dtype=dtype).reshape(-1, columns)


def _same(a, b):
    assert type(a) is type(b)
    for x, y in zip(a if isinstance(a, tuple) else (a,), b if isinstance(b, tuple) else (b,)):
        assert x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y)


@settings(max_examples=300, deadline=None)
@given(_rows(), st.booleans(), st.booleans(), st.booleans())
def test_unique_rows_is_numpys_unique_along_rows(rows, index, inverse, counts):
    flags = dict(return_index=index, return_inverse=inverse, return_counts=counts)
    _same(unique_rows(rows, **flags), np.unique(rows, axis=0, **flags))


def test_unique_rows_packs_the_pairs_it_is_meant_for():
    """(owner, edge key) pairs of a mesh of 10⁵ vertices: packed (the path this function exists for), equal."""
    rng = np.random.default_rng(7)
    rows = np.stack([rng.integers(0, 40, 5000), rng.integers(0, 10 ** 10, 5000)], axis=1)
    rows = rows[rng.integers(0, 5000, 20000)]
    _same(unique_rows(rows, return_index=True, return_inverse=True, return_counts=True),
          np.unique(rows, axis=0, return_index=True, return_inverse=True, return_counts=True))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5), st.sampled_from([-1, 0, 1])), min_size=1,
                max_size=40))
def test_pieces_holding_both_ways_of_a_class_as_numpy_finds_them(triples):
    """``multiplicity.coincident_surfaces``' rows ``(piece, class, sign)`` with the sign shifted by +1 for
    ``unique_rows`` (issue 25, unique19): the (piece, class) rows and their counts are those of the three
    ``numpy.unique`` calls on the unshifted signs it replaced."""
    comp, c, s = (np.array(x, dtype=np.int64) for x in zip(*triples))
    old = np.unique(np.stack([comp, c, s], axis=1), axis=0)
    _, old_counts = np.unique(old[:, :2], axis=0, return_counts=True)
    old_pieces = np.unique(old[:, :2], axis=0)[:, 0]
    new = unique_rows(np.stack([comp, c, s + 1], axis=1))
    piece_class, counts = unique_rows(new[:, :2], return_counts=True)
    assert np.array_equal(new[:, :2], old[:, :2]) and np.array_equal(new[:, 2] - 1, old[:, 2])
    assert np.array_equal(counts, old_counts) and np.array_equal(piece_class[:, 0], old_pieces)
