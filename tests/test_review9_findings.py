"""Review 9 (issue 21, adversarial review at scale): each finding's minimal reproducer.

A finding fixed in this review is a plain regression test; one left open is a strict xfail naming its cause
(so the fix turns the suite red until the mark is removed).  Truths are independent of the engine: exact
rational integrals of boxes, closed forms, or the winding number of the file as written.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from adversary_solids import box, concat, flipped
from inertia_tool import mass_properties


def _run(mesh, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = mass_properties(mesh, density=1.0, **options)
    return props, [str(w.message) for w in caught]


def test_inverted_hollow_box_is_not_said_to_read_as_a_union():
    """A hollow box written wholly inside out (outer skin inward, cavity outward) has winding number −1 in its
    wall and 0 in its cavity: the file itself reads the cavity as empty.  R4's two-readings note (policy
    ``misread_nesting``) said "the file's own winding reads it as part of the body, the union of the bodies:
    64 m³" and counted the shells as flipped in two warnings; the file decides, and the mesh is just inside out."""
    props, said = _run(concat(flipped(box((4.0, 4.0, 4.0))), box((1.0, 1.0, 1.0))))
    assert props.mass == 63.0
    assert props.mesh.certificate.kind == "exact"
    assert not any("union of the bodies" in s for s in said + list(props.mesh.notes))
    assert any(s.startswith("<arrays>: the mesh is inside out") for s in said)


def test_outward_body_inside_a_body_keeps_both_readings():
    """The reading the fix above must keep: a body wound outward wholly inside an outward body (winding 2
    there) is a cavity by depth and part of the body by the file's winding; both are named."""
    props, said = _run(concat(box((4.0, 4.0, 4.0)), box((1.0, 1.0, 1.0))))
    assert props.mass == 63.0
    assert any("union of the bodies: 64 m³" in n for n in props.mesh.notes)
    assert np.allclose(props.center_of_mass, 0.0)


@pytest.mark.xfail(strict=True, reason=(
    "mesh/holes.patched_estimate (holes7's stage) writes 'closed by cones to their centroids' whatever fill was "
    "used: when curved_fills bent the fans onto the quadric the surroundings lie on (here a float32 sphere, so not "
    "convex to round-off and the cones are not kept), the report says cones while it counts 1,636 faces for a file "
    "of 1,240 with 36 rim edges (cones add 36): the note and the face count contradict each other"))
def test_curved_fill_is_named_in_the_repair_note():
    """A 50 mm sphere (icosphere, 1,280 faces) stored in float32, 40 faces gone (4 holes, 36 rim edges), in metres:
    the note must say how the holes were closed; cones over 36 edges make 1,276 faces."""
    import trimesh

    sphere = trimesh.creation.icosphere(3, radius=0.05)
    v = np.asarray(sphere.vertices).astype(np.float32).astype(np.float64)
    f = np.delete(np.asarray(sphere.faces), np.arange(40), axis=0)
    props, _ = _run((v, f), repair=True)
    report = props.mesh
    assert report.certificate.kind == "estimate"
    said = " ".join(report.repair_actions)
    cones_only = "closed by cones" in said and not any(w in said for w in ("quadric", "curved", "bent"))
    assert not (cones_only and report.faces != report.file_faces + 36), (report.faces, said)
