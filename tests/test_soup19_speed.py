"""The repair's shortcuts of issue 25 item 3 (soup19) give what the code they replace gives, bit for bit.

- ``rims.enclosing_balls`` runs Bădoiu–Clarkson's steps on blocks of groups of alike sizes (padded with copies
  of a group's first point): the centres and radii of the reading with one (k, 3) array and ``reduceat`` per step
  (``test_soup17_speed._reference_balls``), on groups of 1 to 300 points with repeated points (ties for the
  farthest) and points on a grid (many equal distances);
- ``seal.seal_seams`` searches each boundary edge once per gap for the points near it (``seal._Pairs``, kept
  from pass to pass: the on-edge passes' with gap 0, the split passes' with the seal's gap), measures only the
  candidates' edges and keys only the face edges whose two ends are ends of an edge to split (and, counting the
  loose faces, of a boundary edge): the reference below is the seal before (every pass searched every edge of
  the frontier's boundary, every edge was measured and every face edge of the frontier keyed).

Meshes: icospheres and tori off the origin with faces removed (scattered holes), faces split at an edge's
midpoint with the neighbour left whole (T-junctions, the midpoint on its edge to round-off), some split points
moved off the edge within the gap, loose triangles, and a crack (a patch cut free, its border corners moved
within the gap); also the T-split grids of ``test_mesh_seal_split`` (several points on one edge).  No timings
here: they are in ``benchmarks/bench_repair.py`` and ``docs/performance.md``.
"""

from __future__ import annotations

import numpy as np
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import seal
from inertia_tool.mesh.edges import edge_keys
from inertia_tool.mesh.rims import enclosing_balls
from test_mesh_seal_split import t_split_grid
from test_soup17_speed import _reference_balls


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.sampled_from([4, 9, 40, 300]), st.integers(1, 50),
       st.booleans(), st.integers(-8, 8))
def test_enclosing_balls_by_size_class_are_the_reading_with_one_array(seed, n_groups, largest, iterations, grid,
                                                                      scale_exp):
    rng = np.random.default_rng(seed)
    size = rng.integers(1, largest + 1, n_groups)               # (every group holds a point: as the callers')
    group = rng.permutation(np.repeat(np.arange(n_groups), size))
    if grid:          # points on a small grid: many ties for the farthest point
        points = rng.integers(-2, 3, size=(len(group), 3)).astype(float)
    else:
        points = rng.normal(size=(len(group), 3))
        repeat = rng.random(len(group)) < 0.2                 # repeated points
        if repeat.any() and len(group):
            points[repeat] = points[rng.integers(len(group), size=int(repeat.sum()))]
    points = points * 10.0 ** scale_exp + rng.uniform(-1e3, 1e3, size=3) * 10.0 ** scale_exp
    centre, radius = enclosing_balls(points, group, n_groups, iterations=iterations)
    want_centre, want_radius = _reference_balls(points, group, n_groups, iterations)
    assert centre.tobytes() == want_centre.tobytes() and radius.tobytes() == want_radius.tobytes()


def _reference_split(v, f, slack, gap, chain, region, on_edge_only):
    """``seal._split`` before soup19, verbatim but for its name: every chain edge searched and measured."""
    if not len(chain.key):
        return f, slack, 0, chain
    edges = seal._chain_edges(chain, len(v))
    edges = seal._unique_rows(edges, len(v))
    a, b = v[edges[:, 0]], v[edges[:, 1]]
    ab = b - a
    length = np.linalg.norm(ab, axis=1)
    e, m = seal._edge_point_candidates(v, edges, 0.0 if on_edge_only else gap)
    if not len(e):
        return f, slack, 0, chain
    t = np.einsum("ij,ij->i", v[m] - a[e], ab[e]) / np.maximum(length[e] ** 2, np.finfo(float).tiny)
    foot = a[e] + t[:, None] * ab[e]
    dist = np.linalg.norm(v[m] - foot, axis=1)
    to_end = np.minimum(np.linalg.norm(v[m] - a[e], axis=1), np.linalg.norm(v[m] - b[e], axis=1))
    on_edge = dist <= seal.ON_EDGE_RTOL * to_end
    ok = (dist <= gap) & (t > 0) & (t < 1) & (to_end > 0) & (on_edge if on_edge_only else (to_end > gap) | on_edge)
    e, m, t, dist = e[ok], m[ok], t[ok], dist[ok]
    if not len(e):
        return f, slack, 0, chain
    nearest = np.lexsort((dist, m))
    first = nearest[np.r_[True, m[nearest][1:] != m[nearest][:-1]]]
    e, m, t, dist = e[first], m[first], t[first], dist[first]
    undirected, forward = edge_keys(f, len(v))
    key = 2 * undirected + forward
    start, end = edges[e, 0].astype(np.int64), edges[e, 1].astype(np.int64)
    want = 2 * edge_keys(np.stack([start, end, end], axis=1), len(v))[0][0::3] + (start > end)
    targets = np.unique(want)
    at = np.minimum(np.searchsorted(targets, key), len(targets) - 1)
    hit = np.flatnonzero(targets[at] == key)
    order = hit[np.argsort(key[hit], kind="stable")]
    pos = np.searchsorted(key[order], want)
    found = (pos < len(order)) & (key[order][np.minimum(pos, len(order) - 1)] == want)
    e, m, t, dist, pos = e[found], m[found], t[found], dist[found], pos[found]
    slot = order[pos]
    face, corner = slot // 3, slot % 3
    own = m != f[face, (corner + 2) % 3]
    face, corner, m, t, dist, slot = face[own], corner[own], m[own], t[own], dist[own], slot[own]
    first_slot = np.full(len(f), -1, dtype=np.int64)
    np.maximum.at(first_slot, face, slot)
    sel = slot == first_slot[face]
    face, corner, m, t, dist = face[sel], corner[sel], m[sel], t[sel], dist[sel]
    if not len(face):
        return f, slack, 0, chain
    _, unique_m = np.unique(face.astype(np.int64) * np.int64(max(len(v), 1)) + m, return_index=True)
    face, corner, m, t, dist = face[unique_m], corner[unique_m], m[unique_m], t[unique_m], dist[unique_m]
    by = np.lexsort((t, face))
    face, corner, m, dist = face[by], corner[by], m[by], dist[by]
    split_faces = np.flatnonzero(np.bincount(face, minlength=len(f)))
    starts = np.searchsorted(face, split_faces)
    count = np.diff(np.r_[starts, len(face)])
    j = corner[starts]
    p, q, c = f[split_faces, j], f[split_faces, (j + 1) % 3], f[split_faces, (j + 2) % 3]
    group = np.repeat(np.arange(len(split_faces)), count)
    rows = len(face) + len(split_faces)
    first_row = starts + np.arange(len(split_faces))
    fan = np.empty((rows, 3), dtype=f.dtype)
    fan[first_row, 0] = p
    fan[np.arange(len(face)) + group + 1, 0] = m
    fan[np.arange(len(face)) + group, 1] = m
    fan[first_row + count, 1] = q
    fan[:, 2] = np.repeat(c, count + 1)
    fan_slack = np.repeat(np.maximum(slack[split_faces], np.maximum.reduceat(dist, starts)), count + 1)
    keep_face = np.ones(len(f), dtype=bool)
    keep_face[split_faces] = False
    chain = seal._chain_update(chain, f[split_faces], fan, len(v), region)
    return np.vstack([f[keep_face], fan]), np.concatenate([slack[keep_face], fan_slack]), int(len(m)), chain


def _reference_loose_faces(faces, n, region):
    """``seal._loose_faces`` before soup19: every face edge of the frontier keyed."""
    if not len(faces):
        return 0
    sk, order = seal.stable_key_order(edge_keys(faces, n)[0])
    nn = np.int64(max(n, 1))
    single = region[sk // nn] | region[sk % nn]
    same = sk[1:] == sk[:-1]
    single[1:] &= ~same
    single[:-1] &= ~same
    alone = np.empty(len(sk), dtype=bool)
    alone[order] = single
    return int(np.count_nonzero(alone.reshape(-1, 3).all(axis=1)))


def _reference_seal(v, f, gap):
    """``seal.seal_seams`` before soup19 (its steps and bookkeeping, with the reference split)."""
    n = len(v)
    from inertia_tool.mesh.rims import boundary_edges

    edges = boundary_edges(f, n)
    if not len(edges):
        return seal.Seal(f, np.zeros(len(f)), 0.0, 0, 0, edges, 0, 0, len(f))
    region = np.zeros(n, dtype=bool)
    region[edges.reshape(-1)] = True
    at_front = region[f].any(axis=1)
    rest, front = f[~at_front], f[at_front]
    slack = np.zeros(len(front))
    vertex_slack = np.zeros(n)
    dropped, welded, split = 0.0, 0, 0
    chain = seal._chain_of_edges(edges, n)
    for _ in range(3 * seal.MAX_SEAL_ROUNDS):
        front, slack, more, chain = _reference_split(v, front, slack, gap, chain, region, True)
        split += more
        if not more:
            break
    for _ in range(seal.MAX_SEAL_ROUNDS):
        front, slack, lost, merged, chain = seal._weld(v, front, slack, vertex_slack, gap, chain, region)
        inserted = 0
        for _ in range(3):
            front, slack, more, chain = _reference_split(v, front, slack, gap, chain, region, False)
            inserted += more
            if not more:
                break
        dropped += lost
        welded += merged
        split += inserted
        if not (merged or inserted):
            break
    slack = np.maximum(slack, vertex_slack[front].max(axis=1)) if len(front) else slack
    duplicates = 0
    if welded or split:
        kept, duplicates = seal.drop_duplicate_faces(front)
        if duplicates:
            front = kept
    out = np.vstack([rest, front]) if len(rest) else front
    if duplicates:
        all_slack = np.full(len(out), float(slack.max(initial=0.0)))
        boundary = seal._frontier_boundary(front, n, region)
    else:
        all_slack = np.concatenate([np.zeros(len(rest)), slack])
        boundary = seal._chain_edges(chain, n) if (welded or split) else edges
    return seal.Seal(out, all_slack, dropped, welded, split, boundary, _reference_loose_faces(front, n, region),
                     duplicates, len(rest))


def _damaged(seed):
    """A closed icosphere or torus off the origin with scattered holes, T-junctions (some points moved off their
    edge within the gap) and sometimes a crack; the seal's gap."""
    rng = np.random.default_rng([seed, 19])
    if rng.random() < 0.5:
        s = trimesh.creation.icosphere(int(rng.integers(2, 4)), radius=float(rng.uniform(0.5, 2.0)))
    else:
        s = trimesh.creation.torus(1.0, float(rng.uniform(0.2, 0.6)), major_sections=int(rng.integers(12, 33)),
                                   minor_sections=int(rng.integers(6, 17)))
    v = np.asarray(s.vertices) + rng.uniform(-5, 5, size=3)
    f = np.asarray(s.faces, dtype=np.int64)
    gap = 1e-4 * float(np.linalg.norm(np.ptp(v, axis=0)))
    f = f[rng.random(len(f)) >= rng.uniform(0.0, 0.1)]               # scattered holes (none at times)
    pick = np.flatnonzero(rng.random(len(f)) < rng.uniform(0.0, 0.3))   # T-junctions at edge midpoints
    if len(pick):
        a, b, c = f[pick, 0], f[pick, 1], f[pick, 2]
        mid = 0.5 * (v[a] + v[b])
        off = rng.random(len(pick)) < rng.uniform(0.0, 0.5)             # some moved off the edge, within the gap
        step = rng.normal(size=(len(pick), 3))
        mid[off] += (rng.uniform(0.0, 0.9, size=(int(off.sum()), 1)) * gap * step[off]
                     / np.linalg.norm(step[off], axis=1, keepdims=True))
        ids = len(v) + np.arange(len(pick))
        v = np.vstack([v, mid])
        keep = np.ones(len(f), dtype=bool)
        keep[pick] = False
        f = np.vstack([f[keep], np.c_[a, ids, c], np.c_[ids, b, c]])
    if rng.random() < 0.4:                      # a crack: a patch cut free, its border moved within the gap
        cut = np.flatnonzero(np.linalg.norm(v[f].mean(axis=1) - v[f[rng.integers(len(f)), 0]], axis=1)
                             < rng.uniform(0.1, 0.6))
        inside = np.zeros(len(f), dtype=bool)
        inside[cut] = True
        border = np.intersect1d(np.unique(f[cut]), np.unique(f[~inside]))
        remap = np.arange(len(v))
        remap[border] = np.arange(len(v), len(v) + len(border))
        f = f.copy()
        f[cut] = remap[f[cut]]
        step = rng.normal(size=(len(border), 3))
        moved = v[border] + rng.uniform(0.0, 0.4) * gap * step / np.linalg.norm(step, axis=1, keepdims=True)
        v = np.vstack([v, moved])
    if rng.random() < 0.4:                      # loose triangles (a soup's), some touching the rims by a corner
        some = f[rng.integers(len(f), size=int(rng.integers(1, 20)))]
        loose = len(v) + np.arange(3 * len(some)).reshape(-1, 3)
        v = np.vstack([v, v[some].reshape(-1, 3) + rng.normal(size=(3 * len(some), 3)) * 0.01])
        touch = rng.random(len(some)) < 0.5
        loose[touch, 0] = some[touch, 0]
        f = np.vstack([f, loose])
    return v, f, gap


def _same(got, want):
    for name in ("faces", "slack", "boundary"):
        g, w = np.asarray(getattr(got, name)), np.asarray(getattr(want, name))
        assert g.dtype == w.dtype and g.shape == w.shape and g.tobytes() == w.tobytes(), name
    for name in ("dropped_doubt", "welded", "split", "loose_faces", "duplicates", "front_start"):
        assert getattr(got, name) == getattr(want, name), name


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_seal_searching_each_edge_once_is_the_seal_that_searched_every_pass(seed):
    v, f, gap = _damaged(seed)
    _same(seal.seal_seams(v, f, gap), _reference_seal(v, f, gap))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(2, 6), splits=st.integers(1, 20),
       per_edge=st.lists(st.integers(1, 4), min_size=1, max_size=3), jitter=st.sampled_from([0.0, 1e-6, 1e-3]))
def test_the_seal_searching_each_edge_once_on_t_split_grids(seed, n, splits, per_edge, jitter):
    v, f = t_split_grid(np.random.default_rng(seed), n, splits, per_edge, jitter)
    _same(seal.seal_seams(v, f, 1e-2), _reference_seal(v, f, 1e-2))


def test_the_damaged_meshes_exercise_the_kept_pairs():
    """The generator makes seals of several passes (the pairs carried over) that split and weld: else the
    tests above would compare nothing but the first search."""
    passes = splits = welds = loose = 0
    original = seal._candidates
    calls = []

    def counting(v, edges, gap, known):
        calls.append(known is not None and known.gap == gap)          # pairs carried over, not searched again
        return original(v, edges, gap, known)

    seal._candidates = counting
    try:
        for seed in range(12):
            v, f, gap = _damaged(seed)
            got = seal.seal_seams(v, f, gap)
            splits += got.split > 0
            welds += got.welded > 0
            loose += got.loose_faces > 0
    finally:
        seal._candidates = original
    passes = sum(calls)
    assert passes >= 12 and splits >= 6 and welds >= 2 and loose >= 2, (passes, splits, welds, loose)
