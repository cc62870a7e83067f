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
    there) is a cavity by depth and part of the body by the file's winding; both are named.  Session 16: the
    file's winding (1 and 2, never below 0) stands, so the answer is the union, 64 m³, and the note names the depth
    reading, 63 m³ (before: 63 m³ given, the union named)."""
    props, said = _run(concat(box((4.0, 4.0, 4.0)), box((1.0, 1.0, 1.0))))
    assert props.mass == 64.0
    assert any("nesting depth" in n and "63 m³" in n for n in props.mesh.notes)
    assert np.allclose(props.center_of_mass, 0.0)


def test_curved_fill_is_named_in_the_repair_note():
    """A 50 mm sphere (icosphere, 1,280 faces) stored in float32, 40 faces gone (4 holes, 36 rim edges), in metres:
    the note must say how the holes were closed; cones over 36 edges make 1,276 faces.  Review 9 found
    ``holes.patched_estimate`` saying only "closed by cones to their centroids" while ``curved_fills`` had bent the
    fans onto the quadric (1,636 faces); holes7's assumptions note (``mesh/hole_assumptions.py``) now names it,
    and the note says how many holes were filled on the quadric."""
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


def _convex_intersection_volume(pieces):
    """Volume of the intersection of convex closed pieces, by qhull's half-space intersection (independent of the
    engine and of manifold3d)."""
    from scipy.optimize import linprog
    from scipy.spatial import ConvexHull, HalfspaceIntersection

    rows = []
    for v, f in pieces:
        n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        rows.append(np.c_[n, -np.einsum("ij,ij->i", n, v[f[:, 0]])])
    hs = np.vstack(rows)
    lp = linprog([0, 0, 0, -1], A_ub=np.c_[hs[:, :3], np.ones(len(hs))], b_ub=-hs[:, 3],
                 bounds=[(None, None)] * 3 + [(0, None)], method="highs")
    if lp.x is None or lp.x[3] <= 1e-12:    # no ball fits: empty (here: apart by far more than that)
        return 0.0
    return float(ConvexHull(HalfspaceIntersection(hs, lp.x[:3]).intersections).volume)


def _hollow_copies(angle):
    """A unit box with a 0.5 m cubic cavity (wound inward), and the same hollow box turned by ``angle`` about the
    axis (1, 2, 3) through a corner: every cavity lies inside both boxes."""
    from adversary_solids import _axis_rotation

    a, ca = box((1.0, 1.0, 1.0)), box((0.5, 0.5, 0.5))
    rot, p = _axis_rotation(np.array([1.0, 2.0, 3.0]), angle), a[0][0]
    b = ((a[0] - p) @ rot.T + p, a[1].copy())
    cb = ((ca[0] - p) @ rot.T + p, ca[1].copy())
    # (A − Ca) ∪ (B − Cb) = A ∪ B − (Ca ∩ Cb) when both cavities lie in A ∩ B: its winding number is 0 only there
    union = 2.0 - _convex_intersection_volume([a, b])
    truth = union - _convex_intersection_volume([ca, cb])
    return concat(a, flipped(ca), b, flipped(cb)), truth


def test_hollow_copies_overlapping_are_not_certified_with_their_cavities_filled():
    """Two overlapping hollow boxes (the second turned 0.1 rad): R4 counted both boxes for the depth of each
    cavity (depth 2, so the cavities were made bodies) and the union filled them: certified ``united``, 1.0674 m³
    against 0.9556 (11.7 % high).  Overlapping bodies now count once for the depth, and a cavity inside bodies
    that overlap is not certified (which body it is cut from, the file does not say)."""
    mesh, truth = _hollow_copies(0.1)
    props, said = _run(mesh)
    kind = props.mesh.certificate.kind
    assert kind not in ("exact", "united") or abs(props.mass - truth) <= 1e-9 * truth, (kind, props.mass, truth)
    assert any("inside bodies that overlap" in s for s in said)


@pytest.mark.parametrize("angle", [0.1, 1e-6])
def test_hollow_copies_overlapping_give_the_solid_meant(angle):
    """The number too: each crossing cavity goes to one of the bodies around it in turn (both went to the first box,
    and the second filled them: 1.0674 m³), so (A − Ca) ∪ (B − Cb), the solid {winding number ≥ 1}, is formed."""
    mesh, truth = _hollow_copies(angle)
    props, _ = _run(mesh)
    assert abs(props.mass - truth) <= 1e-9 * truth


def test_cavities_crossing_each_other_inside_a_box_are_cut():
    """Two cavities that cross each other inside a box (each wound inward): they crossed no outward shell, so R4
    gave each to itself as its own body, and the boolean left the box full (64 m³, the cavities lost).  They are
    now cut from the shell around them: 64 − |C1 ∪ C2|, certified ``united`` (the boolean's union exceeds the
    summed integral by exactly the cavities' common volume, which the sum takes out twice; it was read as "a shell
    read as a cavity reaches out of the body around it" and not verified)."""
    from adversary_solids import _axis_rotation, moved

    c1 = box((1.0, 1.0, 1.0))
    c2 = moved(box((1.0, 1.0, 1.0)), _axis_rotation([1.0, 2.0, 3.0], 0.5), np.array([0.3, 0.2, 0.1]))
    truth = 64.0 - (2.0 - _convex_intersection_volume([c1, c2]))
    props, _ = _run(concat(box((4.0, 4.0, 4.0)), flipped(c1), flipped(c2)))
    assert abs(props.mass - truth) <= 1e-9 * truth, (props.mass, truth)
    assert props.mesh.cavities >= 1
    assert props.mesh.certificate.kind == "united"
    assert not any("reaches out of the body" in n for n in props.mesh.notes)


def _turned_copy_far_away():
    """``benchmarks/bench_review9_convex.py --seed 903 --case 1982`` (mode tiny_turn), redrawn: an 11-sided prism
    (0.208 m³) turned at random, listed with a copy turned 2.1e-9 rad about one of its corners, the pair ~950 km
    from the origin (one ulp there is 1.2e-10 m)."""
    from adversary_solids import _axis_rotation, cylinder, moved, random_rotation

    rng = np.random.default_rng([903, 1982])
    assert rng.integers(3) == 2
    radius, height, sides = float(rng.uniform(0.2, 0.5)), float(rng.uniform(0.4, 1.0)), int(rng.integers(5, 17))
    va, fa = moved(cylinder(radius, height, sides), random_rotation(rng), np.zeros(3))
    angle = float(10.0 ** rng.uniform(-12, -3))
    p = va[rng.integers(len(va))] if rng.random() < 0.5 else va.mean(0)
    rot = _axis_rotation(rng.normal(size=3), angle)
    vb = (va - p) @ rot.T + p
    scale = 1e-3 if rng.random() < 0.3 else 1.0
    assert scale == 1.0 and not rng.random() < 0.4
    far = 10.0 ** rng.uniform(3, 7)
    shift = np.round(rng.normal(size=3) * far)
    return concat((va + shift, fa), (vb + shift, fa.copy()))


def test_near_copy_far_away_is_not_read_as_its_own_cavity():
    v, f = _turned_copy_far_away()
    props, _ = _run((v, f))
    corners = v[f[:44]] - v[0]                      # the first prism, about one of its corners
    one = abs(float(np.einsum("ij,ij->", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])))) / 6
    assert props.mass > 0.5 * one, (props.mass, one, props.mesh.certificate.kind)
    # was a strict xfail (2.09e-10 m³ left: 9.85e-10 and 1.004e-9 of the two volumes unshared, one read as within
    # the other and made its cavity); copies wound alike within 2·rtol of each other are not nested (R4), and the
    # union is the part up to the 2e-9 rad turn
    assert abs(props.mass / one - 1) <= 1e-6, (props.mass, one)
    assert props.mesh.certificate.kind in ("united", "unverified"), props.mesh.certificate.kind


def _drawn_hollow_pair():
    """``benchmarks/bench_review9_convex.py --seed 904 --case 7`` (mode hollow_pair), redrawn: two boxes turned at
    random and overlapping, each with a cavity (a copy shrunk about its vertex mean, wound inward)."""
    from adversary_solids import moved, random_rotation

    rng = np.random.default_rng([904, 7])

    def shrunk(piece, factor):
        c = piece[0].mean(0)
        return c + (piece[0] - c) * factor, piece[1].copy()

    assert rng.integers(3) == 0
    ext = rng.uniform(0.3, 1.0, size=3)
    a = moved(box(ext, subdivide=int(rng.integers(0, 2))), random_rotation(rng), np.zeros(3))
    ca = shrunk(a, float(rng.uniform(0.3, 0.7)))
    assert rng.integers(3) == 0
    ext = rng.uniform(0.3, 1.0, size=3)
    b = moved(box(ext, subdivide=int(rng.integers(0, 2))), random_rotation(rng), rng.normal(size=3) * 0.3)
    cb = shrunk(b, float(rng.uniform(0.3, 0.7)))
    return a, ca, b, cb


def test_hollow_bodies_overlapping_a_cavity_crossing_the_other_body():
    """Two hollow boxes overlapping, a cavity crossing the other box's wall: R4 cut an inward shell from the
    outward shell it crosses (the other box), not from the box containing it, and the union filled it
    (``unverified``, 0.42478 m³ for 0.41402, 2.6 % high; 162 of 200 such draws off by 0.4–18 %).  A cavity inside
    a body is now cut from that body.  Truth: (A − Ca) ∪ (B − Cb) = A + B − Ca − Cb − (A∩B − A∩B∩Ca − A∩B∩Cb +
    A∩B∩Ca∩Cb), every intersection convex (qhull)."""
    a, ca, b, cb = _drawn_hollow_pair()

    def volume(piece):
        v, f = piece
        return abs(float(np.einsum("ij,ij->", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])))) / 6

    truth = volume(a) - volume(ca) + volume(b) - volume(cb) - (
        _convex_intersection_volume([a, b]) - _convex_intersection_volume([a, b, ca])
        - _convex_intersection_volume([a, b, cb]) + _convex_intersection_volume([a, b, ca, cb]))
    props, _ = _run(concat(a, flipped(ca), b, flipped(cb)))
    assert abs(props.mass - truth) <= 1e-9 * truth, (props.mass, truth, props.mesh.certificate.kind)
