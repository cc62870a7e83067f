"""A copy of an edge's end is on no edge's interior (issue 23, robots7: UR5e's visual meshes).

``seal.on_edge_vertices`` keeps the T-vertices lying on a boundary edge out of the weld before repair.  It
tested ``0 < t < 1`` with ``t = (m − a)·(b − a) / |b − a|²``, and for a vertex with exactly the coordinates of
the end ``b`` that ratio is ``1 − 1 ulp`` whenever ``|b − a|²`` (a square root squared) rounds above the dot
product: a third of the exact duplicates of edge ends in a COLLADA soup were taken for T-vertices and kept out
of the weld (78,000 of UR5e's ``upperarm.dae``), welded later by the seal one cluster at a time (71,306 "crack
vertices"), and the search listed ~10 (edge, copy) pairs per edge (1.1M on that mesh).  The seal's own split
test already rejected them (``to_end > 0``); now both tests do, and the C search does not list them.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import HAVE_ACCEL
from inertia_tool.mass.pipeline import mass_properties
from inertia_tool.mesh.read import RawMesh
from inertia_tool.mesh.seal import _edge_point_candidates, on_edge_vertices

both_paths = pytest.mark.usefixtures("engine_path")

#: An edge whose copy of ``B`` gets t = 1 − 1 ulp (|B − A|² rounds above (B − A)·(B − A)) and whose foot
#: A + t (B − A) rounds back to B (distance 0: "on the edge" to any relative tolerance).
A = np.array([0.1, 0.2, 0.3])
B = np.array([0.1, 0.4, 0.4])


def test_the_case_is_the_rounding_case():
    """The premise: numpy puts the copy of ``B`` strictly inside (0, 1) at distance 0 from the edge, so only the
    end test rejects it."""
    ab = (B - A)[None]
    length = np.linalg.norm(ab, axis=1)
    t = np.einsum("ij,ij->i", ab, ab) / length ** 2
    assert 0 < t[0] < 1
    assert np.linalg.norm(B - (A + t[0] * (B - A))) == 0


@both_paths
def test_a_copy_of_an_end_is_not_on_the_edge():
    """Vertex 2 is a copy of B (end of the edge 0→1), on the edge 2→3 to a point off the line: no vertex lies on
    the interior of an edge; the midpoint of 0→1 (vertex 4) added to the boundary is found."""
    off = np.array([0.7, -0.3, 0.4])
    v = np.vstack([A, B, B.copy(), off, 0.5 * (A + B)])
    np.testing.assert_array_equal(on_edge_vertices(v, np.array([[0, 1], [2, 3]])), [])
    np.testing.assert_array_equal(on_edge_vertices(v, np.array([[0, 1], [2, 3], [4, 3]])), [4])


@pytest.mark.skipif(not HAVE_ACCEL, reason="the C kernel's candidates")
def test_the_kernel_lists_no_copy_of_an_end():
    v = np.vstack([A, B, B.copy(), A.copy(), 0.5 * (A + B)])
    edges = np.array([[0, 1], [2, 4], [3, 4]])
    e, m = _edge_point_candidates(v, edges, 0.0)
    assert sorted(m[e == 0].tolist()) == [4]
    e, m = _edge_point_candidates(v, edges, 1e-3)       # within a gap too: copies of ends are the weld's
    assert sorted(m[e == 0].tolist()) == [4]


@both_paths
def test_repair_welds_an_unwelded_soup_as_the_plain_reading_does():
    """An icosphere stored as a soup (three vertices per face, copies bit for bit): without ``repair`` the weld
    joins the copies and the sphere is exact; with it, some copies were kept out of that weld as 'T-vertices'
    and the surface went through the seal ("sealed", 160 crack vertices welded).  Both read it the same now."""
    import trimesh

    sphere = trimesh.creation.icosphere(2)
    v = np.asarray(sphere.vertices)[np.asarray(sphere.faces)].reshape(-1, 3).copy()
    f = np.arange(len(v)).reshape(-1, 3)
    results = []
    for repair in (False, True):
        raw = RawMesh(vertices=v, faces=f, source="soup", units="m", file_faces=len(f))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mp = mass_properties(raw, density=1.0, repair=repair)
        notes = [str(w.message) for w in caught if "welded" in str(w.message) or "sealed" in str(w.message)]
        results.append((mp.mesh.method, mp.mesh.certificate.kind, notes))
        assert mp.volume == pytest.approx(float(sphere.volume), rel=1e-12)
    assert results[0] == results[1]
    assert results[1][0] == "welded"
    assert "repeated vertices (identical coordinates) were joined" in results[1][2][0]
