"""Rigid-body dynamics: stability of free spin, exact torque-free motion, integration with torque, the heavy top.

Stages (one module each): :mod:`.spin_stability` (the ε analysis of §4.4.1) and :mod:`.experiment` (predict and
simulate a perturbed spin); :mod:`.elliptic` (special functions) → :mod:`.torque_free` (closed forms, principal
frame) and :mod:`.integrate` (numerical, with torque), :mod:`.free_flow` (one exact free step) →
:mod:`.splitting` (exact free flow + torque kicks) → :mod:`.simulation` (public entry, frames) →
:mod:`.trajectory` (result), :mod:`.poinsot` (polhode/herpolhode), :mod:`.plot` (matplotlib figure);
:mod:`.top` (the heavy symmetric top, §4.4.3), :mod:`.top_motion` (its ``cos θ(t)`` through Weierstrass' ℘,
exercise 4.10) and :mod:`.impulse` (a sudden blow); :mod:`.rotating_frame` (pseudoforces, §4.2) and
:mod:`.free_precession` (free precession of a symmetric body, the Chandler wobble, §4.4.1).

The names below load on first use (PEP 562): the simulation stages import ``scipy.special`` and
``scipy.integrate`` (about 0.2 s), which ``inertia-tool analyze`` and the stability analysis never need.
"""

from .. import _lazy_names

_PUBLIC = {
    "stability": ".spin_stability", "StabilityReport": ".spin_stability", "AxisStability": ".spin_stability",
    "polhode_period": ".spin_stability",
    "simulate": ".simulation", "METHODS": ".simulation",
    "Trajectory": ".trajectory",
    "polhode": ".poinsot", "herpolhode": ".poinsot", "invariant_plane": ".poinsot",
    "plot_trajectory": ".plot",
    "free_body_parameters": ".torque_free", "FreeBodyParameters": ".torque_free",
    "torque_free_motion": ".torque_free",
    "SCHEMES": ".splitting", "SplittingScheme": ".splitting",
    "heavy_top": ".top", "heavy_top_on_pivot": ".top", "HeavyTopReport": ".top", "simulate_top": ".top",
    "TopTrajectory": ".top",
    "apply_impulse": ".impulse", "ImpulseResult": ".impulse",
    "spin_experiment": ".experiment", "SpinExperiment": ".experiment",
    "pseudoforces": ".rotating_frame", "Pseudoforces": ".rotating_frame",
    "integrate_in_rotating_frame": ".rotating_frame",
    "free_precession_rate": ".free_precession", "free_precession_period": ".free_precession",
    "top_cos_theta": ".top_motion", "top_weierstrass_invariants": ".top_motion",
    "weierstrass_p": ".elliptic",
}

__all__ = sorted(_PUBLIC)


__getattr__, __dir__ = _lazy_names(__name__, _PUBLIC, globals())
