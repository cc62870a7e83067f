"""``inertia-tool analyze FILE [FILE:material ...]``: mass properties report (text, JSON, URDF/SDF/MJCF
``<inertial>`` blocks, CAD-style report), for solids, thin shells and printed parts."""

from __future__ import annotations

import json
import os
import sys
import warnings

from ..errors import InertiaToolWarning, PhysicsError, UsageError
from ..mesh.options import DEFAULT_MAX_FACES
from ..mass.pipeline import DEFAULT_DENSITY, assembly, mass_properties, resolve_density
from ..mesh.options import LoadOptions
from ..mesh.read import load_mesh
from ..tolerances import MERGE_TOLERANCE
from ..reports.serialize import mass_properties_dict, to_jsonable
from ..reports.stability import format_stability, stability_dict
from ..reports.text import format_mass_properties
from ..dynamics.spin_stability import stability
from ..units import MATERIALS, parse_density
# issue 6: exports and thin-walled models
from ..robot.inertial import FRAMES, inertial_frame
from ..mesh.cad import BREP_SUFFIXES, has_ocp
from ..mass.brep import compare as brep_compare
from ..reports.brep import brep_comparison_dict, format_brep_comparison
from ..reports.cad import CAD_UNITS, format_cad_report
from ..reports.models import format_model_note, model_summary
from ..robot.formats import ROBOT_FORMATS, format_inertial
from ..mass.thinwall import printed_part, shell_mass_properties
from ..units import parse_fraction, parse_length
from .options import check_option, density_and_mass
from .report_option import add_report_options, check_report_path, write_report_from_args

__all__ = ["register", "run", "split_part_spec", "add_material_options", "add_mesh_options", "load_from_args",
           "read_meshes",
           "add_output_options", "add_model_options", "output_format", "load_model_from_args", "FORMATS"]


def split_part_spec(spec: str) -> tuple[str, str | None]:
    """``"lid.stl:abs"`` → ``("lid.stl", "abs")``, ``"lid.stl:1.24g/cm3"`` → ``("lid.stl", "1.24g/cm3")``.

    A path that exists as given is never split.  Otherwise the split is at the last ``:`` whatever follows it
    (a density unit may contain ``/``), except after a lone drive letter (``C:\\parts\\a.stl``, ``C:/a.stl``):
    that is a Windows path, reported as missing by the reader.
    """
    if ":" not in spec or os.path.exists(spec):
        return spec, None
    path, _, what = spec.rpartition(":")
    if not path or not what.strip():
        return spec, None
    if len(path) == 1 and path.isalpha() and what[:1] in ("\\", "/"):
        return spec, None
    return path, what


def add_material_options(parser) -> None:
    """``--units``, ``--density``, ``--material``, ``--mass`` (shared by analyze, spin, top, balance, ...)."""
    g = parser.add_argument_group("units and material")
    g.add_argument("--units", default="m", metavar="UNIT",
                   help="length unit of the mesh coordinates: m, cm, mm, um, in, ft (default: m)")
    m = g.add_mutually_exclusive_group()
    m.add_argument("--density", metavar="RHO", help="density, kg/m³ by default (or e.g. 1.24g/cm3)")
    m.add_argument("--material", metavar="NAME",
                   help=f"material name: {', '.join(sorted(MATERIALS))}")
    m.add_argument("--mass", metavar="MASS", help="total mass the part should have, kg by default (or e.g. 412g)")


def add_mesh_options(parser) -> None:
    """``--repair``, ``--overlap``, ``--merge-tolerance``, ``--max-faces``."""
    g = parser.add_argument_group("mesh checks")
    g.add_argument("--repair", action="store_true",
                   help="give a bounded estimate (method and uncertainty in the report) for a mesh with holes, "
                        "cracks or stray pieces instead of refusing it")
    g.add_argument("--overlap", choices=("union", "sum"), default="union",
                   help="overlapping bodies: integrate their union (default) or add them, counting shared "
                        "material twice")
    g.add_argument("--merge-tolerance", type=float, default=MERGE_TOLERANCE, metavar="REL",
                   help="relative tolerance (of the bounding-box diagonal) for welding nearly coincident "
                        f"vertices when exact welding leaves the surface open (default {MERGE_TOLERANCE:g}; 0 off)")
    g.add_argument("--max-faces", type=int, default=DEFAULT_MAX_FACES, metavar="N",
                   help=f"refuse meshes with more triangles (default {DEFAULT_MAX_FACES:,})")


def _part_density(what: str, source=None) -> dict:
    try:
        density = parse_density(what)
    except UsageError:
        return {"material": what}
    name = getattr(source, "source", source)          # a file name, or the RawMesh read from it
    return {"density": check_option("--density", density, typed=what,
                                    label=f"the density of {name}" if name else None)}


def check_mesh_options(args) -> None:
    """Refuse a ``--merge-tolerance`` or ``--max-faces`` outside :data:`.options.OPTION_RANGES` (exit 2)."""
    check_option("--merge-tolerance", getattr(args, "merge_tolerance", 0.0))
    check_option("--max-faces", getattr(args, "max_faces", 1))


def load_options_from_args(args) -> LoadOptions:
    """The one :class:`LoadOptions` of a command, from ``--units`` and the mesh-check options."""
    check_mesh_options(args)
    return LoadOptions(units=args.units, repair=bool(getattr(args, "repair", False)),
                       overlap=getattr(args, "overlap", "union"),
                       merge_tolerance=getattr(args, "merge_tolerance", MERGE_TOLERANCE),
                       max_faces=getattr(args, "max_faces", DEFAULT_MAX_FACES))


def read_meshes(args) -> list:
    """Read every FILE of ``args`` once, at the edge, into :class:`~inertia_tool.mesh.read.RawMesh` (metres).

    The engine and the report writers then take these objects, so nothing reads a file twice."""
    options = load_options_from_args(args)
    files = list(args.files) if isinstance(args.files, (list, tuple)) else [args.files]
    return [load_mesh(split_part_spec(f)[0], units=options.units, max_faces=options.max_faces) for f in files]


def load_from_args(args, meshes=None):
    """Mass properties of the ``files`` in ``args`` (one part or an assembly) and the density description.

    ``meshes``: the files already read by :func:`read_meshes` (one per FILE), used instead of reading them.
    In an assembly, a global ``--density``/``--material`` is the default of the parts named without their own
    ``:material`` or ``:density`` (the description says so); when every part has its own, a global one would
    be ignored and is refused as contradictory (:class:`UsageError`).
    """
    options = load_options_from_args(args)
    density, mass = density_and_mass(args)
    files = list(args.files) if isinstance(args.files, (list, tuple)) else [args.files]
    specs = [split_part_spec(f) for f in files]
    if meshes is not None:
        specs = [(raw, what) for raw, (_, what) in zip(meshes, specs)]
    if len(specs) == 1 and specs[0][1] is None:
        _, described = resolve_density(density=density, material=args.material, mass=mass)
        props = mass_properties(specs[0][0], density=density, material=args.material, mass=mass, options=options)
        return props, described
    default = None
    if density is not None or args.material is not None:
        option = f"--density {args.density}" if density is not None else f"--material {args.material}"
        if all(what is not None for _, what in specs):
            raise UsageError(f"{option} would apply to no part: every FILE has its own :material or :density "
                             "(drop the option, or name a part without its own to give it this default)")
        default, default_text = resolve_density(density=density, material=args.material)
    parts, own = [], []
    for path, what in specs:
        if what is not None:
            parts.append({"source": path, **_part_density(what, path)})
            own.append(what)
        elif density is not None:
            parts.append({"source": path, "density": density})
        elif args.material is not None:
            parts.append({"source": path, "material": args.material})
        else:
            parts.append({"source": path})
    props = assembly(parts, mass=mass, options=options)
    if len(specs) == 1:
        described = resolve_density(**_part_density(own[0]))[1]
    else:
        described = "per part"
        if default is not None:
            described += f"; {default_text} for the parts without their own"
        elif len(own) < len(specs):
            described += f"; {DEFAULT_DENSITY:g} kg/m³ (water) for the parts without their own"
    if mass is not None:
        described += f", scaled to a total mass of {mass:g} kg"
    return props, described


def register(subparsers) -> None:
    p = subparsers.add_parser("analyze", help="mass, centre of mass, inertia tensor and principal axes of a mesh",
                              description="Mass properties of the solid bounded by a closed triangle mesh, exact "
                                          "for the polyhedron. Several files (FILE:material or FILE:density) are "
                                          "combined into one rigid assembly.")
    p.add_argument("files", nargs="+", metavar="FILE", help="mesh file(s): STL, OBJ, PLY, OFF, 3MF; "
                                                           "FILE:material or FILE:density for an assembly")
    add_material_options(p)
    add_mesh_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object (SI); same as --format json")
    add_output_options(p)
    add_model_options(p)
    add_report_options(p)
    p.set_defaults(func=run)


def run(args) -> int:
    fmt = output_format(args)
    check_report_path(args)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaToolWarning)
        meshes = read_meshes(args)
        props, described, model = load_model_from_args(args, meshes)
    messages = [str(w.message) for w in caught if issubclass(w.category, InertiaToolWarning)]
    for w in caught:          # hand them on so the command line prints them on stderr
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    stab, stab_error = _stability_section(props) if fmt in ("json", "text") or args.report else (None, None)
    write_report_from_args(args, props, described, messages, meshes=meshes,
                           stability=stab if stab is not None else stab_error)
    cad = _brep_section(args) if fmt in ("json", "text") else None
    if fmt == "json":
        out = mass_properties_dict(props, density_source=described)
        if cad is not None:
            out["brep"] = brep_comparison_dict(cad, props.density)
        out["stability"] = stability_dict(stab) if stab is not None else None   # spin stability (§4.4.1)
        if model["model"] != "solid":
            out["model"] = to_jsonable(model)
        out["warnings"] = messages
        json.dump(out, sys.stdout, indent=2, ensure_ascii=False, allow_nan=False)
        sys.stdout.write("\n")
    elif fmt in ROBOT_FORMATS:
        frame = inertial_frame(props, args.frame or "principal")
        print(format_inertial(frame, fmt, source=f"{props.name}: {described}{_model_words(model)}"))
    elif fmt == "cad":
        print(format_cad_report(props, units=args.cad_units or "kg-m", density_source=described))
        note = format_model_note(model)
        if note:
            print("\n" + note.strip())
    else:
        print(format_mass_properties(props, density_source=described))
        if cad is not None:
            print(format_brep_comparison(cad, props.density))
        print("\n".join(format_stability(stab)) if stab is not None else f"  spin stability: {stab_error}")
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
    if os.path.splitext(path)[1].lower() not in BREP_SUFFIXES or not has_ocp():
        return None
    return brep_compare(path)


def _stability_section(props):
    """Spin stability of the principal axes for the report, or ``(None, reason)`` when undefined."""
    try:
        return stability(props), None
    except PhysicsError as exc:
        return None, f"undefined ({exc})"


# -- output formats and thin-walled models (issue 6: exports, shells, printed parts) ---------------------------

#: Values of ``--format``.
FORMATS = ("text", "json") + ROBOT_FORMATS + ("cad",)


def add_output_options(parser) -> None:
    """``--format``, ``--frame``, ``--cad-units``."""
    g = parser.add_argument_group("output")
    g.add_argument("--format", choices=FORMATS, default=None,
                   help="text report (default), json, an <inertial> block for urdf, sdf or mjcf (MuJoCo), "
                        "or cad: a SolidWorks-style mass properties report (positive tensor notation)")
    g.add_argument("--frame", choices=FRAMES, default=None,
                   help="inertial frame of urdf/sdf/mjcf: principal axes with a diagonal tensor (default) or "
                        "mesh-aligned axes with the full tensor")
    g.add_argument("--cad-units", choices=tuple(CAD_UNITS), default=None,
                   help="display units of --format cad (default kg-m; g-mm is SolidWorks' default)")


def add_model_options(parser) -> None:
    """``--model``, ``--thickness``, ``--shell``, ``--infill``."""
    g = parser.add_argument_group("thin-walled and printed parts")
    g.add_argument("--model", choices=("solid", "shell"), default="solid",
                   help="solid (default): the mesh bounds homogeneous material; shell: the mesh is the "
                        "mid-surface of a wall of --thickness (sheet metal, thin-walled parts; open meshes allowed)")
    g.add_argument("--thickness", metavar="LEN", help="wall thickness of --model shell, e.g. 2mm "
                                                      "(a bare number is in --units)")
    g.add_argument("--shell", metavar="LEN", help="3D print: solid skin thickness, e.g. 1.2mm (with --infill)")
    g.add_argument("--infill", metavar="FRACTION", help="3D print: core fill fraction, e.g. 20%% or 0.2 (with --shell)")


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


def load_model_from_args(args, meshes=None):
    """Like :func:`load_from_args`, honouring ``--model shell --thickness`` and ``--shell --infill``.

    Returns ``(props, density description, model summary dict)``.
    """
    model = getattr(args, "model", "solid") or "solid"
    thickness, skin, infill = (getattr(args, k, None) for k in ("thickness", "shell", "infill"))
    if model == "solid" and thickness is not None:
        raise UsageError("--thickness needs --model shell (for a printed part use --shell and --infill)")
    if (skin is None) != (infill is None):
        raise UsageError("a printed part needs both --shell (skin thickness) and --infill (core fraction)")
    if model == "shell" and thickness is None:
        raise UsageError("--model shell needs --thickness (e.g. --thickness 2mm)")
    if model == "shell" and skin is not None:
        raise UsageError("--model shell takes --thickness; --shell/--infill describe a printed solid")
    options = load_options_from_args(args)
    if model == "solid" and skin is None:
        props, described = load_from_args(args, meshes)
        return props, described, model_summary("solid")
    files = list(args.files) if isinstance(args.files, (list, tuple)) else [args.files]
    if len(files) != 1:
        raise UsageError("the shell and printed-part models take one mesh file, not an assembly")
    density, mass = density_and_mass(args)
    _, described = resolve_density(density=density, material=args.material, mass=mass)
    common = dict(density=density, material=args.material, mass=mass)
    if model == "shell":
        t = check_option("--thickness", parse_length(thickness, default_unit=args.units), typed=thickness)
        props = shell_mass_properties(meshes[0] if meshes else files[0], thickness=t, units=options.units,
                                      max_faces=options.max_faces, **common)
        return props, described, model_summary("shell", thickness=t)
    skin_m = check_option("--shell", parse_length(skin, default_unit=args.units), typed=skin)
    printed = printed_part(meshes[0] if meshes else files[0], skin=skin_m, infill=parse_fraction(infill),
                           options=options, **common)
    return printed.properties, described, model_summary("printed", printed=printed)


def _model_words(model: dict) -> str:
    if model["model"] == "shell":
        return f"; thin shell {model['thickness']:g} m"
    if model["model"] == "printed":
        return (f"; printed: skin {model['skin']:g} m, infill {100 * model['infill']:g}% "
                f"(first-order model, mass error about {100 * model['mass_error_estimate']:.2g}%)")
    return ""
