"""The STEP/IGES section of ``analyze``: exact B-rep mass properties against the tessellated mesh.

Formatting only; the numbers come from :func:`inertia_tool.mass.brep.compare` (unit density, scaled here by the
density the report uses).
"""

from __future__ import annotations

from ..mass.brep import BrepComparison
from .serialize import to_jsonable

__all__ = ["format_brep_comparison", "brep_comparison_dict"]


def brep_comparison_dict(cmp: BrepComparison, density: float) -> dict:
    """JSON-ready: exact (B-rep) and tessellated volume, centre of mass, inertia at ``density``, and errors."""
    return to_jsonable({
        "chord_tolerance": cmp.chord,
        "angular_deflection": cmp.angular_deflection,
        "triangles": cmp.faces,
        "exact": {"volume": cmp.exact.volume, "mass": cmp.exact.volume * density,
                  "center_of_mass": cmp.exact.center_of_mass, "inertia": cmp.exact.inertia * density},
        "volume_error": cmp.volume_error,
        "volume_error_bound": cmp.volume_bound,
        "center_of_mass_error": cmp.com_error,
        "inertia_error": cmp.inertia_error,
        "note": "exact: OpenCASCADE BRepGProp on the B-rep; the mesh results above are of the tessellation, "
                "whose relative volume error is at most surface area x chord tolerance / volume",
    })


def format_brep_comparison(cmp: BrepComparison, density: float) -> str:
    """A few lines: the exact B-rep values and how far the tessellation is from them, with the bound."""
    e = cmp.exact
    i = e.inertia * density
    return "\n".join([
        f"  CAD B-rep (exact, OpenCASCADE): volume {e.volume:.9g} m³, mass {e.volume * density:.9g} kg, "
        f"centre of mass ({e.center_of_mass[0]:.6g}, {e.center_of_mass[1]:.6g}, {e.center_of_mass[2]:.6g}) m",
        f"    inertia about the centre of mass: Ixx {i[0, 0]:.6g}, Iyy {i[1, 1]:.6g}, Izz {i[2, 2]:.6g}, "
        f"Ixy {i[0, 1]:.6g}, Ixz {i[0, 2]:.6g}, Iyz {i[1, 2]:.6g} kg·m²",
        f"    tessellation ({cmp.faces:,} triangles, chord tolerance {cmp.chord:.3g} m, angular "
        f"{cmp.angular_deflection:g} rad): volume off by {cmp.volume_error:.2e} (at most {cmp.volume_bound:.2e} = "
        f"area × chord / volume), centre of mass by {cmp.com_error:.2e} m, inertia by {cmp.inertia_error:.2e} "
        "(relative, Frobenius)",
    ])
