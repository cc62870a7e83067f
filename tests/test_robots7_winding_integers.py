"""``winding.winding_integers``: a cheaper first treecode pass for callers that only round the winding number
(issue 23, robots7: G1's torso, 3,621 region points against 51,420 faces, 10.0 → 5.4 s).

The claim: at points where the winding number (plus an offset) is an integer, every point the one-pass treecode
at the default tolerance settles (``|w − round(w)| + error ≤ 1/4``) gets the same integer from the two passes,
and every point the two passes settle is settled at the true integer.  Checked against the exact direct sum on
closed surfaces that pass through themselves (two overlapping spheres, a sphere inside another: winding
numbers 0, 1 and 2), at points off the surface, and with the region offsets of a capped open surface.
"""

from __future__ import annotations

import numpy as np
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh.winding import INTEGER_FIRST_TOLERANCE, _direct, winding_integers, winding_numbers_bounded


def _two_spheres(shift: float, inner: float, subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    a = trimesh.creation.icosphere(subdivisions)
    b = trimesh.creation.icosphere(subdivisions, radius=inner)
    v = np.vstack([np.asarray(a.vertices), np.asarray(b.vertices) + [shift, 0.0, 0.0]])
    f = np.vstack([np.asarray(a.faces), np.asarray(b.faces) + len(a.vertices)])
    return v, f


@settings(max_examples=8, deadline=None)
@given(shift=st.floats(0.0, 1.2), inner=st.floats(0.3, 0.9), seed=st.integers(0, 2 ** 32 - 1),
       offset=st.sampled_from([0.0, -1.0, 2.0]))
def test_the_two_passes_round_to_the_one_pass_and_the_truth(shift, inner, seed, offset):
    v, f = _two_spheres(shift, inner, 1)
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1.5, 2.2, size=(60, 3))
    exact = _direct(points, v, f)
    points = points[np.abs(exact - np.round(exact)) < 1e-6]      # off the surface: an integer there
    exact = np.round(_direct(points, v, f))
    w1, e1 = winding_numbers_bounded(points, v, f)
    w2, e2 = winding_integers(points, v, f, offset=np.full(len(points), offset))   # the caller rounds w + offset
    s1 = np.abs(w1 - np.round(w1)) + e1 <= 0.25
    s2 = np.abs(w2 - np.round(w2)) + e2 <= 0.25
    assert np.all(s2[s1])                                         # settled in one pass: settled in two
    np.testing.assert_array_equal(np.round(w2[s2]), exact[s2])    # at the true integer
    assert np.all(np.abs(w2 - exact) <= e2 + 1e-9)                # each value within its own bound


def test_an_offset_that_is_no_integer_settles_nothing_in_the_first_pass():
    """The settling test is on ``w + offset``: with 1/2 added nothing settles at the first tolerance, and every
    point is the one-pass treecode's, bit for bit (a point's value does not depend on the others evaluated)."""
    v, f = _two_spheres(0.4, 0.7, 2)
    points = np.array([[0.1, 0.0, 0.0], [0.6, 0.1, 0.0], [1.6, 0.0, 0.0], [-0.5, 0.5, 0.2]])
    w1, e1 = winding_numbers_bounded(points, v, f)
    w2, e2 = winding_integers(points, v, f, offset=0.5)
    np.testing.assert_array_equal(w1, w2)
    np.testing.assert_array_equal(e1, e2)


def test_a_point_the_first_pass_leaves_is_evaluated_at_the_fine_tolerance():
    """With a first tolerance so loose that nothing settles, the result is the one-pass treecode's exactly."""
    v, f = _two_spheres(0.4, 0.7, 2)
    points = np.array([[0.1, 0.0, 0.0], [0.6, 0.1, 0.0], [1.6, 0.0, 0.0], [-0.5, 0.5, 0.2]])
    w1, e1 = winding_numbers_bounded(points, v, f)
    w2, e2 = winding_integers(points, v, f, first_tolerance=10.0)
    np.testing.assert_array_equal(w1, w2)
    np.testing.assert_array_equal(e1, e2)
    np.testing.assert_array_equal(np.round(w2), np.round(_direct(points, v, f)))


@settings(max_examples=6, deadline=None)
@given(shift=st.floats(0.0, 1.2), inner=st.floats(0.3, 0.9), seed=st.integers(0, 2 ** 32 - 1),
       far=st.sampled_from([1.0, 1e3, 1e6]))
def test_one_tree_for_several_calls_gives_each_call_its_own_values(shift, inner, seed, far):
    """Issue 25 (corpus12): ``corrected_estimate`` builds the tree once for its front probes and its regions'
    integers (``tree=integer_tree(v, f)``).  Every value and bound of each call is the one the call computes with
    its own tree, to the bit, at both tolerances (points close to the surface reach the second pass), for a
    surface far from the origin too (the tree is built about the box's centre)."""
    from inertia_tool.mesh.winding import integer_tree
    v, f = _two_spheres(shift, inner, 1)
    v = v + far
    rng = np.random.default_rng(seed)
    near = v[rng.integers(0, len(v), 20)] + rng.uniform(-0.02, 0.02, (20, 3))
    batches = [rng.uniform(-1.5, 2.2, size=(30, 3)) + far, near]
    tree = integer_tree(v, f)
    for points in batches:
        # the two passes written out with winding_numbers_bounded, which builds its own tree each time
        w, e = winding_numbers_bounded(points, v, f, tolerance=INTEGER_FIRST_TOLERANCE)
        again = np.abs(w - np.round(w)) + e > 0.25
        if again.any():
            w[again], e[again] = winding_numbers_bounded(points[again], v, f)
        for got in (winding_integers(points, v, f), winding_integers(points, v, f, tree=tree)):
            np.testing.assert_array_equal(got[0], w)
            np.testing.assert_array_equal(got[1], e)


def test_a_tree_of_another_surface_is_refused():
    """The tree is checked against the surface it is used for: one built for other vertices or faces is refused
    rather than giving the winding numbers of the wrong surface."""
    import pytest

    from inertia_tool.errors import UsageError
    from inertia_tool.mesh.winding import integer_tree
    v, f = _two_spheres(0.4, 0.7, 1)
    tree = integer_tree(v, f)
    points = np.array([[0.1, 0.0, 0.0]])
    with pytest.raises(UsageError, match="same vertices and faces"):
        winding_integers(points, v + 1e-3, f, tree=tree)
    with pytest.raises(UsageError, match="same vertices and faces"):
        winding_integers(points, v, f[::-1], tree=tree)
