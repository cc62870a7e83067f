"""Reference tests of the signed-tetrahedron engine (inertia_tool.integrals) against closed forms (the chapter's
exercises 4.6 and 4.9 and §4.3.2), Tonon (2004)'s published tetrahedron, trimesh, an independent
surface-quadrature integrator, and hypothesis property tests (rotation, translation, scaling)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool.mass import shapes
from inertia_tool.mass.properties import MassProperties
from inertia_tool.integrals import body_volume_moments, second_moment_to_inertia, volume_moments
from conftest import assert_tensor_close


# every test runs on the C extension (when built) and on the pure-numpy path
pytestmark = pytest.mark.usefixtures("engine_path")


def _props(vertices, faces, **kwargs) -> MassProperties:
    """Unit-density MassProperties of a closed mesh from the engine."""
    m = volume_moments(vertices, faces, **kwargs)
    return MassProperties(mass=m.volume, volume=m.volume, center_of_mass=m.centroid,
                          inertia=second_moment_to_inertia(m.second_moment), surface_area=m.area, density=1.0)


def _rel(actual, expected):
    """Largest entry error relative to the largest entry of ``expected``."""
    expected = np.asarray(expected, dtype=float)
    return float(np.abs(np.asarray(actual) - expected).max() / np.abs(expected).max())


def _hull(seed: int, points: int = 40):
    """A random closed convex mesh (outward, consistently wound) from trimesh's convex hull."""
    rng = np.random.default_rng(seed)
    hull = trimesh.convex.convex_hull(rng.normal(size=(points, 3)) * rng.uniform(0.2, 3.0, size=3))
    return np.asarray(hull.vertices, dtype=float), np.asarray(hull.faces, dtype=np.int64)


# -- closed forms ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("a, b, h", [(0.020, 0.030, 0.050), (1.0, 2.0, 3.0), (3e-4, 7e-4, 1.1e-3)])
def test_octahedron_exercise_4_9(a, b, h):
    """Exercise 4.9 (h > b > a): V = 4abh/3, I_xx = M(b² + h²)/10, I_yy = M(a² + h²)/10, I_zz = M(a² + b²)/10,
    products zero; the exact polyhedron, so agreement to round-off."""
    p = _props(*(lambda s: (s.vertices, s.faces))(shapes.octahedron(a, b, h)))
    mass = 4 * a * b * h / 3
    expected = np.diag([mass * (b * b + h * h) / 10, mass * (a * a + h * h) / 10, mass * (a * a + b * b) / 10])
    assert p.volume == pytest.approx(mass, rel=1e-13)
    assert np.abs(p.center_of_mass).max() <= 1e-13 * h
    assert _rel(p.inertia, expected) <= 1e-13
    # exercise 4.9b: x (largest moment) and z (smallest) are the stable spin axes, y intermediate
    np.testing.assert_allclose(np.abs(p.principal.axes), np.eye(3)[:, [2, 1, 0]], atol=1e-12)


@pytest.mark.parametrize("sides", [3, 4, 5, 6, 17])
def test_regular_pyramid_exercise_4_6(sides):
    """Exercise 4.6 with an n-gonal base: I_zz = 6kMR²/5, I_xx = 3kMR²/5 + 3Mh²/80, k = (2 + cos 2π/n)/12,
    centre of mass h/4 above the base."""
    R, h = 0.02, 0.05
    s = shapes.pyramid(R, h, sides, center=[0.3, -0.1, 0.7])
    p = _props(s.vertices, s.faces)
    area = 0.5 * sides * R * R * math.sin(2 * math.pi / sides)
    k = (2 + math.cos(2 * math.pi / sides)) / 12
    mass = area * h / 3
    expected = np.diag([0.6 * k * mass * R * R + 3 * mass * h * h / 80] * 2 + [1.2 * k * mass * R * R])
    assert p.volume == pytest.approx(mass, rel=1e-13)
    assert s.vertices[:, 2].min() == pytest.approx(0.7 - h / 4, rel=1e-15)
    np.testing.assert_allclose(p.center_of_mass, [0.3, -0.1, 0.7], rtol=0, atol=1e-13 * h)
    assert _rel(p.inertia, expected) <= 1e-13
    assert p.surface_area == pytest.approx(s.exact.surface_area, rel=1e-13)


def _ideal_errors(solid):
    """Relative errors (volume, I_xx, I_zz) of the engine on ``solid``'s mesh against the ideal solid."""
    p = _props(solid.vertices, solid.faces)
    e = solid.exact
    return np.array([p.volume / e.volume - 1, p.inertia[0, 0] / e.inertia[0, 0] - 1,
                     p.inertia[2, 2] / e.inertia[2, 2] - 1])


@pytest.mark.parametrize("n", [32, 64])
def test_cone_exercise_4_6_converges_second_order(n):
    """The n-segment cone mesh against I_zz = 3MR²/10, I_xx = 3M(R² + h²/4)/20 (exercise 4.6): the error
    is O(1/n²), so doubling n divides it by ≈ 4 (measured 3.983–3.994 at n = 32 → 64, 3.996–3.999 at 64 → 128)."""
    coarse = _ideal_errors(shapes.cone(0.02, 0.05, segments=n))
    fine = _ideal_errors(shapes.cone(0.02, 0.05, segments=2 * n))
    assert np.all(coarse < 0) and np.all(fine < 0)       # inscribed: always too small
    ratio = coarse / fine
    assert np.all((ratio > 3.5) & (ratio < 4.5)), ratio
    assert np.abs(fine).max() < 4 * (2 * math.pi / (2 * n)) ** 2


@pytest.mark.parametrize("n", [32, 64])
def test_torus_converges_second_order(n):
    """Torus mesh (n sectors, n/2 tube sides) against V = 2π²Rr², I_zz = M(R² + 3r²/4), I_xx = M(R²/2 + 5r²/8):
    doubling both resolutions divides the error by ≈ 4 (measured 3.949–3.965 at 32 → 64, 3.987–3.991 at 64 → 128)."""
    coarse = _ideal_errors(shapes.torus(0.04, 0.01, segments=n, rings=n // 2))
    fine = _ideal_errors(shapes.torus(0.04, 0.01, segments=2 * n, rings=n))
    ratio = coarse / fine
    assert np.all((ratio > 3.5) & (ratio < 4.5)), ratio


def test_thin_ring_limit_section_4_3_2():
    """§4.3.2: a thin ring has I_zz = MR² and I_xx = I_yy = MR²/2.  The torus tends to it as r/R → 0 with
    relative deviations 3r²/4R² and 5r²/4R².  The mesh's centre line is a regular n-gon inscribed in the
    circle; a thin wire along it has I_zz = MR²(2 + cos θ)/3 (mean of |x|² along a chord), θ = 2π/n — a
    −1.0e-4 relative offset at n = 256, which we divide out before taking the limit."""
    R = 0.05
    deviations = []
    for r in (5e-3, 5e-4, 5e-5):
        s = shapes.thin_ring(R, r)
        theta = 2 * math.pi / 256
        polygon = (2 + math.cos(theta)) / 3
        p = _props(s.vertices, s.faces)
        ratio = np.diag(p.inertia) / (p.mass * R * R * polygon)
        deviations.append(np.abs(ratio - [0.5, 0.5, 1.0]).max())
        np.testing.assert_allclose(ratio, [0.5, 0.5, 1.0], rtol=0, atol=1.3 * r * r / (R * R) + 1e-11)
        # the ideal torus formula itself has exactly these deviations
        e = s.exact
        np.testing.assert_allclose(np.diag(e.inertia) / (e.mass * R * R),
                                   [0.5 + 5 * r * r / (8 * R * R)] * 2 + [1 + 3 * r * r / (4 * R * R)], rtol=1e-14)
    # second order in r/R: each tenfold thinner wire brings the ring 100× closer to MR², MR²/2
    assert deviations[0] / deviations[1] == pytest.approx(100, rel=0.05)
    assert deviations[1] / deviations[2] == pytest.approx(100, rel=0.05)
    assert deviations[-1] < 2e-6


def test_hollow_sphere_is_sphere_minus_sphere():
    """A cavity shell (inward faces) subtracts: the engine on the two-shell mesh equals the engine on the outer
    sphere minus the engine on the inner sphere, and each shell's labelled moments have the right signs."""
    kw = dict(segments=48, rings=24)
    hollow = shapes.hollow_sphere(0.02, 0.015, **kw)
    outer, inner = shapes.sphere(0.02, **kw), shapes.sphere(0.015, **kw)
    h = volume_moments(hollow.vertices, hollow.faces, origin=np.zeros(3))
    o = volume_moments(outer.vertices, outer.faces, origin=np.zeros(3))
    i = volume_moments(inner.vertices, inner.faces, origin=np.zeros(3))
    assert h.volume == pytest.approx(o.volume - i.volume, rel=1e-14)
    assert _rel(h.second_moment, o.second_moment - i.second_moment) <= 1e-13
    labels = (np.linalg.norm(hollow.vertices[hollow.faces[:, 0]], axis=1) < 0.0175).astype(int)
    shell_o, shell_i = body_volume_moments(hollow.vertices, hollow.faces, labels, 2, origin=np.zeros(3))
    assert shell_o.volume == pytest.approx(o.volume, rel=1e-14)
    assert shell_i.volume == pytest.approx(-i.volume, rel=1e-14)
    # and against the ideal shell (8π/15)(r_o⁵ − r_i⁵): the UV meshes are inscribed, error O(1/n²)
    p = _props(hollow.vertices, hollow.faces)
    assert p.inertia[2, 2] == pytest.approx(hollow.exact.inertia[2, 2], rel=2e-2)


# -- published values ------------------------------------------------------------------------------------

# Tonon, F. (2004) "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of its vertex
# coordinates", J. Math. Stat. 1(1): 8-11, numerical example (unit density, about the centroid).
TONON_VERTICES = np.array([[8.33220, -11.86875, 0.93355], [0.75523, 5.00000, 16.37072],
                           [52.61236, 5.00000, -5.38580], [2.00000, 5.00000, 3.00000]])
TONON_VOLUME = 1873.233236
TONON_CENTROID = np.array([15.92492, 0.78281, 3.72962])
TONON_A, TONON_B, TONON_C = 43520.33257, 194711.28938, 191168.76173
TONON_A1, TONON_B1, TONON_C1 = 4417.66150, -46343.16662, 11996.20119


def test_tonon_2004_tetrahedron():
    """Tonon's a, b, c are the moments about x, y, z; his products are a' = ∫yz dμ, b' = ∫xz dμ, c' = ∫xy dμ
    (his Eqs. 9d–9f: b' is built from x and z, c' from x and y).  His printed matrix
    [[a, −b', −c'], [−b', b, −a'], [−c', −a', c]] swaps b' and c' against those definitions; with the
    published numbers the tensor in our convention (off-diagonals −∫xy dm) is
    [[a, −c', −b'], [−c', b, −a'], [−b', −a', c]], i.e. I_yz = −a', I_xz = −b', I_xy = −c'.

    The vertices are printed to 5 decimals and the results were evidently computed from more digits:
    our values differ from the published ones by 6.8e-8 (volume) and 1.6e-8 (every tensor entry), relative;
    the centroid's x differs by 2.8e-5 in the last printed digit (as other implementations also note)."""
    faces = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 3], [1, 2, 3]])
    m = volume_moments(TONON_VERTICES, faces)
    inertia = second_moment_to_inertia(m.second_moment)
    assert m.volume == pytest.approx(TONON_VOLUME, rel=1e-7)
    np.testing.assert_allclose(m.centroid, TONON_CENTROID, rtol=0, atol=5e-5)
    expected = np.array([[TONON_A, -TONON_C1, -TONON_B1],
                         [-TONON_C1, TONON_B, -TONON_A1],
                         [-TONON_B1, -TONON_A1, TONON_C]])
    assert_tensor_close(inertia, expected, rtol=5e-8)
    # the products as integrals, sign made explicit
    c = m.second_moment
    assert (c[1, 2], c[0, 2], c[0, 1]) == pytest.approx((TONON_A1, TONON_B1, TONON_C1), rel=5e-8)


# -- invariances -----------------------------------------------------------------------------------------

def test_rotation_gives_R_I_RT():
    s = shapes.octahedron(0.02, 0.03, 0.05)
    base = _props(s.vertices, s.faces)
    rot = Rotation.from_euler("zyz", [0.3, 1.1, -0.7]).as_matrix()
    turned = _props(s.vertices @ rot.T, s.faces)
    assert _rel(turned.inertia, rot @ base.inertia @ rot.T) <= 1e-13
    assert _rel(turned.inertia, base.transformed(rotation=rot).inertia) <= 1e-13


def test_unit_cube_far_from_origin_keeps_central_tensor():
    """A unit cube at (1e8, 1e8, 1e8): the central tensor stays diag(1/6) to 1e-12 relative."""
    s = shapes.box(1.0, 1.0, 1.0, center=[1e8, 1e8, 1e8])
    p = _props(s.vertices, s.faces)
    assert p.volume == pytest.approx(1.0, rel=1e-12)
    assert _rel(p.inertia, np.eye(3) / 6) <= 1e-12
    np.testing.assert_allclose(p.center_of_mass, 1e8, rtol=1e-15)


def test_translation_leaves_central_tensor_alone():
    v, f = _hull(7)
    base = _props(v, f)
    moved = _props(v + np.array([123.4, -56.7, 8.9]), f)
    assert _rel(moved.inertia, base.inertia) <= 1e-12
    np.testing.assert_allclose(moved.center_of_mass - base.center_of_mass, [123.4, -56.7, 8.9], rtol=1e-13)


@pytest.mark.parametrize("scale", [1e-3, 0.37, 25.0])
def test_scaling_scales_inertia_by_s5(scale):
    s = shapes.torus(0.04, 0.01, segments=24, rings=12)
    base, scaled = _props(s.vertices, s.faces), _props(s.vertices * scale, s.faces)
    assert scaled.volume == pytest.approx(base.volume * scale ** 3, rel=1e-13)
    assert _rel(scaled.inertia, base.inertia * scale ** 5) <= 1e-13
    assert scaled.surface_area == pytest.approx(base.surface_area * scale ** 2, rel=1e-13)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_mirror_image_agrees(axis):
    """Reflecting x_k → −x_k (and reversing each face to keep the normals outward) keeps the volume,
    mirrors the centroid, and maps I → P I P with P = diag(±1)."""
    v, f = _hull(11)
    mirror = np.ones(3)
    mirror[axis] = -1
    base = _props(v, f)
    image = _props(v * mirror, f[:, ::-1])
    assert image.volume == pytest.approx(base.volume, rel=1e-13)
    np.testing.assert_allclose(image.center_of_mass, base.center_of_mass * mirror, rtol=1e-12, atol=1e-14)
    assert _rel(image.inertia, np.diag(mirror) @ base.inertia @ np.diag(mirror)) <= 1e-13
    # without reversing the faces the mirror image is inside-out
    assert volume_moments(v * mirror, f).volume == pytest.approx(-base.volume, rel=1e-13)


# -- independent integrator: Gauss's theorem with surface quadrature ------------------------------------

def _surface_quadrature(vertices, faces, about):
    """Volume and raw second moment ``∫ u uᵀ dV`` (u = x − about) by the divergence theorem:
    ``∫ u_i u_j dV = ∮ u_i² u_j / 2 · n_i dA`` (i ≠ j) and ``∫ u_i² dV = ∮ u_i³/3 · n_i dA``, each face
    integrated with a collapsed 3×3 Gauss–Legendre rule (exact for these cubics).  Shares no code or formula
    with the signed tetrahedra."""
    g, w = np.polynomial.legendre.leggauss(3)
    g, w = 0.5 * (g + 1), 0.5 * w
    uu, vv = np.meshgrid(g, g, indexing="ij")
    s_pts, t_pts = (uu * (1 - vv)).ravel(), (uu * vv).ravel()
    weights = (np.outer(w, w) * uu).ravel()                       # Duffy Jacobian u
    p0 = vertices[faces[:, 0]] - about
    e1 = vertices[faces[:, 1]] - vertices[faces[:, 0]]
    e2 = vertices[faces[:, 2]] - vertices[faces[:, 0]]
    n2a = np.cross(e1, e2)                                        # n · 2A
    pts = p0[:, None, :] + s_pts[None, :, None] * e1[:, None, :] + t_pts[None, :, None] * e2[:, None, :]
    volume = float(np.einsum("q,fqi,fi->", weights, pts, n2a) / 3)
    second = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            if i == j:
                integrand = pts[:, :, i] ** 3 / 3
            else:
                integrand = pts[:, :, i] ** 2 * pts[:, :, j] / 2
            second[i, j] = np.einsum("q,fq,f->", weights, integrand, n2a[:, i])
    return volume, 0.5 * (second + second.T)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_parallel_axis_theorem_eq_4_16(seed):
    """inertia_about(p) (the central tensor shifted by Eq. 4.16) against direct integration about p."""
    v, f = _hull(seed)
    base = _props(v, f)
    point = np.array([2.5, -1.0, 0.75]) * seed
    volume, raw = _surface_quadrature(v, f, point)
    direct = np.trace(raw) * np.eye(3) - raw
    assert volume == pytest.approx(base.volume, rel=1e-12)
    assert _rel(np.asarray(base.inertia_about(point)), direct) <= 1e-12
    axis = np.array([1.0, 2.0, -0.5])
    n = axis / np.linalg.norm(axis)
    assert base.moment_about_axis(axis, point) == pytest.approx(n @ direct @ n, rel=1e-12)


def test_surface_quadrature_agrees_with_engine_on_torus():
    s = shapes.torus(0.04, 0.01, segments=32, rings=16)
    m = volume_moments(s.vertices, s.faces)
    volume, raw = _surface_quadrature(s.vertices, s.faces, m.centroid)
    assert volume == pytest.approx(m.volume, rel=1e-12)
    assert _rel(raw, m.second_moment) <= 1e-12


# -- cross-check with trimesh ----------------------------------------------------------------------------

@pytest.mark.parametrize("seed", range(8))
def test_matches_trimesh_on_random_convex_hulls(seed):
    v, f = _hull(seed, points=20 + 10 * seed)
    ours = _props(v, f)
    mesh = trimesh.Trimesh(v, f, process=False)
    theirs = mesh.mass_properties
    assert ours.volume == pytest.approx(theirs.volume, rel=1e-12)        # measured ≤ 5e-16 over 50 hulls
    np.testing.assert_allclose(ours.center_of_mass, theirs.center_mass, rtol=0,
                               atol=1e-12 * np.ptp(v, axis=0).max())
    assert _rel(ours.inertia, theirs.inertia) <= 1e-12
    assert ours.surface_area == pytest.approx(mesh.area, rel=1e-12)


# -- property tests --------------------------------------------------------------------------------------

seeds = st.integers(min_value=0, max_value=2 ** 32 - 1)


@settings(max_examples=40, deadline=None)
@given(seed=seeds, rot_seed=seeds)
def test_property_rotation(seed, rot_seed):
    v, f = _hull(seed, points=12)
    rot = Rotation.random(random_state=rot_seed).as_matrix()
    base, turned = _props(v, f), _props(v @ rot.T, f)
    assert turned.volume == pytest.approx(base.volume, rel=1e-12)
    np.testing.assert_allclose(turned.center_of_mass, rot @ base.center_of_mass, rtol=0,
                               atol=1e-12 * np.abs(v).max())
    assert _rel(turned.inertia, rot @ base.inertia @ rot.T) <= 1e-12
    np.testing.assert_allclose(turned.principal.moments, base.principal.moments, rtol=1e-11)


@settings(max_examples=40, deadline=None)
@given(seed=seeds, offset=st.lists(st.floats(-1e4, 1e4, allow_nan=False), min_size=3, max_size=3))
def test_property_translation(seed, offset):
    v, f = _hull(seed, points=12)
    base, moved = _props(v, f), _props(v + np.array(offset), f)
    assert moved.volume == pytest.approx(base.volume, rel=1e-11)
    assert _rel(moved.inertia, base.inertia) <= 1e-10
    np.testing.assert_allclose(moved.center_of_mass, base.center_of_mass + offset, rtol=0,
                               atol=1e-11 * (1 + np.abs(offset).max()))


@settings(max_examples=40, deadline=None)
@given(seed=seeds, scale=st.floats(1e-4, 1e4))
def test_property_scaling(seed, scale):
    v, f = _hull(seed, points=12)
    base, scaled = _props(v, f), _props(v * scale, f)
    assert scaled.volume == pytest.approx(base.volume * scale ** 3, rel=1e-12)
    assert _rel(scaled.inertia, base.inertia * scale ** 5) <= 1e-12
