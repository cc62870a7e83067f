"""The small-part paths of the round-off bound (``inertia_tool.integrals``) against their references, bit for bit.

A small part spends most of its engine time in numpy calls on arrays of a few elements: the per-face sums of
``roundoff_bounds`` now run in C (``_accel.roundoff_sums``) and the one-shell tails of ``roundoff_bounds`` and
``_shares`` on Python floats.  Each must give the very bits of the numpy code it replaces (the same operations
in the same order), on hypothesis-generated meshes: far from the origin, tiny and huge, flat slivers, several
labels, chunk boundaries; and whole analyses with the fast paths must give the results and certificates of the
reference paths.
"""

import math
import warnings

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native, integrals
from inertia_tool.integrals import VolumeMoments, body_volume_moments, reference_point, roundoff_bounds

needs_accel = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")

FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _bits(x) -> bytes:
    """The exact bytes of a float64 array (NaN and -0.0 compared by their bits, not by value)."""
    return np.ascontiguousarray(np.asarray(x, dtype=np.float64)).tobytes()


@st.composite
def small_meshes(draw, max_labels=3):
    """``(vertices, faces, labels, n_labels)``: 4-40 vertices at a drawn scale and offset (1e-6 to 1e6 m, up to
    1e7 away), 1-60 faces of random corners (repeated corners and slivers included), labels 0..n-1 each used."""
    n = draw(st.integers(4, 40))
    scale = 10.0 ** draw(st.integers(-6, 6))
    offset = draw(st.sampled_from([0.0, 1.0, 1e3, 1e7, -3.3e5]))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, 3)) * scale + offset
    if draw(st.booleans()):                     # coordinates on a grid (many exact zeros and equal values)
        v = np.round(v / scale * 4) * scale / 4
    m = draw(st.integers(1, 60))
    f = rng.integers(0, n, size=(m, 3))
    n_labels = draw(st.integers(1, max_labels))
    labels = np.arange(m) % n_labels if m >= n_labels else np.zeros(m, dtype=np.int64)
    n_labels = int(labels.max()) + 1
    rng.shuffle(labels)
    dtype = draw(st.sampled_from([np.int32, np.int64]))
    return v, f.astype(dtype), labels.astype(np.intp), n_labels


@needs_accel
@FAST
@given(mesh=small_meshes(), chunk=st.sampled_from([1, 3, 7, 32768]))
def test_c_roundoff_sums_are_the_numpy_sums_bit_for_bit(mesh, chunk):
    v, f, labels, n = mesh
    o = reference_point(v)
    lib = _native.accel()
    c = integrals._roundoff_sums_c(lib, v, f, labels, n, o, chunk)
    ref = integrals._roundoff_sums(v, f, labels, n, o, chunk)
    assert _bits(c) == _bits(ref)


@FAST
@given(mesh=small_meshes(max_labels=1))
def test_one_shell_bound_is_the_array_bound_bit_for_bit(mesh):
    v, f, labels, _ = mesh
    o = reference_point(v)
    shell = body_volume_moments(v, f, labels, 1, origin=o)[0]
    sums = integrals._roundoff_sums(v, f, labels, 1, o, 32768)
    fast = integrals._one_shell_bound(sums[0], len(f), shell, o)
    ref = integrals._shells_bound(sums, np.array([len(f)]), [shell], o)
    for name in ("volume", "centroid", "second_moment"):
        assert _bits(getattr(fast, name)) == _bits(getattr(ref, name)), name


@pytest.mark.usefixtures("engine_path")
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(mesh=small_meshes())
def test_both_paths_are_charged_the_compensated_sums(mesh):
    """Both engine paths sum compensated (C: Sum2) or better (numpy: an error-free tree), so ``roundoff_bounds``
    charges each shell of m faces ``(u + (2 + m²u)·u)·Σ P / 6`` on its volume, whichever path runs; the plain
    sum's ``m·u`` (the dead ``compensated=False`` branch, removed in session 17) is charged by neither."""
    from fractions import Fraction
    v, f, labels, n = mesh
    o = reference_point(v)
    shells = body_volume_moments(v, f, labels, n, origin=o)
    bound = roundoff_bounds(v, f, labels, shells, o)
    sums = integrals._roundoff_sums(v, f, labels, n, o, 32768)
    counts = np.bincount(labels, minlength=n)
    u = Fraction(integrals._U)
    for k in range(n):
        m = int(counts[k])
        expected = (u + (2 + m * m * u) * u) * Fraction(float(sums[k, 0])) / 6
        # the bound is computed in float64: a few roundings of a positive expression
        assert abs(Fraction(float(bound.volume[k])) - expected) <= 8 * u * expected, (k, m)


def test_one_shell_bound_of_a_shell_without_volume_is_infinite():
    shell = VolumeMoments(volume=0.0, centroid=np.full(3, np.nan), second_moment=np.zeros((3, 3)), area=1.0)
    sums = np.array([[1.0, 2.0, 3.0]])
    fast = integrals._one_shell_bound(sums[0], 4, shell, np.zeros(3))
    ref = integrals._shells_bound(sums, np.array([4]), [shell], np.zeros(3))
    assert math.isinf(fast.centroid[0]) and math.isinf(fast.second_moment[0])
    for name in ("volume", "centroid", "second_moment"):
        assert _bits(getattr(fast, name)) == _bits(getattr(ref, name)), name


@FAST
@given(mesh=small_meshes(max_labels=1), magnitude=st.booleans(), only=st.sampled_from([None, 0]),
       errors=st.lists(st.floats(0, 1e-3, allow_subnormal=False), min_size=3, max_size=3))
def test_one_shell_shares_are_the_array_shares_bit_for_bit(mesh, magnitude, only, errors):
    v, f, labels, _ = mesh
    shell = body_volume_moments(v, f, labels, 1)[0]
    e = [np.array([x]) for x in errors]
    fast = integrals._one_shell_shares(shell, *e, only, magnitude)
    ref = integrals._many_shares([shell], *e, only, magnitude)
    for a, b in zip(fast, ref):
        assert _bits(a) == _bits(b)


def _reference_paths(monkeypatch):
    """Route the integrals through the code the small-part paths replace."""
    monkeypatch.setattr(integrals, "_roundoff_sums_c",
                        lambda lib, v, f, lab, n, o, chunk: integrals._roundoff_sums(v, f, lab, n, o, chunk))
    monkeypatch.setattr(integrals, "_one_shell_bound",
                        lambda sums, m, shell, o: integrals._shells_bound(sums[None], np.array([m]), [shell], o))
    monkeypatch.setattr(integrals, "_one_shell_shares",
                        lambda shell, *rest: integrals._many_shares([shell], *rest))


def _analysis(v, f):
    from inertia_tool.mass.pipeline import mass_properties
    from inertia_tool.errors import InertiaToolError
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties((v, f), density=1000.0)
    except InertiaToolError as exc:
        return ("refused", type(exc).__name__, str(exc))
    report = props.mesh
    return (_bits([props.mass, props.volume, props.surface_area]), _bits(props.center_of_mass),
            _bits(props.inertia), report.certificate, report.method, report.notes)


@st.composite
def small_solids(draw):
    """A closed small part: a box, an icosphere or a convex hull of random points, at a drawn scale and offset,
    sometimes two apart or one inside the other (two shells)."""
    kind = draw(st.sampled_from(["box", "sphere", "hull"]))
    scale = 10.0 ** draw(st.integers(-4, 4))
    offset = draw(st.sampled_from([0.0, 1e3, 1e6]))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    if kind == "box":
        m = trimesh.creation.box(rng.uniform(0.2, 3, 3))
    elif kind == "sphere":
        m = trimesh.creation.icosphere(subdivisions=int(rng.integers(0, 2)))
    else:
        m = trimesh.convex.convex_hull(rng.standard_normal((12, 3)))
    v, f = np.asarray(m.vertices) * scale + offset, np.asarray(m.faces)
    shells = draw(st.sampled_from(["one", "apart", "cavity"]))
    if shells == "apart":
        v, f = np.vstack([v, v + 10 * scale]), np.vstack([f, f + len(v)])
    elif shells == "cavity":
        centre = v.mean(axis=0)
        v, f = np.vstack([v, centre + 0.3 * (v - centre)]), np.vstack([f, f[:, ::-1] + len(v)])
    return v, f


@pytest.mark.usefixtures("engine_path")
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(solid=small_solids())
def test_analyses_with_the_small_part_paths_equal_the_reference(solid, monkeypatch):
    """Results, certificates, methods and notes of whole analyses are those of the reference paths, bit for bit."""
    v, f = solid
    fast = _analysis(v, f)
    with monkeypatch.context() as mp:
        _reference_paths(mp)
        ref = _analysis(v, f)
    assert fast == ref


@pytest.mark.parametrize("offset", [0.0, 1e3])
def test_one_shell_over_its_budget_is_still_integrated_again(offset):
    """The one-shell shortcut of accurate_shells returns early only when the bound is within the budget: with a
    budget no float64 sum meets (``rtol=1e-30``) the shell is integrated again, then exactly."""
    m = trimesh.creation.box((1.0, 2.0, 1e-3))
    v, f = np.asarray(m.vertices) + offset, np.asarray(m.faces)
    labels = np.zeros(len(f), dtype=np.intp)
    shells = body_volume_moments(v, f, labels, 1)
    better, refined, bound = integrals.accurate_shells(v, f, labels, shells, rtol=1e-30)
    exact = integrals.exact_volume_moments(v, f)
    assert refined == 1
    assert better[0].volume == exact.volume
    np.testing.assert_array_equal(better[0].centroid, exact.centroid)
    assert bound.volume[0] == integrals._U * abs(exact.volume)
    _, refined, _ = integrals.accurate_shells(v, f, labels, shells)
    assert refined == 0


@needs_accel
def test_roundoff_sums_refuses_bad_arguments():
    lib = _native.accel()
    v = np.zeros((4, 3))
    f = np.array([[0, 1, 2]])
    out = np.empty((1, 3))
    with pytest.raises(ValueError, match="face indices"):
        lib.roundoff_sums(v, np.array([[0, 1, 9]]), (0.0, 0.0, 0.0), None, out, 8)
    with pytest.raises(ValueError, match="labels in 0..1"):
        lib.roundoff_sums(v, f, (0.0, 0.0, 0.0), np.array([5]), np.empty((2, 3)), 8)
    with pytest.raises(ValueError, match="chunk_size"):
        lib.roundoff_sums(v, f, (0.0, 0.0, 0.0), None, out, 0)
    with pytest.raises(ValueError, match="n_labels"):
        lib.roundoff_sums(v, f, (0.0, 0.0, 0.0), None, np.empty((2, 3)), 8)
    with pytest.raises(ValueError, match="vertices"):
        lib.roundoff_sums(v.astype(np.float32), f, (0.0, 0.0, 0.0), None, out, 8)


def test_bound_holds_on_random_small_meshes_both_paths(monkeypatch):
    """The bound (unchanged by the fast paths) still contains the actual error against exact arithmetic."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        m = trimesh.convex.convex_hull(rng.standard_normal((10, 3)))
        v = np.asarray(m.vertices) * 10.0 ** rng.integers(-3, 4) + rng.choice([0.0, 1e4, 1e7])
        f = np.asarray(m.faces)
        labels = np.zeros(len(f), dtype=np.intp)
        o = reference_point(v)
        shell = body_volume_moments(v, f, labels, 1, origin=o)[0]
        bound = roundoff_bounds(v, f, labels, [shell], o)
        exact = integrals.exact_volume_moments(v, f)
        assert abs(shell.volume - exact.volume) <= bound.volume[0] + 2 * integrals._U * abs(exact.volume)


@pytest.mark.usefixtures("engine_path")
def test_roundoff_bounds_of_no_shells_is_empty_on_both_paths():
    """Regression (review of batch2): with no shells the C path refused its (0, 3) output ("Expected `out` ...")
    where the numpy twin returns empty bounds; both return empty bounds now."""
    v = np.zeros((3, 3))
    bound = roundoff_bounds(v, np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.intp), [], np.zeros(3))
    for name in ("volume", "centroid", "second_moment"):
        assert getattr(bound, name).shape == (0,)


@pytest.mark.parametrize("no_accel", [False, True])
def test_accurate_shells_of_no_shells_is_empty_on_both_paths(monkeypatch, no_accel):
    """No shells: nothing to bound or refine (before: a broadcast ValueError on both engine paths)."""
    from inertia_tool.integrals import accurate_shells
    if no_accel:
        monkeypatch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
    shells, refined, bounds = accurate_shells(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
                                              np.zeros(0, dtype=np.int64), [])
    assert shells == [] and refined == 0 and len(bounds.volume) == 0 and len(bounds.second_moment) == 0


@FAST
@given(mesh=small_meshes(max_labels=4), magnitude=st.booleans(),
       errors=st.lists(st.floats(0, 1e-3, allow_subnormal=False), min_size=3, max_size=3))
def test_one_shells_shares_of_many_are_the_full_shares_bit_for_bit(mesh, magnitude, errors):
    """``_many_shares(..., only=k)`` (issue 25, unique19: the total ``‖I‖`` is no longer summed over every shell for
    each refined one) gives the bits of shell ``k``'s shares in the call without ``only``, and ``|V|`` the same."""
    v, f, labels, n = mesh
    if n < 2:
        return
    shells = body_volume_moments(v, f, labels, n)
    e = [x * np.arange(1.0, n + 1) for x in errors]          # (volume, centroid, second moment) per shell
    full_v, full_i, total_v, total_i = integrals._many_shares(shells, *e, None, magnitude)
    for k in range(n):
        sv, si, tv, ti = integrals._many_shares(shells, *e, k, magnitude)
        assert _bits(sv) == _bits(full_v[k]) and _bits(si) == _bits(full_i[k]) and _bits(tv) == _bits(total_v)
        assert math.isnan(ti)
