"""Heavy symmetric top (§4.4.3): closed forms vs quadrature vs an independent vector-form integration."""

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from inertia_tool.errors import AsymmetricTopWarning, PhysicsError, UsageError
from inertia_tool.dynamics.top import heavy_top, heavy_top_on_pivot
from inertia_tool.mass.properties import MassProperties

# a toy top: I1 about the pivot, I3 axial, 0.5 kg with its centre of mass 4 cm above the tip
I1, I3, M, L = 1.2e-3, 6.0e-4, 0.5, 0.04


def _period_by_quadrature(top):
    """2 ∫ du/√f between the roots, with u = u_X + (u_N − u_X) sin² s removing both end singularities."""
    u_x, u_n, _ = top.roots

    def integrand(s):
        u = u_x + (u_n - u_x) * math.sin(s) ** 2
        du = 2.0 * (u_n - u_x) * math.sin(s) * math.cos(s)
        val = top.f(u)
        return du / math.sqrt(val) if val > 0 else 0.0
    value, _ = quad(integrand, 0.0, math.pi / 2, epsabs=0, epsrel=1e-10, limit=200)
    return 2.0 * value


def _upward_crossings(t, y, level):
    idx = np.nonzero((y[:-1] < level) & (y[1:] >= level))[0]
    return t[idx] - (y[idx] - level) * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])


def _check_against_simulation(top, periods=4, samples_per_period=4000):
    traj = top.simulate(periods * top.nutation_period, samples=periods * samples_per_period + 1)
    span = top.theta_max - top.theta_min
    # stays within [θmin, θmax] ...
    assert traj.theta.min() >= top.theta_min - 1e-7
    assert traj.theta.max() <= top.theta_max + 1e-7
    # ... and touches both
    assert traj.theta.min() == pytest.approx(top.theta_min, abs=1e-5 * max(span, 1e-3) + 1e-8)
    assert traj.theta.max() == pytest.approx(top.theta_max, abs=1e-5 * max(span, 1e-3) + 1e-8)
    crossings = _upward_crossings(traj.t, traj.theta, 0.5 * (top.theta_min + top.theta_max))
    assert len(crossings) >= periods - 1
    assert np.diff(crossings).mean() == pytest.approx(top.nutation_period, rel=1e-5)
    # conserved quantities of the vector-form integration: energy, L·ẑ = I1 b
    assert np.ptp(traj.energy) <= 1e-8 * abs(traj.energy).max()
    np.testing.assert_allclose(traj.angular_momentum[:, 2], top.transverse_moment * top.b, rtol=1e-8, atol=1e-12)
    return traj


def test_cusp_when_released_from_rest_fig_4_3c():
    top = heavy_top(I1, I3, M, L, theta0=math.radians(30), omega3=2 * math.pi * 40)
    assert top.precession_kind == "cusp"
    assert top.theta_min == pytest.approx(math.radians(30), abs=1e-12)    # released at the top of the cusp
    assert top.theta_max > top.theta_min
    assert top.nutation_period == pytest.approx(_period_by_quadrature(top), rel=1e-8)
    traj = _check_against_simulation(top)
    # at the cusps (θ = θmin) the precession momentarily stops; it always moves forward otherwise
    assert np.all(np.diff(traj.phi) >= -1e-9)


def test_looping_fig_4_3a_and_undulating_fig_4_3b():
    slow = heavy_top(I1, I3, M, L, theta0=math.radians(50), omega3=2 * math.pi * 40).precession_rate_slow
    looping = heavy_top(I1, I3, M, L, theta0=math.radians(50), omega3=2 * math.pi * 40, phi_dot0=-2 * slow)
    undulating = heavy_top(I1, I3, M, L, theta0=math.radians(50), omega3=2 * math.pi * 40, phi_dot0=0.5 * slow)
    assert looping.precession_kind == "looping"
    assert undulating.precession_kind == "undulating"
    u_x, u_n, _ = looping.roots
    assert u_x < looping.precession_zero_u < u_n
    for top in (looping, undulating):
        assert top.nutation_period == pytest.approx(_period_by_quadrature(top), rel=1e-8)
        traj = _check_against_simulation(top)
        phidot = np.gradient(traj.phi, traj.t)
        if top is looping:
            assert phidot.min() < 0 < phidot.max()       # the precession reverses: loops
        else:
            assert phidot.min() > 0                      # always forward, speeding up and slowing down


def test_moving_start_uses_bracketed_roots():
    """θ̇0 ≠ 0: the start is not a turning point; roots come from bracketing, f(roots) = 0."""
    top = heavy_top(I1, I3, M, L, theta0=math.radians(40), omega3=2 * math.pi * 30, theta_dot0=2.0, phi_dot0=1.0)
    u_x, u_n, u_u = top.roots
    assert u_x < math.cos(math.radians(40)) < u_n < 1 <= u_u
    np.testing.assert_allclose(top.f(np.array(top.roots)), 0.0, atol=1e-9 * top.alpha)
    assert top.nutation_period == pytest.approx(_period_by_quadrature(top), rel=1e-8)
    _check_against_simulation(top)


def test_steady_precession_rates():
    theta = math.radians(25)
    omega3 = 2 * math.pi * 30
    top = heavy_top(I1, I3, M, L, theta0=theta, omega3=omega3)
    mgl = M * 9.80665 * L
    for rate in (top.precession_rate_slow, top.precession_rate_fast):
        assert I1 * math.cos(theta) * rate ** 2 - I3 * omega3 * rate + mgl == pytest.approx(0.0, abs=1e-12 * mgl)
    assert abs(top.precession_rate_slow) < abs(top.precession_rate_fast)
    # gyroscopic limit: slow precession ≈ M g l / (I3 ω3)
    assert top.precession_rate_slow == pytest.approx(mgl / (I3 * omega3), rel=0.05)
    for rate in (top.precession_rate_slow, top.precession_rate_fast):
        steady = heavy_top(I1, I3, M, L, theta0=theta, omega3=omega3, phi_dot0=rate)
        assert steady.precession_kind == "steady"
        assert steady.theta_max - steady.theta_min < 1e-6
        traj = steady.simulate(0.5, samples=2001)
        assert np.ptp(traj.theta) < 1e-6
        assert np.gradient(traj.phi, traj.t)[5:-5] == pytest.approx(rate, rel=1e-5)
    # too little spin for steady precession of an upright-ish top
    assert heavy_top(I1, I3, M, L, theta0=theta, omega3=1.0).precession_rate_slow is None


def test_sleeping_top_criterion():
    """Upright top: stable iff I3² ω3² > 4 I1 M g l (§4.4.3)."""
    mgl = M * 9.80665 * L
    critical = math.sqrt(4 * I1 * mgl) / I3
    fast = heavy_top(I1, I3, M, L, theta0=0.0, omega3=1.2 * critical)
    slow = heavy_top(I1, I3, M, L, theta0=0.0, omega3=0.8 * critical)
    assert fast.sleeping_stable and not slow.sleeping_stable
    assert fast.sleeping_margin == pytest.approx(1.44) and slow.sleeping_margin == pytest.approx(0.64)
    assert fast.theta_min == fast.theta_max == 0.0
    assert slow.theta_min == 0.0
    assert slow.theta_max == pytest.approx(math.acos(slow.a ** 2 / slow.beta - 1))    # third root a²/β − 1
    assert math.isinf(slow.nutation_period)                    # it creeps off the unstable equilibrium
    # a slightly tilted top: stays within a small cone when sleeping-stable, falls far otherwise
    tilt = 1e-3
    near_fast = heavy_top(I1, I3, M, L, theta0=tilt, omega3=1.2 * critical)
    near_slow = heavy_top(I1, I3, M, L, theta0=tilt, omega3=0.8 * critical)
    assert near_fast.theta_max < 5 * tilt
    assert near_slow.theta_max == pytest.approx(slow.theta_max, rel=1e-3)
    _check_against_simulation(near_fast)
    _check_against_simulation(near_slow, periods=2)
    # small-nutation period of the sleeping top, 2π/√(a² − 2β), is the limit of the tilted one
    assert fast.nutation_period == pytest.approx(2 * math.pi / math.sqrt(fast.a ** 2 - 2 * fast.beta), rel=1e-12)
    assert near_fast.nutation_period == pytest.approx(fast.nutation_period, rel=1e-4)


def test_without_gravity_reduces_to_free_symmetric_top():
    top = heavy_top(I1, I3, M, L, theta0=math.radians(20), omega3=50.0, phi_dot0=3.0, g=0.0)
    assert math.isinf(top.roots[2])
    assert top.nutation_period == pytest.approx(2 * math.pi / math.sqrt(top.alpha + top.a ** 2), rel=1e-12)
    _check_against_simulation(top)


def _independent_euler_lagrange(top, duration, t_eval):
    """θ(t) from the chapter's θ equation with a, b conserved (Eqs. 4.36–4.38), integrated by scipy."""
    i1, mgl, a, b = top.transverse_moment, top.mass * top.gravity * top.length, top.a, top.b

    def rhs(_t, y):
        th, thd = y
        s, c = math.sin(th), math.cos(th)
        phid = (b - a * c) / (s * s)
        return [thd, phid * phid * s * c - a * phid * s + mgl / i1 * s]
    sol = solve_ivp(rhs, (0, duration), [top.theta0, top.theta_dot0], method="DOP853", t_eval=t_eval,
                    rtol=1e-11, atol=1e-13)
    return sol.y[0]


def test_vector_integration_matches_euler_lagrange_form():
    top = heavy_top(I1, I3, M, L, theta0=math.radians(60), omega3=2 * math.pi * 20, phi_dot0=1.0)
    traj = top.simulate(3 * top.nutation_period, samples=3001)
    theta = _independent_euler_lagrange(top, traj.t[-1], traj.t)
    np.testing.assert_allclose(traj.theta, theta, atol=1e-7)


def test_from_mesh_properties_cylinder_on_its_base():
    """A solid cylinder pivoting at the centre of its base: I about the pivot by the parallel-axis theorem."""
    radius, height, mass = 0.02, 0.05, 0.3
    axial = 0.5 * mass * radius ** 2
    central_transverse = mass * (radius ** 2 / 4 + height ** 2 / 12)
    # the cylinder axis along mesh y, base centre at (1, 2, 3)
    base = np.array([1.0, 2.0, 3.0])
    props = MassProperties(mass=mass, volume=math.pi * radius ** 2 * height,
                           center_of_mass=base + [0, height / 2, 0],
                           inertia=np.diag([central_transverse, axial, central_transverse]))
    top = heavy_top_on_pivot(props, base, theta0=0.3, omega3=100.0)
    assert top.length == pytest.approx(height / 2)
    assert top.axial_moment == pytest.approx(axial, rel=1e-12)
    assert top.transverse_moment == pytest.approx(central_transverse + mass * (height / 2) ** 2, rel=1e-12)
    expected = heavy_top(central_transverse + mass * (height / 2) ** 2, axial, mass, height / 2,
                         theta0=0.3, omega3=100.0)
    assert top.nutation_period == pytest.approx(expected.nutation_period, rel=1e-12)


def test_from_mesh_asymmetric_warns_and_pivot_at_com_fails():
    props = MassProperties(mass=1.0, volume=1e-3, center_of_mass=[0, 0, 0.1], inertia=np.diag([1e-3, 2e-3, 5e-4]))
    with pytest.warns(AsymmetricTopWarning, match="not a symmetric top"):
        heavy_top_on_pivot(props, [0, 0, 0], theta0=0.2, omega3=50.0)
    with pytest.raises(PhysicsError):
        heavy_top_on_pivot(props, [0, 0, 0.1], theta0=0.2, omega3=50.0)


def test_bad_arguments():
    with pytest.raises(UsageError):
        heavy_top(I1, I3, M, L, theta0=4.0, omega3=1.0)
    with pytest.raises(PhysicsError):
        heavy_top(-1.0, I3, M, L, theta0=0.1, omega3=1.0)
    with pytest.raises(UsageError):
        heavy_top(I1, I3, M, L, theta0=float("nan"), omega3=1.0)


def test_precession_rate_is_undefined_when_the_axis_passes_the_vertical():
    # a non-spinning top released at 20°: a pendulum swinging through θ = π; φ jumps by π there
    falling = heavy_top(1e-4, 5e-5, 0.2, 0.03, theta0=math.radians(20), omega3=0.0)
    assert math.isnan(falling.simulate(duration=1.0, samples=2001).measured_precession_rate())
    # a fast top far from the vertical has a well-defined mean precession close to the slow steady rate
    fast = heavy_top(1e-4, 5e-5, 0.2, 0.03, theta0=math.radians(30), omega3=600.0)
    traj = fast.simulate(duration=2.0, samples=20001)
    assert traj.measured_precession_rate() == pytest.approx(fast.precession_rate_slow, rel=0.02)
