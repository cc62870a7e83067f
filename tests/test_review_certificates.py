"""Adversarial review (issue 21) of three rules that certify an answer without a boolean.

* R3b, :mod:`inertia_tool.mesh.sheets`: flat open sheets inside a closed solid taken out, ``exact`` (check
  ``open-sheets``).
* The coplanar overlay, :mod:`inertia_tool.mesh.coplanar`: bodies welded where their faces overlap in one plane,
  ``united``.
* ``union.two_manifold`` and ``touching-confirmed``: welded slabs whose closed groups are non-manifold.

Each generator draws inputs near the rule's boundary and compares every answer labelled ``exact``, ``united`` or
``summed`` with an independent truth (exact rationals of the intended solid, manifold3d's union of the intended
bodies, or libigl's generalised winding number); an estimate must hold its own bound; a refusal is always
allowed.  Inputs on which a rule gave a wrong number under a proven label are kept as reproducers (strict xfails
until the rule was mended; the docstring of each says which rule and why).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import adversary_solids as S
import test_mesh_folds as F
import inertia_tool as it
from inertia_tool.errors import InvalidMeshError
from inertia_tool.tolerances import MERGE_TOLERANCE, WALL_PLANE_RTOL

pytestmark = pytest.mark.usefixtures("engine_path")

FAST = settings(max_examples=10, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
SMALL = settings(FAST, max_examples=5)
PROVEN = ("exact", "united", "summed")
#: A proven answer farther than this (volume relative, centre relative to the diagonal, inertia relative) from
#: the truth is a wrong number.
RTOL = 1e-9


def _analyse(v, f, repair=False):
    """The tool's answer, or None when it refuses (always allowed)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return it.mass_properties((np.asarray(v, dtype=np.float64), np.asarray(f)), density=1.0, repair=repair)
    except InvalidMeshError:
        return None


def _honest(p, truth, diag):
    """Whether an answer is honest against ``truth`` (an adversary_solids.Truth): a proven label within RTOL, an
    estimate within its own bound; returns the answer's label (or "refused") and the verdict."""
    if p is None:
        return "refused", True
    label = p.mesh.certificate.kind
    dvol, dcom, din = S.compare(p, truth)
    if label in PROVEN:
        return label, bool(dvol <= RTOL and dcom <= RTOL * diag and din <= 10 * RTOL)
    u = p.mesh.uncertainty
    if label == "estimate" and u is not None:
        return label, bool(dvol <= u.mass + RTOL and dcom <= u.center_of_mass + RTOL * diag
                           and din <= u.inertia + RTOL)
    return label, True                                # unverified: no claim to check


def _diag(v):
    return float(np.linalg.norm(np.ptp(np.asarray(v), axis=0)))


# --------------------------------------------------------------------------------------------------- R3b sheets
_OUTER = S.box((4.0, 4.0, 4.0))
_TET = np.array([[1.0, 0, -0.7], [-1.0, 0, -0.7], [0, 1.0, 0.7], [0, -1.0, 0.7]]) * 0.8
_TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def _tet_faces_outward():
    return S._orient_convex(_TET, _TET_FACES.copy())


def _cracked_cavity(scale):
    """The 4 × 4 × 4 box with a tetrahedral cavity whose four faces are written as separate triangles (no corner
    shared), each scaled by ``scale`` about its own centroid in its own plane, wound into the cavity: below 1 the
    cavity's edges are open slits, above 1 the faces cross each other along the cavity's edges."""
    pts, faces = [], []
    for tri in _tet_faces_outward():
        corners = _TET[tri]
        centre = corners.mean(axis=0)
        corners = centre + (corners - centre) * scale
        faces.append([len(pts) + 2, len(pts) + 1, len(pts)])
        pts.extend(corners)
    v = np.vstack([_OUTER[0], np.array(pts)])
    f = np.vstack([_OUTER[1], np.array(faces) + len(_OUTER[0])])
    return v, f


def _cavity_truth():
    return S.truth_from_pieces([(1, _OUTER), (-1, (_TET, _tet_faces_outward()))])


@pytest.mark.parametrize("scale", [0.999, 1.2])
def test_cracked_cavity_reads_as_a_void_by_the_generalised_winding_number(scale):
    """The premise of the two reproducers below, by independent code (libigl): the cavity's centre has generalised
    winding number below 1/2 (a void), the solid well away from it about 1."""
    import igl

    v, f = _cracked_cavity(scale)
    query = np.array([_TET.mean(axis=0), [1.8, 1.8, 1.8]])
    w = igl.fast_winding_number(np.ascontiguousarray(v), np.ascontiguousarray(f), query)
    assert w[0] < 0.5 and abs(w[1] - 1) < 1e-2, w


def test_r3b_cavity_with_open_slits_is_not_certified_solid():
    """R3b (mesh/sheets.py): a cavity whose four flat faces lost their shared corners (each shrunk by 0.1 % in its
    plane, so its rim corners are ~1e-3 apart, far beyond the ``MERGE_TOLERANCE`` reach of ``_rims_meet``).  Each
    face passes alone as a flat sheet inside the solid, so all four are taken out and the answer is the box without
    its cavity (volume 64 instead of 63.52, -0.75 %), certified exact.  The module's lemma holds sheet by sheet
    (|w_Σ| < 1/2 for one plane region) but not for several sheets together: their solid angles add up to nearly
    4π, and the generalised winding number reads the cavity as void (test above).  The rims-meet guard only
    catches corners within the weld distance.  Fixed since (a strict xfail until then): several sheets are taken
    only when every rim corner of each lies on the rest (``sheets._rim_corners``); a free sheet only alone."""
    v, f = _cracked_cavity(0.999)
    assert MERGE_TOLERANCE * _diag(v) < 1e-4                   # the slits are far wider than the weld reach
    p = _analyse(v, f)
    label, ok = _honest(p, _cavity_truth(), _diag(v))
    assert ok, (label, p.volume)


def test_r3b_cavity_whose_faces_cross_each_other_is_not_certified_solid():
    """R3b (mesh/sheets.py): the cavity's four faces each enlarged by 20 % in their planes, so they cross one
    another along the cavity's edges (and no rim corner is near another).  The face-pair check is applied only to
    sheet-versus-rest pairs (``touches_rest``) and rest-versus-rest crossings; sheet-versus-sheet crossings pass,
    so the four are taken out as walls and the cavity is lost (64 instead of 63.52) under exact.  A one-line guard
    (refuse when any contact pair has both faces in sheets of different pieces) would close this case, but not the
    slit case above.  Fixed since by the same guard as above: these sheets are free, so several are not taken."""
    v, f = _cracked_cavity(1.2)
    p = _analyse(v, f)
    label, ok = _honest(p, _cavity_truth(), _diag(v))
    assert ok, (label, p.volume)


def _convex(rng, n=16):
    from scipy.spatial import ConvexHull

    pts = rng.normal(size=(n, 3)) * rng.uniform(0.6, 1.6, size=3) + rng.uniform(-3, 3, size=3)
    hull = ConvexHull(pts)
    f = S._orient_convex(pts, hull.simplices.copy())
    used, inverse = np.unique(f, return_inverse=True)
    return pts[used], inverse.reshape(-1, 3), hull.equations, pts[hull.vertices].mean(axis=0)


def _frame(normal):
    u = np.cross(normal, [1.0, 0, 0] if abs(normal[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    return u, np.cross(normal, u)


def _inner_radius(equations, centre):
    """Radius of a ball about ``centre`` inside the hull."""
    return float(np.min(-(equations[:, :3] @ centre + equations[:, 3])))


def _fan(rng, centre, normal, radius, k, bulge):
    """A fan of ``k`` triangles about ``centre`` in the plane of ``normal``, its hub lifted by ``bulge`` along the
    normal (0: flat), wound one way or the other."""
    u, w = _frame(normal)
    angles = np.sort(rng.uniform(0, 2 * np.pi, size=k))
    if np.min(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) < 0.2:
        angles = np.linspace(0, 2 * np.pi, k, endpoint=False) + rng.uniform(0, 1)
    rim = centre + radius * (np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * w)
    pts = np.vstack([centre + bulge * normal, rim])
    faces = np.array([[0, 1 + i, 1 + (i + 1) % k] for i in range(k)])
    return pts, faces if rng.random() < 0.5 else faces[:, ::-1]


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), sheets=st.integers(1, 3),
       bulge=st.sampled_from([0.0, 0.3, 1.0, 3.0, 30.0, 1e6]), gap=st.sampled_from([1e-9, 1e-4, 0.1]))
def test_r3b_sheets_inside_a_convex_solid_never_give_a_wrong_number(seed, sheets, bulge, gap):
    """Near R3b's boundary: one to three fans inside a convex solid, their hubs lifted by ``bulge`` ×
    WALL_PLANE_RTOL × the largest |coordinate| (within the flatness tolerance and just above it, up to visibly
    curved), two of them parallel and ``gap`` (relative to the radius) apart.  The intended solid is the convex
    solid (the sheets enclose nothing): any proven answer is its exact integral."""
    rng = np.random.default_rng(seed)
    v, f, equations, centre = _convex(rng)
    radius = 0.3 * _inner_radius(equations, centre)
    if radius <= 0:
        return
    scale = float(np.abs(v).max()) + 3 * radius
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    pieces = [(v, f)]
    for i in range(sheets):
        offset = normal * radius * (gap * i if i < 2 else -0.5)
        n_i = normal if i < 2 else _frame(normal)[0]
        pieces.append(_fan(rng, centre + offset, n_i, radius, int(rng.integers(3, 8)),
                           bulge * WALL_PLANE_RTOL * scale))
    mv, mf = S.concat(*pieces)
    p = _analyse(mv, mf)
    label, ok = _honest(p, S.truth_from_pieces([(1, (v, f))]), _diag(mv))
    assert ok, (label, p.volume if p is not None else None)


@SMALL
@given(seed=st.integers(0, 2 ** 32 - 1), where=st.sampled_from(["notch", "cavity", "island"]))
def test_r3b_sheet_in_the_notch_or_cavity_is_never_taken_as_a_wall(seed, where):
    """A flat sheet outside the solid but inside its bounding box (in the notch of an L-shaped part, or inside a
    cavity), or inside an island resting in a cavity (depth 3: inside).  A fin must not be taken out as a wall with
    material on both sides; an island's sheet may be.  Truth: the L part's cells (and cavity/island) in rationals."""
    rng = np.random.default_rng(seed)
    step = 1.0
    if where == "notch":
        cells = S._l_cells(4, 4, 2, 3, 0, (0, 0))
        centre, cavities, islands = np.array([3.0, 3.0, 1.5]), [], []
    else:
        cells = {(i, j, k) for i in range(5) for j in range(5) for k in range(5)}
        cavity = S.box((3.0, 3.0, 3.0), (2.5, 2.5, 2.5))
        island = S.box((1.6, 1.6, 1.6), (2.5, 2.5, 2.5))
        cavities, islands = [cavity], ([island] if where == "island" else [])
        centre = np.array([2.5, 2.5, 2.5]) + (np.array([0.0, 0.0, 1.1]) if where == "cavity" else 0.0)
    body = S.cell_body(cells, step, rng)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    sheet = _fan(rng, centre, normal, 0.3, int(rng.integers(3, 7)), 0.0)
    pieces = [body] + [S.flipped(c) for c in cavities] + islands + [sheet]
    mv, mf = S.concat(*pieces)
    signed = [(1, S.box((step,) * 3, np.asarray(c, dtype=np.float64) + 0.5)) for c in sorted(cells)]
    signed += [(-1, c) for c in cavities] + [(1, x) for x in islands]
    p = _analyse(mv, mf)
    label, ok = _honest(p, S.truth_from_pieces(signed), _diag(mv))
    assert ok, (label, p.volume if p is not None else None)
    if where != "island":
        assert p is None or "open-sheets" not in p.mesh.certificate.checks


# ------------------------------------------------------------------------------------------ coplanar overlay
def _cells(lo, size):
    return {(lo[0] + i, lo[1] + j, lo[2] + k) for i in range(size[0]) for j in range(size[1]) for k in range(size[2])}


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), motion=st.sampled_from(["none", "right", "generic", "far"]),
       below=st.lists(st.booleans(), min_size=3, max_size=3))
def test_coplanar_overlay_three_bodies_on_one_plane_match_their_union(seed, motion, below):
    """Three grid boxes on the plane z = 0, each standing on it or hanging under it (so their faces in the plane
    overlap facing the same way and opposite ways at once), welded bit-exactly, then moved (a generic rotation
    makes the plane coplanar only by rounding).  Truth: the union's cells in rationals."""
    rng = np.random.default_rng(seed)
    bodies = []
    for hang in below:
        size = tuple(int(x) for x in rng.integers(1, 4, size=3))
        lo = (int(rng.integers(-2, 3)), int(rng.integers(-2, 3)), -size[2] if hang else 0)
        bodies.append(_cells(lo, size))
    step = 0.5
    if motion == "none":
        rot, shift = np.eye(3), np.zeros(3)
    elif motion == "right":
        rot, shift = S.right_angle_rotation(rng), rng.integers(-8, 9, size=3) * 0.125
    else:
        rot, shift = S.random_rotation(rng), rng.normal(size=3) * (300.0 if motion == "far" else 2.0)
    v, f = S._weld_exact(*S.concat(*[S.cell_body(c, step, rng) for c in bodies]))
    v = v @ rot.T + shift
    union = set().union(*bodies)
    truth = S.truth_from_pieces([(1, S.moved(S.box((step,) * 3, (np.asarray(c, dtype=np.float64) + 0.5) * step),
                                             rot, shift)) for c in sorted(union)])
    p = _analyse(v, f)
    label, ok = _honest(p, truth, _diag(v))
    assert ok, (label, p.mesh.certificate if p is not None else None)


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), motion=st.sampled_from(["none", "generic"]))
def test_coplanar_overlay_t_vertices_on_the_shared_plane_match_manifold3d(seed, motion):
    """Two boxes standing on z = 0, one tessellated on a grid of step 1/2 and one of step 1/3 (their bottoms'
    vertices fall on each other's edges: T-vertices in the shared plane), plus a third hanging under the plane
    (opposite-facing overlap), welded where bit-identical.  Truth: manifold3d's union of the three (independent
    code).  A second body drawn wholly within the first is skipped: nesting depth (R4) reads it as a cavity flush
    with the first's faces, which is the documented reading, not the union (found by this test, judged honest)."""
    rng = np.random.default_rng(seed)
    a_size = tuple(int(x) for x in rng.integers(2, 5, size=3))
    a = S.cell_body(_cells((0, 0, 0), a_size), 0.5, rng)
    b_lo = (int(rng.integers(1, 3)), int(rng.integers(-2, 1)), 0)
    b_size = tuple(int(x) for x in rng.integers(2, 6, size=3))
    if all(b_lo[i] >= 0 and (b_lo[i] + b_size[i]) / 3 <= a_size[i] / 2 for i in range(3)):
        return          # b within a, flush with its faces: R4 reads it as a cavity (nesting depth), another rule
    b = S.cell_body(_cells(b_lo, b_size), 1 / 3, rng)
    c = S.cell_body(_cells((int(rng.integers(-1, 2)), int(rng.integers(-1, 2)), -2), (2, 2, 2)), 0.5, rng)
    rot, shift = (np.eye(3), np.zeros(3)) if motion == "none" else (S.random_rotation(rng), rng.normal(size=3))
    bodies = [S.moved(x, rot, shift) for x in (a, b, c)]
    v, f = S._weld_exact(*S.concat(*bodies))
    p = _analyse(v, f)
    label, ok = _honest(p, S.truth_from_manifold(bodies), _diag(v))
    assert ok, (label, p.mesh.certificate if p is not None else None)


# ------------------------------------------------------------------------ welded slabs: two_manifold, touching
def _slabs(rng, k):
    """A convex solid cut into ``k`` slabs by parallel planes (manifold3d), each slab's cut faces fanned anew
    (so neighbours' faces in a cut plane are triangulated apart), corners welded where bit-identical."""
    from scipy.spatial import ConvexHull

    pts = rng.normal(size=(20, 3)) * rng.uniform(0.5, 2.0, size=3) + rng.uniform(-5, 5, size=3)
    hull = ConvexHull(pts)
    used, inverse = np.unique(S._orient_convex(pts, hull.simplices.copy()), return_inverse=True)
    v, f = pts[used], inverse.reshape(-1, 3)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    heights = v @ normal
    pieces = [(v, f)]
    for q in sorted(rng.uniform(0.2, 0.8, size=k - 1))[::-1]:
        offset = float(heights.min() + q * (heights.max() - heights.min()))
        upper, lower = F._halves(*pieces.pop(), normal, offset)
        pieces += [(upper[0], F._retriangulate_cut(*upper, normal, offset, rng)),
                   (lower[0], F._retriangulate_cut(*lower, -normal, -offset, rng))]
    return pieces, F._joined(pieces)


@SMALL
@given(seed=st.integers(0, 2 ** 32 - 1), k=st.integers(2, 4), without_r3a=st.booleans(), repair=st.booleans())
def test_welded_slabs_never_give_a_wrong_number(seed, k, without_r3a, repair, monkeypatch):
    """Two to four slabs of one convex solid written face to face and welded (rim edges used by four faces).  With
    R3a (zero-volume folds) switched off, the non-manifold closed groups go to the boolean, where
    ``union.two_manifold`` and ``touching-confirmed`` decide.  Truth: the slabs' exact integrals added."""
    import inertia_tool.mesh.folds as folds

    if without_r3a:
        monkeypatch.setattr(folds, "settle_folds", lambda *args, **kwargs: None)
    rng = np.random.default_rng(seed)
    pieces, (v, f) = _slabs(rng, k)
    p = _analyse(v, f, repair=repair)
    label, ok = _honest(p, S.truth_from_pieces([(1, x) for x in pieces]), _diag(v))
    assert ok, (label, p.mesh.certificate if p is not None else None)


@pytest.mark.parametrize(("reach", "flip"), [(1, False), (1, True), (2, False)])
def test_r3b_sheet_welded_to_a_cavity_wall(reach, flip):
    """A 5 m cube of cells with a 3 m cubic cavity, and a flat sheet in the wall between them (plane y = 2, from
    the outer face x = 0 to ``reach``): with reach 1 its rim is welded by index to both the outer face and the
    cavity's wall (a wall joining them, material on both sides: exact, 98 m³); with reach 2 it runs on into the
    cavity (a fin there: must not be certified as the solid with that piece as a wall)."""
    rng = np.random.default_rng(reach + 2 * flip)
    cells = {(i, j, k) for i in range(5) for j in range(5) for k in range(5)} - \
        {(i, j, k) for i in range(1, 4) for j in range(1, 4) for k in range(1, 4)}
    v, f = S.cell_body(cells, 1.0, rng)
    index = {tuple(p): i for i, p in enumerate(v.tolist())}
    pts = [tuple(float(x) for x in (i, 2, k)) for i in range(reach + 1) for k in range(1, 5)]
    for p in pts:
        index.setdefault(p, len(index))
    v = np.array(sorted(index, key=index.get), dtype=np.float64)
    grid = {(i, k): index[(float(i), 2.0, float(k))] for i in range(reach + 1) for k in range(1, 5)}
    sheet = []
    for i in range(reach):
        for k in range(1, 4):
            a, b, c, d = grid[(i, k)], grid[(i + 1, k)], grid[(i + 1, k + 1)], grid[(i, k + 1)]
            sheet += [[a, b, c], [a, c, d]]
    sheet = np.array(sheet)
    f = np.vstack([f, sheet[:, ::-1] if flip else sheet])
    p = _analyse(v, f)
    truth = S.truth_from_pieces([(1, S.box((1.0,) * 3, np.asarray(c, dtype=np.float64) + 0.5)) for c in sorted(cells)])
    label, ok = _honest(p, truth, _diag(v))
    assert ok, (label, p.volume if p is not None else None)
    if reach == 1:
        assert label == "exact" and "open-sheets" in p.mesh.certificate.checks
