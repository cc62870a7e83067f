"""``LoadOptions``: how a mesh source becomes a checked solid — one definition for every entry point.

``mass_properties``, ``assembly``, the thin-walled models, batch runs and the command line all take these
options through this one object (or its fields as keyword arguments, a shortcut that builds one), so a new
option is added once.
"""

from __future__ import annotations

from dataclasses import fields, replace
from typing import Any

import numpy as np

from ..values import frozen_value
from ..errors import UsageError
from ..tolerances import DEFAULT_MAX_FACES, MAX_SUPPORTED_FACES, MERGE_TOLERANCE
from ..units import length_scale

__all__ = ["LoadOptions", "DEFAULT_MAX_FACES", "MAX_SUPPORTED_FACES"]

@frozen_value
class LoadOptions:
    """How to read and check a mesh.  Immutable; build variants with :meth:`replace`.

    Attributes
    ----------
    units : str or None
        Length unit of the mesh coordinates: ``m``, ``cm``, ``mm``, ``um``, ``in``, ``ft`` (converted to
        metres on reading; everything after is SI).  ``None`` (the default): not given, metres assumed; a
        part whose size is then implausible raises :class:`~inertia_tool.errors.ImplausibleSizeWarning`
        naming the unit that would fit (STL and OBJ carry no unit).
    repair : bool
        Give a bounded estimate for a mesh that does not bound a solid (holes, cracks, stray pieces) instead
        of refusing it; the mesh report's ``method`` and ``uncertainty`` say what was done and how far off
        the answer can be.  Meshes that define a solid exactly (touching bodies, flipped faces, vertex
        copies a rounding apart) are exact without it.
    overlap : str
        Overlapping bodies: ``"union"`` integrates their union, the physical solid (default); ``"sum"`` adds
        their integrals, counting shared material twice on purpose (said in the report).
    merge_tolerance : float
        Spacing of the tolerance weld, relative to the bounding-box diagonal, used when the bit-exact weld
        leaves the surface open; 0 disables it (default :data:`inertia_tool.tolerances.MERGE_TOLERANCE`).
    declared_units_win : bool
        ``units`` is for the files that carry no unit (STL, OBJ, PLY): a file that declares its own (3MF,
        glTF, COLLADA, STEP) is read in its unit instead of being refused as contradicting ``units``
        (``batch`` over a mixed folder; issue 24).  Default False: a contradiction is refused.
    max_faces : int
        Refuse sources with more triangles than this (a memory guard checked before allocating).
    assume : tuple of str
        Assumptions about the surface a hole lost that the user states and the file cannot show
        (:data:`~inertia_tool.mesh.hole_assumptions.USER_ASSUMPTIONS`), only with ``repair``: ``"flat-islands"``
        — each hole that is an island in a flat face lost a flat piece of that face (filled flat and bounded by
        the rim's own deviation from its plane instead of refused; a boss or pocket taken whole there breaks it).
        The estimate names each one taken as the user's.  Default ``()``: none.
    """

    units: str | None = None
    repair: bool = False
    overlap: str = "union"
    merge_tolerance: float = MERGE_TOLERANCE
    max_faces: int = DEFAULT_MAX_FACES
    declared_units_win: bool = False
    assume: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        from .hole_assumptions import user_named
        if isinstance(self.assume, str) or not isinstance(self.assume, (tuple, list)):
            raise UsageError(f"Expected `assume` to be a tuple of assumption names, got {self.assume!r}")
        try:
            names = user_named(self.assume)
        except ValueError as exc:
            raise UsageError(f"Expected `assume` {exc}") from None
        object.__setattr__(self, "assume", names)
        if names and not self.repair:
            raise UsageError(f"`assume` ({', '.join(names)}) is an assumption about the holes a repair fills: "
                             "expected it with `repair=True`")
        if self.units is not None:
            length_scale(self.units)                  # raises UnitsError for an unknown unit
        if not isinstance(self.repair, (bool, np.bool_)):
            raise UsageError(f"Expected `repair` to be True or False, got {self.repair!r}")
        if self.overlap not in ("union", "sum"):
            raise UsageError(f"Expected `overlap` to be 'union' or 'sum', got {self.overlap!r}")
        tol = self.merge_tolerance
        if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating, np.integer)) \
                or not (np.isfinite(tol) and 0 <= tol < 0.1):
            raise UsageError(f"Expected `merge_tolerance` to be a number in [0, 0.1) (relative to the "
                             f"bounding-box diagonal), got {tol!r}")
        if isinstance(self.max_faces, bool) or not (isinstance(self.max_faces, (int, np.integer))
                                                    and 0 < self.max_faces <= MAX_SUPPORTED_FACES):
            raise UsageError(f"Expected `max_faces` to be an integer from 1 to {MAX_SUPPORTED_FACES:,} (corner "
                             f"indices must fit 32 bits), got {self.max_faces!r}")

    def replace(self, **changes: Any) -> LoadOptions:
        """A copy with some fields changed (validated like a new one)."""
        return replace(self, **changes)

    @classmethod
    def build(cls, options: LoadOptions | None = None, **overrides: Any) -> LoadOptions:
        """``options`` (or the defaults) with keyword overrides; unknown names raise :class:`UsageError`."""
        names = _LOAD_OPTION_NAMES
        unknown = sorted(set(overrides) - names)
        if unknown:
            raise UsageError(f"Expected load options among {', '.join(sorted(names))}, got {', '.join(unknown)}")
        if options is not None and not isinstance(options, LoadOptions):
            raise UsageError(f"Expected `options` to be a LoadOptions, got {type(options).__name__}")
        if options is None:                      # the defaults with the overrides: one construction, not two
            return cls(**overrides)
        return replace(options, **overrides) if overrides else options


#: The field names of :class:`LoadOptions` (every one an ``__init__`` argument), for :meth:`LoadOptions.build`.
_LOAD_OPTION_NAMES = frozenset(f.name for f in fields(LoadOptions))
