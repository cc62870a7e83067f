"""Robots: what simulators need, and robot descriptions in, corrected robot descriptions out.

* Inertial frames checked like Gazebo and MuJoCo, and their file formats (:func:`inertial_frame`,
  :func:`format_inertial`).
* Robot descriptions: read a URDF, xacro, SDFormat or MJCF file (:func:`read_robot`), compute each link's mass
  properties from its geometry in the link frame (:func:`link_inertials`), audit the declared inertials
  against them (:func:`audit_links`) and write a copy of the description with corrected ``<inertial>``
  elements (:func:`write_corrected`; the elements are located in the file's own text by the tokenizer of
  ``inertia_tool.robot.xmlspans`` and the copy is checked against the input before it is written).  See
  ``docs/robots.md``.
"""

from .. import _lazy_names
from typing import TYPE_CHECKING

if TYPE_CHECKING:   # what the names below are, for type checkers and the API docs; loaded on first use
    from .formats import ROBOT_FORMATS, format_inertial
    from .inertial import FRAMES, InertialFrame, MomentCheck, check_moments, inertial_frame, principal_frame_nearest
    from .audit import LinkAudit, audit_links
    from .description import DeclaredInertial, GeometryElement, LinkGeometry, RobotDescription, read_robot
    from .geometry import LinkInertial, link_inertials
    from .write import write_corrected

__all__ = ["inertial_frame", "InertialFrame", "check_moments", "MomentCheck", "FRAMES", "format_inertial",
           "ROBOT_FORMATS", "principal_frame_nearest", "read_robot", "RobotDescription", "LinkGeometry",
           "GeometryElement", "DeclaredInertial", "link_inertials", "LinkInertial", "audit_links", "LinkAudit",
           "write_corrected"]

#: The module of each name above; they load on first use (PEP 562), so that ``inertia-tool analyze
#: --format urdf`` imports the inertial frame and its formats without the description readers and writers.
_PUBLIC = {
    "ROBOT_FORMATS": ".formats", "format_inertial": ".formats",
    "FRAMES": ".inertial", "InertialFrame": ".inertial", "MomentCheck": ".inertial", "check_moments": ".inertial",
    "inertial_frame": ".inertial", "principal_frame_nearest": ".inertial",
    "LinkAudit": ".audit", "audit_links": ".audit",
    "DeclaredInertial": ".description", "GeometryElement": ".description", "LinkGeometry": ".description",
    "RobotDescription": ".description", "read_robot": ".description",
    "LinkInertial": ".geometry", "link_inertials": ".geometry",
    "write_corrected": ".write",
}


__getattr__, __dir__ = _lazy_names(__name__, _PUBLIC, globals())
