"""The user's ``faceted-holes`` assumption (issue 21, certified answers): each hole lost a piece of a faceted surface
staying inside the planes of the faces round it (:data:`~inertia_tool.mesh.hole_assumptions.FACETED_HOLES`).  With
``assume=("faceted-holes",)`` a hole is bounded by the region between its cone and those planes continued
(:func:`~inertia_tool.mesh.hole_facets.faceted_doubt`) where that is narrower than its default bound, and filled on
the planes where they close it; the estimate names the assumption as the user's.

Closed forms: an L of three unit cubes (volume 3; its inertia about the centre of mass the sum of the cubes' ``1/6``
and their parallel-axis terms), each face split in eight, less the faces round a convex corner or along a convex
edge: the planes left meet where the corner or edge was, so the faceted fill is exact.  The region between a
subdivided cube's corner and its cone is the lost corner itself (the planes continued are the surface lost).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import adversary_solids as S
from test_hole_bounds import _holds
from test_hole_planes import _polytope
from test_holes7_bend import _grow
from inertia_tool import mass_properties
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh.hole_assumptions import FACETED_HOLES, UserAssumptions, user_stated
from inertia_tool.mesh.hole_facets import faceted_doubt
from inertia_tool.mesh.holes import patched_estimate
from inertia_tool.mesh.rims import boundary_edges, enclosing_balls

FACETED = UserAssumptions(("faceted-holes",))


def _cubes(cells, subdivide=1):
    """The closed outward surface of a union of unit cubes at integer ``cells``, each square face two triangles,
    then split in four ``subdivide`` times (so every plane keeps faces after a patch is taken)."""
    cells = set(cells)
    index: dict[tuple[int, int, int], int] = {}
    faces = []
    sides = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (0, 0, 1), (1, 0, 0)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]
    for c in sorted(cells):
        for n, a, b in sides:
            if tuple(c[i] + n[i] for i in range(3)) in cells:
                continue
            o = tuple(c[i] + (1 if n[i] > 0 else 0) for i in range(3))
            quad = [o, tuple(o[i] + a[i] for i in range(3)), tuple(o[i] + a[i] + b[i] for i in range(3)),
                    tuple(o[i] + b[i] for i in range(3))]
            q = [index.setdefault(p, len(index)) for p in quad]
            faces += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    v = np.array(sorted(index, key=index.__getitem__), dtype=np.float64)
    f = np.array(faces, dtype=np.int64)
    for _ in range(subdivide):
        v, f = S._subdivide(v, f)
    return v, f


L_CELLS = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


def _l_inertia():
    """The L of three unit cubes (density 1) about its centre of mass: each cube ``I/6`` plus ``|r|² I − r rᵀ``."""
    centres = np.array(L_CELLS, dtype=np.float64) + 0.5
    com = centres.mean(axis=0)
    r = centres - com
    return sum(np.eye(3) / 6.0 + (x @ x) * np.eye(3) - np.outer(x, x) for x in r), com


def _l_truth():
    return volume_moments(*_cubes(L_CELLS))


def _lost_at(v, f, point):
    """The faces with a corner at ``point`` (a vertex of the mesh)."""
    at = int(np.argmin(np.linalg.norm(v - np.asarray(point, dtype=np.float64), axis=1)))
    return (f == at).any(axis=1)


@pytest.mark.parametrize("what, point", [("convex corner", (2.0, 1.0, 1.0)), ("corner of the end", (2.0, 0.0, 1.0)),
                                         ("corner on the floor", (0.0, 2.0, 0.0))])
def test_l_corner_or_edge_lost_is_exact(what, point):
    """The L less the faces round a convex corner or the middle of a convex edge: under faceted-holes the three (or
    two) planes left meet where the corner (edge) was, so the answer is the closed form — volume 3, the centre of
    mass and inertia of the three cubes — to round-off, inside a bound no wider than 3 % (the region between the
    cone and the corner), the certificate and the note naming the user's assumption.  By default the same hole is
    bounded by its ball and the answer is the cone's (or refused)."""
    v, f = _cubes(L_CELLS)
    lost = _lost_at(v, f, point)
    kept = f[~lost]
    inertia, com = _l_inertia()
    est = patched_estimate(v, kept, volume_moments, assume=FACETED)
    assert est.assumptions[-1] == "faceted-holes", what
    # the fill follows the planes' creases to the share its grid samples them (PLANE_FILL_LEVELS: 1e-4 of the
    # volume, 1e-3 of the inertia)
    assert abs(est.volume - 3.0) <= 1e-4 * 3.0
    assert np.linalg.norm(est.centroid - com) <= 1e-4
    second = est.second_moment                       # ∫ x xᵀ about the centroid → inertia = tr·I − S
    assert np.linalg.norm((np.trace(second) * np.eye(3) - second) - inertia) <= 1e-3 * np.linalg.norm(inertia)
    assert _holds(est, _l_truth())
    assert 0 < est.uncertainty.mass <= 0.03
    assert user_stated(["faceted-holes"]) in est.detail
    default = patched_estimate(v, kept, volume_moments)
    assert "faceted-holes" not in default.assumptions
    assert default.uncertainty.mass > est.uncertainty.mass


def test_cube_corner_region_is_the_lost_corner():
    """A cube (each face split in eight) less the faces at one corner: the three planes left meet at the corner, so
    the region between the cone and them is exactly the solid lost, ``1 − V(cone-closed)``; the bound is that to
    the rounding up (2 %) and never below it."""
    v, f = S.box((1.0, 1.0, 1.0), subdivide=1)
    corner = v.max(axis=0)
    kept = f[~_lost_at(v, f, corner)]
    edges = boundary_edges(kept, len(v))
    rim = np.unique(edges)
    apex = v[rim].mean(axis=0)
    _, radius = enclosing_balls(v[rim], np.zeros(len(rim), dtype=np.int64), 1)
    region = faceted_doubt(v, kept, edges, apex, float(radius[0]))
    assert region is not None and region.convex and region.planes == 3
    caps = np.column_stack([edges[:, 1], edges[:, 0], np.full(len(edges), len(v))])
    lost = 1.0 - volume_moments(np.vstack([v, apex]), np.vstack([kept, caps])).volume
    assert lost <= region.doubt <= 1.02 * lost
    # the region reaches the corner: at least the corner's distance from the cone's apex along d, at most the ball
    assert np.linalg.norm(corner - apex) * 0.99 <= region.reach <= 2.0 * float(radius[0])


def test_boss_taken_whole_breaks_it():
    """The assumption false: a spike (the L's convex corner pulled out 0.6 along the diagonal) taken whole with the
    faces round it.  The planes left say corner, so the answer misses the spike by more than its bound; the
    estimate says the bound rests on the user's assumption (the certificate names it, the note states what breaks
    it), and the default answer's wider bound holds."""
    v, f = _cubes(L_CELLS)
    at = int(np.argmin(np.linalg.norm(v - [2.0, 1.0, 1.0], axis=1)))
    spiked = v.copy()
    spiked[at] += 0.6 / np.sqrt(3.0)
    truth = mass_properties((spiked, f), density=1.0)
    kept = f[~(f == at).any(axis=1)]
    with pytest.warns(Warning):
        est = mass_properties((spiked, kept), density=1.0, repair=True, assume=("faceted-holes",))
    assert est.mesh.certificate.assumptions == ("faceted-holes",)
    assert not _holds_props(est, truth)
    assert f"assumed by the user: faceted-holes: {FACETED_HOLES.statement}" in " ".join(est.mesh.notes)
    with pytest.warns(Warning):
        default = mass_properties((spiked, kept), density=1.0, repair=True)
    assert default.mesh.certificate.assumptions == ()
    assert _holds_props(default, truth)


def _holds_props(props, truth) -> bool:
    u = props.mesh.uncertainty
    return (abs(props.volume - truth.volume) <= u.mass * props.volume * (1 + 1e-12) + 1e-12 * truth.volume
            and np.linalg.norm(props.center_of_mass - truth.center_of_mass) <= u.center_of_mass * (1 + 1e-12) + 1e-12
            and np.linalg.norm(props.inertia - truth.inertia)
            <= u.inertia * np.linalg.norm(props.inertia) * (1 + 1e-12) + 1e-12 * np.linalg.norm(truth.inertia))


def _staircase(rng):
    """A random staircase of unit cubes (3-6 cells, each on top of or beside the last), stretched per axis."""
    cells = [(0, 0, 0)]
    for _ in range(int(rng.integers(2, 6))):
        x, y, z = cells[-1]
        step = [(1, 0, 0), (0, 1, 0), (0, 0, 1)][int(rng.integers(3))]
        cells.append((x + step[0], y + step[1], z + step[2]))
    v, f = _cubes(cells)
    return v * rng.uniform(0.3, 3.0, size=3), f


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1), share=st.floats(0.01, 0.15), convex=st.booleans())
def test_faceted_bound_holds_on_generated_polyhedra(seed, share, convex):
    """Convex polytopes (hulls of random points, every face split in four, turned and moved) and random
    staircases of stretched cubes (every face split in eight), less a connected patch of faces grown from a random
    face: where the estimate takes faceted-holes, its bound holds (a patch of a polyhedron whose planes keep faces
    at the rim: the assumption true wherever the lost surface does not fold over the hole, which the evidence
    check withdraws)."""
    rng = np.random.default_rng(seed)
    v, f = _polytope(rng) if convex else _staircase(rng)
    truth = volume_moments(v, f)
    gone = _grow(f, int(rng.integers(len(f))), max(1, int(share * len(f))))
    est = patched_estimate(v, np.delete(f, gone, axis=0), volume_moments, assume=FACETED)
    if est.unbounded or "faceted-holes" not in est.assumptions:
        return
    assert _holds(est, truth)
