"""``grid_corrected._distance_above``: the upper bound on a point's distance to a surface with which
:func:`corrected_estimate` clears cells without a distance query (issue 25, item 3: Piper's ``link2.stl``).  Each
bound must be at least the exact distance (libigl's nearest point on every face, an independent computation), on
slivers and needles, at sizes from 1e-3 to 1e3 m and 3e6 m from the origin; and a dense sampling must come close."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import grid_cells, grid_corrected

igl = pytest.importorskip("igl")


def _exact(points, vertices, faces):
    return np.sqrt(np.asarray(igl.point_mesh_squared_distance(points, vertices, faces)[0], dtype=np.float64))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), spacing=st.floats(0.05, 10.0), scale=st.sampled_from([1e-3, 1.0, 1e3]),
       offset=st.sampled_from([0.0, 1e4, -3e6]), needles=st.booleans(), near=st.booleans())
def test_the_bound_is_never_below_the_exact_distance(seed, spacing, scale, offset, needles, near):
    rng = np.random.default_rng(seed)
    n_faces = int(rng.integers(1, 40))
    vertices = rng.normal(size=(3 * n_faces, 3))
    if needles:                                   # slivers and needles: one corner almost on another
        vertices[2::3] = vertices[0::3] + rng.normal(scale=1e-7, size=(n_faces, 3))
    vertices = vertices * scale + offset
    faces = np.arange(3 * n_faces).reshape(-1, 3)
    if near:                                      # points on and within 1e-9 of the faces (distance ~0)
        pick = rng.integers(0, n_faces, 200)
        w = rng.dirichlet(np.ones(3), 200)
        points = np.einsum("pk,pkx->px", w, vertices[faces[pick]]) + rng.normal(scale=1e-9 * scale, size=(200, 3))
    else:
        points = rng.normal(scale=1.5, size=(200, 3)) * scale + offset
    exact = _exact(points, vertices, faces)
    above = grid_corrected._distance_above(points, vertices, faces, spacing * scale)
    assert np.all(above >= exact), f"{np.count_nonzero(above < exact)} bounds below the exact distance"
    # the search stopped at `beyond` (issue 25, corpus13): the same bound where it is finite, inf only beyond
    beyond = float(np.quantile(above, rng.uniform(0.0, 1.0)))
    bounded = grid_corrected._distance_above(points, vertices, faces, spacing * scale, beyond=beyond)
    stopped = ~np.isfinite(bounded)
    np.testing.assert_array_equal(bounded[~stopped], above[~stopped])
    assert np.all(above[stopped] > beyond) and np.all(~stopped[above <= beyond])


def test_a_dense_sampling_comes_within_its_spacing():
    # a flat square of two faces, points above it: with samples every 0.01 the nearest one is within 0.0071 of
    # the foot of each point, so every bound is within 0.0071 (plus the margin) of the height
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    rng = np.random.default_rng(7)
    points = np.column_stack([rng.uniform(0, 1, 500), rng.uniform(0, 1, 500), rng.uniform(0.01, 0.5, 500)])
    above = grid_corrected._distance_above(points, vertices, faces, 0.01)
    assert np.all(above >= points[:, 2])
    assert np.all(above - points[:, 2] < 0.0072)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), cells=st.integers(4, 24), scale=st.sampled_from([1e-3, 1.0, 1e3]),
       offset=st.sampled_from([0.0, 1e4, -3e6]), needles=st.booleans())
def test_cells_two_apart_from_the_marked_ones_are_a_cell_and_a_half_away(seed, cells, scale, offset, needles):
    # the step of corrected_estimate that clears a centre without measuring its distance to the bad faces rests on
    # this: _surface_cells marks every cell a face meets, so a centre whose 3x3x3 block of cells holds no marked
    # cell is at least 1.5 cells from every face
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    n_faces = int(rng.integers(1, 12))
    vertices = rng.uniform(-1, 1, size=(3 * n_faces, 3))
    if needles:
        vertices[2::3] = vertices[0::3] + rng.normal(scale=1e-7, size=(n_faces, 3))
    vertices = vertices * scale + offset
    faces = np.arange(3 * n_faces).reshape(-1, 3)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    h = float(np.max(hi - lo)) / cells
    lo = lo - 3 * h
    dims = tuple(int(x) for x in np.ceil((hi + 3 * h - lo) / h).astype(np.int64))
    marked = grid_cells._surface_cells(vertices, faces, lo, h, dims).reshape(dims)
    apart = np.flatnonzero(~ndimage.maximum_filter(marked, size=3, mode="constant", cval=False).reshape(-1))
    centres = lo + h * (np.stack(np.unravel_index(apart, dims), axis=1) + 0.5)
    exact = _exact(centres, vertices, faces)
    slack = 1e-9 * float(np.linalg.norm(hi - lo)) + 1e-6 * h
    assert np.all(exact >= 1.5 * h - slack)
