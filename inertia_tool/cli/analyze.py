"""``inertia-tool analyze FILE [FILE:material ...]``: mass properties report (text, JSON, URDF/SDF/MJCF
``<inertial>`` blocks, CAD-style report), for solids, thin shells and printed parts."""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from typing import TYPE_CHECKING

from ..errors import ImplausiblePointWarning, OverlapWarning, PhysicsError, UsageError
from ..tolerances import PRINTED_MOMENT_TOLERANCE
from ..reports.cad import CAD_UNITS
from ..robot.formats import FRAMES, ROBOT_FORMATS
from .help import add_command
from .model_options import (add_files_argument, add_model_options, load_model, model_words, shown_with_report,
                            split_part_spec,
                            with_warnings)
from .options import check_option, density_and_mass
from .report_option import add_report_options, check_report_path, write_report_from_args

if TYPE_CHECKING:     # the engine and the report writers load when the command runs, not for its --help
    import numpy as np

__all__ = ["register", "run", "add_output_options", "output_format", "FORMATS", "BREP_METHOD"]

#: ``method`` of a STEP/IGES result: the exact B-rep, integrated by OpenCASCADE.
BREP_METHOD = "brep (OpenCASCADE BRepGProp)"


def register(subparsers) -> None:
    p = add_command(
        subparsers, "analyze",
        description="Mass properties of the solid bounded by a closed triangle mesh, exact for the polyhedron. "
                    "Several files (FILE:material or FILE:density) are combined into one rigid assembly; "
                    "--model shell and --shell/--infill model sheet-metal and 3D-printed parts.",
        examples=["inertia-tool analyze meshes/t_handle.stl --units mm --material aluminium",
                  "inertia-tool analyze meshes/box.stl --units mm --mass 50g --json",
                  "inertia-tool analyze meshes/washer.stl:steel meshes/box.stl:abs --units mm --format urdf"])
    add_files_argument(p)
    add_model_options(p)
    o = add_output_options(p)
    o.add_argument("--json", action="store_true", help="print one JSON object (SI); same as --format json")
    o.add_argument("--moment-tolerance", metavar="FRACTION",
                   help="manufacturing tolerance on the principal moments, e.g. 1%% or 0.01 of the largest: axes "
                        "whose moments lie closer are 'indifferent within tolerance' instead of stable or "
                        f"UNSTABLE (default {100 * PRINTED_MOMENT_TOLERANCE:g}%% with --shell/--infill, else none)")
    add_report_options(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..reports.serialize import command_output, mass_properties_dict, to_jsonable
    from ..reports.stability import format_stability, principal_moment_bound, stability_dict
    from ..reports.text import format_mass_properties
    from ..reports.cad import format_cad_report
    from ..reports.models import format_model_note
    from ..robot.formats import format_inertial
    fmt = output_format(args)
    check_report_path(args)
    loaded = load_model(args)
    props, described, model, messages = loaded.props, loaded.density_source, loaded.model, list(loaded.warnings)
    # a STEP assembly of several parts is integrated part by part (each its material): no single B-rep to compare
    cad = _brep_section(args) if not any(m.parts for m in loaded.meshes) else None
    if cad is not None:           # STEP/IGES: the exact B-rep is the headline, the tessellation a second line
        target = density_and_mass(args)[1]
        props = cad.scaled(props, target_mass=target)
        if target is not None and ": implied density" in described:
            described = described.split(": implied density")[0] + f": implied density {props.density:.4g} kg/m³"
        if cad.fusion == "failed":
            message = (f"{props.name}: the file holds {cad.solids} solids that could not be fused: the exact "
                       "B-rep values are their sum, so any volume they share is counted twice")
            messages.append(message)
            warnings.warn(OverlapWarning(message), stacklevel=1)
    tolerance = _moment_tolerance(args)
    stab, stab_error = (_stability_section(props, tolerance) if fmt in ("json", "text") or args.report
                        else (None, None))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ImplausiblePointWarning)
        system = chosen_frame(args, props)
    messages += [str(w.message) for w in caught if issubclass(w.category, ImplausiblePointWarning)]
    if system is not None and fmt in ROBOT_FORMATS:
        raise UsageError(f"--about applies to text, json and cad output (and --report), not to --format {fmt}: "
                         "an <inertial> block is about the centre of mass")
    # the model in the first table too (its section, with the assumptions, comes after the views and tables)
    result = f"exact B-rep of the CAD file ({BREP_METHOD}); the mesh below is its tessellation" if cad else None
    extra = []
    if cad is not None and getattr(args, "report", None):
        from ..reports.brep import brep_html_section
        extra.append(brep_html_section(cad, props.density))
    if system is not None:
        from ..reports.frame import format_frame_inertia, frame_inertia_dict, frame_inertia_section
        extra.append(frame_inertia_section(system))
    write_report_from_args(args, props, described + model_words(model), messages, meshes=loaded.meshes,
                           stability=stab if stab is not None else stab_error, model=model, extra_sections=extra,
                           result=result)
    if fmt == "json":
        import json         # imported on use: the text report does without
        out = mass_properties_dict(props, density_source=described)
        if cad is not None:
            from ..reports.brep import brep_comparison_dict
            out["brep"] = brep_comparison_dict(cad, props.density)
            out["method"] = BREP_METHOD
        out["stability"] = stability_dict(stab) if stab is not None else None   # spin stability (§4.4.1)
        if model["model"] != "solid":
            out["model"] = to_jsonable(model)
        if system is not None:
            out["coordinate_system"] = frame_inertia_dict(system)
        out["units_assumed"] = loaded.units_assumed          # no --units and no unit in the file: metres taken
        out = command_output("analyze", out, warnings=messages)
        # one string, one write: json.dump writes each of its hundreds of pieces through the terminal-safe stream
        sys.stdout.write(json.dumps(out, indent=2, ensure_ascii=False, allow_nan=False) + "\n")
        shown_with_report(args, messages)
    elif fmt in ROBOT_FORMATS:
        from ..robot.inertial import inertial_frame
        frame = inertial_frame(props, args.frame or "principal")
        print(format_inertial(frame, fmt, source=f"{props.name}: {described}{model_words(model)}"))
    elif fmt == "cad":
        print(format_cad_report(props, units=args.cad_units or "kg-m", density_source=described, frame=system))
        if cad is not None:
            from ..reports.brep import format_brep_comparison
            print("\n" + format_brep_comparison(cad, props.density).strip("\n"))
        note = format_model_note(model)
        if note:
            print("\n" + note.strip())
    else:
        print(with_warnings(format_mass_properties(props, density_source=described, result=result), messages,
                            loaded.notes()))
        shown_with_report(args, messages)
        if cad is not None:
            from ..reports.brep import format_brep_comparison
            print(format_brep_comparison(cad, props.density))
        print("\n".join(format_stability(stab, moment_bound=principal_moment_bound(props))) if stab is not None
              else f"  spin stability: {stab_error}")
        if system is not None:
            print(format_frame_inertia(system))
        note = format_model_note(model)
        if note:
            print(note)
    return 0


def _brep_section(args):
    """For one STEP/IGES solid with OCP installed: the exact B-rep properties against the tessellation."""
    files = list(args.files) if isinstance(args.files, (list, tuple)) else [args.files]
    if len(files) != 1 or getattr(args, "model", "solid") != "solid" or getattr(args, "shell", None):
        return None
    path = split_part_spec(files[0])[0]
    from ..mesh.read import BREP_SUFFIXES
    if os.path.splitext(path)[1].lower() not in BREP_SUFFIXES:
        return None
    from ..mesh.cad import has_ocp      # imported on use, like the B-rep comparison below
    if not has_ocp():
        return None
    from ..mass.brep import compare      # imported on use: only STEP/IGES files need it
    return compare(path)


def _moment_tolerance(args) -> float | None:
    """``--moment-tolerance`` as a fraction; the printed-part default with ``--shell``; else None."""
    text = getattr(args, "moment_tolerance", None)
    if text is None:
        return PRINTED_MOMENT_TOLERANCE if getattr(args, "shell", None) is not None else None
    from ..units import parse_fraction
    try:
        value = parse_fraction(text)
    except UsageError:
        value = -1.0
    if not 0 <= value < 1:
        raise UsageError(f"--moment-tolerance must be a fraction in [0, 1) (e.g. 1% or 0.01), got {text!r}")
    return value


def _stability_section(props, tolerance: float | None = None):
    """Spin stability of the principal axes for the report, or ``(None, reason)`` when undefined."""
    from ..dynamics.spin_stability import stability
    try:
        return stability(props, moment_tolerance=tolerance), None
    except PhysicsError as exc:
        return None, f"undefined ({exc})"


# -- output formats and thin-walled models (issue 6: exports, shells, printed parts) ---------------------------

#: Values of ``--format``.
FORMATS = ("text", "json") + ROBOT_FORMATS + ("cad",)


def add_output_options(parser) -> argparse._ArgumentGroup:
    """``--format``, ``--frame``, ``--cad-units``."""
    g = parser.add_argument_group("output")
    # --json is added by the caller, after --format
    g.add_argument("--format", choices=FORMATS, default=None,
                   help="text report (default), json, an <inertial> block for urdf, sdf or mjcf (MuJoCo), "
                        "or cad: a SolidWorks-style mass properties report (positive tensor notation)")
    g.add_argument("--frame", choices=FRAMES, default=None,
                   help="inertial frame of urdf/sdf/mjcf: principal axes with a diagonal tensor (default) or "
                        "mesh-aligned axes with the full tensor")
    g.add_argument("--cad-units", choices=tuple(CAD_UNITS), default=None,
                   help="display units of --format cad (default kg-m; g-mm is SolidWorks' default)")
    g.add_argument("--about", metavar="X,Y,Z",
                   help="also give the inertia about this point and the centre of mass relative to it (the "
                        "output coordinate system's origin), e.g. 101.6mm,152.4mm,0 (bare numbers in --units); "
                        "text, json, cad and --report")
    g.add_argument("--axes", metavar="SPEC",
                   help="axes of that coordinate system (with --about): axis-angle:AX,AY,AZ,ANGLE (e.g. "
                        "axis-angle:0,0,1,90deg, the system turned from the mesh axes) or matrix:R11,...,R33 "
                        "(nine numbers, rows; the columns are the system's x, y, z in mesh coordinates)")
    return g


def parse_axes(text: str) -> np.ndarray:
    """``--axes``: ``axis-angle:AX,AY,AZ,ANGLE`` or ``matrix:R11,...,R33`` → (3, 3) rotation (columns: axes)."""
    import numpy as np

    from ..rotations import axis_angle_to_matrix
    from ..units import parse_angle
    kind, _, rest = str(text).partition(":")
    parts = [p.strip() for p in rest.split(",")]
    try:
        if kind == "axis-angle" and len(parts) == 4:
            axis = np.array([float(p) for p in parts[:3]])
            if not np.all(np.isfinite(axis)) or not np.linalg.norm(axis) > 0:
                raise ValueError
            # axis_angle_to_matrix is passive (exercise 4.5): its transpose is the active rotation, whose
            # columns are the mesh axes turned counter-clockwise by the angle: the system's axes
            passive = axis_angle_to_matrix(axis / np.linalg.norm(axis), parse_angle(parts[3], "deg"))
            return np.asarray(passive).T
        if kind == "matrix" and len(parts) == 9:
            return np.array([float(p) for p in parts]).reshape(3, 3)
    except (ValueError, UsageError):
        pass
    raise UsageError(f"--axes takes axis-angle:AX,AY,AZ,ANGLE (e.g. axis-angle:0,0,1,90deg) or matrix: and nine "
                     f"numbers, got {text!r}")


def chosen_frame(args, props):
    """The :class:`~inertia_tool.mass.frame.FrameInertia` of ``--about``/``--axes``, or None."""
    about, axes = getattr(args, "about", None), getattr(args, "axes", None)
    if about is None and axes is None:
        return None
    if about is None:
        raise UsageError("--axes needs --about (the origin of the coordinate system; --about 0,0,0 for the "
                         "mesh origin)")
    from ..mass.frame import inertia_in_frame
    from ..units import parse_vector
    from .model_options import length_unit
    point = check_option("--about", list(parse_vector(about, length_unit(args))), typed=about)
    return inertia_in_frame(props, point, None if axes is None else parse_axes(axes))


def output_format(args) -> str:
    """The requested output format; ``--json`` is an alias of ``--format json``.

    ``--frame`` only means something to urdf/sdf/mjcf and ``--cad-units`` to cad: given with another format
    they would be ignored, so they are refused (:class:`UsageError`).
    """
    fmt = getattr(args, "format", None)
    if getattr(args, "json", False):
        if fmt not in (None, "json"):
            raise UsageError(f"--json contradicts --format {fmt}; give one of them")
        fmt = "json"
    fmt = fmt or "text"
    if getattr(args, "frame", None) is not None and fmt not in ROBOT_FORMATS:
        raise UsageError(f"--frame applies to --format {', '.join(ROBOT_FORMATS)} only, not to {fmt} output")
    if getattr(args, "cad_units", None) is not None and fmt != "cad":
        raise UsageError(f"--cad-units applies to --format cad only, not to {fmt} output")
    return fmt


