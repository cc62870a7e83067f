import numpy as np
import pytest

from conftest import box_arrays
from inertia_tool.mesh.checks import edge_topology, repeated_corner_faces, shell_labels, winding_number
from inertia_tool.integrals import volume_moments


# every test runs on the C extension (when built) and on the pure-numpy path
pytestmark = pytest.mark.usefixtures("engine_path")


def test_closed_box_is_oriented():
    v, f = box_arrays()
    t = edge_topology(f, len(v), v)
    assert t.closed and t.oriented
    assert t.edges == 18  # 12 box edges + 6 face diagonals
    assert (t.boundary_edges, t.nonmanifold_edges, t.misoriented_edges) == (0, 0, 0)


def test_missing_face_leaves_three_boundary_edges_and_says_where():
    v, f = box_arrays()
    t = edge_topology(f[1:], len(v), v)
    assert t.boundary_edges == 3 and not t.closed
    missing = set(map(tuple, v[f[0]]))
    for a, b in t.sample[:3]:
        assert tuple(a) in missing and tuple(b) in missing


def test_one_flipped_face_is_three_misoriented_edges():
    v, f = box_arrays()
    f = f.copy()
    f[0] = f[0, ::-1]
    t = edge_topology(f, len(v), v)
    assert t.closed and not t.oriented
    assert t.misoriented_edges == 3


def test_fin_makes_a_nonmanifold_edge():
    v, f = box_arrays()
    # a third face on an existing edge, plus its back side, makes that edge shared by 4 faces
    a, b = f[0, 0], f[0, 1]
    v2 = np.vstack([v, [[5.0, 5.0, 5.0]]])
    fin = np.array([[a, b, len(v)], [b, a, len(v)]])
    t = edge_topology(np.vstack([f, fin]), len(v2), v2)
    assert t.nonmanifold_edges == 1


def test_degenerate_faces_are_split_into_repeated_and_zero_area():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])
    f = np.array([[0, 1, 3], [0, 0, 1], [0, 1, 2]])
    np.testing.assert_array_equal(repeated_corner_faces(f), [False, True, False])
    assert volume_moments(v, f).zero_area_faces == 2  # the repeated-corner face and the collinear one


def test_shell_labels_two_boxes():
    v1, f1 = box_arrays()
    v2, f2 = box_arrays(center=(10, 0, 0))
    v = np.vstack([v1, v2])
    f = np.vstack([f1, f2 + len(v1)])
    labels, n = shell_labels(f, len(v))
    assert n == 2
    np.testing.assert_array_equal(labels, [0] * len(f1) + [1] * len(f2))


@pytest.mark.parametrize("point, expected", [((0, 0, 0), 1.0), ((0.4, 0.9, 1.4), 1.0), ((3, 0, 0), 0.0),
                                             ((0, 0, -7), 0.0)])
def test_winding_number_of_box(point, expected):
    v, f = box_arrays()
    assert winding_number(point, v, f) == pytest.approx(expected, abs=1e-12)
    assert winding_number(point, v, f[:, ::-1]) == pytest.approx(-expected, abs=1e-12)
