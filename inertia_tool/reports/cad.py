"""A CAD-style "Mass properties" report (the layout SolidWorks prints), so users can compare numbers.

Formatting and display units only.  Products of inertia are printed in **positive tensor notation**
(``Lxy = +∫xy dm``), as SolidWorks does, and the report says so; the conversion from the tensor convention
is :func:`inertia_tool.robot.inertial.positive_tensor_notation`.  The "output coordinate system" is the mesh axes
with the mesh origin, or the one given (``analyze --about``/``--axes``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import UsageError
from .numbers import number, round_off_zero

if TYPE_CHECKING:     # numpy loads when a report is formatted, not when a parser lists CAD_UNITS
    import numpy as np

    from ..mass.properties import MassProperties

__all__ = ["format_cad_report", "CAD_UNITS"]

#: Display unit systems: name → (mass unit label, kg→unit factor, length unit label, m→unit factor).
CAD_UNITS = {
    "kg-m": ("kilograms", 1.0, "meters", 1.0),
    "g-mm": ("grams", 1e3, "millimeters", 1e3),
    "kg-mm": ("kilograms", 1.0, "millimeters", 1e3),
    "g-cm": ("grams", 1e3, "centimeters", 1e2),
}

_SHORT = {"kilograms": "kg", "grams": "g", "meters": "m", "millimeters": "mm", "centimeters": "cm"}


def _clean(a, rel: float = 1e-12) -> np.ndarray:
    return round_off_zero(a, rel)


def _g(x: float, digits: int) -> str:
    return number(x, digits)


def _tensor_rows(t, prefix: str, digits: int) -> list[str]:
    axes = "xyz"
    rows = []
    for i in range(3):
        rows.append("\t" + "\t".join(f"{prefix}{axes[i]}{axes[j]} = {_g(t[i, j], digits)}" for j in range(3)))
    return rows


def format_cad_report(props: MassProperties, *, units: str = "kg-m", density_source: str | None = None,
                      digits: int = 8, frame=None) -> str:
    """The SolidWorks-style "Mass properties" text of ``props``.

    Parameters
    ----------
    props : MassProperties
    units : str
        Display units, one of :data:`CAD_UNITS` (``"g-mm"`` is SolidWorks' default, ``"kg-m"`` ours).
    density_source : str, optional
        How the density was chosen (printed as a note).
    digits : int
        Significant digits.
    frame : FrameInertia, optional
        The output coordinate system (``inertia_tool.mass.frame``); default the mesh axes and origin.

    Returns
    -------
    str
    """
    import numpy as np

    from ..robot.inertial import positive_tensor_notation      # imported on use: analyze's parser needs CAD_UNITS
    if units not in CAD_UNITS:
        raise UsageError(f"Expected CAD units among {', '.join(CAD_UNITS)}, got {units!r}")
    mass_name, km, len_name, lm = CAD_UNITS[units]
    mu, lu = _SHORT[mass_name], _SHORT[len_name]
    inertia_unit = f"{mass_name} * square {len_name}"
    ki = km * lm * lm
    pa = props.principal
    if frame is None:
        system = "-- mesh axes and origin --"
        to_frame, origin = np.eye(3), np.zeros(3)
        central_tensor = props.inertia
        about_tensor = np.asarray(props.inertia_about(np.zeros(3), far_point_ratio=None))
    else:
        to_frame, origin = np.asarray(frame.rotation).T, np.asarray(frame.origin)
        system = ("-- origin (" + ", ".join(f"{x:.6g}" for x in origin) + ") m, axes "
                  + "; ".join("(" + ", ".join(f"{x:.6g}" for x in frame.rotation[:, k]) + ")" for k in range(3))
                  + " in mesh coordinates --")
        central_tensor, about_tensor = frame.central_inertia, frame.inertia
    lines = [f"Mass properties of {props.name}",
             f"\tCoordinate system: {system} (output coordinate system)",
             f"\tUnits: {units} ({mu}, {lu}); SI source values from inertia-tool", ""]
    if np.isfinite(props.density):
        lines.append(f"Density = {_g(props.density * km / lm ** 3, digits)} {mass_name} per cubic {len_name[:-1]}"
                     + (f"   ({density_source})" if density_source else ""))
    lines.append("")
    lines.append(f"Mass = {_g(props.mass * km, digits)} {mass_name}")
    lines.append("")
    lines.append(f"Volume = {_g(props.volume * lm ** 3, digits)} cubic {len_name}")
    lines.append("")
    lines.append(f"Surface area = {_g(props.surface_area * lm ** 2, digits)} square {len_name}")
    lines.append("")
    com = _clean(to_frame @ (props.center_of_mass - origin) * lm)
    lines.append(f"Center of mass: ( {len_name} )")
    lines += [f"\t{c} = {_g(x, digits)}" for c, x in zip("XYZ", com)]
    lines.append("")
    lines.append(f"Principal axes of inertia and principal moments of inertia: ( {inertia_unit} )")
    lines.append("Taken at the center of mass.")
    for k, (ax, p) in enumerate(zip("xyz", "xyz")):
        a = _clean(to_frame @ pa.axes[:, k])
        lines.append(f"\t I{ax} = ({', '.join(f'{c:.6f}' for c in a)})   \tP{p} = {_g(pa.moments[k] * ki, digits)}")
    lines.append("")
    notation = ("(Using positive tensor notation: Lxy = +∫xy dm; the inertia tensor element, as in URDF, "
                "is −Lxy.)")
    central = _clean(positive_tensor_notation(central_tensor) * ki)
    lines.append(f"Moments of inertia: ( {inertia_unit} )")
    lines.append("Taken at the center of mass and aligned with the output coordinate system. " + notation)
    lines += _tensor_rows(central, "L", digits)
    lines.append("")
    about = _clean(positive_tensor_notation(about_tensor) * ki)
    lines.append(f"Moments of inertia: ( {inertia_unit} )")
    lines.append("Taken at the output coordinate system. " + notation.replace("Lxy", "Ixy"))
    lines += _tensor_rows(about, "I", digits)
    return "\n".join(lines)
