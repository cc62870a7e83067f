"""How much the file's own number format limits the answer: float32 coordinates far from the origin.

Binary STL, PLY ``float`` properties, glTF/GLB positions and COLLADA arrays (as pycollada reads them) store
coordinates as IEEE float32, 24 significant bits.  A coordinate of magnitude up to ``M`` is stored with an
error of at most ``δ = ulp32(M)/2`` (half the float32 spacing at ``M``): 0.03 m at a million metres.  The
engine integrates the stored triangles exactly, but they are not the part the author drew; the reader
records ``δ`` (:attr:`~inertia_tool.mesh.read.RawMesh.storage_rounding`) and :func:`warn_storage_precision`
turns it into a bound on the volume.

The bound.  Every corner of the stored mesh lies within ``ε = √3 δ`` (Euclidean) of the drawn corner, so every
point of a stored triangle (a convex combination of its corners) lies within ``ε`` of the same combination
of the drawn corners: the straight-line motion ``x(t) = (1 − t) x_drawn + t x_stored`` from the drawn
surface to the stored one stays inside the union of the ε-neighbourhoods ``N_t`` of the triangles.  A
point's winding number (1 inside the solid, 0 outside) changes only when a moving triangle passes through
it; for one triangle that happens where the signed volume of the point and the three moving corners, a cubic
in ``t``, vanishes: at most three times, and only if the point lies in that triangle's ``N_t``.  So
``|w_stored(x) − w_drawn(x)| ≤ 3 · #{t : x ∈ N_t}`` and, integrating, ``|V_stored − V_drawn| ≤ 3 Σ |N_t|``.
For one triangle of area ``A`` and perimeter ``P`` the ε-neighbourhood is a slab, half-cylinders along the
edges and a ball at the corners (Steiner's formula for a flat convex set): ``2εA + (π/2)ε²P + (4/3)πε³``.
Hence

    |V_stored − V_drawn| ≤ B = 3 Σ_triangles (2 ε A_t + (π/2) ε² P_t + (4/3) π ε³),

to first order ``6√3 δ · area``: for a cube of side ``L``, ``36√3 δ / L`` relative.  (A surface crossed once
per triangle, the usual case when ε is far below the feature size, stays within a third of ``B``.)  It holds
for the drawn part rounded to float32 by any exporter that rounds to nearest; an exporter that first
truncated to fewer digits is beyond what the file can show.

The tolerance weld (review 12's R4).  When the bit-exact weld leaves a surface open, ``resolve.py`` merges
vertices closer than a tolerance onto one of them and integrates the welded polyhedron ``W``.  That is the file's
solid only if no corner moved: a weld across a plate thinner than the tolerance folds the plate's faces onto each
other (a 7 mm × 7 mm × 3 nm box with one face listed twice came out 33 % low, labelled exact).  The assumption
stated for the result: *the file's corners are the truth* — the solid meant is bounded by a closed surface that
the weld maps onto ``W`` and that either (a) is made of the file's faces at the file's corners (faces the weld
collapses, or cancels in pairs, aside: a repeated face), or (b) has ``W``'s faces with each welded vertex at one
of the file's corners merged into it.  Either way the straight-line motion from that surface to ``W`` keeps it
closed (each vertex moves as one), every point of a moving triangle stays within ``δ_f`` (the largest move of
its corners: in (a) a corner's own move ``d_i``, in (b) the largest move ``D_g`` in its vertex's group) of the
same point of the triangle at either end, and the winding-number argument above gives

    |V_meant − V_W| ≤ B_w = max over (a), (b) of 3 Σ_faces (2 δ_f A_f + (π/2) δ_f² P_f + (4/3) π δ_f³),

summed over the faces with ``δ_f > 0`` only (at the file's corners for (a), at ``W``'s for (b)).  The region
between the two solids lies within the box of those faces' corners grown by the largest move, so the centroid
and inertia follow as for any volume in doubt (:func:`~inertia_tool.mesh.uncertainty.uncertainty_from`).  The
certificate (:func:`~inertia_tool.mesh.certify.certify`) keeps ``exact`` only when ``B_w`` with the round-off
stays within ``ROUNDOFF_RTOL``; else the result is an estimate within these bounds, or refused when they are
not useful (a weld that collapses a thin part).
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from .._native import accel, faces_for_c, threads
from ..errors import StoragePrecisionWarning
from ..tolerances import STORAGE_PRECISION_RTOL
from ..rounding import round_up
from ..values import frozen_value

if TYPE_CHECKING:
    from .read import RawMesh
    from .uncertainty import Estimate

__all__ = ["conversion_bounds", "float32_rounding", "product_rounding", "volume_rounding_bound",
           "warn_storage_precision", "WeldSweep", "weld_sweep", "weld_reach", "estimate_with_weld", "weld_note",
           "RoundedRegion", "rounded_region", "combined_regions", "region_shares"]

_CHUNK = 1 << 20


def float32_rounding(magnitude: float) -> float:
    """Largest rounding error of a float32 coordinate of magnitude at most ``magnitude``: half the float32
    spacing at ``magnitude`` (``2^(e−24)`` for ``2^e ≤ magnitude < 2^(e+1)``), in the same unit."""
    m = float(np.float32(abs(magnitude))) if math.isfinite(magnitude) else float("inf")
    return 0.5 * float(np.spacing(np.float32(m)))


def volume_rounding_bound(vertices: np.ndarray, faces: np.ndarray, rounding: float) -> float:
    """The bound ``B`` of the module docstring on the volume change when every coordinate moves by at most
    ``rounding``.

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
    rounding : float
        Per-coordinate bound ``δ``, m.

    Returns
    -------
    float
        m³.
    """
    eps = math.sqrt(3.0) * float(rounding)
    lib = accel()
    if lib is not None:     # the same sums in one pass over the faces, in another order (equal to round-off)
        sums = lib.face_measures(np.ascontiguousarray(vertices, dtype=np.float64), faces_for_c(faces), threads())
        area, perimeter = float(sums[0]), float(sums[1])
    else:
        area = perimeter = 0.0
        for start in range(0, len(faces), _CHUNK):
            tri = vertices[faces[start:start + _CHUNK]]
            ab, ac, bc = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], tri[:, 2] - tri[:, 1]
            area += 0.5 * float(np.linalg.norm(np.cross(ab, ac), axis=1).sum())
            perimeter += float((np.linalg.norm(ab, axis=1) + np.linalg.norm(ac, axis=1)
                                + np.linalg.norm(bc, axis=1)).sum())
    return 3.0 * (2.0 * eps * area + 0.5 * math.pi * eps * eps * perimeter
                  + 4.0 / 3.0 * math.pi * eps ** 3 * len(faces))


def product_rounding(vertices: np.ndarray, scale: float) -> float:
    """Largest error, in the scaled unit, of ``vertices * scale`` rounded to float64 (review 12's R6): 0 when
    ``scale`` is a power of two (the products are exact barring underflow), else half the float64 spacing at the
    largest scaled coordinate (round to nearest)."""
    if not len(vertices) or math.frexp(abs(scale))[0] == 0.5:
        return 0.0
    largest = max(float(np.max(vertices)), -float(np.min(vertices))) * abs(scale)   # no |x| temporary
    return 0.5 * float(np.spacing(largest)) if math.isfinite(largest) else float("inf")


def conversion_bounds(vertices: np.ndarray, faces: np.ndarray, rounding: float, volume: float,
                      centroid: np.ndarray, second_moment: np.ndarray) -> tuple[float, float, float]:
    """What rounding every coordinate by at most ``rounding`` (m; the reader's unit conversion,
    :func:`product_rounding`) may change: ``(volume relative, centroid m, inertia relative)``, as an estimate's
    bounds are stated (:class:`~inertia_tool.mesh.uncertainty.Uncertainty`), for R7's "exact".

    The solids before and after differ only in a region of volume at most ``B`` (:func:`volume_rounding_bound`),
    within ``ρ = R + ε`` of the centroid (``R`` the farthest vertex, ``ε = √3·rounding``).  The volume moves by at
    most ``B``; the centroid by at most ``B·ρ / (|V| − B)`` (a region of volume ``B`` added or taken within ``ρ``);
    the inertia tensor by at most ``√2·B·ρ²`` in Frobenius norm (``‖r²E − r rᵀ‖_F = √2·r²``) against ``‖I‖_F ≥
    tr I / √3 = 2 tr C / √3`` (``C`` the second moment about the centroid).  Zeros when ``rounding`` is 0; infs
    for a flat total."""
    if not rounding > 0:
        return 0.0, 0.0, 0.0
    bound = volume_rounding_bound(vertices, faces, rounding)
    if not (abs(volume) > bound and float(np.trace(second_moment)) > 0):
        return float("inf"), float("inf"), float("inf")
    rel = vertices - centroid
    reach = math.sqrt(float(np.max(np.einsum("ij,ij->i", rel, rel)))) + math.sqrt(3.0) * rounding
    return region_shares(bound, reach, volume, second_moment)


def region_shares(bound: float, reach: float, volume: float,
                  second_moment: np.ndarray) -> tuple[float, float, float]:
    """What a region of volume at most ``bound`` (m³) lying within ``reach`` (m) of the centroid may change in a
    solid of signed ``volume`` (m³) and ``second_moment`` (3, 3) m⁵ about that centroid: ``(volume relative,
    centroid m, inertia relative)``, by the formulas of :func:`conversion_bounds`; infs when ``bound`` is not
    below ``|volume|`` or the solid is flat."""
    trace = float(np.trace(second_moment))
    if not (abs(volume) > bound and trace > 0):
        return float("inf"), float("inf"), float("inf")
    return (bound / abs(volume), bound * reach / (abs(volume) - bound),
            math.sqrt(2.0) * bound * reach ** 2 / (2.0 * trace / math.sqrt(3.0)))


@frozen_value
class RoundedRegion:
    """Where a constructed surface (an arrangement's, :mod:`~.arrange`, :mod:`~.coplanar`) may differ from the
    exact solid it stands for, because its new points were rounded to float64: a region of volume at most
    ``volume``, lying within ``spread`` of the convex hull of ``corners``.

    Kept in absolute units so that R7 judges it against the solid it certifies (:func:`~.certify.certify`), not
    only against the shell it was built for: a cavity cut later makes the same region a larger share.

    Attributes
    ----------
    volume : float
        m³, the bound ``B`` of :func:`volume_rounding_bound` over the faces at moved points (their corners moved by
        at most the tier's ``δ`` a coordinate), summed over tiers and arrangements.
    corners : (k, 3) float
        m, the corners of those faces.
    spread : float
        m, ``√3`` times the largest per-coordinate move: every point of the region lies within it of the faces.
    """

    volume: float
    corners: np.ndarray
    spread: float

    def shares(self, volume: float, centroid: np.ndarray,
               second_moment: np.ndarray) -> tuple[float, float, float]:
        """``(volume relative, centroid m, inertia relative)`` of a solid (``volume`` m³, ``centroid`` (3,) m,
        ``second_moment`` (3, 3) m⁵ about it) that this region may change (:func:`region_shares`, the reach
        being the farthest corner from ``centroid`` plus ``spread``); zeros for an empty region."""
        if not (self.volume > 0 and len(self.corners)):
            return 0.0, 0.0, 0.0
        rel = np.asarray(self.corners, dtype=np.float64) - np.asarray(centroid, dtype=np.float64)
        reach = math.sqrt(float(np.max(np.einsum("ij,ij->i", rel, rel)))) + self.spread
        return region_shares(self.volume, reach, volume, second_moment)


def rounded_region(vertices: np.ndarray, faces: np.ndarray,
                   tiers: list[tuple[np.ndarray, float]]) -> RoundedRegion | None:
    """The :class:`RoundedRegion` of a constructed surface (``vertices`` (n, 3) m, ``faces`` (m, 3) int) whose
    faces ``at`` had corners moved by at most ``delta`` m a coordinate, for each ``(at, delta)`` of ``tiers``
    (the tiers of :func:`~.arrange.rounded_points_bounds`); None when nothing moved."""
    volume, spread, corners = 0.0, 0.0, []
    for at, delta in tiers:
        at = np.asarray(at, dtype=bool)
        if not (at.any() and delta > 0):
            continue
        volume += volume_rounding_bound(vertices, faces[at], delta)
        spread = max(spread, math.sqrt(3.0) * float(delta))
        corners.append(np.asarray(vertices, dtype=np.float64)[np.unique(faces[at])])
    if not corners:
        return None
    return RoundedRegion(volume=volume, corners=np.vstack(corners), spread=spread)


def combined_regions(*regions: RoundedRegion | None) -> RoundedRegion | None:
    """One :class:`RoundedRegion` covering all of ``regions`` (volumes added: the triangle inequality; corners
    together; the largest spread); None when there is none."""
    given = [r for r in regions if r is not None]
    if not given:
        return None
    return RoundedRegion(volume=float(sum(r.volume for r in given)),
                         corners=np.vstack([np.asarray(r.corners, dtype=np.float64) for r in given]),
                         spread=max(r.spread for r in given))

def warn_storage_precision(raw: RawMesh, volume: float, *, rtol: float = STORAGE_PRECISION_RTOL,
                           stacklevel: int = 3) -> float | None:
    """Warn (:class:`~inertia_tool.errors.StoragePrecisionWarning`) when the file's float32 storage limits the
    volume of ``raw`` (a :class:`~inertia_tool.mesh.read.RawMesh`) to worse than ``rtol`` relative.

    Parameters
    ----------
    raw : RawMesh
        As read; ``raw.storage_rounding`` (m) is 0 for formats that store text or float64.
    volume : float
        The volume computed from ``raw``, m³.
    rtol : float
        Relative bound above which to warn (default :data:`~inertia_tool.tolerances.STORAGE_PRECISION_RTOL`).

    Returns
    -------
    float or None
        The relative bound ``B / |V|`` when it warned, else None.
    """
    rounding = float(getattr(raw, "storage_rounding", 0.0))
    if not rounding > 0 or not volume:
        return None
    bound = volume_rounding_bound(raw.vertices, raw.faces, rounding)
    relative = bound / abs(volume)
    if not relative > rtol:
        return None
    extent = float(np.max(np.abs(raw.vertices))) if raw.vertices.size else 0.0
    warnings.warn(StoragePrecisionWarning(
        f"{raw.source}: the file stores coordinates as float32; at coordinates up to {extent:.3g} m each is "
        f"rounded by up to {round_up(rounding):.3g} m, so the volume (and mass) is known only to "
        f"±{round_up(relative, 2):.2g} relative (±{round_up(bound):.3g} m³; the mesh as stored is integrated "
        "exactly). Export the part near the origin, or in a format that stores more digits"), stacklevel=stacklevel)
    return relative


@frozen_value
class WeldSweep:
    """What the tolerance weld moved, for the certificate (the module docstring's ``B_w``).

    Attributes
    ----------
    volume : float
        ``B_w``, m³: bound on the volume between the welded solid and the solid the file's corners bound.
    largest_move : float
        m: the farthest any corner moved (a bound on every ``δ_f``).
    tolerance : float
        m: the weld's distance.
    merged : int
        Vertices merged onto another.
    lo, hi : (3,) float
        m: the box of the corners of the faces the weld moved (at the file's corners and at ``W``'s).
    """

    volume: float
    largest_move: float
    tolerance: float
    merged: int
    lo: np.ndarray
    hi: np.ndarray


def weld_sweep(vertices: np.ndarray, faces: np.ndarray, welded_faces: np.ndarray, representative: np.ndarray,
               tolerance: float) -> WeldSweep | None:
    """``B_w`` of the module docstring for a weld that merged each vertex ``i`` onto ``representative[i]``.

    Parameters
    ----------
    vertices : (n, 3) float
        m, the file's corners (the weld moves none of them in the array: faces are re-indexed).
    faces : (m, 3) int
        The faces before the weld (reading (a)).
    welded_faces : (k, 3) int
        The faces after it, collapsed ones dropped, indices onto representatives (reading (b)).
    representative : (n,) int
        The vertex each vertex was merged onto (itself when it stayed).
    tolerance : float
        m, the weld's distance (for the messages).

    Returns
    -------
    WeldSweep or None
        None when no corner moved by a nonzero distance (repeated records of one point joined).
    """
    v = np.asarray(vertices, dtype=np.float64)
    rep = np.asarray(representative, dtype=np.int64)
    moved = np.flatnonzero(rep != np.arange(len(rep)))
    if not len(moved):
        return None
    columns = [np.ascontiguousarray(v[:, axis]) for axis in range(3)]     # read by every pass below
    move = np.zeros(len(v))
    for start in range(0, len(moved), _CHUNK):       # in blocks: a welded soup moves millions of corners
        block = moved[start:start + _CHUNK]
        onto = rep[block]
        # |step|² summed (x² + z²) + y², the order of einsum("ij,ij->i") on (k, 3) rows (the reading this
        # replaced, bit for bit: tests/test_soup18_speed.py), one column at a time (issue 25, soup18)
        square = np.zeros(len(block))
        for axis in (0, 2, 1):
            step = columns[axis][block] - columns[axis][onto]
            step *= step
            square += step
        move[block] = np.sqrt(square, out=square)
        del square, step                              # (not kept through the sweeps below: the peak is there)
    move *= 1.0 + 1e-12                               # the norms' rounding (a few ulp), covered
    largest = float(move.max())
    if not largest > 0:
        return None
    group = np.zeros(len(v))             # D_g, held by each representative (W's faces use representatives only)
    np.maximum.at(group, rep[moved], move[moved])
    written, box_a = _swept_faces(v, np.asarray(faces), move, columns)            # (a): the file's faces
    joined, box_b = _swept_faces(v, np.asarray(welded_faces), group, columns)     # (b): W's faces
    boxes = [b for b in (box_a, box_b) if b is not None]
    if not boxes:                                     # no face uses a moved corner: nothing changed
        return None
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    return WeldSweep(volume=max(written, joined) * (1.0 + 1e-9), largest_move=largest, tolerance=float(tolerance),
                     merged=len(moved), lo=lo, hi=hi)


def weld_reach(sweep: WeldSweep, centroid: np.ndarray) -> float:
    """m: the farthest point of the region the weld may have changed from ``centroid`` (the farthest corner of
    the moved faces' box, plus the largest move)."""
    corners = np.array([[x, y, z] for x in (sweep.lo[0], sweep.hi[0]) for y in (sweep.lo[1], sweep.hi[1])
                        for z in (sweep.lo[2], sweep.hi[2])])
    rel = corners - np.asarray(centroid, dtype=np.float64)
    return float(np.sqrt(np.max(np.einsum("ij,ij->i", rel, rel)))) + sweep.largest_move


def _swept_faces(vertices: np.ndarray, faces: np.ndarray, reach: np.ndarray,
                 columns: list[np.ndarray] | None = None) -> tuple[float, tuple[np.ndarray, np.ndarray] | None]:
    """``3 Σ (2 δ A + (π/2) δ² P + (4/3) π δ³)`` over the faces whose corners reach ``δ = max reach[corner] > 0``
    (Steiner's formula for a triangle's δ-neighbourhood, times three crossings; module docstring), and the box
    of those faces' corners (None when there are none).

    Each coordinate is read as its own column (one gather per corner and axis, no (k, 3, 3) block) and every
    product and sum is formed in the order ``numpy.cross`` and ``numpy.linalg.norm(·, axis=1)`` form them on
    (k, 3) rows (``|x|² = (x₀² + x₁²) + x₂²``), so the sum is the same bit for bit as theirs (issue 25, soup18:
    ~0.9 → ~0.4 s a call on a welded 1.3M-face soup; ``tests/test_soup18_speed.py`` holds it to that).
    ``columns``: the vertices' three coordinate columns when the caller has them (else copied here); the
    differences overwrite the gathered corners, so a chunk holds no more than the (k, 3, 3) reading did.
    """
    total = 0.0
    lo = hi = None
    if columns is None:
        columns = [np.ascontiguousarray(vertices[:, axis]) for axis in range(3)] if len(faces) else []
    for start in range(0, len(faces), _CHUNK):
        f = faces[start:start + _CHUNK]
        r = reach[f]
        d = np.maximum(np.maximum(r[:, 0], r[:, 1]), r[:, 2])     # (a reduce along axis 1 of 3 is slower)
        hit = d > 0
        if not hit.any():
            continue
        if not hit.all():
            f, d = f[hit], d[hit]
        del r, hit
        # the corners a, b, c of each face, one (k,) array per axis
        a, b, c = ([col[f[:, corner]] for col in columns] for corner in range(3))
        low = np.min([[a[k].min(), b[k].min(), c[k].min()] for k in range(3)], axis=1)     # (NaN kept, as a
        high = np.max([[a[k].max(), b[k].max(), c[k].max()] for k in range(3)], axis=1)    # min of the rows)
        lo = low if lo is None else np.minimum(lo, low)
        hi = high if hi is None else np.maximum(hi, high)
        ab = [q - p for p, q in zip(a, b)]
        ac = [np.subtract(q, p, out=p) for p, q in zip(a, c)]          # (into a's columns)
        bc = [np.subtract(q, p, out=q) for p, q in zip(b, c)]          # (into c's columns)
        del a, b, c
        # ab × ac: each product, then the difference, as numpy.cross forms it
        normal = []
        for p, q in ((1, 2), (2, 0), (0, 1)):
            component = ab[p] * ac[q]
            component -= ab[q] * ac[p]
            normal.append(component)
        area = _row_norm(normal)
        area *= 0.5
        del normal
        perimeter = _row_norm(ab)
        perimeter += _row_norm(ac)
        perimeter += _row_norm(bc)
        del ab, ac, bc
        # 2.0·d·A + (0.5·π)·d·d·P + ((4/3)·π)·d³, each product in the order written there
        swept = 2.0 * d
        swept *= area
        rim = (0.5 * math.pi) * d
        rim *= d
        rim *= perimeter
        swept += rim
        swept += 4.0 / 3.0 * math.pi * d ** 3
        total += 3.0 * float(np.sum(swept))
    return total, (None if lo is None or hi is None else (lo, hi))


def _row_norm(x: list[np.ndarray]) -> np.ndarray:
    """``sqrt((x₀² + x₁²) + x₂²)`` of three (k,) float columns, (k,) float: ``numpy.linalg.norm(·, axis=1)`` of
    the (k, 3) rows they form, bit for bit (numpy sums a row of three squares in that order)."""
    square = x[0] * x[0]
    square += x[1] * x[1]
    square += x[2] * x[2]
    root: np.ndarray = np.sqrt(square, out=square)
    return root


def estimate_with_weld(estimate: Estimate, sweep: WeldSweep | None) -> Estimate:
    """``estimate`` (of a surface the tolerance weld formed) with the weld's ``B_w`` added to its volume in doubt
    and the weld's reach to its ``far`` (triangle inequality: the estimate bounds its distance from the welded
    solid, the weld the welded solid's from the file's); unchanged when ``sweep`` is None."""
    if sweep is None:
        return estimate
    import dataclasses

    from .uncertainty import uncertainty_from
    doubt = float(estimate.uncertainty.volume_in_doubt) + sweep.volume
    far = max(float(estimate.far), weld_reach(sweep, estimate.centroid))
    unc = uncertainty_from(estimate.volume, estimate.centroid, estimate.second_moment, doubt, far)
    return dataclasses.replace(estimate, uncertainty=unc, far=far)


def weld_note(sweep: WeldSweep, relative: float | None = None, *, with_merge: bool = False) -> str:
    """The certificate's note on a weld that moved corners: how far, and what it may change (``relative``: of
    the result, when the weld stays within the round-off budget).  The merge itself (how many vertices, within
    what) is the resolve stage's note on a welded surface; ``with_merge`` says it here instead (a repaired
    estimate, which has no such note)."""
    n = sweep.merged
    merge = (f"{n:,} vert{'ex' if n == 1 else 'ices'} within {round_up(sweep.tolerance):.3g} m of another "
             f"{'was' if n == 1 else 'were'} merged; " if with_merge else "")
    said = merge + (f"the weld moved corners by up to {round_up(sweep.largest_move):.3g} m, so the solid the "
                    f"file's corners bound differs from the welded one by at most {round_up(sweep.volume, 2):.2g} m³ "
                    "(the weld's sweep)")
    if relative is not None:
        said += f", {round_up(relative, 2):.2g} of the result, within the round-off budget"
    return said
