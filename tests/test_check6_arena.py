"""The face-pair check's memory reuse (issue 25): the C scan's later phases take the blocks of its earlier ones
(the boxes the twins', the corner indices the stars' lists'), and its blocks go to the pool for the next weld or
census; none of its arrays may be read before it is written.

``INERTIA_TOOL_CT_POISON=1`` fills every block the scan takes with 0xA5 bytes: a read before a write would then
change a pair, a count or a class.  Every field of ``surface_contacts`` must be the same with and without it,
on the first call and on later calls that reuse dirty pages, and the same as the numpy twin and brute force.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia_tool import _native
from inertia_tool.mesh.intersect import surface_contacts
from intersect_reference import CONTACT, CROSSING, NONE, OPPOSITE, brute_kind, pair_kinds

POISON = "INERTIA_TOOL_CT_POISON"
FIELDS = ("crossing", "coplanar_opposite", "contact", "complete", "candidate_pairs", "tested_pairs",
          "exact_evaluations", "degenerate_faces")

needs_c = pytest.mark.skipif(_native.accel() is None, reason="the C extension is not built")


def _fields(r):
    return tuple(np.asarray(getattr(r, k)).tolist() for k in FIELDS)


def _torus(n_major: int, n_minor: int, seed: int | None = None):
    """A closed torus grid (two triangles a quad), vertices jittered when ``seed`` is given."""
    u = 2 * np.pi * np.arange(n_major) / n_major
    w = 2 * np.pi * np.arange(n_minor) / n_minor
    uu, ww = np.meshgrid(u, w, indexing="ij")
    ring = 50.0 + 20.0 * np.cos(ww)
    v = np.stack([ring * np.cos(uu), ring * np.sin(uu), 20.0 * np.sin(ww)], axis=-1).reshape(-1, 3)
    if seed is not None:
        v = v + np.random.default_rng(seed).normal(scale=0.05, size=v.shape)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a, b = i * n_minor + j, ((i + 1) % n_major) * n_minor + j
    c, d = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor, i * n_minor + (j + 1) % n_minor
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, f.astype(np.int32)


def _crossing_pair_torus():
    """Two copies of a 48k-face torus crossing near their rims: blocks over 1 MB (the arena's), pairs found."""
    v, f = _torus(200, 120)
    v2 = v + [135.0, 0.5, 0.25]
    return np.concatenate([v, v2]), np.concatenate([f, f + len(v)]).astype(np.int32)


@needs_c
def test_poisoned_blocks_give_the_same_answer_on_large_arrays(monkeypatch):
    """Regression (issue 25, page reuse): blocks of MBs (the sort words, twins, boxes, corner indices reused
    between phases) filled with 0xA5 give every field identical, on the first call and on a call reusing the
    previous call's dirty pages."""
    v, f = _crossing_pair_torus()
    plain = _fields(surface_contacts(v, f))
    assert plain[0]                                     # crossing pairs found
    again = _fields(surface_contacts(v, f))             # dirty pages of the first call, from the pool
    monkeypatch.setenv(POISON, "1")
    poisoned = _fields(surface_contacts(v, f))
    poisoned64 = _fields(surface_contacts(v, f.astype(np.int64)))
    unpatched = _fields(surface_contacts(v, f, _patches=False))
    monkeypatch.delenv(POISON)
    assert plain == again == poisoned == poisoned64
    assert unpatched[:4] == plain[:4]                   # the same pairs without patches (other counts)


@needs_c
def test_blocks_given_to_the_pool_and_reused_dirty_give_the_same_answer():
    """At the end of a call the check's blocks go to the pool (for the next weld or census); a census then takes
    them dirty, and the next check maps its own again: the answers of a cold call, a warm one and one after the
    census are the same."""
    from inertia_tool.mesh.checks import census_and_shells

    lib = _native.accel()
    v, f = _torus(500, 200, seed=3)                     # 200k faces: blocks above the pool's 2 MB floor (the
    #                                                     boxes' 12 bytes a face, since check7 keeps no corner
    #                                                     indices: at 160k faces no block was left above it)
    lib.release_buffers()
    cold = _fields(surface_contacts(v, f))
    assert lib.kept_buffers() > 0                        # the check's blocks kept for the next call
    census_and_shells(f, len(v))
    assert _fields(surface_contacts(v, f)) == cold
    lib.release_buffers()
    assert lib.kept_buffers() == 0


def _soup(data):
    n = data.draw(st.integers(4, 12))
    coords = data.draw(st.lists(st.sampled_from([0.0, 0.25, 0.5, 1.0, -0.5, 0.75]), min_size=3 * n,
                                max_size=3 * n))
    v = np.array(coords, dtype=float).reshape(n, 3)
    m = data.draw(st.integers(1, 12))
    rows = data.draw(st.lists(st.tuples(*(st.integers(0, n - 1),) * 3), min_size=m, max_size=m))
    return v, np.array(rows, dtype=np.int32)


@needs_c
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_poisoned_heap_blocks_on_small_soups(data, monkeypatch):
    """Small inputs take heap blocks (malloc, no longer calloc: nothing may read before it writes): coplanar,
    touching, crossing and repeated-corner soups on a coarse lattice give the same fields poisoned or not, and
    the same pairs as brute force."""
    v, f = _soup(data)
    plain = surface_contacts(v, f)
    monkeypatch.setenv(POISON, "1")
    poisoned = surface_contacts(v, f)
    monkeypatch.delenv(POISON)
    assert _fields(plain) == _fields(poisoned)
    assert pair_kinds(plain) == _brute_force(v, f)


def _brute_force(v, f):
    """{(i, j): kind} of every pair of nonzero-area faces that meets beyond what it shares (rational clipping)."""
    out = {}
    for i in range(len(f)):
        for j in range(i + 1, len(f)):
            shared = [(a, b) for a in range(3) for b in range(3) if f[i][a] == f[j][b]]
            kind = brute_kind(v[f[i]], v[f[j]], shared)
            if kind is not None and kind != NONE:
                assert kind in (CROSSING, OPPOSITE, CONTACT)
                out[(i, j)] = kind
    return out
