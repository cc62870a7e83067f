import dataclasses

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from conftest import box_arrays
from inertia_tool import mass_properties
from inertia_tool.mass import combine, point_mass
from inertia_tool.errors import UsageError
from conftest import assert_tensor_close


def test_box_closed_form():
    a, b, c = 1.0, 2.0, 3.0
    p = mass_properties(box_arrays((a, b, c)), density=7.0)
    m = 7.0 * a * b * c
    assert p.mass == pytest.approx(m, rel=1e-15)
    np.testing.assert_allclose(p.inertia, np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12,
                               rtol=1e-14, atol=1e-14)
    assert p.surface_area == pytest.approx(2 * (a * b + b * c + a * c), rel=1e-14)


def test_parallel_axis_theorem_against_direct_integration():
    v, f = box_arrays((1.0, 2.0, 3.0), center=(0.3, -0.2, 0.7))
    p = mass_properties((v, f))
    point = np.array([1.0, 2.0, -3.0])
    about = np.asarray(p.inertia_about(point))
    from inertia_tool.integrals import volume_moments
    vm = volume_moments(v - point, f)
    d = vm.centroid
    second_about_point = vm.second_moment + vm.volume * np.outer(d, d)
    direct = p.density * (np.trace(second_about_point) * np.eye(3) - second_about_point)
    np.testing.assert_allclose(about, direct, rtol=1e-13)
    assert p.inertia_about(point).reference_point.tolist() == point.tolist()


def test_moment_about_axis_eq_4_17():
    p = mass_properties(box_arrays((1.0, 2.0, 3.0)))
    # axis along z through (2, 0, 5): I_zz(cm) + M * 2^2 (the z offset does not count)
    assert p.moment_about_axis([0, 0, 2], point=[2, 0, 5]) == pytest.approx(p.inertia[2, 2] + p.mass * 4, rel=1e-14)
    n = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    assert p.moment_about_axis(n) == pytest.approx(n @ p.inertia @ n, rel=1e-14)
    with pytest.raises(UsageError):
        p.moment_about_axis([0, 0, 0])


def test_transformed_matches_integrating_the_moved_mesh():
    m = trimesh.creation.cone(0.5, 2.0, sections=20)
    r = Rotation.from_euler("zyz", [0.3, 1.1, -0.4]).as_matrix()
    t = np.array([3.0, -1.0, 2.0])
    p = mass_properties(m).transformed(r, t)
    moved = mass_properties((m.vertices @ r.T + t, m.faces))
    np.testing.assert_allclose(p.center_of_mass, moved.center_of_mass, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(p.inertia, moved.inertia, atol=1e-14 * np.abs(moved.inertia).max())


def test_combine_equals_union_of_disjoint_parts():
    a = box_arrays((1.0, 1.0, 1.0))
    b = box_arrays((1.0, 2.0, 0.5), center=(3.0, 1.0, -1.0))
    pa = mass_properties(a, density=2.0)
    pb = mass_properties(b, density=2.0)
    union = mass_properties((np.vstack([a[0], b[0]]), np.vstack([a[1], b[1] + len(a[0])])), density=2.0)
    both = pa + pb
    assert both.mass == pytest.approx(union.mass, rel=1e-14)
    np.testing.assert_allclose(both.center_of_mass, union.center_of_mass, rtol=1e-14)
    assert_tensor_close(both.inertia, union.inertia, rtol=1e-13)
    assert len(union.parts) == 2


def test_point_mass_combines_like_a_tiny_cube():
    body = mass_properties(box_arrays((1.0, 1.0, 1.0)), density=1.0)
    tiny = mass_properties(box_arrays((1e-4, 1e-4, 1e-4), center=(2.0, 0.0, 0.0)), density=0.5e12)
    with_point = body + point_mass(tiny.mass, [2.0, 0.0, 0.0])
    with_cube = body + tiny
    np.testing.assert_allclose(with_point.inertia, with_cube.inertia, rtol=1e-8, atol=1e-12 * with_cube.inertia.max())


def test_with_mass_scales_density_and_inertia():
    p = mass_properties(box_arrays(), density=1.0)
    q = p.with_mass(12.0)
    assert q.density == pytest.approx(2.0) and q.mass == 12.0
    assert_tensor_close(q.inertia, 2.0 * p.inertia, rtol=1e-7)


def test_results_are_frozen():
    p = mass_properties(box_arrays())
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.mass = 3.0
    with pytest.raises(ValueError):
        p.inertia[0, 0] = 1.0


def test_combine_rejects_nothing():
    with pytest.raises(UsageError):
        combine([])
