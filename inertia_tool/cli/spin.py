"""``inertia-tool spin FILE --about intermediate --rate 5rev/s``: stability of spin about a principal axis,
predicted and simulated flip or wobble period."""

from __future__ import annotations

import json
import sys

from ..errors import UsageError
from ..tolerances import EQUAL_MOMENTS_RTOL as DEFAULT_EQUAL_RTOL
from ..tolerances import MAX_TRAJECTORY_SAMPLES as MAX_SAMPLES
from ..units import parse_angular_rate, parse_duration
from .help import add_command
from .model_options import (add_files_argument, add_model_options, load_model, model_words, shown_with_report,
                            with_warnings)
from .options import check_option, require_range
from .report_option import save_figure, say_written

# numpy, the engine and the reports load in run(): ``spin --help`` needs none of them (issue 25 item 4)

__all__ = ["register", "run", "MAX_SAMPLES"]

#: The principal axes by moment, as ``--about`` takes them: the parser's copy of
#: ``dynamics.spin_stability.AXIS_NAMES`` (the same tuple: ``tests/test_startup.py``).
AXIS_NAMES = ("minor", "intermediate", "major")


def register(subparsers) -> None:
    p = add_command(
        subparsers, "spin",
        description="Classify spin about each principal axis (Chapter 4, §4.4.1), then spin the body about one "
                    "of them with a small perturbation: print the predicted flip (unstable axis) or wobble "
                    "(stable axis) period and the one measured on a simulation of the torque-free motion. Takes "
                    "the same model options as analyze (assemblies, --model shell, --shell/--infill).",
        examples=["inertia-tool spin meshes/t_handle.stl --units mm --material aluminium --about intermediate",
                  "inertia-tool spin meshes/box.stl --units mm --about major --rate 2rev/s --json",
                  "inertia-tool spin meshes/box.stl --units mm --model shell --thickness 1mm --plot spin.png"])
    add_files_argument(p)
    add_model_options(p)
    p.add_argument("--about", choices=AXIS_NAMES, default="intermediate",
                   help="principal axis to spin about, by moment (default: intermediate)")
    p.add_argument("--rate", default="5rev/s", metavar="RATE",
                   help="spin rate: rad/s, rev/s, Hz, rpm, deg/s (default 5rev/s)")
    p.add_argument("--perturbation", type=float, default=1e-3, metavar="EPS",
                   help="relative transverse angular velocity added on each other principal axis, "
                        "0 < EPS < 1 (default 1e-3)")
    p.add_argument("--duration", default="30s", metavar="TIME", help="simulated time: s, ms, min (default 30s)")
    p.add_argument("--samples", type=int, default=None, metavar="N",
                   help="samples of the simulated trajectory (default 64 per turn, at least 2001, at most "
                        f"{MAX_SAMPLES}; at least 16 per predicted period)")
    p.add_argument("--method", choices=("auto", "exact", "numerical"), default="auto",
                   help="simulation: closed form (auto/exact) or numerical integration (default auto)")
    p.add_argument("--rtol", type=float, default=DEFAULT_EQUAL_RTOL, metavar="REL",
                   help=f"relative tolerance for equal moments (default {DEFAULT_EQUAL_RTOL:g} of the largest)")
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of text")
    p.add_argument("--csv", metavar="OUT.csv", help="write the simulated trajectory as CSV")
    p.add_argument("--plot", metavar="OUT.png", help="plot the simulated angular velocity (needs matplotlib)")
    p.add_argument("--force", action="store_true", help="let --csv and --plot replace existing files")
    p.set_defaults(func=run)


def _write_csv(path: str, traj) -> None:
    import numpy as np

    from ..output import atomic_target

    data = np.column_stack([traj.t, traj.angular_velocity, traj.orientation, traj.angular_momentum, traj.energy])
    header = ("t_s,omega_x_rad_s,omega_y_rad_s,omega_z_rad_s,q_w,q_x,q_y,q_z,"
              "L_x_kg_m2_s,L_y_kg_m2_s,L_z_kg_m2_s,energy_J")
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


def _plot(path: str, experiment) -> None:
    """The body angular velocity on the principal axes (top) and, on their own scale, the two components
    across the spin axis (bottom): a stable axis's small wobble is visible there, an unstable one's flips too."""
    import numpy as np

    plt = _pyplot()
    traj = experiment.trajectory
    axes = np.column_stack([e.axis for e in experiment.report.axes])
    w = np.asarray(traj.angular_velocity) @ axes
    spun = experiment.axis.index
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True,
                                      gridspec_kw={"height_ratios": [1, 1]})
    for k, name in enumerate(AXIS_NAMES):
        top.plot(traj.t, w[:, k], lw=0.8, color=f"C{k}", label=f"ω along I{k + 1} ({name})")
        if k != spun:
            bottom.plot(traj.t, w[:, k], lw=0.8, color=f"C{k}", label=f"ω along I{k + 1} ({name})")
    top.set_ylabel("ω (rad/s)")
    top.set_title(f"spin about the {experiment.axis.name} axis: {experiment.axis.kind}")
    top.legend(loc="best", fontsize=8)
    kind = "grows and flips the body" if experiment.axis.kind == "unstable" else "stays small (wobble)"
    bottom.set_ylabel("ω across the spin axis (rad/s)")
    bottom.set_title(f"the transverse components on their own scale: the perturbation {kind}", fontsize=10)
    bottom.set_xlabel("t (s)")
    bottom.legend(loc="best", fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)


def run(args) -> int:
    from ..dynamics.experiment import spin_experiment
    from ..output import check_targets
    from ..reports.serialize import command_output, method_and_uncertainty
    from ..reports.stability import format_spin, format_stability, principal_moment_bound, spin_dict, stability_dict

    require_range(args.perturbation, "--perturbation", low=0, high=1, low_open=True, high_open=True)
    require_range(args.rtol, "--rtol", low=0, high=1, high_open=True)
    if args.samples is not None and not 2 <= args.samples <= MAX_SAMPLES:
        raise UsageError(f"--samples must be between 2 and {MAX_SAMPLES}, got {args.samples}")
    rate = check_option("--rate", parse_angular_rate(args.rate), typed=args.rate)
    duration = check_option("--duration", parse_duration(args.duration), typed=args.duration)
    check_targets([(args.csv, "--csv"), (args.plot, "--plot")], force=args.force)
    if args.plot:
        _pyplot()                      # a missing matplotlib is refused before any work or any file written
    loaded = load_model(args)
    props, described = loaded.props, loaded.density_source
    experiment = spin_experiment(props, args.about, rate, perturbation=args.perturbation, duration=duration,
                                 samples=args.samples, rtol=args.rtol, method=args.method, max_samples=MAX_SAMPLES)
    if args.csv:
        _write_csv(args.csv, experiment.trajectory)
    if args.plot:
        _plot(args.plot, experiment)
    say_written([args.csv, args.plot])
    if args.json:
        method, uncertainty = method_and_uncertainty(props)
        out = command_output("spin", {
            "name": props.name, "density_source": described, "mass": props.mass, "method": method,
            "uncertainty": uncertainty, "model": loaded.model, "units_assumed": loaded.units_assumed,
            "stability": stability_dict(experiment.report, perturbation=args.perturbation),
            "spin": spin_dict(experiment)}, warnings=loaded.warnings)
        json.dump(out, sys.stdout, indent=2, ensure_ascii=False, allow_nan=False)
        sys.stdout.write("\n")
    else:
        print(with_warnings(f"{props.name}: mass {props.mass:.6g} kg ({described}{model_words(loaded.model)})",
                            loaded.warnings, loaded.notes()))
        print("\n".join(format_stability(experiment.report, perturbation=args.perturbation,
                                          moment_bound=principal_moment_bound(props))))
        print(format_spin(experiment, name=props.name))
    shown_with_report(args, loaded.warnings)
    return 0
