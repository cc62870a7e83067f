"""The numpy path's per-shell sums (``integrals._label_sums``: a tree of TwoSums per shell, whole-array operations)
against exact rational arithmetic, and the two engine paths against exact integrals within their bounds.

``roundoff_bounds`` charges each shell's sums over m faces ``(2 + m²u)·u·Σ|x|`` on either path (the C kernel sums
compensated, Sum2 of Ogita, Rump and Oishi 2005).  The numpy path's trees are claimed to err by at most
``u·|Σx| + 3m(L + C)·u²·Σ|x|`` (``L`` tree levels, ``C`` chunks): checked here on ill-conditioned sums that a plain
sum gets wrong (cancellation, huge and tiny terms mixed, ±0, one term), against ``fractions.Fraction``; and on
hypothesis-drawn multi-shell meshes (faces of the shells interleaved, chunks of a few faces) both paths' moments lie
within ``roundoff_bounds`` of ``exact_volume_moments``.
"""

from __future__ import annotations

import math
import warnings
from fractions import Fraction
from unittest import mock

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from inertia_tool import integrals
from inertia_tool.integrals import body_volume_moments, exact_volume_moments, reference_point, roundoff_bounds

U = Fraction(integrals._U)

#: A term of an ill-conditioned sum: any finite float64 within ±1e280 (huge and tiny mixed, subnormals, ±0), so
#: that no sum of a few hundred of them overflows.
TERMS = st.floats(-1e280, 1e280, allow_nan=False, allow_infinity=False)


@st.composite
def ill_conditioned_segments(draw):
    """``(x (k, n), counts (g,))``: ``g`` segments in ``k`` = 1-3 rows; a segment is 0-5 terms drawn by hypothesis
    (its edge cases: ±0, subnormals, the extremes) and 0-150 of magnitudes across 580 decades, or, half the time,
    those terms, their negatives and 1-3 small terms shuffled together (massive cancellation: the sum is the small
    terms, which a plain sum loses)."""
    k = draw(st.integers(1, 3))
    g = draw(st.integers(1, 6))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    segments, counts = [], []
    for _ in range(g):
        n_drawn = draw(st.integers(0, 5))
        n = draw(st.integers(1 if n_drawn == 0 else 0, 150))
        cancel = draw(st.booleans())
        n_small = draw(st.integers(1, 3))
        rows = []
        for _ in range(k):
            wide = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 280, n)
            base = draw(st.lists(TERMS, min_size=n_drawn, max_size=n_drawn)) + wide.tolist()
            rng.shuffle(base)
            if cancel:
                small = draw(st.lists(st.floats(-1e-3, 1e-3), min_size=n_small, max_size=n_small))
                seg = np.array(base + [-t for t in base] + small)
                rng.shuffle(seg)
            else:
                seg = np.array(base)
            rows.append(seg)
        segments.append(np.array(rows))
        counts.append(segments[-1].shape[1])
    return np.concatenate(segments, axis=1), np.array(counts)


def _exact(terms) -> tuple[Fraction, Fraction]:
    """The exact sum and the sum of magnitudes of float terms."""
    q = [Fraction(float(t)) for t in terms]
    return sum(q, Fraction(0)), sum((abs(t) for t in q), Fraction(0))


def _check_segments(x: np.ndarray, counts: np.ndarray, hi: np.ndarray, lo: np.ndarray) -> None:
    """Each segment's ``hi + lo`` within the tree's bound and the charged bound of the exact sum."""
    got = hi + lo
    start = 0
    for j, m in enumerate(counts.tolist()):
        levels = max(1, math.ceil(math.log2(m))) if m > 1 else 0
        for r in range(x.shape[0]):
            exact, size = _exact(x[r, start:start + m])
            err = abs(Fraction(float(got[r, j])) - exact)
            tree = U * abs(exact) + 3 * m * (levels + 1) * U * U * size
            charged = (2 + m * m * U) * U * size
            assert err <= tree, (j, r, m, float(err), float(tree))
            assert err <= charged, (j, r, m, float(err), float(charged))
        start += m


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=ill_conditioned_segments(), tree_only=st.booleans())
@example(case=(np.array([[1e16, 1.0, -1e16, 3.0, -3.0, 1e-300]]), np.array([3, 3])), tree_only=True)
@example(case=(np.array([[1e308, -1e308, 1e-320, -0.0, 2.0 ** -1074]]), np.array([5])), tree_only=False)
def test_label_sums_are_within_the_bound_of_the_exact_sums(case, tree_only):
    """Against Fraction, segment by segment (a plain sum of the first example is 0 and 3 where the sums are 1 and
    1e-300: outside the bound by 15 orders of magnitude); ``tree_only`` takes the tree for small single segments
    too (otherwise ``math.fsum`` sums them)."""
    x, counts = case
    with mock.patch.object(integrals, "_FSUM_MAX_TERMS", -1 if tree_only else integrals._FSUM_MAX_TERMS):
        hi, lo = integrals._label_sums(x, counts)
    _check_segments(x, counts, hi, lo)


def test_a_plain_sum_fails_the_check():
    """The check above catches a sum that is not compensated: the plain left-to-right sums of the first example
    (0.0 for 1e16 + 1 − 1e16) are outside it."""
    x, counts = np.array([[1e16, 1.0, -1e16, 3.0, -3.0, 1e-300]]), np.array([3, 3])
    plain = np.array([[(1e16 + 1.0) - 1e16, (3.0 - 3.0) + 1e-300]])
    with pytest.raises(AssertionError):
        _check_segments(x, counts, plain, np.zeros_like(plain))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(1, 2000), seed=st.integers(0, 2**32 - 1), n_segments=st.integers(1, 50))
def test_label_sums_of_many_segments_equal_fsum_to_the_bound(n, seed, n_segments):
    """Random segment lengths over up to 2,000 columns (the level loop's padding and finished segments): each
    segment within ``u·|S| + small`` of ``math.fsum`` (correctly rounded), the terms spanning 40 decades."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((2, n)) * 10.0 ** rng.integers(-20, 20, size=(2, n))
    g = min(n_segments, n)
    cuts = np.sort(rng.choice(np.arange(1, n), g - 1, replace=False)) if g > 1 else np.zeros(0, dtype=int)
    counts = np.diff(np.r_[0, cuts, n])
    hi, lo = integrals._label_sums(x, counts)
    start = 0
    for j, m in enumerate(counts.tolist()):
        for r in range(2):
            ref = math.fsum(x[r, start:start + m])
            size = math.fsum(np.abs(x[r, start:start + m]))
            u = integrals._U
            assert abs((hi[r, j] + lo[r, j]) - ref) <= 2 * u * abs(ref) + 3 * m * 12 * u * u * size
        start += m


def _shell(kind: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A closed outward shell: a box, an icosphere, the hull of random points, or a needle box (aspect ~1e6)."""
    if kind == "box":
        m = trimesh.creation.box(rng.uniform(0.1, 3.0, 3))
    elif kind == "sphere":
        m = trimesh.creation.icosphere(subdivisions=int(rng.integers(0, 2)))
    elif kind == "needle":
        m = trimesh.creation.box((1.0, 1e-6, 1.3e-6))
    else:
        m = trimesh.convex.convex_hull(rng.standard_normal((12, 3)))
    return np.asarray(m.vertices), np.asarray(m.faces)


@st.composite
def multi_shell_meshes(draw):
    """``(vertices, faces, labels, n)``: 2-6 shells at a common scale (1e-4..1e4) and offset (up to 1e7), each
    turned and placed at random; the faces of all shells interleaved in one list (labels shuffled with them)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = draw(st.integers(2, 6))
    scale = 10.0 ** draw(st.integers(-4, 4))
    offset = draw(st.sampled_from([0.0, 1.0, 1e3, 1e7]))
    vs, fs, labs, count = [], [], [], 0
    for k in range(n):
        v, f = _shell(draw(st.sampled_from(["box", "sphere", "hull", "needle"])), rng)
        q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        v = (v @ q.T + rng.uniform(-5, 5, 3)) * scale + offset
        vs.append(v)
        fs.append(f + count)
        labs.append(np.full(len(f), k))
        count += len(v)
    faces, labels = np.vstack(fs), np.concatenate(labs)
    order = rng.permutation(len(faces))
    return np.vstack(vs), faces[order], labels[order].astype(np.intp), n


@pytest.mark.usefixtures("engine_path")
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(mesh=multi_shell_meshes(), chunk=st.sampled_from([1, 5, 64, 1 << 15]))
def test_each_path_is_within_its_bound_of_the_exact_integrals(mesh, chunk):
    """Every shell's volume, centroid and central second moment on this engine path within ``roundoff_bounds`` of
    exact integer arithmetic (plus the one rounding of the exact result), chunks of 1 to 32,768 faces; so the two
    paths agree within the sum of their bounds."""
    v, f, labels, n = mesh
    o = reference_point(v)
    shells = body_volume_moments(v, f, labels, n, origin=o, chunk_size=chunk)
    bound = roundoff_bounds(v, f, labels, shells, o)
    for k in range(n):
        exact = exact_volume_moments(v, f[labels == k])
        s = shells[k]
        assert abs(s.volume - exact.volume) <= bound.volume[k] + integrals._U * abs(exact.volume), k
        if exact.volume == 0:           # a shell too thin for its place (a needle 1e-10 m wide at 1e7 m): flat
            continue
        assert np.linalg.norm(s.centroid - exact.centroid) <= \
            bound.centroid[k] + 2 * integrals._U * np.linalg.norm(exact.centroid), k
        assert np.linalg.norm(s.second_moment - exact.second_moment) <= \
            bound.second_moment[k] + 2 * integrals._U * np.linalg.norm(exact.second_moment), k


@pytest.mark.usefixtures("engine_path")
def test_the_paths_agree_on_terms_that_overflow():
    """A box at 1e150 m (the pipeline refuses it; the integrals' API does not): every sum is NaN on both paths, and
    the round-off bound infinite.  Before, the numpy path's math.fsum raised a bare ValueError ("-inf + inf in
    fsum") where C gave NaN; and until session 18 numpy warned of the overflow (RuntimeWarning) where C is silent."""
    m = trimesh.creation.box((1.0, 2.0, 3.0))
    labels = np.zeros(len(m.faces), dtype=np.intp)
    for scale, finite_volume in ((1e100, True), (1e150, False)):
        v, f = np.asarray(m.vertices) * scale, np.asarray(m.faces)
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            got = integrals.volume_moments(v, f)
            shells = body_volume_moments(v, f, labels, 1)
            bound = integrals.roundoff_bounds(v, f, labels, shells, integrals.reference_point(v))
        assert math.isfinite(got.volume) == finite_volume and math.isnan(got.area)      # |n|² overflows at 1e100
        assert np.isnan(got.second_moment).all()
        assert not np.isfinite(bound.second_moment).any()


@pytest.mark.usefixtures("engine_path")
def test_a_label_out_of_range_is_refused_on_both_paths():
    """A face labelled past ``n_labels``: a ValueError naming the range on either path (the numpy twin raised an
    IndexError or a broadcast error, by where the label fell)."""
    m = trimesh.creation.box((1.0, 1.0, 1.0))
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    labels = np.zeros(len(f), dtype=np.intp)
    labels[3] = 2
    with pytest.raises(ValueError, match=r"Expected labels in 0\.\.1"):
        body_volume_moments(v, f, labels, 2)
