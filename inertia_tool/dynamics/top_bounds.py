"""What an estimated part's bounds leave of the heavy symmetric top (§4.4.3; issue 21, notes19).

A repaired surface gives mass properties with bounds (:class:`~inertia_tool.mesh.uncertainty.Uncertainty`): the true
mass within ``δm·M``, the true centre of mass within ``δc`` (m), the true inertia about its own centre of mass within
``δI·‖I_c‖_F`` (Frobenius).  :func:`heavy_top_bounds` carries them to the top's inputs and to the results that are
monotone in them.  Assumption: those three bounds hold for the true part (the estimate's own statement).

The inputs.  About the pivot ``p`` the tensor is ``I_p = I_c + M S(d)``, ``S(d) = |d|² E − d dᵀ``, ``d = c − p``
(parallel-axis theorem, Chapter 4 "Rigid Body Motion", Eq. (4.16)).  With ``|d' − d| ≤ δc`` and ``l = |d|``:
``‖S(d)‖_F = √2 l²`` and ``‖S(d') − S(d)‖_F ≤ (√3 + 1)(2 l δc + δc²)``, so

    ε = δI ‖I_c‖_F + δm M √2 (l + δc)² + M (√3 + 1)(2 l δc + δc²)      bounds ‖I_p' − I_p‖₂.

The symmetry axis ``n = d/l`` turns by at most ``ϑ = asin(δc / l)`` (``δc < l``), a rotation ``R`` with
``‖R − E‖₂ = 2 sin(ϑ/2)``; ``‖Rᵀ I_p R − I_p‖₂ ≤ 2 sin(ϑ/2) Λ`` (``Λ`` the spread of ``I_p``'s eigenvalues).  The
true ``I3 = n'ᵀ I_p' n'`` and the true transverse moments (the eigenvalues of ``I_p'`` on the plane ⊥ ``n'``, the
same as those of ``Rᵀ I_p' R`` on the plane ⊥ ``n``) therefore each lie within

    η = ε + 2 sin(ϑ/2) Λ

of the reported ones (Weyl's inequality on the 2 × 2 block), and so does ``I1``, their mean.  The gravity torque
``M g l`` lies in ``[M(1 − δm) g (l − δc), M(1 + δm) g (l + δc)]``.

The results.  The sleeping-top margin ``I3² ω3² / (4 I1 M g l)`` is monotone in each input, so its range is at the
corners.  The steady precession rates are the roots of ``I1 cos θ φ̇² − I3 ω3 φ̇ + M g l = 0``: where the
discriminant stays positive over the box of inputs (it is monotone in each, so it is checked at the corners) each
root is monotone in each input (``∂r/∂x`` keeps the sign of ``g'(r) = ±√D``), so its range is at the corners too;
where the discriminant changes sign in the box, whether steady precession exists is in doubt.  The symmetric-top
reading needs the two transverse moments equal (and ``n`` a principal axis) within ``rtol``: both the spread and the
off-axis coupling move by at most ``2η``.  The nutation limits, period and the path's kind follow from the same
inputs through the roots of a cubic, not monotonically: they are not bounded here.

Pure functions on SI numbers.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..values import frozen_value
from .top import HeavyTopReport, steady_precession

__all__ = ["HeavyTopBounds", "heavy_top_bounds"]


@frozen_value
class HeavyTopBounds:
    """How far the true part's heavy-top quantities may lie from those reported for an estimated part.

    Attributes
    ----------
    moment : float
        kg·m²: ``η``, the bound on each of ``I1``, ``I3`` and the two transverse moments about the pivot.
    length : float
        m: the bound on ``l`` (the centre of mass's).
    gravity_torque : (float, float)
        N·m: the range of ``M g l``.
    asymmetry : (float, float)
        The range of the true part's larger of (transverse spread, off-axis coupling) over ``I1``.
    symmetric : bool or None
        The true part is a symmetric top within ``rtol`` (True), is not (False), or the bounds do not say (None).
    sleeping_margin : (float, float)
        The range of ``I3² ω3² / (4 I1 M g l)`` (> 1: the upright top is stable).
    steady_possible : bool or None
        Steady precession at ``θ0`` exists for every part within the bounds (True), for none (False), or the
        bounds do not say (None).
    precession_rate_slow, precession_rate_fast : (float, float) or None
        rad/s: the ranges of the steady precession rates at ``θ0``; None where ``steady_possible`` is not True or
        the reported rate is None.
    """

    moment: float
    length: float
    gravity_torque: tuple[float, float]
    asymmetry: tuple[float, float]
    symmetric: bool | None
    sleeping_margin: tuple[float, float]
    steady_possible: bool | None
    precession_rate_slow: tuple[float, float] | None
    precession_rate_fast: tuple[float, float] | None


def heavy_top_bounds(top: HeavyTopReport, *, inertia_com: np.ndarray, inertia_pivot: np.ndarray, mass: float,
                     mass_rtol: float, com_bound: float, inertia_rtol: float,
                     rtol: float = 1e-3) -> HeavyTopBounds | None:
    """The bounds of :class:`HeavyTopBounds` for ``top`` (module docs), or None where they give none: the centre
    of mass may lie at the pivot (``δc ≥ l``), a moment or the mass may vanish within its bound, or a bound is
    not finite.

    Parameters
    ----------
    top : HeavyTopReport
        The reported analysis (:func:`~.top.heavy_top_on_pivot`).
    inertia_com : (3, 3) float
        kg·m², the reported inertia about the centre of mass.
    inertia_pivot : (3, 3) float
        kg·m², the reported inertia about the pivot (mesh axes).
    mass : float
        kg, reported.
    mass_rtol, com_bound, inertia_rtol : float
        ``δm`` (relative), ``δc`` (m), ``δI`` (relative, Frobenius about the centre of mass): the estimate's bounds.
    rtol : float
        The symmetric-top tolerance of :func:`~.top.heavy_top_on_pivot`.
    """
    dm, dc, di = float(mass_rtol), float(com_bound), float(inertia_rtol)
    length, i1, i3 = top.length, top.transverse_moment, top.axial_moment
    if not all(math.isfinite(x) and x >= 0 for x in (dm, dc, di)) or dm >= 1 or dc >= length:
        return None
    eps = (di * float(np.linalg.norm(inertia_com)) + dm * mass * math.sqrt(2.0) * (length + dc) ** 2
           + mass * (math.sqrt(3.0) + 1.0) * (2.0 * length * dc + dc * dc))
    eig = np.linalg.eigvalsh(np.asarray(inertia_pivot, dtype=float))
    turn = math.asin(dc / length)
    eta = eps + 2.0 * math.sin(turn / 2.0) * float(eig[-1] - eig[0])
    if not (math.isfinite(eta) and eta < i1 and eta < i3):
        return None
    g = top.gravity
    torque = (mass * (1.0 - dm) * g * (length - dc), mass * (1.0 + dm) * g * (length + dc))
    both = top.transverse_asymmetry * i1      # reported spread + coupling: at most the sum, at least half of it
    asym = (max(0.0, both / 2.0 - 2.0 * eta) / (i1 + eta), (both + 2.0 * eta) / (i1 - eta))
    symmetric: bool | None = True if asym[1] <= rtol else False if asym[0] > rtol else None
    w = top.omega3
    i1s, i3s = (i1 - eta, i1 + eta), (i3 - eta, i3 + eta)
    if torque[0] > 0:
        margin = ((i3s[0] * w) ** 2 / (4.0 * i1s[1] * torque[1]), (i3s[1] * w) ** 2 / (4.0 * i1s[0] * torque[0]))
    else:                                     # no gravity: no torque, the upright top is stable (margin ∞)
        margin = (math.inf, math.inf)
    roots = [steady_precession(a, b, w, k, top.theta0) for a, b, k in itertools.product(i1s, i3s, torque)]
    exists = [r[0] is not None for r in roots]
    steady: bool | None = True if all(exists) else False if not any(exists) else None
    slow = fast = None
    if steady and top.precession_rate_slow is not None:
        values = [r[0] for r in roots if r[0] is not None]
        slow = (min(values), max(values))
        if top.precession_rate_fast is not None and all(r[1] is not None for r in roots):
            fast_values = [r[1] for r in roots if r[1] is not None]
            fast = (min(fast_values), max(fast_values))
    return HeavyTopBounds(moment=eta, length=dc, gravity_torque=torque, asymmetry=asym, symmetric=symmetric,
                          sleeping_margin=margin, steady_possible=steady, precession_rate_slow=slow,
                          precession_rate_fast=fast)
