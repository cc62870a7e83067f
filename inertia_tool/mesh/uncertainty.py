"""What an estimate is, and when one is worth reporting.

An estimate of the solid behind an open or broken surface (:mod:`~.holes`, :mod:`~.grid_estimate`) carries
moments and an :class:`Uncertainty`.  An estimate whose bound is not finite, or whose mass bound exceeds
``ESTIMATE_MAX_MASS_RTOL`` (50 %), or that encloses no positive volume, is refused (:func:`check_useful`): a
printed mass "within ±297 %" helps no one.

The mass-property bounds (see :class:`Uncertainty`): ``mass`` relative, ``center_of_mass`` as a distance in m,
``inertia`` relative in the Frobenius norm.  With ``δV`` the volume in doubt, ``V`` the estimate, ``D`` the
largest distance from the centre of mass to a point of the doubtful region and ``J = ‖I/ρ‖_F``:
``δm/m = δV/V``, ``δc = δV·D/(V − δV)`` and ``δI/I = (√2 δV D² + (V + δV) δc² · √6) / J`` (a point mass
``δV`` at distance ``D`` has ``‖I‖_F = √2 δV D²``; the shift of the centre adds the parallel-axis term).
The winding estimate sums over its doubtful cells instead (``δV·D → Σ δV_u r_u``, ``δV·D² → Σ δV_u r_u²``,
``r_u`` the distance from the centroid to the farthest point of cell ``u``): the same argument cell by cell,
never wider, and much narrower when most doubt lies near the centre.
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidMeshError
from ..rounding import round_up
from ..tolerances import ESTIMATE_MAX_MASS_RTOL
from ..values import frozen_value

__all__ = ["Uncertainty", "Estimate", "uncertainty_from", "with_roundoff", "check_useful"]


@frozen_value
class Uncertainty:
    """Bounds on mass properties that are estimated rather than exact.

    Attributes
    ----------
    mass : float
        Relative bound on mass (and volume): the true value lies within ``mass · m`` of the reported ``m``.
    center_of_mass : float
        Bound on the distance between the true and the reported centre of mass, m.
    inertia : float
        Relative bound on the inertia tensor about the centre of mass, Frobenius norm.
    volume_in_doubt : float
        m³ of space that may or may not be material.
    """

    mass: float
    center_of_mass: float
    inertia: float
    volume_in_doubt: float


@frozen_value
class Estimate:
    """Unit-density moments of an estimated solid with their bounds.

    Attributes
    ----------
    volume : float
        m³.
    centroid : (3,) float
        m, mesh axes.
    second_moment : (3, 3) float
        ``∫ (x−c)(x−c)ᵀ dV`` about the centroid, m⁵, mesh axes.
    area : float
        Area of the surface as given (before any patch), m².
    uncertainty : Uncertainty
    method : str
        ``"patched"`` or ``"winding"``.
    detail : str
        One line on what was done (loops patched, grid size).
    vertices, faces : arrays
        The closed surface integrated (the patched mesh), or the input for the winding estimate.
    far : float
        Largest distance from ``centroid`` to the region in doubt, m (enters the bounds).
    unbounded : str
        Empty, or why no bound follows (the surface beside a hole contradicts the assumption the bound needs):
        the caller refuses with this reason.
    assumptions : tuple of str
        The names of the assumptions about the missing surface the bound holds under
        (:mod:`~.hole_assumptions`; also stated in ``detail``); empty where the bound assumes nothing of it.
    islands : int
        Holes that are an island in a flat face and kept the ball over their rim (the user did not state
        ``flat-islands``): a refusal for a bound too wide names that option.
    """

    volume: float
    centroid: np.ndarray
    second_moment: np.ndarray
    area: float
    uncertainty: Uncertainty
    method: str
    detail: str
    vertices: np.ndarray
    faces: np.ndarray
    far: float = 0.0
    unbounded: str = ""
    assumptions: tuple[str, ...] = ()
    islands: int = 0


def uncertainty_from(volume: float, centroid: np.ndarray, second_moment: np.ndarray, doubt: float,
                     far: float, *, first_doubt: float | None = None,
                     second_doubt: float | None = None) -> Uncertainty:
    """Bounds from ``doubt`` m³ of undecided space lying within ``far`` m of the centroid (formulas above).

    ``first_doubt`` (m⁴) and ``second_doubt`` (m⁵), when given, replace ``doubt · far`` and ``doubt · far²``:
    bounds on ``∫ |x − c| d|ν|`` and ``∫ |x − c|² d|ν|`` for the difference ``ν`` between the true and the
    estimated material, summed cell by cell (never larger than the products, often much smaller).
    """
    if not volume > 0:
        return Uncertainty(np.inf, np.inf, np.inf, float(doubt))
    inertia = np.trace(second_moment) * np.eye(3) - second_moment
    norm = float(np.linalg.norm(inertia))
    rel_mass = doubt / volume
    first = doubt * far if first_doubt is None else min(first_doubt, doubt * far)
    second = doubt * far ** 2 if second_doubt is None else min(second_doubt, doubt * far ** 2)
    shift = first / (volume - doubt) if doubt < volume else np.inf
    rel_inertia = (np.sqrt(2) * second + (volume + doubt) * shift ** 2 * np.sqrt(6)) / norm \
        if norm > 0 else np.inf
    return Uncertainty(mass=float(rel_mass), center_of_mass=float(shift), inertia=float(rel_inertia),
                       volume_in_doubt=float(doubt))


def with_roundoff(unc: Uncertainty, roundoff: tuple[float, float, float]) -> Uncertainty:
    """``unc`` widened by the float64 round-off of the integration of the estimated solid.

    ``unc`` bounds the distance of the estimated solid's exact moments from the truth; the moments reported are
    that solid's integrals in float64, off by at most ``roundoff`` = ``(volume relative, centroid m, inertia
    relative)`` (:func:`~inertia_tool.integrals.total_roundoff_parts`, the bound the exact path certifies with).
    By the triangle inequality the reported moments are within the sums (review 10: 2 of 300 rotated boxes with a
    lost face were off by ~1e-15 against a stated 6e-16, the rounding of the coordinates alone)."""
    rel_volume, centroid, rel_inertia = roundoff
    return Uncertainty(mass=float(unc.mass + rel_volume), center_of_mass=float(unc.center_of_mass + centroid),
                       inertia=float(unc.inertia + rel_inertia), volume_in_doubt=unc.volume_in_doubt)


def check_useful(estimate_volume: float, unc: Uncertainty, *, source: str, what: str,
                 why: str = "the holes are too large to guess what fills them; close them in a mesh editor",
                 max_mass_rtol: float = ESTIMATE_MAX_MASS_RTOL) -> None:
    """Refuse an estimate that encloses no positive volume or whose bounds say nothing.

    Raises
    ------
    InvalidMeshError
        When ``estimate_volume`` is not positive, a bound is not finite, or the relative mass bound exceeds
        ``max_mass_rtol``; the message says why and what to do.
    """
    if not estimate_volume > 0:
        raise InvalidMeshError(f"{source}: {what} encloses a volume of {estimate_volume:.3g} m³ (expected a "
                               "positive one): the surface does not bound a solid even after repair; close it "
                               "in a mesh editor, or for a sheet use the shell model with a wall `thickness`")
    bounds = (unc.mass, unc.center_of_mass, unc.inertia)
    if not all(np.isfinite(b) for b in bounds) or unc.mass > max_mass_rtol:
        mass = f"±{round_up(100 * unc.mass):.3g} %" if np.isfinite(unc.mass) else "unbounded"
        com = f"within {round_up(unc.center_of_mass):.3g} m" if np.isfinite(unc.center_of_mass) else "unbounded"
        raise InvalidMeshError(f"{source}: {what} cannot be bounded usefully (mass {mass}, centre of mass {com}; "
                               f"an estimate is reported only within ±{100 * max_mass_rtol:g} % mass): {why}",
                               details={"mass_bound": float(unc.mass),
                                        "center_of_mass_bound": float(unc.center_of_mass)})
