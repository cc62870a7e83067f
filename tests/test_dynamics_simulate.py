"""simulate(): frames, body arguments, exact vs numerical routes, torque-driven closed forms."""

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson
from scipy.spatial.transform import Rotation

import inertia_tool as it
from inertia_tool.errors import UsageError
from inertia_tool.rotations import quaternion_to_matrix

from dynamics_reference import dop853

TENSOR_PRINCIPAL = np.diag([1.0, 2.0, 3.0])
R_MESH = Rotation.from_euler("xyz", [0.3, -0.7, 1.1]).as_matrix()
TENSOR_MESH = R_MESH @ TENSOR_PRINCIPAL @ R_MESH.T


def test_mesh_axes_round_trip_against_dop853_in_mesh_axes():
    w0 = R_MESH @ np.array([0.1, 1.0, 0.05])
    q0 = np.roll(Rotation.from_rotvec([0.2, 0.1, -0.4]).as_quat(), 1)
    t = np.linspace(0.0, 30.0, 61)
    traj = it.simulate(TENSOR_MESH, w0, t, orientation=q0)
    w_ref, q_ref, _ = dop853(TENSOR_MESH, w0, t, q0)
    assert traj.method == "exact:elliptic"
    np.testing.assert_allclose(traj.angular_velocity, w_ref, atol=1e-11)
    np.testing.assert_allclose(traj.rotation_matrices, quaternion_to_matrix(q_ref), atol=1e-10)
    np.testing.assert_allclose(traj.angular_momentum, np.broadcast_to(traj.angular_momentum[0], (61, 3)), atol=1e-13)
    np.testing.assert_allclose(traj.energy, 0.5 * w0 @ TENSOR_MESH @ w0, rtol=1e-14)
    assert np.all(traj.orientation[:, 0] >= 0)


def test_body_argument_forms_agree():
    t = np.linspace(0, 5, 6)
    w0 = [0.3, -0.2, 0.9]
    a = it.simulate([2.0, 1.0, 3.0], w0, t)
    b = it.simulate(np.diag([2.0, 1.0, 3.0]), w0, t)
    c = it.simulate(it.mass.principal_axes(np.diag([2.0, 1.0, 3.0])), w0, t)
    for other in (b, c):
        np.testing.assert_allclose(other.angular_velocity, a.angular_velocity, atol=1e-13)
        np.testing.assert_allclose(other.rotation_matrices, a.rotation_matrices, atol=1e-13)
    np.testing.assert_allclose(a.moments, [1.0, 2.0, 3.0])


def test_mass_properties_body_uses_principal():
    props = it.mass.point_mass(2.0, [0.5, 0.0, 0.0]) + it.mass.point_mass(2.0, [-0.5, 0.0, 0.0]) \
        + it.mass.point_mass(1.0, [0.0, 0.7, 0.0]) + it.mass.point_mass(1.0, [0.0, -0.7, 0.3])
    traj = it.simulate(props, [0.2, 0.3, 1.0], np.linspace(0, 3, 4))
    np.testing.assert_allclose(traj.tensor, props.inertia if hasattr(props.inertia, "shape") else
                               np.asarray(props.inertia), atol=1e-12)
    np.testing.assert_allclose(traj.moments, props.principal.moments)


def test_numerical_without_torque_matches_exact():
    t = np.linspace(0.0, 50.0, 26)
    w0 = R_MESH @ np.array([0.4, -0.8, 0.3])
    exact = it.simulate(TENSOR_MESH, w0, t)
    num = it.simulate(TENSOR_MESH, w0, t, method="numerical")
    assert num.method == "numerical:gbs"
    np.testing.assert_allclose(num.angular_velocity, exact.angular_velocity, atol=1e-9)
    np.testing.assert_allclose(num.rotation_matrices, exact.rotation_matrices, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(num.orientation, axis=1), 1.0, atol=1e-15)


def test_constant_torque_along_spin_of_sphere_closed_form():
    """Sphere, τ ∥ ω: ω(t) = ω0 + τ t / I, turned angle ω0 t + τ t² / (2I) about the fixed axis."""
    inertia, tau, w0 = 2.5, 0.4, 1.3
    axis = np.array([1.0, 2.0, -2.0]) / 3.0
    t = np.linspace(0.0, 10.0, 21)
    traj = it.simulate([inertia] * 3, w0 * axis, t, torque=lambda t, q, w: tau * axis)
    np.testing.assert_allclose(traj.angular_velocity, np.outer(w0 + tau * t / inertia, axis), atol=1e-12)
    angle = w0 * t + 0.5 * tau * t * t / inertia
    expected = Rotation.from_rotvec(np.outer(angle, axis)).as_matrix()
    np.testing.assert_allclose(traj.rotation_matrices, expected, atol=1e-11)


@pytest.mark.slow
def test_gravity_gradient_torque_against_dop853_and_work_energy():
    """Orientation-dependent torque (space-fixed field expressed in body axes); dT/dt = ω·τ (§4.4.1)."""
    def torque(t, q, w):
        zb = quaternion_to_matrix(q).T @ np.array([0.0, 0.0, 1.0])
        return 0.75 * np.cross(zb, TENSOR_MESH @ zb)
    w0 = np.array([0.2, 0.9, -0.3])
    t = np.linspace(0.0, 20.0, 41)
    traj = it.simulate(TENSOR_MESH, w0, t, torque=torque)
    w_ref, q_ref, _ = dop853(TENSOR_MESH, w0, t, torque=torque)
    np.testing.assert_allclose(traj.angular_velocity, w_ref, atol=1e-9)
    np.testing.assert_allclose(traj.rotation_matrices, quaternion_to_matrix(q_ref), atol=1e-9)
    # work-energy on the first 5 s at the same spacing (the 20 s run is checked against DOP853 above): 0.14 J of
    # the whole run's 0.16 J energy swing happens there, and the largest misfit (1.0e-10) is the same as on 20 s
    fine = np.linspace(0.0, 5.0, 1001)
    tr = it.simulate(TENSOR_MESH, w0, fine, torque=torque)
    power = np.array([w @ torque(s, q, w) for s, q, w in zip(fine, tr.orientation, tr.angular_velocity)])
    np.testing.assert_allclose(tr.energy - tr.energy[0], cumulative_simpson(power, x=fine, initial=0.0),
                               atol=1e-9)


def test_usage_errors():
    with pytest.raises(UsageError, match="method"):
        it.simulate([1, 2, 3], [0, 0, 1], [0, 1], method="rk4")
    with pytest.raises(UsageError, match="exact"):
        it.simulate([1, 2, 3], [0, 0, 1], [0, 1], method="exact", torque=lambda t, q, w: np.zeros(3))
    with pytest.raises(UsageError, match="increasing"):
        it.simulate([1, 2, 3], [0, 0, 1], [0, 2, 1])
    with pytest.raises(UsageError, match="unit quaternion"):
        it.simulate([1, 2, 3], [0, 0, 1], [0, 1], orientation=[2, 0, 0, 0])
    with pytest.raises(UsageError, match="shape"):
        it.simulate(np.ones((2, 2)), [0, 0, 1], [0, 1])
    with pytest.raises(ValueError):  # UsageError is also a ValueError
        it.simulate([1, 2, 3], [0, 1], [0, 1])
