"""``_accel.winding_tree`` (C, ``_accel.c`` section 13) against ``winding._treecode_numpy`` (the reference).

The claim (issue 25, corpus13): the C kernel takes the same clusters, decisions and terms as the numpy treecode and
sums them in the same order, so on x86-64 (where numpy's 3-vector einsum, ``arctan2`` and ``**`` round as the kernel
writes them out) every value and every error bound is numpy's **bit for bit**, at points far from, near to and
exactly on the surface (where the sign of a zero numerator decides a solid angle of ±2π).  Anywhere, each value lies
within its own bound of the exact direct sum (off the surface) and within round-off of numpy's.

Surfaces drawn by hypothesis: two overlapping spheres (winding numbers 0, 1, 2) and an axis-aligned box, moved far
from the origin and scaled, with a stray soup of random triangles (slivers, duplicates, zero-area faces) added;
points uniform in the box, pushed 10⁻¹²…10⁻² off a face along its normal, on a face, in the plane of a box face
exactly, at vertices; tolerances 10⁻⁶…10⁻¹; the vectorised block of (point, leaf) pairs shrunk so that one point's
leaves span several blocks (numpy's sums split there).
"""

from __future__ import annotations

import math
import platform

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

import inertia_tool.mesh.winding as winding
from inertia_tool._native import accel

from conftest import HAVE_ACCEL, REQUIRE_ACCEL

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")

def _numpy_arctan2_is_libm() -> bool:
    """numpy's float64 arctan2 is the C library's where numpy dispatches no SIMD version of it: on x86-64 CPUs
    with AVX-512 (numpy 2.4's ``X86_V4`` group) numpy uses its own vectorised arctan2, within an ulp of libm's
    but not bit for bit (7 % of random pairs differ), and the kernel calls libm's ``atan2``."""
    rng = np.random.default_rng(0)
    y, x = rng.normal(size=4096), rng.normal(size=4096)
    ours = np.arctan2(y, x)
    return all(float(a) == math.atan2(float(b), float(c)) for a, b, c in zip(ours, y, x))


#: numpy rounds its 3-vector einsum, arctan2 and ``**`` as the kernel writes them out (measured on x86-64),
#: arctan2 only where it is libm's (not under numpy's AVX-512 dispatch); elsewhere the error-bounded
#: comparisons below still hold
BITWISE = platform.machine().lower() in ("x86_64", "amd64") and _numpy_arctan2_is_libm()


def _surface(shift: float, inner: float, scale: float, far: float, stray: int, seed: int
             ) -> tuple[np.ndarray, np.ndarray]:
    a = trimesh.creation.icosphere(2)
    b = trimesh.creation.icosphere(1, radius=inner)
    box = trimesh.creation.box([1.0, 1.0, 1.0])          # axis-aligned faces: points exactly in their planes
    v = np.vstack([np.asarray(a.vertices), np.asarray(b.vertices) + [shift, 0.0, 0.0], np.asarray(box.vertices)])
    f = np.vstack([np.asarray(a.faces), np.asarray(b.faces) + len(a.vertices),
                   np.asarray(box.faces) + len(a.vertices) + len(b.vertices)])
    rng = np.random.default_rng(seed)
    if stray:
        soup = rng.uniform(-1.2, 1.2 + shift, size=(3 * stray, 3))
        soup[1::3] = soup[0::3] + rng.normal(scale=10.0 ** rng.uniform(-6, -1, (stray, 1)), size=(stray, 3))
        f_soup = len(v) + np.arange(3 * stray).reshape(-1, 3)
        f_soup[:stray // 3, 2] = f_soup[:stray // 3, 1]                     # zero-area faces
        v = np.vstack([v, soup])
        f = np.vstack([f, f_soup, f[rng.integers(0, len(f), stray)]])     # and duplicated ones
    return v * scale + far, f


def _points(v: np.ndarray, f: np.ndarray, seed: int, n: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Points of every kind, and whether each is off the surface (the exact sum is then an honest reference)."""
    rng = np.random.default_rng(seed)
    lo, hi = v.min(axis=0), v.max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    box = rng.uniform(lo - 0.1 * size, hi + 0.1 * size, size=(n, 3))
    pick = rng.integers(0, len(f), n)
    tri = v[f[pick]]
    bary = rng.dirichlet([1.0, 1.0, 1.0], n)
    on = np.einsum("pk,pki->pi", bary, tri)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    unit = normal / np.where(length > 0, length, 1.0)[:, None]
    offset = size * 10.0 ** rng.uniform(-12, -2, n) * rng.choice([-1.0, 1.0], n)
    near = on + offset[:, None] * unit
    at_vertex = v[rng.integers(0, len(v), n // 4)]
    points = np.vstack([box, near, on, at_vertex])
    off = np.concatenate([np.ones(n, bool), length > 0, np.zeros(n + n // 4, bool)])
    return points, off


@settings(max_examples=12, deadline=None)
@given(shift=st.floats(0.0, 1.2), inner=st.floats(0.3, 0.9), scale=st.floats(1e-3, 1e3),
       far=st.sampled_from([0.0, 1.0, 1e4]), stray=st.integers(0, 12), seed=st.integers(0, 2 ** 32 - 1),
       tolerance=st.floats(1e-6, 1e-1), leaf=st.sampled_from([1, 4, 16]), per=st.sampled_from([0, 1, 3, 5]),
       chunk=st.sampled_from([5, 2048]))
def test_the_c_treecode_is_the_numpy_treecode(shift, inner, scale, far, stray, seed, tolerance, leaf, per, chunk):
    if accel() is None:
        pytest.fail("inertia_tool._accel did not load (INERTIA_TOOL_NO_ACCEL set, or a stale build)")
    block = winding._BLOCK
    if per:                        # vectorised blocks of `per` (point, leaf) pairs: each point's sum split there
        winding._BLOCK = per * leaf * 4
    try:
        _compare(shift, inner, scale, far, stray, seed, tolerance, leaf, chunk)
    finally:
        winding._BLOCK = block


def _compare(shift, inner, scale, far, stray, seed, tolerance, leaf, chunk):
    v, f = _surface(shift, inner, 1.0, 0.0, stray, seed)
    points, off = _points(v, f, seed)
    rng = np.random.default_rng(seed)
    in_plane = rng.uniform(-0.5, 0.5, size=(24, 3))      # on the box's faces, in their planes exactly (a solid
    in_plane[np.arange(24), rng.integers(0, 3, 24)] = rng.choice([-0.5, 0.5], 24)   # angle's numerator ±0)
    points = np.vstack([points, in_plane])
    off = np.concatenate([off, np.zeros(24, bool)])
    v, points = v * scale + far, points * scale + far
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    tree = winding._Tree(v - centre, f, leaf)
    w_c, e_c = winding._treecode(points - centre, v - centre, f, tolerance=tolerance, leaf=leaf, chunk=chunk,
                                 tree=tree)
    w_np, e_np = winding._treecode_numpy(points - centre, tree, tolerance=tolerance, chunk=chunk)
    if BITWISE:
        np.testing.assert_array_equal(w_c.view(np.int64), w_np.view(np.int64))
        np.testing.assert_array_equal(e_c.view(np.int64), e_np.view(np.int64))
    exact = winding._direct(points[off] - centre, v - centre, f)
    roundoff = 64 * np.finfo(float).eps * len(f)
    assert np.all(np.abs(w_c[off] - exact) <= e_c[off] + roundoff)
    assert np.all(np.abs(w_c[off] - w_np[off]) <= e_c[off] + e_np[off] + roundoff)


def test_a_tree_of_the_wrong_shape_is_refused():
    """The kernel checks the levels it is given against the faces before it walks them: a level count that is not
    half the one below (rounded up), or leaves that do not cover the faces, is refused, not read out of bounds."""
    lib = accel()
    if lib is None:
        pytest.skip("inertia_tool._accel did not load")
    v, f = _surface(0.5, 0.6, 1.0, 0.0, 0, 1)
    tree = winding._Tree(v, f, 16)
    w, e = np.empty(3), np.empty(3)
    points = np.zeros((3, 3))
    for bounds in (tree.bounds[:-1], tree.bounds + np.r_[0, np.ones(len(tree.bounds) - 1, np.int64)],
                   np.r_[tree.bounds[:1], tree.bounds[1:] - 1]):
        with pytest.raises(ValueError, match="Expected"):
            lib.winding_tree(points, tree.clusters, np.ascontiguousarray(bounds, dtype=np.int64), tree.triangles,
                             16, 1e-4, 2048, 65536, w, e, 1)
    with pytest.raises(ValueError, match="Expected"):
        lib.winding_tree(points, tree.clusters, tree.bounds, tree.triangles, 8, 1e-4, 2048, 65536, w, e, 1)
