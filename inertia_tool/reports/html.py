"""Self-contained HTML report of ``analyze --report part.html``: tables and three drawn views.

One file, readable offline: no scripts, no fonts, no CDN; the pictures are inline SVG drawn here.  Each view
is an orthographic projection of the mesh (its silhouette and feature edges for that view, capped at
``max_edges`` segments, over its filled outline: the union of its front-facing triangles, or the convex hull
of the projected vertices for a large mesh) with

* the centre of mass (circle with a cross),
* the three principal axes through it (1 red, 2 green, 3 blue: ascending moments; each drawn ± from the
  centre of mass with a length of 0.6 of the part's largest half-extent; an axis pointing out of the page
  is a circle),
* the **equivalent inertia ellipsoid**: the uniform solid ellipsoid with the part's mass and principal
  moments (semi-axes ``a_k = √(5 (I_i + I_j − I_k) / 2m)``, :mod:`inertia_tool.mass.ellipsoid`), projected to
  its outline ellipse.  It is drawn to the part's scale; its long axis is axis 1 (smallest moment).

Formatting only: every number and verdict comes from the engine; the caller computes them (the spin
stability as a ``StabilityReport``) and passes the geometry to draw.  All text (file names too) is escaped.

Sections: the tables of the text report are always there, then the stability verdict when given, then any
``extra_sections`` other capabilities format themselves (see ``docs/html-report.md``).
"""

from __future__ import annotations

import datetime as _dt
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..mass.ellipsoid import equivalent_ellipsoid_semi_axes
from ..errors import InertiaToolError
from ..mass.properties import MassProperties
from .text import face_count_text
from ..tolerances import TRIANGLE_INEQUALITY_RTOL
from .escape import escape_html
from ..output import check_targets, write_text
from .serialize import TENSOR_CONVENTION
from .text import method_line
from .numbers import number, round_off_zero
from ..rounding import round_up

__all__ = ["HtmlSection", "html_report", "write_html_report", "svg_views", "VIEWS",
           "stability_section", "DEFAULT_MAX_EDGES", "DEFAULT_MAX_FILL_FACES"]

#: Segments drawn per view at most (the longest projected ones are kept), so a 10-million-face part
#: still gives a report of a few hundred kB.
DEFAULT_MAX_EDGES = 4000

#: Front-facing triangles filled per view at most; above it the fill is the projected convex hull.
DEFAULT_MAX_FILL_FACES = 3000

#: Dihedral angle (radians) above which an edge is a feature edge and always drawn.
FEATURE_ANGLE = math.radians(30.0)

#: The three views: (title, horizontal axis, vertical axis, viewing direction), mesh axes.
VIEWS = (
    ("top (looking down −z)", 0, 1, np.array([0.0, 0.0, -1.0])),
    ("front (looking along +y)", 0, 2, np.array([0.0, 1.0, 0.0])),
    ("side (looking along −x)", 1, 2, np.array([-1.0, 0.0, 0.0])),
)

_AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")
_AXIS_LETTERS = "xyz"
_VIEW_PX = 300.0
_PAD_PX = 28.0

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1040px;padding:0 1em;color:#222;line-height:1.4}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.15em;border-bottom:1px solid #ccc;padding-bottom:.2em;
margin-top:1.6em}.muted{color:#666;font-size:.9em}
table{border-collapse:collapse;margin:.5em 0;display:block;overflow-x:auto;max-width:100%}
td,th{border:1px solid #ddd;padding:.25em .6em;text-align:right;
font-variant-numeric:tabular-nums;white-space:nowrap}td.l{white-space:normal}th{white-space:normal;background:#f4f4f4;text-align:left}td.l{text-align:left}
.views{display:flex;flex-wrap:wrap;gap:12px}.views figure{margin:0}.views figcaption{text-align:center;
font-size:.9em;color:#444}svg{background:#fff;border:1px solid #ddd}.warn{color:#8a4b00}
.stable{color:#1a7f37}.unstable{color:#b42318;font-weight:600}.marginal{color:#8a4b00}.neutral{color:#555}
.legend>span{display:inline-block;margin-right:1.2em}.swatch{font-weight:700}
tr.hl td{background:#fff4c2}figure{display:inline-block;margin:0 1em}.small{color:#666;font-size:.9em}
"""


def html_page(title: str, body: str) -> str:
    """The one HTML skeleton of the reports: a self-contained page (no scripts, fonts or external files) with
    the shared style sheet, ``<title>`` and ``<h1>`` set to ``title`` (escaped here); ``body`` is an HTML
    fragment whose text its formatter has escaped."""
    return "\n".join(["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
                      '<meta name="viewport" content="width=device-width, initial-scale=1">',
                      f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>",
                      f"<h1>{_e(title)}</h1>", body, "</body></html>\n"])


@dataclass(frozen=True)
class HtmlSection:
    """One section of the report.

    Attributes
    ----------
    title : str
        Plain text (escaped when written).
    body : str
        HTML fragment.  Builders must escape any text they put in it
        (:func:`inertia_tool.reports.escape.escape_html`).
    anchor : str
        ``id`` of the section (letters, digits and ``-``).
    """

    title: str
    body: str
    anchor: str


_e = escape_html


def _num(x: float, digits: int = 6) -> str:
    return number(x, digits)


def _clean(a, rel: float = 1e-12) -> np.ndarray:
    """Display only: entries below ``rel`` of the largest magnitude show as 0 (round-off), as in the text report."""
    return round_off_zero(a, rel)


def _table(header: Sequence[str] | None, rows: Sequence[Sequence[str]], *, left_cols: int = 1,
           text_cols: Sequence[int] = ()) -> str:
    """Rows of already-escaped cell HTML; the first ``left_cols`` and the ``text_cols`` are left-aligned."""
    out = ["<table>"]
    if header:
        out.append("<tr>" + "".join(f"<th>{h}</th>" for h in header) + "</tr>")
    for r in rows:
        cells = [f'<td class="l">{c}</td>' if i < left_cols or i in text_cols else f"<td>{c}</td>"
                 for i, c in enumerate(r)]
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table>")
    return "".join(out)


def _vec_cells(v) -> list[str]:
    return [_num(x) for x in _clean(v)]


# -- drawing --------------------------------------------------------------------------------------------

def _view_edges(vertices: np.ndarray, faces: np.ndarray, direction: np.ndarray, h: int, v: int,
                max_edges: int) -> np.ndarray:
    """(k, 2, 2) projected segments: silhouette edges for ``direction``, feature edges, boundary edges."""
    import trimesh

    if len(faces) == 0:
        return np.zeros((0, 2, 2))
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False, validate=False)
    normals = mesh.face_normals
    adjacency = mesh.face_adjacency
    edges = mesh.face_adjacency_edges
    facing = normals[adjacency] @ direction                       # (k, 2)
    silhouette = np.sign(facing[:, 0]) != np.sign(facing[:, 1])
    feature = mesh.face_adjacency_angles > FEATURE_ANGLE
    keep = edges[silhouette | feature]
    boundary = trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1)
    if len(boundary):
        keep = np.vstack([keep, mesh.edges_sorted[boundary]])
    seg = vertices[keep][:, :, [h, v]]
    if len(seg) > max_edges:
        length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)
        seg = seg[np.sort(np.argpartition(-length, max_edges)[:max_edges])]
    return seg


def _hull(points2: np.ndarray) -> np.ndarray:
    from scipy.spatial import ConvexHull, QhullError

    if len(points2) < 3:
        return points2
    try:
        return points2[ConvexHull(points2).vertices]
    except (QhullError, ValueError):
        return np.zeros((0, 2))


def _projected_ellipse(semi_axes: np.ndarray, axes: np.ndarray, h: int, v: int):
    """Outline of the orthographic shadow of the ellipsoid ``{x: xᵀ(R diag(a⁻²) Rᵀ)x ≤ 1}`` on the (h, v) plane.

    The shadow of an ellipsoid with shape matrix ``S = R diag(a²) Rᵀ`` is the ellipse with shape matrix
    ``P S Pᵀ`` (P picks the two coordinates).  Returns (semi-axis 1, semi-axis 2, angle in degrees of the
    first, counter-clockwise from the horizontal).
    """
    s = axes @ np.diag(semi_axes ** 2) @ axes.T
    s2 = s[np.ix_([h, v], [h, v])]
    w, q = np.linalg.eigh(0.5 * (s2 + s2.T))
    w = np.clip(w, 0.0, None)
    angle = math.degrees(math.atan2(q[1, 1], q[0, 1]))
    return math.sqrt(w[1]), math.sqrt(w[0]), angle


def _nice_length(target: float) -> float:
    if not target > 0:
        return 1.0
    p = 10 ** math.floor(math.log10(target))
    for m in (5, 2, 1):
        if m * p <= target:
            return m * p
    return p


def _format_length(x: float) -> str:
    for unit, scale in (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6)):
        if x >= scale or unit == "µm":
            return f"{x / scale:g} {unit}"
    return f"{x:g} m"


def svg_views(props: MassProperties, meshes: Sequence[tuple] = (), *, max_edges: int = DEFAULT_MAX_EDGES,
              max_fill_faces: int = DEFAULT_MAX_FILL_FACES) -> list[str]:
    """Three inline SVG drawings (top, front, side) of the part, its centre of mass, principal axes and
    equivalent inertia ellipsoid, all views at one scale.

    Parameters
    ----------
    props : MassProperties
    meshes : sequence of (vertices (n, 3) float m, faces (m, 3) int)
        The geometry to draw (mesh axes, metres); empty draws only the ellipsoid and axes.
    max_edges : int
        Cap on drawn segments per view and mesh.
    max_fill_faces : int
        The part is filled with its front-facing triangles (its exact outline) when it has at most this many
        in a view, else with the convex hull of its projected vertices.

    Returns
    -------
    list of str
        Three ``<svg>`` elements.
    """
    pa = props.principal
    com = np.asarray(props.center_of_mass, dtype=float)
    try:
        semi = equivalent_ellipsoid_semi_axes(pa.moments, props.mass)
    except InertiaToolError:
        semi = None
    pts = [np.asarray(v, dtype=float) for v, _ in meshes if len(v)]
    if pts:
        allp = np.vstack(pts)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
    else:
        r = float(np.max(semi)) if semi is not None and np.max(semi) > 0 else 1.0
        lo, hi = com - r, com + r
    if semi is not None:
        reach = float(np.max(semi))
        lo, hi = np.minimum(lo, com - reach), np.maximum(hi, com + reach)
    half = 0.5 * float(np.max(hi - lo)) or 1.0
    axis_len = 0.6 * half
    lo, hi = np.minimum(lo, com - axis_len), np.maximum(hi, com + axis_len)
    span = float(np.max(hi - lo)) or 1.0
    scale = (_VIEW_PX - 2 * _PAD_PX) / span                     # px per metre, same for all views
    svgs = []
    for title, h, v, direction in VIEWS:
        width = (hi[h] - lo[h]) * scale + 2 * _PAD_PX
        height = (hi[v] - lo[v]) * scale + 2 * _PAD_PX

        def px(p, h=h, v=v):
            p = np.asarray(p, dtype=float)
            return (p[..., 0] - lo[h]) * scale + _PAD_PX, (hi[v] - p[..., 1]) * scale + _PAD_PX

        out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
               f'viewBox="0 0 {width:.1f} {height:.1f}" role="img" aria-label="{_e(title)}">',
               f"<title>{_e(title)}</title>"]
        for vertices, faces in meshes:
            vertices = np.asarray(vertices, dtype=float)
            faces = np.asarray(faces)
            tri = vertices[faces]
            normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            front = tri[normal @ direction < 0][:, :, [h, v]]
            if 0 < len(front) <= max_fill_faces:         # exact silhouette: the union of front faces
                x, y = px(front)
                d = "".join(f"M{x[i, 0]:.1f} {y[i, 0]:.1f}L{x[i, 1]:.1f} {y[i, 1]:.1f}L{x[i, 2]:.1f} "
                            f"{y[i, 2]:.1f}Z" for i in range(len(front)))
                out.append(f'<path class="fill" d="{d}" fill="#dfe7f3" stroke="#dfe7f3" stroke-width="0.3"/>')
            else:                                        # large mesh: its convex outline
                hull = _hull(vertices[:, [h, v]])
                if len(hull) >= 3:
                    x, y = px(hull)
                    out.append('<polygon class="hull" fill="#e8eef7" stroke="none" points="'
                               + " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(x, y)) + '"/>')
            seg = _view_edges(vertices, np.asarray(faces), direction, h, v, max_edges)
            if len(seg):
                x, y = px(seg)
                d = "".join(f"M{x[i, 0]:.1f} {y[i, 0]:.1f}L{x[i, 1]:.1f} {y[i, 1]:.1f}" for i in range(len(seg)))
                out.append(f'<path class="edges" d="{d}" stroke="#555" stroke-width="0.6" fill="none" '
                           'stroke-linecap="round"/>')
        cx, cy = px(com[[h, v]])
        if semi is not None:
            a1, a2, angle = _projected_ellipse(semi, pa.axes, h, v)
            out.append(f'<ellipse class="ellipsoid" cx="{cx:.1f}" cy="{cy:.1f}" rx="{a1 * scale:.1f}" '
                       f'ry="{a2 * scale:.1f}" transform="rotate({-angle:.2f} {cx:.1f} {cy:.1f})" '
                       'fill="#ff7f0e" fill-opacity="0.12" stroke="#ff7f0e" stroke-width="1.5" '
                       'stroke-dasharray="5 3"><title>equivalent inertia ellipsoid</title></ellipse>')
        for k in range(3):
            axis = pa.axes[:, k]
            end = com + axis_len * axis
            start = com - axis_len * axis
            x0, y0 = px(start[[h, v]])
            x1, y1 = px(end[[h, v]])
            colour = _AXIS_COLOURS[k]
            if math.hypot(x1 - x0, y1 - y0) < 4.0:               # pointing out of the page
                out.append(f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="4" fill="none" stroke="{colour}" '
                           f'stroke-width="1.5"><title>axis {k + 1} (out of the page)</title></circle>')
                continue
            out.append(f'<line class="axis{k + 1}" x1="{x0:.1f}" y1="{y0:.1f}" x2="{x1:.1f}" y2="{y1:.1f}" '
                       f'stroke="{colour}" stroke-width="1.8"><title>principal axis {k + 1}</title></line>')
            out.append(f'<text x="{x1 + 3:.1f}" y="{y1 - 3:.1f}" font-size="12" fill="{colour}" '
                       f'font-family="sans-serif">{k + 1}</text>')
        out.append(f'<circle class="com" cx="{cx:.1f}" cy="{cy:.1f}" r="5" fill="#fff" stroke="#000" '
                   'stroke-width="1.2"><title>centre of mass</title></circle>')
        out.append(f'<path d="M{cx - 5:.1f} {cy:.1f}H{cx + 5:.1f}M{cx:.1f} {cy - 5:.1f}V{cy + 5:.1f}" '
                   'stroke="#000" stroke-width="1"/>')
        # view axes and a scale bar
        bar = _nice_length(0.3 * span)
        out.append(f'<path d="M8 {height - 8:.1f}h24M8 {height - 8:.1f}v-24" stroke="#333" stroke-width="1" '
                   'fill="none"/>')
        out.append(f'<text x="35" y="{height - 5:.1f}" font-size="11" font-family="sans-serif">'
                   f"{_AXIS_LETTERS[h]}</text><text x=\"4\" y=\"{height - 36:.1f}\" font-size=\"11\" "
                   f'font-family="sans-serif">{_AXIS_LETTERS[v]}</text>')
        bx = width - 10 - bar * scale
        out.append(f'<path d="M{bx:.1f} {height - 10:.1f}h{bar * scale:.1f}" stroke="#333" stroke-width="2"/>'
                   f'<text x="{bx:.1f}" y="{height - 14:.1f}" font-size="11" font-family="sans-serif">'
                   f"{_e(_format_length(bar))}</text>")
        out.append("</svg>")
        svgs.append("".join(out))
    return svgs


# -- sections -------------------------------------------------------------------------------------------

def stability_section(report) -> HtmlSection:
    """Spin stability of the three principal axes (§4.4.1) from a
    :class:`~inertia_tool.dynamics.spin_stability.StabilityReport`, or the reason it is undefined (a str)."""
    if isinstance(report, str):
        return HtmlSection("Spin stability", f'<p class="warn">{_e(report)}</p>', "stability")
    rows = []
    for ax in report.axes:
        if ax.kind == "stable":
            detail = f"wobbles every {_num(ax.wobble_period_turns, 4)} turns"
        elif ax.kind == "unstable":
            detail = (f"grows e-fold every {_num(ax.e_folding_turns, 4)} turns; a 1e-3 wobble reaches "
                      f"order 1 in {_num(ax.turns_to_grow(1e-3, 1.0), 4)} turns")
        elif ax.kind == "marginal":
            detail = f"grows linearly; 1e-3 → 1 in {_num(ax.turns_to_grow(1e-3, 1.0), 4)} turns"
        else:
            detail = "every axis is a steady spin"
        axis = "(" + ", ".join(_num(x, 4) for x in _clean(ax.axis)) + ")"
        rows.append([f'<span style="color:{_AXIS_COLOURS[ax.index]}">■</span> {ax.index + 1} ({_e(ax.name)})',
                     f"{ax.moment:.6e}", axis, f'<span class="{_e(ax.kind)}">{_e(ax.kind)}</span>',
                     _num(ax.coefficient, 4), _e(detail), "yes" if ax.dissipation_stable else "no"])
    body = ("<p>Torque-free spin about each principal axis, linearised Euler equations (§4.4.1): a small "
            "wobble ε obeys ε̈ = c ω² ε with c = (I<sub>i</sub> − I<sub>k</sub>)(I<sub>k</sub> − I<sub>j</sub>)"
            "/(I<sub>i</sub> I<sub>j</sub>). <em>With energy loss</em> only the axis of largest moment stays "
            "stable (major-axis rule).</p>"
            + _table(["axis", "moment (kg·m²)", "direction (mesh axes)", "free spin", "c",
                      "what a small wobble does", "stable with energy loss"], rows, left_cols=1,
                     text_cols=(3, 5, 6)))
    return HtmlSection("Spin stability", body, "stability")


def _core_sections(props: MassProperties, density_source: str | None, semi,
                   result: str | None = None) -> list[HtmlSection]:
    pa = props.principal
    summary = [["mass", _num(props.mass), "kg"], ["volume", _num(props.volume), "m³"],
               ["surface area", _num(props.surface_area), "m²"], ["density", _num(props.density), "kg/m³"]]
    if density_source:
        summary.append(["density from", _e(density_source), ""])
    summary.append(["centre of mass", "(" + ", ".join(_vec_cells(props.center_of_mass)) + ")", "m"])
    verdict = f"<p><strong>Result:</strong> {_e(result or method_line(props.mesh))}</p>"
    sections = [HtmlSection("Mass properties", verdict + _table(None, summary), "mass")]
    ten = _clean(props.inertia)
    origin = _clean(np.asarray(props.inertia_about(np.zeros(3), far_point_ratio=None)))
    tensor_rows = [[_AXIS_LETTERS[i]] + [f"{x:.6e}" for x in ten[i]] for i in range(3)]
    origin_rows = [[_AXIS_LETTERS[i]] + [f"{x:.6e}" for x in origin[i]] for i in range(3)]
    body = (f"<p>kg·m², mesh axes; {_e(TENSOR_CONVENTION)}. Entries below 1e-12 of the largest show as 0.</p>"
            "<h3>about the centre of mass</h3>" + _table(["", "x", "y", "z"], tensor_rows)
            + "<h3>about the mesh origin (0, 0, 0)</h3>" + _table(["", "x", "y", "z"], origin_rows))
    sections.append(HtmlSection("Inertia tensor", body, "inertia"))
    rows = []
    for k in range(3):
        rows.append([f'<span style="color:{_AXIS_COLOURS[k]}">■</span>&nbsp;I{k + 1}', f"{pa.moments[k]:.6e}",
                     "(" + ", ".join(_vec_cells(pa.axes[:, k])) + ")", _num(pa.radii_of_gyration[k]),
                     _num(semi[k]) if semi is not None else "—"])
    notes = []
    if pa.is_spherical:
        notes.append("All three moments are equal: every axis through the centre of mass is principal.")
    elif pa.is_axisymmetric:
        i, j = pa.equal_pairs[0]
        notes.append(f"I{i + 1} and I{j + 1} are equal within {pa.rtol:g}: any axis in their plane is principal; "
                     "the two shown are one choice.")
    margin = pa.triangle_inequality_margin
    positive = bool(np.all(pa.moments > 0))
    notes.append(f"Checks: moments positive: {'yes' if positive else 'NO'}; triangle inequality I1 + I2 ≥ I3: "
                 f"{'yes' if margin >= -TRIANGLE_INEQUALITY_RTOL else 'NO'} (margin {_num(margin, 3)}).")
    body = (_table(["", "moment (kg·m²)", "unit axis (mesh axes)", "radius of gyration (m)",
                    "equivalent-ellipsoid semi-axis (m)"], rows)
            + "".join(f"<p>{_e(n)}</p>" for n in notes))
    sections.append(HtmlSection("Principal axes (ascending moments, right-handed)", body, "principal"))
    if props.parts and any(b.mesh is not None for b in props.parts):
        rows = [[_e(b.name), _e(b.material or "-"), _num(b.density), _num(b.mass), _num(b.volume),
                 "(" + ", ".join(_vec_cells(b.center_of_mass)) + ")",
                 _e(b.mesh.certificate.brief() if b.mesh is not None else "-")] for b in props.parts]
        sections.append(HtmlSection(
            f"Parts ({len(props.parts)})",
            _table(["part", "material", "density (kg/m³)", "mass (kg)", "volume (m³)", "centre of mass (m)",
                    "certificate"], rows)
            + "<p>Each part is integrated alone; the totals are their sum about the common centre of mass "
              "(parallel-axis theorem, Chapter 4 “Rigid Body Motion”, Eq. (4.16)).</p>", "bodies"))
    elif props.parts:
        rows = [[_e(b.name), _num(b.mass), _num(b.volume), "(" + ", ".join(_vec_cells(b.center_of_mass)) + ")"]
                for b in props.parts]
        sections.append(HtmlSection(f"Bodies ({len(props.parts)})",
                                    _table(["body", "mass (kg)", "volume (m³)", "centre of mass (m)"], rows),
                                    "bodies"))
    mesh = props.mesh
    if mesh is not None:
        u = mesh.uncertainty
        bounds = ("none: exact for the polyhedron" if u is None else
                  f"mass ±{round_up(100 * u.mass):.3g}%, centre of mass {round_up(u.center_of_mass):.3g} m, "
                  f"inertia ±{round_up(100 * u.inertia):.3g}%")
        rows = [["method", _e(mesh.method)], ["certificate", _e(mesh.certificate.describe())],
                ["uncertainty", _e(bounds)],
                ["faces", _e(face_count_text(mesh))], ["vertices", f"{mesh.vertices:,}"],
                ["bodies / cavities", f"{mesh.bodies} / {mesh.cavities}"],
                ["watertight and consistently wound as read", "yes" if mesh.watertight else "no"],
                ["degenerate faces ignored / zero-area faces", f"{mesh.degenerate_faces} / {mesh.zero_area_faces}"],
                ["bounding box (m)", "(" + ", ".join(_vec_cells(mesh.bbox_min)) + ") – ("
                 + ", ".join(_vec_cells(mesh.bbox_max)) + ")"]]
        if mesh.welded_tolerance is not None:
            rows.append(["welded within", f"{round_up(mesh.welded_tolerance):.3g} m"])
        if mesh.flipped_shells:
            rows.append(["inside-out shells flipped", str(mesh.flipped_shells)])
        if mesh.overlapping_shells:
            how = "united, shared volume counted once" if mesh.method == "union" else "volume counted twice"
            rows.append([f"overlapping bodies ({how})", str(mesh.overlapping_shells)])
        for note in mesh.notes:
            rows.append(["note", _e(note)])
        if mesh.repaired and not mesh.notes:
            rows.append(["repaired", _e(", ".join(mesh.repair_actions))])
        sections.append(HtmlSection(f"Mesh ({mesh.units} coordinates, converted to m)",
                                    _table(None, rows, text_cols=(1,)), "mesh"))   # values are text: wrap
    return sections


def html_report(props: MassProperties, *, meshes: Sequence[tuple] = (), density_source: str | None = None,
                warnings: Sequence[str] = (), stability=None, extra_sections: Sequence[HtmlSection] = (),
                max_edges: int = DEFAULT_MAX_EDGES, generated: str | None = None, result: str | None = None) -> str:
    """The complete HTML document (a string).

    Parameters
    ----------
    props : MassProperties
    meshes : sequence of (vertices, faces)
        Geometry to draw, metres, mesh axes (see :func:`svg_views`).
    density_source : str, optional
        How the density was chosen (shown as is, escaped).
    warnings : sequence of str
        Soft problems to list.
    stability : StabilityReport or str, optional
        The spin-stability verdict (:func:`inertia_tool.stability`) or the reason it is undefined; omitted
        when ``None``.  Formatting only: the caller computes it.
    extra_sections : sequence of HtmlSection
        Appended after the built ones (other capabilities' sections, formatted by their callers).
    max_edges : int
        Cap on drawn segments per view.
    generated : str, optional
        Time stamp text; default now (UTC).
    result : str, optional
        Where the numbers come from, instead of the mesh's method (a STEP file's exact B-rep says so).
    """
    pa = props.principal
    try:
        semi = equivalent_ellipsoid_semi_axes(pa.moments, props.mass)
    except InertiaToolError:
        semi = None
    sections = _core_sections(props, density_source, semi, result)
    if stability is not None:
        sections.append(stability_section(stability))
    sections.extend(extra_sections)
    views = svg_views(props, meshes, max_edges=max_edges)
    stamp = generated or _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    from .. import __version__
    figure = "".join(f"<figure>{svg}<figcaption>{_e(t)}</figcaption></figure>"
                     for svg, (t, *_rest) in zip(views, VIEWS))
    legend = ('<p class="legend">'
              + "".join(f'<span><span class="swatch" style="color:{_AXIS_COLOURS[k]}">━</span> principal axis {k + 1} '
                        f"(I{k + 1} = {pa.moments[k]:.4g} kg·m²)</span>" for k in range(3))
              + '<span>⊕ centre of mass</span><span><span class="swatch" style="color:#ff7f0e">┅</span> '
                "equivalent inertia "
                "ellipsoid (uniform solid ellipsoid with the same mass and principal moments)</span>"
                "<span>grey: silhouette and feature edges</span></p>")
    parts = [f'<p class="muted">inertia-tool {_e(__version__)}, {_e(stamp)}. SI units (m, kg, kg·m²); '
             "conventions: docs/conventions.md.</p>",
             '<h2 id="views">Views</h2>', legend, f'<div class="views">{figure}</div>']
    if warnings:
        parts.append('<h2 id="warnings">Warnings</h2><ul>'
                     + "".join(f'<li class="warn">{_e(w)}</li>' for w in warnings) + "</ul>")
    for s in sections:
        anchor = "".join(c for c in s.anchor if c.isalnum() or c == "-") or "section"
        parts.append(f'<h2 id="{anchor}">{_e(s.title)}</h2>{s.body}')
    return html_page(f"Mass properties of {props.name}", "\n".join(parts))


def write_html_report(path: str | os.PathLike, document: str, *, force: bool = False) -> None:
    """Write ``document`` to ``path`` through the one output writer (:mod:`inertia_tool.output`):
    refuse to replace an existing file unless ``force``, write atomically (a failure never leaves half a
    report)."""
    check_targets([os.fspath(path)], force=force)
    write_text(path, document)
