"""Two passes of ``grid_corrected.corrected_estimate`` made cheaper without changing a value (issue 25, item 3).

* The crossed cells are the union of the cells each class of faces marks (``_surface_cells`` samples every
  face on its own and then grows the marked cells by shifts, which distribute over a union), so the corrected
  estimate marks each face once instead of twice.  Checked on hypothesis soups (needles, slivers, grids that do
  not hold the whole surface) split into random classes, on the C kernel and on the numpy path.
* ``_probe_clearance`` finds the faces near each front probe within a slab along x instead of testing every
  face; the same (probe, face) pairs give the same minimum, bit for bit, as the test of every face against
  every probe (written out below as it stood), also when the block is halved down to single probes.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool.mesh.grid_cells import _surface_cells
from inertia_tool.mesh.grid_corrected import _point_triangle_distance, _probe_clearance
from test_mesh_surface_cells import triangle_soups


@pytest.mark.parametrize("accel", [True, False] if HAVE_ACCEL else [False], ids=["C", "numpy"][:1 + HAVE_ACCEL])
@settings(max_examples=40, deadline=None)
@given(case=triangle_soups(), seed=st.integers(0, 2 ** 32 - 1), classes=st.integers(1, 5))
def test_crossed_cells_are_the_union_of_each_class_of_faces(accel, case, seed, classes):
    v, f, lo, h, dims = case
    label = np.random.default_rng(seed).integers(0, classes, size=len(f))
    with pytest.MonkeyPatch.context() as patch:
        if accel:
            patch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
        else:
            patch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
        whole = _surface_cells(v, f, lo, h, dims)
        union = np.zeros_like(whole)
        for k in range(classes):
            if np.any(label == k):
                union |= _surface_cells(v, f[label == k], lo, h, dims)
    np.testing.assert_array_equal(union, whole)


def _clearance_of_every_face(points, reach, own, lo, hi, a, b, c):
    """The loop ``_front_numbers`` ran before: every probe against every face's box."""
    out = np.array(reach, dtype=np.float64)
    for s in range(0, len(points), 7):
        q, r = points[s:s + 7], out[s:s + 7]
        gap = np.maximum(np.maximum(lo[None] - q[:, None], q[:, None] - hi[None]), 0.0)
        near = np.einsum("pki,pki->pk", gap, gap) <= (r ** 2)[:, None]
        near[np.arange(len(q)), own[s:s + 7]] = False
        pi, fi = np.nonzero(near)
        if len(pi):
            d = _point_triangle_distance(q[pi], a[fi], b[fi], c[fi])
            nearest = np.full(len(q), np.inf)
            np.minimum.at(nearest, pi, d)
            out[s:s + 7] = np.minimum(r, 0.25 * nearest)
    return out


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), faces=st.integers(1, 300), spread=st.sampled_from([1e-3, 1.0, 1e3]),
       reach=st.sampled_from([0.01, 0.3, 3.0]), work=st.sampled_from([1, 50, 1 << 22]))
def test_probe_clearance_is_that_of_every_face(seed, faces, spread, reach, work):
    rng = np.random.default_rng(seed)
    centre = rng.normal(size=(faces, 3)) * spread
    if rng.random() < 0.5:                              # many faces stacked along x (one wide slab)
        centre[:, 0] = rng.normal() * spread
    size = spread * 10.0 ** rng.uniform(-3, 0, size=(faces, 1))
    a, b, c = (centre + rng.normal(size=(faces, 3)) * size for _ in range(3))
    lo, hi = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
    own = rng.choice(faces, size=min(faces, rng.integers(1, 60)), replace=False)
    points = (a[own] + b[own] + c[own]) / 3.0
    radius = reach * spread * rng.uniform(0.0, 1.0, size=len(own))
    expected = _clearance_of_every_face(points, radius, own, lo, hi, a, b, c)
    found = _probe_clearance(points, radius, own, lo, hi, a, b, c, work=work)
    np.testing.assert_array_equal(found, expected)
    assert np.all(found <= radius)


def test_a_face_between_two_blocks_is_counted_for_the_cells_on_both_sides():
    """A face in the plane x = 8 (the boundary of two 8-cell blocks) meets the closed cells 7 and 8; the blocks
    listed each face only from its own box, so cell 7 (block 0) counted 0 faces before."""
    from inertia_tool.mesh.grid_corrected import _face_counts
    lo, h, dims = np.zeros(3), 1.0, (16, 4, 4)
    v = np.array([[8.0, 0.5, 0.5], [8.0, 1.5, 0.5], [8.0, 0.5, 1.5]])
    cells = np.ravel_multi_index(([7, 8, 6], [0, 0, 0], [0, 0, 0]), dims)
    for block in (2, 3, 4, 8):
        assert _face_counts(v, np.array([[0, 1, 2]]), cells, lo, h, dims, block=block).tolist() == [1, 1, 0]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), faces=st.integers(1, 80), block=st.sampled_from([2, 3, 4, 8]),
       aligned=st.booleans())
def test_face_counts_are_those_of_every_face_against_every_cell(seed, faces, block, aligned):
    from inertia_tool.mesh.grid_corrected import _face_counts
    rng = np.random.default_rng(seed)
    dims = tuple(int(d) for d in rng.integers(3, 20, size=3))
    lo, h = rng.normal(size=3), float(10.0 ** rng.uniform(-3, 1))
    corners = rng.uniform(-1, np.array(dims) + 1, size=(faces, 3, 3))
    if aligned:                                         # corners on cell boundaries: faces in the grid's planes
        corners = np.round(corners)
    v = (lo + h * corners).reshape(-1, 3)
    f = np.arange(3 * faces).reshape(-1, 3)
    cells = np.unique(rng.integers(0, int(np.prod(dims)), size=50))
    found = _face_counts(v, f, cells, lo, h, dims, block=block)
    flo, fhi = v[f].min(axis=1), v[f].max(axis=1)
    cell_lo = lo + h * np.stack(np.unravel_index(cells, dims), axis=1)
    slack = 1e-9 * h
    meets = np.all((flo[None] <= cell_lo[:, None] + h + slack) & (fhi[None] >= cell_lo[:, None] - slack), axis=2)
    np.testing.assert_array_equal(found, meets.sum(axis=1))
