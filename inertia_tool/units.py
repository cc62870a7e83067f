"""Units and materials: the boundary where user quantities become SI.

The engine never sees anything but metres, kilograms, seconds and radians.  This module turns
``"mm"``, ``"aluminium"``, ``"5rev/s"``, ``"3000rpm"``, ``"30s"`` or ``"2mm"`` into SI numbers.
"""

from __future__ import annotations

import math
import re

from .errors import MaterialError, UnitsError

#: m/s², the conventional standard acceleration of gravity (3rd CGPM, 1901); ``top``'s default gravity.
STANDARD_GRAVITY = 9.80665

__all__ = ["DECIMAL", "LENGTH_UNITS", "MATERIALS", "length_scale", "material_density", "parse_length",
           "parse_angular_rate", "parse_duration", "parse_mass", "parse_density", "parse_angle", "parse_vector",
           "parse_fraction", "PLAUSIBLE_EXTENT", "PLAUSIBLE_DENSITY", "implausible_extent", "implausible_density",
           "STANDARD_GRAVITY"]

#: Length units accepted for mesh coordinates, as metres per unit.
LENGTH_UNITS = {
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "in": 0.0254,
    "ft": 0.3048,
}
_LENGTH_ALIASES = {"meter": "m", "meters": "m", "metre": "m", "metres": "m", "millimeter": "mm",
                   "millimeters": "mm", "millimetre": "mm", "millimetres": "mm", "centimeter": "cm",
                   "centimeters": "cm", "centimetre": "cm", "centimetres": "cm", "inch": "in", "inches": "in",
                   "foot": "ft", "feet": "ft", "µm": "um", "micron": "um", "microns": "um"}

#: Nominal densities in kg/m³ at room temperature.  Typical handbook values; real alloys and prints vary by a
#: few per cent (printed parts far more, with infill) — pass ``density=`` for a measured value.
MATERIALS = {
    "aluminium": 2700.0,       # pure / 6061-T6: 2700
    "steel": 7850.0,           # carbon steel
    "stainless steel": 8000.0,  # 304/316: 7900-8000
    "cast iron": 7200.0,
    "titanium": 4430.0,        # Ti-6Al-4V
    "brass": 8500.0,
    "bronze": 8800.0,
    "copper": 8960.0,
    "magnesium": 1740.0,
    "lead": 11340.0,
    "tungsten": 19300.0,
    "gold": 19300.0,
    "pla": 1240.0,
    "abs": 1040.0,
    "petg": 1270.0,
    "nylon": 1140.0,           # PA6/PA12: 1010-1150
    "polycarbonate": 1200.0,
    "acrylic": 1180.0,         # PMMA
    "hdpe": 950.0,
    "tpu": 1210.0,
    "carbon fibre composite": 1600.0,
    "oak": 750.0,
    "pine": 500.0,
    "glass": 2500.0,
    "concrete": 2400.0,
    "water": 1000.0,
}
_MATERIAL_ALIASES = {"aluminum": "aluminium", "al": "aluminium", "stainless": "stainless steel",
                     "stainless-steel": "stainless steel", "stainless_steel": "stainless steel",
                     "ss": "stainless steel",
                     "ti": "titanium", "cu": "copper", "pa": "nylon", "pa12": "nylon", "pc": "polycarbonate",
                     "pmma": "acrylic", "cast-iron": "cast iron", "carbon fiber composite": "carbon fibre composite",
                     "cfrp": "carbon fibre composite"}


def length_scale(unit: str) -> float:
    """Metres per ``unit`` (``m``, ``cm``, ``mm``, ``um``, ``in``, ``ft`` and spelled-out aliases)."""
    key = str(unit).strip().lower()
    key = _LENGTH_ALIASES.get(key, key)
    if key not in LENGTH_UNITS:
        raise UnitsError(f"Expected a length unit among {', '.join(LENGTH_UNITS)}, got {unit!r}")
    return LENGTH_UNITS[key]


def material_density(name: str) -> float:
    """Density in kg/m³ of a material from :data:`MATERIALS` (case-insensitive, common aliases accepted)."""
    key = " ".join(str(name).strip().lower().replace("_", " ").split())
    key = _MATERIAL_ALIASES.get(key, key)
    if key not in MATERIALS:
        raise MaterialError(f"Unknown material {name!r}; expected one of: {', '.join(sorted(MATERIALS))} "
                            "(or give a density in kg/m³)")
    return MATERIALS[key]


#: The one grammar of a written number (command-line values, robot files, limits in the environment): a decimal
#: as XML Schema's ``xsd:double`` lexical form (optional sign, ASCII digits with an optional fraction or a
#: fraction alone, optional exponent), without ``INF`` and ``NaN``.  Python's ``float()`` also takes
#: ``1_000``, ``inf``, ``nan`` and non-ASCII digits (``١٢``); none of them is accepted.
DECIMAL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)

_NUM = f"({DECIMAL.pattern})"


def _split(text: str, what: str) -> tuple[float, str]:
    m = re.fullmatch(r"\s*" + _NUM + r"\s*([^\d\s].*?)?\s*", str(text))
    if not m:
        raise UnitsError(f"Expected {what} like '12.5' or '12.5 unit', got {text!r}")
    value = float(m.group(1))
    if not math.isfinite(value):
        raise UnitsError(f"Expected {what} that is a finite number, got {text!r}")
    return value, (m.group(2) or "").strip().lower()


def _parse_with_table(text: str | float, table: dict[str, float], what: str, default_unit: str) -> float:
    """Number with an optional unit from ``table`` (unit → SI factor); a bare number is in ``default_unit``."""
    if isinstance(text, (int, float)):
        value, unit = float(text), default_unit
    else:
        value, unit = _split(text, what)
        unit = unit or default_unit
    if unit not in table:
        raise UnitsError(f"Expected {what} unit among {', '.join(table)}, got {unit!r}")
    return value * table[unit]


def parse_length(text: str | float, default_unit: str = "m") -> float:
    """``"2mm"`` → 0.002 (m).  A bare number is in ``default_unit``."""
    if isinstance(text, (int, float)):
        return float(text) * length_scale(default_unit)
    value, unit = _split(text, "a length")
    return value * length_scale(unit or default_unit)


_RATE = {"rad/s": 1.0, "rad/sec": 1.0, "rev/s": 2 * math.pi, "hz": 2 * math.pi, "rps": 2 * math.pi,
         "rpm": 2 * math.pi / 60.0, "rev/min": 2 * math.pi / 60.0, "deg/s": math.pi / 180.0}


def parse_angular_rate(text: str | float, default_unit: str = "rad/s") -> float:
    """``"5rev/s"`` → 31.4159 (rad/s); accepts rad/s, rev/s, Hz, rps, rpm, rev/min, deg/s."""
    return _parse_with_table(text, _RATE, "an angular-rate", default_unit)


_TIME = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}


def parse_duration(text: str | float, default_unit: str = "s") -> float:
    """``"30s"`` → 30.0, ``"2min"`` → 120.0 (s)."""
    return _parse_with_table(text, _TIME, "a time", default_unit)


_MASS = {"kg": 1.0, "g": 1e-3, "mg": 1e-6, "lb": 0.45359237, "t": 1000.0}


def parse_mass(text: str | float, default_unit: str = "kg") -> float:
    """``"412g"`` → 0.412 (kg); accepts kg, g, mg, lb, t."""
    return _parse_with_table(text, _MASS, "a mass", default_unit)


_DENSITY = {"kg/m3": 1.0, "kg/m^3": 1.0, "g/cm3": 1000.0, "g/cm^3": 1000.0, "g/cc": 1000.0,
            "g/ml": 1000.0, "kg/l": 1000.0, "lb/in3": 27679.9047, "lb/ft3": 16.0184634}


def parse_density(text: str | float, default_unit: str = "kg/m3") -> float:
    """``"7850"`` → 7850.0, ``"1.24g/cm3"`` → 1240.0, ``"7850 kg/m³"`` → 7850.0 (kg/m³).

    Units: kg/m3, g/cm3 (g/cc, g/ml, kg/l), lb/in3, lb/ft3; ``³`` may stand for ``3`` or ``^3`` (the tool
    prints densities as ``kg/m³``, so its own output reads back)."""
    if not isinstance(text, (int, float)):
        text = str(text).replace("³", "3")
    return _parse_with_table(text, _DENSITY, "a density", default_unit)


_ANGLE = {"rad": 1.0, "deg": math.pi / 180.0, "°": math.pi / 180.0, "degree": math.pi / 180.0,
          "degrees": math.pi / 180.0, "mrad": 1e-3, "rev": 2 * math.pi, "turn": 2 * math.pi}


def parse_angle(text: str | float, default_unit: str = "rad") -> float:
    """``"20deg"`` → 0.349 (rad); accepts rad, deg (or °), mrad, rev/turn."""
    return _parse_with_table(text, _ANGLE, "an angle", default_unit)


def parse_vector(text: str, default_unit: str = "m") -> tuple[float, float, float]:
    """``"0,0,-12.5"`` or ``"0,0,-12.5mm"`` → three lengths in m (a unit on any component applies to it;
    a unit after the last one applies to bare components too)."""
    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) != 3 or not all(parts):
        raise UnitsError(f"Expected three comma-separated lengths like '0,0,12.5', got {text!r}")
    trailing = _split(parts[-1], "a length")[1]
    unit = trailing or default_unit
    x, y, z = (parse_length(p, unit) for p in parts)
    return x, y, z


def parse_fraction(text: str | float) -> float:
    """``"20%"`` → 0.2, ``"0.2"`` → 0.2 (a fraction in [0, 1]; a bare number above 1 is refused, not guessed)."""
    if isinstance(text, (int, float)):
        value, unit = float(text), ""
    else:
        value, unit = _split(text, "a fraction")
    if unit in ("%", "percent"):
        value /= 100.0
    elif unit:
        raise UnitsError(f"Expected a fraction like '0.2' or '20%', got {text!r}")
    if not 0.0 <= value <= 1.0:
        raise UnitsError(f"Expected a fraction between 0 and 1 (0% to 100%), got {text!r}")
    return value


# -- plausibility of what the units make of a part ---------------------------------------------------------

#: Largest bounding-box extent (m) that is plausible for a part, lower and upper bound: 0.1 mm (a watch
#: screw is ~0.5 mm) to 20 m (a ship's propeller is ~10 m, a wind-turbine blade 80 m but is not balanced
#: from an STL).  Outside it, when no length unit was given, the file is most likely in mm or inches:
#: a 150 mm part read as metres is 150 m and, in steel, 1.3e8 kg.
PLAUSIBLE_EXTENT = (1e-4, 20.0)

#: Densities (kg/m³) of solid materials, lower and upper bound: rigid foams and balsa (~100) to osmium
#: (22,590, the densest element).  :data:`MATERIALS` lie between 500 and 19,300.  A density implied by a
#: target mass outside this range means a wrong mass, mesh or length unit.
PLAUSIBLE_DENSITY = (100.0, 22_600.0)


def _length_text(metres: float, beyond: float | None = None) -> str:
    """``0.15`` → ``"0.15 m"``, ``1.5e-5`` → ``"0.015 mm"``: a length in the unit that reads best, to 3
    significant digits, or to as many more as it takes to read beyond ``beyond`` (a limit it was found past:
    20.0000019 m is "20.0000019 m", not "20 m", beside "above 20 m")."""
    scale, unit = (1.0, "m") if metres >= 0.1 or metres == 0 else (1e3, "mm") if metres >= 1e-3 else (1e6, "µm")
    for digits in range(3, 18):
        text = f"{metres * scale:.{digits}g}"
        if beyond is None or (float(text) / scale != beyond and (float(text) / scale > beyond) == (metres > beyond)):
            break
    return f"{text} {unit}"


def implausible_extent(extent: float, *, low: float = PLAUSIBLE_EXTENT[0],
                       high: float = PLAUSIBLE_EXTENT[1]) -> str | None:
    """Why a largest bounding-box extent of ``extent`` metres (coordinates read as metres) is implausible for
    a part, and which unit of the file would make it plausible; ``None`` when it is plausible.

    Parameters
    ----------
    extent : float
        Largest side of the bounding box, m, with the coordinates taken as metres.
    low, high : float
        The plausible range, m (default :data:`PLAUSIBLE_EXTENT`).

    Returns
    -------
    str or None
        E.g. ``"largest extent 150 m, above 20 m: if the file is in mm, `units` mm gives 0.15 m"``.
    """
    if not (math.isfinite(extent) and extent > 0) or low <= extent <= high:
        return None
    side = f"above {high:g} m" if extent > high else f"below {_length_text(low)}"
    fits = [(name, extent * scale) for name, scale in LENGTH_UNITS.items()
            if name != "m" and low <= extent * scale <= high]
    # the usual CAD export units first: mm, then in, cm, um, ft
    order = {"mm": 0, "in": 1, "cm": 2, "um": 3, "ft": 4}
    fits.sort(key=lambda item: order.get(item[0], 9))
    shown = _length_text(extent, beyond=high if extent > high else low)
    if not fits:
        return f"largest extent {shown}, {side}: check the mesh and its length `units`"
    name, size = fits[0]
    return (f"largest extent {shown}, {side}: if the file is in {name}, `units` {name} "
            f"gives {_length_text(size)}")


def implausible_density(density: float, *, low: float = PLAUSIBLE_DENSITY[0],
                        high: float = PLAUSIBLE_DENSITY[1]) -> str | None:
    """Why a density (kg/m³) is implausible for a solid (:data:`PLAUSIBLE_DENSITY`), or ``None``."""
    if not math.isfinite(density) or low <= density <= high:
        return None
    side = "below" if density < low else "above"
    return (f"{density:.4g} kg/m³, {side} every solid material ({low:g} to {high:,.0f} kg/m³, foams and balsa "
            "to osmium)")
