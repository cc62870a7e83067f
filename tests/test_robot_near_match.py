"""Issue 23: a mesh path that does not exist as written names the file the author probably meant.

MuJoCo Menagerie's Barkour v0 URDF names ``meshes/head.stl``; the files are in ``assets/``.  A path that differs
only in case is a different file on Linux's file systems (and the same one on Windows' and macOS's defaults).  The
tool never reads a file the description does not name; the one-line refusal names the near match instead
(:func:`inertia_tool.robot.resolve.near_match`).
"""

from __future__ import annotations

import os

import pytest

from inertia_tool.errors import RobotDescriptionError
from inertia_tool.robot import read_robot
from inertia_tool.robot.resolve import near_match

STL = b"solid t\nendsolid t\n"


def _urdf(folder, uri: str) -> str:
    path = os.path.join(folder, "r.urdf")
    with open(path, "w") as fh:
        fh.write(f'<robot name="r"><link name="a"><collision><geometry><mesh filename="{uri}"/></geometry>'
                 '</collision></link></robot>')
    return path


def _file(path) -> str:
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as fh:
        fh.write(STL)
    return str(path)


def _refusal(folder, uri: str) -> str:
    with pytest.raises(RobotDescriptionError) as info:
        read_robot(_urdf(folder, uri))
    message = str(info.value)
    assert "\n" not in message and "which does not exist" in message
    return message


def test_the_same_name_in_a_sibling_folder(tmp_path):
    """Barkour v0: ``meshes/`` does not exist, ``assets/head.stl`` does."""
    found = _file(tmp_path / "assets" / "head.stl")
    message = _refusal(tmp_path, "meshes/head.stl")
    assert message.endswith(f"; near match: {found} (the folder meshes/ does not exist beside {tmp_path.name}/; "
                            "a file of that name is in assets/)")


def test_a_path_that_differs_in_case_only(tmp_path):
    found = _file(tmp_path / "Meshes" / "Head.STL")
    if os.path.exists(tmp_path / "meshes" / "head.stl"):
        pytest.skip("a case-insensitive file system: the path as written exists")
    message = _refusal(tmp_path, "meshes/head.stl")
    assert message.endswith(f"; near match: {found} (differs in case only; this file system tells case apart)")


def test_another_extension(tmp_path):
    found = _file(tmp_path / "meshes" / "head.obj")
    message = _refusal(tmp_path, "meshes/head.stl")
    assert message.endswith(f"; near match: {found} (another extension)")


def test_no_near_match_adds_nothing(tmp_path):
    _file(tmp_path / "assets" / "tail.stl")
    _file(tmp_path / "meshes" / "head.txt")         # not a mesh extension
    message = _refusal(tmp_path, "meshes/head.stl")
    assert message.endswith("which does not exist")
    assert near_match(str(tmp_path / "nowhere" / "deeper" / "x.stl")) is None


def test_a_missing_mjcf_mesh_per_link_keeps_its_path_with_a_near_match(tmp_path):
    """``missing_meshes="per-link"`` (the benchmark's reading) takes the path from the refusal: the hint after
    it must not become part of the path."""
    _file(tmp_path / "assets" / "part.obj")
    (tmp_path / "m.xml").write_text(
        '<mujoco><compiler meshdir="assets"/><asset><mesh name="p" file="part.stl"/></asset><worldbody>'
        '<body name="b"><geom type="mesh" mesh="p"/></body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="near match: .*part.obj"):
        read_robot(str(tmp_path / "m.xml"))
    robot = read_robot(str(tmp_path / "m.xml"), missing_meshes="per-link")
    (element,) = robot.links[-1].elements
    assert element.mesh == str(tmp_path / "assets" / "part.stl")
