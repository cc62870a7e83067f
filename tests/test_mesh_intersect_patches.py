"""mesh/intersect.py, the C scan's certified patches (issue 25 item 2; module docstring, "Patches").

A node of the C scan's hierarchy whose faces all project along one coordinate axis with one strict orientation,
and whose boundary chain projects to simple, pairwise disjoint polygons none inside another, is not descended
with itself: its faces meet only in what they share by index.  Every pair the check finds must still be
found, so each test compares, pair for pair, the C scan as the analysis runs it, the C scan without patches
(``_patches=False``, whose counts are the numpy twin's) and the numpy twin, and for small meshes every pair
against the independent rational classifier (``intersect_reference.brute_kind``).

The meshes are made to defeat the certificate: sheets on an integer lattice (exact coincidences) folded back
over themselves (coplanar or a lattice step apart), spiral ramps whose boundary winds twice round the axis
(layers apart, touching or coplanar), ribbons along a polyline that turns by about 90° (normal cones just
under and just over a half-turn) and curls back through itself, thin slabs of two opposite sheets, and
vertices pushed through the surface.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from intersect_reference import NONE, brute_kind, pair_kinds
from inertia_tool.mesh.intersect import SurfaceContacts
from contact_scans import run_scan, same_pairs


pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


def _check(v, f, brute=False) -> tuple[SurfaceContacts, SurfaceContacts]:
    """(patched, unpatched) C scans after comparing both, and the numpy twin, pair for pair."""
    fast = run_scan(v, f, accel=True)
    unpatched = run_scan(v, f, accel=True, _patches=False)
    ref = run_scan(v, f, accel=False)
    same_pairs(fast, unpatched)
    same_pairs(fast, ref)
    same_pairs(fast, run_scan(v, f, accel=True, _star_faces=0))
    assert (unpatched.candidate_pairs, unpatched.tested_pairs) == (ref.candidate_pairs, ref.tested_pairs)
    assert fast.candidate_pairs <= unpatched.candidate_pairs
    if brute:
        got = pair_kinds(fast)
        ff = np.asarray(f)
        for i in range(len(ff)):
            for j in range(i + 1, len(ff)):
                shared = [(a, b) for a in range(3) for b in range(3) if ff[i][a] == ff[j][b]]
                want = brute_kind(v[ff[i]], v[ff[j]], shared)
                assert got.get((i, j), NONE) == (NONE if want is None else want), (i, j)
    return fast, unpatched


def _grid(points: np.ndarray, closed_u: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Faces of a grid of points (nu, nw, 3), two triangles per cell wound (u, w) counterclockwise, and the
    points as (nu * nw, 3) vertices; ``closed_u`` joins the last row to the first."""
    nu, nw = points.shape[:2]
    rows = nu if closed_u else nu - 1
    i, j = np.meshgrid(np.arange(rows), np.arange(nw - 1), indexing="ij")
    a, b = i * nw + j, ((i + 1) % nu) * nw + j
    c, d = ((i + 1) % nu) * nw + j + 1, i * nw + j + 1
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    return points.reshape(-1, 3).astype(float), f.astype(np.int64)


def _sheet(nu, nw, rng, bump=0):
    """A lattice height field z = small integer noise over an nu x nw grid of unit steps (normals up)."""
    x, y = np.meshgrid(np.arange(nu) * 4.0, np.arange(nw) * 4.0, indexing="ij")
    z = rng.integers(-bump, bump + 1, x.shape) if bump else np.zeros(x.shape)
    return _grid(np.stack([x, y, z], -1))


def _fold(v, f, rng):
    """Columns past one fold line mirrored back over the sheet, a lattice step above it, on it, or below."""
    nu = int(round(v[:, 0].max() / 4)) + 1
    at = 4.0 * int(rng.integers(1, max(nu - 1, 2)))
    v = v.copy()
    past = v[:, 0] > at
    v[past, 0] = 2 * at - v[past, 0]
    v[past, 2] += rng.choice([-1.0, 0.0, 1.0, 2.0])
    return v, f


def _spiral(turns, pitch, cells, rng):
    """A ramp of two cells across round the z axis, ``turns`` turns, rising ``pitch`` per turn (0: the turns
    lie on one another); its boundary winds ``turns`` times round the axis."""
    theta = np.linspace(0, 2 * np.pi * turns, cells + 1)
    r = np.array([2.0, 3.0, 4.0])
    tt, rr = np.meshgrid(theta, r, indexing="ij")
    p = np.stack([rr * np.cos(tt) * 8, rr * np.sin(tt) * 8, pitch * tt / (2 * np.pi)], -1)
    return _grid(np.round(p * 4) / 4)


def _ribbon(turn_degrees, rng, width=3):
    """A ribbon along a polyline in the xz-plane turning by ``turn_degrees`` at each step (normals in the
    xz-plane; past 90° in all the ribbon overhangs, and a curl can pass back through itself), y across."""
    heading, x, z, pts = 0.0, 0.0, 0.0, []
    for step in range(len(turn_degrees) + 1):
        pts.append((x, z))
        if step < len(turn_degrees):
            heading += np.radians(turn_degrees[step])
        x, z = x + 6 * np.cos(heading), z + 6 * np.sin(heading)
    pts = np.round(np.array(pts) * 2) / 2
    y = np.arange(width + 1) * 3.0
    grid = np.stack([np.repeat(pts[:, :1], len(y), 1), np.broadcast_to(y, (len(pts), len(y))),
                     np.repeat(pts[:, 1:], len(y), 1)], -1)
    return _grid(grid)


def _slab(nu, nw, gap, rng):
    """Two sheets facing away from each other ``gap`` apart (a thin slab without its rim)."""
    v, f = _sheet(nu, nw, rng)
    top = v + np.array([0.0, 0.0, gap])
    return np.r_[v, top], np.r_[f[:, ::-1], f + len(v)]


def _push(v, f, rng, count):
    """``count`` vertices moved by a lattice vector of up to 8 steps (through the surface, often)."""
    v = v.copy()
    for _ in range(count):
        x = int(rng.integers(len(v)))
        v[x] += rng.integers(-8, 9, 3)
    return v, f


@st.composite
def adversarial_patches(draw):
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    kind = draw(st.sampled_from(["sheet", "fold", "spiral", "ribbon", "slab"]))
    if kind == "sheet":
        v, f = _sheet(draw(st.integers(3, 9)), draw(st.integers(3, 9)), rng, bump=draw(st.integers(0, 1)))
    elif kind == "fold":
        v, f = _fold(*_sheet(draw(st.integers(4, 9)), draw(st.integers(3, 7)), rng), rng)
    elif kind == "spiral":
        v, f = _spiral(draw(st.sampled_from([0.6, 1.0, 1.5, 2.0, 2.5])), draw(st.sampled_from([0.0, 0.5, 3.0])),
                       draw(st.integers(8, 40)), rng)
    elif kind == "ribbon":
        # turning angles near 90 degrees in all: cones just under and just over a half-turn, and curls
        turns = draw(st.lists(st.sampled_from([-30.0, 0.0, 14.0, 15.0, 16.0, 30.0, 45.0, 60.0, 89.0, 91.0]),
                              min_size=3, max_size=14))
        v, f = _ribbon(turns, rng, width=draw(st.integers(1, 4)))
    else:
        v, f = _slab(draw(st.integers(3, 7)), draw(st.integers(3, 7)), draw(st.sampled_from([0.0, 1.0, 4.0])), rng)
    v, f = _push(v, f, rng, draw(st.integers(0, 2)))
    return v, f


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(adversarial_patches())
def test_patches_leave_out_no_pair_the_twins_find(mesh):
    v, f = mesh
    fast, unpatched = _check(v, f, brute=len(f) <= 36)
    event("patches left pairs out" if fast.candidate_pairs < unpatched.candidate_pairs else "no patch")


def test_clean_sheet_is_one_patch():
    """A flat lattice sheet projects one to one along z: the whole of it is certified, no pair is tested."""
    v, f = _sheet(12, 10, np.random.default_rng(1))
    fast, unpatched = _check(v, f)
    assert fast.candidate_pairs == 0 < unpatched.candidate_pairs


@pytest.mark.parametrize("pitch, meets", [(3.0, False), (0.0, True)])
def test_spiral_whose_boundary_winds_twice_is_not_certified(pitch, meets):
    """Two turns of a ramp: every face faces up, but the boundary winds twice round the axis, so the projection
    is not one to one.  Apart (pitch 3) nothing meets; on one another (pitch 0) the turns overlap face to face
    and every such pair is found, as by the unpatched scan."""
    v, f = _spiral(2.0, pitch, 48, np.random.default_rng(2))
    fast, _ = _check(v, f)
    found = len(fast.crossing) + len(fast.coplanar_opposite) + len(fast.contact)
    assert (found > 0) == meets


def test_fold_pushed_through_a_torus_is_found():
    """A 1,600-face torus (certified in patches) with one vertex pushed through the opposite side of the tube:
    the crossings are those of the unpatched scan and of the numpy twin, and the patches still leave most pairs
    out."""
    u = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    w = np.linspace(0, 2 * np.pi, 20, endpoint=False) + 0.1
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = 10 + 3.5 * np.cos(ww)
    p = np.stack([r * np.cos(uu), r * np.sin(uu), 3.5 * np.sin(ww)], -1)
    v, f = _grid(p, closed_u=True)
    nw = 20
    f = np.r_[f, np.stack([np.arange(40) * nw + nw - 1, ((np.arange(40) + 1) % 40) * nw + nw - 1,
                           ((np.arange(40) + 1) % 40) * nw], -1),
              np.stack([np.arange(40) * nw + nw - 1, ((np.arange(40) + 1) % 40) * nw, np.arange(40) * nw], -1)]
    clean, unpatched = _check(v, f)
    assert not (len(clean.crossing) or len(clean.contact) or len(clean.coplanar_opposite))
    assert clean.candidate_pairs < unpatched.candidate_pairs // 2
    x = 5 * nw + 5                                      # through the tube and out of its opposite wall
    v = v.copy()
    v[x] = v[x] - 2.3 * (v[x] - np.array([10 * np.cos(u[5]), 10 * np.sin(u[5]), 0.0]))
    pushed, _ = _check(v, f)
    assert len(pushed.crossing) > 0
