"""Rigid-body dynamics: exact torque-free motion, numerical integration with torque, Poinsot construction.

Stages (one module each): :mod:`.elliptic` (special functions) → :mod:`.torque_free` (closed forms, principal
frame) and :mod:`.integrate` (numerical, with torque), :mod:`.free_flow` (one exact free step) →
:mod:`.splitting` (exact free flow + torque kicks, for torques of time and orientation only) → :mod:`.simulate` (public entry, frames) →
:mod:`.trajectory` (result), :mod:`.poinsot` (polhode/herpolhode), :mod:`.plot` (matplotlib figure).
"""

from .plot import plot_trajectory
from .poinsot import herpolhode, invariant_plane, polhode
from .simulate import METHODS, simulate
from .splitting import SCHEMES, SplittingScheme
from .torque_free import FreeBodyParameters, free_body_parameters, torque_free_motion
from .trajectory import Trajectory

__all__ = ["simulate", "Trajectory", "METHODS", "polhode", "herpolhode", "invariant_plane",
           "plot_trajectory", "free_body_parameters", "FreeBodyParameters", "torque_free_motion", "SCHEMES",
           "SplittingScheme"]
