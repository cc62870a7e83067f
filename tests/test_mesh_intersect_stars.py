"""mesh/intersect.py, certified stars: the pairs within a fan that projects one to one along an axis are left
out of the face-pair check without changing what it finds (module docstring, "Stars").

Every test compares the pruned scan with the unpruned one (``_star_faces=0``) pair for pair, on both twins;
small fans are also checked pair by pair against the independent rational classifier
(``intersect_reference.brute_kind``).  Fans that fold over themselves, wind twice, or are pierced by other
faces must keep every crossing.
"""

import os

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from intersect_reference import NONE, brute_kind, pair_kinds
from inertia_tool import _native
from inertia_tool.mesh.intersect import STAR_MIN_FACES, SurfaceContacts, surface_contacts
from contact_scans import fan_capped_cylinder

FIELDS = ("crossing", "coplanar_opposite", "contact")


@pytest.fixture(autouse=True, params=["c", "numpy"])
def kernel(request, monkeypatch):
    """Every test on both twins: the C kernel (section 8 of _accel.c) and the numpy reference."""
    if request.param == "c":
        if not HAVE_ACCEL:
            pytest.skip("inertia_tool._accel is not built")
        monkeypatch.delenv(_native.NO_ACCEL_ENV, raising=False)
    else:
        monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    return request.param


def _same(pruned: SurfaceContacts, full: SurfaceContacts) -> None:
    assert pruned.complete and full.complete
    for field in FIELDS:
        assert np.array_equal(getattr(pruned, field), getattr(full, field)), field
    assert pruned.candidate_pairs <= full.candidate_pairs


def _fan(angles, radii, heights, closed, apex=(0.0, 0.0, 0.0)):
    """Vertices (apex first, then the ring) and faces (0, r_i, r_{i+1}) of a fan."""
    ring = np.stack([radii * np.cos(angles), radii * np.sin(angles), heights], axis=1)
    v = np.r_[[apex], ring + np.asarray(apex)]
    k = len(angles)
    i = np.arange(k if closed else k - 1)
    f = np.stack([np.zeros(len(i), dtype=np.int64), 1 + i, 1 + (i + 1) % k], axis=1)
    return v, f


# -- the case: a cylinder of 10,000 sections ---------------------------------------------------------

def test_cylinder_of_10000_sections_has_linearly_many_candidates(kernel):
    """Issue 25: every cap face shares the centre vertex, so every pair of a cap's boxes meets: about
    2·C(n, 2) = 10⁸ candidate pairs unpruned for n = 10,000.  Both caps are certified stars, and what is left
    is linear in the face count (the pairs of side faces with their neighbours and a cap face with the side
    faces at its rim).  The numpy twin still enumerates the grid's raw pairs, so it runs a smaller cylinder."""
    n = 10_000 if kernel == "c" else 600
    v, f = fan_capped_cylinder(n)
    result = surface_contacts(v, f)
    assert result.complete and not any(len(getattr(result, k)) for k in FIELDS)
    unpruned_at_least = 2 * (n * (n - 1) // 2)               # the pairs within each cap
    assert result.candidate_pairs < 5 * len(f)                 # 4.25 per face for n = 10,000
    assert unpruned_at_least > 500 * result.candidate_pairs or n < 10_000
    if kernel == "numpy":
        _same(result, surface_contacts(v, f, _star_faces=0))


def test_cylinder_twins_and_thread_counts_count_the_same_candidates(kernel, monkeypatch):
    """The node-level skip of the C hierarchy, its pair-level test, the split over threads and the numpy grid's
    grouping all leave out exactly the pairs within certified stars."""
    if kernel != "c":
        pytest.skip("compares the two paths once")
    big_v, big_f = fan_capped_cylinder(6000)                      # 24,000 faces: above the C scan's threading threshold
    monkeypatch.setenv(_native.THREADS_ENV, "1")
    one = surface_contacts(big_v, big_f, _patches=False)
    monkeypatch.setenv(_native.THREADS_ENV, "2")
    two = surface_contacts(big_v, big_f, _patches=False)
    assert one.candidate_pairs == two.candidate_pairs == 102_020
    v, f = fan_capped_cylinder(300)
    c = surface_contacts(v, f, _patches=False)
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    ref = surface_contacts(v, f)
    assert c.candidate_pairs == ref.candidate_pairs and c.tested_pairs == ref.tested_pairs
    assert c.candidate_pairs < surface_contacts(v, f, _star_faces=0).candidate_pairs // 10


@pytest.mark.parametrize("make", [
    lambda: trimesh.creation.cylinder(radius=0.3, height=1.0, sections=200),
    lambda: trimesh.creation.cone(radius=0.5, height=0.7, sections=150),
    lambda: trimesh.creation.annulus(r_min=0.2, r_max=0.5, height=0.3, sections=100),
    lambda: trimesh.creation.capsule(height=1.0, radius=0.3, count=[40, 40]),
    lambda: trimesh.creation.uv_sphere(radius=1.0, count=[64, 64]),
], ids=["cylinder", "cone", "annulus", "capsule", "uv_sphere"])
def test_trimesh_primitives_find_the_same_pairs(make):
    """Clean primitives (caps, cone tips, sphere poles, tilted copies of them) and the same primitive with a
    turned copy through it: the pruned scan finds exactly the unpruned scan's pairs."""
    mesh = make()
    v, f = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    turn = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])[:3, :3]
    for verts in (v, v @ turn.T):
        _same(surface_contacts(verts, f), surface_contacts(verts, f, _star_faces=0))
    both_v, both_f = np.r_[v, v @ turn.T + 0.05], np.r_[f, f + len(v)]
    pruned, full = surface_contacts(both_v, both_f), surface_contacts(both_v, both_f, _star_faces=0)
    _same(pruned, full)
    assert len(pruned.crossing) > 0


# -- fans that must keep their crossings -----------------------------------------------------------------------

def test_fan_winding_twice_keeps_its_crossings():
    """A closed ring going twice round its apex, rising on one turn and falling on the other: the two sheets
    cross where the heights change sign.  Not a certified star (it winds twice): every crossing is found."""
    k = 2 * STAR_MIN_FACES + 7
    theta = 4 * np.pi * np.arange(k) / k
    v, f = _fan(theta, np.ones(k), 0.5 * np.cos(theta / 2 + 0.3), closed=True)
    pruned = surface_contacts(v, f)
    _same(pruned, surface_contacts(v, f, _star_faces=0))
    assert len(pruned.crossing) > 0


def test_open_fan_overlapping_itself_keeps_its_crossings():
    """An open fan turning 1.25 times round a coplanar apex, its last faces above and crossing down through the
    first ones: not certified; the crossings are found."""
    k = 3 * STAR_MIN_FACES
    theta = 2.5 * np.pi * np.arange(k) / (k - 1)
    heights = np.where(theta > 2 * np.pi, 0.3 - (theta - 2 * np.pi), 0.0)
    v, f = _fan(theta, np.ones(k), heights, closed=False)
    pruned = surface_contacts(v, f)
    _same(pruned, surface_contacts(v, f, _star_faces=0))
    assert len(pruned.crossing) + len(pruned.coplanar_opposite) + len(pruned.contact) > 0


def test_certified_cap_pierced_by_a_face_still_reports_it():
    """A flat certified cap and one extra face piercing it: the cap's own pairs are left out, but the cap
    against the outside face is tested as always."""
    v, f = fan_capped_cylinder(64)
    spike = np.array([[0.1, 0.2, -0.5], [0.3, 0.1, 0.5], [0.2, 0.4, 0.5]])
    verts, faces = np.r_[v, spike], np.r_[f, [[len(v), len(v) + 1, len(v) + 2]]]
    pruned = surface_contacts(verts, faces)
    _same(pruned, surface_contacts(verts, faces, _star_faces=0))
    assert len(pruned.crossing) >= 1 and np.all(pruned.crossing[:, 1] == len(f))


# -- hypothesis: random fans ---------------------------------------------------------------------------------

@st.composite
def fans(draw):
    """A fan of 8-24 faces round an apex: planar caps, cones, saddles (heights ~ sin 2θ), steps that go back
    (folds), windings short of, equal to and beyond one turn, radii down to zero, on a coarse dyadic lattice
    (many exact coincidences) or in general position, optionally turned."""
    k = draw(st.integers(STAR_MIN_FACES, 24))
    closed = draw(st.booleans())
    turns = draw(st.sampled_from([0.5, 0.9, 1.0, 1.0, 1.0, 1.5, 2.0]))
    step = 2 * np.pi * turns / (k if closed else k - 1)
    messy = draw(st.booleans())                                  # else a fan that may well be certified
    jitter = np.array(draw(st.lists(st.floats(-0.4, 0.4), min_size=k, max_size=k)))
    if messy:
        back = np.array(draw(st.lists(st.sampled_from([1.0, 1.0, 1.0, 1.0, -0.5, 0.0]), min_size=k, max_size=k)))
        radii = np.array(draw(st.lists(st.sampled_from([0.0, 0.5, 1.0, 1.0, 1.0, 2.0]), min_size=k,
                                       max_size=k)))
    else:
        back = np.ones(k)
        radii = np.array(draw(st.lists(st.sampled_from([0.5, 1.0, 2.0]), min_size=k, max_size=k)))
    theta = np.cumsum(step * (back + jitter)) - step
    shape = draw(st.sampled_from(["plane", "cone", "saddle", "random"]))
    amp = draw(st.sampled_from([0.0, 0.25, 1.0, -1.0]))
    if shape == "plane":
        heights = np.zeros(k)
    elif shape == "cone":
        heights = np.full(k, amp)
    elif shape == "saddle":
        heights = amp * np.sin(2 * theta)
    else:
        heights = np.array(draw(st.lists(st.floats(-1, 1), min_size=k, max_size=k)))
    v, f = _fan(theta, radii, heights, closed, apex=(1.0, -2.0, 0.5))
    if draw(st.booleans()):
        scale = 16 if messy else 64                              # exact coincidences and collinearities
        v = np.round(v * scale) / scale
    if draw(st.booleans()):
        v = v @ trimesh.transformations.rotation_matrix(draw(st.floats(0, 3)), [1, 1, 0.5])[:3, :3].T
    if draw(st.booleans()):                                      # inconsistent windings
        flip = np.array(draw(st.lists(st.booleans(), min_size=len(f), max_size=len(f))))
        f[flip] = f[flip][:, ::-1]
    return v, f


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fans())
def test_random_fans_find_the_same_pairs_as_the_unpruned_scan_and_the_rational_classifier(fan):
    v, f = fan
    pruned = surface_contacts(v, f)
    event("certified" if pruned.candidate_pairs < len(f) * (len(f) - 1) // 2 else "not certified")
    _same(pruned, surface_contacts(v, f, _star_faces=0))
    got = pair_kinds(pruned)
    for i in range(len(f)):
        for j in range(i + 1, len(f)):
            shared = [(p, q) for p in range(3) for q in range(3) if f[i, p] == f[j, q]]
            want = brute_kind(v[f[i]], v[f[j]], shared)
            assert got.get((i, j), NONE) == (NONE if want is None else want), (i, j)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.25, 1.0]))
def test_random_meshes_of_fans_and_soup_match_the_unpruned_scan(seed, lattice):
    """Several fans with shared apexes and rings, tilted, plus random triangles through them, on a lattice
    (coincidences) or not: pair for pair the same as the unpruned scan, and both twins count the same
    candidates (the two certifications agree)."""
    rng = np.random.default_rng(seed)
    parts_v, parts_f, at = [], [], 0
    for _ in range(rng.integers(1, 4)):
        k = int(rng.integers(STAR_MIN_FACES, 30))
        theta = np.sort(rng.uniform(0, 2 * np.pi, k)) if rng.random() < 0.7 else rng.uniform(0, 4 * np.pi, k)
        heights = rng.choice([0.0, 0.5]) + rng.normal(0, 0.3, k) * rng.integers(0, 2)
        v, f = _fan(theta, rng.uniform(0.2, 1.5, k), heights, bool(rng.integers(0, 2)), apex=rng.normal(0, 0.5, 3))
        parts_v.append(v)
        parts_f.append(f + at)
        at += len(v)
    soup = rng.normal(0, 0.8, (3 * 20, 3))
    parts_v.append(soup)
    parts_f.append(at + np.arange(len(soup)).reshape(-1, 3))
    v, f = np.concatenate(parts_v), np.concatenate(parts_f)
    v = np.round(v / lattice * 8) * lattice / 8
    pruned = surface_contacts(v, f, _patches=False)
    _same(pruned, surface_contacts(v, f, _star_faces=0, _patches=False))
    _same(surface_contacts(v, f), pruned)
    if HAVE_ACCEL and _native.NO_ACCEL_ENV not in os.environ:
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv(_native.NO_ACCEL_ENV, "1")
            ref = surface_contacts(v, f)
        assert ref.candidate_pairs == pruned.candidate_pairs
