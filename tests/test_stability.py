"""Spin stability (§4.4.1): reference cases, property tests, and cross-checks against scipy integrations."""

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from inertia_tool.errors import PhysicalValidityWarning, PhysicsError, UsageError
from inertia_tool.mass.principal import principal_axes
from inertia_tool.mass.properties import MassProperties
from inertia_tool.dynamics.spin_stability import polhode_period, stability
from inertia_tool.integrals import second_moment_to_inertia, volume_moments


def _octahedron(a, b, c):
    """The solid |x|/a + |y|/b + |z|/c <= 1 as a closed, outward-wound 6-vertex mesh."""
    v = np.array([[a, 0, 0], [-a, 0, 0], [0, b, 0], [0, -b, 0], [0, 0, c], [0, 0, -c]], dtype=float)
    faces = []
    for sx, ix in ((1, 0), (-1, 1)):
        for sy, iy in ((1, 2), (-1, 3)):
            for sz, iz in ((1, 4), (-1, 5)):
                tri = [ix, iy, iz]
                if sx * sy * sz < 0:      # keep the normal pointing out of the octant
                    tri = [ix, iz, iy]
                faces.append(tri)
    return v, np.array(faces)


def test_octahedron_exercise_4_9():
    """Exercise 4.9: the aluminium 'diamond' with half-diagonals a < b < h.

    (a) analytic tensor I_xx = M(b²+h²)/10, I_yy = M(a²+h²)/10, I_zz = M(a²+b²)/10 (from ∫x² dV = M a²/10
    over |x|/a+|y|/b+|z|/h <= 1), checked against the signed-tetrahedron integration of the 6-vertex mesh;
    (b) stable spin about the axes of smallest and largest moment (z and x), unstable about y.
    """
    a, b, h = 0.01, 0.02, 0.05
    density = 2700.0
    mass = density * 4.0 * a * b * h / 3.0
    analytic = mass / 10.0 * np.diag([b * b + h * h, a * a + h * h, a * a + b * b])

    v, f = _octahedron(a, b, h)
    vm = volume_moments(v, f)
    assert vm.volume == pytest.approx(4.0 * a * b * h / 3.0, rel=1e-13)
    np.testing.assert_allclose(vm.centroid, 0.0, atol=1e-16)
    mesh_tensor = second_moment_to_inertia(vm.second_moment, density)
    np.testing.assert_allclose(mesh_tensor, analytic, rtol=1e-12, atol=1e-12 * analytic.max())

    props = MassProperties(mass=mass, volume=vm.volume, center_of_mass=vm.centroid, inertia=mesh_tensor)
    report = stability(props)
    assert report.kinds == ("stable", "unstable", "stable")
    # smallest moment about z (I_zz carries a² + b², the two short half-diagonals), largest about x
    np.testing.assert_allclose(np.abs(report.axes[0].axis), [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(np.abs(report.axes[1].axis), [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(np.abs(report.axes[2].axis), [1, 0, 0], atol=1e-12)
    # only the major axis (x) survives dissipation
    assert [e.dissipation_stable for e in report.axes] == [False, False, True]
    # coefficient of §4.4.1 for spin about y (i = z, j = x in cyclic order): (I_z − I_y)(I_y − I_x)/(I_z I_x)
    ix, iy, iz = np.diag(analytic)
    assert report.axes[1].coefficient == pytest.approx((iz - iy) * (iy - ix) / (iz * ix), rel=1e-10)


def test_chapter_sign_rule_spin_about_third_axis():
    """§4.4.1: ε̈₁ = (I2−I3)(I3−I1)/(I1 I2) ω² ε₁ for spin about axis 3, in whatever order I3 sits."""
    for moments in ([1.0, 2.0, 3.0], [2.0, 3.0, 1.0], [1.0, 3.0, 2.0]):
        i1, i2, i3 = moments
        expected = (i2 - i3) * (i3 - i1) / (i1 * i2)
        entry = next(e for e in stability(moments).axes if np.allclose(e.axis, [0, 0, 1]))
        assert entry.coefficient == pytest.approx(expected, rel=1e-14)
        assert entry.kind == ("unstable" if expected > 0 else "stable")


def test_rates_closed_forms():
    rep = stability([1.0, 2.0, 3.0])
    minor, inter, major = rep.axes
    k = inter.coefficient
    assert k == pytest.approx((3 - 2) * (2 - 1) / (3 * 1))
    assert inter.growth_rate_per_unit_spin == pytest.approx(math.sqrt(k))
    assert inter.e_folding_turns == pytest.approx(1 / (2 * math.pi * math.sqrt(k)))
    assert inter.wobble_frequency_per_unit_spin is None and major.growth_rate_per_unit_spin is None
    assert major.wobble_frequency_per_unit_spin == pytest.approx(math.sqrt((3 - 1) * (3 - 2) / (1 * 2)))
    assert minor.wobble_period_turns == pytest.approx(1 / math.sqrt((2 - 1) * (3 - 1) / (2 * 3)))
    # p = q makes the growth a pure exponential: ln(1000) / (2π √k)
    # choose moments with p = q for the intermediate axis: (I3−I2)/I1 = (I2−I1)/I3
    i1, i3 = 1.0, 2.0
    i2 = (i3 * i3 + i1 * i1) / (i1 + i3)       # solves (i3−i2) i3 = (i2−i1) i1
    entry = stability([i1, i2, i3]).axes[1]
    p, q = entry.cross_coefficients
    assert p == pytest.approx(q, rel=1e-12)
    assert entry.turns_to_grow(1e-3, 1.0) == pytest.approx(
        math.log(1000) / (2 * math.pi * math.sqrt(entry.coefficient)),
                                                           rel=1e-9)


def _linear_turns(p, q, initial, final, max_turns=1e5):
    """Independent: propagate the 2×2 linear system with expm, worst case over the four sign patterns."""
    a = np.array([[0.0, p], [q, 0.0]])
    starts = initial * np.array([[1, 1], [1, -1]], dtype=float)

    def reach(x):
        phi = expm(a * x)
        return np.max(np.abs(starts @ phi.T))

    xs = np.linspace(0.0, 2 * math.pi * max_turns, 2001)   # coarse scan up to the first crossing
    for lo, hi in zip(xs[:-1], xs[1:]):   # noqa: B007 (lo brackets the crossing after the loop)
        if reach(hi) >= final:
            break
    else:
        return math.inf
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if reach(mid) >= final else (mid, hi)
    return hi / (2 * math.pi)


@pytest.mark.parametrize("moments,which", [
    ([1.0, 2.0, 3.0], 1),            # plainly unstable
    ([1.0, 1.0 + 1e-4, 2.0], 1),     # nearly degenerate, slowly unstable
    ([1.0, 1.0 + 1e-4, 2.0], 0),     # nearly degenerate, stable but with a large wobble amplification
    ([1.0, 1.0 + 1e-8, 2.0], 0),     # marginal (within rtol)
])
def test_turns_to_grow_matches_linear_propagation(moments, which):
    entry = stability(moments).axes[which]
    p, q = entry.cross_coefficients
    expected = _linear_turns(p, q, 1e-3, 0.1, max_turns=200)
    got = entry.turns_to_grow(1e-3, 0.1)
    if math.isinf(expected):
        assert math.isinf(got)
    else:
        assert got == pytest.approx(expected, rel=1e-6)


def test_nearly_degenerate_is_continuous_across_tolerance():
    """A gap just inside and just outside rtol gives different labels but the same numbers."""
    rtol = 1e-6
    inside = stability([1.0, 1.0 + 1.999e-6, 2.0], rtol=rtol)  # |ΔI| <= rtol · max(I) = 2e-6
    outside = stability([1.0, 1.0 + 2.001e-6, 2.0], rtol=rtol)
    assert inside.kinds == ("marginal", "marginal", "stable")
    assert outside.kinds == ("stable", "unstable", "stable")
    assert inside.axes[1].turns_to_grow() == pytest.approx(outside.axes[1].turns_to_grow(), rel=1e-3)
    assert inside.axes[0].wobble_amplification == pytest.approx(outside.axes[0].wobble_amplification, rel=1e-3)
    # and the slow divergence is quantified rather than hidden: > 100 turns for a 1e-3 wobble
    assert outside.axes[1].turns_to_grow() > 100


def test_marginal_linear_growth_and_neutral():
    rep = stability([2.0, 2.0, 3.0])
    assert rep.kinds == ("marginal", "marginal", "stable")
    # linear growth ε = ε0 (1 + |p| ω t): turns = (final/initial − 1) / (2π |p|), |p| = (I3 − I)/I
    p = (3.0 - 2.0) / 2.0
    assert rep.axes[0].turns_to_grow(1e-3, 1.0) == pytest.approx(999 / (2 * math.pi * p), rel=1e-12)
    assert rep.axes[0].growth_rate_per_unit_spin is None
    # the major axis of a prolate top: the degenerate plane is the dissipation-stable set
    prolate = stability([1.0, 3.0, 3.0])
    assert [e.dissipation_stable for e in prolate.axes] == [False, True, True]
    neutral = stability([5.0, 5.0, 5.0])
    assert neutral.kinds == ("neutral",) * 3
    assert math.isinf(neutral.axes[1].turns_to_grow())


moment = st.floats(min_value=0.1, max_value=10.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(moment, moment, moment, st.floats(min_value=1e-6, max_value=1e6), st.permutations([0, 1, 2]))
def test_classification_invariant_under_scaling_and_permutation(m1, m2, m3, scale, perm):
    moments = np.array([m1, m2, m3])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalValidityWarning)
        base = stability(moments)
        scaled = stability(moments * scale)
        permuted = stability(moments[list(perm)])
    assert scaled.kinds == base.kinds
    assert permuted.kinds == base.kinds
    for a, b in zip(base.axes, scaled.axes):
        assert b.coefficient == pytest.approx(a.coefficient, rel=1e-9, abs=1e-12)
    # the axis of each sorted moment follows the permutation (principal frame for bare moments)
    for e in permuted.axes:
        original_index = perm[int(np.argmax(np.abs(e.axis)))]
        assert moments[original_index] == e.moment
    # a generic body has exactly one unstable axis, the intermediate one
    if "marginal" not in base.kinds and "neutral" not in base.kinds:
        assert base.kinds == ("stable", "unstable", "stable")


@settings(max_examples=50, deadline=None)
@given(st.floats(min_value=1.0, max_value=3.0), st.floats(min_value=1.0, max_value=3.0),
       st.floats(min_value=1.0, max_value=3.0), st.floats(0, 2 * math.pi), st.floats(0, math.pi))
def test_rotated_tensor_gives_rotated_axes(m1, m2, m3, yaw, pitch):
    """Principal axes of R diag Rᵀ: the classified axes are R's columns (up to sign), kinds unchanged."""
    cz, sz, cy, sy = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    rot = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    moments = np.array([m1, m2, m3])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalValidityWarning)
        body = MassProperties(mass=1.0, volume=1.0, center_of_mass=[1, 2, 3],
                              inertia=rot @ np.diag(moments) @ rot.T)
        rep = stability(body)
        bare = stability(moments)
    assert rep.kinds == bare.kinds
    for e_rot, e_bare in zip(rep.axes, bare.axes):
        if e_rot.kind in ("stable", "unstable"):
            assert abs(e_rot.axis @ (rot @ e_bare.axis)) == pytest.approx(1.0, abs=1e-6)
    np.testing.assert_allclose(rep.reference_point, [1, 2, 3])


def test_principal_axes_input_and_about():
    pa = principal_axes(np.diag([3.0, 1.0, 2.0]), reference_point=[0.5, 0, 0])
    rep = stability(pa)
    assert rep.about("intermediate") is rep.axes[1]
    assert rep.about(2).name == "major"
    np.testing.assert_allclose(rep.reference_point, [0.5, 0, 0])
    with pytest.raises(UsageError):
        rep.about("sideways")


def test_bad_input():
    with pytest.raises(PhysicsError):
        stability([0.0, 1.0, 1.0])
    with pytest.raises(UsageError):
        stability([1.0, 2.0])
    with pytest.raises(UsageError):
        stability([1.0, 2.0, 3.0], rtol=-1)
    with pytest.warns(PhysicalValidityWarning):
        stability([1.0, 1.0, 5.0])
    with pytest.raises(UsageError):
        stability([1.0, 2.0, 3.0]).axes[1].turns_to_grow(0.0, 1.0)


def _euler_rhs(moments):
    i1, i2, i3 = moments

    def rhs(_t, w):
        return [(i2 - i3) * w[1] * w[2] / i1, (i3 - i1) * w[2] * w[0] / i2, (i1 - i2) * w[0] * w[1] / i3]
    return rhs


def _measured_period(moments, w0, t_end, component):
    """Period of ω_component from upward zero crossings of a tight scipy integration of Eq. (4.27)."""
    sol = solve_ivp(_euler_rhs(moments), (0, t_end), w0, method="DOP853", rtol=1e-12, atol=1e-14,
                    dense_output=True)
    t = np.linspace(0, t_end, 400001)
    y = sol.sol(t)[component]
    idx = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    crossings = t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])
    return np.diff(crossings).mean()


@pytest.mark.parametrize("w0,component", [
    ([0.3, 0.2, 1.0], 0),            # around the major axis
    ([1.0, 0.3, 0.2], 1),            # around the minor axis
    ([1e-3, 1.0, 1e-3], 0),          # near the intermediate axis: close to the separatrix
])
def test_polhode_period_landau_lifshitz_vs_scipy(w0, component):
    moments = [1.0, 2.0, 3.0]
    predicted = polhode_period(moments, w0)
    measured = _measured_period(moments, w0, 6 * predicted, component)
    assert measured == pytest.approx(predicted, rel=1e-5)


def test_polhode_period_axisymmetric_and_linear_limits():
    i1, i3, w3 = 2.0, 3.0, 10.0
    omega = (i3 - i1) / i1 * w3                      # §4.4.1, body-frame precession rate
    assert polhode_period([i1, i1, i3], [0.1, 0.2, w3]) == pytest.approx(2 * math.pi / omega, rel=1e-12)
    # small wobble about the major axis: 2π / (√(−c) ω)
    rep = stability([1.0, 2.0, 3.0])
    t = polhode_period([1.0, 2.0, 3.0], [1e-6, 0.0, 5.0])
    assert t == pytest.approx(2 * math.pi / (rep.axes[2].wobble_frequency_per_unit_spin * 5.0), rel=1e-9)
    assert math.isinf(polhode_period([1.0, 2.0, 3.0], [0.0, 1.0, 0.0]))
