import numpy as np
import pytest

from inertia_tool.mesh.weld import weld_exact, weld_tolerance


# every test runs on the C extension (when built) and on the pure-numpy path
pytestmark = pytest.mark.usefixtures("engine_path")


def test_weld_exact_recovers_shared_vertices_of_trimesh_icosphere():
    import trimesh
    m = trimesh.creation.icosphere(subdivisions=3)
    corners = m.triangles.astype(np.float32)
    v, f = weld_exact(corners)
    assert len(v) == len(m.vertices)
    np.testing.assert_array_equal(v[f], corners.astype(np.float64))


def test_weld_exact_treats_negative_zero_as_zero():
    corners = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], [[-0.0, 0, 0], [0, 1, 0], [1, 0, 0]]])
    v, f = weld_exact(corners)
    assert len(v) == 3
    assert f[0, 0] == f[1, 0]


def test_weld_exact_writes_a_zero_first_seen_as_negative_as_positive():
    """A vertex whose first corner has -0.0 comes out +0.0 on both paths (the numpy reference wrote -0.0 and
    the C extension +0.0: twins that differed in the sign of zero)."""
    corners = np.array([[[-0.0, 1, -0.0], [1, 0, 0], [0, 0, 1]], [[-0.0, 1, 0.0], [0, 0, 1], [1, 0, 0]]])
    for dtype in (np.float32, np.float64):
        v, f = weld_exact(corners.astype(dtype))
        assert len(v) == 3 and f[0, 0] == f[1, 0]
        assert not np.signbit(v).any()


def test_weld_exact_keeps_points_one_ulp_apart_distinct():
    x = np.float32(1.0)
    y = np.nextafter(x, np.float32(2))
    corners = np.array([[[x, 0, 0], [0, 1, 0], [0, 0, 1]], [[y, 0, 0], [0, 1, 0], [0, 0, 1]]], dtype=np.float32)
    v, _ = weld_exact(corners)
    assert len(v) == 4


def test_weld_tolerance_merges_rounding_noise_only():
    v = np.array([[0.0, 0, 0], [1e-9, 0, 0], [1.0, 0, 0], [0, 1, 0]])
    f = np.array([[0, 2, 3], [1, 3, 2]])
    g = weld_tolerance(v, f, 1e-6)
    assert g[0, 0] == g[1, 0]
    assert len(np.unique(g)) == 3


def test_key_collision_falls_back_to_exact_grouping(monkeypatch):
    import inertia_tool.mesh.weld as weld

    monkeypatch.setenv("INERTIA_TOOL_NO_ACCEL", "1")    # the 64-bit keys exist only on the numpy path
    def constant_key(rows):
        return np.zeros(len(rows), dtype=np.uint64)   # every point collides
    monkeypatch.setattr(weld, "_hash_rows", constant_key)
    corners = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, 0, 0], [0, 1, 0], [0, 0, 1]]])
    v, f = weld.weld_exact(corners)
    assert len(v) == 4
    np.testing.assert_array_equal(v[f], corners)
