"""Robots: what simulators need, and robot descriptions in, corrected robot descriptions out.

* Inertial frames checked like Gazebo and MuJoCo, and their file formats (:func:`inertial_frame`,
  :func:`format_inertial`).
* Robot descriptions: read a URDF, xacro, SDFormat or MJCF file (:func:`read_robot`), compute each link's mass
  properties from its geometry in the link frame (:func:`link_inertials`), audit the declared inertials
  against them (:func:`audit_links`) and write a copy of the description with corrected ``<inertial>``
  elements (:func:`write_corrected`).  See ``docs/robots.md``.
"""

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
