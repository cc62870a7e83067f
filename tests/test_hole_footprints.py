"""Holes that took a whole feature, and the guarantee every hole bound gives (``mesh/holes.py``:
:func:`rim_evidence`, the refusal of footprints in :func:`patched_estimate`).

The guarantee tested here: for every generated part and hole, the estimate is either refused (its surroundings
contradict the assumption, or its mass bound exceeds ``ESTIMATE_MAX_MASS_RTOL``) or its stated bound contains
the exact integral of the undamaged part.
"""

import numpy as np
import pytest
import trimesh
from hypothesis import example, HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh.holes import patched_estimate, rim_evidence
from inertia_tool.mesh.rims import boundary_edges, boundary_loops, enclosing_balls
from inertia_tool.tolerances import ESTIMATE_MAX_MASS_RTOL

m3d = pytest.importorskip("manifold3d")

from solids import featured_box, grown_patch, manifold_neighbours  # noqa: E402
from test_hole_bounds import _holds  # noqa: E402  (the one "inside every bound" test of the hole tests)




def _refused_or_holds(est, truth):
    """Refused (the reason said) or inside its bound: never a stated bound that misses."""
    return bool(est.unbounded) or est.uncertainty.mass > ESTIMATE_MAX_MASS_RTOL or _holds(est, truth)


def _patch(v, f, start, count):
    """``count`` faces grown breadth-first across edges from face ``start``."""
    return grown_patch(manifold_neighbours(v, f), start, count)


# ------------------------------------------------------------------------------ the xarm7 housing, made small

@pytest.mark.parametrize("height", [3.0, 0.4, -0.6])
def test_a_feature_taken_whole_is_refused_with_its_reason(height):
    """``7-38-crack_hole`` of the damage benchmark (xarm7 ``link_base.stl``: a connector housing taken whole,
    its rim the footprint on the flat side, a flat patch with a bound of round-off, 1 % low): a boss or pocket
    on a box taken whole, walls and top.  The rim is an island of the top face with nothing off the face left
    at it, on a surface with no vertex inside a flat face: refused, the reason named, whatever the height."""
    v, f, feature, _ = featured_box((5.0, 4.0, 1.0), (0.5, 0.4), (0.2, 0.25), height)
    open_f = np.delete(f, feature, axis=0)
    est = patched_estimate(v, open_f, volume_moments)
    assert "footprint" in est.unbounded
    with pytest.raises(InvalidMeshError, match="footprint of a feature"):
        mass_properties((v, open_f), density=1.0, repair=True)


def test_a_flat_hole_in_a_cad_face_is_still_answered_exactly():
    """The other side of the rule: a triangle missing from the top face beside the boss (its rim keeps the
    box's side and the boss's wall) is a flat hole, answered with a bound of round-off, exactly."""
    v, f, feature, _ = featured_box((5.0, 4.0, 1.0), (0.5, 0.4), (0.2, 0.25), 2.0)
    top = np.flatnonzero(np.all(np.abs(v[f][:, :, 2] - 1.0) < 1e-6, axis=1))
    truth = volume_moments(v, f)
    for face in top:
        est = patched_estimate(v, np.delete(f, face, axis=0), volume_moments)
        assert not est.unbounded
        assert est.volume == pytest.approx(truth.volume, rel=1e-12)
        assert est.uncertainty.mass < 1e-9
        assert _holds(est, truth)


def test_rim_evidence_on_a_footprint_and_on_a_finely_tessellated_face():
    """The footprint's four rim corners are bare on the manifold3d part (no vertex inside its flat faces);
    the same footprint on the subdivided part is flat all round but not bare (the tessellation puts vertices
    inside flat faces, so it proves nothing): the rule needs both."""
    v, f, feature, _ = featured_box((5.0, 4.0, 1.0), (0.5, 0.4), (0.2, 0.25), 1.0)
    for fine in (False, True):
        vv, ff = (v, f)
        gone = feature
        if fine:
            mesh = trimesh.Trimesh(v, np.delete(f, feature, axis=0), process=False).subdivide()
            vv, ff, gone = np.asarray(mesh.vertices), np.asarray(mesh.faces), np.zeros(0, dtype=np.int64)
        open_f = np.delete(ff, gone, axis=0)
        edges = boundary_edges(open_f, len(vv))
        label, n_loops = boundary_loops(edges, len(vv), open_f, vv)
        pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
        _, radius = enclosing_balls(vv[pairs[:, 1]], pairs[:, 0], n_loops)
        found = rim_evidence(vv, open_f, edges, label, n_loops, radius)
        assert found.flat_all_round.tolist() == [True]
        assert found.bare.tolist() == ([0] if fine else [4])


# ----------------------------------------------------------------------------- the guarantee, generated

@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@example(extents=(1.0, 1.0, 1.0), place=(0.5, 0.875), size=(0.5, 0.125), height=0.25, pattern="patch", start=2250,
         share=0.5, quat=(0.0, 0.0, 0.0, 1.0))       # found by CI: a crease fill over the top face's remaining faces
@example(extents=(1.0, 1.0, 1.0), place=(0.5, 0.875), size=(0.25, 0.25), height=0.25, pattern="patch", start=0,
         share=0.59375, quat=(0.0, 0.0, 0.0, 1.0))   # found by a random run on main before the flat-rim slab check
@given(extents=st.tuples(st.floats(1.0, 6.0), st.floats(1.0, 6.0), st.floats(0.3, 3.0)),
       place=st.tuples(st.floats(0.05, 0.95), st.floats(0.05, 0.95)),
       size=st.tuples(st.floats(0.1, 0.6), st.floats(0.1, 0.6)),
       height=st.one_of(st.floats(0.05, 5.0), st.floats(-0.9, -0.05)),
       pattern=st.sampled_from(["feature", "end", "patch"]), start=st.integers(0, 10 ** 6),
       share=st.floats(0.0, 0.6),
       quat=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_holes_over_bosses_and_pockets_are_refused_or_inside_their_bound(extents, place, size, height, pattern,
                                                                          start, share, quat):
    """A box with a boss or pocket (manifold3d), turned at random, less the whole feature, its top or floor, or
    a connected patch of faces grown from a random face: refused, or inside the stated bound."""
    height = height if height > 0 else height * extents[2]
    v, f, feature, end = featured_box(extents, place, size, height)
    v = v @ Rotation.from_quat(quat).as_matrix().T
    if pattern == "feature":
        gone = feature
    elif pattern == "end":
        gone = end
    else:
        gone = _patch(v, f, start % len(f), max(1, int(share * len(f))))
    truth = volume_moments(v, f)
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert _refused_or_holds(est, truth)


@settings(max_examples=40, deadline=None)
@given(height=st.floats(-0.999, 0.98), quat=st.tuples(*[st.floats(-1, 1)] * 4)
       .filter(lambda q: np.linalg.norm(q) > 0.1))
def test_spherical_caps_up_to_nearly_the_whole_sphere_are_refused_or_inside_their_bound(height, quat):
    """A cap above z = ``height`` cut from an icosphere, turned: up to a hemisphere the cap lies in the ball over
    its rim and the bound holds; beyond it (``height`` < 0) the cap leaves the ball, and the bound, then more than
    the whole remaining part, is refused."""
    s = trimesh.creation.icosphere(3)
    v0, f = np.asarray(s.vertices), np.asarray(s.faces)
    open_f = f[~np.all(v0[f][:, :, 2] > height, axis=1)]
    if not len(open_f):
        return
    v = v0 @ Rotation.from_quat(quat).as_matrix().T
    est = patched_estimate(v, open_f, volume_moments)
    assert _refused_or_holds(est, volume_moments(v, f))


@settings(max_examples=40, deadline=None)
@given(sections=st.integers(3, 12), start=st.integers(0, 10 ** 6), count=st.integers(1, 12),
       quat=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_holes_across_creases_of_prisms_are_refused_or_inside_their_bound(sections, start, count, quat):
    """A coarse prism (``sections`` sides, CAD-like: no vertex inside a face) less a connected patch of faces,
    across its creases and caps: refused, or inside the stated bound."""
    s = trimesh.creation.cylinder(radius=1.0, height=1.3, sections=sections)
    hull = trimesh.convex.convex_hull(s.vertices)          # caps without their centre vertices
    v = np.asarray(hull.vertices) @ Rotation.from_quat(quat).as_matrix().T
    f = np.asarray(hull.faces)
    gone = _patch(v, f, start % len(f), min(count, len(f) - 1))
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert _refused_or_holds(est, volume_moments(v, f))


# ------------------------------------------------------------------------- the benchmark's two failures

@pytest.mark.slow
@pytest.mark.parametrize("case", ["7-38-crack_hole", "15-38-t_junction_hole"])
def test_the_xarm7_link_base_holes_of_the_damage_benchmark_are_inside_their_bound(case):
    """The two bounds that failed in the coverage benchmark (xarm7 ``link_base.stl``, a connector housing taken
    whole or its top cut off; docs/damage-benchmark.md).  Their rims keep bare vertices (the housing's walls
    met the flat side or the shoulder there and are gone), so the slab is withdrawn and the ball states the
    bound, which now holds (the missing surface still leaves the ball: the assumption is false, the bound holds
    by its volume).  Needs the robot parts of ``benchmarks/damage/make_cases.py`` (skipped without them)."""
    from damage_cases import case_row, coverage_module

    cov = coverage_module()
    robots = cov.robot_sources()
    match = [(name, v, f) for name, v, f in robots if name.endswith("xarm7/visual/link_base.stl")]
    if not match:
        pytest.skip("the robot parts are not downloaded (benchmarks/damage/make_cases.py)")
    name, v, f = match[0]
    row = case_row(cov, case, 38, v, f)
    assert row["status"] == "answer" and row["holds"], row


@pytest.mark.parametrize("extents, place, size, height, start, quat", [
    ((1.0, 2.0, 1.0), (0.5, 0.5), (0.5, 0.5), 1.0, 0, (0.0, 0.0, 1.0, 0.5)),          # a boss; estimate = boss
    ((1.0, 1.0, 1.0), (0.25, 0.5), (0.25, 0.5), -0.5, 27, (0.0, 0.0, 1.0, 1.0)),      # a pocket
])
def test_a_crease_fill_when_half_the_part_is_gone_is_refused_or_bounded(extents, place, size, height, start, quat):
    """Found by the generated test above (random seeds 11 and 12, and CI's fixed sequence once more): half of a
    featured box's faces gone in one connected patch leaves a rim of 6 edges in two planes; the crease fill
    (third assumption: the missing surface lies in those planes) closed the feature alone and stated a bound of
    round-off, 80 % low.  Nothing in the faces left contradicts the assumption the way
    ``holes._crease_contradicted`` can see, so the third assumption's narrow bound is withdrawn for every crease
    fill: the fill is kept as the estimate, bounded by its whole ball (first assumption), or refused."""
    height = height if height > 0 else height * extents[2]
    v, f, _, _ = featured_box(extents, place, size, height)
    v = v @ Rotation.from_quat(quat).as_matrix().T
    gone = _patch(v, f, start % len(f), max(1, int(0.5 * len(f))))
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert _refused_or_holds(est, volume_moments(v, f))


@pytest.mark.parametrize("extents, place, size, height, start, share, quat", [
    # the boss alone (16 of 28 faces gone, a hexagonal rim in the top face): 94 % low at ±1e-13
    ((1.0, 1.0, 1.0), (0.5, 0.25), (0.5, 0.5), 0.25, 1, 0.59375, (0.0, 0.0, 0.0, 1.0)),
    # half the top face gone with the pocket in it, the rim touching the pocket's footprint at one corner:
    # the pocket not subtracted, 0.7 % high at ±2e-14 (random seed 2 of the test above)
    ((2.00001, 1.6652643388379098, 1.0), (0.05, 0.05), (0.1, 0.1), -0.7389782412397813, 19063,
     0.5969803190441334, (-0.5544520793490476, 0.9295292324985178, 0.9295292324985178, -0.8341000485155927)),
    # a boss near an edge, most of the box gone (random seed 11 of the test above): 8 % low at ±2e-14
    ((1.1, 1.52157514550787, 0.9982126590266371), (0.05880060467438966, 0.7767143445873239),
     (0.17704087873546454, 0.42776320580330274), 1.178055692181371, 1172, 0.5809652110845349,
     (1e-15, 0.9999999999999999, -0.23104757655614327, 0.443994255804274)),
])
def test_a_flat_rim_whose_faces_say_the_surface_leaves_its_plane_is_refused_or_bounded(extents, place, size,
                                                                                      height, start, share, quat):
    """Found by the generated test above on random (non-CI) runs: a featured box that lost most of its faces in
    one patch leaves a flat rim, and the slab around its plane (second assumption: the missing surface is the
    flat region the rim bounds) was as thin as round-off while the true missing surface left the plane.  The
    faces left at the rim say so (``holes.slab_contradicted``): a rim vertex keeps faces in the plane only, on a
    surface with no vertex inside its flat faces (another face of the part met the plane there and is gone).
    The slab is withdrawn, the ball (first assumption) bounds the hole, and the case is refused or bounded."""
    height = height if height > 0 else height * extents[2]
    v, f, _, _ = featured_box(extents, place, size, height)
    v = v @ Rotation.from_quat(quat).as_matrix().T
    gone = _patch(v, f, start % len(f), max(1, int(share * len(f))))
    truth = volume_moments(v, f)
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert abs(est.volume - truth.volume) > 1e-3 * truth.volume          # the estimate is wrong ...
    assert est.uncertainty.mass > 1e-3                                    # ... and no longer says round-off
    assert _refused_or_holds(est, truth)


def test_slab_contradicted_on_a_hole_in_a_flat_face_and_on_most_of_the_part_gone():
    """The two sides of the rule on one part: one triangle missing from the top face beside the boss keeps
    faces off the top face at every rim vertex (not contradicted: the exact flat answer stays); the boss with
    most of the box gone keeps only top-face triangles at two rim corners (contradicted)."""
    from inertia_tool.mesh.holes import hole_doubt_volumes, slab_contradicted

    def contradicted(v, open_f):
        edges = boundary_edges(open_f, len(v))
        label, n_loops = boundary_loops(edges, len(v), open_f, v)
        pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
        centre, radius = enclosing_balls(v[pairs[:, 1]], pairs[:, 0], n_loops)
        slabs = {}
        hole_doubt_volumes(v, open_f, edges, label, n_loops, centre, radius, pairs[:, 1], pairs[:, 0], slabs=slabs)
        return slab_contradicted(v, open_f, edges, label, n_loops, slabs, radius).tolist()

    v, f, _, _ = featured_box((5.0, 4.0, 1.0), (0.5, 0.4), (0.2, 0.25), 2.0)
    top = np.flatnonzero(np.all(np.abs(v[f][:, :, 2] - 1.0) < 1e-6, axis=1))
    assert all(contradicted(v, np.delete(f, face, axis=0)) == [False] for face in top)
    v, f, _, _ = featured_box((1.0, 1.0, 1.0), (0.5, 0.25), (0.5, 0.5), 0.25)
    assert contradicted(v, np.delete(f, _patch(v, f, 1, 16), axis=0)) == [True]


# ------------------------------------------------------------------------- holes across creases, generated

def chamfered_featured_box(extents, place, size, height, chamfer):
    """``featured_box`` with the top edge along x at y = 0 chamfered by ``chamfer`` (share of the smaller of
    depth and height; 0: none), by manifold3d: the feature may sit on or beside the chamfer."""
    v, f, _, _ = featured_box(extents, place, size, height)
    if chamfer <= 0:
        return v, f
    w, d, h = extents
    c = chamfer * min(d, h)
    body = m3d.Manifold(m3d.Mesh(vert_properties=np.asarray(v, dtype=np.float32), tri_verts=f.astype(np.uint32)))
    side = 2 * c / np.sqrt(2)
    cut = m3d.Manifold.cube([w + 2, side, side], center=True).rotate([45.0, 0.0, 0.0]).translate([w / 2, 0.0, h])
    mesh = (body - cut).to_mesh()
    return np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3], np.asarray(mesh.tri_verts, dtype=np.int64)


def _crease_hole(v, f, start, extra):
    """Two faces across a crease (the first edge from face ``start`` onwards whose faces are not coplanar)
    and ``extra`` more grown from them."""
    mesh = trimesh.Trimesh(v, f, process=False)
    pairs, angles = mesh.face_adjacency, mesh.face_adjacency_angles
    creased = np.flatnonzero(angles > 1e-3)
    a, b = pairs[creased[start % len(creased)]]
    grown = _patch(v, f, int(a), 1 + extra)
    return np.union1d(grown, [a, b])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(extents=st.tuples(st.floats(1.0, 6.0), st.floats(1.0, 6.0), st.floats(0.3, 3.0)),
       place=st.tuples(st.floats(0.05, 0.95), st.floats(0.05, 0.95)),
       size=st.tuples(st.floats(0.1, 0.6), st.floats(0.1, 0.6)),
       height=st.one_of(st.floats(0.05, 5.0), st.floats(-0.9, -0.05)),
       chamfer=st.one_of(st.just(0.0), st.floats(0.05, 0.5)), start=st.integers(0, 10 ** 6),
       extra=st.integers(0, 6),
       quat=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_holes_across_creases_of_featured_chamfered_boxes_are_refused_or_inside_their_bound(
        extents, place, size, height, chamfer, start, extra, quat):
    """A box with a boss or pocket and perhaps a chamfered edge (manifold3d, turned at random) less two faces
    across a crease and a few more grown from them: whatever fills the hole (a cone, or the two planes' fans
    with the narrow bound where the faces at the rim allow it, ``CreaseFill.narrow``), refused or inside the
    stated bound."""
    height = height if height > 0 else height * extents[2]
    v, f = chamfered_featured_box(extents, place, size, height, chamfer)
    v = v @ Rotation.from_quat(quat).as_matrix().T
    gone = _crease_hole(v, f, start, extra)
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert _refused_or_holds(est, volume_moments(v, f))


def test_a_tall_boss_taken_whole_by_a_patch_is_refused_or_inside_its_bound():
    """Found by a random run of the test above (session 14; was a strict xfail): a 1 m box with a 0.25 × 0.11 m
    boss 2 m tall, less a patch of 12 of its 28 faces that takes the whole boss.  Three rim vertices are bare
    (their faces left all in the top's plane, the rim in that plane too), which withdraws the slab, yet the
    capsule round the 4-edge rim was still taken: ±5.6 % mass, the centre and inertia bounds missed.  Diagnosed
    by hypo16 (the cause of the rib case in ``test_hole_capsules.py`` too): no capsule on a rim in the plane of
    a face beside it with a bare vertex; the ball states ±23 % and holds."""
    v, f, _, _ = featured_box((1.0, 1.0, 1.0), (0.28125, 0.4375), (0.25, 0.109375), 2.0)
    gone = _patch(v, f, 643 % len(f), int(0.4375 * len(f)))
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments)
    assert "capsule" not in est.assumptions
    assert _refused_or_holds(est, volume_moments(v, f))
    test_holes_over_bosses_and_pockets_are_refused_or_inside_their_bound.hypothesis.inner_test(
        extents=(1.0, 1.0, 1.0), place=(0.28125, 0.4375), size=(0.25, 0.109375), height=2.0, pattern="patch",
        start=643, share=0.4375, quat=(0.0, 0.0, 0.0, 1.0))
