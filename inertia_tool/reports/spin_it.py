"""Text and JSON of a ``spin_it`` design (formatting only: every number is on the result object)."""

from __future__ import annotations

import math

from .serialize import mass_properties_dict, to_jsonable

__all__ = ["spin_it_dict", "format_spin_it_text"]


def _metrics_dict(m) -> dict:
    return to_jsonable(m)


def spin_it_dict(result, *, output: str | None = None) -> dict:
    """JSON-ready dictionary (SI) of a :class:`inertia_tool.design.SpinItResult`."""
    return {
        "mode": result.mode,
        "axis": to_jsonable(result.axis),
        "origin_m": to_jsonable(result.origin),
        "wall_m": result.wall,
        "measured_wall_m": to_jsonable(result.measured_wall),
        "cavity_volume_m3": result.cavity_volume,
        "cell_size_m": result.cell_size,
        "allowed_cells": result.allowed_cells,
        "removed_cells": result.removed_cells,
        "objective": {"before": result.objective_before, "after": result.objective_after},
        "quadric": {"coefficients": to_jsonable(result.cavity.coefficients),
                    "centre_m": to_jsonable(result.cavity.centre), "half_extent_m": result.cavity.half_extent,
                    "monomials": "1, x, y, z, x², y², z², xy, xz, yz of (design-frame point − centre)/half_extent"},
        "optimisation_seconds": result.optimisation_seconds,
        "objective_evaluations": result.objective_evaluations,
        "seconds": result.seconds,
        "before": {"metrics": _metrics_dict(result.metrics_before), "mass_properties":
                   mass_properties_dict(result.before)},
        "after": {"metrics": _metrics_dict(result.metrics_after), "mass_properties":
                  mass_properties_dict(result.after)},
        "output": output,
        "verified": "after = exact re-analysis of the hollowed mesh",
    }


def _mm(x) -> str:
    return "—" if x is None else f"{x * 1e3:.3f} mm"


def _g(x: float) -> str:
    return f"{x:.5g}"


def format_spin_it_text(result, *, name: str = "", output: str | None = None) -> str:
    """A before/after table of a spin design."""
    before, after = result.metrics_before, result.metrics_after
    mode = "yo-yo (free spin, Chapter 4 §4.4.1)" if result.mode == "yoyo" else \
        "top (heavy symmetric top on a pivot, Chapter 4 §4.4.3)"
    ax = ", ".join(f"{c:.4g}" for c in result.axis)
    org = ", ".join(f"{c * 1e3:.4g}" for c in result.origin)
    where = "pivot" if result.mode == "top" else ("through" if before.axis_offset is not None else
                                                  "through the centre of mass")
    lines = [f"spin-it {name}: {mode}",
             f"  axis ({ax}), {where} ({org}) mm",
             f"  wall: {_mm(result.wall)} asked, thinnest {_mm(result.measured_wall) if math.isfinite(result.measured_wall) else '— (no cavity)'}"
             " measured (cavity vertices to the outer surface)",
             f"  cavity: {result.cavity_volume * 1e6:.4g} cm³ removed, {result.removed_cells} of {result.allowed_cells} "
             f"cells of {_mm(result.cell_size)}; optimised in {result.optimisation_seconds:.2f} s "
             f"({result.objective_evaluations} objective evaluations), {result.seconds:.2f} s in all",
             f"  objective {result.objective_before:.4g} → {result.objective_after:.4g} (exact moments)",
             "  every 'after' number is the exact re-analysis of the hollowed mesh", ""]
    if result.mode == "yoyo":
        rows = [("mass", f"{before.mass * 1e3:.4g} g", f"{after.mass * 1e3:.4g} g"),
                ("I_axis (about the COM) kg·m²", _g(before.axis_moment), _g(after.axis_moment)),
                ("I_next (largest transverse) kg·m²", _g(before.next_moment), _g(after.next_moment)),
                ("I_axis / I_next", f"{before.moment_ratio:.4f}", f"{after.moment_ratio:.4f}"),
                ("axis to nearest principal axis", f"{math.degrees(before.axis_tilt):.3f}°",
                 f"{math.degrees(after.axis_tilt):.3f}°"),
                ("nearest principal axis", before.nearest_principal, after.nearest_principal),
                ("ε coefficient c (stable < 0)", f"{before.epsilon_coefficient:.4f}",
                 f"{after.epsilon_coefficient:.4f}"),
                ("COM offset from the axis", _mm(before.axis_offset), _mm(after.axis_offset))]
    else:
        def rpm(w):
            return f"{w:.4g} rad/s ({w * 60 / (2 * math.pi):.4g} rpm)"
        rows = [("mass", f"{before.mass * 1e3:.4g} g", f"{after.mass * 1e3:.4g} g"),
                ("sleeping-top threshold √(4 I1 M g l)/I3", rpm(before.sleeping_threshold),
                 rpm(after.sleeping_threshold)),
                ("I3 (axial, about the pivot) kg·m²", _g(before.axis_moment), _g(after.axis_moment)),
                ("I1 (transverse, about the pivot) kg·m²", _g(before.next_moment), _g(after.next_moment)),
                ("height l of the COM above the pivot", _mm(before.height), _mm(after.height)),
                ("COM offset from the axis", _mm(before.axis_offset), _mm(after.axis_offset)),
                ("axis to pivot→COM line", f"{math.degrees(before.axis_tilt):.3f}°",
                 f"{math.degrees(after.axis_tilt):.3f}°"),
                ("transverse asymmetry (0 = symmetric top)", f"{before.transverse_asymmetry:.4f}",
                 f"{after.transverse_asymmetry:.4f}")]
    width = max(len(r[0]) for r in rows)
    col = max(len(r[1]) for r in rows) + 2
    lines.append(f"  {'':{width}}  {'before':<{col}}after")
    lines += [f"  {a:{width}}  {b:<{col}}{c}" for a, b, c in rows]
    if output:
        lines += ["", f"  wrote {output}"]
    return "\n".join(lines) + "\n"
