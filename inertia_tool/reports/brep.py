"""The STEP/IGES section of ``analyze``: the exact B-rep mass properties are the headline; this section says so and
gives the tessellated mesh's difference from them.

Formatting only; the numbers come from :func:`inertia_tool.mass.brep.compare` (unit density, scaled here by the
density the report uses).
"""

from __future__ import annotations

from ..mass.brep import BrepComparison
from .serialize import to_jsonable
from ..rounding import round_up

__all__ = ["format_brep_comparison", "brep_comparison_dict", "brep_html_section"]


def brep_comparison_dict(cmp: BrepComparison, density: float) -> dict:
    """JSON-ready: exact (B-rep, the headline) and tessellated volume, centre of mass, inertia at ``density``,
    the differences, and how the solid was formed (several solids fused)."""
    m = cmp.mesh
    return to_jsonable({
        "headline": "exact",
        "chord_tolerance": cmp.chord,
        "angular_deflection": cmp.angular_deflection,
        "triangles": cmp.faces,
        "solids": cmp.solids,
        "fusion": cmp.fusion,
        "overlap_volume": cmp.overlap_volume,
        "mesher_open_edges": cmp.first_open_edges,
        "exact": {"volume": cmp.exact.volume, "mass": cmp.exact.volume * density,
                  "center_of_mass": cmp.exact.center_of_mass, "inertia": cmp.exact.inertia * density},
        "tessellation": {"volume": m.volume, "mass": m.volume * density, "center_of_mass": m.center_of_mass,
                         "inertia": m.inertia * density},
        "volume_error": cmp.volume_error,
        "volume_error_bound": cmp.volume_bound,
        "center_of_mass_error": cmp.com_error,
        "inertia_error": cmp.inertia_error,
        "note": "the mass properties above are the exact B-rep's (OpenCASCADE BRepGProp); `tessellation` is the "
                "triangle mesh, whose relative volume error is at most surface area x chord tolerance / volume",
    })


def format_brep_comparison(cmp: BrepComparison, density: float) -> str:
    """Two or three lines under the headline: where the numbers come from, and the tessellation's difference."""
    lines = ["  source: exact B-rep of the CAD file (OpenCASCADE BRepGProp, Gauss integration on its faces)"]
    if cmp.fusion == "fused":
        lines.append(f"    {cmp.solids} solids fused into one (OpenCASCADE boolean union); they overlapped by "
                     f"{cmp.overlap_volume:.6g} m³, counted once")
    elif cmp.fusion == "apart":
        lines.append(f"    {cmp.solids} solids, no two of which meet: the values are their sum")
    elif cmp.fusion == "failed":
        lines.append(f"    {cmp.solids} solids that could not be fused: the values are their sum (overlaps count "
                     "twice)")
    lines.append(
        f"    tessellation ({cmp.faces:,} triangles, chord tolerance {cmp.chord:.3g} m, angular "
        f"{cmp.angular_deflection:g} rad): mass {cmp.mesh.volume * density:.9g} kg, volume off by "
        f"{cmp.volume_error:.2e} (at most {round_up(cmp.volume_bound):.2e} = area × chord / volume), centre of mass by "
        f"{cmp.com_error:.2e} m, inertia by {cmp.inertia_error:.2e} (relative, Frobenius)")
    if cmp.first_open_edges:
        lines.append(f"    the mesher left {cmp.first_open_edges:,} open edges at the angular deflection asked (a "
                     f"T-junction between B-rep faces); tessellated again at {cmp.angular_deflection:.3g} rad")
    return "\n".join(lines)


def brep_html_section(cmp: BrepComparison, density: float):
    """The lines of :func:`format_brep_comparison` as a section of the HTML report."""
    from .escape import escape_html
    from .html import HtmlSection
    lines = format_brep_comparison(cmp, density).splitlines()
    items = "".join(f"<li>{escape_html(line.strip())}</li>" for line in lines)
    return HtmlSection("CAD B-rep and its tessellation", f"<ul>{items}</ul>", "brep")
