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
