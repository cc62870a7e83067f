"""The exact-union reference of benchmarks/bench_exact_union.py (issue 23, scenes19): libigl's CGAL boolean of
a surface with itself is the solid {winding number > 0}, counted once where bodies overlap, coplanar or not."""

import os
import sys

import numpy as np
import pytest

pytest.importorskip("igl.copyleft.cgal")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks"))

from bench_exact_union import exact_union  # noqa: E402

CORNERS = np.array([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
TRIANGLES = np.array([(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
                      (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)])


def _two_cubes(shift):
    return np.vstack([CORNERS, CORNERS + shift]), np.vstack([TRIANGLES, TRIANGLES + 8])


@pytest.mark.parametrize("shift, volume, centre_x", [
    ((0.5, 0.0, 0.0), 1.5, 0.75),          # TALOS's case: four faces of each cube coplanar with the other's
    ((0.5, 0.5, 0.5), 2 - 0.125, 0.75),    # crossing only: the shared eighth counted once
    ((2.0, 0.0, 0.0), 2.0, 1.5),           # apart: the sum
])
def test_the_union_counts_an_overlap_once(shift, volume, centre_x):
    union = exact_union(*_two_cubes(np.array(shift)))
    assert union.mass == pytest.approx(volume, rel=1e-14)
    assert union.center_of_mass[0] == pytest.approx(centre_x, rel=1e-14)


def test_the_union_of_the_half_overlap_has_the_box_s_tensor():
    # [0, 1.5] x [0, 1] x [0, 1]: about its centre, I_xx = m (1 + 1) / 12, I_yy = I_zz = m (1.5² + 1) / 12
    union = exact_union(*_two_cubes(np.array((0.5, 0.0, 0.0))))
    m = 1.5
    np.testing.assert_allclose(union.inertia, np.diag([m * 2 / 12, m * 3.25 / 12, m * 3.25 / 12]), atol=1e-14)


def test_an_open_surface_has_no_union():
    with pytest.raises(ValueError, match="not closed"):
        exact_union(CORNERS, TRIANGLES[:-2])
