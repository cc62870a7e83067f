"""mesh/intersect.py, the C scan's small certified stars (issue 21 item 2, issue 25 item 2).

The C scan certifies the star of every vertex of at least three faces (``_accel.c`` section 8, ``ct_stars``)
and decides the pairs within a small certified star (fewer than ``STAR_MIN_FACES`` faces) by the certificate,
counting them as tested, instead of rebuilding and testing the two faces.  Nothing it finds may change, and its
counts must stay those of the numpy twin (which certifies only stars of ``STAR_MIN_FACES`` faces or more).

Every test compares, pair for pair: the C scan as the analysis runs it, the C scan without any star
(``_star_faces=0``) and the numpy twin, and for small meshes every pair against the independent rational
classifier (``intersect_reference.brute_kind``).  The meshes are closed grids on an integer lattice (so folds
and coincidences are exact) with faces folded flat over a shared edge, vertices pushed through their own star
(crossings between faces sharing only a vertex), and the compositions of ``adversary_solids``.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import adversary_solids as adv
from conftest import HAVE_ACCEL
from intersect_reference import NONE, brute_kind, pair_kinds
from inertia_tool import _native
from inertia_tool.mesh.intersect import SurfaceContacts, surface_contacts
from contact_scans import same_pairs


pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


def _numpy(v, f, **kwargs) -> SurfaceContacts:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(_native.NO_ACCEL_ENV, "1")
        return surface_contacts(v, f, **kwargs)


def _c(v, f, **kwargs) -> SurfaceContacts:
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv(_native.NO_ACCEL_ENV, raising=False)
        return surface_contacts(v, f, **kwargs)


def _check_all_paths(v, f, brute=False) -> SurfaceContacts:
    """The C scan against its unpruned and unpatched selves and the numpy twin (pairs; candidate and tested
    counts without the C scan's patches, which only lower them), and optionally every pair against the rational
    classifier."""
    fast = _c(v, f)
    same_pairs(fast, _c(v, f, _star_faces=0))
    same_pairs(fast, _c(v, f, _star_faces=0, _patches=False))
    unpatched = _c(v, f, _patches=False)
    same_pairs(fast, unpatched)
    ref = _numpy(v, f)
    same_pairs(fast, ref)
    assert (unpatched.candidate_pairs, unpatched.tested_pairs, unpatched.degenerate_faces) == \
        (ref.candidate_pairs, ref.tested_pairs, ref.degenerate_faces)
    assert fast.candidate_pairs <= ref.candidate_pairs and fast.tested_pairs <= ref.tested_pairs
    assert fast.degenerate_faces == ref.degenerate_faces
    if brute:
        got = pair_kinds(fast)
        for i in range(len(f)):
            for j in range(i + 1, len(f)):
                shared = [(a, b) for a in range(3) for b in range(3) if f[i][a] == f[j][b]]
                want = brute_kind(v[f[i]], v[f[j]], shared)
                assert got.get((i, j), NONE) == (NONE if want is None else want), (i, j)
    return fast


def _lattice_torus(n, k, rng, major=12, minor=5):
    """A closed n × k torus grid with corners rounded to the integer lattice (exact coincidences)."""
    u = 2 * np.pi * np.arange(n) / n + rng.uniform(0, 0.3)
    w = 2 * np.pi * np.arange(k) / k + rng.uniform(0, 0.3)
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = major + minor * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), minor * np.sin(ww)], axis=-1).reshape(-1, 3)
    v = np.round(v + rng.integers(-1, 2, v.shape))
    i, j = np.meshgrid(np.arange(n), np.arange(k), indexing="ij")
    a, b = i * k + j, ((i + 1) % n) * k + j
    c, d = ((i + 1) % n) * k + (j + 1) % k, i * k + (j + 1) % k
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    return v.astype(float), f.astype(np.int64)


def _edge_neighbour(f, face, e):
    """(other face, its corner not on the edge) across edge e of ``face``, or None."""
    x, y = f[face, e], f[face, (e + 1) % 3]
    for g in range(len(f)):
        if g != face and x in f[g] and y in f[g]:
            rest = [c for c in range(3) if f[g, c] not in (x, y)]
            return g, rest[0]
    return None


@st.composite
def damaged_lattice_meshes(draw):
    """Lattice tori with folds over shared edges (the apex moved into the neighbour's plane, on the neighbour's
    side) and vertices pushed through their star (faces sharing only that vertex then cross or touch)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    v, f = _lattice_torus(draw(st.integers(3, 6)), draw(st.integers(3, 5)), rng)
    for _ in range(draw(st.integers(0, 3))):                 # coplanar folds at shared edges
        face, e = int(rng.integers(len(f))), int(rng.integers(3))
        found = _edge_neighbour(f, face, e)
        if found is None:
            continue
        g, corner = found
        a, b, c = v[f[face, e]], v[f[face, (e + 1) % 3]], v[f[face, (e + 2) % 3]]
        s, t = rng.choice([-0.5, 0.25, 0.5, 1.0]), rng.choice([0.25, 0.5, 1.0])
        v[f[g, corner]] = a + s * (b - a) + t * (c - a)       # exact: small integers times quarters
    for _ in range(draw(st.integers(0, 2))):                 # a vertex pushed through its own star
        x = int(rng.integers(len(v)))
        ring = np.unique(f[np.any(f == x, axis=1)])
        ring = ring[ring != x]
        centre = v[ring].mean(axis=0)
        v[x] = np.round(centre + rng.choice([-1.5, -1.0, 0.5, 2.0]) * (v[x] - centre))
    return v, f


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(damaged_lattice_meshes())
def test_folded_and_pushed_lattice_tori_match_unpruned_numpy_and_brute_force(mesh):
    v, f = mesh
    _check_all_paths(v, f, brute=len(f) <= 40)


def test_coplanar_fold_over_a_shared_edge_is_still_found():
    """Regression: a fold at a vertex of valence below STAR_MIN_FACES (its star not certified: the fold makes
    two projected triangles overlap) is found as coplanar_opposite, as before the small stars."""
    rng = np.random.default_rng(7)
    v, f = _lattice_torus(5, 4, rng)
    face, e = 0, 0
    g, corner = _edge_neighbour(f, face, e)
    a, b, c = v[f[face, 0]], v[f[face, 1]], v[f[face, 2]]
    v[f[g, corner]] = a + 0.5 * (b - a) + 0.5 * (c - a)
    result = _check_all_paths(v, f, brute=True)
    assert (min(face, g), max(face, g)) in {tuple(p) for p in result.coplanar_opposite.tolist()}


def test_vertex_pushed_through_its_star_still_crosses():
    """Regression: faces sharing only one vertex that cross (the vertex pushed through its ring) are found."""
    rng = np.random.default_rng(3)
    v, f = _lattice_torus(6, 5, rng)
    x = 7
    ring = np.unique(f[np.any(f == x, axis=1)])
    ring = ring[ring != x]
    centre = v[ring].mean(axis=0)
    v[x] = np.round(centre - 1.5 * (v[x] - centre))
    result = _check_all_paths(v, f, brute=True)
    assert len(result.crossing) + len(result.contact) > 0


def test_clean_grid_pairs_are_decided_by_small_stars_and_counted_as_before():
    """On a clean grid every adjacent pair lies in a certified star of six faces: counted as a candidate and
    as tested, exactly as the numpy twin counts it, and nothing is found."""
    u = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    w = np.linspace(0, 2 * np.pi, 20, endpoint=False) + 0.1
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = 1 + 0.35 * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), 0.35 * np.sin(ww)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(40), np.arange(20), indexing="ij")
    a, b, c, d = i * 20 + j, ((i + 1) % 40) * 20 + j, ((i + 1) % 40) * 20 + (j + 1) % 20, i * 20 + (j + 1) % 20
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    result = _check_all_paths(v, f)
    counted = _c(v, f, _patches=False).candidate_pairs         # the numpy twin's count (_check_all_paths)
    assert counted >= 6 * len(f)                               # every face's 12 neighbours, each pair once
    assert not (len(result.crossing) or len(result.contact) or len(result.coplanar_opposite))


@pytest.mark.parametrize("kind", adv.KINDS)
def test_adversarial_compositions_match_unpruned_and_numpy(kind):
    rng = np.random.default_rng(adv.KINDS.index(kind) + 2100)
    for _ in range(2):
        case = adv.make_case(kind, rng)
        _check_all_paths(np.asarray(case.vertices, dtype=float), np.asarray(case.faces))


def test_star_certificates_and_pairs_do_not_depend_on_the_thread_count():
    """The stars are certified on threads above 20,000 vertices: a 24,000-vertex lattice torus with folds and
    a pushed vertex gives the same pairs, counts and per-face outputs on 1, 2 and 3 threads."""
    from inertia_tool._native import accel, faces_for_c

    rng = np.random.default_rng(11)
    v, f = _lattice_torus(200, 120, rng, major=4000, minor=1500)
    for face in (5, 700, 30001):
        g, corner = _edge_neighbour(f, face, 0)
        a, b, c = v[f[face, 0]], v[f[face, 1]], v[f[face, 2]]
        v[f[g, corner]] = a + 0.5 * (b - a) + 0.25 * (c - a)
    lib = accel()
    ref = lib.contact_scan(v, faces_for_c(f), -1, 1, 8)
    pairs = set(zip(np.frombuffer(ref[0], np.int64), np.frombuffer(ref[1], np.int64), ref[2]))
    assert pairs and ref[3] > 6 * len(f)
    for threads in (2, 3):
        got = lib.contact_scan(v, faces_for_c(f), -1, threads, 8)
        assert set(zip(np.frombuffer(got[0], np.int64), np.frombuffer(got[1], np.int64), got[2])) == pairs
        assert got[3:7] == ref[3:7] and got[7:] == ref[7:]


@st.composite
def closed_fans(draw):
    """One vertex's fan of k faces, consistently oriented as a closed manifold's (each link edge followed by the
    next), that winds once or twice round the centre (a double cover with distinct ring vertices: the oriented
    ring walk accepts it, only the turn count may refuse it), with ring heights from flat (coplanar faces) to
    steep, optionally a face turned over (the walk then fails and the general matching decides) or a ring
    vertex repeated (a pinched fan: neither may certify it).  Integer coordinates: every coincidence is exact."""
    k = draw(st.integers(3, 12))
    turns = draw(st.sampled_from([1, 1, 2]))
    radius = draw(st.integers(4, 12))
    heights = draw(st.lists(st.integers(-2, 2), min_size=k, max_size=k))
    angles = 2 * np.pi * turns * (np.arange(k) + 0.5 * np.array(draw(
        st.lists(st.floats(0.0, 0.8), min_size=k, max_size=k)))) / k
    ring = np.stack([np.round(radius * np.cos(angles)), np.round(radius * np.sin(angles)),
                     np.array(heights, dtype=float)], axis=1)
    v = np.vstack([[[0.0, 0.0, draw(st.integers(-1, 1))]], ring])
    f = np.array([[0, 1 + i, 1 + (i + 1) % k] for i in range(k)], dtype=np.int64)
    if draw(st.booleans()):                                   # one face turned over
        g = draw(st.integers(0, k - 1))
        f[g] = f[g][[0, 2, 1]]
    if k >= 4 and draw(st.booleans()):                        # a ring vertex repeated (pinched)
        a = draw(st.integers(1, k))
        b = 1 + (a - 1 + draw(st.integers(2, k - 2))) % k
        f[f == b] = a
    return v, f


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(closed_fans())
def test_oriented_fans_winding_once_or_twice_match_numpy_and_brute_force(mesh):
    """The C scan's oriented ring walk (``ct_star_ring_oriented``, the fast path of a closed manifold's star)
    finds the ring of a consistently oriented fan; a fan winding twice, turned over in one face or pinched must
    still not be certified: every pair against the numpy twin and the rational classifier."""
    v, f = mesh
    keep = np.array([len(set(row.tolist())) == 3 for row in f])
    _check_all_paths(v, f[keep], brute=True)


def test_fan_winding_twice_is_not_certified_regression():
    """A flat 6-face fan winding twice round its centre, ring vertices distinct and consistently oriented (the
    oriented ring walk closes it): faces i and i + 3 overlap in the plane and are found as coplanar pairs."""
    k = 6
    angles = 4 * np.pi * (np.arange(k) + 0.3 * (np.arange(k) % 2)) / k
    ring = np.stack([np.round(10 * np.cos(angles)), np.round(10 * np.sin(angles)), np.zeros(k)], axis=1)
    v = np.vstack([[[0.0, 0.0, 0.0]], ring])
    f = np.array([[0, 1 + i, 1 + (i + 1) % k] for i in range(k)], dtype=np.int64)
    result = _check_all_paths(v, f, brute=True)
    assert len(result.crossing) + len(result.coplanar_opposite) + len(result.contact) > 0
