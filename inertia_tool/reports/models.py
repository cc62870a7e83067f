"""What a thin-walled model assumed, for the text and JSON reports of ``analyze``.  Formatting only."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .escape import escape_html
from ..rounding import round_up

if TYPE_CHECKING:  # pragma: no cover - annotations only; the thin-wall models load when a command uses them
    from ..mass.thinwall import PrintedPart

__all__ = ["model_summary", "format_model_note", "model_section", "bounds_words"]


def bounds_words(summary: dict) -> str:
    """``"bounds that hold: mass within 1.2 %, centre of mass within 0.01 mm, inertia within 2.3 %"``."""
    if summary["mass_error_bound"] == 0.0:
        return "exact: the part is solid throughout (no core deeper than the skin, or 100 % infill)"
    return (f"bounds that hold (core integrated on {summary['cell_size'] * 1e3:.3g} mm cells): mass within "
            f"{round_up(100 * summary['mass_error_bound'], 2):.2g} %, centre of mass within "
            f"{round_up(summary['center_of_mass_error_bound'] * 1e3, 2):.2g} mm, inertia within "
            f"{round_up(100 * summary['inertia_error_bound'], 2):.2g} % of the largest moment")


def model_summary(model: str, *, thickness: float | None = None, printed: PrintedPart | None = None) -> dict:
    """JSON-ready description of the mass model (``solid``, ``shell`` or ``printed``), SI."""
    out: dict = {"model": model}
    if model == "shell":
        out.update(thickness=thickness,
                   approximation="mass rho*t*A on the mesh taken as the mid-surface of a wall of constant "
                                 "thickness t; exact for flat triangular plates of thickness t (including the "
                                 "t^2/12 through-thickness term); curved or bent walls (radius R) err by O((t/R)^2)")
    elif model == "printed" and printed is not None:
        out.update(skin=printed.skin, infill=printed.infill, envelope_volume=printed.envelope_volume,
                   core_volume=printed.core_volume, skin_volume=printed.skin_volume,
                   mass_error_bound=printed.mass_error_bound,
                   center_of_mass_error_bound=printed.center_of_mass_error_bound,
                   inertia_error_bound=printed.inertia_error_bound, cell_size=printed.cell_size,
                   approximation="skin = the part less its inward offset by s (points within s of the surface); "
                                 "core = the inward offset, filled to the fraction f: M = rho[V - (1-f) V_core]; "
                                 "the core integrated on cells of the exact signed distance, the bounds hold for "
                                 "any closed mesh")
    return out


def format_model_note(summary: dict) -> str:
    """A few lines stating the model, its parameters and its error (empty for the solid model)."""
    model = summary.get("model")
    if model == "shell":
        return (f"  model: thin shell, wall thickness {summary['thickness'] * 1e3:.6g} mm on the mesh as mid-surface\n"
                "    mass ρ·t·A; exact for flat triangular plates of thickness t (with the t²/12 through-thickness "
                "term);\n    walls curved or bent at radius R err by a relative O((t/R)²), e.g. −(t/R)²/3 for a sphere")
    if model == "printed":
        return (f"  model: printed part, skin {summary['skin'] * 1e3:.6g} mm, infill {100 * summary['infill']:.4g}%\n"
                "    skin = the part less its inward offset by the skin thickness; core = the offset, filled to "
                "the infill fraction\n"
                f"    envelope volume {summary['envelope_volume']:.6g} m³, skin {summary['skin_volume']:.6g} m³, "
                f"core {summary['core_volume']:.6g} m³\n"
                f"    {bounds_words(summary)}")
    return ""


def model_section(summary: dict):
    """The mass model and its assumptions as a section of the HTML report (every model, the solid too)."""
    from .html import HtmlSection
    model = summary.get("model", "solid")
    e = escape_html
    if model == "solid":
        rows = [("model", "solid"),
                ("assumes", "homogeneous material fills the closed surface (exact for the polyhedron: "
                            "closed-form integration over signed tetrahedra)")]
    elif model == "shell":
        rows = [("model", "thin shell (sheet metal, thin-walled part)"),
                ("wall thickness", f"{summary['thickness'] * 1e3:.6g} mm, the mesh is the wall's mid-surface"),
                ("assumes", "mass ρ·t·A; exact for flat triangular plates of thickness t (with the t²/12 "
                            "through-thickness term); walls curved or bent at radius R err by a relative O((t/R)²)")]
    else:
        rows = [("model", "3D-printed part (solid skin around a partly filled core)"),
                ("skin", f"{summary['skin'] * 1e3:.6g} mm"), ("infill", f"{100 * summary['infill']:.4g} %"),
                ("envelope volume", f"{summary['envelope_volume']:.6g} m³"),
                ("skin volume", f"{summary['skin_volume']:.6g} m³"),
                ("core volume", f"{summary['core_volume']:.6g} m³"),
                ("assumes", "skin = the part less its inward offset by the skin thickness; core = the offset, "
                            "filled to the infill fraction: M = ρ[V − (1−f)·V_core]"),
                ("bounds", bounds_words(summary))]
    body = "<table>" + "".join(f'<tr><th>{e(k)}</th><td class="l">{e(v)}</td></tr>' for k, v in rows) + "</table>"
    return HtmlSection("Mass model", body, "model")
