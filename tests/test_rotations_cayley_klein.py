"""Exercise 4.11: Cayley–Klein parameters, Möbius maps of the stereographic plane, the SU(2) → SO(3) double cover."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool.errors import UsageError
from inertia_tool.rotations import (cayley_klein_to_matrix, cayley_klein_to_quaternion,
                                    inverse_stereographic_projection, moebius_transform, quaternion_multiply,
                                    quaternion_to_cayley_klein, quaternion_to_matrix, stereographic_projection)

quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).map(np.array).filter(
    lambda q: np.linalg.norm(q) > 0.1).map(lambda q: q / np.linalg.norm(q))


@settings(max_examples=60)
@given(quaternions)
def test_su2_matrix_gives_the_quaternion_rotation_and_scipy(q):
    u = quaternion_to_cayley_klein(q)
    np.testing.assert_allclose(u @ u.conj().T, np.eye(2), atol=1e-12)          # unitary
    assert np.linalg.det(u) == pytest.approx(1.0, abs=1e-12)                  # unimodular
    rotation = cayley_klein_to_matrix(u)
    np.testing.assert_allclose(rotation, quaternion_to_matrix(q), atol=1e-12)
    np.testing.assert_allclose(rotation, Rotation.from_quat(np.roll(q, -1)).as_matrix(), atol=1e-12)
    back = cayley_klein_to_quaternion(u)
    assert np.allclose(back, q, atol=1e-12) or np.allclose(back, -q, atol=1e-12)


@settings(max_examples=60)
@given(quaternions)
def test_double_cover_u_and_minus_u_give_the_same_rotation(q):
    u = quaternion_to_cayley_klein(q)
    np.testing.assert_allclose(cayley_klein_to_matrix(-u), cayley_klein_to_matrix(u), atol=1e-12)
    np.testing.assert_allclose(cayley_klein_to_quaternion(-u), cayley_klein_to_quaternion(u), atol=1e-12)


@settings(max_examples=60)
@given(quaternions, quaternions)
def test_composition_is_a_homomorphism(p, q):
    """Q(U1 U2) = Q(U1) Q(U2), and U of p ⊗ q is U(p) U(q) (exercise 4.11c)."""
    u1, u2 = quaternion_to_cayley_klein(p), quaternion_to_cayley_klein(q)
    np.testing.assert_allclose(cayley_klein_to_matrix(u1 @ u2),
                               cayley_klein_to_matrix(u1) @ cayley_klein_to_matrix(u2), atol=1e-12)
    np.testing.assert_allclose(quaternion_to_cayley_klein(quaternion_multiply(p, q)), u1 @ u2, atol=1e-12)


@settings(max_examples=60)
@given(quaternions)
def test_moebius_map_of_the_projection_is_the_rotation_of_the_sphere(q):
    """Exercise 4.11b: s(Q p) = (α s(p) + β)/(γ s(p) + δ) for points p of the unit sphere."""
    rng = np.random.default_rng(7)
    points = rng.normal(size=(20, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]
    rotated = points @ quaternion_to_matrix(q).T
    keep = (points[:, 2] < 0.99) & (rotated[:, 2] < 0.99)      # stay away from the pole (ξ → ∞)
    u = quaternion_to_cayley_klein(q)
    np.testing.assert_allclose(moebius_transform(u, stereographic_projection(points[keep])),
                               stereographic_projection(rotated[keep]), rtol=1e-9, atol=1e-9)


def test_half_turn_has_one_quaternion_for_both_signs():
    """w = 0 (a half turn): ±q are both "w ≥ 0"; the first non-zero component decides."""
    for q in ([0.0, 0.0, 0.0, 1.0], [0.0, 0.6, -0.8, 0.0]):
        u = quaternion_to_cayley_klein(q)
        np.testing.assert_array_equal(cayley_klein_to_quaternion(u), cayley_klein_to_quaternion(-u))
    np.testing.assert_allclose(cayley_klein_to_quaternion(quaternion_to_cayley_klein([0, 0, 0, -1.0])), [0, 0, 0, 1])


def test_rotation_by_two_pi_is_minus_identity_in_su2():
    """A full turn about any axis is −𝟙 in SU(2) but the identity rotation: the two sheets of the cover."""
    half = np.array([np.cos(np.pi), 0.0, 0.0, np.sin(np.pi)])          # quaternion of a 2π turn about z
    np.testing.assert_allclose(quaternion_to_cayley_klein(half), -np.eye(2), atol=1e-15)
    np.testing.assert_allclose(cayley_klein_to_matrix(-np.eye(2)), np.eye(3), atol=1e-15)


def test_stereographic_round_trip_and_conformal_scale():
    """Exercise 4.11a: the projection inverts, and scales small displacements by 1/(1 − z) in every direction."""
    p = np.array([0.3, -0.4, np.sqrt(1 - 0.25)])
    np.testing.assert_allclose(inverse_stereographic_projection(stereographic_projection(p)), p, atol=1e-14)
    t1 = np.cross(p, [1.0, 0, 0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(p, t1)
    h = 1e-7
    for t in (t1, t2):
        moved = (p + h * t) / np.linalg.norm(p + h * t)
        scale = abs(stereographic_projection(moved) - stereographic_projection(p)) / h
        assert scale == pytest.approx(1.0 / (1.0 - p[2]), rel=1e-5)


def test_non_su2_matrix_is_refused():
    with pytest.raises(UsageError, match="SU\\(2\\)"):
        cayley_klein_to_matrix(np.array([[2.0, 0.0], [0.0, 0.5]]))
