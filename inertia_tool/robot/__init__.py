"""What robot simulators need: inertial frames checked like Gazebo and MuJoCo, and their file formats."""

from .formats import ROBOT_FORMATS, format_inertial
from .inertial import FRAMES, InertialFrame, MomentCheck, check_moments, inertial_frame

__all__ = ["inertial_frame", "InertialFrame", "check_moments", "MomentCheck", "FRAMES", "format_inertial",
           "ROBOT_FORMATS"]
