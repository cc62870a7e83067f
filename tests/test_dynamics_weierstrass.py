"""Weierstrass ℘ from its invariants, and the heavy top's u(t) = cos θ(t) of exercise 4.10."""

import math

import numpy as np
import pytest

from inertia_tool.dynamics.elliptic import (weierstrass_half_periods, weierstrass_p, weierstrass_p_derivative,
                                            weierstrass_roots)
from inertia_tool.dynamics.top_motion import top_cos_theta, top_weierstrass_invariants
from inertia_tool.errors import PhysicsError, UsageError
from inertia_tool.dynamics.top import heavy_top

G2, G3 = 7.0, 1.3          # Δ = 343 − 45.6 > 0: a rectangular lattice


def _lattice_points(w1, w3, n):
    j, k = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    w = (2 * j * w1 + 2 * k * w3).ravel()
    return w[w != 0]


def test_invariants_are_the_eisenstein_sums_of_the_lattice():
    """g2 = 60 Σ′ w⁻⁴, g3 = 140 Σ′ w⁻⁶ over the lattice of the computed half-periods (independent check of
    the periods; the chapter's exercise omits the factors 60 and 140)."""
    w1, w3 = weierstrass_half_periods(G2, G3)
    w = _lattice_points(w1, w3, 400)
    assert 60 * np.sum(w ** -4.0).real == pytest.approx(G2, rel=1e-5)
    assert 140 * np.sum(w ** -6.0).real == pytest.approx(G3, rel=1e-6)


def test_p_against_the_lattice_sum_definition():
    """℘(z) = 1/z² + Σ′ (1/(z − w)² − 1/w²) (exercise 4.10(g)), summed symmetrically over a square of lattice
    points, at complex points off the real and imaginary axes."""
    w1, w3 = weierstrass_half_periods(G2, G3)
    w = _lattice_points(w1, w3, 300)
    for z in (0.3 * w1 + 0.4 * w3, 0.9 * w1 - 0.2 * w3, 0.1 + 0.05j):
        series = 1 / z ** 2 + np.sum(1 / (z - w) ** 2 - 1 / w ** 2)
        assert abs(weierstrass_p(z, G2, G3) - series) < 1e-4 * abs(series)


def test_p_satisfies_its_differential_equation_and_takes_the_roots_at_half_periods():
    e1, e2, e3 = weierstrass_roots(G2, G3)
    assert e1 + e2 + e3 == pytest.approx(0.0, abs=1e-14)
    for e in (e1, e2, e3):
        assert 4 * e ** 3 - G2 * e - G3 == pytest.approx(0.0, abs=1e-12)
    w1, w3 = weierstrass_half_periods(G2, G3)
    assert weierstrass_p(w1, G2, G3).real == pytest.approx(e1, rel=1e-12)
    assert weierstrass_p(w1 + w3, G2, G3).real == pytest.approx(e2, rel=1e-10)
    assert weierstrass_p(w3, G2, G3).real == pytest.approx(e3, rel=1e-10)
    z = np.array([0.2 + 0.1j, 0.7 * w1 + 0.3 * w3, 1.3 - 0.4j])
    p, dp = weierstrass_p(z, G2, G3), weierstrass_p_derivative(z, G2, G3)
    np.testing.assert_allclose(dp ** 2, 4 * p ** 3 - G2 * p - G3, rtol=1e-10)
    h = 1e-6                                          # the derivative is the derivative
    np.testing.assert_allclose((weierstrass_p(z + h, G2, G3) - weierstrass_p(z - h, G2, G3)) / (2 * h), dp,
                               rtol=1e-7)
    # periodicity 2ω1, 2ω3
    np.testing.assert_allclose(weierstrass_p(z + 2 * w1, G2, G3), p, rtol=1e-9)
    np.testing.assert_allclose(weierstrass_p(z + 2 * w3, G2, G3), p, rtol=1e-9)


def test_non_rectangular_lattice_is_refused():
    with pytest.raises(UsageError, match="rectangular"):
        weierstrass_roots(1.0, 1.0)


# a toy top: I1 about the pivot, I3 axial, 0.5 kg with its centre of mass 4 cm above the tip (test_heavy_top)
I1, I3, M, L = 1.2e-3, 6.0e-4, 0.5, 0.04


@pytest.mark.parametrize("omega3, theta_dot0, phi_dot0", [(120.0, 0.0, 0.0), (60.0, 2.0, 3.0),
                                                           (150.0, -1.0, -4.0)])
def test_exercise_4_10_cos_theta_from_weierstrass_matches_turning_points_period_and_simulation(
        omega3, theta_dot0, phi_dot0):
    top = heavy_top(I1, I3, M, L, theta0=0.5, omega3=omega3, theta_dot0=theta_dot0, phi_dot0=phi_dot0)
    u_x, u_n, u_u = top.roots
    g2, g3, c = top_weierstrass_invariants(top)
    # the roots of the cubic in P are β(u_k − c)/4
    np.testing.assert_allclose(weierstrass_roots(g2, g3), [top.beta * (u - c) / 4 for u in (u_u, u_n, u_x)],
                               rtol=1e-8, atol=1e-10 * top.beta)
    period = top.nutation_period
    w1, _ = weierstrass_half_periods(g2, g3)
    assert 2 * w1 == pytest.approx(period, rel=1e-10)
    assert top_cos_theta(top, 0.0) == pytest.approx(u_x, abs=1e-10)
    assert top_cos_theta(top, period / 2) == pytest.approx(u_n, abs=1e-10)
    assert top_cos_theta(top, 3 * period) == pytest.approx(u_x, abs=1e-9)
    # u̇² = f(u) along the closed form
    t = np.linspace(0.01, 0.99, 9) * period
    h = 1e-7 * period
    du = (top_cos_theta(top, t + h) - top_cos_theta(top, t - h)) / (2 * h)
    np.testing.assert_allclose(du ** 2, top.f(top_cos_theta(top, t)), rtol=1e-5, atol=1e-8 * top.beta)
    # against the vector-form simulation of heavy_top: find its first θ_max and compare from there on
    traj = top.simulate(3 * period, samples=6001)
    first_bottom = traj.t[np.argmin(np.cos(traj.theta[: len(traj.t) // 3 + 1]))]
    later = traj.t >= first_bottom + period / 4
    predicted = top_cos_theta(top, traj.t[later] - first_bottom)
    # the sampled minimum is off by up to half a sample: the comparison error is |u̇| × that
    slack = 0.5 * (traj.t[1] - traj.t[0]) * math.sqrt(max(top.f(np.linspace(u_x, u_n, 50)).max(), 0.0))
    assert np.max(np.abs(predicted - np.cos(traj.theta[later]))) < slack + 1e-8


def test_top_without_nutation_or_gravity_is_refused():
    steady = heavy_top(I1, I3, M, 0.0, theta0=0.5, omega3=100.0)
    with pytest.raises(PhysicsError, match="gravity"):
        top_weierstrass_invariants(steady)
