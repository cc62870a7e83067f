"""Range checks of numeric command-line options, with the option's name and the value as typed.

Routing only: the engine checks its own parameters too, but in its own terms (SI, parameter names); these
messages speak the user's language (``--perturbation must be between 0 and 1 (exclusive), got 2``).
"""

from __future__ import annotations

import math

from ..errors import UsageError

__all__ = ["require_range"]


def require_range(value: float, option: str, *, low: float | None = None, high: float | None = None,
                  low_open: bool = False, high_open: bool = False, typed=None, unit: str = "") -> float:
    """Return ``value`` if it is finite and within the bounds, else raise :class:`UsageError` naming
    ``option`` and what the user typed (``typed``, default ``value``)."""
    shown = typed if typed is not None else f"{value:g}"
    u = f" {unit}" if unit else ""
    ok = isinstance(value, (int, float)) and math.isfinite(value)
    ok = ok and (low is None or (value > low if low_open else value >= low))
    ok = ok and (high is None or (value < high if high_open else value <= high))
    if not ok:
        if low is not None and high is not None:
            rule = f"between {low:g} and {high:g}{u}" + (
                " (exclusive)" if low_open and high_open else " (inclusive)" if not (low_open or high_open) else "")
            if low_open != high_open:
                rule = f"{'>' if low_open else '>='} {low:g} and {'<' if high_open else '<='} {high:g}{u}"
        elif low is not None:
            rule = f"{'>' if low_open else '>='} {low:g}{u}" if low != 0 or not low_open else f"positive{u and ' (' + unit + ')'}"
        elif high is not None:
            rule = f"{'<' if high_open else '<='} {high:g}{u}"
        else:
            rule = "a finite number"
        raise UsageError(f"{option} must be {rule}, got {shown}")
    return value
