"""The repair's edge census (mesh/resolve.py ``_census``) against a census counted edge by edge in Python.

soup7 sorts each edge's key and direction bit packed in one int64 instead of a stable argsort of the keys; the
census must not change: every count, the boundary 1-chain, the unbalanced vertices and the non-manifold keys are
compared with a brute-force count over a dictionary of directed edges, on hypothesis-drawn face lists (repeated,
reversed and non-manifold faces included) and on the argsort path the packing falls back to.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import resolve


def _brute_census(faces: np.ndarray, n: int) -> dict:
    """Each undirected edge's uses and net direction (+1 for a use running from the larger index to the smaller,
    edge_keys' direction bit), counted from the face list one directed edge at a time."""
    uses: Counter = Counter()
    net: Counter = Counter()
    bits: dict = {}
    for tri in faces.tolist():
        for k in range(3):
            a, b = tri[k], tri[(k + 1) % 3]
            lo, hi = min(a, b), max(a, b)
            uses[(lo, hi)] += 1
            net[(lo, hi)] += 1 if a > b else -1        # edge_keys' direction bit: a > b
            bits.setdefault((lo, hi), []).append(a > b)
    keys = sorted(uses)
    boundary = []
    for lo, hi in keys:
        k = net[(lo, hi)]
        # |net| copies in the net direction: forward (a > b, i.e. hi → lo) when positive
        boundary += [[hi, lo]] * k if k > 0 else [[lo, hi]] * (-k)
    unbalanced = [e for e in keys if net[e] != 0]
    return {
        "edges": len(keys),
        "boundary_edges": sum(1 for e in keys if uses[e] == 1),
        "nonmanifold_edges": sum(1 for e in keys if uses[e] > 2),
        "unbalanced_edges": len(unbalanced),
        "misoriented": sum(1 for e in keys if uses[e] == 2 and bits[e][0] == bits[e][1]),
        "boundary": np.array(boundary, dtype=np.int64).reshape(-1, 2),
        "unbalanced_vertices": np.array([e[0] for e in unbalanced] + [e[1] for e in unbalanced], dtype=np.int64),
        "nonmanifold_keys": np.array([lo * max(n, 1) + hi for lo, hi in keys if uses[(lo, hi)] > 2], dtype=np.int64),
    }


def _check(faces: np.ndarray, n: int) -> None:
    got = resolve._census(faces, n)
    want = _brute_census(faces, n)
    assert got.balance.edges == want["edges"]
    assert got.balance.boundary_edges == want["boundary_edges"]
    assert got.balance.nonmanifold_edges == want["nonmanifold_edges"]
    assert got.balance.unbalanced_edges == want["unbalanced_edges"]
    assert got.misoriented_pairs == want["misoriented"]
    assert np.array_equal(got.boundary, want["boundary"])
    assert np.array_equal(got.unbalanced_vertices, want["unbalanced_vertices"])
    assert np.array_equal(got.nonmanifold_keys, want["nonmanifold_keys"])


@st.composite
def _face_lists(draw: st.DrawFn) -> tuple[np.ndarray, int]:
    n = draw(st.integers(3, 12))
    tri = st.lists(st.integers(0, n - 1), min_size=3, max_size=3, unique=True)
    faces = draw(st.lists(tri, min_size=1, max_size=24))
    f = np.array(faces, dtype=np.int64).reshape(-1, 3)
    # some faces listed again, some reversed: misoriented pairs, non-manifold and doubled edges
    again = draw(st.lists(st.integers(0, len(f) - 1), max_size=6))
    flip = draw(st.lists(st.integers(0, len(f) - 1), max_size=6))
    f = np.vstack([f, f[again], f[flip][:, ::-1]])
    return f, n


@settings(max_examples=60, deadline=None)
@given(_face_lists())
def test_census_matches_a_brute_force_count(case: tuple[np.ndarray, int]) -> None:
    faces, n = case
    _check(faces, n)


def test_census_of_a_closed_octahedron_and_of_it_less_a_face() -> None:
    faces = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    closed = resolve._census(faces, 6)
    assert closed.balance.balanced and closed.balance.edges == 12 and closed.misoriented_pairs == 0
    _check(faces, 6)
    _check(faces[1:], 6)
    _check(np.vstack([faces, faces[:1]]), 6)               # a repeated face: three non-manifold edges


def test_census_beyond_the_packed_range_takes_the_argsort(monkeypatch) -> None:
    """Past 2·n² ≥ 2⁶³ the key and bit do not pack; the argsort path gives the same census (forced here by
    lowering the limit, since a mesh of 2³¹ vertices is not built in a test)."""
    monkeypatch.setattr(resolve, "_PACKED_EDGE_VERTICES", 2)
    rng = np.random.default_rng(7)
    for _ in range(20):
        n = int(rng.integers(4, 15))
        f = rng.integers(0, n, (int(rng.integers(1, 30)), 3))
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
        if len(f):
            _check(np.vstack([f, f[: len(f) // 2][:, ::-1]]), n)


def test_edge_keys_of_any_layout_match_the_formula() -> None:
    """``edge_keys`` fills its arrays in place (fewer fresh pages): the same keys and bits as
    ``min(a, b)·n + max(a, b)`` and ``a > b`` for int32, unsigned, float, Fortran-ordered and strided face arrays,
    input untouched."""
    from inertia_tool.mesh.edges import edge_keys

    rng = np.random.default_rng(11)
    base = rng.integers(0, 40, (50, 3))
    for faces in (base.astype(np.int32), base.astype(np.uint64), base.astype(np.uint16), base.astype(np.float64),
                  np.asfortranarray(base), base[::2], base[:, ::-1], base[:0]):
        kept = faces.copy()
        a = np.asarray(faces, dtype=np.int64).reshape(-1)
        b = np.asarray(faces, dtype=np.int64)[:, [1, 2, 0]].reshape(-1)
        key, forward = edge_keys(faces, 40)
        assert key.dtype == np.int64 and np.array_equal(key, np.minimum(a, b) * 40 + np.maximum(a, b))
        assert np.array_equal(forward, a > b)
        assert np.array_equal(faces, kept)
