"""The conventions of docs/conventions.md, each pinned by a test."""

import numpy as np
import pytest

from conftest import box_arrays
from inertia_tool import mass_properties
from inertia_tool.errors import UsageError
from inertia_tool.mass import point_mass
from inertia_tool.integrals import volume_moments
from conftest import assert_tensor_close


def test_off_diagonals_are_minus_integral_xy_dm():
    # two cubes in the first and third quadrants of the xy-plane: ∫xy dm > 0, so I_xy < 0
    a = box_arrays((1.0, 1.0, 1.0), center=(1.0, 1.0, 0.0))
    b = box_arrays((1.0, 1.0, 1.0), center=(-1.0, -1.0, 0.0))
    p = mass_properties((np.vstack([a[0], b[0]]), np.vstack([a[1], b[1] + 8])), density=1.0)
    integral_xy = 2 * 1.0 * (1.0 * 1.0)  # each unit cube: ∫xy dm = m x̄ ȳ = 1
    assert p.inertia[0, 1] == pytest.approx(-integral_xy, rel=1e-14)
    assert p.inertia[1, 0] == p.inertia[0, 1]
    # the raw second moment C = ∫ x xᵀ dV (about the origin) has C_xy = +∫xy dV and I = tr(C) 1 − C
    both = (np.vstack([a[0], b[0]]), np.vstack([a[1], b[1] + 8]))
    c = volume_moments(*both, origin=np.zeros(3)).second_moment
    assert c[0, 1] == pytest.approx(+integral_xy, rel=1e-14)
    assert_tensor_close(np.trace(c) * np.eye(3) - c, p.inertia_about([0, 0, 0]).tensor, rtol=1e-14)


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


# -- rotations (docs/conventions.md "Rotations") -----------------------------------------------------------

def _passive_rz(a):      # Eq. (4.29)
    return np.array([[np.cos(a), np.sin(a), 0.0], [-np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])


def _passive_ry(a):      # Eq. (4.30)
    return np.array([[np.cos(a), 0.0, -np.sin(a)], [0.0, 1.0, 0.0], [np.sin(a), 0.0, np.cos(a)]])


def test_euler_angles_are_z_y_z_and_map_space_to_body_eq_4_31():
    from inertia_tool.rotations import euler_to_matrix, matrix_to_euler
    phi, theta, psi = 0.3, 1.1, -0.7
    a = euler_to_matrix(phi, theta, psi)
    np.testing.assert_allclose(a, _passive_rz(psi) @ _passive_ry(theta) @ _passive_rz(phi), atol=1e-15)
    # a body turned by φ about z sees the space x axis at (cos φ, −sin φ, 0) in its own components
    np.testing.assert_allclose(euler_to_matrix(phi, 0.0, 0.0) @ [1.0, 0.0, 0.0], [np.cos(phi), -np.sin(phi), 0.0],
                               atol=1e-15)
    back = matrix_to_euler(a)
    np.testing.assert_allclose(back, [phi, theta, psi % (2 * np.pi)], atol=1e-13)


def test_quaternions_are_scalar_first_for_the_active_body_to_space_rotation():
    from inertia_tool.rotations import matrix_to_quaternion, quaternion_to_matrix
    q = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])        # +90° about z
    big_q = quaternion_to_matrix(q)
    np.testing.assert_allclose(big_q @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)   # body x → space y
    np.testing.assert_allclose(matrix_to_quaternion(big_q), q, atol=1e-15)
    np.testing.assert_allclose(matrix_to_quaternion(np.diag([-1.0, -1.0, 1.0])), [0.0, 0.0, 0.0, 1.0], atol=1e-15)
    with pytest.raises(UsageError, match="proper rotation"):
        matrix_to_quaternion(np.diag([1.0, 1.0, -1.0]))


def test_principal_axis_signs_largest_component_positive_and_axis_3_is_their_cross_product():
    v, f = box_arrays((1.0, 2.0, 3.0))
    rot = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])
    pa = mass_properties((v @ rot.T, f)).principal
    for k in (0, 1):
        axis = pa.axes[:, k]
        assert axis[np.argmax(np.abs(axis))] > 0
    np.testing.assert_allclose(pa.axes[:, 2], np.cross(pa.axes[:, 0], pa.axes[:, 1]), atol=1e-15)


def test_cad_positive_tensor_notation_flips_only_the_products():
    from inertia_tool.robot.inertial import positive_tensor_notation
    t = np.array([[3.0, -0.5, -0.25], [-0.5, 4.0, -0.125], [-0.25, -0.125, 5.0]])
    np.testing.assert_array_equal(positive_tensor_notation(t),
                                  [[3.0, 0.5, 0.25], [0.5, 4.0, 0.125], [0.25, 0.125, 5.0]])


def test_stability_classes_of_a_box_largest_and_smallest_stable_intermediate_unstable():
    from inertia_tool import stability
    v, f = box_arrays((1.0, 2.0, 3.0))
    report = stability(mass_properties((v, f)))
    assert list(report.kinds) == ["stable", "unstable", "stable"]
    c = [ax.coefficient for ax in report.axes]
    i1, i2, i3 = report.axes[0].moment, report.axes[1].moment, report.axes[2].moment
    # c = (I_i − I_k)(I_k − I_j)/(I_i I_j) for spin about k (§4.4.1), e.g. about the intermediate axis
    assert c[1] == pytest.approx((i1 - i2) * (i2 - i3) / (i1 * i3), rel=1e-12) and c[1] > 0


def test_shaft_frame_along_mesh_z_is_the_mesh_frame():
    from inertia_tool.balancing.rotor import shaft_frame
    frame = shaft_frame([0.0, 0.0, 0.0], [0.0, 0.0, 2.0])
    np.testing.assert_allclose(frame.axes, np.eye(3), atol=1e-15)
    tilted = shaft_frame([0.0, 0.0, 0.0], [1.0, 0.0, 1.0]).axes
    # x is the mesh axis most orthogonal to the shaft (y here), projected; y = z × x; angles run x → y
    np.testing.assert_allclose(tilted[:, 2], [2 ** -0.5, 0.0, 2 ** -0.5], atol=1e-15)
    np.testing.assert_allclose(tilted[:, 0], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(tilted[:, 1], np.cross(tilted[:, 2], tilted[:, 0]), atol=1e-15)
