"""design.tetra (marching tetrahedra) and design.grid's capped distance transform: independent truths (scipy's
exact transform, a sphere's volume, manifold3d's manifold check, the exact face-pair test)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

manifold3d = pytest.importorskip("manifold3d")

from inertia_tool.design.grid import _capped_squared_distance  # noqa: E402
from inertia_tool.design.tetra import marching_tetrahedra  # noqa: E402
from inertia_tool.mesh.intersect import surface_contacts  # noqa: E402


def _closed(values):
    v = np.array(values, dtype=float)
    v[[0, -1]] = -1.0
    v[:, [0, -1]] = -1.0
    v[:, :, [0, -1]] = -1.0
    return v


def _manifold(vertices, faces):
    return manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.ascontiguousarray(vertices),
                                                 tri_verts=np.ascontiguousarray(faces, dtype=np.uint64)))


def test_sphere_volume_and_outward_winding():
    """The zero set of 0.8 − |x| on a 0.05 lattice bounds a ball of volume 4π/3 · 0.8³ (to the lattice's
    piecewise-linear error, below 0.5 %), wound outward (positive volume), a manifold of genus 0."""
    n, h = 40, 0.05
    g = np.mgrid[0:n, 0:n, 0:n] * h - 1.0
    vertices, faces = marching_tetrahedra(_closed(0.8 - np.sqrt((g ** 2).sum(axis=0))), [-1.0, -1, -1], h)
    solid = _manifold(vertices, faces)
    assert solid.status() == manifold3d.Error.NoError and solid.genus() == 0
    assert solid.volume() == pytest.approx(4 / 3 * math.pi * 0.8 ** 3, rel=5e-3)
    tri = vertices[faces]
    signed = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert signed == pytest.approx(solid.volume(), rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(4, 12), st.sampled_from([0.0, 0.05]),
       st.sampled_from([0.0, 0.5]))
def test_random_fields_give_embedded_manifolds(seed, n, margin, zeros):
    """Any field (noise, with exact zeros at lattice points) gives a closed, consistently oriented manifold
    whose faces cross nowhere (the exact face-pair test), whatever the edge margin."""
    rng = np.random.default_rng(seed)
    f = rng.normal(size=(n, n, n))
    f[rng.random(f.shape) < zeros * 0.3] = 0.0
    vertices, faces = marching_tetrahedra(_closed(f), [0.0, 0, 0], 1.0, edge_margin=margin)
    if not len(faces):
        return
    solid = _manifold(vertices, faces)
    assert solid.status() == manifold3d.Error.NoError
    assert solid.volume() > 0
    assert not len(surface_contacts(vertices, faces).crossing)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 9))
def test_capped_distance_matches_scipy_within_reach(seed, reach):
    """Exact (scipy's Euclidean transform) up to ``reach`` cells, and reported beyond ``reach`` past it."""
    from scipy.ndimage import distance_transform_edt
    rng = np.random.default_rng(seed)
    shape = tuple(int(k) for k in rng.integers(3, 30, 3))
    target = rng.random(shape) < rng.uniform(0.002, 0.3)
    target.flat[int(rng.integers(target.size))] = True
    exact = np.rint(distance_transform_edt(~target) ** 2)
    got = _capped_squared_distance(target, reach)
    near = exact <= reach * reach
    np.testing.assert_array_equal(got[near], exact[near])
    assert np.all(got[~near] > reach * reach)
