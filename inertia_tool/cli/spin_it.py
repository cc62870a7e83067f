"""``inertia-tool spin-it FILE --axis 0,0,1 --mode yoyo|top --wall 2mm``: hollow a part so that it spins."""

from __future__ import annotations

import json
import math
import os
import sys
from typing import TYPE_CHECKING

from ..errors import UsageError
from ..units import length_scale, parse_density, parse_length, parse_vector
from .help import add_command
from .model_options import (add_assume_option, add_material_options, assumed_from_args, length_unit, recorded_warnings,
                            shown_with_report)
from .options import check_option, density_and_mass
from .report_option import save_figure, say_written

if TYPE_CHECKING:     # numpy and the design stages load in run(): ``spin-it --help`` needs none of them
    import numpy as np

__all__ = ["register", "run", "OUTPUT_SUFFIXES"]

#: Mesh formats ``--out`` writes (through trimesh): STL in the ``--units`` of the input, 3MF in millimetres.
OUTPUT_SUFFIXES = (".stl", ".3mf")


def register(subparsers) -> None:
    from ..design.limits import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
    p = add_command(
        subparsers, "spin-it",
        description="Design the inside of a part (Bächer et al., Spin-It, 2014; Hafner et al., Spin-It Faster, "
                    "2024): a cavity bounded by a quadric, keeping a minimum wall, so that the part spins stably "
                    "about the given axis — as a yo-yo (free spin, Chapter 4 §4.4.1: the axis a principal axis of "
                    "largest moment, through the centre of mass) or a top on a pivot (§4.4.3: centre of mass on "
                    "the axis, equal transverse moments, low sleeping-top spin). The hollowed mesh is re-analysed "
                    "exactly; the report compares before and after.",
        examples=["inertia-tool spin-it meshes/spinning_top.stl --units mm --material pla --mode top --pivot 0,0,0 "
                  "--axis 0,0,1 --wall 2mm --resolution 24",
                  "inertia-tool spin-it meshes/washer.stl --units mm --material pla --axis 0,0,1 --wall 1.5mm "
                  "--resolution 24 --json"])
    p.add_argument("files", metavar="FILE", help="closed mesh: STL, OBJ, PLY, OFF, 3MF")
    add_material_options(p)
    p.add_argument("--axis", required=True, metavar="X,Y,Z",
                   help="spin axis direction (unitless, normalised), or one of x, y, z, -x, -y, -z")
    p.add_argument("--mode", choices=("yoyo", "top"), default="yoyo", help="yoyo (free spin) or top (on a pivot)")
    p.add_argument("--through", metavar="X,Y,Z",
                   help="yo-yo: a point of the axis (in --units unless a unit is given); the centre of mass is "
                        "pulled onto that line. Without it only the direction counts")
    p.add_argument("--pivot", metavar="X,Y,Z", help="top: the pivot point (in --units unless a unit is given)")
    p.add_argument("--wall", required=True, metavar="LENGTH",
                   help="minimum wall thickness, e.g. 2mm (a bare number is in --units)")
    p.add_argument("--insert", metavar="MATERIAL|DENSITY",
                   help="allow a dense insert of this material (e.g. steel or 7850) beside the cavity: a second "
                        "quadric region; written with --out as a two-material 3MF")
    p.add_argument("--resolution", type=int, default=DEFAULT_RESOLUTION, metavar="N",
                   help=f"voxel cells across the largest extent ({MIN_RESOLUTION} to {MAX_RESOLUTION}, "
                        f"default {DEFAULT_RESOLUTION})")
    p.add_argument("--out", metavar="OUT.stl|OUT.3mf",
                   help="write the hollowed part (STL in --units, 3MF in millimetres)")
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw sections of the hollowed part through and across the axis (needs matplotlib)")
    p.add_argument("--report", metavar="OUT.html",
                   help="write a self-contained HTML report: before/after table and the simulated spin before and "
                        "after (yo-yo: body angular velocity of a free spin; top: nutation angle θ(t))")
    p.add_argument("--repair", action="store_true",
                   help="accept a mesh with holes or cracks: design on the repaired surface (every 'after' number "
                        "is the exact re-analysis of the hollowed mesh, an estimate of the hollowed part with the "
                        "repaired part's bounds carried over)")
    add_assume_option(p)
    p.add_argument("--force", action="store_true", help="let --out, --plot and --report replace existing files")
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of text")
    p.set_defaults(func=run)


_NAMED_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def _direction(text: str) -> np.ndarray:
    named = str(text).strip().lower()
    import numpy as np

    sign, bare = (-1.0, named[1:]) if named[:1] == "-" else (1.0, named[1:] if named[:1] == "+" else named)
    if bare in _NAMED_AXES:
        return sign * np.array(_NAMED_AXES[bare])
    parts = [s.strip() for s in str(text).split(",")]
    try:
        v = np.array([float(s) for s in parts])
    except ValueError:
        v = np.zeros(0)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or not np.max(np.abs(v)) > 0:
        raise UsageError(f"--axis must be three finite numbers, not all zero, like 0,0,1, or x, y, z; got {text!r}")
    return v / np.max(np.abs(v))         # a direction: scaled so that its norm cannot overflow


def _insert_density(text: str) -> float:
    try:
        density = parse_density(text)
    except UsageError:
        from ..units import material_density
        density = material_density(text)
    return check_option("--density", density, typed=text, label="--insert")


def _write_two_materials(path: str, result, material: str, insert: str, insert_density: float) -> None:
    """The hollowed part and its insert as a two-material 3MF, each material with the density used (kg/m³),
    so that ``analyze`` of the file gives back the same mass properties."""
    from ..reports.mesh_3mf import write_3mf
    mm = length_scale("mm")
    write_3mf(path, [
        {"name": "part", "material": material, "color": "#9CC3E6FF", "vertices": result.vertices / mm,
         "faces": result.faces, "density": float(result.before.density)},
        {"name": "insert", "material": insert, "color": "#595959FF", "vertices": result.insert_vertices / mm,
         "faces": result.insert_faces, "density": float(insert_density)}], label="--out")


def _write_one_material(path: str, result, material: str) -> None:
    """The hollowed part as a 3MF that carries its material and the density used (kg/m³): ``analyze`` of the
    file gives the mass spin-it printed (a plain mesh export read back at the default density)."""
    from ..reports.mesh_3mf import write_3mf
    mm = length_scale("mm")
    write_3mf(path, [{"name": "part", "material": material, "color": "#9CC3E6FF", "vertices": result.vertices / mm,
                      "faces": result.faces, "density": float(result.before.density)}], label="--out")


def _write(path: str, vertices, faces, units: str) -> None:
    import numpy as np
    import trimesh

    from ..output import atomic_target
    suffix = os.path.splitext(path)[1].lower()
    scale = length_scale("mm") if suffix == ".3mf" else length_scale(units)
    mesh = trimesh.Trimesh(np.asarray(vertices) / scale, np.asarray(faces), process=False)
    with atomic_target(path, label="--out") as tmp:
        mesh.export(tmp, file_type=suffix[1:])


#: Free spin of the yo-yo picture: rate (rad/s), turns simulated, samples per turn, and the tilt (rad) of the
#: initial angular velocity from the requested axis (a small knock, so the "after" spin shows its stability).
_YOYO_RATE, _YOYO_TURNS, _YOYO_SAMPLES, _YOYO_KNOCK = 60.0, 12, 40, math.radians(0.1)
#: Top picture: initial tilt (rad), spin as a multiple of the larger sleeping threshold, nutation periods shown.
_TOP_TILT, _TOP_SPIN_FACTOR, _TOP_PERIODS = 0.05, 1.1, 3.0


def _motion(result):
    """The simulated spin before and after of the ``--report`` picture (engine calls; the report draws)."""
    import numpy as np

    from ..reports.spin_it import SpinMotion
    from ..rotations import perpendicular_basis
    axis = np.asarray(result.axis, dtype=float)
    e1, e2 = perpendicular_basis(axis)
    if result.mode == "yoyo":
        from ..dynamics.simulation import simulate
        t = np.linspace(0.0, _YOYO_TURNS * 2 * math.pi / _YOYO_RATE, _YOYO_TURNS * _YOYO_SAMPLES + 1)
        omega0 = _YOYO_RATE * (math.cos(_YOYO_KNOCK) * axis + math.sin(_YOYO_KNOCK) * e1)
        curves = []
        for props in (result.before, result.after):
            w = simulate(props, omega0, t).angular_velocity
            curves.append(np.column_stack([w @ e1, w @ e2]))
        return SpinMotion(t, curves[0], curves[1], ("ω·x′", "ω·y′"), "ω transverse to the axis (rad/s)",
                          f"Torque-free spin (Chapter 4 §4.4.1, exact solution) started at {_YOYO_RATE:g} rad/s "
                          f"about the spin axis tilted by {math.degrees(_YOYO_KNOCK):g}° towards x′; the body's "
                          "angular velocity across the axis (x′, y′ ⟂ axis, body frame) over "
                          f"{_YOYO_TURNS} turns. A part that spins true about the axis keeps it near zero; the "
                          "wobble is the circle it draws.")
    import warnings

    from ..dynamics.top import heavy_top_on_pivot
    from ..errors import AsymmetricTopWarning
    spin = _TOP_SPIN_FACTOR * max(result.metrics_before.sleeping_threshold, result.metrics_after.sleeping_threshold)
    tops = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AsymmetricTopWarning)    # the "before" part is not symmetric: say so
        for props in (result.before, result.after):
            tops.append(heavy_top_on_pivot(props, result.origin, theta0=_TOP_TILT, omega3=spin))
    periods = [p.nutation_period for p in tops if math.isfinite(p.nutation_period)]
    duration = _TOP_PERIODS * max(periods) if periods else 2.0
    t = np.linspace(0.0, duration, 601)
    thetas = [np.degrees(np.interp(t, tr.t, tr.theta)) for tr in (top.simulate(duration, samples=601)
                                                                   for top in tops)]
    return SpinMotion(t, thetas[0][:, None], thetas[1][:, None], ("θ",), "tilt θ from the vertical (°)",
                      f"Heavy symmetric top on its pivot (Chapter 4 §4.4.3, I1 the mean transverse moment) spun "
                      f"at {spin:.4g} rad/s ({_TOP_SPIN_FACTOR:g} × the larger sleeping threshold), released at "
                      f"θ = {math.degrees(_TOP_TILT):.3g}° with no tilt rate: the nutation θ(t) before and after.")


def run(args) -> int:
    from ..design.verify import spin_it_verified
    from ..output import check_targets
    from ..reports.spin_it import format_spin_it_text, format_verification, spin_it_dict, verification_dict

    if args.out and os.path.splitext(args.out)[1].lower() not in OUTPUT_SUFFIXES:
        raise UsageError(f"--out writes {' or '.join(OUTPUT_SUFFIXES)}, got {args.out!r}")
    check_targets([(args.out, "--out"), (args.plot, "--plot"), (args.report, "--report")], force=args.force)
    insert_density = _insert_density(args.insert) if args.insert is not None else None
    if insert_density is not None and args.out and not args.out.lower().endswith(".3mf"):
        raise UsageError(f"--insert makes a two-material part: --out must be a .3mf file, got {args.out!r}")
    if args.mode == "top" and args.pivot is None:
        raise UsageError("--mode top needs --pivot X,Y,Z")
    if args.mode == "top" and args.through is not None:
        raise UsageError("--through is for --mode yoyo; a top's axis passes through its --pivot")
    if args.mode == "yoyo" and args.pivot is not None:
        raise UsageError("--pivot is for --mode top")
    unit = length_unit(args)
    # the same range checks as every other command (cli/options.py OPTION_RANGES)
    wall = check_option("--wall", parse_length(args.wall, unit), typed=args.wall)
    through = (check_option("--through", list(parse_vector(args.through, unit)), typed=args.through)
               if args.through else None)
    pivot = check_option("--pivot", list(parse_vector(args.pivot, unit)), typed=args.pivot) if args.pivot else None
    density, mass = density_and_mass(args)
    axis = _direction(args.axis)
    # the hollowed mesh is rounded as the file will hold it (float32 STL in --units, 3MF in millimetres) before
    # it is re-analysed, so that `analyze` of the file gives the numbers printed here
    storage = length_scale("mm") if args.out and args.out.lower().endswith(".3mf") else length_scale(unit)
    # verified by re-analysis and simulation, retried on a finer grid; DesignRejectedError (exit 6) otherwise
    with recorded_warnings(args) as messages:
        result, verdicts = spin_it_verified(args.files, axis=axis, mode=args.mode, wall=wall,
                                            through=tuple(through) if through is not None else None,
                                            pivot=tuple(pivot) if pivot is not None else None, units=args.units,
                                            density=density, material=args.material, mass=mass,
                                            resolution=args.resolution, insert_density=insert_density,
                                            repair=bool(getattr(args, "repair", False)), storage_scale=storage,
                                            assume=assumed_from_args(args))
    if args.out and result.insert_vertices is not None:
        _write_two_materials(args.out, result, args.material or "part", args.insert, float(insert_density or 0.0))
    elif args.out and args.out.lower().endswith(".3mf"):
        _write_one_material(args.out, result, args.material or "part")
    elif args.out:
        _write(args.out, result.vertices, result.faces, unit)
    if args.plot:
        try:
            from ..reports.spin_it import spin_it_figure
            figure = spin_it_figure(result)
        except ImportError as exc:
            raise UsageError("--plot needs matplotlib (pip install 'inertia-tool[plots]')") from exc
        save_figure(figure, args.plot)
    if args.report:
        from ..output import write_text
        from ..reports.spin_it import spin_it_html
        write_text(args.report, spin_it_html(result, name=args.files, motion=_motion(result), output=args.out),
                   label="--report")
    # status lines go to stderr, every file named once (stdout is the report; docs/usage.md)
    say_written([args.out, args.plot, args.report])
    if args.json:
        from ..reports.serialize import command_output, method_and_uncertainty
        body = spin_it_dict(result, output=args.out)
        body["method"], body["uncertainty"] = method_and_uncertainty(result.after)   # the hollowed part's
        body["verification"] = verification_dict(verdicts)
        json.dump(command_output("spin-it", body, warnings=messages), sys.stdout, indent=2, ensure_ascii=False,
                  allow_nan=False)
        sys.stdout.write("\n")
        shown_with_report(args, messages)
    else:
        sys.stdout.write(format_spin_it_text(result, name=args.files, output=args.out))
        sys.stdout.write(format_verification(verdicts))
    return 0
