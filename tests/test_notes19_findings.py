"""Review19's finding on the T-junction box (issue 21, "Numbers in messages"), pinned.

A closed box whose face x = −a/2 is split by a T-vertex on its edge z = +c/2, the T-junction sealed by the zero-area
sliver (the edge's two ends and the T-vertex) listed twice one way and once the other.  R1b finds non-manifold
edges where faces lie in a common plane; :func:`~inertia_tool.mesh.coplanar.arrange_coplanar` takes a sliver out
with its reverse (a zero chain) and, no two faces overlapping after that, integrates the rest as it stands.  The
answer was right (``united``, the box's closed form) but the note said "(0 face pairs in 0 planes)" for a weld
that was done, and the text report's result line said "exact for the polyhedron" above "certificate: united".
"""

import re
import warnings

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.reports.text import method_line


def t_junction_box(dims, t, same=2, reverse=1, order=None):
    """A closed box of sides ``dims`` (m) centred at the origin, its face x = −a/2 split by a T-vertex at the
    fraction ``t`` along its edge z = +c/2, the sliver listed ``same`` times as it seals and ``reverse`` times
    the other way; ``order`` permutes the faces.  The T-vertex lies on the edge exactly when ``t`` is a dyadic
    fraction (the tests use k/16) and the sides are dyadic too."""
    a, b, c = (d / 2 for d in dims)
    v = np.array([[-a, -b, -c], [-a, -b, c], [-a, b, -c], [-a, b, c], [a, -b, -c], [a, -b, c], [a, b, -c],
                  [a, b, c], [-a, -b + 2 * b * t, c]])
    f = np.array([[4, 1, 0], [0, 3, 2], [2, 4, 0], [1, 7, 3], [5, 1, 4], [5, 7, 1], [3, 7, 2], [6, 4, 2],
                  [2, 7, 6], [6, 5, 4], [7, 5, 6], [1, 8, 0], [8, 3, 0]])
    f = np.vstack([f] + [[[1, 3, 8]]] * same + [[[1, 8, 3]]] * reverse)
    if order is not None:
        f = f[np.asarray(order)]
    return v, f


def _box_closed_form(dims):
    """Volume (m³) and central inertia diagonal (kg·m², density 1) of a box: m(b² + c²)/12 and cyclic."""
    a, b, c = dims
    m = a * b * c
    return m, np.array([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 12


def _analyse(v, f):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mass_properties((v, f), density=1.0)


def _check(props, dims):
    volume, diag = _box_closed_form(dims)
    assert abs(props.volume - volume) <= 1e-12 * volume
    assert np.allclose(props.inertia, np.diag(diag), rtol=0, atol=1e-12 * diag.max())
    mesh = props.mesh
    assert mesh.certificate.kind == "united" and mesh.uncertainty is None
    welded = [n for n in mesh.notes if "common plane" in n]
    assert len(welded) == 1
    # what was done: one sliver taken out with its reverse (2 faces), no overlay (nothing split, no pair counted)
    assert "0 face pairs" not in welded[0] and "0 planes" not in welded[0]
    assert re.search(r"\b2 faces taken out as zero chains", welded[0])
    assert "no face split" in welded[0]
    line = method_line(mesh)
    assert "united" in line and "polyhedron" not in line


def test_t_junction_box_review19():
    """The case review19 met (its tjunc_sealed3.obj: a 0.1 × 0.2 × 0.3 m box, the T-vertex at mid-edge)."""
    dims = (0.1, 0.2, 0.3)
    _check(_analyse(*t_junction_box(dims, 0.5)), dims)


@settings(max_examples=15, deadline=None)
@given(dims=st.tuples(*[st.integers(1, 64).map(lambda k: k / 32)] * 3), k=st.integers(1, 15),
       seed=st.integers(0, 2**32 - 1))
def test_t_junction_box_variants(dims, k, seed):
    """Box sides, the T-vertex's place along the edge and the order of the faces (the sliver's three copies
    anywhere in the list) drawn by hypothesis: always the closed form, ``united``, and a note counting the two
    faces taken out."""
    order = np.random.default_rng(seed).permutation(16)
    _check(_analyse(*t_junction_box(dims, k / 16, order=order)), dims)


def test_overlay_note_still_counts_pairs_and_planes():
    """Where the overlay does run (two L-shapes welded where faces overlap in a common plane) the note keeps its
    counts of face pairs and planes, both positive, and the result line says united."""
    import adversary_solids as A

    case = A.make_case("welded_l_shapes", np.random.default_rng(0))
    props = _analyse(case.vertices, case.faces)
    welded = [n for n in props.mesh.notes if "overlap in a common plane" in n]
    assert len(welded) == 1
    pairs, planes = (int(x.replace(",", "")) for x in
                     re.search(r"\(([\d,]+) face pairs in ([\d,]+) planes?", welded[0]).groups())
    assert pairs > 0 and planes > 0
    assert props.mesh.certificate.kind == "united" and "united" in method_line(props.mesh)


def test_exact_result_line_unchanged():
    """An exact answer's result line is as before (the T-junction sealed by one sliver: no weld, ``exact``)."""
    props = _analyse(*t_junction_box((0.1, 0.2, 0.3), 0.5, same=1, reverse=0))
    assert props.mesh.certificate.kind == "exact"
    assert method_line(props.mesh) == "exact for the polyhedron (method: exact)"


def test_no_warning_says_exact_when_the_certificate_is_united():
    """notes19's notice: the surface stage's warning began "exact: 3 non-manifold edges ..." (the stage's own
    method: the surface was closed as read) above a result certified ``united``; no warning of a united answer may
    call it exact."""
    dims = (0.1, 0.2, 0.3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = mass_properties(t_junction_box(dims, 0.5), density=1.0)
    assert props.mesh.certificate.kind == "united"
    texts = [str(w.message) for w in caught]
    assert any("closed as read: 3 non-manifold edges" in t for t in texts)
    assert not any(re.search(r": exact: ", t) for t in texts)
