"""The solid ``{w ≥ 1}`` of a closed surface as its exact signed integral, corrected on a grid only where the
winding number may leave ``{0, 1}`` (:func:`corrected_estimate`): the faces whose front is proven to separate
winding numbers 0 and 1 (:func:`_front_numbers`), the cells near the others cleared without a distance query where
a bound allows (:func:`_distance_above`), and the faces counted in each doubtful cell (:func:`_face_counts`).

:func:`~.grid_estimate.closed_surface_estimate` builds it where the plain winding grid's bound would be refused;
the grid (cells a surface meets, regions of free cells) is :mod:`~.grid_cells`'s.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import InternalInvariantError
from .grid_cells import BOUNDED_REGION_POINTS, _first_cells, _label_regions, _surface_cells
from .uncertainty import Estimate, uncertainty_from

if TYPE_CHECKING:
    from .winding import IntegerTree

__all__ = ["corrected_estimate"]


#: Most clean components of the surface whose front winding number is found (one probe each; beyond it the
#: corrected estimate is not built).
FRONT_PROBES_LIMIT = 4096
#: Probes closer than this (relative to the bounding-box diagonal) to another face are not trusted.
PROBE_FLOOR_RTOL = 1e-9
#: Relative round-off allowed for the signed integral of :func:`corrected_estimate` when no cell is in doubt.
SIGNED_ROUNDOFF_RTOL = 1e-12
#: Most distinct front numbers kept as classes by :func:`corrected_estimate`.
MAX_FRONT_CLASSES = 8
#: Most (doubtful cell, candidate face) pairs tested for the face counts of the doubtful cells.
FACE_COUNT_WORK = 20_000_000


def _point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(k,) distance from points ``p`` to triangles ``(a, b, c)`` (all (k, 3)), by the closest point's region
    (Ericson, "Real-Time Collision Detection", §5.1.5); a degenerate triangle gets a lower bound (distance to
    its first corner less its longest edge)."""
    ab, ac, ap = b - a, c - a, p - a
    bp, cp = p - b, p - c

    def dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        out: np.ndarray = np.einsum("ij,ij->i", x, y)
        return out

    d1, d2, d3, d4, d5, d6 = dot(ab, ap), dot(ac, ap), dot(ab, bp), dot(ac, bp), dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        denom = 1.0 / (va + vb + vc)
        inner = a + ab * (vb * denom)[:, None] + ac * (vc * denom)[:, None]
    conditions = [(d1 <= 0) & (d2 <= 0), (d3 >= 0) & (d4 <= d3), (vc <= 0) & (d1 >= 0) & (d3 <= 0),
                  (d6 >= 0) & (d5 <= d6), (vb <= 0) & (d2 >= 0) & (d6 <= 0),
                  (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)]
    choices = [a, b, a + ab * t_ab[:, None], c, a + ac * t_ac[:, None], b + (c - b) * t_bc[:, None]]
    closest = inner.copy()
    for cond, choice in zip(conditions[::-1], choices[::-1]):      # the first condition that holds wins
        closest = np.where(cond[:, None], choice, closest)
    dist = np.linalg.norm(p - closest, axis=1)
    longest = np.max(np.stack([np.linalg.norm(ab, axis=1), np.linalg.norm(ac, axis=1),
                               np.linalg.norm(c - b, axis=1)]), axis=0)
    fallback = np.linalg.norm(ap, axis=1) - longest
    out: np.ndarray = np.where(np.isfinite(dist), dist, fallback)
    return out


#: Spacing of the samples of the good faces (in cells) with which :func:`corrected_estimate` clears cells
#: without a distance query (:func:`_distance_above`; any spacing is sound, a finer one clears more for more
#: samples: on Piper's link2.stl 2, 4 and 8 cells cleared 216k, 209k and 195k of 219k for 1.5, 0.6 and 0.4 s).
SAMPLE_SPACING_CELLS = 4.0
#: Where :func:`corrected_estimate` stops the nearest-sample search of :func:`_distance_above` (cells): its first
#: use needs ``above`` only below 1.5 cells, its second only below the distance to the bad faces, which the exact
#: query it is compared with settles anyway (``inf`` beyond it clears nothing that the exact queries do not: the
#: same cells are cleared).  On Piper's link2.stl's 334,175 centres the query 1.1-1.7 → 0.9 s CPU, 0.6 % of them
#: beyond 6 cells.
DISTANCE_QUERY_CELLS = 6.0
#: Most sample points :func:`_distance_above` takes (the spacing is widened to stay within it).
MAX_SAMPLE_POINTS = 4_000_000


def _distance_above(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, spacing: float, *,
                    beyond: float = np.inf) -> np.ndarray:
    """(p,) m: an upper bound on the distance from each of ``points`` to the surface ``faces`` (``inf`` where the
    nearest sample is farther than ``beyond``: the k-d tree's search then stops early).

    Each face (corners ``a, b, c``) is sampled at ``a (1 − s − t) + b s + c t`` for ``s, t`` on the grid of
    ``1/n``, ``n = ⌈longest edge / spacing⌉`` (at least its corners; the spacing is widened until at most
    :data:`MAX_SAMPLE_POINTS` samples are made).  A sample lies on its face up to the round-off of its
    coordinates, so the distance to the surface is at most the distance ``D`` to the nearest sample plus
    ``ε = 1e-12 · max |coordinate| + 1e-9 · diagonal``, a margin far above that round-off and above that of the
    exact nearest-point query a caller would otherwise compare (libigl's).  Returns ``D + ε``; the nearest
    sample is found with a k-d tree (scipy).
    """
    from scipy.spatial import cKDTree

    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    longest = np.max(np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                               np.linalg.norm(a - c, axis=1)]), axis=0)
    steps = np.ones(len(faces), dtype=np.int64)
    for _ in range(64):                                 # widened until the samples fit (2^64 spans any mesh)
        steps = np.maximum(1, np.ceil(longest / spacing)).astype(np.int64)
        if int(((steps + 1) * (steps + 2) // 2).sum()) <= MAX_SAMPLE_POINTS:
            break
        spacing *= 2.0
    blocks = []
    for n in np.unique(steps).tolist():
        sel = steps == n
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        s, t = i[keep] / n, j[keep] / n
        blocks.append((a[sel, None] * (1 - s - t)[None, :, None] + b[sel, None] * s[None, :, None]
                       + c[sel, None] * t[None, :, None]).reshape(-1, 3))
    samples = np.concatenate(blocks)
    used = vertices[np.unique(faces)]
    margin = 1e-12 * float(np.abs(used).max()) + 1e-9 * float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    nearest, _ = cKDTree(samples).query(points, distance_upper_bound=beyond)
    above: np.ndarray = nearest + margin
    return above


def _probe_clearance(points: np.ndarray, reach: np.ndarray, own: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                     a: np.ndarray, b: np.ndarray, c: np.ndarray, *, work: int = 1 << 22) -> np.ndarray:
    """(p,) m: ``min(reach, d/4)`` for each of ``points`` ((p, 3)), ``d`` the distance to the nearest face other
    than its ``own`` whose bounding box (``lo``, ``hi``: (m, 3)) comes within ``reach`` of it (``inf`` when
    none does); faces ``(a, b, c)`` (each (m, 3)).

    The points are taken in order along x, a block at a time, against the faces whose boxes reach the block's
    slab ``[min(x − reach), max(x + reach)]`` along x: every face a point's box test can pass, so the same
    (point, face) pairs as testing every face against every point (issue 25: that test was most of
    :func:`_front_numbers`' ~1 s on Piper's link2.stl); each point's value is its own minimum over its pairs,
    in any order.  A block is halved while it would test more than ``work`` pairs (a single point is tested
    against its slab whatever its size).
    """
    out = np.array(reach, dtype=np.float64)
    along = np.argsort(points[:, 0], kind="stable")
    by_lo = np.argsort(lo[:, 0], kind="stable")
    sorted_lo = lo[by_lo, 0]
    start, per = 0, 256
    for _ in range(2 * len(along) + 16):                # a pass takes points or halves the block (doubled
        if start >= len(along):                         # after each take, so halvings ≤ takes + 12)
            break
        block = along[start:start + per]
        q, r = points[block], out[block]
        slab_lo, slab_hi = float(np.min(q[:, 0] - r)), float(np.max(q[:, 0] + r))
        within = by_lo[:int(np.searchsorted(sorted_lo, slab_hi, side="right"))]
        within = within[hi[within, 0] >= slab_lo]
        if len(block) * len(within) > work and len(block) > 1:
            per = max(1, len(block) // 2)               # a narrower slab for fewer points
            continue
        start += len(block)
        per = min(4096, 2 * per)
        gap = np.maximum(np.maximum(lo[within][None] - q[:, None], q[:, None] - hi[within][None]), 0.0)
        near = np.einsum("pki,pki->pk", gap, gap) <= (r ** 2)[:, None]
        near &= within[None, :] != own[block][:, None]
        pi, fi = np.nonzero(near)
        if len(pi):
            fi = within[fi]
            d = _point_triangle_distance(q[pi], a[fi], b[fi], c[fi])
            nearest = np.full(len(q), np.inf)
            np.minimum.at(nearest, pi, d)
            out[block] = np.minimum(r, 0.25 * nearest)
    if start < len(along):
        raise InternalInvariantError(f"expected every point's nearest face within the passes, {start} of "
                                     f"{len(along)} done")
    return out


def _front_numbers(v: np.ndarray, f: np.ndarray, clean: np.ndarray, *,
                   max_probes: int = FRONT_PROBES_LIMIT, tree: IntegerTree | None = None) -> np.ndarray | None:
    """(m,) int: the winding number just in front of each clean face (−2³¹ for faces not clean or not settled).

    Clean faces (no other face meets them beyond the vertices and edges they share by index) joined by edges
    that exactly two faces use, both clean, form components across which the region in front stays the same
    (near such an edge the two front sides meet, and no other face passes there).  One probe per component,
    at ``c + (ε/2) n̂`` in front of the centroid ``c`` of its largest face with ``ε`` a quarter of the distance
    from ``c`` to every other face, lies in that face's front region; the winding number there is an integer
    (the surface is a cycle), found by the bounded treecode and rounded (a component more than 1/4 away,
    counting the bound, is left unsettled).  Returns None beyond ``max_probes`` components.  ``tree``: the
    :func:`~.winding.integer_tree` of ``v, f`` when the caller has built it.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .winding import winding_integers

    m, n = len(f), len(v)
    out = np.full(m, np.iinfo(np.int32).min, dtype=np.int64)
    ids = np.flatnonzero(clean)
    if not len(ids):
        return out
    nv = np.int64(max(n, 1))
    e0 = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    e1 = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    key = np.minimum(e0, e1) * nv + np.maximum(e0, e1)
    owner = np.tile(np.arange(m), 3)
    order = np.argsort(key, kind="stable")
    key, owner = key[order], owner[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[starts, len(key)])
    two = starts[count == 2]
    fa, fb = owner[two], owner[two + 1]
    keep = clean[fa] & clean[fb]
    graph = coo_matrix((np.ones(int(keep.sum()), dtype=np.int8), (fa[keep], fb[keep])), shape=(m, m))
    _, comp = connected_components(graph, directed=False)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    comps = np.unique(comp[ids])
    if len(comps) > max_probes:
        return None
    # the largest clean face of each component
    sel = ids[np.lexsort((-area[ids], comp[ids]))]
    first = np.r_[True, comp[sel][1:] != comp[sel][:-1]]
    probe_face = sel[first]
    centroid = (a[probe_face] + b[probe_face] + c[probe_face]) / 3.0
    unit = normal[probe_face] / np.maximum(2 * area[probe_face], np.finfo(float).tiny)[:, None]
    lo, hi = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    # ε: a quarter of the nearest other face, found among the faces whose boxes come within the face's size
    eps = 0.25 * np.sqrt(area[probe_face])
    eps = _probe_clearance(centroid, eps, probe_face, lo, hi, a, b, c)
    ok = eps > PROBE_FLOOR_RTOL * diag
    probes = centroid + 0.5 * eps[:, None] * unit
    w, err = winding_integers(probes[ok], v, f, tree=tree)
    whole = np.round(w)
    settled = np.abs(w - whole) + err <= 0.25
    value = np.full(len(probe_face), np.iinfo(np.int32).min, dtype=np.int64)
    value[np.flatnonzero(ok)[settled]] = whole[settled].astype(np.int64)
    table = np.full(int(comp.max()) + 1, np.iinfo(np.int32).min, dtype=np.int64)
    table[comp[probe_face]] = value
    out[ids] = table[comp[ids]]
    return out


def _raw_moments(centres: np.ndarray, weight: np.ndarray, h: float, origin: np.ndarray
                 ) -> tuple[float, np.ndarray, np.ndarray]:
    """``∫ρ``, ``∫ρ(x−o)``, ``∫ρ(x−o)(x−o)ᵀ`` of cubes of side ``h`` at ``centres`` with densities ``weight``."""
    d = centres - origin
    cube = h ** 3
    m0 = float(weight.sum()) * cube
    m1 = cube * (weight[:, None] * d).sum(axis=0)
    m2 = cube * ((weight[:, None] * d).T @ d) + m0 * h ** 2 / 12.0 * np.eye(3)
    return m0, m1, m2


def _face_blocks(flo: np.ndarray, fhi: np.ndarray, lo: np.ndarray, h: float, dims: tuple[int, ...], block: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(blocks per axis, face, block)``: each face listed in every block of ``block`` cells per axis that its
    bounding box (``flo``, ``fhi``) widened by one cell reaches, so a face whose box meets a cell (within any
    slack below a cell) is listed in that cell's block whatever the rounding at the blocks' boundaries."""
    nb = np.array([-(-d // block) for d in dims])
    span = h * block
    b0 = np.clip(np.floor((flo - h - lo) / span).astype(np.int64), 0, nb - 1)
    b1 = np.clip(np.floor((fhi + h - lo) / span).astype(np.int64), 0, nb - 1)
    size = np.prod(b1 - b0 + 1, axis=1)
    face = np.repeat(np.arange(len(flo)), size)
    offset = np.arange(int(size.sum())) - np.repeat(np.cumsum(size) - size, size)
    ext = (b1 - b0 + 1)[face]
    k = offset % ext[:, 2]
    j = (offset // ext[:, 2]) % ext[:, 1]
    i = offset // (ext[:, 2] * ext[:, 1])
    blk = ((b0[face, 0] + i) * nb[1] + b0[face, 1] + j) * nb[2] + b0[face, 2] + k
    return nb, face, blk


def _face_counts(v: np.ndarray, f: np.ndarray, cells: np.ndarray, lo: np.ndarray, h: float,
                 dims: tuple[int, ...], *, block: int = 8, max_work: int = FACE_COUNT_WORK) -> np.ndarray | None:
    """(k,) for each cell index of ``cells``: how many faces' bounding boxes meet the closed cell (at least
    the faces that meet it); None past ``max_work`` (face, block) entries or (cell, face) tests on blocks of
    ``block`` cells.

    Candidates come from blocks of cells (:func:`_face_blocks`: a face's box widened by a cell, so that a face
    touching a cell at a block's boundary is a candidate: before, a face in the plane between two blocks was not
    counted for the cells of the block below it); each candidate is tested against the cell, so the counts do
    not depend on the block size, and blocks of 2 or 4 cells are used when they test fewer pairs (issue 25:
    Piper's link2.stl 1.06 s → 0.17 s of CPU at 2 cells).  The work bound is counted on ``block``."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    flo, fhi = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
    ci, cj, ck = np.unravel_index(cells, dims)

    def cell_blocks(nb: np.ndarray, size: int) -> np.ndarray:
        found: np.ndarray = ((ci // size) * nb[1] + cj // size) * nb[2] + ck // size
        return found

    def work(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int] | None:
        """(blocks, face, block, pairs) on blocks of ``size`` cells, or None past ``max_work`` entries."""
        nb = np.array([-(-d // size) for d in dims])
        b0 = np.clip(np.floor((flo - h - lo) / (h * size)).astype(np.int64), 0, nb - 1)
        b1 = np.clip(np.floor((fhi + h - lo) / (h * size)).astype(np.int64), 0, nb - 1)
        if int(np.prod(b1 - b0 + 1, axis=1).sum()) > max_work:
            return None
        nb, face, blk = _face_blocks(flo, fhi, lo, h, dims, size)
        pairs = int(np.bincount(blk, minlength=int(np.prod(nb)))[cell_blocks(nb, size)].sum())
        return nb, face, blk, pairs

    chosen = work(block)
    if chosen is None or chosen[3] > max_work:
        return None
    for finer in (2, 4):
        if finer >= block:
            break
        other = work(finer)
        if other is not None and other[3] < chosen[3]:
            chosen, block = other, finer
            break
    nb, face, blk, _ = chosen
    order = np.argsort(blk, kind="stable")
    blk, face = blk[order], face[order]
    cell_block = cell_blocks(nb, block)
    start = np.searchsorted(blk, cell_block, side="left")
    stop = np.searchsorted(blk, cell_block, side="right")
    many = stop - start
    who = np.repeat(np.arange(len(cells)), many)
    idx = np.repeat(start, many) + (np.arange(int(many.sum())) - np.repeat(np.cumsum(many) - many, many))
    cand = face[idx]
    cell_lo = lo + h * np.stack([ci, cj, ck], axis=1)[who]
    slack = 1e-9 * h
    meets = np.all((flo[cand] <= cell_lo + h + slack) & (fhi[cand] >= cell_lo - slack), axis=1)
    counts: np.ndarray = np.bincount(who[meets], minlength=len(cells))
    return counts


def corrected_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                       dilation: int = 4) -> Estimate | None:
    """The solid ``{w ≥ 1}`` of a closed (edge-balanced) surface as its exact signed integral plus a correction
    that a grid bounds only where ``w`` may leave ``{0, 1}``.

    For a 2-cycle the divergence theorem integrates the winding number: the signed volume integrals of the
    faces (:func:`~inertia_tool.integrals.volume_moments`) are ``∫ w φ dV`` for ``φ = 1, x, x xᵀ``, exactly.
    With ``g(w) = [w ≥ 1] − w`` (zero for ``w ∈ {0, 1}``), ``∫_S φ = ∫ w φ + ∫ g(w) φ``.

    * A face no other face meets (beyond what they share by index) has one region in front of it; so do
      such faces joined by two-face edges (:func:`_front_numbers`, one exact probe per component).  Where that
      front number is 0, both sides of the face are in ``{0, 1}``.
    * A grid cell that meets only such faces has ``g = 0`` throughout (every piece of the cell cut by the
      surface borders one of them).  A cell the marking counts as crossed but that meets no face lies in one
      region; the first face met from it towards the face that marked it is within ``2√3`` cells, so dilating
      the cells of every other face ("bad": crossing, touching, unsettled, or a front number ≠ 0) by
      ``dilation`` (4) cells covers every cell whose ``g`` could be nonzero.
    * Cells no surface crosses take the integer of their region (one evaluation each, as
      :func:`~.grid_estimate._closed_part_numbers`) and add ``g(k)`` exactly.
    * A crossed cell near a bad face has ``w`` within ``T`` of each face-neighbour's integer ``k`` (a segment
      in the box of two face-adjacent cells crosses each of the ``T`` faces meeting the cell at most once, and
      none in the free neighbour): ``w ∈ [max k − T, min k + T]``, so ``g`` lies in an interval whose middle is
      counted and whose half-width is the density in doubt (a cell with no free face-neighbour: not built).

    Truth minus estimate is then a signed density bounded cell by cell, which :func:`uncertainty_from` turns
    into bounds **with no assumption on the surface** beyond its being closed.  Returns None when a step's work
    bound is exceeded, the face-pair check is incomplete, or a doubtful cell has no free face-neighbour.
    """
    from scipy import ndimage

    from ..integrals import volume_moments
    from .intersect import surface_contacts
    from .winding import fast_available, integer_tree, winding_integers, winding_numbers

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    m = len(f)
    contacts = surface_contacts(v, f)
    if not contacts.complete:
        return None
    touched = np.zeros(m, dtype=bool)
    for pairs in (contacts.crossing, contacts.coplanar_opposite, contacts.contact):
        touched[np.asarray(pairs, dtype=np.int64).reshape(-1)] = True
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    twice_area = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    clean = ~touched & (twice_area > 1e-14 * diag ** 2)
    # one tree of faces for the front probes and the regions' integers (issue 25: built twice before, ~0.25 s
    # each on Piper's link2.stl; the same values to the bit)
    tree = integer_tree(v, f)
    front = _front_numbers(v, f, clean, tree=tree)
    if front is None:
        return None
    settled_front = front > np.iinfo(np.int32).min
    values = np.unique(front[settled_front])
    if len(values) > MAX_FRONT_CLASSES:                 # the rarest numbers join the unsettled faces
        common = np.argsort(-np.bincount(np.searchsorted(values, front[settled_front])))[:MAX_FRONT_CLASSES]
        values = values[np.sort(common)]
        settled_front &= np.isin(front, values)
    bad = ~settled_front
    lo, hi = v.min(axis=0), v.max(axis=0)
    h = float(np.max(hi - lo)) / int(resolution)
    lo = lo - h
    dims = tuple(int(x) for x in np.ceil((hi + h - lo) / h).astype(np.int64))
    size = 2 * dilation + 1

    def near(marked: np.ndarray) -> np.ndarray:
        grown: np.ndarray = ndimage.maximum_filter(marked, size=size, mode="constant", cval=False).reshape(-1)
        return grown
    # the cells each front class and the bad faces mark; the faces fall into exactly these classes, and the
    # marking of a set of faces is the union of its faces' (each face sampled on its own, then every marked
    # cell grown by the same shifts, which distribute over a union), so ``crossed`` is their union: the cells
    # of every face marked once instead of twice (issue 25: ~0.4 s of Piper's link2.stl at 11.2M cells)
    grown_classes = []
    crossed = np.zeros(int(np.prod(dims)), dtype=bool)
    for value in values.tolist():
        marked = _surface_cells(v, f[front == value], lo, h, dims)
        crossed |= marked
        grown_classes.append((value, near(marked.reshape(dims))))
        del marked
    marked_bad = _surface_cells(v, f[bad], lo, h, dims).reshape(dims) if bad.any() else None
    if marked_bad is not None:
        crossed |= marked_bad.reshape(-1)
    # the range of w on a crossed cell away from bad faces: from the least front number of the faces near it
    # to the greatest plus one
    class_lo = np.full(len(crossed), np.iinfo(np.int32).max, dtype=np.int64)
    class_hi = np.full(len(crossed), np.iinfo(np.int32).min, dtype=np.int64)
    for value, grown in grown_classes:
        hit = grown & crossed
        class_lo[hit] = np.minimum(class_lo[hit], value)
        class_hi[hit] = np.maximum(class_hi[hit], value + 1)
    del grown_classes
    near_bad = near(marked_bad) & crossed if marked_bad is not None else np.zeros_like(crossed)
    if near_bad.any() and fast_available():
        # tighter: a cell whose centre is nearer to some good face than to every bad one, and farther than half
        # its diagonal from the bad ones, meets no bad face, and its region (when it meets no face) borders the
        # good face nearest its centre (within the dilation): it keeps its class range.  The distance to every
        # face is measured only for the centres farther than that from the bad ones (the others are not cleared
        # whatever it is; issue 23: Piper's link2.stl measured 334,175 centres against all 71,916 faces)
        import igl
        ring = np.flatnonzero(near_bad)
        pts = lo + h * (np.stack(np.unravel_index(ring, dims), axis=1) + 0.5)
        slack = 1e-9 * float(np.linalg.norm(hi - lo)) + 1e-6 * h
        half_diagonal = h * np.sqrt(3) / 2
        clear = np.zeros(len(ring), dtype=bool)
        # most are decided without an exact query (issue 25: Piper's link2.stl, 3.3-5.4 s of the queries' CPU to
        # about 1 s), each as the queries below would decide it:
        # ``above`` ≥ the distance to the good faces (:func:`_distance_above`, from their samples).  A centre
        # whose cell is two cells or more (chessboard) from every cell the bad faces mark (a superset of the cells
        # they meet) is at least 1.5 h from them; where ``above`` is below that less twice the slack, the test
        # below (distance to the bad faces > max(h √3/2, distance to every face) + slack) holds: cleared
        # without measuring either distance
        # (the k-d tree's search bounded at DISTANCE_QUERY_CELLS cells: a centre farther from every sample is
        # not cleared by ``above`` below 1.5 h, and goes to the exact queries as one ``above`` does not clear)
        above = (_distance_above(pts, v, f[~bad], SAMPLE_SPACING_CELLS * h, beyond=DISTANCE_QUERY_CELLS * h)
                 if not bad.all() else None)
        if above is not None and marked_bad is not None:
            apart = ~ndimage.maximum_filter(marked_bad, size=3, mode="constant", cval=False).reshape(-1)[ring]
            clear = apart & (above < 1.5 * h - 2 * slack)
        rest = np.flatnonzero(~clear)
        d_bad = np.sqrt(np.asarray(igl.point_mesh_squared_distance(pts[rest], v, f[bad])[0], dtype=np.float64))
        far = d_bad > half_diagonal + slack
        away, d_away = rest[far], d_bad[far]
        # then the centres farther than half a diagonal from the bad faces and nearer to a good face's sample
        # (``above``) than to them less the slack; the others are measured against every face
        sure = above[away] < d_away - slack if above is not None else np.zeros(len(away), dtype=bool)
        ask = np.flatnonzero(~sure)
        if len(ask):
            d_all = np.sqrt(np.asarray(igl.point_mesh_squared_distance(pts[away[ask]], v, f)[0], dtype=np.float64))
            sure[ask] = d_away[ask] > np.maximum(half_diagonal, d_all) + slack
        clear[away[sure]] = True
        near_bad[ring[clear]] = False
    near_bad |= crossed & (class_lo > class_hi)           # none found (not expected): no range
    loose = crossed & ~near_bad & ((class_lo < 0) | (class_hi > 1))     # g may be nonzero there
    doubt_mask = near_bad | loose
    # the integer of each region of free cells, at one cell each
    # (the C labels with each region's first cell when built: scipy's numbering, without np.unique's sort of
    # every cell's label; issue 25: ~1 s of Piper's link2.stl)
    region, n_regions, first_cells, _ = _label_regions(~crossed, dims)
    cell_value = np.zeros(len(region), dtype=np.int64)
    if n_regions:
        first = _first_cells(region, n_regions) if first_cells is None else first_cells
        pts = lo + h * (np.stack(np.unravel_index(first, dims), axis=1) + 0.5)
        if len(first) <= BOUNDED_REGION_POINTS or not fast_available():
            w, err = winding_integers(pts, v, f, tree=tree)
        else:
            w, err = winding_numbers(pts, v, f, fast=True), np.zeros(len(pts))
        whole = np.round(w)
        if np.any(np.abs(w - whole) + err > 0.25):
            return None
        free = region > 0
        cell_value[free] = whole.astype(np.int64)[region[free] - 1]
    free = ~crossed
    origin = 0.5 * (v.min(axis=0) + v.max(axis=0))
    signed = volume_moments(v, f, origin=origin)
    m0 = signed.volume
    m1 = signed.volume * (signed.centroid - origin) if signed.volume != 0 else np.zeros(3)
    m2 = signed.second_moment + (np.outer(m1, m1) / signed.volume if signed.volume != 0 else 0.0)
    if signed.volume == 0:
        return None
    k = cell_value
    g = np.where(k >= 1, 1 - k, -k)
    off = np.flatnonzero(free & (g != 0))
    if len(off):
        centres = lo + h * (np.stack(np.unravel_index(off, dims), axis=1) + 0.5)
        d0, d1, d2 = _raw_moments(centres, g[off].astype(np.float64), h, origin)
        m0, m1, m2 = m0 + d0, m1 + d1, m2 + d2
    doubtful = np.flatnonzero(doubt_mask)
    half = np.zeros(0)
    if len(doubtful):
        counts = _face_counts(v, f[bad], doubtful, lo, h, dims) if bad.any() else np.zeros(len(doubtful), np.int64)
        if counts is None:
            return None
        # w on each cell's closure: free cells their integer, crossed cells away from bad faces {0, 1}; a
        # doubtful cell within its face count T of every neighbour's range (a segment from the shared face)
        unknown = np.iinfo(np.int32).max // 4
        range_lo = np.where(free, k, np.where(crossed, class_lo, 0)).astype(np.int64)
        range_hi = np.where(free, k, np.where(crossed, class_hi, 1)).astype(np.int64)
        range_lo[near_bad], range_hi[near_bad] = -unknown, unknown
        idx = np.stack(np.unravel_index(doubtful, dims), axis=1)
        neighbours = []
        for axis in range(3):
            for step in (-1, 1):
                nb = idx.copy()
                nb[:, axis] += step
                inside = (nb[:, axis] >= 0) & (nb[:, axis] < dims[axis])
                flat = np.full(len(doubtful), -1, dtype=np.int64)
                flat[inside] = np.ravel_multi_index(tuple(nb[inside].T), dims)
                neighbours.append(flat)
        base_lo = np.where(class_lo[doubtful] <= class_hi[doubtful], class_lo[doubtful], unknown)
        base_hi = np.where(class_lo[doubtful] <= class_hi[doubtful], class_hi[doubtful], -unknown)
        for _ in range(max(dims)):                       # each round settles at least one more layer
            new_lo = np.full(len(doubtful), -unknown, dtype=np.int64)
            new_hi = np.full(len(doubtful), unknown, dtype=np.int64)
            for flat in neighbours:
                use = flat >= 0
                known = use.copy()
                known[use] = range_hi[flat[use]] - range_lo[flat[use]] < unknown
                nb_lo = np.minimum(range_lo[flat[known]], base_lo[known])
                nb_hi = np.maximum(range_hi[flat[known]], base_hi[known])
                new_lo[known] = np.maximum(new_lo[known], nb_lo - counts[known])
                new_hi[known] = np.minimum(new_hi[known], nb_hi + counts[known])
            tighter = (new_lo > range_lo[doubtful]) | (new_hi < range_hi[doubtful])
            if not tighter.any():
                break
            range_lo[doubtful] = np.maximum(range_lo[doubtful], new_lo)
            range_hi[doubtful] = np.minimum(range_hi[doubtful], new_hi)
        w_lo = range_lo[doubtful].astype(np.float64)
        w_hi = range_hi[doubtful].astype(np.float64)
        if np.any(w_hi - w_lo >= unknown):
            return None
        w_lo, w_hi = np.ceil(w_lo), np.floor(w_hi)
        g_hi = np.maximum(0.0, -w_lo)                 # g(w) = −w for w ≤ 0
        g_lo = np.minimum(0.0, 1.0 - w_hi)            # g(w) = 1 − w for w ≥ 1
        mid, half = 0.5 * (g_lo + g_hi), 0.5 * (g_hi - g_lo)
        centres = lo + h * (idx + 0.5)
        if np.any(mid != 0):
            d0, d1, d2 = _raw_moments(centres, mid, h, origin)
            m0, m1, m2 = m0 + d0, m1 + d1, m2 + d2
    if not m0 > 0:
        return None
    shift = m1 / m0
    centroid = origin + shift
    second = m2 - m0 * np.outer(shift, shift)
    area = float(0.5 * twice_area.sum())
    if len(doubtful) and half.any():
        centres = lo + h * (np.stack(np.unravel_index(doubtful, dims), axis=1) + 0.5)
        reach = np.linalg.norm(centres - centroid, axis=1) + h * np.sqrt(3) / 2
        cell_doubt = half * h ** 3
        far = float(np.max(reach[half > 0]))
        doubt = float(cell_doubt.sum())
        unc = uncertainty_from(m0, centroid, second, doubt, far, first_doubt=float(np.sum(cell_doubt * reach)),
                               second_doubt=float(np.sum(cell_doubt * reach ** 2)))
    else:
        # nothing in doubt: the signed integral's round-off alone, as a volume within the bounding box
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        far = float(np.max(np.linalg.norm(corners - centroid, axis=1)))
        unc = uncertainty_from(m0, centroid, second, SIGNED_ROUNDOFF_RTOL * m0, far)
    n_bad = int(np.count_nonzero(bad))
    detail = (f"the exact signed integral (winding number weighted) corrected on a {dims[0]}×{dims[1]}×{dims[2]} "
              f"grid of {h:.3g} m cells where the winding number may leave {{0, 1}}: {m - n_bad:,} of {m:,} faces "
              f"proven to separate winding numbers 0 and 1, {len(doubtful):,} cells near the other "
              f"{n_bad:,} in doubt")
    return Estimate(volume=m0, centroid=centroid, second_moment=second, area=area, uncertainty=unc,
                    method="winding", detail=detail, vertices=v, faces=f, far=far)
