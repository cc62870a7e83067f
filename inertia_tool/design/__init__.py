"""Designing the inside of a part from its mass moments (Chapter 4, "Rigid Body Motion", §4.3–4.4).

Every mass moment is linear in the density field, so a cavity can be placed to make a part spin the way the
user wants: :func:`spin_it` hollows a part into a yo-yo (stable free spin about a chosen axis) or a top
(a heavy symmetric top on a pivot).  Stages: :mod:`.grid` (voxels, depth) → :mod:`.moments` (moment vector,
objectives) → :mod:`.optimize` (quadric cavity) → :mod:`.hollow` (mesh, boolean, verification).
"""

from .hollow import SpinDesignMetrics, SpinItResult, design_metrics, spin_it

__all__ = ["spin_it", "SpinItResult", "SpinDesignMetrics", "design_metrics"]
