"""Result values cannot be corrupted (issue: read-only arrays, equality that works, one way to principal axes)."""

import dataclasses

import numpy as np
import pytest

import inertia_tool as it
from inertia_tool.mass import point_mass, shapes
from inertia_tool.values import COPY_LIMIT, frozen_value, readonly


@pytest.fixture
def props():
    solid = shapes.box(0.1, 0.2, 0.3)
    return it.mass_properties((solid.vertices, solid.faces), density=7850.0)


def test_arrays_of_results_are_read_only(props):
    for array in (props.center_of_mass, props.inertia, props.principal.moments, props.principal.axes,
                  props.principal.reference_point, props.inertia_about([1, 2, 3]).tensor,
                  props.mesh.bbox_min):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


def test_caller_arrays_are_copied_so_the_value_cannot_change_later():
    com = np.array([1.0, 2.0, 3.0])
    p = it.MassProperties(mass=1.0, volume=1e-3, center_of_mass=com, inertia=np.eye(3))
    com[0] = 99.0
    assert p.center_of_mass[0] == 1.0


def test_equality_by_value_and_hash(props):
    again = it.mass_properties((shapes.box(0.1, 0.2, 0.3).vertices, shapes.box(0.1, 0.2, 0.3).faces),
                               density=7850.0)
    assert props == again and hash(props) == hash(again)
    assert props != props.with_mass(2 * props.mass)
    assert props.principal == again.principal
    assert len({props, again}) == 1
    assert point_mass(1.0, [0, 0, 0]) == point_mass(1.0, [0, 0, 0])          # NaN density compares equal
    assert it.stability(props) == it.stability(again)


def test_large_arrays_are_read_only_views_not_copies():
    @frozen_value
    class Holder:
        data: np.ndarray

    big = np.zeros(COPY_LIMIT + 1)
    held = Holder(big)
    assert np.shares_memory(held.data, big) and not held.data.flags.writeable
    assert not np.shares_memory(readonly(np.zeros(3)), np.zeros(3))


def test_one_way_to_principal_axes_on_a_body(props):
    assert not hasattr(props, "principal_axes")
    assert props.principal is props.principal                                  # computed once, read-only
    from inertia_tool.mass.principal import principal_axes
    other = principal_axes(props.inertia, reference_point=props.center_of_mass, mass=props.mass, rtol=1e-3)
    np.testing.assert_array_equal(other.moments, props.principal.moments)


@pytest.mark.parametrize("value", [float("inf"), float("-inf"), float("nan"), np.float64("inf"), [1.0, float("nan")],
                                   np.array([[0.0, np.inf]])])
def test_non_finite_check_refuses_every_non_finite_form(value):
    """The float fast path (no numpy) and the array path both refuse inf and NaN, and name the quantity."""
    from inertia_tool.errors import NonFiniteResultError

    with pytest.raises(NonFiniteResultError, match="the mass is"):
        NonFiniteResultError.check("the mass", value)


@pytest.mark.parametrize("value", [0.0, -1e308, 5e-324, np.float64(2.0), [1.0, 2.0], np.eye(3)])
def test_non_finite_check_accepts_finite_values(value):
    from inertia_tool.errors import NonFiniteResultError

    assert NonFiniteResultError.check("the mass", value) is None


def test_frozen_value_field_names_are_per_class():
    """The cached field names are per class: two value classes with different array fields each make their own
    arrays read-only, and compare by their own compared fields."""
    @frozen_value
    class A:
        x: np.ndarray

    @frozen_value
    class B:
        x: np.ndarray
        y: np.ndarray
        note: str = dataclasses.field(default="", compare=False)

    a, b = A(np.zeros(2)), B(np.zeros(2), np.ones(2), note="n")
    assert not a.x.flags.writeable and not b.x.flags.writeable and not b.y.flags.writeable
    assert b == B(np.zeros(2), np.ones(2), note="other") and hash(b) == hash(B(np.zeros(2), np.ones(2)))
    assert b != B(np.zeros(2), np.zeros(2))
