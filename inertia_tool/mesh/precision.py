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

if TYPE_CHECKING:
    from .read import RawMesh

__all__ = ["conversion_bounds", "float32_rounding", "product_rounding", "volume_rounding_bound",
           "warn_storage_precision"]

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
    trace = float(np.trace(second_moment))
    if not (abs(volume) > bound and trace > 0):
        return float("inf"), float("inf"), float("inf")
    rel = vertices - centroid
    reach = math.sqrt(float(np.max(np.einsum("ij,ij->i", rel, rel)))) + math.sqrt(3.0) * rounding
    return (bound / abs(volume), bound * reach / (abs(volume) - bound),
            math.sqrt(2.0) * bound * reach ** 2 / (2.0 * trace / math.sqrt(3.0)))

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
