"""The conventions of docs/conventions.md, each pinned by a test."""

import numpy as np
import pytest

from conftest import box_arrays
from inertia_tool import mass_properties
from inertia_tool.mass import point_mass
from inertia_tool.mass.volume import volume_moments
from conftest import assert_tensor_close


def test_off_diagonals_are_minus_integral_xy_dm():
    # two cubes in the first and third quadrants of the xy-plane: ∫xy dm > 0, so I_xy < 0
    a = box_arrays((1.0, 1.0, 1.0), center=(1.0, 1.0, 0.0))
    b = box_arrays((1.0, 1.0, 1.0), center=(-1.0, -1.0, 0.0))
    p = mass_properties((np.vstack([a[0], b[0]]), np.vstack([a[1], b[1] + 8])), density=1.0)
    integral_xy = 2 * 1.0 * (1.0 * 1.0)  # each unit cube: ∫xy dm = m x̄ ȳ = 1
    assert p.inertia[0, 1] == pytest.approx(-integral_xy, rel=1e-14)
    assert p.inertia[1, 0] == p.inertia[0, 1]
    # the same from the raw second moment C = ∫ x xᵀ dV: I = tr(C) 1 - C
    c = volume_moments(*a).second_moment
    assert c[0, 1] == pytest.approx(0.0, abs=1e-15)


def test_point_mass_tensor_matches_eq_4_11():
    m, r = 2.0, np.array([1.0, 2.0, 3.0])
    body = point_mass(m, r) + point_mass(1e-300, [0, 0, 0])
    about_origin = np.asarray(body.inertia_about([0, 0, 0]))
    np.testing.assert_allclose(about_origin, m * ((r @ r) * np.eye(3) - np.outer(r, r)), rtol=1e-14)


def test_principal_axes_are_columns_of_a_proper_rotation_with_ascending_moments():
    v, f = box_arrays((1.0, 2.0, 3.0))
    rot = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])
    p = mass_properties((v @ rot.T, f))
    pa = p.principal
    assert np.all(np.diff(pa.moments) > 0)
    assert np.linalg.det(pa.axes) == pytest.approx(1.0, abs=1e-12)
    # the smallest moment belongs to the longest box edge (z in the box frame), rotated into mesh axes
    assert abs(pa.axes[:, 0] @ (rot @ [0, 0, 1])) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(pa.axes @ np.diag(pa.moments) @ pa.axes.T, p.inertia, atol=1e-12 * pa.moments[-1])


def test_si_inside_units_at_the_boundary():
    v, f = box_arrays((10.0, 20.0, 30.0))
    mm = mass_properties((v, f), units="mm", density=1000.0)
    m = mass_properties((v * 1e-3, f), units="m", density=1000.0)
    assert mm.volume == pytest.approx(6e-6, rel=1e-14) and mm.mass == pytest.approx(m.mass, rel=1e-14)
    assert_tensor_close(mm.inertia, m.inertia, rtol=1e-13)
