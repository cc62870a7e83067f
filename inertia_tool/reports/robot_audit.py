"""The ``inertia-tool robot`` report: per-link geometry results and the audit, as a text table or JSON.

Formatting only: every number comes from :mod:`inertia_tool.robot` (SI; centres of mass in the link frame;
tensors about the centre of mass in link axes, tensor convention −∫xy dm).
"""

from __future__ import annotations

import math

from ..robot.audit import DENSITY_RANGE, LinkAudit
from ..robot.description import RobotDescription
from ..robot.geometry import LinkInertial
from .serialize import TENSOR_CONVENTION, to_jsonable

__all__ = ["robot_report_dict", "format_robot_report", "links_without_result", "summary_line", "left_unchanged",
           "corpus_report_dict", "format_corpus_report"]


def links_without_result(robot: RobotDescription, inertials) -> list:
    """The results that are missing although the link has geometry or a declared mass, or could not be read
    (an included model not on disk); a virtual frame — no geometry, no mass — has nothing to compute and is
    not counted."""
    geometry = {link.name: link for link in robot.links}
    out = []
    for result in inertials:
        link = geometry[result.name]
        declared_mass = link.declared is not None and link.declared.mass > 0
        if result.properties is None and (link.elements or declared_mass or link.unread):
            out.append(result)
    return out


#: The start of a link's problem that stands for all of it in :func:`left_unchanged` (the rest names files and
#: is in the table).
_SHORT_PROBLEMS = ("mesh needs repair or cannot be read", "mesh cannot be read or bounded, even with repair",
                   "cannot be computed")


def left_unchanged(inertials, changed, *, included: tuple[str, ...] = ()) -> str:
    """``"a (no collision geometry), b (mesh needs repair or cannot be read)"``: the links a written copy left
    as they were, each with the reason; "" when every link was corrected.  ``included``: the files the main file
    includes when all its bodies are theirs (:func:`~inertia_tool.robot.write.included_files`, a Menagerie
    ``scene.xml``): the computed links are then named once, with the file to write instead."""
    parts = []
    elsewhere = []
    for result in inertials:
        if result.name in changed:
            continue
        if result.properties is not None and included:
            elsewhere.append(result.name)
            continue
        if result.properties is not None:
            reason = "no element of its own in the file"          # e.g. a copy made by MJCF <replicate>
        else:
            reason = next((short for short in _SHORT_PROBLEMS if (result.problem or "").startswith(short)),
                          result.problem or "no result")
        parts.append(f"{result.name} ({reason})")
    if elsewhere:
        files = ", ".join(included)
        parts.insert(0, f"{len(elsewhere)} computed bod{'y' if len(elsewhere) == 1 else 'ies'} of {files}, which "
                        f"this file includes (only the main file is written: run --write on {files} to correct "
                        f"them): {', '.join(elsewhere)}")
    return ", ".join(parts)


def other_geometry_only(robot: RobotDescription, inertials, missing=None) -> list:
    """The results missing for links that have geometry only of the kind not read (``<visual>`` in a collision
    audit) and no declared mass: not frames, and not counted in :func:`links_without_result` (a massless link
    with a visual is what URDF and SDFormat simulators take it for)."""
    missing = links_without_result(robot, inertials) if missing is None else missing
    links = {link.name: link for link in robot.links}
    return [r for r in inertials if r.properties is None and r not in missing and links[r.name].unselected]


def summary_line(robot: RobotDescription, inertials) -> str:
    """One line: how many links were computed, by which method, and which have no result."""
    computed = [r for r in inertials if r.properties is not None]
    methods: dict = {}
    for r in computed:
        methods[r.method] = methods.get(r.method, 0) + 1
    by_method = ", ".join(f"{n} {m}" for m, n in sorted(methods.items()))
    missing = links_without_result(robot, inertials)
    text = (f"{len(inertials)} link{'' if len(inertials) == 1 else 's'}: {len(computed)} computed"
            + (f" ({by_method})" if by_method else ""))
    if missing:
        text += f"; {len(missing)} without a result: {', '.join(r.name for r in missing)}"
    other = other_geometry_only(robot, inertials, missing)
    frames = len(inertials) - len(computed) - len(missing) - len(other)
    if other:
        kind = {"collision": "visual geometry", "visual": "collision geometry"}.get(robot.geometry,
                                                                                 "geoms outside the selection")
        text += (f"; {len(other)} with only {kind} and no declared mass, not computed: "
                 f"{', '.join(r.name for r in other)}")
    if frames:
        text += f"; {frames} without geometry or mass (frames)"
    return text


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
        "causes": [{"cause": c.cause, "explanation": c.explanation, "difference_before": c.before,
                    "difference_after": c.after, "corrected_inertia": c.inertia, "corrected_mass": c.mass}
                   for c in audit.causes],
        "nearest_valid_inertia": audit.nearest_valid_inertia,
    }


def robot_report_dict(robot: RobotDescription, inertials, audits) -> dict:
    """The ``robot --json`` object: ``{"robot", "source", "format", "geometry", "units", "links": [...]}``."""
    links = []
    link_geometry = {link.name: link for link in robot.links}
    for result, audit in zip(inertials, audits):
        props = result.properties
        geometry = link_geometry[result.name]
        links.append({
            "name": result.name,
            "mass": None if props is None else props.mass,
            "volume": None if props is None else props.volume,
            "density": result.density,
            "density_basis": result.basis,
            "center_of_mass": None if props is None else props.center_of_mass,
            "inertia": None if props is None else props.inertia,
            "geometry": [{"kind": e.kind, "name": e.name, "mesh": e.uri, "submesh": e.submesh or None}
                         for e in geometry.elements],
            "problem": result.problem,
            "method": result.method,
            "assumptions": list(result.assumptions),
            "uncertainty": None if result.uncertainty is None else {
                "mass": result.uncertainty.mass, "center_of_mass": result.uncertainty.center_of_mass,
                "inertia": result.uncertainty.inertia},
            "warnings": list(result.warnings),
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
        "summary": summary_line(robot, inertials),
        "links_without_result": [r.name for r in links_without_result(robot, inertials)],
    })


def _fmt(x, spec: str, dash: str = "-") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return dash
    return format(x, spec)


def _assumed_cell(result: LinkInertial) -> str:
    """The ``assumed`` cell of a link: the user's assumptions its result rests on (``Certificate.assumptions``
    of its meshes), ``none`` when it rests on none, ``-`` without a result."""
    if result.properties is None:
        return "-"
    return ", ".join(result.assumptions) or "none"


def _bounds_text(result: LinkInertial) -> str:
    """``"mass ±5.1 %, centre of mass ±0.31 mm, inertia ±8.2 %"``: a link estimate's bounds
    (:class:`~inertia_tool.robot.geometry.LinkUncertainty`), or why there are none."""
    u = result.uncertainty
    if u is None:
        return "no bounds given"
    inertia = (f"inertia ±{u.inertia * 100:.3g} %" if u.inertia is not None
               else "inertia: no bound claimed (several elements, or a primitive fitted to an estimate)")
    return f"mass ±{u.mass * 100:.3g} %, centre of mass ±{u.center_of_mass * 1e3:.3g} mm, {inertia}"


def format_robot_report(robot: RobotDescription, inertials, audits) -> str:
    """A text table (one row per link) followed by the issues, link by link."""
    basis = next((r.basis for r in inertials if r.basis), "")
    lines = [f"robot {robot.name or '(unnamed)'}: {robot.source} ({robot.format.upper()}, {robot.geometry} geometry)",
             f"density: {basis}" if basis else "",
             "centre of mass in the link frame; ΔCOM = |declared − geometry|; ΔI = relative Frobenius difference "
             "of the tensors at equal mass",
             ""]
    width = max([4] + [len(r.name) for r in inertials])
    assumed = [_assumed_cell(r) for r in inertials]
    a_width = max([len("assumed")] + [len(a) for a in assumed])
    header = (f"{'link':<{width}} {'method':<10} {'assumed':<{a_width}} {'mass kg':>10} {'declared kg':>12} "
              f"{'ΔCOM mm':>9} {'ΔI':>8} {'implied ρ':>10}  {'COM inside':<10} {'issues':>6}")
    lines += [header, "-" * len(header)]
    inertial: LinkInertial
    missing = links_without_result(robot, inertials)
    other = other_geometry_only(robot, inertials, missing)
    for inertial, audit, assumed_cell in zip(inertials, audits, assumed):
        props = inertial.properties
        declared = audit.declared
        inside = {True: "yes", False: "no", None: "-"}[audit.com_inside_geometry]
        if audit.com_in_bounding_box is False:
            inside = "no (box)"
        method = inertial.method or ("frame" if inertial not in missing and inertial not in other else "none")
        lines.append(f"{inertial.name:<{width}} {method:<10} {assumed_cell:<{a_width}} "
                     f"{_fmt(props.mass if props else None, '10.4g'):>10} "
                     f"{_fmt(declared.mass if declared else None, '12.4g'):>12} "
                     f"{_fmt(audit.com_distance * 1e3, '9.1f'):>9} {_fmt(audit.inertia_difference, '8.0%'):>8} "
                     f"{_fmt(audit.implied_density, '10.4g'):>10}  {inside:<10} {len(audit.issues):>6}")
    bounded = [f"  {r.name}: {_bounds_text(r)}" for r in inertials if r.properties is not None
               and (r.uncertainty is not None or r.method == "estimate")]
    if bounded:
        lines += ["", "bounds of the estimates (as in the JSON 'uncertainty'):"]
        lines += bounded
    findings = [(r, a) for r, a in zip(inertials, audits) if a.issues]
    if findings:
        lines += ["", "issues:"]
        for result, audit in findings:
            for issue in audit.issues:
                lines.append(f"  {result.name}: {issue}")
    else:
        lines += ["", "no issues found"]
    noted = [(r.name, w) for r in inertials for w in r.warnings]
    if noted:
        lines += ["", "warnings:"] + [f"  {name}: {w}" for name, w in noted]
    without = [r for r in missing + other
               if not any(r.problem in i for a in audits if a.name == r.name for i in a.issues)]
    if without:
        lines += ["", "no result:"] + [f"  {r.name}: {r.problem}" for r in without]
    lines += ["", summary_line(robot, inertials)]
    return "\n".join(line for k, line in enumerate(lines) if line or k > 1)


# -- a corpus: one line per model, the causes, one summary --------------------------------------------------

def _cause_counts(models) -> dict:
    counts: dict = {}
    for model in models:
        for audit in model.audits:
            if audit.causes:
                counts[audit.causes[0].cause] = counts.get(audit.causes[0].cause, 0) + 1
    return counts


def _corpus_summary(models) -> str:
    read = [m for m in models if m.robot is not None]
    links = sum(len(m.inertials) for m in read)
    computed = sum(1 for m in read for r in m.inertials if r.properties is not None)
    missing = sum(len(links_without_result(m.robot, m.inertials)) for m in read)
    flagged = sum(1 for m in read for a in m.audits if a.issues)
    causes = _cause_counts(models)
    text = (f"{len(models)} model{'' if len(models) == 1 else 's'} ({len(models) - len(read)} unreadable): "
            f"{links} links, {computed} computed, {missing} without a result, {flagged} with issues")
    if causes:
        text += "; likely causes: " + ", ".join(f"{k} {n}" for k, n in sorted(causes.items(), key=lambda i: -i[1]))
    return text


def corpus_report_dict(models) -> dict:
    """The ``robot DIR --json`` object: ``{"models": [per-model report or {"source", "problem"}], "summary"}``."""
    out = []
    for model in models:
        if model.robot is None:
            out.append(to_jsonable({"source": model.source, "problem": model.problem}))
        else:
            out.append(robot_report_dict(model.robot, model.inertials, model.audits))
    return {"models": out, "summary": _corpus_summary(models), "likely_causes": _cause_counts(models)}


def format_corpus_report(models) -> str:
    """One line per model, then each link's likely cause with its evidence, then the summary line."""
    width = max([5] + [len(m.source) for m in models])
    header = f"{'model':<{width}} {'format':<6} {'links':>5} {'computed':>8} {'no result':>9} {'issues':>6}"
    lines = [header, "-" * len(header)]
    for m in models:
        if m.robot is None:
            lines.append(f"{m.source:<{width}} unreadable: {m.problem}")
            continue
        computed = sum(1 for r in m.inertials if r.properties is not None)
        missing = len(links_without_result(m.robot, m.inertials))
        flagged = sum(1 for a in m.audits if a.issues)
        lines.append(f"{m.source:<{width}} {m.robot.format:<6} {len(m.inertials):>5} {computed:>8} {missing:>9} "
                     f"{flagged:>6}")
    causes = [(m.source, a.name, c) for m in models for a in m.audits for c in a.causes[:1]]
    if causes:
        lines += ["", "likely causes:"] + [f"  {src}: {name}: {c.explanation}" for src, name, c in causes]
    if any(m.robot is not None and (links_without_result(m.robot, m.inertials) or any(a.issues for a in m.audits))
           for m in models):
        # the table counts; a newcomer needs to know where the links, issues and reasons are (user trial)
        lines += ["", "each model's links, issues and reasons without a result: the same command on one FILE, or "
                      "--json here"]
    lines += ["", _corpus_summary(models)]
    return "\n".join(lines)
