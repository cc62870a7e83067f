"""Generated solids for the adversarial tests of the mesh-to-solid path, with truths from independent code.

Every case is a triangle mesh (``vertices`` float64 m, ``faces`` int64) built by composing closed pieces
(boxes, icospheres, cylinders, tori, the repository's ``meshes/*.stl``, swept tubes) under rigid motions, and
the *solid people mean* by it: the union of the bodies less their cavities, a shell's role (body or cavity)
given by its nesting depth, never by its winding; a surface that passes through itself means the set where
its winding number is at least one.  The truth of each case comes from code independent of the engine:

* ``fraction``: exact rational integrals (:class:`fractions.Fraction`) over the signed tetrahedra of the
  pieces of the intended solid, each wound outward, cavities subtracted: exact for the float64 input as given
  (interiors disjoint by construction);
* ``manifold``: the intended solid built as manifold3d ``Manifold`` objects from float64 ``Mesh64`` pieces and
  combined by booleans (union of bodies, difference of cavities), then integrated in float64 about a point
  near the solid;
* ``montecarlo`` (a cross-check, :func:`monte_carlo`): uniform points in the bounding box, inside where
  libigl's generalized winding number is at least 0.5, with a standard error for each quantity.

:func:`make_case` draws one case of a named composition kind from a :class:`numpy.random.Generator`; the
hypothesis strategy :func:`cases` and ``benchmarks/bench_adversarial.py`` both use it, so a failure anywhere
is reproduced by ``make_case(kind, np.random.default_rng(seed))``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from solids import icosahedron

MESH_DIR = Path(__file__).resolve().parent.parent / "meshes"

#: Composition kinds, in the order of the benchmark table.
KINDS = ("single", "disjoint", "shared_vertex_overlap", "shared_vertex_touch", "touching_faces",
         "overlapping", "nested", "internal_wall", "sliver", "figure_eight", "inside_out", "duplicated",
         "coplanar_overlap", "edge_touch", "flush_cavity", "shared_edge_crossing", "welded_l_shapes")

#: Largest mesh integrated with rational arithmetic (faces); larger truths are float64 about a nearby point.
FRACTION_MAX_FACES = 600


# --------------------------------------------------------------------------------------------------- pieces
def box(extents=(1.0, 1.0, 1.0), center=(0.0, 0.0, 0.0), subdivide=0):
    """Axis-aligned box, outward; ``subdivide`` times every triangle split into four (a different triangulation
    of the same faces)."""
    e = np.asarray(extents, dtype=np.float64) / 2
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64) * e
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.int64)
    for _ in range(subdivide):
        v, f = _subdivide(v, f)
    return v + np.asarray(center, dtype=np.float64), f


def _subdivide(v, f):
    """Split each triangle into four at the edge midpoints (midpoints shared between neighbours)."""
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    uniq, inv = np.unique(edges, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    mid = (v[uniq[:, 0]] + v[uniq[:, 1]]) / 2
    n, m = len(v), len(f)
    a, b, c = f[:, 0], f[:, 1], f[:, 2]
    ab, bc, ca = inv[:m] + n, inv[m:2 * m] + n, inv[2 * m:] + n
    nf = np.concatenate([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                         np.stack([ab, bc, ca], 1)])
    return np.vstack([v, mid]), nf


def icosphere(radius=1.0, subdivisions=1):
    """Icosphere (vertices pushed to the sphere after each split), outward."""
    v, f = icosahedron()
    for _ in range(subdivisions):
        v, f = _subdivide(v, f)
        v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v * radius, f


def cylinder(radius=0.5, height=1.0, sections=16):
    """Prism over a regular polygon, axis z, centred, outward."""
    k = np.arange(sections)
    ang = 2 * np.pi * k / sections
    ring = np.stack([radius * np.cos(ang), radius * np.sin(ang)], 1)
    v = np.vstack([np.c_[ring, np.full(sections, -height / 2)], np.c_[ring, np.full(sections, height / 2)],
                   [[0, 0, -height / 2], [0, 0, height / 2]]])
    nxt = (k + 1) % sections
    bot, top = 2 * sections, 2 * sections + 1
    f = np.concatenate([np.stack([k, nxt, nxt + sections], 1), np.stack([k, nxt + sections, k + sections], 1),
                        np.stack([np.full(sections, bot), nxt, k], 1),
                        np.stack([np.full(sections, top), k + sections, nxt + sections], 1)])
    return v, f.astype(np.int64)


def torus(major=1.0, minor=0.3, major_sections=16, minor_sections=8):
    """Torus about z, outward."""
    i, j = np.meshgrid(np.arange(major_sections), np.arange(minor_sections), indexing="ij")
    u = 2 * np.pi * i / major_sections
    w = 2 * np.pi * j / minor_sections
    r = major + minor * np.cos(w)
    v = np.stack([r * np.cos(u), r * np.sin(u), minor * np.sin(w)], -1).reshape(-1, 3)
    idx = lambda a, b: (a % major_sections) * minor_sections + b % minor_sections
    a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, f.astype(np.int64)


_PART_CACHE: dict[str, tuple[np.ndarray, np.ndarray]] = {}

#: Repository parts small enough to compose quickly (faces).
PARTS = ("box.stl", "octahedron.stl", "t_handle.stl", "cone.stl", "spinning_top.stl", "washer.stl")


def part(name):
    """A repository part, welded (by trimesh), scaled to a unit bounding-box diagonal and centred."""
    if name not in _PART_CACHE:
        import trimesh
        m = trimesh.load(MESH_DIR / name, force="mesh")
        v = np.asarray(m.vertices, dtype=np.float64)
        v = (v - (v.min(0) + v.max(0)) / 2) / np.linalg.norm(v.max(0) - v.min(0))
        f = np.asarray(m.faces, dtype=np.int64)
        if _signed_volume(v, f) < 0:
            f = f[:, ::-1]
        _PART_CACHE[name] = (v, f)
    v, f = _PART_CACHE[name]
    return v.copy(), f.copy()


def tube_slabs(height, radius=0.25, rings=48, sections=8, scale=1.0):
    """A tube swept along a figure-eight (lemniscate of Gerono lifted by ``height·cos t``): the tube's surface and
    the closed slabs between consecutive rings (each a prism with polygon caps).

    At t = 0 and t = π the centre line passes (0, 0, ±height): the tube crosses itself when
    ``2·height < 2·radius``.  The union of the slabs is the set where the tube's winding number is ≥ 1.
    """
    t = 2 * np.pi * np.arange(rings) / rings
    c = np.stack([np.sin(t), np.sin(t) * np.cos(t), height * np.cos(t)], 1) * scale
    dc = np.stack([np.cos(t), np.cos(2 * t), -height * np.sin(t)], 1)
    tang = dc / np.linalg.norm(dc, axis=1, keepdims=True)
    nrm = np.cross(tang, [0.0, 0.0, 1.0])
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    bin_ = np.cross(tang, nrm)
    ang = 2 * np.pi * np.arange(sections) / sections
    ringpts = (c[:, None] + radius * scale * (np.cos(ang)[None, :, None] * nrm[:, None]
                                              + np.sin(ang)[None, :, None] * bin_[:, None]))
    v = ringpts.reshape(-1, 3)
    k = np.arange(sections)
    faces = []
    for i in range(rings):
        a, b = i * sections, ((i + 1) % rings) * sections
        faces += [np.stack([a + k, b + (k + 1) % sections, a + (k + 1) % sections], 1),
                  np.stack([a + k, b + k, b + (k + 1) % sections], 1)]
    f = np.concatenate(faces).astype(np.int64)
    if _signed_volume(v, f) < 0:
        f = f[:, ::-1]
        sign = -1
    else:
        sign = 1
    slabs = []
    for i in range(rings):
        r0, r1 = ringpts[i], ringpts[(i + 1) % rings]
        sv = np.vstack([r0, r1])
        side = [np.stack([k, sections + (k + 1) % sections, (k + 1) % sections], 1),
                np.stack([k, sections + k, sections + (k + 1) % sections], 1)]
        fan = np.arange(1, sections - 1)
        caps = [np.stack([np.zeros_like(fan), fan, fan + 1], 1), np.stack([np.full_like(fan, sections),
                                                                            sections + fan + 1, sections + fan], 1)]
        sf = np.concatenate(side + caps).astype(np.int64)
        if sign < 0:
            sf = sf[:, ::-1]
        if _signed_volume(sv, sf) < 0:
            sf = sf[:, ::-1]
        slabs.append((sv, sf))
    return v, f, slabs


def tube_halves(height, radius=0.25, rings=48, sections=8):
    """The figure-eight tube of :func:`tube_slabs` and its two closed halves: the branch through t = 0 and the
    branch through t = π, each a tube from the ring nearest t = −π/2 (resp. π/2) to the ring nearest π/2
    (resp. 3π/2) with polygon caps.  Each half passes clear of itself; only the two halves can overlap, near
    the origin."""
    v, f, slabs = tube_slabs(height, radius, rings, sections)
    qa, qb = int(round(rings / 4)), int(round(3 * rings / 4))
    halves = []
    for start, stop in ((qb, qa + rings), (qa, qb)):
        idx = [i % rings for i in range(start, stop)]
        vs, fs, off = [], [], 0
        for i in idx:                       # each slab's side faces, vertices of its two rings
            sv, sf = slabs[i]
            side = sf[: 2 * sections]
            vs.append(sv)
            fs.append(side + off)
            off += len(sv)
        hv, hf = _weld_exact(np.vstack(vs), np.concatenate(fs))
        first, last = slabs[idx[0]], slabs[idx[-1]]
        caps = []
        for (sv, sf), which in ((first, slice(2 * sections, 2 * sections + sections - 2)),
                                (last, slice(2 * sections + sections - 2, None))):
            cap = sf[which]
            # the cap's vertices are the slab's own: find them in the welded half
            lookup = {_t(p): k for k, p in enumerate(hv)}
            caps.append(np.array([[lookup[tuple(sv[c])] for c in tri] for tri in cap], dtype=np.int64))
        halves.append((hv, np.concatenate([hf] + caps)))
    return v, f, halves


def truth_of_tube(v, f, halves, reach=0.6):
    """Moments of {winding ≥ 1} of the figure-eight tube: the surface integral (which counts the halves'
    overlap twice) less the overlap, formed by manifold3d as (A ∩ box) ∩ (B ∩ box) with the box
    |x| ≤ ``reach`` around the crossing (its planes cut the tube transversally, away from the halves' caps)."""
    vol, cen, central = float_moments(v, f)
    lo, hi = v.min(0) - 1.0, v.max(0) + 1.0
    cut = to_manifold(box([2 * reach, hi[1] - lo[1], hi[2] - lo[2]], [0.0, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2]))
    a, b = (to_manifold(h) ^ cut for h in halves)
    overlap = (a ^ b).to_mesh64()
    ov = np.asarray(overlap.vert_properties, dtype=np.float64)[:, :3]
    of = np.asarray(overlap.tri_verts, dtype=np.int64)
    if len(of) == 0:
        return Truth(vol, cen, _inertia(central), "manifold")
    ovol, ocen, ocentral = float_moments(ov, of)
    total = vol - ovol
    c = (vol * cen - ovol * ocen) / total
    second = (central + vol * np.outer(cen - c, cen - c)) - (ocentral + ovol * np.outer(ocen - c, ocen - c))
    return Truth(total, c, _inertia(second), "manifold")


# ------------------------------------------------------------------------------------------------- motions
def random_rotation(rng):
    """A uniformly random proper rotation (from a normalised Gaussian quaternion)."""
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def right_angle_rotation(rng):
    """One of the 24 proper rotations by multiples of 90° (a signed permutation matrix, det +1): exact."""
    while True:
        m = np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], size=3)[:, None]
        if np.linalg.det(m) > 0:
            return m


def rigid_motion(rng, scale=1.0):
    """(R, t): a right-angle rotation with dyadic translation (coordinates stay exact) or a random one."""
    if rng.random() < 0.4:
        return right_angle_rotation(rng), rng.integers(-8, 9, size=3) * 0.125 * scale
    offset = rng.normal(size=3) * scale * (1000.0 if rng.random() < 0.1 else 2.0)
    return random_rotation(rng), offset


def moved(piece, rot, shift):
    v, f = piece
    return v @ rot.T + shift, f


# -------------------------------------------------------------------------------------------------- truths
@dataclass
class Truth:
    """Unit-density moments of the intended solid: volume m³, centroid (3,) m, inertia (3, 3) m⁵ about the
    centroid (tensor convention), and how they were found.  ``sigma_*`` are standard errors (Monte Carlo only)."""

    volume: float
    centroid: np.ndarray
    inertia: np.ndarray
    source: str
    sigma_volume: float = 0.0
    sigma_centroid: float = 0.0
    sigma_inertia: float = 0.0


def _signed_volume(v, f):
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    ref = v.mean(0)
    return float(np.einsum("ij,ij->i", p0 - ref, np.cross(p1 - ref, p2 - ref)).sum() / 6)


def _outward_exactly(v, f):
    """``f`` wound outward by the sign of its exact rational volume (a float64 sign is wrong for a tetrahedron
    thinner than its coordinates' rounding)."""
    return f if fraction_moments(v, f)[0] > 0 else f[:, ::-1].copy()


def fraction_moments(v, f):
    """Exact (volume, ∫x dV (3,), ∫x_i x_j dV (3, 3)) of a closed surface, as Fractions over signed
    tetrahedra with apex at the origin: det/6, det/24·(a+b+c), det/120·(Σ pᵢpⱼ + sᵢsⱼ), s = a+b+c."""
    cache: dict[int, list[Fraction]] = {}

    def pt(i):
        if i not in cache:
            cache[i] = [Fraction(float(x)) for x in v[i]]
        return cache[i]

    return fraction_sums((pt(int(i0)), pt(int(i1)), pt(int(i2))) for i0, i1, i2 in f)


def fraction_sums(triangles):
    """Exact (volume, ∫x dV (3,), ∫x_i x_j dV (3, 3)) of the signed tetrahedra ``(0, a, b, c)`` over
    ``triangles``, an iterable of three exact (Fraction) points each: det/6, det/24·(a+b+c),
    det/120·(Σ pᵢpⱼ + sᵢsⱼ), s = a+b+c ("Rigid Body Motion" §4.2, the divergence theorem over a closed
    surface).  The one exact integral of the test generators (:func:`fraction_moments`,
    ``review12_generators.rational_moments``)."""
    vol = Fraction(0)
    first = [Fraction(0)] * 3
    second = [[Fraction(0)] * 3 for _ in range(3)]
    for a, b, c in triangles:
        det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
               + a[2] * (b[0] * c[1] - b[1] * c[0]))
        if det == 0:
            continue
        s = [a[k] + b[k] + c[k] for k in range(3)]
        vol += det / 6
        for k in range(3):
            first[k] += det * s[k] / 24
        for r in range(3):
            for q in range(r, 3):
                second[r][q] += det * (a[r] * a[q] + b[r] * b[q] + c[r] * c[q] + s[r] * s[q]) / 120
    for r in range(3):
        for q in range(r):
            second[r][q] = second[q][r]
    return vol, first, second


def float_moments(v, f):
    """(volume, centroid, central second moment) in float64 about the vertex mean (same tetrahedra)."""
    ref = v.mean(0)
    p0, p1, p2 = v[f[:, 0]] - ref, v[f[:, 1]] - ref, v[f[:, 2]] - ref
    det = np.einsum("ij,ij->i", p0, np.cross(p1, p2))
    s = p0 + p1 + p2
    vol = det.sum() / 6
    first = (det[:, None] * s).sum(0) / 24
    sec = np.einsum("n,ni,nj->ij", det, p0, p0) + np.einsum("n,ni,nj->ij", det, p1, p1) \
        + np.einsum("n,ni,nj->ij", det, p2, p2) + np.einsum("n,ni,nj->ij", det, s, s)
    sec /= 120
    cen = first / vol
    central = sec - vol * np.outer(cen, cen)
    return vol, cen + ref, central


def _inertia(central):
    return np.trace(central) * np.eye(3) - central


def truth_from_pieces(pieces):
    """Truth of a solid given as disjoint signed pieces ``[(sign, (v, f)), ...]`` (each outward-wound; sign −1
    for a cavity): each piece of at most ``FRACTION_MAX_FACES`` faces integrated exactly in rationals, a larger
    one in float64 about its own vertex mean (well conditioned for the repository's parts), the sum formed in
    rationals (so a thin piece far from a large one keeps its exact moments)."""
    vol, first, second = Fraction(0), [Fraction(0)] * 3, [[Fraction(0)] * 3 for _ in range(3)]
    exact = True
    for sign, (v, f) in pieces:
        if len(f) <= FRACTION_MAX_FACES:
            pv, pf, ps = fraction_moments(v, f)
        else:
            exact = False
            fv, fc, fcen = float_moments(v, f)
            pv = Fraction(fv)
            pf = [pv * Fraction(x) for x in fc]
            ps = [[Fraction(fcen[r, q]) + pv * Fraction(fc[r]) * Fraction(fc[q]) for q in range(3)] for r in range(3)]
        if pv < 0:
            # a piece thinner than its coordinates' rounding can come out of the rigid motion wound inward, exactly:
            # by nesting depth (R4) it is still the piece it was meant to be, so its moments count turned
            pv, pf, ps = -pv, [-x for x in pf], [[-x for x in row] for row in ps]
        vol += sign * pv
        first = [first[k] + sign * pf[k] for k in range(3)]
        second = [[second[r][q] + sign * ps[r][q] for q in range(3)] for r in range(3)]
    cen = [first[k] / vol for k in range(3)]
    central = [[second[r][q] - vol * cen[r] * cen[q] for q in range(3)] for r in range(3)]
    c = np.array([[float(x) for x in row] for row in central])
    return Truth(float(vol), np.array([float(x) for x in cen]), _inertia(c), "fraction" if exact else "float")


def to_manifold(piece):
    import manifold3d as m3
    v, f = piece
    mesh = m3.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                     tri_verts=np.ascontiguousarray(f, dtype=np.uint64))
    man = m3.Manifold(mesh)
    if man.status() != m3.Error.NoError:
        raise ValueError(f"manifold3d refused a generated piece: {man.status()}")
    return man


def truth_from_manifold(bodies, cavities=()):
    """Truth of (∪ bodies) − (∪ cavities), formed by manifold3d in float64."""
    import manifold3d as m3
    solid = m3.Manifold.batch_boolean([to_manifold(b) for b in bodies], m3.OpType.Add) if len(bodies) > 1 \
        else to_manifold(bodies[0])
    if cavities:
        solid = solid - m3.Manifold.batch_boolean([to_manifold(c) for c in cavities], m3.OpType.Add)
    out = solid.to_mesh64()
    v = np.asarray(out.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(out.tri_verts, dtype=np.int64)
    vol, cen, central = float_moments(v, f)
    return Truth(vol, cen, _inertia(central), "manifold")


def monte_carlo(v, f, rng, n=200_000):
    """Moments of {winding number ≥ 1} by uniform sampling of the bounding box (libigl fast winding numbers),
    with standard errors (volume m³; centroid m, the largest coordinate's; inertia, Frobenius m⁵)."""
    import igl
    lo, hi = v.min(0), v.max(0)
    q = lo + rng.random((n, 3)) * (hi - lo)
    w = igl.fast_winding_number(np.ascontiguousarray(v), np.ascontiguousarray(f), q)
    inside = q[np.abs(w) >= 0.5]
    box_vol = float(np.prod(hi - lo))
    p = len(inside) / n
    vol = box_vol * p
    se_vol = box_vol * np.sqrt(p * (1 - p) / n)
    cen = inside.mean(0)
    se_cen = float(np.max(inside.std(0)) / np.sqrt(len(inside)))
    d = inside - cen
    r2 = np.einsum("ij,ij->i", d, d)
    per = r2[:, None, None] * np.eye(3) - d[:, :, None] * d[:, None, :]      # (k, 3, 3) per-sample inertia
    inertia = per.sum(0) * box_vol / n
    # each sample contributes box_vol/n · (inside · per): variance of the sum over all n samples
    allper = np.zeros((n, 3, 3))
    allper[np.abs(w) >= 0.5] = per
    se_in = float(np.linalg.norm(allper.std(0)) * box_vol / np.sqrt(n))
    return Truth(vol, cen, inertia, "montecarlo", se_vol, se_cen, se_in)


# ---------------------------------------------------------------------------------------------------- cases
@dataclass
class Case:
    """A generated mesh and the solid it means.  ``recipe`` says how it was built (for reproducers)."""

    kind: str
    vertices: np.ndarray
    faces: np.ndarray
    truth: Truth
    recipe: str
    check: Truth | None = field(default=None)   # a second, independent truth (Monte Carlo) when one was made
    #: other readings of the same mesh that the issue's rules also allow (an answer matching one is right)
    alternatives: list = field(default_factory=list)
    motion: tuple | None = None
    #: the truth of the same mesh with every face reversed, where the rules read it otherwise than ``truth``
    #: (a nest whose own winding stands one way round is evidently wrong the other way: R4, session 16)
    reversed_truth: Truth | None = None


def _t(values):
    """A tuple of plain floats, for recipes."""
    return tuple(float(x) for x in values)


def concat(*pieces):
    """Pieces as one mesh (vertex indices offset; nothing merged)."""
    vs, fs, off = [], [], 0
    for v, f in pieces:
        vs.append(v)
        fs.append(f + off)
        off += len(v)
    return np.vstack(vs), np.concatenate(fs)


def flipped(piece):
    v, f = piece
    return v, f[:, ::-1].copy()


def random_piece(rng, convex=False, small=False):
    """(name, (v, f)) a random primitive or part, outward, roughly unit size."""
    choices = ["box", "box_sub", "icosphere", "cylinder"] + ([] if convex else ["torus", "part"])
    kind = choices[rng.integers(len(choices))]
    if kind == "box":
        ext = rng.integers(2, 9, size=3) * 0.125
        return f"box{_t(ext)}", box(ext)
    if kind == "box_sub":
        ext = rng.integers(2, 9, size=3) * 0.125
        return f"box{_t(ext)}/sub1", box(ext, subdivide=1)
    if kind == "icosphere":
        r = float(rng.uniform(0.3, 0.7))
        sub = 0 if small else int(rng.integers(0, 2))
        return f"icosphere(r={r:.3g},sub={sub})", icosphere(r, sub)
    if kind == "cylinder":
        r, h = float(rng.uniform(0.2, 0.5)), float(rng.uniform(0.4, 1.0))
        n = int(rng.integers(5, 17))
        return f"cylinder(r={r:.3g},h={h:.3g},n={n})", cylinder(r, h, n)
    if kind == "torus":
        big = float(rng.uniform(0.4, 0.6))
        return f"torus(R={big:.3g})", torus(big, big * float(rng.uniform(0.2, 0.45)), 12, 6)
    name = PARTS[rng.integers(len(PARTS))]
    return f"part({name})", part(name)


def _motion_all(rng, v, scale=1.0):
    rot, shift = rigid_motion(rng, scale)
    return v @ rot.T + shift, rot, shift


def _finish(kind, rng, pieces_signed, mesh, recipe, union=None):
    """Move the whole assembly rigidly; the truth is computed on the moved pieces (so it is the truth of the
    float64 input as given)."""
    v, f = mesh
    rot, shift = rigid_motion(rng)
    v2 = v @ rot.T + shift
    motion = (rot, shift)
    if union is not None:
        bodies, cavities = union
        truth = truth_from_manifold([moved(b, rot, shift) for b in bodies],
                                    [moved(c, rot, shift) for c in cavities])
    else:
        truth = truth_from_pieces([(s, moved(p, rot, shift)) for s, p in pieces_signed])
    case = Case(kind, v2, f, truth, recipe + f"; whole mesh moved by R={np.round(rot, 3).tolist()}, "
                                               f"t={np.round(shift, 3).tolist()}")
    case.motion = motion
    return case


def make_case(kind, rng):
    """One case of composition ``kind`` drawn from ``rng``."""
    build = _BUILDERS[kind]
    return build(rng)


def _single(rng):
    name, p = random_piece(rng)
    p = moved(p, *rigid_motion(rng))
    return _finish("single", rng, [(1, p)], p, name)


def _disjoint(rng):
    k = int(rng.integers(2, 4))
    pieces, names = [], []
    cursor, last = 0.0, 0.0
    for _ in range(k):
        name, p = random_piece(rng)
        rot = random_rotation(rng) if rng.random() < 0.5 else right_angle_rotation(rng)
        centre = (p[0].min(0) + p[0].max(0)) / 2
        radius = float(np.linalg.norm(p[0] - centre, axis=1).max())     # a ball around the piece, any rotation
        cursor += last + radius + 0.05 * (pieces != [])
        p = moved((p[0] - centre, p[1]), rot, np.array([cursor, 0.0, 0.0]))
        last = radius
        pieces.append(p)
        names.append(name)
    return _finish("disjoint", rng, [(1, p) for p in pieces], concat(*pieces), " + ".join(names) + " side by side")


def _axis_rotation(axis, angle):
    axis = np.asarray(axis, dtype=np.float64)
    axis /= np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def _share(a, b, ia, ib):
    """Concatenate a and b with b's vertex ``ib`` replaced by a's vertex ``ia`` (same index)."""
    va, fa = a
    vb, fb = b
    keep = np.ones(len(vb), dtype=bool)
    keep[ib] = False
    remap = np.full(len(vb), -1, dtype=np.int64)
    remap[keep] = len(va) + np.arange(int(keep.sum()))
    remap[ib] = ia
    return np.vstack([va, vb[keep]]), np.concatenate([fa, remap[fb]])


def _shared_vertex_overlap(rng):
    name, a = random_piece(rng, convex=True, small=True)
    va = a[0]
    ia = int(rng.integers(len(va)))
    p = va[ia]
    diagonal = rng.random() < 0.5
    axis = (p - va.mean(0)) if diagonal else rng.normal(size=3)
    angle = float(rng.uniform(0.1, np.pi - 0.1))
    rot = _axis_rotation(axis, angle)
    b = ((va - p) @ rot.T + p, a[1].copy())
    b[0][ia] = p
    mesh = _share(a, b, ia, ia)
    return _finish("shared_vertex_overlap", rng, None, mesh,
                   f"{name} and a copy turned {angle:.3f} rad about "
                   f"{'its diagonal' if diagonal else 'a random axis'} through vertex {ia}, that vertex shared",
                   union=([a, b], []))


def _shared_vertex_touch(rng):
    name, a = random_piece(rng, convex=True, small=True)
    va, fa = a
    # a vertex that is extreme along a random direction (exposed): the point reflection through it touches there
    ia = int(np.argmax(va @ rng.normal(size=3)))
    p = va[ia]
    b = (2 * p - va, fa[:, ::-1].copy())
    b[0][ia] = p
    mesh = _share(a, b, ia, ia)
    return _finish("shared_vertex_touch", rng, [(1, a), (1, b)], mesh,
                   f"{name} and its point reflection through vertex {ia}, touching there only, vertex shared")


def _touching_faces(rng):
    if rng.random() < 0.3:     # two copies of a real part, side by side along x: touching where both reach
        name = PARTS[rng.integers(len(PARTS))]
        a = part(name)
        w = a[0][:, 0].max() - a[0][:, 0].min()
        b = (a[0] + [w, 0, 0], a[1].copy())
        return _finish("touching_faces", rng, [(1, a), (1, b)], concat(a, b),
                       f"two copies of {name} touching at x = max (width {w:.6g})")
    ea = rng.integers(2, 9, size=3) * 0.125
    eb = rng.integers(2, 9, size=3) * 0.125
    sa, sb = int(rng.integers(0, 2)), int(rng.integers(0, 2))
    # b sits on a's +x face, offset in y and z by dyadic amounts (partial contact, different triangulations)
    off = np.r_[(ea[0] + eb[0]) / 2, rng.integers(-3, 4, size=2) * 0.125]
    a = box(ea, subdivide=sa)
    b = box(eb, off, subdivide=sb)
    if rng.random() < 0.5:   # b's faces turned a quarter about x: the other diagonal on its contact face
        rot = _axis_rotation([1, 0, 0], np.pi / 2).round()
        b = ((b[0] - off) @ rot.T + off, b[1])
    return _finish("touching_faces", rng, [(1, a), (1, b)], concat(a, b),
                   f"box{_t(ea)}/sub{sa} and box{_t(eb)}/sub{sb} face to face at x={off[0]}, "
                   f"offset {off[1:].tolist()}")


def _overlapping(rng):
    k = int(rng.integers(2, 4))
    pieces, names = [], []
    for _ in range(k):
        name, p = random_piece(rng, small=True)
        p = moved(p, random_rotation(rng) if rng.random() < 0.5 else right_angle_rotation(rng),
                  rng.normal(size=3) * 0.25)
        pieces.append(p)
        names.append(name)
    case = _finish("overlapping", rng, None, concat(*pieces), " ∪ ".join(names) + " overlapping",
                   union=(pieces, []))
    # a piece wholly inside another is, by nesting depth (issue 21: "orient per shell by nesting depth"), a
    # cavity wound the wrong way, and by the winding number (≥ 1) a body: both readings are accepted
    inside = _contained(pieces)
    if inside.any():
        rot, shift = case.motion
        bodies = [moved(p, rot, shift) for p, k in zip(pieces, inside) if not k]
        cavities = [moved(p, rot, shift) for p, k in zip(pieces, inside) if k]
        case.alternatives = [truth_from_manifold(bodies, cavities)]
        case.recipe += f"; piece {int(np.flatnonzero(inside)[0])} lies wholly inside another (depth 1)"
    return case


def _contained(pieces):
    """(k,) bool: pieces every vertex of which is strictly inside another piece (libigl winding number > 0.5)."""
    import igl
    out = np.zeros(len(pieces), dtype=bool)
    for j, (vj, _) in enumerate(pieces):
        for i, (vi, fi) in enumerate(pieces):
            if i != j and np.all(igl.fast_winding_number(np.ascontiguousarray(vi), np.ascontiguousarray(fi),
                                                         np.ascontiguousarray(vj)) > 0.5):
                out[j] = True
    return out


def _inner_of(rng, outer_name, outer, scale):
    """A convex piece strictly inside ``outer`` (the box or sphere inscribed, shrunk by ``scale``)."""
    v = outer[0]
    c = (v.min(0) + v.max(0)) / 2
    inr = float(np.min(np.abs(v - c).max(0)))      # inscribed for boxes; safe upper bound shrunk below
    if outer_name.startswith("icosphere") or outer_name.startswith("cylinder"):
        inr *= 0.75                                # inscribed radius of a coarse icosphere / polygon prism
    inr *= scale
    if rng.random() < 0.5:
        e = inr * 2 / np.sqrt(3)
        return "box", box([e, e, e], c)
    return "icosphere", (icosphere(inr, 0)[0] + c, icosphere(inr, 0)[1])


def _nested(rng):
    choices = ["box", "icosphere", "cylinder"]
    oname = choices[rng.integers(3)]
    if oname == "box":
        outer = box(rng.integers(4, 9, size=3) * 0.125, subdivide=int(rng.integers(0, 2)))
    elif oname == "icosphere":
        outer = icosphere(float(rng.uniform(0.4, 0.7)), int(rng.integers(0, 2)))
    else:
        outer = cylinder(0.5, 0.8, int(rng.integers(8, 17)))
    iname, inner = _inner_of(rng, oname, outer, float(rng.uniform(0.3, 0.9)))
    levels = [(1, outer), (-1, inner)]
    names = [oname, iname]
    if rng.random() < 0.3:            # a body inside the cavity (depth 2)
        cname, core = _inner_of(rng, iname, inner, float(rng.uniform(0.3, 0.8)))
        levels.append((1, core))
        names.append(cname)
    wound = []
    mesh_pieces = []
    outwards = []
    for sign, p in levels:
        right = rng.random() < 0.5
        # right: wound as its depth says (outward for a body, inward for a cavity)
        outward = (sign > 0) == right
        mesh_pieces.append(p if outward else flipped(p))
        wound.append(f"{'outward' if outward else 'inward'}")
        outwards.append(outward)
    recipe = " ⊃ ".join(f"{n} ({w})" for n, w in zip(names, wound)) + " nested (depth 0 body, 1 cavity, 2 body)"
    case = _finish("nested", rng, nest_pieces(levels, outwards), concat(*mesh_pieces), recipe)
    rot, shift = case.motion
    case.reversed_truth = truth_from_pieces([(s, moved(p, rot, shift))
                                             for s, p in nest_pieces(levels, [not o for o in outwards])])
    return case


def nest_pieces(levels, outward):
    """The signed pieces of the solid the rules give a chain of strictly nested shells ``levels`` (``(sign by
    depth, piece)``, outermost first) wound ``outward`` (bools): where the file's winding is ≥ 0 in every region
    it stands and the solid is ``{w ≥ 1}`` (R4, session 16: each shell's coefficient ``[w_in ≥ 1] − [w_out ≥ 1]``,
    ``w_in`` the running sum of ±1 from the outside); otherwise the depth reading, the parity solid."""
    running, windings = 0, []
    for o in outward:
        running += 1 if o else -1
        windings.append(running)
    if min(windings) < 0:
        return list(levels)
    pieces, before = [], 0
    for (_, piece), w in zip(levels, windings):
        now = int(w >= 1)
        if now != before:
            pieces.append((now - before, piece))
        before = now
    return pieces


def _internal_wall(rng):
    ext = rng.integers(2, 9, size=3) * 0.125
    cut = int(rng.integers(1, int(ext[0] / 0.125)))   # x position of the wall, in eighths from the left face
    left = np.r_[cut * 0.125, ext[1:]]
    right = np.r_[ext[0] - cut * 0.125, ext[1:]]
    x0 = -ext[0] / 2
    a = box(left, [x0 + left[0] / 2, 0, 0])
    b = box(right, [x0 + left[0] + right[0] / 2, 0, 0])
    merge = rng.random() < 0.5
    if merge:       # the wall's vertices shared by index (as a CAD export that welds)
        va, fa = a
        vb, fb = b
        allv = np.vstack([va, vb])
        uniq, inv = np.unique(allv, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        mesh = (uniq, np.concatenate([inv[fa], inv[fb + len(va)]]))
    else:
        mesh = concat(a, b)
    return _finish("internal_wall", rng, [(1, a), (1, b)], mesh,
                   f"box{_t(ext)} split at x = {x0 + left[0]} into two boxes with a zero-thickness wall "
                   f"({'welded' if merge else 'separate vertices'})")


def _sliver(rng):
    name, body = random_piece(rng)
    v = body[0]
    hi = v.max(0)
    size = float(rng.uniform(0.05, 0.5))
    gap = float(rng.choice([0.0, 1e-3, 0.1]))
    # a flat quad beside the body along +x (both sides: 4 faces, no volume)
    quad = np.array([[0, 0, 0], [0, size, 0], [0, size, size], [0, 0, size]], dtype=np.float64)
    quad += [hi[0] + gap + 0.01, 0, 0]
    quad[:, 0] += rng.uniform(0, 1e-9, size=4) * (rng.random() < 0.3)   # sometimes not quite flat
    qf = np.array([[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]], dtype=np.int64)
    if rng.random() < 0.2:
        # a long thin tetrahedron 10 … 100 body sizes away: a real solid whose volume (1e-10 … 1e-6 of the body's)
        # may fall under a flatness threshold scaled by the diagonal³
        span = float(np.linalg.norm(hi - v.min(0)))
        length = span * 10 ** float(rng.uniform(1, 2))
        vb = abs(_signed_volume(*body))
        thick = 6 * vb * 10 ** float(rng.uniform(-10, -6)) / (length * length / 2)
        tet = np.array([[0, 0, 0], [0, length, 0], [0, 0, length], [thick, length / 3, length / 3]])
        tet += [hi[0] + length, 0, 0]
        tf = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]], dtype=np.int64)
        tf = _outward_exactly(tet, tf)
        return _finish("sliver", rng, [(1, body), (1, (tet, tf))], concat(body, (tet, tf)),
                       f"{name} with a long thin tetrahedron ({length:.3g} m, {thick:.3g} m thin) "
                       f"{length:.3g} m away")
    if rng.random() < 0.5:
        sliver = (quad, qf)
        return _finish("sliver", rng, [(1, body)], concat(body, sliver),
                       f"{name} with a 4-face flat sliver ({size:.3g} m, gap {gap:g}) beside it")
    # a 4-face tetrahedron flattened to a thickness of 1e-9 … 1e-5 of its size: a real, very thin solid
    thick = size * 10 ** float(rng.uniform(-9, -5))
    tet = np.array([[0, 0, 0], [0, size, 0], [0, 0, size], [thick, size / 3, size / 3]], dtype=np.float64)
    tet += [hi[0] + gap + 0.01, 0, 0]
    tf = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]], dtype=np.int64)
    tf = _outward_exactly(tet, tf)
    return _finish("sliver", rng, [(1, body), (1, (tet, tf))], concat(body, (tet, tf)),
                   f"{name} with a 4-face tetrahedron {thick:.3g} m thin ({size:.3g} m across, gap {gap:g}) beside it")


def fold_free_radius(height, margin=0.8):
    """``margin`` × the smallest radius of curvature of the lifted lemniscate of :func:`tube_slabs`: a thicker
    tube folds over itself on the inside of its tightest bends (consecutive rings cross, the winding number is 2
    in slivers there), which :func:`truth_of_tube` does not subtract (it removes only the halves' overlap near
    the crossing)."""
    t = np.linspace(0.0, 2 * np.pi, 20001)
    d1 = np.stack([np.cos(t), np.cos(2 * t), -height * np.sin(t)], 1)
    d2 = np.stack([-np.sin(t), -2 * np.sin(2 * t), -height * np.cos(t)], 1)
    curvature = np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3
    return margin / float(curvature.max())


def _figure_eight(rng, n_mc=0):
    height = float(rng.uniform(0.0, 0.4))
    radius = min(float(rng.uniform(0.1, 0.3)), fold_free_radius(height))     # no local folds: the truth holds
    v, f, halves = tube_halves(height, radius, rings=int(rng.integers(24, 49)), sections=int(rng.integers(5, 9)))
    local = truth_of_tube(v, f, halves)
    rot, shift = rigid_motion(rng)
    truth = Truth(local.volume, rot @ local.centroid + shift, rot @ local.inertia @ rot.T, local.source)
    case = Case("figure_eight", v @ rot.T + shift, f, truth,
                f"figure-eight tube, lift {height:.3f}, radius {radius:.3f} "
                f"({'crosses itself' if height < radius else 'passes clear'}); whole mesh moved by "
                f"R={np.round(rot, 3).tolist()}, t={np.round(shift, 3).tolist()}")
    if n_mc:
        case.check = monte_carlo(case.vertices, case.faces, rng, n_mc)
    return case


def _inside_out(rng):
    base = ("single", "disjoint", "nested", "overlapping", "touching_faces")[rng.integers(5)]
    case = _BUILDERS[base](rng)
    # the base's other allowed readings carry over (an overlapping piece wholly inside another: cavity by depth)
    truth = case.reversed_truth if case.reversed_truth is not None else case.truth
    return Case("inside_out", case.vertices, case.faces[:, ::-1].copy(), truth,
                f"[{base}] {case.recipe}; every face reversed", alternatives=case.alternatives)


def _duplicated(rng):
    base = ("single", "disjoint", "nested")[rng.integers(3)]
    case = _BUILDERS[base](rng)
    v, f = case.vertices, case.faces
    if base == "nested":
        # duplicate the whole nest: each shell's copy has the same depth role, the solid is unchanged
        pick = np.ones(len(f), dtype=bool)
    else:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
        e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        g = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(len(v), len(v)))
        _, lab = connected_components(g, directed=False)
        shell = lab[f[:, 0]]
        pick = shell == shell[rng.integers(len(f))]
    shared = rng.random() < 0.5
    apart = ""
    if shared:      # the copy uses the same vertex indices
        nf = np.concatenate([f, f[pick]])
        nv = v
    else:
        copy = v
        if rng.random() < 0.4:     # the copy's coordinates computed apart: (v + c) − c, equal up to rounding
            c = rng.normal(size=3) * float(np.abs(v).max() + 1.0)
            copy = (v + c) - c
            apart = f", coordinates rounded apart (up to {float(np.abs(copy - v).max()):.2g} m)"
        nv = np.vstack([v, copy])
        nf = np.concatenate([f, f[pick] + len(v)])
    what = "the whole nest" if base == "nested" else "one shell"
    return Case("duplicated", nv, nf, case.truth,
                f"[{base}] {case.recipe}; {what} duplicated ({'same' if shared else 'new'} vertex indices{apart})")


def _coplanar_overlap(rng):
    """Two boxes standing on the same plane z = 0 (their bottom faces coplanar, same orientation) whose
    interiors overlap: the union is one solid with one bottom."""
    ea = rng.integers(2, 9, size=3) * 0.125
    eb = rng.integers(2, 9, size=3) * 0.125
    off = np.r_[rng.integers(-3, 4, size=2) * 0.125, 0.0]
    a = box(ea, [0, 0, ea[2] / 2], subdivide=int(rng.integers(0, 2)))
    b = box(eb, off + [0, 0, eb[2] / 2], subdivide=int(rng.integers(0, 2)))
    lo = np.maximum(-ea / 2 + [0, 0, ea[2] / 2], off - eb / 2 + [0, 0, eb[2] / 2])
    hi = np.minimum(ea / 2 + [0, 0, ea[2] / 2], off + eb / 2 + [0, 0, eb[2] / 2])
    pieces = [(1, a), (1, b)]
    if np.all(hi > lo):           # inclusion–exclusion: the common box counted once
        pieces.append((-1, box(hi - lo, (lo + hi) / 2)))
    case = _finish("coplanar_overlap", rng, pieces, concat(a, b),
                   f"box{_t(ea)} and box{_t(eb)} both on z = 0, offset {off[:2].tolist()}")
    # one box wholly within the other (standing on its floor from inside): by nesting depth (R4 of mesh/policy.py,
    # one rule for a shell strictly inside another and one touching its boundary from inside) a cavity written
    # outward, by the winding number a body; as for `overlapping`, both readings are accepted
    box_a = (-ea / 2 + [0, 0, ea[2] / 2], ea / 2 + [0, 0, ea[2] / 2])
    box_b = (off - eb / 2 + [0, 0, eb[2] / 2], off + eb / 2 + [0, 0, eb[2] / 2])
    for (inner, ib), (outer, ob) in (((a, box_a), (b, box_b)), ((b, box_b), (a, box_a))):
        if np.all(ib[0] >= ob[0]) and np.all(ib[1] <= ob[1]) and not np.array_equal(ea, eb):
            rot, shift = case.motion
            case.alternatives = [truth_from_manifold([moved(outer, rot, shift)], [moved(inner, rot, shift)])]
            case.recipe += "; one box lies within the other (depth 1)"
            break
    return case


def _edge_touch(rng):
    """Two boxes meeting along (part of) an edge only, sharing the edge's vertices by index or not."""
    ea = rng.integers(2, 9, size=3) * 0.125
    a = box(ea)
    eb = np.r_[rng.integers(2, 9, size=2) * 0.125, ea[2]]
    b = box(eb, [(ea[0] + eb[0]) / 2, (ea[1] + eb[1]) / 2, 0.0])     # diagonal neighbour in xy: common z-edge
    if rng.random() < 0.5:
        mesh = _weld_exact(*concat(a, b))
        how = "edge vertices shared"
    else:
        mesh = concat(a, b)
        how = "separate vertices"
    return _finish("edge_touch", rng, [(1, a), (1, b)], mesh,
                   f"box{_t(ea)} and box{_t(eb)} meeting along a z edge ({how})")


def _flush_cavity(rng):
    """A box with a box-shaped cavity flush with one of its faces (the cavity's face lies in the outer face,
    opposite normals): the solid is the box with a notch open to the outside."""
    ea = rng.integers(4, 9, size=3) * 0.125
    ec = np.minimum(rng.integers(1, 4, size=3) * 0.125, ea - 0.25)
    c = np.r_[(ea[0] - ec[0]) / 2, 0.0, 0.0]          # the cavity's +x face in the box's +x face
    outer = box(ea, subdivide=int(rng.integers(0, 2)))
    if rng.random() < 0.3:
        # instead a cavity inside, with a box resting on its floor (face to face, opposite normals)
        ec = ea / 2
        cav = box(ec)
        ek = np.r_[ec[:2] / 2, ec[2] / 4]
        core = box(ek, [0, 0, -ec[2] / 2 + ek[2] / 2])
        mesh = concat(outer, flipped(cav), core)
        return _finish("flush_cavity", rng, [(1, outer), (-1, cav), (1, core)], mesh,
                       f"box{_t(ea)} with a cavity box{_t(ec)}, a box{_t(ek)} resting on its floor")
    cav = box(ec, c)
    if rng.random() < 0.8:
        return _finish("flush_cavity", rng, [(1, outer), (-1, cav)], concat(outer, flipped(cav)),
                       f"box{_t(ea)} with a cavity box{_t(ec)} flush with its +x face")
    # the inner box wound outward as well: winding 2 inside it, 1 in the rest of the box, so the solid
    # ({w >= 1}, the rule of docs/meshes.md) is the whole box, not the notched one
    return _finish("flush_cavity", rng, [(1, outer)], concat(outer, cav),
                   f"box{_t(ea)} with a box{_t(ec)} inside, flush with its +x face, both wound outward")


# ------------------------------------------------------------- bodies crossing exactly along shared edges
def _orient_convex(v, f):
    """``f`` of a convex solid wound outward, triangle by triangle (normal away from the vertex mean)."""
    centre = v.mean(0)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    out = np.einsum("ij,ij->i", np.cross(b - a, c - a), (a + b + c) / 3 - centre) > 0
    return np.where(out[:, None], f, f[:, ::-1])


def grid_box(grids, rng):
    """Closed outward box ``[x₀, x₋₁] × [y₀, y₋₁] × [z₀, z₋₁]`` of ``grids = (xs, ys, zs)`` whose faces are cut
    along every grid line (each cell two triangles, its diagonal drawn at random): another box cut along the
    same lines meets it only along edges of both."""
    g = [np.unique(np.asarray(x, dtype=np.float64)) for x in grids]
    index: dict = {}
    faces = []
    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        for c in (g[axis][0], g[axis][-1]):
            for i in range(len(g[u]) - 1):
                for j in range(len(g[w]) - 1):
                    ids = []
                    for du, dw in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis], p[u], p[w] = c, g[u][i + du], g[w][j + dw]
                        ids.append(index.setdefault(tuple(p), len(index)))
                    a, b, cc, d = ids
                    faces += [[a, b, cc], [a, cc, d]] if rng.random() < 0.5 else [[a, b, d], [b, cc, d]]
    v = np.array(sorted(index, key=index.get), dtype=np.float64)
    f = np.array(faces, dtype=np.int64)
    return v, _orient_convex(v, f)


def _ring_strip(inner, outer):
    """Triangles (``("i"|"o", index)`` corners into ``inner`` (n, 2) and ``outer`` (k, 2), both convex and
    counter-clockwise, the inner inside the outer around its centroid) filling the ring between them, the two
    rings merged by angle; None when a triangle is not clockwise or the areas do not add up (draw again)."""
    c = inner.mean(0)
    ai = np.arctan2(inner[:, 1] - c[1], inner[:, 0] - c[0]) % (2 * np.pi)
    ao = np.arctan2(outer[:, 1] - c[1], outer[:, 0] - c[0]) % (2 * np.pi)
    i0, o0 = int(np.argmin(ai)), int(np.argmin(ao))
    n, k = len(inner), len(outer)

    def after(angles, start, j, m):
        return angles[(start + j + 1) % m] if j + 1 < m else angles[start] + 2 * np.pi

    tris, i, o = [], 0, 0
    while i < n or o < k:                             # n + k triangles in all
        ci, co = ("i", (i0 + i) % n), ("o", (o0 + o) % k)
        if o >= k or (i < n and after(ai, i0, i, n) <= after(ao, o0, o, k)):
            tris.append((ci, ("i", (i0 + i + 1) % n), co))
            i += 1
        else:
            tris.append((ci, ("o", (o0 + o + 1) % k), co))
            o += 1
    pts = {"i": inner, "o": outer}

    def area2(t):
        p = [pts[s][j] for s, j in t]
        return (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0])

    def polygon2(q):
        return float(np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1]))

    areas = np.array([area2(t) for t in tris])
    if np.any(areas >= 0) or abs(-areas.sum() - (polygon2(outer) - polygon2(inner))) > 1e-12 * polygon2(outer):
        return None
    return tris


def prism_through_box(rng):
    """A box and a convex polygon prism along z through its top face (and its bottom one, or ending inside),
    the polygon drawn in the box's top (bottom) face triangulation and the prism's sides cut where they pass the
    box's faces: the surfaces cross only along edges of both.  Returns (box, prism, [(sign, piece)] of the union
    by inclusion–exclusion) or None when the ring could not be triangulated (draw again)."""
    half = rng.integers(2, 7, size=2) * 0.125
    zb, zt = -float(rng.integers(2, 7)) * 0.125, float(rng.integers(2, 7)) * 0.125
    n = int(rng.integers(3, 9))
    radius = float(rng.uniform(0.2, 0.9)) * float(half.min())
    centre = rng.uniform(-1, 1, size=2) * (half - radius) * 0.9
    ang = float(rng.uniform(0, 2 * np.pi)) + 2 * np.pi * np.sort(rng.uniform(0, 1, size=n)) \
        if rng.random() < 0.5 else float(rng.uniform(0, 2 * np.pi)) + 2 * np.pi * np.arange(n) / n
    poly = centre + radius * np.c_[np.cos(ang), np.sin(ang)]
    if n > 3 and np.any(np.diff(np.r_[ang, ang[0] + 2 * np.pi]) >= np.pi):
        return None                                   # not containing its centre: draw again
    square = np.array([[-half[0], -half[1]], [half[0], -half[1]], [half[0], half[1]], [-half[0], half[1]]])
    ring = _ring_strip(poly, square)
    if ring is None:
        return None
    through = rng.random() < 0.5
    z1 = zt + float(rng.integers(1, 5)) * 0.125
    z0 = zb - float(rng.integers(1, 5)) * 0.125 if through else float(rng.uniform(zb, zt) * 0.9)
    # the box: top (and, when the prism passes through, bottom) face with the polygon imprinted
    verts, faces = [], []

    def vid(p):
        verts.append(p)
        return len(verts) - 1

    for z, cut in ((zt, True), (zb, through)):
        sq = [vid([x, y, z]) for x, y in square]
        if not cut:
            faces += [[sq[0], sq[1], sq[2]], [sq[0], sq[2], sq[3]]]
            continue
        pl = [vid([x, y, z]) for x, y in poly]
        ids = {"i": pl, "o": sq}
        faces += [[ids[s][j] for s, j in t] for t in ring]
        faces += [[pl[0], pl[j], pl[j + 1]] for j in range(1, n - 1)]
    top, bot = {}, {}
    for k, p in enumerate(verts):
        (top if p[2] == zt else bot)[(p[0], p[1])] = k
    for j in range(4):                                # the four sides
        a, b = square[j], square[(j + 1) % 4]
        q = [bot[tuple(a)], bot[tuple(b)], top[tuple(b)], top[tuple(a)]]
        faces += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    bv = np.array(verts, dtype=np.float64)
    box_piece = (bv, _orient_convex(bv, np.array(faces, dtype=np.int64)))
    # the prism, its sides cut at every level it passes
    levels = sorted({z0, z1} | {z for z in (zb, zt) if z0 < z < z1})
    pv = np.array([[x, y, z] for z in levels for x, y in poly], dtype=np.float64)
    pf = []
    for li in range(len(levels) - 1):
        for j in range(n):
            a, b = li * n + j, li * n + (j + 1) % n
            c, d = b + n, a + n
            pf += [[a, b, c], [a, c, d]] if rng.random() < 0.5 else [[a, b, d], [b, c, d]]
    last = (len(levels) - 1) * n
    pf += [[0, j, j + 1] for j in range(1, n - 1)] + [[last, last + j, last + j + 1] for j in range(1, n - 1)]
    prism = (pv, _orient_convex(pv, np.array(pf, dtype=np.int64)))
    lo, hi = max(z0, zb), min(z1, zt)
    cv = np.array([[x, y, z] for z in (lo, hi) for x, y in poly], dtype=np.float64)
    cf = [[j, (j + 1) % n, n + (j + 1) % n] for j in range(n)] + [[j, n + (j + 1) % n, n + j] for j in range(n)]
    cf += [[0, j, j + 1] for j in range(1, n - 1)] + [[n, n + j, n + j + 1] for j in range(1, n - 1)]
    common = (cv, _orient_convex(cv, np.array(cf, dtype=np.int64)))
    recipe = (f"box{_t(2 * half)}×z[{zb}, {zt}] and a {n}-gon prism (r={radius:.3g}) z[{z0:.4g}, {z1:.4g}] "
              f"{'through it' if through else 'ending inside it'}, crossing along the polygon drawn in its face")
    return box_piece, prism, [(1, box_piece), (1, prism), (-1, common)], recipe


def boxes_on_shared_grid(rng, k):
    """``k`` boxes with corners on a half-unit grid, each cut along every coordinate of all of them within its
    range, each crossing another and none within another.  Returns (pieces, [(sign, box)] by inclusion–exclusion,
    recipe) or None (draw again)."""
    from itertools import combinations
    lo = rng.integers(0, 4, size=(k, 3)) * 0.5
    hi = lo + rng.integers(1, 5, size=(k, 3)) * 0.5
    generic = rng.random() < 0.6
    if generic:                                       # no two boxes share a plane: only edges cross edges
        shift = np.arange(k)[:, None] * 0.125
        lo, hi = lo + shift, hi + shift
    for a, b in combinations(range(k), 2):
        if np.all(lo[a] <= lo[b]) and np.all(hi[b] <= hi[a]) or np.all(lo[b] <= lo[a]) and np.all(hi[a] <= hi[b]):
            return None                               # one within the other (a cavity by depth): another kind
    for a in range(k):
        if not any(np.all(np.maximum(lo[a], lo[b]) < np.minimum(hi[a], hi[b])) for b in range(k) if b != a):
            return None                               # crossing none of the others
    coords = [np.unique(np.r_[lo[:, d], hi[:, d]]) for d in range(3)]
    pieces = [grid_box([c[(c >= lo[i, d]) & (c <= hi[i, d])] for d, c in enumerate(coords)], rng)
              for i in range(k)]
    signed = []
    for r in range(1, k + 1):
        for sub in combinations(range(k), r):
            low, h = lo[list(sub)].max(0), hi[list(sub)].min(0)
            if np.all(h > low):
                signed.append(((-1) ** (r + 1), box(h - low, (low + h) / 2)))
    recipe = (" and ".join(f"box[{_t(lo[i])}, {_t(hi[i])}]" for i in range(k))
              + " on a shared grid (each cut along all the others' planes), crossing along shared edges"
              + ("" if generic else " (some planes shared: coplanar faces overlap)"))
    return pieces, signed, recipe


def _shared_edge_crossing(rng):
    """Closed shells whose surfaces cross only along edges of both tessellations (no face pair crosses
    transversally: MuJoCo Menagerie's Go1 thigh): 2–3 boxes on a shared grid (L shapes, beams, corners), or a
    polygon prism through a box's face.  Truth: inclusion–exclusion in rationals."""
    for _ in range(100):                              # bounded redraws
        if rng.random() < 0.5:
            made = prism_through_box(rng)
            if made is None:
                continue
            a, b, signed, recipe = made
            pieces = [a, b]
        else:
            made = boxes_on_shared_grid(rng, int(rng.integers(2, 4)))
            if made is None:
                continue
            pieces, signed, recipe = made
        order = rng.permutation(len(pieces))
        mesh = concat(*[pieces[i] for i in order])
        if rng.random() < 0.5:    # as an STL reads: the crossing edges' vertices shared, each edge used by 4 faces
            mesh = _weld_exact(*mesh)
            recipe += "; vertices welded (non-manifold crossing edges)"
        return _finish("shared_edge_crossing", rng, signed, mesh, recipe)
    raise RuntimeError("no shared-edge crossing drawn in 100 tries")


def cell_body(cells, step, rng):
    """Closed outward surface of a union of grid cells ``cells`` (a set of integer ``(i, j, k)``; cells meeting
    only along an edge are not allowed): every cell face with no cell behind it, two triangles each, the
    diagonal drawn at random.  Two bodies of one grid meet only along grid edges of both."""
    index: dict = {}
    faces = []
    for cell in sorted(cells):
        for axis in range(3):
            for side in (0, 1):
                nb = list(cell)
                nb[axis] += 1 if side else -1
                if tuple(nb) in cells:
                    continue
                u, w = (axis + 1) % 3, (axis + 2) % 3
                ids = []
                for du, dw in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [0, 0, 0]
                    p[axis], p[u], p[w] = cell[axis] + side, cell[u] + du, cell[w] + dw
                    ids.append(index.setdefault(tuple(p), len(index)))
                a, b, c, d = ids if side else ids[::-1]         # counter-clockwise seen from outside
                faces += [[a, b, c], [a, c, d]] if rng.random() < 0.5 else [[a, b, d], [b, c, d]]
    v = np.array(sorted(index, key=index.get), dtype=np.float64) * step
    return v, np.array(faces, dtype=np.int64)


def _l_cells(arm_x, arm_y, width, height, turn, offset):
    """Cells of an L-shaped prism: arms of ``arm_x`` and ``arm_y`` cells, ``width`` thick, ``height`` tall
    from z = 0, turned by ``turn`` quarter turns about z, then moved by ``offset`` cells."""
    flat = {(i, j) for i in range(arm_x) for j in range(width)} | {(i, j) for i in range(width) for j in range(arm_y)}
    for _ in range(turn % 4):
        flat = {(-j, i) for i, j in flat}
    return {(i + offset[0], j + offset[1], k) for i, j in flat for k in range(height)}


def _welded_l_shapes(rng):
    """Two L-shaped prisms standing on one plane (their bottom faces coplanar and facing the same way), crossing
    each other, tessellated on one grid and welded bit-exactly: at the crossing edges on the shared plane four
    faces meet, two of them coplanar and facing the same way, so which faces close which body is undefined
    there (R1b).  Truth: the union's cells, each a box, integrated in rationals."""
    for _ in range(100):                              # bounded redraws
        step = 0.5
        a = _l_cells(*(int(x) for x in rng.integers(2, 5, size=2)), int(rng.integers(1, 3)),
                     int(rng.integers(1, 4)), 0, (0, 0))
        b = _l_cells(*(int(x) for x in rng.integers(2, 5, size=2)), int(rng.integers(1, 3)),
                     int(rng.integers(1, 4)), int(rng.integers(4)), tuple(int(x) for x in rng.integers(-2, 4, size=2)))
        if not (a & b) or a <= b or b <= a:
            continue                                  # apart, or one within the other: other kinds
        pieces = [cell_body(a, step, rng), cell_body(b, step, rng)]
        order = rng.permutation(2)
        mesh = _weld_exact(*concat(*[pieces[i] for i in order]))
        union = a | b
        signed = [(1, box((step, step, step), (np.asarray(c, dtype=np.float64) + 0.5) * step)) for c in sorted(union)]
        recipe = (f"two L-shaped prisms of {len(a)} and {len(b)} cells of {step} on one grid, both standing on "
                  f"z = 0 (coplanar bottoms facing the same way), crossing ({len(a & b)} cells shared); vertices "
                  "welded (non-manifold crossing edges)")
        return _finish("welded_l_shapes", rng, signed, mesh, recipe)
    raise RuntimeError("no crossing L shapes drawn in 100 tries")


def _weld_exact(v, f):
    """Merge bit-identical vertices."""
    uniq, inv = np.unique(v, axis=0, return_inverse=True)
    return uniq, inv.reshape(-1)[f]


_BUILDERS = {
    "single": _single, "disjoint": _disjoint, "shared_vertex_overlap": _shared_vertex_overlap,
    "shared_vertex_touch": _shared_vertex_touch, "touching_faces": _touching_faces, "overlapping": _overlapping,
    "nested": _nested, "internal_wall": _internal_wall, "sliver": _sliver, "figure_eight": _figure_eight,
    "inside_out": _inside_out, "duplicated": _duplicated, "coplanar_overlap": _coplanar_overlap,
    "edge_touch": _edge_touch, "flush_cavity": _flush_cavity, "shared_edge_crossing": _shared_edge_crossing,
    "welded_l_shapes": _welded_l_shapes,
}


# ------------------------------------------------------------------------------------------------ the rule
#: Tolerances of a proven answer (exact or united): volume relative, centre of mass relative to the diagonal,
#: inertia relative (Frobenius).
VOLUME_RTOL, COM_RTOL, INERTIA_RTOL = 1e-9, 1e-9, 1e-8

#: Monte Carlo truths: a difference beyond this many standard errors (plus the tolerances above) is wrong.
MC_SIGMAS = 5.0


@dataclass
class Verdict:
    """The outcome of one case: ``label`` exact | united | estimate | summed | unverified | refused | crashed;
    ``wrong`` a reason when the numbers miss the truth (a silent wrong answer when the label claims proof)."""

    label: str
    wrong: str | None = None
    message: str = ""


def certificate_label(report):
    """The label a result carries: the certificate's kind, or on a tool without certificates the one its
    ``method`` claims (exact for the integral as it stands or after welding/orienting/deduplicating)."""
    cert = getattr(report, "certificate", None)
    if cert is not None:
        return cert.kind
    method = report.method
    if method == "union":
        return "united"
    if method == "sum":
        return "summed"
    if report.uncertainty is not None or method in ("patched", "winding"):
        return "estimate"
    return "exact"


def compare(props, truth, density=1.0):
    """Errors (volume relative, centroid relative to the diagonal, inertia relative) and the numbers they
    need; the truth's standard errors are included for a Monte Carlo truth."""
    vol = props.mass / density
    dvol = abs(vol - truth.volume) / abs(truth.volume)
    dcom = float(np.linalg.norm(np.asarray(props.center_of_mass) - truth.centroid))
    din = float(np.linalg.norm(np.asarray(props.inertia) / density - truth.inertia) / np.linalg.norm(truth.inertia))
    return dvol, dcom, din


def repaired_estimate_errors(vertices, damaged_faces, truth):
    """The part with ``damaged_faces`` repaired at density 1 and judged against ``truth`` (the part as it was):
    ``(errors, uncertainty)`` with :func:`compare`'s errors, after checking the answer is an estimate with
    bounds; None when it is refused with a reason (no number to judge)."""
    import warnings

    from inertia_tool import mass_properties
    from inertia_tool.errors import InvalidMeshError
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties((vertices, damaged_faces), density=1.0, repair=True)
    except InvalidMeshError:
        return None
    unc = props.mesh.uncertainty
    assert props.mesh.certificate.kind == "estimate" and unc is not None
    return compare(props, truth), unc


def judge(case, repair=False):
    """:func:`judge_truth` against the case's truth, or against an allowed alternative reading when that one
    holds."""
    verdict = judge_truth(case, case.truth, repair)
    for alt in case.alternatives if verdict.wrong is not None and verdict.label != "crashed" else ():
        other = judge_truth(case, alt, repair)
        if other.wrong is None:
            return other
    return verdict


def judge_truth(case, truth, repair=False):
    """Run the tool on ``case`` and say whether the answer is honest (see the module docstring)."""
    import warnings
    from inertia_tool import mass_properties
    from inertia_tool.errors import InvalidMeshError
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties((case.vertices, case.faces), density=1.0, repair=repair)
    except InvalidMeshError as exc:
        return Verdict("refused", message=str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    except Exception as exc:       # anything else is a crash: counted and shown, never hidden
        return Verdict("crashed", wrong=f"{type(exc).__name__}: {exc}"[:300])
    label = certificate_label(props.mesh)
    t = truth
    lo, hi = case.vertices.min(0), case.vertices.max(0)
    diag = float(np.linalg.norm(hi - lo))
    dvol, dcom, din = compare(props, t)
    if not (np.isfinite(props.mass) and np.all(np.isfinite(props.center_of_mass))
            and np.all(np.isfinite(props.inertia))):
        return Verdict(label, wrong=f"non-finite result (mass {props.mass}, com {props.center_of_mass})")
    numbers = f"volume {props.mass:.10g} vs {t.volume:.10g} ({t.source}); rel {dvol:.2e}, com {dcom / diag:.2e}·diag, "\
              f"inertia rel {din:.2e}"
    if label == "estimate":
        u = props.mesh.uncertainty
        if u is None:
            return Verdict(label, wrong="an estimate without bounds; " + numbers)
        slack = 1e-9
        ok = (dvol <= u.mass + slack + t.sigma_volume * MC_SIGMAS / abs(t.volume)
              and dcom <= u.center_of_mass + slack * diag + t.sigma_centroid * MC_SIGMAS
              and din <= u.inertia + slack + t.sigma_inertia * MC_SIGMAS / np.linalg.norm(t.inertia))
        if not ok:
            return Verdict(label, wrong=f"outside its bounds (±{u.mass:.3g} mass, ±{u.center_of_mass:.3g} m com, "
                                        f"±{u.inertia:.3g} inertia); " + numbers)
        return Verdict(label)
    tol_vol = VOLUME_RTOL + MC_SIGMAS * t.sigma_volume / abs(t.volume)
    tol_com = COM_RTOL * diag + MC_SIGMAS * t.sigma_centroid
    tol_in = INERTIA_RTOL + MC_SIGMAS * t.sigma_inertia / np.linalg.norm(t.inertia)
    if dvol > tol_vol or dcom > tol_com or din > tol_in:
        return Verdict(label, wrong=numbers)
    return Verdict(label)


#: Labels that claim the numbers are the solid's own: a wrong number under one of these is a silent wrong answer.
PROVEN = ("exact", "united")


def silent(verdict):
    """A wrong number presented as proven (or an estimate whose bounds miss the truth)."""
    return verdict.wrong is not None and verdict.label in PROVEN + ("estimate",)
