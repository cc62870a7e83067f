"""mesh/intersect.py: the C face-pair scan (``_accel.c`` section 8) against its numpy twin and against the
independent rational classifier, on hypothesis-generated small and degenerate meshes.

The review of the corner-index blocks, the fan rings followed along link edges and the lazy normals: on meshes
of 0, 1, 2 and a few dozen faces, on an integer lattice (exact coincidences, folds, repeated faces), with
repeated corners, zero-area faces, fans round one vertex of up to 50 faces (the ring past the 32-face stack
buffer), fans wound consistently or not, open or closed, int32 and int64 and non-contiguous face arrays, the C
scan (as the analysis runs it, without stars, and with every star of 3 faces or more certified) must find the
pairs of the numpy twin with the same candidate and tested counts, and every pair must be the rational
classifier's.  Run under AddressSanitizer the same tests check the C scan's memory accesses.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from intersect_reference import NONE, brute_kind, pair_kinds
from inertia_tool import _native
from contact_scans import FIELDS, run_scan

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")

FUZZ = settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@st.composite
def fans(draw):
    """``(vertices, faces)``: a fan of k faces round vertex 0 on a small integer lattice, closed (a cone) or
    open, wound consistently or with some faces turned, and a few stray faces through it."""
    k = draw(st.integers(3, 50))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    t = 2 * np.pi * np.arange(k) / k
    radius = draw(st.sampled_from([3, 10, 40]))
    rim = np.stack([np.round(radius * np.cos(t)), np.round(radius * np.sin(t)),
                    rng.integers(-2, 3, k)], axis=1)
    apex = np.array([[0.0, 0.0, float(draw(st.integers(-3, 3)))]])
    v = np.r_[apex, rim, rng.integers(-radius, radius + 1, (4, 3))].astype(float)
    closed = draw(st.booleans())
    idx = np.arange(k) + 1
    nxt = np.roll(idx, -1)
    f = np.stack([np.zeros(k, dtype=np.int64), idx, nxt], axis=1)
    if not closed:
        f = f[:-1]
    if draw(st.booleans()):                    # turn some faces over (an inconsistently wound star)
        flip = rng.random(len(f)) < 0.2
        f[flip] = f[flip][:, ::-1]
    if draw(st.booleans()):                    # stray faces, some through the apex
        extra = rng.integers(0, len(v), (draw(st.integers(1, 6)), 3))
        f = np.r_[f, extra]
    if draw(st.booleans()):
        f = f[rng.permutation(len(f))]
    return v, f


@st.composite
def soups(draw):
    """``(vertices, faces)``: 0-40 faces of random corners among 1-12 lattice vertices (repeated corners,
    repeated faces, collinear and coincident points included)."""
    n = draw(st.integers(1, 12))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    span = draw(st.sampled_from([1, 2, 5, 1000]))
    v = rng.integers(-span, span + 1, (n, 3)).astype(float)
    if draw(st.booleans()):                    # everything in one plane (coplanar pairs)
        v[:, 2] = 0.0
    m = draw(st.integers(0, 40))
    f = rng.integers(0, n, (m, 3))
    if m and draw(st.booleans()):              # repeated faces, one of them turned over
        f = np.r_[f, f[:1], f[:1, ::-1]]
    return v, f


def _layout(f: np.ndarray, how: str) -> np.ndarray:
    if how == "int32":
        return f.astype(np.int32)
    if how == "fortran":
        return np.asfortranarray(f.astype(np.int64))
    if how == "strided":                       # every other row of a larger array: not contiguous
        big = np.zeros((2 * len(f), 3), dtype=np.int64)
        big[::2] = f
        return big[::2]
    return f.astype(np.int64)


def _check(v, f, how, brute):
    f = _layout(np.asarray(f), how)
    ref = run_scan(v, f, accel=False)
    for star_faces in (None, 0, 3):
        for patches in (True, False):
            kwargs = {"_patches": patches} if star_faces is None else {"_star_faces": star_faces,
                                                                       "_patches": patches}
            fast = run_scan(v, f, accel=True, **kwargs)
            assert fast.complete and ref.complete
            for name in FIELDS:
                assert np.array_equal(getattr(fast, name), getattr(ref, name)), (name, star_faces, patches)
            if star_faces is None and not patches:
                assert (fast.candidate_pairs, fast.tested_pairs, fast.degenerate_faces) == \
                    (ref.candidate_pairs, ref.tested_pairs, ref.degenerate_faces)
            if star_faces is None:
                assert fast.candidate_pairs <= ref.candidate_pairs
    if brute:
        got = pair_kinds(ref)
        ff = np.asarray(f).tolist()
        for i in range(len(ff)):
            for j in range(i + 1, len(ff)):
                shared = [(a, b) for a in range(3) for b in range(3) if ff[i][a] == ff[j][b]]
                want = brute_kind(v[ff[i]], v[ff[j]], shared)
                assert got.get((i, j), NONE) == (NONE if want is None else want), (i, j)


@FUZZ
@given(mesh=soups(), how=st.sampled_from(["int64", "int32", "fortran", "strided"]))
def test_c_scan_is_the_numpy_twin_on_small_soups(mesh, how):
    v, f = mesh
    _check(v, f, how, brute=len(f) <= 16)


@FUZZ
@given(mesh=fans(), how=st.sampled_from(["int64", "int32", "strided"]))
def test_c_scan_is_the_numpy_twin_on_fans(mesh, how):
    v, f = mesh
    _check(v, f, how, brute=len(f) <= 24)


@pytest.mark.parametrize("m", [0, 1, 2])
@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_c_scan_on_zero_one_and_two_faces(m, dtype):
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, -1], [0.2, 0.2, 1]])
    f = np.array([[0, 1, 2], [3, 4, 0]], dtype=dtype)[:m]
    _check(v, f, "int32" if dtype == np.int32 else "int64", brute=True)


@FUZZ
@given(mesh=soups(), max_pairs=st.integers(0, 30))
def test_c_scan_work_bound_agrees_with_the_numpy_twin(mesh, max_pairs):
    """Under a work bound both scans stop at the same count, and agree on whether they finished."""
    v, f = mesh
    ref = run_scan(v, f, accel=False, max_pairs=max_pairs)
    fast = run_scan(v, f, accel=True, max_pairs=max_pairs)
    assert fast.complete == ref.complete
    assert fast.candidate_pairs == ref.candidate_pairs
    if ref.complete:
        for name in FIELDS:
            assert np.array_equal(getattr(fast, name), getattr(ref, name)), name


def test_c_scan_refuses_bad_indices_directly():
    """The kernel itself refuses out-of-range and negative corners (not only its Python caller)."""
    lib = _native.accel()
    v = np.zeros((3, 3))
    for bad in ([[0, 1, 3]], [[0, -1, 2]], [[0, 1, 2**31 - 1]]):
        for dtype in (np.int32, np.int64):
            with pytest.raises(ValueError, match="face indices"):
                lib.contact_scan(v, np.array(bad, dtype=dtype), -1, 1, 8)


@pytest.mark.parametrize("star_faces", [0, 3, 8])
@pytest.mark.parametrize("m", [3, 17, 40])
def test_c_scan_never_visits_the_empty_positions_of_a_leaf(m, star_faces):
    """Regression (review of fpcheck2): faces whose float32 boxes overflow to -inf .. +inf (coordinates past
    float32's range, reachable by a direct call: ``surface_contacts`` scales them first) met the empty boxes
    that pad a leaf's block, and the scan loaded faces past the last one (out of bounds: AddressSanitizer's
    heap-buffer-overflow in ct_face_load) and counted those pairs.  Every pair of these faces is a candidate,
    and only those: m (m - 1) / 2 of them."""
    lib = _native.accel()
    rng = np.random.default_rng(m)
    v = rng.choice([-1e300, 1e300], size=(m + 2, 3))
    f = np.stack([np.zeros(m, dtype=np.int64), np.ones(m, dtype=np.int64), np.arange(m) + 2], axis=1)
    v[0], v[1] = -1e300, 1e300                 # every face spans -1e300 .. 1e300 on every axis
    a, b, _, candidates, tested, *_ = lib.contact_scan(v, f, -1, 1, star_faces)
    assert candidates == m * (m - 1) // 2
    assert tested <= candidates
    assert np.all(np.frombuffer(a, dtype=np.int64) < m) and np.all(np.frombuffer(b, dtype=np.int64) < m)
