"""The tolerance weld's groups (issue 25 item 3, no slow path): the C kernel ``_accel.close_groups`` (section 9b:
cells of side tolerance/2 sorted by their Morton code, a union-find over the cells) against a brute force over
every pair and against the numpy/scipy grid :func:`inertia_tool.mesh.merge._groups`, on hypothesis-generated
clusters (a soup's jittered copies, some straddling cell borders), chains, dense clusters of many points in one
cell, pairs exactly at the tolerance and parts far from the origin.  The 1.3M-face soup spent 2–3 s in
``_groups`` before the kernel.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool.mesh.merge import _groups, lowest_in_group, merge_close_vertices

needs_c = pytest.mark.skipif(not HAVE_ACCEL, reason="the C extension is not built")


def brute_lowest(points: np.ndarray, tol: float) -> np.ndarray:
    """The lowest index of each point's group: components of |p - q|^2 <= tol^2 over every pair (the square
    summed as (dx^2 + dy^2) + dz^2, as both implementations do), by label propagation."""
    d = points[:, None, :] - points[None, :, :]
    close = (d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]) + d[..., 2] * d[..., 2] <= tol * tol
    label = np.arange(len(points))
    for _ in range(len(points)):                     # at most n rounds
        new = np.where(close, label[None, :], len(points)).min(axis=1)
        if (new == label).all():
            break
        label = new
    return label


def lowest_of_groups(group: np.ndarray) -> np.ndarray:
    first = np.full(group.max() + 1, len(group), dtype=np.int64)
    np.minimum.at(first, group, np.arange(len(group)))
    return first[group]


def c_lowest(points: np.ndarray, tol: float) -> np.ndarray | None:
    from inertia_tool._native import accel
    got = accel().close_groups(np.ascontiguousarray(points, dtype=np.float64), tol)
    return None if got is None else np.frombuffer(got, dtype=np.int64)


@st.composite
def point_sets(draw):
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    n = draw(st.integers(2, 80))
    tol = draw(st.sampled_from([1e-6, 1e-3, 0.05, 0.2]))
    scale = draw(st.sampled_from([1.0, 1e-2, 30.0]))
    offset = draw(st.sampled_from([0.0, 1.0, 1e4]))
    kind = draw(st.sampled_from(["random", "soup", "chain", "dense", "grid"]))
    if kind == "random":
        pts = rng.random((n, 3)) * scale
    elif kind == "soup":      # copies a fraction of the tolerance apart, some straddling cell borders
        base = rng.random((n // 4 + 1, 3)) * scale
        pts = np.repeat(base, 4, axis=0) + rng.normal(size=(4 * len(base), 3)) * tol * draw(
            st.sampled_from([0.05, 0.4, 0.6]))
    elif kind == "chain":     # steps just under and just over the tolerance along a random direction
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        steps = tol * np.where(rng.random(n) < 0.7, 1 - 1e-7, 1 + 1e-7)
        pts = np.cumsum(steps)[:, None] * direction
    elif kind == "dense":     # many points in one cell and its neighbours
        pts = rng.random((n, 3)) * tol * draw(st.sampled_from([0.3, 1.0, 3.0]))
    else:                     # points on a lattice of pitch the tolerance: every neighbour pair at it
        side = int(np.ceil(n ** (1 / 3)))
        pts = np.stack(np.meshgrid(*[np.arange(side)] * 3, indexing="ij"), -1).reshape(-1, 3)[:n] * tol
    pts = pts + offset
    order = rng.permutation(len(pts))
    return pts[order].astype(np.float64), tol


@needs_c
@settings(max_examples=150, deadline=None)
@given(case=point_sets())
def test_c_groups_equal_brute_force_and_numpy_grid(case):
    pts, tol = case
    ref = brute_lowest(pts, tol)
    got = c_lowest(pts, tol)
    if got is not None:          # None: the grid would need more than 21 bits per axis (the numpy path)
        assert got.tolist() == ref.tolist()
    lowest = lowest_in_group(pts, tol)
    assert (np.arange(len(pts)) if lowest is None else lowest).tolist() == ref.tolist()
    grid = _groups(pts, tol)
    assert (np.arange(len(pts)) if grid is None else lowest_of_groups(grid)).tolist() == ref.tolist()


@needs_c
def test_c_groups_pair_exactly_at_the_tolerance():
    tol = 0.25                                      # a power of two: the squares are exact
    pts = np.array([[0, 0, 0], [tol, 0, 0], [3, 3, 3], [3 + tol * (1 + 1e-12), 3, 3], [7, 7, 7],
                    [7 + 0.15, 7 + 0.2, 7]])         # 0.15² + 0.2² = 0.0625 = tol² (to round-off)
    ref = brute_lowest(pts, tol)
    assert c_lowest(pts, tol).tolist() == ref.tolist()
    assert ref[:4].tolist() == [0, 0, 2, 3]


@needs_c
def test_c_groups_many_points_in_one_cell_are_one_group():
    rng = np.random.default_rng(7)
    pts = rng.random((20000, 3)) * 1e-4             # all within one cell of side tol / 2
    got = c_lowest(pts, 1e-3)
    assert not got.any()


@needs_c
def test_c_groups_decline_a_grid_beyond_21_bits():
    pts = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0 + 1e-9, 0, 0]])
    assert c_lowest(pts, 1.5e-9) is None             # 1.3e9 cells per axis: the numpy path decides
    assert lowest_in_group(pts, 1.5e-9).tolist() == [0, 1, 1]


@pytest.mark.usefixtures("engine_path")
def test_merge_close_vertices_on_a_jittered_soup_both_paths():
    """A soup of a tetrahedron's faces, each corner copied per face and jittered well under the tolerance: both
    paths weld it back to the four corners, onto the lowest-numbered copy."""
    rng = np.random.default_rng(3)
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    v = corners[faces.reshape(-1)] + rng.normal(size=(12, 3)) * 1e-9
    soup = np.arange(12).reshape(4, 3)
    merged = merge_close_vertices(v, soup, 1e-7)
    assert merged.merged_vertices == 8
    first = {c: int(np.flatnonzero(faces.reshape(-1) == c)[0]) for c in range(4)}
    assert merged.faces.tolist() == [[first[c] for c in f] for f in faces.tolist()]
    assert 0 < merged.largest_move < 1e-7 * 3
