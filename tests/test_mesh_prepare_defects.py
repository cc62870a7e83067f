"""Meshes as people have them through the public API: exact where the solid is defined, estimates on request.

Synthetic twins of trimesh's test models (shared.STL, joined_tetrahedra.obj, fuze.ply, whitespace.off,
cycloidal.ply) with the same pathology, checked against closed forms.
"""

import numpy as np
import pytest
import trimesh

from conftest import assert_tensor_close, box_arrays
from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError, MeshRepairedWarning, MeshResolvedWarning, OverlapWarning


def _concat(*parts):
    vs, fs, n = [], [], 0
    for v, f in parts:
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    return np.vstack(vs), np.vstack(fs)


def _box_inertia(extents, mass):
    a, b, c = extents
    return mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def test_cubes_sharing_an_edge_like_shared_stl_are_exact():
    import trimesh
    a = box_arrays((1.0, 1.0, 1.0))
    b = box_arrays((1.0, 1.0, 1.0), (1.0, 1.0, 0.0))
    merged = trimesh.Trimesh(*_concat(a, b), process=True)       # one vertex array: the edge is shared
    with pytest.warns(MeshResolvedWarning, match="non-manifold edges"):
        p = mass_properties((np.asarray(merged.vertices), np.asarray(merged.faces)), density=1.0)
    assert p.mesh.method == "exact" and p.mesh.nonmanifold_edges == 1 and p.mesh.uncertainty is None
    assert p.volume == pytest.approx(2.0, rel=1e-14)
    assert np.allclose(p.center_of_mass, [0.5, 0.5, 0.0], atol=1e-15)
    # two unit cubes at ±(0.5, 0.5, 0) from the centre: parallel-axis theorem
    d = np.array([0.5, 0.5, 0.0])
    expected = 2 * _box_inertia((1, 1, 1), 1.0) + 2 * (d @ d * np.eye(3) - np.outer(d, d))
    assert_tensor_close(p.inertia, expected, rtol=1e-13)


def test_seam_split_ply_like_fuze_is_read(tmp_path):
    # a box whose vertices are duplicated along a texture seam: the header counts 8, the reader gives more
    v, f = box_arrays()
    path = tmp_path / "seam.ply"
    lines = ["ply", "format ascii 1.0", "element vertex 8", "property float x", "property float y",
             "property float z", "element face 12", "property list uchar int vertex_indices",
             "property list uchar float texcoord", "end_header"]
    lines += [f"{x} {y} {z}" for x, y, z in v]
    for k, t in enumerate(f):
        u = [0.1 * (k % 3), 0.2, 0.3, 0.4 + 0.01 * k, 0.5, 0.6]
        lines.append("3 " + " ".join(map(str, t)) + " 6 " + " ".join(map(str, u)))
    path.write_text("\n".join(lines) + "\n")
    p = mass_properties(str(path))
    assert p.volume == pytest.approx(6.0, rel=1e-7)


def test_off_with_blank_lines_and_keyword_run_into_counts_like_whitespace_off(tmp_path):
    v, f = box_arrays()
    path = tmp_path / "ws.off"
    text = "\t   OFF8 12 0 # comment\n\n" + "".join(f"  {x} {y} {z}\n\n" for x, y, z in v)
    text += "".join(f"3 {a} {b} {c}\n" for a, b, c in f)
    path.write_text(text)
    assert mass_properties(str(path)).volume == pytest.approx(6.0, rel=1e-12)


def test_copies_a_rounding_apart_are_welded_exactly():
    v, f = box_arrays((1.0, 2.0, 3.0))
    soup = v[f].reshape(-1, 3) + np.random.default_rng(3).normal(0, 1e-9, (3 * len(f), 3))
    with pytest.warns(MeshResolvedWarning, match="merged"):
        p = mass_properties((soup, np.arange(len(soup)).reshape(-1, 3)))
    assert p.mesh.method == "welded" and p.volume == pytest.approx(6.0, rel=1e-8)


def test_box_with_300_voids_gives_the_exact_mass():
    rng = np.random.default_rng(11)
    grid = np.stack(np.meshgrid(*[np.arange(-4.5, 5.0, 1.0)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    centres = grid[rng.choice(len(grid), 300, replace=False)] + rng.uniform(-0.2, 0.2, (300, 3))
    parts = [box_arrays((12.0, 12.0, 12.0))]
    for c in centres:
        vv, ff = box_arrays((0.3, 0.3, 0.3), c)
        parts.append((vv, ff[:, ::-1]))
    p = mass_properties(_concat(*parts), density=2.0)
    void = 0.3 ** 3
    assert p.mesh.cavities == 300 and p.mesh.bodies == 1 and p.mesh.method == "exact"
    assert p.mass == pytest.approx(2.0 * (12.0 ** 3 - 300 * void), rel=1e-13)
    com = -void * centres.sum(axis=0) / (12.0 ** 3 - 300 * void)
    assert np.allclose(p.center_of_mass, com, atol=1e-13 * 12)


def test_self_overlapping_bodies_are_united_or_summed_on_request():
    a = box_arrays((2.0, 2.0, 2.0))
    b = box_arrays((2.0, 2.0, 2.0), (1.0, 1.0, 1.0))
    with pytest.warns(OverlapWarning, match="united"):
        p = mass_properties(_concat(a, b), density=1.0)
    assert p.mesh.method == "union" and p.volume == pytest.approx(15.0, rel=1e-13)
    assert np.allclose(p.center_of_mass, (8 * np.ones(3) - 0.5 * np.ones(3)) / 15, atol=1e-13)
    with pytest.warns(OverlapWarning, match="counted twice"):
        q = mass_properties(_concat(a, b), density=1.0, overlap="sum")
    assert q.mesh.method == "sum" and q.volume == pytest.approx(16.0, rel=1e-13)


def test_open_box_refused_in_one_line_then_bounded_with_repair():
    v, f = box_arrays((1.0, 2.0, 3.0))
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    gone = (normals[:, 0] > 0) | (normals[:, 1] > 0)           # two adjacent sides missing
    with pytest.raises(InvalidMeshError, match="`repair=True` gives a bounded estimate") as e:
        mass_properties((v, f[~gone]))
    assert "\n" not in str(e.value)
    # half the box is missing: the ball over that rim is larger than the box, so no honest bound exists
    with pytest.raises(InvalidMeshError, match="cannot be bounded usefully"):
        mass_properties((v, f[~gone]), repair=True, density=1.0)


def test_sphere_with_a_small_hole_is_bounded_with_repair():
    s = trimesh.creation.icosphere(3)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    truth = mass_properties((v, f), density=1.0)
    open_f = f[3:]
    with pytest.warns(MeshRepairedWarning):
        p = mass_properties((v, open_f), repair=True, density=1.0)
    u = p.mesh.uncertainty
    assert p.mesh.method == "patched" and u is not None
    assert 0 < u.mass < 0.05
    assert abs(p.mass - truth.mass) <= u.mass * p.mass
    assert np.linalg.norm(p.center_of_mass - truth.center_of_mass) <= u.center_of_mass
    assert np.linalg.norm(p.inertia - truth.inertia) <= u.inertia * np.linalg.norm(p.inertia)


def test_single_sheet_suggests_the_shell_model():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    f = np.array([[0, 1, 2], [1, 3, 2]])
    with pytest.raises(InvalidMeshError, match="shell model"):
        mass_properties((v, f), repair=True)


def test_stray_triangles_beside_a_closed_part_are_left_out_under_repair():
    """Damage class "stray fragments": loose triangles enclose nothing, so with repair the part is exact and the
    report says what was left out; without repair the open edges are refused."""
    import trimesh
    sphere = trimesh.creation.icosphere(3)
    v, f = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    stray = np.random.default_rng(0).uniform(1.5, 2.0, (9, 3))
    v2, f2 = np.vstack([v, stray]), np.vstack([f, np.arange(9).reshape(3, 3) + len(v)])
    clean = mass_properties((v, f))
    with pytest.warns(MeshResolvedWarning, match="3 closed pieces enclosing no volume"):
        repaired = mass_properties((v2, f2), repair=True)
    assert repaired.mass == pytest.approx(clean.mass, rel=1e-12)
    np.testing.assert_allclose(repaired.center_of_mass, clean.center_of_mass, atol=1e-12)
    assert any("enclosing no volume" in n for n in repaired.mesh.notes)
    with pytest.raises(InvalidMeshError, match="boundary edges"):
        mass_properties((v2, f2))
