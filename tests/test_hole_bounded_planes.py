"""The boundedness test every polytope bound of a hole relies on (``hole_bounds.normals_surround_origin``, used by
``convex_hole_bound`` and ``hole_wraps``): judged against an independent linear programme, and a convex part whose
remaining planes leave it open is never given a convex bound."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from inertia_tool.mesh.hole_bounds import convex_hole_bound, normals_surround_origin


def _bounded_by_lp(normals: np.ndarray) -> bool:
    """{x : N x ≤ 1} (the origin inside) is bounded iff every coordinate is bounded above and below on it."""
    for axis in range(3):
        for sign in (1.0, -1.0):
            c = np.zeros(3)
            c[axis] = -sign
            res = linprog(c, A_ub=normals, b_ub=np.ones(len(normals)), bounds=[(None, None)] * 3, method="highs")
            if res.status == 3:
                return False
    return True


unit_vectors = st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(lambda t: 0.1 < np.linalg.norm(t))


@settings(max_examples=150, deadline=None)
@given(st.lists(unit_vectors, min_size=4, max_size=12), st.integers(0, 2), st.sampled_from([1.0, -1.0]))
def test_surround_agrees_with_lp(normals, axis, sign):
    n = np.asarray(normals, dtype=float)
    # half the draws pushed into one half-space (open along -sign e_axis... or not), so both answers occur often
    if axis == 0:
        n[:, 2] = sign * np.abs(n[:, 2]) + sign * 0.05
    lp = _bounded_by_lp(n)
    margin = np.linalg.norm(n, axis=1)
    ours = normals_surround_origin(n)
    if ours:
        assert lp                              # never bounded where the region is open: the sound direction
    elif lp:
        # the converse only away from the 1e-9 margin: the origin then lies within 1e-9 of the normals' hull
        from scipy.spatial import ConvexHull
        hull = ConvexHull(n / margin[:, None])
        assert float(hull.equations[:, 3].max()) > -1e-8


def _cube():
    v = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f


def test_cube_without_a_whole_side_gets_no_convex_bound():
    v, f = _cube()
    top = np.all(v[f][:, :, 0] == 1.0, axis=1)            # both triangles of the x = 1 side gone
    assert top.sum() == 2
    assert convex_hole_bound(v, f[~top], patched_volume=1.0) is None
    assert not normals_surround_origin(np.array([[-1.0, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]))


def test_cube_less_one_fan_triangle_keeps_its_convex_bound():
    """The x = 1 side as a fan of four round its centre, one of them gone: every plane still attested, the planes
    close the cube, so the convex bound stands (U is the cube; the patched solid, the cube itself, leaves ~0)."""
    v, f = _cube()
    side = np.all(v[f][:, :, 0] == 1.0, axis=1)
    v = np.vstack([v, [[1.0, 0.5, 0.5]]])
    fan = np.array([[4, 6, 8], [6, 7, 8], [7, 5, 8], [5, 4, 8]])
    assert np.all(np.cross(v[fan[:, 1]] - v[fan[:, 0]], v[fan[:, 2]] - v[fan[:, 0]])[:, 0] > 0)   # outward
    kept = np.vstack([f[~side], fan[1:]])
    got = convex_hole_bound(v, kept, patched_volume=1.0)
    assert got is not None
    doubt, corners = got
    assert 0.0 <= doubt < 1e-9
    assert np.allclose(corners.min(axis=0), 0.0, atol=1e-9) and np.allclose(corners.max(axis=0), 1.0, atol=1e-9)
