"""``seal.on_edge_vertices``: the boundary vertices lying on the interior of a boundary edge to round-off.

Issue 25 item 3 (no slow path): on an unwelded soup every vertex is a boundary vertex and every edge a boundary
edge, and the k-d tree search listed the ~9 vertices in each edge's ball as Python lists (15 s of a 288,800-face
soup's 17.5 s, 50 s and 4.6 GB on a 1.3M-face one).  The C kernel (``_accel.on_edge_points``, section 9) visits a
grid of cells along each edge.  Both paths are checked against a brute force over every (vertex, edge) pair with
the documented test, on hypothesis-generated edges with vertices put on them, jittered copies of their ends
(a soup), degenerate and repeated edges, and parts far from the origin.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh.seal import ON_EDGE_RTOL, on_edge_vertices
from conftest import HAVE_ACCEL

both_paths = pytest.mark.usefixtures("engine_path")


def brute_force(v, edges):
    """Every boundary vertex against every boundary edge with the documented test, all pairs at once (no
    spatial search)."""
    v = np.asarray(v, dtype=np.float64)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    boundary = np.unique(edges)
    e = np.repeat(np.arange(len(edges)), len(boundary))
    m = np.tile(boundary, len(edges))
    a, b, p = v[edges[e, 0]], v[edges[e, 1]], v[m]
    d = b - a
    length = np.linalg.norm(d, axis=1)
    t = np.einsum("ij,ij->i", p - a, d) / np.maximum(length ** 2, np.finfo(float).tiny)
    dist = np.linalg.norm(p - (a + t[:, None] * d), axis=1)
    near = np.minimum(np.linalg.norm(p - a, axis=1), np.linalg.norm(p - b, axis=1))
    on = (m != edges[e, 0]) & (m != edges[e, 1]) & (t > 0) & (t < 1) & (near > 0) & (dist <= ON_EDGE_RTOL * near)
    return np.unique(m[on])


@st.composite
def edge_sets(draw):
    """Boundary edges of random length and direction, with vertices on some of them (T-vertices), jittered
    copies of their ends (a soup) and vertices near but off them; optionally far from the origin."""
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    n_edges = draw(st.integers(1, 40))
    scale = 10.0 ** draw(st.integers(-3, 2))
    offset = draw(st.sampled_from([0.0, 1.0, 1e3])) * scale
    a = rng.normal(size=(n_edges, 3)) * scale + offset
    b = a + rng.normal(size=(n_edges, 3)) * scale * 10.0 ** rng.uniform(-3, 0, size=(n_edges, 1))
    points = [a, b]
    # T-vertices: a point of the edge, computed in float64 (on it to round-off)
    pick = rng.integers(n_edges, size=draw(st.integers(0, 20)))
    t = rng.uniform(1e-6, 1 - 1e-6, size=len(pick))
    points.append(a[pick] + t[:, None] * (b[pick] - a[pick]))
    # near misses: moved off the edge by 1e-12..1e-6 of its length
    pick = rng.integers(n_edges, size=draw(st.integers(0, 10)))
    t = rng.uniform(0.01, 0.99, size=len(pick))
    off = rng.normal(size=(len(pick), 3)) * np.linalg.norm(b[pick] - a[pick], axis=1)[:, None]
    points.append(a[pick] + t[:, None] * (b[pick] - a[pick]) + off * 10.0 ** rng.uniform(-12, -6, (len(pick), 1)))
    # a soup's jittered copies of the ends
    pick = rng.integers(n_edges, size=draw(st.integers(0, 30)))
    points.append(a[pick] + rng.normal(size=(len(pick), 3)) * scale * 1e-7)
    v = np.vstack(points)
    idx = np.arange(len(v))
    edges = [np.stack([idx[:n_edges], idx[n_edges:2 * n_edges]], axis=1)]
    # the other points become ends of edges too (every vertex tested is a boundary vertex), some degenerate
    rest = idx[2 * n_edges:]
    if len(rest):
        partner = rng.integers(len(v), size=len(rest))
        edges.append(np.stack([rest, partner], axis=1))
    e = np.vstack(edges)
    if draw(st.booleans()):       # repeated edges (the boundary chain has |net| copies)
        e = np.vstack([e, e[: max(1, len(e) // 3)]])
    if draw(st.booleans()):       # consecutive copies (as the census lists them), which the search drops first
        e = np.repeat(e, rng.integers(1, 4, size=len(e)), axis=0)
    return v, e


@both_paths
@settings(max_examples=80, deadline=None)
@given(edge_sets())
def test_on_edge_vertices_equal_brute_force(case):
    v, edges = case
    np.testing.assert_array_equal(on_edge_vertices(v, edges), brute_force(v, edges))


@both_paths
def test_t_vertex_found_and_soup_copies_not():
    """A vertex at the midpoint of an edge is found; copies of the ends moved by 1e-7 of the length are not;
    a vertex exactly at an end (a duplicate point) is not either (t = 0)."""
    a, b = np.array([0.1, 0.2, 0.3]), np.array([1.7, -0.4, 2.2])
    mid = 0.5 * (a + b)
    jitter = np.array([[1e-7, -2e-7, 0.5e-7], [-1e-7, 1e-7, 1e-7]]) * np.linalg.norm(b - a)
    v = np.vstack([a, b, mid, a + jitter[0], b + jitter[1], a.copy()])
    edges = np.array([[0, 1], [2, 3], [4, 5]])
    np.testing.assert_array_equal(on_edge_vertices(v, edges), [2])


@both_paths
def test_soup_of_a_closed_surface_has_no_on_edge_vertex():
    """The regression case of the slow path, small: a jittered soup of an icosphere (every vertex a boundary
    vertex, every edge a boundary edge): no vertex is on an edge, on both paths, as the brute force says."""
    import trimesh

    sphere = trimesh.creation.icosphere(2)
    tri = np.asarray(sphere.vertices)[np.asarray(sphere.faces)]
    rng = np.random.default_rng(5)
    tri = tri + rng.normal(size=tri.shape) * 1e-7
    v = tri.reshape(-1, 3)
    f = np.arange(len(v)).reshape(-1, 3)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    found = on_edge_vertices(v, edges)
    np.testing.assert_array_equal(found, brute_force(v, edges))
    assert len(found) == 0


@both_paths
def test_no_boundary():
    assert on_edge_vertices(np.zeros((3, 3)), np.zeros((0, 2), dtype=np.int64)).tolist() == []


@both_paths
def test_t_junction_repair_unchanged_on_both_paths():
    """A box whose top face is split at a T-vertex on a shared edge (the vertex is on the neighbour's edge):
    repair seals it exactly (nothing welded onto the T-vertex), as before the kernel."""
    import inertia_tool as it

    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1],
                  [0.5, 0, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 5], [0, 5, 8], [0, 8, 4], [1, 2, 6], [1, 6, 5],
                      [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7],
                      # top face split at the T-vertex 8 on one side only (the front face above uses 5-8-4)
                      [4, 5, 6], [4, 6, 7]])
    with pytest.warns(it.errors.MeshResolvedWarning):
        p = it.mass_properties((v, faces), density=1.0, repair=True)
    assert p.mesh.method == "sealed" and p.mesh.certificate.kind == "exact"
    assert p.volume == pytest.approx(1.0, rel=1e-12)


def _damaged_sphere(seed):
    """An icosphere with a patch split 1→4 at edge midpoints (T-junctions round it) and a crack: a patch cut
    free, its border corners moved by 1e-7…1e-5 of the size (the lips within the seal's gap)."""
    import trimesh

    rng = np.random.default_rng(seed)
    mesh = trimesh.creation.icosphere(3)
    v, f = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)
    patch = np.flatnonzero(np.linalg.norm(v[f].mean(axis=1) - v[rng.integers(len(v))], axis=1) < 0.5)
    pf = f[patch]
    edges = np.sort(pf[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = 0.5 * (v[unique[:, 0]] + v[unique[:, 1]])
    mm = len(v) + inverse.reshape(-1, 3)
    a, b, c = pf[:, 0], pf[:, 1], pf[:, 2]
    fine = np.concatenate([np.c_[a, mm[:, 0], mm[:, 2]], np.c_[mm[:, 0], b, mm[:, 1]],
                           np.c_[mm[:, 2], mm[:, 1], c], np.c_[mm[:, 0], mm[:, 1], mm[:, 2]]])
    keep = np.ones(len(f), dtype=bool)
    keep[patch] = False
    v, f = np.vstack([v, mid]), np.vstack([f[keep], fine])
    cut = np.flatnonzero(np.linalg.norm(v[f].mean(axis=1) - v[rng.integers(len(v))], axis=1) < 0.4)
    inside = np.zeros(len(f), dtype=bool)
    inside[cut] = True
    border = np.intersect1d(np.unique(f[cut]), np.unique(f[~inside]))
    remap = np.arange(len(v))
    remap[border] = np.arange(len(v), len(v) + len(border))
    f = f.copy()
    f[cut] = remap[f[cut]]
    step = rng.normal(size=(len(border), 3))
    moved = v[border] + 10.0 ** rng.uniform(-7, -5) * 2.0 * step / np.linalg.norm(step, axis=1, keepdims=True)
    return np.vstack([v, moved]), f


@pytest.mark.skipif(not HAVE_ACCEL, reason="compares the C kernel's candidates with the k-d tree's")
@settings(max_examples=8, deadline=None)
@given(st.integers(0, 2 ** 32 - 1))
def test_seal_seams_same_on_both_paths(seed):
    """The seal (T-junction splits exactly on their edges, then lip welds and splits within the gap) finds the
    same pairs from the C kernel's candidates as from the k-d tree's: the same faces, slack and counts."""
    from inertia_tool.mesh.seal import seal_seams

    v, f = _damaged_sphere(seed)
    gap = 1e-4 * 2.0
    with pytest.MonkeyPatch.context() as patch:
        patch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
        fast = seal_seams(v, f, gap)
        patch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
        slow = seal_seams(v, f, gap)
    assert fast.split > 0 or fast.welded > 0
    np.testing.assert_array_equal(fast.faces, slow.faces)
    np.testing.assert_array_equal(fast.slack, slow.slack)
    assert (fast.welded, fast.split, fast.duplicates, fast.loose_faces) == \
        (slow.welded, slow.split, slow.duplicates, slow.loose_faces)


@both_paths
def test_long_edges_over_a_fine_part():
    """A few long boundary edges over thousands of tiny ones (the grid is coarsened so that the long edges are
    not cut into millions of pieces): the same vertices as the brute force, the T-vertex on a long edge too."""
    rng = np.random.default_rng(3)
    tiny = rng.normal(size=(3000, 3)) * 1e-6
    tiny_edges = np.stack([np.arange(0, 3000, 2), np.arange(1, 3000, 2)], axis=1)
    far = np.array([[-1.0, 0, 0], [1.0, 0, 0], [0, -1.0, 0], [0, 1.0, 0]])
    t_vertex = np.array([[0.25, 0, 0]])                   # on the first long edge
    v = np.vstack([tiny, far, t_vertex])
    edges = np.vstack([tiny_edges, [[3000, 3001], [3002, 3003], [3004, 0]]])
    found = on_edge_vertices(v, edges)
    np.testing.assert_array_equal(found, brute_force(v, edges))
    assert 3004 in found


@pytest.mark.skipif(not HAVE_ACCEL, reason="the C kernel's threads")
@pytest.mark.parametrize("gap", [0.0, 2e-3])
def test_the_kernel_lists_the_same_pairs_on_any_number_of_threads(gap):
    """The edges are searched in blocks by whichever thread is free and merged by edge: the pairs, and their
    order within an edge, do not depend on the threads (a jittered soup of 245,760 edges, above the kernel's
    threshold for threads, with T-vertices put on some edges; with a gap, millions of pairs)."""
    import trimesh

    from inertia_tool._native import accel

    rng = np.random.default_rng(4)
    s = trimesh.creation.icosphere(6)
    tri = np.asarray(s.vertices)[np.asarray(s.faces)]
    tri = tri + rng.normal(size=tri.shape) * 1e-7
    v = tri.reshape(-1, 3)
    edges = np.stack([np.arange(len(v)), np.arange(len(v)).reshape(-1, 3)[:, [1, 2, 0]].reshape(-1)], axis=1)
    pick = rng.choice(len(edges), size=500, replace=False)
    v = np.vstack([v, 0.5 * (v[edges[pick, 0]] + v[edges[pick, 1]])])      # midpoints: on their edges
    edges = np.vstack([edges, edges[pick][:, ::-1]])                       # and the coarse sides, reversed
    points = np.arange(len(v))
    lib = accel()
    cell = float(np.median(np.linalg.norm(v[edges[:, 1]] - v[edges[:, 0]], axis=1)))
    args = (np.ascontiguousarray(v), np.ascontiguousarray(edges, dtype=np.int64), points, cell, ON_EDGE_RTOL, gap)
    one = lib.edge_point_candidates(*args)
    assert len(one[0]) // 8 >= 500
    for threads in (1, 2, 3, 16):
        assert lib.edge_point_candidates(*args, threads) == one
