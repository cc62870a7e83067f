"""Designing the inside of a part from its mass moments (Chapter 4, "Rigid Body Motion", §4.3–4.4).

Every mass moment is linear in the density field, so a cavity can be placed to make a part spin the way the
user wants: :func:`spin_it` hollows a part into a yo-yo (stable free spin about a chosen axis) or a top
(a heavy symmetric top on a pivot).  Stages: :mod:`.grid` (voxels, depth) → :mod:`.moments` (moment vector,
objectives) → :mod:`.optimize` (quadric cavity) and :mod:`.insert` (a dense insert, a second quadric) →
:mod:`.tetra` and :mod:`.cavity_mesh` (the cavity's surface) → :mod:`.hollow` (re-analysis) → :mod:`.verify`.

The names load on first use (PEP 562), so the command line does not import the design stages to start.
"""

from .. import _lazy_names

_PUBLIC = {"spin_it": ".hollow", "SpinItResult": ".hollow", "SpinDesignMetrics": ".hollow",
           "design_metrics": ".hollow"}

__all__ = sorted(_PUBLIC)


__getattr__, __dir__ = _lazy_names(__name__, _PUBLIC, globals())
