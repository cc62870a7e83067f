"""Free precession of an axisymmetric body and the Chandler wobble (Chapter 4, "Rigid Body Motion", §4.4.1).

For a torque-free body with ``I1 = I2`` and spin ``ω3`` about its symmetry axis, Euler's equations (4.27)
give ``ω̇1 = −Ω ω2``, ``ω̇2 = Ω ω1`` with

    Ω = ω3 (I3 − I1) / I1,

so the angular velocity circles the symmetry axis, seen from the body, once every ``2π/|Ω|``.  For the Earth
(oblate, ``I3 > I1``) this is the Chandler wobble.  The chapter takes ``I3 − I1`` as "about one part in 300" of
``I1`` and ``ω3`` as 2π per sidereal day and finds "once every 10 months": ``300 × 0.99727 d = 299.2 d``.  With
the measured dynamical ellipticity ``H = (C − A)/C = 3.2738e-3`` (IERS Conventions 2010, Table 1.1), i.e.
``(C − A)/A = 1/304.5``, the rigid-Earth (Euler) period is 303.7 days — also "ten months".  The wobble actually
observed has a period of about 433 days: the Earth is not rigid (elastic yielding and the oceans lengthen it),
which this rigid-body formula does not include.
"""

from __future__ import annotations

import math

from ..errors import UsageError

__all__ = ["free_precession_rate", "free_precession_period", "EARTH_DYNAMICAL_ELLIPTICITY"]

#: ``H = (C − A)/C`` of the Earth, dimensionless (IERS Conventions 2010, Table 1.1: 3.2737949e-3).
EARTH_DYNAMICAL_ELLIPTICITY = 3.2737949e-3


def _check(transverse_moment: float, axial_moment: float, spin: float) -> None:
    for name, value in (("transverse_moment", transverse_moment), ("axial_moment", axial_moment),
                        ("spin", spin)):
        if not math.isfinite(value):
            raise UsageError(f"Expected a finite `{name}`, got {value!r}")
    if not (transverse_moment > 0 and axial_moment > 0):
        raise UsageError(f"Expected positive moments, got I1 = {transverse_moment!r}, I3 = {axial_moment!r}")


def free_precession_rate(transverse_moment: float, axial_moment: float, spin: float) -> float:
    """``Ω = ω3 (I3 − I1)/I1``, rad/s: the body-frame precession rate of ω about the symmetry axis (§4.4.1).

    Parameters
    ----------
    transverse_moment : float
        ``I1 = I2``, kg·m² (any unit: only the ratio enters).
    axial_moment : float
        ``I3``, same unit.
    spin : float
        ``ω3``, rad/s.

    Returns
    -------
    float
        rad/s; positive when ω turns the same way as the spin (oblate body, ``I3 > I1``).
    """
    _check(transverse_moment, axial_moment, spin)
    return spin * (axial_moment - transverse_moment) / transverse_moment


def free_precession_period(transverse_moment: float, axial_moment: float, spin: float) -> float:
    """``2π / |Ω|``, s (``inf`` for ``I1 = I3`` or no spin): e.g. the Chandler period of a rigid Earth.

    Parameters
    ----------
    transverse_moment, axial_moment : float
        ``I1 = I2`` and ``I3`` (same unit, only the ratio enters).
    spin : float
        ``ω3``, rad/s.
    """
    rate = free_precession_rate(transverse_moment, axial_moment, spin)
    return math.inf if rate == 0.0 else 2.0 * math.pi / abs(rate)
