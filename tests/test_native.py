"""The optional C extension (inertia_tool._accel, chosen by inertia_tool._native) against the numpy reference.

Welding, the edge census and shell labels must agree exactly with the numpy path (same vertex numbering,
same counts, same sample edges); the compensated tetrahedron sums to round-off.  The kernels must refuse
malformed arguments with an exception, never crash: out-of-range indices, wrong dtypes or shapes, NaN.
"""

import os
import shutil
import subprocess
import sys
import threading

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL, box_arrays, write_binary_stl
from inertia_tool import _native
from inertia_tool.mesh.checks import edge_topology, shell_labels
from inertia_tool.mesh.read import load_mesh
from inertia_tool.integrals import body_volume_moments, volume_moments
from inertia_tool.mesh.weld import weld_exact

needs_accel = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


def both(monkeypatch, fn):
    """``fn()`` on the C path and on the numpy path."""
    monkeypatch.delenv(_native.NO_ACCEL_ENV, raising=False)
    c = fn()
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    ref = fn()
    monkeypatch.delenv(_native.NO_ACCEL_ENV)
    return c, ref


def test_switch_forces_numpy(monkeypatch):
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    assert _native.accel() is None
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "0")
    assert (_native.accel() is not None) == HAVE_ACCEL


def test_ci_builds_the_extension():
    """Under CI (INERTIA_TOOL_REQUIRE_ACCEL=1, set by .ci/run) the extension must have been built and load."""
    if not REQUIRE_ACCEL:
        pytest.skip("INERTIA_TOOL_REQUIRE_ACCEL is not set")
    assert _native.accel() is not None


def test_ci_build_carries_the_crc_of_its_source():
    """setup.py compiles the CRC-32 of _accel.c in; under CI it must equal the source's, so the check below runs."""
    if not REQUIRE_ACCEL:
        pytest.skip("INERTIA_TOOL_REQUIRE_ACCEL is not set")
    module = _native.accel()
    assert module is not None and int(module.SOURCE_CRC) == _native._source_crc()


def test_a_build_of_another_source_is_set_aside_with_a_warning(monkeypatch):
    """A source checkout updated without a rebuild: the stale extension is not called (its kernels' arguments may
    have changed: every file failed with a TypeError), the numpy path answers, and a warning says to rebuild."""
    class Stale:
        SOURCE_CRC = 12345

    monkeypatch.setattr(_native, "_source_crc", lambda: 54321)
    assert not _native._matches_source(Stale())
    monkeypatch.setattr(_native, "_source_crc", lambda: 12345)
    assert _native._matches_source(Stale())
    monkeypatch.setattr(_native, "_source_crc", lambda: None)      # installed without its source: no check
    assert _native._matches_source(Stale())
    assert _native._matches_source(object())                       # built without the CRC: no check
    if not HAVE_ACCEL:
        return
    monkeypatch.setattr(_native, "_source_crc", lambda: -1)
    monkeypatch.setattr(_native, "_MODULE", [])
    with pytest.warns(RuntimeWarning, match="rebuild"):
        assert _native.accel() is None
    v, f = box_arrays()
    before = volume_moments(v, f)                                  # answered on the numpy path
    assert before.volume == pytest.approx(np.prod(np.ptp(v, axis=0)), rel=1e-12)


def _soup(seed=0):
    """Corners of an icosphere with shuffled faces, -0.0 at some zero coordinates, and a detached tetrahedron."""
    m = trimesh.creation.icosphere(subdivisions=4, radius=2.0)
    v = np.asarray(m.vertices).copy()
    v[np.abs(v) < 1e-12] = 0.0
    corners = v[m.faces]
    rng = np.random.default_rng(seed)
    corners = corners[rng.permutation(len(corners))]
    corners[::7][corners[::7] == 0.0] = -0.0
    tet = trimesh.creation.box([0.1, 0.2, 0.3]).triangles + 10.0
    return np.concatenate([corners, tet])


@needs_accel
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_weld_identical_on_both_paths(monkeypatch, dtype):
    corners = _soup().astype(dtype)
    (vc, fc), (vn, fn) = both(monkeypatch, lambda: weld_exact(corners))
    np.testing.assert_array_equal(vc, vn)
    np.testing.assert_array_equal(fc, fn)
    np.testing.assert_array_equal(vc[fc], corners.astype(np.float64) + 0.0)
    first = np.unique(fc.reshape(-1), return_index=True)[1]
    assert np.all(np.diff(first) > 0)      # numbered by first appearance


@needs_accel
def test_weld_keeps_one_ulp_apart_and_merges_signed_zero_in_float64(monkeypatch):
    x = 1.0
    y = np.nextafter(x, 2.0)
    corners = np.array([[[x, 0, 0], [0, 1, 0], [0, 0, -0.0]], [[y, 0, 0], [0, 1, 0], [0, 0, 0.0]]])
    (vc, fc), (vn, fn) = both(monkeypatch, lambda: weld_exact(corners))
    assert len(vc) == len(vn) == 4
    np.testing.assert_array_equal(fc, fn)


@needs_accel
def test_binary_stl_read_identically(monkeypatch, tmp_path):
    corners = _soup(1).astype(np.float32)
    path = tmp_path / "soup.stl"
    v = corners.reshape(-1, 3)
    write_binary_stl(path, v, np.arange(len(v)).reshape(-1, 3))
    c, ref = both(monkeypatch, lambda: load_mesh(path, units="mm"))
    np.testing.assert_array_equal(c.vertices, ref.vertices)
    np.testing.assert_array_equal(c.faces, ref.faces)


@needs_accel
def test_welder_nan_payloads_are_points_not_crashes():
    lib = _native.accel()
    nan_a = np.frombuffer(np.uint32(0x7FC00000).tobytes(), np.float32)[0]
    nan_b = np.frombuffer(np.uint32(0x7FC00001).tobytes(), np.float32)[0]
    pts = np.array([[nan_a, 0, 0], [nan_b, 0, 0], [nan_a, 0, 0], [np.inf, -np.inf, 0]], dtype=np.float32)
    w = lib.Welder("float32", 0)
    ids = np.empty(4, np.int32)
    w.feed(pts, ids)
    assert list(ids) == [0, 1, 0, 2]        # bit patterns: two NaN payloads stay distinct
    out = np.empty((w.count, 3))
    w.vertices_into(out)
    assert np.isnan(out[:2, 0]).all() and np.isinf(out[2, :2]).all()


def test_nan_in_binary_stl_refused_on_both_paths(tmp_path, engine_path):
    from inertia_tool.errors import MeshReadError
    v, f = box_arrays()
    v = v.copy()
    v[3, 1] = np.nan
    write_binary_stl(tmp_path / "nan.stl", v, f)
    with pytest.raises(MeshReadError, match="NaN or infinite"):
        load_mesh(tmp_path / "nan.stl")


@needs_accel
def test_welder_table_grows_from_a_small_hint():
    lib = _native.accel()
    pts = np.random.default_rng(2).integers(0, 60, size=(200_000, 3)).astype(np.float32)
    w = lib.Welder("float32", 1)
    ids = np.empty(len(pts), np.int32)
    for s in range(0, len(pts), 30_000):          # several feeds, one table
        w.feed(pts[s:s + 30_000], ids[s:s + 30_000])
    out = np.empty((w.count, 3))
    w.vertices_into(out)
    assert w.count == len(np.unique(pts, axis=0)) and w.points == len(pts)
    np.testing.assert_array_equal(out[ids], pts)


def _first_appearance_ids(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertex ids in order of first appearance by a Python dict on the exact values (-0.0 equal to +0.0)."""
    seen: dict = {}
    ids = np.array([seen.setdefault(tuple(float(x) + 0.0 for x in p), len(seen)) for p in points], np.int32)
    return ids, np.array(list(seen), dtype=np.float64).reshape(-1, 3)


@needs_accel
@settings(max_examples=150, deadline=None)
@given(n=st.integers(1, 400), alphabet=st.integers(1, 6), seed=st.integers(0, 2**32 - 1),
       wide=st.booleans(), records=st.booleans(), feeds=st.integers(1, 4))
def test_welder_pipeline_matches_a_dict_on_any_feed_size(n, alphabet, seed, wide, records, feeds):
    """The feed loop's prefetch pipeline (64 points ahead) on feeds shorter and longer than its distance, on
    strided record views and plain (k, 3) arrays, with -0.0 and +0.0, many duplicates and table growth from
    a tiny hint: the same ids as a dict in stream order."""
    lib = _native.accel()
    rng = np.random.default_rng(seed)
    values = np.array([0.0, -0.0, 1.0, -1.5, 2.0 ** -149, 3e38][:max(alphabet, 2)])
    pts = rng.choice(values, size=(3 * n, 3)).astype(np.float64 if wide else np.float32)
    ids, ref_vertices = _first_appearance_ids(pts)
    out = np.empty(3 * n, np.int32)
    w = lib.Welder("float64" if wide else "float32", 1)
    cuts = np.unique(np.r_[0, rng.integers(0, n + 1, size=feeds - 1), n])
    for a, b in zip(cuts[:-1], cuts[1:]):
        if records:      # (k, 3, 3) views into 50-byte-like records, as the binary STL reader feeds them
            rec = np.zeros(b - a, dtype=[("n", pts.dtype, (3,)), ("v", pts.dtype, (3, 3)), ("a", "<u2")])
            rec["v"] = pts[3 * a:3 * b].reshape(-1, 3, 3)
            w.feed(rec["v"], out[3 * a:3 * b])
        else:
            w.feed(pts[3 * a:3 * b], out[3 * a:3 * b])
    np.testing.assert_array_equal(out, ids)
    vertices = np.empty((w.count, 3))
    w.vertices_into(vertices)
    np.testing.assert_array_equal(vertices, ref_vertices)
    assert not np.signbit(vertices[vertices == 0]).any()


_faces = st.integers(2, 12).flatmap(lambda n: st.tuples(
    st.just(n), st.lists(st.tuples(*[st.integers(0, n - 1)] * 3), min_size=1, max_size=40)))


@needs_accel
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=_faces)
def test_edge_census_identical_on_random_face_sets(monkeypatch, case):
    """Random faces over a few vertices: holes, fins, flips, duplicated faces, even repeated corners."""
    n, faces = case
    f = np.array(faces, dtype=np.int64)
    v = np.random.default_rng(n).random((n, 3))
    c, ref = both(monkeypatch, lambda: edge_topology(f, n, v))
    assert (c.edges, c.boundary_edges, c.nonmanifold_edges, c.misoriented_edges) == \
        (ref.edges, ref.boundary_edges, ref.nonmanifold_edges, ref.misoriented_edges)
    np.testing.assert_array_equal(c.sample, ref.sample)


@needs_accel
def test_edge_census_on_a_high_degree_fan(monkeypatch):
    """A cone with 40,000 sides: its apex is in every side face (no quadratic scan of a vertex's edges)."""
    k = 40_000
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    v = np.vstack([[0, 0, 1.0], [0, 0, 0.0], np.c_[np.cos(t), np.sin(t), np.zeros(k)]])
    ring = 2 + np.arange(k)
    nxt = 2 + (np.arange(k) + 1) % k
    f = np.vstack([np.c_[np.zeros(k, int), ring, nxt], np.c_[np.ones(k, int), nxt, ring]])
    f_open = f[1:]
    for faces in (f, f_open):
        c, ref = both(monkeypatch, lambda: edge_topology(faces, len(v), v))
        assert (c.edges, c.boundary_edges, c.misoriented_edges) == (ref.edges, ref.boundary_edges,
                                                                     ref.misoriented_edges)
        np.testing.assert_array_equal(c.sample, ref.sample)
    assert c.boundary_edges == 3


@needs_accel
def test_shell_labels_identical_with_shuffled_shells_and_loose_vertices(monkeypatch):
    rng = np.random.default_rng(3)
    parts, n = [], 0
    for k in range(6):
        v, f = box_arrays(center=(3.0 * k, 0, 0))
        parts.append(f + n + 2)       # two loose vertices before each box
        n += len(v) + 2
    faces = np.concatenate(parts)
    perm = rng.permutation(n)         # scatter the vertex numbering
    faces = perm[faces][rng.permutation(len(faces))]
    (lc, kc), (ln, kn) = both(monkeypatch, lambda: shell_labels(faces, n))
    assert kc == kn == 6
    np.testing.assert_array_equal(lc, ln)


def _edge_components_brute(faces: np.ndarray) -> np.ndarray:
    """Faces joined through shared undirected edges by a plain fixed-point iteration (independent of both
    paths), numbered by first face."""
    m = len(faces)
    edges = [{frozenset((int(f[k]), int(f[(k + 1) % 3]))) for k in range(3)} for f in faces]
    label = list(range(m))
    changed = True
    while changed:                      # at most m rounds: each round lowers some label
        changed = False
        for i in range(m):
            for j in range(i + 1, m):
                if edges[i] & edges[j] and label[i] != label[j]:
                    label[i] = label[j] = min(label[i], label[j])
                    changed = True
    rank = {r: k for k, r in enumerate(sorted(set(label)))}
    return np.array([rank[x] for x in label])


@needs_accel
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=_faces)
def test_edge_shell_labels_match_numpy_and_brute_force(monkeypatch, case):
    """Random faces over a few vertices (shared corners without a shared edge, fins, duplicated faces,
    repeated corners): the C kernel, the numpy path and a brute-force fixed point give the same numbering."""
    from inertia_tool.mesh.checks import _edge_shell_labels
    n, faces = case
    f = np.array(faces, dtype=np.int64)
    (lc, kc), (ln, kn) = both(monkeypatch, lambda: _edge_shell_labels(f, n))
    brute = _edge_components_brute(f)
    assert kc == kn == len(set(brute.tolist()))
    np.testing.assert_array_equal(lc, ln)
    np.testing.assert_array_equal(lc, brute)
    lib = _native.accel()
    out32 = np.empty(len(f), np.int32)
    assert lib.edge_shell_labels(f.astype(np.int32), n, out32) == kc      # int32 faces and labels
    np.testing.assert_array_equal(out32, lc)


@needs_accel
def test_edge_shell_labels_on_a_high_degree_fan_and_bowtie(monkeypatch):
    """A 40,000-sided cone (one vertex in every face: a bucket sorted by qsort) and two cones sharing only
    their apex (one vertex-connected piece, two edge-connected shells)."""
    from inertia_tool.mesh.checks import _edge_shell_labels
    k = 40_000
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    v = np.vstack([[0, 0, 1.0], [0, 0, 0.0], np.c_[np.cos(t), np.sin(t), np.zeros(k)]])
    ring = 2 + np.arange(k)
    nxt = 2 + (np.arange(k) + 1) % k
    cone = np.vstack([np.c_[np.zeros(k, int), ring, nxt], np.c_[np.ones(k, int), nxt, ring]])
    second = np.where(cone == 0, 0, cone + len(v))        # a copy sharing the apex (vertex 0) only
    faces = np.vstack([second, cone])
    (lc, kc), (ln, kn) = both(monkeypatch, lambda: _edge_shell_labels(faces, 2 * len(v)))
    assert kc == kn == 2
    np.testing.assert_array_equal(lc, ln)
    assert (lc[:len(cone)] == 0).all() and (lc[len(cone):] == 1).all()
    labels, count = shell_labels(faces, 2 * len(v))
    assert count == 2


def _vertex_components_brute(faces: np.ndarray, n: int) -> tuple[np.ndarray, int]:
    """Faces joined through shared vertices by a plain fixed point over vertex labels, numbered by each
    component's smallest vertex (independent of every kernel)."""
    label = list(range(n))
    changed = True
    while changed:                      # at most n rounds: each round lowers some label
        changed = False
        for f in faces:
            low = min(label[int(x)] for x in f)
            for x in f:
                if label[int(x)] != low:
                    label[int(x)] = low
                    changed = True
    roots = sorted({label[int(f[0])] for f in faces})
    rank = {r: k for k, r in enumerate(roots)}
    return np.array([rank[label[int(f[0])]] for f in faces], dtype=np.int64), len(roots)


@needs_accel
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=_faces, threads=st.integers(1, 5), wide=st.booleans())
def test_census_shells_match_numpy_brute_force_and_the_separate_kernels(monkeypatch, case, threads, wide):
    """The one-adjacency census and shell labels (``census_shells``), on 1-5 threads even for a handful of
    faces (``parallel_min=1``: parts of a face or two, pairs across parts), int32 or int64 faces and labels:
    the census of the numpy path and of ``edge_census``, and the shells of ``checks.shell_labels`` -- numbered
    by smallest vertex when no vertex joins two edge-connected shells (brute force over vertices), else by
    first face (brute force over edges)."""
    from inertia_tool.mesh.checks import census_and_shells
    n, faces = case
    lib = _native.accel()
    f = np.array(faces, dtype=np.int64 if wide else np.int32)
    v = np.random.default_rng(n).random((n, 3))
    by_edge = _edge_components_brute(f)
    by_vertex, k_vertex = _vertex_components_brute(f, n)
    expected = by_vertex if k_vertex == len(set(by_edge.tolist())) else by_edge
    out = np.empty(len(f), np.int64 if wide else np.int32)
    got = lib.census_shells(f, n, out, threads, 1)
    assert got[:7] == lib.edge_census(f, n, 1)
    assert got[7] == len(set(expected.tolist()))
    np.testing.assert_array_equal(out, expected)
    assert lib.census_shells(f, n, None, threads, 1) == got[:7] + (-1,)
    (tc, lc, kc), (tn, ln, kn) = both(monkeypatch, lambda: census_and_shells(f, n, v))
    assert (tc.edges, tc.boundary_edges, tc.nonmanifold_edges, tc.misoriented_edges) == \
        (tn.edges, tn.boundary_edges, tn.nonmanifold_edges, tn.misoriented_edges)
    np.testing.assert_array_equal(tc.sample, tn.sample)
    assert kc == kn == got[7]
    np.testing.assert_array_equal(lc, ln)
    np.testing.assert_array_equal(lc, expected)


def test_census_shells_refuses_malformed_arguments():
    lib = _native.accel()
    if lib is None:
        pytest.skip("inertia_tool._accel is not built")
    v, f = box_arrays()
    f = np.ascontiguousarray(f, dtype=np.int64)
    bad = f.copy()
    bad[5, 1] = len(v)
    with pytest.raises(ValueError, match="face indices"):
        lib.census_shells(bad, len(v), np.empty(len(f), np.int64))
    with pytest.raises(ValueError, match="face indices"):
        lib.census_shells(-f - 1, len(v), None)
    with pytest.raises(ValueError, match="entries"):
        lib.census_shells(f, len(v), np.empty(len(f) - 1, np.int64))
    with pytest.raises(ValueError, match="entries"):
        lib.census_shells(f, len(v), np.empty(len(f), np.float64))
    with pytest.raises(ValueError):
        lib.census_shells(f.astype(np.float64), len(v), None)
    with pytest.raises(ValueError):
        lib.census_shells(f, -1, None)
    with pytest.raises((ValueError, TypeError)):
        lib.census_shells(f, len(v), np.empty(len(f), np.int64)[::-1])   # not contiguous / read-only views
    empty = np.zeros((0, 3), np.int64)
    assert lib.census_shells(empty, 0, np.empty(0, np.int64)) == (0, 0, 0, 0, [], [], [], 0)


def test_edge_shell_labels_refuses_malformed_arguments():
    lib = _native.accel()
    if lib is None:
        pytest.skip("inertia_tool._accel is not built")
    v, f = box_arrays()
    f = np.ascontiguousarray(f, dtype=np.int64)
    bad = f.copy()
    bad[5, 1] = len(v)
    with pytest.raises(ValueError, match="face indices"):
        lib.edge_shell_labels(bad, len(v), np.empty(len(f), np.int64))
    with pytest.raises(ValueError):
        lib.edge_shell_labels(f, len(v), np.empty(len(f) - 1, np.int64))
    with pytest.raises(ValueError):
        lib.edge_shell_labels(f.astype(np.float64), len(v), np.empty(len(f), np.int64))


@needs_accel
@pytest.mark.parametrize("m", [5, 70_000])       # one lane, and 32 lanes over two threads
def test_face_measures_agree_with_numpy_to_round_off(monkeypatch, m):
    """The float32 storage bound's area and perimeter sums: C (lanes) against numpy (chunks) and against
    a direct float64 evaluation, on random triangles with repeated corners and int32 or int64 faces."""
    from inertia_tool.mesh.precision import volume_rounding_bound
    rng = np.random.default_rng(m)
    v = rng.normal(size=(m + 3, 3)) * 10.0 + 100.0
    f = rng.integers(0, len(v), size=(m, 3))
    f[0, 1] = f[0, 0]                              # a zero-area face
    lib = _native.accel()
    for faces in (f, f.astype(np.int32)):
        area, perimeter = lib.face_measures(v, np.ascontiguousarray(faces), 2)
        tri = v[f]
        e = np.roll(tri, -1, axis=1) - tri
        ref_perimeter = np.linalg.norm(e, axis=2).sum()
        ref_area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()
        assert area == pytest.approx(ref_area, rel=1e-12)
        assert perimeter == pytest.approx(ref_perimeter, rel=1e-12)
    c, ref = both(monkeypatch, lambda: volume_rounding_bound(v, f, 1e-6))
    assert c == pytest.approx(ref, rel=1e-12) and c > 0
    with pytest.raises(ValueError, match="face indices"):
        lib.face_measures(v, np.full((1, 3), len(v)))
    with pytest.raises(ValueError):
        lib.face_measures(v.astype(np.float32), f)


def _rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(np.max(np.abs(b)), 1e-300))


@needs_accel
@pytest.mark.parametrize("offset", [0.0, 1e3])
def test_tetra_sums_agree_to_round_off(monkeypatch, offset):
    """An icosphere of 327,680 faces (the benchmark meshes' kind), at the origin and far from it."""
    m = trimesh.creation.icosphere(subdivisions=7, radius=50.0)
    v = np.asarray(m.vertices, dtype=np.float32).astype(float) + offset
    f = np.asarray(m.faces)
    c, ref = both(monkeypatch, lambda: volume_moments(v, f))
    assert c.volume == pytest.approx(ref.volume, rel=1e-13)
    assert c.area == pytest.approx(ref.area, rel=1e-13)
    np.testing.assert_allclose(c.centroid, ref.centroid, rtol=0, atol=1e-13 * 100.0)
    assert _rel(c.second_moment, ref.second_moment) < 1e-13
    assert c.zero_area_faces == ref.zero_area_faces


@needs_accel
def test_tetra_sums_per_label_agree(monkeypatch):
    """Per-shell sums in one labelled pass about one origin, against the numpy labelled pass and the numpy
    single-shell pass.  Shells away from the origin lose digits when the sums are moved to their centroid
    (C − V d dᵀ), so the second moments are compared relative to the raw sum's size ``|C| + V |d|²``."""
    from inertia_tool.integrals import reference_point
    shells = [trimesh.creation.icosphere(subdivisions=4, radius=r) for r in (1.0, 0.5, 2.0)]
    v = np.concatenate([np.asarray(s.vertices) + 5.0 * k for k, s in enumerate(shells)])
    offs = np.cumsum([0] + [len(s.vertices) for s in shells])
    f = np.concatenate([np.asarray(s.faces) + offs[k] for k, s in enumerate(shells)])
    f[len(shells[0].faces):len(shells[0].faces) + len(shells[1].faces)] = \
        f[len(shells[0].faces):len(shells[0].faces) + len(shells[1].faces), ::-1]    # a cavity-like inward shell
    labels = np.repeat(np.arange(3), [len(s.faces) for s in shells])
    c, ref = both(monkeypatch, lambda: body_volume_moments(v, f, labels, 3))
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    single = [volume_moments(v, f[labels == k], origin=reference_point(v)) for k in range(3)]

    o = reference_point(v)
    for a, b, s in zip(c, ref, single):
        raw = np.max(np.abs(s.second_moment)) + abs(s.volume) * float(np.sum((s.centroid - o) ** 2))
        for other in (b, s):
            assert a.volume == pytest.approx(other.volume, rel=1e-13)
            np.testing.assert_allclose(a.centroid, other.centroid, rtol=0, atol=1e-13 * 20)
            assert np.max(np.abs(a.second_moment - other.second_moment)) < 1e-13 * raw
    assert c[1].volume < 0


@needs_accel
def test_kernels_refuse_malformed_arguments():
    lib = _native.accel()
    v, f = box_arrays()
    f = np.ascontiguousarray(f, dtype=np.int64)
    bad = f.copy()
    bad[5, 1] = len(v)
    neg = f.copy()
    neg[0, 0] = -1
    sums, zero = np.empty((1, 11)), np.empty(1, np.int64)
    for faces in (bad, neg):
        with pytest.raises(ValueError, match="face indices"):
            lib.edge_census(faces, len(v))
        with pytest.raises(ValueError, match="face indices"):
            lib.shell_labels(faces, len(v), np.empty(len(f), np.int64))
        with pytest.raises(ValueError, match="face indices"):
            lib.tetra_sums(v, faces, (0.0, 0.0, 0.0), 0.0, None, sums, zero)
    with pytest.raises(ValueError):
        lib.edge_census(f.astype(np.float64), len(v))            # float faces
    with pytest.raises(ValueError):
        lib.edge_census(f.astype(">i8"), len(v))                 # foreign byte order
    with pytest.raises(ValueError):
        lib.edge_census(f[:, :2].copy(), len(v))                 # not triangles
    with pytest.raises(ValueError):
        lib.edge_census(f, -1)
    with pytest.raises(ValueError):
        lib.edge_census(f, 2**40)
    with pytest.raises(ValueError):
        lib.shell_labels(f, len(v), np.empty(len(f) - 1, np.int64))   # short output
    with pytest.raises(ValueError, match="labels"):
        lib.tetra_sums(v, f, (0.0, 0.0, 0.0), 0.0, np.full(len(f), 7), np.empty((2, 11)), np.empty(2, np.int64))
    with pytest.raises(ValueError):
        lib.tetra_sums(v.astype(np.float32), f, (0.0, 0.0, 0.0), 0.0, None, sums, zero)
    with pytest.raises((ValueError, BufferError)):
        lib.tetra_sums(v, f, (0.0, 0.0, 0.0), 0.0, None, sums, np.empty(1, np.int64)[::1].view(np.float64))
    readonly = np.empty(len(f), np.int64)
    readonly.flags.writeable = False
    with pytest.raises((ValueError, BufferError)):
        lib.shell_labels(f, len(v), readonly)
    with pytest.raises(ValueError):
        lib.Welder("float16")
    w = lib.Welder("float32")
    with pytest.raises(RuntimeError):
        w.__init__("float64")                                     # re-initialising would mix key widths
    with pytest.raises(ValueError):
        w.feed(np.zeros((3, 3)), np.empty(3, np.int32))           # float64 into a float32 welder
    with pytest.raises(ValueError):
        w.feed(np.zeros((3, 3), np.float32), np.empty(2, np.int32))   # output too short
    with pytest.raises(ValueError):
        w.vertices_into(np.empty((5, 3)))
    with pytest.raises(RuntimeError):
        lib.Welder.__new__(lib.Welder).feed(np.zeros((3, 3), np.float32), np.empty(3, np.int32))


@needs_accel
def test_kernels_run_concurrently_in_threads():
    """The GIL is released inside the loops; separate welders and censuses in threads give the same results."""
    lib = _native.accel()
    pts = np.random.default_rng(4).integers(0, 50, size=(300_000, 3)).astype(np.float32)
    results = [None] * 4

    def work(i):
        w = lib.Welder("float32", 0)
        ids = np.empty(len(pts), np.int32)
        w.feed(pts, ids)
        results[i] = ids
    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results[1:]:
        np.testing.assert_array_equal(r, results[0])


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux" or shutil.which("gcc") is None, reason="needs gcc with libasan (Linux)")
def test_sanitizer_build_replays_the_corpus_without_reports():
    """scripts/sanitize.sh: the C extension under AddressSanitizer + UndefinedBehaviorSanitizer, a short replay
    (the corpus, 20 mutations, the C API edge cases).  Before the guard in Welder.vertices_into, UBSan
    reported memcpy(NULL, ..., 0) for a welder of zero vertices."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    asan = subprocess.run(["gcc", "-print-file-name=libasan.so"], capture_output=True, text=True).stdout.strip()
    if not os.path.isabs(asan):
        pytest.skip("gcc has no libasan")
    done = subprocess.run(["sh", os.path.join(root, "scripts", "sanitize.sh"), "20", "3"], capture_output=True,
                          text=True, timeout=600, env={**os.environ, "PYTHON": sys.executable})
    assert done.returncode == 0, done.stderr[-3000:]
    assert "findings 0" in done.stdout and "sanitize: OK" in done.stdout


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux" or shutil.which("gcc") is None, reason="needs gcc with libtsan (Linux)")
def test_threaded_kernels_have_no_data_race():
    """scripts/tsan.sh: the thread tests against a ThreadSanitizer build of the extension report no data race
    (it found two while the kernels were written: same-value flag stores, and a Welder read while fed)."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    tsan = subprocess.run(["gcc", "-print-file-name=libtsan.so"], capture_output=True, text=True).stdout.strip()
    if not os.path.isabs(tsan):
        pytest.skip("gcc has no libtsan")
    done = subprocess.run(["sh", os.path.join(root, "scripts", "tsan.sh")], capture_output=True, text=True,
                          timeout=900, env={**os.environ, "PYTHON": sys.executable})
    assert done.returncode == 0, (done.stdout + done.stderr)[-3000:]
    assert "without reports" in done.stdout


def test_accel_source_has_no_identifier_that_windows_h_redefines():
    """_accel.c includes <windows.h> on Windows; the Windows SDK defines some plain words as macros there
    (rpcndr.h: ``#define small char``; minwindef.h: ``far``, ``near``, ``pascal``; combaseapi.h:
    ``interface``), so a variable of that name does not compile with MSVC -- and setup.py's optional build
    would then install the package without its C kernels, silently.  Checked on the source text (comments and
    strings removed) so that it fails on Linux too."""
    import re
    path = os.path.join(os.path.dirname(__file__), "..", "inertia_tool", "_accel.c")
    with open(path, encoding="utf-8") as fh:
        src = fh.read()
    code = re.sub(r"/\*.*?\*/|//[^\n]*|\"(?:\\.|[^\"\\])*\"|'(?:\\.|[^'\\])'", " ", src, flags=re.S)
    words = set(re.findall(r"\b[A-Za-z_]\w*\b", code))
    assert words.isdisjoint({"small", "hyper", "far", "near", "pascal", "interface"}), \
        sorted(words & {"small", "hyper", "far", "near", "pascal", "interface"})
