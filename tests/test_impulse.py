"""Impulse at a point (exercise 4.6(c)): the cone struck at its apex."""

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool.errors import PhysicsError, UsageError
from inertia_tool.dynamics.impulse import apply_impulse
from inertia_tool.mass.properties import MassProperties, point_mass
from inertia_tool.integrals import second_moment_to_inertia, volume_moments

RADIUS, HEIGHT, DENSITY = 0.03, 0.08, 2700.0


def _analytic_cone():
    """Exercise 4.6(a, b): solid cone, base on z = 0, apex at z = h.

    COM h/4 above the base; about the COM: I_zz = 3MR²/10, I_xx = I_yy = 3M(R² + h²/4)/20 (from the apex
    value 3M(R²/4 + h²)/5 moved by the parallel-axis theorem over 3h/4).
    """
    mass = DENSITY * math.pi * RADIUS ** 2 * HEIGHT / 3
    ixx = 3 * mass * (RADIUS ** 2 + HEIGHT ** 2 / 4) / 20
    izz = 3 * mass * RADIUS ** 2 / 10
    return MassProperties(mass=mass, volume=mass / DENSITY, center_of_mass=[0, 0, HEIGHT / 4],
                          inertia=np.diag([ixx, ixx, izz]), density=DENSITY, name="cone")


def test_cone_exercise_4_6_ab_against_mesh():
    """The analytic cone agrees with the exact integration of a finely tessellated cone (O(1/n²) polygon error)."""
    mesh = trimesh.creation.cone(radius=RADIUS, height=HEIGHT, sections=512)
    vm = volume_moments(mesh.vertices, mesh.faces)
    cone = _analytic_cone()
    assert vm.volume == pytest.approx(cone.volume, rel=1e-4)
    np.testing.assert_allclose(vm.centroid, cone.center_of_mass, atol=1e-9)
    np.testing.assert_allclose(second_moment_to_inertia(vm.second_moment, DENSITY), cone.inertia,
                               rtol=2e-4, atol=1e-6 * cone.inertia.max())


def test_cone_hit_at_apex_exercise_4_6c():
    cone = _analytic_cone()
    omega0, push = 40.0, 0.02                       # rad/s about the symmetry axis; N·s along x
    apex = np.array([0.0, 0.0, HEIGHT])
    hit = apply_impulse(cone, [push, 0, 0], apex, angular_velocity=[0, 0, omega0])
    ixx, izz = cone.inertia[0, 0], cone.inertia[2, 2]
    np.testing.assert_allclose(hit.lever_arm, [0, 0, 0.75 * HEIGHT])
    np.testing.assert_allclose(hit.delta_velocity, [push / cone.mass, 0, 0], rtol=1e-14)
    # r × P = (0, 3hP/4, 0): the blow tips the cone about y
    np.testing.assert_allclose(hit.delta_angular_velocity, [0, 0.75 * HEIGHT * push / ixx, 0], rtol=1e-12)
    np.testing.assert_allclose(hit.angular_velocity, [0, 0.75 * HEIGHT * push / ixx, omega0], rtol=1e-12)
    np.testing.assert_allclose(hit.angular_momentum, [0, 0.75 * HEIGHT * push, izz * omega0], rtol=1e-12)
    # energy bookkeeping: only the new motion adds energy here (P ⟂ V0 = 0, r×P ⟂ ω0)
    expected_gain = push ** 2 / (2 * cone.mass) + (0.75 * HEIGHT * push) ** 2 / (2 * ixx)
    assert hit.energy_change == pytest.approx(expected_gain, rel=1e-12)
    assert hit.kinetic_energy == pytest.approx(expected_gain + 0.5 * izz * omega0 ** 2, rel=1e-12)


def _apex_path_closed_form(hit, t):
    """Free symmetric top: the symmetry axis precesses about the fixed L at |L|/I1, so the apex (on the axis)
    moves as R_cm + V t + Rot(L̂, |L| t / I1) r_apex."""
    big_l = hit.angular_momentum
    rate = np.linalg.norm(big_l) / hit.body.inertia[0, 0]
    rot = Rotation.from_rotvec(np.outer(rate * t, big_l / np.linalg.norm(big_l)))
    return hit.body.center_of_mass + np.outer(t, hit.velocity) + rot.apply(np.array(hit.lever_arm))


def test_position_of_follows_a_given_orientation_history():
    """position_of composes R_cm + V t + Q(t) r for any orientation history (here the closed form)."""
    cone = _analytic_cone()
    hit = apply_impulse(cone, [0.02, 0, 0], [0, 0, HEIGHT], angular_velocity=[0, 0, 40.0])
    t = np.linspace(0, 2.0, 201)
    rate = np.linalg.norm(hit.angular_momentum) / cone.inertia[0, 0]
    axis = hit.angular_momentum / np.linalg.norm(hit.angular_momentum)
    quat_xyzw = Rotation.from_rotvec(np.outer(rate * t, axis)).as_quat()

    class _History:                                   # just the field position_of reads
        orientation = np.roll(quat_xyzw, 1, axis=1)   # scalar-first

    np.testing.assert_allclose(hit.position_of([0, 0, HEIGHT], t, _History), _apex_path_closed_form(hit, t),
                               atol=1e-14)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=3, max_size=3), st.lists(st.floats(-0.05, 0.05), min_size=3, max_size=3),
       st.floats(-3, 3))
def test_line_of_action_invariance_and_linearity(impulse, point, slide):
    """Sliding the point along the line of action changes nothing; the response is linear in P."""
    cone = _analytic_cone()
    p = np.array(impulse)
    a = apply_impulse(cone, p, point)
    b = apply_impulse(cone, p, np.array(point) + slide * p)
    np.testing.assert_allclose(b.delta_angular_velocity, a.delta_angular_velocity, atol=1e-9)
    double = apply_impulse(cone, 2 * p, point)
    np.testing.assert_allclose(double.delta_angular_velocity, 2 * a.delta_angular_velocity, atol=1e-9)
    np.testing.assert_allclose(double.delta_velocity, 2 * a.delta_velocity, atol=1e-12)
    # the struck point's velocity jump equals the body's compliance applied to P: (1/M + [r]ᵀ I⁻¹ [r]) P
    r = np.asarray(point) - cone.center_of_mass
    jump = a.delta_velocity + np.cross(a.delta_angular_velocity, r)
    cross = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    compliance = np.eye(3) / cone.mass + cross.T @ np.linalg.inv(cone.inertia) @ cross
    np.testing.assert_allclose(jump, compliance @ p, atol=1e-9)


def test_impulse_through_com_only_translates():
    cone = _analytic_cone()
    hit = apply_impulse(cone, [0, 1.0, 0], cone.center_of_mass, velocity=[1.0, 0, 0])
    np.testing.assert_allclose(hit.delta_angular_velocity, 0.0, atol=1e-15)
    np.testing.assert_allclose(hit.velocity, [1.0, 1.0 / cone.mass, 0])


def test_bad_input():
    cone = _analytic_cone()
    with pytest.raises(UsageError):
        apply_impulse(cone, [1, 0], [0, 0, 0])
    with pytest.raises(UsageError):
        apply_impulse(cone, [1, 0, float("nan")], [0, 0, 0])
    with pytest.raises(PhysicsError):
        apply_impulse(point_mass(1.0, [0, 0, 0]), [1, 0, 0], [0, 0, 1])


@pytest.mark.parametrize("method", ["exact", "numerical"])
def test_cone_apex_path_after_the_blow_matches_free_precession(method):
    """Exercise 4.6(c): after the blow the apex circles the fixed L at |L|/I1 while the COM drifts at P/M.

    The simulated motion (inertia_tool.dynamics.simulation, closed form or numerical) composed by position_of
    must reproduce the closed form of the free symmetric top.
    """
    cone = _analytic_cone()
    hit = apply_impulse(cone, [0.02, 0, 0], [0, 0, HEIGHT], angular_velocity=[0, 0, 40.0])
    t = np.linspace(0, 1.5, 601)
    traj = hit.motion(t, method=method)
    np.testing.assert_allclose(traj.angular_momentum, np.tile(hit.angular_momentum, (len(t), 1)),
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(hit.position_of([0, 0, HEIGHT], t, traj), _apex_path_closed_form(hit, t),
                               atol=1e-9)
    # in the body, ω circles the symmetry axis at Ω = (I3 − I1)/I1 ω3 (§4.4.1) with ω3 fixed
    ixx, izz = cone.inertia[0, 0], cone.inertia[2, 2]
    big_omega = (izz - ixx) / ixx * 40.0
    w = traj.angular_velocity
    np.testing.assert_allclose(w[:, 2], 40.0, rtol=1e-9)
    transverse = hit.delta_angular_velocity[1]
    np.testing.assert_allclose(w[:, 0], -transverse * np.sin(big_omega * t), atol=1e-8 * abs(transverse) + 1e-12)
    np.testing.assert_allclose(w[:, 1], transverse * np.cos(big_omega * t), atol=1e-8 * abs(transverse) + 1e-12)
