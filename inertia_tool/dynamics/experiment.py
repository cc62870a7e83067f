"""The spin experiment: spin a body about one principal axis with a small perturbation, predict what happens
(§4.4.1 and the exact polhode period) and check it against a simulation of the torque-free motion.

This module only wires :mod:`inertia_tool.dynamics.spin_stability` (prediction) to :mod:`inertia_tool.dynamics`
(simulation) and measures the simulated period; it is what ``inertia-tool spin`` runs.
"""

from __future__ import annotations

import math


import numpy as np

from ..values import frozen_value
from ..errors import NonFiniteResultError, UsageError
from .spin_stability import AxisStability, StabilityReport, polhode_period, stability
from ..mass.principal import DEFAULT_EQUAL_RTOL
from ..tolerances import MAX_TRAJECTORY_SAMPLES

__all__ = ["SpinExperiment", "spin_experiment", "SAMPLES_PER_TURN", "MIN_SAMPLES_PER_PERIOD", "MAX_SAMPLES"]

#: Default sampling density of the simulated trajectory (samples per revolution of the spin).
SAMPLES_PER_TURN = 64

#: Fewest samples per predicted flip interval or wobble period for the measured one to mean anything
#: (below a few per period sign changes alias and the "measured" period is wrong without any sign of it).
MIN_SAMPLES_PER_PERIOD = 16


@frozen_value
class SpinExperiment:
    """A perturbed spin about a principal axis: prediction and simulation.

    Attributes
    ----------
    report : StabilityReport
        Classification of all three axes.
    axis : AxisStability
        The axis spun about.
    rate : float
        Spin ω about ``axis``, rad/s.
    perturbation : float
        Relative transverse perturbation ε0: the initial angular velocity is
        ``ω (â_k + ε0 â_i + ε0 â_j)`` for spin axis ``k`` and the other principal axes ``i, j``.
    initial_angular_velocity : (3,) float
        rad/s, mesh axes.
    period_kind : str
        ``"flip"`` (unstable or marginal axis: the spin axis turns over; the period is the interval between
        successive flips), ``"wobble"`` (stable axis: period of the transverse angular velocity) or
        ``"none"`` (neutral).
    predicted_linear_period : float or None
        Stable axes: ``2π / (√(−c) ω)``, s.
    predicted_time_to_grow : float or None
        Unstable/marginal axes: time for the ε0 perturbation to reach order one (linearised,
        ``AxisStability.turns_to_grow``), s.
    predicted_polhode_period : float
        Exact period of the body angular velocity (:func:`inertia_tool.dynamics.spin_stability.polhode_period`), s.
    predicted_period : float
        The prediction comparable with ``measured_period``: the polhode period for a wobble, half of it for
        flips (the body flips twice per period), s; ``inf`` when nothing recurs.
    trajectory : Trajectory
        The simulation (``inertia_tool.dynamics.simulation``).
    measured_period : float
        Mean interval between flips (sign changes of ``ω · â_k``) or between upward zero crossings of
        ``ω · â_i`` (wobble), s; ``nan`` with fewer than two events.
    measured_events : int
        Number of flips or upward crossings seen.
    first_flip_time : float or None
        Time of the first flip, s (flip experiments; ``None`` if none happened).
    max_tilt : float
        Largest angle between the spin axis (carried by the body) and the fixed angular momentum, rad.
    energy_drift : float
        ``ptp(energy) / max(energy)`` of the simulation (0 for the exact solution up to round-off).
    """

    report: StabilityReport
    axis: AxisStability
    rate: float
    perturbation: float
    initial_angular_velocity: np.ndarray
    period_kind: str
    predicted_linear_period: float | None
    predicted_time_to_grow: float | None
    predicted_polhode_period: float
    predicted_period: float
    trajectory: object
    measured_period: float
    measured_events: int
    first_flip_time: float | None
    max_tilt: float
    energy_drift: float


#: Most output samples of a spin experiment (bounds memory and time; ``tolerances``, so the parser states it).
MAX_SAMPLES = MAX_TRAJECTORY_SAMPLES

def _crossings(t: np.ndarray, y: np.ndarray, *, upward_only: bool) -> np.ndarray:
    """Times where ``y`` changes sign (or only goes − → +), linearly interpolated."""
    if upward_only:
        idx = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    else:
        idx = np.nonzero(np.signbit(y[:-1]) != np.signbit(y[1:]))[0]
    return t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])


def spin_experiment(props, about, rate: float, *, perturbation: float = 1e-3, duration: float = 30.0,
                    samples: int | None = None, rtol: float = DEFAULT_EQUAL_RTOL, method: str = "auto",
                    max_samples: int = MAX_SAMPLES,
                    min_samples_per_period: float = MIN_SAMPLES_PER_PERIOD) -> SpinExperiment:
    """Spin ``props`` about a principal axis, predict the flip or wobble period and simulate it.

    Parameters
    ----------
    props : MassProperties
        The body.
    about : {"minor", "intermediate", "major"} or int
        The principal axis (ascending moment order).
    rate : float
        Spin, rad/s (> 0).
    perturbation : float
        Relative transverse perturbation ε0 (> 0), on both transverse principal axes.
    duration : float
        Simulated time, s.
    samples : int, optional
        Output samples; default ``SAMPLES_PER_TURN`` per revolution, at least 2001, at most ``max_samples``.
    rtol : float
        Equality tolerance of the classification (see :func:`inertia_tool.dynamics.spin_stability.stability`).
    method : str
        Passed to ``inertia_tool.dynamics.simulation`` (``"auto"``: exact closed form, ``"numerical"``: an
        independent numerical integration).
    max_samples : int
        Upper bound on the number of samples.
    min_samples_per_period : float
        Refuse (:class:`UsageError`) a sampling with fewer samples per predicted period (flip interval or
        wobble period): the measured period would alias to a wrong value.

    Returns
    -------
    SpinExperiment
    """
    from .simulation import simulate

    if not (rate > 0 and math.isfinite(rate)):
        raise UsageError(f"Expected a positive finite spin rate, got {rate!r} rad/s")
    if not (perturbation > 0 and math.isfinite(perturbation)):
        raise UsageError(f"Expected a positive finite perturbation, got {perturbation!r}")
    if not (duration > 0 and math.isfinite(duration)):
        raise UsageError(f"Expected a positive finite duration, got {duration!r} s")
    report = stability(props, rtol=rtol)
    NonFiniteResultError.check(f"the kinetic energy at {rate:g} rad/s",
                               0.5 * float(np.max(report.moments)) * rate * rate * (1.0 + 2.0 * perturbation ** 2),
                               because="the spin rate is outside any physical range")
    entry = report.about(about)
    k = entry.index
    i, j = (k + 1) % 3, (k + 2) % 3
    axes = np.column_stack([e.axis for e in report.axes])
    w_principal = np.zeros(3)
    w_principal[k] = rate
    w_principal[i] = w_principal[j] = perturbation * rate
    w_mesh = axes @ w_principal
    turns = duration * rate / (2 * math.pi)
    n = samples if samples is not None else int(min(max(2001, math.ceil(turns * SAMPLES_PER_TURN) + 1), max_samples))
    if not 2 <= n <= max_samples:
        raise UsageError(f"Expected 2 <= samples <= {max_samples}, got {n}")
    polhode = polhode_period(report.moments, w_principal)
    if entry.kind != "neutral":
        period = polhode if entry.kind == "stable" else polhode / 2.0
        per_period = (n - 1) * period / duration
        if math.isfinite(period) and per_period < min_samples_per_period:
            what = "wobble period" if entry.kind == "stable" else "flip interval"
            longest = (n - 1) * period / min_samples_per_period
            need = math.ceil(min_samples_per_period * duration / period) + 1
            raise UsageError(
                f"Undersampled: {n} samples over {duration:g} s are {per_period:.3g} per predicted {what} of "
                f"{period:.6g} s, fewer than the {min_samples_per_period:g} needed to measure it (the result "
                f"would alias): shorten the duration to at most {longest:.6g} s or use at least {need} samples"
                f"{f' (at most {max_samples} are allowed)' if need > max_samples else ''}")
    t = np.linspace(0.0, duration, n)
    traj = simulate(props, w_mesh, t, method=method)

    omega_p = np.asarray(traj.angular_velocity) @ axes       # components along the classified axes
    linear_period = None
    time_to_grow = None
    first_flip = None
    if entry.kind == "neutral":
        kind, predicted, measured, events = "none", math.inf, math.nan, 0
    elif entry.kind == "stable":
        kind = "wobble"
        wobble = entry.wobble_frequency_per_unit_spin
        assert wobble is not None, "a stable axis has a wobble frequency"
        linear_period = 2 * math.pi / (wobble * rate)
        predicted = polhode
        times = _crossings(t, omega_p[:, i], upward_only=True)
        events = len(times)
        measured = float(np.diff(times).mean()) if events >= 2 else math.nan
    else:
        kind = "flip"
        time_to_grow = entry.turns_to_grow(perturbation, 1.0) * 2 * math.pi / rate
        predicted = polhode / 2.0
        times = _crossings(t, omega_p[:, k], upward_only=False)
        events = len(times)
        measured = float(np.diff(times).mean()) if events >= 2 else math.nan
        first_flip = float(times[0]) if events else None
    # tilt of the body's spin axis from the (fixed) angular momentum, from the body-frame components
    tensor = axes @ np.diag(report.moments) @ axes.T
    body_l = np.asarray(traj.angular_velocity) @ tensor.T
    cos_tilt = (body_l @ entry.axis) / np.linalg.norm(body_l, axis=1)
    max_tilt = float(np.max(np.arccos(np.clip(cos_tilt, -1.0, 1.0))))
    energy = np.asarray(traj.energy)
    drift = float(np.ptp(energy) / max(np.max(np.abs(energy)), 1e-300))
    return SpinExperiment(report=report, axis=entry, rate=float(rate), perturbation=float(perturbation),
                          initial_angular_velocity=w_mesh, period_kind=kind, predicted_linear_period=linear_period,
                          predicted_time_to_grow=time_to_grow, predicted_polhode_period=polhode,
                          predicted_period=predicted, trajectory=traj, measured_period=measured,
                          measured_events=int(events), first_flip_time=first_flip, max_tilt=max_tilt,
                          energy_drift=drift)
