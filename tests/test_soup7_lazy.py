"""soup7's shortcuts on the repair path, each against the code it stands in for.

* ``rims._cycle_labels`` (the loops of a hole's rim without scipy) gives the labels of scipy's
  ``connected_components`` on every permutation, and declines anything else.
* ``sheets._no_plane_holds`` (a 3 × 3 covariance's smallest eigenvalue over a sample of the seam's corners) never
  says "no plane" where the singular-value plane of ``_seam_plane`` holds the corners, and says it for a soup.
* The loops of a hole's rim import no scipy (its import was a third of a one-hole repair's CPU time at 1.3M
  faces).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from inertia_tool.mesh import rims, sheets


def _scipy_cycles(nxt: np.ndarray) -> tuple[np.ndarray, int]:
    k = len(nxt)
    graph = coo_matrix((np.ones(k, dtype=np.int8), (np.arange(k), nxt)), shape=(k, k))
    count, label = connected_components(graph, directed=False)
    return label.astype(np.int64), int(count)


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 200).flatmap(lambda k: st.permutations(list(range(k)))))
def test_cycle_labels_are_scipys_components(perm: list[int]) -> None:
    nxt = np.array(perm, dtype=np.int64)
    got = rims._cycle_labels(nxt)
    assert got is not None
    want = _scipy_cycles(nxt)
    assert got[1] == want[1]
    assert np.array_equal(got[0], want[0])


def test_cycle_labels_of_long_cycles_and_fixed_points() -> None:
    """One cycle through all of 1,000 edges (the doubling must run its ⌈log₂ k⌉ + 1 rounds), and fixed points."""
    rng = np.random.default_rng(3)
    order = rng.permutation(1000)
    nxt = np.empty(1000, dtype=np.int64)
    nxt[order] = np.roll(order, -1)
    labels, count = rims._cycle_labels(nxt)
    assert count == 1 and not labels.any()
    labels, count = rims._cycle_labels(np.arange(5))
    assert count == 5 and np.array_equal(labels, np.arange(5))


def test_cycle_labels_decline_what_is_not_a_permutation() -> None:
    assert rims._cycle_labels(np.array([1, 1, 0])) is None          # two edges continue into one (a pinch)
    assert rims._cycle_labels(np.array([1, -1, 0])) is None         # an edge with no successor


def test_boundary_loops_of_two_holes() -> None:
    """Two triangular holes' rims (edges listed interleaved): two loops, as scipy numbers them."""
    edges = np.array([[0, 1], [10, 11], [1, 2], [11, 12], [2, 0], [12, 10]])
    labels, count = rims.boundary_loops(edges, 13)
    assert count == 2 and labels.tolist() == [0, 1, 0, 1, 0, 1]


@st.composite
def _rims(draw: st.DrawFn) -> tuple[np.ndarray, float]:
    """Points near a plane through a random point with a random normal, offset by up to ``spread`` each, and a
    tolerance on either side of the spread."""
    k = draw(st.integers(3, 400))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    scale = 10.0 ** draw(st.integers(-3, 3))
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    centre = rng.normal(size=3) * scale * 10.0 ** draw(st.integers(0, 3))
    spread = scale * 10.0 ** draw(st.integers(-16, 0))
    a, b = rng.uniform(-scale, scale, (2, k))
    pts = centre + a[:, None] * u + b[:, None] * w + rng.uniform(-spread, spread, k)[:, None] * normal
    return pts, spread * 10.0 ** draw(st.floats(-2, 2))


@settings(max_examples=40, deadline=None)
@given(_rims())
def test_no_plane_is_said_only_where_the_svd_plane_fails(case: tuple[np.ndarray, float]) -> None:
    pts, tolerance = case
    corners = np.arange(len(pts))
    if sheets._no_plane_holds(pts, corners, tolerance):
        # the early exit: the full decomposition would have found no plane either
        assert _svd_plane_holds(pts, corners, tolerance) is False


def _svd_plane_holds(v: np.ndarray, corners: np.ndarray, tolerance: float) -> bool:
    """``_seam_plane``'s own test without the early exit (the least-squares plane by singular values)."""
    return sheets._least_squares_plane(v, corners, tolerance) is not None


def test_no_plane_for_a_sphere_soup_and_a_plane_kept() -> None:
    rng = np.random.default_rng(5)
    sphere = rng.normal(size=(70_000, 3))     # above _PLANE_SAMPLE: the sample is a stride
    sphere = 0.05 * sphere / np.linalg.norm(sphere, axis=1, keepdims=True)
    everything = np.arange(len(sphere))
    tolerance = 1e-12 * 0.05
    assert sheets._no_plane_holds(sphere, everything, tolerance)
    assert sheets._seam_plane(sphere, everything, tolerance) is None
    flat = sphere.copy()
    flat[:, 2] = 0.01                                   # exactly planar: the early exit must not decide
    assert not sheets._no_plane_holds(flat, everything, tolerance)
    plane = sheets._seam_plane(flat, everything, tolerance)
    assert plane is not None and abs(abs(plane[0][2]) - 1.0) < 1e-12


def test_the_loops_of_a_hole_import_no_scipy() -> None:
    """The rim loops of a one-hole surface (and of two holes) no longer need scipy (its import was a third of a
    one-hole repair's CPU time at 1.3M faces)."""
    code = """
import sys
import numpy as np
sys.path.insert(0, "tests")
from adversary_solids import icosphere
from inertia_tool.mesh.rims import boundary_edges, boundary_loops
v, f = icosphere(0.05, 3)
cen = v[f].mean(axis=1)
for seeds in ([0], [0, 700]):
    gone = np.concatenate([np.argsort(np.linalg.norm(cen - cen[s], axis=1), kind="stable")[:12] for s in seeds])
    edges = boundary_edges(np.delete(f, gone, axis=0), len(v))
    labels, count = boundary_loops(edges, len(v))
    print(count, len(np.unique(labels)))
print(sorted(m for m in sys.modules if m == "scipy" or m.startswith("scipy.")))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__)))).stdout.splitlines()
    assert out == ["1 1", "2 2", "[]"], out
