"""mesh/intersect.py, certified patches whose boundary passes through one vertex more than once (a *pinch*) or has
holes.

A node of the C scan's hierarchy is a range of faces in Morton order, which often touches itself at a corner:
its boundary chain then leaves and enters one vertex two to four times. The C scan resolves such a vertex (the
directions of its boundary edges about it, in exact angular order, must alternate between leaving and entering;
each entering edge is followed by the leaving edge beside it) into cycles that touch there without crossing, and
certifies the node only if those cycles project to simple polygons that meet only at such vertices, nested only
as outline, hole, island in the hole ..., their orientations alternating from the outermost in (module docstring
of ``mesh/intersect.py``, "Patches").

The meshes here are made to defeat that rule: fans of one to three triangles round one shared vertex, in sectors
that are disjoint, touch along a ray, overlap, nest or fold back, lifted by lattice steps or by one unit in the
last place (near-coplanar sheets), some dipping through another fan right next to the shared vertex, some with a
ring point repeated by coordinates under another index; square rings (a patch with a hole) with an island in or
across the hole, and squares stacked on squares facing the same way (nested outlines of one orientation: the
projection covers the inner square twice) a lattice step, one ulp or nothing apart. Each mesh has at most 16
faces, so the whole of it is one leaf of the hierarchy, the first node tried as a patch. Every verdict is
compared pair for pair with the scan without patches, the numpy twin and the independent rational classifier
(``intersect_reference.brute_kind``).
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from test_mesh_intersect_patches import _check, _push

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")

ULP = float(np.nextafter(1.0, 2.0))                 # 1 + 2^-52: a sheet one unit in the last place above z = 1
HEIGHTS = [1.0, ULP, float(np.nextafter(1.0, 0.0)), 0.0, 2.0, 3.0]


def _fans(wedges, centre_z=1.0):
    """Vertices and faces of fans round vertex 0 at (0, 0, centre_z): each wedge a list of ring points
    (x, y, z), its faces (0, r_i, r_i+1) (counterclockwise seen from +z when the ring turns that way); the
    wedges share vertex 0 only."""
    v = [[0.0, 0.0, centre_z]]
    f = []
    for ring in wedges:
        base = len(v)
        v.extend([list(map(float, p)) for p in ring])
        f.extend([0, base + i, base + i + 1] for i in range(len(ring) - 1))
    return np.array(v, dtype=float), np.array(f, dtype=np.int64)


_DIRS = [(6, 0), (5, 3), (3, 5), (0, 6), (-3, 5), (-5, 3), (-6, 0), (-5, -3), (-3, -5), (0, -6), (3, -5), (5, -3)]


@st.composite
def pinched_fans(draw):
    """2 to 4 fans round one vertex: sector start and width (in twelfths of a turn; widths up to 5/12, so each
    fan alone is one to one along z, while fans may overlap, nest or share a ray), per ring point a height
    (lattice steps, or 1 ulp off the centre's plane) and a radius, sometimes reversed (a fan facing down),
    sometimes a ring point repeated by coordinates from another fan."""
    k = draw(st.integers(2, 4))
    wedges = []
    for _ in range(k):
        start = draw(st.integers(0, 11))
        width = draw(st.integers(1, 5))
        ring = []
        for step in range(min(width, 3) + 1):
            dx, dy = _DIRS[(start + step * width // min(width, 3)) % 12]
            scale = draw(st.sampled_from([1, 1, 2]))
            ring.append((dx * scale, dy * scale, draw(st.sampled_from(HEIGHTS))))
        if draw(st.integers(0, 5)) == 0:
            ring.reverse()
        wedges.append(ring)
    if draw(st.integers(0, 4)) == 0 and k >= 2:          # a ring point of one fan repeated in another
        a, b = draw(st.integers(0, k - 1)), draw(st.integers(0, k - 1))
        wedges[b][-1] = wedges[a][0]
    v, f = _fans(wedges, centre_z=draw(st.sampled_from([1.0, 1.0, ULP])))
    return v, f


def _found(result) -> int:
    return len(result.crossing) + len(result.coplanar_opposite) + len(result.contact)


@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(pinched_fans())
@example(_fans([[(6, 0, 1), (0, 6, 1)], [(-6, 0, 2), (0, -6, 2)]]))         # disjoint sectors: certified
@example(_fans([[(6, 0, 1), (0, 6, 1)], [(5, 3, 2), (-6, 0, 2)]]))          # overlapping sectors, apart in z
@example(_fans([[(6, 0, 1), (0, 6, 1)], [(5, 3, 0), (3, 5, 3)]]))           # nested sector, crossing the fan
@example(_fans([[(6, 0, 1), (0, 6, 1)], [(0, 6, 2), (-6, 0, 2)]]))          # touching along a ray
@example(_fans([[(6, 0, 1), (0, 6, 1)], [(-6, 0, 1), (-5, -3, ULP)]]))      # 1 ulp apart
def test_pinched_patches_match_brute_force(mesh):
    v, f = mesh
    fast, unpatched = _check(v, f, brute=True)
    event("certified" if fast.candidate_pairs < unpatched.candidate_pairs else "not certified")


def test_two_fans_in_disjoint_sectors_are_one_patch():
    """Two fans touching only at their shared vertex, in opposite quadrants: the boundary leaves and enters
    that vertex twice, the two cycles touch there without crossing and lie apart, so no pair is tested."""
    v, f = _fans([[(6, 0, 1), (5, 3, 0), (0, 6, 1)], [(-6, 0, 2), (-5, -3, 1), (0, -6, 2)]])
    fast, unpatched = _check(v, f, brute=True)
    assert fast.candidate_pairs == 0 < unpatched.candidate_pairs
    assert _found(fast) == 0


@pytest.mark.parametrize("second, meets", [
    ([(5, 3, 3), (-6, 0, 3)], False),                # overlapping sectors, the second fan above the first
    ([(5, 3, 0), (3, 5, 3)], True),                  # inside the first fan's sector, dipping through it
    ([(5, 3, 1), (3, 5, 1)], True),                  # inside it and coplanar, facing the same way
    ([(0, 6, ULP), (-6, 0, 1)], False),              # along the first fan's edge, its far end 1 ulp above
    ([(0, 6, 1), (-6, 0, 1)], True),                 # along it, the far ends equal under two indices
])
def test_fans_overlapping_in_projection_are_not_certified(second, meets):
    """Fans whose projections overlap, nest or share a ray (the directions about the pinch do not alternate,
    or the cycles meet beyond it) are not certified; the pairs that meet are found as without patches."""
    v, f = _fans([[(6, 0, 1), (0, 6, 1)], second])
    fast, unpatched = _check(v, f, brute=True)
    assert fast.candidate_pairs == unpatched.candidate_pairs
    assert (_found(fast) > 0) == meets


def _icosphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """A subdivided icosahedron on the unit sphere (faces in subdivision order, as trimesh writes them)."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, dtype=float) / np.linalg.norm(p) for p in v]
    faces = np.array(f)
    for _ in range(subdivisions):
        mids: dict[tuple[int, int], int] = {}

        def mid(a: int, b: int) -> int:
            key = (min(a, b), max(a, b))
            if key not in mids:
                p = verts[a] + verts[b]
                verts.append(p / np.linalg.norm(p))
                mids[key] = len(verts) - 1
            return mids[key]

        out = []
        for a, b, c in faces.tolist():
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        faces = np.array(out)
    return np.round(np.array(verts) * 2 ** 20) / 2 ** 20, faces


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_icosphere_pinched_nodes_keep_every_pair(seed):
    """A 5,120-face icosphere (its Morton-order nodes touch themselves at corners), clean and with vertices
    pushed through the surface: the same pairs as without patches and as the numpy twin, and the patches leave
    out most pairs of the clean sphere (4,540 of 31,194 left; 5,343 before pinches were resolved)."""
    v, f = _icosphere(4)
    clean, unpatched = _check(v, f)
    assert _found(clean) == 0
    assert clean.candidate_pairs < unpatched.candidate_pairs // 4
    rng = np.random.default_rng(seed)
    v2, f2 = _push(v * 8, f, rng, 3)
    _check(v2, f2)


def _square(half, z, lo=0.0):
    """Corners (ccw seen from +z) of the square [lo - half, lo + half]^2 at heights z (one per corner)."""
    return [(lo - half, lo - half, z[0]), (lo + half, lo - half, z[1]), (lo + half, lo + half, z[2]),
            (lo - half, lo + half, z[3])]


def _ring(outer, inner):
    """Faces of the square ring between the corner lists ``outer`` and ``inner`` (vertices 0-3 and 4-7), facing
    +z: the boundary is the outer square counterclockwise and the inner one clockwise (a hole)."""
    return [f for k in range(4) for f in ([k, (k + 1) % 4, 4 + (k + 1) % 4], [k, 4 + (k + 1) % 4, 4 + k])]


@st.composite
def rings_and_stacks(draw):
    """A square ring (outer half-size 6, inner 2..4; heights per corner) with, maybe, an island square (two
    faces, facing up or down) of half-size 1..3 anywhere near the hole at any height; or a square with a smaller
    square facing the same way inside its projection, a lattice step, one ulp or nothing above."""
    heights = st.sampled_from(HEIGHTS)
    if draw(st.booleans()):
        outer = _square(6.0, [draw(heights) for _ in range(4)])
        inner = _square(float(draw(st.integers(2, 4))), [draw(heights) for _ in range(4)])
        v = outer + inner
        f = _ring(outer, inner)
        if draw(st.booleans()):
            island = _square(float(draw(st.integers(1, 3))), [draw(heights)] * 4, lo=float(draw(st.integers(-3, 3))))
            f += [[8, 9, 10], [8, 10, 11]] if draw(st.integers(0, 3)) else [[8, 10, 9], [8, 11, 10]]
            v += island
    else:
        z = draw(heights)
        v = _square(6.0, [1.0] * 4) + _square(float(draw(st.integers(1, 5))), [z] * 4,
                                              lo=float(draw(st.integers(-1, 1))))
        f = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]
    return np.array(v, dtype=float), np.array(f, dtype=np.int64)


@pytest.mark.slow
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rings_and_stacks())
def test_rings_and_stacks_match_brute_force(mesh):
    v, f = mesh
    fast, unpatched = _check(v, f, brute=True)
    event("certified" if fast.candidate_pairs < unpatched.candidate_pairs else "not certified")


def test_square_ring_with_an_island_is_one_patch():
    """A ring with an island in its hole, both facing up: outline, hole and island alternate in orientation,
    so the projection is one to one and no pair is tested."""
    outer, inner = _square(6.0, [1.0, 2.0, 1.0, 0.0]), _square(3.0, [1.0, ULP, 1.0, 2.0])
    v = np.array(outer + inner + _square(1.0, [5.0] * 4), dtype=float)
    f = np.array(_ring(outer, inner) + [[8, 9, 10], [8, 10, 11]])
    fast, unpatched = _check(v, f, brute=True)
    assert fast.candidate_pairs == 0 < unpatched.candidate_pairs


@pytest.mark.parametrize("z, meets", [(3.0, False), (ULP, False), (1.0, True)])
def test_square_stacked_on_a_square_is_not_certified(z, meets):
    """A smaller square above a larger one, both facing up: their outlines are disjoint and nested, but of one
    orientation, so the inner square is covered twice and the pair is tested (and found when coplanar)."""
    v = np.array(_square(6.0, [1.0] * 4) + _square(2.0, [z] * 4), dtype=float)
    f = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    fast, unpatched = _check(v, f, brute=True)
    assert fast.candidate_pairs == unpatched.candidate_pairs
    assert (_found(fast) > 0) == meets


@st.composite
def fans_with_bad_edges(draw):
    """Pinched fans (as above) with faces that make an edge not one face each way: a face repeated, a face
    reversed, a face with a repeated corner (zero area), a third face on an edge.  The faces across an edge are
    then not one (no patch holds such a face); the closed oriented fans round a vertex take a shortcut, which
    must never pair such faces."""
    v, f = draw(pinched_fans())
    f = [list(x) for x in f]
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(f) - 1))
        how = draw(st.sampled_from(["repeat", "reverse", "repeated corner", "third"]))
        if how == "repeat":
            f.append(list(f[i]))
        elif how == "reverse":
            f.append(f[i][::-1])
        elif how == "repeated corner":
            f.append([f[i][0], f[i][1], f[i][1]])
        else:                                    # a new point over the edge (0, f[i][1])
            v = np.r_[v, [v[f[i][1]] * 0.5 + np.array([0.0, 0.0, draw(st.sampled_from([1.0, -1.0, 0.0]))])]]
            f.append([f[i][1], 0, len(v) - 1])
    return v, np.array(f[:16], dtype=np.int64)


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fans_with_bad_edges())
def test_fans_with_bad_edges_match_brute_force(mesh):
    v, f = mesh
    fast, unpatched = _check(v, f, brute=True)
    event("certified" if fast.candidate_pairs < unpatched.candidate_pairs else "not certified")
