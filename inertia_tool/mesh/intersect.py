"""Where the faces of a triangle mesh meet other than along what they share by index: exact detection.

A closed, consistently oriented mesh bounds a simple polyhedron only if no two faces intersect except along
the vertices and edges they share by index.  :func:`surface_contacts` tests every pair of faces whose
bounding boxes meet (within one shell and between shells, adjacent faces included), but the pairs within a
fan it proves apart without testing (see "Stars" below), and sorts the pairs that
meet beyond what they share into three kinds (:class:`SurfaceContacts`):

* ``crossing``: the two triangles cross transversally (a point in the relative interior of both, the planes
  distinct), or they are coplanar, overlap in a region of positive area and face the same way.  Either the
  two solids' interiors overlap or the surface passes through itself.
* ``coplanar_opposite``: coplanar, overlapping in a region of positive area, facing opposite ways (two bodies
  touching face to face, or a zero-thickness internal wall).
* ``contact``: the triangles meet, beyond what they share by index, only on the boundary of at least one of
  them (a vertex on a face, an edge along a face, crossing edges: T-junctions, cubes touching along an edge).
  Whether that changes the solid is for the caller to decide.

Pairs sharing an edge by index meet beyond it only if they are coplanar with their third vertices on the
same side of the edge (folded over); they are then ``coplanar_opposite`` when they face opposite ways (which
is the case for a consistently oriented fold) and ``crossing`` when they face the same way.  Faces of zero
area (three collinear corners, exactly) are skipped: they bound no volume; the caller counts them.

Exactness
---------
Every decision is the sign of an orientation determinant of input coordinates (no tolerance decides
topology).  ``orient3d(a, b, c, d) = det[a − d; b − d; c − d]`` and ``orient2d(a, b, c) = det[a − c; b − c]``
are first evaluated in float64 with a static error bound, and recomputed exactly in rational arithmetic
(Python integers: every float64 is a dyadic rational, so all coordinates of one batch scaled by one power of
two are integers) when the floating-point
value is within its bound of zero.

The bound (in the manner of Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
Geometric Predicates", Discrete Comput. Geom. 18, 1997, section 4.3): with ``u = 2⁻⁵³`` the unit roundoff,
each of the six triple products of the cofactor expansion of ``orient3d`` passes through at most eight
roundings (three differences, one product in a 2×2 minor, the minor's subtraction, the product with the
first row, two additions of the sum), so ``|fl(det) − det| ≤ γ₈·P`` with ``P = Σ|triple products|`` and
``γₙ = n·u/(1 − n·u)``; ``P`` itself, evaluated in float64 from the absolute values, is at least
``P/(1 + γ₇)``.  Hence ``|fl(det) − det| ≤ 8.01·u·fl(P)`` and we use ``10·u·fl(P)``.  For ``orient2d`` four
roundings per product give ``γ₄``; we use ``6·u·fl(P)``.  These relative bounds need every rounding to be
relative, i.e. no underflow or overflow: we check once that every nonzero coordinate magnitude lies in
``[2⁻²⁴⁰, 2²⁹⁹]`` (then every nonzero difference lies in ``[2⁻²⁹², 2³⁰⁰]`` and no product of three of
them leaves the normal range; a subnormal difference of two products is exact); a mesh outside that range is
first scaled by a power of two (exact, and orientation signs do not change), and if its dynamic range is
still too wide every sign is computed exactly.  ``fl(P) = 0`` means every triple product has a zero factor,
so the determinant is exactly zero.

A touching corner decides a pair without the exact stage where it can (C kernel): when a face ``B`` meets the
plane of a face ``A`` in one corner ``x`` only (its two other corners strictly on one side, signs the float
filter decided), ``A`` and ``B`` meet at most in ``x``: not at all beyond what they share if ``x`` is shared by
index, else exactly when ``x`` lies in the closed ``A`` (``contact``), whatever ``A``'s corners say of ``B``'s
plane; likewise with the roles swapped once ``A``'s corners are known.  A fan-capped cylinder from an STL file
has every rim corner exactly on its side walls' planes, which no float filter decides: its pairs needed four
exact evaluations per section, now none (the kinds found are the same; ``exact_evaluations`` is lower).

Broad phase
-----------
A hierarchical uniform grid over the face bounding boxes (closed boxes: touching counts): faces are sorted
into levels by size (level ``L`` holds boxes at most ``h·2^L`` across, ``h`` twice the median box size),
each level has its own grid of cells ``h·2^L``, every face is paired with the faces of its own level that share a cell
and with the faces of larger levels through their grids; a pair is kept only in the cell holding the low
corner of the intersection of the two boxes, so it is tested once.  Cell indices are ``floor((x − o)/h)``,
monotone in ``x``, so two closed boxes that meet always share a cell.  Candidate pairs are generated and
tested in chunks of at most ``chunk`` pairs, so memory stays bounded on any mesh.

Stars
-----
Every face of a fan-triangulated cap (cylinders, holes, bosses in CAD exports) contains the centre vertex, so
all their boxes meet there and a cap of ``k`` faces alone gives ``k(k − 1)/2`` candidate pairs.  Those pairs
are left out, without changing the result, for the stars this rule certifies.  A vertex ``v`` of at least
:data:`STAR_MIN_FACES` faces is *certified* when (1) its faces ``(v, x, y)``, with ``v, x, y`` distinct
indices, form one edge-connected fan: the link edges ``x–y`` make one path or one cycle, every link vertex in
at most two of them, giving the ring ``r₀ … r_k`` (``r_k = r₀`` for a cycle); and (2) along some coordinate
axis (dropping that coordinate: an exact projection) every triangle ``(v′, r′ᵢ, r′ᵢ₊₁)`` has the same strict
orientation ``s`` (exact ``orient2d``), and the number of steps ``i`` whose half-open wedge ``(r′ᵢ, r′ᵢ₊₁]``
about ``v′`` holds the direction of ``r′₀`` — ``s·orient2d(v′, r′ᵢ, r′₀) > 0`` and
``s·orient2d(v′, r′₀, r′ᵢ₊₁) ≥ 0`` — is 1 for a cycle and 0 for a path.

Proof that two faces of a certified star meet only in what they share by index (so the check would find
nothing there).  Each step turns by an angle in ``(0, π)`` in the sense ``s``, so the cumulative angle
increases strictly; a wedge narrower than π holds a direction iff the two signs above hold, and holds at most
one multiple of 2π of the cumulative angle, so the count is the number of whole turns: the total is exactly
2π for a cycle and below 2π for a path.  The projected wedges ``Wᵢ`` are then non-overlapping closed sectors
with distinct bounding rays; two non-adjacent ones meet only in ``v′`` and adjacent ones along the ray through
``r′ᵢ₊₁``, which meets ``Tᵢ′`` and ``Tᵢ₊₁′`` (the projected faces, ``Tᵢ′ ⊂ Wᵢ``) only in the projected edge
``[v′, r′ᵢ₊₁]``.  Each face projects one to one (its projection has nonzero area), so a common point of two
faces is the only preimage in each of a point of ``{v′}`` or of the projected shared edge: it is ``v`` or on
the shared edge ``[v, rᵢ₊₁]``.  Distinct ring vertices make non-adjacent faces share only ``v`` by index and
adjacent ones exactly the edge.  Both twins leave out every pair of faces sharing a certified vertex before
counting candidates (the C scan also whole node pairs of its hierarchy whose faces all contain one certified
vertex), so ``candidate_pairs`` counts the box-meeting pairs not within one certified star on both paths.
A fan that folds over itself, winds twice or overlaps after less than a turn fails (2) and is tested pair by
pair as before; faces outside the star are always tested against it.  ``surface_contacts(...,
_star_faces=0)`` runs the unpruned scan (for the tests).

Patches
-------
The C scan (below) also leaves out, without testing, the pairs within a *certified patch*: a node of its
hierarchy whose faces ``K`` (1) all project along one coordinate axis to triangles of one strict orientation
``s`` (exact ``orient2d`` of the corners in winding order: the normals lie in the open half-space of that
axis, the normal-cone condition of self-collision culling, Volino and Magnenat-Thalmann, "Efficient
self-collision detection on smoothly discretized surface animations using geometrical shape regularity",
Computer Graphics Forum 13(3), 1994), and (2) whose boundary chain (the directed edges of its faces, ``u → v``
cancelling ``v → u``) is a union of cycles whose projections along that axis are simple polygons meeting only
at common vertices (by index), without crossing there, nested only as outline, hole, island in the hole, ...
(their contour test; every segment pair, angle and inclusion decided by exact ``orient2d``).

Where the chain passes through one vertex ``w`` ``k = 2 … 4`` times (a *pinch*: a range of faces in Morton
order often touches itself at a corner, or round a hole) its passes are *resolved* into cycles: the ``2k``
directions of the chain's edges about ``w′``, sorted exactly (half-plane, then ``orient2d``), must alternate
between leaving and entering with no two along one ray, and each entering edge is followed by the leaving
edge beside it on one side (tried on either side), so each resolved cycle passes ``w′`` inside a sector
bounded by two adjacent directions, holding no other edge: two resolved cycles touch at ``w′`` without
crossing.  The rule then asks: every edge on one resolved cycle, each cycle through each vertex once, at most
eight cycles; projected segments meeting only where one follows the other or at a vertex common by index
(and not overlapping along one line); for each cycle ``c``, at a vertex of ``c`` on no other cycle, its
*depth* (the cycles whose polygon holds that vertex, by exact ray parity) and its orientation (the sign of
``orient2d`` at its lowest-leftmost vertex, nonzero for a simple polygon) must satisfy orientation
``= s·(−1)^depth``.

Proof that two faces of a certified patch meet only in what they share by index.  For a point ``y`` of the
plane on no projected edge, the number of faces whose projection holds ``y``, times ``s``, is the winding
number round ``y`` of the projected boundary chain (the faces' boundaries add up to the chain), which is the
sum of the winding numbers of the resolved cycles (any resolution of the passes through a vertex is again a
decomposition of the same chain).  Two resolved cycles' boundaries meet only at common vertices, where they
touch without crossing, so each lies (off those points) on one side of the other: either their polygons are
disjoint or one holds the other, and a vertex of one on no other cycle tells which.  The polygons holding
``y`` are therefore nested, ``c₁ ⊃ c₂ ⊃ … ⊃ c_d`` with depths ``0 … d − 1``, and their winding numbers
``s, −s, s, …`` add up to 0 or ``s``: the projected faces have pairwise disjoint interiors.  At a point of
``K`` off the chain the faces round it then cover a neighbourhood
of its projection exactly once (their wedges, all of one orientation, close up into whole turns), so the
projection is one to one near it; two distinct points of ``K`` with one projection therefore both lie on the
chain, on which the projection is one to one (projected chain segments meet only where they share a vertex
by index, i.e. the same point).  So the projection is one to one on ``K`` and a point common to two faces is
one point of ``K``, i.e. on what they share by index.  A fold, a fan winding twice, two layers of a spiral
ramp, coplanar sheets, two outlines of one orientation one inside the other (a square stacked on a square),
fans round one vertex overlapping or nested in projection, or a patch whose boundary winds twice fail (1) or
(2) and are descended as before; failing to certify only costs time.

Which vertices the star certificates are needed for: with patches, a pair of faces of one certified patch is
never enumerated (its node is not paired with itself, and no node pair below it is reached), so the C scan
builds the patches first and certifies only the stars of vertices whose faces are not all in one certified
patch (the pairs found and the counts are those of certifying every star).

The patches change which pairs are enumerated, not which are found: ``candidate_pairs`` and ``tested_pairs``
of the C scan are then below the numpy twin's (``surface_contacts(..., _patches=False)`` gives the twin's
counts, for the tests).  Under a work bound (``max_pairs``) there are no patches, so both twins count alike.

C extension
-----------
When ``inertia_tool._accel`` is built (and the coordinates are in the filter's range) the whole scan runs in
its section 8 (``contact_scan``): the per-face axes and boxes, then a bounding-volume hierarchy over the face
boxes (faces in Morton order of their box centres, radix-sorted) traversed against itself gives the same
candidate pairs as the grid, in another order, and each is classified on the spot with the same predicates
and decisions, the exact stage computed by floating-point expansions instead of Python integers, on
:func:`~inertia_tool._native.threads` threads (the pairs found do not depend on the count; with ``max_pairs``
it runs on one, and which pairs are tested before the bound stops it differs from the grid's order).  Each
face keeps its float normal and its permanent, so a side test against its plane is three products with the
very float value and error bound of ``orient3d``; pairs the filter cannot decide are first tried for a line
separating their projections through what they share (:func:`_projections_separate`, also used here) before
any exact evaluation.  The C scan also certifies, by the rule of "Stars" above, the star of every vertex of
at least three faces: a pair within a certified star of fewer than :data:`STAR_MIN_FACES` faces is still
enumerated and counted as a candidate and as tested (exactly as the numpy twin counts it, which certifies only
the larger stars and tests such a pair), but decided by the certificate, without rebuilding or testing the two
faces.  On a clean mesh that is nearly every candidate pair (the faces sharing a corner: six of the 6.4 per
face of a 1M-face torus); the pairs found are the same, since a certified star's pairs meet only in what they
share.  Its hierarchy's leaves are blocks of 16 faces whose boxes (and, while the traversal is at the leaf,
corner indices) are stored coordinate by coordinate, so that one face's box is tested against a whole leaf at
once, and so are its certified corners: the pairs of a leaf sharing a certified corner are counted a block
at a time, and only the others are tested one by one.  The star of a vertex whose faces are consistently
oriented round it (every vertex of a closed, oriented manifold) is ringed by following its link edges,
``x → y`` then ``y → z``, with no sort; any other star by matching link vertices as before; either way the
certificate is the same.  This module's numpy code stays the reference and the fallback
(``INERTIA_TOOL_NO_ACCEL=1``); the tests run on both.

Memory of the C scan (issue 25): a face's box is six 16-bit step numbers on its leaf's grid — the leaf's
float32 box cut into 65,534 steps per axis by ``T(x) = fl(fl(x − L)·inv)``, a composition of correctly rounded
operations with positive constants and so monotone in ``x``; the lower bound is stored as ``⌊T(lo)⌋``, the
upper as ``⌈T(hi)⌉``, and a face of another leaf is put on this grid by one affine map per pair of leaves,
widened by a bound of its roundings.  Monotonicity alone makes the test conservative: closed boxes that meet,
``lo_b ≤ hi_a`` and ``lo_a ≤ hi_b``, give ``⌊T(lo_a)⌋ ≤ T(hi_b) ≤ ⌈T(hi_b)⌉`` and the same with ``a`` and
``b`` exchanged, so every pair whose boxes meet is still visited, and its float64 boxes decide whether it is a
candidate (the pairs, counts and classes are those of float32 or float64 boxes; an axis with an infinite
float32 bound is not cut).  The scan's arrays are mapped in three phases that never coexist: the sort (16
bytes a face); the faces across each edge (12) from every vertex's faces and each face's hierarchy position
(4), the patches on the hierarchy's shape (which depends on the face count alone), the star certificates from
the lists of the vertices not inside one certified patch; and only then the boxes (12), nodes (4), the order
(4) and flags the traversal reads.  A later phase writes into the pages of an earlier one instead of fresh
ones where that does not raise the high point (the boxes into the twins' block, the leaves' boxes into the
positions'): a fresh page costs the kernel a fault and a zeroing.  Since ``check7`` (issue 25: the check set
the analysis's peak, 1.50× the file at 1e7 faces) the high point is about 27–31 bytes a face (37–40 before,
about 80 before that):

* the faces across each edge are built in rounds (four from 2¹⁹ faces up): the vertices are cut into ranges of
  equal count, and each round lists the faces of its own vertices only (a quarter of the 16 bytes a face of
  every vertex's list) and finds the face across each edge leaving one of them; every (face, corner) belongs to
  the round of its vertex, so the twins are those of one round;
* an array whose content is dead until a later phase writes it again has its pages given back
  (``MADV_DONTNEED``) instead of staying resident under the next phase: the sort words once the order is
  unpacked, the positions during the patches, the twins' block (kept for the boxes) during the star
  certificates;
* the traversal keeps no corner indices by hierarchy position (12 bytes a face): each traversal reads those of
  the two leaves it is at from the caller's faces through the order, once per leaf it moves to, and the
  per-face star bits and the leaves' apexes are made where the boxes are.

None of the scan's arrays is read before it is written (``INERTIA_TOOL_CT_POISON=1`` fills every block it
takes with 0xA5 bytes, and the tests compare every field with and without it, and for any number of rounds,
``INERTIA_TOOL_CT_TWIN_ROUNDS``); at the end its blocks are kept for the next weld or census in the process.
"""

from __future__ import annotations

from collections.abc import Iterator
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from .._native import accel, faces_for_c, threads
from ..errors import InvalidMeshError
from ..values import frozen_value

if TYPE_CHECKING:     # annotations only: numpy.typing is not loaded at run time
    from numpy.typing import ArrayLike

__all__ = ["SurfaceContacts", "surface_contacts", "orient3d_sign", "orient2d_sign"]

_U = 2.0 ** -53
#: Coefficient of the static error bound of orient3d (see the module docstring: 8.01·u suffices).
O3D_BOUND = 10 * _U
#: Coefficient of the static error bound of orient2d (γ₄ suffices).
O2D_BOUND = 6 * _U
#: Nonzero coordinate magnitudes inside [2⁻²⁴⁰, 2²⁹⁹] keep every rounding of the predicates relative.
_SMALLEST, _LARGEST = 2.0 ** -240, 2.0 ** 299
#: Stars of at least this many faces are tried for certification (module docstring, "Stars"); smaller ones cost
#: too few pairs to be worth it.  0 turns the pruning off (the unpruned scan, kept for the tests).
STAR_MIN_FACES = 8
#: Candidate pairs generated and tested at once (memory bound of the narrow phase: ~1 kB per pair).
CHUNK_PAIRS = 1 << 17

_NONE, _CROSSING, _OPPOSITE, _CONTACT = 0, 1, 2, 3


@frozen_value
class SurfaceContacts:
    """The face pairs of a mesh that meet beyond the vertices and edges they share by index.

    Attributes
    ----------
    crossing : (k, 2) intp
        Face pairs ``i < j`` (rows sorted) that cross transversally, or are coplanar and overlap in a region of
        positive area facing the same way: the solids' interiors overlap, or the surface passes through itself.
    coplanar_opposite : (j, 2) intp
        Face pairs ``i < j`` that are coplanar and overlap in a region of positive area facing opposite ways
        (face-to-face contact, or a zero-thickness internal wall).
    contact : (c, 2) intp
        Face pairs ``i < j`` that meet, beyond what they share by index, only on the boundary of at least one
        of them (vertex on a face, edge along a face, edges crossing: T-junctions, bodies touching along an edge).
    complete : bool
        True when every candidate pair was tested; False only when ``max_pairs`` stopped the search (the pairs
        found so far are reported, but the absence of a crossing is then not proven).
    candidate_pairs : int
        Face pairs whose bounding boxes meet, but those within one certified star (module docstring, "Stars":
        they provably meet only in what they share) and, on the C scan without a work bound, those within one
        certified patch (module docstring, "Patches"); the broad phase's output, all of them when ``complete``.
    tested_pairs : int
        Candidate pairs tested exactly (both faces of nonzero area).
    exact_evaluations : int
        Predicate evaluations the floating-point filter could not decide, recomputed in rational arithmetic.
    degenerate_faces : int
        Faces of zero area (skipped).
    """

    crossing: np.ndarray
    coplanar_opposite: np.ndarray
    contact: np.ndarray
    complete: bool
    candidate_pairs: int = 0
    tested_pairs: int = 0
    exact_evaluations: int = 0
    degenerate_faces: int = 0


# -- exact predicates ----------------------------------------------------------------------------------------

def _integers(*points: np.ndarray) -> list[np.ndarray]:
    """The rows of float64 arrays as exact Python integers at one common scale (object arrays, same shapes).

    Every float64 is ``M·2^E`` with an integer mantissa ``|M| < 2⁵³``; scaling all of them by the smallest
    ``2^-E`` makes them integers, and a determinant's sign does not change under a common positive scale.
    """
    mant, expo = np.frexp(np.concatenate([p.reshape(-1) for p in points]))
    m = (mant * 2.0 ** 53).astype(np.int64)
    e = expo.astype(np.int64) - 53
    nonzero = m != 0
    base = int(e[nonzero].min()) if nonzero.any() else 0
    shift = np.where(nonzero, e - base, 0)
    ints = np.array([int(x) << int(k) for x, k in zip(m.tolist(), shift.tolist())] if len(m) else [],
                    dtype=object)
    out, at = [], 0
    for p in points:
        out.append(ints[at:at + p.size].reshape(p.shape))
        at += p.size
    return out


def _exact_orient3d(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Exact sign of orient3d per row (k,) int8, in integer arithmetic."""
    a, b, c, d = _integers(a, b, c, d)
    ad, bd, cd = a - d, b - d, c - d
    det = (ad[:, 0] * (bd[:, 1] * cd[:, 2] - bd[:, 2] * cd[:, 1])
           + ad[:, 1] * (bd[:, 2] * cd[:, 0] - bd[:, 0] * cd[:, 2])
           + ad[:, 2] * (bd[:, 0] * cd[:, 1] - bd[:, 1] * cd[:, 0]))
    return np.array([(x > 0) - (x < 0) for x in det], dtype=np.int8)


def _exact_orient2d(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Exact sign of orient2d per row (k,) int8, in integer arithmetic."""
    a, b, c = _integers(a, b, c)
    det = (a[:, 0] - c[:, 0]) * (b[:, 1] - c[:, 1]) - (a[:, 1] - c[:, 1]) * (b[:, 0] - c[:, 0])
    return np.array([(x > 0) - (x < 0) for x in det], dtype=np.int8)


class _Predicates:
    """Filtered exact predicates over rows of points; counts the rows decided exactly."""

    def __init__(self, force_exact: bool = False) -> None:
        self.force_exact = force_exact
        self.exact = 0

    def orient3d(self, a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Sign of ``det[a − d; b − d; c − d]`` per row, (k,) int8; ``a..d`` (k, 3) float64."""
        with np.errstate(all="ignore"):            # out of the filter's range everything is recomputed exactly
            return self._orient3d(a, b, c, d)

    def orient2d(self, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
        """Sign of ``det[a − c; b − c]`` per row, (k,) int8; ``a, b, c`` (k, 2) float64."""
        with np.errstate(all="ignore"):
            return self._orient2d(a, b, c)

    def _orient3d(self, a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
        sign, unsure = self._orient3d_filter(a, b, c, d)
        return self._orient3d_resolve(sign, unsure, a, b, c, d)

    def orient3d_filter(self, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                        d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Float signs of orient3d per row and the rows the static filter cannot decide (left 0)."""
        with np.errstate(all="ignore"):
            return self._orient3d_filter(a, b, c, d)

    def _orient3d_filter(self, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                         d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ad, bd, cd = a - d, b - d, c - d
        m0 = bd[:, 1] * cd[:, 2] - bd[:, 2] * cd[:, 1]
        m1 = bd[:, 2] * cd[:, 0] - bd[:, 0] * cd[:, 2]
        m2 = bd[:, 0] * cd[:, 1] - bd[:, 1] * cd[:, 0]
        det = ad[:, 0] * m0 + ad[:, 1] * m1 + ad[:, 2] * m2
        ab, bb, cb = np.abs(ad), np.abs(bd), np.abs(cd)
        perm = (ab[:, 0] * (bb[:, 1] * cb[:, 2] + bb[:, 2] * cb[:, 1])
                + ab[:, 1] * (bb[:, 2] * cb[:, 0] + bb[:, 0] * cb[:, 2])
                + ab[:, 2] * (bb[:, 0] * cb[:, 1] + bb[:, 1] * cb[:, 0]))
        sign = np.sign(det).astype(np.int8)
        unsure = np.flatnonzero((np.abs(det) <= O3D_BOUND * perm) & (perm > 0)) if not self.force_exact \
            else np.arange(len(det))
        sign[unsure] = 0
        return sign, unsure

    def orient3d_resolve(self, sign: np.ndarray, unsure: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                         d: np.ndarray) -> np.ndarray:
        """``sign`` with the rows ``unsure`` recomputed exactly."""
        return self._orient3d_resolve(sign, unsure, a, b, c, d)

    def _orient3d_resolve(self, sign: np.ndarray, unsure: np.ndarray, a: np.ndarray, b: np.ndarray,
                          c: np.ndarray, d: np.ndarray) -> np.ndarray:
        if len(unsure):
            pa, pb, pc, pd = a[unsure], b[unsure], c[unsure], d[unsure]
            # two equal points: two equal rows (or a zero row), the determinant is zero
            equal = np.zeros(len(unsure), dtype=bool)
            for p, q in ((pa, pb), (pa, pc), (pa, pd), (pb, pc), (pb, pd), (pc, pd)):
                equal |= np.all(p == q, axis=1)
            sign[unsure[equal]] = 0
            keep = ~equal
            unsure = unsure[keep]
            if len(unsure):
                sign[unsure] = _exact_orient3d(pa[keep], pb[keep], pc[keep], pd[keep])
        self.exact += len(unsure)
        return sign

    def _orient2d(self, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
        acx, acy = a[:, 0] - c[:, 0], a[:, 1] - c[:, 1]
        bcx, bcy = b[:, 0] - c[:, 0], b[:, 1] - c[:, 1]
        left, right = acx * bcy, acy * bcx
        det = left - right
        perm = np.abs(left) + np.abs(right)
        sign = np.sign(det).astype(np.int8)
        unsure = np.flatnonzero((np.abs(det) <= O2D_BOUND * perm) & (perm > 0)) if not self.force_exact \
            else np.arange(len(det))
        if len(unsure):
            sign[unsure] = _exact_orient2d(a[unsure], b[unsure], c[unsure])
        self.exact += len(unsure)
        signs: np.ndarray = sign
        return signs


def orient3d_sign(a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike) -> np.ndarray:
    """Exact sign of ``det[a − d; b − d; c − d]`` for rows of float64 points, (k,) int8.

    Positive when ``d`` sees ``a, b, c`` clockwise, i.e. ``d`` lies below the plane of the counter-clockwise
    triangle ``a, b, c`` (its normal ``(b − a)×(c − a)`` points away from ``d``).
    """
    pts = [np.atleast_2d(np.asarray(p, dtype=np.float64)) for p in (a, b, c, d)]
    return _Predicates(not _filter_safe(np.concatenate(pts))).orient3d(*pts)


def orient2d_sign(a: ArrayLike, b: ArrayLike, c: ArrayLike) -> np.ndarray:
    """Exact sign of ``det[a − c; b − c]`` for rows of float64 2-D points, (k,) int8 (+1: ``a, b, c``
    counter-clockwise)."""
    pts = [np.atleast_2d(np.asarray(p, dtype=np.float64)) for p in (a, b, c)]
    return _Predicates(not _filter_safe(np.concatenate(pts))).orient2d(*pts)


#: Coordinates read at once by :func:`_magnitudes` (a cache-sized buffer, no temporary the size of the mesh).
_MAGNITUDE_CHUNK = 1 << 15


def _magnitudes(v: np.ndarray) -> tuple[float, float]:
    """The largest coordinate magnitude (NaN if any is NaN, inf if any is infinite) and the smallest nonzero one
    (inf when there is none), read chunk by chunk into one small buffer: a fresh temporary of the mesh's size
    costs more in page faults than the comparisons (63 MB and about 0.03 s at 2.6M vertices)."""
    flat = v.reshape(-1)
    buf = np.empty(min(len(flat), _MAGNITUDE_CHUNK))
    largest, smallest = 0.0, np.inf
    for start in range(0, len(flat), _MAGNITUDE_CHUNK):
        part = buf[:len(flat[start:start + _MAGNITUDE_CHUNK])]
        np.abs(flat[start:start + _MAGNITUDE_CHUNK], out=part)
        top = float(part.max())
        if not top <= np.inf:                # NaN: the largest is NaN
            return top, smallest
        largest = max(largest, top)
        part[part == 0] = np.inf             # zeros are exact: only nonzero magnitudes count
        smallest = min(smallest, float(part.min()))
    return largest, smallest


def _filter_safe(v: np.ndarray) -> bool:
    """Whether every nonzero coordinate magnitude lies in the range where the static filter's bound holds."""
    if not v.size:
        return True
    largest, smallest = _magnitudes(v)
    return largest <= _LARGEST and smallest >= _SMALLEST


def _scaled(v: np.ndarray) -> tuple[np.ndarray, bool]:
    """``v`` scaled by a power of two (exact) so that the filter holds, and whether it does."""
    if _filter_safe(v):
        return v, True
    mag = np.abs(v[v != 0])
    _, top = np.frexp(float(mag.max()))
    w = np.ldexp(v, -int(top))                  # largest magnitude in [0.5, 1): exact unless something underflows
    if np.array_equal(np.ldexp(w, int(top)), v) and _filter_safe(w):
        return w, True
    return v, False


# -- per-face data --------------------------------------------------------------------------------------------

_PLANE = np.array([[1, 2], [2, 0], [0, 1]])      # coordinates kept when dropping axis k (orientation-preserving)


def _face_axes(v: np.ndarray, f: np.ndarray, pred: _Predicates) -> tuple[np.ndarray, np.ndarray]:
    """Per face: the axis whose normal component is exactly nonzero and largest in float, and zero-area mask."""
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal = np.cross(p1 - p0, p2 - p0)
    axis = np.argmax(np.abs(normal), axis=1)
    sign = np.zeros(len(f), dtype=np.int8)
    todo = np.arange(len(f))
    for _ in range(3):                                   # try the largest component, then the others
        if not len(todo):
            break
        k = axis[todo]
        keep = _PLANE[k]
        a = np.take_along_axis(p0[todo], keep, 1)
        b = np.take_along_axis(p1[todo], keep, 1)
        c = np.take_along_axis(p2[todo], keep, 1)
        sign[todo] = pred.orient2d(a, b, c)
        todo = todo[sign[todo] == 0]
        axis[todo] = (axis[todo] + 1) % 3
    degenerate = sign == 0
    return axis, degenerate


# -- narrow phase ---------------------------------------------------------------------------------------------

def _classify(v: np.ndarray, f: np.ndarray, axis: np.ndarray, a: np.ndarray, b: np.ndarray,
              pred: _Predicates) -> np.ndarray:
    """Kind of each pair of nondegenerate faces ``(a, b)``: 0 none, 1 crossing, 2 coplanar opposite, 3 contact."""
    k = len(a)
    fa, fb = f[a], f[b]
    same = fa[:, :, None] == fb[:, None, :]              # (k, 3, 3): corner i of a is corner j of b
    n_shared = same.sum(axis=(1, 2))
    t1, t2 = v[fa], v[fb]                                  # (k, 3, 3)
    d1 = np.zeros((k, 3), dtype=np.int8)                   # corners of t1 against the plane of t2
    d2 = np.zeros((k, 3), dtype=np.int8)
    on1 = same.any(axis=2)                                 # a shared corner lies on the other plane: sign 0
    on2 = same.any(axis=1)
    # signs the float filter cannot decide (e.g. adjacent faces in one plane): first try to show without them
    # that the faces meet only in what they share (_projections_separate), as the C scan does
    done = np.zeros(k, dtype=bool)                         # shown to meet only in what they share
    tried = n_shared > 2
    unsure1: list[np.ndarray] = []
    for i in range(3):
        r = np.flatnonzero(~on1[:, i])
        d1[r, i], u = pred.orient3d_filter(t2[r, 0], t2[r, 1], t2[r, 2], t1[r, i])
        unsure1.append(r[u])
    try_rows = np.setdiff1d(np.unique(np.concatenate(unsure1)), np.flatnonzero(tried))
    done[try_rows] = _projections_separate(t1[try_rows], t2[try_rows], same[try_rows], n_shared[try_rows],
                                           axis[a[try_rows]], pred)
    tried[try_rows] = True
    for i in range(3):
        r = unsure1[i][~done[unsure1[i]]]
        d1[r, i] = pred.orient3d_resolve(d1[r, i], np.arange(len(r)), t2[r, 0], t2[r, 1], t2[r, 2], t1[r, i])
    # a pair sharing an edge is coplanar iff the third corner of a lies in b's plane; otherwise nothing
    need2 = ((n_shared < 2) | ~(d1 != 0).any(axis=1)) & ~done
    unsure2: list[np.ndarray] = []
    for i in range(3):
        r = np.flatnonzero(~on2[:, i] & need2)
        d2[r, i], u = pred.orient3d_filter(t1[r, 0], t1[r, 1], t1[r, 2], t2[r, i])
        unsure2.append(r[u])
    try_rows = np.setdiff1d(np.unique(np.concatenate(unsure2)), np.flatnonzero(tried))
    done[try_rows] = _projections_separate(t1[try_rows], t2[try_rows], same[try_rows], n_shared[try_rows],
                                           axis[a[try_rows]], pred)
    for i in range(3):
        r = unsure2[i][~done[unsure2[i]]]
        d2[r, i] = pred.orient3d_resolve(d2[r, i], np.arange(len(r)), t1[r, 0], t1[r, 1], t1[r, 2], t2[r, i])
    kind = np.zeros(k, dtype=np.int8)
    separated = (np.all(d1 > 0, axis=1) | np.all(d1 < 0, axis=1) | np.all(d2 > 0, axis=1)
                 | np.all(d2 < 0, axis=1) | done)
    coplanar = np.all(d1 == 0, axis=1)
    rest = ~separated & ~coplanar & (n_shared < 2)
    cop = np.flatnonzero(coplanar)
    if len(cop):
        kind[cop] = _coplanar(t1[cop], t2[cop], axis[a[cop]], same[cop], n_shared[cop], pred)
    gen = np.flatnonzero(rest)
    if len(gen):
        kind[gen] = _transversal(t1[gen], t2[gen], d1[gen], d2[gen], same[gen], n_shared[gen], pred)
    return kind


def _o2(pred: _Predicates, p: np.ndarray, q: np.ndarray, x: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """orient2d signs of the projections of rows p, q, x (k, 3) along ``axis`` (k,)."""
    keep = _PLANE[axis]
    return pred.orient2d(np.take_along_axis(p, keep, 1), np.take_along_axis(q, keep, 1),
                         np.take_along_axis(x, keep, 1))


def _projections_separate(t1: np.ndarray, t2: np.ndarray, same: np.ndarray, n_shared: np.ndarray, axis: np.ndarray,
                          pred: _Predicates) -> np.ndarray:
    """Pairs (sharing at most an edge) whose projections along ``axis`` (one to one for t1) are separated by a
    line through what they share (an edge line of either face when nothing is shared): they then meet only in
    what they share (a point of both projects onto the shared element, whose only preimage in t1 is itself).
    Exact; False proves nothing.  The twin of ``ct_projections_separate`` in the C extension."""
    out = np.zeros(len(t1), dtype=bool)
    on1 = np.asarray(same.any(axis=2))
    on2 = np.asarray(same.any(axis=1))
    r = np.flatnonzero(n_shared == 2)
    if len(r):
        i1 = np.argmin(on1[r], axis=1)                       # the corner of t1 not shared
        i2 = np.argmin(on2[r], axis=1)
        p, q = t1[r, (i1 + 1) % 3], t1[r, (i1 + 2) % 3]
        out[r] = _o2(pred, p, q, t1[r, i1], axis[r]) * _o2(pred, p, q, t2[r, i2], axis[r]) < 0
    r = np.flatnonzero(n_shared == 1)
    if len(r):
        i1 = np.argmax(on1[r], axis=1)                       # the shared corner
        i2 = np.argmax(on2[r], axis=1)
        v = t1[r, i1]
        mine = [t1[r, (i1 + 1) % 3], t1[r, (i1 + 2) % 3]]
        theirs = [t2[r, (i2 + 1) % 3], t2[r, (i2 + 2) % 3]]
        hit = np.zeros(len(r), dtype=bool)
        for ends, other_ends in ((mine, theirs), (theirs, mine)):
            for e in range(2):
                so = _o2(pred, v, ends[e], ends[1 - e], axis[r])
                hit |= ((so != 0) & (_o2(pred, v, ends[e], other_ends[0], axis[r]) * so < 0)
                        & (_o2(pred, v, ends[e], other_ends[1], axis[r]) * so < 0))
        out[r] = hit
    r = np.flatnonzero(n_shared == 0)
    if len(r):
        hit = np.zeros(len(r), dtype=bool)
        for own, other in ((t1[r], t2[r]), (t2[r], t1[r])):
            for e in range(3):
                p, q = own[:, e], own[:, (e + 1) % 3]
                so = _o2(pred, p, q, own[:, (e + 2) % 3], axis[r])
                ok = so != 0
                for j in range(3):
                    ok &= _o2(pred, p, q, other[:, j], axis[r]) * so < 0
                hit |= ok
        out[r] = hit
    return out


def _touch_corner(d: np.ndarray) -> np.ndarray:
    """Index of the one corner on the other plane when the two others lie strictly on one side, else -1."""
    out = np.full(len(d), -1)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        hit = (d[:, i] == 0) & (d[:, j] != 0) & (d[:, j] == d[:, k])
        out[hit] = i
    return out


def _alone_corner(d: np.ndarray) -> np.ndarray:
    """Index of a corner strictly on one side with the two others on the other closed side, else -1."""
    out = np.full(len(d), -1)
    for i in (2, 1, 0):                                     # the first such corner wins
        j, k = (i + 1) % 3, (i + 2) % 3
        hit = (d[:, i] != 0) & (d[:, j] * d[:, i] <= 0) & (d[:, k] * d[:, i] <= 0)
        out[hit] = i
    return out


def _point_in_triangle(pred: _Predicates, apex: np.ndarray, x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Closed test: ``x``, on the plane of ``tri`` (k, 3, 3), lies in ``tri``; ``apex`` is off that plane."""
    s = [pred.orient3d(apex, x, tri[:, e], tri[:, (e + 1) % 3]) for e in range(3)]
    s0, s1, s2 = s
    return ((s0 >= 0) & (s1 >= 0) & (s2 >= 0)) | ((s0 <= 0) & (s1 <= 0) & (s2 <= 0))


def _transversal(t1: np.ndarray, t2: np.ndarray, d1: np.ndarray, d2: np.ndarray, same: np.ndarray,
                 n_shared: np.ndarray, pred: _Predicates) -> np.ndarray:
    """Pairs in distinct planes, each touching the other's plane, sharing at most one corner."""
    kind = np.zeros(len(t1), dtype=np.int8)
    touch1, touch2 = _touch_corner(d1), _touch_corner(d2)
    # one triangle meets the other's plane in a single corner: at most a contact there
    for touch, s, o in ((touch1, t1, t2), (touch2, t2, t1)):
        r = np.flatnonzero((touch >= 0) & (n_shared == 0) & (kind == _NONE))
        if len(r):
            i = touch[r]
            apex = s[r, (i + 1) % 3]
            inside = _point_in_triangle(pred, apex, s[r, i], o[r])
            kind[r[inside]] = _CONTACT
    general = np.flatnonzero((touch1 < 0) & (touch2 < 0))
    if not len(general):
        return kind
    t1, t2, d1, d2 = t1[general], t2[general], d1[general], d2[general]
    rows = np.arange(len(general))
    # Guigue and Devillers' canonical form: p1 alone on the positive side of t2's plane (q1, r1 on the closed
    # negative side), p2 likewise for t1's plane; swapping q and r of one triangle flips the other's signs.
    i1 = _alone_corner(d1)
    p1, q1, r1 = t1[rows, i1], t1[rows, (i1 + 1) % 3], t1[rows, (i1 + 2) % 3]
    flip2 = d1[rows, i1] < 0
    order2 = np.where(flip2[:, None], [0, 2, 1], [0, 1, 2])
    t2c = t2[rows[:, None], order2]
    d2c = d2[rows[:, None], order2]
    i2 = _alone_corner(d2c)
    p2, q2, r2 = t2c[rows, i2], t2c[rows, (i2 + 1) % 3], t2c[rows, (i2 + 2) % 3]
    flip1 = d2c[rows, i2] < 0
    q1, r1 = np.where(flip1[:, None], r1, q1), np.where(flip1[:, None], q1, r1)
    # s1 = [i, j] with i on p1q1, j on p1r1; s2 = [k, l] likewise; on the common line they meet iff
    # k ≤ j and i ≤ l, which are the signs of these two determinants (zero iff the endpoints coincide)
    low = pred.orient3d(p1, q1, p2, q2)                   # ≤ 0 iff k ≤ j
    high = -pred.orient3d(p1, r1, p2, r2)                 # ≤ 0 iff i ≤ l  (= orient3d(p1, r1, r2, p2))
    meet = (low <= 0) & (high <= 0)
    positive = (low < 0) & (high < 0)                      # both segments have positive length here
    proper1 = np.count_nonzero(d1 == 0, axis=1) < 2        # not an edge lying in the other plane
    proper2 = np.count_nonzero(d2 == 0, axis=1) < 2
    crossing = positive & proper1 & proper2
    shared = n_shared[general] > 0
    contact = ~crossing & np.where(shared, positive, meet)
    sub = np.zeros(len(general), dtype=np.int8)
    sub[crossing] = _CROSSING
    sub[contact] = _CONTACT
    kind[general] = sub
    return kind


def _coplanar(t1: np.ndarray, t2: np.ndarray, axis: np.ndarray, same: np.ndarray, n_shared: np.ndarray,
              pred: _Predicates) -> np.ndarray:
    """Pairs in one plane: positive-area overlap (by facing), boundary contact, or nothing beyond the shared."""
    k = len(t1)
    keep = _PLANE[axis]                                    # (k, 2)
    A = np.stack([np.take_along_axis(t1[:, i], keep, 1) for i in range(3)], axis=1)
    B = np.stack([np.take_along_axis(t2[:, i], keep, 1) for i in range(3)], axis=1)
    s1 = pred.orient2d(A[:, 0], A[:, 1], A[:, 2])
    s2 = pred.orient2d(B[:, 0], B[:, 1], B[:, 2])
    weak = np.zeros(k, dtype=bool)                         # a line through an edge separates the interiors
    strict = np.zeros(k, dtype=bool)                       # ... separates the closed triangles
    for P, Q, s in ((A, B, s1), (B, A, s2)):
        for e in range(3):
            o = np.stack([pred.orient2d(P[:, e], P[:, (e + 1) % 3], Q[:, j]) * s for j in range(3)], axis=1)
            weak |= np.all(o <= 0, axis=1)
            strict |= np.all(o < 0, axis=1)
    kind = np.zeros(k, dtype=np.int8)
    area = ~weak
    kind[area & (s1 == s2)] = _CROSSING
    kind[area & (s1 != s2)] = _OPPOSITE
    touch = weak & ~strict
    kind[touch & (n_shared == 0)] = _CONTACT
    one = np.flatnonzero(touch & (n_shared == 1))
    if len(one):
        i1 = np.argmax(same[one].any(axis=2), axis=1)       # the shared corner in t1 and in t2
        i2 = np.argmax(same[one].any(axis=1), axis=1)
        v = t1[one, i1]
        vv = A[one, i1]
        along = np.zeros(len(one), dtype=bool)
        for x in (1, 2):
            for y in (1, 2):
                px, py = t1[one, (i1 + x) % 3], t2[one, (i2 + y) % 3]
                collinear = pred.orient2d(vv, A[one, (i1 + x) % 3], B[one, (i2 + y) % 3]) == 0
                # collinear vectors from v point the same way iff their coordinates' signs agree
                agree = np.all(np.sign(px - v) == np.sign(py - v), axis=1)
                along |= collinear & agree
        kind[one[along]] = _CONTACT
    return kind


# -- certified stars ------------------------------------------------------------------------------------------

def _star_ring(v: int, link: np.ndarray) -> tuple[np.ndarray, bool] | None:
    """The ring ``r_0 .. r_k`` of the star of ``v`` from its link edges (k, 2), and whether it is closed
    (``r_k = r_0``); None unless the faces form one edge-connected fan of distinct corners."""
    k = len(link)
    if np.any(link == v) or np.any(link[:, 0] == link[:, 1]):
        return None
    ids, count = np.unique(link, return_counts=True)
    if np.any(count > 2):
        return None
    ends = ids[count == 1]
    if len(ends) not in (0, 2):
        return None
    faces_of: dict[int, list[int]] = {}
    for i, (x, y) in enumerate(link.tolist()):
        faces_of.setdefault(x, []).append(i)
        faces_of.setdefault(y, []).append(i)
    closed = len(ends) == 0
    at = int(link[0, 0]) if closed else int(ends[0])
    face = faces_of[at][0]
    ring = [at]
    used = np.zeros(k, dtype=bool)
    for _ in range(k):
        used[face] = True
        x, y = int(link[face, 0]), int(link[face, 1])
        at = y if x == at else x
        ring.append(at)
        nxt = [g for g in faces_of[at] if not used[g]]
        if not nxt:
            break
        face = nxt[0]
    if not used.all() or len(ring) != k + 1 or (closed and ring[-1] != ring[0]):
        return None
    return np.array(ring, dtype=np.int64), closed


def _certified_stars(v: np.ndarray, f: np.ndarray, min_faces: int, pred: _Predicates) -> np.ndarray:
    """(n,) bool: the vertices whose star (at least ``min_faces`` faces) is certified (module docstring,
    "Stars"): one fan whose projection along some coordinate axis turns round the vertex once without overlap
    (a closed fan) or less than once (an open one), every projected triangle strictly of one orientation."""
    cert = np.zeros(len(v), dtype=bool)
    if min_faces <= 0 or not len(f):
        return cert
    valence = np.bincount(f.reshape(-1), minlength=len(v))
    for c in np.flatnonzero(valence >= min_faces).tolist():
        rows, corner = np.nonzero(f == c)
        link = np.stack([f[rows, (corner + 1) % 3], f[rows, (corner + 2) % 3]], axis=1)
        found = _star_ring(c, link)
        if found is None:
            continue
        ring, closed = found
        k = len(ring) - 1
        for axis in range(3):
            keep = _PLANE[axis]
            centre = np.repeat(v[c, keep][None, :], k, axis=0)
            p, q = v[ring[:-1]][:, keep], v[ring[1:]][:, keep]
            r0 = np.repeat(v[ring[0], keep][None, :], k, axis=0)
            turn = pred.orient2d(centre, p, q)
            if turn[0] == 0 or np.any(turn != turn[0]):
                continue
            s = int(turn[0])
            passes = (s * pred.orient2d(centre, p, r0) > 0) & (s * pred.orient2d(centre, r0, q) >= 0)
            if int(np.count_nonzero(passes)) == (1 if closed else 0):
                cert[c] = True
                break
    return cert


def _star_pairs(f: np.ndarray, a: np.ndarray, b: np.ndarray, cert: np.ndarray) -> np.ndarray:
    """(k,) bool: the pairs of faces ``a, b`` sharing a certified vertex (both in its star)."""
    fa, fb = f[a], f[b]
    shared = np.zeros(len(a), dtype=bool)
    for i in range(3):
        hit = cert[fa[:, i]]
        shared |= hit & ((fa[:, i] == fb[:, 0]) | (fa[:, i] == fb[:, 1]) | (fa[:, i] == fb[:, 2]))
    return shared


# -- broad phase ----------------------------------------------------------------------------------------------

def _cells(faces: np.ndarray, lo: np.ndarray, hi: np.ndarray, origin: np.ndarray, h: float,
           dims: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Grid entries (face, cell key) of ``faces`` on cells of side ``h`` covering their boxes."""
    i0 = np.floor((lo[faces] - origin) / h).astype(np.int64)
    i1 = np.floor((hi[faces] - origin) / h).astype(np.int64)
    span = i1 - i0 + 1
    count = span[:, 0] * span[:, 1] * span[:, 2]
    which = np.repeat(np.arange(len(faces)), count)
    k = np.arange(len(which)) - np.repeat(np.cumsum(count) - count, count)
    sy, sz = span[which, 1], span[which, 2]
    key = ((i0[which, 0] + k // (sy * sz)) * dims[1] + i0[which, 1] + (k // sz) % sy) * dims[2] \
        + i0[which, 2] + k % sz
    return faces[which], key


def _home(a: np.ndarray, b: np.ndarray, lo: np.ndarray, origin: np.ndarray, h: float,
          dims: np.ndarray) -> np.ndarray:
    """Cell key (side ``h``) of the low corner of the intersection of the boxes of faces a and b."""
    c = np.floor((np.maximum(lo[a], lo[b]) - origin) / h).astype(np.int64)
    key: np.ndarray = (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
    return key


def _chunks(per_entry: np.ndarray, chunk: int) -> Iterator[tuple[int, int]]:
    """Ranges of entries whose pair counts add up to at most ``chunk`` (or one entry when it alone is more)."""
    total = np.cumsum(per_entry)
    start = 0
    n = len(per_entry)
    while start < n:
        base = total[start - 1] if start else 0
        stop = int(np.searchsorted(total, base + chunk, side="right"))
        stop = max(stop, start + 1)
        yield start, stop
        start = stop


_Raw = tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray]


def _raw_pairs(lo: np.ndarray, hi: np.ndarray, origin: np.ndarray, chunk: int,
               group: np.ndarray | None = None) -> Iterator[_Raw]:
    """Chunks ``(a, b, cell, h, dims)`` of face pairs sharing grid cell ``cell`` (side ``h``): a superset of the
    pairs whose closed boxes meet, each of which appears exactly once with ``cell`` its home (see
    :func:`_keep_mask`), but pairs of faces of one nonnegative ``group`` (m,) int64, which are not generated
    (faces holding one certified vertex: their pairs are within its star; negative groups are one face each)."""
    m = len(lo)
    if m < 2:
        return
    size = float(np.max(hi.max(axis=0) - origin))
    d = hi - lo
    extent = np.max(d, axis=1)
    h0 = max(2.0 * float(np.median(extent)), size / 4096)
    if not h0 > 0:                                        # every face a point at one place
        h0 = 1.0
    level = np.ceil(np.log2(np.maximum(extent, h0) / h0)).astype(np.int64)
    if group is None:
        group = -1 - np.arange(m, dtype=np.int64)         # every face its own group: nothing left out
    # group + shift in [1, 2·shift − 1]: the (cell rank, group) keys below stay ordered.  A group is a vertex
    # index, which can exceed the face count (unwelded files, vertices no face uses): m + 1 alone was too
    # small there and the keys of one cell ran into the next's (pairs missed, or negative counts)
    shift = max(m, int(group.max())) + 1
    for top in np.unique(level):
        h = h0 * 2.0 ** top
        dims = np.full(3, int(np.floor(size / h)) + 2, dtype=np.int64)
        fb, kb = _cells(np.flatnonzero(level == top), lo, hi, origin, h, dims)
        order = np.lexsort((group[fb], kb))               # by cell, then by group within a cell
        fb, kb = fb[order], kb[order]
        gb = group[fb]
        starts = np.flatnonzero(np.r_[True, kb[1:] != kb[:-1]])
        run = np.diff(np.r_[starts, len(kb)])
        cell_end = np.repeat(starts + run, run)
        gstarts = np.flatnonzero(np.r_[True, (kb[1:] != kb[:-1]) | (gb[1:] != gb[:-1])])
        grun = np.diff(np.r_[gstarts, len(kb)])
        after = np.repeat(gstarts + grun, grun)           # first entry of the cell past the entry's own group
        later = cell_end - after
        for s0, s1 in _chunks(later, chunk):
            n = later[s0:s1]
            first = np.repeat(np.arange(s0, s1), n)
            offset = np.arange(len(first)) - np.repeat(np.cumsum(n) - n, n)
            yield fb[first], fb[after[first] + offset], kb[first], h, dims
        # the smaller levels' faces through this level's grid (partners in the cell but those of their group)
        fa, ka = _cells(np.flatnonzero(level < top), lo, hi, origin, h, dims)
        left = np.searchsorted(kb, ka, side="left")
        right = np.searchsorted(kb, ka, side="right")
        rank = np.cumsum(np.r_[True, kb[1:] != kb[:-1]]) - 1          # cell rank of each entry
        combined = rank * (2 * shift) + gb + shift                     # nondecreasing along the entries
        ga = group[fa] + shift
        inside = right > left
        query = np.where(inside, rank[np.minimum(left, len(kb) - 1)], 0) * (2 * shift) + ga
        g_lo = np.where(inside, np.searchsorted(combined, query, side="left"), left)
        g_hi = np.where(inside, np.searchsorted(combined, query, side="right"), left)
        before = g_lo - left
        count = before + (right - g_hi)
        for s0, s1 in _chunks(count, chunk):
            n = count[s0:s1]
            offset = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
            lo_part = np.repeat(left[s0:s1], n) + offset
            b4 = np.repeat(before[s0:s1], n)
            partner = np.where(offset < b4, lo_part, np.repeat(g_hi[s0:s1], n) + (offset - b4))
            yield np.repeat(fa[s0:s1], n), fb[partner], kb[partner], h, dims


def _keep_mask(a: np.ndarray, b: np.ndarray, cell: np.ndarray, lo: np.ndarray, hi: np.ndarray, origin: np.ndarray,
               h: float, dims: np.ndarray) -> np.ndarray:
    """Raw pairs that are candidates: distinct faces, closed boxes meeting, ``cell`` the pair's home."""
    ok: np.ndarray = (a != b) & np.all(lo[a] <= hi[b], axis=1) & np.all(lo[b] <= hi[a], axis=1)
    r = np.flatnonzero(ok)
    ok[r] = _home(a[r], b[r], lo, origin, h, dims) == cell[r]
    return ok


_Scan = tuple[np.ndarray, np.ndarray, np.ndarray, int, int, bool]


def _scan_numpy(v: np.ndarray, f: np.ndarray, axis: np.ndarray, degenerate: np.ndarray, lo: np.ndarray,
                hi: np.ndarray, max_pairs: int | None, chunk: int, pred: _Predicates, cert: np.ndarray) -> _Scan:
    """Pairs that meet (a, b, kind), candidate and tested counts, completeness: the grid and numpy twin
    (pairs within the star of a vertex ``cert`` marks are left out)."""
    found_a, found_b, found_k = [], [], []
    candidates = tested = 0
    complete = True
    origin = lo.min(axis=0)
    group = None
    if cert.any():                          # faces holding a certified vertex, grouped by their first such vertex
        held = cert[f]
        first = np.argmax(held, axis=1)
        group = np.where(held.any(axis=1), f[np.arange(len(f)), first], -1 - np.arange(len(f)))
    for a, b, cell, h, dims in _raw_pairs(lo, hi, origin, chunk, group):
        keep = _keep_mask(a, b, cell, lo, hi, origin, h, dims)
        a, b = a[keep], b[keep]
        if cert.any():
            star = _star_pairs(f, a, b, cert)
            a, b = a[~star], b[~star]
        if max_pairs is not None and candidates + len(a) > max_pairs:
            take = max(max_pairs - candidates, 0)
            a, b = a[:take], b[:take]
            complete = False
        candidates += len(a)
        ok = ~degenerate[a] & ~degenerate[b]
        a, b = np.minimum(a[ok], b[ok]), np.maximum(a[ok], b[ok])
        tested += len(a)
        if len(a):
            kind = _classify(v, f, axis, a, b, pred)
            hit = kind != _NONE
            found_a.append(a[hit])
            found_b.append(b[hit])
            found_k.append(kind[hit])
        if not complete:
            break
    if not found_a:
        e = np.zeros(0, dtype=np.int64)
        return e, e, np.zeros(0, dtype=np.int8), candidates, tested, complete
    return np.concatenate(found_a), np.concatenate(found_b), np.concatenate(found_k), candidates, tested, complete


def _scan_c(lib: ModuleType, v: np.ndarray, f: np.ndarray, max_pairs: int | None, pred: _Predicates,
            star_faces: int, patches: bool) -> tuple[_Scan, np.ndarray, np.ndarray]:
    """The same from the C extension's hierarchy of boxes (pairs it leaves, kind -1, decided on numpy), with the
    per-face projection axes and zero-area flags it computed."""
    raw_a, raw_b, raw_kind, candidates, tested, exact, complete, raw_axis, raw_skip = lib.contact_scan(
        v, f, -1 if max_pairs is None else int(max_pairs), threads(), star_faces, patches)
    pred.exact += exact
    axis = np.frombuffer(raw_axis, dtype=np.int8)           # views of the C bytes: no 9-byte-per-face copies
    degenerate = np.frombuffer(raw_skip, dtype=np.uint8).view(bool)
    a = np.frombuffer(raw_a, dtype=np.int64)
    b = np.frombuffer(raw_b, dtype=np.int64)
    kind = np.frombuffer(raw_kind, dtype=np.int8).copy()
    left = np.flatnonzero(kind < 0)
    if len(left):                       # an expansion too long for the C kernel
        kind[left] = _classify(v, f, axis.astype(np.intp), a[left], b[left], pred)
    return (a, b, kind, int(candidates), int(tested), bool(complete)), axis, degenerate


# -- entry point ----------------------------------------------------------------------------------------------

def surface_contacts(vertices: np.ndarray, faces: np.ndarray, *, max_pairs: int | None = None,
                     chunk: int = CHUNK_PAIRS, _star_faces: int = STAR_MIN_FACES,
                     _patches: bool = True) -> SurfaceContacts:
    """Every pair of faces that meets beyond the vertices and edges it shares by index, classified exactly.

    Parameters
    ----------
    vertices : (n, 3) float
        Coordinates (any unit; the result does not depend on scale).
    faces : (m, 3) int
        Corner indices; a face's winding gives its normal (right-hand rule).
    max_pairs : int, optional
        Work bound: stop after testing this many candidate pairs (box-overlapping pairs not within one
        certified star); the result is then
        ``complete=False``.  Default: no bound.
    chunk : int
        Candidate pairs generated and tested at once (memory bound, not a work bound).
    _star_faces : int
        Private, for the tests: stars of at least this many faces are certified and their pairs left out
        (module docstring, "Stars"); 0 runs the unpruned scan.  The pairs found do not depend on it.
    _patches : bool
        Private, for the tests: False turns off the C scan's certified patches (module docstring, "Patches"),
        so that its counts are the numpy twin's.  The pairs found do not depend on it.

    Returns
    -------
    SurfaceContacts

    Raises
    ------
    InvalidMeshError
        Non-finite coordinates, or a face index out of range.
    """
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = faces_for_c(faces)          # int32 stays int32 (the C scan reads either; no 24-byte-per-face copy)
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise InvalidMeshError(f"Expected vertices (n, 3) and faces (m, 3), got {v.shape} and {f.shape}")
    largest, smallest = _magnitudes(v) if v.size else (0.0, np.inf)
    if not largest < np.inf:
        raise InvalidMeshError("Expected finite vertex coordinates, found NaN or infinity")
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise InvalidMeshError(f"Expected face indices in 0..{len(v) - 1}, found {f.min()}..{f.max()}")
    if chunk < 1:
        raise ValueError(f"Expected chunk >= 1, got {chunk}")
    safe = largest <= _LARGEST and smallest >= _SMALLEST
    if not safe:
        v, safe = _scaled(v)
    pred = _Predicates(force_exact=not safe)
    lib = accel() if safe else None
    empty = np.zeros((0, 2), dtype=np.intp)
    if not len(f):
        return SurfaceContacts(crossing=empty, coplanar_opposite=empty, contact=empty, complete=True)
    if lib is not None:
        (a, b, kind, candidates, tested, complete), axis, degenerate = _scan_c(lib, v, f, max_pairs, pred,
                                                                               _star_faces, _patches)
    else:
        f = f.astype(np.int64, copy=False)
        axis, degenerate = _face_axes(v, f, pred)
        p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        lo = np.minimum(np.minimum(p0, p1), p2)
        hi = np.maximum(np.maximum(p0, p1), p2)
        del p0, p1, p2
        cert = _certified_stars(v, f, _star_faces, pred)
        a, b, kind, candidates, tested, complete = _scan_numpy(v, f, axis, degenerate, lo, hi, max_pairs, chunk,
                                                               pred, cert)

    if not len(kind):                   # nothing meets (every clean mesh): no masks, stacks or sorts to make
        return SurfaceContacts(crossing=empty, coplanar_opposite=empty, contact=empty,
                               complete=complete, candidate_pairs=candidates, tested_pairs=tested,
                               exact_evaluations=pred.exact, degenerate_faces=int(np.count_nonzero(degenerate)))

    def pairs(key: int) -> np.ndarray:
        hit = kind == key
        p = np.stack([a[hit], b[hit]], axis=1).astype(np.intp)
        return p[np.lexsort((p[:, 1], p[:, 0]))]

    return SurfaceContacts(crossing=pairs(_CROSSING), coplanar_opposite=pairs(_OPPOSITE), contact=pairs(_CONTACT),
                           complete=complete, candidate_pairs=candidates, tested_pairs=tested,
                           exact_evaluations=pred.exact, degenerate_faces=int(np.count_nonzero(degenerate)))
