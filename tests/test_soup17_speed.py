"""The hole stages' shortcuts of issue 25 (soup17) give what the readings they replace give, bit for bit.

- ``hole_bounds._sorted_pairs`` (one int64 key per row) for the (face, loop), (vertex, loop) and (loop, vertex)
  rows that ``numpy.unique(axis=0)`` sorted before;
- ``hole_bounds.rim_fans`` computed once and handed to ``level_rings`` and ``bend_doubt_volumes`` (each computed
  it before): the same levels, doubts and heights;
- ``rims.enclosing_balls`` with each step's difference formed once: the centres and radii of the reading that
  formed it twice (the reference below, the code before the change).

Meshes: icospheres and tori with random faces removed (scattered holes of one to many edges) and patches removed
(larger holes), moved off the origin.  No timings here: they are in ``benchmarks/bench_repair.py`` and
``docs/performance.md``.
"""

from __future__ import annotations

import numpy as np
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import hole_bounds
from inertia_tool.mesh.rims import boundary_edges, boundary_loops, enclosing_balls


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 300), st.integers(1, 50), st.integers(1, 4000))
def test_sorted_pairs_are_numpy_uniques_rows(seed, k, width, first_range):
    rng = np.random.default_rng(seed)
    first = rng.integers(0, first_range, k)
    second = rng.integers(0, width, k)
    got = hole_bounds._sorted_pairs(first, second, width)
    want = np.unique(np.stack([first, second], axis=1), axis=0)
    assert got.dtype == want.dtype and got.shape == want.shape and got.tobytes() == want.tobytes()


def _holed(seed):
    """A closed surface less random faces (and sometimes a patch), moved off the origin; its boundary loops and
    their apexes as ``holes.patched_estimate`` forms them."""
    rng = np.random.default_rng([seed, 17])
    if rng.random() < 0.5:
        s = trimesh.creation.icosphere(int(rng.integers(2, 4)), radius=float(rng.uniform(0.5, 2.0)))
    else:
        s = trimesh.creation.torus(1.0, float(rng.uniform(0.2, 0.6)), major_sections=int(rng.integers(12, 33)),
                                   minor_sections=int(rng.integers(6, 17)))
    v = np.asarray(s.vertices) + rng.uniform(-5, 5, size=3)
    f = np.asarray(s.faces, dtype=np.int64)
    keep = rng.random(len(f)) >= rng.uniform(0.02, 0.2)
    if rng.random() < 0.5:                      # and a patch round one face
        centre = v[f].mean(axis=1)
        seed_face = int(rng.integers(len(f)))
        near = np.argsort(np.linalg.norm(centre - centre[seed_face], axis=1))[: int(rng.integers(3, 30))]
        keep[near] = False
    f = f[keep]
    edges = boundary_edges(f, len(v))
    label, n_loops = boundary_loops(edges, len(v), f, v)
    pairs = hole_bounds._sorted_pairs(np.repeat(label, 2), edges.reshape(-1), len(v))
    loop_of, vertex_of = pairs[:, 0], pairs[:, 1]
    size = np.bincount(loop_of, minlength=n_loops)
    apex = np.stack([np.bincount(loop_of, weights=v[vertex_of, i], minlength=n_loops) for i in range(3)], axis=1)
    apex /= np.maximum(size, 1)[:, None]
    return v, f, edges, label, n_loops, apex, loop_of, vertex_of


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_rim_fans_given_once_are_what_each_reading_computes(seed):
    v, f, edges, label, n_loops, apex, _, _ = _holed(seed)
    if not n_loops:
        return
    fans = hole_bounds.rim_fans(v, f, edges, label, n_loops, apex)
    level = hole_bounds.level_rings(v, f, edges, label, n_loops, apex, fans=fans)
    assert level.tobytes() == hole_bounds.level_rings(v, f, edges, label, n_loops, apex).tobytes()
    doubt, height = hole_bounds.bend_doubt_volumes(v, f, edges, label, n_loops, apex, fans=fans)
    alone_doubt, alone_height = hole_bounds.bend_doubt_volumes(v, f, edges, label, n_loops, apex)
    assert doubt.tobytes() == alone_doubt.tobytes() and height.tobytes() == alone_height.tobytes()


def _reference_balls(points, group, n_groups, iterations=400):
    """``enclosing_balls`` as it was: each step's difference formed twice."""
    from inertia_tool.mesh.rims import _small_ball_centres

    p = np.asarray(points, dtype=np.float64)
    g = np.asarray(group, dtype=np.int64)
    order = np.argsort(g, kind="stable")
    p, g = p[order], g[order]
    starts = np.searchsorted(g, np.arange(n_groups))
    size = np.diff(np.r_[starts, len(p)])
    centre = 0.5 * (np.minimum.reduceat(p, starts, axis=0) + np.maximum.reduceat(p, starts, axis=0))
    small = size <= 3
    if small.any():
        centre[small] = _small_ball_centres(p, starts[small], size[small])
    big = np.flatnonzero(~small)
    if len(big):
        pick = np.repeat(starts[big], size[big]) + (np.arange(int(size[big].sum()))
                                                    - np.repeat(np.cumsum(size[big]) - size[big], size[big]))
        q, local = p[pick], np.repeat(np.arange(len(big)), size[big])
        local_starts = np.r_[0, np.cumsum(size[big])[:-1]]
        c = centre[big]
        index = np.arange(len(q))
        for k in range(1, iterations + 1):
            d = np.einsum("ij,ij->i", q - c[local], q - c[local])
            top = np.maximum.reduceat(d, local_starts)
            far = np.minimum.reduceat(np.where(d >= top[local], index, len(q)), local_starts)
            c = c + (q[far] - c) / (k + 1)
        centre[big] = c
    radius = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", p - centre[g], p - centre[g]), starts))
    return centre, radius


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(5, 120))
def test_enclosing_balls_are_the_reading_that_formed_each_difference_twice(seed, iterations):
    v, _, _, _, n_loops, _, loop_of, vertex_of = _holed(seed)
    if not n_loops:
        return
    centre, radius = enclosing_balls(v[vertex_of], loop_of, n_loops, iterations=iterations)
    want_centre, want_radius = _reference_balls(v[vertex_of], loop_of, n_loops, iterations)
    assert centre.tobytes() == want_centre.tobytes() and radius.tobytes() == want_radius.tobytes()


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 2000), st.sampled_from([1, 3, 50, 10**6, 2**40, 2**62]))
def test_stable_key_order_is_the_stable_argsort(seed, k, top):
    """Keys with many ties (a few distinct values) to keys so large that the packed form would overflow (the
    stable argsort then): the sorted keys and the order are ``numpy.argsort(kind="stable")``'s."""
    from inertia_tool.mesh.edges import stable_key_order

    rng = np.random.default_rng(seed)
    key = rng.integers(0, top, k, dtype=np.int64)
    order = np.argsort(key, kind="stable")
    got_key, got_order = stable_key_order(key)
    assert got_order.dtype == order.dtype and got_order.tobytes() == order.tobytes()
    assert got_key.dtype == key.dtype and got_key.tobytes() == key[order].tobytes()


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 3000))
def test_swept_faces_are_the_reading_with_numpys_cross(seed, m):
    """``precision._swept_faces`` forms ``ab × ac`` product by product: the total and the box of the reading
    that called ``numpy.cross``, on faces of any size and place, some with no corner moved."""
    import math

    from inertia_tool.mesh.precision import _swept_faces

    rng = np.random.default_rng(seed)
    n = 3 * m
    v = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-6, 3, size=(n, 1)) + rng.uniform(-1e3, 1e3, size=3)
    f = rng.integers(0, n, size=(m, 3))
    reach = np.where(rng.random(n) < 0.3, 0.0, rng.uniform(0, 1e-3, n))
    total, box = _swept_faces(v, f, reach)
    d = reach[f].max(axis=1)
    hit = d > 0
    tri = v[f[hit]]
    ab, ac, bc = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], tri[:, 2] - tri[:, 1]
    area = 0.5 * np.linalg.norm(np.cross(ab, ac), axis=1)
    perimeter = np.linalg.norm(ab, axis=1) + np.linalg.norm(ac, axis=1) + np.linalg.norm(bc, axis=1)
    dh = d[hit]
    want = 3.0 * float(np.sum(2.0 * dh * area + 0.5 * math.pi * dh * dh * perimeter + 4.0 / 3.0 * math.pi * dh ** 3))
    assert total.hex() == want.hex() if hit.any() else total == 0.0
    if hit.any():
        corners = tri.reshape(-1, 3)
        assert box is not None
        assert box[0].tobytes() == corners.min(axis=0).tobytes() and box[1].tobytes() == corners.max(axis=0).tobytes()
    else:
        assert box is None


def _reference_rim_edge_slots(f, n, edges):
    """Every face edge slot keyed (``edge_keys``) and looked up among the rim's sorted keys: the reading before."""
    from inertia_tool.mesh.edges import edge_keys

    nv = np.int64(max(n, 1))
    key, _ = edge_keys(f, n)
    rim_key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * nv + np.maximum(edges[:, 0], edges[:, 1])
    order = np.argsort(rim_key, kind="stable")
    sorted_rim = rim_key[order]
    pos = np.searchsorted(sorted_rim, key)
    hit = (pos < len(sorted_rim)) & (sorted_rim[np.minimum(pos, len(sorted_rim) - 1)] == key)
    slot = np.flatnonzero(hit)
    return slot, order[pos[slot]]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_rim_edge_slots_are_those_of_every_face_edge(seed, soup):
    """The slots of the face edges that are rim edges, and their rim edge, from the slots with both ends on a rim:
    those a lookup of every slot finds, on holed surfaces and on soups of faces on a small vertex pool (edges of
    three or more faces, repeated rim edges)."""
    if soup:
        rng = np.random.default_rng(seed)
        n = int(rng.integers(4, 40))
        f = rng.integers(0, n, size=(int(rng.integers(1, 200)), 3))
        edges = rng.integers(0, n, size=(int(rng.integers(1, 60)), 2))
    else:
        v, f, edges, _, _, _, _, _ = _holed(seed)
        n = len(v)
    slot, rim_edge = hole_bounds._rim_edge_slots(f, n, edges)
    want_slot, want_edge = _reference_rim_edge_slots(f, n, edges)
    assert slot.tobytes() == want_slot.tobytes() and rim_edge.tobytes() == want_edge.tobytes()
