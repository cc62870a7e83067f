"""The user's ``flat-islands`` assumption (issues 21 and 23): a hole that is an island in a flat face is refused by
default (nothing in the file tells a flat lid from a boss or pocket taken whole), and with
``repair=True, assume=("flat-islands",)`` is filled in its rim's plane and bounded by the slab of the rim's own
deviation, the estimate naming the assumption as the user's.

Truth: the exact rational integral of the closed solid (``review12_generators.rational_moments``), moved by the
same rigid motion as the mesh.  Two tessellations of the face: a grid (vertices inside the flat face, the ball
refusal) and a CAD-like one (vertices on the face's loops only, made by manifold3d: the footprint refusal).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError, UsageError
from inertia_tool.mesh.hole_assumptions import FLAT_ISLANDS, user_stated
from inertia_tool.mesh.options import LoadOptions

from review12_generators import rational_moments, star_polygon

ASSUME = ("flat-islands",)


def _box_truth(w: float, d: float, h: float):
    """Exact moments of the closed box [0, w] × [0, d] × [0, h] (six outward quads)."""
    pts = [(x, y, z) for z in (0.0, h) for y in (0.0, d) for x in (0.0, w)]
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    return rational_moments(pts, quads)


def _moved(v, truth, quat, shift):
    """The mesh and the truth under one rigid motion: x → R x + t, c → R c + t, I → R I Rᵀ."""
    r = Rotation.from_quat(quat).as_matrix()
    return v @ r.T + shift, r @ truth.centroid + shift, r @ truth.inertia @ r.T


def _inside_bound(props, volume, centroid, inertia) -> bool:
    """The truth lies inside every bound the estimate states (plus 1e-12 of it for the float truth)."""
    u = props.mesh.uncertainty
    return (abs(props.volume - volume) <= u.mass * props.volume * (1 + 1e-12) + 1e-12 * volume
            and np.linalg.norm(props.center_of_mass - centroid) <= u.center_of_mass * (1 + 1e-12) + 1e-12
            and np.linalg.norm(props.inertia - inertia)
            <= u.inertia * np.linalg.norm(props.inertia) * (1 + 1e-12) + 1e-12 * np.linalg.norm(inertia))


def _said(props) -> str:
    """Everything the mesh report says of the repair (notes and actions)."""
    return " ".join([*props.mesh.notes, *props.mesh.repair_actions])


def grid_plate(n: int, h: float, hole: set[tuple[int, int]]):
    """A plate [0, n]² × [0, h] with every face on a unit grid, less the top cells in ``hole`` (a polyomino)."""
    index: dict = {}
    verts: list = []

    def at(p):
        if p not in index:
            index[p] = len(verts)
            verts.append(p)
        return index[p]

    faces = []
    for i in range(n):
        for j in range(n):
            a, b, c, e = at((i, j, 0)), at((i + 1, j, 0)), at((i + 1, j + 1, 0)), at((i, j + 1, 0))
            faces += [(a, c, b), (a, e, c)]
            if (i, j) not in hole:
                a, b, c, e = at((i, j, h)), at((i + 1, j, h)), at((i + 1, j + 1, h)), at((i, j + 1, h))
                faces += [(a, b, c), (a, c, e)]
    ring = ([(i, 0) for i in range(n)] + [(n, i) for i in range(n)] + [(n - i, n) for i in range(n)]
            + [(0, n - i) for i in range(n)])
    for k, p in enumerate(ring):
        q = ring[(k + 1) % len(ring)]
        a, b, c, e = at((*p, 0)), at((*q, 0)), at((*q, h)), at((*p, h))
        faces += [(a, b, c), (a, c, e)]
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64)


def cad_box_with_feature(polygon: np.ndarray, extents, height: float):
    """A box whose top face carries a prism boss (``height`` > 0) or pocket (< 0) over ``polygon``, made by
    manifold3d (flat faces triangulated with vertices on their loops only), and the faces of the feature
    (walls and top or floor): taking them away leaves an island hole in the top face."""
    import manifold3d as m3d

    w, d, h = extents
    body = m3d.Manifold.cube([w, d, h])
    prism = m3d.Manifold.extrude(m3d.CrossSection([polygon.tolist()]), abs(height) + (0.0 if height > 0 else 1.0))
    body = body + prism.translate([0, 0, h]) if height > 0 else body - prism.translate([0, 0, h + height])
    mesh = body.to_mesh()
    v = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(mesh.tri_verts, dtype=np.int64)
    corners = v[f]
    off_top = np.any(np.abs(corners[:, :, 2] - h) > 1e-9 * h, axis=1)
    tol = 1e-9 * max(w, d)
    inward = np.all((corners[:, :, 0] > tol) & (corners[:, :, 0] < w - tol) & (corners[:, :, 1] > tol)
                    & (corners[:, :, 1] < d - tol), axis=1)         # not the box's sides or bottom
    return v, f, np.flatnonzero(off_top & inward)


def _polygon(seed: int, extents) -> np.ndarray:
    """A star polygon well inside the top face of a box of ``extents``."""
    rng = np.random.default_rng(seed)
    w, d, _ = extents
    size = 0.3 * min(w, d)
    return star_polygon(rng) * size + np.array([w / 2, d / 2])


# --------------------------------------------------------------------------------------------- grid faces

@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(1, 3), st.integers(1, 3), st.integers(0, 2 ** 16),
       st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1),
       st.lists(st.floats(-50, 50), min_size=3, max_size=3))
def test_grid_plate_with_a_polyomino_hole(width, depth, seed, quat, shift):
    """Refused by default (the ball over the rim says nothing); with the assumption, the closed plate's exact
    moments lie inside the stated bound, which is round-off, and the estimate names the user's assumption."""
    rng = np.random.default_rng(seed)
    n, h = 8, 0.25
    x0, y0 = int(rng.integers(1, n - width)), int(rng.integers(1, n - depth))
    hole = {(x0 + i, y0 + j) for i in range(width) for j in range(depth)}
    hole -= {(x0, y0)} if width * depth > 2 and rng.random() < 0.5 else set()      # an L-shaped rim too
    v, f = grid_plate(n, h, hole)
    v, centroid, inertia = _moved(v, _box_truth(n, n, h), np.asarray(quat), np.asarray(shift))
    volume = float(n * n * h)
    if len(hole) >= 4:
        with pytest.raises(InvalidMeshError, match="--assume flat-islands|`assume` flat-islands"):
            mass_properties((v, f), density=1.0, repair=True)
    props = mass_properties((v, f), density=1.0, repair=True, assume=ASSUME)
    assert props.mesh.certificate.kind == "estimate"
    assert _inside_bound(props, volume, centroid, inertia)
    assert props.mesh.uncertainty.mass < 1e-9
    assert user_stated(["flat-islands"]) in _said(props)


# ----------------------------------------------------------------------------------------- CAD-like faces

@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2 ** 16), st.floats(0.2, 2.0),
       st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1),
       st.lists(st.floats(-50, 50), min_size=3, max_size=3))
def test_cad_box_that_lost_a_flat_lid(seed, depth, quat, shift):
    """A pocket's walls and floor taken away leave a footprint rim (bare vertices): refused by default, the
    message naming the option; with it, the closed box's exact moments inside a round-off bound."""
    extents = (4.0, 3.0, 2.5)
    v, f, feature = cad_box_with_feature(_polygon(seed, extents), extents, -min(depth, 2.0))
    open_f = np.delete(f, feature, axis=0)
    v, centroid, inertia = _moved(v, _box_truth(*extents), np.asarray(quat), np.asarray(shift))
    with pytest.raises(InvalidMeshError, match="footprint.*`assume` flat-islands$"):
        mass_properties((v, open_f), density=1.0, repair=True)
    props = mass_properties((v, open_f), density=1.0, repair=True, assume=ASSUME)
    assert props.mesh.certificate.kind == "estimate"
    assert _inside_bound(props, float(np.prod(extents)), centroid, inertia)
    assert props.mesh.uncertainty.mass < 1e-9


@pytest.mark.parametrize("height", [1.5, -1.0])
def test_a_boss_or_pocket_taken_whole_is_an_estimate_naming_the_users_assumption(height):
    """The assumption false (a boss or pocket taken whole, walls and top): the answer is the box without the
    feature, outside its bound — and labelled so: an estimate, the user's assumption named in the note and in
    the report's assumptions, never exact."""
    extents = (4.0, 3.0, 2.5)
    v, f, feature = cad_box_with_feature(_polygon(7, extents), extents, height)
    props = mass_properties((v, np.delete(f, feature, axis=0)), density=1.0, repair=True, assume=ASSUME)
    truth = mass_properties((v, f), density=1.0)
    assert props.mesh.certificate.kind == "estimate"
    assert "assumed by the user: flat-islands" in _said(props)
    assert FLAT_ISLANDS.fails_for in _said(props)
    assert abs(props.volume - truth.volume) > props.mesh.uncertainty.mass * props.volume   # wrong, and said why


def test_the_assumption_changes_no_other_hole():
    """A hole that is not an island (a triangle gone at the box's edge, its rim on a crease) keeps its bound."""
    extents = (4.0, 3.0, 2.5)
    v, f, _ = cad_box_with_feature(_polygon(3, extents), extents, -1.0)
    side = np.flatnonzero(np.all(np.abs(v[f][:, :, 0]) < 1e-12, axis=1))[:1]
    open_f = np.delete(f, side, axis=0)
    before = mass_properties((v, open_f), density=1.0, repair=True)
    after = mass_properties((v, open_f), density=1.0, repair=True, assume=ASSUME)
    assert after.volume == before.volume
    assert after.mesh.uncertainty == before.mesh.uncertainty
    assert "flat-islands" not in _said(after)


# ------------------------------------------------------------------------------------------------ options

def test_load_options_check_the_assumption():
    with pytest.raises(UsageError, match="repair=True"):
        LoadOptions(assume=ASSUME)
    with pytest.raises(UsageError, match="flat-islands"):
        LoadOptions(repair=True, assume=("flat",))
    with pytest.raises(UsageError, match="tuple"):
        LoadOptions(repair=True, assume="flat-islands")
    assert LoadOptions(repair=True, assume=["flat-islands"]).assume == ASSUME
