"""The model options every command that loads a part takes, defined once.

``analyze``, ``spin``, ``top``, ``balance`` and ``batch`` describe the part the same way, in the same order
in ``--help``:

* ``FILE [FILE ...]`` — one mesh, or an assembly ``a.stl:steel b.stl:1.2g/cm3``;
* units and material — ``--units``, ``--density`` | ``--material`` | ``--mass``;
* the mass model — ``--model shell --thickness 2mm`` (sheet metal) or ``--shell 1.2mm --infill 20%``
  (a printed part);
* mesh checks — ``--repair``, ``--overlap``, ``--merge-tolerance``, ``--max-faces``.

:func:`load_model` turns them into the engine's :class:`~inertia_tool.mass.properties.MassProperties`, the
words the reports print about the density (``density_source``), the model's assumptions and the warnings
the engine raised.  Routing only: numbers come from the engine.

Units: ``--units`` left out means "not given, metres assumed" (``LoadOptions.units=None``), so the engine can
warn when the part's size is implausible for metres (:class:`~inertia_tool.errors.ImplausibleSizeWarning`).
Bare lengths elsewhere on the command line are in ``--units`` (metres without it); a number with a unit
(``2mm``, ``0.5in``) is accepted wherever a length, mass or density is asked for.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import InertiaToolWarning, UsageError
from ..tolerances import DEFAULT_MAX_FACES, MERGE_TOLERANCE
from ..units import LENGTH_UNITS, MATERIALS, parse_density, parse_fraction, parse_length
from .options import check_option, density_and_mass
from ..rounding import round_up

if TYPE_CHECKING:     # the engine loads when a part is loaded, not to build a parser (``analyze --help``)
    from ..mass.properties import MassProperties
    from ..mesh.options import LoadOptions

__all__ = ["add_files_argument", "add_model_options", "add_material_options", "add_mesh_options",
           "add_material_map_option", "parse_material_map", "split_part_spec",
           "length_unit", "load_options_from_args", "read_meshes", "load_model",
           "LoadedModel", "model_words", "with_warnings", "command_parser", "recorded_warnings",
           "shown_with_report", "add_assume_option", "assumed_from_args"]

FILES_HELP = ("mesh file(s): STL, OBJ, PLY, OFF, 3MF; several FILE:material or FILE:density make an "
              "assembly (e.g. a.stl:steel b.stl:1.2g/cm3)")


def add_files_argument(parser, *, help: str = FILES_HELP) -> None:
    """``FILE [FILE ...]``: one part or an assembly."""
    parser.add_argument("files", nargs="+", metavar="FILE", help=help)


def add_material_options(parser) -> None:
    """``--units``, then one of ``--density``, ``--material``, ``--mass``."""
    g = parser.add_argument_group("units and material")
    g.add_argument("--units", default=None, metavar="UNIT",
                   help=f"length unit of the mesh coordinates: {', '.join(LENGTH_UNITS)} (default: m, assumed; "
                        "STL and OBJ carry no unit, so a part implausibly large or small in metres is warned "
                        "about); bare lengths on this command line are in this unit too")
    m = g.add_mutually_exclusive_group()
    m.add_argument("--density", metavar="RHO", help="density, kg/m³ unless a unit is given (e.g. 1.24g/cm3)")
    m.add_argument("--material", metavar="NAME", help=f"material name: {', '.join(sorted(MATERIALS))}")
    m.add_argument("--mass", metavar="MASS", help="total mass the part should have, kg unless a unit is given "
                                                  "(e.g. 412g); the implied density is printed")


def add_material_map_option(parser) -> None:
    """``--material-map NAME=MATERIAL|DENSITY``: materials of the parts inside one file (repeatable)."""
    parser.add_argument("--material-map", action="append", default=None, metavar="NAME=MATERIAL",
                        help="density of the parts of a multi-material file (3MF base materials, PrusaSlicer or "
                             "Bambu Studio filaments, STEP assembly parts): NAME is a part name, 'object ID' "
                             "(3MF) or a material name the file uses; the value a material (steel) or a "
                             "density (1.24g/cm3); repeat for several. A material the tool cannot map is an "
                             "error naming it")


def parse_material_map(args) -> dict[str, float | str]:
    """``--material-map`` entries → ``{name: density kg/m³ or material name}`` (a repeated name is refused)."""
    out: dict[str, float | str] = {}
    for entry in getattr(args, "material_map", None) or ():
        name, sep, value = str(entry).partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise UsageError(f"--material-map takes NAME=MATERIAL or NAME=DENSITY (e.g. insert=steel or "
                             f"PLA=1.24g/cm3), got {entry!r}")
        if name in out:
            raise UsageError(f"--material-map names {name!r} twice")
        try:
            out[name] = check_option("--density", parse_density(value), typed=value,
                                     label=f"the density of {name} (--material-map)")
        except UsageError as exc:
            if any(c.isdigit() for c in value[:1]):
                raise exc from None
            out[name] = value                   # a material name, checked against the table where it is used
    return out


def add_thin_wall_options(parser) -> None:
    """``--model``, ``--thickness``, ``--shell``, ``--infill``."""
    g = parser.add_argument_group("mass model (thin-walled and printed parts)")
    g.add_argument("--model", choices=("solid", "shell"), default="solid",
                   help="solid (default): the mesh bounds homogeneous material; shell: the mesh is the "
                        "mid-surface of a wall of --thickness (sheet metal, thin-walled parts; open meshes allowed)")
    g.add_argument("--thickness", metavar="LEN", help="wall thickness of --model shell, e.g. 2mm "
                                                      "(a bare number is in --units)")
    g.add_argument("--shell", metavar="LEN", help="3D print: solid skin thickness, e.g. 1.2mm (with --infill)")
    g.add_argument("--infill", metavar="FRACTION", help="3D print: core fill fraction, e.g. 20%% or 0.2 (with --shell)")
    g.add_argument("--top-bottom", metavar="LEN",
                   help="3D print: vertical thickness of the solid top and bottom layers, e.g. 1.2mm (with --shell)")
    g.add_argument("--top-layers", type=int, metavar="N", help="3D print: solid top layers (with --layer-height)")
    g.add_argument("--bottom-layers", type=int, metavar="N",
                   help="3D print: solid bottom layers (with --layer-height)")
    g.add_argument("--layer-height", metavar="LEN", help="3D print: layer height, e.g. 0.2mm (with --top-layers "
                                                         "and/or --bottom-layers)")


def add_mesh_options(parser) -> None:
    """``--repair``, ``--overlap``, ``--merge-tolerance``, ``--max-faces``."""
    g = parser.add_argument_group("mesh checks")
    g.add_argument("--repair", action="store_true",
                   help="give a bounded estimate (method and uncertainty in the report) for a mesh with holes, "
                        "cracks or stray pieces instead of refusing it")
    add_assume_option(g)
    g.add_argument("--overlap", choices=("union", "sum"), default="union",
                   help="overlapping bodies: integrate their union (default) or add them, counting shared "
                        "material twice")
    g.add_argument("--merge-tolerance", type=float, default=MERGE_TOLERANCE, metavar="REL",
                   help="relative tolerance (of the bounding-box diagonal) for welding nearly coincident "
                        f"vertices when exact welding leaves the surface open (default {MERGE_TOLERANCE:g}; 0 off)")
    g.add_argument("--max-faces", type=int, default=DEFAULT_MAX_FACES, metavar="N",
                   help=f"refuse meshes with more triangles (default {DEFAULT_MAX_FACES:,})")


#: The names ``--assume`` takes, for help without loading the engine (the same as
#: ``mesh.hole_assumptions.USER_ASSUMPTIONS``: tests/test_cli_assume.py checks it).
ASSUME_NAMES = ("flat-islands", "smooth-holes", "faceted-holes")


def add_assume_option(group) -> None:
    """``--assume NAME`` (repeatable): an assumption about the holes ``--repair`` fills that only the user can
    make (``LoadOptions.assume``; :func:`assumed_from_args` checks it)."""
    group.add_argument("--assume", action="append", default=[], metavar="NAME",
                       help="with --repair: an assumption about the lost surface that the file cannot show, named "
                            "in the report as yours; flat-islands: each hole that is an island in a flat face lost "
                            "a flat piece of that face (filled flat and bounded instead of refused; a boss or "
                            "pocket taken whole there breaks it); smooth-holes: each hole lost a piece of a smooth "
                            "surface continuing the one round it (bounded by how far such a continuation "
                            "may stray; a feature, edge or corner taken whole breaks it); faceted-holes: each hole "
                            "lost a piece of a faceted surface staying inside the planes of the faces round it "
                            "(bounded between the flat fill and those planes continued; a boss or rib taken whole "
                            "breaks it). Known: "
                            + ", ".join(ASSUME_NAMES))


def assumed_from_args(args) -> tuple[str, ...]:
    """``--assume`` checked: known names only, and only with ``--repair`` (else :class:`UsageError`, exit 2)."""
    from ..mesh.hole_assumptions import USER_ASSUMPTIONS
    names = tuple(getattr(args, "assume", None) or ())
    known = [a.name for a in USER_ASSUMPTIONS]
    unknown = sorted(set(names) - set(known))
    if unknown:
        raise UsageError(f"--assume: expected one of {', '.join(known)}, got {', '.join(unknown)}")
    if names and not getattr(args, "repair", False):
        raise UsageError(f"--assume {' '.join(names)} states what the holes --repair fills lost: give --repair too")
    return tuple(n for n in known if n in names)


def add_model_options(parser, *, thin_walls: bool = True) -> None:
    """Every model option, in the order all commands list them: units and material, mass model, mesh checks.

    ``thin_walls=False`` leaves out ``--model``/``--shell`` and ``--material-map`` (``batch``, which analyses
    solids only, one material per file)."""
    add_material_options(parser)
    if thin_walls:
        add_material_map_option(parser.add_argument_group("multi-material files"))
        add_thin_wall_options(parser)
    add_mesh_options(parser)


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


def length_unit(args) -> str:
    """The unit of bare lengths on the command line: ``--units``, metres when it was not given."""
    return getattr(args, "units", None) or "m"


def _files(args) -> list[str]:
    return list(args.files) if isinstance(args.files, (list, tuple)) else [args.files]


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
    from ..mesh.options import LoadOptions
    check_mesh_options(args)
    assume = assumed_from_args(args)
    return LoadOptions(units=getattr(args, "units", None), repair=bool(getattr(args, "repair", False)),
                       assume=assume,
                       overlap=getattr(args, "overlap", "union"),
                       merge_tolerance=getattr(args, "merge_tolerance", MERGE_TOLERANCE),
                       max_faces=getattr(args, "max_faces", DEFAULT_MAX_FACES))


def read_meshes(args) -> list:
    """Read every FILE of ``args`` once, at the edge, into :class:`~inertia_tool.mesh.read.RawMesh` (metres).

    The engine and the report writers then take these objects, so nothing reads a file twice."""
    from ..mesh.read import load_mesh
    options = load_options_from_args(args)
    return [load_mesh(split_part_spec(f)[0], units=options.units, max_faces=options.max_faces)
            for f in _files(args)]


@dataclass(frozen=True)
class LoadedModel:
    """What :func:`load_model` made of the model options.

    Attributes
    ----------
    props : MassProperties
        The part or assembly, SI.
    density_source : str
        Where the density came from, for the reports (``"steel (7850 kg/m³)"``, ``"scaled to a total mass
        of 0.412 kg: implied density 2710 kg/m³"``).
    model : dict
        :func:`~inertia_tool.reports.models.model_summary` of the mass model (solid, shell, printed).
    warnings : tuple of str
        The engine's warnings while loading, in command-line words (also printed on stderr).
    meshes : tuple of RawMesh
        The files as read (for the HTML views).

    Properties
    ----------
    units_assumed : bool
        No ``--units`` was given and no file declares its unit: the coordinates were taken as metres.
    """

    props: MassProperties
    density_source: str
    model: dict
    warnings: tuple
    meshes: tuple

    @property
    def units_assumed(self) -> bool:
        return any(getattr(m, "units_assumed", False) for m in self.meshes)

    def notes(self) -> tuple:
        """Report lines that are not warnings: the metres taken when no unit was given (a part 0.1 mm to 20 m
        long raises no warning, but a 15 mm part exported in millimetres reads as 15 m)."""
        if not self.units_assumed or any("metres assumed" in w for w in self.warnings):
            return ()
        from ..mesh.plausibility import largest_extent
        extent = max(largest_extent(m.vertices) for m in self.meshes if m.units_assumed)
        return (f"no --units given: coordinates taken as metres (largest extent {extent:.3g} m); "
                "STL and OBJ carry no unit, give --units if the file is in mm or in",)


def command_parser(args):
    """The parser of the running subcommand (for :func:`~inertia_tool.cli.speak_options`), or None."""
    return getattr(args, "_subparsers", {}).get(getattr(args, "command", None))


def shown_with_report(args, messages) -> None:
    """Record that ``messages`` (warnings in command-line words) were printed on standard output with the
    command's report or JSON: when standard error is the same terminal the command line does not print them
    there a second time (:func:`inertia_tool.cli.main`)."""
    args.warnings_shown = frozenset(getattr(args, "warnings_shown", frozenset())) | frozenset(messages)


def with_warnings(report: str, messages, notes=()) -> str:
    """A text report with the warnings (and notes) under its first line (title), where they are seen before
    the numbers."""
    if not messages and not notes:
        return report
    title, _, rest = report.partition("\n")
    lines = [f"  WARNING: {m}" for m in messages] + [f"  note: {n}" for n in notes]
    return "\n".join([title, *lines, rest]) if rest else "\n".join([title, *lines])


def load_model(args, *, parser=None, ignore=()) -> LoadedModel:
    """Read the FILEs of ``args`` once and compute their mass properties under the model options.

    ``ignore``: warning classes not to report (``top`` expects two equal moments).  The other engine
    warnings are recorded (in command-line words, through ``parser``'s options) and handed on, so that the
    command line prints them on stderr and the command can put them in its report and JSON.
    """
    with recorded_warnings(args, parser=parser, ignore=ignore) as messages:
        meshes = read_meshes(args)
        props, described, model = _load(args, meshes)
    return LoadedModel(props=props, density_source=described, model=model, warnings=tuple(messages),
                       meshes=tuple(meshes))


@contextmanager
def recorded_warnings(args, *, parser=None, ignore=()) -> Iterator[list[str]]:
    """Record the engine's warnings raised in the ``with`` block into the yielded list (in command-line words,
    through ``parser``'s options), for the command's report and JSON ``warnings``; on leaving the block they
    are handed on, so that the command line still prints them on stderr.  ``ignore``: classes not reported."""
    from . import speak_options
    messages: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaToolWarning)
        for category in ignore:
            warnings.simplefilter("ignore", category)
        yield messages
    kept = [w for w in caught if issubclass(w.category, InertiaToolWarning)]
    for w in kept:          # hand them on so the command line prints them on stderr
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    parser = parser if parser is not None else command_parser(args)
    messages.extend(speak_options(str(w.message), parser) for w in kept)


def _implied(props, mass) -> str:
    """``", implied density 2710 kg/m³"`` when a target mass set the density."""
    if mass is None or not props.volume > 0:
        return ""
    return f": implied density {props.mass / props.volume:.4g} kg/m³"


def _load(args, meshes):
    """``(props, density description, model summary)`` of the model options."""
    from ..reports.models import model_summary
    from ..mass.pipeline import resolve_density
    model = getattr(args, "model", "solid") or "solid"
    thickness, skin, infill = (getattr(args, k, None) for k in ("thickness", "shell", "infill"))
    if model == "solid" and thickness is not None:
        raise UsageError("--thickness needs --model shell (for a printed part use --shell and --infill)")
    if (skin is None) != (infill is None):
        raise UsageError("a printed part needs both --shell (skin thickness) and --infill (core fraction)")
    if skin is None and any(getattr(args, k, None) is not None
                            for k in ("top_bottom", "top_layers", "bottom_layers", "layer_height")):
        raise UsageError("top and bottom layers (--top-bottom, --top-layers, --bottom-layers, --layer-height) "
                         "describe a printed part: give --shell and --infill too")
    if model == "shell" and thickness is None:
        raise UsageError("--model shell needs --thickness (e.g. --thickness 2mm)")
    if model == "shell" and skin is not None:
        raise UsageError("--model shell takes --thickness; --shell/--infill describe a printed solid")
    if model == "solid" and skin is None:
        props, described = _load_solid(args, meshes)
        return props, described, model_summary("solid")
    from ..mass.thinwall import printed_part, shell_mass_properties    # imported on use: solids do without
    files = _files(args)
    if len(files) != 1 or split_part_spec(files[0])[1] is not None or meshes[0].parts:
        raise UsageError("the shell and printed-part models take one mesh file of one material with --density, "
                         "--material or --mass, not an assembly (FILE:material, or a file that names several "
                         "parts or materials)")
    options = load_options_from_args(args)
    density, mass = density_and_mass(args)
    _, described = resolve_density(density=density, material=args.material, mass=mass)
    common = dict(density=density, material=args.material, mass=mass)
    unit = length_unit(args)
    if model == "shell":
        t = check_option("--thickness", parse_length(thickness, default_unit=unit), typed=thickness)
        props = shell_mass_properties(meshes[0], thickness=t, options=options, **common)
        return props, described + _implied(props, mass), model_summary("shell", thickness=t)
    skin_m = check_option("--shell", parse_length(skin, default_unit=unit), typed=skin)
    top, bottom = _top_bottom(args, unit)
    printed = printed_part(meshes[0], skin=skin_m, infill=parse_fraction(infill), options=options, top=top,
                           bottom=bottom, **common)
    return printed.properties, described, model_summary("printed", printed=printed)


def _top_bottom(args, unit):
    """The top and bottom layer thicknesses (m, or None) of ``--top-bottom`` or ``--top-layers``/
    ``--bottom-layers`` × ``--layer-height``."""
    both = getattr(args, "top_bottom", None)
    top_n, bottom_n, height = (getattr(args, k, None) for k in ("top_layers", "bottom_layers", "layer_height"))
    if both is not None and (top_n is not None or bottom_n is not None):
        raise UsageError("give --top-bottom or --top-layers/--bottom-layers with --layer-height, not both")
    if both is not None:
        thickness = check_option("--shell", parse_length(both, default_unit=unit), typed=both, label="--top-bottom")
        return thickness, thickness
    if top_n is None and bottom_n is None:
        if height is not None:
            raise UsageError("--layer-height needs --top-layers and/or --bottom-layers")
        return None, None
    if height is None:
        raise UsageError("--top-layers and --bottom-layers need --layer-height (e.g. 0.2mm)")
    for option, n in (("--top-layers", top_n), ("--bottom-layers", bottom_n)):
        if n is not None and not 0 <= n <= 10_000:
            raise UsageError(f"{option} must be a whole number of layers from 0 to 10000, got {n}")
    h = check_option("--shell", parse_length(height, default_unit=unit), typed=height, label="--layer-height")
    return (None if top_n is None else top_n * h), (None if bottom_n is None else bottom_n * h)


def _load_solid(args, meshes):
    """Mass properties of one solid part or an assembly, and the density description.

    In an assembly, a global ``--density``/``--material`` is the default of the parts named without their own
    ``:material`` or ``:density`` (the description says so); when every part has its own, a global one would
    be ignored and is refused as contradictory (:class:`UsageError`).  A file that names materials per part
    (:mod:`inertia_tool.mesh.parts`) is split into its parts, each with the density of the rule of
    :mod:`inertia_tool.mass.materials` (``--material-map``, the file's densities, the material table); its
    ``FILE:material`` or the global option is the default of its parts without a material.
    """
    from ..mass.pipeline import DEFAULT_DENSITY, assembly, mass_properties, resolve_density
    options = load_options_from_args(args)
    density, mass = density_and_mass(args)
    material_map = parse_material_map(args)
    specs = [(raw, what) for raw, (_, what) in zip(meshes, (split_part_spec(f) for f in _files(args)))]
    if len(specs) == 1 and specs[0][1] is None and not specs[0][0].parts:
        if material_map:            # imported on use: one file without parts and no --material-map needs no rule
            from ..mass.materials import unused_map_keys
            unused_map_keys(material_map, (), meshes)
        _, described = resolve_density(density=density, material=args.material, mass=mass)
        props = mass_properties(specs[0][0], density=density, material=args.material, mass=mass, options=options)
        return props, described + _implied(props, mass)
    from ..mass.materials import material_parts, unused_map_keys
    default = None
    if density is not None or args.material is not None:
        option = f"--density {args.density}" if density is not None else f"--material {args.material}"
        if all(what is not None for _, what in specs):
            raise UsageError(f"{option} would apply to no part: every FILE has its own :material or :density "
                             "(drop the option, or name a part without its own to give it this default)")
        default, default_text = resolve_density(density=density, material=args.material)
    parts, own = [], []
    used: set[str] = set()
    for raw, what in specs:
        if raw.parts:                   # a multi-material file: its parts, FILE:material their default
            given = _part_density(what, raw) if what is not None else (
                {"density": density} if density is not None else
                {"material": args.material} if args.material is not None else {})
            parts += material_parts(raw, material_map=material_map, used=used, **given)
            own.append(what or "per part")
        elif what is not None:
            parts.append({"source": raw, **_part_density(what, raw)})
            own.append(what)
        elif density is not None:
            parts.append({"source": raw, "density": density})
        elif args.material is not None:
            parts.append({"source": raw, "material": args.material})
        else:
            parts.append({"source": raw})
    unused_map_keys(material_map, used, meshes)
    defaulted = [spec["name"] for spec in parts if spec.pop("decided_by", None) == "default (water)"]
    props = assembly(parts, mass=mass, options=options,
                     name=meshes[0].source if len(meshes) == 1 and meshes[0].parts else "assembly")
    if len(specs) == 1 and not specs[0][0].parts:
        described = resolve_density(**_part_density(own[0]))[1]
    else:
        described = "per part" + (" (the file's materials; see the parts)" if any(r.parts for r in meshes) else "")
        if default is not None:
            described += f"; {default_text} for the parts without their own"
        elif len(own) < len(specs) or defaulted:
            described += (f"; {DEFAULT_DENSITY:g} kg/m³ (default: water) for the parts without their own"
                          + (f" ({', '.join(defaulted)}): give --material, --density or --material-map"
                             if defaulted else ""))
    if mass is not None:
        described += f", scaled to a total mass of {mass:g} kg" + _implied(props, mass).replace(":", ";", 1)
    return props, described


def model_words(model: dict) -> str:
    """``"; thin shell 0.002 m"``: the mass model in a few words, for one-line sources (empty for a solid)."""
    if model["model"] == "shell":
        return f"; thin shell {model['thickness']:g} m"
    if model["model"] == "printed":
        return (f"; printed: skin {model['skin']:g} m, infill {100 * model['infill']:g}% "
                f"(inward-offset model, mass within {round_up(100 * model['mass_error_bound'], 2):.2g}%)")
    return ""
