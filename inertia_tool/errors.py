"""Named exceptions and warnings of inertia_tool, in one place.

Every error raised on purpose by the package derives from :class:`InertiaToolError` and also
from the built-in exception a caller would naturally catch (``ValueError``, ``OSError``), so
``except ValueError`` keeps working.  Messages say what was expected and what was found.

====================  ==============================================
exception             meaning
====================  ==============================================
UsageError            bad parameters (units, materials: subclasses)
MeshReadError         the file cannot be read or parsed as a mesh
RobotDescriptionError a robot description (URDF, xacro, SDF, MJCF)
                      cannot be read, or names a mesh that cannot
                      be found
IsolatedProcessError  a parser run in a child process crashed or hit
                      a CPU-time, memory or wall-clock limit
InvalidMeshError      the mesh is read but does not bound a solid
PhysicsError          valid input, but the request cannot be met
                      (e.g. a singular top)
DesignRejectedError   a design (spin-it) is worse than its input by
                      its own verification, on every attempt
OutputCheckError      a file about to be written failed its own
                      check (nothing was written; a bug to report)
====================  ==============================================

Messages name API parameters in backticks (`` `max_faces` ``, `` `repair=True` ``); the command line maps the
exception types to exit codes and the parameter names to its options (``inertia_tool.cli``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from numpy.typing import ArrayLike

__all__ = [
    "InertiaToolError",
    "UsageError",
    "UnitsError",
    "OutputFileError",
    "MaterialError",
    "MeshReadError",
    "RobotDescriptionError",
    "InvalidMeshError",
    "ArrangementError",
    "WorkBudgetError",
    "DesignRejectedError",
    "NoRoomError",
    "PhysicsError",
    "OutputCheckError",
    "InternalInvariantError",
    "IsolatedProcessError",
    "InertiaToolWarning",
    "MeshRepairedWarning",
    "InsideOutWarning",
    "MeshResolvedWarning",
    "DegenerateFacesWarning",
    "NearlyEqualMomentsWarning",
    "PhysicalValidityWarning",
    "OverlapWarning",
    "TrailingDataWarning",
    "AsymmetricTopWarning",
    "MalformedTextWarning",
    "ImplausibleSizeWarning",
    "ImplausibleDensityWarning",
    "ImplausibleCorrectionWarning",
    "ImplausiblePointWarning",
    "PivotOffPartWarning",
    "StoragePrecisionWarning",
    "NonMaterialVolumeWarning",
    "SkippedModelWarning",
    "NonPlanarPolygonWarning",
    "NoCollidingGeomWarning",
    "PackageFolderWarning",
]


class InertiaToolError(Exception):
    """Base class of every error that inertia_tool raises on purpose."""



class UsageError(InertiaToolError, ValueError):
    """A parameter is missing, malformed or contradicts another one."""



class OutputFileError(UsageError):
    """An output file cannot be written: it exists (without ``force``), is a symbolic link or a directory, its
    directory is missing, or the operating system refused the write (:mod:`inertia_tool.output`)."""


class UnitsError(UsageError):
    """A unit or quantity string is not understood (e.g. ``--units furlong``)."""


class MaterialError(UsageError):
    """A material name is not in the documented table (see ``inertia_tool.units.MATERIALS``)."""


class MeshReadError(InertiaToolError, OSError):
    """A file cannot be opened or parsed as a triangle mesh.

    The message names the file and what was wrong with its bytes.
    """



class RobotDescriptionError(InertiaToolError, ValueError):
    """A robot description (URDF, xacro, SDFormat, MJCF) cannot be read or refers to something that is not there.

    The message names the file and, where it applies, the link and the URI that could not be resolved.
    """


class InvalidMeshError(InertiaToolError, ValueError):
    """A mesh was read but does not bound a solid (open, non-manifold, empty, flat, ...).

    Parameters
    ----------
    message : str
        One line naming the file and the problem.
    details : dict, optional
        Machine-readable counts (``boundary_edges``, ``nonmanifold_edges`` ...) where known; kept as the
        ``details`` attribute.
    """


    def __init__(self, message: str, details: dict[str, Any] | None = None):
        super().__init__(message)
        self.details = dict(details or {})


class ArrangementError(InvalidMeshError):
    """The solid {winding number ≥ 1} of a surface passing through itself could not be built by the mesh
    arrangement (:mod:`inertia_tool.mesh.arrange`): a degenerate crossing, or an output that failed its checks.
    The message says which."""


class WorkBudgetError(InvalidMeshError):
    """An estimate would do more work than its stated, deterministic budget (counted before the work is done,
    never timed: the same answer on every machine), e.g. the winding numbers of more grid cells than
    :data:`inertia_tool.mesh.grid_estimate.WINDING_EVALUATION_BUDGET`.  ``details`` holds ``evaluations``,
    ``budget`` and ``resolution``."""


class IsolatedProcessError(InertiaToolError, OSError):
    """Work run in a child process (:mod:`inertia_tool.isolate`: xacro expansion, OpenCASCADE) did not finish:
    it crashed, or it hit its CPU-time, memory or wall-clock limit.

    Parameters
    ----------
    message : str
        One line: what ran and why it stopped ("xacro expansion exceeded 30 s of CPU ...").
    kind : str
        ``"cpu"``, ``"memory"``, ``"wall"``, ``"crash"`` (a signal or no answer) or ``"error"`` (an exception
        that is not one of the package's); kept as the ``kind`` attribute.
    """

    def __init__(self, message: str, kind: str = "crash"):
        super().__init__(message)
        self.kind = kind

    @property
    def reason(self) -> str:
        """The message: what ran and why it stopped."""
        return str(self)


class PhysicsError(InertiaToolError, ValueError):
    """The input is well formed but the physical request has no valid answer."""


class NoRoomError(PhysicsError):
    """``spin-it``: the part is too thin at the chosen resolution for a cavity inside its wall.

    ``suggested`` is the resolution the part's depth suggests (None when none up to the largest would do).
    """

    def __init__(self, message: str, suggested: int | None = None):
        super().__init__(message)
        self.suggested = suggested


class DesignRejectedError(PhysicsError):
    """A design (``spin-it``) made the part worse by its own verification — the spin axis off a principal
    axis, a worse objective or a larger simulated wobble — on every attempt; nothing is written (exit code 6).
    """



class OutputCheckError(InertiaToolError, RuntimeError):
    """A file the tool was about to write failed the check made before it is written (e.g. a corrected robot
    description that, read back, differs from its input outside the corrected elements).  Nothing is written;
    it is a bug of the tool (exit code 1), and the message says which element differed and how.
    """


class InternalInvariantError(InertiaToolError, RuntimeError):
    """A condition the tool's own pipeline guarantees did not hold (e.g. an estimated result without its
    estimate).  Never caused by the input alone: it is a bug of the tool (exit code 1, "unexpected internal
    error"), raised instead of going on with a number that rests on the broken condition.  The message names the
    condition expected and what was found.
    """


class NonFiniteResultError(PhysicsError, OverflowError):
    """A result does not fit a float64: it overflows to infinity, becomes NaN, or underflows to zero, because
    an input (a density, a speed, a length) lies outside any physically meaningful range.

    Raised by the engine instead of returning the number or failing with a bare ``OverflowError``.
    """

    @classmethod
    def check(cls, what: str, value: ArrayLike, *, because: str = "") -> None:
        """Raise unless every entry of ``value`` is finite; the message names ``what`` and ``because``."""
        if type(value) is float and value - value == 0.0:     # a finite Python float: the common case, no numpy
            return
        import numpy as np
        a = np.asarray(value, dtype=np.float64)
        if not np.all(np.isfinite(a)):
            bad = a[~np.isfinite(a)].ravel()[0]
            raise cls(f"{what} is {bad} (not representable as a float64)"
                      + (f": {because}" if because else ": an input is outside any physically meaningful range"))


class InertiaToolWarning(UserWarning):
    """Base class of the soft problems inertia_tool reports (it computed a result, but assumed something)."""


class MeshRepairedWarning(InertiaToolWarning):
    """The mesh was changed (holes closed, winding fixed) before integration, at the user's request."""


class MeshResolvedWarning(InertiaToolWarning):
    """The mesh is not a clean 2-manifold but defines a solid exactly: bodies touching along an edge or at a
    vertex, faces wound the wrong way (turned), vertex copies a rounding apart (welded).  The mass properties
    are exact; the mesh report's ``method`` and ``notes`` say what was found."""


class InsideOutWarning(InertiaToolWarning):
    """A shell had inward-facing normals (negative volume) and was flipped."""


class DegenerateFacesWarning(InertiaToolWarning):
    """Zero-area faces were found; they contribute nothing and were ignored."""


class NearlyEqualMomentsWarning(InertiaToolWarning):
    """Two principal moments agree within the tolerance: the axes in their plane are a free choice."""


class PhysicalValidityWarning(InertiaToolWarning):
    """Principal moments fail positivity or the triangle inequality beyond round-off."""


class OverlapWarning(InertiaToolWarning):
    """Two shells overlap, so some volume is counted twice."""


class TrailingDataWarning(InertiaToolWarning):
    """A file carried bytes after the data its header announced; they were ignored."""


class AsymmetricTopWarning(InertiaToolWarning):
    """A body analysed as a symmetric top is not one: its two moments transverse to the pivot→centre-of-mass
    axis differ (or that axis is not principal about the pivot) beyond the tolerance; their mean was used."""


class MalformedTextWarning(InertiaToolWarning):
    """A text mesh file had lines that were not understood or structure keywords missing.

    The geometry lines were still unambiguous (e.g. three ``vertex`` lines per ``facet`` in an ASCII STL),
    so they were read; the warning says what was skipped.
    """


class ImplausibleSizeWarning(InertiaToolWarning):
    """The mesh is implausibly large or small for a part and no length unit was given (metres assumed):
    most likely the file is in millimetres or inches.  The numbers stay those of the unit assumed; the
    message names the unit that would make the size plausible (rule: :data:`inertia_tool.units.PLAUSIBLE_EXTENT`)."""


class ImplausibleDensityWarning(InertiaToolWarning):
    """The density implied by a target ``mass`` lies outside every solid material
    (:data:`inertia_tool.units.PLAUSIBLE_DENSITY`): the mass, the mesh or its length unit is likely wrong."""


class ImplausiblePointWarning(InertiaToolWarning):
    """A reference point (``inertia_about``, ``--about``) lies implausibly far from the part for its size
    (:data:`inertia_tool.tolerances.FAR_POINT_RATIO` sizes): most likely a units slip, e.g. millimetre
    coordinates passed to an API that takes metres.  The result is computed as asked."""


class PivotOffPartWarning(InertiaToolWarning):
    """spin-it's top pivot lies in empty space, away from the part (farther than
    :data:`inertia_tool.tolerances.PIVOT_GAP_RTOL` of its largest extent from its surface, outside it): a top
    stands on a point of its own surface, so the design is for a part held on a pin it does not have; most likely a
    wrong ``--pivot`` or a units slip.  The design is computed as asked."""


class ImplausibleCorrectionWarning(InertiaToolWarning):
    """A balancing correction lies outside the part (radius beyond its extent, plane beyond its ends) or is a
    sizeable fraction of the part's mass: possible on paper, but check the inputs before drilling."""


class StoragePrecisionWarning(InertiaToolWarning):
    """The file stores coordinates as float32 (binary STL, PLY ``float``, glTF/GLB, COLLADA) and the part lies so
    far from the origin, or is so thin, that this rounding alone bounds the volume only loosely: the stored mesh
    is integrated exactly, but it is not the drawn part to the digits reported.  The message gives the bound
    (:mod:`inertia_tool.mesh.precision`)."""


class NonMaterialVolumeWarning(InertiaToolWarning):
    """A slicer project holds volumes that are not material (PrusaSlicer's modifiers, support blockers and
    enforcers; Bambu Studio's modifier parts): they change how the slicer prints, not what is printed, and
    are left out of the mass properties."""


class SkippedModelWarning(InertiaToolWarning):
    """A robot description (a Gazebo world) includes a stock model that is not on disk and has no link with
    mass (``model://sun``, a light; ``model://ground_plane``, a static plane): it is skipped, and the message
    names it."""


class PackageFolderWarning(InertiaToolWarning):
    """A ``package://NAME/...`` URI names no ROS package that can be found, but a plain folder ``NAME`` beside
    the description holds the file (MuJoCo Menagerie's Barkour vb URDF writes ``package://assets/neck.stl`` for
    its ``assets/`` folder).  The file is read from that folder; ROS tools would not resolve the URI."""


class NoCollidingGeomWarning(InertiaToolWarning):
    """An MJCF description read for its collision geometry has no geom that collides: every geom has
    ``contype`` and ``conaffinity`` 0 and none is in a ``<contact><pair>`` of the file (MuJoCo Menagerie's
    Apptronik Apollo: its collision class collides only through the pairs of the ``scene.xml`` that includes
    it).  MuJoCo finds no contact with the file alone, so no link has collision geometry; the message names the
    files beside it that include it."""


class NonPlanarPolygonWarning(InertiaToolWarning):
    """An OBJ holds quadrilaterals whose corners are not in one plane: such a quad bounds no definite surface,
    and its two possible splits into triangles enclose different solids.  The reader splits each along its
    shorter diagonal (MuJoCo's rule; trimesh and most viewers split from the first corner); the message gives
    how much the other split could change the volume, as a fraction of the enclosed volume."""
