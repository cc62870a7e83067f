"""Bounded estimates for open meshes and generalized winding numbers (mesh/estimate.py, winding.py)."""

import numpy as np
import pytest
import trimesh

from conftest import box_arrays
from inertia_tool.mesh.estimate import boundary_edges, patched_estimate, winding_estimate
from inertia_tool.mesh.winding import winding_numbers
from inertia_tool.mass.volume import volume_moments


def test_winding_numbers_of_a_sphere_direct_sum():
    s = trimesh.creation.icosphere(3)
    points = np.array([[0, 0, 0], [0.3, -0.2, 0.1], [2, 0, 0], [0, -3, 1]], dtype=float)
    w = winding_numbers(points, np.asarray(s.vertices), np.asarray(s.faces), fast=False)
    assert np.allclose(w, [1, 1, 0, 0], atol=1e-12)


def test_winding_number_of_a_hemisphere_at_its_centre_is_one_half():
    s = trimesh.creation.icosphere(4)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    top = v[f].mean(axis=1)[:, 2] > 0
    # faces above the equator, symmetric about the centre up to the tessellation: w = ½ to ~1e-2
    w = winding_numbers(np.zeros((1, 3)), v, f[top], fast=False)[0]
    assert abs(w - 0.5) < 2e-2


def test_boundary_of_a_box_with_a_missing_triangle_is_its_three_edges():
    v, f = box_arrays()
    edges = boundary_edges(f[1:], len(v))
    assert len(edges) == 3
    assert sorted(map(tuple, edges)) == sorted([(f[0, 1], f[0, 0]), (f[0, 2], f[0, 1]), (f[0, 0], f[0, 2])])


def test_box_with_a_missing_square_side_is_patched_exactly():
    v, f = box_arrays((1.0, 2.0, 3.0))
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    side = normals[:, 0] > 0                              # the two triangles of the +x side
    est = patched_estimate(v, f[~side], volume_moments)
    assert est.method == "patched"
    assert np.isclose(est.volume, 6.0, rtol=1e-14)        # planar hole: the cone is the flat side
    assert est.uncertainty.mass == 0.0
    assert np.allclose(est.centroid, 0, atol=1e-14)


def test_box_missing_one_triangle_is_bounded_by_the_hull_of_the_hole():
    v, f = box_arrays((1.0, 2.0, 3.0))
    est = patched_estimate(v, f[1:], volume_moments)
    truth = 6.0
    assert abs(est.volume - truth) <= est.uncertainty.mass * est.volume * (1 + 1e-12)


def test_box_missing_two_adjacent_sides_bounds_contain_the_truth():
    v, f = box_arrays((1.0, 2.0, 3.0))
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    gone = (normals[:, 0] > 0) | (normals[:, 1] > 0)
    est = patched_estimate(v, f[~gone], volume_moments)
    # the hole's boundary spans a triangular prism holding half the box
    assert np.isclose(est.uncertainty.volume_in_doubt, 3.0, rtol=1e-12)
    assert abs(est.volume - 6.0) <= est.uncertainty.mass * est.volume
    assert np.linalg.norm(est.centroid) <= est.uncertainty.center_of_mass


def test_crack_pulled_apart_is_within_its_small_bound():
    s = trimesh.creation.icosphere(4)
    v, f = np.asarray(s.vertices).copy(), np.asarray(s.faces)
    truth = volume_moments(v, f)
    # cut the faces crossing the plane x = 0 into two unwelded halves and pull them 1e-5 apart
    side = v[f].mean(axis=1)[:, 0] > 0
    v2 = np.vstack([v, v + [2e-5, 0, 0]])
    f2 = np.where(side[:, None], f + len(v), f)
    est = patched_estimate(v2, f2, volume_moments)
    rel = abs(est.volume - truth.volume) / truth.volume
    assert rel < 1e-4
    assert rel <= est.uncertainty.mass
    assert np.linalg.norm(est.centroid - truth.centroid) <= est.uncertainty.center_of_mass + 1e-12


def test_winding_estimate_of_a_sphere_with_a_hole_brackets_the_truth():
    s = trimesh.creation.icosphere(3)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    open_f = f[v[f].mean(axis=1)[:, 2] < 0.8]
    est = winding_estimate(v, open_f, resolution=48)
    truth = volume_moments(v, f)
    assert est.method == "winding"
    assert abs(est.volume - truth.volume) <= est.uncertainty.mass * est.volume
    assert np.linalg.norm(est.centroid - truth.centroid) <= est.uncertainty.center_of_mass
    # a hole of radius 0.6 in a unit sphere: the band of ambiguous winding numbers over it and the cells the
    # surface crosses (about 2 · area · cell) are in doubt
    assert est.uncertainty.mass < 0.7


@pytest.mark.parametrize("fast", [False, True])
def test_winding_estimate_direct_and_fast_agree(fast):
    pytest.importorskip("igl") if fast else None
    v, f = box_arrays((1.0, 1.0, 1.0))
    est = winding_estimate(v, f, resolution=16)
    assert abs(est.volume - 1.0) <= est.uncertainty.mass * est.volume
