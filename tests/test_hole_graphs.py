"""Holes filled as a graph over the plane most face-on to the faces round them (``mesh/hole_graphs.py``,
assumption ``graph``; issue 21 item 3, fill13).

Closed forms for the pieces (the face-on direction of a box corner, simple and crossing polygons), a property
test of the triangulation on random non-convex polygons, and the bound on generated solids nobody tuned on:
tori, subdivided boxes, cylinders, capsules and wavy spheres, turned and moved at random, less a connected patch
of 3-20 % of their faces; the truth is the undamaged solid.  Every answer that names ``graph`` holds its bound or
the faces removed are shown to break an assumption it names (the judge of ``test_holes7_bend.py``).
"""

import numpy as np
import pytest
import trimesh
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import adversary_solids as S
from test_hole_bounds import _holds
from test_holes7_bend import _grow, _named_assumption_fails
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh.hole_graphs import (_ear_clip, _refined, _segments_cross, _tiling, face_on_direction)
from inertia_tool.mesh.holes import patched_estimate
from inertia_tool.mesh.polygons import ear_clip_2d
from inertia_tool.tolerances import ESTIMATE_MAX_MASS_RTOL


def test_face_on_direction_of_a_box_corner_is_its_diagonal():
    """Three faces of a box corner, normals along the axes: the direction most face-on to all three is the
    diagonal (1, 1, 1)/√3, at cosine 1/√3 (54.7°) to each."""
    d, least = face_on_direction(np.eye(3))
    assert d == pytest.approx(np.ones(3) / np.sqrt(3), abs=1e-9)
    assert least == pytest.approx(1 / np.sqrt(3), abs=1e-9)
    # two opposite faces: nothing faces both (cosine 0 at best, past any usable slope)
    _, least = face_on_direction(np.array([[0.0, 0, 1], [0.0, 0, -1]]))
    assert least <= 1e-12


def test_simple_and_crossing_polygons():
    square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    assert not _segments_cross(square)
    assert _segments_cross(square[[0, 2, 1, 3]])                         # a bow tie
    assert _segments_cross(np.array([[0.0, 0], [1, 0], [1, 1], [0, 0]]))   # a corner met twice
    # a polygon touching itself at a corner of one edge (a pinch in projection)
    assert _segments_cross(np.array([[0.0, 0], [2, 0], [2, 2], [1, 0], [0, 2]]))


def test_a_clockwise_dart_is_refused_not_cut_both_ways():
    """A dart (arrowhead) whose corners run clockwise has one corner turning left, its notch: the triangle there
    holds no other corner, so it was clipped as an ear, and the last three corners were kept though they turn
    right, a cut of both orientations (hypo16; the generated test below, hypothesis seed 3689).  Refused now;
    the same dart counter-clockwise is cut at its notch (0.5, 1) into the two left-turning triangles with
    corners (0, 0), (2, 1), (0.5, 1) and (2, 1), (0, 2), (0.5, 1), each of area ¾ (½·|cross|), the shoelace area
    ½·(0 + 4 − 1 + 0) = 1.5."""
    ccw = np.array([[0.0, 0.0], [2.0, 1.0], [0.0, 2.0], [0.5, 1.0]])
    assert _ear_clip(ccw[::-1]) is None
    assert ear_clip_2d(ccw[::-1, 0], ccw[::-1, 1]) is None
    tri = _ear_clip(ccw)
    p = ccw[tri]
    signed = 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                    - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))
    assert (signed > 0).all() and signed.tolist() == pytest.approx([0.75, 0.75], rel=1e-15)


@settings(max_examples=60, deadline=None)
@example(seed=252, corners=4, depth=0.9375)   # hypo16: clockwise (the origin outside it), cut both ways before
@given(seed=st.integers(0, 2 ** 31 - 1), corners=st.integers(4, 80), depth=st.floats(0.0, 0.95))
def test_ear_clipped_and_refined_fill_tiles_any_star_polygon_once(seed, corners, depth):
    """Random star polygons (radii drawn down to 5 % of the largest: deeply non-convex), corners by angle about
    the origin: counter-clockwise where the origin is inside, clockwise where all corners lie within a half-turn
    and the origin falls outside.  A clockwise one is refused by ear clipping (None, never triangles of both
    orientations; 45 of 20,000 draws were before hypo16) and tiled once reversed; ear clipping and two splits
    tile every counter-clockwise one once, rim edges kept whole, areas summing to the shoelace area."""
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, corners))
    if len(np.unique(angle)) != corners:
        return
    r = 1.0 - depth * rng.random(corners)
    poly = np.column_stack([r * np.cos(angle), r * np.sin(angle)])
    if _segments_cross(poly):
        return
    area = 0.5 * float(np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1]))
    if area < 0:
        assert _ear_clip(poly) is None
        poly, area = poly[::-1].copy(), -area
    clipped = _ear_clip(poly)
    assert clipped is not None
    tri, pts = _refined(clipped, poly, corners, 2)
    assert _tiling(tri, pts, corners, area)
    # the check itself rejects a triangulation missing a triangle
    assert not _tiling(tri[1:], pts, corners, area)


# ------------------------------------------------------------------------------- the generator (adversarial)

KINDS = ("torus", "box", "cylinder", "capsule", "bumpy")


def _solid(kind, rng):
    """A closed outward surface of the kind drawn, proportions and tessellation from ``rng``."""
    if kind == "torus":
        s = trimesh.creation.torus(1.0, float(rng.uniform(0.2, 0.6)), major_sections=int(rng.integers(16, 49)),
                                   minor_sections=int(rng.integers(8, 25)))
    elif kind == "box":
        s = trimesh.creation.box(extents=rng.uniform(0.3, 3.0, size=3)).subdivide().subdivide().subdivide()
    elif kind == "cylinder":
        s = trimesh.creation.cylinder(radius=1.0, height=float(rng.uniform(0.5, 3.0)),
                                      sections=int(rng.integers(16, 64))).subdivide().subdivide()
    elif kind == "capsule":
        s = trimesh.creation.capsule(height=float(rng.uniform(0.5, 3)), radius=0.5, count=[24, 24])
    else:                                                  # a sphere with radial waves: curved, not convex
        v, f = S.icosphere(1.0, 3)
        lobes, amp = int(rng.integers(2, 6)), float(rng.uniform(0.02, 0.2))
        angle = np.arctan2(v[:, 1], v[:, 0])
        return v * (1.0 + amp * np.cos(lobes * angle) * (1 - v[:, 2] ** 2))[:, None], f
    return np.asarray(s.vertices, dtype=np.float64), np.asarray(s.faces)


def _case(kind, seed):
    rng = np.random.default_rng([seed, 5])
    v, f = _solid(kind, rng)
    gone = _grow(f, int(rng.integers(len(f))), max(1, int(rng.uniform(0.03, 0.2) * len(f))))
    return v, f, gone


@settings(max_examples=25, deadline=None)
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2 ** 31 - 1),
       quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_every_answered_large_hole_is_inside_its_bound_or_names_the_assumption_that_fails(kind, seed, quat):
    v, f, gone = _case(kind, seed)
    v = v @ Rotation.from_quat(quat).as_matrix().T + np.random.default_rng(seed).uniform(-3, 3, size=3)
    truth = volume_moments(v, f)
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    if est.unbounded or not est.uncertainty.mass <= ESTIMATE_MAX_MASS_RTOL or not est.volume > 0:
        return                                                   # refused by repair=True
    if _holds(est, truth):
        return
    failed = _named_assumption_fails(v, f, gone, est)
    assert failed, (f"{kind} seed {seed}: {len(gone)} faces gone, stated ±{est.uncertainty.mass:.3g}, off by "
                    f"{abs(est.volume - truth.volume) / truth.volume:.3g}; named {est.assumptions}, none shown false")


@pytest.mark.parametrize("kind, seed, was", [
    ("bumpy", 0, "2.3 % off at ±34 % (the slab)"),
    ("bumpy", 17, "2.9 % off at ±22 % (the slab)"),
    ("bumpy", 23, "1.1 % off at ±15 % (the slab)"),
])
def test_large_holes_round_the_curvature_or_a_corner_are_graphs_within_one_percent(kind, seed, was):
    """Holes of 3-20 % of a wavy sphere's surface that are not a graph over their rim's mean plane (no bend
    bound): the cone was 1.1-2.9 % off; filled as a graph over the face-on plane they are within 1 % of the
    undamaged solid's volume, under a narrower bound that holds and names ``graph`` (before fill13: ``was``)."""
    v, f, gone = _case(kind, seed)
    truth = volume_moments(v, f)
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert "graph" in est.assumptions, est.detail
    assert est.uncertainty.mass <= ESTIMATE_MAX_MASS_RTOL
    assert abs(est.volume - truth.volume) <= 0.01 * truth.volume
    assert _holds(est, truth)


@settings(max_examples=12, deadline=None)
@given(kind=st.sampled_from(KINDS), seed=st.integers(0, 2 ** 31 - 1), holes=st.integers(1, 4))
def test_graph_fills_read_only_the_faces_near_the_rims_and_give_what_every_face_gives(kind, seed, holes):
    """``graph_fills`` reads only the faces within two rings of the rims it tries (issue 25, soup17: three passes
    over every face per loop before): on generated solids less 1-4 patches, every fill (points, triangles, doubt,
    height, direction, slope) is the one it gives when handed every face as the faces near the rims (the old
    reading), bit for bit."""
    import inertia_tool.mesh.hole_graphs as hg
    from inertia_tool.mesh.rims import boundary_edges, boundary_loops

    rng = np.random.default_rng([seed, 6])
    v, f = _solid(kind, rng)
    gone = np.unique(np.concatenate([_grow(f, int(rng.integers(len(f))), max(1, int(rng.uniform(0.01, 0.08)
                                                                                          * len(f))))
                                     for _ in range(holes)]))
    kept = np.delete(f, gone, axis=0)
    edges = boundary_edges(kept, len(v))
    label, n_loops = boundary_loops(edges, len(v), kept, v)
    apex = np.stack([np.bincount(label, weights=v[edges[:, 0], i], minlength=n_loops) for i in range(3)], axis=1)
    apex /= np.maximum(np.bincount(label, minlength=n_loops), 1)[:, None]
    loops = np.argsort(-np.bincount(label, minlength=n_loops), kind="stable")
    fast = hg.graph_fills(v, kept, edges, label, loops, apex)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(hg, "_faces_near", lambda faces, n, rims: faces)
        every = hg.graph_fills(v, kept, edges, label, loops, apex)
    assert len(fast) == len(every)
    for one, other in zip(fast, every):
        assert one == other
