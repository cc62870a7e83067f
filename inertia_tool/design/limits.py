"""Bounds of the spin-it voxel grid (a module of constants, so the command line can show them without
importing the design stages)."""

__all__ = ["DEFAULT_RESOLUTION", "MIN_RESOLUTION", "MAX_RESOLUTION"]

#: Cells across the part's largest extent.
DEFAULT_RESOLUTION = 48

#: Bounds of ``resolution`` (work and memory grow as its cube).
MIN_RESOLUTION, MAX_RESOLUTION = 12, 128
