"""``hole_bounds.bend_doubt_volumes`` on holes whose ring faces stand at 90° to the rim's plane (an open prism: the
bend assumption cannot apply, ``inf``): no overflow (the slope of such a loop was ``1/1e-300`` and its product
with the rim's distances and areas overflowed on parts ~1 km across, a ``RuntimeWarning``), and the loops it can
bound in the same call keep their own figure."""

from __future__ import annotations

import warnings

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh.hole_bounds import bend_doubt_volumes


def _open_prism(scale: float, offset: np.ndarray, top: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A triangular prism ``scale`` across, open at the top; the top triangle is ``top`` times the bottom one
    (1: vertical walls; below 1: walls leaning in, a frustum).  Returns vertices, faces and the rim's edges
    ``a → b`` (each the edge of one wall in that direction)."""
    tri = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]])
    centre = tri.mean(axis=0)
    lower = np.c_[tri * scale, np.zeros(3)]
    upper = np.c_[(centre + top * (tri - centre)) * scale, np.full(3, 0.2 * scale)]
    v = np.vstack([lower, upper]) + offset
    f = [[0, 2, 1]]
    for i in range(3):
        j = (i + 1) % 3
        f += [[i, j, 3 + j], [i, 3 + j, 3 + i]]
    rim = np.array([[3 + (i + 1) % 3, 3 + i] for i in range(3)])
    return v, np.array(f, dtype=np.int64), rim


@settings(max_examples=40, deadline=None)
@given(scale=st.floats(1e-3, 1e7), far=st.floats(0.0, 1e8), lean=st.floats(0.2, 0.6))
def test_a_rim_of_upright_walls_is_not_bounded_and_does_not_overflow(scale, far, lean):
    offset = np.array([far, -0.6 * far, 0.3 * far])
    v1, f1, rim1 = _open_prism(scale, offset, 1.0)                                   # walls at 90°
    v2, f2, rim2 = _open_prism(scale, offset + np.array([3.0 * scale, 0.0, 0.0]), lean)   # walls leaning in
    v, f = np.vstack([v1, v2]), np.vstack([f1, f2 + len(v1)])
    edges = np.vstack([rim1, rim2 + len(v1)])
    label = np.repeat([0, 1], 3)
    apex = np.stack([v[rim1[:, 0]].mean(axis=0), v[rim2[:, 0] + len(v1)].mean(axis=0)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")                  # an overflow (RuntimeWarning) fails the test
        doubt, height = bend_doubt_volumes(v, f, edges, label, 2, apex)
        alone, alone_height = bend_doubt_volumes(v2, f2, rim2, np.zeros(3, dtype=np.int64), 1, apex[1:])
    assert np.isinf(doubt[0]) and np.isinf(height[0])
    assert np.isfinite(doubt[1]) and doubt[1] == alone[0] and height[1] == alone_height[0]
