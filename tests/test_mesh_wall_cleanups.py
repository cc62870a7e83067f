"""The review's cleanups of issue 21 (walls4): one warning for an outward body read as a cavity, named internal
errors for internal invariants, and the seam-corner search of R3b (mesh/sheets.py) unchanged in its results."""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import inertia_tool as it
from inertia_tool.errors import InsideOutWarning

from test_mesh_misread_nesting import _nested


def _inside_out_warnings(v, f, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = it.mass_properties((v, f), density=1.0, **kwargs)
    return p, [str(w.message) for w in caught if issubclass(w.category, InsideOutWarning)]


@pytest.mark.parametrize("lo", [(0.5, 0.5, 0.5), (0.5, 0.5, 0.0)])
def test_an_outward_body_inside_another_gets_one_warning_naming_both_readings(lo):
    """Before: two InsideOutWarnings, the generic "inside out for its nesting depth ... flipped" and R4's note
    naming the other reading.  Then R4's note alone (the cavity kept, the union named).  Now (session 16: the
    file's winding, 1 and 2, stands) the union is given and turns nothing, and R4's one note names the depth
    reading, a cavity, 7 m³."""
    v, f, parity, union = _nested(lo, (1.0, 1.0, 1.0), inward=False)
    p, said = _inside_out_warnings(v, f)
    assert len(said) == 1, said
    assert "inside out for its nesting depth" not in said[0]                     # nothing turned
    assert "does not decide" in said[0] and "cavit" in said[0] and "7 m³" in said[0] and "nesting depth" in said[0]
    assert p.volume == pytest.approx(union[0], rel=1e-12)


def test_a_lone_body_wound_inward_still_gets_the_generic_warning():
    """A shell flipped for its depth that is not an outward body read as a cavity (a lone body wound inward)
    keeps the generic warning: exactly one."""
    v, f, _, union = _nested((0.5, 0.5, 0.5), (1.0, 1.0, 1.0), inward=False)
    outer = f[:12]
    p, said = _inside_out_warnings(v, outer[:, ::-1])
    assert len(said) == 1 and "inside out" in said[0]
    assert p.volume == pytest.approx(union[0], rel=1e-12)


def test_an_estimate_missing_from_an_estimated_resolution_is_a_named_internal_error():
    """``_estimated`` (mesh/prepare.py) and ``with_patch_doubt`` (mesh/self_crossing.py) checked their invariant
    with ``assert`` (gone under ``python -O``): now an InternalInvariantError, also a RuntimeError, naming what was
    expected and what was found."""
    from inertia_tool.errors import InertiaToolError, InternalInvariantError
    from inertia_tool.mesh.prepare import _estimated
    from inertia_tool.mesh.resolve import Resolution
    from inertia_tool.mesh.self_crossing import with_patch_doubt

    from inertia_tool.cli import EXIT_INTERNAL, exit_code

    assert issubclass(InternalInvariantError, InertiaToolError) and issubclass(InternalInvariantError, RuntimeError)
    assert exit_code(InternalInvariantError("x")) == EXIT_INTERNAL == 1           # docs/usage.md: a bug, exit 1
    broken = Resolution(vertices=np.zeros((0, 3)), faces=np.zeros((0, 3), dtype=np.int64), method="winding",
                        notes=(), flipped_faces=0, welded_tolerance=None, nonmanifold_edges=0, estimate=None)
    with pytest.raises(InternalInvariantError, match="expected to carry its estimate; found none"):
        _estimated(broken, {}, None)
    with pytest.raises(InternalInvariantError, match="<arrays>: the forced .* found none"):
        with_patch_doubt(broken, None, "<arrays>")


def _seam_corners_by_counting(f, n):
    """Reference: the corners of the edges used a different number of times in each direction (a dictionary)."""
    use = {}
    for tri in np.asarray(f).tolist():
        for a, b in zip(tri, tri[1:] + tri[:1]):
            use[(a, b)] = use.get((a, b), 0) + 1
    bad = {x for (a, b), k in use.items() if k != use.get((b, a), 0) for x in (a, b)}
    return np.array(sorted(bad), dtype=np.int64)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1), subdivide=st.integers(0, 2), holes=st.integers(0, 6),
       sheet=st.booleans())
def test_seam_corners_from_the_boundary_equal_those_by_sorting_every_edge(seed, subdivide, holes, sheet):
    """``_seam_corners`` (mesh/sheets.py) sorted every edge of the surface, a second time after ``_seam_plane``:
    now computed once, and taken from the net boundary the caller already has.  Same corners as sorting every
    edge and as counting by hand, on boxes with random faces taken out and a sheet of faces added."""
    from adversary_solids import box
    from inertia_tool.mesh.rims import boundary_edges
    from inertia_tool.mesh.sheets import _seam_corners

    rng = np.random.default_rng(seed)
    v, f = box(rng.uniform(0.5, 2.0, size=3), subdivide=subdivide)
    f = f[rng.permutation(len(f))[holes:]]
    if sheet:
        f = np.vstack([f, f[rng.integers(len(f), size=2)][:, ::-1]])   # reversed copies: unbalanced twice over
    truth = _seam_corners_by_counting(f, len(v))
    assert np.array_equal(_seam_corners(f, len(v)), truth)
    assert np.array_equal(_seam_corners(f, len(v), boundary_edges(f, len(v))), truth)
