"""mesh/intersect.py, pairs decided by a single touching corner (``ct_touch_first`` and the touch shortcut in
``ct_classify``, section 8 of _accel.c): fan-capped prisms as STL files give them (float32 coordinates, each top
rim vertex straight above its bottom one, so a rim corner lies exactly on the side walls' planes, which no float
filter decides).

A cap face and a side wall not sharing an index meet at most in the one corner of the wall on the cap's plane;
the C kernel now decides such pairs from that corner alone (the exact stage no longer runs on the cap's other
corners).  Hypothesis draws prisms and plants either nothing, a contact (one wall corner given a duplicate index at
the same coordinates, so that it lies on a cap face it no longer shares an index with) or a crossing (a top rim
vertex pushed through the bottom cap), and checks the C kernel's pairs against the numpy twin (independent code)
and every reported pair, and every cap-wall pair, against the rational classifier of
``intersect_reference.brute_kind``.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from intersect_reference import CONTACT, CROSSING, NONE, brute_kind, pair_kinds
from inertia_tool import _native
from inertia_tool.mesh.intersect import surface_contacts

FIELDS = ("crossing", "coplanar_opposite", "contact")

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


def _prism(angles, radius, height, offset):
    """A closed prism over the ring at ``angles``: fan caps round a centre vertex at each end, faces in the order
    bottom cap, top cap, walls (the caps first: the lower index of a cap-wall pair is the cap's), coordinates
    rounded to float32 as an STL file stores them."""
    n = len(angles)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    v = np.concatenate([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    v = (v + offset).astype(np.float32).astype(np.float64)
    i = np.arange(n)
    j = (i + 1) % n
    bottom, top = np.full(n, 2 * n), np.full(n, 2 * n + 1)
    f = np.concatenate([np.stack([bottom, j, i], 1), np.stack([top, n + i, n + j], 1),
                        np.stack([n + i, j, n + j], 1), np.stack([i, j, n + i], 1)])
    return v, f


@st.composite
def prisms(draw):
    """A prism of 8-40 sections (angles jittered, not axis-aligned), radius and height 0.5-80 (mm-sized
    parts), anywhere within ±100, and what is planted in it: nothing, a contact or a crossing."""
    n = draw(st.integers(8, 40))
    jitter = np.array(draw(st.lists(st.floats(-0.3, 0.3), min_size=n, max_size=n)))
    angles = 2 * np.pi * (np.arange(n) + jitter) / n + draw(st.floats(0, 1))
    radius, height = draw(st.floats(0.5, 80)), draw(st.floats(0.5, 80))
    offset = np.array(draw(st.lists(st.floats(-100, 100), min_size=3, max_size=3)))
    v, f = _prism(angles, radius, height, offset)
    plant = draw(st.sampled_from(["none", "contact", "crossing"]))
    k = draw(st.integers(0, n - 1))
    touched: tuple[tuple[int, int], ...] = ()        # (cap face, wall) pairs the planted contact must give
    if plant == "contact":                  # a wall of section k: a bottom corner by a duplicate index
        wall, corner = draw(st.sampled_from([(3 * n + k, 0), (2 * n + k, 1)]))   # (i, j, n + i) or (n + i, j, n + j)
        v = np.concatenate([v, v[f[wall, corner]][None]])
        f[wall, corner] = len(v) - 1
        touched = tuple((cap, wall) for cap in (k, (k - 1) % n if corner == 0 else (k + 1) % n))
    elif plant == "crossing":               # top rim vertex k pushed through the bottom cap, towards the axis
        centre = v[2 * n]
        v[n + k] = centre + 0.5 * (v[k] - centre) - [0, 0, draw(st.floats(0.05, 1.0)) * height]
    return v, f, plant, n, touched


def _kinds(v, f, monkeypatch, twin):
    if twin == "numpy":
        monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    else:
        monkeypatch.delenv(_native.NO_ACCEL_ENV, raising=False)
    got = surface_contacts(v, f)
    monkeypatch.delenv(_native.NO_ACCEL_ENV, raising=False)
    assert got.complete
    return got


def _shared(f, a, b):
    return [(p, q) for p in range(3) for q in range(3) if f[a, p] == f[b, q]]


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(prism=prisms())
def test_fan_capped_prisms_find_exactly_the_planted_pairs(prism, monkeypatch):
    v, f, plant, n, touched = prism
    c, ref = _kinds(v, f, monkeypatch, "c"), _kinds(v, f, monkeypatch, "numpy")
    for field in FIELDS:
        assert np.array_equal(getattr(c, field), getattr(ref, field)), field
    got = pair_kinds(c)
    for (a, b), kind in got.items():        # every pair reported is what the rational classifier says
        assert brute_kind(v[f[a]], v[f[b]], _shared(f, a, b)) == kind, (a, b)
    t = v[f]
    lo, hi = t.min(axis=1), t.max(axis=1)
    for a in range(2 * n):                  # and every cap-wall pair whose boxes meet: those the shortcut decides
        meet = np.all((lo[a] <= hi[2 * n:]) & (lo[2 * n:] <= hi[a]), axis=1)
        for b in 2 * n + np.flatnonzero(meet):
            want = brute_kind(t[a], t[b], _shared(f, a, b))
            assert got.get((a, int(b)), NONE) == (NONE if want is None else want), (a, b, plant)
    if plant == "none":
        assert not got
    elif plant == "contact":
        assert set(got.values()) == {CONTACT}
        assert set(touched) <= set(got)     # both bottom cap faces round the duplicated corner touch the wall
    else:
        assert CROSSING in got.values()


def test_clean_fan_capped_prism_needs_no_exact_evaluation():
    """Each wall's bottom corner on the cap's plane and each cap corner on a wall's plane (float32 STL
    coordinates: exactly, which no float filter decides) was resolved by the exact stage, 4 per section (64 on
    16 sections before the shortcut); now the touching corner decides every such pair."""
    v, f = _prism(2 * np.pi * np.arange(16) / 16 + 0.3, 7.3, 11.1, np.array([3.1, -2.2, 5.5]))
    got = surface_contacts(v, f)
    assert got.complete and not len(got.crossing) and not len(got.contact) and not len(got.coplanar_opposite)
    assert got.exact_evaluations == 0
