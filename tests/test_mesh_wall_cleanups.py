"""The review's cleanups of issue 21 (walls4): one warning for an outward body read as a cavity, named internal
errors for internal invariants, and the seam-corner search of R3b (mesh/sheets.py) unchanged in its results."""

import warnings

import numpy as np
import pytest

import inertia_tool as it
from inertia_tool.errors import InsideOutWarning

from test_mesh_misread_nesting import _nested


def _inside_out_warnings(v, f, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = it.mass_properties((v, f), density=1.0, **kwargs)
    return p, [str(w.message) for w in caught if issubclass(w.category, InsideOutWarning)]


@pytest.mark.parametrize("lo", [(0.5, 0.5, 0.5), (0.5, 0.5, 0.0)])
def test_an_outward_body_read_as_a_cavity_gets_one_warning_naming_both_readings(lo):
    """Before: two InsideOutWarnings, the generic "inside out for its nesting depth ... flipped" and R4's note
    naming the other reading.  Now R4's note alone, with both readings (the cavity kept, the union of the bodies
    the file's own winding gives, 8 m³)."""
    v, f, parity, union = _nested(lo, (1.0, 1.0, 1.0), inward=False)
    p, said = _inside_out_warnings(v, f)
    assert len(said) == 1, said
    assert "does not decide" in said[0] and "cavit" in said[0] and "8 m³" in said[0] and "union" in said[0]
    assert p.volume == pytest.approx(parity[0], rel=1e-12)


def test_a_lone_body_wound_inward_still_gets_the_generic_warning():
    """A shell flipped for its depth that is not an outward body read as a cavity (a lone body wound inward)
    keeps the generic warning: exactly one."""
    v, f, _, union = _nested((0.5, 0.5, 0.5), (1.0, 1.0, 1.0), inward=False)
    outer = f[:12]
    p, said = _inside_out_warnings(v, outer[:, ::-1])
    assert len(said) == 1 and "inside out" in said[0]
    assert p.volume == pytest.approx(union[0], rel=1e-12)


def test_an_estimate_missing_from_an_estimated_resolution_is_a_named_internal_error():
    """``_estimated`` (mesh/prepare.py) and ``_with_patch_doubt`` (mesh/self_crossing.py) checked their invariant
    with ``assert`` (gone under ``python -O``): now an InternalInvariantError, also a RuntimeError, naming what was
    expected and what was found."""
    from inertia_tool.errors import InertiaToolError, InternalInvariantError
    from inertia_tool.mesh.prepare import _estimated
    from inertia_tool.mesh.resolve import Resolution
    from inertia_tool.mesh.self_crossing import _with_patch_doubt

    assert issubclass(InternalInvariantError, InertiaToolError) and issubclass(InternalInvariantError, RuntimeError)
    broken = Resolution(vertices=np.zeros((0, 3)), faces=np.zeros((0, 3), dtype=np.int64), method="winding",
                        notes=(), flipped_faces=0, welded_tolerance=None, nonmanifold_edges=0, estimate=None)
    with pytest.raises(InternalInvariantError, match="expected to carry its estimate; found none"):
        _estimated(broken, {})
    with pytest.raises(InternalInvariantError, match="<arrays>: the forced .* found none"):
        _with_patch_doubt(broken, None, "<arrays>")
