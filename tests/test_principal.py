import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool.errors import UsageError
from inertia_tool.mass.principal import principal_axes


def _random_rotation(seed):
    return Rotation.random(random_state=seed).as_matrix()


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31 - 1), st.lists(st.floats(0.1, 10.0), min_size=3, max_size=3))
def test_reconstructs_tensor_with_proper_rotation_and_ascending_moments(seed, diag):
    r = _random_rotation(seed)
    tensor = r @ np.diag(diag) @ r.T
    pa = principal_axes(tensor)
    assert np.all(np.diff(pa.moments) >= 0)
    assert np.linalg.det(pa.axes) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(pa.axes.T @ pa.axes, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(pa.axes @ np.diag(pa.moments) @ pa.axes.T, tensor, atol=1e-12 * max(diag))
    np.testing.assert_allclose(np.sort(diag), pa.moments, rtol=1e-12)


def test_axes_are_columns_in_moment_order():
    pa = principal_axes(np.diag([3.0, 1.0, 2.0]))
    np.testing.assert_allclose(pa.moments, [1, 2, 3])
    np.testing.assert_allclose(np.abs(pa.axes), [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)
    for k in range(3):
        np.testing.assert_allclose(np.diag([3.0, 1.0, 2.0]) @ pa.axes[:, k], pa.moments[k] * pa.axes[:, k])


def test_sign_convention_largest_component_positive_for_first_two_axes():
    r = _random_rotation(7)
    pa = principal_axes(r @ np.diag([1.0, 2.0, 3.0]) @ r.T)
    for k in (0, 1):
        a = pa.axes[:, k]
        assert a[np.argmax(np.abs(a))] > 0


def test_axisymmetric_choice_is_deterministic_and_flagged():
    r = _random_rotation(3)
    base = r @ np.diag([2.0, 2.0, 5.0]) @ r.T
    noisy = base + 1e-14 * np.array([[1, 2, 3], [2, -1, 0.5], [3, 0.5, 2]])
    a = principal_axes(base)
    b = principal_axes(noisy)
    assert a.is_axisymmetric and a.equal_pairs == ((0, 1),)
    np.testing.assert_allclose(a.axes, b.axes, atol=1e-9)
    np.testing.assert_allclose(abs(a.axes[:, 2] @ r[:, 2]), 1.0, atol=1e-12)


def test_spherical_gives_mesh_axes():
    pa = principal_axes(4.0 * np.eye(3) + 1e-15)
    assert pa.is_spherical
    np.testing.assert_array_equal(pa.axes, np.eye(3))


def test_triangle_inequality_margin_of_flat_plate_is_zero():
    pa = principal_axes(np.diag([1.0, 2.0, 3.0]))
    assert pa.triangle_inequality_margin == pytest.approx(0.0, abs=1e-15)


def test_bad_input():
    with pytest.raises(UsageError, match=r"shape \(3, 3\)"):
        principal_axes(np.eye(2))
    with pytest.raises(UsageError, match="finite"):
        principal_axes(np.full((3, 3), np.nan))


_FINITE = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e150, max_value=1e150)


@settings(max_examples=300, deadline=None)
@given(st.lists(_FINITE, min_size=6, max_size=6))
def test_cross3_is_numpy_cross_bit_for_bit(values):
    """The third principal axis is ``a1 × a2`` computed without ``np.cross``'s axis handling (issue 25 item 6:
    per-part overhead); it must be numpy's result to the last bit, for any magnitudes and signs."""
    from inertia_tool.mass.principal import _cross3
    a, b = np.array(values[:3]), np.array(values[3:])
    ours, theirs = _cross3(a, b), np.cross(a, b)
    assert ours.dtype == theirs.dtype and ours.shape == theirs.shape
    assert ours.tobytes() == theirs.tobytes()


@pytest.mark.parametrize("seed", range(20))
def test_principal_axes_unchanged_by_the_cross_product_shortcut(seed, monkeypatch):
    """The whole result (moments, axes, pairs) is the same with numpy's cross product put back."""
    import inertia_tool.mass.principal as principal
    rng = np.random.default_rng(seed)
    m = rng.standard_normal((3, 3)) * 10.0 ** rng.uniform(-6, 6)
    tensor = m @ m.T + np.diag(rng.uniform(0, 1, 3))
    fast = principal_axes(tensor)
    monkeypatch.setattr(principal, "_cross3", np.cross)
    slow = principal_axes(tensor)
    assert fast.moments.tobytes() == slow.moments.tobytes() and fast.axes.tobytes() == slow.axes.tobytes()
    assert fast.equal_pairs == slow.equal_pairs
