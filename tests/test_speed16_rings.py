"""The hole fills' neighbourhoods grown over the faces near the rims alone (issue 25, speed16) are the ones grown
over every face, and :func:`~inertia_tool.mesh.hole_fills.curved_fills` tries the same loops on the same points.

The reference is the reading before the change: each rim's two rings grown over all faces (``near[f].any``
twice per rim), the loops tried in ``order`` picked by ``edges[label == k]``.  Meshes: random soups on a small
vertex pool (edges shared by three or more faces, vertices of no face) and icospheres with random faces removed
(scattered holes of one to many edges, holes meeting at corners).  No timings here: they are in
``benchmarks/bench_repair.py`` and ``docs/performance.md``.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import hole_fills
from inertia_tool.mesh.rims import boundary_edges, boundary_loops, enclosing_balls


def _reference_two_rings(f, n, rim):
    """The rim's vertices, then those of every face holding one, twice, reading every face."""
    near = np.zeros(n, dtype=bool)
    near[rim] = True
    for _ in range(2):
        near[f[near[f].any(axis=1)].reshape(-1)] = True
    return near


def _soup(rng, n_vertices, n_faces):
    """Random faces on a pool of vertices (some never used): edges shared by three or more faces."""
    return np.array([rng.choice(n_vertices, 3, replace=False) for _ in range(n_faces)], dtype=np.int64)


def _holed_sphere(level, seed, share):
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=level)
    v, f = np.asarray(s.vertices, dtype=np.float64), np.asarray(s.faces, dtype=np.int64)
    rng = np.random.default_rng(seed)
    keep = rng.random(len(f)) >= share
    # a few larger holes too (every face at a vertex), so that some rims are long enough to be fitted
    for centre in rng.choice(len(v), 3, replace=False):
        keep &= ~(f == centre).any(axis=1)
    return v, f[keep]


@settings(max_examples=60, deadline=None)
@given(st.integers(4, 40), st.integers(1, 80), st.integers(0, 2**32 - 1), st.integers(1, 6))
def test_two_rings_over_the_faces_near_the_rims_equal_the_rings_over_every_face(n_vertices, n_faces, seed,
                                                                                   n_rims):
    rng = np.random.default_rng(seed)
    f = _soup(rng, n_vertices, n_faces)
    n = n_vertices + int(rng.integers(0, 3))           # vertices of no face at the end
    rims = [rng.choice(n, int(rng.integers(1, min(n, 6) + 1)), replace=False) for _ in range(n_rims)]
    near_faces = hole_fills._faces_near(f, n, rims)
    assert set(map(tuple, near_faces.tolist())) <= set(map(tuple, f.tolist()))
    for rim in rims:
        got = hole_fills._two_rings(near_faces, n, rim)
        want = _reference_two_rings(f, n, rim)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(hole_fills._two_rings(f, n, rim), want)


def _reference_tried(edges, label, order, max_loops):
    """The loops curved_fills tries, and each one's two-ring mask, as the code before the change picked them."""
    tried = []
    for k in order.tolist():
        if len(tried) >= max_loops:
            break
        rim_edges = edges[label == k]
        rim = np.unique(rim_edges)
        if len(rim) < 5 or len(rim_edges) != len(rim):
            continue
        tried.append((k, rim))
    return tried


@settings(max_examples=12, deadline=None)
@given(st.integers(2, 3), st.integers(0, 2**32 - 1), st.floats(0.02, 0.3), st.integers(0, 8))
def test_curved_fills_fit_the_same_points_of_the_same_loops(level, seed, share, max_loops):
    v, f = _holed_sphere(level, seed, share)
    edges = boundary_edges(f, len(v))
    label, n_loops = boundary_loops(edges, len(v), f, v)
    rims = np.concatenate([edges[:, 0], edges[:, 1]])
    centre, radius = enclosing_balls(v[rims], np.concatenate([label, label]), n_loops)
    apex = centre.copy()
    order = np.random.default_rng(seed).permutation(n_loops)
    fitted: list[np.ndarray] = []
    real = hole_fills._fitted_quadric

    def spy(x, fit_rtol):
        fitted.append(x.copy())
        return real(x, fit_rtol)

    far = np.full(n_loops, np.inf)
    capsule = (centre, centre, far)
    slab = (np.zeros((n_loops, 3)), np.zeros((n_loops, 3)), far)
    hole_fills._fitted_quadric = spy
    try:
        fills = hole_fills.curved_fills(v, f, edges, label, n_loops, apex, centre, radius, capsule, slab, order,
                                        max_loops=max_loops)
    finally:
        hole_fills._fitted_quadric = real
    want = _reference_tried(edges, label, order, max_loops)
    assert len(fitted) == len(want)
    for x, (k, rim) in zip(fitted, want):
        near = _reference_two_rings(f, len(v), rim)
        assert x.tobytes() == ((v[near] - centre[k]) / radius[k]).tobytes()
    assert [fill.loop for fill in fills] == [k for k, _ in want if k in {fill.loop for fill in fills}]



def _meeting_pairs(centre, radius):
    gap = np.linalg.norm(centre[:, None, :] - centre[None, :, :], axis=2)
    meet = gap <= radius[:, None] + radius[None, :]
    np.fill_diagonal(meet, False)
    return {(int(i), int(j)) for i, j in zip(*np.nonzero(meet)) if i < j}


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 400), st.sampled_from(["cloud", "shell", "point", "far", "zero"]),
       st.floats(1e-4, 0.5), st.integers(0, 30))
def test_meeting_candidates_hold_every_meeting_pair(seed, n, layout, scale, tangent):
    """The grid's candidates (scipy's k-d tree left out) hold every pair of balls that meet: clouds, balls on a
    sphere's surface (scattered holes), all at one point (too many pairs: None), tiny balls far apart (cells too
    fine: None), radius zero (equal centres only); exactly tangent pairs."""
    from inertia_tool.mesh import hole_bounds

    rng = np.random.default_rng(seed)
    centre = rng.normal(size=(n, 3))
    if layout == "shell":
        centre /= np.linalg.norm(centre, axis=1, keepdims=True)
    elif layout == "point":
        centre[:] = centre[0]
    elif layout == "far":
        centre *= 1e9
    radius = rng.exponential(scale, size=n) * (layout != "zero")
    if layout == "zero":
        centre = np.round(centre, 0)
    for k in rng.integers(0, n - 1, size=tangent):      # balls exactly touching (gap == r_i + r_j)
        d = float(np.linalg.norm(centre[k] - centre[k + 1]))
        radius[k] = d / 2
        radius[k + 1] = d - radius[k]
    pairs = hole_bounds._meeting_candidates(centre, radius)
    if layout == "point" and n > 2 * hole_bounds.MEETING_PAIRS_PER_BALL:
        assert pairs is None
    if pairs is not None:
        i, j = pairs
        assert (i != j).all()
        found = {(min(a, b), max(a, b)) for a, b in zip(i.tolist(), j.tolist())}
        assert _meeting_pairs(centre, radius) <= found
    want = ~np.isin(np.arange(n), [k for pair in _meeting_pairs(centre, radius) for k in pair])
    np.testing.assert_array_equal(hole_bounds._alone(centre, radius, chunk=1), want)


def _reference_partition(a, b, n):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(a), dtype=np.int8), (a, b)), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def _same_partition(x, y):
    """Two labellings that group the nodes alike (a bijection between their labels)."""
    pairs = set(zip(x.tolist(), y.tolist()))
    return len(pairs) == len(set(x.tolist())) == len(set(y.tolist()))


@settings(max_examples=80, deadline=None)
@given(st.integers(1, 60), st.integers(0, 120), st.integers(0, 2**32 - 1), st.sampled_from(["random", "path", "star"]),
       st.integers(1, 64))
def test_fan_components_partition_the_nodes_as_scipy_does(n, n_edges, seed, shape, rounds):
    rng = np.random.default_rng(seed)
    if shape == "random":
        a, b = rng.integers(0, n, n_edges), rng.integers(0, n, n_edges)
    elif shape == "path":                 # a long path in a shuffled numbering: the most rounds of hooking
        perm = rng.permutation(n)
        a, b = perm[:-1], perm[1:]
    else:                                 # a star whose centre is the highest node
        a, b = np.full(n - 1, n - 1), np.arange(n - 1)
    from inertia_tool.mesh import rims

    saved = rims.COMPONENT_ROUNDS
    rims.COMPONENT_ROUNDS = rounds       # few rounds: scipy takes over, with the same partition
    try:
        got = rims._components(a, b, n)
    finally:
        rims.COMPONENT_ROUNDS = saved
    want = _reference_partition(a, b, n)
    assert got.shape == (n,) and _same_partition(got, want)
    if rounds == 64:
        # the hooking's own labels: the lowest node of each component
        lowest = {}
        for node, comp in enumerate(want.tolist()):
            lowest.setdefault(comp, node)
        assert got.tolist() == [lowest[c] for c in want.tolist()]


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 300), st.integers(1, 50), st.integers(1, 40))
def test_loop_vertex_pairs_are_numpy_uniques_rows(seed, k, n_loops, n_vertices):
    """The (loop, vertex) pairs of patched_estimate (one edge at least: it asks only when there are loops) by
    one int64 key per row: numpy.unique(axis=0)'s rows."""
    from inertia_tool.mesh.seal import _unique_rows

    rng = np.random.default_rng(seed)
    label = rng.integers(0, n_loops, k)
    edges = rng.integers(0, n_vertices, (k, 2))
    rows = np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1)
    got = _unique_rows(rows, n_vertices)
    want = np.unique(rows, axis=0)
    assert got.dtype == want.dtype and got.tobytes() == want.tobytes()
