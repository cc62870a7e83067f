"""Splitting integrator (exact free flow + torque kicks): order, agreement with DOP853 and the heavy top,
unit quaternions, total-energy conservation, refusal of ω-dependent torques, exact output times."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import inertia_tool as it
from inertia_tool.dynamics.splitting import SCHEMES, integrate_splitting
from inertia_tool.errors import UsageError
from inertia_tool.dynamics.top import heavy_top, simulate_top
from inertia_tool.rotations import quaternion_to_matrix

from dynamics_reference import dop853

TENSOR = np.diag([1.0, 2.0, 3.0])
R_MESH = Rotation.from_euler("xyz", [0.3, -0.7, 1.1]).as_matrix()
TENSOR_MESH = R_MESH @ TENSOR @ R_MESH.T


def gravity_gradient(tensor, rate):
    """τ = 3 n² ẑ_b × (I ẑ_b) (body axes, ẑ_b = Qᵀ e_z) and its potential V = (3 n²/2) ẑ_bᵀ I ẑ_b."""
    k = 3.0 * rate ** 2

    def z_body(q):
        return quaternion_to_matrix(np.asarray(q))[..., 2, :]

    def torque(t, q, w):
        zb = z_body(q)
        return k * np.cross(zb, tensor @ zb)

    def potential(q):
        zb = z_body(q)
        return 0.5 * k * np.einsum("ni,ij,nj->n", zb, tensor, zb)

    return torque, potential


def max_error(w, q, w_ref, q_ref):
    return max(np.max(np.abs(w - w_ref)), np.max(np.abs(quaternion_to_matrix(q) - quaternion_to_matrix(q_ref))))


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_order_error_ratio_at_h_and_half_h(name):
    """Fixed steps h and h/2 against a tight DOP853: log2 of the error ratio is the order of Table 3 /
    Yoshida 1990 (Blanes & Moan 2002 for the SRKN schemes)."""
    torque, _ = gravity_gradient(TENSOR, 0.5)
    w0, t = np.array([0.1, 1.0, 0.05]), np.linspace(0.0, 4.0, 3)
    w_ref, q_ref, _ = dop853(TENSOR, w0, t, torque=torque, rtol=3e-14, atol=1e-16)
    scheme = SCHEMES[name]
    h = {2: 0.05, 4: 0.2, 6: 0.4}[scheme.order]
    errors = []
    for step in (h, h / 2):
        w, q, _ = integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], t, torque, scheme=name, step=step)
        errors.append(max_error(w, q, w_ref, q_ref))
    observed = np.log2(errors[0] / errors[1])
    assert errors[1] > 1e-12  # above the reference's own error
    assert abs(observed - scheme.order) < 0.35, (errors, observed)


def test_order_with_explicitly_time_dependent_torque():
    """Kicks at the stage times keep order 6 for τ(t, Q): a rotating space-frame torque."""
    def torque(t, q, w):
        space = np.array([0.3 * np.cos(0.7 * t), 0.2 * np.sin(1.3 * t), 0.1])
        return quaternion_to_matrix(q).T @ space

    w0, t = np.array([0.4, -0.3, 1.2]), np.linspace(0.0, 6.0, 4)
    w_ref, q_ref, _ = dop853(TENSOR, w0, t, torque=torque, rtol=3e-14, atol=1e-16)
    errors = [max_error(*integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], t, torque, step=s)[:2],
                        w_ref, q_ref) for s in (0.5, 0.25)]
    assert abs(np.log2(errors[0] / errors[1]) - 6) < 0.5, errors


def test_gravity_gradient_in_rotated_mesh_axes_agrees_with_dop853():
    torque, _ = gravity_gradient(TENSOR_MESH, 0.5)
    w0 = R_MESH @ np.array([0.1, 1.0, 0.05])
    q0 = np.roll(Rotation.from_rotvec([0.2, 0.1, -0.4]).as_quat(), 1)
    t = np.linspace(0.0, 20.0, 41)
    traj = it.simulate(TENSOR_MESH, w0, t, torque=torque, orientation=q0, torque_depends_on_angular_velocity=False)
    assert traj.method == "splitting:blanes-moan6"
    w_ref, q_ref, _ = dop853(TENSOR_MESH, w0, t, q0, torque=torque, rtol=3e-14, atol=1e-16)
    assert max_error(traj.angular_velocity, traj.orientation, w_ref, q_ref) < 1e-8
    tight = it.simulate(TENSOR_MESH, w0, t, torque=torque, orientation=q0, method="splitting",
                        torque_depends_on_angular_velocity=False, max_step=0.05)
    assert max_error(tight.angular_velocity, tight.orientation, w_ref, q_ref) < 1e-11


@pytest.mark.slow
def test_heavy_symmetric_top_agrees_with_heavy_top_simulation():
    """Top about its pivot (I1 = I2): τ_body = −M g l e3 × ẑ_b; θ(t) = acos(n_z) against heavy_top.simulate_top
    (vector form, DOP853), and the nutation period of the analytic report (Eqs. 4.36–4.40)."""
    i1, i3, mass, length, g = 0.02, 0.005, 0.5, 0.04, 9.80665
    top = heavy_top(i1, i3, mass, length, theta0=0.6, omega3=60.0, g=g)
    mgl = mass * g * length
    e3 = np.array([0.0, 0.0, 1.0])

    def torque(t, q, w):
        return -mgl * np.cross(e3, quaternion_to_matrix(q)[2, :])

    duration = 3.0 * top.nutation_period
    ref = simulate_top(top, duration, samples=121, rtol=1e-13, atol=1e-15)
    q0 = np.roll(Rotation.from_rotvec([0.0, 0.6, 0.0]).as_quat(), 1)
    traj = it.simulate([i1, i1, i3], [0.0, 0.0, 60.0], ref.t, torque=torque, orientation=q0,
                       torque_depends_on_angular_velocity=False, max_step=top.nutation_period / 40)
    axis = traj.rotation_matrices[:, :, 2]
    np.testing.assert_allclose(axis, ref.axis, atol=1e-9)
    theta = np.arccos(axis[:, 2])
    # θ returns to θ0 (its minimum, released at rest) after whole nutation periods
    fine_t = np.linspace(0.0, duration, 3001)
    fine = it.simulate([i1, i1, i3], [0.0, 0.0, 60.0], fine_t, torque=torque, orientation=q0,
                       torque_depends_on_angular_velocity=False)
    th = np.arccos(fine.rotation_matrices[:, 2, 2])
    minima = fine_t[1:-1][(th[1:-1] < th[:-2]) & (th[1:-1] <= th[2:])]
    assert np.allclose(np.diff(minima), top.nutation_period, rtol=2e-3)
    assert theta[0] == pytest.approx(0.6, abs=1e-15)


def test_quaternion_stays_unit_with_long_steps():
    torque, _ = gravity_gradient(TENSOR, 0.5)
    t = np.linspace(0.0, 500.0, 1001)
    w, q, _ = integrate_splitting([1, 2, 3], np.eye(3), [0.1, 1.0, 0.05], [1, 0, 0, 0], t, torque,
                                  scheme="strang", step=0.5)
    assert np.max(np.abs(np.linalg.norm(q, axis=1) - 1.0)) < 1e-14


@pytest.mark.slow
def test_total_energy_of_conservative_torque_bounded_and_of_method_order():
    """Symplectic: the total energy ½ω·Iω + V error oscillates without drift, and shrinks as h^p."""
    torque, potential = gravity_gradient(TENSOR, 0.5)
    w0 = np.array([0.1, 1.0, 0.05])
    t = np.linspace(0.0, 2000.0, 4001)

    def energy_error(scheme, step, times=t):
        w, q, _ = integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], times, torque, scheme=scheme,
                                      step=step)
        total = 0.5 * np.einsum("ni,ij,nj->n", w, TENSOR, w) + potential(q)
        return np.abs(total - total[0])

    err = energy_error("strang", 0.1)
    first, last = np.max(err[: len(t) // 10]), np.max(err[-len(t) // 10:])
    assert last < 2.0 * first  # no secular drift over 2000 s
    # the order is read on the first 400 samples only, so only those are integrated (fixed steps that divide
    # the sampling interval: bit for bit the first 400 rows of the 2000 s run)
    coarse = np.max(energy_error("blanes-moan4", 0.25, t[:400]))
    fine = np.max(energy_error("blanes-moan4", 0.125, t[:400]))
    assert 10.0 < coarse / fine < 25.0  # 2^4 = 16


def test_refuses_angular_velocity_dependent_torque():
    def damping(t, q, w):
        return -0.1 * np.asarray(w)

    with pytest.raises(UsageError, match="torque_depends_on_angular_velocity"):
        it.simulate([1, 2, 3], [0.1, 1, 0], [0, 1], torque=damping, method="splitting")
    with pytest.raises(UsageError, match="changed with ω"):
        it.simulate([1, 2, 3], [0.1, 1, 0], [0, 1], torque=damping, method="splitting",
                    torque_depends_on_angular_velocity=False)
    with pytest.raises(UsageError, match="scheme"):
        it.simulate([1, 2, 3], [0.1, 1, 0], [0, 1], method="splitting", scheme="leapfrog")
    assert it.simulate([1, 2, 3], [0.1, 1, 0], [0, 1], torque=damping).method == "numerical:gbs"


def test_outputs_exactly_at_requested_irregular_times():
    torque, _ = gravity_gradient(TENSOR_MESH, 0.3)
    w0 = R_MESH @ np.array([0.2, 0.9, -0.3])
    t = np.array([0.0, 0.1, 0.37, 2.0, 2.05, 9.3, 9.300001])
    traj = it.simulate(TENSOR_MESH, w0, t, torque=torque, method="splitting",
                       torque_depends_on_angular_velocity=False, max_step=0.1)
    assert np.array_equal(traj.t, t)
    w_ref, q_ref, _ = dop853(TENSOR_MESH, w0, t, torque=torque, rtol=3e-14, atol=1e-16)
    assert max_error(traj.angular_velocity, traj.orientation, w_ref, q_ref) < 1e-11


def test_without_torque_splitting_is_the_exact_flow():
    t = np.linspace(0.0, 50.0, 11)
    exact = it.simulate(TENSOR_MESH, [0.1, 1.0, 0.05], t)
    split = it.simulate(TENSOR_MESH, [0.1, 1.0, 0.05], t, method="splitting")
    assert split.method == "splitting:blanes-moan6"
    np.testing.assert_allclose(split.angular_velocity, exact.angular_velocity, atol=1e-12)
    np.testing.assert_allclose(split.rotation_matrices, exact.rotation_matrices, atol=1e-11)


def test_tighter_tolerance_gives_smaller_error_and_max_step_bounds_steps():
    torque, _ = gravity_gradient(TENSOR, 0.5)
    w0, t = np.array([0.1, 1.0, 0.05]), np.linspace(0.0, 10.0, 3)
    w_ref, q_ref, _ = dop853(TENSOR, w0, t, torque=torque, rtol=3e-14, atol=1e-16)
    errors = [max_error(*integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], t, torque, rtol=tol,
                                             atol=tol)[:2], w_ref, q_ref) for tol in (1e-6, 1e-12)]
    assert errors[1] < errors[0] / 100
    *_, steps = integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], t, torque, max_step=0.05,
                                    rtol=1.0, atol=1.0)
    assert steps >= 200
