"""The compact census (issue 25, sixth pass; ``_accel.c`` section 4c): 32-bit edge slots bucketed by their
smaller end, the face unions made while the runs are tallied, the parents and the offsets kept inside the
caller's label array (int32 labels: in place; int64 labels: the parents in the first half, widened into labels
in rounds from the top, the offsets in the second half when the vertices are fewer than the faces).

Every case is compared with two independent references: the separate one-thread C kernels of sections 3, 4
and 4b (another adjacency, another union-find) for the counts and the sample edges, and the pure-numpy
``edge_topology`` / ``shell_labels`` (one global sort; ``INERTIA_TOOL_NO_ACCEL``) for the counts and the labels.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL, REQUIRE_ACCEL
from inertia_tool import _native
from inertia_tool.mesh.checks import edge_topology, shell_labels
from test_native_threads import _separate_kernels

pytestmark = pytest.mark.skipif(not HAVE_ACCEL and not REQUIRE_ACCEL, reason="inertia_tool._accel is not built")


@pytest.fixture(scope="module")
def lib():
    return _native.accel()


def _numpy_reference(faces, n, monkeypatch):
    """(edges, boundary, nonmanifold, misoriented), labels, count of the pure-numpy path."""
    with monkeypatch.context() as m:
        m.setenv(_native.NO_ACCEL_ENV, "1")
        topo = edge_topology(faces, n)
        labels, count = shell_labels(faces, n)
    return (topo.edges, topo.boundary_edges, topo.nonmanifold_edges, topo.misoriented_edges), labels, count


def _check(lib, faces, n, threads, monkeypatch, label_dtype=np.int64):
    census, (labels, count) = _separate_kernels(lib, faces.astype(np.int32), n)
    counts, np_labels, np_count = _numpy_reference(faces, n, monkeypatch)
    assert tuple(census[:4]) == counts and count == np_count
    np.testing.assert_array_equal(labels, np_labels)
    out = np.full(len(faces), -7, label_dtype)
    got = lib.census_shells(faces, n, out, threads, 1)         # parallel_min 1: threads on any size
    assert got == census + (count,)
    np.testing.assert_array_equal(out, labels)
    assert lib.census_shells(faces, n, None, threads, 1) == census + (-1,)


def _soup(draw_faces, n_vertices, seed):
    """Faces over ``n_vertices`` with what breaks a census: copies, flipped copies, fins (three faces on an
    edge), faces sharing only a vertex, unused vertices; no repeated index within a face."""
    rng = np.random.default_rng(seed)
    f = rng.integers(0, n_vertices, size=(draw_faces, 3))
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])]
    if len(f) > 2:
        k = rng.integers(1, len(f))
        extra = [f[:k], f[:k][:, ::-1], np.c_[f[:k, :2], (f[:k, 2] + 1) % n_vertices]]
        f = np.concatenate([f, *extra])
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])]
    return f[rng.permutation(len(f))]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(n_faces=st.integers(1, 300), n_vertices=st.integers(3, 200), seed=st.integers(0, 2**32 - 1),
       threads=st.integers(1, 5), wide_faces=st.booleans(), wide_labels=st.booleans())
def test_census_shells_match_both_references_on_broken_soups(lib, monkeypatch, n_faces, n_vertices, seed, threads,
                                                             wide_faces, wide_labels):
    """Random soups with copies, flips, fins and bow-ties; more vertices than faces (the offsets apart) and
    fewer (inside int64 labels); int32 and int64 faces and labels; 1-5 threads."""
    f = _soup(n_faces, n_vertices, seed)
    if len(f) == 0:
        return
    f = f.astype(np.int64 if wide_faces else np.int32)
    _check(lib, f, n_vertices, threads, monkeypatch, np.int64 if wide_labels else np.int32)


def _tetrahedra(count, seed, unused=0):
    """``count`` closed tetrahedra on their own vertices (some flipped whole), faces shuffled: ``count``
    shells, numbered by smallest vertex."""
    rng = np.random.default_rng(seed)
    tet = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    f = (tet[None] + 4 * np.arange(count)[:, None, None]).reshape(-1, 3)
    flip = rng.random(count) < 0.3
    f.reshape(count, 4, 3)[flip] = f.reshape(count, 4, 3)[flip][:, :, ::-1]
    return f[rng.permutation(len(f))], 4 * count + unused


@pytest.mark.parametrize("unused", [0, 400_000])
def test_many_shells_widened_in_parallel_rounds(lib, monkeypatch, unused):
    """70,000 faces of 17,500 tetrahedra: the int64 widening's first rounds run on threads (each round at
    least 32,768 faces); with 400,000 unused vertices more the offsets cannot live in the labels' second half.
    Labels by smallest vertex, as the references."""
    f, n = _tetrahedra(17_500, 3, unused)
    for threads in (1, 2, 3):
        for dtype in (np.int32, np.int64):
            census, (labels, count) = _separate_kernels(lib, f.astype(np.int32), n)
            out = np.empty(len(f), dtype)
            assert lib.census_shells(f.astype(np.int32), n, out, threads) == census + (count,)
            np.testing.assert_array_equal(out, labels)
    counts, np_labels, np_count = _numpy_reference(f, n, monkeypatch)
    assert count == np_count == 17_500 and tuple(census[:4]) == counts
    np.testing.assert_array_equal(labels, np_labels)


def test_shells_joined_at_a_vertex_keep_first_face_numbering(lib, monkeypatch):
    """Two tetrahedra sharing one vertex (a bow-tie), shuffled with others: components numbered by first face
    (the vertex owners disagree), as both references."""
    f, n = _tetrahedra(300, 5)
    f = np.where(f == 4 * 299, 0, f)              # the last tetrahedron's first vertex is the first one's
    _check(lib, f.astype(np.int32), n, 2, monkeypatch)


@pytest.mark.parametrize("n_vertices", [3, 60])
def test_a_bad_index_is_named(lib, n_vertices):
    """An index past the vertices is refused with the index named, whether the offsets live apart (3 vertices,
    2 faces) or in the labels' second half (60 vertices, 100 faces)."""
    f = np.tile(np.array([[0, 1, 2]], np.int32), (100 if n_vertices == 60 else 2, 1))
    f[-1, 2] = n_vertices + 4
    out = np.full(len(f), -7, np.int64)
    with pytest.raises(ValueError, match=str(n_vertices + 4)):
        lib.census_shells(f, n_vertices, out, 2, 1)
