"""The bounds of a repaired part carried over to the part hollowed by spin-it.

``spin-it --repair`` designs on the surface the repair made (``mesh.holes``): the part ``P`` it integrates is an
estimate of the true part ``T``, with bounds (:class:`~inertia_tool.mesh.uncertainty.Uncertainty`).  The hollowed
mesh ``P − C`` is integrated exactly, but the part the user holds is ``T − C``: the missing surface is as unknown
after the cavity ``C`` is cut as before.  Every moment is additive and ``C`` is known exactly, so the error of the
hollowed part's moments about any fixed point is the repaired part's error about that point; only the reference
points move (to the hollowed part's centre of mass).  With ``e_V = δm·V_P`` (the bound on ``|V_T − V_P|``), ``δc``
and ``δI`` the repaired part's bounds (centre of mass, m; inertia, relative Frobenius), ``d = |c_P − c_A|`` the
distance between the reported centres of mass before and after, and unit density:

- first moment about ``c_P``: ``|∫_T (x − c_P) − ∫_P (x − c_P)| = V_T |c_T − c_P| ≤ (V_P + e_V) δc =: e_s``;
- about ``c_A``: ``e_s + e_V d``; the hollowed part's centre of mass is within
  ``δc_A = (e_s + e_V d) / (V_A − e_V)`` of the reported ``c_A``;
- inertia about ``c_P``: the repaired part's bound plus the parallel-axis term of its centre's shift,
  ``e_I = δI ‖I_P‖ + (V_P + e_V) √2 δc²`` (``‖|r|²𝟙 − r rᵀ‖_F = √2 |r|²``, Eq. (4.16));
- moved to ``c_A`` (``J(a + b) = J(a) + J(b) + 2(a·b)𝟙 − a bᵀ − b aᵀ`` with ``J(r) = |r|²𝟙 − r rᵀ``, integrated
  over the difference of the two solids): ``e_I + e_V √2 d² + (2√3 + 2) e_s d``;
- about the hollowed part's true centre of mass: ``+ (V_A + e_V) √2 δc_A²``; relative to ``‖I_A‖``.

The hollowed mesh's own float64 integration (certified ``exact``: within ``ROUNDOFF_RTOL``) is added to each.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..mesh.uncertainty import Uncertainty
from ..tolerances import ROUNDOFF_RTOL

__all__ = ["carry_repair_bounds"]

#: ``‖2(a·b)𝟙 − a bᵀ − b aᵀ‖_F ≤ (2√3 + 2)|a||b|`` (the triangle inequality over its three terms).
_CROSS_TERM = 2.0 * math.sqrt(3.0) + 2.0


def hollowed_bounds(before, after) -> Uncertainty:
    """Bounds on the hollowed true part ``T − C`` about the reported hollowed ``after`` (module docstring).

    Parameters
    ----------
    before : MassProperties
        The repaired part ``P``, its ``mesh.uncertainty`` the bounds of ``P`` against ``T``.
    after : MassProperties
        ``P − C`` integrated exactly (same density).

    Returns
    -------
    Uncertainty
        ``mass`` relative, ``center_of_mass`` m, ``inertia`` relative (Frobenius, about the centre of mass),
        ``volume_in_doubt`` m³ (the repaired part's: the cavity takes nothing from the doubt it does not know).
    """
    unc = before.mesh.uncertainty
    v_p, v_a = float(before.volume), float(after.volume)
    e_v = float(unc.mass) * v_p
    dc = float(unc.center_of_mass)
    d = float(np.linalg.norm(np.asarray(before.center_of_mass) - np.asarray(after.center_of_mass)))
    diagonal = float(np.linalg.norm(after.mesh.bbox_max - after.mesh.bbox_min)) if after.mesh is not None else 0.0
    if not (v_a > e_v and math.isfinite(dc) and math.isfinite(float(unc.inertia))):
        return Uncertainty(math.inf, math.inf, math.inf, float(unc.volume_in_doubt))
    norm_p = float(np.linalg.norm(before.inertia)) / float(before.density)
    norm_a = float(np.linalg.norm(after.inertia)) / float(after.density)
    e_s = (v_p + e_v) * dc
    shift = (e_s + e_v * d) / (v_a - e_v)
    e_i = float(unc.inertia) * norm_p + (v_p + e_v) * math.sqrt(2.0) * dc ** 2
    e_i_a = e_i + e_v * math.sqrt(2.0) * d ** 2 + _CROSS_TERM * e_s * d + (v_a + e_v) * math.sqrt(2.0) * shift ** 2
    rel_inertia = e_i_a / norm_a if norm_a > 0 else math.inf
    grow = 1.0 + 1e-12            # the few roundings of the sums above
    return Uncertainty(mass=(e_v / v_a + ROUNDOFF_RTOL) * grow,
                       center_of_mass=(shift + ROUNDOFF_RTOL * diagonal) * grow,
                       inertia=(rel_inertia + ROUNDOFF_RTOL) * grow,
                       volume_in_doubt=float(unc.volume_in_doubt))


def carry_repair_bounds(before, after):
    """``after`` (the hollowed mesh, integrated exactly) as the estimate of the hollowed part it is when
    ``before`` is a repaired estimate: the repaired part's method, certificate and assumptions, the bounds of
    :func:`hollowed_bounds`, and a note saying why.  ``after`` unchanged when ``before`` is proven (no bounds)."""
    report_before = getattr(before, "mesh", None)
    report_after = getattr(after, "mesh", None)
    if report_before is None or report_before.uncertainty is None or report_after is None:
        return after
    bounds = hollowed_bounds(before, after)
    note = ("the hollowed mesh is integrated exactly, but its outer surface is the repair's: the part's missing "
            f"surface leaves {bounds.volume_in_doubt:.3g} m³ in doubt after hollowing as before (bounds carried "
            "over from the repaired part)")
    report = replace(report_after, method=report_before.method, uncertainty=bounds,
                     certificate=report_before.certificate, notes=(*report_after.notes, note))
    return replace(after, mesh=report)
