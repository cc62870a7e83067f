"""``inertia-tool balance FILE ...``: the dynamic-balancing report (text, JSON, HTML or Markdown).

Routing and formatting only: lengths given on the command line are converted to SI here, the engine is
``inertia_tool.balancing.rotor.balance`` and the writers are in ``inertia_tool.reports.balance``.
"""

from __future__ import annotations

import json
import os

from ..errors import UsageError
from ..units import parse_angular_rate, parse_length
from . import speak_options
from .help import add_command
from .model_options import (add_files_argument, add_model_options, command_parser, length_unit, load_model,
                            shown_with_report, with_warnings)
from .options import check_option
from .report_option import say_written

# numpy, the engine and the reports load in run(): ``balance --help`` needs none of them (issue 25 item 4)

__all__ = ["register", "run"]

#: The ISO 21940-11 grades ``--grade`` names in its help: the parser's copy of the names of
#: ``balancing.rotor.ISO_GRADES`` (the same, in order: ``tests/test_startup.py``).
ISO_GRADE_NAMES = ("G0.4", "G1", "G2.5", "G6.3", "G16", "G40", "G100", "G250", "G630", "G1600", "G4000")

def _lengths(text: str, unit: str, name: str, count) -> list[float]:
    items = [t for t in str(text).replace(";", ",").split(",")]
    if len(items) not in count:
        want = " or ".join(str(c) for c in count)
        raise UsageError(f"Expected --{name} to be {want} comma-separated length(s), got {text!r}")
    return check_option(f"--{name}", [parse_length(t.strip(), default_unit=unit) for t in items], typed=text)


def register(subparsers) -> None:
    grades = ", ".join(ISO_GRADE_NAMES)
    p = add_command(
        subparsers, "balance",
        description="Balancing report of a rigid rotor turning about a given shaft (Chapter 4, §4.3.2): static "
                    "and couple unbalance, ISO 21940-2 kind, rotating bearing loads and the torque of Eq. (4.26), "
                    "the permissible residual unbalance of an ISO 21940-11 grade, and correction masses in one or "
                    "two planes, verified by re-analysing the part with them. All lengths on this command line "
                    "(axis point, planes, radius, bearings) are in the mesh unit given by --units unless they "
                    "carry a unit (e.g. 40mm). Axial positions are measured along the axis direction from the "
                    "axis point. Takes the same model options as analyze.",
        examples=["inertia-tool balance meshes/unbalanced_wheel.stl --units mm --material steel --rpm 3000 "
                  "--planes -30,30 --radius 180 --grade G6.3 --bearings -120,120",
                  "inertia-tool balance meshes/unbalanced_wheel.stl --units mm --material steel --rpm 3000 "
                  "--single-plane --radius 180mm --json",
                  "inertia-tool balance meshes/unbalanced_wheel.stl --units mm --material steel --rpm 3000 "
                  "--planes -30mm,30mm --radius 180mm --report balance.md"])
    add_files_argument(p)
    add_model_options(p)
    s = p.add_argument_group("shaft and correction")
    s.add_argument("--axis-point", default="0,0,0", metavar="X,Y,Z",
                   help="a point of the shaft, mesh coordinates in --units (default 0,0,0)")
    s.add_argument("--axis-direction", default="0,0,1", metavar="DX,DY,DZ",
                   help="direction of the shaft, mesh axes (default 0,0,1)")
    s.add_argument("--rpm", required=True, metavar="SPEED",
                   help="maximum service speed, rev/min (or with a unit: 50Hz, 314rad/s)")
    s.add_argument("--planes", metavar="Z1,Z2",
                   help="axial positions of the two correction planes (one with --single-plane), in --units")
    s.add_argument("--radius", required=True, metavar="R", help="radius of the correction masses, in --units")
    s.add_argument("--single-plane", action="store_true",
                   help="static correction in one plane (narrow discs); without --planes, the plane of the "
                        "centre of mass")
    s.add_argument("--grade", metavar="G", help=f"ISO 21940-11 balance quality grade: {grades}")
    s.add_argument("--bearings", metavar="ZA,ZB",
                   help="axial positions of the two bearings, in --units: the tolerance is checked there and "
                        "the report gives the rotating bearing loads")
    s.add_argument("--drill", metavar="DIAMETER",
                   help="also propose removing material: each correction as a hole of this diameter drilled "
                        "parallel to the shaft at --radius from its plane, e.g. 6mm (in --units); checked to lie "
                        "inside the part")
    o = p.add_argument_group("output")
    o.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of the text report")
    o.add_argument("--report", metavar="FILE.html|FILE.md",
                   help="also write an HTML (self-contained, with polar plots) or Markdown report")
    o.add_argument("--force", action="store_true", help="overwrite an existing --report file")
    p.set_defaults(func=run)


def _report_paths(path: str, count: int) -> tuple[str, list[str]]:
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".html", ".htm", ".md", ".markdown"):
        raise UsageError(f"Expected --report to end in .html or .md, got {path!r}")
    svgs = []
    if ext in (".md", ".markdown"):
        stem = os.path.splitext(path)[0]
        svgs = [f"{stem}-plane{k + 1}.svg" for k in range(count)]
    return ext, svgs


def run(args) -> int:
    from ..balancing.rotor import balance
    from ..output import check_targets, write_files
    from ..reports.balance import balance_dict, balance_html, balance_markdown, format_balance_text, polar_svg
    from ..reports.serialize import command_output, method_and_uncertainty

    unit = length_unit(args)
    axis_point = _lengths(args.axis_point, unit, "axis-point", (3,))
    try:
        direction = [float(t) for t in str(args.axis_direction).split(",")]
    except ValueError:
        direction = []
    if len(direction) != 3:
        raise UsageError(f"Expected --axis-direction to be 3 comma-separated numbers, got {args.axis_direction!r}")
    if args.planes is not None and not args.single_plane and len(str(args.planes).replace(";", ",").split(",")) == 1:
        raise UsageError(f"--planes {args.planes} is one plane: a two-plane (static and couple) correction needs "
                         "two, --planes Z1,Z2; for a static-only correction in one plane add --single-plane")
    planes = None if args.planes is None else _lengths(args.planes, unit, "planes",
                                                       (1,) if args.single_plane else (2,))
    if planes is None and not args.single_plane:
        raise UsageError("Expected --planes Z1,Z2 (or --single-plane)")
    bearings = None if args.bearings is None else _lengths(args.bearings, unit, "bearings", (2,))
    radius = check_option("--radius", parse_length(args.radius, default_unit=unit), typed=args.radius)
    speed = check_option("--rpm", parse_angular_rate(args.rpm, default_unit="rpm"), typed=args.rpm)
    if args.report is not None:      # every file the report will write, checked before any work
        _, svgs = _report_paths(args.report, 1 if args.single_plane else 2)
        check_targets([(args.report, "--report")] + [(name, "--report") for name in svgs], force=args.force)

    drill = None
    if args.drill is not None:
        drill = check_option("--radius", parse_length(args.drill, default_unit=unit), typed=args.drill,
                             label="--drill")             # a length in the range of --radius
    loaded = load_model(args)
    props = loaded.props
    part_mesh = None
    if drill is not None:
        if len(loaded.meshes) != 1 or loaded.model["model"] != "solid":
            raise UsageError("--drill needs a single solid part (an assembly has no one material to drill; a "
                             "shell or printed part no solid to drill into)")
        part_mesh = (loaded.meshes[0].vertices, loaded.meshes[0].faces)     # the file as read, not read again
    report = balance(props, axis_point=axis_point, axis_direction=direction, speed=speed, planes=planes,
                     radius=radius, grade=args.grade, bearings=bearings, single_plane=args.single_plane,
                     drill_diameter=drill, part_mesh=part_mesh)

    parser = command_parser(args)
    if args.report is not None:       # written before anything is printed, so a failure prints one line only
        ext, svgs = _report_paths(args.report, len(report.corrections))
        if ext in (".html", ".htm"):
            files = {args.report: balance_html(report)}
        else:   # the plots first, so the Markdown never links to a plot that is not there
            files = {name: polar_svg(report, k) for k, name in enumerate(svgs)}
            files[args.report] = balance_markdown(report, svg_links=[os.path.basename(n) for n in svgs])
        write_files(files, force=args.force, label="--report")
        say_written(list(files))
    if args.json:
        out = balance_dict(report)
        out["notes"] = [speak_options(n, parser) for n in out.get("notes", [])]
        out["density_source"] = loaded.density_source
        out["model"] = loaded.model
        out["method"], out["uncertainty"] = method_and_uncertainty(loaded.props)
        out["units_assumed"] = loaded.units_assumed
        out = command_output("balance", out, warnings=loaded.warnings)
        print(json.dumps(out, indent=2, ensure_ascii=False, allow_nan=False))
    else:
        print(with_warnings(speak_options(format_balance_text(report), parser), loaded.warnings,
                            loaded.notes()), end="")
    shown_with_report(args, loaded.warnings)
    return 0
