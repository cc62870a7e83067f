"""What a thin-walled model assumed, for the text and JSON reports of ``analyze``.  Formatting only."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .escape import escape_html

if TYPE_CHECKING:  # pragma: no cover - annotations only; the thin-wall models load when a command uses them
    from ..mass.thinwall import PrintedPart

__all__ = ["model_summary", "format_model_note", "model_section"]


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
                   skin_volume_first_order=printed.skin_volume, offset_coefficient=printed.offset_coefficient,
                   mass_error_estimate=printed.mass_error_estimate, inertia_error_order=printed.inertia_error_order,
                   approximation="first order in the skin thickness s: M = rho[f V + (1-f) A s], "
                                 "I = rho[f I_solid + (1-f) I_shell(s)]; the exact skin volume is "
                                 "A s - K s^2 + O(s^3)")
    return out


def format_model_note(summary: dict) -> str:
    """A few lines stating the model, its parameters and its error (empty for the solid model)."""
    model = summary.get("model")
    if model == "shell":
        return (f"  model: thin shell, wall thickness {summary['thickness'] * 1e3:.6g} mm on the mesh as mid-surface\n"
                "    mass ρ·t·A; exact for flat triangular plates of thickness t (with the t²/12 through-thickness "
                "term);\n    walls curved or bent at radius R err by a relative O((t/R)²), e.g. −(t/R)²/3 for a sphere")
    if model == "printed":
        e = summary["mass_error_estimate"]
        order = summary["inertia_error_order"]
        return (f"  model: printed part, skin {summary['skin'] * 1e3:.6g} mm, infill {100 * summary['infill']:.4g}%\n"
                "    first order in the skin thickness s: M = ρ[f·V + (1−f)·A·s], "
                "I = ρ[f·I_solid + (1−f)·I_shell(s)]\n"
                f"    envelope volume {summary['envelope_volume']:.6g} m³, skin volume A·s "
                f"{summary['skin_volume_first_order']:.6g} m³\n"
                f"    estimated error: the mass is over-counted by about {100 * e:.3g}% "
                f"(second-order edge term K·s², K = {summary['offset_coefficient']:.4g} m); "
                f"inertia error of order {order} (L: part size)")
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
                ("skin volume A·s", f"{summary['skin_volume_first_order']:.6g} m³"),
                ("assumes", "first order in the skin thickness s: M = ρ[f·V + (1−f)·A·s], "
                            "I = ρ[f·I_solid + (1−f)·I_shell(s)]"),
                ("estimated error", f"mass over-counted by about {100 * summary['mass_error_estimate']:.3g} % "
                                    f"(edge term K·s², K = {summary['offset_coefficient']:.4g} m); inertia error of "
                                    f"order {summary['inertia_error_order']}")]
    body = "<table>" + "".join(f'<tr><th>{e(k)}</th><td class="l">{e(v)}</td></tr>' for k, v in rows) + "</table>"
    return HtmlSection("Mass model", body, "model")
