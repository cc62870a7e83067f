"""Adversarial review of three certificate proofs (review6): the face-pair check's certified patches
(``mesh/intersect.py``, "Patches"), holes3's convex-part hole bound (``mesh/holes.py``) and walls3's T-vertex
sheet rule (``mesh/sheets.py``).

Each generator builds small inputs meant to defeat one rule and checks the verdict against an independent
truth: for patches, the rational all-pairs classifier ``intersect_reference.brute_kind`` on meshes of at most
16 faces (one leaf of the C scan's hierarchy, the first node tried as a patch).
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from test_mesh_intersect_patches import _check

ULP = float(np.nextafter(1.0, 2.0))


def _orient2d(a, b, c) -> int:
    d = (int(b[0]) - int(a[0])) * (int(c[1]) - int(a[1])) - (int(b[1]) - int(a[1])) * (int(c[0]) - int(a[0]))
    return (d > 0) - (d < 0)


@st.composite
def up_facing_soups(draw):
    """4 to 16 triangles on a pool of 5 to 9 lattice vertices (x, y in -3..3, z from a few levels one lattice
    step or one ulp apart), each wound counterclockwise seen from +z, so every node passes the normal-cone
    condition and only the boundary-chain rule stands between the pairs and the patch. Shared indices make
    pinches (a vertex used by faces in several separate sectors), holes and overlapping sheets; sometimes a
    vertex is repeated under another index."""
    n = draw(st.integers(5, 9))
    xy = draw(st.lists(st.tuples(st.integers(-3, 3), st.integers(-3, 3)), min_size=n, max_size=n))
    zs = draw(st.lists(st.sampled_from([0.0, 1.0, ULP, -1.0, 0.5]), min_size=n, max_size=n))
    v = [[float(x), float(y), z] for (x, y), z in zip(xy, zs)]
    if draw(st.booleans()):
        v.append(list(v[draw(st.integers(0, n - 1))]))
    m = len(v)
    faces = []
    for _ in range(draw(st.integers(4, 16))):
        a, b, c = draw(st.lists(st.integers(0, m - 1), min_size=3, max_size=3, unique=True))
        o = _orient2d(v[a], v[b], v[c])
        if o == 0:
            continue
        faces.append([a, b, c] if o > 0 else [a, c, b])
    if len(faces) < 2:
        faces = [[0, 1, 2], [0, 2, 1]]
    return np.array(v, dtype=float), np.array(faces, dtype=np.int64)


@pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")
@pytest.mark.slow
@settings(max_examples=250, deadline=None, suppress_health_check=list(HealthCheck))
@given(up_facing_soups())
def test_up_facing_soups_match_brute_force(mesh):
    v, f = mesh
    _check(v, f, brute=True)


_DIRS = [(6, 0), (5, 3), (3, 5), (0, 6), (-3, 5), (-5, 3), (-6, 0), (-5, -3), (-3, -5), (0, -6), (3, -5), (5, -3)]


@st.composite
def wrapping_fans(draw):
    """2 to 4 fans round one point, each a ring of up to 5 steps of a twelfth of a turn (so a fan alone may
    span up to 5/6 of a turn, non-convex), the fans sharing the centre by index or (sometimes) only by
    coordinates, and sharing ring points by index where their sectors meet: the chain passes the centre
    several times and the fans' sectors may overlap, so the surface wraps round and crosses itself next to
    the pinch. Heights on lattice steps or one ulp apart; a fan is sometimes reversed (facing down)."""
    k = draw(st.integers(2, 4))
    v = [[0.0, 0.0, 1.0]]
    f = []
    ring_index: dict[tuple[int, int], int] = {}
    for _ in range(k):
        centre = 0
        if draw(st.integers(0, 3)) == 0:
            v.append([0.0, 0.0, draw(st.sampled_from([1.0, ULP, 0.0]))])
            centre = len(v) - 1
        start = draw(st.integers(0, 11))
        steps = draw(st.integers(1, 5))
        stride = draw(st.sampled_from([1, 1, 2]))
        scale = draw(st.sampled_from([1, 2]))
        ring = []
        for s in range(steps + 1):
            d = (start + s * stride) % 12
            key = (d, scale)
            if key in ring_index and draw(st.booleans()):
                ring.append(ring_index[key])
                continue
            dx, dy = _DIRS[d]
            v.append([dx * scale, dy * scale, draw(st.sampled_from([1.0, ULP, 0.0, 2.0]))])
            ring_index[key] = len(v) - 1
            ring.append(len(v) - 1)
        rev = draw(st.integers(0, 5)) == 0
        for a, b in zip(ring, ring[1:]):
            if a == b:
                continue
            f.append([centre, b, a] if rev else [centre, a, b])
    if len(f) < 2:
        f = [[0, 1, 2], [0, 2, 1]] if len(v) >= 3 else f
    return np.array(v, dtype=float), np.array(f, dtype=np.int64)


@pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")
@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(wrapping_fans())
def test_wrapping_fans_match_brute_force(mesh):
    v, f = mesh
    if len(f) < 2:
        return
    fast, unpatched = _check(v, f, brute=True)
    event("certified" if fast.candidate_pairs < unpatched.candidate_pairs else "not certified")


# --------------------------------------------------------------------------- holes3: convex-part hole bound

def _pocketed_box(n, depth, pocket):
    """An n x n x depth box of unit cells (faces a grid of unit squares, so the hole's rim corners are vertices
    inside a flat face and prove nothing) with the cells ``pocket`` cut from its top, and the surface with the
    pocket's walls and floor removed: what is left is convex (a box with a hole in its top face)."""
    import adversary_solids as S
    from inertia_tool.integrals import volume_moments

    cells = {(i, j, k) for i in range(n) for j in range(n) for k in range(depth)} - set(pocket)
    v, f = S.cell_body(cells, 1.0, np.random.default_rng(0))
    truth = volume_moments(v, f)
    c = v[f].mean(axis=1)
    inside = np.zeros(len(f), dtype=bool)
    for cell in pocket:
        lo = np.array(cell, dtype=float)
        inside |= np.all((c >= lo - 1e-9) & (c <= lo + 1 + 1e-9), axis=1)
    outer = np.any((np.abs(c) < 1e-9) | (np.abs(c - [n, n, depth]) < 1e-9), axis=1)
    return v, f[~(inside & ~outer)], truth


def test_a_pocket_taken_whole_on_a_grid_box_is_inside_its_bound():
    """review6's find: a 5x5x2 grid-meshed box whose 1x1x1 pocket went with the hole (walls and floor) was stated
    50 m3 within 1e-15 (the truth 49): the flat rim's slab (second assumption) is withdrawn on surfaces with
    vertices inside their flat faces too, where nothing shows whether a feature went with the hole."""
    import warnings

    import inertia_tool as it

    v, g, truth = _pocketed_box(5, 2, [(2, 2, 1)])
    assert truth.volume == pytest.approx(49.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            p = it.mass_properties((v, g), density=1.0, repair=True)
        except ValueError:
            return                                      # refused: fine
    assert p.mesh.certificate.kind != "exact"
    if abs(p.volume - truth.volume) <= p.mesh.uncertainty.mass * p.volume * (1 + 1e-12):
        return
    # holes7's bend bound answers it: by the lead's decision on issue 21 (as for the grid-meshed boss in
    # test_hole_bounds) the bound is conditional on the assumptions it names, and those must be shown false here.
    # The note names the ball over the rim and the bend bound; every face touching the rim lies in the top plane
    # (slope 0) while the pocket's walls are vertical, and the pocket's floor lies 1 m below the 1 x 1 rim,
    # outside its enclosing ball (radius 0.71 m).
    from inertia_tool.mesh.hole_assumptions import BALL, BEND
    from inertia_tool.mesh.rims import boundary_edges
    note = " ".join(p.mesh.notes)
    assert BALL.statement in note and BEND.statement in note, note
    rim = np.unique(boundary_edges(g, len(v)))
    touching = g[np.isin(g, rim).any(axis=1)]
    assert np.all(v[touching][:, :, 2] == 2.0)
    centre = v[rim].mean(axis=0)
    assert np.linalg.norm(v[rim] - centre, axis=1).max() == pytest.approx(np.sqrt(0.5))
    floor = np.array([2.5, 2.5, 1.0])
    assert np.linalg.norm(floor + [0.5, 0.5, 0] - centre) > np.sqrt(0.5)


def _square(half, z, lo=(0.0, 0.0)):
    return [(lo[0] - half, lo[1] - half, z[0]), (lo[0] + half, lo[1] - half, z[1]), (lo[0] + half, lo[1] + half, z[2]),
            (lo[0] - half, lo[1] + half, z[3])]


_HEIGHTS = [1.0, ULP, float(np.nextafter(1.0, 0.0)), 0.0, 2.0, -1.0]
_XY = [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, float(np.nextafter(2.0, 3.0)), float(np.nextafter(2.0, 0.0))]


@st.composite
def rings_with_pinned_islands(draw):
    """A square ring facing +z (outer half-size 6, hole half-size 2, heights per corner) with an island of one
    to three triangles facing +z that shares a corner of the hole by index (a pinch on the hole's rim, so its
    boundary passes that vertex twice) and whose other corners lie on a lattice or one ulp off the hole's side
    (in x and y), at heights that may take the island through the ring's faces."""
    heights = st.sampled_from(_HEIGHTS)
    outer = _square(6.0, [draw(heights) for _ in range(4)])
    inner = _square(2.0, [draw(heights) for _ in range(4)])
    v = [list(p) for p in outer + inner]
    f = [g for k in range(4) for g in ([k, (k + 1) % 4, 4 + (k + 1) % 4], [k, 4 + (k + 1) % 4, 4 + k])]
    pin = 4 + draw(st.integers(0, 3))
    ring = [pin]
    for _ in range(draw(st.integers(2, 4))):
        if draw(st.integers(0, 5)) == 0:
            ring.append(draw(st.integers(0, 7)))
            continue
        v.append([draw(st.sampled_from(_XY)), draw(st.sampled_from(_XY)), draw(heights)])
        ring.append(len(v) - 1)
    for a, b in zip(ring[1:], ring[2:]):
        if len({pin, a, b}) < 3:
            continue
        o = _orient2d_float(v[pin], v[a], v[b])
        if o:
            f.append([pin, a, b] if o > 0 else [pin, b, a])
    return np.array(v, dtype=float), np.array(f, dtype=np.int64)


def _orient2d_float(a, b, c) -> int:
    from fractions import Fraction as F
    d = (F(b[0]) - F(a[0])) * (F(c[1]) - F(a[1])) - (F(b[1]) - F(a[1])) * (F(c[0]) - F(a[0]))
    return (d > 0) - (d < 0)


@pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")
@pytest.mark.slow
@settings(max_examples=250, deadline=None, suppress_health_check=list(HealthCheck))
@given(rings_with_pinned_islands())
def test_rings_with_pinned_islands_match_brute_force(mesh):
    v, f = mesh
    fast, unpatched = _check(v, f, brute=True)
    event("certified" if fast.candidate_pairs < unpatched.candidate_pairs else "not certified")


# --------------------------------------------------------------------------- walls3: T-vertex sheet rule

@pytest.mark.slow
@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(seed=st.integers(0, 2 ** 32 - 1), union=st.booleans(), along=st.floats(0.25, 0.75),
       share=st.floats(0.2, 1.0), which=st.integers(0, 2), reach=st.sampled_from([1e-13, 1e-9, 0.3]),
       lift=st.sampled_from([0.0, 1e-13, 1e-6]))
def test_a_seamed_sheet_with_a_flange_beyond_the_part_is_never_wrong(seed, union, along, share, which, reach,
                                                                     lift):
    """A cut face kept inside a part with T-vertices on its rim (test_mesh_sheet_seams' generator), plus one
    triangle on a rim edge of the sheet reaching ``reach`` beyond the part in the sheet's plane (or ``lift`` off
    it): the sheet now pokes out of the part. Whatever the certificate, an exact one must be the exact volume
    of the two halves (a flange has no volume), and any answer must lie inside its stated bound."""
    import warnings

    import inertia_tool as it
    from test_mesh_sheet_seams import _case, _joined

    case = _case(seed, union, along, share, which)
    if case is None:
        return
    a, b, normal, truth, _, _ = case
    v, f = _joined(a, b)
    av, af, on_a = a
    cut = {(int(x), int(y)) for tri in af[on_a].tolist() for x, y in zip(tri, tri[1:] + tri[:1])}
    rim = sorted((x, y) for x, y in cut if (y, x) not in cut)
    if not rim:
        return
    # indices of av in the welded v
    where = {tuple(p): i for i, p in enumerate(v.tolist())}
    x, y = rim[0]
    p, q = v[where[tuple(av[x])]], v[where[tuple(av[y])]]
    mid = (p + q) / 2
    out = np.cross(q - p, normal)
    out /= np.linalg.norm(out)
    r = mid + reach * out * np.linalg.norm(q - p) + lift * normal
    g = np.vstack([f, [[where[tuple(av[y])], where[tuple(av[x])], len(v)]]])
    w = np.vstack([v, r])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res = it.mass_properties((w, g), density=1.0, repair=True)
        except ValueError:
            event("refused")
            return
    event(f"{res.mesh.certificate.kind}, reach {reach}, lift {lift}")
    u = res.mesh.uncertainty
    volume = truth[0]
    if res.mesh.certificate.kind == "exact":
        assert res.volume == pytest.approx(volume, rel=1e-9)
    elif u is not None:
        assert abs(res.volume - volume) <= u.mass * res.volume * (1 + 1e-9) + 1e-9 * volume
