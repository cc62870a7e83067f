"""robot/mjcf.py: an OBJ mesh of several objects is noted on its link (issue 23, item 3): MuJoCo 4.0 compiles only
the first object ('o' or 'g' group) of an OBJ file, the tool the whole file.  The grouping rule is checked
against MuJoCo itself on generated files."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.mjcf import _may_hold_objects, _object_triangles, obj_object_triangles


def _cube_lines(offset, first_vertex):
    corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    lines = [f"v {x + offset} {y} {z}" for x, y, z in corners]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    lines += ["f " + " ".join(str(first_vertex + i) for i in q) for q in quads]
    return lines


def _two_cubes(path, keyword="o"):
    lines = [f"{keyword} first"] + _cube_lines(0.0, 1) + [f"{keyword} second"] + _cube_lines(3.0, 9)
    path.write_text("\n".join(lines) + "\n")


def _model(tmp_path, mesh_file):
    xml = tmp_path / "robot.xml"
    xml.write_text(f'<mujoco><asset><mesh name="m" file="{mesh_file.name}"/></asset><worldbody>'
                   '<body name="link"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
    return xml


@pytest.mark.parametrize("keyword", ["o", "g"])
def test_objects_are_counted_as_mujoco_groups_them(tmp_path, keyword):
    mesh = tmp_path / "cubes.obj"
    _two_cubes(mesh, keyword)
    assert obj_object_triangles(str(mesh)) == [12, 12]
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(_model(tmp_path, mesh)))
    assert int(model.mesh_facenum[0]) == 12                 # MuJoCo keeps the first object only


def test_one_object_and_leading_groups_are_not_counted_twice(tmp_path):
    """Group lines before any face (a file that names its one object) start nothing."""
    mesh = tmp_path / "cube.obj"
    mesh.write_text("\n".join(["o a", "g b"] + _cube_lines(0.0, 1)) + "\n")
    assert obj_object_triangles(str(mesh)) == [12]


def test_the_link_says_mujoco_reads_only_the_first_object(tmp_path):
    mesh = tmp_path / "cubes.obj"
    _two_cubes(mesh)
    robot = read_robot(str(_model(tmp_path, mesh)))
    (link,) = link_inertials(robot, density=1000.0)
    assert link.properties.volume == pytest.approx(2.0)      # the whole file: two unit cubes
    said = [w for w in link.warnings if "MuJoCo 4.0 reads only the first object" in w]
    assert len(said) == 1 and "2 objects" in said[0] and "(12 triangles)" in said[0]


def test_a_single_object_file_has_no_note(tmp_path):
    mesh = tmp_path / "cube.obj"
    mesh.write_text("\n".join(_cube_lines(0.0, 1)) + "\n")
    (link,) = link_inertials(read_robot(str(_model(tmp_path, mesh))), density=1000.0)
    assert not any("first object" in w for w in link.warnings)
    assert np.isclose(link.properties.volume, 1.0)


_LINES = ["f 1 2 3", "f 1 2 3 4", "f 1 2", "o a", "g", "g b", " o c", "\to d", "f\t1 2 3", " f 1 2 3", "v 0 0 0",
          "# o x", "", "fo 1 2 3", "og", "o", "\x0bf 1 2 3", "f\x0c1 2 3 4"]


@settings(max_examples=300, deadline=None)
@given(lines=st.lists(st.sampled_from(_LINES), max_size=12), ending=st.sampled_from(["\n", "\r\n", "\r"]),
       last=st.sampled_from(["", "\n"]))
def test_the_quick_look_misses_no_file_of_several_objects(lines, ending, last):
    """``_may_hold_objects`` (the look that spares most files the line scan) is False only where the scan finds
    fewer than two objects; on a file of two cubes it is True."""
    data = (ending.join(lines) + last).encode()
    if len(_object_triangles(data)) >= 2:
        assert _may_hold_objects(data)


def test_the_quick_look_sees_two_cubes(tmp_path):
    _two_cubes(tmp_path / "two.obj")
    data = (tmp_path / "two.obj").read_bytes()
    assert _may_hold_objects(data) and len(_object_triangles(data)) == 2
    one = b"".join(line + b"\n" for line in data.splitlines() if not line.startswith(b"o"))
    assert not _may_hold_objects(one)
