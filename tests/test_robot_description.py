"""Reading URDF, xacro, SDFormat and MJCF into links, geometry and declared inertials (inertia_tool.robot)."""

import os

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool.errors import RobotDescriptionError, UsageError
from inertia_tool.robot import read_robot
from inertia_tool.robot.description import rpy_to_matrix
from inertia_tool.robot.mjcf import orientation_matrix

from conftest import assert_tensor_close
from robot_data import PACKAGES, PANDA, UR5, UR5_MESHES

angles = st.floats(-np.pi, np.pi, allow_nan=False)


@settings(max_examples=50, deadline=None)
@given(angles, angles, angles)
def test_rpy_is_fixed_axis_roll_pitch_yaw_like_scipy_extrinsic_xyz(roll, pitch, yaw):
    # URDF: R = Rz(yaw) Ry(pitch) Rx(roll); scipy's lower-case "xyz" is the same extrinsic sequence
    expected = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_matrix()
    np.testing.assert_allclose(rpy_to_matrix([roll, pitch, yaw]), expected, atol=1e-14)


def test_rpy_yaw_turns_x_towards_y():
    np.testing.assert_allclose(rpy_to_matrix([0, 0, np.pi / 2]) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_mjcf_euler_lower_case_rotates_with_the_frame():
    # MuJoCo: lower-case eulerseq letters are intrinsic (rotating) axes, upper-case fixed ones
    attrs = {"euler": "10 20 30"}
    intrinsic = orientation_matrix(attrs, degrees=True, eulerseq="xyz", what="g", source="s")
    fixed = orientation_matrix(attrs, degrees=True, eulerseq="XYZ", what="g", source="s")
    np.testing.assert_allclose(intrinsic, Rotation.from_euler("XYZ", [10, 20, 30], degrees=True).as_matrix(),
                               atol=1e-14)
    np.testing.assert_allclose(fixed, Rotation.from_euler("xyz", [10, 20, 30], degrees=True).as_matrix(), atol=1e-14)


def test_ur5_links_meshes_and_declared_inertials():
    robot = read_robot(UR5, packages=PACKAGES)
    assert robot.format == "urdf" and robot.name == "ur5" and robot.geometry == "collision"
    names = [link.name for link in robot.links]
    assert names[:7] == ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
                         "wrist_2_link", "wrist_3_link"]
    upper = robot.link("upper_arm_link")
    assert len(upper.elements) == 1 and upper.elements[0].kind == "mesh"
    assert os.path.samefile(upper.elements[0].mesh, UR5_MESHES / "upperarm.stl")
    # declared in the file: mass 8.393, origin xyz 0 0 0.28, ixx = iyy = 0.22689067591, izz = 0.0151074
    assert upper.declared.mass == 8.393
    np.testing.assert_array_equal(upper.declared.center_of_mass, [0, 0, 0.28])
    np.testing.assert_array_equal(np.diag(upper.declared.inertia), [0.22689067591, 0.22689067591, 0.0151074])
    assert robot.link("world").declared is None and robot.link("world").elements == ()


def test_declared_inertia_is_rotated_into_link_axes(tmp_path):
    f = tmp_path / "r.urdf"
    f.write_text('<robot name="r"><link name="a"><inertial><origin xyz="1 2 3" rpy="0 0 1.5707963267948966"/>'
                 '<mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/></inertial>'
                 '</link></robot>')
    d = read_robot(f).link("a").declared
    assert_tensor_close(d.inertia, np.diag([2.0, 1.0, 3.0]), 1e-14)   # x and y swap under a 90° yaw
    np.testing.assert_array_equal(d.center_of_mass, [1, 2, 3])


def test_unresolved_package_names_the_link_and_the_uri(monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    with pytest.raises(RobotDescriptionError) as exc:
        read_robot(UR5)
    msg = str(exc.value)
    assert "link 'base_link'" in msg
    assert "package://example-robot-data/robots/ur_description/meshes/ur5/collision/base.stl" in msg
    assert "\n" not in msg


def test_ros_package_path_is_searched(monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", os.pathsep.join(["/nonexistent", str(PACKAGES["example-robot-data"])]))
    robot = read_robot(UR5)
    assert robot.link("base_link").elements[0].mesh.endswith("base.stl")


def test_file_uri_relative_path_and_missing_file(tmp_path):
    stl = str(UR5_MESHES / "base.stl")
    f = tmp_path / "r.urdf"
    os.symlink(stl, tmp_path / "b.stl")
    f.write_text(f'<robot name="r"><link name="a"><collision><geometry><mesh filename="file://{stl}"/></geometry>'
                 '</collision><collision><geometry><mesh filename="b.stl"/></geometry></collision></link>'
                 '<link name="c"><collision><geometry><mesh filename="missing.stl"/></geometry></collision>'
                 '</link></robot>')
    with pytest.raises(RobotDescriptionError,
                       match=r"link 'c': mesh 'missing.stl': resolves to .*missing.stl, which does not exist"):
        read_robot(f)
    f.write_text(f.read_text().replace('<link name="c"><collision><geometry><mesh filename="missing.stl"/></geometry>'
                                       '</collision></link>', ""))
    a = read_robot(f).link("a")
    assert [os.path.realpath(e.mesh) for e in a.elements] == [os.path.realpath(stl)] * 2


def test_visual_geometry_is_chosen_on_request():
    robot = read_robot(PANDA, packages=PACKAGES, geometry="collision")
    assert robot.link("panda_link1").elements[0].mesh.endswith("collision/link1.stl")
    with pytest.raises(RobotDescriptionError, match="visual/link0.dae"):   # visual meshes are not bundled
        read_robot(PANDA, packages=PACKAGES, geometry="visual")
    with pytest.raises(UsageError):
        read_robot(PANDA, packages=PACKAGES, geometry="both")


XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="radius" default="0.05"/>
  <xacro:property name="r" value="$(arg radius)"/>
  <xacro:macro name="rod" params="name length">
    <link name="${name}">
      <collision><origin xyz="0 0 ${length/2}" rpy="0 0 0"/>
        <geometry><cylinder radius="${r}" length="${length}"/></geometry></collision>
    </link>
  </xacro:macro>
  <xacro:rod name="upper" length="0.4"/>
  <xacro:rod name="lower" length="0.3"/>
  <link name="tool"><collision><geometry>
    <mesh filename="$(find example-robot-data)/robots/ur_description/meshes/ur5/collision/wrist3.stl"/>
  </geometry></collision></link>
</robot>
"""


def test_xacro_is_expanded_with_arguments_and_find(tmp_path):
    f = tmp_path / "arm.urdf.xacro"
    f.write_text(XACRO)
    robot = read_robot(f, packages=PACKAGES, mappings={"radius": "0.02"}, run_xacro=True)
    assert robot.format == "xacro" and [link.name for link in robot.links] == ["upper", "lower", "tool"]
    lower = robot.link("lower").elements[0]
    assert lower.kind == "cylinder" and lower.size == (0.02, 0.3)
    np.testing.assert_allclose(lower.translation, [0, 0, 0.15])
    assert robot.link("tool").elements[0].mesh.endswith("wrist3.stl")
    assert read_robot(f, packages=PACKAGES, run_xacro=True).link("upper").elements[0].size == (0.05, 0.4)


def test_xacro_errors_are_one_line(tmp_path):
    f = tmp_path / "bad.xacro"
    f.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:undefined_macro/></robot>')
    with pytest.raises(RobotDescriptionError, match="xacro expansion failed"):
        read_robot(f, run_xacro=True)
    with pytest.raises(UsageError, match="not a xacro file"):
        read_robot(UR5, packages=PACKAGES, mappings={"a": "1"})


SDF = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="m">
    <link name="l">
      <pose>5 5 5 0 0 0</pose>
      <inertial><pose>0.1 0 0 0 0 1.5707963267948966</pose><mass>3</mass>
        <inertia><ixx>1</ixx><ixy>0</ixy><ixz>0</ixz><iyy>2</iyy><iyz>0</iyz><izz>3</izz></inertia></inertial>
      <collision name="box"><pose>0 0 0.5 0 0 0</pose><geometry><box><size>1 2 3</size></box></geometry></collision>
      <collision name="cap"><geometry><capsule><radius>0.1</radius><length>0.2</length></capsule></geometry></collision>
      <visual name="v"><geometry><sphere><radius>9</radius></sphere></geometry></visual>
    </link>
  </model>
</sdf>
"""


def test_sdf_links_poses_and_inertial(tmp_path):
    f = tmp_path / "m.sdf"
    f.write_text(SDF)
    robot = read_robot(f)
    link = robot.link("l")
    assert robot.format == "sdf" and [e.name for e in link.elements] == ["box", "cap"]
    assert link.elements[0].size == (1.0, 2.0, 3.0) and link.elements[1].size == (0.1, 0.2)
    np.testing.assert_array_equal(link.elements[0].translation, [0, 0, 0.5])   # relative to the link
    assert_tensor_close(link.declared.inertia, np.diag([2.0, 1.0, 3.0]), 1e-14)
    assert read_robot(f, geometry="visual").link("l").elements[0].size == (9.0,)


def test_malformed_and_unknown_files(tmp_path):
    f = tmp_path / "x.urdf"
    f.write_text("<robot><link name='a'>")
    with pytest.raises(RobotDescriptionError, match="not well-formed XML"):
        read_robot(f)
    with pytest.raises(RobotDescriptionError, match="no such file"):
        read_robot(tmp_path / "none.urdf")
    g = tmp_path / "x.txt"
    g.write_text("<robot/>")
    with pytest.raises(RobotDescriptionError, match="unknown robot description type"):
        read_robot(g)
    f.write_text("<robot name='r'><link name='a'><collision><geometry><box size='1 -2 3'/></geometry></collision>"
                 "</link></robot>")
    with pytest.raises(RobotDescriptionError, match="expected a positive size"):
        read_robot(f)


LAUGHS = ('<?xml version="1.0"?>\n<!DOCTYPE r [\n <!ENTITY a "aaaaaaaaaa">\n'
          + "".join(f' <!ENTITY {c} "{("&" + p + ";") * 10}">\n' for p, c in zip("abcdefgh", "bcdefghi"))
          + ']>\n<robot name="&i;"><link name="a"/></robot>\n')


@pytest.mark.parametrize("suffix", [".urdf", ".urdf.xacro"])
def test_billion_laughs_is_refused_not_expanded(tmp_path, suffix):
    f = tmp_path / f"laughs{suffix}"
    f.write_text(LAUGHS)                          # 10⁹ bytes if expanded
    with pytest.raises(RobotDescriptionError, match="amplification"):
        read_robot(f, run_xacro=True)


@pytest.mark.parametrize("suffix, text", [
    (".urdf", '<robot name="r"><link name="l"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" '
              'iyz="0" izz="1"/></inertial><collision><geometry><box size="1 1 1"/></geometry></collision></link>'
              '<link name="l"><collision><geometry><box size="1 2 1"/></geometry></collision></link></robot>'),
    (".sdf", '<sdf version="1.9"><model name="m"><link name="l"><collision name="c"><geometry><box><size>1 1 1'
             '</size></box></geometry></collision></link><link name="l"><collision name="c"><geometry><box><size>'
             '1 2 1</size></box></geometry></collision></link></model></sdf>'),
    (".xml", '<mujoco><worldbody><body name="l"><geom type="box" size="1 1 1"/></body><body name="l">'
             '<geom type="box" size="1 2 1"/></body></worldbody></mujoco>')])
def test_two_links_of_one_name_are_refused(tmp_path, suffix, text):
    # results, declared inertials and --write corrections are matched by link name: with two links named 'l',
    # --keep-mass paired the first link's declared mass with the second and --write put the first box's tensor
    # into the second link's new <inertial>
    path = tmp_path / f"dup{suffix}"
    path.write_text(text)
    with pytest.raises(RobotDescriptionError, match="two links are named 'l'"):
        read_robot(path)


def test_a_package_uri_with_three_slashes_names_the_package_in_its_path(tmp_path):
    # example-robot-data 6.0.0, talos_full_v2.urdf: package:///example-robot-data/robots/talos_data/meshes/...
    from inertia_tool.mass import shapes
    from inertia_tool.robot.resolve import resolve_uri
    (tmp_path / "pkg" / "meshes").mkdir(parents=True)
    shapes.write_stl(shapes.box(0.1, 0.2, 0.3), tmp_path / "pkg" / "meshes" / "b.stl")
    expected = str(tmp_path / "pkg" / "meshes" / "b.stl")
    for uri in ("package:///pkg/meshes/b.stl", "package://pkg/meshes/b.stl"):
        assert resolve_uri(uri, base=str(tmp_path), packages={"pkg": tmp_path / "pkg"}, source="r.urdf",
                           link="l") == expected


def test_a_package_uri_naming_a_plain_folder_beside_the_description_is_read_with_a_warning(tmp_path):
    # MuJoCo Menagerie's Barkour vb URDF: package://assets/neck.stl for the assets/ folder beside it
    import warnings as _warnings

    from inertia_tool.errors import PackageFolderWarning
    from inertia_tool.mass import shapes
    from inertia_tool.robot.resolve import resolve_uri
    (tmp_path / "assets").mkdir()
    shapes.write_stl(shapes.box(0.1, 0.2, 0.3), tmp_path / "assets" / "neck.stl")
    with pytest.warns(PackageFolderWarning, match="no ROS package 'assets' found"):
        path = resolve_uri("package://assets/neck.stl", base=str(tmp_path), packages={}, source="r.urdf", link="l")
    assert path == str(tmp_path / "assets" / "neck.stl")
    # nothing above the description is guessed, a missing file stays an error, and a folder whose package.xml
    # names another package is not taken for this one
    (tmp_path / "sub").mkdir()
    with _warnings.catch_warnings():
        _warnings.simplefilter("error")
        with pytest.raises(RobotDescriptionError, match="cannot resolve package 'assets'"):
            resolve_uri("package://assets/neck.stl", base=str(tmp_path / "sub"), packages={}, source="r.urdf",
                        link="l")
        with pytest.raises(RobotDescriptionError, match="cannot resolve package 'assets'"):
            resolve_uri("package://assets/head.stl", base=str(tmp_path), packages={}, source="r.urdf", link="l")
        (tmp_path / "assets" / "package.xml").write_text("<package><name>other</name></package>")
        with pytest.raises(RobotDescriptionError, match="cannot resolve package 'assets'"):
            resolve_uri("package://assets/neck.stl", base=str(tmp_path), packages={}, source="r.urdf", link="l")
