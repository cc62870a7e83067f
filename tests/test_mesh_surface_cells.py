"""``estimate._surface_cells`` in C (``_accel.surface_cells``, section 10) and in numpy mark the same cells.

Issue 25 item 3 (no slow path), session 16 (issues 23/25): every triangle is clipped to the grid's slabs and rows
and the cells its row pieces span are marked (before: sampled on a barycentric grid of ``ceil(longest edge /
spacing)`` steps, so a needle cost the square of its length in samples).  The kernel evaluates the numpy twin's
expressions in the same order, so the grids are equal bit for bit; checked on hypothesis-generated triangles
(needles, slivers, parts far from the origin, cells outside the grid clamped).  That the cells are exactly the
ones the surface meets: ``test_surface_cells_exact``.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool.mesh.grid_cells import _surface_cells


def _both(v, f, lo, h, dims):
    with pytest.MonkeyPatch.context() as patch:
        patch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
        fast = _surface_cells(v, f, lo, h, dims)
        patch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
        slow = _surface_cells(v, f, lo, h, dims)
    return fast, slow


@st.composite
def triangle_soups(draw):
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    n = draw(st.integers(1, 60))
    scale = 10.0 ** draw(st.integers(-3, 3))
    offset = draw(st.sampled_from([0.0, 1.0, 1e4])) * scale
    a = rng.normal(size=(n, 3)) * scale + offset
    b = a + rng.normal(size=(n, 3)) * scale
    kind = draw(st.sampled_from(["free", "needle", "sliver"]))
    if kind == "free":
        c = a + rng.normal(size=(n, 3)) * scale
    elif kind == "needle":                # a third corner a hair from the line a-b: no area, long
        t = rng.uniform(0, 1, size=(n, 1))
        c = a + t * (b - a) + rng.normal(size=(n, 3)) * scale * 1e-9
    else:                                 # a corner a hair from a: a sliver
        c = a + rng.normal(size=(n, 3)) * scale * 1e-7
    v = np.concatenate([a, b, c])
    f = np.stack([np.arange(n), n + np.arange(n), 2 * n + np.arange(n)], axis=1)
    cells = draw(st.integers(4, 40))
    extent = float((v.max(axis=0) - v.min(axis=0)).max())
    h = max(extent, 1e-12) / cells
    # a grid that may not hold the whole surface (samples outside are clamped to its faces)
    lo = v.min(axis=0) + draw(st.sampled_from([-0.5, 0.0, 0.3])) * extent
    dims = tuple(int(x) for x in np.maximum(1, np.ceil((v.max(axis=0) - lo) / h) + draw(st.integers(-2, 2))))
    return v, f, lo, h, dims


@pytest.mark.skipif(not HAVE_ACCEL, reason="compares the C kernel with numpy")
@settings(max_examples=60, deadline=None)
@given(triangle_soups())
def test_same_cells_as_numpy(case):
    v, f, lo, h, dims = case
    fast, slow = _both(v, f, lo, h, dims)
    np.testing.assert_array_equal(fast, slow)


@pytest.mark.skipif(not HAVE_ACCEL, reason="compares the C kernel with numpy")
def test_needle_marks_its_line():
    """A needle along the x axis through a 10-cell grid, a hair above the plane y = 0.5, marks the cells along
    it and nothing else, on both paths (the sampling of before also marked each cell's upper neighbours)."""
    v = np.array([[0.05, 0.5, 0.5], [9.95, 0.5, 0.5], [5.0, 0.5 + 1e-12, 0.5]])
    f = np.array([[0, 1, 2]])
    lo, h, dims = np.zeros(3), 1.0, (10, 3, 3)
    fast, slow = _both(v, f, lo, h, dims)
    np.testing.assert_array_equal(fast, slow)
    grid = fast.reshape(dims)
    assert grid[:, 0, 0].all() and grid.sum() == 10


@pytest.mark.skipif(not HAVE_ACCEL, reason="compares the C kernel with numpy")
def test_faces_in_cell_planes_mark_both_sides():
    """A square in the plane x = 2 (a plane of cell faces) meets the closed cells on both sides of it; one
    corner on a cell corner meets the 8 cells around it."""
    v = np.array([[2.0, 0.5, 0.5], [2.0, 2.5, 0.5], [2.0, 2.5, 2.5], [3.0, 3.0, 3.0]])
    f = np.array([[0, 1, 2]])
    lo, h, dims = np.zeros(3), 1.0, (5, 4, 4)
    fast, slow = _both(v, f, lo, h, dims)
    np.testing.assert_array_equal(fast, slow)
    grid = fast.reshape(dims)
    # in (y, z) the triangle is z <= y over [0.5, 2.5]²: the cells under the diagonal, and the two the
    # diagonal touches at a corner, (1, 1) and (2, 2)
    below = np.zeros((4, 4), dtype=bool)
    for j, k in [(0, 0), (1, 0), (2, 0), (1, 1), (2, 1), (2, 2), (0, 1), (1, 2)]:
        below[j, k] = True
    assert np.array_equal(grid[1], below) and np.array_equal(grid[2], below) and grid.sum() == 16
    corner = _both(v, np.array([[3, 3, 3]]), lo, h, dims)[0].reshape(dims)
    assert corner.sum() == 8 and corner[2:4, 2:4, 2:4].all()
