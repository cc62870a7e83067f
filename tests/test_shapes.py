"""Tests of inertia_tool.mass.shapes: the meshes are valid closed solids, ``mesh_exact`` is the polyhedron the mesh
bounds (checked against the signed-tetrahedron engine), and ``exact`` is the ideal solid (checked against
scipy quadrature of the solid of revolution and against Richardson extrapolation of ``mesh_exact``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from scipy import integrate

from inertia_tool import mass_properties
from inertia_tool.mass import shapes
from inertia_tool.errors import UsageError
from inertia_tool.integrals import body_volume_moments, second_moment_to_inertia, volume_moments

# Small resolutions keep the suite fast; every constructor appears once.
SOLIDS = {
    "box": lambda: shapes.box(0.03, 0.02, 0.05),
    "octahedron": lambda: shapes.octahedron(0.02, 0.03, 0.05),
    "cone": lambda: shapes.cone(0.02, 0.05, segments=48),
    "pyramid": lambda: shapes.pyramid(0.02, 0.05, 5),
    "cylinder": lambda: shapes.cylinder(0.01, 0.04, segments=40),
    "prism": lambda: shapes.prism(0.01, 0.04, 6),
    "washer": lambda: shapes.washer(0.03, 0.012, 0.004, segments=40),
    "torus": lambda: shapes.torus(0.04, 0.01, segments=48, rings=16),
    "thin_ring": lambda: shapes.thin_ring(0.05, 0.0005, segments=64, rings=6),
    "sphere": lambda: shapes.sphere(0.02, segments=32, rings=16),
    "hollow_sphere": lambda: shapes.hollow_sphere(0.02, 0.015, segments=32, rings=16),
}
SHELLS = {"hollow_sphere": 2}


def _engine(vertices, faces):
    m = volume_moments(vertices, faces)
    return m, second_moment_to_inertia(m.second_moment)


@pytest.fixture(params=sorted(SOLIDS))
def solid(request):
    return request.param, SOLIDS[request.param]()


# -- mesh validity --------------------------------------------------------------------------------------

def test_mesh_is_closed_consistently_wound_and_outward(solid):
    key, s = solid
    assert s.vertices.dtype == np.float64 and s.vertices.shape[1] == 3
    assert s.faces.dtype == np.int64 and s.faces.shape[1] == 3
    mesh = trimesh.Trimesh(s.vertices, s.faces, process=False)
    assert mesh.is_watertight
    assert mesh.is_winding_consistent
    bodies = mesh.split(only_watertight=True)
    assert len(bodies) == SHELLS.get(key, 1)
    # outward: total volume positive; a cavity shell (inner) has negative volume on its own
    volumes = sorted(b.volume for b in bodies)
    assert mesh.volume > 0
    if key == "hollow_sphere":
        assert volumes[0] < 0 < volumes[1]
    else:
        assert volumes[0] > 0


def test_mesh_has_no_duplicate_vertices_or_degenerate_faces(solid):
    _, s = solid
    assert len(np.unique(s.vertices, axis=0)) == len(s.vertices)
    assert len(np.unique(s.faces, axis=0)) == len(s.faces)
    f = s.faces
    assert np.all((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2]))
    tri = s.vertices[f]
    areas = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    scale = np.ptp(s.vertices, axis=0).max()
    assert areas.min() > 1e-10 * scale ** 2
    assert set(np.unique(f)) == set(range(len(s.vertices)))      # no unused vertices


def test_arrays_are_read_only(solid):
    _, s = solid
    with pytest.raises(ValueError):
        s.vertices[0, 0] = 1.0
    with pytest.raises(ValueError):
        s.faces[0, 0] = 1


def test_exact_is_unit_density_about_the_center(solid):
    _, s = solid
    for props in (s.exact, s.mesh_exact):
        assert props.density == 1.0
        assert props.mass == props.volume > 0
        assert np.allclose(props.center_of_mass, 0.0, atol=1e-15)
        np.testing.assert_array_equal(props.inertia, props.inertia.T)


# -- mesh_exact: the faceted polyhedron -------------------------------------------------------------------

def test_mesh_exact_matches_signed_tetrahedra(solid):
    """The closed forms of the faceted polyhedron (Green's theorem on the meridian polygon, module notes)
    against the independent signed-tetrahedron engine.  The thin ring loses ~2 digits to cancellation
    (volume 1e-4 of its bounding box)."""
    key, s = solid
    rtol = 1e-12 if key == "thin_ring" else 1e-13
    m, inertia = _engine(s.vertices, s.faces)
    e = s.mesh_exact
    scale = np.ptp(s.vertices, axis=0).max()
    assert m.volume == pytest.approx(e.volume, rel=rtol)
    assert np.abs(m.centroid - e.center_of_mass).max() <= rtol * scale
    assert np.abs(inertia - e.inertia).max() <= rtol * np.abs(e.inertia).max()
    assert m.area == pytest.approx(e.surface_area, rel=1e-13)


@pytest.mark.parametrize("key", ["box", "octahedron", "pyramid", "prism"])
def test_polyhedra_mesh_exact_is_exact(key):
    s = SOLIDS[key]()
    assert s.mesh_exact is s.exact


def test_pyramid_is_the_cone_mesh():
    """The n-segment cone mesh bounds the regular n-gonal pyramid: same vertices, same closed form."""
    c = shapes.cone(0.02, 0.05, segments=7)
    p = shapes.pyramid(0.02, 0.05, 7)
    np.testing.assert_array_equal(c.vertices, p.vertices)
    np.testing.assert_array_equal(c.faces, p.faces)
    np.testing.assert_allclose(c.mesh_exact.inertia, p.exact.inertia, rtol=1e-14, atol=0)
    assert c.mesh_exact.surface_area == pytest.approx(p.exact.surface_area, rel=1e-14)


def test_square_prism_is_a_box():
    """A 4-gonal prism of circumradius R is a square box of side R√2 (rotated 45° about z)."""
    r, h = 0.3, 0.7
    p = shapes.prism(r, h, 4).exact
    b = shapes.box(r * math.sqrt(2), r * math.sqrt(2), h).exact
    assert p.volume == pytest.approx(b.volume, rel=1e-15)
    np.testing.assert_allclose(p.inertia, b.inertia, rtol=1e-14, atol=0)
    assert p.surface_area == pytest.approx(b.surface_area, rel=1e-15)


# -- exact: the ideal solid ------------------------------------------------------------------------------

def _scipy_revolution(region, rho_range):
    """Volume, ∫z²dV about z = 0 and ∫(x²+y²)dV of the solid of revolution of ``region`` by scipy dblquad.

    ``region(ρ) -> (z_low, z_high)`` on ``rho_range``; returns ``(V, ∫z² dV, ∫ρ² dV)`` (about z = 0).
    """
    lo, hi = rho_range
    out = []
    for p, q in ((1, 0), (1, 2), (3, 0)):
        val, _ = integrate.dblquad(lambda z, rho: rho ** p * z ** q, lo, hi,
                                   lambda rho: region(rho)[0], lambda rho: region(rho)[1],
                                   epsabs=0, epsrel=1e-12)
        out.append(2 * math.pi * val)
    return out


CONE_R, CONE_H = 0.02, 0.05
TORUS_R, TORUS_A = 0.04, 0.01


@pytest.mark.parametrize("key, factory, region, rho_range", [
    ("cone", lambda: shapes.cone(CONE_R, CONE_H),
     lambda rho: (-CONE_H / 4, -CONE_H / 4 + CONE_H * (1 - rho / CONE_R)), (0, CONE_R)),
    ("torus", lambda: shapes.torus(TORUS_R, TORUS_A),
     lambda rho: (-math.sqrt(max(TORUS_A ** 2 - (rho - TORUS_R) ** 2, 0)),
                  math.sqrt(max(TORUS_A ** 2 - (rho - TORUS_R) ** 2, 0))), (TORUS_R - TORUS_A, TORUS_R + TORUS_A)),
    ("sphere", lambda: shapes.sphere(0.02),
     lambda rho: (-math.sqrt(max(0.02 ** 2 - rho ** 2, 0)), math.sqrt(max(0.02 ** 2 - rho ** 2, 0))), (0, 0.02)),
    ("washer", lambda: shapes.washer(0.03, 0.012, 0.004), lambda rho: (-0.002, 0.002), (0.012, 0.03)),
    ("cylinder", lambda: shapes.cylinder(0.01, 0.04), lambda rho: (-0.02, 0.02), (0, 0.01)),
])
def test_exact_matches_scipy_quadrature(key, factory, region, rho_range):
    """The closed forms of the ideal solids against adaptive quadrature of Eq. (4.13) in cylindrical coordinates."""
    e = factory().exact
    volume, zz, radial = _scipy_revolution(region, rho_range)
    assert e.volume == pytest.approx(volume, rel=1e-9)
    assert e.inertia[2, 2] == pytest.approx(radial, rel=1e-9)
    assert e.inertia[0, 0] == pytest.approx(0.5 * radial + zz, rel=1e-9)


def test_hollow_sphere_exact_is_sphere_minus_sphere():
    outer, inner = shapes.sphere(0.02).exact, shapes.sphere(0.015).exact
    hollow = shapes.hollow_sphere(0.02, 0.015).exact
    assert hollow.volume == pytest.approx(outer.volume - inner.volume, rel=1e-14)
    np.testing.assert_allclose(hollow.inertia, outer.inertia - inner.inertia, rtol=1e-14, atol=0)
    assert hollow.surface_area == pytest.approx(outer.surface_area + inner.surface_area, rel=1e-14)


def test_octahedron_exact_against_six_tetrahedra_formula():
    """Exercise 4.9 closed form against Tonon's simplex formula applied by hand to the 8 octant tetrahedra:
    ∫x² over the tetrahedron (0, a e_x, b e_y, c e_z) is V_t (a² + a²)/20 = V_t a²/10."""
    a, b, c = 0.02, 0.03, 0.05
    e = shapes.octahedron(a, b, c).exact
    v_t = a * b * c / 6
    second = 8 * v_t * np.array([a, b, c]) ** 2 / 10
    assert e.volume == pytest.approx(8 * v_t, rel=1e-15)
    np.testing.assert_allclose(np.diag(e.inertia), second.sum() - second, rtol=1e-15)


@pytest.mark.parametrize("factory", [
    lambda n: shapes.cone(0.02, 0.05, segments=n),
    lambda n: shapes.torus(0.04, 0.01, segments=n, rings=n // 2),
    lambda n: shapes.sphere(0.02, segments=n, rings=n // 2),
    lambda n: shapes.washer(0.03, 0.012, 0.004, segments=n),
], ids=["cone", "torus", "sphere", "washer"])
def test_richardson_extrapolated_mesh_exact_reaches_exact(factory):
    """mesh_exact = exact·(1 + c/n² + O(1/n⁴)); one Richardson step (4 f(2n) − f(n))/3 must land within
    O(1/n⁴) of the ideal closed form — an independent check of both sets of formulas."""
    n = 256
    coarse, fine, ideal = factory(n).mesh_exact, factory(2 * n).mesh_exact, factory(n).exact
    for get in (lambda p: p.volume, lambda p: p.inertia[0, 0], lambda p: p.inertia[2, 2],
                lambda p: p.surface_area):
        extrapolated = (4 * get(fine) - get(coarse)) / 3
        raw = abs(get(coarse) / get(ideal) - 1)
        assert raw > 1e-5                                           # the raw error is visible ...
        assert abs(extrapolated / get(ideal) - 1) < 1e-3 * raw      # ... and cancels at second order


# -- parameters ------------------------------------------------------------------------------------------

def test_center_moves_vertices_and_center_of_mass():
    c = np.array([0.1, -0.2, 0.3])
    base = shapes.torus(0.04, 0.01, segments=12, rings=6)
    moved = shapes.torus(0.04, 0.01, segments=12, rings=6, center=c)
    np.testing.assert_allclose(moved.vertices, base.vertices + c, rtol=0, atol=1e-17)
    np.testing.assert_array_equal(moved.exact.center_of_mass, c)
    np.testing.assert_allclose(moved.mesh_exact.center_of_mass, c, rtol=0, atol=1e-17)
    np.testing.assert_array_equal(moved.exact.inertia, base.exact.inertia)
    m = volume_moments(moved.vertices, moved.faces)
    np.testing.assert_allclose(m.centroid, c, rtol=0, atol=1e-15)


def test_cone_center_of_mass_is_quarter_height_above_base():
    """Exercise 4.6a: the centre of mass is h/4 above the base; the base lies at z = center − h/4."""
    s = shapes.cone(0.02, 0.05, segments=16, center=[0, 0, 1.0])
    assert s.vertices[:, 2].min() == pytest.approx(1.0 - 0.05 / 4, rel=1e-15)
    assert s.vertices[:, 2].max() == pytest.approx(1.0 + 0.75 * 0.05, rel=1e-15)
    assert volume_moments(s.vertices, s.faces).centroid[2] == pytest.approx(1.0, rel=1e-14)


def test_resolution_keywords_control_face_counts():
    assert len(shapes.cone(1, 1, segments=10).faces) == 20
    assert len(shapes.cylinder(1, 1, segments=10).faces) == 40
    assert len(shapes.torus(2, 1, segments=10, rings=6).faces) == 120
    assert len(shapes.sphere(1, segments=10, rings=6).faces) == 2 * 10 * (6 - 1)
    assert len(shapes.sphere(1, segments=10, rings=6).vertices) == 10 * 5 + 2
    assert len(shapes.hollow_sphere(2, 1, segments=10, rings=6).faces) == 4 * 10 * 5


@pytest.mark.parametrize("call", [
    lambda: shapes.cone(-1, 1), lambda: shapes.cone(1, float("nan")), lambda: shapes.cone(1, 1, segments=2),
    lambda: shapes.cone(1, 1, segments=3.0), lambda: shapes.cone("a", 1), lambda: shapes.box(1, 0, 1),
    lambda: shapes.torus(1, 1), lambda: shapes.torus(1, 2), lambda: shapes.torus(2, 1, rings=2),
    lambda: shapes.washer(1, 2, 1), lambda: shapes.hollow_sphere(1, 1), lambda: shapes.sphere(1, rings=1),
    lambda: shapes.pyramid(1, 1, 2), lambda: shapes.octahedron(1, 1, 1, center=[0, 0]),
    lambda: shapes.prism(1, 1, True),
])
def test_bad_parameters_raise_usage_error(call):
    with pytest.raises(UsageError) as info:
        call()
    assert isinstance(info.value, ValueError)
    assert "Expected" in str(info.value)


# -- STL output ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("binary", [True, False])
def test_write_stl_round_trips_through_trimesh(tmp_path, binary):
    s = shapes.torus(0.04, 0.01, segments=24, rings=12)
    path = shapes.write_stl(s, tmp_path / "torus.stl", binary=binary, units="mm")
    loaded = trimesh.load(path, file_type="stl")
    assert len(loaded.faces) == len(s.faces)
    assert loaded.is_watertight and loaded.is_winding_consistent
    # coordinates written in mm (float32): volume in mm³ to float32 precision
    assert loaded.volume == pytest.approx(s.mesh_exact.volume * 1e9, rel=1e-6)
    normals = np.cross(*(s.vertices[s.faces[:, k]] - s.vertices[s.faces[:, 0]] for k in (1, 2)))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    np.testing.assert_allclose(loaded.face_normals, normals, atol=1e-5)
    if binary:
        assert path.stat().st_size == 84 + 50 * len(s.faces)


def test_hollow_sphere_shells_have_opposite_orientation():
    """Outer shell positive, cavity shell negative: per-shell engine volumes via body labels."""
    s = shapes.hollow_sphere(0.02, 0.015, segments=16, rings=8)
    labels = (np.linalg.norm(s.vertices[s.faces[:, 0]], axis=1) < 0.0175).astype(int)
    outer, inner = body_volume_moments(s.vertices, s.faces, labels, 2)
    assert outer.volume > 0 > inner.volume
    assert outer.volume + inner.volume == pytest.approx(s.mesh_exact.volume, rel=1e-14)


# -- the committed sample meshes -------------------------------------------------------------------------

def _sample_table():
    import importlib.util
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "meshes" / "make_meshes.py"
    spec = importlib.util.spec_from_file_location("make_meshes", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.HERE, module.SAMPLES


MESH_DIR, SAMPLES = _sample_table()


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_sample_mesh_files_are_current_and_exact(tmp_path, name):
    """meshes/*.stl are byte-identical to what ``python meshes/make_meshes.py`` writes, stay under 200 KB,
    and ``inertia_tool.mass_properties(..., units="mm")`` reads them back (float32) to the closed-form
    polyhedron values within 1e-6."""
    solid = SAMPLES[name][0]()
    committed = MESH_DIR / name
    fresh = shapes.write_stl(solid, tmp_path / name, units="mm")
    assert committed.read_bytes() == fresh.read_bytes()
    assert committed.stat().st_size < 200 * 1024
    props = mass_properties(committed, units="mm", density=1.0)          # the project's own reader
    e = solid.mesh_exact
    assert props.volume == pytest.approx(e.volume, rel=1e-6)
    assert np.abs(props.center_of_mass - e.center_of_mass).max() <= 1e-6 * np.ptp(solid.vertices, axis=0).max()
    assert np.abs(props.inertia - e.inertia).max() <= 1e-6 * np.abs(e.inertia).max()
    assert props.surface_area == pytest.approx(e.surface_area, rel=1e-6)
    assert "mm" in (MESH_DIR / "README.md").read_text(encoding="utf-8")
    assert f"`{name}`" in (MESH_DIR / "README.md").read_text(encoding="utf-8")
