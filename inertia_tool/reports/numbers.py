"""The one number formatter of the reports: how a computed value is shown (never what it is).

The writers (text, HTML, CAD, balance, stability, spin-it, the simulator snippets) format numbers here, so a
rule such as "no −0", "a missing value is —" or "round-off zeros print as 0" is made once.  Two places do not,
on purpose or not yet: corrected robot files write ``repr`` (the exact float, not a display), and the robot
audit's text table still formats with its own fixed-width specs (``reports/robot_audit._fmt``: decimals and
percentages, which :func:`number` has no style for).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..tolerances import DISPLAY_ZERO_RTOL

if TYPE_CHECKING:     # numpy loads when a number is formatted, not when a parser lists the choices
    import numpy as np
    from numpy.typing import ArrayLike, NDArray

__all__ = ["number", "round_off_zero"]


def number(x: float | None, digits: int = 6, *, style: str = "general", none: str = "—",
           infinite: str | None = None) -> str:
    """``x`` with ``digits`` significant digits.

    Parameters
    ----------
    x : float or None
        The value.  ``None`` and NaN print as ``none``; ±inf as ``infinite`` (default: ``none``); −0 as 0.
    digits : int
        Significant digits.
    style : str
        ``"general"``: Python's ``g`` format (``0.0219038``, ``1.2e-07``); ``"fixed"``: fixed decimals for
        magnitudes in [1e-3, 1e6) (``64.89``, ``0.2314``) and scientific notation outside.
    none : str
        Text for a missing value.
    infinite : str, optional
        Text for an infinite value (e.g. ``"never"`` for a growth time).
    """
    if x is None:
        return none
    value = float(x)
    if math.isnan(value):
        return none
    if math.isinf(value):
        return infinite if infinite is not None else none
    value += 0.0                                       # −0.0 → 0.0
    if style == "fixed":
        if value == 0:
            return "0"
        if abs(value) >= 1e6 or abs(value) < 1e-3:
            return f"{value:.{digits - 1}e}"
        decimals = max(0, digits - 1 - math.floor(math.log10(abs(value))))
        return f"{value:.{decimals}f}"
    if style != "general":
        raise ValueError(f"Expected style 'general' or 'fixed', got {style!r}")
    return f"{value:.{digits}g}"


def round_off_zero(values: ArrayLike, rel: float = DISPLAY_ZERO_RTOL, scale: float = 0.0) -> NDArray[np.float64]:
    """Display only: entries at most ``rel`` times the largest magnitude (or ``scale``, if larger) become 0.

    Parameters
    ----------
    values : array_like
        The numbers to show.
    rel : float
        Relative size below which an entry is round-off, not data.
    scale : float
        A floor for the reference magnitude (e.g. the part's size for coordinates near zero).
    """
    import numpy as np

    a = np.asarray(values, dtype=float)
    reference = max(float(np.max(np.abs(a))) if a.size else 0.0, scale)
    return np.where(np.abs(a) <= rel * reference, 0.0, a) + 0.0
