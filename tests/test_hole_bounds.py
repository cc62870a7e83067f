"""Each hole's volume in doubt: the ball over its rim cut to the slab around the plane beside it
(``mesh/holes.py``: :func:`hole_doubt_volumes`, :func:`ball_slab_volume`)."""

import numpy as np
import pytest
import trimesh
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.spatial.transform import Rotation

from conftest import box_arrays
from inertia_tool import mass_properties
from inertia_tool.errors import MeshRepairedWarning
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh.holes import ball_slab_volume, patched_estimate
from inertia_tool.mesh.rims import boundary_edges


def _inertia(m):
    return np.trace(m.second_moment) * np.eye(3) - m.second_moment


def _holds(est, truth):
    """The truth lies inside every bound the estimate states."""
    u = est.uncertainty
    return (abs(est.volume - truth.volume) <= u.mass * est.volume * (1 + 1e-12) + 1e-12 * truth.volume
            and np.linalg.norm(est.centroid - truth.centroid) <= u.center_of_mass * (1 + 1e-12) + 1e-12
            and np.linalg.norm(_inertia(est) - _inertia(truth))
            <= u.inertia * np.linalg.norm(_inertia(est)) * (1 + 1e-12) + 1e-12 * np.linalg.norm(_inertia(truth)))


# ------------------------------------------------------------------------------------------ ball ∩ slab

def test_ball_slab_volume_closed_forms():
    r = 2.0
    ball = 4 / 3 * np.pi * r ** 3
    assert ball_slab_volume(np.array([r]), np.array([0.0]), np.array([5.0]))[0] == pytest.approx(ball, rel=1e-14)
    # a slab from the centre plane outwards past the ball: a hemisphere
    assert ball_slab_volume(np.array([r]), np.array([-3.0]), np.array([3.0]))[0] == pytest.approx(ball / 2)
    # a slab that misses the ball
    assert ball_slab_volume(np.array([r]), np.array([10.0]), np.array([1.0]))[0] == 0.0
    # a cap of height h: π h² (3r − h) / 3 (slab from r − h above the centre to beyond the ball)
    h = 0.7
    cap = np.pi * h ** 2 * (3 * r - h) / 3
    assert ball_slab_volume(np.array([r]), np.array([-(r - h) - 10.0]), np.array([10.0]))[0] == pytest.approx(cap)


@settings(max_examples=60, deadline=None)
@given(r=st.floats(0.01, 10.0), s=st.floats(-20.0, 20.0), t=st.floats(0.0, 20.0))
def test_ball_slab_volume_agrees_with_quadrature(r, s, t):
    """Against scipy's quadrature of the disc areas π(r² − z²) over the slab clipped to the ball."""
    lo, hi = max(-t - s, -r), min(t - s, r)
    expected = quad(lambda z: np.pi * (r * r - z * z), lo, hi)[0] if hi > lo else 0.0
    got = ball_slab_volume(np.array([r]), np.array([s]), np.array([t]))[0]
    assert got == pytest.approx(expected, rel=1e-9, abs=1e-12 * r ** 3)
    assert 0.0 <= got <= 4 / 3 * np.pi * r ** 3 * (1 + 1e-12)


# ------------------------------------------------------------------------------------ flat holes (CAD)

def test_missing_triangle_of_a_flat_face_is_answered_not_refused_at_400_percent():
    """Benchmark case 3-07-holes_scattered (``meshes/box.stl`` less one triangle) was refused with "mass
    ±409 %": the ball over a triangle across a whole side of a 12-triangle box is larger than the box.  The
    other half of that side lies in the hole's plane, so the slab is as thin as round-off and the (exact)
    patched answer is given with a tiny bound.

    holes7 (the lead's decision on issue 21): the file cannot tell this hole from a boss taken whole with the
    faces round its footprint (``test_review7``'s box with a boss), so the answer is an estimate, never exact,
    and its tiny bound is stated conditional on the named assumption that the flat face continues across the
    hole (``hole_assumptions.FLAT``), printed among the notes."""
    from inertia_tool.mesh.hole_assumptions import FLAT
    v, f = box_arrays((1.0, 2.0, 3.0))
    for k in range(len(f)):
        open_f = np.delete(f, k, axis=0)
        est = patched_estimate(v, open_f, volume_moments)
        assert est.volume == pytest.approx(6.0, rel=1e-14)
        assert 0 < est.uncertainty.mass < 1e-12
        assert "flat" in est.assumptions and "convex" not in est.assumptions
        with pytest.warns(MeshRepairedWarning):
            p = mass_properties((v, open_f), density=1.0, repair=True)
        assert p.mesh.method == "patched" and p.mesh.certificate.kind == "estimate"
        assert 0 < p.mesh.uncertainty.mass < 1e-12
        assert any(FLAT.statement in note for note in p.mesh.notes)
        assert p.mass == pytest.approx(6.0, rel=1e-12)


def test_hole_across_a_crease_is_filled_in_its_two_planes():
    """Issue 21 item 4: two triangles of different sides (sharing the box's edge) missing.  The rim is bent over
    the edge; no one plane holds it, and the slab was as wide as the hole (the ball's bound, ±330 %, refused).
    Each of the two sides holds three rim corners, every rim edge lies in one side, and the rim changes side
    twice, at the edge's ends: each side's part is filled in its own plane, which is exact for the box.  The
    bound is the ball cut to the two planes' slabs (third assumption), round-off here, since nothing the file
    keeps at the rim contradicts it (``CreaseFill.narrow``: every rim corner off the crease keeps a face of a
    third side, no face in a plane faces against its fan).  Every such pair of the 12-triangle box."""
    v, f = box_arrays((1.0, 2.0, 3.0))
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    truth = volume_moments(v, f)
    pairs = [(a, b) for a in range(len(f)) for b in range(a + 1, len(f))
             if len(set(f[a]) & set(f[b])) == 2 and abs(float(normals[a] @ normals[b])) == 0.0]
    assert len(pairs) == 12
    for pair in pairs:
        est = patched_estimate(v, np.delete(f, list(pair), axis=0), volume_moments)
        assert "across a crease" in est.detail
        assert est.volume == pytest.approx(6.0, rel=1e-14)
        assert np.allclose(est.second_moment, truth.second_moment, rtol=1e-13, atol=1e-13)
        assert 0 < est.uncertainty.mass < 1e-12
        assert _holds(est, truth)


@settings(max_examples=30, deadline=None)
@given(quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1),
       corner=st.integers(0, 7), extents=st.lists(st.floats(0.2, 5.0), min_size=3, max_size=3))
def test_crease_fill_of_a_turned_subdivided_box_holds_its_bound(quat, corner, extents):
    """A box whose faces are each split in four, turned at random, less the triangles touching one edge at a
    corner (parts of two faces, the rim bent over the edge; sometimes a third face's triangle goes too, and
    then no pair of planes holds the rim and the cone and ball stay): the stated bound contains the truth."""
    v0, f0 = box_arrays(tuple(extents))
    mesh = trimesh.Trimesh(v0, f0, process=False).subdivide()
    v, f = np.asarray(mesh.vertices) @ Rotation.from_quat(quat).as_matrix().T, np.asarray(mesh.faces)
    truth = volume_moments(v, f)
    near = np.argsort(np.linalg.norm(v[f].mean(axis=1) - v[corner % len(v)], axis=1))[:2]
    open_f = np.delete(f, near, axis=0)
    est = patched_estimate(v, open_f, volume_moments)
    assert _holds(est, truth)


@settings(max_examples=30, deadline=None)
@given(sections=st.integers(5, 16), seed=st.integers(0, 2 ** 31 - 1), count=st.integers(1, 6))
def test_holes_near_the_rim_of_a_coarse_cylinder_are_inside_their_bound(sections, seed, count):
    """A coarse cylinder (a faceted side, fan caps) less ``count`` faces nearest a random point of its top rim:
    holes across the crease between cap and side (filled in the two planes when they qualify), holes of one
    plane, holes across several facets (cone and ball): whatever the fill, the stated bound holds."""
    s = trimesh.creation.cylinder(radius=1.0, height=1.5, sections=sections)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi)
    point = np.array([np.cos(angle), np.sin(angle), 0.75])
    gone = np.argsort(np.linalg.norm(v[f].mean(axis=1) - point, axis=1))[:count]
    open_f = np.delete(f, gone, axis=0)
    est = patched_estimate(v, open_f, volume_moments)
    assert _holds(est, volume_moments(v, f))


def test_the_octahedron_is_not_a_crease_hole():
    """Two faces of the octahedron missing: the rim lies on two of the faces beside it, but each holds only an
    edge of the rim (two corners), and the missing faces lie in two other planes: not filled in the ring's
    planes (that would be 33 % off with a bound of round-off), the ball decides."""
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    est = patched_estimate(v, f[2:], volume_moments)
    assert "across a crease" not in est.detail
    assert _holds(est, volume_moments(v, f))


def test_a_hole_that_took_a_whole_boss_on_a_grid_tessellation_names_the_assumptions_that_fail():
    """The mechanism of ``7-38-crack_hole`` of the coverage benchmark (a connector housing of xarm7's
    ``link_base.stl`` taken whole), made small: a 5 × 5 × 1 slab with a 1 × 1 × 3 boss on top, the boss's
    walls and top removed.  The rim is the boss's footprint, flat, in the slab's top face; the patch is flat
    and its bound round-off, the boss (3 of 28 cells) is missing.  Here the top face is a grid of unit squares:
    the rim's corners are vertices *inside* a flat face, which any tessellation may have, so they prove nothing
    (on a CAD tessellation they would be bare, and the hole is refused:
    ``test_hole_footprints.test_a_feature_taken_whole_is_refused_with_its_reason``).

    holes7 (was a strict xfail; the stated limit stays): by the lead's decision on issue 21 the answer is an
    estimate whose bound is conditional on named assumptions, and this checks that the ones named fail: the
    slab is withdrawn here (a rim corner keeps only faces of the top), and the hole is an island in the flat top
    (every face touching the rim lies in the top's plane), so by the rule that a slab of zero width is no evidence
    (``hole_bounds.flat_islands``; the bend bound of slope 0 was named here before, dome14) the bound rests on the
    ball over the rim alone (radius 0.71 m), and the boss rises 3 m above the rim: the ball's stated limit."""
    from inertia_tool.mesh.hole_assumptions import BALL
    from inertia_tool.mesh.rims import enclosing_balls
    import adversary_solids as S
    cells = {(i, j, 0) for i in range(5) for j in range(5)} | {(2, 2, k) for k in range(1, 4)}
    v, f = S.cell_body(cells, 1.0, np.random.default_rng(0))
    truth = volume_moments(v, f)
    assert truth.volume == pytest.approx(28.0)
    boss = np.all(v[f][:, :, 2] >= 1.0, axis=1) & np.all(np.abs(v[f][:, :, :2] - 2.5) <= 0.5, axis=(1, 2))
    est = patched_estimate(v, f[~boss], volume_moments)
    assert est.assumptions == ("ball",) and BALL.statement in est.detail and "island in a flat face" in est.detail
    touching = f[~boss][np.isin(f[~boss], np.unique(boundary_edges(f[~boss], len(v)))).any(axis=1)]
    assert np.all(v[touching][:, :, 2] == 1.0)           # slope 0 round the rim: the boss's walls break `bend`
    assert not _holds(est, truth)
    rim = np.unique(boundary_edges(f[~boss], len(v)))
    centre, radius = enclosing_balls(v[rim], np.zeros(len(rim), dtype=np.int64), 1)
    reach = np.linalg.norm(v[f[boss]].reshape(-1, 3) - centre[0], axis=1).max()
    assert reach > 4 * radius[0]                        # the missing boss leaves the ball (and the capsule in it)


def test_octahedron_missing_a_face_is_bounded_by_the_planes_of_its_other_faces():
    """Every face beside the hole meets it at 109.5°: nothing says the hole is flat, and the ball holds 330 % of
    the solid (refused before).  What remains is convex, so the part is taken to be convex (fourth assumption,
    ``holes.convex_hole_bound``): it lies inside the other seven faces' half-spaces, the octahedron plus the
    tetrahedron over the missing face with apex (1, 1, 1), volume 1/3 (a closed form): the volume in doubt is
    1/3 of 4/3, a 25 % bound, and the patched answer (exact here) lies inside it."""
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    est = patched_estimate(v, f[1:], volume_moments)
    assert "convex" in est.detail
    assert est.uncertainty.volume_in_doubt == pytest.approx(1 / 3, rel=3e-3)
    assert 0.25 <= est.uncertainty.mass <= 0.251
    assert _holds(est, volume_moments(v, f))
    with pytest.warns(MeshRepairedWarning):
        p = mass_properties((v, f[1:]), repair=True)
    assert p.mesh.certificate.kind == "estimate" and p.volume == pytest.approx(4 / 3, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(height=st.floats(-0.9, 0.98), quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4)
       .filter(lambda q: np.linalg.norm(q) > 0.1))
def test_convex_bound_of_sphere_caps_holds_and_is_never_wider_than_the_ball(height, quat):
    """A cap above z = height cut from an icosphere (convex), turned: the bound of the planes of the faces left
    (``convex_hole_bound``) contains the truth, and it is chosen only where it is narrower than the ball's."""
    from inertia_tool.mesh.holes import convex_hole_bound
    s = trimesh.creation.icosphere(3)
    v0, f = np.asarray(s.vertices), np.asarray(s.faces)
    open_f = f[~np.all(v0[f][:, :, 2] > height, axis=1)]
    v = v0 @ Rotation.from_quat(quat).as_matrix().T
    est = patched_estimate(v, open_f, volume_moments)
    truth = volume_moments(v, f)
    assert est.uncertainty.mass > 0.5 or _holds(est, truth)       # beyond a hemisphere: refused by the ball
    # the convex bound is stated about the cone fill (the patch inside the part); a quadric fill kept under the
    # ball's bound may answer otherwise, so the bound is taken here about the cone's volume
    cone = _cone_volume(v, open_f)
    bound = convex_hole_bound(v, open_f, cone)
    if height >= 0:                  # the faces left close the part in (below the equator they do not: None)
        assert bound is not None
    if bound is not None:
        assert bound[0] >= truth.volume - cone >= 0
        assert est.uncertainty.volume_in_doubt <= bound[0] * (1 + 1e-12)


def _cone_volume(v, f):
    """The volume of ``f`` with its one boundary loop closed by a cone to the mean of the loop's vertices."""
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    given = {(int(a), int(b)) for a, b in edges}
    rim = np.array([(a, b) for a, b in given if (b, a) not in given])
    apex = v[np.unique(rim)].mean(axis=0)
    cap = np.column_stack([rim[:, 1], rim[:, 0], np.full(len(rim), len(v))])
    return volume_moments(np.vstack([v, apex]), np.vstack([f, cap])).volume


# ---------------------------------------------------------------------------------- curved holes hold

@settings(max_examples=25, deadline=None)
@given(height=st.floats(0.0, 0.98), quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4)
       .filter(lambda q: np.linalg.norm(q) > 0.1))
def test_spherical_cap_holes_in_any_orientation_are_inside_their_bound(height, quat):
    """A cap above the plane z = height cut from a finely tessellated sphere, turned at random: the ring's
    planes are tilted by the cap's half-angle, the rim's far side stands off them by more than the cap's
    height, and the stated bound contains the truth (mass, centre of mass, inertia)."""
    s = trimesh.creation.icosphere(4)
    rot = Rotation.from_quat(quat).as_matrix()
    v0, f = np.asarray(s.vertices), np.asarray(s.faces)
    open_f = f[~np.all(v0[f][:, :, 2] > height, axis=1)]
    v = v0 @ rot.T
    est = patched_estimate(v, open_f, volume_moments)
    assert est.uncertainty.mass > 0
    assert _holds(est, volume_moments(v, f))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1), share=st.floats(0.001, 0.1))
def test_patches_cut_from_a_torus_are_inside_their_bound(seed, share):
    """Saddles: a torus's inner side bends up one way and down the other.  A patch of nearby faces (the
    faces whose centroids are closest to a random one, up to ``share`` of them) removed: the bound holds.

    Only holes with one rim: a band all round the tube leaves two rims, and the bound assumes each rim closes
    over its own missing disc (docs/meshes.md, limits), which a band is not."""
    s = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=40, minor_sections=20)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    rng = np.random.default_rng(seed)
    centroids = v[f].mean(axis=1)
    start = centroids[rng.integers(len(f))]
    gone = np.argsort(np.linalg.norm(centroids - start, axis=1))[:max(1, int(share * len(f)))]
    open_f = np.delete(f, gone, axis=0)
    assume(len(connected_components_of(boundary_edges(open_f, len(v)))) == 1)
    est = patched_estimate(v, open_f, volume_moments)
    assert _holds(est, volume_moments(v, f))


def connected_components_of(edges):
    """The vertex sets of the components of an edge list (a few hundred edges: a plain union-find)."""
    parent = {}

    def root(x):
        while parent.setdefault(x, x) != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b in edges.tolist():
        parent[root(a)] = root(b)
    groups = {}
    for x in list(parent):
        groups.setdefault(root(x), set()).add(x)
    return list(groups.values())


# ------------------------------------------------------------------------------- seams on sliver faces

def _box_with_a_sliver_side(height=1e-7):
    """A 1×2×3 box whose +x side holds a sliver: E lies ``height`` from the side's diagonal A–C, so the side
    is (A, B, E), (B, C, E), (A, E, C) (the sliver, apex E over its base A–C) and (A, C, D)."""
    v, f = box_arrays((1.0, 2.0, 3.0))
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    side = normals[:, 0] > 0
    corners = np.unique(f[side])
    # the side's corners in turn about +x (counter-clockwise seen from outside)
    angle = np.arctan2(v[corners, 2], v[corners, 1])
    a, b, c, d = corners[np.argsort(angle)]
    towards_b = v[b] - 0.5 * (v[a] + v[c])
    e_point = 0.5 * (v[a] + v[c]) + height * towards_b / np.linalg.norm(towards_b)
    e = len(v)
    v = np.vstack([v, e_point])
    faces = np.vstack([f[~side], [[a, b, e], [b, c, e], [a, e, c], [a, c, d]]])
    return v, faces, (a, e, c)


def test_t_junctions_on_a_sliver_are_sealed_exactly_not_welded_into_a_fold():
    """so101 parts (benchmark 3-14, 3-18 ``t_junction``): the T-junction patch held a sliver whose apex lies
    within the seam gap of its own base's neighbour edge.  The seal put that apex on the edge beside the
    exact T-vertex (and welded a midpoint to a near end), folding the surface: "passes through itself at 2
    face pairs", then refused at ±70 %.  Exact T-junctions are now split first, each vertex onto its
    nearest edge, never onto its own face: the box comes back exactly."""
    v, f, (a, e, c) = _box_with_a_sliver_side()
    sliver = np.flatnonzero((np.sort(f, axis=1) == np.sort([a, e, c])).all(axis=1))[0]
    mid = {}
    extra = []

    def midpoint(p, q):
        key = (min(p, q), max(p, q))
        if key not in mid:
            mid[key] = len(v) + len(extra)
            extra.append(0.5 * (v[p] + v[q]))
        return mid[key]

    ab, bc, ca = midpoint(a, e), midpoint(e, c), midpoint(c, a)
    fine = [[a, ab, ca], [ab, e, bc], [ca, bc, c], [ab, bc, ca]]
    split_v = np.vstack([v, extra])
    split_f = np.vstack([np.delete(f, sliver, axis=0), fine])
    truth = volume_moments(v, f)
    assert truth.volume == pytest.approx(6.0, rel=1e-12)
    with pytest.warns(MeshRepairedWarning):
        p = mass_properties((split_v, split_f), density=1.0, repair=True)
    assert p.mass == pytest.approx(6.0, rel=1e-12)
    u = p.mesh.uncertainty
    assert u is None or u.mass < 1e-12
