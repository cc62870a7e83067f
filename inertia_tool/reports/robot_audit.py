"""The ``inertia-tool robot`` report: per-link geometry results and the audit, as a text table or JSON.

Formatting only: every number comes from :mod:`inertia_tool.robot` (SI; centres of mass in the link frame;
tensors about the centre of mass in link axes, tensor convention −∫xy dm).
"""

from __future__ import annotations

import math

from ..robot.audit import DENSITY_RANGE, LinkAudit
from ..robot.description import RobotDescription
from ..robot.geometry import LinkInertial
from .serialize import TENSOR_CONVENTION, method_and_uncertainty, to_jsonable

__all__ = ["robot_report_dict", "format_robot_report"]


def _declared_dict(audit: LinkAudit):
    d = audit.declared
    if d is None:
        return None
    return {"mass": d.mass, "center_of_mass": d.center_of_mass, "inertia": d.inertia}


def _audit_dict(audit: LinkAudit) -> dict:
    check = audit.declared_check
    return {
        "mass_ratio": audit.mass_ratio,
        "com_distance": audit.com_distance,
        "com_distance_relative": audit.com_distance_relative,
        "inertia_difference": audit.inertia_difference,
        "declared_positive_definite": None if check is None else check.positive,
        "declared_triangle_inequality": None if check is None else check.triangle,
        "implied_density": audit.implied_density,
        "density_plausible": audit.density_plausible,
        "com_in_bounding_box": audit.com_in_bounding_box,
        "com_inside_geometry": audit.com_inside_geometry,
        "link_size": audit.size,
        "issues": list(audit.issues),
    }


def robot_report_dict(robot: RobotDescription, inertials, audits) -> dict:
    """The ``robot --json`` object: ``{"robot", "source", "format", "geometry", "units", "links": [...]}``."""
    links = []
    link_geometry = {link.name: link for link in robot.links}
    for result, audit in zip(inertials, audits):
        props = result.properties
        geometry = link_geometry[result.name]
        method, uncertainty = (None, None) if props is None else method_and_uncertainty(props)
        links.append({
            "name": result.name,
            "mass": None if props is None else props.mass,
            "volume": None if props is None else props.volume,
            "density": result.density,
            "density_basis": result.basis,
            "center_of_mass": None if props is None else props.center_of_mass,
            "inertia": None if props is None else props.inertia,
            "method": method,
            "uncertainty": uncertainty,
            "geometry": [{"kind": e.kind, "name": e.name, "mesh": e.uri} for e in geometry.elements],
            "problem": result.problem,
            "declared": _declared_dict(audit),
            "audit": _audit_dict(audit),
        })
    return to_jsonable({
        "robot": robot.name,
        "source": robot.source,
        "format": robot.format,
        "geometry": robot.geometry,
        "units": {"length": "m", "mass": "kg", "inertia": "kg*m^2", "density": "kg/m^3"},
        "frames": "center_of_mass in the link frame; inertia about the center of mass, link axes",
        "inertia_convention": TENSOR_CONVENTION,
        "density_range": list(DENSITY_RANGE),
        "links": links,
    })


def _fmt(x, spec: str, dash: str = "-") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return dash
    return format(x, spec)


def format_robot_report(robot: RobotDescription, inertials, audits) -> str:
    """A text table (one row per link) followed by the issues, link by link."""
    basis = next((r.basis for r in inertials if r.basis), "")
    lines = [f"robot {robot.name or '(unnamed)'}: {robot.source} ({robot.format.upper()}, {robot.geometry} geometry)",
             f"density: {basis}" if basis else "",
             "centre of mass in the link frame; ΔCOM = |declared − geometry|; ΔI = relative Frobenius difference "
             "of the tensors at equal mass",
             ""]
    header = (f"{'link':<22} {'mass kg':>10} {'declared kg':>12} {'ΔCOM mm':>9} {'ΔI':>8} {'implied ρ':>10}  "
              f"{'COM inside':<10} {'issues':>6}")
    lines += [header, "-" * len(header)]
    inertial: LinkInertial
    for inertial, audit in zip(inertials, audits):
        props = inertial.properties
        declared = audit.declared
        inside = {True: "yes", False: "no", None: "-"}[audit.com_inside_geometry]
        if audit.com_in_bounding_box is False:
            inside = "no (box)"
        lines.append(f"{inertial.name[:22]:<22} {_fmt(props.mass if props else None, '10.4g'):>10} "
                     f"{_fmt(declared.mass if declared else None, '12.4g'):>12} "
                     f"{_fmt(audit.com_distance * 1e3, '9.1f'):>9} {_fmt(audit.inertia_difference, '8.0%'):>8} "
                     f"{_fmt(audit.implied_density, '10.4g'):>10}  {inside:<10} {len(audit.issues):>6}")
    findings = [(r, a) for r, a in zip(inertials, audits) if a.issues]
    if findings:
        lines += ["", "issues:"]
        for result, audit in findings:
            for issue in audit.issues:
                lines.append(f"  {result.name}: {issue}")
    else:
        lines += ["", "no issues found"]
    return "\n".join(line for k, line in enumerate(lines) if line or k > 1)
