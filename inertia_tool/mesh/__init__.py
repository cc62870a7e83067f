"""The mesh layer: reading files into SI arrays, welding, checking what the triangles bound, preparing shells.

Stages: :mod:`.read` (files, trimesh objects and arrays → :class:`~.read.RawMesh` in metres) →
:mod:`.weld` (shared vertices) → :mod:`.checks` (edge census, shells, :class:`~.checks.MeshReport`) →
:mod:`.prepare` (what the triangles mean as a solid: refusals, repair, orientation, cavities, overlaps).
:mod:`.intersect` finds, exactly, the face pairs that meet beyond what they share by index (crossings,
face-to-face contact, edge and vertex contact), which is what lets an answer be certified exact.
:class:`~.options.LoadOptions` says how, for every entry point.  :mod:`.plausibility` warns when a part read
without a unit is implausibly large or small (a millimetre file read as metres).
"""

from .checks import MeshReport
from .options import DEFAULT_MAX_FACES, LoadOptions
from .prepare import PreparedMesh, prepare_mesh
from .read import SUPPORTED_SUFFIXES, RawMesh, load_mesh

__all__ = ["LoadOptions", "load_mesh", "RawMesh", "prepare_mesh", "PreparedMesh", "MeshReport",
           "SUPPORTED_SUFFIXES", "DEFAULT_MAX_FACES"]
