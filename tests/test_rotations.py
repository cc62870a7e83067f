"""Tests of inertia_tool.rotations: Eqs. (4.29)-(4.33), exercise 4.5, scipy Rotation cross-checks."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool import rotations as rot
from inertia_tool.errors import UsageError

RNG = np.random.default_rng(20240611)
ANGLES = [(0.3, 1.1, 2.0), (5.9, 0.2, 4.4), (1.0, 3.0, 0.5), (2.5, np.pi / 2, 6.0), (0.1, 2.9, 3.3)]


def explicit_eq_4_31(phi, theta, psi):
    """The closed-form matrix printed in Eq. (4.31)."""
    sf, cf, st_, ct, sp, cp = np.sin(phi), np.cos(phi), np.sin(theta), np.cos(theta), np.sin(psi), np.cos(psi)
    return np.array([[-sf * sp + ct * cf * cp, cf * sp + ct * sf * cp, -st_ * cp],
                     [-sf * cp - ct * cf * sp, cf * cp - ct * sf * sp, st_ * sp],
                     [st_ * cf, st_ * sf, ct]])


@pytest.mark.parametrize("angles", ANGLES)
def test_euler_matrix_equals_explicit_eq_4_31(angles):
    np.testing.assert_allclose(rot.euler_to_matrix(*angles), explicit_eq_4_31(*angles), atol=1e-15)


@pytest.mark.parametrize("angles", ANGLES)
def test_orientation_is_scipy_intrinsic_zyz(angles):
    q_scipy = Rotation.from_euler("ZYZ", angles).as_matrix()
    np.testing.assert_allclose(rot.euler_to_matrix(*angles).T, q_scipy, atol=1e-15)
    quat = rot.euler_to_quaternion(*angles)
    ref = np.roll(Rotation.from_euler("ZYZ", angles).as_quat(), 1)
    ref = ref if ref[0] >= 0 else -ref
    np.testing.assert_allclose(quat, ref, atol=1e-15)


def test_passive_rotations_eq_4_29_4_30_are_transposed_active():
    a = 0.7
    np.testing.assert_allclose(rot.rotation_z(a), Rotation.from_euler("z", a).as_matrix().T, atol=1e-16)
    np.testing.assert_allclose(rot.rotation_y(a), Rotation.from_euler("y", a).as_matrix().T, atol=1e-16)


@pytest.mark.parametrize("angles", ANGLES)
def test_matrix_to_euler_roundtrip(angles):
    phi, theta, psi = rot.matrix_to_euler(rot.euler_to_matrix(*angles))
    np.testing.assert_allclose([phi, theta, psi], angles, atol=1e-12)


@pytest.mark.parametrize("theta", [0.0, np.pi])
def test_matrix_to_euler_gimbal_cases_reproduce_the_matrix(theta):
    a = rot.euler_to_matrix(1.2, theta, 0.4)
    phi, th, psi = rot.matrix_to_euler(a)
    assert psi == 0.0 and th == pytest.approx(theta, abs=1e-15)
    np.testing.assert_allclose(rot.euler_to_matrix(phi, th, psi), a, atol=1e-15)


def test_matrix_to_euler_against_scipy_random():
    r = Rotation.random(200, random_state=3)
    phi, theta, psi = rot.matrix_to_euler(np.swapaxes(r.as_matrix(), 1, 2))
    ref = r.as_euler("ZYZ")  # scipy: theta in [0, pi], phi, psi in (-pi, pi]
    np.testing.assert_allclose(theta, ref[:, 1], atol=1e-12)
    np.testing.assert_allclose(np.exp(1j * phi), np.exp(1j * ref[:, 0]), atol=1e-12)
    np.testing.assert_allclose(np.exp(1j * psi), np.exp(1j * ref[:, 2]), atol=1e-12)
    assert np.all((phi >= 0) & (phi < 2 * np.pi) & (psi >= 0) & (psi < 2 * np.pi))


def angles_at(t):
    """A smooth Euler-angle history used for the Eq. (4.33) check, and its exact rates."""
    return (0.3 + 0.7 * t + 0.2 * t * t, 1.0 + 0.4 * np.sin(t), 2.0 - 1.3 * t), (0.7 + 0.4 * t, 0.4 * np.cos(t), -1.3)


@pytest.mark.parametrize("t", [0.0, 0.37, 1.5, 2.9])
def test_eq_4_33_against_numerical_derivative_of_A(t):
    h = 1e-5
    a_plus = rot.euler_to_matrix(*angles_at(t + h)[0])
    a_minus = rot.euler_to_matrix(*angles_at(t - h)[0])
    a = rot.euler_to_matrix(*angles_at(t)[0])
    # Omega' = -A d(A^-1)/dt = -A d(A^T)/dt (section 4.2), central difference
    omega_prime = -a @ (a_plus.T - a_minus.T) / (2 * h)
    omega_vec = np.array([omega_prime[1, 2], omega_prime[2, 0], omega_prime[0, 1]])
    np.testing.assert_allclose(omega_prime, -omega_prime.T, atol=1e-9)
    np.testing.assert_allclose(rot.euler_rates_to_angular_velocity(*angles_at(t)[0], *angles_at(t)[1]),
                               omega_vec, atol=1e-9)


def test_eq_4_33_is_body_angular_velocity_of_scipy_rotation():
    """Q(t) = A(t)^T; body angular velocity is vee(Q^T dQ/dt)."""
    t, h = 0.8, 1e-6
    q = lambda s: Rotation.from_euler("ZYZ", angles_at(s)[0]).as_matrix()
    w_hat = q(t).T @ (q(t + h) - q(t - h)) / (2 * h)
    np.testing.assert_allclose(rot.euler_rates_to_angular_velocity(*angles_at(t)[0], *angles_at(t)[1]),
                               [w_hat[2, 1], w_hat[0, 2], w_hat[1, 0]], atol=1e-8)


@pytest.mark.parametrize("axis,angle", [((0, 0, 1), 0.5), ((1, 2, 3), 2.0), ((-1, 0.5, 0.2), 3.1),
                                        ((0, 1, 0), np.pi)])
def test_axis_angle_exercise_4_5(axis, angle):
    n = np.asarray(axis, float) / np.linalg.norm(axis)
    a = rot.axis_angle_to_matrix(axis, angle)
    np.testing.assert_allclose(a.T, Rotation.from_rotvec(angle * n).as_matrix(), atol=1e-15)
    ax, ang = rot.matrix_to_axis_angle(a)
    assert ang == pytest.approx(angle, abs=1e-12)
    if angle < np.pi:
        np.testing.assert_allclose(ax, n, atol=1e-12)
    np.testing.assert_allclose(rot.axis_angle_to_matrix(ax, ang), a, atol=1e-12)


def test_axis_angle_about_z_is_eq_4_29():
    np.testing.assert_allclose(rot.axis_angle_to_matrix([0, 0, 1], 0.9), rot.rotation_z(0.9), atol=1e-16)


def test_quaternion_matrix_against_scipy_and_roundtrip():
    r = Rotation.random(500, random_state=7)
    q = np.roll(r.as_quat(), 1, axis=-1)
    np.testing.assert_allclose(rot.quaternion_to_matrix(q), r.as_matrix(), atol=1e-15)
    q_back = rot.matrix_to_quaternion(r.as_matrix())
    q_ref = np.where(q[:, :1] < 0, -q, q)
    np.testing.assert_allclose(q_back, q_ref, atol=2e-15)


def test_quaternion_near_pi_rotations():
    for axis in np.eye(3):
        m = Rotation.from_rotvec(np.pi * axis).as_matrix()
        np.testing.assert_allclose(rot.quaternion_to_matrix(rot.matrix_to_quaternion(m)), m, atol=1e-15)


def test_quaternion_multiply_composes_rotations():
    a, b = Rotation.random(2, random_state=11)
    qa, qb = np.roll(a.as_quat(), 1), np.roll(b.as_quat(), 1)
    np.testing.assert_allclose(rot.quaternion_to_matrix(rot.quaternion_multiply(qa, qb)),
                               (a * b).as_matrix(), atol=1e-15)
    np.testing.assert_allclose(rot.quaternion_multiply(qa, rot.quaternion_conjugate(qa)), [1, 0, 0, 0],
                               atol=1e-15)


@given(st.lists(st.floats(-10, 10), min_size=3, max_size=3))
@settings(max_examples=100, deadline=None)
def test_rotation_vector_quaternion_matches_scipy(v):
    q = rot.rotation_vector_to_quaternion(v)
    ref = np.roll(Rotation.from_rotvec(v).as_quat(canonical=False), 1)
    np.testing.assert_allclose(rot.quaternion_to_matrix(q), Rotation.from_rotvec(v).as_matrix(), atol=1e-14)
    assert abs(abs(q @ ref) - 1) < 1e-14


def test_quaternion_euler_roundtrip():
    phi, theta, psi = rot.quaternion_to_euler(rot.euler_to_quaternion(0.4, 2.2, 5.0))
    np.testing.assert_allclose([phi, theta, psi], [0.4, 2.2, 5.0], atol=1e-12)


def test_bad_shapes_raise_usage_error():
    with pytest.raises(UsageError, match="shape"):
        rot.quaternion_to_matrix([1, 0, 0])
    with pytest.raises(UsageError, match="shape"):
        rot.matrix_to_euler(np.eye(2))
    with pytest.raises(UsageError):
        rot.axis_angle_to_matrix([0, 0, 0], 1.0)


def test_perpendicular_basis_is_right_handed_and_deterministic():
    from inertia_tool.rotations import perpendicular_basis
    rng = np.random.default_rng(3)
    for n in list(np.eye(3)) + [v / np.linalg.norm(v) for v in rng.normal(size=(20, 3))]:
        e1, e2 = perpendicular_basis(n)
        frame = np.column_stack([e1, e2, n])
        np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-15)
        assert np.linalg.det(frame) == pytest.approx(1.0, abs=1e-14)
    e1, _ = perpendicular_basis(np.array([0.0, 0.0, 1.0]))
    np.testing.assert_array_equal(e1, [1.0, 0.0, 0.0])      # the first mesh axis most orthogonal to z
