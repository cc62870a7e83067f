"""``inertia-tool top FILE --pivot X,Y,Z --spin 50rev/s --tilt 20deg``: the body as a heavy symmetric top."""

from __future__ import annotations

import json
import math
import sys

from ..errors import NearlyEqualMomentsWarning, UsageError
from ..tolerances import MAX_TRAJECTORY_SAMPLES as MAX_SAMPLES
from ..units import STANDARD_GRAVITY, parse_angle, parse_angular_rate, parse_duration, parse_vector
from .help import add_command
from .model_options import (add_files_argument, add_model_options, length_unit, load_model, model_words,
                            shown_with_report, with_warnings)
from .options import check_option, require_range
from .report_option import save_figure, say_written

# numpy, the engine and the reports load in run(): ``top --help`` needs none of them (issue 25 item 4)

__all__ = ["register", "run", "MAX_SAMPLES", "MIN_SAMPLES_PER_PERIOD"]

#: Simulated nutation periods when ``--duration`` is not given.
DEFAULT_PERIODS = 5


#: Fewest samples per nutation period (or per turn of the spin when there is no nutation) of a simulation:
#: fewer alias the measured period, and bound the integrator's work (its steps follow the fastest motion).
MIN_SAMPLES_PER_PERIOD = 16


def register(subparsers) -> None:
    p = add_command(
        subparsers, "top",
        description="Treat the body as a heavy symmetric top on a fixed pivot (Chapter 4, §4.4.3): the symmetry "
                    "axis runs from the pivot to the centre of mass. Prints the nutation limits and period, the "
                    "kind of precession (Fig. 4.3), the sleeping-top criterion and the steady precession rates, and "
                    "checks them on a simulation. Takes the same model options as analyze.",
        examples=["inertia-tool top meshes/spinning_top.stl --units mm --material pla --pivot 0,0,0 --spin 50rev/s "
                  "--tilt 20deg",
                  "inertia-tool top meshes/spinning_top.stl --units mm --pivot 0,0,0 --spin 30rev/s --tilt 10deg "
                  "--no-simulate --json",
                  "inertia-tool top meshes/spinning_top.stl --units mm --shell 1.2mm --infill 20% --pivot 0,0,0 "
                  "--spin 50rev/s --tilt 20deg --plot top.png"])
    add_files_argument(p)
    add_model_options(p)
    p.add_argument("--pivot", required=True, metavar="X,Y,Z",
                   help="pivot point in mesh coordinates (in --units unless a unit is given, e.g. 0,0,-2mm)")
    p.add_argument("--spin", required=True, metavar="RATE", help="spin about the symmetry axis, e.g. 50rev/s")
    p.add_argument("--tilt", default="0deg", metavar="ANGLE",
                   help="initial tilt of the symmetry axis from the vertical, e.g. 20deg or 0.3rad "
                        "(bare number: degrees; default 0)")
    p.add_argument("--precession", default="0", metavar="RATE", help="initial precession rate φ̇ (default 0)")
    p.add_argument("--nutation", default="0", metavar="RATE", help="initial tilting rate θ̇ (default 0)")
    p.add_argument("--gravity", type=float, default=STANDARD_GRAVITY, metavar="G",
                   help=f"gravitational acceleration, m/s² (default {STANDARD_GRAVITY})")
    p.add_argument("--symmetry-rtol", type=float, default=1e-3, metavar="REL",
                   help="relative tolerance for the two transverse moments about the pivot (default 1e-3)")
    p.add_argument("--duration", default=None, metavar="TIME",
                   help=f"simulated time (default {DEFAULT_PERIODS} nutation periods, at most 10 s)")
    p.add_argument("--samples", type=int, default=4001, metavar="N",
                   help=f"simulation samples (default 4001, at most {MAX_SAMPLES}, at least "
                        f"{MIN_SAMPLES_PER_PERIOD} per nutation period)")
    p.add_argument("--no-simulate", action="store_true", help="analysis only")
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of text")
    p.add_argument("--csv", metavar="OUT.csv", help="write the simulated axis path as CSV")
    p.add_argument("--plot", metavar="OUT.png", help="plot θ(t) and the path of the axis (needs matplotlib)")
    p.add_argument("--force", action="store_true", help="let --csv and --plot replace existing files")
    p.set_defaults(func=run)


def _write_csv(path: str, traj) -> None:
    import numpy as np

    from ..output import atomic_target

    data = np.column_stack([traj.t, traj.theta, traj.phi, traj.axis, traj.angular_momentum, traj.energy])
    header = "t_s,theta_rad,phi_rad,axis_x,axis_y,axis_z,L_x_kg_m2_s,L_y_kg_m2_s,L_z_kg_m2_s,energy_J"
    with atomic_target(path, label="--csv") as tmp:
        np.savetxt(tmp, data, delimiter=",", header=header, comments="", fmt="%.10g")


def _pyplot():
    """``matplotlib.pyplot`` on the Agg backend, or :class:`UsageError` when matplotlib is missing."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise UsageError("--plot needs matplotlib (pip install 'inertia-tool[plots]')") from exc
    return plt


def _plot(path: str, top, traj) -> None:
    """θ(t) with the predicted limits, and the path of the axis as θ against the precession angle φ (the
    chapter's Fig. 4.3: waves, loops or cusps between the two limiting circles)."""
    import numpy as np

    plt = _pyplot()
    from matplotlib.ticker import MaxNLocator
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    theta = np.degrees(traj.theta)
    a1.plot(traj.t, theta, lw=0.8)
    for th in (top.theta_min, top.theta_max):
        a1.axhline(math.degrees(th), color="k", lw=0.5, ls="--")
    a1.set_xlabel("t (s)")
    a1.set_ylabel("tilt θ (deg)")
    a1.set_title("nutation (dashed: predicted limits)")
    a2.plot(np.degrees(traj.phi - traj.phi[0]), theta, lw=0.8)
    for th in (top.theta_min, top.theta_max):
        a2.axhline(math.degrees(th), color="k", lw=0.5, ls="--")
    a2.invert_yaxis()                       # the axis tip seen from outside the sphere: θ grows downwards
    a2.set_xlabel("precession φ − φ0 (deg)")
    a2.set_ylabel("tilt θ (deg)")
    a2.set_title(f"path of the axis (Fig. 4.3): {top.precession_kind}")
    for ax in (a1, a2):
        ax.xaxis.set_major_locator(MaxNLocator(nbins=6, steps=[1, 2, 2.5, 5, 10]))
        ax.yaxis.set_major_locator(MaxNLocator(nbins=6, steps=[1, 2, 2.5, 5, 10]))
        ax.ticklabel_format(axis="y", useOffset=False)
    fig.tight_layout()
    save_figure(fig, path)


def _check_sampling(top, duration: float, samples: int) -> None:
    """Refuse a simulation with fewer than :data:`MIN_SAMPLES_PER_PERIOD` samples per nutation period (per
    turn of the spin when the nutation period is not finite)."""
    period, what = top.nutation_period, "nutation period"
    if not (math.isfinite(period) and period > 0):
        period, what = (2 * math.pi / abs(top.omega3), "turn of the spin") if top.omega3 else (math.inf, "")
    per_period = (samples - 1) * period / duration
    if math.isfinite(period) and per_period < MIN_SAMPLES_PER_PERIOD:
        longest = (samples - 1) * period / MIN_SAMPLES_PER_PERIOD
        need = math.ceil(MIN_SAMPLES_PER_PERIOD * duration / period) + 1
        raise UsageError(f"Undersampled: {samples} samples over {duration:g} s are {per_period:.3g} per {what} "
                         f"({period:.6g} s), fewer than the {MIN_SAMPLES_PER_PERIOD} needed: shorten --duration to "
                         f"at most {longest:.6g} s or use at least {need} --samples"
                         + (f" (at most {MAX_SAMPLES})" if need > MAX_SAMPLES else ""))


def _estimate_bounds(props, top, pivot, rtol: float):
    """``(estimated, per_part, bounds)`` of a top (issue 21, notes19): whether the part is an estimate, whether it
    is an assembly with bounds per part only, and :func:`~..dynamics.top_bounds.heavy_top_bounds` (None where the
    part is exact or its bounds give none)."""
    import numpy as np

    from ..dynamics.top_bounds import heavy_top_bounds

    mesh = props.mesh
    if mesh is None:
        estimated = any(getattr(getattr(p, "mesh", None), "uncertainty", None) is not None for p in props.parts)
        return estimated, estimated, None
    u = mesh.uncertainty
    if u is None:
        return False, False, None
    bounds = heavy_top_bounds(top, inertia_com=np.asarray(props.inertia),
                              inertia_pivot=np.asarray(props.inertia_about(pivot).tensor), mass=props.mass,
                              mass_rtol=u.mass, com_bound=u.center_of_mass, inertia_rtol=u.inertia, rtol=rtol)
    return True, False, bounds


def run(args) -> int:
    import numpy as np

    from ..dynamics.top import heavy_top_on_pivot
    from ..output import check_targets
    from ..reports.serialize import command_output, method_and_uncertainty
    from ..reports.stability import format_heavy_top, format_top_estimate, heavy_top_dict, top_bounds_dict

    tilt = parse_angle(args.tilt, default_unit="deg")
    if not (math.isfinite(tilt) and 0.0 <= tilt <= math.pi):
        raise UsageError(f"--tilt must be between 0 and 180 deg (0 and π rad) from the vertical, got {args.tilt} "
                         f"(= {math.degrees(tilt):.6g} deg)")
    check_option("--gravity", args.gravity)
    require_range(args.symmetry_rtol, "--symmetry-rtol", low=0, high=1, high_open=True)
    if not 2 <= args.samples <= MAX_SAMPLES:
        raise UsageError(f"--samples must be between 2 and {MAX_SAMPLES}, got {args.samples}")
    duration = None
    if args.duration is not None:
        duration = check_option("--duration", parse_duration(args.duration), typed=args.duration)
    if args.no_simulate and (args.csv or args.plot):
        raise UsageError("--csv and --plot need the simulation (drop --no-simulate)")
    check_targets([(args.csv, "--csv"), (args.plot, "--plot")], force=args.force)
    if args.plot:
        _pyplot()                      # a missing matplotlib is refused before any work or any file written
    # a symmetric top has two equal moments by design; heavy_top_on_pivot reports its own asymmetry
    loaded = load_model(args, ignore=(NearlyEqualMomentsWarning,))
    props, described = loaded.props, loaded.density_source
    pivot = np.array(check_option("--pivot", list(parse_vector(args.pivot, default_unit=length_unit(args))),
                                  typed=args.pivot))
    rates = {name: check_option(f"--{name}", parse_angular_rate(getattr(args, name)), typed=getattr(args, name))
             for name in ("spin", "nutation", "precession")}
    top = heavy_top_on_pivot(props, pivot, theta0=tilt, omega3=rates["spin"], theta_dot0=rates["nutation"],
                             phi_dot0=rates["precession"], g=args.gravity, rtol=args.symmetry_rtol)
    estimated, per_part, bounds = _estimate_bounds(props, top, pivot, args.symmetry_rtol)
    traj = None
    if not args.no_simulate:
        if duration is not None:
            _check_sampling(top, duration, args.samples)
        elif math.isfinite(top.nutation_period):
            duration = min(DEFAULT_PERIODS * top.nutation_period, 10.0)
        else:
            duration = 10.0
        traj = top.simulate(duration, samples=args.samples)
    if args.csv:
        _write_csv(args.csv, traj)
    if args.plot:
        _plot(args.plot, top, traj)
    say_written([args.csv, args.plot])
    if args.json:
        method, uncertainty = method_and_uncertainty(props)
        out = command_output("top", {
            "name": props.name, "density_source": described, "mass": props.mass, "method": method,
            "uncertainty": uncertainty, "model": loaded.model, "units_assumed": loaded.units_assumed,
            "top": heavy_top_dict(top, traj),
            "top_bounds": top_bounds_dict(top, bounds, estimated=estimated)}, warnings=loaded.warnings)
        json.dump(out, sys.stdout, indent=2, ensure_ascii=False, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(with_warnings(f"{props.name}: mass {props.mass:.6g} kg ({described}{model_words(loaded.model)})",
                            loaded.warnings, loaded.notes()))
        print(format_heavy_top(top, traj))
        for line in format_top_estimate(top, bounds, estimated=estimated, per_part=per_part):
            print(line)
    shown_with_report(args, loaded.warnings)
    return 0
