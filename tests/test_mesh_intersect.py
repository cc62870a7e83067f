"""mesh/intersect.py: exact detection of faces meeting beyond what they share by index.

The cases of issue 21 (overlapping cubes sharing a corner's vertex index, a tube passing through itself,
touching copies, an internal wall, T-junctions, clean meshes), and property tests of single triangle pairs
against an independent exact classifier (``intersect_reference.brute_kind``: rational clipping of one
triangle by the other's plane or half-planes, a different algorithm from the orientation-sign logic).
"""

import glob
import os

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, box_arrays
from intersect_reference import NONE, OPPOSITE, brute_kind, pair_kinds
from inertia_tool import _native
from inertia_tool.errors import InvalidMeshError
from inertia_tool.mesh.checks import shell_labels
from inertia_tool.mesh.intersect import orient2d_sign, orient3d_sign, surface_contacts

MESHES = os.path.join(os.path.dirname(__file__), os.pardir, "meshes")


@pytest.fixture(autouse=True, params=["c", "numpy"])
def kernel(request, monkeypatch):
    """Every test on both twins: the C kernel (section 8 of _accel.c) and the numpy reference.  A test marked by
    :func:`_each_example_on_both_twins` runs both twins itself, in its ``[numpy]`` run; its ``[c]`` run is skipped."""
    if request.param == "c" and getattr(request.function, "_both_twins", False):
        pytest.skip("each example is checked on both twins in the [numpy] run")
    if request.param == "c":
        if not HAVE_ACCEL:
            pytest.skip("inertia_tool._accel is not built")
        monkeypatch.delenv(_native.NO_ACCEL_ENV, raising=False)
    else:
        monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    return request.param


def _rotation(axis, degrees):
    return trimesh.transformations.rotation_matrix(np.radians(degrees), axis)[:3, :3]


def _unit_cube():
    v, f = box_arrays((1.0, 1.0, 1.0), (0.5, 0.5, 0.5))          # [0, 1]³, outward
    return v, f


def _welded(v, f):
    u, inverse = np.unique(np.round(v, 12), axis=0, return_inverse=True)
    return u, inverse.reshape(-1)[f]


# -- the cases of the issue -------------------------------------------------------------------------------

def test_issue21_cube_and_turned_cube_sharing_the_corner_index_cross():
    v, f = _unit_cube()
    corner = int(np.argmin(np.linalg.norm(v, axis=1)))            # (0, 0, 0), on the body diagonal
    turned = v @ _rotation(np.ones(3), 30.0).T
    f2 = f + len(v)
    f2[f2 == corner + len(v)] = corner                             # the same vertex INDEX at the shared corner
    verts, faces = np.r_[v, turned], np.r_[f, f2]
    assert shell_labels(faces, len(verts))[1] == 2                # the shared vertex split into its fans (R1)
    result = surface_contacts(verts, faces)
    assert result.complete
    assert len(result.crossing) > 0
    # every crossing is between the two cubes, never within one (each cube alone is clean)
    assert np.all((result.crossing[:, 0] < 12) & (result.crossing[:, 1] >= 12))
    for part in (f, f2):
        alone = surface_contacts(verts, part)
        assert len(alone.crossing) == len(alone.coplanar_opposite) == len(alone.contact) == 0


def test_issue21_nudged_turned_cube_still_crosses():
    v, f = _unit_cube()
    turned = v @ _rotation(np.ones(3), 30.0).T + 1e-9
    result = surface_contacts(np.r_[v, turned], np.r_[f, f + len(v)])
    assert len(result.crossing) > 0


def _figure_eight_tube(n_along=160, n_around=12, radius=0.12):
    """A closed tube swept along the lemniscate (sin t, sin t cos t, 0): it passes through itself at 0."""
    t = np.linspace(0, 2 * np.pi, n_along, endpoint=False)
    c = np.stack([np.sin(t), np.sin(t) * np.cos(t), np.zeros_like(t)], axis=1)
    tangent = np.stack([np.cos(t), np.cos(2 * t), np.zeros_like(t)], axis=1)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    up = np.array([0.0, 0.0, 1.0])
    side = np.cross(tangent, up)
    phi = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
    ring = radius * (np.cos(phi)[None, :, None] * side[:, None] + np.sin(phi)[None, :, None] * up)
    verts = (c[:, None] + ring).reshape(-1, 3)
    i = np.arange(n_along)[:, None]
    j = np.arange(n_around)[None, :]
    a = i * n_around + j
    b = ((i + 1) % n_along) * n_around + j
    c2 = ((i + 1) % n_along) * n_around + (j + 1) % n_around
    d = i * n_around + (j + 1) % n_around
    faces = np.r_[np.stack([a, b, c2], -1).reshape(-1, 3), np.stack([a, c2, d], -1).reshape(-1, 3)]
    return verts, faces


def test_issue21_figure_eight_tube_crosses_itself_within_one_shell():
    v, f = _figure_eight_tube()
    assert shell_labels(f, len(v))[1] == 1
    result = surface_contacts(v, f)
    assert result.complete and len(result.crossing) > 0
    # the crossings are where the two branches pass through each other, near the origin
    centres = v[f[result.crossing.reshape(-1)]].mean(axis=1)
    assert np.all(np.abs(centres[:, :2]) < 0.5)


def test_issue21_boxes_touching_face_to_face_are_coplanar_opposite():
    a = box_arrays((1.0, 1.0, 1.0))
    b = box_arrays((1.0, 1.0, 1.0), (1.0, 0.0, 0.0))
    result = surface_contacts(np.r_[a[0], b[0]], np.r_[a[1], b[1] + len(a[0])])
    assert len(result.crossing) == 0
    assert len(result.coplanar_opposite) > 0
    # the opposite pairs are the faces on the plane x = 0.5, one of each box
    v = np.r_[a[0], b[0]]
    f = np.r_[a[1], b[1] + len(a[0])]
    for i, j in result.coplanar_opposite:
        assert np.all(v[f[i], 0] == 0.5) and np.all(v[f[j], 0] == 0.5) and i < 12 <= j


def test_issue21_zero_thickness_internal_wall_is_coplanar_opposite():
    left = box_arrays((1.0, 1.0, 1.0), (-0.5, 0.0, 0.0))
    right = box_arrays((1.0, 1.0, 1.0), (0.5, 0.0, 0.0))
    v, f = _welded(np.r_[left[0], right[0]], np.r_[left[1], right[1] + len(left[0])])
    assert len(v) == 12                                              # the wall's corners are shared by index
    result = surface_contacts(v, f)
    assert len(result.crossing) == 0
    wall = [k for k in range(len(f)) if np.all(v[f[k], 0] == 0.0)]
    assert len(wall) == 4
    # each wall face of the left box overlaps a wall face of the right box (diagonals may differ)
    pairs = {tuple(p) for p in result.coplanar_opposite}
    assert pairs and pairs <= {(i, j) for i in wall[:2] for j in wall[2:]}
    assert {i for p in pairs for i in p} == set(wall)


def test_duplicate_face_same_winding_is_crossing_and_reversed_is_opposite():
    v, f = _unit_cube()
    same = surface_contacts(v, np.r_[f, f[:1]])
    assert {tuple(p) for p in same.crossing} == {(0, 12)}
    back = surface_contacts(v, np.r_[f, f[:1, ::-1]])
    assert {tuple(p) for p in back.coplanar_opposite} == {(0, 12)}
    assert len(back.crossing) == 0


def test_cubes_touching_along_an_edge_are_contact_only():
    a = box_arrays((1.0, 1.0, 1.0))
    b = box_arrays((1.0, 1.0, 1.0), (1.0, 1.0, 0.0))
    result = surface_contacts(np.r_[a[0], b[0]], np.r_[a[1], b[1] + len(a[0])])
    assert len(result.crossing) == len(result.coplanar_opposite) == 0
    assert len(result.contact) > 0


def _t_junction_cube():
    """[0, 1]³ whose top face is fanned from the midpoint m of its front edge; the front face is not split."""
    p = {k: np.array(k, dtype=float) for k in
         [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]}
    verts = [p[k] for k in sorted(p)] + [np.array([0.5, 0.0, 1.0])]
    idx = {k: i for i, k in enumerate(sorted(p))}
    m = 8

    def q(*ks):
        return [idx[k] if k != "m" else m for k in ks]
    faces = [
        q((0, 0, 0), (0, 1, 0), (1, 1, 0)), q((0, 0, 0), (1, 1, 0), (1, 0, 0)),       # bottom, -z
        q((0, 0, 1), "m", (0, 1, 1)),                                                 # top, +z: fan from m
        q("m", (1, 1, 1), (0, 1, 1)), q("m", (1, 0, 1), (1, 1, 1)),
        q((0, 0, 0), (1, 0, 0), (1, 0, 1)), q((0, 0, 0), (1, 0, 1), (0, 0, 1)),       # front, -y (unsplit)
        q((0, 1, 0), (0, 1, 1), (1, 1, 1)), q((0, 1, 0), (1, 1, 1), (1, 1, 0)),       # back, +y
        q((0, 0, 0), (0, 0, 1), (0, 1, 1)), q((0, 0, 0), (0, 1, 1), (0, 1, 0)),       # left, -x
        q((1, 0, 0), (1, 1, 0), (1, 1, 1)), q((1, 0, 0), (1, 1, 1), (1, 0, 1)),       # right, +x
    ]
    return np.array(verts), np.array(faces)


def test_t_junction_is_contact_only():
    v, f = _t_junction_cube()
    # outward winding everywhere: the closed surface's volume is 1
    tri = v[f]
    assert np.isclose(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6, 1.0)
    result = surface_contacts(v, f)
    assert len(result.crossing) == len(result.coplanar_opposite) == 0
    front = {k for k in range(len(f)) if np.all(v[f[k], 1] == 0.0)}
    touching_m = {k for k in range(len(f)) if 8 in f[k]}
    pairs = {tuple(p) for p in result.contact}
    assert pairs and all((i in front) != (j in front) and (i in touching_m or j in touching_m) for i, j in pairs)


@pytest.mark.parametrize("mesh", [
    trimesh.creation.icosphere(subdivisions=4),
    trimesh.creation.torus(1.0, 0.3),
    trimesh.creation.cylinder(radius=0.5, height=2.0, sections=64),
    trimesh.creation.capsule(),
    trimesh.creation.annulus(0.5, 1.0, 1.0),
], ids=["icosphere", "torus", "cylinder", "capsule", "annulus"])
def test_clean_meshes_have_no_contacts(mesh):
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    unpatched = surface_contacts(v, f, _patches=False)          # the C scan's patches skip most pairs
    assert unpatched.complete and unpatched.candidate_pairs > len(mesh.faces)
    for result in (surface_contacts(v, f), unpatched):
        assert result.complete and result.candidate_pairs <= unpatched.candidate_pairs
        assert len(result.crossing) == len(result.coplanar_opposite) == len(result.contact) == 0


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(MESHES, "*.stl"))), ids=os.path.basename)
def test_repository_meshes_have_no_contacts(path):
    from inertia_tool.mesh.read import load_mesh
    raw = load_mesh(path)
    result = surface_contacts(raw.vertices, raw.faces)
    assert len(result.crossing) == len(result.coplanar_opposite) == len(result.contact) == 0


def test_disjoint_and_nested_boxes_have_no_contacts():
    outer = box_arrays((4.0, 4.0, 4.0))
    inner = box_arrays((1.0, 1.0, 1.0))
    far = box_arrays((1.0, 1.0, 1.0), (10.0, 0.0, 0.0))
    v = np.r_[outer[0], inner[0], far[0]]
    f = np.r_[outer[1], inner[1][:, ::-1] + 8, far[1] + 16]
    result = surface_contacts(v, f)
    assert len(result.crossing) == len(result.coplanar_opposite) == len(result.contact) == 0


def test_work_bound_makes_the_result_incomplete():
    v, f = _figure_eight_tube()
    full = surface_contacts(v, f)
    cut = surface_contacts(v, f, max_pairs=full.candidate_pairs // 2)
    assert full.complete and not cut.complete
    assert cut.candidate_pairs <= full.candidate_pairs // 2
    assert {tuple(p) for p in cut.crossing} <= {tuple(p) for p in full.crossing}


def test_small_chunks_give_the_same_answer():
    v, f = _figure_eight_tube(80, 8)
    assert surface_contacts(v, f, chunk=7) == surface_contacts(v, f)


def test_degenerate_faces_are_skipped_and_counted():
    v, f = _unit_cube()
    v = np.r_[v, [[0.25, 0.5, 0.5], [0.75, 0.5, 0.5], [0.5, 0.5, 0.5]]]
    # a face with a repeated corner and one with three collinear corners, both through the cube's interior
    result = surface_contacts(v, np.r_[f, [[8, 9, 9], [8, 10, 9]]])
    assert result.degenerate_faces == 2
    assert len(result.crossing) == len(result.coplanar_opposite) == len(result.contact) == 0


@pytest.mark.parametrize("vertices, faces, message", [
    (np.array([[0.0, 0, 0], [1, 0, 0], [np.nan, 1, 0]]), np.array([[0, 1, 2]]), "finite"),
    (np.zeros((3, 3)), np.array([[0, 1, 3]]), "indices"),
    (np.zeros((3, 2)), np.array([[0, 1, 2]]), "Expected vertices"),
])
def test_malformed_input_is_refused(vertices, faces, message):
    with pytest.raises(InvalidMeshError, match=message):
        surface_contacts(vertices, faces)


def test_result_is_invariant_under_vertex_face_and_corner_permutation():
    v, f = _unit_cube()
    corner = int(np.argmin(np.linalg.norm(v, axis=1)))
    turned = v @ _rotation(np.ones(3), 30.0).T
    f2 = f + len(v)
    f2[f2 == corner + len(v)] = corner
    v, f = np.r_[v, turned, _t_junction_cube()[0] + [3.0, 0, 0]], np.r_[f, f2, _t_junction_cube()[1] + 16]
    base = pair_kinds(surface_contacts(v, f))
    rng = np.random.default_rng(7)
    for _ in range(3):
        vp = rng.permutation(len(v))
        fp = rng.permutation(len(f))
        roll = rng.integers(0, 3, len(f))
        new_index = np.empty_like(vp)
        new_index[vp] = np.arange(len(v))
        g = new_index[f][fp]
        g = np.stack([np.roll(row, k) for row, k in zip(g, roll[fp])])
        got = pair_kinds(surface_contacts(v[vp], g))
        mapped = {tuple(sorted((int(fp[i]), int(fp[j])))): k for (i, j), k in got.items()}
        assert mapped == base


# -- predicates --------------------------------------------------------------------------------------------

def _exact_orient3d(a, b, c, d):
    from fractions import Fraction
    m = [[Fraction(float(p[i])) - Fraction(float(d[i])) for i in range(3)] for p in (a, b, c)]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    return (det > 0) - (det < 0)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=9, max_size=9),
       st.floats(-2.0, 2.0), st.floats(-2.0, 2.0), st.integers(-60, 60), st.floats(-1.0, 1.0))
def test_orient3d_sign_is_exact_near_the_plane(coords, s, t, exponent, wiggle):
    a, b, c = np.array(coords).reshape(3, 3)
    d = a + s * (b - a) + t * (c - a) + (wiggle * 2.0 ** exponent) * np.cross(b - a, c - a)   # near the plane
    got = int(orient3d_sign(a, b, c, d)[0])
    assert got == _exact_orient3d(a, b, c, d)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=4, max_size=4), st.floats(-3.0, 3.0),
       st.sampled_from([1e-300, 1e-200, 1.0, 1e250]))
def test_orient2d_sign_is_exact_on_the_line_at_any_scale(coords, t, scale):
    from fractions import Fraction
    a, b = np.array(coords).reshape(2, 2) * scale
    c = a + t * (b - a)
    got = int(orient2d_sign(a, b, c)[0])
    A, B, C = ([Fraction(float(x)) for x in p] for p in (a, b, c))
    det = (A[0] - C[0]) * (B[1] - C[1]) - (A[1] - C[1]) * (B[0] - C[0])
    assert got == (det > 0) - (det < 0)


# -- triangle pairs against the independent classifier ------------------------------------------------------

def _each_example_on_both_twins(test):
    """Mark a property test that classifies each drawn example on both twins itself (:func:`_on_twins`): the
    example is drawn and the rational reference run once, not once per twin (the same examples either way: CI's
    derandomized sequence is the same for both parametrised runs)."""
    test._both_twins = True
    return test


def _on_twins(v, f):
    """``surface_contacts(v, f)`` on the numpy twin and, when built, the C twin: ``[(twin, result), ...]``."""
    results = []
    saved = os.environ.get(_native.NO_ACCEL_ENV)
    try:
        for twin in ("numpy", "c") if HAVE_ACCEL else ("numpy",):
            if twin == "numpy":
                os.environ[_native.NO_ACCEL_ENV] = "1"
            else:
                os.environ.pop(_native.NO_ACCEL_ENV, None)
            results.append((twin, surface_contacts(v, f)))
    finally:
        if saved is None:
            os.environ.pop(_native.NO_ACCEL_ENV, None)
        else:
            os.environ[_native.NO_ACCEL_ENV] = saved
    return results


_SIGNED_PERMS = [np.eye(3)[list(p)] * s for p in ((0, 1, 2), (1, 2, 0), (2, 0, 1), (1, 0, 2))
                 for s in (np.array([1, 1, 1]), np.array([-1, 1, 1]), np.array([1, -1, -1]))]


@st.composite
def triangle_pairs(draw):
    """Two triangles (small integers: exact degeneracies) sharing 0-3 corners by index, maybe coplanar, maybe
    a corner snapped onto the other's edge or plane, under an exact or a floating-point rigid motion."""
    coord = st.integers(-3, 3)
    t1 = np.array(draw(st.lists(coord, min_size=9, max_size=9)), dtype=float).reshape(3, 3)
    t2 = np.array(draw(st.lists(coord, min_size=9, max_size=9)), dtype=float).reshape(3, 3)
    mode = draw(st.sampled_from(["free", "coplanar", "on_edge", "on_plane", "on_corner"]))
    if mode == "coplanar":
        t1[:, 2] = t2[:, 2] = draw(coord)
    elif mode == "on_edge":
        i = draw(st.integers(0, 2))
        t2[draw(st.integers(0, 2))] = t1[i] + (t1[(i + 1) % 3] - t1[i]) * draw(st.sampled_from([0.25, 0.5, 0.75]))
    elif mode == "on_plane":
        s, t = draw(st.sampled_from([-0.5, 0.25, 0.5, 1.0])), draw(st.sampled_from([-0.5, 0.25, 0.5]))
        t2[draw(st.integers(0, 2))] = t1[0] + s * (t1[1] - t1[0]) + t * (t1[2] - t1[0])
    elif mode == "on_corner":
        t2[draw(st.integers(0, 2))] = t1[draw(st.integers(0, 2))]          # same point, different index
    n_shared = draw(st.integers(0, 3))
    c1 = draw(st.permutations([0, 1, 2]))
    c2 = draw(st.permutations([0, 1, 2]))
    idx2 = [3, 4, 5]
    shared = []
    for k in range(n_shared):
        t2[c2[k]] = t1[c1[k]]
        idx2[c2[k]] = c1[k]
        shared.append((c1[k], c2[k]))
    v = np.r_[t1, t2]
    motion = draw(st.sampled_from(["none", "exact", "float"]))
    if motion == "exact":
        m = _SIGNED_PERMS[draw(st.integers(0, len(_SIGNED_PERMS) - 1))]
        v = v @ m.T * 2.0 ** draw(st.integers(-30, 30)) + np.array(draw(st.lists(coord, min_size=3, max_size=3)))
    elif motion == "float":
        q = np.array(draw(st.lists(st.floats(-1, 1), min_size=4, max_size=4)))
        if np.linalg.norm(q) > 1e-3:
            q /= np.linalg.norm(q)
            w, x, y, z = q
            r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                          [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                          [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            v = v @ r.T + np.array(draw(st.lists(st.floats(-100, 100), min_size=3, max_size=3)))
    faces = np.array([[0, 1, 2], idx2])
    return v, faces, shared


# 1,000 examples (3,000 until tidy11): each of seven mutants of the numpy twin's classifier (closed point-in-
# triangle test made open, strict segment overlap, an edge in the other plane counted as proper, ...) fails
# within the first 462 of CI's derandomized sequence.
@_each_example_on_both_twins
@settings(max_examples=1000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(triangle_pairs(), st.booleans(), st.integers(0, 2))
def test_triangle_pair_matches_the_independent_classifier(case, swap, roll):
    v, faces, shared = case
    want = brute_kind(v[faces[0]], v[faces[1]], shared)
    f = np.stack([np.roll(faces[0], roll), faces[1]])
    if swap:
        f = f[::-1]
    for twin, result in _on_twins(v, f):
        if want is None:                                    # a zero-area triangle: skipped
            assert result.degenerate_faces >= 1, twin
            assert len(result.crossing) == len(result.coplanar_opposite) == len(result.contact) == 0, twin
            continue
        assert result.degenerate_faces == 0, twin
        got = pair_kinds(result).get((0, 1), NONE)
        assert got == want, twin


@st.composite
def adjacent_pairs(draw):
    """Two faces sharing an edge or a corner by index, the other corners on a small lattice of the plane of
    the first face (exactly coplanar before the motion) or nudged off it by a few units in the last places,
    on either side of the shared edge or inside the shared corner's wedge, moved exactly onto a tilted plane
    (maybe one corner then one unit in the last place off it) or by a floating-point rotation and offset (so
    the float filter cannot decide most signs): the cases the C scan's shortcuts decide
    (a line through the shared element separating the projections, early rejection by one plane)."""
    lattice = st.integers(-3, 3)
    n_shared = draw(st.sampled_from([1, 2]))
    points = [np.array([draw(lattice), draw(lattice), 0.0]) for _ in range(6 - n_shared)]
    t1 = [np.zeros(3), points[0], points[1]]
    t2 = [t1[0], t1[1] if n_shared == 2 else points[2], points[-1]]
    nudge = draw(st.sampled_from([0.0, 0.0, 2.0 ** -44, -(2.0 ** -44), 2.0 ** -20]))
    t2[2] = t2[2] + np.array([0.0, 0.0, nudge])
    if draw(st.booleans()):                                  # scale one in-plane direction: slivers
        t2[2] = t2[2] * np.array([draw(st.sampled_from([1.0, 1e-6, 3.0])), 1.0, 1.0])
    v = np.array(t1 + t2[1:] if n_shared == 1 else t1 + [t2[2]])
    faces = np.array([[0, 1, 2], [0, 3, 4]]) if n_shared == 1 else np.array([[0, 1, 2], [1, 0, 3]])
    if draw(st.booleans()):
        faces[1] = faces[1][[0, 2, 1]]
    motion = draw(st.sampled_from(["tilted", "tilted", "float", "none"]))
    if motion == "tilted":                  # onto a tilted plane, exactly: dyadic slopes, an offset
        c1, c2 = draw(st.sampled_from([0.5, -0.25, 3.0])), draw(st.sampled_from([0.125, -2.0, 0.75]))
        v = np.stack([v[:, 0] + 64.5, v[:, 1] - 32.25, 10.0 + c1 * v[:, 0] + c2 * v[:, 1] + v[:, 2]], axis=1)
        if draw(st.booleans()):             # one corner one unit in the last place off the plane
            v[-1, 2] = np.nextafter(v[-1, 2], draw(st.sampled_from([-np.inf, np.inf])))
    q = np.array(draw(st.lists(st.floats(-1, 1), min_size=4, max_size=4)))
    if motion == "float" and np.linalg.norm(q) > 1e-3:
        q /= np.linalg.norm(q)
        a, x, y, z = q
        r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * a), 2 * (x * z + y * a)],
                      [2 * (x * y + z * a), 1 - 2 * (x * x + z * z), 2 * (y * z - x * a)],
                      [2 * (x * z - y * a), 2 * (y * z + x * a), 1 - 2 * (x * x + y * y)]])
        v = v @ r.T + np.array(draw(st.lists(st.floats(-100, 100), min_size=3, max_size=3)))
    shared = [(i, j) for i in range(3) for j in range(3) if faces[0, i] == faces[1, j]]
    return v, faces, shared


# 700 examples (2,000 until tidy11): the same mutants of the numpy twin fail within the first 132 of CI's
# derandomized sequence here (an "along the shared corner" test loosened from all to any coordinate: 12).
@_each_example_on_both_twins
@settings(max_examples=700, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(adjacent_pairs(), st.booleans())
def test_adjacent_pair_near_one_plane_matches_the_independent_classifier(case, swap):
    """Faces sharing an edge or a corner, coplanar or within a few ulps of it (folded over, side by side,
    overlapping, slivers): the same kind as the rational reference on both twins."""
    v, faces, shared = case
    want = brute_kind(v[faces[0]], v[faces[1]], shared)
    f = faces[::-1] if swap else faces
    for twin, result in _on_twins(v, f):
        if want is None:
            assert result.degenerate_faces >= 1, twin
            continue
        assert pair_kinds(result).get((0, 1), NONE) == want, twin


def test_planar_quad_grid_is_decided_without_exact_arithmetic(kernel):
    """A torus grid whose quads are exactly planar trapezoids (each quad's two faces coplanar, every corner of
    a quad in the planes of its neighbours' faces): nothing meets, and on the C path the separating-line
    shortcut decides the pairs the float filter cannot (a handful of exact evaluations, not one per quad)."""
    n, k = 60, 30
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(k) / k + 0.1234
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = 1.0 + 0.35 * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), 0.35 * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(k), indexing="ij")
    a, b = i * k + j, ((i + 1) % n) * k + j
    c, d = ((i + 1) % n) * k + (j + 1) % k, i * k + (j + 1) % k
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    result = surface_contacts(v, f)
    assert result.complete and result.degenerate_faces == 0
    assert len(result.crossing) == len(result.coplanar_opposite) == len(result.contact) == 0
    if kernel == "c":
        assert result.exact_evaluations < len(f) // 100


def test_coplanar_fan_folded_over_is_found(kernel):
    """A flat fan of four faces around one vertex, then one face folded exactly onto its neighbour (same
    plane, same side of the shared edge): the fold is coplanar_opposite with that neighbour and overlaps the
    next one; every other adjacent pair meets only in what it shares."""
    plane = np.array([[0.0, 0], [1, 0], [0, 1], [-1, 0], [0, -1], [0.625, 0.375]])
    a, b = plane[:, 0], plane[:, 1]
    v = np.stack([a + 10.0, b - 3.0, 0.5 + 0.25 * a - 0.5 * b], axis=1)   # a tilted plane, exactly (dyadic)
    flat = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    assert sum(len(getattr(surface_contacts(v, flat), k)) for k in ("crossing", "coplanar_opposite",
                                                                    "contact")) == 0
    folded = np.r_[flat, [[0, 5, 1]]]                       # on top of face 0, reversed: shares edge 0-1
    got = pair_kinds(surface_contacts(v, folded))
    assert got[(0, 4)] == OPPOSITE
    for i in range(4):
        want = brute_kind(v[folded[i]], v[folded[4]],
                          [(p, q) for p in range(3) for q in range(3) if folded[i, p] == folded[4, q]])
        assert got.get((i, 4), NONE) == want


# -- the two twins against each other -----------------------------------------------------------------------

def test_c_and_numpy_twins_agree_on_a_degenerate_soup(kernel, monkeypatch):
    """400 triangles on a small integer lattice (shared corners, coplanar overlaps, touching edges): the same
    pairs on both paths."""
    if kernel != "c":
        pytest.skip("compares the two paths once")
    rng = np.random.default_rng(3)
    v = rng.integers(0, 6, (300, 3)).astype(float)
    f = rng.integers(0, 300, (400, 3))
    c = surface_contacts(v, f)
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    ref = surface_contacts(v, f)
    assert c.candidate_pairs == ref.candidate_pairs and c.tested_pairs == ref.tested_pairs
    for field in ("crossing", "coplanar_opposite", "contact"):
        assert np.array_equal(getattr(c, field), getattr(ref, field)), field
    assert len(c.crossing) and len(c.coplanar_opposite) and len(c.contact)


@pytest.mark.parametrize("bad", ["faces", "dtype", "shape", "vertex dtype"])
def test_c_kernel_refuses_malformed_arguments(kernel, bad):
    if kernel != "c":
        pytest.skip("the C kernel's own argument checks")
    lib = _native.accel()
    v, f = _unit_cube()
    v = np.ascontiguousarray(v)
    f = np.ascontiguousarray(f, dtype=np.int64)
    if bad == "faces":
        f = f.copy()
        f[3, 1] = 99
    elif bad == "dtype":
        f = f.astype(np.int16)          # int32 and int64 are read (see the next test)
    elif bad == "shape":
        v = np.ascontiguousarray(v[:, :2])
    elif bad == "vertex dtype":
        v = v.astype(np.float32)
    with pytest.raises(ValueError, match="Expected"):
        lib.contact_scan(v, f, -1)


def test_c_kernel_reads_int32_faces_as_int64(kernel):
    """The C scan reads int32 faces in place (no 24-byte-per-face int64 copy): same pairs, counts and flags."""
    if kernel != "c":
        pytest.skip("the C kernel's face types")
    lib = _native.accel()
    rng = np.random.default_rng(5)
    v = rng.random((40, 3))
    f = rng.integers(0, 40, size=(120, 3))
    wide = lib.contact_scan(v, np.ascontiguousarray(f, dtype=np.int64), -1, 1)
    narrow = lib.contact_scan(v, np.ascontiguousarray(f, dtype=np.int32), -1, 1)
    assert wide[3] > 0 and wide[3:7] == narrow[3:7]
    for w, n in zip(wide[:3] + wide[7:], narrow[:3] + narrow[7:]):
        assert w == n


@settings(max_examples=25, deadline=None)
@given(st.integers(2, 300), st.integers(0, 2**32 - 1), st.sampled_from([0.05, 0.3, 3.0]))
def test_broad_phase_finds_every_pair_of_meeting_boxes(n_faces, seed, spread):
    """The candidate count equals the brute-force count of face pairs whose closed boxes meet (faces of mixed
    sizes, some sharing corners, some identical), and every pair of a soup on a small lattice is classified as
    the all-pairs reference says."""
    rng = np.random.default_rng(seed)
    v = np.round(rng.normal(size=(n_faces, 3)) * 4) / 4
    f = rng.integers(0, n_faces, (n_faces, 3))
    f[: n_faces // 10] = f[n_faces // 10: 2 * (n_faces // 10)]           # duplicated faces
    v = v * np.where(rng.random((n_faces, 1)) < 0.1, 1.0, spread)         # a few large faces among small ones
    result = surface_contacts(v, f, _star_faces=0)        # the broad phase alone (no certified-star pruning)
    lo, hi = v[f].min(axis=1), v[f].max(axis=1)
    meet = np.all(lo[:, None] <= hi[None], axis=2) & np.all(lo[None] <= hi[:, None], axis=2)
    assert result.candidate_pairs == int(np.count_nonzero(np.triu(meet, 1)))
    if n_faces <= 60:
        got = pair_kinds(result)
        for i in range(n_faces):
            for j in range(i + 1, n_faces):
                if not meet[i, j]:
                    continue
                shared = [(p, q) for p in range(3) for q in range(3) if f[i, p] == f[j, q]]
                want = brute_kind(v[f[i]], v[f[j]], shared)
                assert got.get((i, j), NONE) == (NONE if want is None else want), (i, j)


def test_c_scan_on_threads_finds_the_same_pairs(kernel, monkeypatch):
    """Above 20,000 faces the C scan splits its traversal over threads: the same pairs on 1 and 2 threads and
    on the numpy grid."""
    if kernel != "c":
        pytest.skip("compares the C scan's thread counts")
    v, f = _figure_eight_tube(1000, 12)
    monkeypatch.setenv(_native.THREADS_ENV, "1")
    one = surface_contacts(v, f)
    monkeypatch.setenv(_native.THREADS_ENV, "2")
    two = surface_contacts(v, f)
    unpatched = surface_contacts(v, f, _patches=False)
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    ref = surface_contacts(v, f)
    assert len(f) > 20_000 and len(one.crossing) > 0
    assert two.candidate_pairs == one.candidate_pairs <= unpatched.candidate_pairs == ref.candidate_pairs
    for other in (two, ref, unpatched):
        for field in ("crossing", "coplanar_opposite", "contact"):
            assert np.array_equal(getattr(other, field), getattr(one, field)), field


@pytest.mark.parametrize("exponent", [-1000, -900, 900])
def test_result_does_not_depend_on_scale(exponent):
    """Scaling by a power of two changes no orientation sign: the same pairs at 2^-1000 (partly subnormal
    coordinates: every sign exact) and 2^±900 (rescaled into the filter's range first)."""
    v, f = _t_junction_cube()
    w, g = _unit_cube()
    corner = int(np.argmin(np.linalg.norm(w, axis=1)))
    turned = w @ _rotation(np.ones(3), 30.0).T
    g2 = g + len(w)
    g2[g2 == corner + len(w)] = corner
    verts = np.r_[v, w + 3.0, turned + 3.0]
    faces = np.r_[f, g + len(v), g2 + len(v)]
    base = surface_contacts(verts, faces)
    scaled = surface_contacts(np.ldexp(verts, exponent), faces)
    assert len(base.crossing) and len(base.contact)
    for field in ("crossing", "coplanar_opposite", "contact"):
        assert np.array_equal(getattr(scaled, field), getattr(base, field)), field


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 3 * (1 << 15) + 7), st.integers(0, 2**32 - 1),
       st.sampled_from([None, np.nan, np.inf, -np.inf, 0.0, 5e-324, 1e300]))
def test_magnitudes_chunk_by_chunk_match_numpy(rows, seed, planted):
    """The chunked magnitude scan (no mesh-sized temporary) gives numpy's largest and smallest nonzero |x|,
    NaN and infinities included, across chunk boundaries."""
    from inertia_tool.mesh.intersect import _MAGNITUDE_CHUNK, _magnitudes
    rng = np.random.default_rng(seed)
    v = rng.choice([0.0, 1.0, -2.5, 1e-200, 3e10], size=(rows, 3)) * rng.random((rows, 3))
    if planted is not None and rows:
        v.reshape(-1)[int(rng.integers(v.size))] = planted
    if rows and rng.integers(2):
        v.reshape(-1)[min(_MAGNITUDE_CHUNK, v.size - 1)] = -7.0       # at a chunk boundary
    largest, smallest = _magnitudes(v) if v.size else (0.0, np.inf)
    mag = np.abs(v)
    if np.isnan(v).any():
        assert np.isnan(largest)
        return
    assert largest == (mag.max() if v.size else 0.0)
    nonzero = mag[mag != 0]
    assert smallest == (nonzero.min() if nonzero.size else np.inf)
