"""``inertia-tool analyze FILE [FILE:material ...]``: mass properties report (text or JSON)."""

from __future__ import annotations

import json
import os
import sys
import warnings

from ..errors import InertiaToolWarning, PhysicsError, UsageError
from ..io import DEFAULT_MAX_FACES
from ..pipeline import DEFAULT_MERGE_TOLERANCE, assembly, mass_properties, resolve_density
from ..properties import combine
from ..reports.serialize import mass_properties_dict
from ..reports.stability import format_stability, stability_dict
from ..reports.text import format_mass_properties
from ..stability import stability
from ..units import MATERIALS, parse_density, parse_mass

__all__ = ["register", "run", "split_part_spec", "add_material_options", "add_mesh_options", "load_from_args"]


def split_part_spec(spec: str) -> tuple[str, str | None]:
    """``"lid.stl:abs"`` → ``("lid.stl", "abs")``; a path that exists as given is never split."""
    if os.path.exists(spec) or ":" not in spec:
        return spec, None
    path, _, what = spec.rpartition(":")
    if not path or os.sep in what or "/" in what:
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
    """``--repair``, ``--merge-tolerance``, ``--max-faces``."""
    g = parser.add_argument_group("mesh checks")
    g.add_argument("--repair", action="store_true",
                   help="close holes and fix inconsistent winding instead of refusing the mesh")
    g.add_argument("--merge-tolerance", type=float, default=DEFAULT_MERGE_TOLERANCE, metavar="REL",
                   help="relative tolerance (of the bounding-box diagonal) for welding nearly coincident "
                        f"vertices when exact welding leaves the surface open (default {DEFAULT_MERGE_TOLERANCE:g}; 0 off)")
    g.add_argument("--max-faces", type=int, default=DEFAULT_MAX_FACES, metavar="N",
                   help=f"refuse meshes with more triangles (default {DEFAULT_MAX_FACES:,})")


def _part_density(what: str) -> dict:
    try:
        return {"density": parse_density(what)}
    except UsageError:
        return {"material": what}


def load_from_args(args):
    """Mass properties of the ``files`` in ``args`` (one part or an assembly) and the density description."""
    density = parse_density(args.density) if args.density is not None else None
    mass = parse_mass(args.mass) if args.mass is not None else None
    options = dict(repair=args.repair, merge_tolerance=args.merge_tolerance, max_faces=args.max_faces)
    files = list(args.files) if isinstance(args.files, (list, tuple)) else [args.files]
    specs = [split_part_spec(f) for f in files]
    if len(specs) == 1 and specs[0][1] is None:
        _, described = resolve_density(density=density, material=args.material, mass=mass)
        props = mass_properties(specs[0][0], units=args.units, density=density, material=args.material,
                                mass=mass, **options)
        return props, described
    parts = []
    for path, what in specs:
        if what is not None:
            parts.append({"source": path, **_part_density(what)})
        elif density is not None or args.material is not None:
            parts.append({"source": path, "density": density, "material": args.material})
        else:
            parts.append({"source": path})
    for p in parts:
        for k in ("density", "material"):
            if k in p and p[k] is None:
                del p[k]
    props = assembly(parts, units=args.units, mass=mass, **options)
    described = "per part" + (f", scaled to a total mass of {mass:g} kg" if mass is not None else "")
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
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of the text report")
    p.set_defaults(func=run)


def run(args) -> int:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaToolWarning)
        props, described = load_from_args(args)
    messages = [str(w.message) for w in caught if issubclass(w.category, InertiaToolWarning)]
    for w in caught:          # hand them on so the command line prints them on stderr
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    stab, stab_error = _stability_section(props)
    if args.json:
        out = mass_properties_dict(props, density_source=described)
        out["stability"] = stability_dict(stab) if stab is not None else None   # spin stability (§4.4.1)
        out["warnings"] = messages
        json.dump(out, sys.stdout, indent=2, ensure_ascii=False, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(format_mass_properties(props, density_source=described))
        print("\n".join(format_stability(stab)) if stab is not None else f"  spin stability: {stab_error}")
    return 0


def _stability_section(props):
    """Spin stability of the principal axes for the report, or ``(None, reason)`` when undefined."""
    try:
        return stability(props), None
    except PhysicsError as exc:
        return None, f"undefined ({exc})"
