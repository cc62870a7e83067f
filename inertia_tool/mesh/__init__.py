"""The mesh layer: reading files into SI arrays, welding, checking what the triangles bound, preparing shells.

Stages: :mod:`.read` (files, trimesh objects and arrays → :class:`~.read.RawMesh` in metres) →
:mod:`.weld` (shared vertices) → :mod:`.checks` (edge census, shells, :class:`~.checks.MeshReport`) →
:mod:`.prepare` (what the triangles mean as a solid: refusals, repair, orientation, cavities, overlaps; its stages
:mod:`.surface`, :mod:`.shells`, :mod:`.welded`, :mod:`.settle`, :mod:`.self_crossing`, :mod:`.classify`,
:mod:`.unite`, :mod:`.certify`).
:mod:`.intersect` finds, exactly, the face pairs that meet beyond what they share by index (crossings,
face-to-face contact, edge and vertex contact), which is what lets an answer be certified exact.
:class:`~.options.LoadOptions` says how, for every entry point.  :mod:`.plausibility` warns when a part read
without a unit is implausibly large or small (a millimetre file read as metres).
"""

from typing import TYPE_CHECKING

from .. import _lazy_names

if TYPE_CHECKING:   # what the names below are, for type checkers and the API docs; loaded on first use
    from .checks import MeshReport
    from .hole_assumptions import UserAssumptions
    from .options import DEFAULT_MAX_FACES, LoadOptions
    from .prepare import PreparedMesh, prepare_mesh
    from .read import SUPPORTED_SUFFIXES, RawMesh, load_mesh

__all__ = ["LoadOptions", "load_mesh", "RawMesh", "prepare_mesh", "PreparedMesh", "MeshReport",
           "SUPPORTED_SUFFIXES", "DEFAULT_MAX_FACES", "UserAssumptions"]

#: The module of each name above; they load on first use (PEP 562), so that a module of this layer can be
#: imported alone (a command's parser reads ``LoadOptions``' limits without the readers and checks).
_PUBLIC = {
    "LoadOptions": ".options", "DEFAULT_MAX_FACES": ".options",
    "load_mesh": ".read", "RawMesh": ".read", "SUPPORTED_SUFFIXES": ".read",
    "prepare_mesh": ".prepare", "PreparedMesh": ".prepare",
    "MeshReport": ".checks", "UserAssumptions": ".hole_assumptions",
}

__getattr__, __dir__ = _lazy_names(__name__, _PUBLIC, globals())
