"""Directed-edge balance, consistent orientation and the distance-based tolerance weld (mesh/orient.py, merge.py)."""

import numpy as np
import trimesh

from conftest import box_arrays
from inertia_tool.mesh.merge import merge_close_vertices
from inertia_tool.mesh.orient import edge_balance, orient_consistently
from inertia_tool.integrals import volume_moments


def _two_tetrahedra_sharing_an_edge():
    """Two unit right tetrahedra meeting only along the edge (0,0,0)-(0,0,1): non-manifold but balanced."""
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], dtype=float)
    tet = np.array([[0, 3, 2], [0, 1, 3], [0, 2, 1], [1, 2, 3]])    # outward for corners 0, 1, 2, 3
    other = np.where(tet == 2, 4, np.where(tet == 3, 5, tet))       # the half turn about z keeps the winding
    return v, np.vstack([tet, other])


def test_closed_box_is_balanced():
    v, f = box_arrays()
    census = edge_balance(f, len(v))
    assert census.balanced and census.edges == 18 and census.nonmanifold_edges == 0


def test_tetrahedra_sharing_an_edge_are_balanced_but_not_manifold():
    v, f = _two_tetrahedra_sharing_an_edge()
    census = edge_balance(f, len(v))
    assert census.balanced and census.nonmanifold_edges == 1 and census.boundary_edges == 0
    assert np.isclose(volume_moments(v, f).volume, 2 * (1 / 6))


def test_missing_face_is_unbalanced():
    v, f = box_arrays()
    census = edge_balance(f[1:], len(v))
    assert not census.balanced and census.boundary_edges == 3 and census.unbalanced_edges == 3


def test_flipped_faces_are_turned_back_keeping_the_majority():
    v, f = box_arrays((1.0, 2.0, 3.0))
    broken = f.copy()
    broken[[0, 5, 7]] = broken[[0, 5, 7]][:, ::-1]
    assert not edge_balance(broken, len(v)).balanced
    fixed = orient_consistently(broken, len(v), v)
    assert fixed.flipped_faces == 3 and fixed.patches == 1 and fixed.orientable
    assert np.array_equal(fixed.faces, f)
    assert np.isclose(volume_moments(v, fixed.faces).volume, 6.0, rtol=1e-14)


def test_each_shell_oriented_on_its_own_and_an_inward_cavity_stays_inward():
    outer_v, outer_f = box_arrays((4.0, 4.0, 4.0))
    inner_v, inner_f = box_arrays((1.0, 1.0, 1.0))
    v = np.vstack([outer_v, inner_v])
    f = np.vstack([outer_f, inner_f[:, ::-1] + len(outer_v)])     # cavity wound inward on purpose
    broken = f.copy()
    broken[[2, 14]] = broken[[2, 14]][:, ::-1]
    fixed = orient_consistently(broken, len(v), v)
    assert fixed.flipped_faces == 2 and fixed.patches == 2
    assert np.isclose(volume_moments(v, fixed.faces).volume, 64.0 - 1.0, rtol=1e-14)


def test_moebius_strip_is_reported_non_orientable():
    n = 12
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = lambda s: np.stack([(1 + s * np.cos(t / 2)) * np.cos(t), (1 + s * np.cos(t / 2)) * np.sin(t),  # noqa: E731
                               s * np.sin(t / 2)], axis=1)
    v = np.vstack([ring(-0.2), ring(0.2)])
    f = []
    for i in range(n):
        j = (i + 1) % n
        a, b = i, n + i
        c, d = (j, n + j) if j else (n + j, j)    # the half twist swaps the two rims
        f += [[a, c, b], [b, c, d]]
    assert not orient_consistently(np.array(f), len(v), v).orientable


def test_tolerance_weld_closes_a_soup_with_rounding_noise():
    sphere = trimesh.creation.icosphere(3)
    rng = np.random.default_rng(1)
    soup = np.asarray(sphere.vertices)[np.asarray(sphere.faces)].reshape(-1, 3)
    soup = soup + rng.normal(0, 2e-8, soup.shape)          # copies differ by ~1e-8 of the diagonal
    faces = np.arange(len(soup)).reshape(-1, 3)
    merged = merge_close_vertices(soup, faces, 1e-6)
    assert edge_balance(merged.faces, len(soup)).balanced
    assert merged.merged_vertices == len(soup) - len(sphere.vertices)
    assert merged.largest_move < 1e-6
    assert np.isclose(volume_moments(soup, merged.faces).volume, sphere.volume, rtol=1e-6)


def test_tolerance_weld_merges_pairs_a_grid_would_split():
    # two copies 1e-9 apart on either side of a multiple of the tolerance: a grid cell boundary
    v, f = box_arrays((1.0, 1.0, 1.0))
    soup = v[f].reshape(-1, 3)
    soup[0::2] += np.array([0.5e-9, 0, 0])
    soup[1::2] -= np.array([0.5e-9, 0, 0])
    merged = merge_close_vertices(soup, np.arange(len(soup)).reshape(-1, 3), 1e-6)
    assert edge_balance(merged.faces, len(soup)).balanced
