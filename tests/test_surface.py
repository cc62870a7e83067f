"""Surface and curve moments (inertia_tool.mass.surface) and the shell model (thinwall.shell_mass_properties)."""

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate
from scipy.spatial.transform import Rotation

from inertia_tool.errors import UsageError
from inertia_tool.mass.surface import (curve_moments, inward_offset_coefficient, shell_inertia, surface_moments,
                                  wire_inertia)
from inertia_tool.mass.thinwall import shell_mass_properties
from conftest import assert_tensor_close


def _triangle_quadrature(p1, p2, p3):
    """Area, ∫x dA and ∫x xᵀ dA over one triangle by scipy's adaptive 2-D quadrature (independent of the identity)."""
    e1, e2 = p2 - p1, p3 - p1
    jac = np.linalg.norm(np.cross(e1, e2))

    def point(u, w):
        return p1 + u * e1 + w * e2

    area = jac * integrate.dblquad(lambda w, u: 1.0, 0, 1, 0, lambda u: 1 - u)[0]
    first = np.array([jac * integrate.dblquad(lambda w, u: point(u, w)[i], 0, 1, 0, lambda u: 1 - u)[0]
                      for i in range(3)])
    second = np.array([[jac * integrate.dblquad(lambda w, u: point(u, w)[i] * point(u, w)[j], 0, 1, 0,
                                                lambda u: 1 - u)[0] for j in range(3)] for i in range(3)])
    return area, first, second


def test_triangle_identity_against_quadrature():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(3, 3)) + np.array([0.7, -0.2, 1.5])
    sm = surface_moments(p, np.array([[0, 1, 2]]), origin=np.zeros(3))
    area, first, second = _triangle_quadrature(*p)
    assert sm.area == pytest.approx(area, rel=1e-12)
    np.testing.assert_allclose(sm.centroid * sm.area, first, rtol=1e-10)
    # central second moment + parallel-axis term = raw second moment about the origin
    raw = sm.second_moment + sm.area * np.outer(sm.centroid, sm.centroid)
    np.testing.assert_allclose(raw, second, rtol=1e-9, atol=1e-12)


def test_segment_identity_against_quadrature():
    p, q = np.array([0.3, -1.0, 2.0]), np.array([1.1, 0.4, -0.5])
    cm = curve_moments(np.array([p, q]), np.array([[0, 1]]), origin=np.zeros(3))
    length = np.linalg.norm(q - p)
    raw = cm.second_moment + cm.length * np.outer(cm.centroid, cm.centroid)
    for i in range(3):
        for j in range(3):
            ref = length * integrate.quad(lambda u: (p + u * (q - p))[i] * (p + u * (q - p))[j], 0, 1)[0]
            assert raw[i, j] == pytest.approx(ref, rel=1e-12, abs=1e-14)
    assert cm.length == pytest.approx(length)


def test_thin_walled_box_equals_sum_of_six_plates():
    a, b, c, t, rho = 0.3, 0.2, 0.1, 0.004, 7850.0
    box = trimesh.creation.box([a, b, c])
    props = shell_mass_properties((box.vertices, box.faces), thickness=t, density=rho)
    # closed form: six plates of thickness t centred on the faces, each I = m/12 (sides² + t²) + offset terms
    total = np.zeros(3)
    mass = 0.0
    for (u, v, w, axis) in ((a, b, c, 2), (a, c, b, 1), (b, c, a, 0)):
        m = rho * t * u * v
        mass += 2 * m
        dims = {2: (a, b, t), 1: (a, t, c), 0: (t, b, c)}[axis]
        own = m / 12 * np.array([dims[1] ** 2 + dims[2] ** 2, dims[0] ** 2 + dims[2] ** 2, dims[0] ** 2 + dims[1] ** 2])
        shift = np.full(3, m * (w / 2) ** 2)
        shift[axis] = 0.0
        total += 2 * (own + shift)
    assert props.mass == pytest.approx(mass, rel=1e-13)
    np.testing.assert_allclose(np.diag(props.inertia), total, rtol=1e-12)
    np.testing.assert_allclose(props.inertia - np.diag(np.diag(props.inertia)), 0, atol=1e-15)


def test_flat_plate_matches_trimesh_solid_slab():
    """An open two-triangle sheet of thickness t is exactly the a × b × t slab (trimesh's volume integral)."""
    a, b, t = 0.5, 0.2, 0.01
    v = np.array([[-a / 2, -b / 2, 0], [a / 2, -b / 2, 0], [a / 2, b / 2, 0], [-a / 2, b / 2, 0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    rot = Rotation.from_euler("zyx", [20, 30, -40], degrees=True).as_matrix()
    props = shell_mass_properties(((v @ rot.T) + [1, 2, 3], f), thickness=t, density=1000)
    slab = trimesh.creation.box([a, b, t])
    slab.apply_transform(np.vstack([np.hstack([rot, [[1], [2], [3]]]), [0, 0, 0, 1]]))
    slab.density = 1000
    assert props.mass == pytest.approx(slab.mass, rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, slab.center_mass, atol=1e-12)
    np.testing.assert_allclose(props.inertia, slab.moment_inertia, rtol=1e-9, atol=1e-12 * slab.moment_inertia.max())
    assert props.mesh.watertight is False


def test_thin_spherical_shell_two_thirds_mr2_converges():
    """Thin spherical shell: I = 2/3 M R²; the icosphere error falls ~4× per subdivision (O(h²))."""
    radius, t = 1.0, 1e-4
    errors = []
    for level in (3, 4, 5):
        s = trimesh.creation.icosphere(level, radius=radius)
        props = shell_mass_properties((s.vertices, s.faces), thickness=t, density=1.0)
        exact = 2.0 / 3.0 * props.mass * radius ** 2
        np.testing.assert_allclose(props.principal.moments / exact, 1.0, atol=0.01)
        errors.append(abs(props.principal.moments.mean() / exact - 1))
    assert errors[2] < 5e-4
    assert 3.0 < errors[0] / errors[1] < 5.0 and 3.0 < errors[1] / errors[2] < 5.0


def test_thick_spherical_shell_error_is_second_order_in_t_over_r():
    """The exact hollow sphere (radii R ± t/2) has I/M = 2/5 (R2⁵ − R1⁵)/(R2³ − R1³) = R²(2/3 + 5/18 (t/R)²) + ...
    The mid-surface model gives R²(2/3 + 1/18 (t/R)²): a curvature error of −(t/R)²/3 relative, as documented."""
    radius = 1.0
    s = trimesh.creation.icosphere(6, radius=radius)

    def error(t):
        props = shell_mass_properties((s.vertices, s.faces), thickness=t, density=1.0)
        r1, r2 = radius - t / 2, radius + t / 2
        i_per_mass = 0.4 * (r2 ** 5 - r1 ** 5) / (r2 ** 3 - r1 ** 3)
        return props.principal.moments.mean() / props.mass / i_per_mass - 1

    facets = error(1e-6)        # the polyhedron's own O(h²) error, common to every t
    for t in (0.1, 0.05):
        assert error(t) - facets == pytest.approx(-(t / radius) ** 2 / 3, rel=0.02)


def test_thin_ring_wire_polygon_exact_and_limit():
    """Regular n-gon of circumradius R: each chord L = 2R sin(π/n) at distance d = R cos(π/n) gives
    ∫ r² ds = L d² + L³/12 exactly; n → ∞ gives the thin ring I_z = M R², I_x = I_y = M R²/2 (§4.3.2)."""
    radius, lam = 0.3, 2.0
    for n in (6, 64, 1024):
        ang = 2 * np.pi * np.arange(n) / n
        pts = np.column_stack([radius * np.cos(ang), radius * np.sin(ang), np.zeros(n)])
        segs = np.column_stack([np.arange(n), (np.arange(n) + 1) % n])
        cm = curve_moments(pts, segs)
        inertia = wire_inertia(cm, lam)
        chord, dist = 2 * radius * np.sin(np.pi / n), radius * np.cos(np.pi / n)
        mass = lam * n * chord
        assert lam * cm.length == pytest.approx(mass, rel=1e-13)
        assert inertia[2, 2] == pytest.approx(lam * n * (chord * dist ** 2 + chord ** 3 / 12), rel=1e-12)
        assert inertia[0, 0] == pytest.approx(inertia[2, 2] / 2, rel=1e-12)
    assert inertia[2, 2] == pytest.approx(mass * radius ** 2, rel=1e-5)


def test_cube_offset_coefficient_and_exact_inner_box():
    """Box a×b×c: the inner offset box is exact, volume lost = A s − 4(a+b+c) s² + 8 s³, so K = 4(a+b+c)."""
    a, b, c = 0.3, 0.2, 0.1
    box = trimesh.creation.box([a, b, c])
    assert inward_offset_coefficient(box.vertices, box.faces) == pytest.approx(4 * (a + b + c), rel=1e-12)


def test_tetrahedron_offset_coefficient_equals_area_over_inradius():
    """A polyhedron with an inscribed sphere offsets inward to a scaled copy: K = A / r (regular tetrahedron)."""
    v = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    f = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    mesh = trimesh.Trimesh(v, f)
    assert mesh.volume > 0
    edge = np.linalg.norm(v[0] - v[1])
    area = np.sqrt(3) * edge ** 2
    inradius = edge / (2 * np.sqrt(6))
    assert inward_offset_coefficient(v, f) == pytest.approx(area / inradius, rel=1e-12)


def test_offset_coefficient_of_sphere_tends_to_area_over_radius():
    s = trimesh.creation.icosphere(5, radius=2.0)
    assert inward_offset_coefficient(s.vertices, s.faces) == pytest.approx(4 * np.pi * 2.0, rel=2e-3)


def test_offset_coefficient_refuses_open_surface():
    box = trimesh.creation.box([1, 1, 1])
    with pytest.raises(UsageError):
        inward_offset_coefficient(box.vertices, box.faces[:-1])


def test_winding_does_not_matter():
    box = trimesh.creation.box([1, 2, 3])
    f = box.faces.copy()
    f[::2] = f[::2, ::-1]
    a = surface_moments(box.vertices, box.faces)
    b = surface_moments(box.vertices, f)
    assert_tensor_close(a.second_moment, b.second_moment, rtol=1e-13)
    np.testing.assert_allclose(a.normal_moment, b.normal_moment, rtol=1e-13)


def test_zero_area_refused():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], dtype=float)
    with pytest.raises(UsageError):
        surface_moments(v, np.array([[0, 1, 2]]))
    with pytest.raises(UsageError):
        shell_inertia(surface_moments(*_unit_square()), 0.0, 1.0)


def _unit_square():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
       st.lists(st.floats(-5, 5), min_size=3, max_size=3))
def test_rigid_motion_rotates_the_tensor(angles, shift):
    """Property: moving the surface by x ↦ R x + t gives the inertia R I Rᵀ about the moved centroid."""
    mesh = trimesh.creation.cylinder(radius=0.2, height=0.7, sections=12)
    rot = Rotation.from_euler("xyz", angles).as_matrix()
    base = shell_mass_properties((mesh.vertices, mesh.faces), thickness=0.01, density=10.0)
    moved = shell_mass_properties((mesh.vertices @ rot.T + shift, mesh.faces), thickness=0.01, density=10.0)
    np.testing.assert_allclose(moved.center_of_mass, rot @ base.center_of_mass + shift, atol=1e-12)
    np.testing.assert_allclose(moved.inertia, rot @ base.inertia @ rot.T, atol=1e-12 * np.abs(base.inertia).max())


def test_cli_shell_model_end_to_end(tmp_path):
    """``analyze --model shell --thickness 2mm`` in a subprocess: mass ρ t A of a 100 × 50 × 20 mm box surface."""
    import json
    import os
    import subprocess
    import sys
    from conftest import write_binary_stl
    box = trimesh.creation.box([100.0, 50.0, 20.0])
    p = tmp_path / "casing.stl"
    write_binary_stl(p, box.vertices, box.faces)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    run = subprocess.run([sys.executable, "-m", "inertia_tool.cli", "analyze", str(p), "--units", "mm", "--material",
                          "steel", "--model", "shell", "--thickness", "2mm", "--json"], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": root}, timeout=120)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    area = 2 * (0.1 * 0.05 + 0.1 * 0.02 + 0.05 * 0.02)
    assert out["mass"] == pytest.approx(7850 * 0.002 * area, rel=1e-6)
    assert out["model"] == {"model": "shell", "thickness": pytest.approx(0.002),
                            "approximation": out["model"]["approximation"]}
