"""Paths of the robot descriptions bundled in tests/data (see tests/data/README.md) shared by the robot tests."""

from pathlib import Path

DATA = Path(__file__).parent / "data" / "robots"
#: Root of the ``example-robot-data`` package files (its ``package://example-robot-data/...`` URIs).
ERD = DATA / "example-robot-data"
PACKAGES = {"example-robot-data": str(ERD)}
UR5 = ERD / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"
PANDA = ERD / "robots" / "panda_description" / "urdf" / "panda.urdf"
UR5_MESHES = ERD / "robots" / "ur_description" / "meshes" / "ur5" / "collision"
PANDA_MESHES = ERD / "robots" / "panda_description" / "meshes" / "collision"
#: Cassie (Agility Robotics, via DAIRLab cassie-gazebo-sim, ISC): an SDFormat 1.x model whose collision geometry
#: is all primitives.
CASSIE_SDF = ERD / "robots" / "cassie_description" / "robots" / "cassie_simple.sdf"
#: MuJoCo models of the Gymnasium environments (MIT): MJCF with default classes, capsules from `fromto`, no meshes.
GYM = DATA / "gymnasium"
