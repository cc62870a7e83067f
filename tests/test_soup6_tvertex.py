"""The T-vertex kernel's box test (``_accel.edge_point_candidates``, section 9; issue 25, the soup's 2.3 s).

Each point of a visited cell is first compared with the edge's box widened by the kernel's reach ``r``; only those
inside are tested on the segment.  That may only drop pairs the callers reject: every pair that passes their
tests lies within ``r`` of the segment.  Checked against all (edge, vertex) pairs of hypothesis-generated edge
sets (T-vertices, near misses, a soup's jittered copies of the ends, degenerate and repeated edges, parts far
from the origin) with the callers' own tests: ``on_edge_vertices``'s (gap 0) and the seal's split test within a
gap (``_split``: within the gap of the interior, farther than the gap from the ends or on the edge).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool.mesh.seal import ON_EDGE_RTOL, _edge_point_candidates
from test_mesh_seal_on_edge import edge_sets

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="the C kernel's candidates")


def _accepted(v, edges, e, m, gap):
    """The pairs (edge, vertex) among ``e, m`` that the seal's split test (``gap`` > 0) or the on-edge test
    (``gap`` = 0) accepts, as a sorted set of tuples (the tests of ``seal._split`` and ``on_edge_vertices``)."""
    a, b = v[edges[e, 0]], v[edges[e, 1]]
    ab = b - a
    length = np.linalg.norm(ab, axis=1)
    t = np.einsum("ij,ij->i", v[m] - a, ab) / np.maximum(length ** 2, np.finfo(float).tiny)
    dist = np.linalg.norm(v[m] - (a + t[:, None] * ab), axis=1)
    to_end = np.minimum(np.linalg.norm(v[m] - a, axis=1), np.linalg.norm(v[m] - b, axis=1))
    on_edge = dist <= ON_EDGE_RTOL * to_end
    if gap > 0:
        ok = (dist <= gap) & (t > 0) & (t < 1) & (to_end > 0) & ((to_end > gap) | on_edge)
    else:
        ok = (t > 0) & (t < 1) & (to_end > 0) & on_edge
    ok &= (m != edges[e, 0]) & (m != edges[e, 1])
    return sorted(zip(e[ok].tolist(), m[ok].tolist()))


def _all_pairs(v, edges):
    points = np.unique(edges)
    return np.repeat(np.arange(len(edges)), len(points)), np.tile(points, len(edges))


@settings(max_examples=30, deadline=None)
@given(edge_sets(), st.sampled_from([0.0, 1e-9, 1e-6, 1e-3, 1e-1]))
def test_the_box_test_drops_no_pair_the_callers_accept(case, gap_rtol):
    v, edges = case
    edges = np.unique(edges, axis=0)               # the seal passes each edge once
    gap = gap_rtol * float(np.max(np.ptp(v, axis=0)))
    e, m = _edge_point_candidates(v, edges, gap)
    assert len(set(zip(e.tolist(), m.tolist()))) == len(e)        # each pair once
    assert np.all(np.diff(e) >= 0)                                # by edge
    everything = _all_pairs(v, edges)
    assert _accepted(v, edges, e, m, gap) == _accepted(v, edges, *everything, gap)


def test_a_soup_s_copies_of_the_ends_are_no_candidates():
    """The copies of an edge's ends jittered away from the segment (7 of 8 lie outside its box) are not
    listed; a copy jittered along the edge's own direction is listed only if the segment test keeps it, and a
    midpoint is always listed."""
    rng = np.random.default_rng(11)
    a, b = np.array([0.3, -0.2, 0.1]), np.array([0.9, 0.4, 0.5])
    copies = a + rng.normal(size=(64, 3)) * 1e-7
    v = np.vstack([a, b, 0.5 * (a + b), copies])
    edges = np.array([[0, 1]] + [[3 + i, 2] for i in range(64)] + [[2, 0]])
    e, m = _edge_point_candidates(v, edges, 0.0)
    on_first = m[e == 0]
    assert 2 in on_first
    assert len(on_first) == 1
