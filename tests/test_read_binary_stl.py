"""The binary-STL read path of ``mesh/read.py`` (records chunk by chunk -> the C extension's radix-partition
weld -> one pass for finiteness and the largest magnitude) against the pure-numpy reference path
(``INERTIA_TOOL_NO_ACCEL``: padded chunks, sorted 64-bit keys, ``numpy.isfinite`` and ``numpy.abs``) and against
a Python dict on the bit patterns: the same vertices bit for bit, the same faces, the same float32 storage
rounding, and the same refusal of NaN and infinite coordinates.

The inputs are adversarial for a hash weld: many equal points, -0.0 beside +0.0 (one point), subnormals next to
zero, the largest float32 magnitudes of either sign (the magnitude comes from the most negative coordinate),
points recurring far apart (past the recent-point cache, in another chunk and another thread's part).
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from inertia_tool.errors import MeshReadError
from inertia_tool.mesh import read as read_mod
from inertia_tool.mesh import read_stl as stl_mod
from inertia_tool.mesh import weld as weld_mod
from inertia_tool.mesh.precision import float32_rounding
from test_weld_partition import _dict_weld

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")

_RECORD = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
#: Coordinates a hash weld can get wrong: signed zeros, subnormals, the extremes of float32, near-equal values.
_COORDS = np.array([0.0, -0.0, 2.0 ** -149, -(2.0 ** -149), 2.0 ** -126, 1.0, np.nextafter(np.float32(1), 2),
                    -1.0, 3.4e38, -3.4e38, 1e-30, 7.25, -7.25, 1e6], dtype=np.float32)


def _write(path, corners: np.ndarray) -> None:
    rec = np.zeros(len(corners), dtype=_RECORD)
    rec["v"] = corners
    rec["n"] = 1.0
    path.write_bytes(b"binary".ljust(80, b" ") + np.uint32(len(rec)).tobytes() + rec.tobytes())


def _load_both(path) -> tuple:
    """load_mesh on the C extension (radix partition forced, chunks of 37 faces) and on the numpy reference."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(weld_mod, "PARTITION_MIN_POINTS", 1)
        mp.setattr(stl_mod, "_CHUNK_FACES", 37)
        fast = read_mod.load_mesh(str(path))
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(_native.NO_ACCEL_ENV, "1")
        mp.setattr(stl_mod, "_CHUNK_FACES", 37)
        ref = read_mod.load_mesh(str(path))
    return fast, ref


@settings(max_examples=40, deadline=None)
@given(n_faces=st.integers(1, 300), alphabet=st.integers(1, 12), seed=st.integers(0, 2**32 - 1),
       far=st.booleans())
def test_binary_stl_fast_path_matches_numpy_reference_and_dict(tmp_path_factory, n_faces, alphabet, seed, far):
    """Random soups over a few adversarial points (many equal keys), optionally repeated after 5,001 distinct
    filler points: vertices bit for bit, faces and storage rounding equal on both paths and to the dict."""
    rng = np.random.default_rng(seed)
    points = rng.choice(_COORDS, size=(alphabet, 3)).astype(np.float32)
    corners = points[rng.integers(0, alphabet, size=3 * n_faces)]
    if far:
        filler = np.arange(15_003, dtype=np.float32).reshape(-1, 3) * np.float32(0.5) - np.float32(3e3)
        corners = np.concatenate([corners, filler, corners[::-1]])
    path = tmp_path_factory.mktemp("stl") / "soup.stl"
    _write(path, corners.reshape(-1, 3, 3))
    fast, ref = _load_both(path)
    np.testing.assert_array_equal(fast.vertices.view(np.uint64), ref.vertices.view(np.uint64))
    np.testing.assert_array_equal(fast.faces, ref.faces)
    assert fast.storage_rounding == ref.storage_rounding
    vertices, ids = _dict_weld(corners)
    np.testing.assert_array_equal(fast.vertices.view(np.uint64), vertices.view(np.uint64))
    np.testing.assert_array_equal(fast.faces.reshape(-1), ids)
    assert not np.signbit(fast.vertices[fast.vertices == 0]).any()          # -0.0 welded onto +0.0
    assert fast.storage_rounding == float32_rounding(float(np.abs(corners.astype(np.float64)).max()))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", [0, 4_000, -1])
def test_binary_stl_nan_or_infinity_is_refused_on_both_paths(tmp_path, bad, where):
    """One NaN or infinite coordinate anywhere (first corner, a later chunk, the last corner) is refused with
    the same one-line error on the C path and the numpy path, naming the file."""
    corners = np.random.default_rng(5).normal(size=(5_001, 3)).astype(np.float32)
    corners[where, 1] = bad
    path = tmp_path / "bad.stl"
    _write(path, corners.reshape(-1, 3, 3))
    messages = []
    for env in (None, "1"):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(weld_mod, "PARTITION_MIN_POINTS", 1)
            if env:
                mp.setenv(_native.NO_ACCEL_ENV, env)
            with pytest.raises(MeshReadError, match="NaN or infinite") as err:
                read_mod.load_mesh(str(path))
        messages.append(str(err.value))
    assert messages[0] == messages[1] and "bad.stl" in messages[0] and "\n" not in messages[0]


@pytest.mark.parametrize("values", [
    [[-0.0, 0.0, -0.0]],                                  # only zeros: magnitude +0.0
    [[1.0, -3.4e38, 2.0], [0.0, 5.0, 6.0]],               # the magnitude from the most negative coordinate
    [[2.0 ** -149, -(2.0 ** -149), 0.0]],                 # subnormals
    [[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]],
])
def test_finite_magnitude_is_numpy_max_abs(values):
    """One C pass (column extremes) gives numpy's max |v| exactly, as a non-negative float."""
    v = np.array(values, dtype=np.float64)
    got = stl_mod._finite_magnitude(v)
    assert got is not None and got == float(np.max(np.abs(v))) and not np.signbit(got)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_finite_magnitude_refuses_nan_and_infinity(bad):
    v = np.zeros((1000, 3))
    v[617, 2] = bad
    assert stl_mod._finite_magnitude(v) is None
    assert stl_mod._finite_magnitude(v[:, ::-1]) is None                   # not contiguous: numpy's pass


def test_binary_stl_cut_short_while_read_is_refused(tmp_path, monkeypatch):
    """A file that holds fewer records than the count checked before reading (cut short meanwhile) ends the
    chunk reader with a one-line error saying how many triangles were there, not a short or stale chunk of the
    reused buffer."""
    corners = np.arange(3 * 3 * 100, dtype=np.float32).reshape(-1, 3, 3)
    path = tmp_path / "cut.stl"
    _write(path, corners)
    monkeypatch.setattr(stl_mod, "_CHUNK_FACES", 30)
    views = stl_mod._binary_stl_chunks(str(path), 130, padded=False)
    seen = []
    with pytest.raises(MeshReadError, match=r"ended after 100 of 130 triangles"):
        for v in views():
            seen.append(v.copy())
    np.testing.assert_array_equal(np.concatenate(seen), corners[:90])
