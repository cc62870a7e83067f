"""R3b's early exit (mesh/sheets.py, ``_nothing_to_take``): it may only say "nothing to take" where the full rule
would find nothing, and it must say so on the cases it exists for (a large part with a hole, a soup).

The truth is the rule itself run without the exit (``_nothing_to_take`` replaced by one that never exits), on
hypothesis-generated parts: convex solids with a flat sheet inside (free, or lifted off its plane by a multiple of
the flatness tolerance, around the boundary of what the rule accepts), faces removed at random, a part cut by a
random plane with its cut face kept.
"""

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import sheets
from inertia_tool.mesh.resolve import _census
from inertia_tool.mesh.sheets import MAX_SHEET_PIECES, _nothing_to_take, open_sheets
from inertia_tool.tolerances import WALL_PLANE_RTOL
from solids import random_convex as _convex
from test_mesh_sheets import _polygon_sheet, _with

FAST = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _boundary(v, f):
    return _census(np.asarray(f, dtype=np.int64), len(v)).boundary


def _tolerance(v):
    return WALL_PLANE_RTOL * float(np.abs(v).max())


def _unguarded(v, f):
    with pytest.MonkeyPatch.context() as m:
        m.setattr(sheets, "_nothing_to_take", lambda *args: False)
        return open_sheets(v, f)


def _same(a, b):
    if a is None or b is None:
        return a is None and b is None
    return (np.array_equal(a.faces, b.faces) and (a.inside, a.fins, a.inside_faces, a.fin_faces) ==
            (b.inside, b.fins, b.inside_faces, b.fin_faces) and a.inside_area == b.inside_area)


def _check(v, f):
    """The guarded rule answers as the unguarded one; an exit only where that finds nothing."""
    v, f = np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64)
    boundary = _boundary(v, f)
    truth = _unguarded(v, f)
    exits = _nothing_to_take(v, f, boundary, _tolerance(v), MAX_SHEET_PIECES)
    if exits:
        assert truth is None
    assert _same(open_sheets(v, f, boundary=boundary), truth)
    return exits, truth


def test_a_sphere_with_one_hole_exits_early():
    """The case the exit is for (issue 25 item 3: R3b cost 1.6 s of a 1.3M-face part with one hole)."""
    s = trimesh.creation.icosphere(4, radius=3.0)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    centre = v[f].mean(axis=1)
    keep = np.argsort(np.linalg.norm(centre - centre[0], axis=1))[40:]
    exits, truth = _check(v, f[keep])
    assert exits and truth is None


def test_a_soup_exits_early():
    """Every triangle with its own corners: each an open piece of its own, more than the rule tries."""
    s = trimesh.creation.icosphere(3)
    tri = np.asarray(s.vertices)[np.asarray(s.faces)]
    v, f = tri.reshape(-1, 3), np.arange(3 * len(tri)).reshape(-1, 3)
    assert _nothing_to_take(v, f, None, _tolerance(v), MAX_SHEET_PIECES)
    exits, truth = _check(v, f)
    assert exits and truth is None


def test_a_flat_face_with_a_hole_does_not_exit():
    """A box with a hole in a flat side: every face beside the hole is flat with its neighbours, so the local test
    proves nothing and the rule runs (and finds nothing: the piece is the whole box, bent)."""
    m = trimesh.creation.box([1.0, 2.0, 3.0])
    m = m.subdivide().subdivide().subdivide()
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    centre = v[f].mean(axis=1)
    middle = np.argsort(np.linalg.norm(centre - [0.0, 0.0, 1.5], axis=1))[:2]    # faces beside it: all on top
    exits, truth = _check(v, np.delete(f, middle, axis=0))
    assert not exits and truth is None


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), share=st.floats(0.05, 0.95), lift=st.sampled_from([0.0, 0.5, 0.99, 1.01,
                                                                                             2.0, 1e3]))
def test_a_sheet_inside_lifted_about_the_tolerance(seed, share, lift):
    """A free polygon inside, its fan centre moved off the polygon's plane by ``lift`` times the flatness
    tolerance (the rule takes it up to about 1, the exit must never claim otherwise)."""
    v, f, eq, centre = _convex(seed)
    rng = np.random.default_rng(seed + 1)
    sv, sf = _polygon_sheet(rng, eq, centre, share)
    normal = np.cross(sv[1] - sv[0], sv[2] - sv[0])
    normal /= np.linalg.norm(normal)
    dv, df = _with(v, f, sv, sf)
    dv[len(v)] += lift * _tolerance(dv) * normal
    exits, truth = _check(dv, df)
    if lift == 0.0:
        assert not exits and truth is not None and truth.inside == 1


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), removed=st.integers(1, 6), sheet=st.booleans())
def test_random_holes_with_and_without_a_sheet(seed, removed, sheet):
    """Faces removed at random from a convex part (with a flat sheet inside or not): the exit agrees with the
    rule, whatever it finds."""
    v, f, eq, centre = _convex(seed, n=30)
    rng = np.random.default_rng(seed + 7)
    f = np.delete(f, rng.choice(len(f), size=min(removed, len(f) - 4), replace=False), axis=0)
    if sheet:
        sv, sf = _polygon_sheet(rng, eq, centre, 0.5)
        v, f = _with(v, f, sv, sf)
    _check(v, f)


@pytest.mark.parametrize("seed", range(6))
def test_a_cut_face_kept_inside_does_not_exit(seed):
    """The wall the rule exists for: a part cut in two and joined with one cut face kept (rim on the surface)."""
    from test_mesh_sheets import _fan_cut, _halves, _on_plane

    v, f, _, _ = _convex(seed)
    rng = np.random.default_rng(seed + 2)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    offset = float((v @ normal).min() + 0.5 * np.ptp(v @ normal))
    halves = _halves(v, f, normal, offset)
    if len(halves) != 2:
        pytest.skip("the plane missed the part")
    (av, af), (bv, bf) = halves
    on_a, on_b = _on_plane(av, af, normal, offset), _on_plane(bv, bf, normal, offset)
    fan = _fan_cut(av, af, on_a, rng)
    if fan is None or not on_b.any():
        pytest.skip("no single cut loop")
    uniq, inverse = np.unique(np.vstack([av, bv]), axis=0, return_inverse=True)
    df = inverse.reshape(-1)[np.vstack([af[~on_a], fan, bf[~on_b] + len(av)])]
    exits, truth = _check(uniq, df)
    assert not exits and truth is not None and truth.inside == 1


def test_thousands_of_holes_exit_on_a_sample_of_their_edges():
    """More unbalanced edges than the exit tests (every k-th by key): one witness among them is enough."""
    s = trimesh.creation.icosphere(6)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    f = f[np.random.default_rng(2).random(len(f)) >= 0.1]
    boundary = _boundary(v, f)
    assert len(boundary) > 4 * sheets._GUARD_EDGES
    assert _nothing_to_take(v, f, boundary, _tolerance(v), MAX_SHEET_PIECES)
    assert _unguarded(v, f) is None
