"""``hole_bounds.rim_evidence`` after its speed-up (issue 25: the scattered-holes sphere's 0.92 s and 249 MB, the
one-hole sphere's 0.17 s): the same answer, bit for bit, as the implementation it replaced.

The reference below is that implementation, kept verbatim: every face edge sorted to find each rim edge's ring
face, the (vertex, loop) rows made unique by ``numpy.unique(axis=0)``, the corners of every face at a rim vertex
measured at once.  The new one sorts only the face edges with both ends on a rim, makes the rows unique by one
int64 key and measures the corners a block at a time.  Compared on hypothesis-generated damaged surfaces: spheres
and boxes with faces taken out (one hole, scattered holes meeting at corners, a pinch where two rims share a
vertex), flat faces and curved ones, with the block size cut to a few rows so that the blocks are exercised.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import hole_bounds
from inertia_tool.mesh.hole_bounds import FLAT_RIM_RTOL, FLAT_VERTEX_COSINE, bare_vertices, rim_evidence
from inertia_tool.mesh.rims import boundary_edges, boundary_loops, enclosing_balls


def reference_rim_evidence(vertices, faces, edges, label, n_loops, radius, *, flat_rtol=FLAT_RIM_RTOL,
                           flat_cosine=FLAT_VERTEX_COSINE, bare=None):
    """``rim_evidence`` as it was before issue 25's speed-up (main at 4fb8025), returned as (flat, bare)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    flat = np.zeros(n_loops, dtype=bool)
    if not n_loops or not len(edges) or not len(f):
        return flat, np.zeros(n_loops, dtype=np.int64)
    nv = np.int64(max(n, 1))
    directed = f.reshape(-1) * nv + f[:, [1, 2, 0]].reshape(-1)
    order = np.argsort(directed, kind="stable")
    query = edges[:, 0].astype(np.int64) * nv + edges[:, 1]
    pos = np.minimum(np.searchsorted(directed[order], query), len(order) - 1)
    found = directed[order[pos]] == query
    face = order[pos] // 3
    a, b, c = (v[f[face, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1)
    score = np.where(found & (area > 0), area, -1.0)
    top = np.full(n_loops, -1.0)
    np.maximum.at(top, label, score)
    pick = np.flatnonzero((score >= top[label]) & (score > 0))
    best = np.full(n_loops, -1, dtype=np.int64)
    best[label[pick]] = pick
    has = best >= 0
    if has.any():
        unit = np.zeros((n_loops, 3))
        unit[has] = normal[best[has]] / area[best[has], None]
        origin = np.zeros((n_loops, 3))
        origin[has] = a[best[has]]
        rim_pairs = np.unique(np.stack([np.r_[edges[:, 0], edges[:, 1]], np.r_[label, label]], axis=1), axis=0)
        loop_at = np.full(n, -1, dtype=np.int64)
        loop_at[rim_pairs[:, 0]] = rim_pairs[:, 1]
        on_two = np.bincount(rim_pairs[:, 0], minlength=n) > 1
        fi, ci = np.nonzero(loop_at[f] >= 0)
        loop = loop_at[f[fi, ci]]
        dist = np.abs(np.einsum("ijk,ik->ij", v[f[fi]] - origin[loop][:, None, :], unit[loop])).max(axis=1)
        worst = np.zeros(n_loops)
        np.maximum.at(worst, loop, dist)
        pinched = np.zeros(n_loops, dtype=bool)
        pinched[rim_pairs[on_two[rim_pairs[:, 0]], 1]] = True
        scale = float(np.max(np.abs(v)))
        margin = 16.0 * np.finfo(np.float64).eps * max(scale, 1e-300)
        flat = has & ~pinched & (worst <= flat_rtol * radius + margin)
    if bare is None:
        bare = bare_vertices(v, f, edges, flat_cosine=flat_cosine)
    rim = np.unique(np.stack([edges[:, 0], label], axis=1), axis=0)
    count = np.bincount(rim[:, 1], weights=bare[rim[:, 0]], minlength=n_loops).astype(np.int64)
    return flat, count


def _base(kind, detail):
    if kind == "sphere":
        mesh = trimesh.creation.icosphere(detail)
    elif kind == "box":            # flat faces subdivided: vertices inside them, holes in the middle of a face
        mesh = trimesh.creation.box(extents=(2.0, 3.0, 1.5)).subdivide()
        for _ in range(detail - 1):
            mesh = mesh.subdivide()
    else:                          # a cylinder: flat caps meeting a curved side at two creases
        mesh = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=8 * detail)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def _inputs(v, f):
    """What ``patched_estimate`` gives ``rim_evidence``: the boundary, its loops, the balls' radii, the bare
    vertices."""
    edges = boundary_edges(f, len(v))
    label, n_loops = boundary_loops(edges, len(v), f, v)
    pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
    _, radius = enclosing_balls(v[pairs[:, 1]], pairs[:, 0], n_loops)
    return edges, label, n_loops, radius, bare_vertices(v, f, edges)


@st.composite
def damaged_surfaces(draw):
    kind = draw(st.sampled_from(["sphere", "box", "cylinder"]))
    v, f = _base(kind, draw(st.integers(1, 2)))
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    how = draw(st.sampled_from(["one", "scattered", "pinch"]))
    keep = np.ones(len(f), dtype=bool)
    if how == "one":               # a connected patch round a random face
        centroid = v[f].mean(axis=1)
        seed = centroid[rng.integers(len(f))]
        near = np.argsort(np.linalg.norm(centroid - seed, axis=1), kind="stable")
        keep[near[: draw(st.integers(1, max(1, len(f) // 4)))]] = False
    elif how == "scattered":       # faces taken one by one: holes meeting at corners
        keep &= rng.random(len(f)) >= draw(st.sampled_from([0.05, 0.2, 0.4]))
    else:                          # two faces sharing only a vertex: two rims through it
        vertex = int(rng.integers(len(v)))
        at = np.flatnonzero((f == vertex).any(axis=1))
        keep[at[:1]] = False
        keep[at[len(at) // 2: len(at) // 2 + 1]] = False
    if draw(st.booleans()):        # faces in another order: the lowest ring face is another one
        f = f[rng.permutation(len(f))]
        keep = keep[: len(f)]
    f = f[keep]
    if draw(st.booleans()):
        v = v * 10.0 ** draw(st.integers(-3, 3)) + draw(st.sampled_from([0.0, 1e3]))
    return v, f


@settings(max_examples=15, deadline=None)
@given(damaged_surfaces(), st.sampled_from([3, 64, 1 << 17]))
def test_rim_evidence_is_the_same_bit_for_bit(case, rows):
    v, f = case
    edges, label, n_loops, radius, bare = _inputs(v, f)
    want_flat, want_bare = reference_rim_evidence(v, f, edges, label, n_loops, radius, bare=bare)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(hole_bounds, "_RIM_ROWS", rows)
        got = rim_evidence(v, f, edges, label, n_loops, radius, bare=bare)
        unbare = rim_evidence(v, f, edges, label, n_loops, radius)
    assert got.flat_all_round.dtype == want_flat.dtype and got.bare.dtype == want_bare.dtype
    np.testing.assert_array_equal(got.flat_all_round, want_flat)
    np.testing.assert_array_equal(got.bare, want_bare)
    np.testing.assert_array_equal(unbare.bare, want_bare)


def test_a_flat_island_and_a_curved_hole():
    """Named cases with a known answer: a hole inside a flat face of a subdivided box is flat all round; a hole
    in a sphere is not; and both agree with the reference."""
    v, f = _base("box", 3)
    centroid = v[f].mean(axis=1)
    top = int(np.argmin(np.linalg.norm(centroid - [0.0, 0.0, 0.75], axis=1)))     # inside the top face
    f_box = np.delete(f, top, axis=0)
    v_s, f_s = _base("sphere", 2)
    f_s = f_s[1:]
    for v_, f_, flat in ((v, f_box, True), (v_s, f_s, False)):
        edges, label, n_loops, radius, bare = _inputs(v_, f_)
        got = rim_evidence(v_, f_, edges, label, n_loops, radius, bare=bare)
        want_flat, want_bare = reference_rim_evidence(v_, f_, edges, label, n_loops, radius, bare=bare)
        assert n_loops == 1 and bool(got.flat_all_round[0]) is flat
        np.testing.assert_array_equal(got.flat_all_round, want_flat)
        np.testing.assert_array_equal(got.bare, want_bare)


def test_no_ring_face_found():
    """Rim edges that no face holds in their direction (a caller's boundary of other faces): nothing found,
    nothing flat, as before."""
    v, f = _base("sphere", 1)
    edges = np.array([[f[0, 1], f[0, 0]], [f[0, 2], f[0, 1]], [f[0, 0], f[0, 2]]])     # reversed: no face
    label = np.zeros(3, dtype=np.int64)
    got = rim_evidence(v, f, edges, label, 1, np.ones(1), bare=np.zeros(len(v), dtype=bool))
    want = reference_rim_evidence(v, f, edges, label, 1, np.ones(1), bare=np.zeros(len(v), dtype=bool))
    np.testing.assert_array_equal(got.flat_all_round, want[0])
    np.testing.assert_array_equal(got.bare, want[1])


@settings(max_examples=10, deadline=None)
@given(damaged_surfaces())
def test_each_rim_edge_finds_its_lowest_ring_face(case):
    """The ring face of a rim edge a→b is the lowest-numbered face holding a→b (brute force: a dict of every
    face edge, first face kept), found from the face edges on the rims alone."""
    v, f = case
    edges = boundary_edges(f, len(v))
    first = {}
    for i, (p, q, r) in enumerate(f.tolist()):
        for key in ((p, q), (q, r), (r, p)):
            first.setdefault(key, i)
    face, found = hole_bounds._ring_face_of_edges(f, len(v), edges)
    assert found.all()
    assert face.tolist() == [first[(a, b)] for a, b in edges.tolist()]
