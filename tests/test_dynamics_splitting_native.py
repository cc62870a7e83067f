"""The splitting integrator's two paths: the C kernel ``_accel.split_steps`` and the pure-Python
``splitting._python_steps`` (with ``free_flow.free_flow_step``).  They agree to round-off with each other, and
each agrees with closed forms: the torque-free body (Landau–Lifshitz §37, ``torque_free_motion``) and the heavy
top's cos θ(t) through Weierstrass' ℘ (Chapter 4, "Rigid Body Motion", exercise 4.10)."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import inertia_tool as it
from inertia_tool.dynamics.free_flow import NEAR_SEPARATRIX_M1, free_flow_step
from inertia_tool.dynamics.splitting import SCHEMES, integrate_splitting
from inertia_tool.dynamics.top import heavy_top
from inertia_tool.dynamics.top_motion import top_cos_theta
from inertia_tool.dynamics.torque_free import NEGLIGIBLE_COMPONENT, torque_free_motion
from inertia_tool.errors import NonFiniteResultError, UsageError
from inertia_tool.rotations import quaternion_to_matrix

from conftest import HAVE_ACCEL, REQUIRE_ACCEL

needs_accel = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")

R_MESH = Rotation.from_euler("xyz", [0.3, -0.7, 1.1]).as_matrix()
TENSOR_MESH = R_MESH @ np.diag([1.0, 2.0, 3.0]) @ R_MESH.T


def gravity_gradient(tensor, rate):
    """τ = 3 n² ẑ_b × (I ẑ_b), body axes, ẑ_b = Qᵀ e_z (numpy, as a user writes it)."""
    def torque(t, q, w):
        zb = quaternion_to_matrix(np.asarray(q))[2, :]
        return 3.0 * rate ** 2 * np.cross(zb, tensor @ zb)
    return torque


def c_free_flow(moments, w, q, h):
    """One exact free flow of the C kernel: a one-drift composition without kicks or torque."""
    from inertia_tool import _accel
    w1, q1, _ = _accel.split_steps(tuple(moments), (1.0,), (0.0, 0.0), tuple(w), tuple(q), (0.0, 0.0, 0.0), 0.0,
                                   h, 1, None, None, np.zeros(4), np.zeros(3), NEGLIGIBLE_COMPONENT,
                                   NEAR_SEPARATRIX_M1, free_flow_step)
    return np.array(w1), np.array(q1)


def both_paths(monkeypatch, run):
    """``run()`` on the C kernel and on the pure-Python path."""
    monkeypatch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
    compiled = run()
    monkeypatch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
    python = run()
    monkeypatch.delenv("INERTIA_TOOL_NO_ACCEL")
    return compiled, python


@needs_accel
@pytest.mark.parametrize("moments", [(1.0, 2.0, 3.0), (0.3, 2.5, 2.6), (0.02, 0.02, 0.005), (1.0, 3.0, 3.0),
                                     (2.0, 2.0, 2.0), (1.0, 1.0001, 5.0)])
def test_c_free_flow_equals_free_flow_step(moments):
    """Asymmetric (both polhode families), both symmetric kinds, spherical, nearly symmetric; steps of either
    sign up to many periods: the C closed form (own AGM and Carlson R_F, R_J) against the Python one (scipy's
    ellipj, elliprf, elliprj), error relative to |ω| and to the angle turned."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        w = rng.normal(size=3) * rng.choice([1e-3, 1.0, 100.0])
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        h = float(rng.normal() * rng.choice([0.01, 1.0, 30.0]))
        w_c, q_c = c_free_flow(moments, w, q, h)
        w_p, q_p = free_flow_step(moments, w, q, h)
        q_p = np.array(q_p) / np.linalg.norm(q_p)
        scale = max(1.0, float(np.linalg.norm(w)) * abs(h))
        assert np.max(np.abs(w_c - w_p)) <= 1e-13 * scale * np.max(np.abs(w))
        assert np.max(np.abs(q_c - q_p)) <= 1e-13 * scale


@needs_accel
def test_c_free_flow_steady_spin_and_separatrix_fallback():
    """A spin about one principal axis is a plain rotation; a state on the separatrix (2 E I2 = |L|², here
    ω = (√3 c, ε, c) for I = (1, 2, 3)) goes to the Python fallback and gives its result exactly."""
    w_c, q_c = c_free_flow((1.0, 2.0, 3.0), (0.0, 0.0, 2.0), (1.0, 0.0, 0.0, 0.0), 0.3)
    assert np.array_equal(w_c, [0.0, 0.0, 2.0])
    np.testing.assert_allclose(q_c, [math.cos(0.3), 0.0, 0.0, math.sin(0.3)], atol=1e-16)
    w0, q0 = (math.sqrt(3.0) * 0.5, 1e-12, 0.5), (1.0, 0.0, 0.0, 0.0)
    w_c, q_c = c_free_flow((1.0, 2.0, 3.0), w0, q0, 0.7)
    w_p, q_p = free_flow_step((1.0, 2.0, 3.0), w0, q0, 0.7)
    np.testing.assert_allclose(w_c, w_p, rtol=0, atol=1e-15)
    np.testing.assert_allclose(q_c, np.array(q_p) / np.linalg.norm(q_p), rtol=0, atol=1e-15)


@needs_accel
@pytest.mark.parametrize("scheme", ["blanes-moan6", "yoshida4"])
def test_c_and_python_integrations_agree_to_round_off(monkeypatch, scheme):
    """Gravity gradient in rotated mesh axes (frame change in C) with a time-dependent factor, fixed and
    error-controlled steps: the two paths agree to round-off and take the same number of steps."""
    base = gravity_gradient(TENSOR_MESH, 0.5)

    def torque(t, q, w):
        return (1.0 + 0.3 * math.sin(0.7 * t)) * base(t, q, w)

    w0 = R_MESH @ np.array([0.2, 0.9, -0.3])
    q0 = np.array([0.9, 0.1, -0.3, 0.2])
    t = np.array([0.0, 0.4, 1.3, 3.0, 5.0])
    for kwargs in (dict(step=0.1), dict(rtol=1e-10, atol=1e-10)):
        (w_c, q_c, n_c), (w_p, q_p, n_p) = both_paths(
            monkeypatch, lambda: integrate_splitting([1, 2, 3], R_MESH, w0, q0, t, torque, scheme=scheme,
                                                     **kwargs))
        assert n_c == n_p
        np.testing.assert_allclose(w_c, w_p, rtol=0, atol=1e-13)
        np.testing.assert_allclose(q_c, q_p, rtol=0, atol=1e-13)


def test_torque_free_splitting_is_the_closed_form(engine_path):
    """Without torque every step is the exact flow: many steps of either sign (Blanes–Moan drifts include
    negative ones) reproduce torque_free_motion (Landau–Lifshitz §37) on both paths."""
    moments, w0 = np.array([1.0, 2.0, 3.0]), np.array([0.3, 0.2, 1.0])
    q0 = np.array([0.8, 0.2, -0.4, 0.4]) / np.linalg.norm([0.8, 0.2, -0.4, 0.4])
    t = np.linspace(0.0, 20.0, 21)
    w_ref, q_ref, _ = torque_free_motion(moments, w0, t, orientation=q0)
    w, q, _ = integrate_splitting(moments, np.eye(3), w0, q0, t, None, step=0.25)  # 880 exact flows
    np.testing.assert_allclose(w, w_ref, rtol=0, atol=5e-13)
    np.testing.assert_allclose(quaternion_to_matrix(q), quaternion_to_matrix(q_ref), rtol=0, atol=1e-12)


def test_heavy_top_cos_theta_against_weierstrass_exercise_4_10(engine_path):
    """Heavy symmetric top released at rest (cusps, §4.4.3): cos θ(t) of the splitting against the closed
    form u(t) = c + (4/β) ℘(t − ω3) of exercise 4.10, shifted by half a nutation period (θ0 = θ_min)."""
    i1, i3, mass, length, g, theta0, omega3 = 0.02, 0.005, 0.5, 0.04, 9.80665, 0.6, 30.0
    top = heavy_top(i1, i3, mass, length, theta0=theta0, omega3=omega3, g=g)
    mgl = mass * g * length

    def torque(t, q, w):
        zb = quaternion_to_matrix(np.asarray(q))[2, :]
        return -mgl * np.cross([0.0, 0.0, 1.0], zb)

    period = top.nutation_period
    t = np.linspace(0.0, 3.0 * period, 61)
    q0 = np.array([math.cos(0.5 * theta0), 0.0, math.sin(0.5 * theta0), 0.0])
    traj = it.simulate([i1, i1, i3], [0.0, 0.0, omega3], t, torque=torque, orientation=q0,
                       torque_depends_on_angular_velocity=False, max_step=period / 40)
    cos_theta = traj.rotation_matrices[:, 2, 2]
    u = top_cos_theta(top, t + 0.5 * period)
    assert np.max(np.abs(cos_theta - u)) < 1e-11
    assert np.ptp(cos_theta) > 0.2  # a real nutation, not a steady precession


@pytest.mark.parametrize("form", ["list", "float32", "strided", "tuple"])
def test_torque_results_of_any_sequence_form_agree(engine_path, form):
    """The torque may return a list, a float32 array, a strided view or a tuple; the result does not change
    (the C kernel reads float64 buffers directly and everything else as a sequence)."""
    base = gravity_gradient(np.diag([1.0, 2.0, 3.0]), 0.5)
    convert = {"list": lambda v: v.tolist(), "float32": lambda v: v.astype(np.float32),
               "strided": lambda v: np.repeat(v, 2)[::2], "tuple": lambda v: tuple(v.tolist())}[form]

    def torque(t, q, w):
        return convert(base(t, q, w))

    def reference(t, q, w):  # the same numbers as a contiguous float64 array
        return np.asarray(convert(base(t, q, w)), dtype=np.float64)

    w0, t = np.array([0.1, 1.0, 0.05]), np.linspace(0.0, 2.0, 3)
    w_ref, q_ref, _ = integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], t, reference, step=0.1)
    w, q, _ = integrate_splitting([1, 2, 3], np.eye(3), w0, [1, 0, 0, 0], t, torque, step=0.1)
    assert np.array_equal(w, w_ref) and np.array_equal(q, q_ref)


def test_torque_sees_unchanged_arrays_and_errors_propagate(engine_path):
    """Arguments a torque keeps are never overwritten later (the C kernel reuses an argument array only when
    nobody else holds it); an exception raised by the torque reaches the caller; a torque of the wrong shape
    is refused before integrating."""
    kept = []

    def keeping(t, q, w):
        kept.append((q, q.copy(), w[1:], w[1:].copy()))
        return np.array([0.01 * q[1], 0.0, -0.02 * q[3]])

    it.simulate([1, 2, 3], [0.1, 1, 0.05], np.linspace(0.0, 1.0, 3), torque=keeping,
                torque_depends_on_angular_velocity=False, max_step=0.1)
    assert len(kept) > 100
    assert all(np.array_equal(q, q_copy) and np.array_equal(w, w_copy) for q, q_copy, w, w_copy in kept)

    calls = []

    def failing(t, q, w):
        calls.append(t)
        if len(calls) > 30:
            raise RuntimeError("sensor offline")
        return np.zeros(3)

    with pytest.raises(RuntimeError, match="sensor offline"):
        it.simulate([1, 2, 3], [0.1, 1, 0.05], [0.0, 5.0], torque=failing, torque_depends_on_angular_velocity=False)
    with pytest.raises(UsageError, match=r"shape \(3,\)"):
        it.simulate([1, 2, 3], [0.1, 1, 0.05], [0.0, 5.0], torque=lambda t, q, w: np.zeros(4),
                    torque_depends_on_angular_velocity=False)


@pytest.mark.parametrize("bad_call", [0, 40])
def test_non_finite_torque_is_refused(engine_path, bad_call):
    """A torque that returns NaN (at the start or after 40 calls) stops the integration with
    NonFiniteResultError instead of returning NaN states."""
    calls = []

    def torque(t, q, w):
        calls.append(t)
        return np.array([np.nan if len(calls) > bad_call else 0.01, 0.0, 0.0])

    with pytest.raises(NonFiniteResultError, match="not finite"):
        integrate_splitting([1, 2, 3], np.eye(3), [0.1, 1.0, 0.05], [1, 0, 0, 0], [0.0, 5.0], torque, step=0.1)


def test_every_scheme_runs_on_both_paths(engine_path):
    """Each composition (Strang, Yoshida, Blanes–Moan) conserves |q| and reaches the end time."""
    torque = gravity_gradient(np.diag([1.0, 2.0, 3.0]), 0.2)
    for name in SCHEMES:
        w, q, steps = integrate_splitting([1, 2, 3], np.eye(3), [0.1, 1.0, 0.05], [1, 0, 0, 0], [0.0, 1.0],
                                          torque, scheme=name, step=0.05)
        assert steps == 20
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
