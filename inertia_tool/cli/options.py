"""Range checks of numeric command-line options, with the option's name and the value as typed.

Routing only: the engine checks its own parameters too, but in its own terms (SI, parameter names) and
refuses results that overflow (:class:`~inertia_tool.errors.NonFiniteResultError`); these messages speak the
user's language (``--perturbation must be between 0 and 1 (exclusive), got 2``).

:data:`OPTION_RANGES` is the one table of physically meaningful ranges of the numeric options (SI, after
unit parsing), each with its reason; ``docs/bad-input.md`` prints it.  A value outside is
refused before any work (exit 2, one line naming the option and the accepted range).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import UsageError
from ..tolerances import MAX_SUPPORTED_FACES

__all__ = ["require_range", "OptionRange", "OPTION_RANGES", "check_option", "density_and_mass"]

_RPM = 2 * math.pi / 60          # rad/s per rev/min


@dataclass(frozen=True)
class OptionRange:
    """The accepted values of one numeric option.

    Attributes
    ----------
    low, high : float
        Bounds in SI (``unit``), inclusive; of the magnitude when ``signed``.
    unit : str
        SI unit of the bounds.
    reason : str
        Why these bounds (what lies at each end).
    below : bool
        The upper bound is excluded.
    signed : bool
        A signed quantity (a coordinate, a rate that may be negative): ``|value|`` must be at most ``high``;
        ``low`` is then 0.
    shown : str
        The range as the user usually writes it (e.g. ``"1e-4 to 1e7 rpm"``), when not in SI.
    """

    low: float
    high: float
    unit: str
    reason: str
    signed: bool = False
    shown: str = ""
    below: bool = False

    def text(self) -> str:
        """The accepted range in words, e.g. ``between 0.1 and 1e+05 kg/m³``."""
        def num(x):
            return f"{x:,}" if isinstance(x, int) else f"{x:g}"
        if self.signed:
            rule = f"at most {num(self.high)} {self.unit} in magnitude"
        else:
            rule = f"between {num(self.low)} and {num(self.high)} {self.unit}"
            if self.below:
                rule = f"at least {num(self.low)} and below {num(self.high)} {self.unit}"
        return f"{rule} ({self.shown})" if self.shown else rule


_LENGTH = OptionRange(1e-9, 1e6, "m", "a nanometre (the size of a molecule) to 1000 km")
_COORDINATE = OptionRange(0.0, 1e6, "m", "a point within 1000 km of the mesh origin", signed=True)
_SPEED = OptionRange(1e-4 * _RPM, 1e7 * _RPM, "rad/s", "1e-4 rpm (a turn a week) to 1e7 rpm (beyond the "
                     "fastest machine rotors, ~1e6 rpm)", shown="1e-4 to 1e7 rpm")
_SIGNED_RATE = OptionRange(0.0, 1e7 * _RPM, "rad/s", "as the speeds, either sense, 0 allowed", signed=True,
                           shown="up to ±1e7 rpm")

#: Physically meaningful ranges of the numeric options, SI after unit parsing (docs/bad-input.md prints it).
OPTION_RANGES: dict[str, OptionRange] = {
    "--density": OptionRange(0.1, 1e5, "kg/m³", "below the lightest solids (aerogels, ~0.16 kg/m³) to 4x the "
                             "densest element (osmium, 22,590 kg/m³)"),
    "--mass": OptionRange(1e-12, 1e9, "kg", "a nanogram (a micro-machined part) to a million tonnes"),
    "--radius": _LENGTH,
    "--thickness": _LENGTH,
    "--shell": _LENGTH,
    "--axis-point": _COORDINATE,
    "--planes": _COORDINATE,
    "--bearings": _COORDINATE,
    "--pivot": _COORDINATE,
    "--through": _COORDINATE,
    "--about": _COORDINATE,
    "--wall": _LENGTH,
    "--rpm": _SPEED,
    "--rate": _SPEED,
    "--spin": _SIGNED_RATE,
    "--precession": _SIGNED_RATE,
    "--nutation": _SIGNED_RATE,
    "--duration": OptionRange(1e-6, 1e6, "s", "a microsecond to 11.6 days of simulated motion"),
    "--gravity": OptionRange(1e-6, 1e4, "m/s²", "microgravity to 1000 g"),
    "--merge-tolerance": OptionRange(0.0, 0.1, "(of the bounding-box diagonal)",
                                     "0 turns tolerant welding off; welding across a tenth of the part is "
                                     "no longer rounding noise", below=True),
    "--max-faces": OptionRange(1, MAX_SUPPORTED_FACES, "triangles",
                               "the reader indexes corners with 32-bit integers (3 x faces < 2^31)"),
    "--jobs": OptionRange(1, 1024, "processes", "one process to a large machine"),
}


def _same_number(typed, value) -> bool:
    """Whether what the user typed is already ``value`` (a bare number in the range's unit)."""
    try:
        return float(str(typed)) == value
    except ValueError:
        return False


def check_option(option: str, value, *, typed=None, label: str | None = None):
    """Return ``value`` (a number or a sequence of numbers, SI) if it lies in ``OPTION_RANGES[option]``,
    else raise :class:`UsageError` naming ``option`` (or ``label``), the accepted range and what the user
    typed."""
    rng = OPTION_RANGES[option]
    values = list(value) if isinstance(value, (list, tuple)) else [value]
    for v in values:
        ok = isinstance(v, (int, float)) and math.isfinite(v)
        if ok and rng.signed:
            ok = abs(v) <= rng.high
        elif ok:
            ok = rng.low <= v and (v < rng.high if rng.below else v <= rng.high)
        if not ok:
            si = f"{v:g}" if isinstance(v, (int, float)) else repr(v)
            shown = si if typed is None else str(typed)
            if typed is not None and len(values) == 1 and not _same_number(typed, v):
                shown += f" (= {si} {rng.unit})"            # the value in the unit of the range
            raise UsageError(f"{label or option} must be {rng.text()}, got {shown}")
    return value


def density_and_mass(args) -> tuple[float | None, float | None]:
    """``--density`` and ``--mass`` of ``args`` parsed (units) and checked against :data:`OPTION_RANGES`."""
    from ..units import parse_density, parse_mass
    density = mass = None
    if getattr(args, "density", None) is not None:
        density = check_option("--density", parse_density(args.density), typed=args.density)
    if getattr(args, "mass", None) is not None:
        mass = check_option("--mass", parse_mass(args.mass), typed=args.mass)
    return density, mass


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
            rule = (f"{'>' if low_open else '>='} {low:g}{u}" if low != 0 or not low_open
                    else f"positive{u and ' (' + unit + ')'}")
        elif high is not None:
            rule = f"{'<' if high_open else '<='} {high:g}{u}"
        else:
            rule = "a finite number"
        raise UsageError(f"{option} must be {rule}, got {shown}")
    return value
