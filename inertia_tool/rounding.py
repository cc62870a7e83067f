"""How a bound is shown: rounded *up* to the digits printed, so that the printed number is still a bound.

A bound printed with ``:.3g`` rounds to the nearest: 14.29 % prints as 14 % at two digits, below the true
difference, and the message then states a bound that does not hold.  Every message, report and warning that
prints a bound or a tolerance within which something was done (mass ±…, centre of mass within … m, vertices
moved by at most … m, the float32 volume rounding, the non-planar quad warning) passes the value through
:func:`round_up` first and formats it with the same number of significant digits.

It lives at the top of the package, below both the mesh reader (warnings) and the report writers, so that
there is one such rule; the formatting itself stays with the caller (``reports/numbers.py`` for reports).
"""

from __future__ import annotations

import math
from decimal import Decimal

from .tolerances import PRINTED_BOUND_RTOL

__all__ = ["round_up"]


def round_up(bound: float, digits: int = 3, *, rtol: float = PRINTED_BOUND_RTOL) -> float:
    """``bound`` rounded up to ``digits`` significant digits (towards +∞), for printing with ``:.{digits}g``.

    Parameters
    ----------
    bound : float
        A non-negative bound (a relative error, a distance, a volume).  0 stays 0; +∞ and NaN are returned as
        they are (the caller prints them as words).
    digits : int
        Significant digits that will be printed (at least 1).
    rtol : float
        ``bound`` is first raised by this share of itself, for the float64 rounding of the computation it came
        from (default ``tolerances.PRINTED_BOUND_RTOL``, 1e-12).

    Returns
    -------
    float
        The smallest float nearest to a decimal of ``digits`` significant digits that is not below
        ``bound · (1 + rtol)``: printed with ``:.{digits}g`` it shows exactly that decimal, and read back it is
        ``>= bound · (1 + rtol)``.  With ``rtol=0`` a bound that already is such a decimal (``0.25``) is returned
        unchanged.

    Raises
    ------
    ValueError
        When ``bound`` is negative (a bound cannot be) or ``digits`` < 1.
    """
    if digits < 1:
        raise ValueError(f"expected at least 1 significant digit, got {digits}")
    x = float(bound)
    if math.isnan(x) or (math.isinf(x) and x > 0):
        return x
    if x < 0:
        raise ValueError(f"expected a bound of at least 0, got {x!r}")
    if x == 0:
        return 0.0
    x *= 1.0 + rtol
    text = f"{x:.{digits - 1}e}"                   # the nearest decimal of that many digits: d.dd…e±XX
    nearest = float(text)
    if nearest >= x:
        return nearest
    # it rounded down: the next decimal up lies at least half a step above x, far more than one ulp
    mantissa, exponent = text.split("e")
    up = Decimal(mantissa) + Decimal(1).scaleb(-(digits - 1))
    return float(f"{up}e{exponent}")
