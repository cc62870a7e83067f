"""Adversarial review 7 (issue 21, target 4: zero silent wrong answers) of the rules the last sessions added.

* the fourth hole assumption (``mesh/holes.py``, :func:`~inertia_tool.mesh.holes.convex_hole_bound`): where what
  remains of a surface with holes is convex, the part is taken to be convex too;
* R3b through T-vertices (``mesh/sheets.py``, ``_seamed_sheet``): a cut face kept inside a part whose rim meets
  the other half only at T-vertices;
* R4's reading of a body wound outward wholly inside another (``mesh/certify.py``, ``misread_reading``): exact
  when the turned surface is proven, else an estimate whose bounds span both readings;
* real files (trimesh's models, Gazebo's and Menagerie's meshes, when present on this machine) with random
  damage that keeps the solid, checked against the undamaged file's exact values.

Truths come from code independent of the rule under test: exact rationals over the intended solid's
tetrahedra (``adversary_solids.truth_from_pieces``), manifold3d's booleans, or the undamaged file's exact
integral.  The rule is the one of ``tests/test_adversarial_solids.py``: an answer labelled ``exact`` or
``united`` within 1e-9 of the truth, an ``estimate`` within its own bounds, or a refusal.  Failures found are
kept below as strict-xfail reproducers whose reason names the rule at fault.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import adversary_solids as S
from conftest import HAVE_ACCEL
from solids import edge_neighbours, grown_patch, split_at_edge_points
from test_mesh_intersect_patches import _check
from test_mesh_sheets import _cut_in_two

FAST = settings(max_examples=10, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def _verdict(v, f, truth, recipe="", repair=False):
    """The adversarial harness's verdict on ``(v, f)`` against ``truth`` (an ``adversary_solids.Truth``)."""
    case = S.Case("review7", np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64), truth, recipe)
    return S.judge_truth(case, truth, repair=repair)


def _assert_honest(verdict, recipe=""):
    assert verdict.label != "crashed", f"{recipe}: {verdict.wrong}"
    assert not S.silent(verdict), f"silent wrong answer ({verdict.label}) on {recipe}: {verdict.wrong}"
    return verdict


# -------------------------------------------------------------------- the fourth hole assumption (convex)
def _dented_sphere(subdivisions, depth):
    """An icosphere of radius 1 whose vertex 0 is pushed in by ``depth`` (a dent, the part no longer convex), and
    the same surface with the dent's faces (vertex 0's ring) removed: what remains is convex."""
    v, f = S.icosphere(1.0, subdivisions)
    v = v.copy()
    v[0] *= 1.0 - depth
    truth = S.truth_from_pieces([(1, (v, f))])
    return v, f[~np.any(f == 0, axis=1)], truth


def test_a_dent_taken_whole_is_an_estimate_conditional_on_the_convex_assumption_which_fails():
    """Icosphere (3 subdivisions, radius 1) with one vertex pushed in by 0.05 (a dimple 5 % of the radius deep,
    inside the ball over its rim) and the dimple's six faces removed.  The rest is convex, so the fourth
    assumption takes the part to be convex: stated ±5.7e-5 of the mass, found 1.47e-4 off (centre of mass
    1.44e-4 m off, bound 5.8e-5 m).  Without the convex bound the ball bound, ±9.7e-4, holds.

    holes7 (was a strict xfail): the file cannot tell this from the octahedron less a face (pinned at ±25 % by
    ``test_hole_bounds``), so by the lead's decision on issue 21 the answer is an estimate whose bound is stated
    conditional on the named assumption, and the test checks that the assumption named is the one that fails:
    the part is not convex (the dent's vertex lies inside the hull of the others), while the ball over the rim
    does hold the missing dent."""
    from scipy.spatial import ConvexHull

    from inertia_tool.integrals import volume_moments
    from inertia_tool.mesh.hole_assumptions import CONVEX
    from inertia_tool.mesh.holes import patched_estimate
    from inertia_tool.mesh.rims import boundary_edges, enclosing_balls

    v, f, truth = _dented_sphere(3, 0.05)
    est = patched_estimate(v, f, volume_moments)
    assert est.assumptions == ("convex",)
    assert CONVEX.statement in est.detail
    assert abs(est.volume - truth.volume) > est.uncertainty.mass * est.volume     # the conditional bound misses
    hull = ConvexHull(v)
    assert 0 not in hull.vertices and hull.volume > truth.volume * (1 + 1e-5)     # the part is not convex
    rim = np.unique(boundary_edges(f, len(v)))
    centre, radius = enclosing_balls(v[rim], np.zeros(len(rim), dtype=np.int64), 1)
    assert np.linalg.norm(v[0] - centre[0]) <= radius[0]                          # the ball does hold the dent
    verdict = _verdict(v, f, truth, "icosphere(3) dented 0.05 at vertex 0, dent's ring removed", repair=True)
    assert verdict.label == "estimate"


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), share=st.floats(0.02, 0.4))
def test_holes_in_a_convex_part_stay_inside_the_convex_hole_bound(seed, share):
    """Where the fourth assumption holds (the part is convex: a random polytope, moved at random), the bound
    holds: a connected patch of faces removed (up to 40 % of them), repair=True, truth the closed polytope."""
    from solids import random_convex

    solid = random_convex(seed % 100_000, n=int(10 + seed % 40))
    v, f = solid.vertices, solid.faces
    rng = np.random.default_rng(seed)
    truth = S.truth_from_pieces([(1, (v, f))])
    patch = _patch(f, int(rng.integers(len(f))), max(1, int(share * len(f))))
    keep = np.ones(len(f), dtype=bool)
    keep[patch] = False
    _assert_honest(_verdict(v, f[keep], truth, f"random_convex({seed}) less {len(patch)} faces", repair=True))


def _patch(f, start, size):
    """Up to ``size`` faces grown breadth-first from ``start`` through shared edges (indices into ``f``)."""
    return grown_patch(edge_neighbours(f), start, size)


# ------------------------------------------------------------------------ R3b through T-vertices (seams)
def _solid(rng, shape):
    """A manifold3d solid of a named shape, turned and moved at random (sometimes far from the origin, sometimes
    scaled to a millimetre or a kilometre): ``box``, ``union`` (two or three boxes), ``ushape`` (a box less a
    box through one side: a cut plane may meet it in two regions), ``hollow`` (a box with a box cavity),
    ``cylinder``, ``sphere``, ``torus``."""
    import manifold3d as m3d

    e = rng.uniform(0.5, 2.0, size=3)
    if shape == "box":
        solid = m3d.Manifold.cube(tuple(e))
    elif shape == "union":
        solid = m3d.Manifold.cube(tuple(e))
        for _ in range(int(rng.integers(1, 3))):
            solid = solid + m3d.Manifold.cube(tuple(rng.uniform(0.3, 1.5, size=3))).translate(
                tuple(rng.uniform(0.1, 0.9, size=3) * e))
    elif shape == "ushape":
        solid = m3d.Manifold.cube(tuple(e)) - m3d.Manifold.cube((e[0] / 3, e[1] * 2, e[2] * 0.7)).translate(
            (e[0] / 3, -e[1] / 2, e[2] * 0.4))
    elif shape == "hollow":
        solid = m3d.Manifold.cube(tuple(e)) - m3d.Manifold.cube(tuple(e * 0.6)).translate(tuple(e * 0.2))
    elif shape == "cylinder":
        solid = m3d.Manifold.cylinder(float(e[2]), float(e[0] / 2), float(e[0] / 2), int(rng.integers(5, 24)))
    elif shape == "sphere":
        solid = m3d.Manifold.sphere(float(e[0] / 2), int(rng.integers(8, 24)))
    else:
        v, f = S.torus(float(e[0]), float(e[0]) * rng.uniform(0.15, 0.45), int(rng.integers(6, 16)),
                       int(rng.integers(4, 9)))
        solid = S.to_manifold((v, f))
    solid = solid.rotate(tuple(rng.uniform(0, 360, size=3)))
    scale = float(rng.choice([1e-3, 1.0, 1.0, 1.0, 1e3]))
    far = float(rng.choice([0.0, 3.0, 3.0, 1e3]))
    solid = solid.scale((scale, scale, scale)).translate(tuple(rng.uniform(-1, 1, size=3) * far * scale))
    mesh = solid.to_mesh64()
    return np.array(mesh.vert_properties, dtype=np.float64)[:, :3].copy(), np.array(mesh.tri_verts, dtype=np.int64)


def _rim(hf, on):
    """Directed rim edges of the cut faces ``hf[on]`` (used by one cut face and not back)."""
    cut = {(int(x), int(y)) for tri in hf[on].tolist() for x, y in zip(tri, tri[1:] + tri[:1])}
    return sorted((x, y) for x, y in cut if (y, x) not in cut)


def _t_vertices(hv, hf, on, rng, share, ends):
    """Points put on about ``share`` of the rim edges of one half (every face holding such an edge fanned
    through them, so the half stays closed by index): 1-5 points at fractions drawn uniformly in (0.05, 0.95),
    or with ``ends`` log-uniformly from 1e-9 to 0.5 of either end.  Float: off the edge by rounding.  Returns
    vertices, faces, cut-face mask and the number of points."""
    holder: dict[tuple[int, int], list[int]] = {}
    for i, tri in enumerate(hf.tolist()):
        for x, y in zip(tri, tri[1:] + tri[:1]):
            holder.setdefault((min(x, y), max(x, y)), []).append(i)
    chosen, busy = [], set()
    for x, y in _rim(hf, on):                         # each face on at most one chosen edge
        faces = holder[(min(x, y), max(x, y))]
        if rng.random() < share and not busy.intersection(faces):
            chosen.append((x, y))
            busy.update(faces)
    verts, n, inner = [hv], len(hv), {}
    for p, q in chosen:
        k = int(rng.integers(1, 6))
        if ends:
            ts = np.exp(rng.uniform(np.log(1e-9), np.log(0.5), size=k))
            ts = np.where(rng.random(k) < 0.5, ts, 1.0 - ts)
        else:
            ts = rng.uniform(0.05, 0.95, size=k)
        ts = np.unique(ts)
        pts = hv[p] + ts[:, None] * (hv[q] - hv[p])
        keep = np.any(pts != hv[p], axis=1) & np.any(pts != hv[q], axis=1)
        pts = np.unique(pts[keep], axis=0)
        if not len(pts):
            continue
        order = np.argsort((pts - hv[p]) @ (hv[q] - hv[p]))
        inner[(p, q)] = list(range(n, n + len(pts)))
        verts.append(pts[order])
        n += len(pts)
    rows, source = split_at_edge_points(hf, inner)
    new_on = np.asarray(on, dtype=bool)[np.asarray(source, dtype=np.int64)]
    return np.vstack(verts), np.array(rows, dtype=np.int64), np.array(new_on, dtype=bool), n - len(hv)


def _seamed_case(seed, shape, along, share, which, ends):
    """A random solid cut by a random plane (manifold3d), joined again with half A's cut face kept inside and
    half B's left out, T-vertices on the rim of A (``which`` 0), B (1) or both (2), welded bit-exactly; with the
    exact truth of the two closed halves.  None when the cut does not give two halves with cut faces."""
    rng = np.random.default_rng(seed)
    v, f = _solid(rng, shape)
    cut = _cut_in_two(v, f, rng, along)
    if cut is None:
        return None
    _, _, (av, af, on_a), (bv, bf, on_b) = cut
    points = 0
    if which in (0, 2):
        av, af, on_a, k = _t_vertices(av, af, on_a, rng, share, ends)
        points += k
    if which in (1, 2):
        bv, bf, on_b, k = _t_vertices(bv, bf, on_b, rng, share, ends)
        points += k
    truth = S.truth_from_pieces([(1, (av, af)), (1, (bv, bf))])
    dv, df = S._weld_exact(np.vstack([av, bv]), np.vstack([af, bf[~on_b] + len(av)]))
    recipe = (f"_seamed_case({seed}, {shape!r}, {along!r}, {share!r}, {which}, {ends}): {points} T-vertices, "
              f"{len(df)} faces")
    return dv, df, truth, recipe, points


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1),
       shape=st.sampled_from(["box", "union", "ushape", "hollow", "cylinder", "sphere", "torus"]),
       along=st.floats(0.03, 0.97), share=st.floats(0.1, 1.0), which=st.integers(0, 2), ends=st.booleans())
def test_seamed_sheets_of_generated_parts_are_never_wrong(seed, shape, along, share, which, ends):
    """R3b through T-vertices on parts the rule's own tests do not draw (non-convex cuts meeting the part in
    several regions, hollow parts whose cut is an annulus, curved parts, tori, T-vertices a hair from an edge's
    end, millimetre and kilometre parts far from the origin): exact and right, an estimate within its bounds, or
    refused; with and without repair."""
    case = _seamed_case(seed, shape, along, share, which, ends)
    if case is None:
        return
    dv, df, truth, recipe, _ = case
    for repair in (False, True):
        _assert_honest(_verdict(dv, df, truth, recipe, repair=repair), recipe)


# ------------------------------------------------------- R4: a body wound outward wholly inside another
def _standing(rng, kind, floor_z, span):
    """An outward body of ``kind`` standing on the plane z = ``floor_z`` (its lowest corners exactly on it) inside
    the square |x|, |y| < ``span`` (a flat bottom for ``box`` and ``cylinder``; a point or an edge for the others)."""
    size = float(rng.uniform(0.15, 0.45)) * span
    if kind == "box":
        v, f = S.box(rng.uniform(0.3, 1.0, size=3) * size)
    elif kind == "cylinder":
        v, f = S.cylinder(size / 2, float(rng.uniform(0.3, 1.0)) * size, int(rng.integers(5, 17)))
    elif kind == "icosphere":
        v, f = S.icosphere(size / 2, int(rng.integers(0, 2)))
        v = v @ S.random_rotation(rng).T
    else:
        name, (v, f) = S.random_piece(rng, convex=True)
        v = v / float(np.ptp(v, axis=0).max()) * size
    v = v - [0.0, 0.0, float(v[:, 2].min())]                 # the lowest corners land exactly on z = 0
    xy = rng.uniform(-1, 1, size=2) * (span - size)
    return v + [float(xy[0]), float(xy[1]), float(floor_z)], f


def _misread_case(seed, inner_kind, outer_kind, core, second, motion, holed=False):
    """A 2 m outer body (a box, or a 16-sided prism) with an outward body standing on its floor (R4 reads it as a
    cavity; in a box, a third of the time pushed into a corner, flush with two walls as well), optionally a core
    inside that one (a body again by nesting depth) and a second outward body free inside; moved by ``motion``
    ("none", a right-angle rotation with a dyadic shift, a random rotation, or far); with ``holed``, the outer box's
    faces split in 16 and one of them removed (a hole for repair).  Returns the mesh, the parity truth, the union
    truth and a recipe."""
    rng = np.random.default_rng(seed)
    outer = S.box([2.0, 2.0, 2.0], subdivide=2 if holed else 0) if outer_kind == "box" else S.cylinder(1.0, 2.0, 16)
    span = 0.95 if outer_kind == "box" else 0.65
    inner = _standing(rng, inner_kind, -1.0, span)
    if outer_kind == "box" and rng.random() < 0.3:        # pushed into a corner: flush with two walls too
        iv, fi = inner
        iv = iv.copy()
        for axis in (0, 1):
            top = iv[:, axis].max()
            iv[:, axis] = np.where(iv[:, axis] == top, 1.0, iv[:, axis] + (1.0 - top))
        inner = (iv, fi)
    pieces = [(1, outer), (-1, inner)]
    bodies = [outer, inner]
    if core:
        iv, fi = inner
        centre = iv.mean(axis=0)
        reach = float(np.min(np.abs(iv - centre))) if inner_kind == "box" else 0.0
        small = S.box([max(reach, 1e-3) * 0.5] * 3, centre) if reach > 1e-3 else None
        if small is not None:
            pieces.append((1, small))
            bodies.append(small)
    if second:
        free = S.icosphere(0.12, 1)
        spot = np.array([0.0, 0.0, 0.7])
        free = (free[0] + spot, free[1])
        pieces.append((-1, free))
        bodies.append(free)
    if motion == "right":
        rot, shift = S.right_angle_rotation(rng), rng.integers(-8, 9, size=3) * 0.125
    elif motion == "generic":
        rot, shift = S.random_rotation(rng), rng.normal(size=3)
    elif motion == "far":
        rot, shift = S.random_rotation(rng), rng.normal(size=3) * 1000.0
    else:
        rot, shift = np.eye(3), np.zeros(3)
    moved = [S.moved(b, rot, shift) for b in bodies]
    signed = [(sign, S.moved(p, rot, shift)) for sign, p in pieces]
    v, f = S.concat(*moved)
    parity = S.truth_from_pieces(signed)
    union = S.truth_from_pieces([signed[0]])
    if holed:
        f = np.delete(f, int(rng.integers(len(outer[1]))), axis=0)
    recipe = f"_misread_case({seed}, {inner_kind!r}, {outer_kind!r}, {core}, {second}, {motion!r}, {holed})"
    return v, f, parity, union, recipe


def _judge_misread(v, f, parity, union, recipe, repair=False):
    """R4's rule for a body wound outward inside another (session 16): every shell here is wound outward, so no
    region's winding is below 0 and the file's winding stands: proven only as the union (the outer body); an
    estimate's bounds hold the union, and both readings where it is R4's estimate for crossing shells (without
    repair); or refused / unverified.  (Before session 16: proven only as the parity solid.)"""
    case = S.Case("review7", v, f, union, recipe)
    to_union = S.judge_truth(case, union, repair)
    assert to_union.label != "crashed", f"{recipe}: {to_union.wrong}"
    if to_union.label == "estimate":
        assert to_union.wrong is None, f"{recipe}: the estimate's bounds must hold the union: {to_union.wrong}"
        if not repair:
            to_parity = S.judge_truth(case, parity, repair)
            assert to_parity.wrong is None, f"{recipe}: R4's estimate must span both readings: {to_parity.wrong}"
    elif to_union.label in S.PROVEN:
        assert to_union.wrong is None, f"{recipe}: {to_union.label} but not the union: {to_union.wrong}"
    return to_union.label


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), inner_kind=st.sampled_from(["box", "cylinder", "icosphere", "piece"]),
       outer_kind=st.sampled_from(["box", "prism"]), core=st.booleans(), second=st.booleans(),
       motion=st.sampled_from(["none", "right", "generic", "far"]))
def test_an_outward_body_standing_inside_another_is_never_wrong(seed, inner_kind, outer_kind, core, second,
                                                                   motion):
    """R4's misread-nesting reading on bodies the rule's own tests do not draw: prisms, icospheres and parts
    standing on the floor of a box or of a prism (flush, on an edge or on a point), with a core inside (a body
    again by depth) and a second outward body free inside, turned exactly, generically or far from the origin."""
    _judge_misread(*_misread_case(seed, inner_kind, outer_kind, core, second, motion))


# ------------------------------------------------------------ the slab (second hole assumption) unchecked
def _fan(v_index, pts, normal, faces):
    """Append the fan of the convex planar polygon ``pts`` to ``faces``, each triangle wound to face ``normal``."""
    ids = [v_index(p) for p in pts]
    for i in range(1, len(ids) - 1):
        tri = [ids[0], ids[i], ids[i + 1]]
        a, b, c = (np.asarray(pts[k], dtype=float) for k in (0, i, i + 1))
        faces.append(tri if np.dot(np.cross(b - a, c - a), normal) > 0 else tri[::-1])


def _box_with_a_boss(height=0.5, pocket=False):
    """A 4 × 2 × 1 box tessellated as CAD exports do (vertices only on the loops of its flat faces): its top has an
    outer loop of six corners ((2, 0, 1) and (2, 2, 1) on its long edges, where the sides are split) and an inner
    loop, the footprint [2.5, 3.5] × [0.5, 1.5] of a boss ``height`` high (or, with ``pocket``, a pocket as deep).
    Returns vertices, faces, the mask of the faces a hole takes (the top's faces at the footprint and the feature:
    the rim is the rectangle (2, 0)–(4, 0)–(4, 2)–(2, 2), on the outer loop) and the exact truth."""
    where: dict[tuple[float, float, float], int] = {}
    corners: list[tuple[float, float, float]] = []

    def index(p):
        key = tuple(float(x) for x in p)
        if key not in where:
            where[key] = len(corners)
            corners.append(key)
        return where[key]

    faces: list[list[int]] = []
    _fan(index, [(0, 0, 0), (4, 0, 0), (4, 2, 0), (0, 2, 0)], (0, 0, -1), faces)
    _fan(index, [(0, 0, 0), (4, 0, 0), (4, 0, 1), (2, 0, 1), (0, 0, 1)], (0, -1, 0), faces)
    _fan(index, [(0, 2, 0), (4, 2, 0), (4, 2, 1), (2, 2, 1), (0, 2, 1)], (0, 1, 0), faces)
    _fan(index, [(0, 0, 0), (0, 2, 0), (0, 2, 1), (0, 0, 1)], (-1, 0, 0), faces)
    _fan(index, [(4, 0, 0), (4, 2, 0), (4, 2, 1), (4, 0, 1)], (1, 0, 0), faces)
    _fan(index, [(0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)], (0, 0, 1), faces)
    first = len(faces)
    outer = [(2, 0, 1), (4, 0, 1), (4, 2, 1), (2, 2, 1)]
    inner = [(2.5, 0.5, 1), (3.5, 0.5, 1), (3.5, 1.5, 1), (2.5, 1.5, 1)]
    for k in range(4):
        _fan(index, [outer[k], outer[(k + 1) % 4], inner[(k + 1) % 4], inner[k]], (0, 0, 1), faces)
    z = 1 - height if pocket else 1 + height
    lid = [(x, y, z) for x, y, _ in inner]
    for k in range(4):
        a, b = inner[k], inner[(k + 1) % 4]
        out = np.cross(np.subtract(b, a), (0, 0, 1)) * (-1 if pocket else 1)
        _fan(index, [a, b, lid[(k + 1) % 4], lid[k]], out, faces)
    _fan(index, lid, (0, 0, 1), faces)                # the boss's top or the pocket's floor: facing up
    v, f = np.array(corners, dtype=np.float64), np.array(faces, dtype=np.int64)
    hole = np.zeros(len(f), dtype=bool)
    hole[first:] = True
    return v, f, hole, S.truth_from_pieces([(1, (v, f))])


def test_the_box_with_a_boss_is_closed_and_exact():
    """The builder's surface is closed and read exact (8 ± 0.5 m³), so the hole test below tests the hole rule."""
    for pocket in (False, True):
        v, f, _, truth = _box_with_a_boss(pocket=pocket)
        assert truth.volume == (7.5 if pocket else 8.5)
        assert _verdict(v, f, truth).label == "exact"


@pytest.mark.parametrize("pocket", [False, True])
def test_a_feature_taken_whole_inside_a_rim_on_the_outer_loop_names_the_flat_assumption_that_fails(pocket):
    """The box with a boss (or pocket) 0.5 m high, its top's faces at the footprint and the feature removed: the
    patch closes the top flat (8 m³), stated within ±2.2e-14, truth 8.5 m³ (5.9 % off; the pocket 7.5 m³, 6.7 %).
    The rim (2, 0)-(4, 0)-(4, 2)-(2, 2) lies in the top's plane, and the top's remaining faces beside it put the
    slab's width at round-off; the rim's corners all keep a side face, so ``slab_contradicted`` (a rim vertex
    whose faces all lie in the plane) does not fire, and the hole is no island (``rim_evidence``).  On a CAD
    tessellation the feature's footprint vertices went with the hole: nothing in the file confirms the slab.

    holes7 (was a strict xfail): the file shows the same evidence as a missing triangle of a flat face
    (``test_hole_bounds.test_missing_triangle_of_a_flat_face…``), so by the lead's decision on issue 21 the answer
    is an estimate (never exact) whose bound is stated conditional on the flat face continuing across the hole
    (``hole_assumptions.FLAT``, printed among the notes).  The test checks that this named assumption is the one
    that fails here: the faces the hole took leave the top's plane by the feature's height, far past the slab."""
    import warnings

    from inertia_tool import mass_properties
    from inertia_tool.integrals import volume_moments
    from inertia_tool.mesh.hole_assumptions import FLAT
    from inertia_tool.mesh.holes import patched_estimate

    v, f, hole, truth = _box_with_a_boss(pocket=pocket)
    est = patched_estimate(v, f[~hole], volume_moments)
    assert "flat" in est.assumptions and FLAT.statement in est.detail
    assert est.uncertainty.volume_in_doubt < 1e-12                         # the slab: round-off wide
    assert abs(est.volume - truth.volume) == pytest.approx(0.5)            # the conditional bound misses
    taken = v[f[hole]].reshape(-1, 3)
    assert np.max(np.abs(taken[:, 2] - 1.0)) == pytest.approx(0.5)          # the flat assumption fails by 0.5 m
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = mass_properties((v, f[~hole]), density=1.0, repair=True)
    assert p.mesh.certificate.kind == "estimate"
    assert any(FLAT.statement in note for note in p.mesh.notes)


# --------------------------------------------------- the face-pair check's certified patches: pinches
@st.composite
def pinched_grids(draw):
    """A sheet of up to 16 up-facing triangles on a lattice grid (2-4 × 2-4 cells, each split along a random
    diagonal) with random cells removed, so that the boundary chain passes a corner where two removed cells
    meet diagonally twice (a pinch), round holes, or touches itself; the corners jittered by up to ``reach``
    lattice steps in x and y (neighbouring triangles may then overlap in projection, still counterclockwise
    seen from +z: condition (1) holds and only the chain rule decides), heights on lattice steps or one ulp
    apart, and sometimes a corner split into two indices at the same point (a crack through a pinch)."""
    ulp = float(np.nextafter(1.0, 2.0))
    nx, ny = draw(st.integers(2, 4)), draw(st.integers(2, 4))
    reach = draw(st.sampled_from([0, 1, 3, 5]))
    v = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            dx, dy = draw(st.integers(-reach, reach)), draw(st.integers(-reach, reach))
            v.append([float(4 * i + dx), float(4 * j + dy), draw(st.sampled_from([0.0, 1.0, -1.0, ulp, 0.5]))])
    idx = lambda i, j: j * (nx + 1) + i                      # noqa: E731
    faces = []
    for j in range(ny):
        for i in range(nx):
            if draw(st.integers(0, 9)) < 3:
                continue                                  # a removed cell
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            faces += [[a, b, c], [a, c, d]] if draw(st.booleans()) else [[a, b, d], [b, c, d]]
    faces = faces[:16]
    keep = []
    for tri in faces:
        (ax, ay, _), (bx, by, _), (cx, cy, _) = (v[k] for k in tri)
        if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0:     # exact on the integer lattice
            keep.append(tri)
    if draw(st.booleans()) and keep:
        corner = draw(st.sampled_from(sorted({k for tri in keep for k in tri})))
        v.append(list(v[corner]))
        for tri in keep[: len(keep) // 2]:
            tri[:] = [len(v) - 1 if k == corner else k for k in tri]
    if len(keep) < 2:
        keep = [[0, 1, nx + 2], [0, nx + 2, nx + 1]]
    return np.array(v, dtype=float), np.array(keep, dtype=np.int64)


@pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")
@settings(max_examples=30, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(pinched_grids())
def test_pinched_grids_match_brute_force(mesh):
    """The C scan with its certified patches finds, pair for pair, what the unpatched scan, the numpy twin and the
    rational all-pairs classifier find, on jittered grid sheets with pinches (``pinched_grids``)."""
    v, f = mesh
    fast, unpatched = _check(v, f, brute=True)
    event("certified" if fast.candidate_pairs < unpatched.candidate_pairs else "not certified")
    event("crossing found" if len(fast.crossing) else "no crossing")


# ------------------------------------------------------------------- real files with random damage
def _real_files_module():
    import importlib.util
    import sys
    from pathlib import Path

    if "damage_real_files" in sys.modules:
        return sys.modules["damage_real_files"]
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "damage" / "real_files.py"
    spec = importlib.util.spec_from_file_location("damage_real_files", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["damage_real_files"] = module
    spec.loader.exec_module(module)
    return module


def _repo_sources():
    rf = _real_files_module()
    out = []
    for name, v, f in rf.cov.repo_sources():
        truth = rf.cov.truth_of(v, f)
        if truth is not None and len(f) <= 4000:
            out.append((name, v, f, truth))
    return out


def _assert_rows_honest(rows):
    for row in rows:
        assert row["status"] != "error", row
        assert row.get("holds") is not False, row


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["duplicate", "flipped", "flip_patch", "touching_translate", "t_junction",
                                  "sliver", "hole"])
def test_repository_meshes_with_damage_that_keeps_the_solid(kind):
    """Each repository mesh (clean, exact) damaged once by ``kind`` (benchmarks/damage/real_files.py; a third of
    them quantised first): every answer, with and without repair, right within its certificate or refused."""
    rf = _real_files_module()
    for s, source in enumerate(_repo_sources()):
        _assert_rows_honest(rf.run_case(source, kind, [707, s, len(kind)]))


def test_real_files_from_the_environment():
    """``INERTIA_TOOL_REAL_MESHES`` (folders, separated by the path separator; unset: skipped): a seeded sample of
    the clean closed files there, each damaged once by every kind of ``real_files.py``."""
    import os

    roots = [r for r in os.environ.get("INERTIA_TOOL_REAL_MESHES", "").split(os.pathsep) if r]
    if not roots:
        pytest.skip("INERTIA_TOOL_REAL_MESHES is not set")
    rf = _real_files_module()
    count = int(os.environ.get("INERTIA_TOOL_REAL_MESHES_COUNT", "5"))
    sources = rf.find_sources(roots, 3000, np.random.default_rng(7), count)
    for s, source in enumerate(sources):
        for k, kind in enumerate(rf.cov.KINDS + rf.EXTRA_KINDS):
            _assert_rows_honest(rf.run_case(source, kind, [708, s, k]))


def test_a_misread_body_inside_a_part_with_a_hole_spans_both_readings():
    """Regression (review 7, certify): a 2 m box (faces split in 16, one removed) with a 0.8 m box wound outward
    standing on its floor, turned at random (the floors meet only to rounding).  Then R4 answered an estimate
    spanning the parity solid (7.488 m³) and the union (8 m³); with the hole, repair's estimate kept only the
    patch's bound (±0.31 %) and dropped R4's: the union reading lay 6.4 % outside.  Session 16: the file's winding
    stands (1 and 2), so the inner box is left out and the estimate's bound, the patch's, holds the union."""
    outer = S.box([2.0, 2.0, 2.0], subdivide=3)
    inner = S.box([0.8, 0.8, 0.8], [0.0, 0.0, -0.6])
    rot = S.random_rotation(np.random.default_rng(1))
    outer, inner = S.moved(outer, rot, np.zeros(3)), S.moved(inner, rot, np.zeros(3))
    v, f = S.concat(outer, inner)
    parity = S.truth_from_pieces([(1, outer), (-1, inner)])
    union = S.truth_from_pieces([(1, outer)])
    assert _judge_misread(v, np.delete(f, 5, axis=0), parity, union, "box in a holed box, turned", repair=True) \
        == "estimate"


@pytest.mark.slow
@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), inner_kind=st.sampled_from(["box", "cylinder", "icosphere", "piece"]),
       core=st.booleans(), second=st.booleans(), motion=st.sampled_from(["generic", "far"]))
def test_a_misread_body_inside_a_holed_part_is_never_wrong(seed, inner_kind, core, second, motion):
    """As the generator above with a hole in the outer box and repair: an estimate spans both readings."""
    _judge_misread(*_misread_case(seed, inner_kind, "box", core, second, motion, holed=True), repair=True)


# ---------------------------------------------- R0 / R4: a misread body listed twice, the copy not merged
@pytest.mark.parametrize("shift", [1e-13, 1e-9])
def test_a_body_wound_outward_inside_another_listed_twice_is_never_united(shift):
    """A 2 m box with a 0.5 m box wound outward inside it, the inner box listed twice, the copy moved by ``shift``
    (1e-13: beyond R0's corner match of 64 ulp, within rounding of an export).  Listed once, R4 reads the inner box
    as a cavity (7.875 m³, exact, the union named in a warning).  Listed twice, the copies cross each other: R4
    gave them no nesting depth and the boolean united all three, 8 m³ certified ``united`` (1.6 % off the parity
    reading, which R4 says the file does not decide).  Found by this review; fixed on main meanwhile (the group
    of crossing copies probed for its depth past the copies): a regression test."""
    outer, inner = S.box([2.0, 2.0, 2.0]), S.box([0.5, 0.5, 0.5])
    copy = (inner[0] + shift, inner[1])
    v, f = S.concat(outer, inner, copy)
    parity = S.truth_from_pieces([(1, outer), (-1, inner)])
    union = S.truth_from_pieces([(1, outer)])
    _judge_misread(v, f, parity, union, f"outer box, inner box outward listed twice, copy moved {shift}")


def test_bench_adversarial_seed_7007_case_7168():
    """The one silent wrong answer of ``bench_adversarial.py --seed 7007 --cases 10000``: a 16-sided prism (wound
    inward) with a small box inside (wound outward: a cavity by depth), moved 2,900 m from the origin, the whole nest
    listed twice with coordinates rounded apart (2.3e-13 m).  R0 counts the prism's copy once but not the box's;
    the two boxes cross, and the boolean united them with the prism: 0.6101 m³ certified united, truth 0.6082
    (0.31 % high).  Fixed on main meanwhile: a regression test."""
    case = S.make_case("duplicated", np.random.default_rng([7007, 7168]))
    assert "the whole nest duplicated" in case.recipe
    _assert_honest(S.judge(case), case.recipe)


# ------------------------------- a body and its inverted copy rounded apart, sharing a corner: crashes
_BOX = [[-0.8787160378112229, -1.7726153956802853, 0.6062915938982375],
        [-0.8787160378112229, -1.7726153956802853, 2.41997827530728],
        [-0.8787160378112229, -1.1156383150843927, 0.6062915938982375],
        [-0.8787160378112229, -1.1156383150843927, 2.41997827530728],
        [0.8787160378112229, -1.7726153956802853, 0.6062915938982375],
        [0.8787160378112229, -1.7726153956802853, 2.41997827530728],
        [0.8787160378112229, -1.1156383150843927, 0.6062915938982375],
        [0.8787160378112229, -1.1156383150843927, 2.41997827530728]]
#: The box's copy turned about its corner 0 by a rotation that rounds to a few ulp (two draws of
#: test_mesh_certificate's ``scenes``, mode "shared-vertex", seed 7007 with INERTIA_TOOL_HYPOTHESIS_SCALE=10).
_COPIES = {
    "ValueError": [[-0.8787160378112229, -1.7726153956802853, 0.6062915938982375],
                   [-0.8787160378112217, -1.7726153956802846, 2.41997827530728],
                   [-0.8787160378112224, -1.1156383150843927, 0.6062915938982373],
                   [-0.8787160378112212, -1.115638315084392, 2.4199782753072796],
                   [0.8787160378112229, -1.7726153956802864, 0.6062915938982363],
                   [0.8787160378112242, -1.7726153956802855, 2.4199782753072787],
                   [0.8787160378112233, -1.1156383150843938, 0.6062915938982361],
                   [0.8787160378112246, -1.115638315084393, 2.4199782753072783]],
    "UsageError": [[-0.8787160378112229, -1.7726153956802853, 0.6062915938982375],
                   [-0.8787160378112229, -1.7726153956802866, 2.41997827530728],
                   [-0.8787160378112224, -1.1156383150843927, 0.606291593898238],
                   [-0.8787160378112224, -1.115638315084394, 2.4199782753072805],
                   [0.8787160378112229, -1.7726153956802864, 0.6062915938982375],
                   [0.8787160378112229, -1.7726153956802877, 2.41997827530728],
                   [0.8787160378112233, -1.1156383150843938, 0.606291593898238],
                   [0.8787160378112233, -1.1156383150843951, 2.4199782753072805]],
}


@pytest.mark.parametrize("found", sorted(_COPIES))
def test_a_body_with_its_inverted_copy_rounded_apart_is_refused_not_a_crash(found):
    """A 1.76 × 0.66 × 1.81 m box and its inverted copy, the copy's corners a few ulp from the box's (turned about
    the shared corner 0 by a rotation that rounds to almost nothing), corner 0 shared by index: the two cancel
    (winding number 0 but for slivers of rounding).  Listed exactly, R0 refuses it ("cancel to nothing"); rounded
    apart, ``mass_properties`` raised ``ValueError: Expected `sums` as a C-contiguous (n_labels, 11) float64 array``
    or ``UsageError: Expected a positive total mass, got 0.0`` (a traceback at the CLI)."""
    import warnings

    import inertia_tool as it
    from inertia_tool.errors import InvalidMeshError

    box = np.array(_BOX)
    faces = S.box()[1]
    copy = np.array(_COPIES[found])
    v = np.vstack([box, copy])
    f = np.vstack([faces, np.where(faces[:, ::-1] == 0, -8, faces[:, ::-1]) + 8])   # corner 0 shared by index
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InvalidMeshError, match="enclose no material"):
            it.mass_properties((v, f), density=1.0)


# ------------------------------------------------ a seamed wall inside a part with a hole: repair's estimates
@pytest.mark.slow
@pytest.mark.parametrize("args, gone", [
    ((1993102077, "hollow", 0.49037461818697947, 0.21577182756018304, 2, True), [54, 56, 57]),
    ((1596054528, "hollow", 0.5245655717771776, 0.539956890146432, 1, False), [2]),
    ((1453299742, "sphere", 0.7324975718589595, 0.12998286392214461, 0, False), [6, 9]),
    ((872029316, "sphere", 0.9371485979357826, 0.23290742249393626, 0, True), [24, 28]),
])
def test_a_part_with_a_seamed_wall_and_a_hole_stays_inside_its_bound(args, gone):
    """Fixed: the winding estimate forced on the patched surface (R1b, R6) now adds the patches' doubt (as R3's did),
    and faces that orientation turned on the open surface are in doubt too (resolve); three are refused, one answered
    within its bound. Four draws (of 350, 109 of them estimates) of the seamed-sheet generator with one to three
    faces removed (a hole), with repair; without the hole each is exact. A hollow box cut near its middle, one
    half's cut face (a frame round the cavity) kept inside: the union is not formed and the winding-number estimate
    answers 3.7291 m³ within ±14.1 % (truth 4.4431, 16.1 % low), or 1.3445 within ±13.2 % (truth 1.1758, 14.3 %
    high). A millimetre sphere cut near a pole, its cap's cut face kept: 56 faces turned to agree with their
    neighbours, the patch answers 1.041e-9 m³ within ±17.8 % (truth 1.536e-9, 32 % low); a sphere cut near a pole,
    0.16045 m³ within ±0.96 % (truth 0.16348, 1.9 % low)."""
    case = _seamed_case(*args)
    assert case is not None
    dv, df, truth, recipe, _ = case
    _assert_honest(_verdict(dv, np.delete(df, gone, axis=0), truth, f"{recipe}; faces {gone} removed", repair=True),
                   recipe)
