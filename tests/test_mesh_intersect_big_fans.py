"""mesh/intersect.py's C scan on fans too large for the stack paths (section 8 of ``_accel.c``): the star
certificate of a vertex of more than 32 faces (``ct_star_certify``) and the faces across each edge at a vertex
of more than 64 faces (``ct_twin_task``) group the link vertices in a hash table (``ct_vid_table``) instead of a
comparison sort, and the patches' segment sweep sorts inline (``ct_sweep_sort``).  Each must decide what the
sort decided: the same ring (the walk of an open fan starts at its end of smallest vertex id), the same twins
(-1 none, -2 an edge in three faces or run twice one way), the same sweep order.

Every mesh is checked three ways, pair for pair: the C scan as used (stars and patches), the C scan without
patches and without stars, and the numpy twin (an independent certification of the stars, no twins, no
patches); the C scan without patches counts what the numpy twin counts.  The fans are adversarial: folds, fans
winding twice, open fans (one or several paths), a face listed twice either way, a face reversed, a link vertex
in three faces, a second fan through the same apex; and fan-capped cylinders of 65 and 129 sections whose faces
are moved to cross, to touch at a vertex, to fold onto a neighbour (sharing an edge) and to overlap coplanar,
each of which the scan must find, checked pair by pair against the rational classifier
(``intersect_reference.brute_kind``) on the faces moved.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from intersect_reference import NONE, brute_kind, edge_twins, pair_kinds
from inertia_tool import _native
from inertia_tool.mesh.intersect import SurfaceContacts
from contact_scans import fan_capped_cylinder, run_scan, same_pairs


pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


def _check(v, f) -> SurfaceContacts:
    """The C scan as used, after comparing it with the C scan without patches or stars and the numpy twin."""
    fast = run_scan(v, f, accel=True)
    unpatched = run_scan(v, f, accel=True, _patches=False)
    bare = run_scan(v, f, accel=True, _patches=False, _star_faces=0)
    ref = run_scan(v, f, accel=False)
    same_pairs(fast, unpatched)
    same_pairs(fast, bare)
    same_pairs(fast, ref)
    assert (unpatched.candidate_pairs, unpatched.tested_pairs) == (ref.candidate_pairs, ref.tested_pairs)
    assert fast.candidate_pairs <= unpatched.candidate_pairs <= bare.candidate_pairs
    return fast


def _brute(v, f, found: SurfaceContacts, faces) -> None:
    """Every pair holding one of ``faces`` against the rational classifier."""
    got = pair_kinds(found)
    for i in sorted(set(int(x) for x in faces)):
        for j in range(len(f)):
            if j == i:
                continue
            shared = [(a, b) for a in range(3) for b in range(3) if f[i][a] == f[j][b]]
            want = brute_kind(v[f[i]], v[f[j]], shared)
            key = (min(i, j), max(i, j))
            assert got.get(key, NONE) == (NONE if want is None else want), key


def _fan(angles, radii, heights, closed, apex):
    """Vertices (apex first, then the ring) and faces (0, r_i, r_{i+1}) of a fan."""
    ring = np.stack([radii * np.cos(angles), radii * np.sin(angles), heights], axis=1)
    v = np.concatenate([[apex], ring + apex])
    k = len(angles)
    i = np.arange(k if closed else k - 1)
    return v, np.stack([np.zeros_like(i), 1 + i, 1 + (i + 1) % k], axis=1)


@st.composite
def big_fans(draw):
    """A fan of 33-150 faces round an apex (above the stack paths of both the star certificate, 32, and the
    twins, 64), clean or damaged, on a dyadic lattice (exact coincidences) or not."""
    k = draw(st.integers(33, 150))
    closed = draw(st.booleans())
    turns = draw(st.sampled_from([0.6, 1.0, 1.0, 1.0, 2.0]))
    step = 2 * np.pi * turns / (k if closed else k - 1)
    back = np.ones(k)
    if draw(st.booleans()):                                      # steps that go back: a fold
        back[draw(st.integers(1, k - 1))] = draw(st.sampled_from([-0.5, 0.0]))
    theta = np.cumsum(step * back) - step
    radii = np.array(draw(st.lists(st.sampled_from([0.5, 1.0, 2.0]), min_size=k, max_size=k)))
    heights = draw(st.sampled_from([0.0, 0.25])) * np.array(draw(st.lists(st.sampled_from([0.0, 1.0]), min_size=k,
                                                                          max_size=k)))
    v, f = _fan(theta, radii, heights, closed, apex=np.array([1.0, -2.0, 0.5]))
    damage = draw(st.sampled_from(["none", "none", "twice", "twice reversed", "reversed", "three", "paths",
                                   "second fan"]))
    at = draw(st.integers(0, len(f) - 1))
    if damage == "twice":                                        # an edge run twice one way
        f = np.concatenate([f, f[at:at + 1]])
    elif damage == "twice reversed":
        f = np.concatenate([f, f[at:at + 1, ::-1]])
    elif damage == "reversed":
        f[at] = f[at, ::-1]
    elif damage == "three":                                      # a link vertex in three faces
        f = np.concatenate([f, [[0, f[at, 1], len(v)]]])
        v = np.concatenate([v, [v[f[at, 1]] + (0.0, 0.0, 0.5)]])
    elif damage == "paths" and len(f) > 4:                       # several open paths round the apex
        keep = np.ones(len(f), dtype=bool)
        keep[draw(st.lists(st.integers(0, len(f) - 1), min_size=1, max_size=3))] = False
        f = f[keep]
    elif damage == "second fan":                                 # a second fan through the same apex
        w, g = _fan(theta[:40] + 0.01, radii[:40], 0.5 + heights[:40], False, apex=v[0])
        f = np.concatenate([f, np.where(g == 0, 0, g + len(v) - 1)])
        v = np.concatenate([v, w[1:]])
    event(damage)
    if draw(st.booleans()):
        v = np.round(v * 64) / 64
    order = draw(st.permutations(range(len(f))))
    return v, np.asarray(f)[list(order)]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(big_fans())
def test_big_fans_find_what_the_unpruned_scan_and_the_numpy_twin_find(fan):
    v, f = fan
    found = _check(v, f)
    event("crossing found" if len(found.crossing) else "no crossing")


@pytest.mark.parametrize("sections", [65, 129])
@pytest.mark.parametrize("defect", ["crossing", "vertex", "edge", "coplanar", "none"])
def test_fan_capped_cylinders_keep_every_defect(sections, defect):
    """A closed cylinder whose caps are fans of 65 or 129 faces, with one defect made on purpose; the scan must
    find it (and nothing else new) on every path."""
    v, f = fan_capped_cylinder(sections)
    n = sections
    bottom = 2 * n
    moved = []
    if defect == "crossing":                                     # a triangle through the bottom cap
        v = np.concatenate([v, [[0.3, 0.1, -0.5], [0.4, -0.1, 0.5], [0.2, 0.3, 0.5]]])
        f = np.concatenate([f, [[len(v) - 3, len(v) - 2, len(v) - 1]]])
        moved = [len(f) - 1]
    elif defect == "vertex":                                     # a triangle touching the top cap at one point
        v = np.concatenate([v, [[0.25, 0.25, 2.0], [0.25, 0.75, 3.0], [-0.25, 0.25, 3.0]]])
        f = np.concatenate([f, [[len(v) - 3, len(v) - 2, len(v) - 1]]])
        moved = [len(f) - 1]
    elif defect == "edge":                                       # a cap face folded onto its neighbour
        v = np.concatenate([v, [v[2] * 0.5 + v[3] * 0.5]])
        f = np.concatenate([f, [[bottom, 2, len(v) - 1]]])       # shares the edge (bottom, 2) with a cap face
        moved = [len(f) - 1]
    elif defect == "coplanar":                                   # a face lying in the top cap, facing up
        v = np.concatenate([v, [[0.1, 0.1, 2.0], [0.5, 0.1, 2.0], [0.1, 0.5, 2.0]]])
        f = np.concatenate([f, [[len(v) - 3, len(v) - 2, len(v) - 1]]])
        moved = [len(f) - 1]
    found = _check(v, f)
    if defect == "none":
        assert not (len(found.crossing) or len(found.coplanar_opposite) or len(found.contact))
        assert found.candidate_pairs < 8 * len(f)                # the caps' pairs are left out
        return
    assert pair_kinds(found), defect
    _brute(v, f, found, moved)


# -- the faces across each edge (ct_twins), against the rule written out (intersect_reference.edge_twins) -----

@st.composite
def twin_meshes(draw):
    """Faces on few vertices (edges in many faces, either way), fans of up to 150 faces round one vertex with
    faces repeated, reversed or holding a vertex twice, and both together."""
    parts, at = [], 0
    if draw(st.booleans()):
        k = draw(st.integers(3, 150))
        i = np.arange(k)
        closed = draw(st.booleans())
        fan = np.stack([np.zeros(k, dtype=np.int64), 1 + i, 1 + (i + 1) % k if closed else 2 + i], 1)
        parts.append(fan)
        at = int(fan.max()) + 1
    few = draw(st.integers(3, 8))
    soup = draw(st.lists(st.lists(st.integers(0, few - 1), min_size=3, max_size=3), max_size=30))
    if soup:
        parts.append(np.asarray(soup, dtype=np.int64) + (0 if draw(st.booleans()) else at))
    f = np.concatenate(parts) if parts else np.zeros((0, 3), dtype=np.int64)
    if len(f) and draw(st.booleans()):                           # repeat and reverse some faces
        pick = draw(st.lists(st.integers(0, len(f) - 1), max_size=4))
        f = np.concatenate([f, f[pick], f[pick][:, ::-1]])
    order = draw(st.permutations(range(len(f))))
    return np.ascontiguousarray(f[list(order)]), draw(st.sampled_from([1, 2, 3]))


@settings(max_examples=150, deadline=None)
@given(twin_meshes(), st.sampled_from([np.int32, np.int64]))
def test_faces_across_each_edge_follow_the_rule(mesh, dtype):
    f, rounds = mesh
    n = int(f.max()) + 1 if len(f) else 0
    got = np.frombuffer(_native.accel().edge_twins(f.astype(dtype), n, rounds), dtype=np.int32).reshape(-1, 3)
    want = np.array(edge_twins(f, n), dtype=np.int64).reshape(-1, 3)
    event("fan above 64" if len(f) and np.bincount(f.ravel()).max() > 64 else "small stars only")
    assert np.array_equal(got, want)


@pytest.mark.parametrize("k", [63, 64, 150])
@pytest.mark.parametrize("closed", [True, False])
def test_an_edge_run_twice_one_way_has_no_twin_at_any_fan_size(k, closed):
    """One rule on both sides of 64 faces (issue 21): a fan round vertex 0 with one face listed twice.  Its edges
    from the apex are then run twice one way, so neither copy nor the face across has a twin there (-2); before,
    above 64 faces, the copies got the face across as their twin while that face got -2 (the table path counted
    only the faces running the edge back; k = 63 is 64 faces at the apex, the stack path, which always said -2).
    Every other edge keeps its one twin (-1 at an open fan's ends)."""
    i = np.arange(k)
    fan = np.stack([np.zeros(k, dtype=np.int64), 1 + i, 1 + (i + 1) % k if closed else 2 + i], 1)
    f = np.ascontiguousarray(np.concatenate([fan, fan[[k // 2]]]))
    n = int(f.max()) + 1
    got = np.frombuffer(_native.accel().edge_twins(f, n, 1), dtype=np.int32).reshape(-1, 3)
    want = np.array(edge_twins(f, n), dtype=np.int64).reshape(-1, 3)
    assert np.array_equal(got, want)
    face = k // 2                                            # (0, a, b), listed again as face k
    assert (got[[face, k]] == -2).all()                      # each of its edges is run twice one way
    assert got[face - 1, 2] == -2 and got[face + 1, 0] == -2   # a -> 0 and 0 -> b: two faces run them back
    far = [g for g in range(k) if abs(g - face) > 1]
    assert (got[far, 0] != -2).all() and (got[far, 2] != -2).all()
