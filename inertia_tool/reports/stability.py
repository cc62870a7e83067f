"""Text and JSON-ready forms of the stability, heavy-top and spin-experiment results.  Formatting only."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover - annotations only; keeps scipy.integrate out of `analyze`
    from ..dynamics.top import HeavyTopReport, TopTrajectory
    from ..dynamics.top_bounds import HeavyTopBounds

from ..dynamics.spin_stability import StabilityReport
from .serialize import to_jsonable
from .numbers import number

__all__ = ["stability_dict", "format_stability", "heavy_top_dict", "format_heavy_top", "format_top_estimate",
           "top_bounds_dict", "spin_dict",
           "format_spin", "DEFAULT_REPORT_PERTURBATION"]

#: Relative perturbation used for the "turns to grow" figure in reports.
DEFAULT_REPORT_PERTURBATION = 1e-3

_KIND_TEXT = {
    "stable": "stable (wobbles)",
    "unstable": "UNSTABLE (tumbles: ε grows exponentially)",
    "marginal": "marginal (two equal moments: ε grows linearly)",
    "neutral": "neutral (all moments equal: any axis is steady)",
    "indifferent": "indifferent within tolerance",
}


def _g(x, digits: int = 4) -> str:
    return number(x, digits, infinite="never")


def _period(x, none: str, digits: int = 6) -> str:
    """``"0.0219 s"``, or ``none`` when the period is infinite or undefined (nothing recurs / not seen)."""
    if x is None or not math.isfinite(x):
        return none
    return f"{x:.{digits}g} s"


def _vec(v) -> str:
    v = np.asarray(v, dtype=float)
    v = np.where(np.abs(v) <= 1e-12 * max(np.max(np.abs(v)), 1e-300), 0.0, v) + 0.0
    v = np.round(v, 4) + 0.0          # what rounds to zero prints as 0.0000, not -0.0000
    return "(" + ", ".join(f"{x: .4f}" for x in v) + ")"


def stability_dict(report: StabilityReport, *, perturbation: float = DEFAULT_REPORT_PERTURBATION) -> list:
    """The ``stability`` list of the JSON reports: one object per principal axis, ascending moment."""
    out = []
    for e in report.axes:
        out.append({
            "axis_name": e.name,
            "moment": e.moment,
            "axis": e.axis,
            "kind": e.kind,
            "coefficient": e.coefficient,
            "growth_rate_per_unit_spin": e.growth_rate_per_unit_spin,
            "e_folding_turns": e.e_folding_turns,
            "wobble_frequency_per_unit_spin": e.wobble_frequency_per_unit_spin,
            "wobble_period_turns": e.wobble_period_turns,
            "wobble_amplification": e.wobble_amplification,
            "perturbation": perturbation,
            "turns_to_grow": e.turns_to_grow(perturbation, 1.0),
            "dissipation_stable": e.dissipation_stable,
        })
    return to_jsonable(out)


def principal_moment_bound(props) -> float | None:
    """kg·m²: how far each principal moment of an estimated part (a repaired surface) may lie from the true one, or
    None for a part proven exact; ``inf`` for an assembly with estimated parts (whose inertia bounds are per part).

    The estimate's bound is relative to ``‖I‖_F`` about the centre of mass; by Weyl's inequality each eigenvalue of
    a symmetric matrix moves by at most the perturbation's spectral norm, which is at most its Frobenius norm."""
    mesh = getattr(props, "mesh", None)
    if mesh is None:
        parts = getattr(props, "parts", ())
        estimated = any(getattr(getattr(p, "mesh", None), "uncertainty", None) is not None for p in parts)
        return float("inf") if estimated else None
    bounds = getattr(mesh, "uncertainty", None)
    if bounds is None:
        return None
    return float(bounds.inertia) * float(np.linalg.norm(props.inertia))


def _estimate_line(report: StabilityReport, moment_bound: float) -> str:
    """The caveat of an estimated part's classification (review19): which moments its bound leaves in doubt."""
    if not np.isfinite(moment_bound):
        return ("    the part is an estimate with bounds per part only: the moments' order and the classes are not "
                "proven")
    close = [(a, b) for a, b in zip(report.axes, report.axes[1:]) if b.moment - a.moment <= 2 * moment_bound]
    said = (f"    the part is an estimate: each moment within ±{moment_bound:.3e} kg·m² of the true one (the repaired "
            "part's inertia bound, Weyl's inequality)")
    if not close:
        return said + "; the moments are further apart than twice that, so their order and the classes hold"
    pairs = ", ".join(f"I{a.index + 1} and I{b.index + 1}" for a, b in close)
    return (said + f"; {pairs} lie within twice that of each other, so which axis is which there, their classes "
            "and the periods are not certain")


def format_stability(report: StabilityReport, *, perturbation: float = DEFAULT_REPORT_PERTURBATION,
                     moment_bound: float | None = None) -> list[str]:
    """Lines of the "spin stability" section (§4.4.1); ``moment_bound`` (kg·m², :func:`principal_moment_bound`)
    adds the caveat of an estimated part."""
    tolerance = getattr(report, "moment_tolerance", None)
    lines = ["  spin stability about the principal axes (§4.4.1; ε̈ = c ω² ε; "
             f"equal moments within {report.rtol:g}"
             + (f"; manufacturing tolerance {100 * tolerance:.3g}% of the largest moment" if tolerance else "")
             + "):"]
    for e in report.axes:
        detail = f"c = {e.coefficient:+.4g}"
        if e.kind == "stable":
            detail += f", wobble period {_g(e.wobble_period_turns)} turns"
            if e.wobble_amplification > 10:
                detail += f", a small perturbation can grow ×{_g(e.wobble_amplification, 3)}"
        elif e.kind in ("unstable", "marginal"):
            detail += (f", a {perturbation:g} wobble reaches order one in "
                       f"{_g(e.turns_to_grow(perturbation, 1.0))} turns")
        elif e.kind == "indifferent":
            gap = min(abs(e.moment - o.moment) for o in report.axes if o is not e) / report.moments[2]
            detail += (f" as designed; its moment differs from the next by {gap:.2g} of the largest, less than "
                       f"the {100 * (tolerance or 0.0):.3g}% tolerance: c is a product of moment differences (§4.4.1), "
                       "so the made part may wobble or tumble")
        lines.append(f"    I{e.index + 1} {e.name:<12} {e.moment:.6e} kg·m²  axis {_vec(e.axis)}  "
                     f"{_KIND_TEXT[e.kind]}; {detail}")
    stable = [e for e in report.axes if e.dissipation_stable]
    names = " or ".join(f"I{e.index + 1} ({e.name})" for e in stable)
    lines.append(f"    with energy loss (flexing, fluid): only spin about {names} lasts (major-axis rule)")
    if moment_bound is not None:
        lines.append(_estimate_line(report, moment_bound))
    return lines


def heavy_top_dict(top: HeavyTopReport, trajectory: TopTrajectory | None = None) -> dict:
    """JSON-ready ``top`` object (SI); with a ``trajectory``, a ``simulation`` summary."""
    out = to_jsonable(top)
    out["critical_sleeping_spin"] = to_jsonable(top.critical_sleeping_spin)
    if trajectory is not None:
        out["simulation"] = to_jsonable({
            "duration": float(trajectory.t[-1]),
            "samples": int(len(trajectory.t)),
            "theta_min": float(trajectory.theta.min()),
            "theta_max": float(trajectory.theta.max()),
            "nutation_period": trajectory.measured_nutation_period(),
            "mean_precession_rate": trajectory.measured_precession_rate(),
            "relative_energy_drift": float(np.ptp(trajectory.energy) / max(abs(trajectory.energy).max(), 1e-300)),
        })
    return out


def _precession_text(rate: float) -> str:
    if not math.isfinite(rate):
        return "undefined (the axis passes through the vertical)"
    return f"{rate:.6g} rad/s"


def _deg(x: float) -> str:
    return f"{math.degrees(x):.4g}°"


def format_heavy_top(top: HeavyTopReport, trajectory: TopTrajectory | None = None, *, name: str = "") -> str:
    """Multi-line text report of the heavy-top analysis (and simulation)."""
    lines = [f"Heavy symmetric top{': ' + name if name else ''} (§4.4.3)"]
    if top.pivot is not None:
        lines.append(f"  pivot {_vec(top.pivot)} m; symmetry axis pivot → centre of mass {_vec(top.symmetry_axis)}"
                     " (mesh axes)")
    lines.append(f"  mass {top.mass:.6g} kg, l = {top.length:.6g} m, g = {top.gravity:g} m/s²")
    lines.append(f"  about the pivot: I1 = {top.transverse_moment:.6e} kg·m² (transverse), "
                 f"I3 = {top.axial_moment:.6e} kg·m² (axial)")
    if top.transverse_asymmetry > 1e-9:
        lines.append(f"  transverse asymmetry {top.transverse_asymmetry:.2e} (0 for a true symmetric top)")
    lines.append(f"  start: spin ω3 = {top.omega3:.6g} rad/s ({top.omega3 / (2 * math.pi):.4g} rev/s), "
                 f"tilt θ0 = {_deg(top.theta0)}, θ̇0 = {top.theta_dot0:g} rad/s, φ̇0 = {top.phi_dot0:g} rad/s")
    crit = top.critical_sleeping_spin
    lines.append(f"  upright (sleeping) top: {'stable' if top.sleeping_stable else 'UNSTABLE'} — "
                 f"I3²ω3²/(4 I1 M g l) = {top.sleeping_margin:.4g} (needs > 1: spin above {crit:.4g} rad/s = "
                 f"{crit / (2 * math.pi):.4g} rev/s)")
    lines.append(f"  nutation: θ between {_deg(top.theta_min)} and {_deg(top.theta_max)}, "
                 + ("period " + _period(top.nutation_period, "") if math.isfinite(top.nutation_period)
                    else "no nutation period (θ never returns)"))
    kinds = {"looping": "looping (Fig. 4.3a: the precession has opposite signs at θ_min and θ_max)",
             "undulating": "undulating (Fig. 4.3b: precession keeps its direction)",
             "cusp": "cusps (Fig. 4.3c: precession stops at θ_min, as when released from rest)",
             "steady": "steady (no nutation)", "planar": "none (no spin and no azimuthal motion)"}
    lines.append(f"  path of the axis: {kinds[top.precession_kind]}")
    if top.precession_rate_slow is None:
        lines.append("  steady precession at θ0: impossible (too little spin)")
    else:
        fast = "" if top.precession_rate_fast is None else f", fast {top.precession_rate_fast:.6g} rad/s"
        lines.append(f"  steady precession at θ0: slow {top.precession_rate_slow:.6g} rad/s{fast}")
    if trajectory is not None:
        measured = trajectory.measured_nutation_period()
        drift = float(np.ptp(trajectory.energy) / max(abs(trajectory.energy).max(), 1e-300))
        lines.append(f"  simulated {trajectory.t[-1]:.4g} s: θ between {_deg(trajectory.theta.min())} and "
                     f"{_deg(trajectory.theta.max())}, "
                     + (f"nutation period {measured:.6g} s" if math.isfinite(measured)
                        else "no nutation period seen within the simulated time") + ", mean precession "
                     f"{_precession_text(trajectory.measured_precession_rate())}, energy drift {drift:.1e}")
    return "\n".join(lines)


def _range(r: tuple[float, float], fmt: str = ".4g") -> str:
    return f"{r[0]:{fmt}} and {r[1]:{fmt}}"


def format_top_estimate(top: HeavyTopReport, bounds: HeavyTopBounds | None, *, estimated: bool = True,
                        per_part: bool = False) -> list[str]:
    """The caveat of a heavy top on an estimated part (issue 21, notes19): which of the results the part's bounds
    (:func:`~inertia_tool.dynamics.top_bounds.heavy_top_bounds`) leave in doubt; no lines for an exact part.

    ``per_part``: an assembly whose parts carry their own bounds only (nothing bounded for the whole);
    ``bounds`` None on an estimate: the bounds give none (the centre of mass may lie at the pivot, a moment
    may vanish)."""
    if not estimated:
        return []
    if per_part or bounds is None:
        why = ("an assembly with estimated parts, bounds per part only" if per_part else
               "its bounds reach the pivot or a moment's size")
        return [f"  the part is an estimate ({why}): none of the results above is proven; the symmetric-top "
                "reading, the moments, the sleeping-top verdict and the precession rates are not bounded"]
    b = bounds
    lines = [f"  the part is an estimate: about the pivot I1 and I3 (and the two transverse moments) each within "
             f"±{b.moment:.3e} kg·m², l within ±{b.length:.3g} m, M g l between {_range(b.gravity_torque)} N·m "
             "(the repaired part's bounds, under its assumptions, carried by Eq. 4.16 and Weyl's inequality)"]
    in_doubt: list[str] = []
    if b.symmetric is True:
        lines.append(f"    symmetric top: holds (the true part's asymmetry at most {b.asymmetry[1]:.3g} of I1, within "
                     "the tolerance)")
    elif b.symmetric is False:
        lines.append(f"    symmetric top: NOT one (the true part's asymmetry at least {b.asymmetry[0]:.3g} of I1, "
                     "beyond the tolerance): the results are those of the mean transverse moment")
    else:
        in_doubt.append("the symmetric-top reading")
        lines.append(f"    symmetric top: in doubt (the true part's asymmetry between {_range(b.asymmetry, '.3g')} "
                     "of I1; the reading needs two equal transverse moments)")
    lo, hi = b.sleeping_margin
    holds = lo > 1.0 if top.sleeping_stable else hi <= 1.0
    if not holds:
        in_doubt.append("the sleeping-top verdict")
    lines.append(f"    upright (sleeping) top: I3²ω3²/(4 I1 M g l) between {_range(b.sleeping_margin)}: the verdict "
                 + ("holds" if holds else "is in doubt"))
    if b.steady_possible is None:
        in_doubt.append("whether steady precession exists")
        lines.append("    steady precession at θ0: possible for some parts within the bounds, not for others (in "
                     "doubt)")
    elif b.steady_possible and b.precession_rate_slow is not None:
        fast = ("" if b.precession_rate_fast is None else
                f", fast between {_range(b.precession_rate_fast, '.6g')} rad/s")
        lines.append(f"    steady precession at θ0: slow between {_range(b.precession_rate_slow, '.6g')} rad/s{fast}")
    elif not b.steady_possible:
        lines.append("    steady precession at θ0: impossible for every part within the bounds")
    in_doubt.append("the nutation limits and period and the path's kind (not bounded: they follow from the same "
                    "inputs through a cubic's roots)")
    lines.append("    in doubt: " + "; ".join(in_doubt))
    return lines


def _in_doubt(top: HeavyTopReport, b: HeavyTopBounds) -> list[str]:
    """Keys of the results the bounds leave in doubt (``top_bounds.in_doubt`` of the JSON)."""
    lo, hi = b.sleeping_margin
    return ([] if b.symmetric is not None else ["symmetric_top"]) \
        + ([] if (lo > 1.0 if top.sleeping_stable else hi <= 1.0) else ["sleeping_top"]) \
        + ([] if b.steady_possible is not None else ["steady_precession"]) \
        + ["nutation_limits", "nutation_period", "precession_kind"]


def top_bounds_dict(top: HeavyTopReport, bounds: HeavyTopBounds | None, *, estimated: bool) -> dict | None:
    """JSON-ready ``top_bounds`` (issue 21, notes19): None for an exact part; for an estimate ``bounded`` (False
    when the bounds give none: every result in doubt), the fields of :class:`HeavyTopBounds` (SI) and
    ``in_doubt``, the keys of the results they leave in doubt."""
    if not estimated:
        return None
    if bounds is None:
        return {"bounded": False, "in_doubt": ["symmetric_top", "moments", "sleeping_top", "steady_precession",
                                               "nutation_limits", "nutation_period", "precession_kind"]}
    return {"bounded": True, **to_jsonable(bounds), "in_doubt": _in_doubt(top, bounds)}


def spin_dict(experiment) -> dict:
    """JSON-ready ``spin`` object of a :class:`inertia_tool.dynamics.experiment.SpinExperiment`."""
    e = experiment
    return to_jsonable({
        "axis_name": e.axis.name,
        "moment": e.axis.moment,
        "axis": e.axis.axis,
        "kind": e.axis.kind,
        "coefficient": e.axis.coefficient,
        "rate": e.rate,
        "perturbation": e.perturbation,
        "initial_angular_velocity": e.initial_angular_velocity,
        "predicted": {
            "linear_period": e.predicted_linear_period,
            "time_to_grow": e.predicted_time_to_grow,
            "turns_to_grow": e.axis.turns_to_grow(e.perturbation, 1.0),
            "polhode_period": e.predicted_polhode_period,
            "period": e.predicted_period,
        },
        "simulated": {
            "duration": float(e.trajectory.t[-1]),
            "samples": int(len(e.trajectory.t)),
            "method": e.trajectory.method,
            "period": e.measured_period,
            "events": e.measured_events,
            "first_flip_time": e.first_flip_time,
            "max_tilt": e.max_tilt,
            "relative_energy_drift": e.energy_drift,
        },
        "period_kind": e.period_kind,
    })


def format_spin(experiment, *, name: str = "") -> str:
    """Text report of a spin experiment: classification, predicted and simulated period."""
    e = experiment
    a = e.axis
    turn = 2 * math.pi / e.rate
    lines = [f"Spin about the {a.name} axis{' of ' + name if name else ''} (I{a.index + 1} = {a.moment:.6e} kg·m², "
             f"axis {_vec(a.axis)} mesh axes)",
             f"  spin {e.rate:.6g} rad/s ({e.rate / (2 * math.pi):.4g} rev/s, one turn {turn:.4g} s), "
             f"perturbation {e.perturbation:g} of the spin on each transverse axis",
             f"  classification: {_KIND_TEXT[a.kind]}; c = {a.coefficient:+.4g} (§4.4.1)"]
    what = "flip interval (time between flips)" if e.period_kind == "flip" else "wobble period"
    if a.kind == "stable":
        lines.append(f"  predicted (linear): wobble period {_g(e.predicted_linear_period, 6)} s "
                     f"({_g(a.wobble_period_turns)} turns)")
    elif a.kind in ("unstable", "marginal"):
        lines.append(f"  predicted (linear): the {e.perturbation:g} wobble reaches order one after "
                     f"{_g(e.predicted_time_to_grow, 6)} s ({_g(a.turns_to_grow(e.perturbation, 1.0))} turns)")
    lines.append("  predicted (exact, Landau–Lifshitz §37): "
                 + (f"{what} {_period(e.predicted_period, '')}" if math.isfinite(e.predicted_period)
                    else "nothing recurs (no flip, no wobble)"))
    event = "flip" if e.period_kind == "flip" else "upward crossing"
    if math.isfinite(e.measured_period):
        seen = f"{what} {e.measured_period:.6g} s from {e.measured_events} events"
    elif e.measured_events == 1:
        seen = f"one {event} only, no {what} within the simulated time (two are needed)"
    else:
        seen = f"no {event} within the simulated time, so no {what}"
    lines.append(f"  simulated {e.trajectory.t[-1]:.4g} s ({e.trajectory.method}, {len(e.trajectory.t)} samples): "
                 f"{seen}; largest tilt of the "
                 f"spin axis {math.degrees(e.max_tilt):.3g}°; energy drift {e.energy_drift:.1e}")
    if e.period_kind == "flip":
        lines.append(f"  first flip after {_g(e.first_flip_time, 6)} s" if e.first_flip_time is not None
                     else "  no flip within the simulated time")
    return "\n".join(lines)
