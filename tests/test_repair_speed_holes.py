"""The faster hole stages (issue 25, "no slow path") give the same answers, bit for bit, as the plain readings
they replace: every face read, ``np.add.at`` / ``np.minimum.at`` sums, one Python dict of rim keys.

The references below are the straightforward forms of the same definitions (the code before the change); the
fast forms read only the faces near the rims, or sort only the rims' edges.  Meshes: prisms with fan-triangulated
caps (a CAD tessellation: rim vertices left *bare*), grid-meshed boxes (vertices inside flat faces), spheres,
and random non-manifold soups on a small vertex pool (edges shared by three or more faces), with random faces
removed.  No timings here: they are in ``benchmarks/bench_repair.py`` and ``docs/performance.md``.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mesh import hole_fills, holes
from inertia_tool.mesh.edges import edge_keys
from inertia_tool.mesh.rims import boundary_edges, boundary_loops

COSINE = holes.FLAT_VERTEX_COSINE


# --------------------------------------------------------------------------------------------- references

def _reference_flatness(v, f):
    """Per-vertex flatness with np.add.at and np.minimum.at (the unbuffered sums, in face order)."""
    n = len(v)
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    area = np.linalg.norm(normal, axis=1)
    good = area > 0
    g, unit = f[good], normal[good] / area[good, None]
    mean = np.zeros((n, 3))
    for k in range(3):
        np.add.at(mean, g[:, k], normal[good])
    size = np.linalg.norm(mean, axis=1)
    mean_unit = mean / np.where(size > 0, size, 1.0)[:, None]
    least = np.ones(n)
    for k in range(3):
        np.minimum.at(least, g[:, k], np.einsum("ij,ij->i", unit, mean_unit[g[:, k]]))
    return g, unit, least, size


def _reference_bare(v, f, edges, flat_cosine=COSINE):
    """bare_vertices reading every face of the surface."""
    n = len(v)
    g, unit, least, size = _reference_flatness(v, f)
    key, _ = edge_keys(g, n)
    order = np.argsort(key, kind="stable")
    same = key[order][1:] == key[order][:-1]
    first, second = order[:-1][same] // 3, order[1:][same] // 3
    coplanar = np.einsum("ij,ij->i", unit[first], unit[second]) >= flat_cosine
    in_flat_face = np.zeros(len(g), dtype=bool)
    in_flat_face[first[coplanar]] = True
    in_flat_face[second[coplanar]] = True
    on_flat_face = np.zeros(n, dtype=bool)
    for k in range(3):
        on_flat_face[g[in_flat_face, k]] = True
    flat = (least >= flat_cosine) & (size > 0) & on_flat_face
    on_rim = np.zeros(n, dtype=bool)
    on_rim[np.asarray(edges, dtype=np.int64).reshape(-1)] = True
    off = flat & ~on_rim
    near_flat = np.zeros(n, dtype=bool)
    for k in range(3):
        for j in range(3):
            if j != k:
                near_flat[f[off[f[:, j]], k]] = True
    return flat & on_rim & ~near_flat


def _reference_rings(f, n, edges, label, candidates):
    """The ring faces of each candidate loop through one dict of rim keys (the last rim edge of a key wins)."""
    nv = np.int64(max(n, 1))
    rim_key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * nv + np.maximum(edges[:, 0], edges[:, 1])
    key, _ = edge_keys(f, n)
    hit = np.isin(key, rim_key[np.isin(label, candidates)])
    face_loop: dict[int, set[int]] = {}
    rim_lookup = dict(zip(rim_key.tolist(), label.tolist()))
    for slot in np.flatnonzero(hit).tolist():
        face_loop.setdefault(rim_lookup[int(key[slot])], set()).add(slot // 3)
    return {k: np.array(sorted(faces), dtype=np.int64) for k, faces in face_loop.items()}, rim_key


# ------------------------------------------------------------------------------------------------- meshes

def _prism(sides, height=1.0, radius=1.0, twist=0.0):
    """A prism over a regular polygon, its caps fanned from their first corner (no vertex inside a flat face),
    outward."""
    angle = 2 * np.pi * np.arange(sides) / sides + twist
    ring = np.stack([radius * np.cos(angle), radius * np.sin(angle), np.zeros(sides)], axis=1)
    v = np.vstack([ring, ring + [0.0, 0.0, height]])
    bottom = [[0, k + 1, k] for k in range(1, sides - 1)]
    top = [[sides, sides + k, sides + k + 1] for k in range(1, sides - 1)]
    side = []
    for k in range(sides):
        a, b = k, (k + 1) % sides
        side += [[a, b, sides + b], [a, sides + b, sides + a]]
    return v, np.array(bottom + top + side, dtype=np.int64)


def _grid_box(cells):
    """An axis-aligned box with every face a grid of ``cells`` x ``cells`` squares (vertices inside its flat
    faces), outward, welded."""
    import trimesh

    box = trimesh.creation.box(extents=(1.0, 1.5, 0.7))
    for _ in range(cells):
        box = box.subdivide()
    return np.asarray(box.vertices, dtype=np.float64), np.asarray(box.faces, dtype=np.int64)


def _sphere(level):
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=level)
    return np.asarray(s.vertices, dtype=np.float64), np.asarray(s.faces, dtype=np.int64)


def _soup(rng, n_vertices, n_faces):
    """Random faces on a small pool of vertices, some of them coplanar (edges shared by 3+ faces)."""
    v = rng.integers(-2, 3, size=(n_vertices, 3)).astype(np.float64)
    v[: n_vertices // 2, 2] = 0.0                          # half the pool in one plane: flat fans
    f = np.array([rng.choice(n_vertices, 3, replace=False) for _ in range(n_faces)], dtype=np.int64)
    return v, f


def _damaged(v, f, rng, share):
    keep = rng.random(len(f)) >= share
    keep[rng.integers(len(f))] = True
    return f[keep]


def _check_same(v, f):
    edges = boundary_edges(f, len(v))
    got = holes.bare_vertices(v, f, edges)
    want = _reference_bare(v, f, edges)
    assert got.dtype == want.dtype and got.shape == want.shape
    np.testing.assert_array_equal(got, want)
    g, unit, least, size = holes._vertex_flatness(v, f)
    rg, runit, rleast, rsize = _reference_flatness(v, f)
    for a, b in ((g, rg), (unit, runit), (least, rleast), (size, rsize)):
        assert a.tobytes() == b.tobytes()
    return want


# -------------------------------------------------------------------------------------------------- tests

def test_bare_rim_vertex_of_a_fanned_prism_is_found_reading_only_the_faces_near_the_rim():
    """The side faces at one top corner of a hexagonal prism gone: that corner keeps only top faces (a flat face
    of the part, fanned), so it is bare; the reference and the local reading agree on every vertex."""
    v, f = _prism(6)
    top0 = 6
    keep = ~np.any(f[:, None, :] == top0, axis=(1, 2)) | (np.ptp(v[f, 2], axis=1) == 0)
    bare = _check_same(v, f[keep])
    assert bare[top0]
    assert bare.sum() >= 1


@settings(max_examples=60, deadline=None)
@given(sides=st.integers(3, 12), seed=st.integers(0, 2**32 - 1), share=st.floats(0.02, 0.6))
def test_bare_vertices_equal_the_whole_surface_reading_on_damaged_prisms(sides, seed, share):
    rng = np.random.default_rng(seed)
    v, f = _prism(sides, height=rng.uniform(0.2, 3.0), twist=rng.uniform(0, 1))
    _check_same(v, _damaged(v, f, rng, share))


@settings(max_examples=25, deadline=None)
@given(cells=st.integers(0, 2), seed=st.integers(0, 2**32 - 1), share=st.floats(0.005, 0.3))
def test_bare_vertices_equal_the_whole_surface_reading_on_damaged_grid_boxes(cells, seed, share):
    rng = np.random.default_rng(seed)
    v, f = _grid_box(cells)
    _check_same(v, _damaged(v, f, rng, share))


@settings(max_examples=40, deadline=None)
@given(pool=st.integers(4, 14), count=st.integers(1, 60), seed=st.integers(0, 2**32 - 1))
def test_bare_vertices_equal_the_whole_surface_reading_on_non_manifold_soups(pool, count, seed):
    rng = np.random.default_rng(seed)
    v, f = _soup(rng, pool, count)
    _check_same(v, f)


def test_bare_vertices_on_a_holed_sphere_and_on_a_closed_surface():
    rng = np.random.default_rng(5)
    v, f = _sphere(3)
    _check_same(v, _damaged(v, f, rng, 0.01))
    _check_same(v, f)                                     # no rim at all: nothing bare
    _check_same(v, f[:0])                                 # no face at all


def _crease_case(rng):
    """A grid box or a fanned prism with patches removed (holes across creases among them), its loops."""
    if rng.random() < 0.5:
        v, f = _grid_box(int(rng.integers(0, 2)))
    else:
        v, f = _prism(int(rng.integers(3, 9)), height=rng.uniform(0.3, 2.0))
    f = _damaged(v, f, rng, rng.uniform(0.02, 0.4))
    edges = boundary_edges(f, len(v))
    label, n_loops = boundary_loops(edges, len(v), f, v)
    return v, f, edges, label, n_loops


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), duplicate=st.booleans())
def test_ring_faces_equal_the_dict_reading(seed, duplicate):
    """``_ring_faces`` (sorting only edges on candidate rims) against one dict over every face edge, with the
    last rim edge of a key deciding its loop; ``duplicate`` lists some rim edges twice, in other loops."""
    rng = np.random.default_rng(seed)
    v, f, edges, label, n_loops = _crease_case(rng)
    if not n_loops:
        return
    if duplicate:                                        # the same key on two loops: the later one wins
        pick = rng.choice(len(edges), size=min(3, len(edges)), replace=False)
        edges = np.vstack([edges, edges[pick][:, ::-1]])
        label = np.r_[label, (label[pick] + 1) % n_loops]
    counts = np.bincount(label, minlength=n_loops)
    candidates = np.flatnonzero(counts >= int(rng.integers(1, 5))).tolist()
    if not candidates:
        return
    want, rim_key = _reference_rings(f, len(v), edges, label, candidates)
    pairs, start = holes._ring_faces(f, len(v), rim_key, label, candidates, n_loops)
    for k in range(n_loops):
        got = pairs[start[k]:start[k + 1], 1]
        expected = want.get(k, np.zeros(0, dtype=np.int64))
        assert got.dtype == expected.dtype
        np.testing.assert_array_equal(got, expected)


def _fills(v, faces):
    from inertia_tool.mesh.rims import enclosing_balls

    edges = boundary_edges(faces, len(v))
    label, n_loops = boundary_loops(edges, len(v), faces, v)
    pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
    ball_centre, radius = enclosing_balls(v[pairs[:, 1]], pairs[:, 0], n_loops)
    return holes.crease_fills(v, faces, edges, label, n_loops, ball_centre, radius,
                              bare=holes.bare_vertices(v, faces, edges))


def test_crease_fills_of_box_edge_holes_are_unchanged_by_a_far_hole():
    """Holes across one edge of a box whose faces are split in four (two triangles of different sides sharing
    an edge gone; those whose rim qualifies are filled in their two planes): a second hole far off (the
    triangle farthest away) changes neither the fill's caps and apexes nor its doubt nor its narrow bound
    (each loop reads only its own ring)."""
    import trimesh

    from conftest import box_arrays

    v0, f0 = box_arrays((1.0, 2.0, 3.0))
    mesh = trimesh.Trimesh(v0, f0, process=False).subdivide()
    v, f = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    centre = v[f].mean(axis=1)
    filled = 0
    for a in range(len(f)):
        for b in range(a + 1, len(f)):
            if len(set(f[a]) & set(f[b])) != 2 or float(normal[a] @ normal[b]) != 0.0:
                continue
            alone = _fills(v, np.delete(f, [a, b], axis=0))
            far = int(np.argmax(np.linalg.norm(centre - centre[a], axis=1)))
            both = _fills(v, np.delete(f, [a, b, far], axis=0))
            assert len(alone) == len(both) <= 1
            for one, two in zip(alone, both):
                filled += 1
                assert one.doubt == two.doubt and one.narrow == two.narrow
                np.testing.assert_array_equal(one.apexes, two.apexes)
                np.testing.assert_array_equal(one.caps, two.caps)
    assert filled == 4          # as before the change (the other pairs keep their cone)


def _all_fills(v, faces):
    from inertia_tool.mesh.rims import enclosing_balls

    edges = boundary_edges(faces, len(v))
    label, n_loops = boundary_loops(edges, len(v), faces, v)
    if not n_loops:
        return []
    pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
    ball_centre, radius = enclosing_balls(v[pairs[:, 1]], pairs[:, 0], n_loops)
    fills = holes.crease_fills(v, faces, edges, label, n_loops, ball_centre, radius,
                               bare=holes.bare_vertices(v, faces, edges))
    return [(x.loop, x.apexes.tobytes(), x.caps.tobytes(), x.doubt, x.narrow) for x in fills]


def _box_with_edge_holes(rng, turned):
    """A box whose faces are split in four (optionally turned at random), less random pairs of triangles
    sharing one of its edges and a few random triangles: holes across creases among plain ones."""
    import trimesh
    from scipy.spatial.transform import Rotation

    from conftest import box_arrays

    v0, f0 = box_arrays(tuple(rng.uniform(0.2, 3.0, size=3)))
    mesh = trimesh.Trimesh(v0, f0, process=False).subdivide()
    v, f = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    if turned:
        v = v @ Rotation.random(random_state=int(rng.integers(2**31))).as_matrix().T + rng.normal(size=3) * 10
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    pairs = [(a, b) for a in range(len(f)) for b in range(a + 1, len(f))
             if len(set(f[a]) & set(f[b])) == 2 and abs(float(normal[a] @ normal[b])) < 0.5]
    gone: set[int] = set()
    for i in rng.choice(len(pairs), size=int(rng.integers(1, 4)), replace=False):
        if not gone & set(pairs[i]):
            gone |= set(pairs[i])
    gone |= set(rng.choice(len(f), size=int(rng.integers(0, 3)), replace=False).tolist())
    return v, np.delete(f, sorted(gone), axis=0)


def _sphere_with_patches(rng):
    """An icosphere less a few patches of two to six triangles (loops of four edges or more on a curved
    surface: the screen's skips) and the box's kind of hole nowhere."""
    v, f = _sphere(2)
    centre = v[f].mean(axis=1)
    gone: list[int] = []
    for _ in range(int(rng.integers(1, 5))):
        seed_face = int(rng.integers(len(f)))
        near = np.argsort(np.linalg.norm(centre - centre[seed_face], axis=1), kind="stable")
        gone += near[: int(rng.integers(2, 7))].tolist()
    return v * rng.uniform(0.1, 10.0), np.delete(f, sorted(set(gone)), axis=0)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), turned=st.booleans(), sphere=st.booleans())
def test_crease_screen_keeps_every_fill(seed, turned, sphere):
    """The batch screen of ``crease_fills`` (``_may_hold_two_planes``) only skips loops the loop would skip:
    the fills with the screen and with every loop let through are the same, bit for bit, on boxes (turned at
    random, off the origin) with holes across their edges and on spheres with patches taken out."""
    rng = np.random.default_rng(seed)
    v, faces = _sphere_with_patches(rng) if sphere else _box_with_edge_holes(rng, turned)
    screened = _all_fills(v, faces)
    original = hole_fills._may_hold_two_planes
    try:
        hole_fills._may_hold_two_planes = lambda *a, **k: np.ones(a[4], dtype=bool)
        unscreened = _all_fills(v, faces)
    finally:
        hole_fills._may_hold_two_planes = original
    assert screened == unscreened


def test_crease_screen_is_exercised_and_lets_the_fills_through():
    """Non-vacuous: across these boxes the screen skips loops and some fills are made."""
    skipped = made = 0
    original = hole_fills._may_hold_two_planes

    def counting(*a, **k):
        nonlocal skipped
        got = original(*a, **k)
        skipped += int(np.count_nonzero(~got[np.asarray(a[5], dtype=np.int64)]))
        return got

    hole_fills._may_hold_two_planes = counting
    try:
        for seed in range(8):
            made += len(_all_fills(*_box_with_edge_holes(np.random.default_rng(seed), seed % 2 == 1)))
            _all_fills(*_sphere_with_patches(np.random.default_rng(seed)))
    finally:
        hole_fills._may_hold_two_planes = original
    assert skipped > 0 and made > 0
