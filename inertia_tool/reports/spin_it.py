"""Text and JSON of a ``spin_it`` design (formatting only: every number is on the result object)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .escape import escape_html
from .html import html_page
from .serialize import mass_properties_dict, to_jsonable
from .numbers import number

__all__ = ["spin_it_dict", "format_spin_it_text", "spin_it_figure", "SpinMotion", "spin_it_html", "motion_svgs",
           "verification_dict", "format_verification"]


def verification_dict(verdicts) -> dict:
    """JSON-ready record of ``design.verify`` verdicts: the one accepted (last) and every attempt, SI (rad)."""
    def one(v) -> dict:
        return {"resolution": v.resolution, "ok": v.ok, "reasons": list(v.reasons),
                "axis_tilt_before": v.axis_tilt_before, "axis_tilt_after": v.axis_tilt_after,
                "objective_before": v.objective_before, "objective_after": v.objective_after,
                "wobble_before": v.wobble_before, "wobble_after": v.wobble_after, "notes": list(v.notes),
                "product_weight": v.product_weight}
    return {"passed": bool(verdicts and verdicts[-1].ok), "attempts": [one(v) for v in verdicts]}


def format_verification(verdicts) -> str:
    """Lines saying what the design was checked against and, when it took retries, why."""
    import math
    v = verdicts[-1]
    lines = [f"  verified against the input: spin axis {math.degrees(v.axis_tilt_after):.3g}° from principal "
             f"(at most 1°, or no worse than the input's {math.degrees(v.axis_tilt_before):.3g}°), objective "
             f"not worse"]
    if v.wobble_after is not None:
        lines[-1] += (f", simulated wobble |ω⊥|/|ω| {v.wobble_before:.3g} → {v.wobble_after:.3g} "
                      "(free spin knocked 0.1° off the axis)")
    lines += [f"  NOTE: {note}" for note in v.notes]
    for earlier in verdicts[:-1]:
        lines.append(f"  resolution {earlier.resolution} (product weight {earlier.product_weight:.0e}) was "
                     "rejected: " + "; ".join(earlier.reasons))
    return "\n".join(lines) + "\n"


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
        "insert": None if result.insert is None else {
            "density_kg_m3": result.insert_density, "volume_m3": result.insert.volume, "mass_kg": result.insert.mass,
            "shape": getattr(result, "insert_shape", None),
            "mass_properties": mass_properties_dict(result.insert)},
        "output": output,
        "verified": _verified(result.after),
    }


def _verified(after) -> str:
    """How the result after hollowing was checked: an exact re-analysis, unless its certificate says less."""
    cert = _certificate_of(after)
    if cert is None or cert.proven:
        return "after = exact re-analysis of the hollowed mesh"
    mesh = getattr(after, "mesh", None) or next(p.mesh for p in after.parts if _certificate_of(p) is cert)
    return f"after = re-analysis of the hollowed mesh, certificate {cert.kind}: {'; '.join(mesh.notes)}"


def _certificate_of(props):
    """The :class:`~inertia_tool.mesh.policy.Certificate` of a result's mesh report; for a combination (the
    hollowed part with its insert) the first part's that is not proven; None without one."""
    cert = getattr(getattr(props, "mesh", None), "certificate", None)
    if cert is None:
        for part in getattr(props, "parts", ()):
            said = _certificate_of(part)
            if said is not None and not said.proven:
                return said
    return cert


def _certificates_text(result) -> str:
    """``"certificate: before estimate, assuming flat-islands (mass ±…); after estimate, assuming flat-islands
    (mass ±…) (the re-analysis of the hollowed mesh)"``: how far the part's numbers before and after can be
    trusted (:meth:`Certificate.brief`: the kind and the user's assumptions taken), for the text report."""
    before, after = _certificate_of(result.before), _certificate_of(result.after)
    said_before = "not stated" if before is None else before.brief() + _mass_bound(result.before)
    said_after = "exact" if after is None else after.brief() + _mass_bound(result.after)
    return f"certificate: before {said_before}; after {said_after} (the re-analysis of the hollowed mesh)"


def _mass_bound(props) -> str:
    """``" (mass ±4.2 %)"`` for an estimate with bounds (a repaired part, and the part hollowed from it); ``""``."""
    from .serialize import method_and_uncertainty

    cert = _certificate_of(props)
    bounds = method_and_uncertainty(props)[1] if cert is not None and not cert.proven else None
    mass = bounds.get("mass") if isinstance(bounds, dict) else getattr(bounds, "mass", None)
    return "" if mass is None else f" (mass ±{mass * 100:.3g} %)"


def _mm(x) -> str:
    return "—" if x is None else f"{x * 1e3:.3f} mm"


def _g(x: float) -> str:
    return number(x, 5)


def _rows(result) -> list[tuple[str, str, str]]:
    """The before/after rows (label, before, after) of the text and HTML reports."""
    before, after = result.metrics_before, result.metrics_after
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
    return rows


def format_spin_it_text(result, *, name: str = "", output: str | None = None) -> str:
    """A before/after table of a spin design."""
    before = result.metrics_before
    mode = "yo-yo (free spin, Chapter 4 §4.4.1)" if result.mode == "yoyo" else \
        "top (heavy symmetric top on a pivot, Chapter 4 §4.4.3)"
    ax = ", ".join(f"{c:.4g}" for c in result.axis)
    org = ", ".join(f"{c * 1e3:.4g}" for c in result.origin)
    where = "pivot" if result.mode == "top" else ("through" if before.axis_offset is not None else
                                                  "through the centre of mass")
    lines = [f"spin-it {name}: {mode}",
             f"  axis ({ax}), {where} ({org}) mm",
             f"  wall: {_mm(result.wall)} asked, thinnest "
             f"{_mm(result.measured_wall) if math.isfinite(result.measured_wall) else '— (no cavity)'}"
             " measured (cavity vertices to the outer surface)",
             f"  cavity: {result.cavity_volume * 1e6:.4g} cm³ removed, "
             f"{result.removed_cells} of {result.allowed_cells} cells of {_mm(result.cell_size)}; "
             f"optimised in {result.optimisation_seconds:.2f} s "
             f"({result.objective_evaluations} objective evaluations), {result.seconds:.2f} s in all",
             f"  objective {result.objective_before:.4g} → {result.objective_after:.4g} (exact moments)",
             f"  {_certificates_text(result)}", ""]
    if result.insert is not None:
        lines.insert(5, f"  insert: {result.insert.volume * 1e6:.4g} cm³ of {result.insert_density:g} kg/m³ "
                        f"({result.insert.mass * 1e3:.4g} g), "
                        + ("a ring about the spin axis" if getattr(result, "insert_shape", None) == "ring" else
                           "a second quadric region") + "; 'after' includes it")
    elif result.insert_density is not None:
        lines.insert(5, f"  insert of {result.insert_density:g} kg/m³ allowed (a quadric region and a ring about the "
                        "axis tried, meshed and re-analysed), but none helps: cavity only")
    rows = _rows(result)
    width = max(len(r[0]) for r in rows)
    col = max(len(r[1]) for r in rows) + 2
    lines.append(f"  {'':{width}}  {'before':<{col}}after")
    lines += [f"  {a:{width}}  {b:<{col}}{c}" for a, b, c in rows]
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class SpinMotion:
    """A simulated spin of the part before and after, for the picture of :func:`spin_it_html` (the caller
    simulates; this module only draws).

    Attributes
    ----------
    t : (N,) float
        Sample times, s (the same for both).
    before, after : (N, k) float
        The ``k`` plotted quantities at ``t``, in the unit of ``ylabel``.
    labels : tuple of str
        Names of the ``k`` quantities (legend).
    ylabel : str
        Axis label with its unit.
    description : str
        One or two sentences: what was simulated and how it was started (plain text).
    """

    t: np.ndarray
    before: np.ndarray
    after: np.ndarray
    labels: tuple[str, ...]
    ylabel: str
    description: str


_COLOURS = ("#1f4e79", "#c55a11", "#548235")


def _ticks(lo: float, hi: float, count: int = 5) -> list[float]:
    """Round tick values covering [lo, hi]."""
    span = hi - lo if hi > lo else (abs(hi) or 1.0)
    raw = span / count
    step = 10 ** math.floor(math.log10(raw))
    for m in (1, 2, 5, 10):
        if m * step >= raw:
            step *= m
            break
    first = math.ceil(lo / step - 1e-9) * step
    return [first + k * step for k in range(int(math.floor((hi - first) / step + 1e-9)) + 1)]


def _panel_svg(title: str, t: np.ndarray, ys: np.ndarray, labels, ylabel: str, ylim: tuple[float, float], *,
               width: int = 470, height: int = 300) -> str:
    """One line plot as an inline ``<svg>``: ``ys`` (N, k) against ``t`` (s), y range ``ylim``."""
    e = escape_html
    left, right, top, bottom = 62, 12, 28, 44
    pw, ph = width - left - right, height - top - bottom
    t0, t1 = float(t[0]), float(t[-1]) if t[-1] > t[0] else float(t[0]) + 1.0
    y0, y1 = ylim

    def x(v):
        return left + (v - t0) / (t1 - t0) * pw

    def y(v):
        return top + (y1 - v) / (y1 - y0) * ph

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="11">',
           f'<text x="{left + pw / 2:.1f}" y="16" text-anchor="middle" font-size="13">{e(title)}</text>',
           f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>']
    for v in _ticks(y0, y1):
        out.append(f'<line x1="{left}" x2="{left + pw}" y1="{y(v):.1f}" y2="{y(v):.1f}" stroke="#e4e4e4"/>'
                   f'<text x="{left - 4}" y="{y(v) + 4:.1f}" text-anchor="end">{e(number(v, 3))}</text>')
    for v in _ticks(t0, t1):
        out.append(f'<line x1="{x(v):.1f}" x2="{x(v):.1f}" y1="{top + ph}" y2="{top + ph + 4}" stroke="#888"/>'
                   f'<text x="{x(v):.1f}" y="{top + ph + 16}" text-anchor="middle">{e(number(v, 3))}</text>')
    out.append(f'<text x="{left + pw / 2:.1f}" y="{height - 8}" text-anchor="middle">time (s)</text>'
               f'<text transform="translate(14 {top + ph / 2:.1f}) rotate(-90)" text-anchor="middle">'
               f'{e(ylabel)}</text>')
    for k in range(ys.shape[1]):
        points = " ".join(f"{x(a):.1f},{y(b):.1f}" for a, b in zip(t, ys[:, k]))
        colour = _COLOURS[k % len(_COLOURS)]
        out.append(f'<polyline fill="none" stroke="{colour}" stroke-width="1.4" points="{points}"/>')
        lx = left + 8 + 120 * k
        out.append(f'<line x1="{lx}" x2="{lx + 18}" y1="{top + 12}" y2="{top + 12}" stroke="{colour}" '
                   f'stroke-width="2"/><text x="{lx + 22}" y="{top + 16}">{e(labels[k])}</text>')
    out.append("</svg>")
    return "".join(out)


def motion_svgs(motion: SpinMotion) -> list[str]:
    """The before and after panels of ``motion`` on one y scale (two ``<svg>`` elements)."""
    both = np.concatenate([np.ravel(motion.before), np.ravel(motion.after)])
    lo, hi = float(np.min(both)), float(np.max(both))
    pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.1
    lim = (lo - pad, hi + 2.5 * pad)                                  # room for the legend at the top
    return [_panel_svg(title, np.asarray(motion.t, float), np.asarray(ys, float).reshape(len(motion.t), -1),
                       motion.labels, motion.ylabel, lim)
            for title, ys in (("before (the part as it is)", motion.before), ("after (hollowed)", motion.after))]


def _extent_captions(motion: SpinMotion) -> list[str]:
    """Under each panel: the range the plotted quantities sweep (the size of the wobble or nutation)."""
    out = []
    for ys in (motion.before, motion.after):
        ys = np.asarray(ys, float).reshape(len(motion.t), -1)
        parts = [f"{label}: {number(float(ys[:, k].min()), 3)} to {number(float(ys[:, k].max()), 3)}"
                 for k, label in enumerate(motion.labels)]
        out.append("; ".join(parts))
    return out


def _html_table(head, rows, *, left: int = 1, css: str = "") -> str:
    """A table of escaped text; the first ``left`` columns left-aligned; no header row when ``head`` is None."""
    e = escape_html
    thead = "" if head is None else "<thead><tr>" + "".join(f"<th>{e(h)}</th>" for h in head) + "</tr></thead>"
    cells = ('<td class="l">', "<td>")
    body = "".join("<tr>" + "".join(f"{cells[k >= left]}{e(c)}</td>" for k, c in enumerate(r)) + "</tr>"
                   for r in rows)
    attribute = f' class="{css}"' if css else ""
    return f"<table{attribute}>{thead}<tbody>{body}</tbody></table>"


def spin_it_html(result, *, name: str = "", motion: SpinMotion | None = None, output: str | None = None) -> str:
    """A self-contained HTML page of a spin design: the text report's facts, the before/after table of the
    exact re-analyses, and the simulated spin before and after (``motion``) as inline SVG."""
    e = escape_html
    kind = "yo-yo (free spin, Chapter 4 §4.4.1)" if result.mode == "yoyo" else \
        "top (heavy symmetric top on a pivot, Chapter 4 §4.4.3)"
    wall = _mm(result.measured_wall) if math.isfinite(result.measured_wall) else "— (no cavity)"
    facts = [("part", name or "—"), ("design", kind),
             ("axis", ", ".join(number(c, 4) for c in result.axis)),
             ("pivot" if result.mode == "top" else "axis point", ", ".join(number(c * 1e3, 4) for c in result.origin)
              + " mm"),
             ("wall", f"{_mm(result.wall)} asked, thinnest {wall} measured"),
             ("cavity", f"{number(result.cavity_volume * 1e6, 4)} cm³ removed ({result.removed_cells} of "
                        f"{result.allowed_cells} cells of {_mm(result.cell_size)})"),
             ("objective", f"{number(result.objective_before, 4)} → {number(result.objective_after, 4)} "
                           "(exact moments)"),
             ("time", f"{result.seconds:.2f} s ({result.objective_evaluations} objective evaluations)")]
    if result.insert is not None:
        facts.append(("insert", f"{number(result.insert.volume * 1e6, 4)} cm³ of {result.insert_density:g} kg/m³ "
                                f"({number(result.insert.mass * 1e3, 4)} g); 'after' includes it"))
    if output:
        facts.append(("hollowed part", output))
    body = [_html_table(None, facts, left=2),
            "<h2>Before and after</h2>",
            f"<p>Every “after” number is the re-analysis of the hollowed mesh; {e(_certificates_text(result))}.</p>",
            _html_table(["quantity", "before", "after"], _rows(result), css="before-after")]
    if motion is not None:
        title = "Free spin about the axis" if result.mode == "yoyo" else "Nutation of the top"
        body += [f"<h2>{e(title)}</h2>", f"<p>{e(motion.description)}</p>",
                 '<div class="views">' + "".join(
                     f"<figure>{svg}<figcaption>{e(caption)}</figcaption></figure>"
                     for svg, caption in zip(motion_svgs(motion), _extent_captions(motion))) + "</div>"]
    return html_page(f"spin-it: {name or 'part'}", "\n".join(body))


def _section_polygons(vertices, faces, origin, frame, plane: str, height: float):
    """Polygons (list of (k, 2) arrays, design-frame coordinates in mm) of the section of a closed mesh by the
    plane ``y' = 0`` (``plane="axial"``: it contains the spin axis and ``e1``) or ``z' = height``
    (``"transverse"``), through manifold3d's slicer."""
    import manifold3d

    local = (np.asarray(vertices) - origin) @ frame                  # design frame: z' along the axis
    if plane == "axial":
        local = np.column_stack([local[:, 0], local[:, 2], -local[:, 1]])   # (x', z', −y'): a proper rotation
        height = 0.0
    mesh = manifold3d.Mesh64(vert_properties=np.array(local, dtype=np.float64, order="C"),
                             tri_verts=np.array(faces, dtype=np.uint64, order="C"))
    section = manifold3d.Manifold(mesh).slice(float(height))
    return [np.asarray(p) * 1e3 for p in section.to_polygons()]


def spin_it_figure(result):
    """A matplotlib figure: sections of the part before (outline) and after (filled, with its cavity) through
    the spin axis and across it at the centre of mass, in the design frame (mm); centre of mass before and
    after marked.  Needs matplotlib and manifold3d."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    frame = np.column_stack(_design_axes(result.axis))
    com_b = (result.before.center_of_mass - result.origin) @ frame * 1e3
    com_a = (result.after.center_of_mass - result.origin) @ frame * 1e3
    fig, panels = plt.subplots(1, 2, figsize=(11, 5))
    for ax, plane, title in ((panels[0], "axial", "section through the axis (x′, axis)"),
                             (panels[1], "transverse", "section across the axis at the centre of mass (x′, y′)")):
        height = com_a[2] * 1e-3
        bodies = [(result.vertices, result.faces, "#9cc3e6", "#1f4e79", "hollowed part (cavity white)")]
        if result.insert_vertices is not None:
            bodies.append((result.insert_vertices, result.insert_faces, "#595959", "#202020",
                           f"insert ({result.insert_density:g} kg/m³)"))
        for verts, tris, face, edge, label in bodies:
            polygons = _section_polygons(verts, tris, result.origin, frame, plane, height)
            if not polygons:
                continue
            codes, points = [], []
            for poly in polygons:
                points += list(poly) + [poly[0]]
                codes += [Path.MOVETO] + [Path.LINETO] * (len(poly) - 1) + [Path.CLOSEPOLY]
            ax.add_patch(PathPatch(Path(np.array(points), codes), facecolor=face, edgecolor=edge, lw=0.8,
                                   label=label))
        pick = (0, 2) if plane == "axial" else (0, 1)
        ax.plot(*com_b[list(pick)], "x", color="#c00000", ms=9, mew=2, label="centre of mass before")
        ax.plot(*com_a[list(pick)], "+", color="#006000", ms=11, mew=2, label="centre of mass after")
        if plane == "axial":
            ax.axvline(0.0, color="k", lw=0.6, ls="--", label="spin axis")
        else:
            ax.plot(0.0, 0.0, "o", color="k", ms=4, label="spin axis")
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.set_xlabel("x′ (mm)")
        ax.set_ylabel("along the axis (mm)" if plane == "axial" else "y′ (mm)")
        ax.set_title(title, fontsize=10)
    seen = {}
    for panel in panels:
        for handle, label in zip(*panel.get_legend_handles_labels()):
            seen.setdefault(label, handle)
    fig.legend(list(seen.values()), list(seen.keys()), loc="lower center", ncol=5, fontsize=9, frameon=False)
    kind = "yo-yo" if result.mode == "yoyo" else "top"
    fig.suptitle(f"spin-it ({kind}): wall ≥ {result.wall * 1e3:.3g} mm, {result.cavity_volume * 1e6:.3g} cm³ of "
                 f"material removed" + ("" if result.insert is None else
                                        f", {result.insert.mass * 1e3:.3g} g insert"))
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    return fig


def _design_axes(axis):
    from ..rotations import perpendicular_basis
    e1, e2 = perpendicular_basis(np.asarray(axis, dtype=float))
    return e1, e2, np.asarray(axis, dtype=float)
