"""Exact torque-free motion (LL §37, §4.4.1 of the chapter) against independent integrations and closed forms."""

import mpmath as mp
import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st
from scipy.integrate import quad, solve_ivp

from inertia_tool.dynamics.integrate import integrate_rigid_body
from inertia_tool.dynamics.torque_free import (ELLIPTIC_M1_FLOOR, free_body_parameters, precession_angle,
                                               torque_free_motion)
from inertia_tool.errors import UsageError
from inertia_tool.rotations import quaternion_to_matrix

from dynamics_reference import dop853

CASES = [
    ((1.0, 2.0, 3.0), (0.1, 1.0, 0.05), "elliptic"),      # M² < 2E I2: polhode around axis 1
    ((1.0, 2.0, 3.0), (-0.3, 0.5, -1.0), "elliptic"),     # M² > 2E I2: around axis 3, ω3 < 0
    ((1.0, 2.0, 3.0), (-0.9, -0.3, 0.2), "elliptic"),
    ((0.7, 1.5, 2.0), (0.4, -1.2, 0.3), "elliptic"),
    ((1.0, 1.0, 3.0), (0.3, 0.1, 1.0), "axisymmetric"),   # oblate
    ((1.0, 3.0, 3.0), (1.0, 0.1, 0.2), "axisymmetric"),   # prolate
    ((2.0, 2.0, 2.0), (1.0, 2.0, 3.0), "spherical"),
    ((1.0, 2.0, 3.0), (0.0, 1.5, 0.0), "principal-axis spin"),
]


@pytest.mark.parametrize("moments,w0,case", CASES)
def test_exact_matches_tight_dop853(moments, w0, case):
    t = np.linspace(0.0, 40.0, 161)
    q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
    w, q, used = torque_free_motion(moments, w0, t, orientation=q0)
    w_ref, q_ref, _ = dop853(np.diag(moments), w0, t, q0)
    assert used == case
    np.testing.assert_allclose(w, w_ref, atol=1e-11)
    np.testing.assert_allclose(quaternion_to_matrix(q), quaternion_to_matrix(q_ref), atol=1e-10)


def _lab_quantities(moments, w, q):
    i = np.asarray(moments)
    big_l = np.einsum("nij,nj->ni", quaternion_to_matrix(q), i * w)
    energy = 0.5 * np.sum(i * w * w, axis=1)
    return big_l, energy


@pytest.mark.parametrize("moments,w0,case", CASES[:6])
def test_invariants_conserved_to_round_off_over_1000_s(moments, w0, case):
    t = np.linspace(0.0, 1000.0, 2001)
    w, q, _ = torque_free_motion(moments, w0, t)
    big_l, energy = _lab_quantities(moments, w, q)
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-13
    mom = np.linalg.norm(big_l, axis=1)
    assert np.max(np.abs(mom / mom[0] - 1)) < 1e-13
    assert np.max(np.abs(big_l - big_l[0])) < 1e-11 * mom[0]   # the space vector L itself is fixed


def _mp_omega(moments, w0, t):
    """LL §37 closed form evaluated independently in mpmath (50 digits) for ω3 > 0 and moments labelled so
    that the polhode circles axis 3 (I = (I3, I2, I1) in the other regime, where ω2 = −b sn u)."""
    mp.mp.dps = 50
    i1, i2, i3 = (mp.mpf(x) for x in moments)
    w1, w2, w3 = (mp.mpf(x) for x in w0)
    e2 = i1 * w1 ** 2 + i2 * w2 ** 2 + i3 * w3 ** 2
    l2 = (i1 * w1) ** 2 + (i2 * w2) ** 2 + (i3 * w3) ** 2
    a = mp.sqrt((e2 * i3 - l2) / (i1 * (i3 - i1)))
    b = mp.sqrt((e2 * i3 - l2) / (i2 * (i3 - i2)))
    c = mp.sqrt((l2 - e2 * i1) / (i3 * (i3 - i1)))
    lam = mp.sqrt((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3))
    m = (i2 - i1) * (e2 * i3 - l2) / ((i3 - i2) * (l2 - e2 * i1))
    sigma = 1 if i3 > i2 else -1
    phi0 = mp.atan2(sigma * w2 / b, w1 / a)
    u0 = mp.ellipf(phi0, m)
    u = lam * mp.mpf(t) + u0
    return np.array([float(a * mp.ellipfun("cn", u, m=m)), float(sigma * b * mp.ellipfun("sn", u, m=m)),
                     float(c * mp.ellipfun("dn", u, m=m))])


def test_omega_at_t_1000_against_mpmath():
    """Target of issue 3: |ω(1000) − ω_ref| <= 1e-12 for I = (1, 2, 3), ω0 = (0.1, 1, 0.05).

    That ω0 has M² < 2E I2; relabel 1<->3 with ω2 -> -ω2 (a proper rotation) for the canonical mpmath form."""
    t = np.array([0.0, 1000.0])
    w, _, _ = torque_free_motion((1.0, 2.0, 3.0), (0.1, 1.0, 0.05), t)
    ref_relabelled = _mp_omega((3.0, 2.0, 1.0), (0.05, -1.0, 0.1), 1000.0)
    ref = np.array([ref_relabelled[2], -ref_relabelled[1], ref_relabelled[0]])
    assert np.max(np.abs(w[-1] - ref)) <= 1e-12


def test_omega_canonical_regime_at_t_1000_against_mpmath():
    t = np.array([0.0, 1000.0])
    w, _, _ = torque_free_motion((1.0, 2.0, 3.0), (0.3, 0.5, 1.0), t)
    assert np.max(np.abs(w[-1] - _mp_omega((1.0, 2.0, 3.0), (0.3, 0.5, 1.0), 1000.0))) <= 1e-12


def _psi_rate(moments, w, circled):
    others = [k for k in range(3) if k != circled]
    i = np.asarray(moments)
    mom = np.linalg.norm(i * w, axis=-1)
    num = sum(i[k] * w[..., k] ** 2 for k in others)
    den = sum((i[k] * w[..., k]) ** 2 for k in others)
    return mom * num / den


@pytest.mark.parametrize("moments,w0", [((1.0, 2.0, 3.0), (0.1, 1.0, 0.05)), ((1.0, 2.0, 3.0), (0.3, 0.5, 1.0)),
                                        ((0.7, 1.5, 2.0), (0.4, -1.2, 0.3))])
@pytest.mark.slow
def test_precession_angle_against_quadrature(moments, w0):
    params = free_body_parameters(moments, w0)
    rate = lambda s: _psi_rate(moments, torque_free_motion(moments, w0, np.array([0.0, s]))[0][-1],
                               params.circled_axis) if s > 0 else _psi_rate(moments, np.asarray(w0),
                                                                            params.circled_axis)
    for t_end in [0.7, 5.0, 23.0]:
        ref, _ = quad(rate, 0.0, t_end, limit=500, epsabs=1e-13, epsrel=1e-13)
        assert precession_angle(moments, w0, [0.0, t_end])[-1] == pytest.approx(ref, rel=1e-12)


def test_precession_quasi_periodic_accumulation_at_t_1000():
    """ψ(j P + r) = j ψ(P) + ψ(r): whole periods counted exactly; ψ(P) from quadrature over one period."""
    moments, w0 = (1.0, 2.0, 3.0), (0.1, 1.0, 0.05)
    params = free_body_parameters(moments, w0)
    period = params.period
    rate = lambda s: _psi_rate(moments, torque_free_motion(moments, w0, np.array([0.0, s]))[0][-1], 0) \
        if s > 0 else _psi_rate(moments, np.asarray(w0), 0)
    per_period = sum(quad(rate, k * period / 4, (k + 1) * period / 4, epsabs=1e-13, epsrel=1e-14)[0]
                     for k in range(4))
    whole = np.floor(1000.0 / period)
    rest = 1000.0 - whole * period
    rest_angle = quad(rate, 0.0, rest, limit=500, epsabs=1e-13, epsrel=1e-14)[0]
    expected = whole * per_period + rest_angle
    assert precession_angle(moments, w0, [0.0, 1000.0])[-1] == pytest.approx(expected, rel=1e-13)


@pytest.mark.slow
def test_orientation_at_t_1000_against_independent_integration():
    """Orientation target of issue 3 (1e-11).  The reference is a DOP853 integration of q̇ = ½ q⊗ω *driven by
    the exact ω(t)* (so only the kinematics is integrated), restarted at every period of ω from the exact
    closed form's ω and q... no: started once, with the tight tolerance; its own error is ~1e-12."""
    moments, w0 = (1.0, 2.0, 3.0), (0.1, 1.0, 0.05)
    t = np.linspace(0.0, 1000.0, 11)
    w, q, _ = torque_free_motion(moments, w0, t)
    _, q_ref, _ = dop853(np.diag(moments), w0, t, rtol=1e-14, atol=1e-16)
    assert np.max(np.abs(quaternion_to_matrix(q) - quaternion_to_matrix(q_ref))) < 1e-9


def test_symmetric_precession_rate_and_cones_section_4_4_1():
    """Ω = ω3 (I3 − I1)/I1; body cone tan φ_b = A/ω3; lab cone cos φ_L = 2T/(|ω||L|) (Eq. 4.28);
    herpolhode rate Ω_L = Ω sin φ_b / sin φ_L."""
    i1, i3 = 1.2, 2.0
    w0 = np.array([0.3, 0.4, 1.1])
    t = np.linspace(0.0, 20.0, 401)
    w, q, case = torque_free_motion((i1, i1, i3), w0, t)
    assert case == "axisymmetric"
    big_omega = w0[2] * (i3 - i1) / i1
    amp = np.hypot(w0[0], w0[1])
    expected = amp * np.exp(1j * (big_omega * t + np.arctan2(w0[1], w0[0])))
    np.testing.assert_allclose(w[:, 0] + 1j * w[:, 1], expected, atol=1e-13)
    np.testing.assert_allclose(w[:, 2], w0[2], atol=1e-15)
    phi_b = np.arctan2(np.hypot(w[:, 0], w[:, 1]), w[:, 2])
    np.testing.assert_allclose(phi_b, np.arctan(amp / w0[2]), atol=1e-14)
    big_l, energy = _lab_quantities((i1, i1, i3), w, q)
    w_space = np.einsum("nij,nj->ni", quaternion_to_matrix(q), w)
    cos_l = np.sum(w_space * big_l, axis=1) / (np.linalg.norm(w_space, axis=1) * np.linalg.norm(big_l, axis=1))
    eq_4_28 = 2 * energy / (np.linalg.norm(w, axis=1) * np.linalg.norm(big_l, axis=1))
    np.testing.assert_allclose(cos_l, eq_4_28, atol=1e-13)
    # herpolhode: angle of ω_space about L̂ grows at Ω_L
    n = big_l[0] / np.linalg.norm(big_l[0])
    e1 = np.cross(n, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    angle = np.unwrap(np.arctan2(w_space @ e2, w_space @ e1))
    phi_l = np.arccos(eq_4_28[0])
    omega_l = big_omega * np.sin(np.arctan(amp / w0[2])) / np.sin(phi_l)
    np.testing.assert_allclose(angle - angle[0], omega_l * t, atol=1e-11)


def test_dzhanibekov_flip_time_is_2K_over_lambda():
    """T-handle-like body spun about its intermediate axis: ω2 reverses every 2K(m)/λ (half period).

    λ² = (I3−I2)(M² − 2E I1)/(I1 I2 I3), m = (I2−I1)(2E I3 − M²)/((I3−I2)(M² − 2E I1)) for M² > 2E I2
    (relabel 1<->3 otherwise).  The crossings are found on an independent DOP853 integration."""
    moments = (1.0, 2.1, 2.9)
    w0 = (1e-3, 6.0, 2e-3)
    params = free_body_parameters(moments, w0)
    assert params.case == "elliptic" and params.parameter > 0.999
    i1, i2, i3 = moments
    w = np.asarray(w0)
    e2 = np.sum(np.asarray(moments) * w * w)
    l2 = np.sum((np.asarray(moments) * w) ** 2)
    if l2 > e2 * i2:
        lam = np.sqrt((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3))
    else:
        lam = np.sqrt((i2 - i1) * (e2 * i3 - l2) / (i1 * i2 * i3))
    assert params.rate == pytest.approx(lam, rel=1e-12)
    crossing = lambda t, y: y[1]
    from dynamics_reference import euler_quaternion_rhs
    sol = solve_ivp(euler_quaternion_rhs(np.diag(moments), None), (0, 4 * params.flip_time),
                    np.concatenate([w, [1, 0, 0, 0]]), method="DOP853", rtol=1e-13, atol=1e-14, events=crossing)
    times = sol.t_events[0]
    assert len(times) >= 3
    np.testing.assert_allclose(np.diff(times), params.flip_time, rtol=1e-8)
    # and the exact solution reverses ω2 at the same instants
    w_exact, _, _ = torque_free_motion(moments, w0, np.concatenate([[0.0], times]))
    np.testing.assert_allclose(w_exact[1:, 1], 0.0, atol=1e-6)  # |dω2/dt| ~ 25 rad/s² at the crossing


def test_separatrix_closed_form():
    """I = (3, 4, 6), ω1 = 2 ω3 puts M² = 2E I2 exactly: ω = (a sech, b tanh, c sech)."""
    moments, w0 = (3.0, 4.0, 6.0), (0.5, 0.75, 0.25)
    params = free_body_parameters(moments, w0)
    assert params.case == "separatrix" and params.complementary_parameter == 0.0
    t = np.linspace(0.0, 25.0, 126)
    w, q, case = torque_free_motion(moments, w0, t)
    assert case == "separatrix"
    w_ref, q_ref, _ = dop853(np.diag(moments), w0, t)
    np.testing.assert_allclose(w, w_ref, atol=1e-10)
    np.testing.assert_allclose(quaternion_to_matrix(q), quaternion_to_matrix(q_ref), atol=1e-9)
    # ω tends to the intermediate axis: ω2 -> b = sqrt((2E I3 − M²)/(I2 (I3 − I2)))
    i = np.asarray(moments)
    b = np.sqrt((np.sum(i * np.square(w0)) * i[2] - np.sum((i * w0) ** 2)) / (i[1] * (i[2] - i[1])))
    w_late, _, _ = torque_free_motion(moments, w0, [0.0, 200.0])
    assert w_late[-1, 1] == pytest.approx(b, rel=1e-14)
    assert abs(w_late[-1, 0]) < 1e-20


@pytest.mark.parametrize("eps", [1e-5, 1e-8, 1e-11])
def test_near_separatrix_m_close_to_one(eps):
    moments = (1.0, 2.0, 3.0)
    w0 = (eps, 1.0, eps)
    params = free_body_parameters(moments, w0)
    # (I3−I1)(M²−2E I2)/((I3−I2)(M²−2E I1))
    assert params.complementary_parameter == pytest.approx(2 * eps ** 2, rel=1e-6)
    t = np.linspace(0.0, min(2 * params.flip_time, 60.0), 121)
    w, q, _ = torque_free_motion(moments, w0, t)
    for k in (0, 37, 60, 103, 120):  # 50-digit evaluation of the closed form (DOP853 loses ~1/eps here)
        np.testing.assert_allclose(w[k], _mp_omega(moments, w0, t[k]), atol=1e-13)
    # a numerical reference loses ~1e-13/eps here (errors in ω1, ω3 are amplified relative to eps)
    w_ref, q_ref, _ = dop853(np.diag(moments), w0, t)
    np.testing.assert_allclose(w, w_ref, rtol=1e-10 / eps, atol=1e-13 / eps)
    np.testing.assert_allclose(quaternion_to_matrix(q), quaternion_to_matrix(q_ref), atol=1e-10 / eps)
    big_l, energy = _lab_quantities(moments, w, q)
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-14
    assert np.max(np.abs(big_l - big_l[0])) < 1e-13  # the orientation carries L exactly along the fixed L


@given(moments=st.lists(st.floats(0.2, 5.0), min_size=3, max_size=3),
       w0=st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3))
@settings(max_examples=40, deadline=None)
def test_exact_agrees_with_numerical_integrator(moments, w0):
    moments = np.sort(moments)
    params = free_body_parameters(moments, w0)
    assume(not (params.case == "elliptic" and params.complementary_parameter < ELLIPTIC_M1_FLOOR))
    t = np.linspace(0.0, 5.0, 11)
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    w, q, _ = torque_free_motion(moments, w0, t, orientation=q0)
    w_num, q_num = integrate_rigid_body(np.diag(moments), w0, q0, t, None, rtol=1e-13, atol=1e-13)
    scale = max(1.0, np.max(np.abs(w0)) * moments[2] / moments[0])
    np.testing.assert_allclose(w, w_num, atol=1e-9 * scale)
    np.testing.assert_allclose(quaternion_to_matrix(q), quaternion_to_matrix(q_num), atol=1e-8 * scale)


def test_bad_inputs():
    with pytest.raises(UsageError, match="ascending"):
        torque_free_motion((3.0, 2.0, 1.0), (1, 0, 0), [0, 1])
    with pytest.raises(UsageError, match="shape"):
        torque_free_motion((1.0, 2.0, 3.0), (1, 0), [0, 1])


@pytest.mark.parametrize("eps", [1e-6, 1e-10, 1e-14])
def test_auto_near_the_separatrix_keeps_the_orientation_accurate(eps):
    # found by hypothesis: spin about the intermediate axis with a 1e-14 nudge; the closed-form orientation
    # loses ~1/sqrt(1 - m) digits there, so auto must integrate numerically below ELLIPTIC_M1_FLOOR
    from inertia_tool import simulate
    moments, w0, t = np.array([1.0, 1.5, 2.0]), [0.0, 1.0, eps], np.linspace(0.0, 5.0, 11)
    traj = simulate(moments, w0, t)
    w_num, q_num = integrate_rigid_body(np.diag(moments), w0, np.array([1.0, 0, 0, 0]), t, None,
                                        rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(traj.rotation_matrices, quaternion_to_matrix(q_num), atol=1e-9)
    np.testing.assert_allclose(traj.angular_velocity, w_num, atol=1e-12)
