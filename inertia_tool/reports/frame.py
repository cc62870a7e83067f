"""Mass properties in a chosen coordinate system (``analyze --about``/``--axes``): text, JSON and HTML.

Formatting only; the numbers are :class:`inertia_tool.mass.frame.FrameInertia`'s.
"""

from __future__ import annotations

import numpy as np

from .escape import escape_html
from .numbers import round_off_zero

__all__ = ["format_frame_inertia", "frame_inertia_dict", "frame_inertia_section"]


def _vec(v) -> str:
    return "(" + ", ".join(f"{x: .6g}" for x in round_off_zero(np.asarray(v), 1e-12)) + ")"


def _axes_words(rotation) -> str:
    r = np.asarray(rotation)
    if np.array_equal(r, np.eye(3)):
        return "mesh axes"
    return "axes x′ " + _vec(r[:, 0]) + ", y′ " + _vec(r[:, 1]) + ", z′ " + _vec(r[:, 2]) + " (mesh coordinates)"


def format_frame_inertia(frame) -> str:
    """Lines of the text report: the coordinate system, the centre of mass in it, and both tensors."""
    lines = [f"  in the coordinate system at {_vec(frame.origin)} m (mesh coordinates), {_axes_words(frame.rotation)}:",
             f"    centre of mass:  {_vec(frame.center_of_mass)} m (in this system)",
             "    inertia about the system's origin, its axes (kg·m², tensor convention: off-diagonals −∫xy dm):"]
    for row in round_off_zero(np.asarray(frame.inertia), 1e-12):
        lines.append("      [" + "  ".join(f"{x: .6e}" for x in row) + " ]")
    lines.append("    inertia about the centre of mass, the system's axes (kg·m²):")
    for row in round_off_zero(np.asarray(frame.central_inertia), 1e-12):
        lines.append("      [" + "  ".join(f"{x: .6e}" for x in row) + " ]")
    return "\n".join(lines)


def frame_inertia_dict(frame) -> dict:
    """JSON-ready, SI: origin (mesh coordinates), axes (rows: the system's x, y, z in mesh coordinates)."""
    return {"origin": [float(x) for x in frame.origin],
            "axes": [[float(x) for x in frame.rotation[:, k]] for k in range(3)],
            "center_of_mass": [float(x) for x in frame.center_of_mass],
            "inertia_about_origin": [[float(x) for x in row] for row in frame.inertia],
            "inertia_about_center_of_mass": [[float(x) for x in row] for row in frame.central_inertia],
            "convention": "tensor elements (off-diagonals -∫xy dm), kg·m², the system's axes"}


def frame_inertia_section(frame):
    """The coordinate system's numbers as a section of the HTML report."""
    from .html import HtmlSection
    e = escape_html

    def table(m) -> str:
        rows = "".join("<tr><th>" + "xyz"[i] + "′</th>" + "".join(f"<td>{x:.6e}</td>" for x in row) + "</tr>"
                       for i, row in enumerate(round_off_zero(np.asarray(m), 1e-12)))
        return "<table><tr><th></th><th>x′</th><th>y′</th><th>z′</th></tr>" + rows + "</table>"

    body = (f"<p>Origin {e(_vec(frame.origin))} m (mesh coordinates); {e(_axes_words(frame.rotation))}. "
            f"Centre of mass in this system: {e(_vec(frame.center_of_mass))} m.</p>"
            "<h3>inertia about the origin, the system's axes (kg·m²)</h3>" + table(frame.inertia)
            + "<h3>inertia about the centre of mass, the system's axes (kg·m²)</h3>" + table(frame.central_inertia))
    return HtmlSection("Chosen coordinate system", body, "frame")
