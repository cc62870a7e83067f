"""Is this a part? The size and density checks that catch a wrong length unit.

STL and OBJ carry no unit.  A millimetre part read as metres is a thousand times too long and a billion times
too heavy, and every number after that is consistent with the mistake, so nothing downstream notices.  These
checks look at the one thing that gives it away, the size (and, with a target mass, the implied density),
and warn with the unit that would fit.  They never change a number: the result stays what was asked for.

Rules (the bounds are in :mod:`inertia_tool.units`):

* size: when no length unit was given (``units=None``, metres assumed), the largest side of the bounding box
  must lie within :data:`~inertia_tool.units.PLAUSIBLE_EXTENT` (0.1 mm to 20 m), else
  :class:`~inertia_tool.errors.ImplausibleSizeWarning`;
* density: a density implied by a target mass must lie within
  :data:`~inertia_tool.units.PLAUSIBLE_DENSITY` (100 to 22,600 kg/m³), else
  :class:`~inertia_tool.errors.ImplausibleDensityWarning` (whether or not a unit was given).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ImplausibleDensityWarning, ImplausibleSizeWarning
from ..units import implausible_density, implausible_extent
from ..integrals import bounding_box

if TYPE_CHECKING:
    from .read import RawMesh

__all__ = ["largest_extent", "warn_implausible_size", "warn_implausible_density"]


def largest_extent(vertices: np.ndarray) -> float:
    """Largest side of the axis-aligned bounding box of ``vertices`` ((n, 3), m); 0 for no vertices."""
    v = np.asarray(vertices, dtype=np.float64)
    if v.size == 0:
        return 0.0
    lo, hi = bounding_box(v)
    return float(np.max(hi - lo))


def warn_implausible_size(raw: RawMesh, *, stacklevel: int = 3) -> bool:
    """Warn (:class:`~inertia_tool.errors.ImplausibleSizeWarning`) when ``raw`` (a
    :class:`~inertia_tool.mesh.read.RawMesh`) was read without a length unit and its size is implausible for
    a part.  Returns whether it warned."""
    if not getattr(raw, "units_assumed", False):
        return False
    why = implausible_extent(largest_extent(raw.vertices))
    if why is None:
        return False
    warnings.warn(ImplausibleSizeWarning(f"{raw.source}: no length unit given (`units`), metres assumed; {why}"),
                  stacklevel=stacklevel)
    return True


def warn_implausible_density(source: str, density: float, mass: float, volume: float, *,
                             stacklevel: int = 3) -> bool:
    """Warn (:class:`~inertia_tool.errors.ImplausibleDensityWarning`) when the density implied by a target
    ``mass`` (kg) over ``volume`` (m³) lies outside every solid material.  Returns whether it warned."""
    why = implausible_density(density)
    if why is None:
        return False
    warnings.warn(ImplausibleDensityWarning(
        f"{source}: the target `mass` {mass:.6g} kg over a volume of {volume:.6g} m³ implies a density of {why}; "
        "check the mass, the mesh and its length `units`"), stacklevel=stacklevel)
    return True
