"""The engine's per-part Python costs cut for batches of small parts (issue 25 item 6), checked against the code
they replaced: principal axes without ``numpy.linalg.qr``, the plane basis on floats, one finiteness test per
``MassProperties``, frozen values stored without a call per field."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.errors import NonFiniteResultError
from inertia_tool.mass.principal import principal_axes
from inertia_tool.mass.properties import MassProperties
from inertia_tool.rotations import perpendicular_basis
from inertia_tool.values import frozen_value

EPS = np.finfo(float).eps


def _reference_axes(tensor: np.ndarray, rtol: float = 1e-6) -> tuple[np.ndarray, np.ndarray, tuple]:
    """The principal axes as the engine computed them before (``numpy.linalg.qr`` with the sign of ``R``'s
    diagonal, ``np.cross``, the array form of the plane basis): the independent code the new path must match."""
    t = 0.5 * (tensor + tensor.T)
    moments, vecs = np.linalg.eigh(t)
    scale = max(abs(moments[-1]), np.finfo(float).tiny)
    eq01 = abs(moments[1] - moments[0]) <= rtol * scale
    eq12 = abs(moments[2] - moments[1]) <= rtol * scale
    eq02 = abs(moments[2] - moments[0]) <= rtol * scale
    pairs = tuple(p for p, flag in (((0, 1), eq01), ((1, 2), eq12), ((0, 2), eq02)) if flag)

    def sign(v):
        k = int(np.argmax(np.abs(v)))
        return -v if v[k] < 0 else v

    def basis(n):
        k = int(np.argmin(np.abs(n)))
        e1 = -n[k] * n
        e1[k] += 1.0
        e1 /= np.linalg.norm(e1)
        return e1, np.cross(n, e1)

    if eq01 and eq12 or eq02:
        axes, pairs = np.eye(3), ((0, 1), (1, 2), (0, 2))
    elif eq01:
        a3 = sign(vecs[:, 2])
        axes = np.column_stack([*basis(a3), a3])
    elif eq12:
        a1 = sign(vecs[:, 0])
        axes = np.column_stack([a1, *basis(a1)])
    else:
        a1, a2 = sign(vecs[:, 0]), sign(vecs[:, 1])
        axes = np.column_stack([a1, a2, np.cross(a1, a2)])
    q, r = np.linalg.qr(axes)
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 2] = -q[:, 2]
    return moments, q, pairs


def _rotation(quaternion: list[float]) -> np.ndarray:
    w, x, y, z = np.asarray(quaternion) / np.linalg.norm(quaternion)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


_QUAT = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: math.fsum(c * c for c in q) > 1e-3)
_MOMENT = st.floats(1e-3, 1e3)


@st.composite
def _tensors(draw):
    """Inertia tensors ``R diag(I) Rᵀ`` at any scale: generic, two moments equal (a rotor, either pair), three
    equal (a sphere or cube), and moments a rounding apart (the tolerance's edge)."""
    kind = draw(st.sampled_from(["generic", "low pair", "high pair", "spherical", "near"]))
    a, b, c = sorted(draw(st.lists(_MOMENT, min_size=3, max_size=3)))
    moments = {"generic": [a, b, c], "low pair": [a, a, c], "high pair": [a, c, c], "spherical": [b, b, b],
               "near": [a, a * (1 + draw(st.floats(0, 3e-6))), c]}[kind]
    rotation = _rotation(draw(_QUAT))
    scale = 10.0 ** draw(st.integers(-12, 6))
    return rotation @ np.diag(moments) @ rotation.T * scale


@settings(max_examples=400, deadline=None)
@given(_tensors())
def test_principal_axes_match_the_qr_reference(tensor):
    """Moments bit for bit (the same ``eigh``), the same equal pairs, axes within a few units in the last place of
    the QR-based reference, orthonormal and right-handed."""
    pa = principal_axes(tensor)
    moments, axes, pairs = _reference_axes(tensor)
    assert pa.moments.tobytes() == moments.tobytes()
    assert pa.equal_pairs == pairs
    np.testing.assert_allclose(pa.axes, axes, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(pa.axes.T @ pa.axes, np.eye(3), rtol=0, atol=4 * EPS)
    assert abs(np.linalg.det(pa.axes) - 1.0) <= 4 * EPS
    assert not pa.axes.flags.writeable


def test_principal_axes_of_a_sphere_are_the_identity_exactly():
    pa = principal_axes(np.eye(3) * 2.5)
    assert pa.axes.tobytes() == np.eye(3).tobytes()
    assert pa.is_spherical


@pytest.mark.parametrize("moments", [[1.0, 1.0, 2.0], [1.0, 2.0, 2.0]])
def test_principal_axes_of_a_rotor_follow_the_conventions(moments):
    """An axisymmetric tensor in mesh axes: the symmetry axis along the odd moment's column, the plane's basis
    the deterministic one of ``docs/conventions.md`` (for the z axis: e1 = x, e2 = y)."""
    pa = principal_axes(np.diag(moments))
    odd = 2 if moments[0] == moments[1] else 0
    np.testing.assert_array_equal(np.abs(pa.axes[:, odd]), [0.0, 0.0, 1.0] if odd == 2 else [1.0, 0.0, 0.0])
    np.testing.assert_allclose(pa.axes @ np.diag(pa.moments) @ pa.axes.T, np.diag(moments), atol=1e-15)
    assert pa.is_axisymmetric


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: math.fsum(c * c for c in v) > 1e-4))
def test_perpendicular_basis_on_floats_matches_the_array_form(values):
    n = np.asarray(values) / np.linalg.norm(values)
    e1, e2 = perpendicular_basis(n)
    k = int(np.argmin(np.abs(n)))
    ref1 = -n[k] * n
    ref1[k] += 1.0
    ref1 /= np.linalg.norm(ref1)
    np.testing.assert_allclose(e1, ref1, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(e2, np.cross(n, ref1), rtol=0, atol=4 * EPS)
    frame = np.column_stack([e1, e2, n])
    np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=8 * EPS)
    assert np.linalg.det(frame) > 0


def test_perpendicular_basis_refuses_a_matrix():
    with pytest.raises(ValueError, match=r"shape \(3,\), got \(3, 3\)"):
        perpendicular_basis(np.eye(3))


@pytest.mark.parametrize("field", ["mass", "volume", "surface_area", "center_of_mass", "inertia"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_mass_properties_refuse_every_non_finite_field(field, bad):
    """One finite sum replaced five checks: a NaN or an infinity anywhere still raises, naming the field."""
    values = dict(mass=2.0, volume=1e-3, surface_area=0.06, center_of_mass=np.zeros(3), inertia=np.eye(3))
    if field in ("center_of_mass", "inertia"):
        arr = np.array(values[field], dtype=float)
        arr.flat[1] = bad
        values[field] = arr
    else:
        values[field] = bad
    names = {"center_of_mass": "centre of mass", "inertia": "inertia tensor", "surface_area": "surface area"}
    with pytest.raises(NonFiniteResultError, match=names.get(field, field)):
        MassProperties(**values, density=2000.0, name="part")


def test_mass_properties_accept_finite_values_whose_sum_overflows():
    """The one-sum test overflows for values near the float64 limit; the checks one by one then pass them."""
    big = 1e308
    props = MassProperties(mass=big, volume=big, surface_area=big, center_of_mass=[big, big, big],
                           inertia=np.full((3, 3), big), density=1.0)
    assert props.mass == big and np.all(props.inertia == big)


def test_mass_properties_store_read_only_copies():
    com = np.array([1.0, 2.0, 3.0])
    props = MassProperties(mass=1, volume=1, center_of_mass=com, inertia=np.eye(3))
    com[0] = 99.0
    assert props.center_of_mass[0] == 1.0 and not props.center_of_mass.flags.writeable
    assert type(props.mass) is float and type(props.volume) is float
    with pytest.raises(dataclasses.FrozenInstanceError):
        props.mass = 2.0  # type: ignore[misc]


def test_frozen_value_init_stores_fields_in_the_instance_dictionary():
    """The generated ``__init__`` writes the instance dictionary: defaults, factories, the refusal afterwards and
    read-only copies of small arrays, as the call-per-field version did."""

    @frozen_value
    class Sample:
        a: np.ndarray
        b: int = 3
        c: list = dataclasses.field(default_factory=list)

    arr = np.arange(3.0)
    s = Sample(arr)
    assert s.__dict__.keys() == {"a", "b", "c"} and s.b == 3 and s.c == []
    assert not s.a.flags.writeable and not np.shares_memory(s.a, arr)
    assert Sample(arr) == s and hash(Sample(arr)) == hash(s)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.b = 4  # type: ignore[misc]


# -- Dask's short batches: one chunk per worker --------------------------------------------------------------

def test_dask_short_batch_is_one_equal_chunk_per_worker():
    """200 equal parts under a round of 0.5 s chunks on 2 workers: 2 chunks of 100 on Dask (each task costs the
    cluster milliseconds), 4 of 50 on a process pool; unequal files split by weight, not by count."""
    from test_batch_chunks import _drive

    from inertia_tool.batch.chunks import DASK_SHORT_CHUNKS_PER_WORKER, POOL_SHORT_CHUNKS_PER_WORKER, ChunkSizer

    assert (DASK_SHORT_CHUNKS_PER_WORKER, POOL_SHORT_CHUNKS_PER_WORKER) == (1, 2)
    s = ChunkSizer([50_000.0] * 200, 0.5, tail_seconds=0.02, prior_seconds_per_byte=2e-8, short_chunks_per_worker=1)
    assert _drive(s, 2, lambda a, b: (b - a) * 1e-3) == [100, 100]
    s = ChunkSizer([50_000.0] * 200, 0.5, tail_seconds=0.02, prior_seconds_per_byte=2e-8)
    assert _drive(s, 2, lambda a, b: (b - a) * 1e-3) == [50, 50, 50, 50]
    s = ChunkSizer([1_000.0] * 100 + [99_000.0] * 100, 1.0, prior_seconds_per_byte=2e-8, short_chunks_per_worker=1)
    assert _drive(s, 2, lambda a, b: 0.0) == [149, 51]                    # the boundary nearest 5 MB
    s = ChunkSizer([50_000.0] * 30, 0.5, prior_seconds_per_byte=2e-8, short_chunks_per_worker=1)
    sizes = _drive(s, 4, lambda a, b: (b - a) * 1e-3)
    assert len(sizes) == 4 and set(sizes) == {7, 8}                       # 30 / 4, no 5th chunk of rounding
    with pytest.raises(ValueError, match="short_chunks_per_worker"):
        ChunkSizer([1.0], 0.5, short_chunks_per_worker=0)


@settings(max_examples=40, deadline=None)
@given(files=st.integers(1, 3000), per_file=st.sampled_from([0.0005, 0.0015, 0.004, 0.03]),
       spread=st.floats(0.0, 3.0), seed=st.integers(0, 2**16), prior=st.sampled_from([0.1, 1.0, 10.0]))
def test_dask_short_batches_take_one_task_per_worker_and_bound_the_wait(files, per_file, spread, seed, prior):
    """Files of random sizes on two Dask workers (the model of ``test_batch_chunks._makespan``), the prior off by
    10x either way: a short batch takes 2 chunks plus one per file heavier than a chunk (and more where a half
    holds over ``max_files`` files), and ends at most half its work plus two files after the ideal; a long one is
    sized as before."""
    from test_batch_chunks import _makespan

    from inertia_tool.batch.chunks import DASK_CHUNK_SECONDS, DASK_TAIL_SECONDS, ChunkSizer

    rng = np.random.default_rng(seed)
    weights = 33_000.0 * np.exp(spread * rng.standard_normal(files))
    rate = per_file / 33_000.0
    sizer = ChunkSizer(weights, DASK_CHUNK_SECONDS, tail_seconds=DASK_TAIL_SECONDS,
                       prior_seconds_per_byte=rate * prior, short_chunks_per_worker=1)
    total = float(weights.sum()) * rate
    makespan, chunks = _makespan(weights, rate, 2, sizer)
    largest = float(weights.max()) * rate
    assert makespan >= total / 2 - 1e-9
    if total * prior <= 4 * DASK_CHUNK_SECONDS:
        heavy = int(np.count_nonzero(weights > weights.sum() / 2))
        # a chunk holds at most max_files (1,000) files: a half of more is cut again
        assert chunks <= min(2 + heavy + files // sizer.max_files, files)
        assert makespan - total / 2 <= total / 2 + 2 * largest + 1e-9
    else:
        assert makespan - total / 2 <= max(DASK_TAIL_SECONDS, DASK_CHUNK_SECONDS / prior) + 2 * largest + 1e-9


# -- the steps moved onto Python floats: the same bits as their array form ---------------------------------

_COORD = st.floats(-1e6, 1e6, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(st.floats(1e-9, 1e9) | st.floats(-1e9, -1e-9), st.lists(_COORD, min_size=3, max_size=3),
       st.lists(_COORD, min_size=9, max_size=9), st.lists(_COORD, min_size=3, max_size=3))
def test_shell_moments_on_floats_are_the_array_form_bit_for_bit(volume, first, second, origin):
    """``_finish`` (a shell's centroid and central second moment) on floats: the array form's bits."""
    from inertia_tool.integrals import _finish

    first_a, second_a, origin_a = np.array(first), np.array(second).reshape(3, 3), np.array(origin)
    got = _finish(volume, first_a, second_a, 1.0, origin_a)
    d = first_a / volume
    central = second_a - volume * np.outer(d, d)
    central = 0.5 * (central + central.T)
    assert got.second_moment.tobytes() == central.tobytes()
    assert got.centroid.tobytes() == (origin_a + d).tobytes()
    assert got.volume == volume and got.area == 1.0


def test_shell_of_no_volume_has_no_centroid():
    from inertia_tool.integrals import _finish

    got = _finish(0.0, np.zeros(3), np.eye(3), 2.0, np.ones(3))
    assert np.isnan(got.centroid).all() and got.second_moment.tobytes() == np.eye(3).tobytes()


@pytest.mark.parametrize("lo, hi, match", [
    ([0.0, 0.0, 0.0], [1e31, 1.0, 1.0], r"reach 1e\+31 m"),
    ([-math.inf, 0.0, 0.0], [math.inf, 1.0, 1.0], "reach inf m"),
    ([math.nan, 0.0, 0.0], [1.0, 1.0, 1.0], "reach nan m"),
    ([0.0, 0.0, 0.0], [1e-31, 0.0, 0.0], "spans only 1e-31 m"),
])
def test_magnitude_check_on_floats_keeps_its_messages(lo, hi, match):
    """The bounding box's magnitude check on floats refuses what it refused, with the same words (NaN and
    infinity named as numpy's max named them)."""
    from inertia_tool.errors import InvalidMeshError
    from inertia_tool.mesh.surface import check_magnitude

    with pytest.raises(InvalidMeshError, match=match):
        check_magnitude(np.array(lo), np.array(hi), "part.stl")
    check_magnitude(np.array([-1.0, -2.0, -3.0]), np.array([1.0, 2.0, 3.0]), "part.stl")   # a plain box passes


def test_needle_warning_still_names_the_digits():
    """The needle check of the principal moments (on floats now): a rod whose smallest moment is 1e-12 of the
    largest warns with the digits it carries, -log10(eps · I3 / I1) = 3.65, printed 4."""
    from inertia_tool.errors import PhysicalValidityWarning
    from inertia_tool.mass.pipeline import _warn_about_principal

    props = MassProperties(mass=1.0, volume=1.0, center_of_mass=np.zeros(3),
                           inertia=np.diag([1e-12, 1.0, 1.0 + 1e-3]), density=1.0, name="rod")
    with pytest.warns(PhysicalValidityWarning, match=r"a needle\); it carries only about 4 correct digits"):
        _warn_about_principal(props, "rod")
    thick = MassProperties(mass=1.0, volume=1.0, center_of_mass=np.zeros(3),
                           inertia=np.diag([1e-9, 1.0, 1.0 + 1e-3]), density=1.0, name="rod")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _warn_about_principal(thick, "rod")                  # 1e-9 of the largest: above the needle limit
