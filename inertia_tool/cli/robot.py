"""``inertia-tool robot ROBOT``: per-link mass properties from a robot description's geometry, an audit of
the declared inertials, and optionally a corrected copy of the description."""

from __future__ import annotations

import json
import os
import sys

from ..errors import UsageError
from ..tolerances import DEFAULT_MAX_FACES
from ..units import MATERIALS, parse_density
from . import EXIT_INCOMPLETE, EXIT_OK, speak_options
from .help import add_command
from .options import check_option
from ..reports.escape import escape_terminal
from .model_options import add_assume_option, assumed_from_args, recorded_warnings, shown_with_report
from .report_option import check_output_file

# the readers, the engine and the reports load in run(): ``robot --help`` needs none of them (issue 25 item 4)

__all__ = ["register", "run", "parse_packages", "parse_mappings"]

#: ``--geometry``'s choices and ``--density``'s word for the description's own densities: the parser's copies
#: of ``robot.description.GEOMETRY_KINDS`` and ``robot.geometry.MODEL_DENSITY`` (the same: tests/test_startup.py).
GEOMETRY_KINDS = ("collision", "visual", "all")
MODEL_DENSITY = "model"


def register(subparsers) -> None:
    ur5 = ("tests/data/robots/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf "
           "--package example-robot-data=tests/data/robots/example-robot-data")
    panda = ("tests/data/robots/example-robot-data/robots/panda_description/urdf/panda.urdf "
             "--package example-robot-data=tests/data/robots/example-robot-data")
    p = add_command(
        subparsers, "robot",
        description="Read a robot description (URDF, xacro, SDFormat, MuJoCo MJCF), compute every link's mass, "
                    "centre of mass and inertia tensor from its collision (or visual) geometry in the link frame, "
                    "compare them with the declared <inertial> elements, and optionally write a copy of the "
                    "description with corrected <inertial> elements (origin at the centre of mass, rpy 0, full "
                    "tensor). See docs/robots.md.",
        examples=[f"inertia-tool robot {panda} --keep-mass",
                  f"inertia-tool robot {ur5} --material aluminium --json"])
    p.add_argument("robot", metavar="ROBOT", nargs="+",
                   help="*.urdf, *.xacro, *.sdf, or MuJoCo *.xml; several files or folders audit every description "
                        "in them (a corpus) with one summary")
    p.add_argument("--package", action="append", default=[], metavar="NAME=DIR",
                   help="directory of package NAME for package://NAME/... URIs (repeatable; ROS_PACKAGE_PATH is "
                        "searched after these)")
    p.add_argument("--arg", action="append", default=[], metavar="NAME:=VALUE",
                   help="xacro argument (repeatable)")
    p.add_argument("--run-xacro", action="store_true",
                   help="expand a *.xacro file: this RUNS CODE FROM THE FILE (xacro evaluates Python in ${...}); "
                        "only for files you trust. It runs in a child process without your environment "
                        "variables, under CPU, memory and wall-clock limits (INERTIA_TOOL_CPU_LIMIT, "
                        "INERTIA_TOOL_MEMORY_LIMIT, INERTIA_TOOL_WALL_LIMIT). Without it a xacro file is refused")
    p.add_argument("--geometry", default="collision", metavar="|".join(GEOMETRY_KINDS) + "|group=LIST|class=LIST",
                   help="which geometry of each link to integrate (default: collision; MuJoCo MJCF: collision = "
                        "geoms that can collide, visual = the others; also 'all': every geom in <compiler "
                        "inertiagrouprange>, as MuJoCo's inertia from geometry; group=3 or group=0-2,5: the geoms "
                        "of those groups; class=collision: the geoms of that default class or a class nested in "
                        "it)")
    m = p.add_mutually_exclusive_group(required=True)
    m.add_argument("--density", metavar="RHO",
                   help="density of every link, kg/m³ by default (or e.g. 2.7g/cm3); 'model' takes the MJCF "
                        "file's own geom density, mass and shellinertia (massless geoms are named)")
    m.add_argument("--material", metavar="NAME", help=f"material of every link: {', '.join(sorted(MATERIALS))}")
    m.add_argument("--keep-mass", action="store_true",
                   help="keep each link's declared mass and take its distribution from the geometry "
                        "(the implied density is reported)")
    p.add_argument("--max-faces", type=int, default=DEFAULT_MAX_FACES, metavar="N",
                   help=f"refuse meshes holding more than N triangles, all the robot's mesh files together (default "
                        f"{DEFAULT_MAX_FACES:,}; protects memory: each file is checked before it is read in full)")
    p.add_argument("--repair", action="store_true",
                   help="repair open or inconsistently wound link meshes instead of reporting them (warned)")
    add_assume_option(p)
    p.add_argument("--jobs", "-j", type=int, default=1, metavar="N",
                   help="with several descriptions (a corpus): audit them in N worker processes, the descriptions "
                        "of one folder together (default 1)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    p.add_argument("--write", metavar="OUT", help="write a copy of the description with corrected <inertial> elements")
    p.add_argument("--force", action="store_true", help="let --write replace an existing file")
    p.set_defaults(func=run, robot_parser=p)


def parse_packages(items) -> dict:
    """``["ur_description=/path", ...]`` → ``{"ur_description": "/path"}``; UsageError naming the item."""
    packages = {}
    for item in items:
        name, sep, directory = item.partition("=")
        if not sep or not name or not directory:
            raise UsageError(f"--package expects NAME=DIR, got {item!r}")
        if not os.path.isdir(directory):
            raise UsageError(f"--package {item}: {directory} is not a directory")
        packages[name] = directory
    return packages


def parse_mappings(items) -> dict:
    """``["prefix:=ur5_", ...]`` → ``{"prefix": "ur5_"}``; UsageError naming the item."""
    mappings = {}
    for item in items:
        name, sep, value = item.partition(":=")
        if not sep or not name:
            raise UsageError(f"--arg expects NAME:=VALUE, got {item!r}")
        mappings[name] = value
    return mappings


def _density(args) -> float | str | None:
    """``--density``: kg/m³, ``model`` (the description's own densities), or None when not given."""
    if args.density is None:
        return None
    if args.density.strip() == MODEL_DENSITY:
        return MODEL_DENSITY
    return check_option("--density", parse_density(args.density), typed=args.density)


def _run_corpus(args, packages: dict) -> int:
    """Several files or folders: every description audited, one summary (no --write, no xacro arguments)."""
    from ..reports.robot_audit import corpus_report_dict, format_corpus_report, links_without_result
    from ..reports.serialize import command_output
    from ..robot.corpus import audit_corpus
    if args.write or args.arg:
        raise UsageError("--write and --arg apply to one description; a corpus (several files or a folder) is "
                         "only audited")
    check_option("--max-faces", args.max_faces)
    check_option("--jobs", args.jobs)
    density = _density(args)
    with recorded_warnings(args, parser=getattr(args, "robot_parser", None)) as messages:
        models = audit_corpus(args.robot, density=density, material=args.material, keep_mass=args.keep_mass,
                              repair=args.repair, assume=assumed_from_args(args), packages=packages,
                              geometry=args.geometry,
                              max_faces=args.max_faces, run_xacro=args.run_xacro, jobs=args.jobs)
    if not models:
        raise UsageError(f"no robot description found in {', '.join(args.robot)}")
    if args.json:
        out = command_output("robot-corpus", corpus_report_dict(models), warnings=messages)
        print(json.dumps(out, indent=2, ensure_ascii=False, allow_nan=False))
        shown_with_report(args, messages)
    else:
        print(speak_options(format_corpus_report(models), getattr(args, "robot_parser", None)))
    incomplete = any(m.robot is None or links_without_result(m.robot, m.inertials) for m in models)
    return EXIT_INCOMPLETE if incomplete else EXIT_OK


def run(args) -> int:
    from ..reports.robot_audit import (format_robot_report, left_unchanged, links_without_result, robot_report_dict,
                                       summary_line)
    from ..reports.serialize import command_output
    from ..robot.audit import audit_links
    from ..robot.description import read_robot
    from ..robot.geometry import link_inertials
    from ..robot.mjcf import inertia_from_geometry, warn_if_nothing_collides
    from ..robot.write import included_files, write_corrected

    from ..robot.description import parse_geometry
    parse_geometry(args.geometry)            # a malformed --geometry is the command's error, not each model's
    packages = parse_packages(args.package)
    if len(args.robot) > 1 or os.path.isdir(args.robot[0]):
        return _run_corpus(args, packages)
    args.robot = args.robot[0]
    mappings = parse_mappings(args.arg)
    if args.write is not None and not args.write.strip():
        raise UsageError(f"--write expects the name of the file to write, got {args.write!r}")
    if args.force and not args.write:
        raise UsageError("--force only applies to --write")
    if (args.write and not args.force and os.path.exists(args.write) and os.path.exists(args.robot)
            and os.path.samefile(args.write, args.robot)):
        raise UsageError(f"--write {args.write}: is the input description; refusing to overwrite it "
                         "(--force overwrites it)")
    check_output_file(args.write, "--write", args.force)
    check_option("--max-faces", args.max_faces)
    density = _density(args)
    with recorded_warnings(args, parser=getattr(args, "robot_parser", None)) as messages:
        robot = read_robot(args.robot, packages=packages, geometry=args.geometry, mappings=mappings,
                           run_xacro=args.run_xacro, missing_meshes="per-link")
        warn_if_nothing_collides(robot)
        inertials = link_inertials(robot, density=density, material=args.material, keep_mass=args.keep_mass,
                                   repair=args.repair, max_faces=args.max_faces, assume=assumed_from_args(args))
        audits = audit_links(robot, inertials, keep_mass=args.keep_mass)
    if args.write:
        basis = next((r.basis for r in inertials if r.properties is not None), "")
        note = "declared masses kept" if args.keep_mass else f"density {basis}"
        changed = write_corrected(robot, inertials, args.write, force=args.force, note=note)
        message = f"wrote {args.write}: <inertial> of {len(changed)} link{'' if len(changed) == 1 else 's'} corrected"
        unchanged = left_unchanged(inertials, changed, included=included_files(robot))
        if unchanged:
            message += f"; left as they were: {unchanged}"
        if robot.format == "mjcf" and inertia_from_geometry(robot.source, robot.document) == "true":
            message += ('; note: <compiler inertiafromgeom="true"> makes MuJoCo compute the inertias from the geoms '
                        "and ignore every <inertial>, these included")
        print(escape_terminal(message), file=sys.stderr)
    if args.json:
        out = command_output("robot", robot_report_dict(robot, inertials, audits), warnings=messages)
        print(json.dumps(out, indent=2, ensure_ascii=False, allow_nan=False))
        shown_with_report(args, messages)
    else:
        # engine sentences name API parameters (`repair=True`); here they name this command's options
        parser = getattr(args, "robot_parser", None)
        print(speak_options(format_robot_report(robot, inertials, audits), parser))
        # the report lists the links' warnings, not those of reading the description
        shown_with_report(args, [speak_options(w, parser) for r in inertials for w in r.warnings])
    if links_without_result(robot, inertials):
        if args.json:        # the table ends with the same line
            print(escape_terminal(f"inertia-tool robot: {summary_line(robot, inertials)}"), file=sys.stderr)
        return EXIT_INCOMPLETE
    return EXIT_OK
