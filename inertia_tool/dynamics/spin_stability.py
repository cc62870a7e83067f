"""Stability of free spin about the principal axes (the ε analysis of §4.4.1) and the major-axis rule.

A torque-free body spinning at ω about principal axis ``k`` with a small transverse perturbation
``ε = (ε_i, ε_j)`` obeys, to first order (Euler's equations, Eq. 4.27, linearised as in §4.4.1)::

    ε̇_i = p ω ε_j,   ε̇_j = q ω ε_i,   p = (I_j − I_k)/I_i,   q = (I_k − I_i)/I_j,

for ``(i, j, k)`` a cyclic permutation of the principal axes, hence ``ε̈ = c ω² ε`` with the coefficient::

    c = p q = (I_i − I_k)(I_k − I_j) / (I_i I_j)         (§4.4.1, generalised to any spin axis)

* ``c < 0`` — **stable**: ε wobbles at ``√(−c) ω`` (spin about the largest or smallest moment).
* ``c > 0`` — **unstable**: ε grows as ``exp(√c ω t)`` (spin about the intermediate moment).
* two moments equal within ``rtol`` and spin about one of them — **marginal**: ``c = 0`` but one of
  ``p, q`` is not, so ε grows *linearly* (the chapter's "slightly unstable").
* all three equal — **neutral**: every axis is a steady spin.
* two moments equal within a stated manufacturing tolerance ``moment_tolerance`` (larger than ``rtol``;
  equal moments included) and spin about one of them — **indifferent** (within tolerance): ``c`` is the
  product of two moment *differences*, and one of them is smaller than the tolerance, so its sign —
  stable wobble or tumble — is not fixed by the design; a real part (a print, a casting) may land on
  either side.

Labels come from a tolerance, but the user-facing numbers do not jump at its edge: ``turns_to_grow``
solves the linearised motion exactly for any ``p, q`` (exponential, linear or bounded), so a nearly
degenerate axis reads "unstable, but a 1e-3 wobble needs 40 000 turns to reach order one" and the
value is continuous as the gap between two moments shrinks through the tolerance into "marginal".

The exact (non-linear) torque-free period of the angular-velocity components is given in closed form
by :func:`polhode_period` (Landau & Lifshitz, *Mechanics*, §37), which the ``spin`` command compares
with a simulation.  Conventions (ascending moments, axes in mesh axes) are in ``docs/conventions.md``.
"""

from __future__ import annotations

import math
import warnings


import numpy as np

from ..values import frozen_value
from ..errors import PhysicalValidityWarning, PhysicsError, UsageError
from ..mass.principal import DEFAULT_EQUAL_RTOL, PrincipalAxes, principal_axes
from ..mass.properties import MassProperties
from ..tolerances import TRIANGLE_INEQUALITY_RTOL

__all__ = ["AxisStability", "StabilityReport", "stability", "polhode_period", "KINDS", "AXIS_NAMES"]

#: The stability classes, see ``docs/conventions.md`` ("Spin stability classes").
KINDS = ("stable", "unstable", "marginal", "neutral", "indifferent")

#: Names of the principal axes in ascending order of moment.
AXIS_NAMES = ("minor", "intermediate", "major")


def _cross_coefficients(moments: np.ndarray, index: int) -> tuple[float, float]:
    """``(p, q)`` of the linearised Euler equations about axis ``index`` (see the module docstring)."""
    k = index
    i, j = (k + 1) % 3, (k + 2) % 3        # (i, j, k) cyclic
    mi, mj, mk = moments[i], moments[j], moments[k]
    return float((mj - mk) / mi), float((mk - mi) / mj)


def _growth_argument(p: float, q: float, ratio: float) -> float:
    """Smallest ``x = ω t ≥ 0`` at which the linearised perturbation can first reach ``ratio`` times its
    initial size, or ``inf`` if it never does.

    With both initial components bounded by ε₀ (max norm), the largest reachable component is
    ``ε₀ A(x)`` with ``A = cosh(√c x) + R sinh(√c x)`` (c > 0), ``cos(√−c x) + R sin(√−c x)`` (c < 0, up to
    its maximum ``√(1 + R²)``), or ``1 + max(|p|, |q|) x`` (c = 0), where ``R = max(√|p/q|, √|q/p|)``.
    """
    if ratio <= 1.0:
        return 0.0
    big, small = max(abs(p), abs(q)), min(abs(p), abs(q))
    if big == 0.0:                                   # all moments equal: nothing grows
        return math.inf
    if small == 0.0:                                 # marginal: linear growth
        return (ratio - 1.0) / big
    c = p * q
    root = math.sqrt(abs(c))
    r = math.sqrt(big / small)
    if c > 0:
        # cosh y + R sinh y = ratio  ⇔  (1+R) e^y + (1−R) e^−y = 2 ratio  (a quadratic in e^y)
        a, b = 1.0 + r, 1.0 - r
        ey = (ratio + math.sqrt(ratio * ratio - a * b)) / a
        return math.log(ey) / root
    amplitude = math.hypot(1.0, r)
    if ratio > amplitude:
        return math.inf
    # cos y + R sin y = √(1+R²) cos(y − φ), φ = atan R; first crossing of ratio
    y = math.atan(r) - math.acos(min(1.0, ratio / amplitude))
    return max(0.0, y) / root


@frozen_value
class AxisStability:
    """Stability of steady spin about one principal axis.

    Attributes
    ----------
    index : int
        0, 1, 2 in ascending order of moment (``name`` gives "minor", "intermediate", "major").
    moment : float
        Principal moment about this axis, kg·m² (about the centre of mass for ``MassProperties`` input).
    axis : (3,) float
        Unit vector of the axis, mesh axes (principal frame for bare moments).  Its sign is a convention
        (``docs/conventions.md``); spin in either sense has the same stability.
    kind : str
        One of ``"stable"``, ``"unstable"``, ``"marginal"``, ``"neutral"`` (module docstring).
    coefficient : float
        ``c`` of ``ε̈ = c ω² ε``, dimensionless: ``(I_i − I_k)(I_k − I_j)/(I_i I_j)`` (§4.4.1), computed from
        the moments as given (so it may be a tiny non-zero number for a "marginal" axis).
    cross_coefficients : (float, float)
        ``(p, q)`` of ``ε̇_i = p ω ε_j``, ``ε̇_j = q ω ε_i``; ``c = p q``.
    dissipation_stable : bool
        True when the spin survives slow energy loss at fixed angular momentum (the major-axis rule):
        only the axis (or degenerate plane) of largest moment, where the energy ``L²/2I`` is least.
    """

    index: int
    moment: float
    axis: np.ndarray
    kind: str
    coefficient: float
    cross_coefficients: tuple
    dissipation_stable: bool

    @property
    def name(self) -> str:
        """``"minor"``, ``"intermediate"`` or ``"major"``."""
        return AXIS_NAMES[self.index]

    @property
    def growth_rate_per_unit_spin(self) -> float | None:
        """``√c``: e-folding rate of ε in 1/s per rad/s of spin (unstable axes; ``None`` otherwise)."""
        return math.sqrt(self.coefficient) if self.kind == "unstable" else None

    @property
    def e_folding_turns(self) -> float | None:
        """Spin revolutions per e-fold of the growing mode, ``1/(2π√c)`` (unstable axes; ``None`` otherwise)."""
        return 1.0 / (2.0 * math.pi * math.sqrt(self.coefficient)) if self.kind == "unstable" else None

    @property
    def wobble_frequency_per_unit_spin(self) -> float | None:
        """``√(−c)``: angular frequency of the wobble in rad/s per rad/s of spin (stable axes; else ``None``)."""
        return math.sqrt(-self.coefficient) if self.kind == "stable" else None

    @property
    def wobble_period_turns(self) -> float | None:
        """Spin revolutions per wobble period, ``1/√(−c)`` (stable axes; ``None`` otherwise).

        The wobble period in seconds at spin ω (rad/s) is ``2π / (√(−c) ω)``.
        """
        return 1.0 / math.sqrt(-self.coefficient) if self.kind == "stable" else None

    @property
    def wobble_amplification(self) -> float:
        """Largest factor by which the linearised transverse perturbation can grow while staying bounded,
        ``√(1 + R²)`` with ``R = max(√|p/q|, √|q/p|)`` when ``c < 0``; ``inf`` when it grows without bound
        (``c > 0``, or exactly one of ``p, q`` zero); 1 when ``p = q = 0``.  Computed from the exact ``p, q``:
        near a degenerate pair a "stable" axis can still wobble far (large ``R``)."""
        p, q = self.cross_coefficients
        if p == 0.0 and q == 0.0:
            return 1.0
        if p * q >= 0.0:
            return math.inf
        return math.hypot(1.0, math.sqrt(max(abs(p / q), abs(q / p))))

    def turns_to_grow(self, initial: float = 1e-3, final: float = 1.0) -> float:
        """Spin revolutions until a transverse perturbation can grow from ``initial`` to ``final``.

        Both quantities are relative to the spin (``|ε_i| / ω``).  The linearised equations are solved
        exactly for an initial perturbation with both transverse components at most ``initial`` (the worst
        case over its direction), which reduces to the familiar ``ln(final/initial) / (2π√c)`` when
        ``p = q``, is ``(final/initial − 1) / (2π max(|p|,|q|))`` for linear (marginal) growth, and is
        continuous between the two as a gap between moments closes.  ``inf`` when the perturbation stays
        below ``final`` (stable axes with ``wobble_amplification · initial < final``; neutral axes).

        Parameters
        ----------
        initial : float
            Initial relative perturbation, > 0 (default 1e-3).
        final : float
            Relative size deemed "order one" (default 1).  The linearisation is only an estimate there.

        Returns
        -------
        float
            Number of revolutions of the spin (``ω t / 2π``).
        """
        if not (initial > 0 and math.isfinite(initial)) or not (final > 0 and math.isfinite(final)):
            raise UsageError(f"Expected positive finite `initial` and `final`, got {initial!r}, {final!r}")
        p, q = self.cross_coefficients     # the exact values, whatever the label: no jump at the tolerance
        return _growth_argument(p, q, final / initial) / (2.0 * math.pi)


@frozen_value
class StabilityReport:
    """Spin stability about the three principal axes.

    Attributes
    ----------
    axes : tuple of AxisStability
        One entry per principal axis, ascending moment order (minor, intermediate, major).
    reference_point : (3,) float
        Point the moments are about, m, mesh axes (the centre of mass for ``MassProperties``); zeros for
        bare moments.
    rtol : float
        Relative tolerance (of the largest moment) under which two moments count as equal.
    moment_tolerance : float or None
        Relative manufacturing tolerance (of the largest moment) under which two moments are indistinguishable
        in the made part ("indifferent" axes); None when not stated.
    """

    axes: tuple
    reference_point: np.ndarray
    rtol: float
    moment_tolerance: float | None = None

    @property
    def moments(self) -> np.ndarray:
        """(3,) kg·m², ascending."""
        return np.array([a.moment for a in self.axes])

    @property
    def kinds(self) -> tuple:
        """The three ``kind`` labels, ascending moment order."""
        return tuple(a.kind for a in self.axes)

    @property
    def major_axis(self) -> AxisStability:
        """The axis of largest moment: the one a dissipating body ends up spinning about (major-axis rule)."""
        return self.axes[2]

    @property
    def unstable_axes(self) -> tuple:
        """Entries whose ``kind`` is ``"unstable"`` or ``"marginal"``."""
        return tuple(a for a in self.axes if a.kind in ("unstable", "marginal"))

    def about(self, which) -> AxisStability:
        """The entry for ``which``: 0/1/2 or ``"minor"``, ``"intermediate"``, ``"major"``."""
        if isinstance(which, str):
            key = which.strip().lower()
            if key not in AXIS_NAMES:
                raise UsageError(f"Expected an axis among {', '.join(AXIS_NAMES)}, got {which!r}")
            return self.axes[AXIS_NAMES.index(key)]
        if which not in (0, 1, 2):
            raise UsageError(f"Expected an axis index 0, 1 or 2, got {which!r}")
        return self.axes[int(which)]


def _moments_and_axes(x, rtol: float):
    if isinstance(x, MassProperties):
        pa = principal_axes(x.inertia, reference_point=x.center_of_mass, mass=x.mass, rtol=rtol)
        return np.array(pa.moments, dtype=float), np.array(pa.axes, dtype=float), pa.reference_point
    if isinstance(x, PrincipalAxes):
        return np.array(x.moments, dtype=float), np.array(x.axes, dtype=float), np.array(x.reference_point)
    m = np.asarray(x, dtype=np.float64)
    if m.shape != (3,):
        raise UsageError(f"Expected MassProperties, PrincipalAxes or three moments of shape (3,), got {m.shape}")
    order = np.argsort(m, kind="stable")
    return m[order], np.eye(3)[:, order], np.zeros(3)


def stability(x, *, rtol: float = DEFAULT_EQUAL_RTOL, triangle_rtol: float = TRIANGLE_INEQUALITY_RTOL,
              moment_tolerance: float | None = None) -> StabilityReport:
    """Classify steady spin about each principal axis (§4.4.1) and apply the major-axis rule.

    Parameters
    ----------
    x : MassProperties, PrincipalAxes or (3,) array_like
        The body (its central principal moments are used), principal axes, or three principal moments in
        kg·m² in any order (then ``axis`` is the principal-frame unit vector of each moment as given).
    rtol : float
        Two moments ``I_a, I_b`` count as equal when ``|I_a − I_b| ≤ rtol · max(I)`` (default 1e-6, as
        :data:`inertia_tool.mass.principal.DEFAULT_EQUAL_RTOL`).  This only decides the *label* ("marginal"
        vs "stable"/"unstable"); ``turns_to_grow`` stays continuous across it.
    triangle_rtol : float
        Relative slack for the triangle inequality ``I1 + I2 ≥ I3`` before a ``PhysicalValidityWarning``
        (bare moments and ``PrincipalAxes`` only; ``mass_properties`` already checks bodies it loads).
    moment_tolerance : float, optional
        A manufacturing tolerance on the moments, relative to the largest (e.g. 0.01 for a print).  An axis
        whose moment lies within it of another's (equal ones included) is labelled ``"indifferent"``:
        the sign of ``c`` depends on that difference (§4.4.1), which the made part does not keep.  The
        numbers (``c``, ``turns_to_grow``) stay those of the moments as given.

    Returns
    -------
    StabilityReport

    Raises
    ------
    PhysicsError
        If a moment is not positive (a line or point body has no meaningful spin stability).
    """
    if not (rtol >= 0 and math.isfinite(rtol)):
        raise UsageError(f"Expected a finite `rtol` >= 0, got {rtol!r}")
    if moment_tolerance is not None and not (0 <= moment_tolerance < 1):
        raise UsageError(f"Expected `moment_tolerance` in [0, 1), got {moment_tolerance!r}")
    moments, axes, ref = _moments_and_axes(x, rtol)
    if not np.all(np.isfinite(moments)):
        raise UsageError(f"Expected finite moments, got {moments.tolist()}")
    if not np.all(moments > 0):
        raise PhysicsError(f"Expected three positive principal moments, got {moments.tolist()} kg·m² "
                           "(a body with a zero moment is a line; spin stability is undefined)")
    # (a MassProperties from a mesh was already checked by the pipeline; do not warn twice)
    if not isinstance(x, MassProperties) and moments[0] + moments[1] < moments[2] * (1.0 - triangle_rtol):
        warnings.warn(f"principal moments {moments.tolist()} violate I1 + I2 >= I3; no rigid body has them",
                      PhysicalValidityWarning, stacklevel=2)
    tol = rtol * moments[2]
    eq = [abs(moments[1] - moments[0]) <= tol, abs(moments[2] - moments[1]) <= tol]
    all_equal = abs(moments[2] - moments[0]) <= tol
    stated = moment_tolerance is not None and moment_tolerance > rtol
    made = (moment_tolerance or 0.0) * moments[2]
    near = [stated and abs(moments[1] - moments[0]) <= made, stated and abs(moments[2] - moments[1]) <= made]
    entries = []
    for k in range(3):
        p, q = _cross_coefficients(moments, k)
        c = p * q
        in_pair = (k <= 1 and eq[0]) or (k >= 1 and eq[1])
        in_tolerance = (k <= 1 and near[0]) or (k >= 1 and near[1])
        if in_tolerance:          # the made part need not keep the design's order (or equality) of these moments
            kind = "indifferent"
        elif all_equal:
            kind = "neutral"
        elif in_pair:
            kind = "marginal"
        else:
            kind = "stable" if c < 0 else "unstable"
        # major-axis rule: minimum energy at fixed |L| is spin about the largest moment (or its plane)
        dissipation_stable = all_equal or k == 2 or (k == 1 and eq[1])
        entries.append(AxisStability(index=k, moment=float(moments[k]), axis=axes[:, k].copy(), kind=kind,
                                     coefficient=float(c), cross_coefficients=(p, q),
                                     dissipation_stable=bool(dissipation_stable)))
    for e in entries:
        e.axis.flags.writeable = False
    ref = np.array(ref, dtype=float)
    ref.flags.writeable = False
    return StabilityReport(axes=tuple(entries), reference_point=ref, rtol=float(rtol),
                           moment_tolerance=None if moment_tolerance is None else float(moment_tolerance))


def polhode_period(moments, angular_velocity) -> float:
    """Exact period of the body-frame angular velocity of a torque-free asymmetric body, s.

    Landau & Lifshitz, *Mechanics*, §37 (Euler's equations, Eq. 4.27 with τ = 0, solved by Jacobi
    elliptic functions).  With ``I1 < I2 < I3``, ``2E = Σ I_i ω_i²``, ``L² = Σ I_i² ω_i²``:

    * ``L² > 2E I2`` (polhode around the major axis): ``T = 4 K(m) / s`` with
      ``s² = (I3 − I2)(L² − 2E I1) / (I1 I2 I3)``, ``m = (I2 − I1)(2E I3 − L²) / ((I3 − I2)(L² − 2E I1))``;
    * ``L² < 2E I2`` (around the minor axis): exchange ``I1 ↔ I3``;

    ``K`` is the complete elliptic integral of the first kind with parameter ``m``, evaluated through
    ``1 − m = (I3 − I1)(L² − 2E I2)/((I3 − I2)(L² − 2E I1))`` (through
    :func:`~inertia_tool.dynamics.elliptic.complete_k`) so that orbits near the
    separatrix keep their digits.  For spin near the intermediate axis the body flips twice per period
    (the intermediate-axis, or Dzhanibekov, effect): the interval between flips is ``T/2``.  An
    axisymmetric body (``I1 = I2`` or ``I2 = I3``) gives ``T = 2π/|Ω|``, Ω of §4.4.1.

    Parameters
    ----------
    moments : (3,) array_like
        Principal moments, kg·m², ascending (equal neighbours allowed, not all three equal).
    angular_velocity : (3,) array_like
        Initial angular velocity in the principal frame (components along the ascending axes), rad/s.

    Returns
    -------
    float
        Period in s; ``inf`` on the separatrix (``L² = 2E I2`` exactly) or for a steady spin.
    """
    m_ = np.asarray(moments, dtype=np.float64)
    w = np.asarray(angular_velocity, dtype=np.float64)
    if m_.shape != (3,) or w.shape != (3,):
        raise UsageError(f"Expected `moments` and `angular_velocity` of shape (3,), got {m_.shape}, {w.shape}")
    if not (np.all(m_ > 0) and np.all(np.diff(m_) >= 0)):
        raise UsageError(f"Expected positive ascending moments, got {m_.tolist()}")
    i1, i2, i3 = m_
    if i3 == i1:
        return math.inf
    w2 = w * w
    # the three combinations, each a sum of non-negative terms (no cancellation)
    l_minus_1 = float(np.sum(m_ * (m_ - i1) * w2))        # L² − 2E I1 ≥ 0
    three_minus_l = float(np.sum(m_ * (i3 - m_) * w2))    # 2E I3 − L² ≥ 0
    l_minus_2 = float(np.sum(m_ * (m_ - i2) * w2))        # L² − 2E I2 (either sign)
    if l_minus_2 == 0.0 or l_minus_1 == 0.0 and three_minus_l == 0.0:
        return math.inf
    if l_minus_2 > 0:
        if i3 == i2:
            return math.inf
        rate2 = (i3 - i2) * l_minus_1 / (i1 * i2 * i3)
        one_minus_m = (i3 - i1) * l_minus_2 / ((i3 - i2) * l_minus_1)
    else:
        if i2 == i1:
            return math.inf
        rate2 = (i2 - i1) * three_minus_l / (i1 * i2 * i3)
        one_minus_m = (i3 - i1) * (-l_minus_2) / ((i2 - i1) * three_minus_l)
    if rate2 <= 0:
        return math.inf
    one_minus_m = min(max(one_minus_m, 0.0), 1.0)
    from .elliptic import complete_k   # scipy.special on first use: `analyze` never needs it
    return 4.0 * complete_k(one_minus_m) / math.sqrt(rate2)
