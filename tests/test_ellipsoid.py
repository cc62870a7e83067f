"""Equivalent inertia ellipsoid (inertia_tool.mass.ellipsoid)."""

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.mass.ellipsoid import equivalent_ellipsoid_semi_axes
from inertia_tool.errors import PhysicsError, UsageError


def test_solid_ellipsoid_closed_form_round_trip():
    # I_1 = m (b² + c²)/5 etc. for a solid ellipsoid (standard closed form)
    m, a = 3.0, np.array([0.5, 1.2, 2.0])
    moments = m / 5 * np.array([a[1] ** 2 + a[2] ** 2, a[0] ** 2 + a[2] ** 2, a[0] ** 2 + a[1] ** 2])
    np.testing.assert_allclose(equivalent_ellipsoid_semi_axes(moments, m), a, rtol=1e-14)


def test_box_gives_sides_times_sqrt_5_12():
    props = mass_properties(trimesh.creation.box([1.0, 2.0, 3.0]), density=7.0)
    semi = equivalent_ellipsoid_semi_axes(props.principal.moments, props.mass)
    np.testing.assert_allclose(semi, np.array([3.0, 2.0, 1.0]) * np.sqrt(5 / 12), rtol=1e-12)


def test_faceted_sphere_is_close_to_itself():
    s = trimesh.creation.icosphere(subdivisions=5, radius=2.0)
    props = mass_properties(s)
    np.testing.assert_allclose(equivalent_ellipsoid_semi_axes(props.principal.moments, props.mass), 2.0,
                               rtol=2e-3)


def test_flat_plate_gives_a_zero_axis_and_violations_raise():
    m = 2.0
    np.testing.assert_allclose(equivalent_ellipsoid_semi_axes([1.0, 2.0, 3.0], m)[2], 0.0, atol=1e-12)
    with pytest.raises(PhysicsError, match="triangle inequality"):
        equivalent_ellipsoid_semi_axes([1.0, 1.0, 3.0], m)
    with pytest.raises(UsageError):
        equivalent_ellipsoid_semi_axes([1.0, 1.0, 1.0], 0.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.01, 10.0), min_size=3, max_size=3), st.floats(0.1, 100.0))
def test_property_ellipsoid_reproduces_its_moments(semi, mass):
    a = np.array(semi)
    moments = mass / 5 * (np.sum(a ** 2) - a ** 2)
    np.testing.assert_allclose(equivalent_ellipsoid_semi_axes(moments, mass), a, rtol=1e-9, atol=1e-12)
