"""``grid_estimate._nearer_to_samples``: the proof that clears a cell of :func:`corrected_estimate` without a distance
query (issue 25, item 3: Piper's ``link2.stl``).  A point is marked only when its exact distance to the surface is
below the given bound; the exact distance here is libigl's nearest point on every face, and the bounds are set a
hair either side of it, so a marking that ignored its own margin or the samples' spacing would be caught."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import grid_estimate

igl = pytest.importorskip("igl")


def _exact(points, vertices, faces):
    return np.sqrt(np.asarray(igl.point_mesh_squared_distance(points, vertices, faces)[0], dtype=np.float64))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), spacing=st.floats(0.05, 10.0), scale=st.sampled_from([1e-3, 1.0, 1e3]),
       offset=st.sampled_from([0.0, 1e4, -3e6]), needles=st.booleans())
def test_marked_points_are_nearer_than_the_bound(seed, spacing, scale, offset, needles):
    rng = np.random.default_rng(seed)
    n_faces = int(rng.integers(1, 40))
    vertices = rng.normal(size=(3 * n_faces, 3))
    if needles:                                   # slivers and needles: one corner almost on another
        vertices[2::3] = vertices[0::3] + rng.normal(scale=1e-7, size=(n_faces, 3))
    vertices = vertices * scale + offset
    faces = np.arange(3 * n_faces).reshape(-1, 3)
    points = (rng.normal(scale=1.5, size=(200, 3))) * scale + offset
    exact = _exact(points, vertices, faces)
    # just above the exact distance by a relative 1e-6 (markable), exactly at it and just below it (never)
    for factor, may_mark in ((1 + 1e-6, True), (1.0, False), (1 - 1e-12, False), (0.5, False)):
        below = exact * factor
        marked = grid_estimate._nearer_to_samples(points, below, vertices, faces, spacing * scale)
        if not may_mark:
            assert not marked.any(), f"marked {np.count_nonzero(marked)} points at or beyond their distance"
        else:
            assert np.all(exact[marked] < below[marked])


def test_fine_samples_mark_the_points_well_inside_the_bound():
    # a flat square of two faces, points above it: with samples every 0.01 the nearest one is within 0.0071 of
    # the foot of each point, so a bound 0.02 above the height is met by every point over the square
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    rng = np.random.default_rng(7)
    points = np.column_stack([rng.uniform(0, 1, 500), rng.uniform(0, 1, 500), rng.uniform(0.01, 0.5, 500)])
    marked = grid_estimate._nearer_to_samples(points, points[:, 2] + 0.02, vertices, faces, 0.01)
    assert marked.all()
    # and none when the bound is the height itself (the true distance)
    assert not grid_estimate._nearer_to_samples(points, points[:, 2], vertices, faces, 0.01).any()
