"""§4.2 pseudoforces and the §4.4.1 free precession (Chandler wobble): closed forms vs numerical integration."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from inertia_tool.dynamics.free_precession import (EARTH_DYNAMICAL_ELLIPTICITY, free_precession_period,
                                                   free_precession_rate)
from inertia_tool.dynamics.rotating_frame import (EARTH_SIDEREAL_RATE, eastward_drop_deflection,
                                                  foucault_precession_rate, integrate_in_rotating_frame,
                                                  pseudoforces)
from inertia_tool.errors import UsageError

G = 9.80665
DAY = 86400.0


def _local_earth_rotation(latitude, rate=EARTH_SIDEREAL_RATE):
    """ω in local axes x east, y north, z up at ``latitude``."""
    return rate * np.array([0.0, math.cos(latitude), math.sin(latitude)])


def test_pseudoforces_match_the_chapter_formula_term_by_term():
    rng = np.random.default_rng(4)
    r, v, w, wd, acc = rng.normal(size=(5, 3))
    f = pseudoforces(2.0, r, v, w, angular_acceleration=wd, frame_acceleration=acc)
    np.testing.assert_allclose(f.translation, -2.0 * acc)
    np.testing.assert_allclose(f.coriolis, -4.0 * np.cross(w, v))
    np.testing.assert_allclose(f.angular_acceleration, -2.0 * np.cross(wd, r))
    # bac-cab: ω × (ω × r) = ω (ω·r) − r ω²
    np.testing.assert_allclose(f.centrifugal, -2.0 * (w * (w @ r) - r * (w @ w)), rtol=1e-12)
    # centrifugal force points away from the axis, with magnitude m ω² r⊥
    r_perp = r - w * (w @ r) / (w @ w)
    np.testing.assert_allclose(f.centrifugal, 2.0 * (w @ w) * r_perp, rtol=1e-12)


def test_pseudoforces_equal_inertial_acceleration_of_a_point_fixed_in_space():
    """A point at rest in the inertial frame, seen from a frame turning at ω: a′ = pseudoforces/m exactly.

    In the frame r(t) = Rz(−ωt) r0, so v′ = −ω × r and a′ = ω × (ω × r); the formula gives
    −2ω×v′ − ω×(ω×r) = 2ω×(ω×r) − ω×(ω×r) = ω×(ω×r)."""
    w = np.array([0.0, 0.0, 0.7])
    r0 = np.array([1.0, 0.5, 0.2])
    t = np.linspace(0.0, 3.0, 7)
    r, v = integrate_in_rotating_frame(lambda *_: np.zeros(3), r0, -np.cross(w, r0), t, angular_velocity=w)
    c, s = np.cos(-0.7 * t), np.sin(-0.7 * t)
    expected = np.column_stack([c * r0[0] - s * r0[1], s * r0[0] + c * r0[1], np.full_like(t, r0[2])])
    np.testing.assert_allclose(r, expected, atol=1e-10)


@pytest.mark.parametrize("latitude_deg", [0.0, 45.0, 60.0])
def test_dropped_body_eastward_deflection(latitude_deg):
    """A body dropped from rest 100 m up lands ω g t³ cos λ / 3 east (≈ 2.2 cm at the equator)."""
    lat = math.radians(latitude_deg)
    height = 100.0
    fall = math.sqrt(2 * height / G)
    t = np.linspace(0.0, fall, 3)
    r, _ = integrate_in_rotating_frame(lambda *_: np.array([0.0, 0.0, -G]), [0.0, 0.0, height], [0.0, 0.0, 0.0],
                                       t, angular_velocity=_local_earth_rotation(lat))
    east = r[-1, 0]
    expected = eastward_drop_deflection(fall, lat)
    # the first-order formula misses O(Ω²) terms: relative ~ Ω t ≈ 3e-4
    assert east == pytest.approx(expected, rel=1e-3)
    assert expected == pytest.approx(EARTH_SIDEREAL_RATE * G * fall ** 3 * math.cos(lat) / 3)


def test_foucault_pendulum_plane_turns_at_omega_sin_latitude():
    """Linearised pendulum (ω0 = 2 rad/s) on a planet turning at 0.02 rad/s, latitude 45°: the plane of swing
    turns clockwise at Ω sin λ; the string's tension cancels the vertical forces."""
    lat, rate, w0 = math.radians(45.0), 0.02, 2.0
    w = _local_earth_rotation(lat, rate)

    def force(_t, r, v):
        f = -w0 ** 2 * np.array([r[0], r[1], 0.0])
        f[2] = -pseudoforces(1.0, r, v, w).total[2]      # tension keeps the bob in the horizontal plane
        return f

    duration = 30.0
    t = np.concatenate([[0.0], np.linspace(duration - 2 * math.pi / w0, duration, 4001)])
    r, _ = integrate_in_rotating_frame(force, [0.1, 0.0, 0.0], [0.0, 0.0, 0.0], t, angular_velocity=w)
    # in a frame turning with the plane the path is an ellipse with its major axis along x': the farthest
    # excursion of the last swing lies on the plane of swing
    far = 1 + int(np.argmax(np.linalg.norm(r[1:, :2], axis=1)))
    angle = math.atan2(r[far, 1], r[far, 0])
    angle = (angle + math.pi / 2) % math.pi - math.pi / 2          # a line: angle modulo π
    turned = -angle                                                   # clockwise is negative
    expected = foucault_precession_rate(lat, rotation_rate=rate) * t[far]
    assert abs(r[:, 2]).max() < 1e-9
    assert turned == pytest.approx(expected, rel=2e-4)


def test_chandler_wobble_chapter_and_measured_ellipticity():
    """Chapter: I3 − I1 one part in 300, ω3 = 2π per sidereal day → 299 days (≈ 10 months). With the IERS
    dynamical ellipticity H = (C − A)/C the rigid-Earth (Euler) period is 304 days."""
    sidereal_day = 2 * math.pi / EARTH_SIDEREAL_RATE
    chapter = free_precession_period(300.0, 301.0, EARTH_SIDEREAL_RATE) / DAY
    assert chapter == pytest.approx(300 * sidereal_day / DAY, rel=1e-12)
    assert 298.5 < chapter < 299.5
    h = EARTH_DYNAMICAL_ELLIPTICITY
    real = free_precession_period(1.0 - h, 1.0, EARTH_SIDEREAL_RATE) / DAY
    assert 303 < real < 305            # Euler period ~ 304-305 days; the observed 433 d needs an elastic Earth
    assert free_precession_rate(1.0, 2.0, 3.0) == pytest.approx(3.0)
    assert free_precession_period(1.0, 1.0, 3.0) == math.inf
    with pytest.raises(UsageError):
        free_precession_rate(-1.0, 1.0, 1.0)


def test_free_precession_against_euler_equations():
    """ω1 + i ω2 of an axisymmetric free body turns at Ω = ω3 (I3 − I1)/I1 in the body (Eq. 4.27 integrated)."""
    i1, i3, w3 = 2.0, 3.0, 5.0

    def euler(_t, w):
        return [(i1 - i3) * w[1] * w[2] / i1, (i3 - i1) * w[0] * w[2] / i1, 0.0]
    t_end = 4.0
    sol = solve_ivp(euler, (0, t_end), [0.1, 0.0, w3], rtol=1e-12, atol=1e-14, method="DOP853")
    w1, w2 = sol.y[0, -1], sol.y[1, -1]
    rate = free_precession_rate(i1, i3, w3)
    np.testing.assert_allclose([w1, w2], [0.1 * math.cos(rate * t_end), 0.1 * math.sin(rate * t_end)],
                               atol=1e-10)
