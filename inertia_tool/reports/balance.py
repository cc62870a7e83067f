"""Writers of the dynamic-balancing report (``inertia_tool.balancing.rotor.BalanceReport``): text, JSON-ready dict,
Markdown and HTML with an inline SVG polar plot per correction plane.  Formatting only; every number comes
from the engine.

Display units (always labelled): lengths in mm, masses in g, unbalance in g·mm, moments of unbalance in
g·mm², forces in N, torques in N·m, angles in degrees from the shaft x axis towards y.  The JSON dict is SI.
"""

from __future__ import annotations

import math


from ..balancing.rotor import ISO_GRADES, BalanceReport, PlaneUnbalance
from .escape import escape_html, escape_markdown
from .serialize import to_jsonable
from .html import html_page
from .numbers import number

__all__ = ["balance_dict", "format_balance_text", "balance_markdown", "balance_html", "polar_svg"]

_G_MM = 1e6        # kg·m → g·mm
_G_MM2 = 1e9       # kg·m² → g·mm²

_KIND_TEXT = {
    "balanced": "balanced (centre of mass on the shaft, shaft a principal axis)",
    "static": "static: principal axis parallel to the shaft, displaced",
    "couple": "couple: centre of mass on the shaft, principal axis tilted",
    "quasi-static": "quasi-static: principal axis tilted, crossing the shaft away from the centre of mass",
    "dynamic": "dynamic: principal axis skew to the shaft",
}


def _deg(rad: float) -> float:
    """Degrees in [0, 360) rounded to 0.1 (so that 359.99° prints as 0.0°, not 360.0°)."""
    return round(math.degrees(rad), 1) % 360.0


def _vec_angle(v) -> float:
    return math.atan2(v[1], v[0]) % (2 * math.pi)


def _mag(v) -> float:
    return float(math.hypot(v[0], v[1]))


def _num(x: float, digits: int = 4) -> str:
    return number(x, digits, style="fixed")


def _grade_name(g, value) -> str:
    if g is None:
        return f"worse than G 4000 ({_num(value)} mm/s)"
    return f"{g.name} ({_num(value)} mm/s)"


def _plane_labels(report: BalanceReport) -> tuple[list[str], str]:
    bearings = len(report.tolerance_planes) == 2 and not _same_positions(report.tolerance_planes,
                                                                         report.correction_planes)
    if bearings:
        return ["bearing A", "bearing B"], "bearing"
    if len(report.tolerance_planes) == 1:
        return ["plane 1"], "correction"
    return ["plane 1", "plane 2"], "correction"


def _same_positions(a, b) -> bool:
    return len(a) == len(b) and all(p.position == q.position for p, q in zip(a, b))


# ---- JSON ----------------------------------------------------------------------------------------------
def _state_dict(state) -> dict:
    return {
        "kind": state.kind,
        "center_of_mass_shaft": state.center_of_mass,
        "offset": state.offset,
        "static_unbalance": state.static_unbalance,
        "static_unbalance_magnitude": _mag(state.static_unbalance),
        "moment_unbalance_about_axis_point": state.moment_unbalance,
        "couple_unbalance": state.couple_unbalance,
        "couple_unbalance_magnitude": _mag(state.couple_unbalance),
        "products_of_inertia_xz_yz": state.products_of_inertia,
        "principal_axis_mesh": state.principal_axis,
        "tilt": state.tilt,
        "tilt_angle": state.tilt_angle,
        "principal_axis_distance_to_shaft": state.axis_distance,
    }


def _plane_dict(p: PlaneUnbalance) -> dict:
    return {"position": p.position, "unbalance": p.unbalance, "magnitude": p.magnitude, "angle": p.angle,
            "permissible": p.permissible, "share": p.share, "within_tolerance": p.within_tolerance,
            "bearing_load": p.force}


def balance_dict(report: BalanceReport) -> dict:
    """The ``balance --json`` object: SI units, shaft-frame vectors, angles in rad from shaft x towards y."""
    g = report.quality_grade
    return to_jsonable({
        "name": report.name,
        "units": {"length": "m", "mass": "kg", "unbalance": "kg*m", "moment_unbalance": "kg*m^2",
                  "force": "N", "torque": "N*m", "angle": "rad", "speed": "rad/s", "grade": "mm/s"},
        "conventions": "shaft frame: origin axis_point, z along axis_direction, x = mesh axis most orthogonal "
                       "to z projected, y = z × x; axial positions from axis_point; products of inertia are "
                       "tensor elements (−∫xz dm); loads and torques rotate with the part",
        "mass": report.mass,
        "speed": report.speed,
        "rpm": report.rpm,
        "axis_point": report.frame.origin,
        "shaft_axes_mesh": report.frame.axes.T,
        "initial": _state_dict(report.initial),
        "support_force": report.force,
        "support_torque_about_axis_point": report.torque,
        "grade": None if g is None else {"name": g.name, "value": g.value, "typical_parts": g.typical_parts},
        "permissible_unbalance": report.permissible_unbalance,
        "tolerance_planes": [_plane_dict(p) for p in report.tolerance_planes],
        "achieved_value": report.achieved_value,
        "achieved_grade": None if report.achieved_grade is None else report.achieved_grade.name,
        "single_plane": report.single_plane,
        "correction_planes": [_plane_dict(p) for p in report.correction_planes],
        "corrections": [{"plane": c.plane, "mass": c.mass, "radius": c.radius, "angle": c.angle,
                         "position": c.position, "removal_angle": c.removal_angle,
                         "removal_position": c.removal_position} for c in report.corrections],
        "verification": {**_state_dict(report.corrected), "achieved_value": report.corrected_value,
                         "achieved_grade": None if report.corrected_grade is None else report.corrected_grade.name,
                         "couple_corrected": not _couple_left(report),
                         "summary": _verification_text(report)},
        "drillings": [{"plane": h.plane, "angle": h.angle, "radius": h.radius, "diameter": h.diameter,
                       "depth": h.depth, "direction": h.direction, "mass": h.mass, "entry": h.entry, "axis": h.axis,
                       "centroid": h.centroid, "inside_checked": h.inside_checked} for h in report.drillings],
        "drilled_verification": None if report.drilled is None else {
            **_state_dict(report.drilled), "achieved_value": report.drilled_value,
            "achieved_grade": None if report.drilled_grade is None else report.drilled_grade.name},
        "notes": list(report.notes),
    })


# ---- shared rows ---------------------------------------------------------------------------------------
def _summary_rows(report: BalanceReport) -> list[tuple[str, str]]:
    s = report.initial
    com = s.center_of_mass * 1e3 + 0.0
    rows = [
        ("kind (ISO 21940-2)", _KIND_TEXT[s.kind]),
        ("centre of mass (shaft frame)", f"({com[0]:.4g}, {com[1]:.4g}, {com[2]:.4g}) mm; "
                                          f"offset from the shaft e = {_num(s.offset * 1e3)} mm"),
        ("static unbalance U = M·e", f"{_num(_mag(s.static_unbalance) * _G_MM)} g·mm at "
                                     f"{_deg(_vec_angle(s.static_unbalance)):.1f}°  "
                                     f"(x {_num(s.static_unbalance[0] * _G_MM)}, "
                                     f"y {_num(s.static_unbalance[1] * _G_MM)} g·mm)"),
        ("couple unbalance (about the c.o.m. plane)", f"{_num(_mag(s.couple_unbalance) * _G_MM2)} g·mm² at "
                                                       f"{_deg(_vec_angle(s.couple_unbalance)):.1f}°"),
        ("products of inertia J_xz, J_yz", f"{_num(s.products_of_inertia[0])}, {_num(s.products_of_inertia[1])} "
                                           "kg·m² (about the axis point, shaft axes, −∫xz dm)"),
        ("tilt of the nearest central principal axis",
         f"{math.degrees(s.tilt):.4g}° towards {_deg(s.tilt_angle):.1f}°; "
         f"closest approach to the shaft {_num(s.axis_distance * 1e3)} mm"),
    ]
    return rows


def _load_rows(report: BalanceReport) -> list[tuple[str, str]]:
    rows = [("total rotating force on the supports", f"{_num(_mag(report.force))} N (= M·e·Ω²)")]
    labels, kind = _plane_labels(report)
    if kind == "bearing":
        for lab, p in zip(labels, report.tolerance_planes):
            rows.append((f"load on {lab} (z = {p.position * 1e3:.4g} mm)",
                         f"{_num(_mag(p.force))} N at {_deg(_vec_angle(p.force)):.1f}°"))
    t = report.torque
    rows.append(("torque of the supports, Eq. (4.26)",
                 f"{_num(_mag(t))} N·m about the axis point: τ = Ω²(−J_yz, J_xz, 0) = "
                 f"({_num(t[0])}, {_num(t[1])}, 0) N·m"))
    return rows


def _tolerance_rows(report: BalanceReport) -> list[list[str]]:
    labels, _ = _plane_labels(report)
    rows = []
    for lab, p in zip(labels, report.tolerance_planes):
        status = "—" if not math.isfinite(p.permissible) else ("OK" if p.within_tolerance else "OUT")
        rows.append([lab, f"{p.position * 1e3:.4g}", f"{p.share:.3f}", _num(p.permissible * _G_MM),
                     _num(p.magnitude * _G_MM), f"{_deg(p.angle):.1f}", status])
    return rows


def _correction_rows(report: BalanceReport) -> list[list[str]]:
    rows = []
    for k, (c, p) in enumerate(zip(report.corrections, report.correction_planes), start=1):
        pos = c.position * 1e3
        rows.append([str(k), f"{c.plane * 1e3:.4g}", _num(p.magnitude * _G_MM), f"{_deg(p.angle):.1f}",
                     _num(c.mass * 1e3), f"{c.radius * 1e3:.4g}", f"{_deg(c.angle):.1f}",
                     f"{_deg(c.removal_angle):.1f}",
                     f"({pos[0]:.4g}, {pos[1]:.4g}, {pos[2]:.4g})"])
    return rows


_TOL_HEAD = ["plane", "z [mm]", "share", "U_per [g·mm]", "residual [g·mm]", "angle [°]", "status"]
_CORR_HEAD = ["plane", "z [mm]", "unbalance [g·mm]", "at [°]", "add [g]", "radius [mm]", "add at [°]",
              "or remove at [°]", "add position (mesh, mm)"]


def _couple_left(report: BalanceReport) -> bool:
    """A single-plane (static) correction that leaves a couple unbalance (ISO 21940-2 kind not balanced/static)."""
    return report.single_plane and report.corrected.kind not in ("balanced", "static")


def _verification_text(report: BalanceReport) -> str:
    v = report.corrected
    head = (f"static {_num(_mag(v.static_unbalance) * _G_MM)} g·mm, couple {_num(_mag(v.couple_unbalance) * _G_MM2)} "
            f"g·mm², kind {v.kind}")
    if _couple_left(report):
        bearings = len(report.tolerance_planes) == 2   # the bearing check includes the couple
        where = (f"; at the bearings it meets {_grade_name(report.corrected_grade, report.corrected_value)}"
                 if bearings else "")
        return (f"{head}, couple not corrected (a single-plane correction removes the static unbalance only; "
                f"two correction planes correct both){where}")
    said = f"{head}, meets {_grade_name(report.corrected_grade, report.corrected_value)}"
    if report.residual_bound is not None:      # an estimated part: the verification is the repaired surface's
        said += (f" — for the repaired surface; the part's own static unbalance is uncertain by "
                 f"{_num(report.residual_bound * _G_MM)} g·mm (see the notes)")
    return said


def _header(report: BalanceReport) -> list[tuple[str, str]]:
    f = report.frame
    ax = f.axes + 0.0            # + 0.0 turns -0.0 into 0.0, which prints as "0", not "-0"
    o = f.origin * 1e3 + 0.0
    return [
        ("part", f"{report.name or '(unnamed)'}: {_num(report.mass)} kg"),
        ("speed", f"{report.rpm:.6g} rpm (Ω = {report.speed:.6g} rad/s)"),
        ("shaft", f"through ({o[0]:.4g}, {o[1]:.4g}, {o[2]:.4g}) mm "
                  f"along ({ax[0, 2]:.4g}, {ax[1, 2]:.4g}, {ax[2, 2]:.4g})"),
        ("shaft frame", f"x = ({ax[0, 0]:.4g}, {ax[1, 0]:.4g}, {ax[2, 0]:.4g}), y = ({ax[0, 1]:.4g}, {ax[1, 1]:.4g}, "
                        f"{ax[2, 1]:.4g}) in mesh axes; angles from x towards y"),
    ]


def _grade_lines(report: BalanceReport) -> list[str]:
    g = report.quality_grade
    lines = []
    if g is not None:
        e_per = g.speed_eccentricity / report.speed * 1e6
        lines.append(f"grade {g.name} (typical: {g.typical_parts})")
        lines.append(f"U_per = G·M/Ω = {_num(report.permissible_unbalance * _G_MM)} g·mm (e_per = {_num(e_per)} µm)")
    else:
        lines.append("no grade given (a grade such as G6.3 checks a tolerance); shares below are the lever rule")
    a = report.achieved_grade
    lines.append(f"as it is, the part meets {_grade_name(a, report.achieved_value)}"
                 + (f" (typical: {a.typical_parts})" if a is not None else ""))
    return lines


# ---- text ----------------------------------------------------------------------------------------------
def _table_text(head, rows) -> list[str]:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(head)]
    out = ["  " + "  ".join(h.ljust(w) for h, w in zip(head, widths))]
    out += ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)) for r in rows]
    return out


def format_balance_text(report: BalanceReport) -> str:
    """The terminal report."""
    lines = ["Balancing report (§4.3.2 of the chapter; ISO 21940-2 / ISO 21940-11)"]
    lines += [f"  {k}: {v}" for k, v in _header(report)]
    lines += ["", "Unbalance as it is"] + [f"  {k}: {v}" for k, v in _summary_rows(report)]
    lines += ["", f"At {report.rpm:.6g} rpm (loads rotate with the part; gravity not included)"]
    lines += [f"  {k}: {v}" for k, v in _load_rows(report)]
    lines += ["", "ISO 21940-11 tolerance"] + [f"  {x}" for x in _grade_lines(report)]
    lines += _table_text(_TOL_HEAD, _tolerance_rows(report))
    title = "Single-plane (static) correction" if report.single_plane else "Two-plane correction"
    lines += ["", title] + _table_text(_CORR_HEAD, _correction_rows(report))
    lines += ["", "Verification (part + correction masses re-analysed)", "  " + _verification_text(report)]
    if report.drillings:
        lines += ["", "Or remove material: drill parallel to the shaft from each correction plane"]
        rows = [[str(k), f"{h.plane * 1e3:.4g}", f"{h.diameter * 1e3:.4g}", f"{h.depth * 1e3:.4g}",
                 "+z" if h.direction > 0 else "−z", f"{h.radius * 1e3:.4g}", f"{_deg(h.angle):.1f}",
                 _num(h.mass * 1e3), "yes" if h.inside_checked else "not checked"]
                for k, h in enumerate(report.drillings, start=1)]
        lines += _table_text(["hole", "from z [mm]", "Ø [mm]", "depth [mm]", "towards", "radius [mm]", "at [°]",
                              "removes [g]", "inside the part"], rows)
        d = report.drilled
        assert d is not None, "a balance report with drillings holds their verification"
        lines += ["  verification (part less the drilled cylinders re-analysed): static "
                  f"{_num(_mag(d.static_unbalance) * _G_MM)} g·mm, couple {_num(_mag(d.couple_unbalance) * _G_MM2)} "
                  f"g·mm², kind {d.kind}, meets {_grade_name(report.drilled_grade, report.drilled_value)}"]
    if report.notes:
        lines += ["", "Notes"] + [f"  - {n}" for n in report.notes]
    return "\n".join(lines) + "\n"


# ---- SVG -----------------------------------------------------------------------------------------------
def polar_svg(report: BalanceReport, index: int, *, size: int = 260) -> str:
    """Polar plot of correction plane ``index``: the plane's unbalance (arrow, length ∝ g·mm, scaled to the
    largest of the planes), the correction mass to add (filled dot on the rim) and the removal point
    (hollow dot), the permissible unbalance of the plane as a dashed circle when it is a tolerance plane.
    Angles from the shaft x axis (right) counter-clockwise towards y (up)."""
    plane = report.correction_planes[index]
    corr = report.corrections[index]
    c = size / 2
    rim = size * 0.38
    biggest = max((p.magnitude for p in report.correction_planes), default=0.0)
    tol_here = (math.isfinite(plane.permissible) and _same_positions(report.tolerance_planes,
                                                                   report.correction_planes))
    if tol_here:
        biggest = max(biggest, plane.permissible)
    scale = (rim * 0.9 / biggest) if biggest > 0 else 0.0

    def pt(radius, angle):
        return c + radius * math.cos(angle), c - radius * math.sin(angle)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size + 24}" '
             f'viewBox="0 0 {size} {size + 24}" font-family="sans-serif" font-size="11">',
             f'<title>plane {index + 1} at z = {plane.position * 1e3:.4g} mm</title>',
             f'<circle cx="{c}" cy="{c}" r="{rim}" fill="none" stroke="#888"/>']
    for deg in range(0, 360, 30):
        x1, y1 = pt(rim, math.radians(deg))
        x2, y2 = pt(rim + (8 if deg % 90 == 0 else 4), math.radians(deg))
        parts.append(f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="#888"/>')
        if deg % 90 == 0:
            tx, ty = pt(rim + 20, math.radians(deg))
            parts.append(f'<text x="{tx:.1f}" y="{ty + 4:.1f}" text-anchor="middle" fill="#444">{deg}°</text>')
    if tol_here and scale > 0:
        parts.append(f'<circle cx="{c}" cy="{c}" r="{plane.permissible * scale:.1f}" fill="none" stroke="#2a7" '
                     'stroke-dasharray="4 3"><title>U_per of this plane</title></circle>')
    if plane.magnitude > 0 and scale > 0:
        x, y = pt(plane.magnitude * scale, plane.angle)
        parts.append(f'<line x1="{c}" y1="{c}" x2="{x:.1f}" y2="{y:.1f}" stroke="#c22" stroke-width="3">'
                     f'<title>unbalance {_num(plane.magnitude * _G_MM)} g·mm at {_deg(plane.angle):.1f}°'
                     '</title></line>')
        parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3.5" fill="#c22"/>')
    if corr.mass > 0:
        ax, ay = pt(rim, corr.angle)
        rx, ry = pt(rim, corr.removal_angle)
        parts.append(f'<circle cx="{ax:.1f}" cy="{ay:.1f}" r="7" fill="#16c"><title>add {_num(corr.mass * 1e3)} g '
                     f'at {_deg(corr.angle):.1f}°</title></circle>')
        parts.append(f'<circle cx="{rx:.1f}" cy="{ry:.1f}" r="7" fill="white" stroke="#16c" stroke-width="2">'
                     f'<title>or remove {_num(corr.mass * 1e3)} g at {_deg(corr.removal_angle):.1f}°</title></circle>')
    parts.append(f'<text x="{c}" y="{size + 16}" text-anchor="middle">plane {index + 1}, z = '
                 f'{plane.position * 1e3:.4g} mm: add {_num(corr.mass * 1e3)} g at {_deg(corr.angle):.1f}°</text>')
    parts.append("</svg>")
    return "\n".join(parts)


# ---- Markdown ------------------------------------------------------------------------------------------
def _md_table(head, rows) -> list[str]:
    m = escape_markdown
    return ["| " + " | ".join(map(m, head)) + " |", "|" + "|".join("---" for _ in head) + "|"] + \
        ["| " + " | ".join(map(m, r)) + " |" for r in rows]


def balance_markdown(report: BalanceReport, *, svg_links=()) -> str:
    """The report as Markdown; ``svg_links`` are file names of polar plots written next to it.  Every text
    cell, the part name and the notes are escaped (:func:`inertia_tool.reports.escape.escape_markdown`)."""
    m = escape_markdown
    out = [f"# Balancing report: {m(report.name or 'part')}", ""]
    out += _md_table(["", ""], [[k, v] for k, v in _header(report)])
    out += ["", "## Unbalance as it is", ""] + _md_table(["quantity", "value"],
                                                         [list(r) for r in _summary_rows(report)])
    out += ["", f"## Loads at {report.rpm:.6g} rpm", "", "They rotate with the part; gravity is not included.", ""]
    out += _md_table(["quantity", "value"], [list(r) for r in _load_rows(report)])
    out += ["", "## ISO 21940-11 tolerance", ""] + [f"- {m(x)}" for x in _grade_lines(report)] + [""]
    out += _md_table(_TOL_HEAD, _tolerance_rows(report))
    out += ["", "## " + ("Single-plane (static) correction" if report.single_plane else "Two-plane correction"), ""]
    out += _md_table(_CORR_HEAD, _correction_rows(report))
    out += [""] + [f"![polar plot, plane {k + 1}](<{_link(name)}>)" for k, name in enumerate(svg_links)]
    out += ["", "## Verification", "", "Part plus correction masses, re-analysed: " + m(_verification_text(report))]
    out += ["", "## Balance quality grades (ISO 21940-11)", ""]
    out += _md_table(["grade", "e·Ω [mm/s]", "typical rotors"], [[g.name, f"{g.value:g}", g.typical_parts]
                                                                   for g in ISO_GRADES])
    if report.notes:
        out += ["", "## Notes", ""] + [f"- {m(n)}" for n in report.notes]
    return "\n".join(out) + "\n"


def _link(name: str) -> str:
    """A file name as a CommonMark link destination in ``<...>``: percent-encode what would end it."""
    from urllib.parse import quote
    return quote(name, safe="/-_.~!$'*+,;=:@")


# ---- HTML ----------------------------------------------------------------------------------------------
def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _html_cell(text: str) -> str:
    if _is_number(text):
        return f"<td>{escape_html(text)}</td>"
    keep = ' style="white-space:nowrap"' if len(text) <= 16 else ""       # a label ("G 1600") stays whole
    return f'<td class="l"{keep}>{escape_html(text)}</td>'


def _html_table(head, rows, highlight: str | None = None) -> str:
    """Numbers right-aligned and kept on one line; text cells (descriptions, values with words) left-aligned
    and wrapping (``td.l``), so that a long one cannot push the table past the page (issue 24: the grades
    table was cut off at 1280 px)."""
    e = escape_html
    th = "".join(f"<th>{e(h)}</th>" for h in head)
    body = []
    for r in rows:
        cls = ' class="hl"' if highlight is not None and r[0] == highlight else ""
        body.append(f"<tr{cls}>" + "".join(_html_cell(str(c)) for c in r) + "</tr>")
    return f"<table><thead><tr>{th}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def balance_html(report: BalanceReport) -> str:
    """A self-contained HTML page (no scripts, no external files) with tables and polar plots."""
    e = escape_html
    title = f"Balancing report: {report.name or 'part'}"
    plots = "".join(f'<figure>{polar_svg(report, k)}</figure>' for k in range(len(report.corrections)))
    grades = _html_table(["grade", "e·Ω [mm/s]", "typical rotors"],
                         [[g.name, f"{g.value:g}", g.typical_parts] for g in ISO_GRADES],
                         highlight=None if report.quality_grade is None else report.quality_grade.name)
    notes = "".join(f"<li>{e(n)}</li>" for n in report.notes)
    return html_page(title, f"""{_html_table(["", ""], [list(r) for r in _header(report)])}
<h2>Unbalance as it is</h2>
{_html_table(["quantity", "value"], [list(r) for r in _summary_rows(report)])}
<h2>Loads at {report.rpm:.6g} rpm</h2>
<p class="small">They rotate with the part; gravity is not included.</p>
{_html_table(["quantity", "value"], [list(r) for r in _load_rows(report)])}
<h2>ISO 21940-11 tolerance</h2>
<ul>{''.join(f'<li>{e(x)}</li>' for x in _grade_lines(report))}</ul>
{_html_table(_TOL_HEAD, _tolerance_rows(report))}
<h2>{"Single-plane (static) correction" if report.single_plane else "Two-plane correction"}</h2>
{_html_table(_CORR_HEAD, _correction_rows(report))}
<div>{plots}</div>
<p class="small">Red arrow: the part's unbalance in the plane (length to scale across planes). Filled blue dot:
where to add the correction mass at the correction radius; hollow dot: where to remove it instead. Dashed
green circle: the plane's permissible residual unbalance (when the correction planes are the tolerance planes).
Angles from the shaft x axis towards y.</p>
<h2>Verification</h2>
<p>Part plus correction masses, re-analysed by the engine: {e(_verification_text(report))}</p>
<h2>Balance quality grades (ISO 21940-11)</h2>
{grades}
{f"<h2>Notes</h2><ul>{notes}</ul>" if notes else ""}
<p class="small">Static unbalance U = M·e; couple unbalance: the moment of unbalance about the plane of the centre
of mass; U_per = G·M/Ω, shared between the tolerance planes by the lever rule limited to 0.3–0.7.
Conventions: docs/conventions.md ("Shaft frame").</p>
""")
